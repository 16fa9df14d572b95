//! The Python example `examples/python/redraw.py` (polars and matplotlib) redraws the RMSE figure
//! of a small run from its summary.csv and summary.json, and refuses bad input with exit code 2
//! and one line. Where Python 3 with polars and matplotlib is missing the test prints why and
//! passes, unless `MCBENCH_REQUIRE_PYTHON=1` (CI sets it) makes that a failure.

use mcbench::config::{powers_of_four, EstimatorSpec, Mode, Sweep, TestBedSpec};
use mcbench::run::execute::{execute, ExecOptions};
use mcbench::run::runner::Silent;
use mcbench_core::params::Params;
use std::path::Path;
use std::process::Command;

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/python/redraw.py");

/// Whether the example can run here; `Err` says why not.
fn python_ready() -> Result<(), String> {
    match Command::new("python3").args(["-c", "import polars, matplotlib"]).output() {
        Ok(out) if out.status.success() => Ok(()),
        Ok(out) => Err(format!("python3 lacks polars or matplotlib: {}", String::from_utf8_lossy(&out.stderr).trim())),
        Err(e) => Err(format!("no python3: {e}")),
    }
}

/// A two-estimator run on a small gradient plane, the results of `surface-smc` in miniature.
fn small_run(dir: &Path) {
    let sweep = Sweep {
        experiment: "surface-smc".into(),
        testbeds: vec![TestBedSpec {
            id: "gradient-plane".into(),
            variant: Some("default".into()),
            params: Params::new().with("resolution", 4.0),
        }],
        estimators: ["is0_cv0", "is1_cv2"].iter().map(|id| EstimatorSpec::new(id)).collect(),
        budgets: powers_of_four(1..=3),
        reps: 4,
        seed: 7,
        mode: Mode::Quick,
        baseline: Some("is0_cv0".into()),
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    };
    let registry = experiments::registry();
    let plan = mcbench::plan::Plan::prepare(sweep, &registry).expect("valid sweep");
    let opts = ExecOptions {
        results_root: dir.join("results"),
        plots_root: dir.join("plots"),
        threads: Some(2),
        observer: &Silent,
        plots: false,
        wait: false,
        registry: &registry,
        integrals: Default::default(),
    };
    execute(&plan, None, &opts).expect("run succeeds");
}

#[test]
fn the_python_example_redraws_the_rmse_figure() {
    if let Err(why) = python_ready() {
        assert!(std::env::var("MCBENCH_REQUIRE_PYTHON").as_deref() != Ok("1"), "MCBENCH_REQUIRE_PYTHON=1: {why}");
        println!("skipped: {why}");
        return;
    }
    let dir = tempfile::tempdir().expect("tempdir");
    small_run(dir.path());
    let results = dir.path().join("results/surface-smc");
    let out = dir.path().join("rmse.png");
    let run = Command::new("python3").arg(SCRIPT).arg(&results).arg("--out").arg(&out).output().expect("python3 runs");
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let png = std::fs::read(&out).expect("the figure is written");
    assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000, "{} bytes", png.len());

    // Bad input: one line naming it, exit code 2, nothing written.
    let none = dir.path().join("none.png");
    let bad = Command::new("python3")
        .arg(SCRIPT)
        .arg(&results)
        .args(["--testbed", "no-such-bed", "--out"])
        .arg(&none)
        .output()
        .expect("python3 runs");
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(2), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(stderr.contains("--testbed") && !none.exists(), "{stderr}");
}
