//! Scale-out (book: scale-out.md): an experiment run as 3 separate `--shard i/3` processes and
//! merged equals a single run byte for byte (wall-clock fields aside), and bad shard sets are
//! refused with exit code 2, one line naming what is wrong, and nothing written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::deterministic_csv;
use mcbench::analysis::metrics::TIMING_COLUMNS;
use mcbench::store::{Record, Store};

/// The transmittance experiment (its claims and post hook included) shrunk to seconds: two small
/// test beds, three fetch budgets (pilot-calibrated per cell), and 40 repetitions, i.e. three
/// repetition blocks per cell, so shards split repetitions as well as cells.
const TINY: &str = "budgets = [10, 20, 40]\n[[testbeds]]\nid = 'eq21-medium'\nvariant = 'transmittance'\nparams = { resolution = 4 }\n[[testbeds]]\nid = 'eq21-medium'\nvariant = 'central-ray'\n";

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("binary runs")
}

fn ok(dir: &Path, args: &[&str]) {
    let o = mcbench(dir, args);
    assert!(o.status.success(), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
}

fn run_args<'a>(results: &'a str, plots: &'a str, reps: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
    let mut a = vec!["run", "transmittance", "--config", "tiny.toml", "--reps", reps, "--threads", "2"];
    a.extend(["--results", results, "--plots", plots]);
    a.extend(extra);
    a
}

/// summary.json without wall-clock fields (timing columns, wall seconds, speed-ups).
fn deterministic_json(path: &Path) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.retain(|k, _| {
                    !TIMING_COLUMNS.contains(&k.as_str())
                        && ![
                            "wall_seconds",
                            "overhead",
                            "speedup",
                            "overhead_wall",
                            "speedup_wall",
                            "run_id",
                            "speedup_ci_low",
                            "speedup_ci_high",
                            "overhead_renderer",
                            "speedup_renderer",
                            "speedup_renderer_ci_low",
                            "speedup_renderer_ci_high",
                            "break_even_ray_ns",
                        ]
                        .contains(&k.as_str())
                });
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(path).expect("read")).expect("json");
    strip(&mut v);
    v
}

fn read(path: PathBuf) -> Vec<u8> {
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn three_shard_processes_merged_equal_a_single_run() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("tiny.toml"), TINY).expect("write config");
    ok(d, &run_args("single/results", "single/plots", "40", &[]));
    for i in 1..=3 {
        ok(d, &run_args("sh/results", "sh/plots", "40", &["--shard", &format!("{i}/3")]));
    }
    assert!(!d.join("sh/results/transmittance/summary.csv").exists(), "a shard writes only its statistics");
    ok(d, &["merge", "sh/results/transmittance", "--results", "sh/results", "--plots", "sh/plots", "--threads", "2"]);
    let (single, merged) = (d.join("single/results/transmittance"), d.join("sh/results/transmittance"));
    assert_eq!(deterministic_csv(&merged.join("summary.csv")), deterministic_csv(&single.join("summary.csv")));
    assert_eq!(common::integrals_text(&merged), common::integrals_text(&single), "integrals.csv differs");
    assert!(read(merged.join("fig8_bands.csv")) == read(single.join("fig8_bands.csv")), "fig8_bands.csv differs");
    // A finished shard folder is its block store and its manifest (the lock file exists only while held).
    let mut names: Vec<String> = std::fs::read_dir(d.join("sh/results/transmittance/shard-2-of-3"))
        .expect("shard folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().to_string())
        .collect();
    names.sort();
    assert_eq!(names, ["blocks.store", "manifest.json"]);
    assert_eq!(deterministic_json(&merged.join("summary.json")), deterministic_json(&single.join("summary.json")));
    // Plots that do not show time are byte-identical too (a test bed's figure has panels against
    // CPU time; its RMSE bands are summary.csv's rmse_lo and rmse_hi, compared above).
    for f in ["fig8_bands.svg", "fig8_bands.png"] {
        let p = |root: &str| d.join(root).join("plots/transmittance").join(f);
        assert!(read(p("sh")) == read(p("single")), "{f} differs");
    }
    // The merged cells are a single run's resume store: a run over them recomputes nothing.
    let o = mcbench(d, &run_args("sh/results", "sh/plots", "40", &["--no-plots", "--progress"]));
    let log = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !log.is_empty(), "{log}");
    assert!(log.lines().filter(|l| l.starts_with('[')).all(|l| l.ends_with("(resumed)")), "{log}");
}

