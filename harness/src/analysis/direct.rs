//! Zero variance: the mean compared with the reference directly.
//!
//! When every repetition of a cell (and of its gate) agrees to within round-off
//! ([`super::spread::Spread::ZeroVariance`]), the estimator is deterministic: a t-test would divide
//! its deviation by a spread of rounding errors (a skewness of rounding errors keeps it from
//! running at all, or a 2% error reads as t = 1e16 on one run and as untestable on the next). So
//! the mean is compared with the reference itself. Against an exact reference a deviation beyond
//! the round-off bound `u` plus the reference's stated bound `B` is a bias with certainty (p = 0),
//! one within them agreement (p = 1); against a stored reference the deviation beyond round-off is
//! tested against the reference's standard error (Student t with its samples' degrees of freedom).
//! The three rows keep their meaning: per integral and channel (Holm over them), the summed
//! deviation (`pooled_t`, against `sum u + n B`), and the decision, the weighted Bonferroni of the
//! two. A pass needs an independent gate, as every pass does: without one, a cell that missed the
//! rare values of a random estimator would look deterministic.

use super::bias::{RowBase, TestRow, POOLED_SHARE};
use super::spread::ZeroChannels;
use super::POWER;
use mcbench_core::stats::{detectable_shift_t, holm_bonferroni, t_test, TestOutcome};
use mcbench_core::testbed::{Reference, ReferenceKind};

/// Degrees of freedom of a stored reference's standard error.
fn reference_dof(samples: u64) -> f64 {
    samples.saturating_sub(1).max(1) as f64
}

/// One zero-variance integral-channel of mean `mean` against reference `r` (standard error `rse`
/// when stored), with round-off bound `u`: the test of its deviation beyond round-off (and an
/// exact reference's bound), and whether it lies beyond them.
fn channel(mean: f64, r: f64, rse: f64, u: f64, kind: &ReferenceKind) -> (TestOutcome, bool) {
    let d = mean - r;
    match kind {
        ReferenceKind::Exact { bound, .. } => {
            let tol = u + bound.max(0.0);
            let excess = d - d.clamp(-tol, tol);
            (t_test(excess, 0.0, f64::INFINITY), excess != 0.0)
        }
        ReferenceKind::Stored { samples, .. } => {
            let excess = d - d.clamp(-u, u);
            (t_test(excess, rse, reference_dof(*samples)), excess != 0.0)
        }
    }
}

/// The integral-channel whose deviation is largest against its allowance (round-off, the exact
/// bound and the stored standard error): (integral, channel, deviation, round-off).
fn worst(zero: &ZeroChannels, cell_means: &[[f64; 3]], reference: &Reference, bound: f64) -> (usize, usize, f64, f64) {
    let mut best = (0, 0, 0.0, 0.0, -1.0);
    for (i, z) in zero.zero.iter().enumerate() {
        for (c, u) in z.iter().enumerate() {
            let u = u.unwrap_or(0.0);
            let d = cell_means[i][c] - reference.value[i][c];
            let room = u + bound + reference.std_err[i][c];
            let score = if room > 0.0 {
                d.abs() / room
            } else if d != 0.0 {
                f64::INFINITY
            } else {
                0.0
            };
            if score > best.4 {
                best = (i, c, d, u, score);
            }
        }
    }
    (best.0, best.1, best.2, best.3)
}

