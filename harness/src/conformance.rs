//! The conformance suite: the checks every estimator of a [`Registry`] goes through
//! ([`Conformance::check`]; `mcbench conformance` on the command line, `tests/conformance.rs` for
//! every built-in estimator), so a new plug-in is covered without new test code:
//!
//! 1. **builds** with its default parameters;
//! 2. **finite output on the stability cases** (book: stability.md) it runs on (the `Stability` cases the test
//!    beds declare, [`mcbench_core::entry::BedCase`]: albedo 1 and 0, optical depth 1e4 and 0,
//!    rays missing the medium, Phong n = 10000, an environment of dynamic range 1e6, mostly
//!    occluded lights): every estimate finite or a clean one-line
//!    refusal, never a panic, a NaN or an infinity; a validation error must be one line;
//! 3. **determinism**: the same stream key gives the same bits twice;
//! 4. **chi-square of its samplers**: the samplers its registry entry names
//!    ([`mcbench_core::entry::EstimatorEntry::samplers`]) are registered in
//!    [`mcbench_core::samplers::registry`] and pass their checks at the Sidak family level;
//! 5. **unbiasedness at a small budget** (estimators whose bias claim is `unbiased`): on every small
//!    case it runs on (the `Check` cases the test beds declare), 4 samples per estimate, the
//!    harness's own test ([`crate::analysis::unbiasedness`], deciding test as in the claims; about
//!    8000 estimates per bed) must
//!    not flag it. The same check must flag the known-biased control `clamped_is0_cv0`
//!    (`tests/conformance.rs` asserts that), so it has teeth;
//! 6. **independence** (estimators that declare
//!    [`mcbench_core::estimator::Estimator::integrals_independent`]): on the first bed with sequences
//!    longer than one integral, the sequence estimated at once equals its tasks estimated one by
//!    one from the same stream (no state carried from task to task).

use crate::analysis::claims::decisive_test;
use crate::analysis::{unbiasedness, Gate, TestRow};
use crate::registry::Registry;
use crate::run::cell::CellResult;
use crate::run::guarded::{self, Stopped};
use mcbench_core::budget::Budget;
use mcbench_core::entry::{CaseRole, EstimatorEntry};
use mcbench_core::error::ConfigError;
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::params::Params;
use mcbench_core::rng::StreamKey;
use mcbench_core::samplers::registry as samplers;
use mcbench_core::samplers::testing::sampler_alpha;
use mcbench_core::testbed::TestBed;
use rayon::prelude::*;
use std::sync::OnceLock;

/// One failed conformance check.
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    /// Estimator id.
    pub estimator: String,
    /// Which check (`build`, `finite`, `determinism`, `independence`, `samplers`, `unbiasedness`).
    pub check: &'static str,
    /// What went wrong (one line).
    pub detail: String,
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} [{}]: {}", self.estimator, self.check, self.detail)
    }
}

type Beds = Vec<(String, Box<dyn TestBed>)>;

/// The test beds of the suite, built once: every registered test bed's declared cases
/// ([`mcbench_core::entry::BedCase`]) of the roles `Stability` and `Check`.
pub struct Conformance {
    stability: Beds,
    check: Beds,
    /// Samplers the registry adds to the built-in ones ([`Registry::with_sampler`]).
    samplers: Vec<&'static mcbench_core::SamplerEntry>,
}

impl Conformance {
    /// Builds the cases of every test bed of `registry` (a case that does not build is bad input
    /// naming it).
    pub fn new(registry: &Registry) -> crate::error::Result<Self> {
        let (mut stability, mut check) = (Vec::new(), Vec::new());
        for entry in registry.test_beds() {
            for case in entry.cases {
                let into = match case.role {
                    CaseRole::Stability => &mut stability,
                    CaseRole::Check => &mut check,
                    CaseRole::Unbiasedness { .. } => continue,
                };
                let params = case.params();
                let bed = (entry.build)(case.variant, &params, registry.references()).map_err(|e| {
                    ConfigError::invalid(
                        format!("{} case {}", entry.id, case.variant),
                        format!("{params:?}"),
                        e.to_string(),
                    )
                })?;
                into.push((format!("{}/{} {params:?}", entry.id, case.variant), bed));
            }
        }
        Ok(Conformance { stability, check, samplers: registry.samplers.clone() })
    }

    /// Runs every conformance check on one estimator and returns what failed.
    pub fn check(&self, entry: &EstimatorEntry) -> Vec<Failure> {
        conformance_on(entry, &self.stability, &self.check, &self.samplers)
    }
}

