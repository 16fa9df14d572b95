//! The named experiments (SPEC §7): each builds a sweep for quick or full mode and states the
//! paper's claims, which are judged against what the run measured.

pub mod canonical_cells;
pub mod canonical_sweep;
pub mod canonical_sweep_claims;
pub mod canonical_sweep_plots;
pub mod canonical_sweep_post;
#[cfg(test)]
mod canonical_tests;
pub mod canonical_winners;
pub mod claims;
pub mod envmap_smc;
pub mod envmap_smc_post;
pub mod envmap_unbiasedness;
pub mod media_smc;
pub mod media_smc_post;
pub mod particle_sweep;
pub mod particle_sweep_post;
pub mod pmc_hi;
pub mod pmc_hi_post;
pub mod pmc_ip;
pub mod pmc_ip_post;
pub mod single_scatter;
pub mod single_scatter_post;
pub mod stability;
pub mod stability_cases;
pub mod stability_list;
pub mod stability_numeric;
pub mod surface_smc;
pub mod transmittance;
pub mod transmittance_post;
pub mod unbiasedness;
pub mod unbiasedness_reps;
pub mod unbiasedness_run;
pub mod unbiasedness_stats;
pub mod unbiasedness_table;
pub mod variance_claims;

use crate::config::{EstimatorSpec, Mode, Sweep};
use crate::folder::OutputDir;
use crate::output::{Claim, RunReport};
use crate::plan::Plan;
use crate::runner::RunResults;
use estimators::error::ConfigError;
use estimators::registry;
use std::path::{Path, PathBuf};

/// A named experiment.
pub struct ExperimentDef {
    /// Name (results folder, CLI argument).
    pub name: &'static str,
    /// The paper figure or table it reproduces.
    pub reproduces: &'static str,
    /// One line for `mcbench list experiments`.
    pub summary: &'static str,
    /// Every estimator id it runs (ids not registered yet are reported as unavailable).
    pub ids: &'static [&'static str],
    /// The sweep for a mode.
    pub sweep: fn(Mode) -> Sweep,
    /// The paper's claims judged on a finished run.
    pub claims: fn(&RunReport) -> Vec<Claim>,
    /// Optional analysis beyond the summary rows, run after the claims with the cells of the run:
    /// it may add claims and write extra result files and plots (returned for the report).
    pub post: Option<PostFn>,
}

/// An experiment's own analysis: (plan, finished cells, report to extend, results folder (its
/// files are written through it and committed with the run's), plots folder when plots are
/// drawn) -> extra plot files.
pub type PostFn =
    fn(&Plan, &RunResults, &mut RunReport, &OutputDir, Option<&Path>) -> crate::error::Result<Vec<PathBuf>>;

/// Every experiment, in the order the default suite runs them.
pub static EXPERIMENTS: &[&ExperimentDef] = &[
    &surface_smc::DEF,
    &media_smc::DEF,
    &transmittance::DEF,
    &particle_sweep::DEF,
    &pmc_hi::DEF,
    &pmc_ip::DEF,
    &envmap_smc::DEF,
    &single_scatter::DEF,
    &canonical_sweep::DEF,
    &unbiasedness::DEF,
    &stability::DEF,
];

/// Looks an experiment up by name.
pub fn experiment(name: &str) -> Result<&'static ExperimentDef, ConfigError> {
    EXPERIMENTS
        .iter()
        .copied()
        .find(|e| e.name == name)
        .ok_or_else(|| ConfigError::unknown("experiment", name, EXPERIMENTS.iter().map(|e| e.name)))
}

/// Splits the ids an experiment names into registered estimators and ids not available yet
/// (estimator families land issue by issue; the run says which ones it could not include).
pub fn available(ids: &[&str]) -> (Vec<EstimatorSpec>, Vec<String>) {
    let (mut have, mut missing) = (Vec::new(), Vec::new());
    for id in ids {
        match registry::estimator(id) {
            Ok(_) => have.push(EstimatorSpec::new(id)),
            Err(_) => missing.push(id.to_string()),
        }
    }
    (have, missing)
}

impl ExperimentDef {
    /// The ids this experiment names that are not registered yet.
    pub fn unavailable(&self) -> Vec<String> {
        available(self.ids).1
    }
}
