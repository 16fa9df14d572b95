//! `unbiasedness --repetitions rounds` end to end on a small selection: bit-identical tables at 1
//! and 2 threads, the planted biased control flagged, a row stopped at `R` repetitions equal to
//! the fixed mode's row at `--reps R`, and a share of the budget (`--rounds-budget`) bounding the
//! work the rounds spend.

use mcbench::registry::Registry;
use std::path::Path;

/// Runs `unbiasedness` on gradient-plane with an unbiased estimator and a biased control into
/// `root`, with `extra` arguments; returns the table's rows as maps of column to value.
fn table(root: &Path, extra: &[&str]) -> Vec<std::collections::BTreeMap<String, String>> {
    let (results, plots) = (root.join("results"), root.join("plots"));
    let mut args = vec![
        "mcbench",
        "run",
        "unbiasedness",
        "--testbeds",
        "gradient-plane",
        "--estimators",
        "is0_cv0,clamped_is0_cv0",
        "--no-plots",
        "--integrals",
        "none",
        "--results",
        results.to_str().expect("utf8"),
        "--plots",
        plots.to_str().expect("utf8"),
    ];
    args.extend_from_slice(extra);
    assert_eq!(mcbench::cli::main_with_args(Registry::new().with_catalog(mcbench_papers::catalog()), args), 0);
    let mut rd = csv::Reader::from_path(results.join("unbiasedness/unbiasedness.csv")).expect("table");
    rd.deserialize().map(|r| r.expect("row")).collect()
}

/// The `columns` of `is0_cv0`'s summary row on `variant`.
fn summary(root: &Path, variant: &str, columns: &[&str]) -> Vec<String> {
    let mut rd = csv::Reader::from_path(root.join("results/unbiasedness/summary.csv")).expect("summary");
    let rows: Vec<std::collections::BTreeMap<String, String>> = rd.deserialize().map(|r| r.expect("row")).collect();
    let row = rows.iter().find(|r| r["estimator"] == "is0_cv0" && r["variant"] == variant).expect("summary row");
    columns.iter().map(|c| row[*c].clone()).collect()
}

#[test]
fn rounds_are_deterministic_flag_the_control_and_stop_where_the_fixed_mode_would_run() {
    let dirs: Vec<tempfile::TempDir> = (0..3).map(|_| tempfile::tempdir().expect("tempdir")).collect();
    let rounds = ["--repetitions", "rounds", "--reps", "256"];
    let one = table(dirs[0].path(), &[&rounds[..], &["--threads", "1"]].concat());
    let two = table(dirs[1].path(), &[&rounds[..], &["--threads", "2"]].concat());
    assert_eq!(one, two, "the same table at 1 and 2 threads");
    assert_eq!(one.len(), 8, "4 variants x 2 estimators");
    let look_alpha = mcbench::unbiasedness::rounds::look_alpha();
    assert!(
        one.iter().all(|r| r["repetitions"] == "rounds" && r["decision_alpha"].parse::<f64>() == Ok(look_alpha)),
        "{one:?}"
    );
    for control in one.iter().filter(|r| r["estimator"].starts_with("clamped_is0_cv0")) {
        assert_eq!(control["verdict"], "biased", "{control:?}");
    }
    // The row that ran the most rounds.
    let row = one
        .iter()
        .filter(|r| r["estimator"] == "is0_cv0")
        .max_by_key(|r| r["rounds"].parse::<usize>().expect("rounds"))
        .expect("unbiased row");
    let reps: usize = row["reps"].parse().expect("reps");
    let looks: usize = row["rounds"].parse().expect("rounds");
    assert_eq!(reps, 64 << (looks - 1), "{row:?}");
    assert!(looks > 1, "a row grew past its first round: {one:?}");
    // The same row in the fixed mode at the repetitions it stopped at: the same cell.
    let fixed = table(dirs[2].path(), &["--reps", &reps.to_string(), "--threads", "2"]);
    let same = fixed.iter().find(|r| r["estimator"] == "is0_cv0" && r["variant"] == row["variant"]).expect("fixed row");
    assert_eq!(same["repetitions"], "fixed");
    for column in ["reps", "rel_bias", "rel_bias_se", "budget"] {
        assert_eq!(row[column], same[column], "{column}");
    }
    let columns = ["reps", "mse", "variance", "bias"];
    let variant = &row["variant"];
    assert_eq!(summary(dirs[0].path(), variant, &columns), summary(dirs[2].path(), variant, &columns));
}

/// The work the rounds spent and the fixed mode's work, from the run's note in summary.json
/// (`work S of the fixed mode's F`, or `work S of the budget B (share X of the fixed mode's F)`).
fn work(root: &Path) -> (u64, u64) {
    let text = std::fs::read_to_string(root.join("results/unbiasedness/summary.json")).expect("summary.json");
    let summary: serde_json::Value = serde_json::from_str(&text).expect("json");
    let notes = summary["meta"]["notes"].as_array().expect("notes");
    let note = notes.iter().filter_map(|n| n.as_str()).find(|n| n.contains("rounds: ")).expect("rounds note");
    let number_after = |key: &str| -> u64 {
        let at = note.find(key).unwrap_or_else(|| panic!("'{key}' in {note}")) + key.len();
        note[at..].split(|c: char| !c.is_ascii_digit()).next().and_then(|d| d.parse().ok()).expect(note)
    };
    (number_after("work "), number_after("of the fixed mode's "))
}

#[test]
fn a_share_of_the_budget_bounds_the_work_of_the_rounds_whatever_the_threads() {
    let dirs: Vec<tempfile::TempDir> = (0..3).map(|_| tempfile::tempdir().expect("tempdir")).collect();
    let share = ["--repetitions", "rounds", "--rounds-budget", "0.3"];
    let one = table(dirs[0].path(), &[&share[..], &["--threads", "1"]].concat());
    let two = table(dirs[1].path(), &[&share[..], &["--threads", "2"]].concat());
    assert_eq!(one, two, "the same table at 1 and 2 threads");
    assert_eq!(work(dirs[0].path()), work(dirs[1].path()), "the same work at 1 and 2 threads");
    let whole = table(dirs[2].path(), &["--repetitions", "rounds", "--threads", "2"]);
    let ((spent, fixed), (whole_spent, whole_fixed)) = (work(dirs[0].path()), work(dirs[2].path()));
    assert_eq!(fixed, whole_fixed, "the same fixed-mode work");
    assert!(spent as f64 <= 0.3 * fixed as f64, "spent {spent} of a share 0.3 of {fixed}");
    assert!(spent < whole_spent, "spent {spent} at a share 0.3, {whole_spent} at the whole budget");
    let rows = |t: &[std::collections::BTreeMap<String, String>]| -> Vec<(String, String)> {
        t.iter().map(|r| (r["estimator"].clone(), r["variant"].clone())).collect()
    };
    assert_eq!(rows(&one), rows(&whole), "the same rows in the same order");
    for control in one.iter().filter(|r| r["estimator"].starts_with("clamped_is0_cv0")) {
        assert_eq!(control["verdict"], "biased", "{control:?}");
    }
}
