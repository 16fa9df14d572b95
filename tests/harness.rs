//! Integration tests of the harness over its public API: a small sweep into a
//! temp dir, the result files, determinism across thread counts, resume, and the unbiasedness
//! test's teeth.

use mcbench::config::{powers_of_four, EstimatorSpec, Mode, Sweep, TestBedSpec};
use mcbench::output::integrals::IntegralsFormat;
use mcbench::run::execute::{execute, ExecOptions};
use mcbench::run::runner::Silent;
use mcbench_core::params::Params;
use std::path::Path;

mod common;
use common::deterministic_csv;

fn sweep(ids: &[&str], reps: usize) -> Sweep {
    Sweep {
        experiment: "itest".into(),
        testbeds: vec![TestBedSpec {
            id: "gradient-plane".into(),
            variant: Some("default".into()),
            params: Params::new().with("resolution", 6.0),
        }],
        estimators: ids.iter().map(|id| EstimatorSpec::new(id)).collect(),
        budgets: powers_of_four(1..=4),
        reps,
        seed: 42,
        mode: Mode::Quick,
        baseline: Some("is0_cv0".into()),
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    }
}

fn run_into(dir: &Path, sweep: Sweep, threads: usize, plots: bool) -> mcbench::run::execute::Outcome {
    run_with(dir, sweep, threads, plots, IntegralsFormat::default())
}

fn run_with(
    dir: &Path,
    sweep: Sweep,
    threads: usize,
    plots: bool,
    integrals: IntegralsFormat,
) -> mcbench::run::execute::Outcome {
    let plan = plan_of(sweep).expect("valid sweep");
    let opts = ExecOptions {
        results_root: dir.join("results"),
        plots_root: dir.join("plots"),
        threads: Some(threads),
        observer: &Silent,
        plots,
        wait: false,
        registry: registry(),
        integrals,
    };
    execute(&plan, None, &opts).expect("run succeeds")
}

#[test]
fn writes_the_contract_files_with_the_contract_columns() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = run_into(dir.path(), sweep(&["is0_cv0", "brdf_is0_cv0", "clamped_is0_cv0"], 4), 2, true);
    let res = dir.path().join("results/itest");
    for f in ["summary.csv", "integrals.csv.gz", "summary.json", "cells.store"] {
        assert!(res.join(f).is_file(), "{f} missing");
    }
    let header =
        std::fs::read_to_string(res.join("summary.csv")).expect("read").lines().next().unwrap_or_default().to_string();
    let contract = "testbed,variant,estimator,budget_kind,budget,reps,integrals,rmse,mse,variance,bias,bias_se,samples,fetches,rays,seconds,efficiency,fom";
    assert!(header.starts_with(contract), "{header}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(res.join("summary.json")).expect("read")).expect("json");
    for k in ["meta", "fits", "tests", "paper"] {
        assert!(json.get(k).is_some(), "summary.json lacks {k}");
    }
    let integrals = common::integrals_text(&res);
    assert!(
        integrals.starts_with("testbed,variant,estimator,integral,px,py,channel,reference,reference_se,mean,std_err")
    );
    // 3 estimators x 36 pixels x 3 channels at the largest budget.
    assert_eq!(integrals.lines().count(), 1 + 3 * 36 * 3);
    // Parameters are summary.csv's, per (testbed, variant, estimator); integrals.csv keeps the id.
    let first = integrals.lines().next().unwrap_or_default();
    assert!(first.ends_with(",estimator_id") && !first.contains("params"), "{first}");
    assert!(header.contains(",estimator_id,params,testbed_params,"), "{header}");
    // The plain file on request, with the same text; the commit lists whichever was written.
    run_with(dir.path(), sweep(&["is0_cv0", "brdf_is0_cv0", "clamped_is0_cv0"], 4), 2, false, IntegralsFormat::Csv);
    assert!(!res.join("integrals.csv.gz").exists());
    assert_eq!(std::fs::read_to_string(res.join("integrals.csv")).expect("plain"), integrals);
    mcbench::output::read_results(&res).expect("the folder is one committed run");
    assert_eq!(out.report.rows.len(), 3 * 4);
    // Costs are counted by the harness: samples per estimate equal the sample budget.
    assert!(out.report.rows.iter().all(|r| r.samples == r.budget as f64 && r.fetches == 0.0));
    assert!(dir.path().join("plots/itest/report.md").is_file());
}

