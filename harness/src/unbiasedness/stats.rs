//! The statistics behind a row of the `unbiasedness` table: the Holm and pooled tests combined, the
//! pooled test over shared-state sequences, the measured relative bias, and the repetitions that
//! would resolve a 0.1% relative bias.

use crate::analysis::{unbiasedness, TestRow, POWER, UNBIASEDNESS_ALPHA};
use crate::cell::CellResult;
use estimators::estimator::Bias;
use estimators::stats::{detectable_shift, z_test};
use estimators::testbed::{Reference, ReferenceKind};

/// The relative bias `--full` aims to resolve (issue 9: 0.1%).
pub const TARGET_REL_BIAS: f64 = 1e-3;

/// The repetitions `R'` at which the detectable relative bias `d` (measured at `reps`) would reach
/// [`TARGET_REL_BIAS`], when a share `est_share` of the tested variance comes from the estimates
/// (the rest from a stored reference, which more repetitions do not shrink): `d^2 (s R / R' + 1 - s)
/// = target^2`. `None` when the reference alone is too noisy or `d` is unknown.
pub fn reps_for_target(d: f64, reps: usize, est_share: f64) -> Option<f64> {
    if !d.is_finite() || d <= 0.0 {
        return None;
    }
    let s = est_share.clamp(0.0, 1.0);
    let room = TARGET_REL_BIAS * TARGET_REL_BIAS - (1.0 - s) * d * d;
    // Rounded up, ignoring the last-bit noise of the division.
    (room > 0.0).then(|| (reps as f64 * s * d * d / room - 1e-9).ceil().max(2.0))
}

/// The measured relative bias, its standard error, and the share of the tested variance that comes
/// from the estimates (1 for exact references).
pub fn measured(cell: &CellResult, reference: &Reference) -> (f64, f64, f64) {
    let (mut dev, mut var, mut ref_var, mut ref_sum) = (0.0, 0.0, 0.0, 0.0);
    for (i, m) in cell.moments.iter().enumerate() {
        for (c, mc) in m.iter().enumerate() {
            let (r, rse) = (reference.value[i][c], reference.std_err[i][c]);
            dev += mc.mean() - r;
            var += mc.std_err() * mc.std_err();
            ref_var += rse * rse;
            ref_sum += r.abs();
        }
    }
    let share = if var + ref_var > 0.0 { var / (var + ref_var) } else { 1.0 };
    (dev / ref_sum, (var + ref_var).sqrt() / ref_sum, share)
}

/// The SPEC §6 tests of a cell combined into one decision: the Holm test (per-integral t or Welch)
/// where it is valid and the pooled z-test, Bonferroni over the two (`p = min(1, 2 min(p_holm,
/// p_pooled))`, so the family-wise alpha stays 1e-3): the Holm test sees a bias in a few integrals,
/// the pooled one a small bias spread over all of them, which at a few repetitions per integral only
/// the pooled test resolves. The detectable bias is the smaller of the two (each at its own alpha).
/// Returns (test name, p-value, detectable relative bias); the p-value is NaN when neither ran.
pub fn combined(tests: &[TestRow]) -> (String, f64, f64) {
    let holm = tests.iter().find(|t| t.test.starts_with("holm") && t.verdict != "untested" && !t.p_value.is_nan());
    let valid = |name: &str| tests.iter().find(|t| t.test == name && !t.p_value.is_nan());
    let pooled = valid("pooled_z_rep").or_else(|| valid("pooled_z_seq")).or_else(|| valid("pooled_z"));
    match (holm, pooled) {
        (Some(h), Some(z)) => (
            format!("{}+{}", h.test, z.test),
            (2.0 * h.p_value.min(z.p_value)).min(1.0),
            h.detectable_rel_bias.min(z.detectable_rel_bias),
        ),
        (Some(t), None) | (None, Some(t)) => (t.test.clone(), t.p_value, t.detectable_rel_bias),
        (None, None) => (String::new(), f64::NAN, f64::NAN),
    }
}

/// The pooled z-test for test beds whose integrals come in sequences that share adaptive state
/// (`sequence_length > 1`: the frames of one `envmap-sequence` pixel, the whole image of
/// `gradient-box` and `checker-image`): the harness's `pooled_z` takes integrals as independent,
/// which the shared state breaks, so here the standard errors of one sequence's integrals are
/// summed (taken as fully correlated, the worst case) before sequences are combined as independent.
/// `None` when nothing varies.
pub fn pooled_over_sequences(cell: &CellResult, reference: &Reference, sequence: usize) -> Option<TestRow> {
    let bound = match &reference.kind {
        ReferenceKind::Exact { bound, .. } => Some(bound.max(0.0)),
        ReferenceKind::Stored { .. } => None,
    };
    let (mut dev, mut var, mut ref_sum, mut seq_se) = (0.0, 0.0, 0.0, 0.0);
    for (i, m) in cell.moments.iter().enumerate() {
        for (c, mc) in m.iter().enumerate() {
            let (r, rse) = (reference.value[i][c], reference.std_err[i][c]);
            // As the harness: an exact reference is known to within its bound.
            let r_test = bound.map_or(r, |b| mc.mean().clamp(r - b, r + b));
            dev += mc.mean() - r_test;
            seq_se += (mc.std_err() * mc.std_err() + rse * rse).sqrt();
            ref_sum += r.abs();
        }
        if (i + 1) % sequence.max(1) == 0 || i + 1 == cell.moments.len() {
            var += seq_se * seq_se;
            seq_se = 0.0;
        }
    }
    if !(var > 0.0 && ref_sum > 0.0) {
        return None;
    }
    let z = z_test(dev, var.sqrt(), 0.0);
    let mut row = unbiasedness(cell, reference, Bias::Unbiased).into_iter().find(|t| t.test == "pooled_z")?;
    row.test = "pooled_z_seq".into();
    row.statistic = z.statistic;
    row.p_value = z.p_value;
    row.verdict = if z.p_value < UNBIASEDNESS_ALPHA { "biased" } else { "pass" }.into();
    row.detectable_rel_bias = detectable_shift(var.sqrt(), UNBIASEDNESS_ALPHA, POWER) / ref_sum;
    Some(row)
}
