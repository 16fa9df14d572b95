//! Resuming: the cells of a plan that a results folder's cell store ([`crate::store`]) already
//! holds, read back and checked before anything runs (the runner computes only the others).

use crate::error::{HarnessError, Result};
use crate::plan::Plan;
use crate::run::cell::{CellKey, CellResult};
use crate::run::runner::cell_key;
use crate::store::Store;
use std::path::Path;

/// Reads a stored cell back from `store`: `None` when absent; a record that does not decode, holds
/// another cell or does not fit the plan (integrals, repetitions, finite statistics) is bad input
/// naming the store and the cell.
pub fn read_cell(store: &Store, key: &CellKey, integrals: usize) -> Result<Option<CellResult>> {
    let name = key.name();
    let Some(record) = store.get(&name) else { return Ok(None) };
    let refuse = |why: String| {
        HarnessError::bad_file(
            store.path(),
            format!("corrupt stored cell {name} ({why}); delete the store to recompute its cells"),
        )
    };
    let cell = crate::store::packed::decode_cell(&record.payload).map_err(refuse)?;
    if cell.key != *key {
        return Err(refuse("it holds another cell than its name says".into()));
    }
    cell.check_shape(integrals, key.reps).map_err(refuse)?;
    Ok(Some(cell))
}

/// The stored cells of a plan, in (pair, budget) order, read and checked before anything runs:
/// a corrupt cell is refused before any other cell is recomputed or written.
pub fn preload(plan: &Plan, store: Option<&Path>) -> Result<Vec<Option<CellResult>>> {
    match store {
        Some(path) => preload_from(plan, Some(&Store::open(path)?)),
        None => preload_from(plan, None),
    }
}

/// [`preload`] from a store already read (one reading for several plans).
pub fn preload_from(plan: &Plan, store: Option<&Store>) -> Result<Vec<Option<CellResult>>> {
    let mut out = Vec::with_capacity(plan.pairs.len() * plan.sweep.budgets.len());
    for &(bi, ei) in &plan.pairs {
        for &budget in &plan.sweep.budgets {
            let key = cell_key(plan, bi, ei, budget);
            out.push(match store {
                Some(s) => read_cell(s, &key, plan.beds[bi].bed.integrals())?,
                None => None,
            });
        }
    }
    Ok(out)
}
