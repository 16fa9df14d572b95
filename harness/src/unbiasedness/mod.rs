//! The `unbiasedness` experiment (book: unbiasedness.md): every registered estimator on every test-bed case it
//! runs on, each cell tested by [`crate::analysis::unbiasedness`] (per-integral Holm t / Welch and
//! the pooled per-repetition t-test, combined by Bonferroni) behind the gate of a pilot on its own
//! seed, with the biased controls in the same run and required to be flagged (except where their
//! registry entry exempts a test bed, [`mcbench_core::entry::Checks`]). One table,
//! `unbiasedness.csv`: estimator x test bed -> p-value, verdict (`pass`, `inconclusive`,
//! `biased`), the relative bias the row could detect with 80% power, the repetitions that would
//! resolve the tolerance, and whether the registry calls the estimator unbiased.
//!
//! Nothing here names an estimator or a test bed: the experiment is derived from the registry it
//! runs over ([`parts`]), so a plug-in registered from any crate is in it. Each test bed declares
//! its cases ([`mcbench_core::entry::BedCase`] with the role `Unbiasedness`: a variant, small
//! parameters, samples per estimate and repetitions); cases of equal samples and repetitions form
//! one part, an ordinary [`Sweep`] of those cases x every estimator whose needs they provide
//! (with the estimator's check parameters, e.g. a control's coarse step). The first part is the
//! experiment's sweep (what `--config` overrides); the others run in its analysis ([`run`]) into
//! the same results folder, summary rows and tests.

pub mod rounds;
pub mod run;
pub mod stats;
pub mod table;

use crate::config::{EstimatorSpec, Mode, Sweep, TestBedSpec};
use crate::registry::{Experiment, Registry, Sweeps};
use mcbench_core::budget::Budget;
use mcbench_core::entry::CaseRole;

/// The experiment's name.
pub const NAME: &str = "unbiasedness";

/// The `unbiasedness` experiment over whatever registry it runs in.
pub fn experiment() -> Experiment {
    Experiment {
        name: NAME.into(),
        reproduces: "the unbiasedness tests over every estimator x test bed".into(),
        summary: "every estimator on every test-bed case it runs on: Holm t / pooled z / Welch, detectable bias, the biased controls flagged".into(),
        sweeps: Sweeps::Derived(first_part),
        claims: None,
        post: Some(run::post),
        preflight: Some(run::preflight),
    }
}

/// One part of the experiment: a sweep at one budget suited to its cases.
pub struct Part {
    /// Samples per estimate.
    pub samples: u64,
    /// The sweep.
    pub sweep: Sweep,
}

/// The parts for a mode, in registry order of their first case (the first is the experiment's
/// sweep): every `Unbiasedness` case of every test bed that runs in the mode (the quick mode
/// leaves out the cases of 0 quick repetitions, [`CaseRole::full_only`]), grouped by (samples,
/// repetitions), each with every estimator whose static needs one of its cases provides.
pub fn parts(registry: &Registry, mode: Mode) -> Vec<Part> {
    type Group = ((u64, (usize, usize)), Vec<TestBedSpec>);
    let mut groups: Vec<Group> = Vec::new();
    for bed in registry.test_beds() {
        for case in bed.cases {
            let CaseRole::Unbiasedness { samples, reps } = case.role else { continue };
            if mode == Mode::Quick && case.role.full_only() {
                continue;
            }
            let spec = TestBedSpec { id: bed.id.into(), variant: Some(case.variant.into()), params: case.params() };
            match groups.iter_mut().find(|g| g.0 == (samples, reps)) {
                Some(g) => g.1.push(spec),
                None => groups.push(((samples, reps), vec![spec])),
            }
        }
    }
    groups
        .into_iter()
        .map(|((samples, reps), testbeds)| {
            let provided: Vec<mcbench_core::testbed::Needs> =
                testbeds.iter().filter_map(|t| registry.test_bed(&t.id).ok().map(|e| e.provides)).collect();
            let estimators = registry
                .estimators()
                .iter()
                .filter(|e| provided.iter().any(|p| e.skip_reason(*p).is_none()))
                .map(|e| EstimatorSpec {
                    id: e.id.into(),
                    params: e
                        .checks
                        .params
                        .iter()
                        .fold(Default::default(), |p: mcbench_core::params::Params, (k, v)| p.with(k, *v)),
                })
                .collect();
            Part {
                samples,
                sweep: Sweep {
                    experiment: NAME.into(),
                    testbeds,
                    estimators,
                    budgets: vec![Budget { kind: mcbench_core::budget::BudgetKind::Samples, amount: samples }],
                    reps: if mode == Mode::Quick { reps.0 } else { reps.1 },
                    seed: 1,
                    mode,
                    baseline: None,
                    claims: Vec::new(),
                    bias_tolerance: None,
                    cost_model: Default::default(),
                    repetitions: Default::default(),
                },
            }
        })
        .collect()
}

/// The `unbiasedness` cases the quick mode leaves out (`test bed/variant`, registry order).
pub fn full_only(registry: &Registry) -> Vec<String> {
    registry
        .test_beds()
        .iter()
        .flat_map(|bed| {
            bed.cases.iter().filter(|c| c.role.full_only()).map(move |c| format!("{}/{}", bed.id, c.variant))
        })
        .collect()
}

/// The experiment's own sweep: the first part.
fn first_part(registry: &Registry, mode: Mode) -> Sweep {
    let mut all = parts(registry, mode);
    if all.is_empty() {
        // Nothing registered declares a case: an empty sweep, refused by planning with its reason.
        return Sweep {
            experiment: NAME.into(),
            testbeds: Vec::new(),
            estimators: Vec::new(),
            budgets: Vec::new(),
            reps: 2,
            seed: 1,
            mode,
            baseline: None,
            claims: Vec::new(),
            bias_tolerance: None,
            cost_model: Default::default(),
            repetitions: Default::default(),
        };
    }
    all.swap_remove(0).sweep
}

/// Re-exported for the analysis and tests.
pub use table::Row;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_cover_every_case_and_every_estimator_that_can_run() {
        let registry = Registry::new().with_catalog(mcbench_papers::catalog());
        let count = |quick: bool| -> usize {
            registry
                .test_beds()
                .iter()
                .map(|t| {
                    t.cases
                        .iter()
                        .filter(|c| matches!(c.role, CaseRole::Unbiasedness { .. }) && !(quick && c.role.full_only()))
                        .count()
                })
                .sum()
        };
        let full = parts(&registry, Mode::Full);
        assert_eq!(full.iter().map(|p| p.sweep.testbeds.len()).sum::<usize>(), count(false));
        let parts = parts(&registry, Mode::Quick);
        assert_eq!(parts.iter().map(|p| p.sweep.testbeds.len()).sum::<usize>(), count(true));
        // The quick mode leaves out exactly the full-only cases.
        assert_eq!(count(false) - count(true), full_only(&registry).len());
        assert!(!full_only(&registry).is_empty());
        for e in registry.estimators() {
            assert!(parts.iter().any(|p| p.sweep.estimators.iter().any(|s| s.id == e.id)), "{} is in no part", e.id);
        }
        // A control runs with its check parameters.
        let marching = parts.iter().flat_map(|p| &p.sweep.estimators).find(|s| s.id == "ray_marching").unwrap();
        assert_eq!(marching.name(), "ray_marching[step=5]");
    }
}
