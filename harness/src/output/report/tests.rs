use super::*;
use crate::analysis::TestRow;
use crate::output::plot::{plot_stem, tests::synthetic_report, write_plots, PlotKind};
use crate::verdict::Verdict;

#[test]
fn report_summarises_every_table_and_shows_every_plot() {
    let report = synthetic_report();
    let dir = tempfile::TempDir::new().unwrap();
    let (plots_dir, results_dir) = (dir.path().join("plots"), dir.path().join("results"));
    std::fs::create_dir_all(&results_dir).unwrap();
    std::fs::write(results_dir.join("summary.csv"), "x").unwrap();
    std::fs::write(results_dir.join("tests.csv"), "x").unwrap();
    std::fs::write(results_dir.join("summary.json"), "x").unwrap();
    let plots = write_plots(&report, &plots_dir).unwrap();
    let path = write_report(&report, &plots, &plots_dir, &results_dir).unwrap();
    assert_eq!(path, plots_dir.join("report.md"));
    let md = std::fs::read_to_string(&path).unwrap();
    for h in [
        "# mcbench report: surface-smc",
        "[index.html](index.html)",
        "## Paper claims",
        "Verdicts: 1 held (of 1)",
        "[summary.json](../results/summary.json)",
        "paper value",
        "## Convergence fits",
        "95% CI",
        "## Speed-ups",
        "sample ratio",
        "## Unbiasedness tests",
        "| holm_t | 1    | 1      | 0",
        "### Against the claim (1)",
        "[tests.csv](../results/tests.csv)",
        "## Skipped pairs",
        "needs a medium",
        "## Unavailable estimators",
        "brdf_is1_cv2",
        "## Results",
        "| gradient-plane / default | 2",
        "4 .. 64 (3 budgets)",
        "[summary.csv](../results/summary.csv)",
        "**CPU time in the estimators**",
    ] {
        assert!(md.contains(h), "missing {h:?} in\n{md}");
    }
    for kind in PlotKind::ALL {
        let stem = plot_stem("gradient-plane", "default", kind);
        assert!(md.contains(&format!("![{stem}]({stem}.png)")), "missing plot {stem}");
        assert!(md.contains(&format!("([SVG]({stem}.svg))")));
    }
    assert!(md.contains("### gradient-plane / default") && !md.contains("### Other plots"), "{md}");
}

#[test]
fn long_tables_are_cut_to_the_rows_that_need_attention() {
    let mut report = synthetic_report();
    let claim = report.paper[0].clone();
    report.paper = (0..500)
        .map(|i| {
            let verdict = if i % 50 == 7 { Verdict::NotHeld } else { Verdict::Held };
            let held = verdict.held();
            Claim { claim: format!("claim {i} {}", "x".repeat(400)), verdict: Some(verdict), held, ..claim.clone() }
        })
        .collect();
    let test = report.tests[0].clone();
    report.tests = (0..3000)
        .map(|i| {
            let verdict = if i % 1000 == 3 { "biased" } else { "inconclusive" };
            TestRow {
                test: "combined".into(),
                estimator: format!("e{i}"),
                verdict: verdict.into(),
                agrees: false,
                ..test.clone()
            }
        })
        .collect();
    let dir = tempfile::TempDir::new().unwrap();
    let md = render_report(&report, &[], dir.path(), dir.path());
    assert!(md.len() < 100_000, "{} bytes", md.len());
    assert!(md.contains("Verdicts: 490 held, 10 not held (of 500)"), "{md}");
    assert!(md.contains("claim 7 ") && !md.contains("claim 8 "), "only the claims that need attention");
    assert!(md.contains("### Against the claim (3)") && md.contains("### Inconclusive (2997)"));
    assert!(md.contains("2982 more inconclusive rows"), "{md}");
}

#[test]
fn empty_or_nan_reports_do_not_panic() {
    let dir = tempfile::TempDir::new().unwrap();
    let mut report = synthetic_report();
    report.rows.clear();
    report.diagnostics.clear();
    report.fits.clear();
    report.paper[0].held = None;
    report.paper[0].our_value = None;
    let md = render_report(&report, &[], dir.path(), dir.path());
    assert!(md.contains("No result rows.") && md.contains("not measured") && md.contains("No plots."));

    let mut report = synthetic_report();
    for r in &mut report.rows {
        (r.rmse, r.variance, r.bias, r.seconds, r.efficiency) = (f64::NAN, f64::NAN, f64::INFINITY, 0.0, None);
    }
    report.tests[0].p_value = f64::NAN;
    report.speedups.clear();
    let plots = write_plots(&report, dir.path()).unwrap();
    assert!(plots.is_empty());
    let path = write_report(&report, &plots, dir.path(), dir.path()).unwrap();
    let md = std::fs::read_to_string(path).unwrap();
    assert!(md.contains("| - "), "{md}");
    // A plot not named after a group still gets embedded.
    let md = render_report(&report, &[dir.path().join("extra.png")], dir.path(), dir.path());
    assert!(md.contains("![extra](extra.png)") && !md.contains("### Other plots"), "{md}");
}
