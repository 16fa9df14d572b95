//! The run's `report.md` (book: outputs.md), a summary of at most about 100 KB: metadata and links to the
//! result files, the paper's claims beside ours, convergence fits, speed-ups, the tests' verdict
//! counts with the rows that need attention, what did not run, one line per (test bed, variant),
//! and every plot. The long tables (every test row, every claim, every cell) are CSV files in the
//! results folder ([`tables`]) that the summary links to; `index.html` beside it ([`crate::output::html`])
//! shows the same run in a browser. Every text that comes from a config, a label, a registry entry
//! or a stored file is escaped ([`md_text`]): no HTML tag of it reaches a markdown viewer.

pub mod digest;
mod format;
pub mod tables;

pub use format::{count, interval, join_present, markdown_table, md_target, md_text, opt, relative_path, shorten, sig};
pub use tables::write_tables;

use crate::error::Result;
use crate::output::plot::{budget_axis_label, label_of};
use crate::output::{write_atomic, Claim, RunReport};
use digest::FigureFiles;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Claims listed in full up to this many; beyond it, the ones that need attention.
const CLAIM_ROWS: usize = 40;
/// Longest note of a claim or reason of a test row in the summary (the CSV files hold all).
const NOTE_CHARS: usize = 240;
/// Notes of the run's metadata listed.
const NOTE_LINES: usize = 12;
/// Rows of the fits and speed-up tables.
const FIT_ROWS: usize = 60;
/// Test rows against their claim listed.
const FAILING_ROWS: usize = 40;
/// Inconclusive test rows listed.
const INCONCLUSIVE_ROWS: usize = 15;
/// Reasons of skipped pairs listed.
const SKIP_REASONS: usize = 15;
/// (test bed, variant) lines of the results table.
const GROUP_ROWS: usize = 80;

fn name(report: &RunReport, id: &str) -> String {
    match label_of(report, id) {
        l if l == id => id.to_string(),
        l => format!("{id}: {l}"),
    }
}

/// `name` in the results folder as a markdown link relative to the plots folder, or, when the run
/// did not write it (an older results folder), `summary.json`, which holds every table; plain text
/// when neither is there.
fn table_link(plots_dir: &Path, results_dir: &Path, name: &str) -> String {
    match [name, "summary.json"].into_iter().map(|n| results_dir.join(n)).find(|p| p.is_file()) {
        Some(file) => {
            let shown = file.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            format!("[{}]({})", md_text(&shown), md_target(plots_dir, &file))
        }
        None => format!("`{name}` (not in the results folder)"),
    }
}

fn counts_line(counts: &[(String, usize)]) -> String {
    counts.iter().map(|(w, n)| format!("{n} {}", md_text(w))).collect::<Vec<_>>().join(", ")
}

fn heading(out: &mut String, title: &str) {
    let _ = write!(out, "\n## {title}\n\n");
}

fn table_or(out: &mut String, header: &[&str], rows: Vec<Vec<String>>, empty: &str) {
    if rows.is_empty() {
        let _ = writeln!(out, "{empty}");
    } else {
        out.push_str(&markdown_table(header, &rows));
    }
}

fn more(out: &mut String, shown: usize, total: usize, what: &str, link: &str) {
    if total > shown {
        let _ = write!(out, "\n{} more {what}: {link}.\n", total - shown);
    }
}

