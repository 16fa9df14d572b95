//! The unbiasedness tests of one cell (book: statistics.md), and their three-way verdict.
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
//! [`mcbench_core::stats::t_test_skewness_limit`]), and the sample skewness of the cell itself is low exactly when its
//! repetitions missed a rare large value. So the gate takes the larger of the cell's skewness and
//! that of an independent [`Gate`] (the same pair on a pilot seed, or at the previous budget), and
//! the pooled test's variance is the mean of the cell's and the gate's: half of it cannot have
//! missed the tail with the cell. Without a gate the per-integral test does not run at all
//! (choosing integrals by their own sample skewness keeps exactly the ones that missed their
//! tails), and the pooled test can flag but never pass.
//!
//! Verdicts: `biased` when the combined p-value is below `alpha`; `pass` only when the pooled test
//! ran behind an independent gate and the decision detects the stated relative bias tolerance
//! (default 1%) with 80% power at the upper 95% bound of its estimated spread; otherwise
//! `inconclusive`, with what it could detect and the repetitions that would resolve the tolerance.
//! No untested, skipped or NaN test ever reads as `pass`. The decision's detectable bias is the
//! smaller of its two tests' (it flags when either does): the pooled test's, and the per-integral
//! test's, whose independent groups of integrals (one integral each, or a sequence through which
//! an estimator carries state: [`Gate::group`]) each count as a chance.
//!
//! Zero and round-off variance are a case of their own ([`super::spread`]): a cell whose every
//! repetition, and its gate's, agree to within round-off ([`crate::analysis::roundoff`]) is compared with
//! the reference directly (the private `direct` module); in a gated cell where only some
//! integrals are so, those are not t-tested on their rounding errors (agreements within an exact
//! reference's bound join the per-integral family, the rest are left untested) and the others are
//! tested as above.

use super::holm::holm;
use super::pooled::{pooled, reps_needed};
use super::spread::{Spread, ZeroChannels};
use super::UNBIASEDNESS_ALPHA;
use crate::run::cell::CellResult;
use mcbench_core::estimator::Bias;
use mcbench_core::stats::Moments;
use mcbench_core::testbed::Reference;
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
    /// How many consecutive integrals may share state: 1 when every integral's estimate is
    /// independent of the others', a test bed's sequence length when an estimator carries state
    /// through a sequence ([`mcbench_core::estimator::Estimator::integrals_independent`]). Known
    /// before any outcome; [`Gate::from_cell`] takes the whole cell as one group.
    pub group: usize,
    /// The repetitions its spread and skewness come from (what their precision rests on).
    pub reps: u64,
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
            group: cell.moments.len().max(1),
            reps: cell.key.reps as u64,
        }
    }

    /// The degrees of freedom of the mean of a tested cell's variance (from `reps` repetitions)
    /// and this gate's: twice the cell's when the gate has as many repetitions, else (the two
    /// estimate the same variance when the estimator is unbiased, on independent draws) the
    /// Satterthwaite degrees of freedom of an even mean of two variance estimates of equal
    /// expectation, `4 / (1 / (reps - 1) + 1 / (gate reps - 1))`.
    pub fn mixed_dof(&self, reps: u64) -> f64 {
        let d = (reps as f64 - 1.0).max(1.0);
        if self.reps == reps {
            return 2.0 * d;
        }
        let g = (self.reps as f64 - 1.0).max(1.0);
        4.0 / (1.0 / d + 1.0 / g)
    }

    /// The degrees of freedom of a t-test of a cell of `reps` repetitions whose variance is the
    /// mean of its own and this gate's: the cell's `reps - 1`, or fewer when a gate of fewer
    /// repetitions makes the mean less precise than the cell alone ([`Gate::mixed_dof`]).
    pub fn t_dof(&self, reps: u64) -> f64 {
        let d = (reps as f64 - 1.0).max(1.0);
        d.min(self.mixed_dof(reps))
    }

    /// With integrals independent in groups of `group` consecutive ones (see [`Gate::group`]).
    pub fn with_group(self, group: usize) -> Gate {
        Gate { group: group.max(1), ..self }
    }

    /// The group of `estimator` on `bed`: 1 if its integrals are independent, else the bed's
    /// sequence length.
    pub fn group_of(
        estimator: &dyn mcbench_core::estimator::Estimator,
        bed: &dyn mcbench_core::testbed::TestBed,
    ) -> usize {
        if estimator.integrals_independent() {
            1
        } else {
            bed.sequence_length().max(1)
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
    /// Relative bias the test detects with 80% power (for the pooled and combined rows: an
    /// estimator off by that factor over the whole image, the combined row's the smaller of its two
    /// tests'; for the Holm row: the median over integrals of one integral's).
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
    /// How the cell's spread was judged: `sampled` (the t-tests), `zero_variance` (every
    /// repetition equal to within round-off, in the cell and its gate: the mean compared with the
    /// reference directly) or `mixed` (behind a gate, the integrals without spread are not
    /// t-tested on their rounding errors, the others are); `sampled` in files written before it.
    #[serde(default)]
    pub spread: Spread,
}

/// What every test row of one cell shares.
pub(super) struct RowBase<'a> {
    pub(super) cell: &'a CellResult,
    pub(super) claim: Bias,
    pub(super) gate: Option<&'a Gate>,
    pub(super) tolerance: f64,
    pub(super) spread: Spread,
    /// The family-wise level of the decision.
    pub(super) alpha: f64,
}

