//! Runs limited to what the user names (book: cli.md): `--estimators` and `--testbeds`, comma
//! lists of ids with `*` globs, for `run` (named experiments, the suite and custom sweeps) and
//! `conformance`. A pattern that matches nothing is bad input naming it and the valid ids.
//!
//! The registry a run sees is narrowed ([`Selection::apply`]), so the experiments derived from it
//! (`unbiasedness`, `calibration`) and the conformance suite run only the named plug-ins; when
//! estimators are named, a test bed none of them runs on is left out with a one-line note, so a
//! reference it would need is never asked for. Fixed sweeps keep only their named entries and the
//! claims on them alone ([`Selection::filter_sweep`]; a note names each claim left out).
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

use crate::config::claim_spec::ClaimSpec;
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

    /// `sweep` with only the named estimators and test beds. Its claims that name an estimator or
    /// a test bed left out (or a speed-up measured against a baseline left out) go with them
    /// ([`Selection::claims_left_out`] says which), and a baseline left out is no longer the
    /// sweep's, so a named experiment runs on any part of it.
    pub fn filter_sweep(&self, mut sweep: Sweep) -> Sweep {
        let claims = std::mem::take(&mut sweep.claims);
        sweep.claims = claims.into_iter().filter(|c| self.keeps_claim(&sweep, c)).collect();
        // Only a baseline the selection leaves out goes; one that names no estimator of the sweep
        // stays, for validation to refuse.
        if sweep.baseline.as_deref().is_some_and(|b| !self.keeps_estimator(&sweep, b)) {
            sweep.baseline = None;
        }
        sweep.estimators.retain(|e| any(&self.estimators, &e.id));
        sweep.testbeds.retain(|t| any(&self.testbeds, &t.id));
        sweep
    }

    /// One note per claim of `sweep` that [`Selection::filter_sweep`] leaves out, naming it.
    pub fn claims_left_out(&self, sweep: &Sweep) -> Vec<String> {
        sweep
            .claims
            .iter()
            .filter(|c| !self.keeps_claim(sweep, c))
            .map(|c| {
                format!(
                    "note: a claim on {} naming {} left out: it names an estimator or test bed outside the selection",
                    c.testbed().unwrap_or("every test bed"),
                    c.estimators().join(", ")
                )
            })
            .collect()
    }

    /// Whether the estimator `name` of `sweep` is selected (a name of no estimator of the sweep is
    /// kept, for validation to refuse).
    fn keeps_estimator(&self, sweep: &Sweep, name: &str) -> bool {
        let mut named = sweep.estimators.iter().filter(|e| e.name() == name).peekable();
        named.peek().is_none() || named.any(|e| any(&self.estimators, &e.id))
    }

    /// Whether every estimator and test bed `claim` names (a speed-up's baseline, its own or the
    /// sweep's, included) is in the selection.
    fn keeps_claim(&self, sweep: &Sweep, claim: &ClaimSpec) -> bool {
        let kept_estimator = |name: &str| self.keeps_estimator(sweep, name);
        let kept_bed = |bed: &str| any(&self.testbeds, bed.split_once('/').map_or(bed, |(id, _)| id));
        let baseline = match claim {
            ClaimSpec::Speedup { baseline: None, .. } => sweep.baseline.as_deref(),
            _ => None,
        };
        claim.estimators().into_iter().chain(baseline).all(kept_estimator) && claim.testbed().is_none_or(kept_bed)
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
    fn a_sweep_keeps_only_the_claims_on_what_is_selected() {
        let file: crate::config::SweepFile = toml::from_str(
            r#"
            name = "x"
            reps = 4
            budgets = [4, 16, 64]
            baseline = "is0_cv0"
            [[testbeds]]
            id = "gradient-plane"
            [[testbeds]]
            id = "gradient-box"
            variant = "albedo-0.5"
            [[estimators]]
            id = "is0_cv0"
            [[estimators]]
            id = "is1_cv2"
            [[claims]]
            kind = "slope"
            testbed = "gradient-plane/default"
            estimator = "is0_cv0"
            value = -0.5
            text = "independent MC converges with slope -0.5"
            [[claims]]
            kind = "slope"
            testbed = "gradient-box/albedo-0.5"
            estimator = "is0_cv0"
            value = -0.5
            text = "the same in the box"
            [[claims]]
            kind = "speedup"
            testbed = "gradient-plane/default"
            estimator = "is1_cv2"
            value = 2.0
            text = "is1_cv2 against the sweep's baseline"
            "#,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        let sweep = file.apply(None, crate::config::Mode::Quick).unwrap();
        sweep.validate().unwrap();
        let texts = |s: &Sweep| s.claims.iter().map(|c| c.testbed().unwrap_or("-").to_string()).collect::<Vec<_>>();

        // Only is0_cv0: the speed-up (is1_cv2 against is0_cv0) leaves, the slopes stay.
        let only = Selection::new(Some("is0_cv0"), None);
        let notes = only.claims_left_out(&sweep);
        let narrowed = only.filter_sweep(sweep.clone());
        assert_eq!(texts(&narrowed), ["gradient-plane/default", "gradient-box/albedo-0.5"]);
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(notes[0].contains("is1_cv2") && notes[0].contains("left out"), "{notes:?}");
        narrowed.validate().expect("the narrowed sweep is valid");

        // Only is1_cv2: the baseline is left out, so is the speed-up measured against it.
        let narrowed = Selection::new(Some("is1_cv2"), None).filter_sweep(sweep.clone());
        assert!(narrowed.claims.is_empty() && narrowed.baseline.is_none(), "{narrowed:?}");
        narrowed.validate().expect("valid without a baseline");

        // Only the box: the plane's claims leave.
        let narrowed = Selection::new(None, Some("gradient-box")).filter_sweep(sweep.clone());
        assert_eq!(texts(&narrowed), ["gradient-box/albedo-0.5"]);

        // A baseline that names no estimator of the sweep stays, for validation to refuse.
        let mut typo = sweep.clone();
        typo.baseline = Some("is9_cv9".into());
        let narrowed = Selection::new(Some("is0_cv0"), None).filter_sweep(typo);
        assert_eq!(narrowed.baseline.as_deref(), Some("is9_cv9"));
        assert!(narrowed.validate().is_err());

        // Nothing named: the sweep as it was.
        assert_eq!(Selection::new(None, None).filter_sweep(sweep.clone()), sweep);
        assert!(Selection::new(None, None).claims_left_out(&sweep).is_empty());
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
