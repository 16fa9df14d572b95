//! CPU time per estimate (book: outputs.md): measured on the estimating thread's clock beside wall time,
//! time spent sleeping or waiting not counted; cells stored before it still load (wall-clock
//! fallback, said so); and the interleaved scheduling of the cells of one (test bed, budget) does
//! not change any result.

mod common;
use mcbench::config::{EstimatorSpec, Mode, Sweep, TestBedSpec};
use mcbench::run::runner::{self, RunOptions, Silent};
use mcbench::{Bias, Checks, EstimateError, Estimator, EstimatorEntry, Needs, Registry, Rgb, StreamRng, Task};
use mcbench_core::budget::{Budget, BudgetKind};
use mcbench_core::params::{ParamSpec, Params};

/// Takes the task's samples (all along the surface normal), returning their mean.
fn spend_budget(task: &Task<'_>) -> Result<Rgb, EstimateError> {
    let probe = task.hemisphere().ok_or_else(|| EstimateError::Refused("needs a surface".into()))?;
    let normal = probe.point().normal;
    let (mut sum, mut n) = (Rgb::ZERO, 0.0);
    while task.more() {
        sum += probe.integrand(normal);
        n += 1.0;
    }
    Ok(sum / n)
}

/// Does almost no work and sleeps 2 ms per estimate.
struct Sleeper;

impl Estimator for Sleeper {
    fn estimate(&self, task: &Task<'_>, _rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        spend_budget(task)?;
        std::thread::sleep(std::time::Duration::from_millis(2));
        Ok(Rgb::ZERO)
    }
}

/// Only computes: about a million multiply-adds per estimate.
struct Spinner;

impl Estimator for Spinner {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        use rand::Rng;
        spend_budget(task)?;
        let mut x: u64 = rng.gen();
        for i in 0..1_000_000u64 {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(i);
        }
        Ok(Rgb::ZERO * std::hint::black_box(x) as f64)
    }
}

/// A registry entry for a timing test estimator.
macro_rules! entry {
    ($id:literal, $make:expr) => {
        EstimatorEntry {
            id: $id,
            paper: "tests",
            label: $id,
            bias: Bias::Unbiased,
            needs: Needs::SURFACE,
            samplers: &[],
            summary: "timing test estimator",
            build: |_: &Params| Ok(Box::new($make)),
            checks: Checks::DEFAULT,
            params: ParamSpec::NONE,
        }
    };
}

static SLEEPER: EstimatorEntry = entry!("sleeper", Sleeper);
static SPINNER: EstimatorEntry = entry!("spinner", Spinner);

fn registry() -> &'static Registry {
    static REGISTRY: std::sync::OnceLock<Registry> = std::sync::OnceLock::new();
    REGISTRY.get_or_init(|| {
        experiments::registry().with_estimator(&SLEEPER).with_estimator(&SPINNER).with_references(
            mcbench::store::references::ReferenceDir::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../estimators/references"
            )),
        )
    })
}

fn sweep(ids: &[&str], resolution: f64, budgets: Vec<Budget>, reps: usize) -> Sweep {
    Sweep {
        experiment: "cpu-time".into(),
        testbeds: vec![TestBedSpec {
            id: "gradient-plane".into(),
            variant: Some("diffuse".into()),
            params: Params::new().with("resolution", resolution),
        }],
        estimators: ids.iter().map(|id| EstimatorSpec::new(id)).collect(),
        budgets,
        reps,
        seed: 7,
        mode: Mode::Quick,
        baseline: None,
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    }
}

fn samples(amounts: &[u64]) -> Vec<Budget> {
    amounts.iter().map(|&amount| Budget { kind: BudgetKind::Samples, amount }).collect()
}

fn summaries(plan: &mcbench::plan::Plan, run: &runner::RunResults) -> Vec<mcbench::analysis::metrics::SummaryRow> {
    run.cells.iter().map(|(bi, ei, cell)| plan.summary_row(*bi, *ei, cell)).collect()
}

