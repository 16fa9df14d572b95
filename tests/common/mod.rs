//! Helpers shared by the integration tests.

use mcbench::metrics::TIMING_COLUMNS;
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
