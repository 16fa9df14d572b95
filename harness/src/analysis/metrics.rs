//! The metrics of one cell (book: outputs.md) against its test bed's reference: RMSE (noise-corrected for
//! stored references: `E[(X - R)^2] = MSE + Var R`), variance, pooled bias with its standard
//! error, costs per estimate, efficiency and FoM. Time-based metrics (efficiency, P-Eff) use the
//! estimating thread's CPU seconds, which load from other processes does not inflate; wall-clock
//! seconds are reported beside them.

use crate::run::cell::{CellResult, RepBlock};
use mcbench_core::stats::NeumaierSum;
use mcbench_core::testbed::Reference;
use serde::{Deserialize, Serialize};

/// One row of `summary.csv` (the first 18 columns are the original contract, the rest extend it; book: contract.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Estimator name.
    pub estimator: String,
    /// `samples`, `fetches` or `micros`.
    pub budget_kind: String,
    /// Budget per estimate.
    pub budget: u64,
    /// Repetitions.
    pub reps: usize,
    /// Integrals (pixels).
    pub integrals: usize,
    /// Root mean square error over integrals and channels.
    pub rmse: f64,
    /// Mean square error (noise-corrected).
    pub mse: f64,
    /// Mean variance of one estimate.
    pub variance: f64,
    /// Pooled bias (mean over integrals and channels of mean - reference).
    pub bias: f64,
    /// Standard error of the pooled bias, from the spread of the per-repetition summed deviations
    /// (so integrals and channels that a repetition shares, frames of one sequence or correlated
    /// colour channels, count once), plus the stored reference's variance; from the per-integral
    /// variances as if independent only for cells stored without per-repetition aggregates.
    pub bias_se: f64,
    /// Samples per estimate.
    pub samples: f64,
    /// Medium fetches per estimate.
    pub fetches: f64,
    /// Rays per estimate.
    pub rays: f64,
    /// Mean wall-clock seconds per estimate on the thread that computed it (timing: varies run to
    /// run, and with the load of the machine).
    pub seconds: f64,
    /// 1 / (variance x CPU seconds per estimate) (`cpu_seconds`; timing).
    pub efficiency: Option<f64>,
    /// 1 / (MSE x fetches per estimate), empty without fetches.
    pub fom: Option<f64>,
    /// RMSE relative to the reference (over non-zero references).
    pub rel_rmse: f64,
    /// Mean reference variance subtracted from the MSE (0 for exact references).
    pub reference_var: f64,
    /// Cheap approximate-extinction fetches per estimate.
    pub cheap_fetches: f64,
    /// Median wall-clock seconds per estimate (timing).
    pub seconds_median: f64,
    /// 1 / (MSE x CPU seconds per estimate) (`cpu_seconds`; timing).
    pub efficiency_mse: Option<f64>,
    /// Paper 003's perceptual error `Err` = mean over integrals of `MSE / tvi(L_ref)` (channel-mean
    /// MSE; reference luminance).
    #[serde(default)]
    pub p_err: f64,
    /// Paper 003's `P-Eff = 1 / (T Err)` with `T` the CPU seconds of a whole image
    /// (`cpu_seconds` x integrals) (timing).
    #[serde(default)]
    pub p_eff: Option<f64>,
    /// Registered id of the estimator (`estimator` is the id with the parameters given).
    #[serde(default)]
    pub estimator_id: String,
    /// The estimator's parameters with every default filled in, as JSON.
    #[serde(default)]
    pub params: String,
    /// The test bed's parameters with every default filled in, as JSON.
    #[serde(default)]
    pub testbed_params: String,
    /// Standard error of `mse`: `sqrt(s^2 / reps)` with `s^2` the sample variance over repetitions
    /// of each repetition's mean squared deviation (the cell's `rep_sq`); it weights the slope fits.
    /// NaN in files written before it and for fewer than 2 repetitions.
    #[serde(default = "crate::output::nan")]
    pub mse_se: f64,
    /// Mean CPU seconds per estimate: the estimating thread's CPU clock, which does not advance
    /// while the thread waits for a core or sleeps, so machine load does not inflate it the way it
    /// inflates `seconds` (timing). Every time-based metric divides by it. For cells stored before
    /// CPU time was measured it is the wall-clock `seconds` (`time_clock` says `wall`); NaN in files
    /// written before it.
    #[serde(default = "crate::output::nan")]
    pub cpu_seconds: f64,
    /// 1 / (variance x wall-clock seconds per estimate): the efficiency as it was computed before
    /// CPU time, which load from other processes lowers (timing).
    #[serde(default)]
    pub efficiency_wall: Option<f64>,
    /// The clock the time-based metrics (`cpu_seconds`, `efficiency`, `efficiency_mse`, `p_eff`)
    /// use: `cpu`, or `wall` for a cell stored before CPU time was measured (empty in files written
    /// before this column, whose time-based metrics all used wall-clock seconds).
    #[serde(default)]
    pub time_clock: String,
    /// Shadow (visibility) rays per estimate, a subset of `rays` (0 in files written before they
    /// were counted apart, and where a scene reports its rays as one count).
    #[serde(default)]
    pub shadow_rays: f64,
    /// 1 / (variance x seconds per estimate in the `renderer` cost regime): CPU seconds plus the
    /// counted rays and fetches at the sweep's unit costs ([`crate::plan::cost_model`]; timing; empty in
    /// files written before it).
    #[serde(default)]
    pub efficiency_renderer: Option<f64>,
    /// Free-flight segments per estimate, a subset of `rays` (0 in files written before they were
    /// counted apart); `rays - shadow_rays - free_flights` are primary rays.
    #[serde(default)]
    pub free_flights: f64,
    /// Target-density evaluations per estimate ([`mcbench_core::task::Costs::target_evals`]: paper
    /// 004's `p~` evaluations, paper 003's PMC population members; 0 elsewhere and in files
    /// written before they were counted).
    #[serde(default)]
    pub target_evals: f64,
    /// Radiance-cache operations per estimate ([`mcbench_core::task::Costs::cache_ops`]: reads,
    /// records and refinements of papers 000 and 001's caches; 0 elsewhere and in files written
    /// before they were counted).
    #[serde(default)]
    pub cache_ops: f64,
    /// RMSE of the display-clamped values: every estimate and the reference clamped to `[0, 1]`
    /// before the difference, as an image is shown (paper 002 §4.2). Clamping is not linear, so
    /// this is the error a viewer sees, not an unbiased estimator's spread; the stored reference's
    /// own noise is not subtracted. Empty for cells stored before it was kept.
    #[serde(default)]
    pub rmse_display: Option<f64>,
    /// Figure of merit on display-clamped values, 1 / (`rmse_display`^2 x fetches).
    #[serde(default)]
    pub fom_display: Option<f64>,
    /// Low end of the 90% bootstrap interval of `rmse` over the cell's repetition blocks
    /// ([`crate::analysis::rmse_band`]; the band of the RMSE plots). Empty for cells with fewer than two
    /// blocks and in files written before it.
    #[serde(default)]
    pub rmse_lo: Option<f64>,
    /// High end of that interval.
    #[serde(default)]
    pub rmse_hi: Option<f64>,
    /// The RMSE the cell may show through floating-point round-off and its exact reference's
    /// stated error alone ([`crate::analysis::roundoff::rmse_bound`]): a row whose `rmse` is at most this is
    /// exact ([`SummaryRow::at_roundoff`]). NaN against a stored reference with a standard error
    /// (its noise dwarfs round-off) and in files written before it.
    #[serde(default = "crate::output::nan")]
    pub rmse_roundoff: f64,
    /// The cell's repetition blocks, for the bootstrap intervals of ratio claims: carried in memory
    /// only (neither `summary.csv` nor `summary.json` has them), so rows read back from files, and
    /// rows of cells stored before blocks were kept, have none and fall back to the delta method.
    #[serde(skip)]
    pub rep_blocks: RowBlocks,
}

