//! The SPEC §6 unbiasedness tests of one cell, and their three-way verdict.
//!
//! Two tests, combined by a weighted Bonferroni at the family-wise `alpha` (the pooled test gets
//! [`POOLED_SHARE`] of it, the per-integral one the rest): when the two are nearly the same test
//! (an image of one integral) the size stays above `POOLED_SHARE * alpha`, not `alpha / 2`:
//! - `pooled_t`: each repetition's summed deviation from the reference over every integral and
//!   channel ([`CellResult::rep_dev`]) is one independent observation, whatever the integrals of a
//!   repetition share (one adaptive structure per image, frames of one pixel, correlated
//!   channels); a t-test on them (Student quantiles, Welch-Satterthwaite degrees of freedom when a
//!   stored reference adds its variance) sees a bias spread over the image;
//! - `holm_t` / `holm_welch`: per integral and channel, a t-test (exact reference) or Welch test
//!   (stored), Holm-Bonferroni over them: sees a bias in a few integrals.
//!
//! Both are *gated* by skewness before the outcome is seen: a t-test's tail at a tiny `alpha` is
//! only right when the skewness of the tested mean is small (the first Edgeworth term,
//! [`t_test_skewness_limit`]), and the sample skewness of the cell itself is low exactly when its
//! repetitions missed a rare large value. So the gate takes the larger of the cell's skewness and
//! that of an independent [`Gate`] (the same pair on a pilot seed, or at the previous budget), and
//! the pooled test's variance is the mean of the cell's and the gate's: half of it cannot have
//! missed the tail with the cell. Without a gate the per-integral test does not run at all
//! (choosing integrals by their own sample skewness keeps exactly the ones that missed their
//! tails), and the pooled test can flag but never pass.
//!
//! Verdicts: `biased` when the combined p-value is below `alpha`; `pass` only when the pooled test
//! ran behind an independent gate and detects the stated relative bias tolerance (default 1%) with
//! 80% power; otherwise `inconclusive`, with what it could detect and the repetitions that would
//! resolve the tolerance. No untested, skipped or NaN test ever reads as `pass`.

use super::{POWER, UNBIASEDNESS_ALPHA};
use crate::cell::CellResult;
use estimators::estimator::Bias;
use estimators::stats::{detectable_shift_t, holm_bonferroni, t_test, t_test_skewness_limit, Moments};
use estimators::testbed::{Reference, ReferenceKind};
use serde::{Deserialize, Serialize};

/// The relative bias a `pass` must be able to detect unless the sweep says otherwise.
pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// The share of the family-wise `alpha` given to the pooled test (the rest goes to the
/// per-integral Holm test), fixed before any outcome is seen.
pub const POOLED_SHARE: f64 = 0.8;

/// What a test knows before it sees its cell: spread and skewness of the same estimator on the same
/// test bed from data independent of the cell.
#[derive(Clone, Debug, PartialEq)]
pub struct Gate {
    /// Where they come from (`pilot`, `previous budget`).
    pub source: String,
    /// Skewness of the per-repetition summed deviation.
    pub rep_skew: f64,
    /// Standard deviation of the per-repetition summed deviation, scaled to the tested cell.
    pub rep_sd: f64,
    /// Sample skewness per integral and channel.
    pub integral_skew: Vec<[f64; 3]>,
    /// Sample variance of one repetition's estimate per integral and channel, scaled to the tested
    /// cell.
    pub integral_var: Vec<[f64; 3]>,
}

impl Gate {
    /// The gate of an independent cell of the same pair; `scale` multiplies its spread and its
    /// skewness (for a cell at another budget: `sqrt(its budget / tested budget)`, since both the
    /// standard deviation and the skewness of a mean of n independent samples fall like
    /// 1/sqrt(n); conservative for estimators whose error falls at least that fast).
    pub fn from_cell(cell: &CellResult, source: &str, scale: f64) -> Gate {
        let skew = |m: &Moments| m.skewness() * scale;
        Gate {
            source: source.into(),
            rep_skew: skew(&cell.rep_dev),
            rep_sd: cell.rep_dev.variance().sqrt() * scale,
            integral_skew: cell.moments.iter().map(|m| [skew(&m[0]), skew(&m[1]), skew(&m[2])]).collect(),
            integral_var: cell.moments.iter().map(|m| [0, 1, 2].map(|c| m[c].variance() * scale * scale)).collect(),
        }
    }
}

