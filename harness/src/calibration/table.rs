//! The calibration table: per row family, the measured false-flag rate, power and 80% point beside
//! what the unbiasedness rows report, and the checks they are held to.

use super::measure::{bias_grid, Family, Measured, SeedOutcome, NOMINAL};
use super::size;
use mcbench_core::estimator::Bias;
use serde::{Deserialize, Serialize};

/// One family's row of `calibration.csv`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// What the registry claims (`unbiased`, `biased`).
    pub claim: String,
    /// Samples per estimate.
    pub samples: u64,
    /// Repetitions per cell (and per pilot).
    pub reps: usize,
    /// Independent seeds (cell and pilot pairs).
    pub seeds: usize,
    /// Seeds in which the pooled test ran (its skewness gate let it).
    pub tested_fraction: f64,
    /// Unbiased families, no injected bias, seeds whose pooled test ran: the fraction with the
    /// combined p-value below the nominal level (5%).
    pub false_flag_rate: f64,
    /// Its 95% Wilson interval.
    pub false_flag_lo: f64,
    /// Its 95% Wilson interval.
    pub false_flag_hi: f64,
    /// No injected bias: the fraction of seeds flagged `biased` at the harness's alpha (for a
    /// control: its detection rate).
    pub flag_rate: f64,
    /// No injected bias: the fraction of seeds whose verdict is `pass`.
    pub pass_rate: f64,
    /// The fraction of seeds in which a +1% bias is flagged.
    pub power_1pct: f64,
    /// The same among the seeds that pass without it (what a `pass` promises).
    pub power_1pct_on_pass: f64,
    /// The fraction of seeds in which a +3% bias is flagged.
    pub power_3pct: f64,
    /// The median over seeds of the relative bias the row reports it detects with 80% power.
    pub detectable: f64,
    /// The injected relative bias flagged in 80% of seeds (interpolated; NaN when even 100% is not).
    pub measured_80: f64,
    /// `detectable / measured_80`.
    pub detectable_ratio: f64,
    /// The firefly rejection's threshold (the pilot's 99% quantile of values).
    pub firefly_threshold: f64,
    /// Its mean relative bias over seeds.
    pub firefly_rel_bias: f64,
    /// The fraction of seeds in which it is flagged.
    pub firefly_flag_rate: f64,
    /// False-flag rate consistent with 1.5x of nominal: its Wilson interval meets the band (None:
    /// fewer than 50 tested seeds, a zero-variance estimator, or a control).
    pub ok_false_flag: Option<bool>,
    /// Reported detectable within 25% of the measured 80% point (None: the pooled test ran in
    /// fewer than 80% of seeds, so the rows are inconclusive and the detectable bias decides no pass).
    pub ok_detectable: Option<bool>,
    /// A +1% bias flagged in at least 80% of the seeds that pass at 1%, to within the Wilson
    /// interval of the passing seeds (None: no seed passes).
    pub ok_power: Option<bool>,
    /// A control flagged in at least 99% of seeds (None: not a control).
    pub ok_control: Option<bool>,
    /// What the checks found.
    pub note: String,
    /// Unbiased families, no injected bias: seeds with a combined p-value (the decision-level size
    /// check's sample; 0 for a control or a zero-variance estimator).
    pub size_seeds: usize,
    /// Of those, the count below the verdicts' alpha.
    pub below_alpha: usize,
    /// Of those, the count below 1%.
    pub below_1pct: usize,
    /// Of those, the count below 5%.
    pub below_5pct: usize,
    /// The family's size p-value at the decision level ([`super::size::family_p`]).
    pub size_p: f64,
    /// The decision-level size check, Holm across the families judged ([`super::size`]; None: not
    /// judged).
    pub ok_size: Option<bool>,
    /// The planted miscalibrated test's size p-value on the same seeds.
    pub planted_size_p: f64,
    /// Its count below the verdicts' alpha.
    pub planted_below_alpha: usize,
    /// Whether the planted test passes the same check (it should not).
    pub planted_ok_size: Option<bool>,
}

/// Below this flag rate of the firefly rejection an unbiased row's note says its power against a
/// rare-large-value bug is low.
pub const FIREFLY_LOW_POWER: f64 = 0.5;

/// The band the false-flag rate must be consistent with: within 1.5x of [`NOMINAL`].
pub const SIZE_BAND: (f64, f64) = (NOMINAL / 1.5, NOMINAL * 1.5);
/// The power at 1% a passing row must have.
pub const MIN_POWER: f64 = 0.8;

