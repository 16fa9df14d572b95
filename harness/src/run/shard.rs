//! Scale-out (book: scale-out.md): `mcbench run <experiment> --shard i/n` runs a deterministic, disjoint part
//! of a sweep and writes its sufficient statistics (per-integral [`Moments`] of whole repetition
//! blocks, integer cost totals, time histograms, diagnostic sums: never averages) into
//! `<results>/<experiment>/shard-<i>-of-<n>/`: one record per finished unit in the folder's block
//! store `blocks.store` ([`crate::store`]), and `manifest.json` when the shard has finished;
//! [`crate::run::merge`] turns the `n` shard folders into the files a single run writes.
//!
//! The unit of work is one repetition block ([`runner::REP_BLOCK`]) of one cell, numbered in plan
//! order (pair, budget, block); shard `i` of `n` owns the units `u` with `u mod n = i - 1`. The
//! split depends on the sweep alone, and a single run reduces the same blocks in the same order
//! ([`runner::run_cell`]), which is why a merge reproduces it bit for bit.
//!
//! [`Moments`]: mcbench_core::stats::Moments

use crate::config::Sweep;
use crate::error::{HarnessError, Result};
use crate::output::write_atomic;
use crate::plan::Plan;
use crate::registry::Experiment;
use crate::run::cell::{CellKey, CellResult};
use crate::run::runner::{self, Observer};
use crate::store::{Store, StoreWriter};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// The format of shard folders; a merge refuses any other.
pub const FORMAT: u32 = 1;
/// The manifest of a shard folder, written when the shard has finished.
pub const MANIFEST: &str = "manifest.json";

/// Shard `index` (1-based) of `count`, as given to `--shard i/n`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardSpec {
    /// Which shard, 1..=count.
    pub index: usize,
    /// How many shards.
    pub count: usize,
}

impl FromStr for ShardSpec {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let bad = || format!("'{s}' is not I/N with 1 <= I <= N (e.g. 2/3)");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) =
            (i.trim().parse::<usize>().map_err(|_| bad())?, n.trim().parse::<usize>().map_err(|_| bad())?);
        if index == 0 || count == 0 || index > count {
            return Err(bad());
        }
        Ok(ShardSpec { index, count })
    }
}

impl std::fmt::Display for ShardSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl ShardSpec {
    /// The shard's folder name below `<results>/<experiment>/`.
    pub fn dir_name(&self) -> String {
        format!("shard-{}-of-{}", self.index, self.count)
    }
    /// Whether unit `u` (plan order) belongs to this shard.
    pub fn owns(&self, u: usize) -> bool {
        u % self.count == self.index - 1
    }
}

/// One unit of work: repetition block `block` of the cell (pair `pair`, budget `budget`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Unit {
    /// Index into [`Plan::pairs`].
    pub pair: usize,
    /// Index into the sweep's budgets.
    pub budget: usize,
    /// Repetition block.
    pub block: usize,
}

/// Every unit of a plan, in plan order (pair, budget, block).
pub fn units(plan: &Plan) -> Vec<Unit> {
    let blocks = runner::rep_blocks(plan.sweep.reps);
    let mut out = Vec::new();
    for pair in 0..plan.pairs.len() {
        for budget in 0..plan.sweep.budgets.len() {
            out.extend((0..blocks).map(|block| Unit { pair, budget, block }));
        }
    }
    out
}

/// What a shard folder says about itself; every field but `shard` must agree across a merge.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    /// Shard-folder format ([`FORMAT`]).
    pub format: u32,
    /// Harness version that ran the shard.
    pub version: String,
    /// The named experiment whose claims and post hook apply (None: a custom sweep).
    pub definition: Option<String>,
    /// Experiment seed.
    pub seed: u64,
    /// Repetitions per integral.
    pub reps: usize,
    /// Repetitions per block ([`runner::REP_BLOCK`]).
    pub rep_block: usize,
    /// Which shard of how many.
    pub shard: ShardSpec,
    /// Units of the whole sweep.
    pub units: usize,
    /// FNV-1a digest of the sweep's JSON: equal digests, equal configs.
    pub sweep_digest: String,
    /// The sweep itself, from which a merge rebuilds the plan.
    pub sweep: Sweep,
}

/// The digest recorded in [`Manifest::sweep_digest`].
pub fn sweep_digest(sweep: &Sweep) -> String {
    format!("{:016x}", mcbench_core::rng::fnv1a(&serde_json::to_string(sweep).unwrap_or_default()))
}

