//! The claim tables of the book's claims-table page (which the README links), generated from a
//! committed snapshot of the quick suite's claims (`results/snapshots/quick/claims.json`) so that
//! they never show a number no run printed.
//!
//! `cargo run --release -p experiments --example readme_table -- snapshot results` reads every
//! experiment's `summary.json` under a results root (the quick suite's and, when present,
//! `sensitivity`'s) into the snapshot; `... -- readme` rewrites that page's tables from it. The
//! test `readme_table` fails when the page and the snapshot differ.

use mcbench::output::{Claim, Verdict};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Where the snapshot lives, relative to the repository root.
pub const SNAPSHOT: &str = "results/snapshots/quick/claims.json";
/// The book page that holds the generated tables (the README links it).
pub const TABLE_FILE: &str = "docs/src/claims-table.md";
/// The line that opens the generated part of the README.
pub const BEGIN: &str = "<!-- claims table: generated from results/snapshots/quick/claims.json by `cargo run --release -p experiments --example readme_table -- readme`; do not edit -->";
/// The line that closes it.
pub const END: &str = "<!-- end of the generated claims table -->";

/// One experiment's claims as its `summary.json` has them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExperimentClaims {
    /// The experiment's name.
    pub experiment: String,
    /// `quick` or `full`.
    pub mode: String,
    /// The seed of the run.
    pub seed: u64,
    /// The commit the binary was built from.
    pub git_commit: String,
    /// Its claims (`paper` in summary.json).
    pub claims: Vec<Claim>,
}

/// The snapshot: the claims of every experiment of one run of the suite.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// The commands that made the runs it was read from.
    pub commands: Vec<String>,
    /// One entry per experiment, in suite order.
    pub experiments: Vec<ExperimentClaims>,
}

/// Errors of reading a results root or the README.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// A file could not be read.
    #[error("{path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// A summary.json is not what a run writes.
    #[error("{path}: not a summary.json ({reason})")]
    Malformed {
        /// The file.
        path: String,
        /// Why.
        reason: String,
    },
    /// The README lacks the markers of the generated part.
    #[error("README: no generated part (the lines `{BEGIN}` and `{END}`)")]
    NoMarkers,
}

/// The snapshot of the experiments `names` under `root` (`<root>/<name>/summary.json`); an
/// experiment without a summary is left out.
pub fn snapshot(root: &Path, names: &[String], commands: Vec<String>) -> Result<Snapshot, TableError> {
    let mut experiments = Vec::new();
    for name in names {
        let path = root.join(name).join("summary.json");
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => continue,
            Err(source) => return Err(TableError::Read { path: path.display().to_string(), source }),
        };
        let malformed = |reason: String| TableError::Malformed { path: path.display().to_string(), reason };
        let v: serde_json::Value = serde_json::from_str(&text).map_err(|e| malformed(e.to_string()))?;
        let meta = &v["meta"];
        let claims: Vec<Claim> =
            serde_json::from_value(v["paper"].clone()).map_err(|e| malformed(format!("paper: {e}")))?;
        experiments.push(ExperimentClaims {
            experiment: name.clone(),
            mode: meta["mode"].as_str().unwrap_or_default().to_string(),
            seed: meta["seed"].as_u64().ok_or_else(|| malformed("meta.seed missing".into()))?,
            git_commit: meta["git_commit"].as_str().unwrap_or_default().to_string(),
            claims,
        });
    }
    Ok(Snapshot { commands, experiments })
}

/// The paper a claim's text names (`paper 002 ...` -> `002`), `-` when none.
fn paper_of(text: &str) -> String {
    text.match_indices("paper ")
        .map(|(i, m)| &text[i + m.len()..])
        .find(|rest| rest.len() >= 3 && rest.as_bytes()[..3].iter().all(u8::is_ascii_digit))
        .map_or("-".to_string(), |rest| rest[..3].to_string())
}

/// A number with about four significant figures.
fn num(v: f64) -> String {
    if v == 0.0 || (1e-3..1e4).contains(&v.abs()) {
        format!("{:.4}", v).trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.3e}")
    }
}

/// Our value with its interval, or `-`.
fn value(c: &Claim) -> String {
    match (c.our_value, c.interval) {
        (Some(v), Some([lo, hi])) => format!("{} [{}, {}]", num(v), num(lo), num(hi)),
        (Some(v), None) => num(v),
        _ => "-".into(),
    }
}

/// Text for a markdown table cell: no pipes, no line breaks, no HTML.
fn cell(s: &str) -> String {
    s.replace('|', "\\|").replace(['\n', '\r'], " ").replace('<', "&lt;").replace('>', "&gt;")
}

/// One row of the generated table: a claim text with one verdict, over the test beds that share it.
struct Row {
    claim: String,
    verdict: Verdict,
    beds: Vec<String>,
    values: Vec<String>,
    /// Whether the value divides by measured CPU time.
    time: bool,
}

