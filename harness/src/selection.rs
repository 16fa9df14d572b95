//! Runs limited to what the user names (book: cli.md): `--estimators` and `--testbeds`, comma
//! lists of ids with `*` globs, for `run` (named experiments, the suite and custom sweeps) and
//! `conformance`. A pattern that matches nothing is bad input naming it and the valid ids.
//!
//! The registry a run sees is narrowed ([`Selection::apply`]), so the experiments derived from it
//! (`unbiasedness`, `calibration`) and the conformance suite run only the named plug-ins; when
//! estimators are named, a test bed none of them runs on is left out with a one-line note, so a
//! reference it would need is never asked for. Fixed sweeps keep only their named entries
//! ([`Selection::filter_sweep`]).
//!
//! ```
//! use mcbench::selection::Selection;
//!
//! let registry = mcbench::Registry::new().with_catalog(mcbench_papers::catalog());
//! let only = Selection::new(Some("integrand_*"), None);
//! let (narrowed, notes) = only.apply(&registry).unwrap();
//! assert!(narrowed.estimators().iter().all(|e| e.id.starts_with("integrand_")));
//! assert!(narrowed.test_beds().iter().all(|t| t.id == "product-peak" || t.id == "cosine-power"));
//! assert!(notes.iter().any(|n| n.contains("checker-image")));
//! let e = Selection::new(Some("no_such*"), None).apply(&registry).unwrap_err().to_string();
//! assert!(e.contains("--estimators") && e.contains("no_such*") && e.contains("integrand_mc"), "{e}");
//! ```

use crate::config::Sweep;
use crate::registry::Registry;
use mcbench_core::error::ConfigError;

/// The estimators and test beds named on the command line (`None`: all).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Selection {
    estimators: Option<Vec<String>>,
    testbeds: Option<Vec<String>>,
}

/// Whether `name` matches `pattern`, where `*` stands for any run of characters.
pub fn glob(pattern: &str, name: &str) -> bool {
    let parts: Vec<&str> = pattern.split('*').collect();
    if parts.len() == 1 {
        return pattern == name;
    }
    let (first, last) = (parts[0], parts[parts.len() - 1]);
    if !name.starts_with(first) || name.len() < first.len() + last.len() || !name.ends_with(last) {
        return false;
    }
    let mut rest = &name[first.len()..name.len() - last.len()];
    for part in &parts[1..parts.len() - 1] {
        match rest.find(part) {
            Some(i) => rest = &rest[i + part.len()..],
            None => return false,
        }
    }
    true
}

fn split(list: Option<&str>) -> Option<Vec<String>> {
    list.map(|l| l.split(',').map(|p| p.trim().to_string()).filter(|p| !p.is_empty()).collect())
}

fn any(patterns: &Option<Vec<String>>, id: &str) -> bool {
    patterns.as_ref().is_none_or(|ps| ps.iter().any(|p| glob(p, id)))
}

/// Every pattern matches some id, else bad input naming `flag`, the pattern and the valid ids.
fn check(flag: &str, patterns: &Option<Vec<String>>, ids: &[&str]) -> Result<(), ConfigError> {
    for p in patterns.iter().flatten() {
        if !ids.iter().any(|id| glob(p, id)) {
            return Err(ConfigError::invalid(flag, p, format!("matches nothing (valid: {})", ids.join(", "))));
        }
    }
    if patterns.as_ref().is_some_and(|p| p.is_empty()) {
        return Err(ConfigError::invalid(flag, "", format!("names nothing (valid: {})", ids.join(", "))));
    }
    Ok(())
}

impl Selection {
    /// From the two comma lists (`None`: all).
    pub fn new(estimators: Option<&str>, testbeds: Option<&str>) -> Self {
        Selection { estimators: split(estimators), testbeds: split(testbeds) }
    }

    /// The same with the estimator ids `ids` added (the ids `conformance` takes as arguments).
    pub fn with_estimator_ids(mut self, ids: &[String]) -> Self {
        if !ids.is_empty() {
            self.estimators.get_or_insert_with(Vec::new).extend(ids.iter().cloned());
        }
        self
    }

    /// True when nothing is named.
    pub fn is_all(&self) -> bool {
        self.estimators.is_none() && self.testbeds.is_none()
    }

    /// `registry` with only the named estimators and test beds, and, when estimators are named,
    /// only the test beds one of them runs on; with one note per test bed left out for that.
    pub fn apply(&self, registry: &Registry) -> Result<(Registry, Vec<String>), ConfigError> {
        let est_ids: Vec<&str> = registry.estimators().iter().map(|e| e.id).collect();
        let bed_ids: Vec<&str> = registry.test_beds().iter().map(|t| t.id).collect();
        check("--estimators", &self.estimators, &est_ids)?;
        check("--testbeds", &self.testbeds, &bed_ids)?;
        let mut out = registry.clone();
        if out.unselected.is_none() {
            out.unselected = Some(std::sync::Arc::new((registry.estimators.clone(), registry.test_beds.clone())));
        }
        out.estimators.retain(|e| any(&self.estimators, e.id));
        out.test_beds.retain(|t| any(&self.testbeds, t.id));
        let mut notes = Vec::new();
        if self.estimators.is_some() {
            let estimators = out.estimators.clone();
            out.test_beds.retain(|t| {
                let used = estimators.iter().any(|e| e.skip_reason(t.provides).is_none());
                if !used {
                    notes.push(format!("note: test bed {} skipped: none of the named estimators runs on it", t.id));
                }
                used
            });
        }
        Ok((out, notes))
    }

    /// `sweep` with only the named estimators and test beds.
    pub fn filter_sweep(&self, mut sweep: Sweep) -> Sweep {
        sweep.estimators.retain(|e| any(&self.estimators, &e.id));
        sweep.testbeds.retain(|t| any(&self.testbeds, &t.id));
        sweep
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn globs_match_prefixes_suffixes_and_middles() {
        for (p, n, m) in [
            ("is1_*", "is1_cv2", true),
            ("*_cv2", "is1_cv2", true),
            ("*cv*", "is1_cv2", true),
            ("is*cv2", "is1_cv2", true),
            ("is1_cv2", "is1_cv2", true),
            ("*", "anything", true),
            ("is1_*", "is0_cv2", false),
            ("a*a", "a", false),
            ("is1_cv2", "is1_cv", false),
            ("*x*", "is1_cv2", false),
        ] {
            assert_eq!(glob(p, n), m, "{p} {n}");
        }
    }

    #[test]
    fn test_bed_patterns_narrow_and_unknown_ones_are_refused() {
        let registry = Registry::new().with_catalog(mcbench_papers::catalog());
        let (r, notes) = Selection::new(None, Some("product-peak, cosine-*")).apply(&registry).unwrap();
        assert_eq!(r.test_beds().len(), 2);
        assert_eq!(r.estimators().len(), registry.estimators().len());
        assert!(notes.is_empty());
        let e = Selection::new(None, Some("peak")).apply(&registry).unwrap_err().to_string();
        assert!(e.contains("--testbeds") && e.contains("gradient-plane"), "{e}");
        assert!(Selection::new(Some(","), None).apply(&registry).is_err());
        assert!(Selection::default().is_all());
    }
}
