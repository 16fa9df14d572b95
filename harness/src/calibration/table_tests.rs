//! Unit tests of the calibration table: its markdown, intervals, interpolation, notes and the
//! decision-level size check across rows.

use super::*;
use crate::analysis::TestRow;
use crate::calibration::report::markdown;
use crate::config::{EstimatorSpec, TestBedSpec};

#[test]
fn calibration_md_escapes_names_and_claims() {
    let r = Row {
        testbed: "t<script>".into(),
        variant: "v|w".into(),
        estimator: "<img src=x onerror=alert(1)>".into(),
        claim: "a & b".into(),
        ..Row::default()
    };
    let md = markdown(&[r], "seeds <b>");
    assert!(!md.contains('<') && !md.contains('>'), "{md}");
    assert!(md.contains("| t&lt;script&gt;/v\\|w | &lt;img src=x onerror=alert(1)&gt; | a &amp; b |"), "{md}");
    assert!(md.contains("seeds &lt;b&gt;"), "{md}");
}

#[test]
fn wilson_interval_matches_known_values() {
    let (lo, hi) = wilson(10, 200);
    assert!((lo - 0.0274).abs() < 5e-4 && (hi - 0.0898).abs() < 5e-4, "{lo} {hi}");
    assert_eq!(wilson(0, 0), (0.0, 1.0));
}

#[test]
fn the_size_band_takes_the_interval_into_account() {
    // 2 of 100: the interval [0.6%, 7.0%] meets [3.3%, 7.5%]; 0 of 400 does not; 30 of 100 does not.
    assert!(within_band(2, 100));
    assert!(!within_band(0, 400));
    assert!(!within_band(30, 100));
    assert!(within_band(5, 100));
}

#[test]
fn the_80_point_is_interpolated_in_log_bias() {
    let grid = [0.01, 0.1, 1.0];
    assert!((point_of(&grid, &[0.0, 0.6, 1.0], 0.8) - 10f64.powf(-0.5)).abs() < 1e-12);
    assert_eq!(point_of(&grid, &[0.9, 1.0, 1.0], 0.8), 0.01);
    assert!(point_of(&grid, &[0.0, 0.1, 0.2], 0.8).is_nan());
}

fn family() -> Family {
    Family {
        bed: TestBedSpec { id: "bed".into(), variant: Some("v".into()), params: Default::default() },
        estimator: EstimatorSpec { id: "est".into(), params: Default::default() },
        samples: 8,
        reps: 64,
        bias: Bias::Unbiased,
    }
}

/// 100 seeds whose p-values are `p(k)` (planted: `planted(k)`), firefly flagged in the first
/// `fireflies`.
fn measured(p: impl Fn(usize) -> f64, planted: impl Fn(usize) -> f64, fireflies: usize) -> Measured {
    let row = |p: f64| TestRow {
        p_value: p,
        verdict: if p < crate::analysis::UNBIASEDNESS_ALPHA { "biased" } else { "pass" }.into(),
        detectable_rel_bias: 0.01,
        ..Default::default()
    };
    let seeds = (0..100)
        .map(|k| SeedOutcome {
            null: row(p(k)),
            pooled_ran: true,
            flagged: vec![true; bias_grid().len()],
            firefly_flagged: k < fireflies,
            firefly_rel: -0.05,
            planted: row(planted(k)),
        })
        .collect();
    Measured { seeds, threshold: 1.0 }
}

/// Uniform-looking p-values: the k-th of 100 evenly spread in (0, 1).
fn even(k: usize) -> f64 {
    (k as f64 + 0.5) / 100.0
}

#[test]
fn a_row_with_low_power_against_a_firefly_rejection_says_so() {
    let low = row(&family(), &measured(even, even, 30), "est");
    assert!(
        low.note.contains("low power against a rare-large-value bug") && low.note.contains("30% of seeds"),
        "{}",
        low.note
    );
    let high = row(&family(), &measured(even, even, 90), "est");
    assert!(!high.note.contains("rare-large-value"), "{}", high.note);
}

/// The decision-level size check passes evenly spread p-values and fails a family with three of
/// 100 below alpha (P = 1.5e-4 for a sized test) or twelve below 1%; the claims say so, and that
/// the planted test fails it.
#[test]
fn the_decision_level_size_check_can_fail() {
    let sized = || row(&family(), &measured(even, |k| even(k) * 0.2, 0), "est");
    let mut rows = vec![sized(), sized()];
    judge_size(&mut rows);
    assert_eq!(rows[0].ok_size, Some(true));
    assert_eq!((rows[0].below_alpha, rows[0].below_1pct, rows[0].below_5pct, rows[0].size_seeds), (0, 1, 5, 100));
    assert_eq!(rows[0].planted_ok_size, Some(false), "{}", rows[0].planted_size_p);
    let claims = size::claims(&rows);
    assert_eq!(claims.iter().map(|c| c.held).collect::<Vec<_>>(), vec![Some(true), Some(true), Some(true)]);

    let three_at_alpha = |k: usize| if k < 3 { 1e-4 } else { even(k) };
    let twelve_at_1pct = |k: usize| if k < 12 { 0.005 } else { even(k) };
    let mut rows = vec![
        sized(),
        row(&family(), &measured(three_at_alpha, even, 0), "est"),
        row(&family(), &measured(twelve_at_1pct, even, 0), "est"),
    ];
    judge_size(&mut rows);
    assert_eq!(rows.iter().map(|r| r.ok_size).collect::<Vec<_>>(), vec![Some(true), Some(false), Some(false)]);
    assert!(rows[1].note.contains("size fails at the decision level: 3 below 0.001"), "{}", rows[1].note);
    let claims = size::claims(&rows);
    assert_eq!(claims[0].held, Some(false), "{}", claims[0].note);
    assert_eq!(claims[1].held, Some(false), "{}", claims[1].note);
    assert_eq!(claims[2].held, Some(true), "the first row's planted test fails: {}", claims[2].note);
    // The planted p-values of the other two rows are evenly spread: on them alone the planted
    // claim does not hold.
    assert_eq!(size::claims(&rows[1..])[2].held, Some(false));
}