#[test]
fn same_seed_same_results_whatever_the_thread_count() {
    // Adaptive estimators (caches, SMC) and a fetch budget (pilot calibration) too, at 1, 2 and 4
    // threads.
    let ids = ["is0_cv0", "brdf_is0_cv0", "is1_cv2"];
    let runs: Vec<(String, Vec<u8>)> = [1, 2, 4]
        .into_iter()
        .map(|threads| {
            let d = tempfile::tempdir().expect("tempdir");
            run_into(d.path(), sweep(&ids, 3), threads, false);
            let mut media = sweep(&["delta_tracking", "residual_ratio_tracking"], 3);
            media.experiment = "itest-media".into();
            media.testbeds = vec![TestBedSpec {
                id: "eq21-medium".into(),
                variant: Some("transmittance".into()),
                params: Params::new().with("resolution", 4.0),
            }];
            media.budgets =
                vec![mcbench_core::budget::Budget { kind: mcbench_core::budget::BudgetKind::Fetches, amount: 30 }];
            media.baseline = None;
            run_into(d.path(), media, threads, false);
            let mut csv = deterministic_csv(&d.path().join("results/itest/summary.csv"));
            csv.push_str(&deterministic_csv(&d.path().join("results/itest-media/summary.csv")));
            let mut integrals = common::integrals_text(&d.path().join("results/itest")).into_bytes();
            integrals.extend(common::integrals_text(&d.path().join("results/itest-media")).into_bytes());
            (csv, integrals)
        })
        .collect();
    for (threads, run) in [2, 4].iter().zip(&runs[1..]) {
        assert_eq!(run.0, runs[0].0, "summary.csv differs at {threads} threads");
        assert!(run.1 == runs[0].1, "integrals.csv differs at {threads} threads");
    }
}

#[test]
fn a_rerun_resumes_from_stored_cells() {
    let dir = tempfile::tempdir().expect("tempdir");
    run_into(dir.path(), sweep(&["is0_cv0"], 3), 2, false);
    let first = std::fs::read(dir.path().join("results/itest/summary.csv")).expect("read");
    let store = dir.path().join("results/itest/cells.store");
    assert_eq!(common::stored_cells(&store).len(), 4);
    let before = std::fs::read(&store).expect("store");
    // Same seed: cells are read back, so even the timing columns are identical.
    run_into(dir.path(), sweep(&["is0_cv0"], 3), 1, false);
    assert_eq!(first, std::fs::read(dir.path().join("results/itest/summary.csv")).expect("read"));
    assert_eq!(before, std::fs::read(&store).expect("store"), "a run that computes nothing leaves the store as it was");
    // A different seed does not reuse them.
    let mut s = sweep(&["is0_cv0"], 3);
    s.seed = 43;
    run_into(dir.path(), s, 2, false);
    assert_ne!(
        deterministic_csv(&dir.path().join("results/itest/summary.csv")),
        String::from_utf8_lossy(&first).to_string()
    );
    assert_eq!(common::stored_cells(&store).len(), 8, "the other seed's cells are appended beside the first's");
    // The store is a cache beside the committed files, not one of them: it grows, the commit holds.
    let commit = std::fs::read_to_string(dir.path().join("results/itest/commit.json")).expect("commit");
    assert!(!commit.contains("cells.store"), "{commit}");
    mcbench::output::read_results(&dir.path().join("results/itest")).expect("a consistent folder");
}

