//! Unit tests of zero and round-off variance: cells compared with the reference directly, and the
//! integrals without spread of mixed cells.

use super::super::bias::tests::{cell_from, decision, exact, normal_reps};
use super::super::bias::{unbiasedness, Gate, DEFAULT_TOLERANCE};
use crate::analysis::Spread;
use mcbench_core::estimator::Bias;
use mcbench_core::math::Rgb;
use mcbench_core::testbed::{Reference, ReferenceKind};
use rand::{Rng, SeedableRng};

/// `reps` repetitions of `values` (one per integral, every channel alike) each off by `1 + err`,
/// with round-off as it comes out of an estimator: a value one ulp up in about one estimate in
/// seven (discrete and skewed, as rounding errors are).
fn roundoff_reps(seed: u64, values: &[f64], reps: usize, err: f64) -> Vec<Vec<[f64; 3]>> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    (0..reps)
        .map(|_| {
            values
                .iter()
                .map(|v| {
                    let x = v * (1.0 + err);
                    [0; 3].map(|_| if rng.gen::<f64>() < 0.15 { x + x * f64::EPSILON } else { x })
                })
                .collect()
        })
        .collect()
}

/// A furnace-like cell whose spread is round-off: a constant 2% error is `biased`, agreement is a
/// `pass`, each compared directly, with notes that say so (before, the skewness of the rounding
/// errors kept every t-test from running: both were inconclusive).
#[test]
fn a_deterministic_error_at_round_off_is_biased_and_agreement_passes() {
    let values = [0.3, 0.45, 0.6, 0.75];
    let reference = exact(&values.map(|v| [v; 3]));
    let decide = |err: f64| {
        let cell = cell_from(&roundoff_reps(31, &values, 16, err), &reference);
        let gate = Gate::from_cell(&cell_from(&roundoff_reps(32, &values, 16, err), &reference), "pilot", 1.0);
        unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), DEFAULT_TOLERANCE)
    };
    let off = decide(0.02);
    let d = decision(&off);
    assert_eq!((d.verdict.as_str(), d.spread, d.p_value), ("biased", Spread::ZeroVariance, 0.0), "{d:?}");
    assert!((d.rel_bias - 0.02).abs() < 1e-12, "{d:?}");
    assert!(
        d.reason.starts_with("zero variance: repetitions equal to round-off")
            && d.reason.contains("mean differs from the reference by")
            && d.reason.contains("above round-off"),
        "{}",
        d.reason
    );
    assert!(off.iter().all(|t| t.spread == Spread::ZeroVariance && !t.p_value.is_nan()), "{off:?}");
    let ok = decide(0.0);
    let d = decision(&ok);
    assert_eq!((d.verdict.as_str(), d.spread, d.agrees), ("pass", Spread::ZeroVariance, true), "{d:?}");
    assert!(d.reason.contains("mean within round-off of the reference"), "{}", d.reason);
    // It detects any bias above round-off: far below the tolerance.
    assert!(d.detectable_rel_bias > 0.0 && d.detectable_rel_bias < 1e-12, "{d:?}");
    // Equal repetitions say so; without a gate agreement is not a pass (a random estimator's
    // cell may have missed its rare values), a deviation still a bias.
    let equal: Vec<Vec<[f64; 3]>> = (0..8).map(|_| values.iter().map(|v| [*v; 3]).collect()).collect();
    let alone = unbiasedness(&cell_from(&equal, &reference), &reference, Bias::Unbiased, None, 0.01);
    let d = decision(&alone);
    assert_eq!(d.verdict, "inconclusive", "{d:?}");
    assert!(d.reason.starts_with("zero variance: every repetition equal") && d.reason.contains("no independent gate"));
}

/// Against a stored reference a zero-variance mean is tested against the reference's own error:
/// a deviation of several of its standard errors is a bias, one within them a pass when the
/// reference resolves the tolerance, inconclusive when it does not.
#[test]
fn a_zero_variance_mean_is_tested_against_a_stored_references_error() {
    let values = [1.0; 16];
    let mut reference = exact(&values.map(|v| [v; 3]));
    reference.kind = ReferenceKind::Stored { command: "x".into(), samples: 1 << 20 };
    let with_se = |se: f64| Reference { std_err: vec![Rgb::splat(se); values.len()], ..reference.clone() };
    let decide = |err: f64, reference: &Reference| {
        let cell = cell_from(&roundoff_reps(41, &values, 16, err), reference);
        let gate = Gate::from_cell(&cell_from(&roundoff_reps(42, &values, 16, err), reference), "pilot", 1.0);
        decision(&unbiasedness(&cell, reference, Bias::Unbiased, Some(&gate), DEFAULT_TOLERANCE)).clone()
    };
    let precise = with_se(0.002);
    let off = decide(0.02, &precise);
    assert_eq!((off.verdict.as_str(), off.spread), ("biased", Spread::ZeroVariance), "{off:?}");
    // A t against the reference's error, not the infinite statistic of an exact comparison.
    assert!(off.statistic.is_finite() && off.reason.contains("stored reference"), "{off:?}");
    let ok = decide(0.0005, &precise);
    assert_eq!(ok.verdict, "pass", "{ok:?}");
    let noisy = decide(0.0005, &with_se(0.02));
    assert_eq!(noisy.verdict, "inconclusive", "{noisy:?}");
    assert!(noisy.reason.contains("the reference's error resolves"), "{}", noisy.reason);
}

/// A mixed cell behind a gate: half its integrals sampled, half without spread. Integrals whose
/// repetitions differ by rounding errors only are not t-tested on them (before, a mean two ulps off
/// the reference over a spread of one ulp read t = 40 and flagged a correct estimator); an
/// integral without spread that lies off the reference is not evidence by itself (a rare value
/// that the cell and its gate missed looks the same): it is left untested, and the note counts it.
#[test]
fn integrals_without_spread_in_a_mixed_cell_are_not_t_tested_on_rounding_errors() {
    let reference = exact(&[[1.0; 3]; 8]);
    let mixed = |seed: u64, off: f64| -> Vec<Vec<[f64; 3]>> {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(seed + 100);
        normal_reps(seed, 8, 256, 1.0, 0.05)
            .into_iter()
            .map(|mut rep| {
                for (i, v) in rep.iter_mut().enumerate().skip(4) {
                    // One to three ulps above 1, evenly: a round-off spread with a round-off bias.
                    let ulps = [0; 3].map(|_| 1.0 + f64::EPSILON * rng.gen_range(1..=3) as f64);
                    *v = if i == 7 { [1.0 + off; 3] } else { ulps };
                }
                rep
            })
            .collect()
    };
    let decide = |off: f64| {
        let gate = Gate::from_cell(&cell_from(&mixed(52, off), &reference), "pilot", 1.0);
        unbiasedness(&cell_from(&mixed(51, off), &reference), &reference, Bias::Unbiased, Some(&gate), 0.01)
    };
    let rows = decide(0.0);
    let d = decision(&rows);
    assert_eq!((d.verdict.as_str(), d.spread), ("pass", Spread::Mixed), "{d:?}");
    // 9 channels with a round-off spread and 3 exact ones (in the reference's bound: agreements).
    assert_eq!(rows[0].untested, 9, "{:?}", rows[0]);
    assert!(!d.reason.contains("without spread"), "{}", d.reason);
    let rows = decide(0.005);
    let d = decision(&rows);
    assert_ne!(d.verdict, "biased", "{d:?}");
    assert_eq!(rows[0].untested, 12, "{:?}", rows[0]);
    assert!(d.reason.contains("3 of 12 integral-channels without spread lie off the reference"), "{}", d.reason);
}
