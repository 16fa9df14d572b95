//! The book's contract chapter (`docs/src/contract.md`) against the code and against the files a
//! run writes: each list the chapter marks with `<!-- contract: NAME -->` (the fenced block after
//! the marker, comma-separated) must equal what the binary produces, so a column, a field or a
//! subcommand added, renamed or dropped without the chapter fails here.
//!
//! - `summary.csv`, `tests.csv`, `claims.csv`: the header lines of a small run through the CLI;
//!   `summary.csv` also against `mcbench::output::SUMMARY_HEADER` (the header written when a run
//!   has no rows);
//! - `integrals.csv`: `mcbench::output::integrals::COLUMNS`, and the run's header starts with them and ends
//!   with `estimator_id`;
//! - `timing columns`: `mcbench::analysis::metrics::TIMING_COLUMNS` (and `scripts/perf/timing_columns.txt`,
//!   the list the scaling script strips);
//! - `summary.json` and `summary.json meta`: the run's top-level and `meta` field names;
//! - `reference json`: the fields of a file `mcbench reference` wrote;
//! - `subcommands`: the `Commands:` of `mcbench --help`;
//! - the exit-code table: `mcbench::error`'s constants.

use std::path::Path;
use std::process::{Command, Output};

const SWEEP: &str = r#"
name = "tiny"
reps = 16
budgets = [4, 16]
[[testbeds]]
id = "gradient-plane"
params = { resolution = 4 }
[[estimators]]
id = "is0_cv0"
[[estimators]]
id = "clamped_is0_cv0"
params = { clamp = 1.5 }
[[claims]]
kind = "control_flagged"
estimator = "clamped_is0_cv0[clamp=1.5]"
"#;

fn chapter() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/src/contract.md");
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The comma-separated list in the fenced block after `<!-- contract: NAME -->`.
fn listed(chapter: &str, name: &str) -> Vec<String> {
    let marker = format!("<!-- contract: {name} -->");
    let after = chapter.split_once(&marker).unwrap_or_else(|| panic!("contract.md has no `{marker}`")).1;
    let mut lines = after.lines().skip_while(|l| l.trim().is_empty());
    let fence = lines.next().unwrap_or_default();
    assert!(fence.starts_with("```"), "`{marker}` is not followed by a fenced block: {fence}");
    let body: Vec<&str> = lines.take_while(|l| !l.starts_with("```")).collect();
    body.join(",").split(',').map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect()
}

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("the binary runs")
}