impl RowBase<'_> {
    /// A row of `test` with its outcome (the decision's level; callers set the others').
    pub(super) fn row(&self, test: &str, statistic: f64, p: f64, verdict: &str, detectable: f64) -> TestRow {
        let cell = self.cell;
        TestRow {
            testbed: cell.key.testbed.clone(),
            variant: cell.key.variant.clone(),
            estimator: cell.key.estimator.clone(),
            test: test.into(),
            budget: cell.key.budget.amount,
            statistic,
            p_value: p,
            verdict: verdict.into(),
            alpha: self.alpha,
            detectable_rel_bias: detectable,
            claim: self.claim.name().into(),
            agrees: agrees(self.claim, verdict),
            untested: 0,
            tolerance: self.tolerance,
            reps_needed: None,
            gate: self.gate.map_or("none".into(), |g| g.source.clone()),
            rel_bias: f64::NAN,
            rel_bias_se: f64::NAN,
            reason: String::new(),
            spread: self.spread,
        }
    }
}

fn agrees(claim: Bias, verdict: &str) -> bool {
    match claim {
        Bias::Unbiased => verdict == "pass",
        Bias::Biased => verdict == "biased",
        Bias::Consistent => true,
    }
}

/// The upper 95% bound of `true sd / estimated sd` for a spread estimated with `dof` degrees of
/// freedom (at least 1).
pub(super) fn spread_upper(dof: f64) -> f64 {
    let dof = dof.max(1.0);
    (dof / mcbench_core::stats::hypothesis::chi_square_quantile(0.05, dof)).sqrt().max(1.0)
}

/// The relative bias `b` of an estimator off by the factor `1 + b` that a test detecting the
/// relative shift `shift` at the unbiased spread finds: the spread scales by `1 + b` too, so
/// `b = shift / (1 - shift)` (none for a shift of 1 or more).
pub(super) fn multiplicative(shift: f64) -> f64 {
    if shift < 1.0 {
        shift / (1.0 - shift)
    } else {
        f64::INFINITY
    }
}

/// The unbiasedness tests of one cell: the Holm row, the pooled row and the combined row (the
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
    unbiasedness_at(cell, reference, claim, gate, tolerance, UNBIASEDNESS_ALPHA)
}

