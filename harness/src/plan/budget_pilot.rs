//! The pilot passes that turn a fetch or time budget into a fixed number of samples per estimate
//! (a renderer's one spp for the whole image): on their own stream, over sequences stratified
//! across the test bed.

use crate::error::Result;
use crate::plan::Plan;
use crate::run::runner::{run_sequence, CellRun, Item, PILOT_REP};
use mcbench_core::budget::Budget;
use mcbench_core::task::FETCH_BUDGET_SAMPLE_CAP;
use rayon::prelude::*;

/// At most this many sequences run in a pilot.
pub(crate) const PILOT_SEQUENCES: usize = 256;

/// The `k`-th of `picks` pilot sequences out of `sequences`: one per stratum of consecutive
/// sequences, at a golden-ratio offset inside it. Integrals are numbered row by row in an image, so
/// equal offsets (the stratum's first, as before) put every pilot pixel in one or two columns (at
/// 64x64 and 64 pilots, column 0: the image's edge, where rays are shortest and cheapest); the
/// offsets of `frac(k phi)` spread them over the columns as the strata spread them over the rows.
pub(crate) fn pilot_sequence(k: usize, picks: usize, sequences: usize) -> usize {
    const PHI: f64 = 0.618_033_988_749_894_8;
    let (lo, hi) = (k * sequences / picks, (k + 1) * sequences / picks);
    let offset = ((k as f64 * PHI).fract() * (hi - lo) as f64) as usize;
    (lo + offset).min(hi.max(lo + 1) - 1)
}

/// Runs the pilot sequences of a cell under its budget's own stopping rule: each one's costs and
/// its CPU seconds.
fn run_pilots(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> Result<Vec<(Item, f64)>> {
    let b = &plan.beds[bi];
    let frames = b.bed.sequence_length().max(1);
    let sequences = b.bed.integrals() / frames;
    let picks = sequences.min(PILOT_SEQUENCES);
    let label = b.label();
    let pilot = CellRun { plan, label: &label, bi, ei, budget, samples: None };
    (0..picks)
        .into_par_iter()
        .map(|k| {
            let mut out = Item::default();
            let t0 = crate::run::cputime::thread_seconds();
            run_sequence(&pilot, PILOT_REP, pilot_sequence(k, picks, sequences) * frames, &mut out)?;
            Ok((out, crate::run::cputime::thread_seconds() - t0))
        })
        .collect()
}

/// The fixed number of samples per estimate that a fetch budget buys (paper 002 compares
/// estimators at equal fetches per pixel). Stopping each estimate when its fetches run out would
/// bias it ([`Task::with_samples`]), so a pilot pass on its own stream (repetition [`PILOT_REP`],
/// up to [`PILOT_SEQUENCES`] sequences stratified over the test bed, [`pilot_sequence`]) runs with
/// that stopping rule, and `n = round(budget / mean_k(fetches_k / samples_k))` over the pilot
/// sequences that fetched at all ([`samples_for_mean_cost`]), the same for every integral and
/// repetition, as a renderer sets one spp for the whole image. The
/// reported costs are the fetches the estimates really spent (pixels whose rays miss the medium
/// spend none, so the image's mean is below the budget).
pub(crate) fn samples_for_fetch_budget(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> Result<u64> {
    let pilots = run_pilots(plan, bi, ei, budget)?;
    let mut per_sample = Vec::with_capacity(pilots.len());
    for (p, _) in pilots {
        if p.costs.fetches > 0 && p.costs.samples > 0 {
            per_sample.push(p.costs.fetches as f64 / p.costs.samples as f64);
        }
    }
    let cap = budget.amount.saturating_mul(FETCH_BUDGET_SAMPLE_CAP);
    Ok(samples_for_mean_cost(budget.amount as f64, &per_sample).map_or(cap, |n| n.clamp(1, cap)))
}

/// The sample count whose mean cost over the pilot sequences is `budget`:
/// `round(budget / mean_k(cost per sample of sequence k))`; None without a costing sequence.
///
/// Not `budget x total samples / total cost`: each pilot sequence runs until *its* budget is
/// spent, so it takes `budget / c_k` samples, and that ratio is `budget x mean(1 / c_k)`, which by
/// Jensen's inequality buys more than the budget wherever costs differ over the image (on the
/// eq21 transmittance image, where rays grazing the sphere fetch almost nothing, trackers spent
/// 14-50% more than their budget).
pub(crate) fn samples_for_mean_cost(budget: f64, per_sample: &[f64]) -> Option<u64> {
    if per_sample.is_empty() {
        return None;
    }
    let mean = per_sample.iter().sum::<f64>() / per_sample.len() as f64;
    (mean > 0.0).then(|| (budget / mean).round() as u64)
}

/// The fixed number of samples per estimate that a time budget buys: a pilot on its own stream
/// (as for fetch budgets) runs the estimator until each pilot estimate's time is up, and
/// `n = budget / mean_k(CPU microseconds_k / samples_k)` ([`samples_for_mean_cost`]). Stopping each real estimate when its time
/// runs out would make its sample count depend on the values drawn (slow paths and their values go
/// together); a count fixed in advance does not. The count depends on the machine, so a time budget
/// is the one setting whose results are not bit-reproducible (`meta.reproducible` says so).
pub(crate) fn samples_for_time_budget(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> Result<u64> {
    let pilots = run_pilots(plan, bi, ei, budget)?;
    let mut per_sample = Vec::with_capacity(pilots.len());
    for (p, s) in pilots {
        let n = p.costs.samples;
        if n > 0 {
            // A clock tick below a microsecond reads as one.
            per_sample.push((s * 1e6).max(1.0 / n as f64) / n as f64);
        }
    }
    let n = samples_for_mean_cost(budget.amount as f64, &per_sample).unwrap_or(1);
    Ok(n.clamp(1, crate::config::limits::MAX_SAMPLES))
}

#[cfg(test)]
mod tests {
    use super::pilot_sequence;

    /// At 64x64 and 32x32 with 64 pilots, the pilot pixels cover many columns and every stratum of
    /// rows (before: column 0 only, and columns 0 and 16).
    /// Two pixels, one costing 1 per sample and one 99: a budget of 100 buys 2 samples each (mean
    /// spend 100), not the 50.5 that total samples over total cost would give (mean spend 2525).
    #[test]
    fn the_count_aims_at_the_mean_spend_over_pixels() {
        assert_eq!(super::samples_for_mean_cost(100.0, &[1.0, 99.0]), Some(2));
        assert_eq!(super::samples_for_mean_cost(100.0, &[]), None);
    }

    #[test]
    fn pilot_pixels_spread_over_rows_and_columns() {
        for side in [16usize, 32, 64] {
            let n = side * side;
            let picks = n.min(64);
            let pixels: Vec<usize> = (0..picks).map(|k| pilot_sequence(k, picks, n)).collect();
            let mut sorted = pixels.clone();
            sorted.dedup();
            assert_eq!(sorted.len(), picks, "distinct and in stratum order at {side}");
            for (k, &p) in pixels.iter().enumerate() {
                assert!(p >= k * n / picks && p < (k + 1) * n / picks, "pilot {k} in its stratum at {side}");
            }
            let mut columns: Vec<usize> = pixels.iter().map(|p| p % side).collect();
            columns.sort_unstable();
            columns.dedup();
            assert!(columns.len() >= side / 2, "{} columns of {side}", columns.len());
        }
        assert_eq!(pilot_sequence(0, 1, 1), 0);
        assert_eq!(pilot_sequence(2, 3, 3), 2);
    }
}
