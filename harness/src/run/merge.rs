//! `mcbench merge <dir>...` (book: scale-out.md): shard folders ([`crate::run::shard`]) back into the files a
//! single run writes. The shard set is checked first: one format, harness version (this binary's),
//! experiment, seed, repetitions and config (sweep digest) throughout, every shard `1..=n` exactly
//! once, every owned block present in its shard's block store, decodable and of the right cell.
//! Then the plan is rebuilt from the manifests' sweep, each cell's blocks are merged in block order
//! ([`runner::merge_blocks`], exactly as a single run reduces them), appended to the results
//! folder's cell store for resume, and the run ends in [`execute::finish`] like a single run: same
//! metrics, claims, post hook, files and plots.

use crate::error::{HarnessError, Result};
use crate::plan::Plan;
use crate::run::execute::{self, ExecOptions, Outcome};
use crate::run::runner::{self, RunResults};
use crate::run::shard::{self, Manifest, ShardSpec, MANIFEST};
use crate::store::{Store, StoreWriter};
use mcbench_core::error::ConfigError;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The shard folders named by `dirs`: each is a shard folder (it holds a manifest) or a folder
/// whose `shard-*` subfolders are (an experiment's results folder).
pub fn shard_dirs(dirs: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for d in dirs {
        if d.join(MANIFEST).is_file() {
            out.push(d.clone());
            continue;
        }
        let entries = std::fs::read_dir(d).map_err(|e| HarnessError::bad_file(d, e))?;
        let mut found: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir() && p.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.starts_with("shard-")))
            .collect();
        if found.is_empty() {
            return Err(HarnessError::bad_file(
                d,
                "not a shard folder: no manifest.json (an unfinished shard has none) and no shard-* folders below",
            ));
        }
        found.sort();
        out.extend(found);
    }
    Ok(out)
}

fn read_manifest(dir: &Path) -> Result<Manifest> {
    let path = dir.join(MANIFEST);
    let text = std::fs::read_to_string(&path)
        .map_err(|e| HarnessError::bad_file(&path, format!("{e} (an unfinished shard has no manifest)")))?;
    let m: Manifest = serde_json::from_str(&text)
        .map_err(|e| HarnessError::bad_file(&path, format!("corrupt shard manifest ({e})")))?;
    if shard::sweep_digest(&m.sweep) != m.sweep_digest {
        return Err(HarnessError::bad_file(&path, "corrupt shard manifest (its sweep does not match its digest)"));
    }
    Ok(m)
}

fn refuse(field: &str, value: impl std::fmt::Display, reason: impl std::fmt::Display) -> HarnessError {
    ConfigError::invalid(field, value, reason.to_string()).into()
}

/// Checks that `shards` (folder, manifest) form one complete set; returns them ordered by index.
pub fn check_set(mut shards: Vec<(PathBuf, Manifest)>) -> Result<Vec<(PathBuf, Manifest)>> {
    let Some((d0, m0)) = shards.first().cloned() else {
        return Err(refuse("merge", "(none)", "name at least one shard folder"));
    };
    let this = env!("CARGO_PKG_VERSION");
    for (d, m) in &shards {
        let at = d.display();
        let differs = |field: &str, a: String, b: String| {
            refuse(field, &a, format!("shards disagree: {at} has {a}, {} has {b}", d0.display()))
        };
        if m.format != shard::FORMAT {
            return Err(refuse("format", m.format, format!("{at}: this mcbench reads shard format {}", shard::FORMAT)));
        }
        if m.version != this {
            return Err(refuse(
                "version",
                &m.version,
                format!("{at} was run by mcbench {}, this is {this}", m.version),
            ));
        }
        if m.seed != m0.seed {
            return Err(differs("seed", m.seed.to_string(), m0.seed.to_string()));
        }
        if m.sweep.experiment != m0.sweep.experiment || m.definition != m0.definition {
            return Err(differs("experiment", m.sweep.experiment.clone(), m0.sweep.experiment.clone()));
        }
        if m.reps != m0.reps || m.rep_block != m0.rep_block {
            return Err(differs("reps", m.reps.to_string(), m0.reps.to_string()));
        }
        if m.sweep_digest != m0.sweep_digest || m.units != m0.units {
            return Err(differs("config", m.sweep_digest.clone(), m0.sweep_digest.clone()));
        }
        if m.shard.count != m0.shard.count {
            return Err(differs("shard count", m.shard.count.to_string(), m0.shard.count.to_string()));
        }
    }
    shards.sort_by_key(|(_, m)| m.shard.index);
    for w in shards.windows(2) {
        if w[0].1.shard.index == w[1].1.shard.index {
            let (a, b) = (w[0].0.display(), w[1].0.display());
            return Err(refuse("shard", w[0].1.shard, format!("duplicated: given by {a} and {b}")));
        }
    }
    let n = m0.shard.count;
    let missing: Vec<String> = (1..=n)
        .filter(|i| !shards.iter().any(|(_, m)| m.shard.index == *i))
        .map(|i| ShardSpec { index: i, count: n }.to_string())
        .collect();
    if !missing.is_empty() {
        return Err(refuse("shard", missing.join(", "), format!("missing from the set of {n} given to merge")));
    }
    Ok(shards)
}

