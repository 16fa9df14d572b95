use super::*;
use crate::analysis::metrics::SummaryRow;
use crate::analysis::{fits, SpeedUp, TestRow};
use crate::output::{Claim, Diagnostic, Meta};
use crate::plan::Skipped;

pub(crate) fn row(estimator: &str, budget: u64, rmse: f64, seconds: f64) -> SummaryRow {
    let variance = rmse * rmse * 0.9;
    SummaryRow {
        testbed: "gradient-plane".into(),
        variant: "default".into(),
        estimator: estimator.into(),
        budget_kind: "samples".into(),
        budget,
        reps: 16,
        integrals: 64,
        rmse,
        mse: rmse * rmse,
        variance,
        bias: 1e-4,
        bias_se: 2e-4,
        samples: budget as f64,
        fetches: 0.0,
        rays: budget as f64,
        seconds,
        efficiency: Some(1.0 / (variance * seconds)),
        fom: None,
        rel_rmse: rmse / 0.7,
        reference_var: 0.0,
        cheap_fetches: 0.0,
        seconds_median: seconds,
        efficiency_mse: Some(1.0 / (rmse * rmse * seconds)),
        p_err: 0.0,
        p_eff: None,
        estimator_id: String::new(),
        params: String::new(),
        testbed_params: String::new(),
        mse_se: rmse * rmse * 0.3,
        cpu_seconds: seconds,
        efficiency_wall: Some(1.0 / (variance * seconds)),
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
    }
}

/// A small report: two estimators x three budgets on one test bed, with fits, tests and claims.
pub fn synthetic_report() -> RunReport {
    let mut rows = Vec::new();
    for (k, budget) in [4u64, 16, 64].into_iter().enumerate() {
        let b = budget as f64;
        rows.push(row("is0_cv0", budget, 0.2 * b.powf(-0.5) * (1.0 + 0.01 * k as f64), 2e-7 * b));
        rows.push(row("is1_cv2", budget, 0.15 * b.powf(-0.9), 3.5e-7 * b));
    }
    let fits = fits(&rows);
    let test = |estimator: &str, p: f64, verdict: &str| TestRow {
        testbed: "gradient-plane".into(),
        variant: "default".into(),
        estimator: estimator.into(),
        test: "holm_t".into(),
        budget: 64,
        statistic: 2.5,
        p_value: p,
        verdict: verdict.into(),
        alpha: 1e-3,
        detectable_rel_bias: 3.2e-3,
        claim: "unbiased".into(),
        agrees: verdict == "pass",
        untested: 0,
        ..Default::default()
    };
    RunReport {
        meta: Meta {
            experiment: "surface-smc".into(),
            seed: 7,
            git_commit: "abc1234".into(),
            threads: 2,
            cpu: "Test CPU".into(),
            version: "0.1.0".into(),
            mode: "quick".into(),
            reps: 16,
            wall_seconds: 12.5,
            notes: vec!["exact reference".into()],
            run_id: "r1".into(),
            reproducible: true,
            cost_model: Default::default(),
        },
        fits,
        tests: vec![test("is0_cv0", 0.42, "pass"), test("is1_cv2", 3.1e-7, "biased")],
        paper: vec![Claim {
            testbed: "gradient-plane".into(),
            claim: "is1_cv2 slope about -0.94 (paper 001 Fig. 4)".into(),
            paper_value: Some(-0.94),
            our_value: Some(-0.9),
            held: Some(true),
            note: "within the CI".into(),
            ..Default::default()
        }],
        speedups: vec![SpeedUp {
            testbed: "gradient-plane".into(),
            variant: "default".into(),
            estimator: "is1_cv2".into(),
            baseline: "is0_cv0".into(),
            budget: 64,
            sample_ratio: 20.0,
            overhead: 1.75,
            speedup: 11.43,
            overhead_wall: 2.0,
            speedup_wall: 10.0,
            log_se: 0.1,
            speedup_ci_low: 11.43 / 0.2f64.exp(),
            speedup_ci_high: 11.43 * 0.2f64.exp(),
            overhead_renderer: 1.25,
            speedup_renderer: 16.0,
            speedup_ray_limit: 20.0,
            break_even_ray_ns: 0.0,
            cpu_seconds: Some((1.75e-6, 1e-6)),
            rays: Some((64.0, 64.0)),
            reps: 16,
            speedup_renderer_ci_low: 16.0 / 0.2f64.exp(),
            speedup_renderer_ci_high: 16.0 * 0.2f64.exp(),
            interval_method: "delta method".into(),
            outcome: Default::default(),
        }],
        skipped: vec![Skipped {
            testbed: "gradient-plane".into(),
            variant: "default".into(),
            estimator: "ratio_tracking".into(),
            reason: "needs a medium".into(),
        }],
        unavailable: vec!["brdf_is1_cv2".into()],
        rows,
        labels: vec![("is0_cv0".into(), "MCMC (independent MC)".into()), ("is1_cv2".into(), "IS1 + CV2".into())],
        diagnostics: vec![Diagnostic {
            testbed: "gradient-plane".into(),
            variant: "default".into(),
            estimator: "is1_cv2".into(),
            budget: 64,
            name: "cache_bytes".into(),
            mean: 4096.0,
        }],
        counts: Vec::new(),
        beds: Vec::new(),
    }
}

