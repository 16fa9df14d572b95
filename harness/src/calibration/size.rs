//! The size of the unbiasedness test at the decision level: every seed's combined p-value of a
//! family with no injected bias is kept, and the lower tail of their distribution is held to what
//! a test of the right size gives.
//!
//! - Per family: the counts below [`LEVELS`] (the verdicts' alpha, 1% and 5%) are each tested
//!   one-sided against a binomial of that level (exact tail, [`binomial_upper`]); the family's size
//!   p-value is the smallest of the three tails times three (Bonferroni). A family fails when Holm
//!   across the families judged rejects it at [`FAMILY_FWER`].
//! - Pooled: the count below the verdicts' alpha over every judged family's seeds against a
//!   binomial of that level; it fails when its upper tail is below [`POOLED_LEVEL`].
//!
//! Both are one-sided: a test whose p-values are super-uniform (a Bonferroni combination is) is
//! conservative, not miscalibrated; a test that flags more than its level is. The thresholds are
//! fixed here, before the runs they judge; with uniform p-values the whole check fails in at most
//! about 6% of calibrations (measured by simulation in the tests), and a test whose standard error
//! is shrunk by [`PLANTED_SE_FACTOR`] fails it.

use super::measure::{Family, Measured};
use super::table::Row;
use crate::analysis::UNBIASEDNESS_ALPHA;
use crate::output::Claim;
use serde::{Deserialize, Serialize};

/// The p-value levels whose counts are checked: the verdicts' alpha, 1% and 5%.
pub const LEVELS: [f64; 3] = [UNBIASEDNESS_ALPHA, 0.01, 0.05];
/// The family-wise level of the per-family check (Holm across families).
pub const FAMILY_FWER: f64 = 0.05;
/// The level of the pooled check.
pub const POOLED_LEVEL: f64 = 0.01;
/// The planted miscalibrated test: the same test with every standard error multiplied by this
/// (its statistics inflated by its inverse).
pub const PLANTED_SE_FACTOR: f64 = 0.75;
/// Fewest seeds with a p-value for a family to be judged.
pub const MIN_SEEDS: usize = 50;

/// `P(X >= k)` for `X ~ Binomial(n, p)`, summed from `k` upward (accurate in the far tail).
pub fn binomial_upper(k: usize, n: usize, p: f64) -> f64 {
    if k == 0 {
        return 1.0;
    }
    if k > n {
        return 0.0;
    }
    let ln_fact = |m: usize| (1..=m).map(|i| (i as f64).ln()).sum::<f64>();
    let mut ln_pmf = ln_fact(n) - ln_fact(k) - ln_fact(n - k) + k as f64 * p.ln() + (n - k) as f64 * (1.0 - p).ln();
    let mut sum = 0.0;
    for i in k..=n {
        let term = ln_pmf.exp();
        sum += term;
        if term < sum * 1e-17 {
            break;
        }
        ln_pmf += ((n - i) as f64 / (i + 1) as f64).ln() + (p / (1.0 - p)).ln();
    }
    sum.min(1.0)
}

/// The counts of `p_values` (finite ones) below each of [`LEVELS`], and how many are finite.
pub fn tail_counts(p_values: &[f64]) -> ([usize; 3], usize) {
    let finite: Vec<f64> = p_values.iter().copied().filter(|p| p.is_finite()).collect();
    (LEVELS.map(|l| finite.iter().filter(|&&p| p < l).count()), finite.len())
}

/// A family's size p-value: the smallest one-sided binomial tail of its counts below [`LEVELS`],
/// times their number (NaN with fewer than [`MIN_SEEDS`] seeds).
pub fn family_p(counts: [usize; 3], n: usize) -> f64 {
    if n < MIN_SEEDS {
        return f64::NAN;
    }
    let tails = LEVELS.iter().zip(counts).map(|(&l, k)| binomial_upper(k, n, l));
    (LEVELS.len() as f64 * tails.fold(1.0, f64::min)).min(1.0)
}

/// Holm's step-down procedure at family-wise level `fwer`: whether each p-value is rejected (NaN:
/// not judged, never rejected).
pub fn holm_rejects(p: &[f64], fwer: f64) -> Vec<bool> {
    let mut order: Vec<usize> = (0..p.len()).filter(|&i| p[i].is_finite()).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let m = order.len();
    let mut out = vec![false; p.len()];
    for (rank, &i) in order.iter().enumerate() {
        if p[i] >= fwer / (m - rank) as f64 {
            break;
        }
        out[i] = true;
    }
    out
}

