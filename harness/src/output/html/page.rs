//! An experiment's `index.html`: the run's metadata and a table of contents, every figure of the
//! plots folder with a section per test bed (its figures, per-pixel maps and cells), then the
//! claims with their verdicts and intervals, fits and speed-ups, the tests summarised (verdict
//! counts, the rows against their claim and the inconclusive ones), what did not run, and links to
//! every result file.

use super::markup::{badge, count_badges, esc, interval_cell, page, table, url, verdict_class, Cell};
use super::pixel_maps::PixelGroup;
use crate::analysis::TestRow;
use crate::output::plot::label_of;
use crate::output::report::digest::{self, FigureFiles};
use crate::output::report::{interval, opt, relative_path, shorten, sig, tables};
use crate::output::RunReport;
use std::fmt::Write as _;
use std::path::Path;

/// Test rows listed per kind (against the claim, inconclusive); the rest are in tests.csv.
const TEST_ROWS: usize = 200;
/// Reasons of skipped pairs listed.
const SKIP_REASONS: usize = 50;
/// Notes longer than this are folded.
const NOTE_CHARS: usize = 200;

/// Where the page is and what it links to.
pub struct Context<'a> {
    /// The plots folder (the page's own).
    pub plots_dir: &'a Path,
    /// The results folder of the run.
    pub results_dir: &'a Path,
    /// The figures to show.
    pub figures: &'a [FigureFiles],
    /// The per-pixel maps.
    pub maps: &'a [PixelGroup],
}

/// An estimator's id with its paper label.
pub(super) fn label(report: &RunReport, id: &str) -> String {
    match label_of(report, id) {
        l if l == id => id.to_string(),
        l => format!("{id} ({l})"),
    }
}

/// An estimator's cell: its label linking to its page under the plots root's `estimators/` when it
/// has cells in this run (the root index writes a page for each), else its label.
pub(super) fn estimator_cell(report: &RunReport, id: &str) -> Cell {
    if report.rows.iter().any(|r| r.estimator == id) {
        Cell::html(super::estimators::link_from_experiment(id, &label(report, id)))
    } else {
        Cell::text(&label(report, id))
    }
}

fn link(ctx: &Context<'_>, file: &Path, text: &str) -> String {
    format!("<a href=\"{}\">{}</a>", url(&relative_path(ctx.plots_dir, file)), esc(text))
}

/// `name` in the results folder, or summary.json when the run did not write it.
fn table_link(ctx: &Context<'_>, name: &str) -> String {
    let file = [name, "summary.json"].into_iter().map(|n| ctx.results_dir.join(n)).find(|p| p.is_file());
    match file {
        Some(f) => link(ctx, &f, &f.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()),
        None => esc(name),
    }
}

/// The page's HTML: a table of contents at the top, then the figures (with a section per test bed),
/// then the long tables (claims, fits, tests), what did not run and the files.
pub fn render(report: &RunReport, ctx: &Context<'_>) -> crate::error::Result<String> {
    let m = &report.meta;
    let mut b = format!("<h1>{}</h1>\n", esc(&m.experiment));
    let _ = writeln!(
        b,
        "<p class=\"muted\">A run of mcbench: the claims, fits and tests it judged, every figure it drew and the files it \
         wrote. The summary in markdown: <a href=\"report.md\">report.md</a>. Click a table's header to sort it.</p>"
    );
    meta(&mut b, report, ctx);
    let mut rest = String::new();
    let sections = super::groups::figures(&mut rest, report, ctx)?;
    claims(&mut rest, report, ctx);
    fits(&mut rest, report);
    tests(&mut rest, report, ctx);
    skipped(&mut rest, report);
    files(&mut rest, ctx);
    b.push_str(&super::contents::render(report, ctx.figures.len(), &sections));
    b.push_str(&rest);
    b.push_str(&super::index::embed(&super::Overview::of(report, ctx.figures.len()))?);
    let mut nav = vec![("../index.html".to_string(), "all experiments".to_string())];
    for (id, text) in [("figures", "figures"), ("claims", "claims"), ("fits", "fits"), ("tests", "tests")] {
        nav.push((format!("#{id}"), text.to_string()));
    }
    nav.extend(sections);
    nav.extend([("#skipped".to_string(), "skipped".to_string()), ("#files".to_string(), "files".to_string())]);
    Ok(page(&format!("mcbench: {}", m.experiment), &nav, &b))
}

