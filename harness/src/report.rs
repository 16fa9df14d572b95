//! The run's `report.md` (SPEC §8): metadata, the paper's claims beside ours, convergence fits,
//! speed-ups, unbiasedness tests, what did not run, the summary rows and every plot.

use crate::error::Result;
use crate::metrics::SummaryRow;
use crate::output::{write_atomic, Diagnostic, RunReport};
use crate::plot::{budget_axis_label, label_of, plot_stem, PlotKind};
use std::fmt::Write as _;
use std::path::{Component, Path, PathBuf};

/// Formats `x` with `digits` significant digits: fixed notation for magnitudes in
/// [1e-3, 10^(digits + 1)), scientific (`1.235e-5`) otherwise; `-` for NaN, `inf` / `-inf`.
pub fn sig(x: f64, digits: usize) -> String {
    if x.is_nan() {
        return "-".to_string();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.to_string();
    }
    if x == 0.0 {
        return "0".to_string();
    }
    let d = digits.max(1);
    let sci = format!("{:.*e}", d - 1, x);
    let exp: i32 = sci.rsplit('e').next().and_then(|e| e.parse().ok()).unwrap_or(0);
    if exp < -3 || exp > d as i32 {
        sci
    } else {
        format!("{:.*}", (d as i32 - 1 - exp).max(0) as usize, x)
    }
}

/// `sig(x, 4)` for a present value, `-` for a missing one.
fn opt(x: Option<f64>) -> String {
    x.map(|v| sig(v, 4)).unwrap_or_else(|| "-".to_string())
}

/// A cost: whole numbers as integers, others with 4 significant digits.
fn count(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e12 {
        format!("{}", x as i64)
    } else {
        sig(x, 4)
    }
}

fn cell(text: &str) -> String {
    text.replace('|', "\\|").replace(['\n', '\r'], " ")
}

/// A GitHub-flavoured markdown table with padded columns (readable as plain text too). Rows
/// shorter than the header are padded with empty cells; `|` in cells is escaped.
pub fn markdown_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let ncol = header.len().max(rows.iter().map(Vec::len).max().unwrap_or(0));
    let grid: Vec<Vec<String>> = std::iter::once(header.iter().map(|h| cell(h)).collect::<Vec<_>>())
        .chain(rows.iter().map(|r| r.iter().map(|c| cell(c)).collect()))
        .map(|mut r| {
            r.resize(ncol, String::new());
            r
        })
        .collect();
    let widths: Vec<usize> =
        (0..ncol).map(|c| grid.iter().map(|r| r[c].chars().count()).max().unwrap_or(0).max(3)).collect();
    let line = |r: &[String]| {
        let cells: Vec<String> =
            r.iter().zip(&widths).map(|(c, w)| format!("{c}{}", " ".repeat(w - c.chars().count()))).collect();
        format!("| {} |\n", cells.join(" | "))
    };
    let mut out = line(&grid[0]);
    out.push_str(&format!("|{}|\n", widths.iter().map(|w| "-".repeat(w + 2)).collect::<Vec<_>>().join("|")));
    for r in &grid[1..] {
        out.push_str(&line(r));
    }
    out
}

/// `to` relative to the folder `from`, with `/` separators (for links in markdown).
fn relative(from: &Path, to: &Path) -> String {
    let rel = match to.strip_prefix(from) {
        Ok(r) => r.to_path_buf(),
        Err(_) => {
            let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
            let (f, t) = (abs(from), abs(to));
            let (fc, tc): (Vec<Component>, Vec<Component>) = (f.components().collect(), t.components().collect());
            let common = fc.iter().zip(&tc).take_while(|(a, b)| a == b).count();
            let mut r = PathBuf::new();
            (common..fc.len()).for_each(|_| r.push(".."));
            tc[common..].iter().for_each(|c| r.push(c));
            r
        }
    };
    let s = rel.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect::<Vec<_>>().join("/");
    if s.contains([' ', '(', ')', '<', '>']) {
        format!("<{s}>")
    } else {
        s
    }
}

