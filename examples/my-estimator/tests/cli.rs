//! The crate's binary is the whole mcbench command line for its plug-ins: it runs its own sweep
//! (plots, tests, claims), and its estimator passes the conformance suite every estimator goes
//! through.

use std::path::Path;
use std::process::{Command, Output};

fn run(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_my-estimator")).current_dir(dir).args(args).output().expect("runs")
}

fn text(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr)
}

#[test]
fn the_crate_runs_its_sweep_with_plots_tests_and_claims() {
    let dir = tempfile::tempdir().expect("tempdir");
    let config = concat!(env!("CARGO_MANIFEST_DIR"), "/my-sweep.toml");
    let o = run(dir.path(), &["run", "--config", config, "--threads", "2"]);
    assert!(o.status.success(), "{}", text(&o));
    let results = dir.path().join("results/my-sweep");
    let mut rows = csv::Reader::from_path(results.join("summary.csv")).expect("summary.csv");
    let ours = rows
        .records()
        .map(|r| r.expect("row"))
        .filter(|r| &r[0] == "tilted-patches" && &r[2] == "antithetic_cosine")
        .count();
    assert_eq!(ours, 5, "one row per budget");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(results.join("summary.json")).expect("json")).expect("json");
    let claims = summary["paper"].as_array().expect("claims");
    let held = |needle: &str| {
        claims.iter().find(|c| c["claim"].as_str().is_some_and(|t| t.contains(needle))).map(|c| c["held"].clone())
    };
    assert_eq!(held("converges like independent MC"), Some(serde_json::json!(true)), "{claims:?}");
    assert_eq!(held("clamped_uniform[clamp=1]"), Some(serde_json::json!(true)), "{claims:?}");
    assert!(held("4x as efficient").is_some(), "the speed-up claim is judged");
    let tests = summary["tests"].as_array().expect("tests");
    assert!(tests.iter().any(|t| t["estimator"] == "antithetic_cosine" && t["agrees"] == true));
    let plots = dir.path().join("plots/my-sweep");
    assert!(plots.join("tilted-patches_matte_convergence.svg").is_file() && plots.join("report.md").is_file());
}

#[test]
fn its_estimator_passes_the_conformance_suite_and_lists_its_parameters() {
    let dir = tempfile::tempdir().expect("tempdir");
    // No --references: the crate's own test beds have exact references.
    let o = run(dir.path(), &["conformance", "antithetic_cosine"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("antithetic_cosine: conforms"), "{}", text(&o));
    let o = run(dir.path(), &["list", "estimators", "--params"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(text(&o).contains("antithetic_cosine") && text(&o).contains("offset"), "{}", text(&o));
    let o = run(dir.path(), &["list", "testbeds"]);
    assert!(text(&o).contains("tilted-patches"), "{}", text(&o));
}