/// Every registered sampler's checks: (sampler id, failures as text).
fn sampler_results() -> &'static Vec<(&'static str, Vec<String>)> {
    static RESULTS: OnceLock<Vec<(&'static str, Vec<String>)>> = OnceLock::new();
    RESULTS.get_or_init(|| samplers::SAMPLERS.par_iter().map(|s| (s.id, sampler_failures(s))).collect())
}

/// The failed chi-square tests of one sampler, as text.
fn sampler_failures(s: &mcbench_core::SamplerEntry) -> Vec<String> {
    (s.check)()
        .into_iter()
        .filter(|(_, c)| c.p_value.is_nan() || c.p_value <= sampler_alpha())
        .map(|(name, c)| format!("{name}: chi-square {:.1} on {} dof, p = {:.2e}", c.statistic, c.dof, c.p_value))
        .collect()
}

/// Whether `est` runs on `bed` (static needs, dynamic support, validation).
fn runs_on(entry: &EstimatorEntry, est: &dyn Estimator, bed: &dyn TestBed) -> Result<bool, String> {
    if entry.skip_reason(bed.provides()).is_some() || est.supports(bed).is_err() {
        return Ok(false);
    }
    match est.validate(bed) {
        Ok(()) => Ok(true),
        Err(e) => {
            let text = e.to_string();
            if text.lines().count() == 1 && !text.is_empty() {
                Ok(false)
            } else {
                Err(format!("validation error is not one line: {text:?}"))
            }
        }
    }
}

/// Estimates of the sequence holding integrals `first..first + frames`, on its own stream key
/// ([`guarded::sequence`]); a one-line refusal gives no estimates.
fn estimate(
    est: &dyn Estimator,
    bed: &dyn TestBed,
    label: &str,
    id: &str,
    first: usize,
    samples: u64,
    rep: u64,
) -> Result<Vec<[f64; 3]>, String> {
    let budget = Budget::samples(samples).map_err(|e| e.to_string())?;
    let key = StreamKey { seed: 9, testbed: label, estimator: id, budget: samples, rep, integral: first as u64 };
    match guarded::sequence(est, bed, &key, budget, first) {
        Err(Stopped::Panicked(_)) => Err(format!("panicked on {label} integral {first}")),
        Err(Stopped::Error(EstimateError::Refused(t))) if t.lines().count() == 1 => Ok(Vec::new()),
        Err(Stopped::Error(e)) => Err(format!("{label} integral {first}: {e}")),
        Ok(v) if v.iter().all(|x| x.iter().all(|c| c.is_finite())) => Ok(v),
        Ok(v) => Err(format!("{label} integral {first}: non-finite estimate {:?}", v.first())),
    }
}

/// The small-budget unbiasedness test of `est` on `bed` (4 samples per estimate, about 8000
/// estimates per bed): the deciding row of [`unbiasedness`] for the estimator's bias claim, or
/// `None` when the estimator refused. The test is gated by a pilot cell of as many repetitions on
/// streams of its own (repetitions `R..2R`): a rare-hit estimator (a small bright light on
/// `checker-direct`) whose tested repetitions happened to miss the light has a low sample skewness
/// and a small standard error in exactly those integrals, and a t-test gated by the cell alone
/// flagged correct estimators there (Holm p 1e-4 for an antithetic cosine sampler).
pub fn small_budget_unbiasedness(entry: &EstimatorEntry, est: &dyn Estimator, bed: &dyn TestBed) -> Option<TestRow> {
    let n = bed.integrals();
    let reps = (8000 / n).max(8) as u64;
    let tested = small_budget_cell(entry, est, bed, 0..reps)?;
    let pilot = small_budget_cell(entry, est, bed, reps..2 * reps)?;
    let gate = Gate::from_cell(&pilot, "pilot", 1.0).with_group(Gate::group_of(est, bed));
    let rows = unbiasedness(&tested, bed.reference(), entry.bias, Some(&gate), crate::analysis::DEFAULT_TOLERANCE);
    decisive_test(&rows, bed.variant(), entry.id, "").cloned()
}

/// The cell of repetitions `reps` at 4 samples per estimate; `None` when the estimator refused.
fn small_budget_cell(
    entry: &EstimatorEntry,
    est: &dyn Estimator,
    bed: &dyn TestBed,
    reps: std::ops::Range<u64>,
) -> Option<CellResult> {
    let n = bed.integrals();
    let f = bed.sequence_length().max(1);
    let label = format!("{}/{}", bed.id(), bed.variant());
    let count = (reps.end - reps.start) as usize;
    let per_rep: Vec<Result<Vec<[f64; 3]>, String>> = reps
        .into_par_iter()
        .map(|rep| {
            let mut out = Vec::with_capacity(n);
            for first in (0..n).step_by(f) {
                let v = estimate(est, bed, &label, entry.id, first, 4, rep)?;
                if v.is_empty() {
                    return Err("refused".into());
                }
                out.extend(v);
            }
            Ok(out)
        })
        .collect();
    let per_rep: Vec<Vec<[f64; 3]>> = per_rep.into_iter().collect::<Result<_, _>>().ok()?;
    debug_assert_eq!(per_rep.len(), count);
    Some(guarded::cell_of(bed, entry.id, Budget::samples(4).ok()?, 9, &per_rep))
}

/// The first bed with sequences longer than one integral that `est` runs on: whether its sequence
/// estimate differs from its tasks' estimates one by one (what `integrals_independent` promises).
fn independence<'a>(
    est: &dyn Estimator,
    beds: impl Iterator<Item = &'a (String, Box<dyn TestBed>)>,
    entry: &EstimatorEntry,
) -> Option<String> {
    let (label, bed) = beds
        .filter(|(_, b)| b.sequence_length() > 1)
        .find(|(_, b)| matches!(runs_on(entry, est, b.as_ref()), Ok(true)))?;
    let budget = Budget::samples(4).ok()?;
    let key = StreamKey { seed: 9, testbed: label, estimator: entry.id, budget: 4, rep: 0, integral: 0 };
    // Tasks count what they spend, so each pass gets its own.
    let tasks = || -> Vec<mcbench_core::task::Task<'_>> {
        (0..bed.sequence_length()).map(|i| mcbench_core::task::Task::new(bed.as_ref(), i, budget)).collect()
    };
    let at_once = est.estimate_sequence(&tasks(), &mut key.rng()).ok()?;
    let mut rng = key.rng();
    let one_by_one: Vec<_> = tasks().iter().map(|t| est.estimate(t, &mut rng)).collect::<Result<_, _>>().ok()?;
    (at_once != one_by_one).then(|| {
        format!(
            "{label}: declares its integrals independent, but its sequence estimate differs from its tasks' one by one"
        )
    })
}