/// One statistical test verdict (a row of summary.json's `tests`).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TestRow {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// `holm_t` / `holm_welch` (per integral), `pooled_t` (per repetition) or `combined` (the
    /// decision: weighted Bonferroni over the two, [`POOLED_SHARE`] of `alpha` to the pooled test).
    pub test: String,
    /// Budget the test ran at.
    pub budget: u64,
    /// Test statistic (largest |t| for the Holm tests; infinite when a zero-variance estimate misses
    /// the reference, which JSON stores as `null` and reads back as NaN).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub statistic: f64,
    /// p-value (Holm-adjusted minimum for the Holm tests); NaN when the test did not run.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub p_value: f64,
    /// `pass`, `inconclusive` or `biased`.
    pub verdict: String,
    /// The level the row is decided at: its share of the family-wise alpha for the Holm and pooled
    /// rows, the family-wise alpha for the combined row.
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub alpha: f64,
    /// Relative bias the test detects with 80% power (for the pooled and combined rows: over the
    /// whole image; for the Holm row: the median over integrals).
    #[serde(deserialize_with = "crate::output::f64_or_nan")]
    pub detectable_rel_bias: f64,
    /// What the registry claims (`unbiased`, `consistent`, `biased`).
    pub claim: String,
    /// Whether the verdict is the one the claim expects: `pass` for unbiased, `biased` for a
    /// control; an inconclusive verdict never agrees.
    pub agrees: bool,
    /// Holm tests: integral-channels left out by the skewness gate or without variance.
    #[serde(default)]
    pub untested: usize,
    /// The relative bias a `pass` must detect.
    #[serde(default, deserialize_with = "crate::output::f64_or_nan")]
    pub tolerance: f64,
    /// Repetitions that would resolve the tolerance (and the skewness gate), when inconclusive.
    #[serde(default)]
    pub reps_needed: Option<f64>,
    /// Where the gate's spread and skewness came from (`pilot`, `previous budget`, `none`).
    #[serde(default)]
    pub gate: String,
    /// Measured relative bias: the mean over repetitions of the summed deviation (estimate -
    /// reference over every integral and channel) over the sum of |reference|.
    #[serde(default, deserialize_with = "crate::output::f64_or_nan")]
    pub rel_bias: f64,
    /// Standard error of `rel_bias` (repetitions independent; integrals, channels and frames of
    /// one repetition counted once).
    #[serde(default, deserialize_with = "crate::output::f64_or_nan")]
    pub rel_bias_se: f64,
    /// Why the verdict is inconclusive, or how it was reached.
    #[serde(default)]
    pub reason: String,
}

fn agrees(claim: Bias, verdict: &str) -> bool {
    match claim {
        Bias::Unbiased => verdict == "pass",
        Bias::Biased => verdict == "biased",
        Bias::Consistent => true,
    }
}

/// The per-integral Holm test: (test name, max |t|, Holm p, median detectable, untested).
fn holm(cell: &CellResult, reference: &Reference, gate: Option<&Gate>, alpha: f64) -> (String, f64, f64, f64, usize) {
    let reps = cell.key.reps as u64;
    let m = cell.moments.len() * 3;
    let (stored_n, bound) = match &reference.kind {
        ReferenceKind::Stored { samples, .. } => (Some(*samples), 0.0),
        ReferenceKind::Exact { bound, .. } => (None, bound.max(0.0)),
    };
    let per_test_alpha = alpha / m.max(1) as f64;
    let limit = t_test_skewness_limit(reps, per_test_alpha);
    // An estimator with no spread at all (and none in its gate) is deterministic: any deviation is
    // a bias. One whose gate saw spread only missed its tail in this cell.
    let deterministic = reps >= 2
        && cell.moments.iter().flatten().all(|m| m.std_err() == 0.0)
        && gate.is_none_or(|g| g.rep_sd.is_nan() || g.rep_sd <= 0.0);
    let (mut ps, mut max_t, mut detect, mut untested) = (Vec::new(), 0.0f64, Vec::new(), 0);
    if gate.is_none() && !deterministic {
        // The cell's own skewness would choose which integrals to test: no test.
        let name = if stored_n.is_some() { "holm_welch" } else { "holm_t" };
        return (name.into(), f64::NAN, f64::NAN, f64::NAN, m);
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
        all.get(all.len() / 2).is_some_and(|&median| median > limit + 2.0 * (6.0 / reps.max(1) as f64).sqrt())
    });
    for (i, mom) in cell.moments.iter().enumerate() {
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
                detect
                    .push(detectable_shift_t(se_total, per_test_alpha, POWER, reps.saturating_sub(1) as f64) / r.abs());
            }
            let gate_skew = gate.and_then(|g| g.integral_skew.get(i)).map_or(0.0, |s| s[c].abs());
            let skew = mc.skewness().abs().max(if gate_skew.is_nan() { 0.0 } else { gate_skew });
            let t = match stored_n {
                None if se == 0.0 && mc.mean() == r_test => t_test(0.0, 0.0, f64::INFINITY),
                None if deterministic => t_test(1.0, 0.0, f64::INFINITY),
                _ if heavy || se == 0.0 || skew > limit => {
                    untested += 1;
                    continue;
                }
                None => t_test(mc.mean() - r_test, se, reps as f64 - 1.0),
                Some(n) => estimators::stats::welch(mc.mean(), se, reps, r, rse, n),
            };
            max_t = max_t.max(t.statistic.abs());
            ps.push(t.p_value);
        }
    }
    let p = if ps.is_empty() {
        f64::NAN
    } else {
        holm_bonferroni(&ps).into_iter().filter(|p| !p.is_nan()).fold(1.0, f64::min)
    };
    detect.sort_by(f64::total_cmp);
    let name = if stored_n.is_some() { "holm_welch" } else { "holm_t" };
    (name.into(), max_t, p, detect.get(detect.len() / 2).copied().unwrap_or(f64::NAN), untested)
}

