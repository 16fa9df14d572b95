//! The per-integral unbiasedness test (`holm_t` / `holm_welch`): per integral and channel a t-test
//! (exact reference) or Welch test (stored), Holm-Bonferroni over them, and the relative bias it
//! detects over independent groups of integrals.

use super::bias::{multiplicative, spread_upper, Gate};
use super::spread::{Spread, ZeroChannels};
use super::POWER;
use crate::run::cell::CellResult;
use mcbench_core::stats::{detectable_shift_t, holm_bonferroni, t_test, t_test_skewness_limit};
use mcbench_core::testbed::{Reference, ReferenceKind};

/// The per-integral Holm test.
pub(super) struct Holm {
    pub(super) name: String,
    pub(super) max_t: f64,
    pub(super) p: f64,
    /// Median over integrals of the relative bias one integral's test detects.
    pub(super) median_detect: f64,
    pub(super) untested: usize,
    /// Per independent group of integrals ([`Gate::group`]), its strongest tested channel's
    /// `|reference| / standard error`: the noncentrality of its test per unit relative shift.
    pub(super) strengths: Vec<f64>,
    pub(super) dof: f64,
    /// Upper 95% bound over the estimate of the ratio of true to estimated standard errors.
    pub(super) spread_upper: f64,
    /// Zero-variance integral-channels of a mixed cell (not t-tested).
    pub(super) direct: usize,
    /// How many of those lie off the reference beyond round-off, an exact reference's bound and
    /// three of a stored reference's standard errors (left untested).
    pub(super) direct_beyond: usize,
}

impl Holm {
    /// The relative bias `b` (an estimator off by `1 + b` everywhere) that the test, at family
    /// level `alpha`, flags with 80% power: at least one of its integrals rejects at the Bonferroni
    /// level `alpha / tests` (Holm's first step; it rejects at least as often). Independent
    /// groups' chances combine (a group counts with its strongest test, a bound from below on its
    /// power whatever its integrals share). `upper`: at the upper 95% bound of the
    /// spread, what a pass needs.
    pub(super) fn detectable(&self, alpha: f64, upper: bool) -> f64 {
        let tests = self.strengths.len();
        if tests == 0 || self.p.is_nan() {
            return f64::NAN;
        }
        let scale = if upper { self.spread_upper } else { 1.0 };
        let scaled: Vec<f64> = self.strengths.iter().map(|q| q / scale).collect();
        let shift = mcbench_core::stats::detectable_shift_any(&scaled, alpha / tests as f64, POWER, self.dof);
        if shift.is_nan() {
            f64::NAN
        } else {
            multiplicative(shift)
        }
    }
}

