//! Property tests of bad input (book: cli.md): random edits of every kind of file the harness reads (a
//! sweep file in TOML or JSON, `summary.json`, a stored cell, a shard manifest, a stored
//! reference) never panic, and every rejection is one non-empty line that names the field (or the
//! file, and for parse errors its position) and maps to exit code 2 (`tests/cli.rs` and
//! `tests/promises.rs` check that the binary exits with the mapped code).

use mcbench::config::{Mode, SweepFile};
use mcbench::error::HarnessError;
use mcbench::output::{read_results, read_results_unverified};
use mcbench::run::execute::{execute, ExecOptions};
use mcbench::run::runner::Silent;
use mcbench::store::Store;
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
    "version",
    "format",
    "config",
    "shard",
    "experiment",
    "merge",
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

/// Whether a refusal of a file's content names that file (`<path>.json: why`).
fn names_the_file(msg: &str, file: &str) -> bool {
    msg.split(':').next().is_some_and(|p| p.ends_with(file))
}

/// As [`rejected_well`], for a file read back: the refusal may name the file instead of a field.
fn file_rejected_well<T>(file: &str, f: impl FnOnce() -> Result<T, HarnessError>) -> Result<(), String> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Err(_) => Err("panicked".into()),
        Ok(Ok(_)) => Ok(()),
        Ok(Err(e)) => {
            let msg = e.to_string();
            if msg.trim().is_empty() || msg.trim_end().lines().count() != 1 {
                Err(format!("not one line: {msg:?}"))
            } else if e.exit_code() != 2 {
                Err(format!("exit code {} for bad input: {msg}", e.exit_code()))
            } else if !names_the_file(&msg, file) && !names_a_field(&msg) {
                Err(format!("names neither {file} nor a field: {msg}"))
            } else {
                Ok(())
            }
        }
    }
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

/// A tiny finished run of [`SMALL`] in a temp folder: (folder, plan, options' roots).
fn tiny_run() -> (tempfile::TempDir, mcbench::plan::Plan) {
    let dir = tempfile::tempdir().expect("tempdir");
    let config = dir.path().join("tiny.toml");
    std::fs::write(&config, SMALL).expect("write");
    let sweep = SweepFile::read(&config).and_then(|f| f.apply(None, Mode::Quick)).expect("valid sweep");
    let plan = plan_of(sweep).expect("plan");
    execute(&plan, None, &options(dir.path())).expect("runs");
    (dir, plan)
}

fn options(root: &Path) -> ExecOptions<'static> {
    ExecOptions {
        results_root: root.join("results"),
        plots_root: root.join("plots"),
        threads: Some(1),
        observer: &Silent,
        plots: false,
        wait: false,
        registry: registry(),
        integrals: Default::default(),
    }
}

fn runner(cases: u32) -> proptest::test_runner::TestRunner {
    proptest::test_runner::TestRunner::new(ProptestConfig {
        cases,
        failure_persistence: None,
        ..ProptestConfig::default()
    })
}

fn edits() -> impl Strategy<Value = Vec<(usize, usize, u8)>> {
    prop::collection::vec((0usize..1_000_000, 0usize..64, 0u8..3), 1..6)
}

/// Random edits of a finished run's summary.json: what `mcbench plot` reads never panics and
/// rejects in one line; the reader's own checks are exercised with the folder's commit bypassed,
/// and with the commit in place every edit that changed the file is refused as a mixed folder.
#[test]
fn edited_result_files_never_panic_and_fail_in_one_line() {
    let (dir, _) = tiny_run();
    let res = dir.path().join("results/tiny");
    let original = std::fs::read_to_string(res.join("summary.json")).expect("summary.json");
    read_results(&res).expect("the untouched files read back");
    runner(300)
        .run(&edits(), |edits| {
            let copy = dir.path().join("copy");
            std::fs::create_dir_all(&copy).expect("dir");
            for f in ["summary.csv", "integrals.csv.gz", "commit.json"] {
                std::fs::copy(res.join(f), copy.join(f)).expect("copy");
            }
            let edited = mutate(&original, &edits);
            std::fs::write(copy.join("summary.json"), &edited).expect("json");
            prop_assert_eq!(rejected_well(|| read_results_unverified(&copy)), Ok(()));
            let verified = read_results(&copy);
            prop_assert!(edited == original || verified.is_err(), "an edited summary.json passed its commit");
            prop_assert_eq!(file_rejected_well("summary.json", || verified), Ok(()));
            Ok(())
        })
        .expect("no edit makes the reader panic or fail in more than one line");
}

/// Random edits of a stored cell's JSON (inside its record, checksums made good): the resume's
/// check ([`mcbench::run::runner::preload`]) never panics, and refuses in one line naming the cell.
#[test]
fn edited_cells_never_panic_and_fail_in_one_line() {
    let (dir, plan) = tiny_run();
    let path = dir.path().join("results/tiny/cells.store");
    let records = Store::open(&path).expect("store").records().to_vec();
    let name = records[0].name.clone();
    let original = mcbench::store::packed::split(&records[0].payload).expect("a record");
    runner(300)
        .run(&edits(), |edits| {
            let mut parts = original.clone();
            parts.meta = mutate(&original.meta, &edits);
            let mut edited = records.clone();
            edited[0].payload = mcbench::store::packed::join(&parts);
            mcbench::store::write_records(&path, &edited).expect("write");
            prop_assert_eq!(
                file_rejected_well("cells.store", || mcbench::run::runner::preload(&plan, Some(&path))),
                Ok(())
            );
            if let Err(e) = mcbench::run::runner::preload(&plan, Some(&path)) {
                prop_assert!(e.to_string().contains(&name), "the refusal names the cell: {}", e);
            }
            Ok(())
        })
        .expect("no edit makes the resume panic or fail in more than one line");
}