impl SummaryRow {
    /// Whether the row's error is round-off: its `rmse` at most `rmse_roundoff` (never for rows
    /// without that bound: stored references with a standard error, files written before it).
    pub fn at_roundoff(&self) -> bool {
        self.rmse <= self.rmse_roundoff
    }
}

/// A cell's repetition blocks ([`crate::run::cell::RepBlock`]) with what turns a resample of them into
/// the row's metrics: MSE = sum of `sq` / repetitions + `mse_offset`, paper 003's `Err` likewise
/// with `p_err_offset` (the offsets carry the stored reference's variance, subtracted from both),
/// costs and CPU seconds per estimate = sums / (repetitions x `integrals`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RowBlocks {
    /// The blocks, in repetition order (empty: none kept).
    pub blocks: Vec<RepBlock>,
    /// Integrals per repetition.
    pub integrals: usize,
    /// The row's `mse` less the mean over repetitions of the per-repetition squared deviation.
    pub mse_offset: f64,
    /// The row's `p_err` less the mean over repetitions of the per-repetition `Err`.
    pub p_err_offset: f64,
}

impl RowBlocks {
    /// Whether there are blocks to resample (at least two, and every one holding repetitions).
    pub fn usable(&self) -> bool {
        self.blocks.len() >= 2 && self.integrals > 0 && self.blocks.iter().all(|b| b.reps > 0)
    }