fn read(dir: &Path, name: &str) -> String {
    std::fs::read_to_string(dir.join(name)).unwrap()
}

#[test]
fn one_figure_of_panels_per_test_bed_as_svg_and_png() {
    let report = synthetic_report();
    assert_eq!(report.fits.len(), 2);
    let dir = tempfile::TempDir::new().unwrap();
    let files = write_plots(&report, dir.path()).unwrap();
    // RMSE, efficiency and RMSE against time, and the speed-up against the cost of a ray: one file.
    assert_eq!(files.len(), 2, "{files:?}");
    let stem = plot_stem("gradient-plane", "default", PlotKind::Convergence);
    let bytes = std::fs::read(dir.path().join(format!("{stem}.png"))).unwrap();
    assert!(bytes.len() > 1000 && bytes.starts_with(b"\x89PNG\r\n\x1a\n"));
    let svg = read(dir.path(), &format!("{stem}.svg"));
    for panel in
        ["(a) RMSE vs samples per pixel (spp)", "(b) efficiency vs", "(c) RMSE vs CPU time", "(d) speed-up over"]
    {
        assert!(svg.contains(panel), "{panel} missing");
    }
    // One legend entry per estimator, with its slope; the guides have their own.
    assert_eq!(svg.matches("MCMC (independent MC): slope -0.4").count(), 1, "legend text missing or repeated");
    assert!(svg.contains("IS1 + CV2: slope -0.90 ["), "legend slope missing");
    assert!(!svg.contains("right end"), "three budgets: the right end is the whole fit");
    assert!(svg.contains("slope -1/2 (guide)") && svg.contains("break-even (speed-up 1)"));
    // Panel (b) draws the MSE-based efficiency dashed beside the variance-based one, and says so.
    assert!(svg.contains("(b) solid: 1/(variance × CPU s)") && svg.contains("(b) dashed: 1/(MSE × CPU s)"));
    let panels =
        super::testbed::figure(&report, "gradient-plane", "default", &["is0_cv0", "is1_cv2"], &DisplayNames::NONE)
            .expect("figure");
    let b = &panels.panels[1];
    let dashed: Vec<_> = b.series.iter().filter(|s| s.line == Line::Dashed).collect();
    assert_eq!(dashed.len(), 2, "one MSE-based twin per estimator");
    let mse: Vec<f64> =
        report.rows.iter().filter(|r| r.estimator == "is1_cv2").filter_map(|r| r.efficiency_mse).collect();
    let twin = dashed.iter().find(|s| s.style == 1).expect("is1_cv2's twin");
    assert_eq!(twin.points.iter().map(|p| p.1).collect::<Vec<_>>(), mse, "its points are efficiency_mse");
    // No band columns in the rows: no band, no note.
    assert!(!svg.contains("Shaded: 90%"));
    let names: Vec<String> =
        std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().all(|n| !n.starts_with('.')), "no temporary files left: {names:?}");
}