/// The generated markdown: one row per claim of the suite's experiments (claims with the same
/// text and verdict on several test beds share a row), a mark on those whose value depends on
/// measured CPU time, then the sensitivity outcomes.
pub fn table(s: &Snapshot) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "Made by: {}.\n\n",
        s.commands.iter().map(|c| format!("`{c}`")).collect::<Vec<_>>().join(", ")
    ));
    out.push_str(
        "| paper | experiment | claim | test bed | ours [95% interval] | verdict |\n|---|---|---|---|---|---|\n",
    );
    let mut timed = false;
    for e in s.experiments.iter().filter(|e| e.experiment != "sensitivity") {
        let mut rows: Vec<Row> = Vec::new();
        for c in &e.claims {
            let time = c.regime == "measured";
            timed |= time;
            match rows.iter_mut().find(|r| r.claim == c.claim && r.verdict == c.verdict() && r.time == time) {
                Some(r) => {
                    r.beds.push(c.testbed.clone());
                    r.values.push(value(c));
                }
                None => rows.push(Row {
                    claim: c.claim.clone(),
                    verdict: c.verdict(),
                    beds: vec![c.testbed.clone()],
                    values: vec![value(c)],
                    time,
                }),
            }
        }
        for r in rows {
            out.push_str(&format!(
                "| {} | {} | {}{} | {} | {} | {} |\n",
                paper_of(&r.claim),
                e.experiment,
                cell(&r.claim),
                if r.time { " (time)" } else { "" },
                cell(&r.beds.join(", ")),
                cell(&r.values.join("; ")),
                r.verdict
            ));
        }
    }
    if let Some(e) = s.experiments.iter().find(|e| e.experiment == "sensitivity") {
        out.push_str(
            "\nWhere each claim holds (`sensitivity`, each claim judged across a parameter its paper leaves open):\n\n",
        );
        out.push_str("| paper | claim | at the paper-like setting (else our default) | outcome |\n|---|---|---|---|\n");
        for c in &e.claims {
            let time = c.regime == "measured";
            timed |= time;
            out.push_str(&format!(
                "| {} | {}{} | {}: {} | {} |\n",
                paper_of(&c.claim),
                cell(&c.claim),
                if time { " (time)" } else { "" },
                cell(&value(c)),
                c.verdict(),
                cell(&c.note)
            ));
        }
    }
    if timed {
        out.push_str("\n(time): the value divides by measured CPU seconds, so it moves with the machine's load (up to about 30% between runs on the shared 2-core machine); the other values are the same bit for bit on every rerun with the same seed.\n");
    }
    out
}

/// `readme` with its generated part replaced by `table`.
pub fn rewrite(readme: &str, table: &str) -> Result<String, TableError> {
    let begin = readme.find(BEGIN).ok_or(TableError::NoMarkers)?;
    let end = readme[begin..].find(END).ok_or(TableError::NoMarkers)? + begin;
    Ok(format!("{}{BEGIN}\n\n{table}\n{}", &readme[..begin], &readme[end..]))
}

/// The generated part of `readme` as it stands.
pub fn current(readme: &str) -> Result<&str, TableError> {
    let begin = readme.find(BEGIN).ok_or(TableError::NoMarkers)? + BEGIN.len();
    let end = readme[begin..].find(END).ok_or(TableError::NoMarkers)? + begin;
    Ok(readme[begin..end].trim())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn claim(text: &str, bed: &str, v: f64, verdict: Verdict, regime: &str) -> Claim {
        Claim {
            testbed: bed.into(),
            claim: text.into(),
            our_value: Some(v),
            interval: Some([v * 0.9, v * 1.1]),
            verdict: Some(verdict),
            regime: regime.into(),
            note: "n | m".into(),
            ..Default::default()
        }
    }

    fn snap() -> Snapshot {
        let e = |name: &str, claims| ExperimentClaims {
            experiment: name.into(),
            mode: "quick".into(),
            seed: 1,
            git_commit: "abc".into(),
            claims,
        };
        Snapshot {
            commands: vec!["mcbench run".into()],
            experiments: vec![
                e(
                    "x",
                    vec![
                        claim("paper 002 Fig. 9: a", "eq21", 28.3, Verdict::Held, ""),
                        claim("paper 002 Fig. 9: a", "perlin", 6.8, Verdict::Held, ""),
                        claim("paper 002 Fig. 9: a", "other", 0.5, Verdict::NotHeld, ""),
                        claim("paper 004 §7: <b>", "env", 0.17, Verdict::NotHeld, "measured"),
                    ],
                ),
                e(
                    "sensitivity",
                    vec![
                        claim("paper 002: h (against v)", "eq21", 1.0, Verdict::Inconclusive, ""),
                        claim("paper 003: t (against d)", "checker", 1.4, Verdict::Held, "measured"),
                    ],
                ),
            ],
        }
    }

    #[test]
    fn rows_merge_same_verdicts_mark_time_and_escape() {
        let t = table(&snap());
        assert!(
            t.contains(
                "| 002 | x | paper 002 Fig. 9: a | eq21, perlin | 28.3 [25.47, 31.13]; 6.8 [6.12, 7.48] | held |"
            ),
            "{t}"
        );
        assert!(t.contains("| 002 | x | paper 002 Fig. 9: a | other | 0.5 [0.45, 0.55] | not held |"), "{t}");
        assert!(t.contains("| 004 | x | paper 004 §7: &lt;b&gt; (time) |"), "{t}");
        assert!(t.contains("(time): the value divides by measured CPU seconds"));
        assert!(t.contains("| 002 | paper 002: h (against v) | 1 [0.9, 1.1]: inconclusive | n \\| m |"), "{t}");
        assert!(t.contains("| 003 | paper 003: t (against d) (time) | 1.4 [1.26, 1.54]: held |"), "{t}");
        // the note on timed values follows both tables
        assert!(t.find("(time): the value").unwrap() > t.find("Where each claim holds").unwrap(), "{t}");
    }

    #[test]
    fn rewrite_replaces_only_the_generated_part_and_reads_it_back() {
        let readme = format!("intro\n{BEGIN}\nold table\n{END}\noutro\n");
        let new = rewrite(&readme, "new table\n").unwrap();
        assert_eq!(new, format!("intro\n{BEGIN}\n\nnew table\n\n{END}\noutro\n"));
        assert_eq!(current(&new).unwrap(), "new table");
        assert!(matches!(rewrite("no markers", "t"), Err(TableError::NoMarkers)));
        assert_eq!(paper_of("paper 003 Table 1"), "003");
        assert_eq!(paper_of("harness: every cell"), "-");
    }
}