/// Whether `k` flags in `n` seeds are consistent with a rate inside [`SIZE_BAND`]: the 95% Wilson
/// interval meets the band (with 100 seeds a test of size exactly 5% shows 3 or fewer flags in a
/// quarter of families, so the point estimate alone would fail sized tests by chance; the pooled
/// rate over all families, [`claims`](super::report::claims), is the sharp check).
pub fn within_band(k: usize, n: usize) -> bool {
    let (lo, hi) = wilson(k, n);
    hi >= SIZE_BAND.0 && lo <= SIZE_BAND.1
}

/// The 95% Wilson score interval of `k` successes in `n` trials.
pub fn wilson(k: usize, n: usize) -> (f64, f64) {
    if n == 0 {
        return (0.0, 1.0);
    }
    let (z, n, p) = (1.959_963_984_540_054, n as f64, k as f64 / n as f64);
    let centre = (p + z * z / (2.0 * n)) / (1.0 + z * z / n);
    let half = z / (1.0 + z * z / n) * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt();
    ((centre - half).max(0.0), (centre + half).min(1.0))
}

/// The bias flagged in `target` of the seeds, interpolated in log bias between grid points.
fn point_of(grid: &[f64], rate: &[f64], target: f64) -> f64 {
    for k in 0..grid.len() {
        if rate[k] >= target {
            if k == 0 {
                return grid[0];
            }
            let t = (target - rate[k - 1]) / (rate[k] - rate[k - 1]);
            return (grid[k - 1].ln() + t * (grid[k].ln() - grid[k - 1].ln())).exp();
        }
    }
    f64::NAN
}

pub(super) fn frac(k: usize, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        k as f64 / n as f64
    }
}

