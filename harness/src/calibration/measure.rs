//! One row family measured over many seeds: the unbiasedness test of the harness
//! ([`crate::analysis::unbiasedness`], gated by a pilot exactly as the `unbiasedness` experiment
//! gates it) run on `seeds` independent (cell, pilot) pairs of the same estimator on the same test
//! bed, with no bias, with injected relative biases ([`super::wrap::Scaled`]) and with a firefly
//! rejection ([`super::wrap::FireflyRejection`]).
//!
//! Seed `k`'s cell is repetitions `2kR .. 2kR + R` of one long run and its pilot the next `R`:
//! disjoint repetitions are independent streams, so these are independent replicates of a row, at
//! the cost of one run of `2 S R` repetitions. The firefly threshold comes from repetitions
//! `2SR .. 2SR + 2R`, used by no seed.

use super::wrap::{drop_above, quantile_threshold};
use crate::analysis::{unbiasedness, Gate, TestRow};
use crate::config::{EstimatorSpec, Mode, Sweep, TestBedSpec};
use crate::error::Result;
use crate::plan::Plan;
use crate::registry::Registry;
use crate::run::guarded;
use crate::run::runner::sequence_estimates;
use mcbench_core::budget::Budget;
use mcbench_core::estimator::Bias;
use rayon::prelude::*;

/// The nominal level at which the false-flag rate is measured (resolvable in a few hundred seeds).
pub const NOMINAL: f64 = 0.05;
/// The quantile of a pilot's values above which the firefly rejection drops values.
pub const FIREFLY_QUANTILE: f64 = 0.99;
/// The injected relative biases: 1e-4 .. 1 at four per decade (the 80% point is interpolated on
/// this grid), with 1% and 3% among them.
pub fn bias_grid() -> Vec<f64> {
    let mut g: Vec<f64> = (0..=16).map(|k| 10f64.powf(-4.0 + k as f64 / 4.0)).collect();
    g.extend([0.01, 0.03]);
    g.sort_by(f64::total_cmp);
    g.dedup_by(|a, b| (*a / *b - 1.0).abs() < 1e-9);
    g
}

/// A row family: one estimator on one test-bed case at the budget and repetitions its
/// `unbiasedness` row runs with.
#[derive(Clone, Debug)]
pub struct Family {
    /// The test-bed case.
    pub bed: TestBedSpec,
    /// The estimator (with its check parameters).
    pub estimator: EstimatorSpec,
    /// Samples per estimate.
    pub samples: u64,
    /// Repetitions per cell.
    pub reps: usize,
    /// What the registry claims.
    pub bias: Bias,
}

/// What one seed showed.
#[derive(Clone, Debug, Default)]
pub struct SeedOutcome {
    /// The deciding row with no injected bias.
    pub null: TestRow,
    /// Whether the pooled test ran with no injected bias (its skewness gate let it).
    pub pooled_ran: bool,
    /// Whether each bias of [`bias_grid`] was flagged (`biased`).
    pub flagged: Vec<bool>,
    /// Whether the firefly rejection was flagged.
    pub firefly_flagged: bool,
    /// The firefly rejection's relative deviation from the reference in this cell.
    pub firefly_rel: f64,
    /// The deciding row of the planted miscalibrated test ([`shrunk`] by
    /// [`super::size::PLANTED_SE_FACTOR`]) with no injected bias.
    pub planted: TestRow,
}

/// The seeds' outcomes of a family, and the firefly threshold used.
pub struct Measured {
    /// Per seed.
    pub seeds: Vec<SeedOutcome>,
    /// The firefly threshold.
    pub threshold: f64,
}

pub(super) fn plan_of(f: &Family, reps: usize, seed: u64, mode: Mode, registry: &Registry) -> Result<Plan> {
    let sweep = Sweep {
        experiment: super::NAME.into(),
        testbeds: vec![f.bed.clone()],
        estimators: vec![f.estimator.clone()],
        budgets: vec![Budget::samples(f.samples)?],
        reps: reps.max(2),
        seed,
        mode,
        baseline: None,
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    };
    Plan::prepare(sweep, registry)
}

/// Every integral's estimates of repetition `rep`, as a run computes them.
pub(super) fn rep_estimates(plan: &Plan, rep: u64) -> Result<Vec<[f64; 3]>> {
    let bed = plan.beds[0].bed.as_ref();
    let budget = plan.sweep.budgets[0];
    let mut out = Vec::with_capacity(bed.integrals());
    for first in (0..bed.integrals()).step_by(bed.sequence_length().max(1)) {
        out.extend(sequence_estimates(plan, 0, 0, budget, rep, first)?.into_iter().map(|v| v.0));
    }
    Ok(out)
}

fn reps_range(plan: &Plan, from: u64, n: usize) -> Result<Vec<Vec<[f64; 3]>>> {
    (from..from + n as u64).map(|r| rep_estimates(plan, r)).collect()
}