/// Exit code 2, one line on stderr containing `needle`, nothing written under `bad/`.
fn refused(d: &Path, dirs: &[&str], needle: &str) {
    let mut args = vec!["merge"];
    args.extend(dirs);
    args.extend(["--results", "bad/results", "--plots", "bad/plots"]);
    let o = mcbench(d, &args);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{dirs:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{dirs:?}: {err}");
    assert!(err.contains(needle), "{dirs:?}: '{err}' lacks '{needle}'");
    assert!(!d.join("bad").exists(), "{dirs:?} wrote files");
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("mkdir");
    for e in std::fs::read_dir(from).expect("read_dir") {
        let e = e.expect("entry");
        std::fs::copy(e.path(), to.join(e.file_name())).expect("copy");
    }
}

#[test]
fn bad_shard_values_and_bad_shard_sets_are_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("tiny.toml"), TINY).expect("write config");
    for bad in ["0/3", "4/3", "a/b", "1/0"] {
        let o = mcbench(d, &run_args("r", "p", "20", &["--shard", bad]));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad}: {err}");
        assert!(err.trim_end().lines().count() == 1 && err.contains("--shard"), "{bad}: {err}");
        assert!(!d.join("r").exists());
    }
    for i in 1..=3 {
        ok(d, &run_args("sh", "p", "20", &["--shard", &format!("{i}/3")]));
    }
    ok(d, &run_args("seed2", "p", "20", &["--shard", "2/3", "--seed", "2"]));
    ok(d, &run_args("reps", "p", "24", &["--shard", "2/3"]));
    let s = |i: usize| format!("sh/transmittance/shard-{i}-of-3");
    let (s1, s2, s3) = (s(1), s(2), s(3));
    refused(d, &[&s1, &s3], "2/3");
    refused(d, &[&s1, &s2, &s3, &s1], "duplicated");
    refused(d, &[&s1, "seed2/transmittance/shard-2-of-3", &s3], "seed");
    refused(d, &[&s1, "reps/transmittance/shard-2-of-3", &s3], "reps");
    refused(d, &["nowhere"], "nowhere");
    // Damaged copies of shard 2: a truncated block, a missing block, a foreign block, a torn or
    // corrupt store, a garbled or absent manifest.
    let records = |p: &Path| -> Vec<Record> { Store::open(&p.join("blocks.store")).expect("store").records().to_vec() };
    let rewrite = |p: &Path, r: &[Record]| mcbench::store::write_records(&p.join("blocks.store"), r).expect("write");
    let damage = |name: &str, how: &dyn Fn(&Path)| -> String {
        let to = d.join(name).join("shard-2-of-3");
        copy_dir(&d.join(&s2), &to);
        how(&to);
        format!("{name}/shard-2-of-3")
    };
    let truncated = damage("truncated", &|p| {
        let mut r = records(p);
        let half = r[0].payload.len() / 2;
        r[0].payload.truncate(half);
        rewrite(p, &r);
    });
    refused(d, &[&s1, &truncated, &s3], "corrupt shard block");
    let missing = damage("missing", &|p| rewrite(p, &records(p)[1..]));
    refused(d, &[&s1, &missing, &s3], "shard 2/3 is incomplete");
    let foreign = damage("foreign", &|p| {
        let mut r = records(p);
        let first = r[0].name.clone();
        r[0].name = r[1].name.clone();
        r[1].name = first;
        rewrite(p, &r);
    });
    refused(d, &[&s1, &foreign, &s3], "holds another cell or block");
    let torn = damage("torn", &|p| {
        let bytes = std::fs::read(p.join("blocks.store")).expect("read");
        std::fs::write(p.join("blocks.store"), &bytes[..bytes.len() - 7]).expect("write");
    });
    refused(d, &[&s1, &torn, &s3], "shard 2/3 is incomplete");
    let corrupt = damage("corrupt", &|p| {
        let mut bytes = std::fs::read(p.join("blocks.store")).expect("read");
        bytes[mcbench::store::HEADER_LEN + mcbench::store::FRAME_LEN + 8] ^= 0x10;
        std::fs::write(p.join("blocks.store"), &bytes).expect("write");
    });
    refused(d, &[&s1, &corrupt, &s3], "corrupt record");
    let garbled = damage("garbled", &|p| std::fs::write(p.join("manifest.json"), "{\"format\": 1,").expect("write"));
    refused(d, &[&s1, &garbled, &s3], "corrupt shard manifest");
    let unfinished = damage("unfinished", &|p| std::fs::remove_file(p.join("manifest.json")).expect("rm"));
    refused(d, &[&s1, &unfinished, &s3], "unfinished shard");
    // The intact set merges.
    ok(d, &["merge", &s1, &s2, &s3, "--results", "ok", "--plots", "ok-plots", "--no-plots"]);
    assert!(d.join("ok/transmittance/summary.csv").is_file());
}
