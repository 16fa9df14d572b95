//! Sensitivity sweeps: where a claim holds. A sensitivity file lists *parts*, each one claim (a
//! [`ClaimSpec`], judged exactly as in an experiment) on a small sweep, and one parameter the
//! claim's source leaves open, with the settings to try, our default among them and, where one can
//! be named, the setting closest to the source's. Every setting is an ordinary sweep run into the
//! experiment's results folder (cells resume and merge as any other); the claim is judged on each
//! setting's cells alone, and the part ends in exactly one outcome ([`outcome::Outcome`]): held at
//! the paper-like setting, holds where (the settings where it held), cannot hold on this scene (a
//! proven bound, [`Bound`], below the claim at every setting), or unsupportable as written (a
//! reason the file states with its numbers). A measured limit ([`Ceiling`]) is reported as the
//! best measured value and decides nothing.
//!
//! ```
//! use mcbench::sensitivity::SensitivityFile;
//!
//! let file = SensitivityFile::parse(r#"
//!     name = "where-it-holds"
//!     reproduces = "my paper's speed-up"
//!     summary = "the speed-up against the plane's resolution"
//!     [[parts]]
//!     id = "speedup-resolution"
//!     paper = "mine"
//!     headline = "2x at equal time"
//!     vary = "testbed.resolution"
//!     values = [4, 8]
//!     default = 8
//!     open = "the paper never states the image size"
//!     testbed = { id = "gradient-plane", variant = "diffuse" }
//!     estimators = [{ id = "is0_cv0" }, { id = "brdf_is0_cv0" }]
//!     claim = { kind = "speedup", testbed = "gradient-plane/diffuse", estimator = "brdf_is0_cv0", baseline = "is0_cv0", value = 2.0, text = "2x" }
//!     quick = { reps = 4, budgets = [4, 16] }
//!     full = { reps = 16, budgets = [4, 16, 64] }
//! "#).unwrap();
//! let part = &file.parts[0];
//! let (sweep, claim) = part.setting(&file.name, 1, mcbench::config::Mode::Quick, &part.values[0]).unwrap();
//! assert_eq!(sweep.testbeds[0].params.0["resolution"], mcbench_core::params::ParamValue::Number(4.0));
//! assert_eq!(claim.testbed(), Some("gradient-plane/diffuse"));
//! ```

pub mod outcome;
pub mod run;
pub mod table;

use crate::config::claim_spec::ClaimSpec;
use crate::config::{EstimatorSpec, Mode, Sweep, SweepFile, TestBedSpec};
use crate::error::Result;
use mcbench_core::error::ConfigError;
use mcbench_core::params::ParamValue;
use serde::Deserialize;

/// A sensitivity file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensitivityFile {
    /// Experiment name (results folder, CLI argument).
    pub name: String,
    /// What it examines.
    pub reproduces: String,
    /// One line for `mcbench list experiments`.
    pub summary: String,
    /// The parts.
    pub parts: Vec<Part>,
}

/// Repetitions and budgets of a part in one mode.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartMode {
    /// Repetitions.
    pub reps: usize,
    /// Budgets.
    pub budgets: Vec<u64>,
}

/// A measured limit of a claim computed at every setting from the run (`ceiling = "work_ratio"`
/// in a part; the key keeps its name): it is what the claim's estimator achieved, not a bound, so
/// the result files call it `best_measured` and it never decides that a claim cannot hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ceiling {
    /// The speed-up of a claim's estimator over its baseline if its own overhead were free: the
    /// ratio of error x rays per estimate (the work ratio), the limit of the renderer regime as
    /// rays get costly. For `speedup` claims the error is the variance, at the largest budget; for
    /// `ratio` claims on an efficiency it is the error that efficiency divides by (MSE for
    /// `efficiency_mse`, paper 003's `Err` for `p_eff`), at the claim's budget.
    WorkRatio,
}