/// Random byte edits of a whole cell store (frames, checksums, compressed payloads): reading it
/// back never panics; it reads (a damaged last record is dropped as a torn tail) or is refused in
/// one line naming the store.
#[test]
fn edited_stores_never_panic_and_fail_in_one_line() {
    let (dir, plan) = tiny_run();
    let path = dir.path().join("results/tiny/cells.store");
    let original = std::fs::read(&path).expect("store");
    let byte_edits = prop::collection::vec((0usize..1_000_000, any::<u8>(), 0u8..3), 1..4);
    runner(300)
        .run(&byte_edits, |edits| {
            let mut b = original.clone();
            for &(pos, byte, kind) in &edits {
                let i = pos % b.len().max(1);
                match kind {
                    0 if !b.is_empty() => drop(b.remove(i)),
                    1 => b.insert(i, byte),
                    _ if !b.is_empty() => b[i] ^= byte | 1,
                    _ => {}
                }
            }
            std::fs::write(&path, &b).expect("write");
            prop_assert_eq!(
                file_rejected_well("cells.store", || mcbench::run::runner::preload(&plan, Some(&path))),
                Ok(())
            );
            Ok(())
        })
        .expect("no edit makes the store's reader panic or fail in more than one line");
}

/// Random edits of a shard manifest: `merge` never panics and refuses in one line naming the
/// manifest or the field.
#[test]
fn edited_manifests_never_panic_and_fail_in_one_line() {
    let (dir, plan) = tiny_run();
    let root = dir.path().join("results");
    let shard = "1/1".parse().expect("spec");
    let pre = mcbench::run::shard::preflight(&plan, shard, &root).expect("preflight");
    mcbench::run::shard::run_shard(&plan, None, pre, Some(1), false, &Silent).expect("shard");
    let folder = root.join("tiny/shard-1-of-1");
    let manifest = folder.join("manifest.json");
    let original = std::fs::read_to_string(&manifest).expect("manifest");
    let out = dir.path().join("merged");
    runner(150)
        .run(&edits(), |edits| {
            std::fs::write(&manifest, mutate(&original, &edits)).expect("write");
            let opts = options(&out);
            let merged = mcbench::run::merge::merge(std::slice::from_ref(&folder), &opts);
            prop_assert_eq!(file_rejected_well("manifest.json", || merged), Ok(()));
            Ok(())
        })
        .expect("no edit makes the merge panic or fail in more than one line");
}

/// Random edits of a stored reference (the gradient-box file of the repository): parsing and
/// checking it against its test bed never panics, and every reference that passes has the test
/// bed's shape and resolution, finite values and non-negative standard errors, all small enough
/// that their squares, which the metrics sum, stay finite.
#[test]
fn edited_references_never_panic_and_pass_only_when_well_formed() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../estimators/references/gradient-box_albedo-0.8.json");
    let original = std::fs::read_to_string(path).expect("stored reference");
    runner(300)
        .run(&edits(), |edits| {
            let text = mutate(&original, &edits);
            let outcome = catch_unwind(AssertUnwindSafe(|| {
                let s: mcbench_core::references::StoredReference =
                    serde_json::from_str(&text).map_err(|e| e.to_string())?;
                s.check(256, (16, 16)).map(|()| s)
            }));
            match outcome {
                Err(_) => prop_assert!(false, "panicked"),
                Ok(Ok(s)) => {
                    let r = &s.reference;
                    prop_assert!(s.resolution == (16, 16) && r.value.len() == 256 && r.std_err.len() == 256);
                    let squared = |x: f64| (x * x * 768.0).is_finite();
                    prop_assert!(r.value.iter().all(|v| v.0.iter().all(|&x| squared(x))));
                    prop_assert!(r.std_err.iter().all(|s| s.0.iter().all(|&x| x >= 0.0 && squared(x))));
                }
                Ok(Err(why)) => prop_assert!(!why.is_empty() && why.lines().count() == 1, "{why}"),
            }
            Ok(())
        })
        .expect("no edit makes the reference check panic");
}

/// The repository's stored references.
const REFERENCES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../estimators/references");

/// The registry of the `mcbench` binary (built-in plug-ins and the paper suite), reading the
/// repository's stored references.
fn registry() -> &'static mcbench::Registry {
    static REGISTRY: std::sync::OnceLock<mcbench::Registry> = std::sync::OnceLock::new();
    REGISTRY.get_or_init(|| {
        experiments::registry().with_references(mcbench::store::references::ReferenceDir::new(REFERENCES))
    })
}

/// Plans a sweep against [`registry`].
fn plan_of(sweep: mcbench::config::Sweep) -> mcbench::error::Result<mcbench::plan::Plan> {
    mcbench::plan::Plan::prepare(sweep, registry())
}