/// The per-integral test of a cell at family level `alpha`; in a mixed cell (`zero` and `spread`)
/// its zero-variance integral-channels are not t-tested: within an exact reference's bound they
/// join the family as agreements (p = 1), otherwise they are left untested.
pub(super) fn holm(
    cell: &CellResult,
    reference: &Reference,
    gate: Option<&Gate>,
    alpha: f64,
    (zero, spread): (&ZeroChannels, Spread),
) -> Holm {
    let reps = cell.key.reps as u64;
    let m = cell.moments.len() * 3;
    let (stored_n, bound) = match &reference.kind {
        ReferenceKind::Stored { samples, .. } => (Some(*samples), 0.0),
        ReferenceKind::Exact { bound, .. } => (None, bound.max(0.0)),
    };
    let per_test_alpha = alpha / m.max(1) as f64;
    let limit = t_test_skewness_limit(reps, per_test_alpha);
    // A cell with no spread at all is compared directly before it gets here
    // ([`super::direct::rows`]); one whose gate saw spread only missed its tail in this cell.
    let (mut ps, mut max_t, mut detect, mut untested) = (Vec::new(), 0.0f64, Vec::new(), 0);
    let (mut direct, mut direct_beyond) = (0, 0);
    if gate.is_none() {
        // The cell's own skewness would choose which integrals to test: no test.
        let name = if stored_n.is_some() { "holm_welch" } else { "holm_t" };
        return Holm {
            name: name.into(),
            max_t: f64::NAN,
            p: f64::NAN,
            median_detect: f64::NAN,
            untested: m,
            strengths: Vec::new(),
            dof: f64::NAN,
            spread_upper: f64::NAN,
            direct: 0,
            direct_beyond: 0,
        };
    }
    // The integrals of one test bed share their sampling process, and a pixel's sample skewness
    // from a few hundred repetitions is low exactly when it missed its rare large values (in the
    // pilot as in the cell). So when the pilot's median skewness over the image is beyond the
    // limit by more than two standard errors of a sample skewness (`sqrt(6 / R)`: the median is
    // then clearly too skewed, not merely noisy, as it is for any estimator at a few
    // repetitions), no integral is tested.
    let heavy = gate.is_some_and(|g| {
        let mut all: Vec<f64> = g.integral_skew.iter().flatten().map(|s| s.abs()).filter(|s| s.is_finite()).collect();
        all.sort_by(f64::total_cmp);
        all.get(all.len() / 2).is_some_and(|&median| median > limit + 2.0 * (6.0 / g.reps.max(1) as f64).sqrt())
    });
    // Per independent group of integrals, its strongest test (the tests within a group may share
    // everything).
    let group = gate.map_or(usize::MAX, |g| g.group.max(1));
    // The degrees of freedom of a variance that is the mean of the cell's and the gate's
    // ([`Gate::t_dof`]: the cell's unless the gate has fewer repetitions), and the repetitions a
    // Welch test counts for them.
    let t_dof = gate.map_or((reps as f64 - 1.0).max(1.0), |g| g.t_dof(reps));
    let welch_reps = gate.map_or(reps, |g| if g.reps == reps { reps } else { (t_dof.floor() as u64 + 1).min(reps) });
    let mut strengths = Vec::new();
    let mut strongest = 0.0f64;
    for (i, mom) in cell.moments.iter().enumerate() {
        if i > 0 && i % group == 0 && strongest > 0.0 {
            strengths.push(std::mem::take(&mut strongest));
        }
        for (c, mc) in mom.iter().enumerate() {
            let (r, rse) = (reference.value[i][c], reference.std_err[i][c]);
            let r_test = if stored_n.is_none() { mc.mean().clamp(r - bound, r + bound) } else { r };
            // As in the pooled test: the variance is the mean of the cell's and the gate's, so a
            // cell that missed a rare large value (small spread, low mean) is not flagged on its own
            // small standard error.
            let var_gate = gate.and_then(|g| g.integral_var.get(i)).map(|v| v[c]).filter(|v| v.is_finite());
            let se = match var_gate {
                Some(v) if reps > 0 => ((0.5 * (mc.variance() + v)) / reps as f64).sqrt(),
                _ => mc.std_err(),
            };
            let se_total = (se * se + rse * rse).sqrt();
            if r != 0.0 {
                detect.push(
                    detectable_shift_t(se_total, per_test_alpha, POWER, t_dof.min(reps.saturating_sub(1) as f64))
                        / r.abs(),
                );
            }
            if let Some(u) = zero.direct(spread, i, c) {
                // No spread beyond round-off in the cell or its gate while other integrals vary:
                // not t-tested (its spread is rounding), and no evidence by itself (a rare value
                // that the cell and its gate both missed looks the same). A mean within an exact
                // reference's bound joins the family as an agreement, as an exactly constant
                // integral always did; any other is left untested, and counted when it lies off
                // the reference beyond round-off.
                direct += 1;
                let d = mc.mean() - r;
                if stored_n.is_none() && d.abs() <= bound {
                    ps.push(1.0);
                } else {
                    untested += 1;
                    direct_beyond += usize::from(d.abs() > u + bound + 3.0 * rse);
                }
                continue;
            }
            let gate_skew = gate.and_then(|g| g.integral_skew.get(i)).map_or(0.0, |s| s[c].abs());
            let skew = mc.skewness().abs().max(if gate_skew.is_nan() { 0.0 } else { gate_skew });
            let t = match stored_n {
                _ if heavy || se == 0.0 || skew > limit => {
                    untested += 1;
                    continue;
                }
                None => t_test(mc.mean() - r_test, se, t_dof.min(reps as f64 - 1.0)),
                Some(n) => mcbench_core::stats::welch(mc.mean(), se, welch_reps, r, rse, n),
            };
            max_t = max_t.max(t.statistic.abs());
            ps.push(t.p_value);
            if r != 0.0 && se_total > 0.0 {
                strongest = strongest.max(r.abs() / se_total);
            }
        }
    }
    if strongest > 0.0 {
        strengths.push(strongest);
    }
    let p = if ps.is_empty() {
        f64::NAN
    } else {
        holm_bonferroni(&ps).into_iter().filter(|p| !p.is_nan()).fold(1.0, f64::min)
    };
    detect.sort_by(f64::total_cmp);
    let name = if stored_n.is_some() { "holm_welch" } else { "holm_t" };
    // Each integral's variance is the mean of the cell's and the gate's (when it has one).
    let spread_dof = gate.map_or((reps as f64 - 1.0).max(1.0), |g| g.mixed_dof(reps));
    Holm {
        name: name.into(),
        max_t,
        p,
        median_detect: detect.get(detect.len() / 2).copied().unwrap_or(f64::NAN),
        untested,
        strengths,
        dof: t_dof,
        spread_upper: spread_upper(spread_dof),
        direct,
        direct_beyond,
    }
}
