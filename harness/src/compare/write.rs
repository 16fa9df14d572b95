//! A comparison's files (`compare.csv`, `compare.json`, `compare.html`, each written atomically
//! into the output folder and nowhere else) and its one-screen console summary.

use super::change::{ChangeVerdict, Metric};
use super::{Change, Comparison};
use crate::error::{HarnessError, Result};
use std::path::{Path, PathBuf};

/// The files a comparison writes.
pub const FILES: [&str; 3] = ["compare.csv", "compare.json", "compare.html"];
/// The files `--two-sample` adds.
pub const TWO_SAMPLE_FILES: [&str; 4] =
    ["two_sample.csv", "two_sample.json", "two_sample_integrals.csv", "two_sample_tiles.csv"];

/// At most this many regressed rows are listed on the console.
pub const LISTED: usize = 15;

/// The default output folder: `<results>/compare/<A>-vs-<B>`.
pub fn default_out(results: &Path, a: &str, b: &str) -> PathBuf {
    results.join("compare").join(format!("{a}-vs-{b}"))
}

/// Checks the output folder before anything is computed or written: a folder (or a path that can
/// become one), not a symbolic link.
pub fn check_out(out: &Path) -> Result<()> {
    crate::store::folder::check_own_dir("--out", out)
}

/// Writes the three files into `out` (created when absent).
pub fn write_files(out: &Path, c: &Comparison) -> Result<Vec<PathBuf>> {
    let mut csv = csv::Writer::from_writer(Vec::new());
    for row in &c.changes {
        csv.serialize(row).map_err(|e| HarnessError::write(out.join(FILES[0]), e))?;
    }
    let csv = csv.into_inner().map_err(|e| HarnessError::write(out.join(FILES[0]), e))?;
    let json = serde_json::to_vec_pretty(c).map_err(|e| HarnessError::write(out.join(FILES[1]), e))?;
    let html = super::html::page(c);
    let mut files: Vec<(&str, Vec<u8>)> = FILES.iter().copied().zip([csv, json, html.into_bytes()]).collect();
    if let Some(t) = &c.two_sample {
        let [rows, whole, per, tiles] = TWO_SAMPLE_FILES;
        let fail = |name: &str, e: String| HarnessError::write(out.join(name), e);
        files.push((rows, super::two_sample::csv_bytes(t).map_err(|e| fail(rows, e.to_string()))?));
        files.push((whole, serde_json::to_vec_pretty(t).map_err(|e| fail(whole, e.to_string()))?));
        files.push((per, super::two_sample::integrals_csv_bytes(t).map_err(|e| fail(per, e.to_string()))?));
        let cut = super::two_sample_maps::tiles(t, &super::two_sample_maps::maps(t));
        files.push((tiles, super::two_sample_maps::tiles_csv_bytes(&cut).map_err(|e| fail(tiles, e.to_string()))?));
    }
    std::fs::create_dir_all(out).map_err(|e| HarnessError::write(out, e))?;
    let mut written = Vec::new();
    for (name, bytes) in files {
        let path = out.join(name);
        crate::output::write_atomic(&path, &bytes)?;
        written.push(path);
    }
    Ok(written)
}

/// Formats a change and its interval: `x1.23 [1.10, 1.37]` for ratios, `+0.12 [+0.02, +0.22]` for
/// slope differences, `pass -> biased` for unbiasedness rows.
pub fn describe(c: &Change) -> String {
    match c.metric {
        Metric::Unbiasedness => format!("{} -> {}", c.a_verdict, c.b_verdict),
        Metric::Slope => format!("{:+.3} [{:+.3}, {:+.3}]", c.change, c.change_lo, c.change_hi),
        _ => format!("x{:.3} [{:.3}, {:.3}]", c.change, c.change_lo, c.change_hi),
    }
}

/// Where a row is: `experiment testbed/variant estimator @budget`.
pub fn place(c: &Change) -> String {
    let budget = c.budget.map(|b| format!(" @{b}")).unwrap_or_default();
    format!("{} {}/{} {}{budget}", c.experiment, c.testbed, c.variant, c.estimator)
}