    /// The blocks' repetition counts: two rows with the same layout were cut the same way and
    /// are resampled jointly (paired).
    pub fn layout(&self) -> Vec<u64> {
        self.blocks.iter().map(|b| b.reps).collect()
    }
}

impl SummaryRow {
    /// Seconds per estimate for time-based metrics: `cpu_seconds`, or the wall-clock `seconds` in
    /// rows read from files written before CPU time was measured.
    pub fn metric_seconds(&self) -> f64 {
        if self.cpu_seconds.is_finite() {
            self.cpu_seconds
        } else {
            self.seconds
        }
    }
}

/// Column names whose values depend on the wall clock (excluded from determinism checks).
pub const TIMING_COLUMNS: &[&str] = &[
    "seconds",
    "efficiency",
    "seconds_median",
    "efficiency_mse",
    "p_eff",
    "cpu_seconds",
    "efficiency_wall",
    "efficiency_renderer",
];

pub(crate) fn inverse(x: f64) -> Option<f64> {
    (x > 0.0 && x.is_finite()).then(|| 1.0 / x)
}

/// Computes the summary row of a cell.
pub fn summarize(cell: &CellResult, reference: &Reference) -> SummaryRow {
    let reps = cell.key.reps as f64;
    let (mut mse, mut var, mut bias, mut bias_var, mut rel, mut ref_var) = (
        NeumaierSum::new(),
        NeumaierSum::new(),
        NeumaierSum::new(),
        NeumaierSum::new(),
        NeumaierSum::new(),
        NeumaierSum::new(),
    );
    let mut rel_n = 0usize;
    let mut p_err = NeumaierSum::new();
    for (i, m) in cell.moments.iter().enumerate() {
        let tvi = mcbench_core::perception::tvi(mcbench_core::perception::luminance(reference.value[i]));
        let mut e2_mean = 0.0;
        for (c, mc) in m.iter().enumerate() {
            let (r, rse2) = (reference.value[i][c], reference.std_err[i][c].powi(2));
            let sample_var = mc.variance();
            let d = mc.mean() - r;
            // Mean over repetitions of (x - R)^2, minus the reference's own variance.
            let e2 = d * d + sample_var * (reps - 1.0) / reps - rse2;
            mse.add(e2);
            e2_mean += e2 / 3.0;
            var.add(sample_var);
            bias.add(d);
            bias_var.add(sample_var / reps + rse2);
            ref_var.add(rse2);
            if r != 0.0 {
                rel.add(e2 / (r * r));
                rel_n += 1;
            }
        }
        p_err.add(e2_mean / tvi);
    }
    let m = (cell.moments.len() * 3) as f64;
    let per = |x: u64| x as f64 / cell.estimates.max(1) as f64;
    let mse_v = mse.value() / m;
    let variance = var.value() / m;
    let seconds = cell.time.mean();
    let (metric_time, cpu) = cell.metric_time();
    let cpu_seconds = metric_time.mean();
    let fetches = per(cell.costs.fetches);
    let p_err_v = p_err.value() / cell.moments.len().max(1) as f64;
    let display_mse = (!cell.blocks.is_empty())
        .then(|| cell.blocks.iter().map(|b| b.display_sq).sum::<Option<f64>>())
        .flatten()
        .map(|s| s / cell.blocks.iter().map(|b| b.reps).sum::<u64>().max(1) as f64);
    let band = {
        let held = cell.blocks.iter().map(|b| b.reps).sum::<u64>().max(1) as f64;
        let offset = mse_v - cell.blocks.iter().map(|b| b.sq).sum::<f64>() / held;
        crate::analysis::rmse_band::rmse_band(&cell.blocks, offset, crate::analysis::rmse_band::seed(&cell.key))
    };
    let rep_blocks = if cpu && !cell.blocks.is_empty() {
        let held = cell.blocks.iter().map(|b| b.reps).sum::<u64>().max(1) as f64;
        let (sq, pe) = cell.blocks.iter().fold((0.0, 0.0), |(s, p), b| (s + b.sq, p + b.p_err));
        RowBlocks {
            blocks: cell.blocks.clone(),
            integrals: cell.moments.len(),
            mse_offset: mse_v - sq / held,
            p_err_offset: p_err_v - pe / held,
        }
    } else {
        RowBlocks::default()
    };
    SummaryRow {
        testbed: cell.key.testbed.clone(),
        variant: cell.key.variant.clone(),
        estimator: cell.key.estimator.clone(),
        budget_kind: cell.key.budget.kind.name().to_string(),
        budget: cell.key.budget.amount,
        reps: cell.key.reps,
        integrals: cell.moments.len(),
        rmse: mse_v.max(0.0).sqrt(),
        mse: mse_v,
        variance,
        bias: bias.value() / m,
        bias_se: pooled_bias_se(cell, ref_var.value()).unwrap_or(bias_var.value().sqrt()) / m,
        samples: per(cell.costs.samples),
        fetches,
        rays: per(cell.costs.rays),
        seconds,
        efficiency: inverse(variance * cpu_seconds),
        fom: if fetches > 0.0 { inverse(mse_v * fetches) } else { None },
        rel_rmse: (rel.value() / rel_n.max(1) as f64).max(0.0).sqrt(),
        reference_var: ref_var.value() / m,
        cheap_fetches: per(cell.costs.cheap_fetches),
        seconds_median: cell.time.median(),
        efficiency_mse: inverse(mse_v * cpu_seconds),
        p_err: p_err_v,
        p_eff: inverse(cpu_seconds * cell.moments.len() as f64 * p_err.value() / cell.moments.len().max(1) as f64),
        estimator_id: String::new(),
        params: String::new(),
        testbed_params: String::new(),
        mse_se: if cell.rep_sq.count() >= 2 { (cell.rep_sq.variance() / reps).sqrt() } else { f64::NAN },
        cpu_seconds,
        efficiency_wall: inverse(variance * seconds),
        time_clock: if cpu { "cpu" } else { "wall" }.to_string(),
        shadow_rays: per(cell.costs.shadow_rays),
        efficiency_renderer: None,
        free_flights: per(cell.costs.free_flights),
        target_evals: per(cell.costs.target_evals),
        cache_ops: per(cell.costs.cache_ops),
        rmse_display: display_mse.map(f64::sqrt),
        fom_display: display_mse.filter(|_| fetches > 0.0).and_then(|m| inverse(m * fetches)),
        rmse_lo: band.map(|b| b.0),
        rmse_hi: band.map(|b| b.1),
        rmse_roundoff: crate::analysis::roundoff::rmse_bound(cell, reference),
        rep_blocks,
    }
}

/// The standard error of the summed deviation of a cell from its per-repetition aggregates (and
/// the reference's summed variance `ref_var`); `None` without them.
fn pooled_bias_se(cell: &CellResult, ref_var: f64) -> Option<f64> {
    let r = cell.rep_dev.count();
    (r >= 2).then(|| (cell.rep_dev.variance() / r as f64 + ref_var).sqrt())
}