/// [`unbiasedness`] at the family-wise level `alpha` instead of [`UNBIASEDNESS_ALPHA`]: one look
/// of the round-based repetitions ([`crate::unbiasedness::rounds`]) decides at its share of it.
pub fn unbiasedness_at(
    cell: &CellResult,
    reference: &Reference,
    claim: Bias,
    gate: Option<&Gate>,
    tolerance: f64,
    alpha: f64,
) -> Vec<TestRow> {
    let zero = ZeroChannels::of(cell, reference, gate);
    let spread = zero.spread(gate.is_some());
    let rows = RowBase { cell, claim, gate, tolerance, spread, alpha };
    if spread == Spread::ZeroVariance {
        return super::direct::rows(&rows, reference, &zero);
    }
    let base = |test: &str, statistic: f64, p: f64, verdict: &str, detectable: f64| {
        rows.row(test, statistic, p, verdict, detectable)
    };
    // Each test at its share of alpha: the combined p below is below `alpha` exactly when one of
    // them is below its share (the whole alpha when the other does not run).
    let (alpha_holm, alpha_pooled) = (alpha * (1.0 - POOLED_SHARE), alpha * POOLED_SHARE);
    let h = holm(cell, reference, gate, alpha_holm, (&zero, spread));
    let (max_t, p_holm, untested) = (h.max_t, h.p, h.untested);
    let pl = pooled(cell, reference, gate, alpha_pooled, tolerance);
    let p_pooled = if pl.gated_out.is_some() { f64::NAN } else { pl.p };
    // A pooled test kept from running by skewness (not by the deviation it would test) leaves the
    // whole alpha to the per-integral test; the calibration measures the size of the whole rule.
    let holm_alpha = if p_pooled.is_nan() { alpha } else { alpha_holm };
    let holm_verdict = if p_holm < holm_alpha { "biased" } else { "inconclusive" };
    let mut holm_row = base(&h.name, max_t, p_holm, holm_verdict, h.median_detect);
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
    // The decision flags when either test does, so it detects at least what the stronger of the
    // two detects: on an image whose spread sits in a few integrals the per-integral test sees a
    // bias spread over the others before the pooled sum does.
    let min_defined = |a: f64, b: f64| if b.is_nan() || b >= a { a } else { b };
    let detectable = min_defined(pl.detectable, h.detectable(holm_alpha, false));
    let detectable_upper = min_defined(pl.detectable_upper, h.detectable(holm_alpha, true));
    let verdict = if p < alpha {
        "biased"
    } else if pl.gated_out.is_none() && gate.is_some() && detectable_upper <= tolerance {
        "pass"
    } else {
        "inconclusive"
    };
    let reason = match verdict {
        "biased" => format!("flagged at p = {p:.2e} (weighted Bonferroni over the pooled and Holm tests)"),
        "pass" => {
            format!("no bias detected; a {:.2}% relative bias would be found with 80% power", 100.0 * detectable)
        }
        _ => match (&pl.gated_out, gate) {
            (Some(why), _) => format!("no valid pooled test: {why}"),
            (None, None) => "no independent gate (a pilot or a previous budget): a pass needs one".into(),
            (None, Some(_)) if detectable <= tolerance => format!(
                "detects {:.2}% with 80% power, but not at the upper 95% bound of its estimated spread \
                 ({:.2}%), more than the {:.2}% tolerance",
                100.0 * detectable,
                100.0 * detectable_upper,
                100.0 * tolerance
            ),
            (None, Some(_)) => format!(
                "detects {:.2}% with 80% power, more than the {:.2}% tolerance",
                100.0 * detectable,
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
    let mut combined = base("combined", pl.statistic, p, verdict, detectable);
    combined.reps_needed = if verdict == "inconclusive" {
        reps_needed(detectable_upper, cell.key.reps, pl.share, tolerance, pl.for_skew)
    } else {
        None
    };
    combined.rel_bias = pl.rel_bias;
    combined.rel_bias_se = pl.rel_bias_se;
    combined.untested = untested;
    combined.reason = reason;
    if spread == Spread::Mixed && h.direct_beyond > 0 {
        let note = format!(
            "; {} of {} integral-channels without spread lie off the reference beyond round-off, left untested \
             (in a cell whose other integrals vary they may be rare values that the cell and its gate missed)",
            h.direct_beyond, h.direct
        );
        holm_row.reason.push_str(&note);
        combined.reason.push_str(&note);
    }
    vec![holm_row, pooled_row, combined]
}

#[cfg(test)]
#[path = "bias_tests.rs"]
pub(crate) mod tests;
