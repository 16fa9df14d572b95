//! The `calibration` experiment in the rounds mode (`--repetitions rounds`): each family's rows
//! decided by the round-based rule of `unbiasedness` ([`crate::unbiasedness::rounds`]) on many
//! independent seeds, with no bias: how often a correct row is ever flagged when every look runs at
//! its share of a nominal 5% (the false-flag rate of the whole rule, optional stopping included),
//! and, at the experiment's own 1e-3, how often a row is decided and at how many repetitions.
//!
//! Seed `k`'s cell is repetitions `2kM .. 2kM + M` of one long run and its pilot the first round's
//! repetitions after them, where `M` is the most repetitions a row can reach (its first round
//! times `2^(LOOKS-1)`); a look at `R` repetitions uses the first `R` of the cell's and the whole
//! pilot, as the rounds of a run do. Repetitions are computed only as far as some look needs them. There is no
//! shared budget here: each row may take all its looks (the budget of a run only stops rows
//! earlier, which cannot raise the rate).

use super::measure::{rep_estimates, Family};
use super::table::wilson;
use crate::analysis::{unbiasedness_at, Gate, TestRow, UNBIASEDNESS_ALPHA};
use crate::config::Mode;
use crate::error::Result;
use crate::plan::Plan;
use crate::registry::{PostContext, Registry};
use crate::run::guarded;
use crate::unbiasedness::rounds::{first_round, stays_open, LOOKS};
use rayon::prelude::*;
use serde::Serialize;
use std::path::PathBuf;

/// The nominal family-wise level at which the false-flag rate is measured.
pub const NOMINAL: f64 = super::measure::NOMINAL;

/// One family measured in the rounds mode (a row of `calibration_rounds.csv`).
#[derive(Clone, Debug, Serialize)]
pub struct RoundsRow {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// What the registry claims.
    pub claim: String,
    /// Seeds measured.
    pub seeds: usize,
    /// Seeds where some look ran a test (the false-flag rate's denominator).
    pub tested: usize,
    /// Seeds flagged at some look, each look at `NOMINAL / LOOKS`.
    pub flagged_at_nominal: usize,
    /// Their rate.
    pub false_flag_rate: f64,
    /// Its 95% Wilson interval, low end.
    pub rate_low: f64,
    /// Its 95% Wilson interval, high end.
    pub rate_high: f64,
    /// At the experiment's own level (1e-3 over the looks): seeds that passed.
    pub pass: usize,
    /// ... that were flagged.
    pub biased: usize,
    /// The fixed mode's repetitions of the family.
    pub fixed_reps: usize,
    /// Mean repetitions a seed stopped at (at 1e-3).
    pub mean_reps: f64,
}

/// Per repetition, every integral's estimate.
type Reps = Vec<Vec<[f64; 3]>>;

/// One seed's looks at the family-wise `alpha`: the last look's deciding row, whether any look
/// flagged it, whether any look ran a test, and the repetitions it stopped at.
fn looks(
    plan: &Plan,
    family: &Family,
    (cell_reps, pilot_reps): (&mut Reps, &mut Reps),
    (cell_from, pilot_from): (u64, u64),
    alpha: f64,
    tolerance: f64,
) -> Result<(TestRow, bool, bool, usize)> {
    let bed = plan.beds[0].bed.as_ref();
    let id = plan.estimators[0].name.clone();
    let budget = plan.sweep.budgets[0];
    let group = Gate::group_of(plan.estimators[0].estimator.as_ref(), bed);
    let first = first_round(family.reps);
    while pilot_reps.len() < first {
        pilot_reps.push(rep_estimates(plan, pilot_from + pilot_reps.len() as u64)?);
    }
    let pilot = guarded::cell_of(bed, &id, budget, plan.sweep.seed, &pilot_reps[..first]);
    let gate = Gate::from_cell(&pilot, "pilot", 1.0).with_group(group);
    let (mut reps, mut flagged, mut tested) = (first, false, false);
    for look in 1..=LOOKS {
        while cell_reps.len() < reps {
            cell_reps.push(rep_estimates(plan, cell_from + cell_reps.len() as u64)?);
        }
        let cell = guarded::cell_of(bed, &id, budget, plan.sweep.seed, &cell_reps[..reps]);
        let tests = unbiasedness_at(&cell, bed.reference(), family.bias, Some(&gate), tolerance, alpha / LOOKS as f64);
        let row = tests.iter().find(|t| t.test == "combined").cloned().unwrap_or_default();
        tested |= !row.p_value.is_nan();
        flagged |= row.verdict == "biased";
        if !stays_open(&tests, reps, look, true, false) {
            return Ok((row, flagged, tested, reps));
        }
        reps *= 2;
    }
    unreachable!("the last look never stays open")
}