/// The repetitions with every value moved towards its (integral, channel) mean over them by
/// `factor`: the means are unchanged and every standard error (per integral and of the
/// per-repetition sums) is `factor` times the original, so the same test on them is the test with
/// its standard errors shrunk by `factor`, a planted miscalibration.
pub fn shrunk(reps: &[Vec<[f64; 3]>], factor: f64) -> Vec<Vec<[f64; 3]>> {
    let n = reps.len().max(1) as f64;
    let width = reps.first().map_or(0, Vec::len);
    let mean: Vec<[f64; 3]> =
        (0..width).map(|i| std::array::from_fn(|c| reps.iter().map(|r| r[i][c]).sum::<f64>() / n)).collect();
    reps.iter()
        .map(|r| r.iter().zip(&mean).map(|(x, m)| std::array::from_fn(|c| m[c] + factor * (x[c] - m[c]))).collect())
        .collect()
}

/// Measures `family` over `seeds` seeds from `seed` at the relative `tolerance`.
pub fn measure(
    family: &Family,
    seeds: usize,
    seed: u64,
    tolerance: f64,
    mode: Mode,
    registry: &Registry,
) -> Result<Measured> {
    let plan = plan_of(family, family.reps, seed, mode, registry)?;
    let r = family.reps;
    let threshold = quantile_threshold(&reps_range(&plan, (2 * seeds * r) as u64, 2 * r)?, FIREFLY_QUANTILE);
    let grid = bias_grid();
    let bed = plan.beds[0].bed.as_ref();
    let reference = bed.reference();
    let id = plan.estimators[0].name.clone();
    let budget = plan.sweep.budgets[0];
    let ref_sum: f64 = reference.value.iter().flat_map(|v| v.0).map(f64::abs).sum();
    let group = Gate::group_of(plan.estimators[0].estimator.as_ref(), bed);
    let seeds: Vec<Result<SeedOutcome>> = (0..seeds)
        .into_par_iter()
        .map(|k| {
            let tested = reps_range(&plan, (2 * k * r) as u64, r)?;
            let pilot = reps_range(&plan, (2 * k * r + r) as u64, r)?;
            let cell = |reps: &[Vec<[f64; 3]>], f: &dyn Fn([f64; 3]) -> [f64; 3]| {
                let t: Vec<Vec<[f64; 3]>> = reps.iter().map(|v| v.iter().map(|x| f(*x)).collect()).collect();
                guarded::cell_of(bed, &id, budget, seed, &t)
            };
            let decide_on = |tested: &[Vec<[f64; 3]>], pilot: &[Vec<[f64; 3]>], f: &dyn Fn([f64; 3]) -> [f64; 3]| {
                let gate = Gate::from_cell(&cell(pilot, f), "pilot", 1.0).with_group(group);
                let rows = unbiasedness(&cell(tested, f), reference, family.bias, Some(&gate), tolerance);
                let ran = rows.iter().any(|t| t.test == "pooled_t" && !t.p_value.is_nan());
                (rows.into_iter().find(|t| t.test == "combined").unwrap_or_default(), ran)
            };
            let decide = |f: &dyn Fn([f64; 3]) -> [f64; 3]| decide_on(&tested, &pilot, f);
            let (null, pooled_ran) = decide(&|x| x);
            let factor = super::size::PLANTED_SE_FACTOR;
            let planted = decide_on(&shrunk(&tested, factor), &shrunk(&pilot, factor), &|x| x).0;
            let flagged =
                grid.iter().map(|b| decide(&|x: [f64; 3]| x.map(|c| c * (1.0 + b))).0.verdict == "biased").collect();
            let fire = decide(&|x| drop_above(x, threshold)).0;
            let fire_cell = cell(&tested, &|x| drop_above(x, threshold));
            Ok(SeedOutcome {
                null,
                pooled_ran,
                flagged,
                firefly_flagged: fire.verdict == "biased",
                firefly_rel: fire_cell.rep_dev.mean() / ref_sum,
                planted,
            })
        })
        .collect();
    Ok(Measured { seeds: seeds.into_iter().collect::<Result<_>>()?, threshold })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Shrinking keeps every (integral, channel) mean and scales every deviation from it, hence
    /// every standard error, by the factor.
    #[test]
    fn shrunk_keeps_the_means_and_scales_the_deviations() {
        let reps: Vec<Vec<[f64; 3]>> =
            (0..5).map(|r| vec![[r as f64, 2.0 * r as f64, 7.0], [1.0 - r as f64, 0.5, r as f64 * r as f64]]).collect();
        let s = shrunk(&reps, 0.5);
        for i in 0..2 {
            for c in 0..3 {
                let mean = |v: &[Vec<[f64; 3]>]| v.iter().map(|r| r[i][c]).sum::<f64>() / 5.0;
                assert!((mean(&s) - mean(&reps)).abs() < 1e-12);
                for r in 0..5 {
                    assert!(((s[r][i][c] - mean(&s)) - 0.5 * (reps[r][i][c] - mean(&reps))).abs() < 1e-12);
                }
            }
        }
    }
}
