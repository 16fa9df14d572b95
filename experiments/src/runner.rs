//! Executing a [`Plan`]: every cell's repetitions in parallel (rayon) in fixed batches, each
//! estimate on its own counter-derived stream, reduced in index order so results are bit-identical
//! whatever the thread count; finished cells are stored and read back on a re-run (resume).

use crate::cell::{add_diagnostics, CellKey, CellResult, TimeStats};
use crate::error::{HarnessError, Result};
use crate::output::write_atomic;
use crate::plan::Plan;
use estimators::budget::Budget;
use estimators::error::EstimateError;
use estimators::math::Rgb;
use estimators::rng::StreamKey;
use estimators::stats::Moments;
use estimators::task::{Costs, Task};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Integrals per work item: small enough to balance, large enough to amortise scheduling.
const BATCH: usize = 16;

/// Receives progress (no-op by default): the CLI draws bars from it.
pub trait Observer: Sync {
    /// A cell finished (`resumed` when it was read back from disk).
    fn cell_done(&self, _done: usize, _total: usize, _label: &str, _resumed: bool) {}
}

/// The silent observer.
pub struct Silent;
impl Observer for Silent {}

/// Run options.
pub struct RunOptions<'a> {
    /// Worker threads (None: rayon's default).
    pub threads: Option<usize>,
    /// Where finished cells are stored for resume (None: no resume store).
    pub cell_dir: Option<PathBuf>,
    /// Progress receiver.
    pub observer: &'a dyn Observer,
}

/// The finished cells of a plan, in (pair, budget) order.
pub struct RunResults {
    /// Cells with their (bed index, estimator index).
    pub cells: Vec<(usize, usize, CellResult)>,
}

struct Item {
    values: Vec<Rgb>,
    costs: Costs,
    time: TimeStats,
    diagnostics: Vec<(String, f64)>,
}

fn add(a: &mut Costs, b: &Costs) {
    a.samples += b.samples;
    a.fetches += b.fetches;
    a.cheap_fetches += b.cheap_fetches;
    a.rays += b.rays;
}

/// Runs one cell (no resume logic).
pub fn run_cell(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> Result<CellResult> {
    let (b, e) = (&plan.beds[bi], &plan.estimators[ei]);
    let label = b.label();
    let n = b.bed.integrals();
    let reps = plan.sweep.reps;
    let batches = n.div_ceil(BATCH);
    let items: Vec<Result<Item>> = (0..reps * batches)
        .into_par_iter()
        .map(|item| {
            let (rep, batch) = (item / batches, item % batches);
            let mut out = Item {
                values: Vec::with_capacity(BATCH),
                costs: Costs::default(),
                time: TimeStats::default(),
                diagnostics: Vec::new(),
            };
            for i in batch * BATCH..((batch + 1) * BATCH).min(n) {
                let key = StreamKey {
                    seed: plan.sweep.seed,
                    testbed: &label,
                    estimator: &e.name,
                    budget: budget.amount,
                    rep: rep as u64,
                    integral: i as u64,
                };
                let mut rng = key.rng();
                let task = Task::new(b.bed.as_ref(), i, budget);
                let t0 = Instant::now();
                let v = e.estimator.estimate(&task, &mut rng);
                out.time.push(t0.elapsed().as_secs_f64());
                let v = v.and_then(|v| {
                    if v.is_finite() {
                        Ok(v)
                    } else {
                        Err(EstimateError::NonFinite { integral: i, value: v.0 })
                    }
                });
                let v = v.map_err(|source| HarnessError::Estimate {
                    estimator: e.name.clone(),
                    testbed: label.clone(),
                    source,
                })?;
                add(&mut out.costs, &task.costs());
                add_diagnostics(&mut out.diagnostics, &task.diagnostics());
                out.values.push(v);
            }
            Ok(out)
        })
        .collect();
    let mut moments = vec![[Moments::default(), Moments::default(), Moments::default()]; n];
    let (mut costs, mut time, mut diagnostics) = (Costs::default(), TimeStats::default(), Vec::new());
    for (item, r) in items.into_iter().enumerate() {
        let r = r?;
        let batch = item % batches;
        for (k, v) in r.values.iter().enumerate() {
            for c in 0..3 {
                moments[batch * BATCH + k][c].push(v[c]);
            }
        }
        add(&mut costs, &r.costs);
        time.merge(&r.time);
        add_diagnostics(&mut diagnostics, &r.diagnostics);
    }
    let key = cell_key(plan, bi, ei, budget);
    Ok(CellResult { key, moments, costs, estimates: (reps * n) as u64, time, diagnostics })
}

/// The key of a cell.
pub fn cell_key(plan: &Plan, bi: usize, ei: usize, budget: Budget) -> CellKey {
    let b = &plan.beds[bi];
    CellKey {
        testbed: b.spec.id.clone(),
        variant: b.variant.clone(),
        testbed_params: serde_json::to_string(&b.spec.params).unwrap_or_default(),
        estimator: plan.estimators[ei].name.clone(),
        budget,
        reps: plan.sweep.reps,
        seed: plan.sweep.seed,
        version: env!("CARGO_PKG_VERSION").to_string(),
    }
}

fn read_cell(path: &Path, key: &CellKey) -> Result<Option<CellResult>> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(HarnessError::bad_file(path, e)),
    };
    let cell: CellResult = serde_json::from_str(&text)
        .map_err(|e| HarnessError::bad_file(path, format!("corrupt stored cell ({e}); delete it to recompute")))?;
    Ok((cell.key == *key).then_some(cell))
}

/// Runs every cell of the plan, reading back stored cells and storing new ones.
pub fn run(plan: &Plan, opts: &RunOptions<'_>) -> Result<RunResults> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| HarnessError::write("thread pool", e))?;
    let total = plan.pairs.len() * plan.sweep.budgets.len();
    let mut cells = Vec::with_capacity(total);
    for &(bi, ei) in &plan.pairs {
        for &budget in &plan.sweep.budgets {
            let key = cell_key(plan, bi, ei, budget);
            let path = opts.cell_dir.as_ref().map(|d| d.join(key.file_name()));
            let stored = match &path {
                Some(p) => read_cell(p, &key)?,
                None => None,
            };
            let resumed = stored.is_some();
            let cell = match stored {
                Some(c) => c,
                None => {
                    let c = pool.install(|| run_cell(plan, bi, ei, budget))?;
                    if let Some(p) = &path {
                        let text = serde_json::to_string(&c).map_err(|e| HarnessError::write(p, e))?;
                        write_atomic(p, text.as_bytes())?;
                    }
                    c
                }
            };
            let label = format!(
                "{} {} {}={}",
                plan.beds[bi].label(),
                plan.estimators[ei].name,
                budget.kind.name(),
                budget.amount
            );
            opts.observer.cell_done(cells.len() + 1, total, &label, resumed);
            cells.push((bi, ei, cell));
        }
    }
    Ok(RunResults { cells })
}
