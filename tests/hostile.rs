//! The promises of the folders under a hostile user, through the binary: no file outside the
//! folders named is touched (symbolic links planted as lock files or as an experiment's folder
//! are refused and left alone, and what they point to is neither written nor created), every
//! refusal leaves the tree exactly as it was (no new empty folder either), and a stored reference
//! whose numbers would break a metric is refused naming its file and field.
#![cfg(unix)]

use mcbench::store::folder::FolderLock;
use std::collections::BTreeMap;
use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

fn ok(dir: &Path, args: &[&str]) {
    let o = mcbench(dir, args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
}

/// One entry of a tree: a folder, a file with its bytes, or a symbolic link with its target.
#[derive(Debug, PartialEq)]
enum Entry {
    Folder,
    File(Vec<u8>),
    Link(PathBuf),
}

/// Everything under `dir`, folders (empty ones too) and links included, never following a link.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Entry> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("folder") {
            let p = e.expect("entry").path();
            let t = std::fs::symlink_metadata(&p).expect("entry").file_type();
            let entry = if t.is_symlink() {
                Entry::Link(std::fs::read_link(&p).expect("link"))
            } else if t.is_dir() {
                stack.push(p.clone());
                Entry::Folder
            } else {
                Entry::File(std::fs::read(&p).expect("file"))
            };
            out.insert(p.strip_prefix(dir).expect("below").to_path_buf(), entry);
        }
    }
    out
}

/// Runs `args` in `dir` and checks the refusal: exit `code`, one line on stderr containing
/// `needle`, no panic, and everything under `dir` (the outside files the links point to are
/// there too) exactly as it was.
fn refused(dir: &Path, args: &[&str], code: i32, needle: &str) {
    let before = tree(dir);
    let o = mcbench(dir, args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(code), "{args:?} ({needle}): {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: not one line: {err}");
    assert!(err.contains(needle), "{args:?}: '{err}' lacks '{needle}'");
    assert!(!err.contains("panicked"), "{err}");
    let after = tree(dir);
    let changed: Vec<_> = before
        .keys()
        .chain(after.keys())
        .filter(|k| before.get(*k) != after.get(*k))
        .map(|k| k.display().to_string())
        .collect();
    assert!(changed.is_empty(), "{args:?} changed {changed:?}");
}

const TINY: &str = "name = 'tiny'\nreps = 3\nbudgets = [4, 16]\n[[testbeds]]\nid = 'gradient-plane'\nparams = { resolution = 4 }\n[[estimators]]\nid = 'is0_cv0'\n";

/// A folder with `tiny.toml`, a finished run of it (results and plots), its shard 1/1 for
/// `merge`, the references folder, and `outside/precious`: a file no command may touch.
fn finished() -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("tiny.toml"), TINY).expect("config");
    ok(d, &["run", "--config", "tiny.toml", "--threads", "2"]);
    ok(d, &["run", "--config", "tiny.toml", "--shard", "1/1"]);
    std::fs::create_dir_all(d.join("results/references")).expect("references");
    std::fs::create_dir(d.join("outside")).expect("outside");
    std::fs::write(d.join("outside/precious"), b"precious").expect("file");
    dir
}

/// A lock file that is a symbolic link (to a real file, or dangling) is refused with exit
/// 2 naming it, by every command that locks a folder, for results, plots and references folders;
/// the link stays, the file it points to keeps its bytes, a dangling one's target is not created.
#[test]
fn a_linked_lock_file_is_refused_and_left_alone() {
    let dir = finished();
    let d = dir.path();
    let commands: [(&[&str], &[&str]); 4] = [
        (&["run", "--config", "tiny.toml"], &["results/tiny", "plots/tiny"]),
        (&["merge", "results/tiny/shard-1-of-1"], &["results/tiny", "plots/tiny"]),
        (&["reference", "gradient-plane"], &["results/references"]),
        (&["plot", "results/tiny"], &["results/tiny", "plots/tiny"]),
    ];
    for target in [d.join("outside/precious"), d.join("outside/created")] {
        for (args, folders) in commands {
            for folder in folders {
                let lock = d.join(folder).join(".lock");
                symlink(&target, &lock).expect("link");
                refused(d, args, 2, &format!("{folder}/.lock: is a symbolic link"));
                std::fs::remove_file(&lock).expect("unlink");
            }
        }
    }
    assert_eq!(std::fs::read(d.join("outside/precious")).expect("precious"), b"precious");
    assert!(!d.join("outside/created").exists());
    // The same folders with no link in them: every command runs.
    ok(d, &["run", "--config", "tiny.toml"]);
    ok(d, &["merge", "results/tiny/shard-1-of-1"]);
    ok(d, &["reference", "gradient-plane"]);
    ok(d, &["plot", "results/tiny"]);
}