fn ok(dir: &Path, args: &[&str]) -> String {
    let o = mcbench(dir, args);
    assert!(o.status.success(), "mcbench {args:?}: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn header(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines().next().unwrap_or_default().split(',').map(str::to_string).collect()
}

/// The field names of a JSON object, sorted (the order of an object's fields carries no meaning).
fn json_keys(v: &serde_json::Value) -> Vec<String> {
    let mut keys: Vec<String> = v.as_object().expect("a JSON object").keys().cloned().collect();
    keys.sort();
    keys
}

/// A list of the chapter, sorted, for comparison with [`json_keys`].
fn sorted(mut list: Vec<String>) -> Vec<String> {
    list.sort();
    list
}

fn strs(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

#[test]
fn the_files_a_run_writes_have_the_columns_and_fields_the_chapter_lists() {
    let doc = chapter();
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("tiny.toml"), SWEEP).expect("config");
    ok(d, &["run", "--config", "tiny.toml", "--no-plots", "--integrals", "csv"]);
    let res = d.join("results/tiny");

    let summary = listed(&doc, "summary.csv");
    assert_eq!(header(&res.join("summary.csv")), summary, "summary.csv's header");
    assert_eq!(strs(mcbench::output::SUMMARY_HEADER), summary, "the header of a summary.csv without rows");
    assert_eq!(listed(&doc, "timing columns"), strs(mcbench::analysis::metrics::TIMING_COLUMNS));
    assert!(
        mcbench::analysis::metrics::TIMING_COLUMNS.iter().all(|c| summary.iter().any(|s| s == c)),
        "every timing column is a summary.csv column"
    );

    let integrals = listed(&doc, "integrals.csv");
    assert_eq!(integrals, strs(&mcbench::output::integrals::COLUMNS));
    let got = header(&res.join("integrals.csv"));
    assert_eq!(got[..integrals.len()], integrals[..], "integrals.csv's first columns");
    assert_eq!(got.last().map(String::as_str), Some("estimator_id"), "integrals.csv ends with estimator_id");

    assert_eq!(header(&res.join("tests.csv")), listed(&doc, "tests.csv"), "tests.csv's header");
    assert_eq!(header(&res.join("claims.csv")), listed(&doc, "claims.csv"), "claims.csv's header");

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(res.join("summary.json")).expect("summary.json"))
            .expect("summary.json parses");
    assert_eq!(json_keys(&json), sorted(listed(&doc, "summary.json")), "summary.json's top-level fields");
    assert_eq!(json_keys(&json["meta"]), sorted(listed(&doc, "summary.json meta")), "summary.json's meta fields");

    ok(d, &["reference", "gradient-plane", "--variant", "diffuse", "--references", "refs"]);
    let made: Vec<_> = std::fs::read_dir(d.join("refs")).expect("refs").map(|e| e.expect("entry").path()).collect();
    assert_eq!(made.len(), 1, "{made:?}");
    assert_eq!(made[0].file_name().and_then(|n| n.to_str()), Some("gradient-plane_diffuse.json"));
    let stored: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&made[0]).expect("reference")).expect("reference parses");
    assert_eq!(json_keys(&stored), sorted(listed(&doc, "reference json")), "a stored reference's fields");
    assert_eq!(json_keys(&stored["reference"]), ["kind", "std_err", "value"], "the reference's fields");
}

#[test]
fn the_subcommands_and_exit_codes_are_the_chapters() {
    let doc = chapter();
    let dir = tempfile::tempdir().expect("tempdir");
    let top = ok(dir.path(), &["--help"]);
    let subcommands: Vec<String> = top
        .lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|s| s != "help")
        .collect();
    assert_eq!(subcommands, listed(&doc, "subcommands"), "the subcommands of `mcbench --help`");

    let table = doc.split_once("### Exit codes").expect("an exit-code section").1;
    let codes: Vec<i32> = table
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .filter_map(|l| l.trim_matches('|').split('|').next().and_then(|c| c.trim().parse().ok()))
        .collect();
    use mcbench::error::{EXIT_BAD_INPUT, EXIT_BUSY, EXIT_FAILURE, EXIT_OK};
    assert_eq!(codes, [EXIT_OK, EXIT_FAILURE, EXIT_BAD_INPUT, EXIT_BUSY], "the exit-code table");
    // The table's meanings are the codes the binary gives: bad input is 2, in one line.
    let o = mcbench(dir.path(), &["run", "no-such-experiment"]);
    assert_eq!(o.status.code(), Some(EXIT_BAD_INPUT));
    assert_eq!(String::from_utf8_lossy(&o.stderr).trim_end().lines().count(), 1);
    assert!(!dir.path().join("results").exists() && !dir.path().join("plots").exists(), "bad input wrote nothing");
}

/// `scripts/perf/measure.sh` strips the timing columns it reads from `scripts/perf/timing_columns.txt`
/// before it compares runs at different thread counts: that list is the code's.
#[test]
fn the_scaling_script_strips_the_codes_timing_columns() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scripts/perf/timing_columns.txt");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let listed: Vec<String> = text.lines().map(str::trim).filter(|l| !l.is_empty()).map(str::to_string).collect();
    assert_eq!(listed, strs(mcbench::analysis::metrics::TIMING_COLUMNS), "{}", path.display());
}