/// The text of `report.md` (see [`write_report`]): `plots` are the figure files to show (the
/// plots folder's SVG and PNG files), linked relative to `plots_dir`; `results_dir` holds the
/// result files it links to.
pub fn render_report(report: &RunReport, plots: &[PathBuf], plots_dir: &Path, results_dir: &Path) -> String {
    let m = &report.meta;
    let mut out = format!("# mcbench report: {}\n\n", md_text(&m.experiment));
    out.push_str(
        "A summary of the run. [index.html](index.html) shows it in a browser with every figure (and per-pixel \
         error maps of image test beds); every row of the long tables is in the result files.\n\n",
    );
    let _ = writeln!(out, "- **mode**: {} ({} repetitions)", md_text(&m.mode), m.reps);
    let _ = writeln!(out, "- **seed**: {}", m.seed);
    let _ = writeln!(out, "- **commit**: {} (mcbench {})", md_text(&m.git_commit), md_text(&m.version));
    let _ = writeln!(out, "- **threads**: {}; **cpu**: {}", m.threads, md_text(&m.cpu));
    let cpu = digest::estimator_cpu_seconds(&report.rows);
    let _ = writeln!(
        out,
        "- **wall time**: {} s; **CPU time in the estimators**: {} s",
        sig(m.wall_seconds, 4),
        sig(cpu, 4)
    );
    let files: Vec<String> = digest::result_files(results_dir)
        .iter()
        .filter_map(|(p, _)| {
            p.file_name().map(|n| format!("[{}]({})", md_text(&n.to_string_lossy()), md_target(plots_dir, p)))
        })
        .collect();
    if !files.is_empty() {
        let _ = writeln!(out, "- **result files**: {}", files.join(", "));
    }
    let _ = writeln!(out, "- **notes**:{}", if m.notes.is_empty() { " none" } else { "" });
    m.notes.iter().take(NOTE_LINES).for_each(|n| {
        let _ = writeln!(out, "  - {}", md_text(&shorten(n, NOTE_CHARS)));
    });
    if m.notes.len() > NOTE_LINES {
        let _ = writeln!(out, "  - ... {} more in summary.json (`meta.notes`)", m.notes.len() - NOTE_LINES);
    }
    claims_section(&mut out, report, plots_dir, results_dir);
    fits_section(&mut out, report);
    speedups_section(&mut out, report);
    tests_section(&mut out, report, plots_dir, results_dir);
    skipped_section(&mut out, report, plots_dir, results_dir);
    results_section(&mut out, report, plots_dir, results_dir);
    plots_section(&mut out, report, &digest::pair_figures(plots), plots_dir);
    out
}

fn claim_row(c: &Claim) -> Vec<String> {
    let note = if c.reason.is_empty() { c.note.clone() } else { format!("{}. {}", c.reason, c.note) };
    vec![
        c.testbed.clone(),
        c.claim.clone(),
        opt(c.paper_value),
        opt(c.our_value),
        interval(c.interval),
        c.pair.clone(),
        c.regime.clone(),
        c.verdict().to_string(),
        shorten(&note, NOTE_CHARS),
    ]
}

fn claims_section(out: &mut String, report: &RunReport, plots_dir: &Path, results_dir: &Path) {
    heading(out, crate::wording::claims_heading(&report.paper));
    let claims = &report.paper;
    if claims.is_empty() {
        out.push_str("No claims for this experiment.\n");
        return;
    }
    let link = table_link(plots_dir, results_dir, tables::CLAIMS_CSV);
    let counts = counts_line(&digest::claim_counts(claims));
    let _ = write!(out, "Verdicts: {counts} (of {}). Every claim with its whole note: {link}.\n\n", claims.len());
    let shown: Vec<&Claim> = if claims.len() <= CLAIM_ROWS {
        claims.iter().collect()
    } else {
        let _ = write!(out, "The claims that did not hold or are inconclusive (up to {CLAIM_ROWS}):\n\n");
        claims.iter().filter(|c| digest::claim_needs_attention(c)).take(CLAIM_ROWS).collect()
    };
    let header =
        ["testbed", "claim", "paper value", "our value", "95% interval", "pair", "cost regime", "verdict", "note"];
    table_or(out, &header, shown.iter().map(|c| claim_row(c)).collect(), "None.");
    more(out, shown.len(), claims.len(), "claims", &link);
}

