//! Experiments declared as data: a TOML file with the experiment's name and description, the sweep
//! fields of a config file ([`SweepFile`]: seed, reps, budget_kind, budgets, baseline, testbeds,
//! estimators) shared by both modes, and `[quick]` / `[full]` tables that override them.
//!
//! ```
//! use mcbench::config::Mode;
//! use mcbench::config::declare::ExperimentFile;
//!
//! let file = ExperimentFile::parse(r#"
//!     name = "my-slopes"
//!     reproduces = "my paper, Fig. 2"
//!     summary = "independent MC against cosine sampling on the diffuse plane"
//!     baseline = "is0_cv0"
//!     estimators = [{ id = "is0_cv0" }, { id = "brdf_is0_cv0" }]
//!     testbeds = [{ id = "gradient-plane", variant = "diffuse", params = { resolution = 8 } }]
//!     [quick]
//!     reps = 8
//!     budgets = [4, 16, 64]
//!     [full]
//!     reps = 32
//!     budgets = [4, 16, 64, 256, 1024]
//! "#).unwrap();
//! let quick = file.sweep(Mode::Quick).unwrap();
//! assert_eq!((quick.reps, quick.budgets.len()), (8, 3));
//! assert_eq!(file.sweep(Mode::Full).unwrap().budgets.len(), 5);
//! ```

use crate::config::claim_spec::ClaimSpec;
use crate::config::{EstimatorSpec, Mode, Sweep, SweepFile, TestBedSpec};
use crate::error::{HarnessError, Result};
use crate::registry::{ClaimsFn, Experiment, PostFn, Sweeps};
use serde::Deserialize;

/// An experiment file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentFile {
    /// Name (results folder, CLI argument).
    pub name: String,
    /// The paper figure or table it reproduces.
    pub reproduces: String,
    /// One line for `mcbench list experiments`.
    pub summary: String,
    /// Seed (default 1).
    pub seed: Option<u64>,
    /// Repetitions.
    pub reps: Option<usize>,
    /// Budget kind (`samples`, `fetches`, `micros`).
    pub budget_kind: Option<String>,
    /// Budgets.
    pub budgets: Option<Vec<u64>>,
    /// Baseline estimator name for speed-ups.
    pub baseline: Option<String>,
    /// Test beds.
    pub testbeds: Option<Vec<TestBedSpec>>,
    /// Estimators.
    pub estimators: Option<Vec<EstimatorSpec>>,
    /// Claims judged on every run of it (`[[claims]]`).
    pub claims: Option<Vec<ClaimSpec>>,
    /// The relative bias an unbiasedness `pass` must detect (default 0.01).
    pub bias_tolerance: Option<f64>,
    /// Unit costs of the `renderer` cost regime (`[cost_model]`).
    pub cost_model: Option<crate::plan::cost_model::CostModel>,
    /// Overrides for `--quick`.
    #[serde(default)]
    pub quick: SweepFile,
    /// Overrides for `--full`.
    #[serde(default)]
    pub full: SweepFile,
}

impl ExperimentFile {
    /// Parses the TOML text of an experiment file; an error says where.
    pub fn parse(text: &str) -> std::result::Result<Self, String> {
        toml::from_str(text).map_err(|e| e.to_string().lines().next().unwrap_or("malformed").to_string())
    }

    /// The sweep of a mode: the shared fields, then the mode's overrides.
    pub fn sweep(&self, mode: Mode) -> Result<Sweep> {
        let shared = SweepFile {
            name: Some(self.name.clone()),
            seed: Some(self.seed.unwrap_or(1)),
            reps: self.reps,
            budget_kind: self.budget_kind.clone(),
            budgets: self.budgets.clone(),
            baseline: self.baseline.clone(),
            testbeds: self.testbeds.clone(),
            estimators: self.estimators.clone(),
            claims: self.claims.clone(),
            bias_tolerance: self.bias_tolerance,
            cost_model: self.cost_model,
        };
        let base = shared.apply(None, mode)?;
        let mut overrides = match mode {
            Mode::Quick => self.quick.clone(),
            Mode::Full => self.full.clone(),
        };
        // Budgets given per mode are of the shared kind unless the mode says otherwise.
        if overrides.budget_kind.is_none() {
            overrides.budget_kind = self.budget_kind.clone();
        }
        overrides.apply(Some(base), mode)
    }

    /// The experiment, with its claims and analysis (code: they are functions of the run).
    pub fn experiment(&self, claims: Option<ClaimsFn>, post: Option<PostFn>) -> Result<Experiment> {
        let quick = self.sweep(Mode::Quick)?;
        let full = self.sweep(Mode::Full)?;
        for s in [&quick, &full] {
            s.validate()?;
        }
        Ok(Experiment {
            name: self.name.clone(),
            reproduces: self.reproduces.clone(),
            summary: self.summary.clone(),
            sweeps: Sweeps::Fixed { quick: Box::new(quick), full: Box::new(full) },
            claims,
            post,
            preflight: None,
        })
    }
}

/// The experiment declared by `text` (an experiment file embedded in a binary); an error names
/// the experiment.
pub fn experiment(text: &str, claims: Option<ClaimsFn>, post: Option<PostFn>) -> Result<Experiment> {
    let file = ExperimentFile::parse(text).map_err(|e| HarnessError::bad_file("experiment file", e))?;
    file.experiment(claims, post).map_err(|e| HarnessError::bad_file(format!("experiment file of {}", file.name), e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn modes_override_the_shared_fields_and_bad_files_are_refused() {
        let text = "name = 'x'\nreproduces = 'r'\nsummary = 's'\nreps = 4\nbudgets = [4, 16]\n\
                    testbeds = [{ id = 'gradient-plane' }]\nestimators = [{ id = 'is0_cv0' }]\n\
                    [full]\nreps = 16\nbudgets = [4, 16, 64]\n";
        let f = ExperimentFile::parse(text).expect("parses");
        assert_eq!(f.sweep(Mode::Quick).expect("quick").reps, 4);
        let full = f.sweep(Mode::Full).expect("full");
        assert_eq!((full.reps, full.budgets.len(), full.seed), (16, 3, 1));
        assert!(ExperimentFile::parse("name = 'x'\nreproduces = 'r'\nsummary = 's'\nrep = 3\n").is_err());
        let bad = experiment(&text.replace("reps = 4", "reps = 1"), None, None).expect_err("reps 1");
        assert!(bad.to_string().contains("reps"), "{bad}");
    }
}