/// A refusal that comes once a lock is taken, or at a lock, leaves no folder behind:
/// `merge` into a folder whose cell store is a folder, and runs refused because another holds
/// the plots folder or the results folder (exit 3), into roots that did not exist.
#[test]
fn refusals_leave_no_new_folder() {
    let dir = finished();
    let d = dir.path();
    std::fs::remove_dir_all(d.join("plots")).expect("no plots yet");
    std::fs::remove_file(d.join("results/tiny/cells.store")).expect("rm");
    std::fs::create_dir(d.join("results/tiny/cells.store")).expect("a folder in its place");
    refused(d, &["merge", "results/tiny/shard-1-of-1"], 2, "cells.store");
    std::fs::remove_dir(d.join("results/tiny/cells.store")).expect("rm");
    // This process holds `new-plots/tiny` as another run would: the run into fresh roots is
    // refused and leaves neither `new-results` nor anything else it made.
    let held = FolderLock::acquire(&d.join("new-plots/tiny"), false, &[]).expect("free");
    let run = ["run", "--config", "tiny.toml", "--results", "new-results", "--plots", "new-plots"];
    refused(d, &run, 3, "new-plots/tiny is in use");
    refused(d, &["merge", "results/tiny/shard-1-of-1", "--plots", "new-plots"], 3, "new-plots/tiny is in use");
    drop(held);
    let held = FolderLock::acquire(&d.join("new-results/tiny"), false, &[]).expect("free");
    refused(d, &run, 3, "new-results/tiny is in use");
    drop(held);
    ok(d, &run);
}

/// An experiment's results or plots folder (or a shard's, or the references folder
/// below a results root) that is a symbolic link, dangling or to a folder elsewhere, is refused
/// with exit 2 naming it, and nothing is written there. A root the user names may be a link.
#[test]
fn links_in_place_of_an_experiment_folder_are_refused() {
    let dir = finished();
    let d = dir.path();
    std::fs::rename(d.join("results/tiny"), d.join("outside/tiny")).expect("move");
    std::fs::rename(d.join("plots/tiny"), d.join("outside/plots-tiny")).expect("move");
    std::fs::create_dir(d.join("outside/empty")).expect("folder");
    let runs: [&[&str]; 3] = [
        &["run", "--config", "tiny.toml"],
        &["run", "--config", "tiny.toml", "--shard", "1/2"],
        &["merge", "outside/tiny/shard-1-of-1"],
    ];
    for target in ["outside/gone", "outside/empty"] {
        symlink(d.join(target), d.join("results/tiny")).expect("link");
        for args in runs {
            refused(d, args, 2, "--results results/tiny: is a symbolic link");
        }
        std::fs::remove_file(d.join("results/tiny")).expect("unlink");
        symlink(d.join(target), d.join("plots/tiny")).expect("link");
        for args in runs.iter().filter(|a| !a.contains(&"--shard")) {
            refused(d, args, 2, "--plots plots/tiny: is a symbolic link");
        }
        refused(d, &["plot", "outside/tiny"], 2, "--plots plots/tiny: is a symbolic link");
        std::fs::remove_file(d.join("plots/tiny")).expect("unlink");
        std::fs::remove_dir(d.join("results/references")).expect("rm");
        symlink(d.join(target), d.join("results/references")).expect("link");
        refused(d, &["reference", "gradient-plane"], 2, "--results results/references: is a symbolic link");
        std::fs::remove_file(d.join("results/references")).expect("unlink");
        std::fs::create_dir(d.join("results/references")).expect("references");
    }
    // A shard's folder that is a link.
    std::fs::create_dir(d.join("results/tiny")).expect("folder");
    symlink(d.join("outside/empty"), d.join("results/tiny/shard-1-of-2")).expect("link");
    refused(d, &["run", "--config", "tiny.toml", "--shard", "1/2"], 2, "shard-1-of-2: is a symbolic link");
    // Roots named on the command line may be links: the run writes below the folder they name.
    symlink(d.join("outside/empty"), d.join("linked-results")).expect("link");
    ok(d, &["run", "--config", "tiny.toml", "--results", "linked-results", "--no-plots"]);
    assert!(d.join("outside/empty/tiny/summary.csv").is_file());
}

