//! Coverage of the convergence-slope intervals (book: slope-fits.md): how often the 95% interval of independent
//! MC's slope holds the true -1/2, over many seeds, for the whole-range and the right-end fit, by
//! ordinary least squares of log RMSE (the fit before `summary.csv` had `mse_se`) and by the weighted fit
//! with delta-method variances that `mcbench::analysis::fits` makes now.
//!
//! ```text
//! cargo run --release -p mcbench --example slope_coverage -- [seeds] [threads] [resolution] [case] [first seed]
//! ```
//!
//! Cases: `gradient-plane/default` with 16 repetitions (light tails) and `gradient-plane/stiff` with
//! 8 repetitions (heavy tails), estimator `is0_cv0`, spp 4, 16, ..., 4096, at `resolution` x
//! `resolution` pixels (default 8); `case` is `default`, `stiff` or `all` (default). Seeds are
//! `first seed` (default 1) and the `seeds - 1` (default 199) after it; everything is deterministic.

use mcbench::analysis::metrics::SummaryRow;
use mcbench::analysis::{fits, RIGHT_END_BUDGETS};
use mcbench::config::{powers_of_four, EstimatorSpec, Mode, Sweep, TestBedSpec};
use mcbench::plan::Plan;
use mcbench::registry::Registry;
use mcbench::run::runner::{run, RunOptions, Silent};
use mcbench_core::params::Params;
use mcbench_core::stats::log_log_fit;

const TRUE_SLOPE: f64 = -0.5;

fn rows(
    registry: &Registry,
    variant: &str,
    reps: usize,
    seed: u64,
    threads: usize,
    resolution: f64,
) -> Vec<SummaryRow> {
    let sweep = Sweep {
        experiment: "slope-coverage".into(),
        testbeds: vec![TestBedSpec {
            id: "gradient-plane".into(),
            variant: Some(variant.into()),
            params: Params::new().with("resolution", resolution),
        }],
        estimators: vec![EstimatorSpec::new("is0_cv0")],
        budgets: powers_of_four(1..=6),
        reps,
        seed,
        mode: Mode::Quick,
        baseline: None,
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    };
    let plan = Plan::prepare(sweep, registry).expect("valid sweep");
    let opts = RunOptions { threads: Some(threads), store: None, observer: &Silent };
    let done = run(&plan, &opts).expect("run");
    done.cells.iter().map(|(bi, ei, cell)| plan.summary_row(*bi, *ei, cell)).collect()
}

/// Hits and mean slope of one (fit, method) column.
#[derive(Default)]
struct Tally {
    hits: usize,
    n: usize,
    slope_sum: f64,
    width_sum: f64,
}

impl Tally {
    fn add(&mut self, (slope, lo, hi): (f64, f64, f64)) {
        self.n += 1;
        self.hits += usize::from(lo <= TRUE_SLOPE && TRUE_SLOPE <= hi);
        self.slope_sum += slope;
        self.width_sum += hi - lo;
    }
    fn line(&self, case: &str, fit: &str, method: &str) -> String {
        let n = self.n.max(1) as f64;
        format!(
            "| {case} | {fit} | {method} | {} | {:.1}% | {:.3} | {:.3} |",
            self.n,
            100.0 * self.hits as f64 / n,
            self.slope_sum / n,
            self.width_sum / n
        )
    }
}

fn ols(rows: &[SummaryRow]) -> (f64, f64, f64) {
    let x: Vec<f64> = rows.iter().map(|r| r.budget as f64).collect();
    let y: Vec<f64> = rows.iter().map(|r| r.rmse).collect();
    log_log_fit(&x, &y).map_or((f64::NAN, f64::NAN, f64::NAN), |f| (f.slope, f.slope_ci_low, f.slope_ci_high))
}

fn main() {
    let mut args = std::env::args().skip(1);
    let seeds: u64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(200);
    let threads: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let resolution: f64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(8.0);
    let only: Option<String> = args.next().filter(|o| o != "all");
    let first: u64 = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let registry = Registry::new().with_catalog(mcbench_papers::catalog());
    println!("| case | fit | method | seeds | covers -0.5 | mean slope | mean width |");
    println!("|---|---|---|---|---|---|---|");
    for (variant, reps) in [("default", 16), ("stiff", 8)] {
        if only.as_deref().is_some_and(|o| o != variant) {
            continue;
        }
        let case = format!("gradient-plane/{variant}, {reps} reps, {resolution}x{resolution}");
        let mut t: [Tally; 4] = Default::default();
        for seed in first..first + seeds {
            let r = rows(&registry, variant, reps, seed, threads, resolution);
            let f = &fits(&r)[0];
            assert_eq!(f.method, "wls", "seed {seed}: rows without mse_se");
            t[0].add(ols(&r));
            t[1].add((f.slope, f.slope_ci_low, f.slope_ci_high));
            t[2].add(ols(&r[r.len() - RIGHT_END_BUDGETS..]));
            t[3].add((f.slope_right, f.slope_right_ci_low, f.slope_right_ci_high));
        }
        println!("{}", t[0].line(&case, "whole range", "OLS (before)"));
        println!("{}", t[1].line(&case, "whole range", "WLS, delta method"));
        println!("{}", t[2].line(&case, "right end (last 3)", "OLS (before)"));
        println!("{}", t[3].line(&case, "right end (last 3)", "WLS, delta method"));
    }
}