fn meta(b: &mut String, report: &RunReport, ctx: &Context<'_>) {
    let m = &report.meta;
    let cpu = digest::estimator_cpu_seconds(&report.rows);
    let items = [
        ("mode", format!("{} ({} repetitions)", m.mode, m.reps)),
        ("seed", m.seed.to_string()),
        ("commit", format!("{} (mcbench {})", m.git_commit, m.version)),
        ("threads", m.threads.to_string()),
        ("cpu", m.cpu.clone()),
        ("wall time", format!("{} s", sig(m.wall_seconds, 4))),
        ("CPU time in the estimators", format!("{} s (summed over cells from summary.csv)", sig(cpu, 4))),
        ("run id", m.run_id.clone()),
        (
            "reproducible",
            if m.reproducible { "yes: the same seed gives the same results" } else { "no (time budgets)" }.into(),
        ),
    ];
    let _ = writeln!(
        b,
        "<details class=\"run\"><summary>{} mode, {} repetitions, seed {}, {} s of wall time: the run's details</summary>",
        esc(&m.mode),
        m.reps,
        m.seed,
        sig(m.wall_seconds, 3)
    );
    b.push_str("<dl class=\"meta\">\n");
    for (k, v) in items {
        let _ = writeln!(b, "<dt>{}</dt><dd>{}</dd>", esc(k), esc(&v));
    }
    let folder = relative_path(ctx.plots_dir, ctx.results_dir);
    let _ = writeln!(b, "<dt>results folder</dt><dd>{}</dd>", link(ctx, ctx.results_dir, &folder));
    b.push_str("</dl></details>\n");
    if !m.notes.is_empty() {
        let n = m.notes.len();
        let _ = writeln!(
            b,
            "<details><summary>{n} note{} (references, corrections)</summary><ul>",
            if n == 1 { "" } else { "s" }
        );
        m.notes.iter().for_each(|n| {
            let _ = writeln!(b, "<li>{}</li>", esc(n));
        });
        b.push_str("</ul></details>\n");
    }
}

fn claims(b: &mut String, report: &RunReport, ctx: &Context<'_>) {
    b.push_str(&format!("<h2 id=\"claims\">{}</h2>\n", crate::wording::claims_heading(&report.paper)));
    if report.paper.is_empty() {
        b.push_str("<p class=\"muted\">No claims for this experiment.</p>\n");
        return;
    }
    let counts = count_badges(&digest::claim_counts(&report.paper));
    let _ = writeln!(b, "<p>{counts} &nbsp; every claim as CSV: {}</p>", table_link(ctx, tables::CLAIMS_CSV));
    let rows = report
        .paper
        .iter()
        .map(|c| {
            let note = if c.reason.is_empty() || c.note.contains(&c.reason) {
                c.note.clone()
            } else {
                format!("{}. {}", c.reason, c.note)
            };
            let cells = vec![
                Cell::text(&c.claim),
                Cell::text(&c.testbed),
                Cell::num(&opt(c.paper_value)),
                Cell::num(&if c.p_value.is_some() && c.our_value == c.p_value { "-".into() } else { opt(c.our_value) }),
                interval_cell(&interval(c.interval), c.interval),
                Cell::num(&c.p_value.map_or_else(|| "-".to_string(), |p| format!("{p:.2e}"))),
                Cell::html(badge(c.verdict().as_str())),
                Cell::text(&crate::output::report::join_present(&[c.pair.as_str(), c.regime.as_str()])),
                Cell::html(note_html(&note)),
            ];
            (verdict_class(c.verdict().as_str()), cells)
        })
        .collect();
    let header =
        ["claim", "testbed", "paper", "ours", "95% interval", "p-value", "verdict", "pair; cost regime", "note"];
    b.push_str(&table(&header, rows));
}

