//! The claim tables of the book's claims-table page from a committed snapshot of the quick suite's
//! claims (`experiments::readme_table`).
//!
//! - `cargo run --release -p experiments --example readme_table -- snapshot RESULTS [COMMAND]...`
//!   reads `RESULTS/<experiment>/summary.json` of every suite experiment and of `sensitivity` into
//!   `results/snapshots/quick/claims.json` (the commands that made the runs are stored with it);
//! - `cargo run --release -p experiments --example readme_table -- readme` rewrites that page's
//!   generated part from the snapshot.
//!
//! Run from the repository root. Exit 2 with one line on bad input.

use experiments::readme_table::{rewrite, snapshot, table, Snapshot, SNAPSHOT, TABLE_FILE};
use std::path::Path;

fn fail(msg: impl std::fmt::Display) -> ! {
    eprintln!("readme_table: {msg}");
    std::process::exit(2)
}

/// Writes `path` atomically (a temporary beside it, then a rename).
fn write(path: &Path, text: &str) {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, text)
        .and_then(|_| std::fs::rename(&tmp, path))
        .unwrap_or_else(|e| fail(format!("{}: {e}", path.display())));
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("snapshot") => {
            let Some(root) = args.get(1) else { fail("snapshot needs the results root (e.g. results)") };
            let mut names: Vec<String> = experiments::registry().suite().map(|e| e.name.clone()).collect();
            names.push("sensitivity".into());
            let s = snapshot(Path::new(root), &names, args[2..].to_vec()).unwrap_or_else(|e| fail(e));
            if s.experiments.is_empty() {
                fail(format!("{root}: no experiment's summary.json found"));
            }
            let text = serde_json::to_string_pretty(&s).unwrap_or_else(|e| fail(e)) + "\n";
            std::fs::create_dir_all(Path::new(SNAPSHOT).parent().unwrap_or(Path::new("."))).unwrap_or_else(|e| fail(e));
            write(Path::new(SNAPSHOT), &text);
            println!("{SNAPSHOT}: {} experiments", s.experiments.len());
        }
        Some("readme") => {
            let text = std::fs::read_to_string(SNAPSHOT).unwrap_or_else(|e| fail(format!("{SNAPSHOT}: {e}")));
            let s: Snapshot = serde_json::from_str(&text).unwrap_or_else(|e| fail(format!("{SNAPSHOT}: {e}")));
            let readme = std::fs::read_to_string(TABLE_FILE).unwrap_or_else(|e| fail(format!("{TABLE_FILE}: {e}")));
            let new = rewrite(&readme, &table(&s)).unwrap_or_else(|e| fail(e));
            write(Path::new(TABLE_FILE), &new);
            println!("README.md: claims table rewritten from {SNAPSHOT}");
        }
        _ => fail("usage: readme_table snapshot RESULTS [COMMAND]... | readme"),
    }
}