/// The row of a measured family.
pub fn row(family: &Family, m: &Measured, name: &str) -> Row {
    let s = &m.seeds;
    let n = s.len();
    let grid = bias_grid();
    let at = |b: f64| grid.iter().position(|g| (g / b - 1.0).abs() < 1e-9).expect("1% and 3% are on the grid");
    let (i1, i3) = (at(0.01), at(0.03));
    let tested: Vec<_> = s.iter().filter(|o| o.pooled_ran && !o.null.p_value.is_nan()).collect();
    let ff = tested.iter().filter(|o| o.null.p_value < NOMINAL).count();
    let (lo, hi) = wilson(ff, tested.len());
    let passing: Vec<_> = s.iter().filter(|o| o.null.verdict == "pass").collect();
    let rate: Vec<f64> = (0..grid.len()).map(|g| frac(s.iter().filter(|o| o.flagged[g]).count(), n)).collect();
    let mut detect: Vec<f64> = s.iter().map(|o| o.null.detectable_rel_bias).filter(|d| d.is_finite()).collect();
    detect.sort_by(f64::total_cmp);
    let detectable = detect.get(detect.len() / 2).copied().unwrap_or(f64::NAN);
    let measured_80 = point_of(&grid, &rate, 0.8);
    let tested_fraction = frac(tested.len(), n);
    let flag_rate = frac(s.iter().filter(|o| o.null.verdict == "biased").count(), n);
    let unbiased = family.bias == Bias::Unbiased;
    // A zero-variance estimator is compared exactly: no size to measure, any bias is flagged (its
    // reported detectable bias is its round-off allowance, far below the smallest injected bias).
    let zero = s.iter().filter(|o| o.null.spread == crate::analysis::Spread::ZeroVariance).count();
    let deterministic = n > 0 && 2 * zero > n;
    let ok_false_flag = (unbiased && !deterministic && tested.len() >= 50).then(|| within_band(ff, tested.len()));
    let ok_detectable = (unbiased && tested_fraction >= 0.8).then(|| {
        if deterministic {
            measured_80 == grid[0]
        } else {
            measured_80.is_finite() && (detectable / measured_80 - 1.0).abs() <= 0.25
        }
    });
    let on_pass = passing.iter().filter(|o| o.flagged[i1]).count();
    let power_1pct_on_pass = frac(on_pass, passing.len());
    // Not shown to be below 80%: the Wilson interval reaches it.
    let ok_power = (unbiased && !passing.is_empty()).then(|| wilson(on_pass, passing.len()).1 >= MIN_POWER);
    let ok_control = (family.bias == Bias::Biased).then_some(flag_rate >= 0.99);
    let mut note = Vec::new();
    if unbiased && tested_fraction < 0.8 {
        note.push(format!(
            "pooled test gated out in {:.0}% of seeds (too skewed at {} repetitions)",
            100.0 * (1.0 - tested_fraction),
            family.reps
        ));
    }
    if ok_false_flag == Some(false) {
        note.push(format!(
            "false-flag rate {:.1}% [{:.1}, {:.1}] at nominal {:.0}%",
            100.0 * frac(ff, tested.len()),
            100.0 * lo,
            100.0 * hi,
            100.0 * NOMINAL
        ));
    }
    if ok_detectable == Some(false) {
        note.push(format!(
            "reports {:.3}% detectable, measured 80% point {:.3}%",
            100.0 * detectable,
            100.0 * measured_80
        ));
    }
    if ok_control == Some(false) {
        note.push(format!("control flagged in {:.1}% of seeds", 100.0 * flag_rate));
    }
    let firefly_flag_rate = frac(s.iter().filter(|o| o.firefly_flagged).count(), n);
    let firefly_rel_bias = s.iter().map(|o| o.firefly_rel).sum::<f64>() / n.max(1) as f64;
    if unbiased && firefly_flag_rate < FIREFLY_LOW_POWER {
        note.push(format!(
            "low power against a rare-large-value bug: a firefly rejection ({:+.2}% bias) flagged in {:.0}% of seeds",
            100.0 * firefly_rel_bias,
            100.0 * firefly_flag_rate
        ));
    }
    let judged = unbiased && !deterministic;
    let p_of = |t: fn(&SeedOutcome) -> f64| -> Vec<f64> {
        if judged {
            s.iter().map(t).collect()
        } else {
            Vec::new()
        }
    };
    let (counts, size_seeds) = size::tail_counts(&p_of(|o| o.null.p_value));
    let (planted, planted_seeds) = size::tail_counts(&p_of(|o| o.planted.p_value));
    Row {
        testbed: family.bed.id.clone(),
        variant: family.bed.variant.clone().unwrap_or_default(),
        estimator: name.into(),
        claim: family.bias.name().into(),
        samples: family.samples,
        reps: family.reps,
        seeds: n,
        tested_fraction,
        false_flag_rate: frac(ff, tested.len()),
        false_flag_lo: lo,
        false_flag_hi: hi,
        flag_rate,
        pass_rate: frac(passing.len(), n),
        power_1pct: rate[i1],
        power_1pct_on_pass,
        power_3pct: rate[i3],
        detectable,
        measured_80,
        detectable_ratio: detectable / measured_80,
        firefly_threshold: m.threshold,
        firefly_rel_bias,
        firefly_flag_rate,
        ok_false_flag,
        ok_detectable,
        ok_power,
        ok_control,
        note: if note.is_empty() { "ok".into() } else { note.join("; ") },
        size_seeds,
        below_alpha: counts[0],
        below_1pct: counts[1],
        below_5pct: counts[2],
        size_p: size::family_p(counts, size_seeds),
        ok_size: None,
        planted_size_p: size::family_p(planted, planted_seeds),
        planted_below_alpha: planted[0],
        planted_ok_size: None,
    }
}

/// The decision-level size check across `rows` (Holm over the families judged, [`super::size`]):
/// sets `ok_size` and `planted_ok_size`, and adds a failing family's counts to its note.
pub fn judge_size(rows: &mut [Row]) {
    let real = size::holm_rejects(&rows.iter().map(|r| r.size_p).collect::<Vec<_>>(), size::FAMILY_FWER);
    let planted = size::holm_rejects(&rows.iter().map(|r| r.planted_size_p).collect::<Vec<_>>(), size::FAMILY_FWER);
    for (r, (bad, planted_bad)) in rows.iter_mut().zip(real.into_iter().zip(planted)) {
        r.ok_size = r.size_p.is_finite().then_some(!bad);
        r.planted_ok_size = r.planted_size_p.is_finite().then_some(!planted_bad);
        if bad {
            let text = format!(
                "size fails at the decision level: {} below {}, {} below 1%, {} below 5% of {} seeds (size p {:.1e})",
                r.below_alpha,
                crate::analysis::UNBIASEDNESS_ALPHA,
                r.below_1pct,
                r.below_5pct,
                r.size_seeds,
                r.size_p
            );
            r.note = if r.note == "ok" { text } else { format!("{}; {text}", r.note) };
        }
    }
}

#[cfg(test)]
#[path = "table_tests.rs"]
mod tests;