/// The pooled test over repetitions.
struct Pooled {
    statistic: f64,
    p: f64,
    detectable: f64,
    /// `detectable` at the one-sided 95% upper bound of the estimated spread: what a pass needs.
    detectable_upper: f64,
    reps_needed: Option<f64>,
    gated_out: Option<String>,
    rel_bias: f64,
    rel_bias_se: f64,
}

/// The relative bias `b` of an estimator off by the factor `1 + b` that a test detecting the
/// relative shift `shift` at the unbiased spread finds: the spread scales by `1 + b` too, so
/// `b = shift / (1 - shift)` (none for a shift of 1 or more).
fn multiplicative(shift: f64) -> f64 {
    if shift < 1.0 {
        shift / (1.0 - shift)
    } else {
        f64::INFINITY
    }
}

fn pooled(cell: &CellResult, reference: &Reference, gate: Option<&Gate>, alpha: f64, tolerance: f64) -> Pooled {
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
    let dof = if var_ref > 0.0 && a > 0.0 {
        (a + var_ref).powi(2) / (a * a / (r as f64 - 1.0).max(1.0) + var_ref * var_ref / dof_ref)
    } else if var_ref > 0.0 {
        dof_ref
    } else {
        (r as f64 - 1.0).max(1.0)
    };
    let t = t_test(dev, se, dof);
    let shift = if se > 0.0 { detectable_shift_t(se, alpha, POWER, dof) / ref_sum } else { 0.0 };
    let detectable = multiplicative(shift);
    // The spread is estimated from the cell's repetitions (and the gate's, when they are averaged):
    // a pass asks that the bias be detectable at the upper 95% bound of that estimate, so that a
    // row at the edge of its tolerance does not pass in the seeds that underestimate its spread.
    let spread_dof = (r as f64 - 1.0).max(1.0) * if gate.is_some_and(|g| !g.rep_sd.is_nan()) { 2.0 } else { 1.0 };
    let upper = (spread_dof / estimators::stats::hypothesis::chi_square_quantile(0.05, spread_dof)).sqrt();
    let detectable_upper = multiplicative(shift * upper.max(1.0));
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
    let for_tolerance = super::reps_for(detectable, r as usize, share, tolerance);
    let for_skew = (skew > limit && limit > 0.0).then(|| (r as f64 * (skew / limit).powi(2)).ceil());
    let reps_needed = match (for_tolerance, for_skew) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    Pooled {
        statistic: t.statistic,
        p: t.p_value,
        detectable,
        detectable_upper,
        reps_needed,
        gated_out,
        rel_bias: mean / ref_sum,
        rel_bias_se: (sd_run * sd_run / r.max(1) as f64 + var_ref).sqrt() / ref_sum,
    }
}

