//! What a run's summary leads with, read from what the harness already knows: the claims' verdict
//! counts, the tests' verdict counts and the rows that need attention, the estimators' CPU time,
//! and the files of the run's folders (figures by listing the plots folder, result files by
//! listing the results folder). `report.md` and the HTML pages both build on it.

use crate::analysis::metrics::SummaryRow;
use crate::analysis::TestRow;
use crate::output::{Claim, Verdict};
use std::path::{Path, PathBuf};

/// Claim verdicts in the order summaries list them (any other word follows, alphabetically).
pub const CLAIM_VERDICTS: [&str; 5] = [
    Verdict::Held.as_str(),
    Verdict::NotHeld.as_str(),
    Verdict::Inconclusive.as_str(),
    Verdict::Reported.as_str(),
    Verdict::NotMeasured.as_str(),
];

/// Test verdicts in the order summaries list them (any other word follows, alphabetically).
pub const TEST_VERDICTS: [&str; 3] = ["pass", "biased", "inconclusive"];

/// Counts of `words`, in the order of `known` first, then any other word alphabetically; words
/// with no occurrence are left out.
pub fn tally<'a>(words: impl IntoIterator<Item = &'a str>, known: &[&str]) -> Vec<(String, usize)> {
    let mut counts: Vec<(String, usize)> = Vec::new();
    for w in words {
        match counts.iter_mut().find(|(k, _)| k == w) {
            Some((_, n)) => *n += 1,
            None => counts.push((w.to_string(), 1)),
        }
    }
    let rank = |w: &str| known.iter().position(|k| *k == w).unwrap_or(known.len());
    counts.sort_by(|a, b| rank(&a.0).cmp(&rank(&b.0)).then_with(|| a.0.cmp(&b.0)));
    counts
}

/// The claims' verdict counts.
pub fn claim_counts(claims: &[Claim]) -> Vec<(String, usize)> {
    tally(claims.iter().map(|c| c.verdict().as_str()), &CLAIM_VERDICTS)
}

/// Whether a claim needs a reader's attention first: it did not hold or the run could not decide.
pub fn claim_needs_attention(c: &Claim) -> bool {
    c.verdict().needs_attention()
}

/// The deciding rows of `tests`, in order: the `combined` row of a (test bed, variant, estimator,
/// budget) decides where there is one (the per-integral and pooled rows are its parts); where
/// there is none, every row of it decides.
pub fn deciding(tests: &[TestRow]) -> Vec<&TestRow> {
    let key = |t: &TestRow| (t.testbed.clone(), t.variant.clone(), t.estimator.clone(), t.budget);
    let combined: std::collections::HashSet<_> =
        tests.iter().filter(|t| t.test.starts_with("combined")).map(key).collect();
    tests.iter().filter(|t| t.test.starts_with("combined") || !combined.contains(&key(t))).collect()
}

/// A deciding row whose verdict contradicts what the estimator claims (a `biased` verdict for an
/// unbiased estimator, a `pass` for a biased control).
pub fn is_failing(row: &TestRow) -> bool {
    row.verdict != "inconclusive" && !row.agrees
}

/// A test's verdict counts over every row of that test.
#[derive(Clone, Debug, PartialEq)]
pub struct TestCount {
    /// Test name (`combined`, `holm_t`, ...).
    pub test: String,
    /// Rows per verdict ([`TEST_VERDICTS`] order).
    pub verdicts: Vec<(String, usize)>,
    /// Rows whose verdict is the one the estimator's claim expects.
    pub agrees: usize,
    /// Rows.
    pub total: usize,
}

/// Verdict counts per test name, deciding tests first, then in order of appearance.
pub fn test_counts(tests: &[TestRow]) -> Vec<TestCount> {
    let mut names: Vec<&str> = Vec::new();
    for t in tests {
        if !names.contains(&t.test.as_str()) {
            names.push(&t.test);
        }
    }
    names.sort_by_key(|n| !n.starts_with("combined"));
    names
        .into_iter()
        .map(|n| {
            let rows: Vec<&TestRow> = tests.iter().filter(|t| t.test == n).collect();
            TestCount {
                test: n.to_string(),
                verdicts: tally(rows.iter().map(|t| t.verdict.as_str()), &TEST_VERDICTS),
                agrees: rows.iter().filter(|t| t.agrees).count(),
                total: rows.len(),
            }
        })
        .collect()
}

