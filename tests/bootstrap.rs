//! Repetition blocks and the bootstrap intervals of ratio claims over the public API: a cell's
//! blocks add up to its totals, do not depend on the thread count or on running its repetition
//! blocks apart and merging them (as shards do), give paired, reproducible intervals, and a cell
//! stored without them falls back to the delta method.

use mcbench::analysis::claims::{Ratio, RatioMetric};
use mcbench::config::{powers_of_four, EstimatorSpec, Mode, Sweep, TestBedSpec};
use mcbench::plan::Plan;
use mcbench::run::cell::{rep_block_count, CellResult};
use mcbench::run::runner::{self, RunOptions, Silent};
use mcbench_core::budget::Budget;
use mcbench_core::params::Params;

const REFERENCES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../estimators/references");

fn registry() -> &'static mcbench::Registry {
    static REGISTRY: std::sync::OnceLock<mcbench::Registry> = std::sync::OnceLock::new();
    REGISTRY.get_or_init(|| {
        experiments::registry().with_references(mcbench::store::references::ReferenceDir::new(REFERENCES))
    })
}

/// Two estimators on a small image at two budgets, 40 repetitions: blocks of 2 repetitions (20
/// of them) across three shard blocks of 16.
fn plan(reps: usize) -> Plan {
    let sweep = Sweep {
        experiment: "boot".into(),
        testbeds: vec![TestBedSpec {
            id: "gradient-plane".into(),
            variant: Some("default".into()),
            params: Params::new().with("resolution", 4.0),
        }],
        estimators: ["is0_cv0", "is1_cv2"].iter().map(|id| EstimatorSpec::new(id)).collect(),
        budgets: powers_of_four(1..=2),
        reps,
        seed: 7,
        mode: Mode::Quick,
        baseline: Some("is0_cv0".into()),
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    };
    Plan::prepare(sweep, registry()).expect("valid sweep")
}

fn run(plan: &Plan, threads: usize) -> Vec<CellResult> {
    let opts = RunOptions { threads: Some(threads), store: None, observer: &Silent };
    runner::run(plan, &opts).expect("runs").cells.into_iter().map(|(_, _, c)| c).collect()
}

/// The blocks without their time sums (which vary run to run).
fn untimed(c: &CellResult) -> Vec<(u64, u64, u64, mcbench_core::task::Costs)> {
    c.blocks.iter().map(|b| (b.reps, b.sq.to_bits(), b.p_err.to_bits(), b.costs)).collect()
}

#[test]
fn blocks_add_up_to_the_cell_whatever_the_threads_or_the_split() {
    let p = plan(40);
    let (one, two) = (run(&p, 1), run(&p, 2));
    for (a, b) in one.iter().zip(&two) {
        assert_eq!(a.blocks.len(), rep_block_count(40));
        assert_eq!(a.blocks.len(), 20);
        assert_eq!(untimed(a), untimed(b), "{}: blocks depend on the thread count", a.key.estimator);
        assert!(a.blocks.iter().all(|b| b.reps == 2 && b.cpu_seconds > 0.0 && b.wall_seconds > 0.0));
        // The blocks' sums are the cell's per-repetition aggregates and cost totals.
        let sq: f64 = a.blocks.iter().map(|b| b.sq).sum();
        assert!((sq / 40.0 - a.rep_sq.mean()).abs() <= 1e-12 * a.rep_sq.mean().abs().max(1e-300), "{sq}");
        let samples: u64 = a.blocks.iter().map(|b| b.costs.samples).sum();
        assert_eq!(samples, a.costs.samples);
        let cpu: f64 = a.blocks.iter().map(|b| b.cpu_seconds).sum();
        let total = a.cpu_time.as_ref().expect("cpu time").total;
        assert!((cpu - total).abs() <= 1e-9 * total, "{cpu} vs {total}");
    }
    // The repetition blocks of one cell run apart (as shards own them) and merged in block order
    // give the single run's blocks bit for bit.
    let (bi, ei) = p.pairs[1];
    let budget: Budget = p.sweep.budgets[1];
    let parts = runner::run_blocks(&p, bi, ei, budget, &[0, 1, 2]).expect("blocks run");
    let merged = runner::merge_blocks(runner::cell_key(&p, bi, ei, budget), &parts);
    let single = one.iter().find(|c| c.key == merged.key).expect("same cell");
    assert_eq!(untimed(&merged), untimed(single));
    assert_eq!(merged.rep_sq, single.rep_sq);
}

#[test]
fn ratio_intervals_are_paired_bootstraps_that_rerun_identically_and_fall_back_without_blocks() {
    let p = plan(32);
    let cells = run(&p, 2);
    let rows: Vec<_> = p
        .pairs
        .iter()
        .flat_map(|&(bi, ei)| std::iter::repeat_n((bi, ei), p.sweep.budgets.len()))
        .zip(&cells)
        .map(|((bi, ei), c)| p.summary_row(bi, ei, c))
        .collect();
    let at = |est: &str| rows.iter().find(|r| r.estimator == est && r.budget == 16).expect("row");
    let (a, b) = (at("is1_cv2"), at("is0_cv0"));
    for metric in [RatioMetric::Mse, RatioMetric::EfficiencyMse, RatioMetric::PEff, RatioMetric::PErr] {
        let r = Ratio::of(metric, a, b).expect("ratio");
        assert_eq!(r.method(), "bootstrap over 32 blocks of repetitions, paired (expanded percentile x1.25 for heavy tails, 2000 resamples)");
        let (lo, hi) = r.interval();
        assert!(lo < r.value && r.value < hi, "{metric:?}: {} outside [{lo}, {hi}]", r.value);
        // Same cells, same interval, to the bit.
        let again = Ratio::of(metric, a, b).expect("ratio").interval();
        assert_eq!((lo.to_bits(), hi.to_bits()), (again.0.to_bits(), again.1.to_bits()));
        // A Bonferroni level gives a wider interval.
        let (l2, h2) = r.interval_at(0.99);
        assert!(l2 < lo && h2 > hi);
    }
    // The same cells stored before blocks were kept: the delta method, as before.
    let (mut a_old, mut b_old) = (a.clone(), b.clone());
    a_old.rep_blocks = Default::default();
    b_old.rep_blocks = Default::default();
    let old = Ratio::of(RatioMetric::Mse, &a_old, &b_old).expect("ratio");
    assert_eq!(old.method(), "delta method");
    let boot = Ratio::of(RatioMetric::Mse, a, b).expect("ratio");
    assert_eq!(old.value, boot.value);
    let (ol, oh) = old.interval();
    assert!(ol < old.value && old.value < oh);
    // And a cell read back from a file written before blocks: it parses and has none.
    let text = serde_json::to_string(&cells[0]).expect("json");
    let mut v: serde_json::Value = serde_json::from_str(&text).expect("json");
    v.as_object_mut().expect("object").remove("blocks");
    let back: CellResult = serde_json::from_value(v).expect("old cell parses");
    assert!(back.blocks.is_empty());
    back.check_shape(cells[0].moments.len(), 32).expect("an old cell is well formed");
    assert!(p.summary_row(0, 0, &back).rep_blocks.blocks.is_empty());
}