/// A note: whole when short, else its start with the rest folded away.
fn note_html(note: &str) -> String {
    if note.chars().count() <= NOTE_CHARS {
        esc(note)
    } else {
        format!("<details><summary>{}</summary>{}</details>", esc(&shorten(note, NOTE_CHARS / 2)), esc(note))
    }
}

fn fits(b: &mut String, report: &RunReport) {
    b.push_str("<h2 id=\"fits\">Convergence fits and speed-ups</h2>\n");
    if report.fits.is_empty() {
        b.push_str("<p class=\"muted\">No fits (a fit needs 3 budgets with RMSE &gt; 0).</p>\n");
    } else {
        let rows = report
            .fits
            .iter()
            .map(|f| {
                let right = f.describe(crate::analysis::SlopeRange::Right);
                let exact = f.outcome == crate::analysis::SlopeOutcome::Exact;
                let cells = vec![
                    Cell::text(&format!("{} / {}", f.testbed, f.variant)),
                    estimator_cell(report, &f.estimator),
                    Cell::num(&if exact { "exact at every budget".into() } else { format!("{:.3}", f.slope) }),
                    Cell::num(&if exact {
                        "-".into()
                    } else {
                        format!("[{:.3}, {:.3}]", f.slope_ci_low, f.slope_ci_high)
                    }),
                    Cell::num(&if exact { "-".into() } else { format!("{:.4}", f.r2) }),
                    Cell::num(&if exact { "-".into() } else { right }),
                    Cell::text(&f.budgets.iter().map(u64::to_string).collect::<Vec<_>>().join(", ")),
                ];
                (String::new(), cells)
            })
            .collect();
        let header = ["testbed / variant", "estimator", "slope", "95% CI", "r2", "right-end slope [95% CI]", "budgets"];
        b.push_str(&table(&header, rows));
    }
    if !report.speedups.is_empty() {
        let rows = report
            .speedups
            .iter()
            .map(|s| {
                let unbounded = s.outcome == crate::analysis::SpeedUpOutcome::Unbounded;
                let measured = crate::plan::cost_model::Regime::Measured;
                let cells = vec![
                    Cell::text(&format!("{} / {}", s.testbed, s.variant)),
                    estimator_cell(report, &s.estimator),
                    Cell::text(&s.baseline),
                    Cell::num(&s.budget.to_string()),
                    Cell::num(&if unbounded { "unbounded".into() } else { sig(s.sample_ratio, 4) }),
                    Cell::num(&sig(s.overhead, 4)),
                    if unbounded {
                        Cell::num(&s.describe(measured))
                    } else {
                        interval_cell(
                            &format!(
                                "{} [{}, {}]",
                                s.describe(measured),
                                sig(s.speedup_ci_low, 3),
                                sig(s.speedup_ci_high, 3)
                            ),
                            Some([s.speedup_ci_low, s.speedup_ci_high]),
                        )
                    },
                    Cell::num(&s.describe(crate::plan::cost_model::Regime::Renderer)),
                ];
                (String::new(), cells)
            })
            .collect();
        let header = [
            "testbed / variant",
            "estimator",
            "baseline",
            "budget",
            "sample ratio",
            "overhead (CPU)",
            "speed-up (CPU) [95% CI]",
            "speed-up (renderer)",
        ];
        b.push_str("<h3>Speed-ups against the baseline</h3>\n");
        b.push_str(&table(&header, rows));
    }
}

fn test_table(report: &RunReport, rows: &[&TestRow]) -> String {
    let rows = rows
        .iter()
        .take(TEST_ROWS)
        .map(|t| {
            let class = if digest::is_failing(t) { "v-fail".to_string() } else { verdict_class(&t.verdict) };
            let p = if t.p_value.is_nan() { "-".to_string() } else { format!("{:.2e}", t.p_value) };
            let cells = vec![
                Cell::text(&format!("{} / {}", t.testbed, t.variant)),
                estimator_cell(report, &t.estimator),
                Cell::text(&t.test),
                Cell::num(&t.budget.to_string()),
                Cell::num(&sig(t.statistic, 4)),
                Cell::num(&p),
                Cell::html(badge(&t.verdict)),
                Cell::text(&t.claim),
                Cell::num(&sig(t.detectable_rel_bias, 3)),
                Cell::html(note_html(&t.reason)),
            ];
            (class, cells)
        })
        .collect();
    let header = [
        "testbed / variant",
        "estimator",
        "test",
        "budget",
        "statistic",
        "p-value",
        "verdict",
        "claim",
        "detectable rel. bias",
        "reason",
    ];
    table(&header, rows)
}