/// The three test rows of a zero-variance cell (see the module documentation).
pub(super) fn rows(base: &RowBase<'_>, reference: &Reference, zero: &ZeroChannels) -> Vec<TestRow> {
    let cell = base.cell;
    let alpha = base.alpha;
    let (alpha_holm, alpha_pooled) = (alpha * (1.0 - POOLED_SHARE), alpha * POOLED_SHARE);
    let (bound, stored) = match &reference.kind {
        ReferenceKind::Exact { bound, .. } => (bound.max(0.0), None),
        ReferenceKind::Stored { samples, .. } => (0.0, Some(reference_dof(*samples))),
    };
    let means: Vec<[f64; 3]> = cell.moments.iter().map(|m| [0, 1, 2].map(|c| m[c].mean())).collect();
    let m = zero.total.max(1);
    // Per integral and channel.
    let (mut ps, mut max_t, mut beyond, mut holm_detect) = (Vec::new(), 0.0f64, 0, f64::INFINITY);
    for (i, z) in zero.zero.iter().enumerate() {
        for (c, u) in z.iter().enumerate() {
            let (u, r, rse) = (u.unwrap_or(0.0), reference.value[i][c], reference.std_err[i][c]);
            let (t, off) = channel(means[i][c], r, rse, u, &reference.kind);
            ps.push(t.p_value);
            max_t = max_t.max(t.statistic.abs());
            beyond += usize::from(off);
            // An estimator off by `1 + b` everywhere is flagged once one channel's shift `b |r|`
            // clears its allowance (with 80% power against a stored reference's noise).
            let noise = stored.map_or(0.0, |dof| detectable_shift_t(rse, alpha_holm / m as f64, POWER, dof));
            if r != 0.0 {
                holm_detect = holm_detect.min((u + bound + noise) / r.abs());
            }
        }
    }
    if holm_detect.is_infinite() {
        holm_detect = f64::NAN; // every reference zero: no relative bias to detect
    }
    let p_holm = holm_bonferroni(&ps).into_iter().filter(|p| !p.is_nan()).fold(1.0, f64::min);
    // The summed deviation.
    let ref_sum: f64 = reference.value.iter().flat_map(|v| v.0).map(f64::abs).sum();
    let u_sum: f64 = zero.zero.iter().flatten().map(|u| u.unwrap_or(0.0)).sum();
    let var_ref: f64 = reference.std_err.iter().map(|s| (s[0] + s[1] + s[2]).powi(2)).sum();
    let (d, r) = (cell.rep_dev.mean(), cell.rep_dev.count());
    let tol = u_sum + bound * m as f64;
    let excess = d - d.clamp(-tol, tol);
    let dof = stored.unwrap_or(f64::INFINITY);
    let tp = t_test(excess, var_ref.sqrt(), dof);
    let pooled_detect = (tol + detectable_shift_t(var_ref.sqrt(), alpha_pooled, POWER, dof)) / ref_sum;
    let p = (p_holm / (1.0 - POOLED_SHARE)).min(tp.p_value / POOLED_SHARE).min(1.0);
    let detectable = pooled_detect.min(holm_detect);
    let gated = base.gate.is_some();
    let verdict = |p: f64, alpha: f64, detect: f64| {
        if p < alpha {
            "biased"
        } else if gated && detect <= base.tolerance {
            "pass"
        } else {
            "inconclusive"
        }
    };
    let lead = if zero.largest_sd == 0.0 {
        "zero variance: every repetition equal".to_string()
    } else {
        format!("zero variance: repetitions equal to round-off (largest spread {:.1e})", zero.largest_sd)
    };
    let (wi, wc, wd, wu) = worst(zero, &means, reference, bound);
    let at = format!("integral {wi}, channel {wc}");
    let refb = if bound > 0.0 { format!(" and the reference's bound {bound:.1e}") } else { String::new() };
    let compared = match (stored, wd.abs() > wu + bound) {
        (None, true) => format!("mean differs from the reference by {wd:.3e} ({at}), above round-off {wu:.1e}{refb}"),
        (None, false) => format!(
            "mean within round-off of the reference: largest difference {wd:.1e} ({at}), round-off {wu:.1e}{refb}"
        ),
        (Some(_), _) => format!(
            "mean differs from the stored reference by {wd:.3e} ({at}; round-off {wu:.1e}), tested against its \
             standard error {:.1e}",
            reference.std_err[wi][wc]
        ),
    };
    let decided = verdict(p, alpha, detectable);
    let reason = match decided {
        "inconclusive" if !gated => format!(
            "{lead}; {compared}; no independent gate (a pilot or a previous budget) to show the cell did not \
             miss the rare values of a random estimator: a pass needs one"
        ),
        "inconclusive" => format!(
            "{lead}; {compared}; the reference's error resolves {:.2}%, more than the {:.2}% tolerance (a more \
             precise reference would resolve it)",
            100.0 * detectable,
            100.0 * base.tolerance
        ),
        _ => format!("{lead}; {compared}"),
    };
    let name = if stored.is_some() { "holm_welch" } else { "holm_t" };
    let holm_verdict = if p_holm < alpha_holm { "biased" } else { "inconclusive" };
    let mut holm = base.row(name, max_t, p_holm, holm_verdict, holm_detect);
    holm.alpha = alpha_holm;
    holm.reason = format!(
        "zero variance: each integral and channel compared with its reference directly, {beyond} of {} beyond \
         round-off{}",
        zero.total,
        if stored.is_some() { "" } else { " and the reference's bound" }
    );
    let rel_bias_se = ((cell.rep_dev.variance().max(0.0) / r.max(1) as f64) + var_ref).sqrt() / ref_sum;
    let pooled_verdict = verdict(tp.p_value, alpha_pooled, pooled_detect);
    let mut pooled = base.row("pooled_t", tp.statistic, tp.p_value, pooled_verdict, pooled_detect);
    pooled.alpha = alpha_pooled;
    pooled.reason = format!("zero variance: the summed deviation {d:.3e} compared directly (allowance {tol:.1e})");
    pooled.rel_bias = d / ref_sum;
    pooled.rel_bias_se = rel_bias_se;
    let mut combined = base.row("combined", tp.statistic, p, decided, detectable);
    combined.rel_bias = d / ref_sum;
    combined.rel_bias_se = rel_bias_se;
    combined.reason = reason;
    vec![holm, pooled, combined]
}

#[cfg(test)]
#[path = "direct_tests.rs"]
mod tests;
