//! The pooled unbiasedness test (`pooled_t`): one observation per repetition, its summed deviation
//! from the reference over every integral and channel.

use super::bias::{multiplicative, spread_upper, Gate};
use super::POWER;
use crate::run::cell::CellResult;
use mcbench_core::stats::{detectable_shift_t, t_test, t_test_skewness_limit, Moments};
use mcbench_core::testbed::{Reference, ReferenceKind};

/// The pooled test over repetitions.
pub(super) struct Pooled {
    pub(super) statistic: f64,
    pub(super) p: f64,
    pub(super) detectable: f64,
    /// `detectable` at the one-sided 95% upper bound of the estimated spread: what a pass needs.
    pub(super) detectable_upper: f64,
    pub(super) reps_needed: Option<f64>,
    /// The share of the tested variance that more repetitions shrink.
    pub(super) share: f64,
    /// Repetitions that bring the skewness under the t-test's limit, when it is beyond it.
    pub(super) for_skew: Option<f64>,
    pub(super) gated_out: Option<String>,
    pub(super) rel_bias: f64,
    pub(super) rel_bias_se: f64,
}

pub(super) fn pooled(
    cell: &CellResult,
    reference: &Reference,
    gate: Option<&Gate>,
    alpha: f64,
    tolerance: f64,
) -> Pooled {
    let d: &Moments = &cell.rep_dev;
    let r = d.count();
    let ref_sum: f64 = reference.value.iter().flat_map(|v| v.0).map(f64::abs).sum();
    let n = (reference.value.len() * 3) as f64;
    let (bound_total, var_ref, dof_ref) = match &reference.kind {
        ReferenceKind::Exact { bound, .. } => (bound.max(0.0) * n, 0.0, f64::INFINITY),
        ReferenceKind::Stored { samples, .. } => {
            let v: f64 = reference.std_err.iter().map(|s| (s[0] + s[1] + s[2]).powi(2)).sum();
            (0.0, v, samples.saturating_sub(1).max(1) as f64)
        }
    };
    let mean = d.mean();
    let dev = mean - mean.clamp(-bound_total, bound_total);
    let sd_run = d.variance().sqrt();
    let sd = gate.map_or(sd_run, |g| {
        if g.rep_sd.is_nan() {
            sd_run
        } else {
            (0.5 * (sd_run * sd_run + g.rep_sd * g.rep_sd)).sqrt()
        }
    });
    let a = sd * sd / r.max(1) as f64;
    let se = (a + var_ref).sqrt();
    // The spread's degrees of freedom: the cell's, or those of the mean with the gate's (fewer
    // than the cell's alone when the gate has fewer repetitions, [`Gate::t_dof`]).
    let mixed = gate.filter(|g| !g.rep_sd.is_nan());
    let cell_dof = mixed.map_or((r as f64 - 1.0).max(1.0), |g| g.t_dof(r));
    let dof = if var_ref > 0.0 && a > 0.0 {
        (a + var_ref).powi(2) / (a * a / cell_dof + var_ref * var_ref / dof_ref)
    } else if var_ref > 0.0 {
        dof_ref
    } else {
        cell_dof
    };
    let t = t_test(dev, se, dof);
    let shift = if se > 0.0 { detectable_shift_t(se, alpha, POWER, dof) / ref_sum } else { 0.0 };
    let detectable = multiplicative(shift);
    // The spread is estimated from the cell's repetitions (and the gate's, when they are averaged):
    // a pass asks that the bias be detectable at the upper 95% bound of that estimate, so that a
    // row at the edge of its tolerance does not pass in the seeds that underestimate its spread.
    let spread_dof = mixed.map_or((r as f64 - 1.0).max(1.0), |g| g.mixed_dof(r));
    let detectable_upper = multiplicative(shift * spread_upper(spread_dof));
    let limit = t_test_skewness_limit(r, alpha);
    let skew_run = d.skewness().abs();
    let skew_gate = gate.map_or(0.0, |g| g.rep_skew.abs());
    let skew = [skew_run, skew_gate].into_iter().filter(|x| x.is_finite()).fold(0.0, f64::max);
    let gated_out = (r < 2 || skew > limit).then(|| {
        if r < 2 {
            "fewer than 2 repetitions".to_string()
        } else {
            format!("per-repetition skewness {skew:.2} beyond the t-test's limit {limit:.2} at {r} repetitions")
        }
    });
    // Repetitions that resolve the tolerance, and that bring the skewness under the limit (the
    // limit grows like sqrt(R)).
    let share = if a + var_ref > 0.0 { a / (a + var_ref) } else { 1.0 };
    let for_skew = (skew > limit && limit > 0.0).then(|| (r as f64 * (skew / limit).powi(2)).ceil());
    let reps_needed = reps_needed(detectable, r as usize, share, tolerance, for_skew);
    Pooled {
        statistic: t.statistic,
        p: t.p_value,
        detectable,
        detectable_upper,
        reps_needed,
        share,
        for_skew,
        gated_out,
        rel_bias: mean / ref_sum,
        rel_bias_se: (sd_run * sd_run / r.max(1) as f64 + var_ref).sqrt() / ref_sum,
    }
}

/// Repetitions that resolve the tolerance at detectable bias `detectable` and bring the skewness
/// under the limit (`for_skew`; the limit grows like sqrt(R)).
pub(super) fn reps_needed(
    detectable: f64,
    reps: usize,
    share: f64,
    tolerance: f64,
    for_skew: Option<f64>,
) -> Option<f64> {
    match (super::reps_for(detectable, reps, share, tolerance), for_skew) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
}
