//! Property tests of bad input (SPEC §9, issue 9 item 4): random edits of a valid sweep file and
//! of a valid `summary.json` never panic, and every rejection is one non-empty line that names the
//! field (or the file and its position) and maps to exit code 2 (`tests/cli.rs` checks that the
//! binary exits with the mapped code).

use experiments::config::{Mode, SweepFile};
use experiments::error::HarnessError;
use experiments::execute::{execute, prepare, ExecOptions};
use experiments::output::read_results;
use experiments::runner::Silent;
use proptest::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

const SMALL: &str = "name = 'tiny'\nreps = 3\nbudgets = [4, 16, 64]\n[[testbeds]]\nid = 'gradient-plane'\nparams = { resolution = 4 }\n[[estimators]]\nid = 'is0_cv0'\n[[estimators]]\nid = 'clamped_is0_cv0'\nparams = { clamp = 1.5 }\n";

/// Characters that make structural edits likely to parse (digits, quotes, brackets, names).
const ALPHABET: &[u8] = b"0123456789-.e'\"[]{}=,\n #abcdefghijklmnopqrstuvwxyz_";

/// Applies `edits` (position, byte index into ALPHABET, kind: 0 delete, 1 insert, 2 replace).
fn mutate(text: &str, edits: &[(usize, usize, u8)]) -> String {
    let mut b = text.as_bytes().to_vec();
    for &(pos, ch, kind) in edits {
        if b.is_empty() {
            break;
        }
        let (i, c) = (pos % b.len(), ALPHABET[ch % ALPHABET.len()]);
        match kind {
            0 => {
                b.remove(i);
            }
            1 => b.insert(i, c),
            _ => b[i] = c,
        }
    }
    String::from_utf8_lossy(&b).to_string()
}

/// Names an error message may point at: the sweep file's fields, the ids and parameters of the
/// small sweeps below, and the result files' columns. Matched as whole words, so `valid` is not
/// `id`; the file name alone does not count (see [`names_a_position`]).
const FIELDS: &[&str] = &[
    "name",
    "seed",
    "reps",
    "budget_kind",
    "budgets",
    "budget",
    "baseline",
    "testbeds",
    "testbed",
    "estimators",
    "estimator",
    "id",
    "params",
    "variant",
    "resolution",
    "clamp",
];

/// Whether `msg` names one of [`FIELDS`] as a whole word (a path counts by its file name).
fn names_a_field(msg: &str) -> bool {
    msg.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == '-'))
        .map(|w| w.rsplit('/').next().unwrap_or(w).trim_end_matches('.'))
        .any(|w| FIELDS.contains(&w))
}

/// Whether a parse error names the file and the line where it went wrong (TOML errors also quote
/// that line, whose key is the field; JSON errors give line and column).
fn names_a_position(msg: &str) -> bool {
    let file = msg.split(':').next().unwrap_or("");
    (file.ends_with(".toml") || file.ends_with(".json")) && msg.contains("line ")
}

/// `Ok(())` when `f` neither panicked nor failed with anything but bad input (exit code 2) in one
/// non-empty line that names the field or file.
fn rejected_well<T>(f: impl FnOnce() -> Result<T, HarnessError>) -> Result<(), String> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Err(_) => Err("panicked".into()),
        Ok(Ok(_)) => Ok(()),
        Ok(Err(e)) => {
            let msg = e.to_string();
            if msg.trim().is_empty() || msg.trim_end().lines().count() != 1 {
                Err(format!("not one line: {msg:?}"))
            } else if e.exit_code() != 2 {
                Err(format!("exit code {} for bad input: {msg}", e.exit_code()))
            } else if !names_a_field(&msg) && !names_a_position(&msg) {
                Err(format!("names no field: {msg}"))
            } else {
                Ok(())
            }
        }
    }
}

#[test]
fn the_field_check_has_teeth() {
    assert!(names_a_field("reps = 0: at least 2 repetitions are needed"));
    assert!(names_a_position("/tmp/x/sweep.toml: line 2, column 7: invalid array (in `reps = [`)"));
    assert!(!names_a_field("/tmp/x/sweep.toml: invalid array"));
    assert!(!names_a_position("/tmp/x/sweep.toml: invalid array"));
    assert!(!names_a_field("something is invalid"));
    assert!(!names_a_field("the value 3 is out of range"));
}

fn check_config(dir: &Path, text: &str, ext: &str) -> Result<(), String> {
    let path = dir.join(format!("sweep.{ext}"));
    std::fs::write(&path, text).map_err(|e| e.to_string())?;
    rejected_well(|| SweepFile::read(&path).and_then(|f| f.apply(None, Mode::Quick)).and_then(|s| s.validate()))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn edited_sweep_files_never_panic_and_fail_in_one_line(
        edits in prop::collection::vec((0usize..10_000, 0usize..64, 0u8..3), 1..8)
    ) {
        let dir = tempfile::tempdir().expect("tempdir");
        let text = mutate(SMALL, &edits);
        prop_assert_eq!(check_config(dir.path(), &text, "toml"), Ok(()), "{}", text);
    }

    #[test]
    fn edited_json_sweep_files_never_panic_and_fail_in_one_line(
        edits in prop::collection::vec((0usize..10_000, 0usize..64, 0u8..3), 1..8)
    ) {
        let dir = tempfile::tempdir().expect("tempdir");
        let json = r#"{"name": "tiny", "reps": 3, "budgets": [4, 16], "testbeds": [{"id": "gradient-plane", "params": {"resolution": 4}}], "estimators": [{"id": "is0_cv0"}]}"#;
        let text = mutate(json, &edits);
        prop_assert_eq!(check_config(dir.path(), &text, "json"), Ok(()), "{}", text);
    }
}

/// A tiny real run, then random edits of its summary.json: `read_results` (what `mcbench plot`
/// reads) never panics and rejects in one line.
#[test]
fn edited_result_files_never_panic_and_fail_in_one_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, SMALL).expect("write");
    let sweep = SweepFile::read(&config).and_then(|f| f.apply(None, Mode::Quick)).expect("valid sweep");
    let plan = prepare(sweep).expect("plan");
    let opts = ExecOptions {
        results_root: dir.path().join("results"),
        plots_root: dir.path().join("plots"),
        threads: Some(1),
        observer: &Silent,
        plots: false,
    };
    execute(&plan, None, &opts).expect("runs");
    let res = dir.path().join("results/tiny");
    let original = std::fs::read_to_string(res.join("summary.json")).expect("summary.json");
    read_results(&res).expect("the untouched files read back");
    let mut runner = proptest::test_runner::TestRunner::new(ProptestConfig {
        cases: 300,
        failure_persistence: None,
        ..ProptestConfig::default()
    });
    let strategy = prop::collection::vec((0usize..1_000_000, 0usize..64, 0u8..3), 1..6);
    runner
        .run(&strategy, |edits| {
            let copy = dir.path().join("copy");
            std::fs::create_dir_all(&copy).expect("dir");
            std::fs::copy(res.join("summary.csv"), copy.join("summary.csv")).expect("csv");
            std::fs::write(copy.join("summary.json"), mutate(&original, &edits)).expect("json");
            prop_assert_eq!(rejected_well(|| read_results(&copy)), Ok(()));
            Ok(())
        })
        .expect("no edit makes the reader panic or fail in more than one line");
}
