//! Unit tests of [`super`].

use super::*;
use crate::verdict::Verdict;

fn spec(extra: &str, kind: &str) -> ClaimSpec {
    let text = format!(
        "kind = '{kind}'\n{extra}testbed = 'gradient-plane/default'\nestimator = 'is1_cv2'\nvalue = -0.94\ntext = 't'"
    );
    toml::from_str(&text).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn slope_claims_are_judged_on_the_range_they_name() {
    let mut report = crate::output::plot::tests::synthetic_report();
    let f = report.fits.iter_mut().find(|f| f.estimator == "is1_cv2").expect("fit");
    (f.slope, f.slope_ci_low, f.slope_ci_high) = (-0.8, -0.85, -0.75);
    (f.slope_right, f.slope_right_ci_low, f.slope_right_ci_high) = (-0.93, -0.97, -0.89);
    let whole = spec("", "slope").judge(&report);
    assert_eq!((whole.held, whole.our_value), (Some(false), Some(-0.8)), "{whole:?}");
    assert!(whole.note.contains("whole-range fit") && whole.note.contains("right-end slope -0.930"), "{whole:?}");
    assert_eq!(whole.interval, Some([-0.85, -0.75]));
    let right = spec("range = 'right'\n", "slope").judge(&report);
    assert_eq!((right.held, right.our_value), (Some(true), Some(-0.93)), "{right:?}");
    assert!(right.note.contains("right-end fit"), "{right:?}");
    // slope_below -0.94: the right end's interval holds it (inconclusive), the whole range's
    // lies above it (not held).
    let straddles = spec("range = 'right'\n", "slope_below").judge(&report);
    assert_eq!((straddles.held, straddles.verdict()), (None, Verdict::Inconclusive), "{straddles:?}");
    assert_eq!(spec("range = \"whole\"\n", "slope_below").judge(&report).verdict(), Verdict::NotHeld);
    // An interval wider than the tolerance holds the slope but cannot confirm it.
    let f = report.fits.iter_mut().find(|f| f.estimator == "is1_cv2").expect("fit");
    (f.slope_right_ci_low, f.slope_right_ci_high) = (-1.1, -0.8);
    let wide = spec("range = 'right'\n", "slope").judge(&report);
    assert_eq!((wide.held, wide.verdict()), (None, Verdict::Inconclusive), "{wide:?}");
    assert!(wide.reason.contains("wider than"), "{}", wide.reason);
    // No right-end slope (too few budgets): not measured, not failed.
    let f = report.fits.iter_mut().find(|f| f.estimator == "is1_cv2").expect("fit");
    f.slope_right = f64::NAN;
    let none = spec("range = 'right'\n", "slope").judge(&report);
    assert_eq!(none.held, None, "{none:?}");
    // Unknown ranges are refused.
    let bad = "kind = 'slope'\nrange = 'left'\ntestbed = 'a/b'\nestimator = 'e'\nvalue = -0.5\ntext = 't'";
    assert!(toml::from_str::<ClaimSpec>(bad).is_err());
}

#[test]
fn speedup_claims_are_judged_on_their_interval_in_their_regime() {
    let report = crate::output::plot::tests::synthetic_report();
    let judge = |value: f64, extra: &str| {
        let text = format!(
            "kind = 'speedup'\n{extra}testbed = 'gradient-plane/default'\nestimator = 'is1_cv2'\nvalue = {value}\ntext = 't'"
        );
        toml::from_str::<ClaimSpec>(&text).unwrap_or_else(|e| panic!("{e}")).judge(&report)
    };
    // Our CPU speed-up 11.43 with ln-scale SE 0.1 at 16 repetitions (t quantile 2.131): [9.24, 14.15] against half the paper's factor.
    let held = judge(10.0, "");
    assert_eq!(
        (held.verdict, held.held, held.regime.as_str()),
        (Some(Verdict::Held), Some(true), "measured"),
        "{held:?}"
    );
    assert_eq!(held.pair, "is1_cv2 vs is0_cv0");
    let [lo, hi] = held.interval.expect("interval");
    assert!((lo - 9.236).abs() < 1e-3 && (hi - 14.145).abs() < 1e-3, "{lo} {hi}");
    let straddles = judge(20.0, "");
    assert_eq!((straddles.verdict, straddles.held), (Some(Verdict::Inconclusive), None), "{straddles:?}");
    assert!(straddles.reason.contains("repetitions would decide"), "{}", straddles.reason);
    assert_eq!(judge(40.0, "").verdict, Some(Verdict::NotHeld));
    // In the renderer regime the same pair is 16x: [12.93, 19.80] clears half of 20.
    let renderer = judge(20.0, "regime = 'renderer'\n");
    assert_eq!((renderer.verdict, renderer.our_value), (Some(Verdict::Held), Some(16.0)), "{renderer:?}");
    assert!(renderer.note.contains("limit 20.000"), "{}", renderer.note);
    // A pair the run has no speed-up for is not measured, not failed.
    let missing = judge(2.0, "baseline = 'no_such_estimator'\n");
    assert_eq!((missing.verdict(), missing.held), (Verdict::NotMeasured, None), "{missing:?}");
    assert!(toml::from_str::<ClaimSpec>(
        "kind = 'speedup'\nregime = 'gpu'\ntestbed = 'a/b'\nestimator = 'e'\nvalue = 2.0\ntext = 't'"
    )
    .is_err());
}

/// Claims on an estimator that is exact (its error round-off) are not judged on numbers made of
/// rounding errors: a slope claim is inconclusive (no slope), a speed-up over the baseline is
/// unbounded (held), and a ratio with the exact cell is zero or unbounded.
#[test]
fn claims_on_an_exact_estimator_are_not_judged_on_round_off() {
    let mut report = crate::output::plot::tests::synthetic_report();
    let f = report.fits.iter_mut().find(|f| f.estimator == "is1_cv2").expect("fit");
    (f.slope, f.slope_ci_low, f.slope_ci_high) = (f64::NAN, f64::NAN, f64::NAN);
    f.outcome = crate::analysis::SlopeOutcome::Exact;
    let slope = spec("", "slope").judge(&report);
    assert_eq!((slope.verdict(), slope.held, slope.our_value), (Verdict::Inconclusive, None, None), "{slope:?}");
    assert!(slope.reason.starts_with("exact at every budget"), "{}", slope.reason);
    let s = &mut report.speedups[0];
    (s.speedup, s.speedup_renderer, s.sample_ratio) = (f64::INFINITY, f64::INFINITY, f64::INFINITY);
    s.outcome = crate::analysis::SpeedUpOutcome::Unbounded;
    let text = "kind = 'speedup'\ntestbed = 'gradient-plane/default'\nestimator = 'is1_cv2'\nvalue = 1e6\ntext = 't'";
    let speedup = toml::from_str::<ClaimSpec>(text).expect("parses").judge(&report);
    assert_eq!(
        (speedup.verdict, speedup.held, speedup.our_value),
        (Some(Verdict::Held), Some(true), None),
        "{speedup:?}"
    );
    assert!(speedup.reason.contains("unbounded"), "{}", speedup.reason);
    // RMSE of is1_cv2 over is0_cv0 at 64 with is1_cv2 exact there: zero, below 1.
    for r in report.rows.iter_mut().filter(|r| r.estimator == "is1_cv2") {
        r.rmse_roundoff = r.rmse;
    }
    let spec = |above: bool| crate::analysis::claims::RatioSpec {
        tb: ("gradient-plane", "default"),
        estimator: "is1_cv2",
        baseline: "is0_cv0",
        budget: 64,
        metric: crate::analysis::claims::RatioMetric::Rmse,
        threshold: 1.0,
        above,
        paper: None,
    };
    let below = crate::analysis::claims::ratio_claim(&report, &spec(false), "lower error", "");
    assert_eq!((below.verdict, below.our_value), (Some(Verdict::Held), None), "{below:?}");
    assert!(below.reason.starts_with("exact: the ratio is zero"), "{}", below.reason);
    assert_eq!(crate::analysis::claims::ratio_claim(&report, &spec(true), "", "").verdict, Some(Verdict::NotHeld));
}