/// The pooled check: `k` of `n` seeds below the verdicts' alpha -> (upper tail, held).
pub fn pooled(k: usize, n: usize) -> (f64, bool) {
    let tail = binomial_upper(k, n, UNBIASEDNESS_ALPHA);
    (tail, tail >= POOLED_LEVEL)
}

/// The whole check on families' p-values: whether each family holds (None: not judged) and whether
/// the pooled count holds.
pub fn check(families: &[Vec<f64>]) -> (Vec<Option<bool>>, bool) {
    let judged: Vec<([usize; 3], usize)> = families.iter().map(|f| tail_counts(f)).collect();
    let ps: Vec<f64> = judged.iter().map(|&(c, n)| family_p(c, n)).collect();
    let rejected = holm_rejects(&ps, FAMILY_FWER);
    let per = ps.iter().zip(&rejected).map(|(p, &r)| p.is_finite().then_some(!r)).collect();
    let (k, n) =
        judged.iter().zip(&ps).filter(|(_, p)| p.is_finite()).fold((0, 0), |(k, n), ((c, m), _)| (k + c[0], n + m));
    (per, pooled(k, n).1)
}

/// One seed of one family in `calibration-pvalues.csv`: the p-values the size check reads.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SeedP {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// The seed's index in the family (its cell is repetitions `2kR .. 2kR + R`).
    pub seed: usize,
    /// The combined p-value with no injected bias.
    pub p_value: f64,
    /// Its verdict.
    pub verdict: String,
    /// Whether the pooled test ran (its skewness gate let it).
    pub pooled_ran: bool,
    /// The planted miscalibrated test's combined p-value on the same seed.
    pub planted_p_value: f64,
    /// Whether the firefly rejection was flagged on this seed.
    pub firefly_flagged: bool,
}

/// The per-seed rows of a measured family.
pub fn seed_rows(family: &Family, m: &Measured, name: &str) -> Vec<SeedP> {
    m.seeds
        .iter()
        .enumerate()
        .map(|(k, o)| SeedP {
            testbed: family.bed.id.clone(),
            variant: family.bed.variant.clone().unwrap_or_default(),
            estimator: name.into(),
            seed: k,
            p_value: o.null.p_value,
            verdict: o.null.verdict.clone(),
            pooled_ran: o.pooled_ran,
            planted_p_value: o.planted.p_value,
            firefly_flagged: o.firefly_flagged,
        })
        .collect()
}

/// The decision-level size claims over judged rows (after [`super::table::judge_size`]): every
/// family holds, the pooled count holds, and the planted miscalibrated test fails the same check.
pub fn claims(rows: &[Row]) -> Vec<Claim> {
    let judged: Vec<&Row> = rows.iter().filter(|r| r.ok_size.is_some()).collect();
    let failed: Vec<String> = judged
        .iter()
        .filter(|r| r.ok_size == Some(false))
        .map(|r| format!("{} on {}/{}", r.estimator, r.testbed, r.variant))
        .collect();
    let (k, n) = judged.iter().fold((0, 0), |(k, n), r| (k + r.below_alpha, n + r.size_seeds));
    let (tail, held) = pooled(k, n);
    let planted: Vec<&Row> = rows.iter().filter(|r| r.planted_ok_size.is_some()).collect();
    let planted_failed = planted.iter().filter(|r| r.planted_ok_size == Some(false)).count();
    let (pk, pn) = planted.iter().fold((0, 0), |(k, n), r| (k + r.planted_below_alpha, n + r.size_seeds));
    let (planted_tail, planted_pooled) = pooled(pk, pn);
    let some = |held: bool, any: bool| any.then_some(held);
    let claim = |text: String, our: f64, held: Option<bool>, note: String| Claim {
        testbed: "all".into(),
        claim: format!("harness: {text}"),
        paper_value: None,
        our_value: Some(our),
        held,
        note,
        ..Default::default()
    };
    vec![
        claim(
            format!(
                "size at the decision level: no unbiased family's p-values below {UNBIASEDNESS_ALPHA}, 1% and 5% exceed their levels (binomial tails, Holm across families at {FAMILY_FWER})"
            ),
            (judged.len() - failed.len()) as f64,
            some(failed.is_empty(), !judged.is_empty()),
            if failed.is_empty() {
                format!("holds on all {} families judged", judged.len())
            } else {
                format!("fails on {} of {}: {}", failed.len(), judged.len(), failed.join(", "))
            },
        ),
        claim(
            format!("pooled over the unbiased families, p-values below {UNBIASEDNESS_ALPHA} within a binomial of that rate (upper tail at least {POOLED_LEVEL})"),
            frac(k, n),
            some(held, n > 0),
            format!("{k} of {n} seeds (expected {:.1}), upper tail {tail:.2e}", n as f64 * UNBIASEDNESS_ALPHA),
        ),
        claim(
            format!("the planted miscalibrated test (standard errors x{PLANTED_SE_FACTOR}) fails the same size check"),
            planted_failed as f64,
            some(planted_failed > 0 || !planted_pooled, pn > 0),
            format!(
                "fails on {planted_failed} of {} families; pooled {pk} of {pn} seeds below {UNBIASEDNESS_ALPHA}, upper tail {planted_tail:.2e}",
                planted.len()
            ),
        ),
    ]
}

