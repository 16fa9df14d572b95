//! # experiments
//!
//! The paper suite of mcbench: the named experiments of SPEC §7 (each a sweep for quick and for
//! full mode, the paper's claims judged against what the run measured, and the figures and tables
//! of its own), registered on top of the harness ([`mcbench`]) by [`registry`]; the `mcbench`
//! binary is `mcbench::cli::main_with(experiments::registry())`.

pub mod canonical_cells;
pub mod canonical_sweep;
pub mod canonical_sweep_claims;
pub mod canonical_sweep_plots;
pub mod canonical_sweep_post;
#[cfg(test)]
mod canonical_tests;
pub mod canonical_winners;
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
pub mod variance_claims;

use mcbench::config::{EstimatorSpec, Mode, Sweep};
use mcbench::output::{Claim, RunReport};
use mcbench::registry::{Experiment, PostFn, Registry, Sweeps};

/// A named experiment of the suite, as a static definition (see [`Experiment`]).
pub struct ExperimentDef {
    /// Name (results folder, CLI argument).
    pub name: &'static str,
    /// The paper figure or table it reproduces.
    pub reproduces: &'static str,
    /// One line for `mcbench list experiments`.
    pub summary: &'static str,
    /// Every estimator id it runs.
    pub ids: &'static [&'static str],
    /// The sweep for a mode.
    pub sweep: fn(Mode) -> Sweep,
    /// The paper's claims judged on a finished run.
    pub claims: fn(&RunReport) -> Vec<Claim>,
    /// Optional analysis beyond the summary rows, run after the claims with the cells of the run:
    /// it may add claims and write extra result files and plots (returned for the report).
    pub post: Option<PostFn>,
}

impl ExperimentDef {
    /// The harness's experiment.
    pub fn experiment(&self) -> Experiment {
        Experiment {
            name: self.name.into(),
            reproduces: self.reproduces.into(),
            summary: self.summary.into(),
            sweeps: Sweeps::Fixed {
                quick: Box::new((self.sweep)(Mode::Quick)),
                full: Box::new((self.sweep)(Mode::Full)),
            },
            claims: Some(self.claims),
            post: self.post,
            preflight: None,
        }
    }
}

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
    &stability::DEF,
];

/// The built-in estimators and test beds with every experiment of the suite, in the order the
/// default suite runs them (the harness's `unbiasedness` before `stability`): what the `mcbench`
/// binary runs.
pub fn registry() -> Registry {
    let (papers, last) = EXPERIMENTS.split_at(EXPERIMENTS.len() - 1);
    let r = papers.iter().fold(Registry::builtin().without_experiments(), |r, d| r.with_experiment(d.experiment()));
    let r = r.with_experiment(mcbench::unbiasedness::experiment());
    last.iter().fold(r, |r, d| r.with_experiment(d.experiment()))
}

/// The registry for the crate's own tests: [`registry`] reading the repository's stored
/// references.
#[cfg(test)]
pub(crate) fn test_registry() -> Registry {
    registry().with_references(mcbench::references::ReferenceDir::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../results/references"
    )))
}

/// Estimator specs with default parameters for `ids`.
pub fn available(ids: &[&str]) -> (Vec<EstimatorSpec>, Vec<String>) {
    (ids.iter().map(|id| EstimatorSpec::new(id)).collect(), Vec::new())
}
