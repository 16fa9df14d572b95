//! The long tables of a run as CSV files in its results folder, so that the summary (`report.md`)
//! and the HTML page can link to every row instead of repeating it: `tests.csv` (every test row
//! of summary.json's `tests`) and `claims.csv` (every claim of its `paper`, the interval as two
//! columns).

use crate::error::Result;
use crate::output::{Claim, RunReport};
use crate::store::folder::OutputDir;
use serde::Serialize;

/// The file of every test row.
pub const TESTS_CSV: &str = "tests.csv";
/// The file of every claim.
pub const CLAIMS_CSV: &str = "claims.csv";

/// One row of `claims.csv`.
#[derive(Serialize)]
struct ClaimRow<'a> {
    testbed: &'a str,
    claim: &'a str,
    paper_value: Option<f64>,
    our_value: Option<f64>,
    interval_low: Option<f64>,
    interval_high: Option<f64>,
    verdict: &'a str,
    pair: &'a str,
    regime: &'a str,
    reason: &'a str,
    note: &'a str,
    p_value: Option<f64>,
}

impl<'a> From<&'a Claim> for ClaimRow<'a> {
    fn from(c: &'a Claim) -> Self {
        ClaimRow {
            testbed: &c.testbed,
            claim: &c.claim,
            paper_value: c.paper_value,
            our_value: c.our_value,
            interval_low: c.interval.map(|i| i[0]),
            interval_high: c.interval.map(|i| i[1]),
            verdict: c.verdict().as_str(),
            pair: &c.pair,
            regime: &c.regime,
            reason: &c.reason,
            note: &c.note,
            p_value: c.p_value,
        }
    }
}

/// Writes `tests.csv` and `claims.csv` into a run's results folder (atomically, recorded for its
/// commit). Neither holds a time-based column beyond what summary.json holds.
pub fn write_tables(results: &OutputDir, report: &RunReport) -> Result<()> {
    write_or_header(results, TESTS_CSV, &report.tests, TEST_HEADER)?;
    let claims: Vec<ClaimRow> = report.paper.iter().map(ClaimRow::from).collect();
    write_or_header(results, CLAIMS_CSV, &claims, CLAIM_HEADER)
}

fn write_or_header<T: Serialize>(results: &OutputDir, name: &str, rows: &[T], header: &[&str]) -> Result<()> {
    if rows.is_empty() {
        let line = format!("{}\n", header.join(","));
        results.write(name, line.as_bytes()).map(|_| ())
    } else {
        results.write_csv(name, rows).map(|_| ())
    }
}

const TEST_HEADER: &[&str] = &[
    "testbed",
    "variant",
    "estimator",
    "test",
    "budget",
    "statistic",
    "p_value",
    "verdict",
    "alpha",
    "detectable_rel_bias",
    "claim",
    "agrees",
    "untested",
    "tolerance",
    "reps_needed",
    "gate",
    "rel_bias",
    "rel_bias_se",
    "reason",
    "spread",
];

const CLAIM_HEADER: &[&str] = &[
    "testbed",
    "claim",
    "paper_value",
    "our_value",
    "interval_low",
    "interval_high",
    "verdict",
    "pair",
    "regime",
    "reason",
    "note",
    "p_value",
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::plot::tests::synthetic_report;

    fn header(path: &std::path::Path) -> Vec<String> {
        let mut rd = csv::Reader::from_path(path).expect("csv");
        rd.headers().expect("header").iter().map(String::from).collect()
    }

    #[test]
    fn every_test_and_claim_gets_a_row_and_empty_tables_keep_their_header() {
        let dir = tempfile::tempdir().expect("tempdir");
        let out = OutputDir::new(dir.path());
        let mut report = synthetic_report();
        report.paper[0].interval = Some([1.5, 2.5]);
        write_tables(&out, &report).expect("written");
        let tests = dir.path().join(TESTS_CSV);
        assert_eq!(header(&tests), TEST_HEADER, "the header written from rows is the empty table's");
        assert_eq!(csv::Reader::from_path(&tests).expect("csv").records().count(), report.tests.len());
        let claims = dir.path().join(CLAIMS_CSV);
        assert_eq!(header(&claims), CLAIM_HEADER);
        let text = std::fs::read_to_string(&claims).expect("claims");
        assert!(text.contains(",1.5,2.5,"), "{text}");

        report.tests.clear();
        report.paper.clear();
        write_tables(&out, &report).expect("written");
        assert_eq!(header(&tests), TEST_HEADER);
        assert_eq!(header(&claims), CLAIM_HEADER);
    }
}