/// The deciding rows that need attention: the failing ones ([`is_failing`]) and the inconclusive
/// ones, each in the order of `tests`.
pub fn attention(tests: &[TestRow]) -> (Vec<&TestRow>, Vec<&TestRow>) {
    let rows = deciding(tests);
    let failing = rows.iter().copied().filter(|t| is_failing(t)).collect();
    let inconclusive = rows.into_iter().filter(|t| t.verdict == "inconclusive").collect();
    (failing, inconclusive)
}

/// CPU seconds the estimators spent on the run's cells: per cell, CPU seconds per estimate of one
/// integral x repetitions x integrals, summed (timing: cells read back from a resumed run count
/// with the time they took when they ran). NaN when no row carries CPU time.
pub fn estimator_cpu_seconds(rows: &[SummaryRow]) -> f64 {
    let timed: Vec<f64> = rows
        .iter()
        .map(|r| r.metric_seconds() * r.reps as f64 * r.integrals as f64)
        .filter(|s| s.is_finite())
        .collect();
    if timed.is_empty() {
        f64::NAN
    } else {
        timed.iter().sum()
    }
}

/// The (test bed, variant) groups of a run, in order of first appearance in its rows, then its
/// diagnostics.
pub fn groups(report: &crate::output::RunReport) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    let keys = report.rows.iter().map(|r| (&r.testbed, &r.variant));
    for (t, v) in keys.chain(report.diagnostics.iter().map(|d| (&d.testbed, &d.variant))) {
        if !out.iter().any(|(a, b)| a == t && b == v) {
            out.push((t.clone(), v.clone()));
        }
    }
    out
}

/// One figure of a plots folder: its SVG and PNG files (either may be missing).
#[derive(Clone, Debug, PartialEq)]
pub struct FigureFiles {
    /// File name without extension.
    pub stem: String,
    /// The SVG file.
    pub svg: Option<PathBuf>,
    /// The PNG file.
    pub png: Option<PathBuf>,
}

impl FigureFiles {
    /// The file to show: the SVG when there is one, else the PNG.
    pub fn shown(&self) -> &Path {
        self.svg.as_deref().or(self.png.as_deref()).unwrap_or(Path::new(""))
    }
}