/// The SPEC §6 tests of one cell: the Holm row, the pooled row and the combined row (the
/// decision), each with its verdict. `gate` is the independent spread and skewness (None: the
/// cell's own, which can flag a bias but never pass); `tolerance` the relative bias a `pass`
/// must be able to detect.
pub fn unbiasedness(
    cell: &CellResult,
    reference: &Reference,
    claim: Bias,
    gate: Option<&Gate>,
    tolerance: f64,
) -> Vec<TestRow> {
    let alpha = UNBIASEDNESS_ALPHA;
    let base = |test: &str, statistic: f64, p: f64, verdict: &str, detectable: f64| TestRow {
        testbed: cell.key.testbed.clone(),
        variant: cell.key.variant.clone(),
        estimator: cell.key.estimator.clone(),
        test: test.into(),
        budget: cell.key.budget.amount,
        statistic,
        p_value: p,
        verdict: verdict.into(),
        alpha,
        detectable_rel_bias: detectable,
        claim: claim.name().into(),
        agrees: agrees(claim, verdict),
        untested: 0,
        tolerance,
        reps_needed: None,
        gate: gate.map_or("none".into(), |g| g.source.clone()),
        rel_bias: f64::NAN,
        rel_bias_se: f64::NAN,
        reason: String::new(),
    };
    // Each test at its share of alpha: the combined p below is below `alpha` exactly when one of
    // them is below its share (the whole alpha when the other does not run).
    let (alpha_holm, alpha_pooled) = (alpha * (1.0 - POOLED_SHARE), alpha * POOLED_SHARE);
    let (holm_name, max_t, p_holm, holm_detect, untested) = holm(cell, reference, gate, alpha_holm);
    let pl = pooled(cell, reference, gate, alpha_pooled, tolerance);
    let p_pooled = if pl.gated_out.is_some() { f64::NAN } else { pl.p };
    // A pooled test kept from running by skewness (not by the deviation it would test) leaves the
    // whole alpha to the per-integral test; the calibration measures the size of the whole rule.
    let holm_alpha = if p_pooled.is_nan() { alpha } else { alpha_holm };
    let holm_verdict = if p_holm < holm_alpha { "biased" } else { "inconclusive" };
    let mut holm_row = base(&holm_name, max_t, p_holm, holm_verdict, holm_detect);
    holm_row.alpha = holm_alpha;
    holm_row.untested = untested;
    holm_row.reason = if holm_verdict == "biased" {
        format!("an integral flagged at Holm-adjusted p = {p_holm:.2e}")
    } else {
        "per-integral tests can flag a bias, never pass one: the combined row decides".into()
    };
    let pooled_verdict = if p_pooled < alpha_pooled {
        "biased"
    } else if pl.gated_out.is_none() && gate.is_some() && pl.detectable_upper <= tolerance {
        "pass"
    } else {
        "inconclusive"
    };
    let mut pooled_row = base("pooled_t", pl.statistic, p_pooled, pooled_verdict, pl.detectable);
    pooled_row.alpha = alpha_pooled;
    let p = match (p_holm.is_nan(), p_pooled.is_nan()) {
        (false, false) => (p_holm / (1.0 - POOLED_SHARE)).min(p_pooled / POOLED_SHARE).min(1.0),
        (false, true) => p_holm,
        (true, false) => p_pooled,
        (true, true) => f64::NAN,
    };
    let verdict = if p < alpha {
        "biased"
    } else if pooled_verdict == "pass" {
        "pass"
    } else {
        "inconclusive"
    };
    let reason = match verdict {
        "biased" => format!("flagged at p = {p:.2e} (weighted Bonferroni over the pooled and Holm tests)"),
        "pass" => {
            format!("no bias detected; a {:.2}% relative bias would be found with 80% power", 100.0 * pl.detectable)
        }
        _ => match (&pl.gated_out, gate) {
            (Some(why), _) => format!("no valid pooled test: {why}"),
            (None, None) => "no independent gate (a pilot or a previous budget): a pass needs one".into(),
            (None, Some(_)) => format!(
                "detects {:.2}% with 80% power, more than the {:.2}% tolerance",
                100.0 * pl.detectable,
                100.0 * tolerance
            ),
        },
    };
    pooled_row.reps_needed = pl.reps_needed;
    pooled_row.reason = match (&pl.gated_out, pooled_verdict) {
        (Some(why), _) => format!("not run: {why}"),
        (None, "biased") => format!("flagged at p = {p_pooled:.2e}"),
        (None, "pass") => "no bias detected at the tolerance".into(),
        (None, _) => "no bias detected, but not resolved to the tolerance".into(),
    };
    pooled_row.rel_bias = pl.rel_bias;
    pooled_row.rel_bias_se = pl.rel_bias_se;
    let mut combined = base("combined", pl.statistic, p, verdict, pl.detectable);
    combined.reps_needed = if verdict == "inconclusive" { pl.reps_needed } else { None };
    combined.rel_bias = pl.rel_bias;
    combined.rel_bias_se = pl.rel_bias_se;
    combined.untested = untested;
    combined.reason = reason;
    vec![holm_row, pooled_row, combined]
}

#[cfg(test)]
#[path = "bias_tests.rs"]
pub(crate) mod tests;