fn name(report: &RunReport, id: &str) -> String {
    match label_of(report, id) {
        l if l == id => id.to_string(),
        l => format!("{id}: {l}"),
    }
}

fn yes_no(b: bool) -> String {
    if b { "yes" } else { "no" }.to_string()
}

fn section(out: &mut String, title: &str, header: &[&str], rows: Vec<Vec<String>>, empty: &str) {
    let _ = write!(out, "\n## {title}\n\n");
    if rows.is_empty() {
        let _ = writeln!(out, "{empty}");
    } else {
        out.push_str(&markdown_table(header, &rows));
    }
}

/// The text of `report.md` (see [`write_report`]): metadata, then the tables of paper claims,
/// fits, speed-ups, unbiasedness tests, skipped pairs and unavailable estimators, then per
/// (test bed, variant) the summary rows, the estimators' diagnostics and the plots.
pub fn render_report(report: &RunReport, plots: &[PathBuf], plots_dir: &Path, results_dir: &Path) -> String {
    let m = &report.meta;
    let mut out = format!("# mcbench report: {}\n\n", m.experiment);
    let _ = writeln!(out, "- **mode**: {} ({} repetitions)", m.mode, m.reps);
    let _ = writeln!(out, "- **seed**: {}", m.seed);
    let _ = writeln!(out, "- **commit**: {} (mcbench {})", m.git_commit, m.version);
    let _ = writeln!(out, "- **threads**: {}; **cpu**: {}", m.threads, m.cpu);
    let _ = writeln!(out, "- **wall time**: {} s", sig(m.wall_seconds, 4));
    let files: Vec<String> = ["summary.csv", "summary.json", "integrals.csv", "integrals.csv.gz"]
        .iter()
        .filter(|f| results_dir.join(f).is_file())
        .map(|f| format!("[{f}]({})", relative(plots_dir, &results_dir.join(f))))
        .collect();
    if !files.is_empty() {
        let _ = writeln!(out, "- **result files**: {}", files.join(", "));
    }
    let _ = writeln!(out, "- **notes**:{}", if m.notes.is_empty() { " none" } else { "" });
    m.notes.iter().for_each(|n| {
        let _ = writeln!(out, "  - {n}");
    });

    let claims = report.paper.iter().map(|c| {
        let interval = c.interval.map(|[lo, hi]| format!("[{}, {}]", sig(lo, 4), sig(hi, 4))).unwrap_or_default();
        let note = if c.reason.is_empty() { c.note.clone() } else { format!("{}. {}", c.reason, c.note) };
        vec![
            c.testbed.clone(),
            c.claim.clone(),
            opt(c.paper_value),
            opt(c.our_value),
            interval,
            c.pair.clone(),
            c.regime.clone(),
            c.verdict().to_string(),
            note,
        ]
    });
    let header =
        ["testbed", "claim", "paper value", "our value", "95% interval", "pair", "cost regime", "verdict", "note"];
    section(&mut out, "Paper claims", &header, claims.collect(), "No paper claims for this experiment.");

    let fits = report.fits.iter().map(|f| {
        let budgets: Vec<String> = f.budgets.iter().map(u64::to_string).collect();
        vec![
            f.testbed.clone(),
            f.variant.clone(),
            name(report, &f.estimator),
            format!("{:.3}", f.slope),
            format!("[{:.3}, {:.3}]", f.slope_ci_low, f.slope_ci_high),
            format!("{:.4}", f.r2),
            budgets.join(", "),
            if f.slope_right.is_finite() { format!("{:.3}", f.slope_right) } else { "-".into() },
            if f.slope_right.is_finite() {
                format!("[{:.3}, {:.3}]", f.slope_right_ci_low, f.slope_right_ci_high)
            } else {
                "-".into()
            },
            if f.method.is_empty() { "ols".into() } else { f.method.clone() },
        ]
    });
    let header = [
        "testbed",
        "variant",
        "estimator",
        "slope",
        "95% CI",
        "r2",
        "budgets",
        "right-end slope (last 3 budgets)",
        "right-end 95% CI",
        "fit",
    ];
    section(&mut out, "Convergence fits", &header, fits.collect(), "No fits (a fit needs 3 budgets with RMSE > 0).");

    let speedups = report.speedups.iter().map(|s| {
        let (sr, ov, su) = (sig(s.sample_ratio, 4), sig(s.overhead, 4), sig(s.speedup, 4));
        vec![
            s.testbed.clone(),
            s.variant.clone(),
            name(report, &s.estimator),
            s.baseline.clone(),
            s.budget.to_string(),
            sr,
            ov,
            su,
            format!("[{}, {}]", sig(s.speedup_ci_low, 4), sig(s.speedup_ci_high, 4)),
            sig(s.overhead_renderer, 4),
            sig(s.speedup_renderer, 4),
            sig(s.speedup_ray_limit, 4),
            sig(s.break_even_ray_ns, 4),
            sig(s.overhead_wall, 4),
            sig(s.speedup_wall, 4),
        ]
    });
    let header = [
        "testbed",
        "variant",
        "estimator",
        "baseline",
        "budget",
        "sample ratio",
        "overhead (CPU)",
        "speed-up (CPU)",
        "95% CI",
        "overhead (renderer)",
        "speed-up (renderer)",
        "limit (costly rays)",
        "break-even ray ns",
        "overhead (wall)",
        "speed-up (wall)",
    ];
    section(&mut out, "Speed-ups", &header, speedups.collect(), "No speed-ups computed.");

    let tests = report.tests.iter().map(|t| {
        vec![
            format!("{} / {}", t.testbed, t.variant),
            name(report, &t.estimator),
            t.test.clone(),
            t.budget.to_string(),
            sig(t.statistic, 4),
            if t.p_value.is_nan() { "-".to_string() } else { format!("{:.2e}", t.p_value) },
            t.verdict.clone(),
            sig(t.detectable_rel_bias, 3),
            t.claim.clone(),
            yes_no(t.agrees),
        ]
    });
    let header = [
        "testbed",
        "estimator",
        "test",
        "budget",
        "statistic",
        "p-value",
        "verdict",
        "detectable rel. bias",
        "claim",
        "agrees",
    ];
    section(&mut out, "Unbiasedness tests", &header, tests.collect(), "No tests in this run.");

    let skipped = report
        .skipped
        .iter()
        .map(|s| vec![s.testbed.clone(), s.variant.clone(), s.estimator.clone(), s.reason.clone()]);
    let header = ["testbed", "variant", "estimator", "reason"];
    section(&mut out, "Skipped pairs", &header, skipped.collect(), "None.");
    let unavailable = report.unavailable.iter().map(|u| vec![u.clone(), "not registered in this build".to_string()]);
    section(&mut out, "Unavailable estimators", &["estimator", "reason"], unavailable.collect(), "None.");

    let mut used = vec![false; plots.len()];
    out.push_str("\n## Results\n");
    let mut groups: Vec<(&str, &str)> = Vec::new();
    let keys = report.rows.iter().map(|r| (&r.testbed, &r.variant));
    for (t, v) in keys.chain(report.diagnostics.iter().map(|d| (&d.testbed, &d.variant))) {
        if !groups.contains(&(t.as_str(), v.as_str())) {
            groups.push((t, v));
        }
    }
    if groups.is_empty() {
        out.push_str("\nNo result rows.\n");
    }
    for (testbed, variant) in groups {
        let rows: Vec<&SummaryRow> =
            report.rows.iter().filter(|r| r.testbed == testbed && r.variant == variant).collect();
        results_table(&mut out, report, testbed, variant, &rows);
        diagnostics_table(&mut out, report, testbed, variant);
        let stems = PlotKind::ALL.iter().map(|k| plot_stem(testbed, variant, *k));
        for stem in stems.chain([crate::plot::ray_cost::stem(testbed, variant)]) {
            let png = format!("{stem}.png");
            if let Some(i) = plots.iter().position(|p| p.file_name().is_some_and(|n| n.to_string_lossy() == png)) {
                used[i] = true;
                embed(&mut out, &plots[i], plots, &mut used, plots_dir);
            }
        }
    }
    let rest: Vec<usize> = (0..plots.len()).filter(|&i| !used[i] && is_ext(&plots[i], "png")).collect();
    let rest_svg: Vec<usize> = (0..plots.len()).filter(|&i| !used[i] && is_ext(&plots[i], "svg")).collect();
    if !rest.is_empty() || !rest_svg.is_empty() {
        out.push_str("\n## Other plots\n");
        for i in rest.into_iter().chain(rest_svg) {
            if !used[i] {
                used[i] = true;
                embed(&mut out, &plots[i], plots, &mut used, plots_dir);
            }
        }
    }
    out
}

