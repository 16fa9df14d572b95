//! `mcbench compare` and the baselines of `run` (book: compare.md): two runs of the same code at
//! different seeds compare as no change but for a nominal share of rows; a planted 2% bias and a
//! planted 20% variance increase read regressed; bad input is refused with exit code 2.
//!
//! The planted changes are the versions of `planted_mc` in `experiments::planted`; a run is one
//! in-process call of the CLI over a registry holding one version.

use experiments::planted::{run, BIASED, NOISY, PLAIN};
use mcbench::compare::change::{ChangeVerdict, Metric};
use mcbench::compare::{Change, Comparison};
use std::path::Path;
use std::process::{Command, Output};

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("binary runs")
}

/// Compares two folders below `dir` (through the library, as the CLI does) and reads the JSON back.
fn compare(dir: &Path, a: &str, b: &str) -> Comparison {
    let out = dir.join(format!("{a}-vs-{b}"));
    let args = mcbench::compare::command::CompareArgs {
        a: dir.join(a).to_string_lossy().into(),
        b: dir.join(b).to_string_lossy().into(),
        results: dir.join("results"),
        out: Some(out.clone()),
        margins: Default::default(),
        fail_on_regression: false,
        two_sample: None,
    };
    mcbench::compare::command::compare_command(&args).expect("compares");
    serde_json::from_slice(&std::fs::read(out.join("compare.json")).expect("compare.json")).expect("parses")
}

fn rows<'a>(c: &'a Comparison, estimator: &str, metric: Metric) -> Vec<&'a Change> {
    c.changes.iter().filter(|r| r.estimator == estimator && r.metric == metric).collect()
}

#[test]
fn same_code_reads_no_change_and_planted_bias_and_variance_read_regressed() {
    let t0 = std::time::Instant::now();
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    run(d, "a", &PLAIN, 1);
    run(d, "same", &PLAIN, 2);
    run(d, "biased", &BIASED, 2);
    run(d, "noisy", &NOISY, 2);
    run(d, "biased-paired", &BIASED, 1);

    // Same code, another seed: unpaired; of the rows that do not divide by CPU time, most read no
    // change and at most a nominal share (5%) improved or regressed. The timing rows also compare
    // the machine's load during the two runs (book: compare.md), so they are only printed.
    let same = compare(d, "a", "same");
    for r in &same.changes {
        eprintln!(
            "{} {:?} {} {:.3} [{:.3}, {:.3}] {:?}",
            r.estimator,
            r.budget,
            r.metric.name(),
            r.change,
            r.change_lo,
            r.change_hi,
            r.verdict
        );
    }
    assert!(same.changes.iter().filter(|r| r.metric != Metric::Unbiasedness).all(|r| !r.paired));
    let steady: Vec<&Change> = same.changes.iter().filter(|r| !r.metric.timing()).collect();
    let n = steady.len();
    let no_change = steady.iter().filter(|r| r.verdict == ChangeVerdict::NoChange).count();
    let flagged_steady: Vec<&&Change> =
        steady.iter().filter(|r| matches!(r.verdict, ChangeVerdict::Improved | ChangeVerdict::Regressed)).collect();
    assert!(n >= 8, "{n} rows");
    assert!(flagged_steady.len() as f64 <= (0.05 * n as f64).ceil(), "{flagged_steady:?}");
    assert!(no_change * 4 >= n * 3, "most rows read no change: {no_change} of {n}");

    // A planted 2% bias: the unbiasedness verdict turns from pass to biased.
    let biased = compare(d, "a", "biased");
    let u = rows(&biased, "planted_mc", Metric::Unbiasedness);
    assert!(
        u.iter().any(|r| r.verdict == ChangeVerdict::Regressed && r.a_verdict == "pass" && r.b_verdict == "biased"),
        "{u:?}"
    );
    assert!(rows(&biased, "is0_cv0", Metric::Unbiasedness).is_empty(), "the unchanged estimator keeps its verdict");

    // A planted 20% variance increase: the RMSE (x1.095) reads regressed.
    let noisy = compare(d, "a", "noisy");
    let rmse = rows(&noisy, "planted_mc", Metric::Rmse);
    assert!(rmse.iter().any(|r| r.verdict == ChangeVerdict::Regressed), "{rmse:?}");
    assert!(rmse.iter().all(|r| r.verdict != ChangeVerdict::Improved), "{rmse:?}");
    // --fail-on-regression: exit code 1 here, 0 where nothing regressed.
    let args = |b: &str| mcbench::compare::command::CompareArgs {
        a: d.join("a").to_string_lossy().into(),
        b: d.join(b).to_string_lossy().into(),
        results: d.join("results"),
        out: Some(d.join("fail")),
        margins: Default::default(),
        fail_on_regression: true,
        two_sample: None,
    };
    let e = mcbench::compare::command::compare_command(&args("noisy")).expect_err("a regression fails");
    assert_eq!(e.exit_code(), 1, "{e}");
    // A run against itself: every cell paired and identical, every row no change, exit code 0.
    mcbench::compare::command::compare_command(&args("a")).expect("no regression: exit 0");
    let itself: Comparison =
        serde_json::from_slice(&std::fs::read(d.join("fail/compare.json")).expect("json")).expect("parses");
    assert!(
        !itself.changes.is_empty() && itself.changes.iter().all(|r| r.verdict == ChangeVerdict::NoChange && r.paired)
    );

    // Same seed: paired, the unchanged estimator's cells are identical (exactly no change).
    let paired = compare(d, "a", "biased-paired");
    for r in rows(&paired, "is0_cv0", Metric::Rmse) {
        assert!(r.paired && r.change == 1.0 && r.change_lo == 1.0 && r.verdict == ChangeVerdict::NoChange, "{r:?}");
    }
    eprintln!("compare test: {:.1} s", t0.elapsed().as_secs_f64());
}

