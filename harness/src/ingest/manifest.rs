//! The manifest of estimates another program wrote (`manifest.toml`, book: contract.md): the
//! experiment name, the reference (a built-in test bed or an image with its variance), and per
//! estimator its bias claim and, per budget, the files of its repetitions. Every field is checked
//! here, before any estimate is read; paths stay inside the manifest's folder.

use crate::config::claim_spec::ClaimSpec;
use crate::error::{HarnessError, Result};
use mcbench_core::params::Params;
use serde::Deserialize;
use std::path::{Component, Path, PathBuf};

/// The whole manifest.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Experiment name: the results folder `<results>/<name>/`.
    pub name: String,
    /// What the estimates are compared with.
    pub reference: ReferenceSpec,
    /// The estimators whose repetitions were written.
    pub estimators: Vec<IngestEstimator>,
    /// The estimator the others are compared with (efficiency ratios, `speedup` claims without a
    /// baseline of their own), as a config's `baseline`.
    pub baseline: Option<String>,
    /// Claims judged on the ingested run (`[[claims]]` tables, exactly as in a config file).
    #[serde(default)]
    pub claims: Vec<ClaimSpec>,
}

/// The reference: a built-in test bed (`testbed`, `variant`, `params`) or an image of the
/// reference's mean with its per-pixel variance (`image`, `variance`).
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// A built-in test bed's id.
    pub testbed: Option<String>,
    /// Its variant (default: its first).
    pub variant: Option<String>,
    /// Its parameters.
    #[serde(default)]
    pub params: Params,
    /// An image of the reference's mean (`.npy` or `.exr`).
    pub image: Option<String>,
    /// The per-pixel variance of that mean, same shape.
    pub variance: Option<String>,
    /// The samples per pixel the reference image averaged: its variance is an estimate with
    /// `samples - 1` degrees of freedom. Without it the variance is taken as exact.
    pub samples: Option<u64>,
}

/// The bias an estimator is declared to have.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BiasClaim {
    /// Tested; expected to pass.
    Unbiased,
    /// A control; expected to be flagged `biased`.
    Biased,
    /// Tested with no expectation.
    Unknown,
}

/// One estimator of the manifest.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IngestEstimator {
    /// The user's name, shown everywhere.
    pub id: String,
    /// Its declared bias.
    pub bias: BiasClaim,
    /// Its budgets, each with the files of its repetitions.
    pub budgets: Vec<BudgetFiles>,
}

/// The repetitions of one estimator at one budget.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BudgetFiles {
    /// Samples per integral (per pixel) of each repetition.
    pub samples: u64,
    /// One image per repetition (`{rep}` or `{rep:0N}` in the name), or one CSV of scalars.
    pub files: String,
    /// Number of repetitions.
    pub reps: usize,
    /// Optional CSV `rep,seconds`: each repetition's seconds.
    pub seconds: Option<String>,
}

impl Manifest {
    /// Reads and checks `path`: every field, every name and every path (inside the folder).
    pub fn read(path: &Path) -> Result<Manifest> {
        let text = std::fs::read_to_string(path).map_err(|e| HarnessError::bad_file(path, e))?;
        let m: Manifest =
            toml::from_str(&text).map_err(|e| HarnessError::bad_file(path, crate::config::toml_reason(&text, &e)))?;
        m.check().map_err(|(field, why)| HarnessError::bad_file(path, format!("field `{field}`: {why}")))?;
        Ok(m)
    }

    /// Checks names, counts and the shape of the reference; `Err((field, reason))`.
    fn check(&self) -> std::result::Result<(), (String, String)> {
        let bad = |f: &str, why: &str| Err((f.to_string(), why.to_string()));
        if self.name.is_empty() || !self.name.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)) {
            return bad("name", "must be letters, digits, `-`, `_` or `.`");
        }
        if self.name.starts_with('.') {
            return bad("name", "may not start with `.`");
        }
        let r = &self.reference;
        match (&r.testbed, &r.image) {
            (Some(_), Some(_)) => return bad("reference", "give `testbed` or `image`, not both"),
            (None, None) => return bad("reference", "give `testbed` (a built-in test bed) or `image` and `variance`"),
            (None, Some(_)) if r.variance.is_none() => {
                return bad("reference.variance", "an image reference needs its per-pixel variance")
            }
            (None, Some(_)) if r.variant.is_some() || !r.params.0.is_empty() => {
                return bad("reference", "`variant` and `params` belong to a `testbed` reference")
            }
            (Some(_), None) if r.variance.is_some() => {
                return bad("reference.variance", "belongs to an `image` reference")
            }
            (Some(_), None) if r.samples.is_some() => {
                return bad("reference.samples", "belongs to an `image` reference")
            }
            (None, Some(_)) if r.samples.is_some_and(|n| n < 2) => {
                return bad("reference.samples", "a variance estimate needs at least 2 samples")
            }
            _ => {}
        }
        if self.estimators.is_empty() {
            return bad("estimators", "lists no estimator");
        }
        let first: Vec<u64> = self.estimators[0].budgets.iter().map(|b| b.samples).collect();
        for (i, e) in self.estimators.iter().enumerate() {
            let f = |s: &str| format!("estimators[{i}].{s}");
            if e.id.is_empty() || !e.id.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)) {
                return Err((f("id"), "must be letters, digits, `-`, `_` or `.`".into()));
            }
            if self.estimators[..i].iter().any(|o| o.id == e.id) {
                return Err((f("id"), format!("`{}` is listed twice", e.id)));
            }
            if e.budgets.is_empty() {
                return Err((f("budgets"), "lists no budget".into()));
            }
            for (j, b) in e.budgets.iter().enumerate() {
                let g = |s: &str| f(&format!("budgets[{j}].{s}"));
                if b.samples == 0 || b.samples > crate::config::limits::MAX_SAMPLES {
                    return Err((
                        g("samples"),
                        format!("{} is not in 1..={}", b.samples, crate::config::limits::MAX_SAMPLES),
                    ));
                }
                if j > 0 && b.samples <= e.budgets[j - 1].samples {
                    return Err((g("samples"), "budgets must increase".into()));
                }
                if b.reps < 2 || b.reps > crate::config::limits::MAX_REPS {
                    return Err((g("reps"), format!("{} is not in 2..={}", b.reps, crate::config::limits::MAX_REPS)));
                }
                safe_relative(&b.files).map_err(|why| (g("files"), why))?;
                if let Some(s) = &b.seconds {
                    safe_relative(s).map_err(|why| (g("seconds"), why))?;
                }
            }
            let mine: Vec<u64> = e.budgets.iter().map(|b| b.samples).collect();
            if mine != first {
                return Err((f("budgets"), "every estimator needs the same budgets (samples) as the first".into()));
            }
        }
        if let Some(b) = &self.baseline {
            if !self.estimators.iter().any(|e| &e.id == b) {
                let ids: Vec<&str> = self.estimators.iter().map(|e| e.id.as_str()).collect();
                return Err(("baseline".into(), format!("`{b}` names no estimator (valid: {})", ids.join(", "))));
            }
        }
        for (i, c) in self.claims.iter().enumerate() {
            c.check().map_err(|e| (format!("claims[{i}].{}", e.field), format!("{} (`{}`)", e.problem, e.value)))?;
        }
        for (field, p) in [("reference.image", &r.image), ("reference.variance", &r.variance)] {
            if let Some(p) = p {
                safe_relative(p).map_err(|why| (field.to_string(), why))?;
            }
        }
        Ok(())
    }
}