#[test]
fn cpu_seconds_count_work_and_not_sleep() {
    let plan =
        mcbench::plan::Plan::prepare(sweep(&["sleeper", "spinner"], 2.0, samples(&[1]), 3), registry()).expect("plans");
    let opts = RunOptions { threads: Some(1), store: None, observer: &Silent };
    let run = runner::run(&plan, &opts).expect("runs");
    let rows = summaries(&plan, &run);
    let row = |name: &str| rows.iter().find(|r| r.estimator == name).expect("row");
    let (sleeper, spinner) = (row("sleeper"), row("spinner"));
    for r in [sleeper, spinner] {
        assert_eq!(r.time_clock, "cpu");
        assert!(r.cpu_seconds > 0.0 && r.cpu_seconds <= r.seconds * 1.01 + 1e-6, "{}: {r:?}", r.estimator);
    }
    // Sleeping takes wall time but (almost) no CPU time.
    assert!(sleeper.seconds >= 0.002, "{}", sleeper.seconds);
    assert!(sleeper.cpu_seconds < 0.2 * sleeper.seconds, "{} vs {}", sleeper.cpu_seconds, sleeper.seconds);
    // Computing alone on its thread: CPU time is most of the wall time (loosely, since other
    // processes may share the machine's cores).
    assert!(spinner.cpu_seconds > 0.2 * spinner.seconds, "{} vs {}", spinner.cpu_seconds, spinner.seconds);
    // Efficiency divides by CPU time; the wall-clock one is beside it.
    let eff = |v: f64, s: f64| (v > 0.0).then(|| 1.0 / (v * s));
    assert_eq!(spinner.efficiency, eff(spinner.variance, spinner.cpu_seconds));
    assert_eq!(spinner.efficiency_wall, eff(spinner.variance, spinner.seconds));
}

/// Interleaving the cells of a (test bed, budget) changes the schedule only: every cell equals the
/// same cell run alone, at one thread and at two, timing aside; a fetch budget (pilot per cell) and
/// a partial second repetition block included.
#[test]
fn interleaved_cells_equal_cells_run_alone() {
    let strip = |mut c: mcbench::run::cell::CellResult| {
        c.time = Default::default();
        c.cpu_time = None;
        for b in &mut c.blocks {
            (b.cpu_seconds, b.wall_seconds) = (0.0, 0.0);
        }
        c
    };
    let surface = sweep(&["is0_cv0", "brdf_is0_cv0", "is1_cv2"], 4.0, samples(&[4, 16]), 20);
    let mut media = sweep(&["delta_tracking", "residual_ratio_tracking"], 3.0, Vec::new(), 18);
    media.testbeds = vec![TestBedSpec {
        id: "eq21-medium".into(),
        variant: Some("transmittance".into()),
        params: Params::new().with("resolution", 3.0),
    }];
    media.budgets = vec![Budget { kind: BudgetKind::Fetches, amount: 20 }];
    for s in [surface, media] {
        let plan = mcbench::plan::Plan::prepare(s, registry()).expect("plans");
        for threads in [1, 2] {
            let opts = RunOptions { threads: Some(threads), store: None, observer: &Silent };
            let run = runner::run(&plan, &opts).expect("runs");
            assert_eq!(run.cells.len(), plan.pairs.len() * plan.sweep.budgets.len());
            let mut k = 0;
            for &(bi, ei) in &plan.pairs {
                for &budget in &plan.sweep.budgets {
                    let (rbi, rei, cell) = &run.cells[k];
                    assert_eq!((*rbi, *rei), (bi, ei), "cells come in plan order");
                    let alone = runner::run_cell(&plan, bi, ei, budget).expect("runs alone");
                    assert!(cell.cpu_time.as_ref().is_some_and(|t| t.count == cell.estimates));
                    assert_eq!(strip(cell.clone()), strip(alone), "{} at {threads} threads", cell.key.estimator);
                    k += 1;
                }
            }
        }
    }
}

/// A cell stored before CPU time was measured (no `cpu_time`) is read back, and its time-based
/// metrics use wall time, saying so in `time_clock`.
#[test]
fn cells_stored_without_cpu_time_fall_back_to_wall_time() {
    let dir = tempfile::tempdir().expect("tempdir");
    let plan = mcbench::plan::Plan::prepare(sweep(&["is0_cv0"], 3.0, samples(&[4]), 4), registry()).expect("plans");
    let store = dir.path().join(mcbench::store::CELLS);
    let opts = RunOptions { threads: Some(2), store: Some(store.clone()), observer: &Silent };
    let first = runner::run(&plan, &opts).expect("runs");
    let mut edited = 0;
    common::edit_cells(&store, |_, json| {
        assert!(json.as_object_mut().expect("object").remove("cpu_time").is_some());
        edited += 1;
    });
    assert_eq!(edited, 1);
    let again = runner::run(&plan, &opts).expect("resumes");
    let (old, new) = (&summaries(&plan, &first)[0], &summaries(&plan, &again)[0]);
    assert_eq!(old.time_clock, "cpu");
    assert_eq!(new.time_clock, "wall");
    assert_eq!(new.seconds, old.seconds, "read back, not recomputed");
    assert_eq!(new.cpu_seconds, new.seconds);
    assert_eq!(new.efficiency, new.efficiency_wall);
    // A merge of a block with CPU times and one without has none.
    let (with, without) = (first.cells[0].2.clone(), again.cells[0].2.clone());
    assert!(runner::merge_blocks(with.key.clone(), &[with.clone(), without]).cpu_time.is_none());
    assert!(runner::merge_blocks(with.key.clone(), &[with.clone(), with]).cpu_time.is_some());
}