/// Merges shard folders into `<results>/<experiment>/` (and its plots), as a single run writes them.
pub fn merge(dirs: &[PathBuf], opts: &ExecOptions<'_>) -> Result<Outcome> {
    let started = Instant::now();
    let shards =
        shard_dirs(dirs)?.into_iter().map(|d| read_manifest(&d).map(|m| (d, m))).collect::<Result<Vec<_>>>()?;
    let shards = check_set(shards)?;
    let first = &shards[0].1;
    let def = first.definition.as_deref().map(|n| opts.registry.experiment(n)).transpose()?;
    // The shards' claims were checked against the plan when they ran (or deliberately not).
    let plan = Plan::prepare_unchecked(first.sweep.clone(), opts.registry)?;
    let units = shard::units(&plan);
    if units.len() != first.units {
        return Err(refuse(
            "config",
            &first.sweep_digest,
            "this mcbench splits the sweep differently from the shards'",
        ));
    }
    let blocks = runner::rep_blocks(plan.sweep.reps);
    let results_dir = opts.results_root.join(&plan.sweep.experiment);
    crate::store::folder::check_own_dir("--results", &results_dir)?;
    if opts.plots {
        crate::store::folder::check_own_dir("--plots", &opts.plots_root.join(&plan.sweep.experiment))?;
    }
    // The results folder's cell store, appended to below, is read (and refused) before any lock.
    Store::open(&results_dir.join(crate::store::CELLS))?;
    let stores = shards.iter().map(|(d, _)| Store::open(&d.join(crate::store::BLOCKS))).collect::<Result<Vec<_>>>()?;
    let mut cells = Vec::with_capacity(plan.pairs.len() * plan.sweep.budgets.len());
    for (c, cell_units) in units.chunks(blocks).enumerate() {
        let (bi, ei) = plan.pairs[cell_units[0].pair];
        let budget = plan.sweep.budgets[cell_units[0].budget];
        let key = runner::cell_key(&plan, bi, ei, budget);
        let integrals = plan.beds[bi].bed.integrals();
        let mut parts = Vec::with_capacity(blocks);
        for (k, u) in cell_units.iter().enumerate() {
            let owner = (c * blocks + k) % first.shard.count;
            let store = &stores[owner];
            let file = shard::read_checked_block(store, &key, u.block, blocks, integrals)?.ok_or_else(|| {
                let name = shard::block_name(&key, u.block);
                let why = format!("block {name} missing: shard {} is incomplete or damaged", shards[owner].1.shard);
                HarnessError::bad_file(store.path(), why)
            })?;
            parts.push(file.stats);
        }
        cells.push((bi, ei, runner::merge_blocks(key, &parts)));
    }
    // Only a complete, consistent set gets here: nothing is written before.
    let _locks = execute::lock_folders(&plan.sweep.experiment, opts)?;
    // Stored like a single run's cells, so `mcbench run` on these results resumes from them.
    let mut store = StoreWriter::open(&results_dir.join(crate::store::CELLS))?;
    for (_, _, cell) in &cells {
        store.append(&cell.key.name(), &crate::store::packed::encode_cell(cell))?;
    }
    execute::finish(&plan, def, &RunResults { cells }, opts, started)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{EstimatorSpec, Mode, Sweep, TestBedSpec};

    fn manifest(index: usize, count: usize, seed: u64) -> (PathBuf, Manifest) {
        let sweep = Sweep {
            experiment: "tiny".into(),
            testbeds: vec![TestBedSpec { id: "gradient-plane".into(), variant: None, params: Default::default() }],
            estimators: vec![EstimatorSpec::new("is0_cv0")],
            budgets: crate::config::powers_of_four(1..=2),
            reps: 8,
            seed,
            mode: Mode::Quick,
            baseline: None,
            claims: Vec::new(),
            bias_tolerance: None,
            cost_model: Default::default(),
            repetitions: Default::default(),
        };
        let m = Manifest {
            format: shard::FORMAT,
            version: env!("CARGO_PKG_VERSION").into(),
            definition: None,
            seed,
            reps: sweep.reps,
            rep_block: runner::REP_BLOCK,
            shard: ShardSpec { index, count },
            units: 10,
            sweep_digest: shard::sweep_digest(&sweep),
            sweep,
        };
        (PathBuf::from(format!("s{index}")), m)
    }

    fn err(set: Vec<(PathBuf, Manifest)>) -> String {
        check_set(set).expect_err("refused").to_string()
    }

    #[test]
    fn complete_sets_pass_and_bad_sets_are_refused_naming_why() {
        let ok = check_set(vec![manifest(2, 2, 1), manifest(1, 2, 1)]).expect("complete set");
        assert_eq!(ok[0].1.shard.index, 1);
        assert!(err(vec![manifest(1, 3, 1), manifest(3, 3, 1)]).contains("2/3"), "missing shard named");
        assert!(err(vec![manifest(1, 2, 1), manifest(1, 2, 1), manifest(2, 2, 1)]).contains("duplicated"));
        assert!(err(vec![manifest(1, 2, 1), manifest(2, 2, 9)]).contains("seed"));
        assert!(err(vec![manifest(1, 2, 1), manifest(2, 3, 1)]).contains("shard count"));
        let mut other = manifest(2, 2, 1);
        other.1.version = "0.0.1".into();
        assert!(err(vec![manifest(1, 2, 1), other]).contains("version"));
        let mut other = manifest(2, 2, 1);
        other.1.sweep.budgets.pop();
        other.1.sweep_digest = shard::sweep_digest(&other.1.sweep);
        assert!(err(vec![manifest(1, 2, 1), other]).contains("config"));
        assert!(err(Vec::new()).contains("at least one"));
    }
}
