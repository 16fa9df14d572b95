//! # experiments
//!
//! The paper suite of mcbench: the named experiments (book: experiments.md; each a sweep for quick and for
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
pub mod planted;
pub mod pmc_hi;
pub mod pmc_hi_post;
pub mod pmc_ip;
pub mod pmc_ip_post;
pub mod readme_table;
pub mod sensitivity;
pub mod single_scatter;
pub mod single_scatter_post;
pub mod stability;
pub mod stability_cases;
pub mod stability_numeric;
pub mod surface_smc;
pub mod transmittance;
pub mod transmittance_post;
pub mod variance_claims;

use mcbench::output::{Claim, RunReport};
use mcbench::registry::{Experiment, PostFn, Registry};

/// A named experiment of the suite: its sweep as data (a TOML experiment file beside the code,
/// [`mcbench::config::declare`]), its claims and, for real figures and tables, its own analysis.
pub struct ExperimentDef {
    /// The experiment file.
    pub toml: &'static str,
    /// The paper's claims that need code (the rest are `[[claims]]` tables of the file), judged
    /// on a finished run.
    pub claims: Option<fn(&RunReport) -> Vec<Claim>>,
    /// Optional analysis beyond the summary rows, run after the claims with the cells of the run:
    /// it may add claims and write extra result files and plots (returned for the report).
    pub post: Option<PostFn>,
}

impl ExperimentDef {
    /// The harness's experiment (the embedded file is checked by a test of this crate).
    pub fn experiment(&self) -> Experiment {
        mcbench::config::declare::experiment(self.toml, self.claims, self.post)
            .unwrap_or_else(|e| panic!("an experiment file of the suite does not parse: {e}"))
    }

    /// Its name.
    pub fn name(&self) -> String {
        self.experiment().name
    }
}

/// One step of the default suite: an experiment file of this crate, or the harness's
/// `unbiasedness`, which runs over every registered estimator.
pub enum Step {
    /// An experiment of the suite.
    Paper(&'static ExperimentDef),
    /// The harness's `unbiasedness` experiment.
    Unbiasedness,
}

impl Step {
    /// The harness's experiment.
    pub fn experiment(&self) -> Experiment {
        match self {
            Step::Paper(d) => d.experiment(),
            Step::Unbiasedness => mcbench::unbiasedness::experiment(),
        }
    }
}

/// The default suite, in the order it runs.
pub static SUITE: &[Step] = &[
    Step::Paper(&surface_smc::DEF),
    Step::Paper(&media_smc::DEF),
    Step::Paper(&transmittance::DEF),
    Step::Paper(&particle_sweep::DEF),
    Step::Paper(&pmc_hi::DEF),
    Step::Paper(&pmc_ip::DEF),
    Step::Paper(&envmap_smc::DEF),
    Step::Paper(&single_scatter::DEF),
    Step::Paper(&canonical_sweep::DEF),
    Step::Unbiasedness,
    Step::Paper(&stability::DEF),
];

/// Every experiment file of the suite, in suite order.
pub fn experiment_files() -> impl Iterator<Item = &'static ExperimentDef> {
    SUITE.iter().filter_map(|s| match s {
        Step::Paper(d) => Some(*d),
        Step::Unbiasedness => None,
    })
}

/// The built-in estimators and test beds ([`mcbench_papers::catalog`]) with the default suite
/// ([`SUITE`]), and the harness's `calibration` and the suite's `sensitivity`, which run only when
/// named: what the `mcbench` binary runs.
pub fn registry() -> Registry {
    SUITE
        .iter()
        .fold(Registry::empty().with_catalog(mcbench_papers::catalog()), |r, s| r.with_experiment(s.experiment()))
        .with_experiment_on_demand(mcbench::calibration::experiment())
        .with_experiment_on_demand(sensitivity::experiment())
}

/// The registry for the crate's own tests: [`registry`] reading the repository's stored
/// references.
#[cfg(test)]
pub(crate) fn test_registry() -> Registry {
    registry().with_references(mcbench::store::references::ReferenceDir::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../estimators/references"
    )))
}

/// The README's code blocks, compiled and run as doc tests (here, in the crate that is not
/// published, so the published ones include no file outside their package).
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
pub struct ReadmeDoctests;

/// The Rust blocks of the book's plug-in chapter, compiled and run as doc tests.
#[cfg(doctest)]
#[doc = include_str!("../../docs/src/extending.md")]
pub struct BookPluginDoctests;

#[cfg(test)]
mod tests {
    /// Every experiment file parses and gives valid sweeps in both modes.
    #[test]
    fn every_experiment_file_parses() {
        for d in super::experiment_files() {
            let e = mcbench::config::declare::experiment(d.toml, d.claims, d.post).expect("parses");
            assert!(!e.name.is_empty());
        }
    }

    /// Every claim of every experiment file, in both modes, passes the checks a run makes before
    /// it writes anything: it names test beds, estimators and budgets the plan runs (a claim about
    /// a cell that never runs would only ever be `not measured`), every number is finite, and none
    /// compares an estimator with itself. A full-mode test bed is built at the parameters of the
    /// quick one of the same id and variant: which pairs run does not depend on a scene's size,
    /// and the exact references of `envmap-smc`'s full sizes take minutes.
    #[test]
    fn every_claim_names_what_its_experiment_runs() {
        use mcbench::config::Mode;
        let registry = super::test_registry();
        let mut judged = 0;
        for d in super::experiment_files() {
            let file = mcbench::config::declare::ExperimentFile::parse(d.toml).expect("parses");
            let quick = file.sweep(Mode::Quick).expect("quick sweep");
            for mode in [Mode::Quick, Mode::Full] {
                let mut sweep = file.sweep(mode).expect("sweep");
                for t in &mut sweep.testbeds {
                    if let Some(q) = quick.testbeds.iter().find(|q| q.id == t.id && q.variant == t.variant) {
                        t.params = q.params.clone();
                    }
                }
                judged += sweep.claims.len();
                if let Err(e) = mcbench::plan::Plan::prepare(sweep, &registry) {
                    panic!("{} ({}): {e}", file.name, mode.name());
                }
            }
        }
        assert!(judged > 0);
    }
}
