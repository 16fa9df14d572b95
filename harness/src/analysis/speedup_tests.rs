//! Unit tests of the speed-up.

use super::super::fits;
use super::*;

#[test]
fn speedup_uses_the_baseline_fit() {
    let mk = |est: &str, budget: u64, rmse: f64, seconds: f64| SummaryRow {
        testbed: "t".into(),
        variant: "v".into(),
        estimator: est.into(),
        budget_kind: "samples".into(),
        budget,
        reps: 2,
        integrals: 1,
        rmse,
        mse: rmse * rmse,
        variance: rmse * rmse,
        bias: 0.0,
        bias_se: 0.0,
        samples: budget as f64,
        fetches: 0.0,
        rays: 0.0,
        seconds,
        efficiency: None,
        fom: None,
        rel_rmse: 0.0,
        reference_var: 0.0,
        cheap_fetches: 0.0,
        seconds_median: seconds,
        efficiency_mse: None,
        p_err: 0.0,
        p_eff: None,
        estimator_id: String::new(),
        params: String::new(),
        testbed_params: String::new(),
        mse_se: f64::NAN,
        cpu_seconds: if est == "fast" { 0.75 * seconds } else { seconds },
        efficiency_wall: None,
        time_clock: "cpu".into(),
        shadow_rays: 0.0,
        efficiency_renderer: None,
        free_flights: 0.0,
        target_evals: 0.0,
        cache_ops: 0.0,
        rmse_display: None,
        rmse_lo: None,
        rmse_hi: None,
        rmse_roundoff: f64::NAN,
        fom_display: None,
        rep_blocks: Default::default(),
    };
    let mut rows = Vec::new();
    for b in [4u64, 16, 64] {
        rows.push(mk("base", b, 1.0 / (b as f64).sqrt(), b as f64));
        rows.push(mk("fast", b, 1.0 / b as f64, 2.0 * b as f64));
    }
    let f = fits(&rows);
    let s = speedups(&rows, &f, "base", &CostModel::default());
    // At 64 spp the fast method's RMSE 1/64 needs 4096 baseline samples: 64x; overhead 1.5x
    // in CPU time, 2x on the wall clock.
    assert_eq!(s.len(), 1);
    assert!((s[0].sample_ratio - 64.0).abs() < 1e-6 && (s[0].overhead - 1.5).abs() < 1e-12);
    assert!((s[0].speedup - 64.0 / 1.5).abs() < 1e-6);
    assert!((s[0].overhead_wall - 2.0).abs() < 1e-12 && (s[0].speedup_wall - 32.0).abs() < 1e-6);
    // Rows read from files written before CPU time: the wall clock, as then.
    rows.iter_mut().for_each(|r| r.cpu_seconds = f64::NAN);
    let s = speedups(&rows, &f, "base", &CostModel::default());
    assert!((s[0].overhead - 2.0).abs() < 1e-12 && (s[0].speedup - 32.0).abs() < 1e-6);
}

/// A method whose error at the budget is round-off has an unbounded speed-up, not a ratio of
/// the baseline's error to rounding errors; an exact baseline has none.
#[test]
fn a_speedup_over_round_off_is_unbounded() {
    let mut rows = Vec::new();
    for b in [4u64, 16, 64] {
        let mut base = crate::output::plot::tests::row("base", b, 1.0 / (b as f64).sqrt(), 1e-6 * b as f64);
        let mut exact = crate::output::plot::tests::row("exact", b, 3e-17 * b as f64, 2e-6 * b as f64);
        base.rmse_roundoff = 1e-15;
        exact.rmse_roundoff = 1e-15 * b as f64;
        rows.extend([base, exact]);
    }
    let f = fits(&rows);
    let s = speedups(&rows, &f, "base", &CostModel::default());
    assert_eq!(s.len(), 1);
    let s = &s[0];
    assert_eq!((s.estimator.as_str(), s.outcome), ("exact", SpeedUpOutcome::Unbounded), "{s:?}");
    assert!(s.speedup.is_infinite() && s.sample_ratio.is_infinite() && s.speedup_ci_low.is_infinite());
    assert!((s.overhead - 2.0).abs() < 1e-12, "the overhead is measured: {s:?}");
    assert_eq!(s.describe(Regime::Measured), "unbounded (exact)");
    assert!(s.curve().is_none());
    // Against the exact estimator as the baseline there is no speed-up.
    assert!(speedups(&rows, &f, "exact", &CostModel::default()).is_empty());
    // summary.json writes the infinities as null and keeps the outcome.
    let text = serde_json::to_string(s).expect("serialises");
    assert!(text.contains("\"speedup\":null") && text.contains("\"outcome\":\"unbounded\""), "{text}");
}