fn frac(k: usize, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        k as f64 / n as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn binomial_tail_matches_known_values() {
        // P(X >= 2 | 100, 0.001) = 1 - 0.999^100 - 100 * 0.001 * 0.999^99 = 0.0046381...
        assert!((binomial_upper(2, 100, 0.001) - 0.004_638_1).abs() < 1e-6);
        assert!((binomial_upper(1, 10, 0.5) - (1.0 - 0.5f64.powi(10))).abs() < 1e-12);
        assert_eq!(binomial_upper(0, 5, 0.3), 1.0);
        assert_eq!(binomial_upper(6, 5, 0.3), 0.0);
        assert!((binomial_upper(5, 5, 0.3) - 0.3f64.powi(5)).abs() < 1e-15);
    }

    #[test]
    fn holm_steps_down_and_skips_unjudged() {
        assert_eq!(holm_rejects(&[0.001, 0.02, f64::NAN, 0.04], 0.05), vec![true, true, false, true]);
        assert_eq!(holm_rejects(&[0.001, 0.03, 0.04], 0.05), vec![true, false, false]);
    }

    /// `families` families of `seeds` seeds, p-values of a z-test whose standard error is `factor`
    /// times the true one (1: the right size).
    fn simulated(rng: &mut rand_pcg::Pcg64, families: usize, seeds: usize, factor: f64) -> Vec<Vec<f64>> {
        let mut normal = || {
            let (u, v): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        };
        (0..families)
            .map(|_| (0..seeds).map(|_| mcbench_core::stats::z_test(normal(), factor, 0.0).p_value).collect())
            .collect()
    }

    /// With correctly sized p-values the whole check (per family with Holm, and pooled) fails in
    /// few calibrations; with the standard error shrunk by the planted factor it fails in nearly
    /// all, both per family and pooled. 400 calibrations of 40 families x 100 seeds each.
    #[test]
    fn the_size_check_rarely_fails_a_sized_test_and_fails_the_planted_one() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let runs = 400;
        let (mut false_fail, mut planted_family, mut planted_pooled) = (0, 0, 0);
        for _ in 0..runs {
            let (per, pooled) = check(&simulated(&mut rng, 40, 100, 1.0));
            if !pooled || per.contains(&Some(false)) {
                false_fail += 1;
            }
            let (per, pooled) = check(&simulated(&mut rng, 40, 100, PLANTED_SE_FACTOR));
            planted_family += usize::from(per.contains(&Some(false)));
            planted_pooled += usize::from(!pooled);
        }
        let rate = false_fail as f64 / runs as f64;
        assert!(rate <= 0.06 + 0.03, "false-fail rate of the check {rate}");
        assert!(planted_family as f64 >= 0.95 * runs as f64, "{planted_family} of {runs}");
        assert!(planted_pooled as f64 >= 0.95 * runs as f64, "{planted_pooled} of {runs}");
    }

    /// One family alone: the planted test fails it in most calibrations at 100 seeds.
    #[test]
    fn a_single_planted_family_is_usually_caught() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let caught =
            (0..200).filter(|_| check(&simulated(&mut rng, 1, 100, PLANTED_SE_FACTOR)).0[0] == Some(false)).count();
        assert!(caught >= 150, "{caught} of 200");
    }
}