/// The console summary: the counts per verdict, then the regressed rows (at most [`LISTED`]).
pub fn summary(c: &Comparison) -> String {
    let counts: Vec<String> = c.counts().iter().map(|(v, n)| format!("{n} {}", v.word())).collect();
    let mut s = format!(
        "compare {} -> {}: {} rows: {} (no change: ratios within ±{}%, slopes within ±{}, CPU-time rows x{} wider)\n",
        c.a,
        c.b,
        c.changes.len(),
        counts.join(", "),
        c.margin * 100.0,
        c.slope_margin,
        1.0 + c.time_margin
    );
    let regressed: Vec<&Change> = c.changes.iter().filter(|r| r.verdict == ChangeVerdict::Regressed).collect();
    if !regressed.is_empty() {
        s.push_str("regressed:\n");
    }
    for r in regressed.iter().take(LISTED) {
        let timing = if r.metric.timing() { " (CPU time)" } else { "" };
        s.push_str(&format!("  {} {}: {}{timing}\n", place(r), r.metric.name(), describe(r)));
    }
    if regressed.len() > LISTED {
        s.push_str(&format!("  ... and {} more in compare.csv\n", regressed.len() - LISTED));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn change(metric: Metric, verdict: ChangeVerdict) -> Change {
        Change {
            experiment: "x".into(),
            testbed: "t".into(),
            variant: "v".into(),
            estimator: "e".into(),
            budget_kind: "samples".into(),
            budget: Some(16),
            metric,
            a: 1.0,
            b: 1.3,
            change: 1.3,
            change_lo: 1.2,
            change_hi: 1.4,
            verdict,
            paired: false,
            method: "m".into(),
            a_verdict: String::new(),
            b_verdict: String::new(),
            note: String::new(),
        }
    }

    fn comparison(changes: Vec<Change>) -> Comparison {
        Comparison {
            a: "old".into(),
            a_dir: "r/old".into(),
            b: "new".into(),
            b_dir: "r/new".into(),
            margin: 0.1,
            slope_margin: 0.1,
            time_margin: 0.25,
            experiments: vec!["x".into()],
            notes: vec![],
            changes,
            two_sample: None,
        }
    }

    #[test]
    fn the_summary_counts_every_verdict_and_lists_only_regressions() {
        let c = comparison(vec![
            change(Metric::Rmse, ChangeVerdict::Regressed),
            change(Metric::Fom, ChangeVerdict::NoChange),
            change(Metric::EfficiencyMse, ChangeVerdict::Improved),
        ]);
        let s = summary(&c);
        assert!(
            s.starts_with("compare old -> new: 3 rows: 1 improved, 1 regressed, 1 no change, 0 inconclusive"),
            "{s}"
        );
        assert!(s.contains("x t/v e @16 rmse: x1.300 [1.200, 1.400]"), "{s}");
        assert_eq!(s.lines().count(), 3, "{s}");
        let many = comparison((0..LISTED + 3).map(|_| change(Metric::Rmse, ChangeVerdict::Regressed)).collect());
        assert!(summary(&many).contains("... and 3 more"));
    }

    #[test]
    fn the_files_read_back_and_nothing_else_is_written() {
        let dir = tempfile::tempdir().expect("tempdir");
        let out = dir.path().join("cmp");
        let mut slope = change(Metric::Slope, ChangeVerdict::Inconclusive);
        (slope.budget, slope.change_lo) = (None, f64::NAN);
        let c = comparison(vec![change(Metric::Rmse, ChangeVerdict::Regressed), slope]);
        write_files(&out, &c).expect("writes");
        let mut names: Vec<String> = std::fs::read_dir(&out)
            .expect("dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into())
            .collect();
        names.sort();
        assert_eq!(names, ["compare.csv", "compare.html", "compare.json"]);
        let back: Comparison =
            serde_json::from_slice(&std::fs::read(out.join("compare.json")).expect("json")).expect("parses");
        assert_eq!(back.changes.len(), 2);
        assert!(back.changes[1].change_lo.is_nan() && back.changes[1].budget.is_none());
        let mut rd = csv::Reader::from_path(out.join("compare.csv")).expect("csv");
        let rows: Vec<Change> = rd.deserialize().collect::<std::result::Result<_, _>>().expect("rows");
        assert_eq!(rows[0].verdict, ChangeVerdict::Regressed);
        assert_eq!(rows[1].metric, Metric::Slope);
    }
}