/// A stored reference whose standard errors or values would make a metric infinite or
/// NaN (1e308: the MSE subtracts their squares), that holds a NaN or a negative standard error,
/// or whose resolution is not the test bed's, is refused with exit 2 naming the file and the
/// field; nothing is written.
#[test]
fn stored_references_that_break_a_metric_are_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let name = "gradient-box_albedo-0.8.json";
    let stored = concat!(env!("CARGO_MANIFEST_DIR"), "/../estimators/references/gradient-box_albedo-0.8.json");
    let original: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(stored).expect("stored")).expect("json");
    std::fs::create_dir(d.join("refs")).expect("refs");
    let box_toml = "name = 'box'\nreps = 2\nbudgets = [1]\n[[testbeds]]\nid = 'gradient-box'\nvariant = 'albedo-0.8'\n[[estimators]]\nid = 'is0_cv0'\n";
    std::fs::write(d.join("box.toml"), box_toml).expect("config");
    let run = ["run", "--config", "box.toml", "--references", "refs"];
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let every = |field: &'static str, x: f64| -> Edit {
        Box::new(move |v| {
            for s in v["reference"][field].as_array_mut().expect("array") {
                *s = serde_json::json!([x, x, x]);
            }
        })
    };
    let edits: [(&str, Edit); 6] = [
        ("std_err[0]", every("std_err", 1e308)),
        ("std_err[0]", every("std_err", 1e160)),
        ("value[0]", every("value", 1e300)),
        ("std_err[3]", Box::new(|v| v["reference"]["std_err"][3][1] = serde_json::json!(-0.01))),
        ("resolution [8, 32]", Box::new(|v| v["resolution"] = serde_json::json!([8, 32]))),
        ("resolution [16, 8]", Box::new(|v| v["resolution"] = serde_json::json!([16, 8]))),
    ];
    for (needle, edit) in edits.iter() {
        let mut v = original.clone();
        edit(&mut v);
        std::fs::write(d.join("refs").join(name), serde_json::to_string(&v).expect("json")).expect("write");
        refused(d, &run, 2, needle);
        refused(d, &run, 2, name);
    }
    // A NaN cannot be written in JSON: the file is refused as malformed, naming it.
    let text = serde_json::to_string(&original).expect("json");
    let first = original["reference"]["std_err"][0][0].to_string();
    std::fs::write(d.join("refs").join(name), text.replacen(&first, "NaN", 1)).expect("write");
    refused(d, &run, 2, &format!("refs/{name}: malformed"));
    // The file as it was made runs, and every metric is finite.
    std::fs::write(d.join("refs").join(name), &text).expect("write");
    ok(d, &[&run[..], &["--no-plots"]].concat());
    let mut rows = csv::Reader::from_path(d.join("results/box/summary.csv")).expect("summary");
    let header = rows.headers().expect("header").clone();
    for row in rows.records() {
        let row = row.expect("row");
        for column in ["rmse", "mse", "bias", "bias_se", "reference_var"] {
            let i = header.iter().position(|h| h == column).expect("column");
            assert!(row[i].parse::<f64>().is_ok_and(f64::is_finite), "{column} = {}", &row[i]);
        }
    }
}