/// A bound no estimator of the claim's family can beat on the scene, one value per setting,
/// computed outside the run by a stated command and derived in the book (`bound = { ... }` in a
/// part). Only such a bound below the claim at every setting makes a part "cannot hold on this
/// scene".
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bound {
    /// What it bounds, in a few words (shown beside its value).
    pub method: String,
    /// The command that computes `values`.
    pub command: String,
    /// One value per setting, in the order of the part's `values`.
    pub values: Vec<f64>,
}

/// One claim against one parameter.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Part {
    /// Short id (file names, rows).
    pub id: String,
    /// The paper (or source) the claim is from.
    pub paper: String,
    /// The claim in a few words.
    pub headline: String,
    /// What varies: `testbed.<param>`, `variant`, `estimator.<id>.<param>` (the first estimator
    /// of that id) or `budget_max` (the budgets up to the setting: the range a slope is fitted
    /// over).
    pub vary: String,
    /// The settings, in plot order.
    pub values: Vec<ParamValue>,
    /// Our default setting (one of `values`).
    pub default: ParamValue,
    /// The setting closest to the paper's (one of `values`), where one can be named.
    #[serde(default)]
    pub paper_like: Option<ParamValue>,
    /// What the paper leaves open, and why these settings.
    pub open: String,
    /// The test bed at our default.
    pub testbed: TestBedSpec,
    /// The estimators.
    pub estimators: Vec<EstimatorSpec>,
    /// Baseline of the speed-ups.
    #[serde(default)]
    pub baseline: Option<String>,
    /// Budget kind (default `samples`).
    #[serde(default)]
    pub budget_kind: Option<String>,
    /// The claim, written for the default setting.
    pub claim: ClaimSpec,
    /// A measured limit computed at every setting (reported as `best_measured`).
    #[serde(default)]
    pub ceiling: Option<Ceiling>,
    /// A proven bound at every setting (reported as `ceiling`).
    #[serde(default)]
    pub bound: Option<Bound>,
    /// An idealised value at every setting that bounds only a narrower family than the claim's
    /// (reported as `limit`, never deciding an outcome; same fields as `bound`).
    #[serde(default)]
    pub limit: Option<Bound>,
    /// Why the claim cannot be supported as the paper writes it, with the numbers that show it.
    #[serde(default)]
    pub unsupportable: Option<String>,
    /// Quick mode.
    pub quick: PartMode,
    /// Full mode.
    pub full: PartMode,
}

/// A setting as text: numbers as result files write them.
pub fn setting_text(v: &ParamValue) -> String {
    match v {
        ParamValue::Number(x) => crate::config::compact_number(*x),
        ParamValue::Text(t) => t.clone(),
    }
}

impl SensitivityFile {
    /// Parses and checks a sensitivity file; an error says where.
    pub fn parse(text: &str) -> std::result::Result<Self, String> {
        let file: SensitivityFile =
            toml::from_str(text).map_err(|e| e.to_string().lines().next().unwrap_or("malformed").to_string())?;
        for p in &file.parts {
            p.check().map_err(|e| format!("part {}: {e}", p.id))?;
        }
        if let Some(p) = file.parts.iter().enumerate().find(|(i, p)| file.parts[..*i].iter().any(|q| q.id == p.id)) {
            return Err(format!("part {} is listed twice", p.1.id));
        }
        Ok(file)
    }
}