fn tests(b: &mut String, report: &RunReport, ctx: &Context<'_>) {
    b.push_str("<h2 id=\"tests\">Unbiasedness tests</h2>\n");
    if report.tests.is_empty() {
        b.push_str("<p class=\"muted\">No tests in this run.</p>\n");
        return;
    }
    let (failing, inconclusive) = digest::attention(&report.tests);
    let deciding = digest::deciding(&report.tests);
    let counts = count_badges(&digest::tally(deciding.iter().map(|t| t.verdict.as_str()), &digest::TEST_VERDICTS));
    let _ = writeln!(
        b,
        "<p>Deciding rows (the <code>combined</code> test where there is one): {counts} &nbsp; {} against the estimator's \
         claim. Every row: {}</p>",
        failing.len(),
        table_link(ctx, tables::TESTS_CSV)
    );
    let rows = digest::test_counts(&report.tests)
        .into_iter()
        .map(|c| {
            (
                String::new(),
                vec![
                    Cell::text(&c.test),
                    Cell::html(count_badges(&c.verdicts)),
                    Cell::num(&c.agrees.to_string()),
                    Cell::num(&c.total.to_string()),
                ],
            )
        })
        .collect();
    b.push_str(&table(&["test", "verdicts", "agree with the claim", "rows"], rows));
    let _ = writeln!(b, "<h3>Against the claim ({})</h3>", failing.len());
    if failing.is_empty() {
        b.push_str("<p class=\"muted\">None.</p>\n");
    } else {
        b.push_str(&test_table(report, &failing));
    }
    let listed = if inconclusive.len() > TEST_ROWS { format!("; the first {TEST_ROWS} listed") } else { String::new() };
    let _ = writeln!(b, "<details><summary>Inconclusive ({}{listed})</summary>", inconclusive.len());
    b.push_str(&test_table(report, &inconclusive));
    b.push_str("</details>\n");
}

fn skipped(b: &mut String, report: &RunReport) {
    b.push_str("<h2 id=\"skipped\">What did not run</h2>\n");
    let mut reasons = digest::tally(report.skipped.iter().map(|s| s.reason.as_str()), &[]);
    reasons.sort_by(|a, b| b.1.cmp(&a.1).then_with(|| a.0.cmp(&b.0)));
    if reasons.is_empty() && report.unavailable.is_empty() {
        b.push_str("<p class=\"muted\">Every pair ran.</p>\n");
        return;
    }
    if !reasons.is_empty() {
        let _ = writeln!(
            b,
            "<p>{} pairs skipped, by reason (every pair in summary.json, <code>skipped</code>):</p>",
            report.skipped.len()
        );
        let rows = reasons
            .iter()
            .take(SKIP_REASONS)
            .map(|(r, n)| (String::new(), vec![Cell::text(r), Cell::num(&n.to_string())]))
            .collect();
        b.push_str(&table(&["reason", "pairs"], rows));
    }
    if !report.unavailable.is_empty() {
        let _ = writeln!(b, "<p>Not registered in this build: {}</p>", esc(&report.unavailable.join(", ")));
    }
}

fn files(b: &mut String, ctx: &Context<'_>) {
    b.push_str("<h2 id=\"files\">Files</h2>\n");
    let rows: Vec<_> = digest::result_files(ctx.results_dir)
        .into_iter()
        .map(|(p, bytes)| {
            let name = p.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
            (String::new(), vec![Cell::html(link(ctx, &p, &name)), Cell::num(&digest::human_bytes(bytes))])
        })
        .collect();
    if rows.is_empty() {
        b.push_str("<p class=\"muted\">The results folder has no files to link.</p>\n");
    } else {
        b.push_str("<p>The result files of the run (the book's chapter on outputs describes their columns):</p>\n");
        b.push_str(&table(&["file", "size"], rows));
    }
}