#[test]
fn unbiased_baselines_pass_and_the_biased_control_is_flagged() {
    let dir = tempfile::tempdir().expect("tempdir");
    let mut s = sweep(&["is0_cv0", "brdf_is0_cv0", "clamped_is0_cv0"], 96);
    // 96 repetitions bring the per-repetition skewness under the t-test's limit; this small image
    // then resolves a 5% bias, not the default 1%.
    s.bias_tolerance = Some(0.05);
    let out = run_into(dir.path(), s, 2, false);
    let row = |id: &str, test: &str| {
        out.report.tests.iter().find(|t| t.estimator == id && t.test == test).cloned().expect("test row")
    };
    for id in ["is0_cv0", "brdf_is0_cv0"] {
        let t = row(id, "combined");
        assert_eq!(t.verdict, "pass", "{id}: {t:?}");
        assert!(t.detectable_rel_bias <= 0.05, "{id}: detectable {}", t.detectable_rel_bias);
    }
    let c = row("clamped_is0_cv0", "combined");
    assert_eq!(c.verdict, "biased");
    assert!(c.p_value < 1e-6, "control p = {}", c.p_value);
    // No row of an unbiased estimator is flagged; inconclusive rows say what would resolve them.
    for t in &out.report.tests {
        if t.claim == "unbiased" {
            assert_ne!(t.verdict, "biased", "{t:?}");
        }
        assert!(!t.reason.is_empty(), "{t:?}");
        if t.test == "combined" && t.verdict == "inconclusive" {
            assert!(t.reps_needed.is_some_and(|r| r > 96.0), "{t:?}");
        }
    }
}

#[test]
fn independent_mc_error_falls_as_the_inverse_square_root() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = run_into(dir.path(), sweep(&["is0_cv0"], 16), 2, false);
    let f = &out.report.fits[0];
    assert!(
        f.slope_ci_low <= -0.5 && -0.5 <= f.slope_ci_high,
        "slope {} [{}, {}]",
        f.slope,
        f.slope_ci_low,
        f.slope_ci_high
    );
}

#[test]
fn incompatible_pairs_are_skipped_with_a_reason_and_bad_sweeps_refused() {
    let plan = plan_of(sweep(&["is0_cv0", "delta_tracking"], 3)).expect("valid");
    assert_eq!(plan.pairs.len(), 1);
    assert!(plan.skipped[0].reason.contains("medium"), "{}", plan.skipped[0].reason);
    // A sweep in which no pair can run is refused (it would only overwrite results with nothing).
    let mut s = sweep(&["is0_cv0"], 3);
    s.budgets = vec![mcbench_core::budget::Budget { kind: mcbench_core::budget::BudgetKind::Fetches, amount: 10 }];
    let err = plan_of(s).err().expect("refused");
    assert!(err.to_string().contains("medium") && err.exit_code() == 2, "{err}");
    let mut s = sweep(&["no_such_estimator"], 3);
    assert!(plan_of(s.clone()).err().map(|e| e.to_string()).unwrap_or_default().contains("is0_cv0"));
    s.estimators = vec![EstimatorSpec::new("is0_cv0")];
    s.reps = 1;
    assert_eq!(plan_of(s).err().map(|e| e.exit_code()), Some(2));
}

