//! A built-in estimator is one file plus one line in the built-ins list: in a copy of the
//! workspace (the files `git ls-files` names), a throw-away estimator file is written into a family
//! folder of the papers' crate (with the `pub mod` line Rust needs in that family's `mod.rs`) and
//! one line is added to `ESTIMATORS` (estimators/src/builtins.rs). Nothing else is edited, and in
//! that copy:
//!
//! - `mcbench list estimators` shows it with its display name;
//! - `mcbench conformance --estimators <id>` passes;
//! - `cargo test -p mcbench-papers --lib` passes;
//! - `cargo test -p experiments --test pinned` fails only because the new estimator is not pinned,
//!   with a message naming `MCBENCH_REPIN=1`; re-pinned with that command it passes, and the pins
//!   file gains exactly the new estimator's line.
//!
//! It builds the copy (minutes), so it is ignored by default and run by hand (book: extending.md):
//! `cargo test -p experiments --test one_file_one_line -- --ignored`. The copy and its builds live
//! under `<target dir>/one-file-one-line/`, so a rerun is incremental: files whose contents did not
//! change keep their modification times.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The throw-away estimator's id.
const ID: &str = "one_file_probe";

/// Its display name (what `mcbench list estimators` must show).
const DISPLAY: &str = "one-file probe (cosine importance sampling)";

/// The family folder the file goes into, and the file.
const FAMILY: &str = "estimators/src/independent";
const FILE: &str = "estimators/src/independent/one_file_probe.rs";

/// The estimator file: cosine-weighted hemisphere sampling (the book's example estimator).
const ESTIMATOR: &str = r#"//! `one_file_probe`: cosine-weighted hemisphere sampling, f / p averaged over the budget.

use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::{Frame, Rgb};
use mcbench_core::params::{parse, NoParams, ParamSpec};
use mcbench_core::rng::StreamRng;
use mcbench_core::samplers::cosine_hemisphere;
use mcbench_core::task::Task;
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "one_file_probe",
    paper: "harness",
    label: "one-file probe",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE,
    samplers: &["cosine_hemisphere"],
    summary: "cosine-weighted hemisphere sampling",
    build: |params| {
        parse::<NoParams>("one_file_probe", params)?;
        Ok(Box::new(OneFileProbe))
    },
    params: ParamSpec::NONE.display("one-file probe (cosine importance sampling)"),
    checks: Checks::DEFAULT,
};

/// The estimator (no parameters).
pub struct OneFileProbe;

impl Estimator for OneFileProbe {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.hemisphere().ok_or(EstimateError::Refused("needs a surface".into()))?;
        let frame = Frame::around(probe.point().normal);
        let (mut sum, mut n) = (Rgb::ZERO, 0u64);
        while task.more() {
            let local = cosine_hemisphere::sample_local(rng);
            sum += probe.integrand(frame.to_world(local)) / cosine_hemisphere::pdf(local.z);
            n += 1;
        }
        Ok(sum / n as f64)
    }
}
"#;

/// The repository root (the experiments package is one folder below it).
fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..").canonicalize().expect("the repository root")
}

/// `<target dir>/one-file-one-line`: beside the real builds, so reruns reuse the copy's builds.
fn work_dir() -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).parent().expect("the target dir").join("one-file-one-line")
}

fn text(o: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr))
}

/// The files of the workspace: tracked ones and new ones not ignored, that exist.
fn sources(repo: &Path) -> Vec<PathBuf> {
    let out = Command::new("git")
        .args(["ls-files", "-z", "--cached", "--others", "--exclude-standard"])
        .current_dir(repo)
        .output()
        .expect("git runs");
    assert!(out.status.success(), "git ls-files: {}", text(&out));
    let mut files: Vec<PathBuf> = out
        .stdout
        .split(|b| *b == 0)
        .filter(|p| !p.is_empty())
        .map(|p| PathBuf::from(String::from_utf8_lossy(p).into_owned()))
        .filter(|p| repo.join(p).is_file())
        .collect();
    files.sort();
    files.dedup();
    files
}