/// Measures `family` in the rounds mode over `seeds` seeds from `seed`.
pub fn measure(
    family: &Family,
    seeds: usize,
    seed: u64,
    tolerance: f64,
    mode: Mode,
    registry: &Registry,
) -> Result<RoundsRow> {
    let plan = super::measure::plan_of(family, family.reps, seed, mode, registry)?;
    let most = (first_round(family.reps) << (LOOKS - 1)) as u64;
    type Outcome = ((TestRow, bool, bool, usize), (TestRow, bool, bool, usize));
    let outcomes: Vec<Result<Outcome>> = (0..seeds as u64)
        .into_par_iter()
        .map(|k| {
            let from = (2 * k * most, 2 * k * most + most);
            let (mut cell, mut pilot) = (Vec::new(), Vec::new());
            let nominal = looks(&plan, family, (&mut cell, &mut pilot), from, NOMINAL, tolerance)?;
            let own = looks(&plan, family, (&mut cell, &mut pilot), from, UNBIASEDNESS_ALPHA, tolerance)?;
            Ok((nominal, own))
        })
        .collect();
    let outcomes: Vec<Outcome> = outcomes.into_iter().collect::<Result<_>>()?;
    let tested = outcomes.iter().filter(|o| o.0 .2).count();
    let flagged = outcomes.iter().filter(|o| o.0 .2 && o.0 .1).count();
    let (rate_low, rate_high) = wilson(flagged, tested);
    Ok(RoundsRow {
        testbed: family.bed.id.clone(),
        variant: family.bed.variant.clone().unwrap_or_default(),
        estimator: family.estimator.name(),
        claim: family.bias.name().into(),
        seeds,
        tested,
        flagged_at_nominal: flagged,
        false_flag_rate: flagged as f64 / tested.max(1) as f64,
        rate_low,
        rate_high,
        pass: outcomes.iter().filter(|o| o.1 .0.verdict == "pass").count(),
        biased: outcomes.iter().filter(|o| o.1 .1).count(),
        fixed_reps: family.reps,
        mean_reps: outcomes.iter().map(|o| o.1 .3 as f64).sum::<f64>() / seeds.max(1) as f64,
    })
}

/// The analysis of `calibration --repetitions rounds`: every family of the run measured in the
/// rounds mode, written to `calibration_rounds.csv`.
pub fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    let PostContext { plan, report, out: results, registry, .. } = cx;
    let t0 = std::time::Instant::now();
    let mode = plan.sweep.mode;
    let n = super::seeds(mode);
    let tolerance = plan.sweep.tolerance();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(report.meta.threads.max(1))
        .build()
        .map_err(|e| crate::error::HarnessError::write("thread pool", e))?;
    let mut rows = Vec::new();
    for family in super::families_of_run(plan, registry) {
        if family.bias == mcbench_core::estimator::Bias::Unbiased {
            rows.push(pool.install(|| measure(&family, n, plan.sweep.seed, tolerance, mode, registry))?);
        }
    }
    results.write_csv("calibration_rounds.csv", &rows)?;
    report.meta.notes.push(format!(
        "calibration in rounds: {n} seeds per unbiased family, up to {LOOKS} looks each at {NOMINAL}/{LOOKS} \
         (false flags) and at {UNBIASEDNESS_ALPHA}/{LOOKS} (decisions); {:.0} s",
        t0.elapsed().as_secs_f64()
    ));
    Ok(Vec::new())
}
