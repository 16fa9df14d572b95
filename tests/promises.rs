//! The promises of the book's contract chapter under attack, through the binary: a run validates everything
//! before it writes anything (the whole plan, every bound on every input path, output paths, the
//! stored files it will read), refuses in one line naming the field or file with the exit code of
//! the one table, and leaves the results and plots folders byte for byte as they were; folders are
//! locked, committed as a whole and checked when read back.

mod common;
use mcbench::store::Store;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// Every file under `dir/results` and `dir/plots` with its bytes.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.join("results"), dir.join("plots")];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.clone(), std::fs::read(&p).expect("readable"));
            }
        }
    }
    out
}

/// Runs `args` in `dir` and checks the refusal: exit `code`, one line on stderr containing
/// `needle`, no panic, and the results and plots folders byte for byte unchanged.
fn refused(dir: &Path, args: &[&str], code: i32, needle: &str) {
    let before = tree(dir);
    let o = mcbench(dir, args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: not one line: {err}");
    assert!(err.contains(needle), "{args:?}: '{err}' lacks '{needle}'");
    assert!(!err.contains("panicked"), "{err}");
    assert!(tree(dir) == before, "{args:?} changed the results or plots folders");
}

fn ok(dir: &Path, args: &[&str]) -> Output {
    let o = mcbench(dir, args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    o
}

const TINY: &str = "name = 'tiny'\nreps = 3\nbudgets = [4, 16, 64]\nbaseline = 'is0_cv0'\n[[testbeds]]\nid = 'gradient-plane'\nparams = { resolution = 4 }\n[[estimators]]\nid = 'is0_cv0'\n[[estimators]]\nid = 'clamped_is0_cv0'\nparams = { clamp = 1.5 }\n";

/// A folder with a finished run of [`TINY`] (results and plots) and `tiny.toml`.
fn finished() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    std::fs::write(dir.path().join("tiny.toml"), TINY).expect("config");
    ok(dir.path(), &["run", "--config", "tiny.toml", "--threads", "2"]);
    dir
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    std::fs::write(dir.join(name), text).expect("write");
    name.to_string()
}

/// Re-digests `name` in `folder`'s commit.json, as if a run had committed the edited file: what
/// is left to refuse it is the reader's own check of the content.
fn recommit(folder: &Path, name: &str) {
    let path = folder.join("commit.json");
    let mut c: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).expect("commit")).expect("json");
    let bytes = std::fs::read(folder.join(name)).expect("file");
    for f in c["files"].as_array_mut().expect("files") {
        if f["name"] == name {
            f["bytes"] = serde_json::json!(bytes.len());
            f["digest"] = serde_json::json!(mcbench::store::folder::digest(&bytes));
        }
    }
    std::fs::write(&path, serde_json::to_string(&c).expect("json")).expect("write");
}

/// Class 1: a sweep in which nothing can run (a fetch budget on a surface test bed) is refused and
/// leaves a finished run's files alone, whether custom or overriding a named experiment.
#[test]
fn runs_that_can_do_nothing_write_nothing() {
    let dir = finished();
    let d = dir.path();
    let cfg =
        write(d, "fetch.toml", &TINY.replace("budgets = [4, 16, 64]", "budget_kind = 'fetches'\nbudgets = [4, 16]"));
    refused(d, &["run", "--config", &cfg], 2, "no estimator of the sweep can run");
    let over = write(d, "over.toml", "budget_kind = 'fetches'\nbudgets = [10, 20]\n");
    refused(d, &["run", "surface-smc", "--config", &over], 2, "estimators");
}

/// Class 2: cross-references are checked: a baseline that names no estimator of the sweep, or one
/// that runs on none of its test beds; duplicate entries.
#[test]
fn cross_references_are_checked() {
    let dir = finished();
    let d = dir.path();
    let cfg = write(d, "b.toml", &TINY.replace("baseline = 'is0_cv0'", "baseline = 'is9_cv9'"));
    refused(d, &["run", "--config", &cfg], 2, "baseline");
    let cfg = write(
        d,
        "b2.toml",
        &(TINY.replace("baseline = 'is0_cv0'", "baseline = 'delta_tracking'")
            + "[[estimators]]\nid = 'delta_tracking'\n"),
    );
    refused(d, &["run", "--config", &cfg], 2, "baseline");
    let cfg = write(d, "dup.toml", &(TINY.to_string() + "[[estimators]]\nid = 'is0_cv0'\n"));
    refused(d, &["run", "--config", &cfg], 2, "listed twice");
    let cfg = write(
        d,
        "dup2.toml",
        &(TINY.to_string() + "[[testbeds]]\nid = 'gradient-plane'\nvariant = 'default'\nparams = { resolution = 4 }\n"),
    );
    refused(d, &["run", "--config", &cfg], 2, "listed twice");
}