/// Sequences (paper 004 frames) are scheduled whole, each on the stream of its first integral:
/// results do not depend on the thread count.
#[test]
fn sequences_are_deterministic_whatever_the_thread_count() {
    let mk = || {
        let mut s = sweep(&["smc", "bidirectional_is"], 3);
        let params =
            Params::new().with("resolution", 3.0).with("frames", 3.0).with("env_width", 32.0).with("env_height", 16.0);
        s.testbeds = vec![TestBedSpec { id: "envmap-sequence".into(), variant: Some("mixed".into()), params }];
        s.budgets = vec![mcbench_core::budget::Budget { kind: mcbench_core::budget::BudgetKind::Samples, amount: 8 }];
        s.baseline = None;
        s
    };
    let a = tempfile::tempdir().expect("tempdir");
    let b = tempfile::tempdir().expect("tempdir");
    run_into(a.path(), mk(), 1, false);
    run_into(b.path(), mk(), 2, false);
    let ia = common::integrals_text(&a.path().join("results/itest")).into_bytes();
    let ib = common::integrals_text(&b.path().join("results/itest")).into_bytes();
    assert_eq!(ia, ib);
    // 9 pixels x 3 frames x 3 channels per estimator; px, py come from the pixel, not the integral.
    let text = String::from_utf8_lossy(&ia).to_string();
    assert_eq!(text.lines().count(), 1 + 2 * 27 * 3);
    assert!(text
        .lines()
        .skip(1)
        .all(|l| l.split(',').nth(4).is_some_and(|px| px.parse::<usize>().is_ok_and(|v| v < 3))));
}

#[test]
fn a_fetch_budget_buys_a_fixed_calibrated_number_of_rays() {
    // Delta tracking scores 0 on a ray that collides early, and that ray is also cheap: stopping
    // each estimate when its fetches run out would bias the mean. The harness fixes the ray count
    // from a pilot instead, so every estimate of every pixel takes exactly the same number of rays.
    let dir = tempfile::tempdir().expect("tempdir");
    let mut s = sweep(&["delta_tracking", "ratio_tracking"], 8);
    s.testbeds = vec![TestBedSpec {
        id: "eq21-medium".into(),
        variant: Some("transmittance".into()),
        params: Params::new().with("resolution", 4.0),
    }];
    s.budgets = vec![mcbench_core::budget::Budget { kind: mcbench_core::budget::BudgetKind::Fetches, amount: 40 }];
    s.baseline = None;
    let out = run_into(dir.path(), s, 2, false);
    for row in &out.report.rows {
        let fixed = out
            .report
            .diagnostics
            .iter()
            .find(|d| d.estimator == row.estimator && d.name == "samples_per_estimate")
            .map(|d| d.mean)
            .expect("the calibrated ray count is reported");
        assert!(fixed >= 1.0 && fixed == fixed.round(), "{fixed}");
        // Rays that miss the sphere cost one sample each and no fetch; every other estimate takes
        // exactly `fixed` rays, so the mean sample count is at most `fixed` and never a fraction
        // of a ray off from a mix of the two.
        assert!(row.samples <= fixed && row.samples >= 1.0, "{} samples vs {fixed}", row.samples);
        // The calibration aims at the budget: the mean fetches land within a factor 2 of it.
        assert!(row.fetches > 20.0 && row.fetches < 80.0, "{}: {} fetches", row.estimator, row.fetches);
    }
}

/// The repository's stored references.
const REFERENCES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../estimators/references");

/// The registry of the `mcbench` binary (built-in plug-ins and the paper suite), reading the
/// repository's stored references.
fn registry() -> &'static mcbench::Registry {
    static REGISTRY: std::sync::OnceLock<mcbench::Registry> = std::sync::OnceLock::new();
    REGISTRY.get_or_init(|| {
        experiments::registry().with_references(mcbench::store::references::ReferenceDir::new(REFERENCES))
    })
}

/// Plans a sweep against [`registry`].
fn plan_of(sweep: mcbench::config::Sweep) -> mcbench::error::Result<mcbench::plan::Plan> {
    mcbench::plan::Plan::prepare(sweep, registry())
}