/// The test bed under a display name of its own.
static BED: mcbench_core::entry::TestBedEntry = mcbench_core::entry::TestBedEntry {
    params: mcbench_core::ParamSpec::NONE.display("gradient plane (a test)"),
    ..mcbench_papers::testbeds::gradient_plane::ENTRY
};

#[test]
fn bands_display_names_and_the_same_bytes_twice() {
    let mut report = synthetic_report();
    report.rows.push(row("is0_cv0", 256, 0.2 / 16.0, 2e-7 * 256.0));
    report.rows.push(row("is1_cv2", 256, 0.15 * 256f64.powf(-0.9), 3.5e-7 * 256.0));
    report.fits = fits(&report.rows);
    for r in &mut report.rows {
        (r.rmse_lo, r.rmse_hi) = (Some(r.rmse * 0.8), Some(r.rmse * 1.25));
    }
    // Only `is1_cv2` is registered: `is0_cv0` is shown by its label.
    let (estimators, testbeds) = ([&mcbench_papers::surface_smc::is1_cv2::ENTRY], [&BED]);
    let names = DisplayNames::new(&estimators, &testbeds);
    let (a, b) = (tempfile::TempDir::new().unwrap(), tempfile::TempDir::new().unwrap());
    let files = write_plots_named(&report, a.path(), &names).unwrap();
    write_plots_named(&report, b.path(), &names).unwrap();
    for f in &files {
        let name = f.file_name().unwrap();
        assert_eq!(std::fs::read(f).unwrap(), std::fs::read(b.path().join(name)).unwrap(), "{name:?} differs");
    }
    let svg = read(a.path(), "gradient-plane_default_convergence.svg");
    assert!(svg.contains("surface-smc: gradient plane (a test)"), "the test bed's display name");
    assert!(svg.contains("IS1 CV2 (SMC cache): slope"), "the estimator's display name");
    assert!(svg.contains(", right end -0.90 ["), "four budgets: the slope over the last three");
    assert!(svg.contains("MCMC (independent MC): slope"), "the registered label of an estimator not registered");
    assert!(svg.contains("Shaded: 90%"), "the band's note");
    assert!(svg.contains("opacity=\"0.16\""), "a shaded band");
}

#[test]
fn empty_and_degenerate_reports_do_not_panic() {
    let dir = tempfile::TempDir::new().unwrap();
    let mut report = synthetic_report();
    report.rows.clear();
    assert!(write_plots(&report, dir.path()).unwrap().is_empty());

    // Single-point series only (a single-budget sweep): no figure is drawn.
    let mut report = synthetic_report();
    report.rows.truncate(2);
    report.speedups.clear();
    assert!(write_plots(&report, dir.path()).unwrap().is_empty());

    let mut report = synthetic_report();
    report.rows.truncate(3); // is0_cv0 at 4 and 16 spp, is1_cv2 at 4 spp only
    report.rows.push(row("nan_estimator", 4, f64::NAN, f64::NAN));
    report.rows.push(row("zero_estimator", 4, 0.0, 0.0));
    report.rows[0].efficiency = None;
    report.rows[1].rmse_lo = Some(-1.0);
    report.rows[1].rmse_hi = Some(f64::NAN);
    report.rows.push(row("inf", 8, f64::INFINITY, -1.0));
    report.fits[0].slope = f64::NAN;
    // A two-point series beside single points and undrawable values (NaN, zero, infinite,
    // negative) still makes the figure.
    let files = write_plots(&report, dir.path()).unwrap();
    assert_eq!(files.len(), 2, "{files:?}");
}

#[test]
fn names_are_sanitised() {
    assert_eq!(sanitize("a b/c.d-e_f"), "a_b_c_d-e_f");
    assert_eq!(sanitize(""), "_");
    assert_eq!(plot_stem("checker direct", "occl/uded", PlotKind::Convergence), "checker_direct_occl_uded_convergence");
}

#[test]
fn svgs_drop_default_opacities_and_round_font_sizes() {
    let svg = r##"<text x="1" font-size="8.064516129032258" opacity="1" fill="#000">a</text><rect opacity="0.16"/>"##;
    assert_eq!(compact_svg(svg), r##"<text x="1" font-size="8.06" fill="#000">a</text><rect opacity="0.16"/>"##);
}