fn fits_section(out: &mut String, report: &RunReport) {
    heading(out, "Convergence fits");
    let fits = report.fits.iter().take(FIT_ROWS).map(|f| {
        let budgets: Vec<String> = f.budgets.iter().map(u64::to_string).collect();
        let right = f.slope_right.is_finite();
        let exact = f.outcome == crate::analysis::SlopeOutcome::Exact;
        vec![
            f.testbed.clone(),
            f.variant.clone(),
            name(report, &f.estimator),
            if exact { "exact at every budget".into() } else { format!("{:.3}", f.slope) },
            if exact { "-".into() } else { format!("[{:.3}, {:.3}]", f.slope_ci_low, f.slope_ci_high) },
            if exact { "-".into() } else { format!("{:.4}", f.r2) },
            budgets.join(", "),
            if right { format!("{:.3}", f.slope_right) } else { "-".into() },
            if right { format!("[{:.3}, {:.3}]", f.slope_right_ci_low, f.slope_right_ci_high) } else { "-".into() },
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
    table_or(out, &header, fits.collect(), "No fits (a fit needs 3 budgets with RMSE > 0).");
    more(out, FIT_ROWS, report.fits.len(), "fits", "summary.json (`fits`)");
}

fn speedups_section(out: &mut String, report: &RunReport) {
    heading(out, "Speed-ups");
    let rows = report.speedups.iter().take(FIT_ROWS).map(|s| {
        let unbounded = s.outcome == crate::analysis::SpeedUpOutcome::Unbounded;
        vec![
            s.testbed.clone(),
            s.variant.clone(),
            name(report, &s.estimator),
            s.baseline.clone(),
            s.budget.to_string(),
            if unbounded { "unbounded".into() } else { sig(s.sample_ratio, 4) },
            sig(s.overhead, 4),
            s.describe(crate::plan::cost_model::Regime::Measured),
            if unbounded {
                "-".into()
            } else {
                format!("[{}, {}]", sig(s.speedup_ci_low, 4), sig(s.speedup_ci_high, 4))
            },
            s.describe(crate::plan::cost_model::Regime::Renderer),
            sig(s.break_even_ray_ns, 4),
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
        "speed-up (renderer)",
        "break-even ray ns",
    ];
    table_or(out, &header, rows.collect(), "No speed-ups computed.");
    more(out, FIT_ROWS, report.speedups.len(), "speed-ups", "summary.json (`speedups`)");
}

/// The rows of a table of test rows.
pub(crate) fn test_rows(report: &RunReport, rows: &[&crate::analysis::TestRow]) -> Vec<Vec<String>> {
    rows.iter()
        .map(|t| {
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
                shorten(&t.reason, NOTE_CHARS),
            ]
        })
        .collect()
}

/// The header of [`test_rows`].
pub(crate) const TEST_ROW_HEADER: [&str; 10] = [
    "testbed",
    "estimator",
    "test",
    "budget",
    "statistic",
    "p-value",
    "verdict",
    "detectable rel. bias",
    "claim",
    "reason",
];

fn tests_section(out: &mut String, report: &RunReport, plots_dir: &Path, results_dir: &Path) {
    heading(out, "Unbiasedness tests");
    if report.tests.is_empty() {
        out.push_str("No tests in this run.\n");
        return;
    }
    let link = table_link(plots_dir, results_dir, tables::TESTS_CSV);
    let (failing, inconclusive) = digest::attention(&report.tests);
    let decided = digest::deciding(&report.tests);
    let counts = digest::tally(decided.iter().map(|t| t.verdict.as_str()), &digest::TEST_VERDICTS);
    let _ = write!(
        out,
        "Deciding rows (the `combined` test where there is one): {}; {} against the estimator's claim. Every row: {link}.\n\n",
        counts_line(&counts),
        failing.len()
    );
    let rows = digest::test_counts(&report.tests).into_iter().map(|c| {
        let n = |v: &str| c.verdicts.iter().find(|(w, _)| w == v).map_or(0, |(_, n)| *n);
        let other: usize =
            c.verdicts.iter().filter(|(w, _)| !digest::TEST_VERDICTS.contains(&w.as_str())).map(|(_, n)| n).sum();
        let cells = [n("pass"), n("biased"), n("inconclusive"), other, c.agrees, c.total];
        std::iter::once(c.test.clone()).chain(cells.iter().map(usize::to_string)).collect()
    });
    let header = ["test", "pass", "biased", "inconclusive", "other", "agrees with the claim", "rows"];
    out.push_str(&markdown_table(&header, &rows.collect::<Vec<_>>()));
    let _ = write!(out, "\n### Against the claim ({})\n\n", failing.len());
    let shown: Vec<_> = failing.iter().copied().take(FAILING_ROWS).collect();
    table_or(out, &TEST_ROW_HEADER, test_rows(report, &shown), "None.");
    more(out, shown.len(), failing.len(), "rows against the claim", &link);
    let _ = write!(out, "\n### Inconclusive ({})\n\n", inconclusive.len());
    let shown: Vec<_> = inconclusive.iter().copied().take(INCONCLUSIVE_ROWS).collect();
    table_or(out, &TEST_ROW_HEADER, test_rows(report, &shown), "None.");
    more(out, shown.len(), inconclusive.len(), "inconclusive rows", &link);
}

fn skipped_section(out: &mut String, report: &RunReport, plots_dir: &Path, results_dir: &Path) {
    heading(out, "Skipped pairs");
    let reasons = digest::tally(report.skipped.iter().map(|s| s.reason.as_str()), &[]);
    let mut reasons = reasons;
    reasons.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    if !report.skipped.is_empty() {
        let _ = write!(out, "{} pairs did not run, by reason:\n\n", report.skipped.len());
    }
    let rows = reasons.iter().take(SKIP_REASONS).map(|(r, n)| {
        let first = report.skipped.iter().find(|s| &s.reason == r).expect("a pair with this reason");
        vec![r.clone(), n.to_string(), format!("{} on {} / {}", first.estimator, first.testbed, first.variant)]
    });
    table_or(out, &["reason", "pairs", "for example"], rows.collect(), "None.");
    more(out, SKIP_REASONS, reasons.len(), "reasons", &table_link(plots_dir, results_dir, "summary.json"));
    heading(out, "Unavailable estimators");
    let unavailable = report.unavailable.iter().map(|u| vec![u.clone(), "not registered in this build".to_string()]);
    table_or(out, &["estimator", "reason"], unavailable.collect(), "None.");
}

fn results_section(out: &mut String, report: &RunReport, plots_dir: &Path, results_dir: &Path) {
    heading(out, "Results");
    let groups = digest::groups(report);
    let link = table_link(plots_dir, results_dir, "summary.csv");
    let _ = write!(
        out,
        "One line per test bed and variant; every cell (estimator x budget) is a row of {link}, the estimators' \
         diagnostics per cell are in summary.json (`diagnostics`).\n\n"
    );
    let rows = groups.iter().take(GROUP_ROWS).map(|(t, v)| {
        let rows: Vec<_> = report.query().testbed(t).variant(v).iter().collect();
        let mut estimators: Vec<&str> = rows.iter().map(|r| r.estimator.as_str()).collect();
        estimators.dedup();
        let mut budgets: Vec<u64> = rows.iter().map(|r| r.budget).collect();
        budgets.sort_unstable();
        budgets.dedup();
        let last = budgets.last().copied();
        let best = rows
            .iter()
            .filter(|r| Some(r.budget) == last && r.rmse.is_finite())
            .min_by(|a, b| a.rmse.total_cmp(&b.rmse))
            .map(|r| format!("{} ({})", sig(r.rmse, 4), name(report, &r.estimator)))
            .unwrap_or_else(|| "-".into());
        let kind = rows.first().map(|r| budget_axis_label(&r.budget_kind)).unwrap_or_default();
        let span = match (budgets.first(), last) {
            (Some(a), Some(b)) if *a != b => format!("{a} .. {b} ({} budgets)", budgets.len()),
            (Some(a), _) => a.to_string(),
            _ => "-".into(),
        };
        let distinct = estimators.iter().collect::<std::collections::BTreeSet<_>>().len();
        vec![format!("{t} / {v}"), distinct.to_string(), kind, span, rows.len().to_string(), best]
    });
    let header = ["testbed / variant", "estimators", "budget", "budgets", "cells", "lowest RMSE at the largest budget"];
    table_or(out, &header, rows.collect(), "No result rows.");
    more(out, GROUP_ROWS, groups.len(), "test beds and variants", &link);
}

fn embed(out: &mut String, f: &FigureFiles, plots_dir: &Path) {
    let shown = f.png.as_deref().unwrap_or(f.shown());
    let _ = write!(out, "\n![{}]({})", md_text(&f.stem), md_target(plots_dir, shown));
    if let (Some(svg), Some(_)) = (&f.svg, &f.png) {
        let _ = write!(out, "\n([SVG]({}))", md_target(plots_dir, svg));
    }
    out.push('\n');
}

fn plots_section(out: &mut String, report: &RunReport, figures: &[FigureFiles], plots_dir: &Path) {
    let groups = digest::groups(report);
    let (by_group, rest) = digest::figures_by_group(figures, &groups);
    heading(out, "Plots");
    if figures.is_empty() {
        out.push_str("No plots.\n");
    }
    for ((t, v), figs) in groups.iter().zip(&by_group).filter(|(_, f)| !f.is_empty()) {
        let _ = writeln!(out, "### {} / {}", md_text(t), md_text(v));
        figs.iter().for_each(|f| embed(out, f, plots_dir));
        out.push('\n');
    }
    if !rest.is_empty() {
        let title = if by_group.iter().any(|f| !f.is_empty()) { "### Other plots\n" } else { "" };
        out.push_str(title);
        rest.iter().for_each(|f| embed(out, f, plots_dir));
    }
}

/// Writes `plots_dir/report.md` (atomically): the summary of the run with every plot in `plots`
/// (linked relative to `plots_dir`); `results_dir` holds the result files it links to.
pub fn write_report(report: &RunReport, plots: &[PathBuf], plots_dir: &Path, results_dir: &Path) -> Result<PathBuf> {
    let path = plots_dir.join("report.md");
    write_atomic(&path, render_report(report, plots, plots_dir, results_dir).as_bytes())?;
    Ok(path)
}

#[cfg(test)]
mod tests;