/// Claims declared in a config file are judged on the run and land in summary.json's `paper`.
#[test]
fn claims_declared_in_a_config_are_judged() {
    let text = "name = 'claimed'\nreps = 8\nbudgets = [4, 16, 64, 256]\nbaseline = 'is0_cv0'\n\
                [[testbeds]]\nid = 'gradient-plane'\nvariant = 'diffuse'\nparams = { resolution = 4 }\n\
                [[estimators]]\nid = 'is0_cv0'\n[[estimators]]\nid = 'clamped_is0_cv0'\nparams = { clamp = 0.5 }\n\
                [[claims]]\nkind = 'slope'\ntestbed = 'gradient-plane/diffuse'\nestimator = 'is0_cv0'\nvalue = -0.5\ntext = 'independent MC at -1/2'\n\
                [[claims]]\nkind = 'control_flagged'\nestimator = 'clamped_is0_cv0[clamp=0.5]'\n";
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("claimed.toml");
    std::fs::write(&path, text).expect("write");
    let sweep = mcbench::config::SweepFile::read(&path).and_then(|f| f.apply(None, Mode::Quick)).expect("parses");
    assert_eq!(sweep.claims.len(), 2);
    let out = run_into(dir.path(), sweep, 2, false);
    let slope = out.report.paper.iter().find(|c| c.claim == "independent MC at -1/2").expect("judged");
    assert_eq!(slope.held, Some(true), "{slope:?}");
    let control = out.report.paper.iter().find(|c| c.claim.contains("clamped_is0_cv0")).expect("judged");
    assert_eq!(control.held, Some(true), "{control:?}");
    let bad = text.replace("kind = 'slope'", "kind = 'slop'");
    std::fs::write(&path, bad).expect("write");
    let err = mcbench::config::SweepFile::read(&path).expect_err("unknown kind");
    assert!(err.to_string().contains("slop") && err.exit_code() == 2, "{err}");
}

/// Target evaluations and cache operations are columns of summary.csv (before the display-clamped
/// error, which ends it) and a `counts`
/// section of summary.json, per estimate: paper 001's cache counts a read and a record per sample
/// plus its refinements, the independent estimator neither.
#[test]
fn summary_files_report_target_evaluations_and_cache_operations() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = run_into(dir.path(), sweep(&["is0_cv0", "is1_cv2"], 2), 2, false);
    let res = dir.path().join("results/itest");
    let csv = std::fs::read_to_string(res.join("summary.csv")).expect("read");
    assert!(
        csv.lines()
            .next()
            .unwrap_or_default()
            .ends_with(",free_flights,target_evals,cache_ops,rmse_display,fom_display,rmse_lo,rmse_hi,rmse_roundoff"),
        "{csv}"
    );
    for row in &out.report.rows {
        let shown = row.rmse_display.expect("display-clamped error kept");
        assert!(shown > 0.0 && shown <= row.rmse + 1e-12, "clamping to [0, 1] never adds error here: {row:?}");
        assert_eq!(row.fom_display, None, "no fetches on a surface, no FoM");
        let band = row.rmse_lo.zip(row.rmse_hi).expect("a band over the repetition blocks");
        assert!(band.0 <= row.rmse && row.rmse <= band.1, "the band brackets the RMSE: {band:?} {}", row.rmse);
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(res.join("summary.json")).expect("read")).expect("json");
    let counts = json["counts"].as_array().expect("a counts section");
    assert_eq!(counts.len(), out.report.rows.len());
    for (row, c) in out.report.rows.iter().zip(counts) {
        assert_eq!(c["estimator"], row.estimator.as_str());
        assert_eq!((c["target_evals"].as_f64(), c["cache_ops"].as_f64()), (Some(0.0), Some(row.cache_ops)));
        assert_eq!(row.target_evals, 0.0);
        if row.estimator == "is1_cv2" {
            assert!(row.cache_ops >= 2.0 * row.samples, "{} at {}: {}", row.estimator, row.budget, row.cache_ops);
            assert!(row.cache_ops <= 2.0 * row.samples + 8.0, "{} at {}: {}", row.estimator, row.budget, row.cache_ops);
        } else {
            assert_eq!(row.cache_ops, 0.0);
        }
    }
}