/// Class 3: every count is bounded on every input path: TOML, JSON, and the sweep of a shard
/// manifest given to `merge` (with a digest that matches, so the bound is what refuses it).
#[test]
fn numbers_are_bounded_on_every_input_path() {
    let dir = finished();
    let d = dir.path();
    let cfg = write(d, "r.toml", &TINY.replace("reps = 3", "reps = 1000000000000"));
    refused(d, &["run", "--config", &cfg], 2, "reps");
    let json = r#"{"name":"tiny","reps":1000000000000,"budgets":[4],"testbeds":[{"id":"gradient-plane"}],"estimators":[{"id":"is0_cv0"}]}"#;
    let cfg = write(d, "r.json", json);
    refused(d, &["run", "--config", &cfg], 2, "reps");
    let cfg = write(d, "b.toml", &TINY.replace("[4, 16, 64]", "[4, 18446744073709551000]"));
    refused(d, &["run", "--config", &cfg], 2, "budgets");
    let cfg =
        write(d, "m.toml", &TINY.replace("budgets = [4, 16, 64]", "budget_kind = 'micros'\nbudgets = [4000000000000]"));
    refused(d, &["run", "--config", &cfg], 2, "budgets");
    // A manifest whose sweep asks for 1e12 repetitions, digest and all.
    ok(d, &["run", "--config", "tiny.toml", "--shard", "1/1"]);
    let shard = d.join("results/tiny/shard-1-of-1");
    let path = shard.join("manifest.json");
    let mut m: mcbench::run::shard::Manifest =
        serde_json::from_str(&std::fs::read_to_string(&path).expect("manifest")).expect("parses");
    m.sweep.reps = 1_000_000_000_000;
    m.reps = m.sweep.reps;
    m.sweep_digest = mcbench::run::shard::sweep_digest(&m.sweep);
    std::fs::write(&path, serde_json::to_string(&m).expect("json")).expect("write");
    refused(d, &["merge", "results/tiny/shard-1-of-1"], 2, "reps");
}

/// Class 4: parameter values with huge or tiny exponents run, and no file name grows with them.
#[test]
fn parameter_values_never_become_long_file_names() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    for (name, clamp) in [("big.toml", "1e200"), ("small.toml", "1e-200")] {
        let cfg = write(d, name, &TINY.replace("clamp = 1.5", &format!("clamp = {clamp}")));
        ok(d, &["run", "--config", &cfg, "--no-plots"]);
        let csv = std::fs::read_to_string(d.join("results/tiny/summary.csv")).expect("summary");
        assert!(csv.contains(&format!("clamped_is0_cv0[clamp={clamp}]")), "{csv}");
    }
    for (p, _) in tree(d) {
        let n = p.file_name().and_then(|n| n.to_str()).expect("name").len();
        assert!(n <= 160, "{} is {n} characters long", p.display());
    }
}

/// Class 5: output paths and stored cells are checked before anything is written: `--plots` or
/// `--results` naming a file, and a corrupt cell among cells that are missing (none of the missing
/// ones is recomputed before the refusal).
#[test]
fn outputs_and_stored_cells_are_checked_first() {
    let dir = finished();
    let d = dir.path();
    std::fs::write(d.join("afile"), b"").expect("file");
    refused(d, &["run", "--config", "tiny.toml", "--plots", "afile"], 2, "--plots");
    refused(d, &["run", "--config", "tiny.toml", "--results", "afile"], 2, "--results");
    refused(d, &["reference", "gradient-plane", "--results", "afile"], 2, "--results");
    let store = d.join("results/tiny/cells.store");
    let mut records = Store::open(&store).expect("store").records().to_vec();
    records.sort_by(|a, b| a.name.cmp(&b.name));
    records.drain(..3);
    let corrupt =
        mcbench::store::packed::join(&mcbench::store::packed::Parts { meta: "{\"key\":".into(), columns: Vec::new() });
    records[2].payload = corrupt;
    let name = records[2].name.clone();
    mcbench::store::write_records(&store, &records).expect("rewrite");
    refused(d, &["run", "--config", "tiny.toml"], 2, &name);
    refused(d, &["run", "--config", "tiny.toml"], 2, "cells.store");
}