fn is_ext(p: &Path, ext: &str) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Embeds one plot, with a link to its SVG twin when there is one.
fn embed(out: &mut String, plot: &Path, plots: &[PathBuf], used: &mut [bool], plots_dir: &Path) {
    let alt = plot.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let _ = write!(out, "\n![{alt}]({})", relative(plots_dir, plot));
    if is_ext(plot, "png") {
        if let Some(j) = plots.iter().position(|q| is_ext(q, "svg") && q.with_extension("png") == plot) {
            used[j] = true;
            let _ = write!(out, "\n([SVG]({}))", relative(plots_dir, &plots[j]));
        }
    }
    out.push('\n');
}

/// The estimators' diagnostics of one group, one column per diagnostic name.
fn diagnostics_table(out: &mut String, report: &RunReport, testbed: &str, variant: &str) {
    let diags: Vec<&Diagnostic> =
        report.diagnostics.iter().filter(|d| d.testbed == testbed && d.variant == variant).collect();
    let (mut names, mut keys): (Vec<&str>, Vec<(&str, u64)>) = (Vec::new(), Vec::new());
    for d in &diags {
        if !names.contains(&d.name.as_str()) {
            names.push(&d.name);
        }
        if !keys.contains(&(d.estimator.as_str(), d.budget)) {
            keys.push((&d.estimator, d.budget));
        }
    }
    if diags.is_empty() {
        return;
    }
    let header: Vec<&str> = ["estimator", "budget"].into_iter().chain(names.iter().copied()).collect();
    let rows: Vec<Vec<String>> = keys
        .iter()
        .map(|&(e, b)| {
            let values = names.iter().map(|n| {
                let d = diags.iter().find(|d| d.estimator == e && d.budget == b && d.name == *n);
                d.map(|d| count(d.mean)).unwrap_or_else(|| "-".to_string())
            });
            [name(report, e), b.to_string()].into_iter().chain(values).collect()
        })
        .collect();
    out.push_str("\nEstimator diagnostics (mean per estimate):\n\n");
    out.push_str(&markdown_table(&header, &rows));
}