/// Writes `bytes` to `path` unless it already holds them (an unchanged file keeps its
/// modification time, so cargo does not rebuild it).
fn write_if_changed(path: &Path, bytes: &[u8]) {
    if std::fs::read(path).is_ok_and(|b| b == bytes) {
        return;
    }
    std::fs::create_dir_all(path.parent().expect("a parent")).expect("folder");
    std::fs::write(path, bytes).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
}

/// `text` with `line` inserted after the first line that contains `after`.
fn insert_after(text: &str, after: &str, line: &str) -> String {
    let at = text.find(after).unwrap_or_else(|| panic!("no `{after}`"));
    let end = at + text[at..].find('\n').expect("a line end") + 1;
    format!("{}{line}\n{}", &text[..end], &text[end..])
}

/// The copy: every source file, with the new file, its `mod` line and the built-ins line.
/// Returns the edited files (paths relative to the root) for the check that nothing else changed.
fn make_copy(repo: &Path, copy: &Path) -> Vec<String> {
    let files = sources(repo);
    let mut edited = BTreeMap::new();
    let family_mod = format!("{FAMILY}/mod.rs");
    let family = std::fs::read_to_string(repo.join(&family_mod)).expect("the family's mod.rs");
    edited.insert(family_mod, insert_after(&family, "pub mod is0_cv0;", "pub mod one_file_probe;"));
    let builtins = std::fs::read_to_string(repo.join("estimators/src/builtins.rs")).expect("builtins.rs");
    let line = "    &crate::independent::one_file_probe::ENTRY,";
    edited.insert(
        "estimators/src/builtins.rs".to_string(),
        insert_after(&builtins, "&crate::independent::clamped_is0_cv0::ENTRY,", line),
    );
    edited.insert(FILE.to_string(), ESTIMATOR.to_string());
    let mut wanted: Vec<PathBuf> = files.clone();
    wanted.push(PathBuf::from(FILE));
    for f in &files {
        let bytes = match edited.get(f.to_string_lossy().as_ref()) {
            Some(t) => t.clone().into_bytes(),
            None => std::fs::read(repo.join(f)).expect("a source file"),
        };
        write_if_changed(&copy.join(f), &bytes);
    }
    write_if_changed(&copy.join(FILE), ESTIMATOR.as_bytes());
    // Files of an earlier copy that the workspace no longer has go (build folders aside).
    remove_stale(copy, copy, &wanted);
    // Each edit is the one intended: one line more in each edited file, the new file whole.
    for (f, t) in &edited {
        if f != FILE {
            let before = std::fs::read_to_string(repo.join(f)).expect("source");
            assert_eq!(t.lines().count(), before.lines().count() + 1, "{f}: one line added");
        }
    }
    edited.into_keys().collect()
}

fn remove_stale(root: &Path, dir: &Path, wanted: &[PathBuf]) {
    for e in std::fs::read_dir(dir).expect("read the copy").flatten() {
        let path = e.path();
        let rel = path.strip_prefix(root).expect("inside").to_path_buf();
        if path.is_dir() {
            if rel != Path::new(".git") {
                remove_stale(root, &path, wanted);
            }
        } else if !wanted.contains(&rel) {
            std::fs::remove_file(&path).expect("remove a stale file");
        }
    }
}

/// Runs `cargo <args>` in the copy with the copy's target dir; `env` adds variables.
fn cargo(copy: &Path, target: &Path, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO"));
    c.args(args).current_dir(copy).env("CARGO_TARGET_DIR", target).env_remove("MCBENCH_REPIN");
    for (k, v) in env {
        c.env(k, v);
    }
    let started = std::time::Instant::now();
    let out = c.output().expect("cargo runs");
    eprintln!("cargo {} ({:.0} s)", args.join(" "), started.elapsed().as_secs_f64());
    out
}