/// Class 5b: a store a killed writer left with a torn last record is read without it and the
/// next run truncates it before appending; a record damaged in the middle is refused naming the
/// store, and nothing is written.
#[test]
fn a_torn_store_tail_is_dropped_and_a_corrupt_middle_refused() {
    let dir = finished();
    let d = dir.path();
    let store = d.join("results/tiny/cells.store");
    let whole = std::fs::read(&store).expect("store");
    let records = Store::open(&store).expect("store").records().to_vec();
    // The last record cut in half, as SIGKILL during its write leaves it.
    let last = mcbench::store::frame(&records[records.len() - 1].name, &records[records.len() - 1].payload);
    std::fs::write(&store, &whole[..whole.len() - last.len() / 2]).expect("cut");
    let o = ok(d, &["run", "--config", "tiny.toml", "--progress"]);
    assert_eq!(stderr(&o).matches("(resumed)").count(), records.len() - 1, "{}", stderr(&o));
    let again = Store::open(&store).expect("store");
    assert_eq!((again.records().len(), again.torn_bytes()), (records.len(), 0), "truncated, then appended");
    // One flipped byte inside the second record: refused, naming the store and where.
    let mut bad = std::fs::read(&store).expect("store");
    let second =
        mcbench::store::HEADER_LEN + mcbench::store::frame(&again.records()[0].name, &again.records()[0].payload).len();
    bad[second + mcbench::store::FRAME_LEN + 20] ^= 0x40;
    std::fs::write(&store, &bad).expect("damage");
    refused(d, &["run", "--config", "tiny.toml"], 2, "cells.store");
    refused(d, &["run", "--config", "tiny.toml"], 2, &format!("corrupt record at byte {second}"));
    // Deleting the store recomputes every cell (an older folder's cells/ is never read).
    std::fs::remove_file(&store).expect("rm");
    std::fs::create_dir_all(d.join("results/tiny/cells")).expect("old cells folder");
    std::fs::write(d.join("results/tiny/cells/old.json"), "{").expect("old cell");
    let o = ok(d, &["run", "--config", "tiny.toml", "--progress"]);
    assert_eq!(stderr(&o).matches("(resumed)").count(), 0, "{}", stderr(&o));
}

/// Class 6: files read back are checked, and no path comes from their content: `plot` of a
/// summary.json whose experiment name is a path, stored cells of the wrong shape or with no
/// repetitions.
#[test]
fn files_read_back_are_checked() {
    let dir = finished();
    let d = dir.path();
    let res = d.join("results/tiny");
    let json = std::fs::read_to_string(res.join("summary.json")).expect("summary");
    for bad in ["../escape", "/tmp/escape"] {
        std::fs::write(
            res.join("summary.json"),
            json.replace("\"experiment\": \"tiny\"", &format!("\"experiment\": \"{bad}\"")),
        )
        .expect("edit");
        recommit(&res, "summary.json");
        refused(d, &["plot", "results/tiny"], 2, "meta.experiment");
        assert!(!d.join("escape").exists() && !Path::new("/tmp/escape").exists());
    }
    std::fs::write(res.join("summary.json"), &json).expect("restore");
    recommit(&res, "summary.json");
    ok(d, &["plot", "results/tiny"]);
    let store = res.join("cells.store");
    let original = std::fs::read(&store).expect("store");
    let name = Store::open(&store).expect("store").records()[0].name.clone();
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let edits: [(&str, Edit); 4] = [
        ("integrals", Box::new(|v| drop(v["moments"].as_array_mut().expect("m").pop()))),
        (
            "integrals",
            Box::new(|v| {
                let m = v["moments"][0].clone();
                v["moments"].as_array_mut().expect("m").push(m);
            }),
        ),
        (
            "repetitions",
            Box::new(|v| {
                for m in v["moments"].as_array_mut().expect("m") {
                    for c in m.as_array_mut().expect("c") {
                        c["n"] = serde_json::json!(0);
                    }
                }
            }),
        ),
        ("another cell", Box::new(|v| v["key"]["seed"] = serde_json::json!(99))),
    ];
    for (needle, edit) in edits.iter() {
        std::fs::write(&store, &original).expect("restore");
        common::edit_cells(&store, |n, v| {
            if n == name {
                edit(v)
            }
        });
        refused(d, &["run", "--config", "tiny.toml"], 2, needle);
        refused(d, &["run", "--config", "tiny.toml"], 2, &name);
    }
    std::fs::write(&store, original).expect("restore");
    ok(d, &["run", "--config", "tiny.toml"]);
}