fn has_ext(p: &Path, ext: &str) -> bool {
    p.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// Pairs figure files (`.svg`, `.png`) by stem, sorted by stem; other files are ignored.
pub fn pair_figures(files: &[PathBuf]) -> Vec<FigureFiles> {
    let mut out: Vec<FigureFiles> = Vec::new();
    for f in files {
        let (svg, png) = (has_ext(f, "svg"), has_ext(f, "png"));
        let Some(stem) = f.file_stem().and_then(|s| s.to_str()).filter(|_| svg || png) else { continue };
        let i = match out.iter().position(|g| g.stem == stem) {
            Some(i) => i,
            None => {
                out.push(FigureFiles { stem: stem.to_string(), svg: None, png: None });
                out.len() - 1
            }
        };
        let slot = if svg { &mut out[i].svg } else { &mut out[i].png };
        *slot = Some(f.clone());
    }
    out.sort_by(|a, b| a.stem.cmp(&b.stem));
    out
}

/// The visible regular files directly in `dir` (hidden and temporary files left out), sorted by
/// name; empty when `dir` cannot be read.
pub fn list_files(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else { return Vec::new() };
    let mut out: Vec<PathBuf> = entries
        .flatten()
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter(|e| e.file_name().to_str().is_some_and(|n| !n.starts_with('.')))
        .map(|e| e.path())
        .collect();
    out.sort();
    out
}

/// The figures of a plots folder (every SVG and PNG in it, paired by stem).
pub fn figures_in(plots_dir: &Path) -> Vec<FigureFiles> {
    pair_figures(&list_files(plots_dir))
}

/// The tables and records of a results folder a reader opens (`.csv`, `.json`, `.md`, `.gz`,
/// `.txt` files directly in it), with their sizes in bytes.
pub fn result_files(results_dir: &Path) -> Vec<(PathBuf, u64)> {
    list_files(results_dir)
        .into_iter()
        .filter(|p| ["csv", "json", "md", "gz", "txt"].iter().any(|e| has_ext(p, e)))
        .map(|p| {
            let bytes = std::fs::metadata(&p).map(|m| m.len()).unwrap_or(0);
            (p, bytes)
        })
        .collect()
}

/// A byte count for people: `812 B`, `14.2 KB`, `3.1 MB`.
pub fn human_bytes(bytes: u64) -> String {
    match bytes {
        b if b < 1000 => format!("{b} B"),
        b if b < 1_000_000 => format!("{:.1} KB", b as f64 / 1e3),
        b => format!("{:.1} MB", b as f64 / 1e6),
    }
}

/// The figures whose stem starts with the group's prefix (`<testbed>_<variant>_`, sanitised as
/// figure names are), and those of no group.
pub fn figures_by_group<'a>(
    figures: &'a [FigureFiles],
    groups: &[(String, String)],
) -> (Vec<Vec<&'a FigureFiles>>, Vec<&'a FigureFiles>) {
    let prefixes: Vec<String> = groups
        .iter()
        .map(|(t, v)| format!("{}_{}_", crate::output::plot::sanitize(t), crate::output::plot::sanitize(v)))
        .collect();
    let mut by_group = vec![Vec::new(); groups.len()];
    let mut rest = Vec::new();
    for f in figures {
        // The longest matching prefix wins (a variant named like another's prefix).
        let best =
            prefixes.iter().enumerate().filter(|(_, p)| f.stem.starts_with(p.as_str())).max_by_key(|(_, p)| p.len());
        match best {
            Some((i, _)) => by_group[i].push(f),
            None => rest.push(f),
        }
    }
    (by_group, rest)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(test: &str, verdict: &str, agrees: bool, estimator: &str) -> TestRow {
        TestRow {
            testbed: "t".into(),
            variant: "v".into(),
            estimator: estimator.into(),
            test: test.into(),
            budget: 4,
            verdict: verdict.into(),
            agrees,
            ..Default::default()
        }
    }

    #[test]
    fn tallies_keep_the_known_order_then_the_rest() {
        let t = tally(["inconclusive", "held", "odd", "held", "not held"], &CLAIM_VERDICTS);
        let words: Vec<(&str, usize)> = t.iter().map(|(w, n)| (w.as_str(), *n)).collect();
        assert_eq!(words, [("held", 2), ("not held", 1), ("inconclusive", 1), ("odd", 1)]);
    }

    #[test]
    fn the_combined_row_decides_and_failing_means_against_the_claim() {
        let tests = vec![
            row("holm_t", "biased", true, "a"),
            row("pooled_t", "pass", true, "a"),
            row("combined", "biased", false, "a"),
            row("holm_t", "inconclusive", false, "b"),
            row("combined", "inconclusive", false, "b"),
            row("pooled_t", "pass", true, "c"),
        ];
        let d = deciding(&tests);
        assert_eq!(d.len(), 3, "the combined rows, and c's only row");
        let (failing, inconclusive) = attention(&tests);
        assert_eq!((failing.len(), failing[0].estimator.as_str()), (1, "a"));
        assert_eq!((inconclusive.len(), inconclusive[0].estimator.as_str()), (1, "b"));
        let counts = test_counts(&tests);
        assert_eq!(counts[0].test, "combined");
        assert_eq!((counts[0].total, counts[0].agrees), (2, 0));
        let pooled = counts.iter().find(|c| c.test == "pooled_t").expect("pooled");
        assert_eq!(pooled.verdicts, vec![("pass".to_string(), 2)]);
    }

    #[test]
    fn figures_pair_by_stem_and_group_by_prefix() {
        let files: Vec<PathBuf> = ["b_x_rmse.svg", "b_x_rmse.png", "solo.png", "report.md", "b_x-2_rmse.svg"]
            .iter()
            .map(PathBuf::from)
            .collect();
        let figs = pair_figures(&files);
        assert_eq!(figs.len(), 3);
        assert_eq!(figs[0].stem, "b_x-2_rmse");
        assert_eq!(figs[1].shown(), Path::new("b_x_rmse.svg"));
        assert_eq!(figs[2].shown(), Path::new("solo.png"));
        let groups = vec![("b".to_string(), "x".to_string()), ("b".to_string(), "x-2".to_string())];
        let (by, rest) = figures_by_group(&figs, &groups);
        assert_eq!((by[0].len(), by[1].len(), rest.len()), (1, 1, 1));
        assert_eq!(human_bytes(14_200), "14.2 KB");
    }
}