fn results_table(out: &mut String, report: &RunReport, testbed: &str, variant: &str, rows: &[&SummaryRow]) {
    let kind = rows.first().map(|r| r.budget_kind.as_str()).unwrap_or("samples");
    let _ = write!(out, "\n### {testbed} / {variant}\n\n");
    if rows.is_empty() {
        out.push_str("No result rows.\n");
        return;
    }
    let _ = write!(out, "Budget: {}.\n\n", budget_axis_label(kind));
    let fetches = rows.iter().any(|r| r.fetches > 0.0);
    let mut header = vec!["estimator", "budget", "rmse", "variance", "bias ± se", "samples"];
    if fetches {
        header.push("fetches");
    }
    header.extend(["seconds (wall)", "seconds (CPU)", "efficiency"]);
    if fetches {
        header.push("FoM");
    }
    let table: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            let mut v = vec![
                name(report, &r.estimator),
                r.budget.to_string(),
                sig(r.rmse, 4),
                sig(r.variance, 4),
                format!("{} ± {}", sig(r.bias, 4), sig(r.bias_se, 4)),
                count(r.samples),
            ];
            if fetches {
                v.push(count(r.fetches));
            }
            v.extend([sig(r.seconds, 4), sig(r.cpu_seconds, 4), opt(r.efficiency)]);
            if fetches {
                v.push(opt(r.fom));
            }
            v
        })
        .collect();
    out.push_str(&markdown_table(&header, &table));
}