/// A path a manifest may name: relative, with no `..`, no root and no drive.
fn safe_relative(p: &str) -> std::result::Result<(), String> {
    if p.is_empty() {
        return Err("is empty".into());
    }
    for c in Path::new(p).components() {
        match c {
            Component::Normal(_) | Component::CurDir => {}
            _ => return Err(format!("`{p}` leaves the manifest's folder (only relative paths without `..`)")),
        }
    }
    Ok(())
}

/// `rel` below the manifest's folder `dir`, checked to exist and to resolve (symlinks followed)
/// inside `dir`. `Err` is the reason, for a line naming the field.
pub fn resolve(dir: &Path, rel: &str) -> std::result::Result<PathBuf, String> {
    safe_relative(rel)?;
    let path = dir.join(rel);
    let real = std::fs::canonicalize(&path).map_err(|e| format!("{}: {}", path.display(), e))?;
    let root = std::fs::canonicalize(dir).map_err(|e| format!("{}: {}", dir.display(), e))?;
    if !real.starts_with(&root) {
        return Err(format!("{} leads out of the manifest's folder", path.display()));
    }
    if !real.is_file() {
        return Err(format!("{} is not a file", path.display()));
    }
    Ok(path)
}

/// The file name of repetition `rep` from a pattern with `{rep}` or `{rep:0N}` (zero padded to
/// `N` digits); `None` when the pattern has no such placeholder.
pub fn rep_name(pattern: &str, rep: usize) -> Option<String> {
    let start = pattern.find("{rep")?;
    let end = start + pattern[start..].find('}')?;
    let spec = &pattern[start + 4..end];
    let digits = if spec.is_empty() {
        format!("{rep}")
    } else {
        let width: usize = spec.strip_prefix(":0")?.parse().ok().filter(|w| *w <= 20)?;
        format!("{rep:0width$}")
    };
    Some(format!("{}{}{}", &pattern[..start], digits, &pattern[end + 1..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repetition_names_with_and_without_padding() {
        assert_eq!(rep_name("a/rep-{rep}.npy", 7).as_deref(), Some("a/rep-7.npy"));
        assert_eq!(rep_name("rep-{rep:04}.exr", 7).as_deref(), Some("rep-0007.exr"));
        assert_eq!(rep_name("scalars.csv", 7), None);
        assert_eq!(rep_name("rep-{rep:4}.exr", 7), None, "padding needs a leading zero");
    }

    #[test]
    fn paths_leaving_the_folder_are_refused() {
        assert!(safe_relative("a/b.npy").is_ok());
        assert!(safe_relative("../b.npy").is_err());
        assert!(safe_relative("a/../../b.npy").is_err());
        assert!(safe_relative("/etc/passwd").is_err());
        assert!(safe_relative("").is_err());
    }

    #[test]
    fn unknown_fields_and_mixed_references_are_refused() {
        let base = "name='x'\n[reference]\ntestbed='gradient-plane'\n[[estimators]]\nid='a'\nbias='unbiased'\n[[estimators.budgets]]\nsamples=4\nfiles='r-{rep}.npy'\nreps=4\n";
        let m: Manifest = toml::from_str(base).unwrap();
        assert_eq!(m.check(), Ok(()));
        assert!(toml::from_str::<Manifest>(&format!("{base}colour=1\n")).is_err());
        let both = base.replace("testbed='gradient-plane'", "testbed='gradient-plane'\nimage='r.npy'");
        let m: Manifest = toml::from_str(&both).unwrap();
        assert_eq!(m.check().unwrap_err().0, "reference");
        let reps = base.replace("reps=4", "reps=1");
        let m: Manifest = toml::from_str(&reps).unwrap();
        assert_eq!(m.check().unwrap_err().0, "estimators[0].budgets[0].reps");
    }
}