#[test]
#[ignore = "copies the workspace and builds the copy: minutes; run by hand with --ignored (book: extending.md)"]
fn a_built_in_estimator_is_one_file_and_one_line() {
    let started = std::time::Instant::now();
    let repo = repo();
    let work = work_dir();
    let (copy, target) = (work.join("workspace"), work.join("target"));
    let edited = make_copy(&repo, &copy);
    eprintln!("copied {} with {} edited: {}", repo.display(), edited.join(", "), copy.display());
    // Every run starts from the repository's pins.
    let pins = "tests/pinned_estimates.json";
    let original = std::fs::read(repo.join(pins)).expect("the pins");
    std::fs::write(copy.join(pins), &original).expect("restore the pins");

    // The binary, built in the test profile like the test builds below (one build of the crates).
    let build = cargo(
        &copy,
        &target,
        &["build", "--offline", "-q", "--profile", "test", "-p", "experiments", "--bin", "mcbench"],
        &[],
    );
    assert!(build.status.success(), "cargo build: {}", text(&build));
    let run = |args: &[&str]| {
        let out = Command::new(target.join("debug").join("mcbench")).args(args).current_dir(&copy).output();
        out.expect("mcbench runs")
    };

    // Listed, with its display name.
    let list = run(&["list", "estimators"]);
    assert!(list.status.success(), "mcbench list estimators: {}", text(&list));
    let listed = String::from_utf8_lossy(&list.stdout);
    let line = listed.lines().find(|l| l.contains(ID)).unwrap_or_else(|| panic!("{ID} not listed:\n{listed}"));
    assert!(line.contains(DISPLAY), "{ID} listed without its display name: {line}");

    // Conformance.
    let conf = run(&["conformance", "--estimators", ID]);
    assert!(conf.status.success(), "mcbench conformance --estimators {ID}: {}", text(&conf));

    // The papers' crate's own tests.
    let lib = cargo(&copy, &target, &["test", "--offline", "-q", "-p", "mcbench-papers", "--lib"], &[]);
    assert!(lib.status.success(), "cargo test -p mcbench-papers --lib: {}", text(&lib));

    // The pins: only the new estimator is missing, and the message names the command.
    let pinned = ["test", "--offline", "-q", "-p", "experiments", "--test", "pinned"];
    let first = cargo(&copy, &target, &pinned, &[]);
    let said = text(&first);
    assert!(!first.status.success(), "the pinned test passed without a pin for {ID}:\n{said}");
    assert!(said.contains("MCBENCH_REPIN=1 cargo test -p experiments --test pinned"), "{said}");
    assert!(said.contains("test result: FAILED. ") && said.contains(" 1 failed;"), "more than one failure:\n{said}");
    let diffs: Vec<&str> = said
        .lines()
        .filter(|l| l.contains(": pinned ") || l.contains(": not pinned yet") || l.contains("no longer registered"))
        .collect();
    assert_eq!(diffs.len(), 1, "{diffs:?}");
    assert!(diffs[0].starts_with(&format!("{ID}: not pinned yet")), "{diffs:?}");

    // Re-pinned with the command the message names, it passes, and only the new line is new.
    let repin = cargo(&copy, &target, &pinned, &[("MCBENCH_REPIN", "1")]);
    assert!(repin.status.success(), "re-pin: {}", text(&repin));
    let again = cargo(&copy, &target, &pinned, &[]);
    assert!(again.status.success(), "after the re-pin: {}", text(&again));
    let read = |b: &[u8]| serde_json::from_slice::<BTreeMap<String, String>>(b).expect("pins parse");
    let (before, mut after) = (read(&original), read(&std::fs::read(copy.join(pins)).expect("the new pins")));
    assert!(after.remove(ID).is_some(), "{ID} not pinned");
    assert_eq!(before, after, "the re-pin changed another estimator's pin");
    eprintln!("one file + one line: {:.0} s", started.elapsed().as_secs_f64());
}