impl Part {
    fn check(&self) -> std::result::Result<(), String> {
        if self.values.is_empty() {
            return Err("no settings".into());
        }
        if !self.values.contains(&self.default) {
            return Err(format!("the default {} is not one of the settings", setting_text(&self.default)));
        }
        if let Some(p) = self.paper_like.as_ref().filter(|p| !self.values.contains(p)) {
            return Err(format!("the paper-like setting {} is not one of the settings", setting_text(p)));
        }
        let known = self.vary == "variant"
            || self.vary == "budget_max"
            || self.vary.strip_prefix("testbed.").is_some_and(|k| !k.is_empty())
            || self.vary.strip_prefix("estimator.").and_then(|r| r.split_once('.')).is_some();
        if !known {
            return Err(format!(
                "vary = {:?} is not testbed.<param>, variant, estimator.<id>.<param> or budget_max",
                self.vary
            ));
        }
        for (name, b) in [("bound", &self.bound), ("limit", &self.limit)] {
            let Some(b) = b else { continue };
            if b.values.len() != self.values.len() {
                return Err(format!("{name}: {} values for {} settings", b.values.len(), self.values.len()));
            }
            if let Some(v) = b.values.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
                return Err(format!("{name}: {v} is not a positive number"));
            }
        }
        self.claim.check().map_err(|e| e.to_string())
    }

    /// The mode's repetitions and budgets.
    pub fn mode(&self, mode: Mode) -> &PartMode {
        match mode {
            Mode::Quick => &self.quick,
            Mode::Full => &self.full,
        }
    }

    /// The sweep of one setting, and the claim rewritten for it (test bed label and estimator
    /// names follow the setting).
    pub fn setting(&self, experiment: &str, seed: u64, mode: Mode, value: &ParamValue) -> Result<(Sweep, ClaimSpec)> {
        let m = self.mode(mode);
        let (mut testbed, mut estimators, mut budgets) =
            (self.testbed.clone(), self.estimators.clone(), m.budgets.clone());
        let mut renames: Vec<(String, String)> = Vec::new();
        let bad = |why: &str| ConfigError::invalid(format!("parts.{}.values", self.id), setting_text(value), why);
        let old_label = label(&testbed);
        if self.vary == "variant" {
            let ParamValue::Text(v) = value else { return Err(bad("a variant is a name").into()) };
            testbed.variant = Some(v.clone());
            renames.push((old_label, label(&testbed)));
        } else if self.vary == "budget_max" {
            let ParamValue::Number(max) = value else { return Err(bad("a budget is a number").into()) };
            budgets.retain(|b| (*b as f64) <= *max);
        } else if let Some(key) = self.vary.strip_prefix("testbed.") {
            testbed.params.0.insert(key.to_string(), value.clone());
        } else if let Some((id, key)) = self.vary.strip_prefix("estimator.").and_then(|r| r.split_once('.')) {
            let e = estimators.iter_mut().find(|e| e.id == id).ok_or_else(|| bad("no estimator of that id"))?;
            let old = e.name();
            e.params.0.insert(key.to_string(), value.clone());
            renames.push((old, e.name()));
        }
        let sweep = SweepFile {
            name: Some(experiment.to_string()),
            seed: Some(seed),
            reps: Some(m.reps),
            budget_kind: self.budget_kind.clone(),
            budgets: Some(budgets),
            baseline: self.baseline.clone(),
            testbeds: Some(vec![testbed]),
            estimators: Some(estimators),
            ..SweepFile::default()
        }
        .apply(None, mode)?;
        let baseline = sweep.baseline.as_ref().map(|b| renamed(b, &renames));
        let sweep = Sweep { baseline, ..sweep };
        Ok((sweep, rename_claim(&self.claim, &renames)))
    }
}

fn label(t: &TestBedSpec) -> String {
    format!("{}/{}", t.id, t.variant.as_deref().unwrap_or_default())
}

fn renamed(name: &str, renames: &[(String, String)]) -> String {
    renames.iter().find(|(old, _)| old == name).map_or_else(|| name.to_string(), |(_, new)| new.clone())
}

/// The claim with every name in `renames` replaced (test bed labels and estimator names are
/// plain strings of the claim, wherever its kind keeps them).
fn rename_claim(claim: &ClaimSpec, renames: &[(String, String)]) -> ClaimSpec {
    fn walk(v: &mut serde_json::Value, renames: &[(String, String)]) {
        match v {
            serde_json::Value::String(s) => *s = renamed(s, renames),
            serde_json::Value::Array(a) => a.iter_mut().for_each(|x| walk(x, renames)),
            serde_json::Value::Object(o) => {
                o.iter_mut().filter(|(k, _)| *k != "text").for_each(|(_, x)| walk(x, renames))
            }
            _ => {}
        }
    }
    let mut v = serde_json::to_value(claim).expect("a claim serialises");
    walk(&mut v, renames);
    serde_json::from_value(v).expect("renaming keeps a claim valid")
}

#[cfg(test)]
#[path = "tests.rs"]
mod tests;