/// Class 7: a folder is one run's: a second run into a folder another holds is refused (exit 3)
/// or waits (`--wait`); files of two runs side by side (a run killed between two writes, or
/// another seed's file copied in) are refused by every reader.
#[test]
fn folders_are_locked_and_committed_as_a_whole() {
    let dir = finished();
    let d = dir.path();
    // Another seed's summary.csv beside this run's summary.json: the mix a kill between the two
    // writes leaves.
    let other = tempfile::tempdir().expect("tempdir");
    std::fs::write(other.path().join("tiny.toml"), TINY).expect("config");
    ok(other.path(), &["run", "--config", "tiny.toml", "--seed", "2", "--no-plots"]);
    std::fs::copy(other.path().join("results/tiny/summary.csv"), d.join("results/tiny/summary.csv")).expect("copy");
    refused(d, &["plot", "results/tiny"], 2, "mixed folder");
    refused(d, &["plot", "results/tiny"], 2, "summary.csv");
    // The next run rewrites the folder whole and it reads back again.
    ok(d, &["run", "--config", "tiny.toml"]);
    ok(d, &["plot", "results/tiny"]);
    // A slow run holds the folder: a second run is refused, a waiting one finishes after it.
    let slow = TINY
        .replace("budgets = [4, 16, 64]", "budgets = [4, 16, 64, 256, 1024, 4096, 16384, 65536]")
        .replace("resolution = 4", "resolution = 16");
    write(d, "slow.toml", &slow);
    let mut first = Command::new(env!("CARGO_BIN_EXE_mcbench"))
        .current_dir(d)
        .args(["run", "--config", "slow.toml", "--threads", "1", "--no-plots"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("starts");
    let store = d.join("results/tiny/cells.store");
    let stored = || Store::open(&store).map(|s| s.records().len()).unwrap_or(0);
    let t0 = std::time::Instant::now();
    // The finished run's 6 cells, and a first one of the slow sweep.
    while stored() < 7 && t0.elapsed().as_secs() < 60 {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(first.try_wait().expect("status").is_none(), "the first run finished too soon to be raced");
    let o = mcbench(d, &["run", "--config", "slow.toml", "--threads", "1", "--no-plots"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(stderr(&o).contains("in use by another mcbench run") && stderr(&o).trim_end().lines().count() == 1);
    let o = mcbench(d, &["plot", "results/tiny"]);
    assert_eq!(o.status.code(), Some(3), "a reader waits for the writer: {}", stderr(&o));
    let waited = mcbench(d, &["run", "--config", "slow.toml", "--threads", "1", "--no-plots", "--wait", "--progress"]);
    assert!(first.wait().expect("first run").success());
    assert!(waited.status.success(), "{}", stderr(&waited));
    assert!(stderr(&waited).contains("(resumed)"), "the waiting run resumed the first one's cells");
    ok(d, &["plot", "results/tiny", "--wait"]);
}

/// Class 8: a time budget is calibrated to a sample count by a CPU-time pilot and is the one
/// setting whose results are not promised bit-identical: summary.json says so, and it cannot be
/// split into shards.
#[test]
fn time_budgets_are_reported_as_not_reproducible() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let cfg = write(d, "t.toml", &TINY.replace("budgets = [4, 16, 64]", "budget_kind = 'micros'\nbudgets = [20, 80]"));
    ok(d, &["run", "--config", &cfg, "--no-plots"]);
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("results/tiny/summary.json")).expect("json"))
            .expect("json");
    assert_eq!(meta["meta"]["reproducible"], false);
    assert!(meta["meta"]["notes"].to_string().contains("not bit-reproducible"));
    refused(d, &["run", "--config", &cfg, "--shard", "1/2"], 2, "budget_kind");
    let cfg = write(d, "s.toml", TINY);
    ok(d, &["run", "--config", &cfg, "--no-plots"]);
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("results/tiny/summary.json")).expect("json"))
            .expect("json");
    assert_eq!(meta["meta"]["reproducible"], true);
}

/// Class 9: stale temp files of killed writers are removed by the next run; off a terminal a run
/// prints no progress unless asked, so an error is the only line on stderr; one exit-code table.
#[test]
fn temp_files_progress_and_exit_codes() {
    let dir = finished();
    let d = dir.path();
    let stale = [
        d.join("results/tiny/.summary.csv.tmp-4242"),
        d.join("results/tiny/.cells.store.tmp-4242"),
        d.join("plots/tiny/.report.md.tmp-4242"),
    ];
    for s in &stale {
        std::fs::write(s, b"half").expect("stale temp");
    }
    let o = ok(d, &["run", "--config", "tiny.toml"]);
    assert!(stale.iter().all(|s| !s.exists()), "stale temp files removed");
    assert!(stderr(&o).is_empty(), "no progress off a terminal: {}", stderr(&o));
    let o = ok(d, &["run", "--config", "tiny.toml", "--progress"]);
    assert!(stderr(&o).contains("(resumed)"));
    std::fs::write(d.join("afile"), b"").expect("file");
    // The same mistake (an output path that is a file) is exit 2 in every subcommand.
    refused(d, &["run", "--config", "tiny.toml", "--plots", "afile"], 2, "--plots");
    refused(d, &["plot", "results/tiny", "--plots", "afile"], 2, "--plots");
    ok(d, &["run", "--config", "tiny.toml", "--shard", "1/1"]);
    refused(d, &["merge", "results/tiny", "--results", "afile"], 2, "--results");
    refused(d, &["reference", "gradient-plane", "--results", "afile"], 2, "--results");
}