/// One stored unit: a repetition block's statistics under the whole cell's key.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockFile {
    /// Repetition block.
    pub block: usize,
    /// Blocks per cell.
    pub blocks: usize,
    /// The block's sufficient statistics.
    pub stats: CellResult,
}

/// The name of block `block` of the cell `key` in a shard's block store.
pub fn block_name(key: &CellKey, block: usize) -> String {
    format!("{}_b{block}", key.name())
}

/// Repetitions in block `block` of a sweep with `reps` repetitions.
pub fn block_reps(reps: usize, block: usize) -> usize {
    ((block + 1) * runner::REP_BLOCK).min(reps).saturating_sub(block * runner::REP_BLOCK)
}

/// Reads block `block` of the cell `key` from a shard's block store and checks it against the
/// plan: the cell `key`, block `block` of `blocks`, `integrals` integrals with the block's
/// repetitions each. `None` when absent; a record that does not decode or holds another cell or
/// block is bad input naming the store and the block.
pub fn read_checked_block(
    store: &Store,
    key: &CellKey,
    block: usize,
    blocks: usize,
    integrals: usize,
) -> Result<Option<BlockFile>> {
    let name = block_name(key, block);
    let Some(record) = store.get(&name) else { return Ok(None) };
    let refuse = |why: String| HarnessError::bad_file(store.path(), format!("corrupt shard block {name} ({why})"));
    let f = crate::store::packed::decode_block(&record.payload).map_err(refuse)?;
    if f.stats.key != *key || f.block != block || f.blocks != blocks {
        return Err(refuse("it holds another cell or block".into()));
    }
    f.stats.check_shape(integrals, block_reps(key.reps, block)).map_err(refuse)?;
    Ok(Some(f))
}

/// What a shard checked before writing anything: its folder, and which of its units an earlier,
/// interrupted run of the same shard already finished.
pub struct ShardPreflight {
    dir: PathBuf,
    shard: ShardSpec,
    /// Per owned cell (in plan order): its units' blocks still to run.
    todo: Vec<(usize, usize, Vec<usize>)>,
    owned: usize,
    resumed: usize,
    units: usize,
}

/// Checks a shard run before anything is written: the sweep can be split (a time budget is
/// calibrated per machine, so its blocks could not be merged exactly), the shard folder can be
/// written, and every block its store already holds is well formed.
pub fn preflight(plan: &Plan, shard: ShardSpec, results_root: &Path) -> Result<ShardPreflight> {
    if plan.sweep.budgets.iter().any(|b| b.kind == mcbench_core::budget::BudgetKind::Micros) {
        return Err(mcbench_core::error::ConfigError::invalid(
            "budget_kind",
            "micros",
            "time budgets are calibrated on each machine, so their shards could not be merged exactly; use samples or fetches",
        )
        .into());
    }
    let dir = results_root.join(&plan.sweep.experiment).join(shard.dir_name());
    crate::store::folder::check_own_dir("--results", &results_root.join(&plan.sweep.experiment))?;
    crate::store::folder::check_own_dir("--results", &dir)?;
    let all = units(plan);
    let blocks = runner::rep_blocks(plan.sweep.reps);
    let store = Store::open(&dir.join(crate::store::BLOCKS))?;
    let owned: Vec<&Unit> = all.iter().enumerate().filter(|(u, _)| shard.owns(*u)).map(|(_, unit)| unit).collect();
    let mut resumed = 0;
    let mut todo = Vec::new();
    for cell in owned.chunk_by(|a, b| (a.pair, a.budget) == (b.pair, b.budget)) {
        let (bi, ei) = plan.pairs[cell[0].pair];
        let budget = plan.sweep.budgets[cell[0].budget];
        let key = runner::cell_key(plan, bi, ei, budget);
        let integrals = plan.beds[bi].bed.integrals();
        let mut missing = Vec::new();
        for u in cell {
            match read_checked_block(&store, &key, u.block, blocks, integrals)? {
                Some(_) => resumed += 1,
                None => missing.push(u.block),
            }
        }
        todo.push((cell[0].pair, cell[0].budget, missing));
    }
    Ok(ShardPreflight { dir, shard, todo, owned: owned.len(), resumed, units: all.len() })
}