#[test]
fn the_binary_compares_saves_and_uses_baselines_and_refuses_bad_input() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    let config = "name = 'tiny'\nreps = 8\nbudgets = [4, 16, 64]\n[[testbeds]]\nid = 'gradient-plane'\nparams = { resolution = 4 }\n[[estimators]]\nid = 'is0_cv0'\n";
    std::fs::write(d.join("tiny.toml"), config).expect("config");
    std::fs::write(d.join("other.toml"), config.replace("resolution = 4", "resolution = 2")).expect("config");
    let run = |args: &[&str]| {
        let mut all = vec!["run", "--config", "tiny.toml", "--no-plots", "--integrals", "none"];
        all.extend_from_slice(args);
        mcbench(d, &all)
    };
    let o = run(&["--save-baseline", "before"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(d.join("results/baselines/before/tiny/summary.json").is_file());
    let o = run(&["--seed", "5", "--baseline", "before"]);
    let text = String::from_utf8_lossy(&o.stdout).to_string();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(text.contains("compare before -> latest:"), "{text}");
    assert!(d.join("results/compare/before-vs-latest/compare.html").is_file());
    // By name and by folder; the default output folder.
    let o = mcbench(d, &["compare", "before", "results"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let c: Comparison =
        serde_json::from_slice(&std::fs::read(d.join("results/compare/before-vs-results/compare.json")).expect("json"))
            .expect("parses");
    assert!(c.changes.iter().any(|r| r.metric == Metric::Rmse) && c.changes.iter().any(|r| r.metric == Metric::Slope));
    // The columns and fields are the contract chapter's.
    let csv = std::fs::read_to_string(d.join("results/compare/before-vs-results/compare.csv")).expect("csv");
    assert_eq!(csv.lines().next().map(String::from), Some(listed("compare.csv")), "compare.csv's header");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("results/compare/before-vs-results/compare.json")).expect("json"))
            .expect("parses");
    let mut keys: Vec<&str> = json.as_object().expect("an object").keys().map(String::as_str).collect();
    let doc = listed("compare.json");
    let mut want: Vec<&str> = doc.split(',').collect();
    keys.sort();
    want.sort();
    assert_eq!(keys, want, "compare.json's fields");

    // Bad input: exit 2, one line naming the field or file, nothing written.
    let bad = |args: &[&str], needle: &str| {
        let before = list(d);
        let o = mcbench(d, args);
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err} lacks {needle}");
        assert_eq!(list(d), before, "{args:?} wrote files");
    };
    bad(&["compare", "nothing-here", "results"], "A");
    bad(&["compare", "before", "results", "--margin", "0"], "--margin");
    bad(&["compare", "before", "results", "--slope-margin", "-1"], "--slope-margin");
    bad(&["run", "--config", "tiny.toml", "--baseline", "missing"], "--baseline");
    bad(&["run", "--config", "tiny.toml", "--save-baseline", "../x"], "--save-baseline");
    let o = mcbench(d, &["run", "--config", "other.toml", "--no-plots", "--results", "other"]);
    assert_eq!(o.status.code(), Some(0));
    bad(&["compare", "results/tiny", "other/tiny"], "gradient-plane");
    // A run whose test bed differs from the baseline's is refused before it writes anything.
    bad(&["run", "--config", "other.toml", "--no-plots", "--baseline", "before"], "test bed gradient-plane/default");
}

/// The list after `<!-- contract: NAME -->` in the contract chapter.
fn listed(name: &str) -> String {
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/src/contract.md"))
        .expect("chapter");
    let after = doc.split_once(&format!("<!-- contract: {name} -->")).expect("a marker").1;
    after.lines().nth(2).expect("a list").to_string()
}

/// Every path below `dir`, sorted.
fn list(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(p) = stack.pop() {
        for e in std::fs::read_dir(&p).expect("dir") {
            let path = e.expect("entry").path();
            if path.is_dir() {
                stack.push(path.clone());
            }
            out.push(path.to_string_lossy().to_string());
        }
    }
    out.sort();
    out
}