fn conformance_on(
    entry: &EstimatorEntry,
    stability: &Beds,
    unbiased: &Beds,
    own_samplers: &[&'static mcbench_core::SamplerEntry],
) -> Vec<Failure> {
    let fail = |check, detail: String| Failure { estimator: entry.id.into(), check, detail };
    let est = match (entry.build)(&Params::new()) {
        Ok(e) => e,
        Err(e) => return vec![fail("build", format!("default parameters refused: {e}"))],
    };
    let mut out = Vec::new();
    // 2. Finite output (or a clean refusal) on the stability beds; 3. determinism on the first.
    let mut determinism_done = false;
    for (label, bed) in stability {
        match runs_on(entry, est.as_ref(), bed.as_ref()) {
            Err(e) => out.push(fail("finite", format!("{label}: {e}"))),
            Ok(false) => {}
            Ok(true) => {
                let f = bed.sequence_length().max(1);
                let firsts: Vec<usize> = (0..bed.integrals()).step_by(f).take(16).collect();
                let results: Vec<Result<Vec<[f64; 3]>, String>> = firsts
                    .par_iter()
                    .flat_map(|&first| (0..2).into_par_iter().map(move |rep| (first, rep)))
                    .map(|(first, rep)| estimate(est.as_ref(), bed.as_ref(), label, entry.id, first, 4, rep))
                    .collect();
                out.extend(results.into_iter().filter_map(Result::err).map(|e| fail("finite", e)));
                if !determinism_done {
                    determinism_done = true;
                    let a = estimate(est.as_ref(), bed.as_ref(), label, entry.id, firsts[0], 4, 5);
                    let b = estimate(est.as_ref(), bed.as_ref(), label, entry.id, firsts[0], 4, 5);
                    let bits = |r: &Result<Vec<[f64; 3]>, String>| {
                        r.as_ref().map(|v| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>()).ok()
                    };
                    if bits(&a) != bits(&b) {
                        out.push(fail("determinism", format!("{label}: the same stream key gave {a:?} and {b:?}")));
                    }
                }
            }
        }
    }
    // 6. Independent integrals, where the estimator declares them: a sequence estimated at once
    // equals its tasks estimated one by one in order from the same stream.
    if est.integrals_independent() {
        if let Some(e) = independence(est.as_ref(), stability.iter().chain(unbiased), entry) {
            out.push(fail("independence", e));
        }
    }
    // 4. Samplers.
    for name in entry.samplers {
        let bad = match own_samplers.iter().find(|s| s.id == *name) {
            Some(own) => Some(sampler_failures(own)),
            None => sampler_results().iter().find(|(id, _)| id == name).map(|(_, bad)| bad.clone()),
        };
        match bad {
            None => out.push(fail(
                "samplers",
                format!(
                    "names `{name}`, which is neither in samplers::registry nor registered with Registry::with_sampler"
                ),
            )),
            Some(bad) => out.extend(bad.iter().map(|b| fail("samplers", format!("{name}: {b}")))),
        }
    }
    // 5. Unbiasedness at a small budget.
    if entry.bias == Bias::Unbiased {
        for (label, bed) in unbiased {
            if !matches!(runs_on(entry, est.as_ref(), bed.as_ref()), Ok(true)) {
                continue;
            }
            if let Some(t) = small_budget_unbiasedness(entry, est.as_ref(), bed.as_ref()) {
                // A flag is a failure; `inconclusive` (4 samples resolve no 1% bias on most beds)
                // is not.
                if t.verdict == "biased" {
                    out.push(fail(
                        "unbiasedness",
                        format!("{label}: {} p = {:.2e} at 4 samples per estimate ({})", t.test, t.p_value, t.verdict),
                    ));
                }
            }
        }
    }
    out
}