/// What a finished shard did.
pub struct ShardOutcome {
    /// The shard folder.
    pub dir: PathBuf,
    /// Units this shard owns.
    pub owned: usize,
    /// Of them, read back from an earlier, interrupted run of the same shard.
    pub resumed: usize,
    /// Units of the whole sweep.
    pub units: usize,
}

/// Runs a shard of a prepared plan whose [`preflight`] passed into
/// `<results_root>/<experiment>/shard-<i>-of-<n>/`: takes the shard folder's lock, appends one
/// record per owned unit to its block store as soon as it is reduced (units an interrupted run
/// finished are kept), then writes the manifest, last, so a folder without one is an unfinished
/// shard.
pub fn run_shard(
    plan: &Plan,
    def: Option<&Experiment>,
    pre: ShardPreflight,
    threads: Option<usize>,
    wait: bool,
    observer: &dyn Observer,
) -> Result<ShardOutcome> {
    let ShardPreflight { dir, shard, todo, owned, resumed, units } = pre;
    let _lock = crate::store::folder::FolderLock::acquire(&dir, wait, &[])?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| HarnessError::write("thread pool", e))?;
    let blocks = runner::rep_blocks(plan.sweep.reps);
    let mut writer = StoreWriter::open(&dir.join(crate::store::BLOCKS))?;
    // The owned cells of one (test bed, budget) run together, interleaved, so that machine load
    // falls on the estimators they compare alike; the owned blocks of one cell run together, so a
    // fetch budget's pilot runs once per cell.
    let mut groups: Vec<(usize, usize, Vec<usize>)> = Vec::new();
    for (t, (pair, budget, _)) in todo.iter().enumerate() {
        let bi = plan.pairs[*pair].0;
        match groups.iter_mut().find(|g| (g.0, g.1) == (bi, *budget)) {
            Some(g) => g.2.push(t),
            None => groups.push((bi, *budget, vec![t])),
        }
    }
    let mut done = 0;
    for (bi, budget, members) in &groups {
        let budget = plan.sweep.budgets[*budget];
        let cells: Vec<runner::GroupCell<'_>> =
            members.iter().map(|&t| runner::GroupCell { ei: plan.pairs[todo[t].0].1, blocks: &todo[t].2 }).collect();
        let keys: Vec<CellKey> = cells.iter().map(|c| runner::cell_key(plan, *bi, c.ei, budget)).collect();
        pool.install(|| {
            runner::run_group_with(plan, *bi, budget, &cells, |k, pos, stats| {
                let block = cells[k].blocks[pos];
                let file = BlockFile { block, blocks, stats };
                writer.append(&block_name(&keys[k], block), &crate::store::packed::encode_block(&file))
            })
        })?;
        for (c, key) in cells.iter().zip(&keys) {
            let label =
                format!("{} {} {}={}", plan.beds[*bi].label(), key.estimator, budget.kind.name(), budget.amount);
            done += 1;
            observer.cell_done(done, todo.len(), &label, c.blocks.is_empty());
        }
    }
    let manifest = Manifest {
        format: FORMAT,
        version: env!("CARGO_PKG_VERSION").to_string(),
        definition: def.map(|d| d.name.to_string()),
        seed: plan.sweep.seed,
        reps: plan.sweep.reps,
        rep_block: runner::REP_BLOCK,
        shard,
        units,
        sweep_digest: sweep_digest(&plan.sweep),
        sweep: plan.sweep.clone(),
    };
    let path = dir.join(MANIFEST);
    let text = serde_json::to_string_pretty(&manifest).map_err(|e| HarnessError::write(&path, e))?;
    write_atomic(&path, text.as_bytes())?;
    Ok(ShardOutcome { dir, owned, resumed, units })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_specs_parse_and_bad_ones_are_refused() {
        assert_eq!("2/3".parse::<ShardSpec>(), Ok(ShardSpec { index: 2, count: 3 }));
        for bad in ["0/3", "4/3", "a/b", "1/0", "3", "1/2/3", ""] {
            assert!(bad.parse::<ShardSpec>().is_err(), "{bad} accepted");
        }
    }

    #[test]
    fn shards_partition_the_units() {
        for n in 1..6 {
            for u in 0..40 {
                let owners = (1..=n).filter(|&i| ShardSpec { index: i, count: n }.owns(u)).count();
                assert_eq!(owners, 1, "unit {u} of {n} shards");
            }
        }
    }
}
