//! Helpers shared by the integration tests.
#![allow(dead_code)]

use mcbench::analysis::metrics::TIMING_COLUMNS;
use std::path::Path;

/// summary.csv with the wall-clock columns removed.
pub fn deterministic_csv(path: &Path) -> String {
    let mut rd = csv::Reader::from_path(path).expect("summary.csv readable");
    let header = rd.headers().expect("header").clone();
    let keep: Vec<usize> = (0..header.len()).filter(|&i| !TIMING_COLUMNS.contains(&&header[i])).collect();
    let mut out = keep.iter().map(|&i| header[i].to_string()).collect::<Vec<_>>().join(",");
    for rec in rd.records() {
        let rec = rec.expect("record");
        out.push('\n');
        out.push_str(&keep.iter().map(|&i| rec[i].to_string()).collect::<Vec<_>>().join(","));
    }
    out
}

/// The cells of a cell store (`cells.store`) as JSON, with their record names, in file order.
pub fn stored_cells(store: &Path) -> Vec<(String, serde_json::Value)> {
    let s = mcbench::store::Store::open(store).expect("store readable");
    s.records()
        .iter()
        .map(|r| {
            let cell = mcbench::store::packed::decode_cell(&r.payload).expect("cell decodes");
            (r.name.clone(), serde_json::to_value(&cell).expect("json"))
        })
        .collect()
}

/// Rewrites a cell store with each cell passed through `edit` (as JSON; the edited JSON must
/// still be a cell, whose checks are the reader's).
pub fn edit_cells(store: &Path, mut edit: impl FnMut(&str, &mut serde_json::Value)) {
    let records: Vec<mcbench::store::Record> = stored_cells(store)
        .into_iter()
        .map(|(name, mut v)| {
            edit(&name, &mut v);
            let cell: mcbench::run::cell::CellResult = serde_json::from_value(v).expect("still a cell");
            mcbench::store::Record { payload: mcbench::store::packed::encode_cell(&cell), name }
        })
        .collect();
    mcbench::store::write_records(store, &records).expect("rewrites");
}

/// The text of a results folder's integrals.csv (plain or gzip-compressed).
pub fn integrals_text(results_dir: &Path) -> String {
    mcbench::output::integrals::read_text(results_dir).expect("readable").expect("an integrals file")
}