/// Writes `plots_dir/report.md` (atomically) showing every table of the run and every plot in
/// `plots` (linked relative to `plots_dir`); `results_dir` holds the result files it links to.
pub fn write_report(report: &RunReport, plots: &[PathBuf], plots_dir: &Path, results_dir: &Path) -> Result<PathBuf> {
    let path = plots_dir.join("report.md");
    write_atomic(&path, render_report(report, plots, plots_dir, results_dir).as_bytes())?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::{tests::synthetic_report, write_plots};

    #[test]
    fn sig_formats() {
        assert_eq!(sig(0.012345678, 4), "0.01235");
        assert_eq!(sig(1.23456e-5, 4), "1.235e-5");
        assert_eq!(sig(9.99996, 4), "10.00");
        assert_eq!(sig(12345.0, 4), "12345");
        assert_eq!(sig(1.5e8, 4), "1.500e8");
        assert_eq!(sig(-2.0, 3), "-2.00");
        assert_eq!(sig(0.0, 4), "0");
        assert_eq!(sig(f64::NAN, 4), "-");
    }

    #[test]
    fn tables_are_aligned_and_escaped() {
        let t = markdown_table(&["a", "long header"], &[vec!["x|y".into()], vec!["1".into(), "2".into()]]);
        let lines: Vec<&str> = t.lines().collect();
        assert_eq!(lines.len(), 4);
        assert!(lines.iter().all(|l| l.chars().count() == lines[0].chars().count()), "{t}");
        assert!(t.contains("x\\|y"));
        assert!(lines[1].starts_with("|---"));
    }

    #[test]
    fn report_shows_every_table_and_plot() {
        let report = synthetic_report();
        let dir = tempfile::TempDir::new().unwrap();
        let (plots_dir, results_dir) = (dir.path().join("plots"), dir.path().join("results"));
        std::fs::create_dir_all(&results_dir).unwrap();
        std::fs::write(results_dir.join("summary.csv"), "x").unwrap();
        let plots = write_plots(&report, &plots_dir).unwrap();
        let path = write_report(&report, &plots, &plots_dir, &results_dir).unwrap();
        assert_eq!(path, plots_dir.join("report.md"));
        let md = std::fs::read_to_string(&path).unwrap();
        for h in [
            "# mcbench report: surface-smc",
            "## Paper claims",
            "paper value",
            "## Convergence fits",
            "95% CI",
            "## Speed-ups",
            "sample ratio",
            "## Unbiasedness tests",
            "detectable rel. bias",
            "## Skipped pairs",
            "needs a medium",
            "## Unavailable estimators",
            "brdf_is1_cv2",
            "Estimator diagnostics (mean per estimate)",
            "| cache_bytes |",
            "| 4096        |",
            "## Results",
            "bias ± se",
            "3.10e-7",
            "[summary.csv](../results/summary.csv)",
        ] {
            assert!(md.contains(h), "missing {h:?} in\n{md}");
        }
        for kind in PlotKind::ALL {
            let stem = plot_stem("gradient-plane", "default", kind);
            assert!(md.contains(&format!("![{stem}]({stem}.png)")), "missing plot {stem}");
            assert!(md.contains(&format!("([SVG]({stem}.svg))")));
        }
        assert!(!md.contains("## Other plots"));
    }

    #[test]
    fn empty_or_nan_reports_do_not_panic() {
        let dir = tempfile::TempDir::new().unwrap();
        let mut report = synthetic_report();
        report.rows.clear();
        report.fits.clear();
        report.paper[0].held = None;
        report.paper[0].our_value = None;
        let md = render_report(&report, &[], dir.path(), dir.path());
        assert!(md.contains("No result rows.") && md.contains("not measured"));

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
        assert!(md.contains("inf ± ") && md.contains("| - "));
        // An extra plot not named after a group still gets embedded.
        let md = render_report(&report, &[dir.path().join("extra.png")], dir.path(), dir.path());
        assert!(md.contains("## Other plots") && md.contains("![extra](extra.png)"));
    }
}
