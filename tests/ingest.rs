//! `mcbench ingest` (book: your-renderer.md): estimates another program wrote, read from a manifest.
//! Series drawn here as a renderer would write them (the built-in bed's exact reference plus
//! zero-mean noise, and the same 1% too high) read `pass` and `biased`, in `.npy` and in OpenEXR;
//! two ingested runs of one bed compare with `--two-sample` (an unbiased pair never reads
//! `differ`, the biased series against the unbiased always does); every malformed manifest or file is
//! refused with exit code 2, one line naming the file and the field, and nothing written.

use mcbench::ingest::npy::encode_f64;
use mcbench_core::params::Params;
use rand::Rng;
use rand_pcg::Pcg64;
use std::path::Path;
use std::process::{Command, Output};

const SIDE: usize = 4;
const REPS: usize = 64;
const BUDGETS: [u64; 3] = [16, 64, 256];

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("binary runs")
}

/// The exact reference of `gradient-plane`/diffuse at resolution 4, row-major from the top.
fn reference() -> Vec<[f64; 3]> {
    let entry = mcbench_papers::builtins::testbed("gradient-plane").expect("bed");
    let bed = entry.build_exact("diffuse", &Params::new().with("resolution", SIDE as f64)).expect("builds");
    bed.reference().value.iter().map(|v| v.0).collect()
}

fn normal(rng: &mut Pcg64) -> f64 {
    let (u, v): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
    (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}

/// One repetition at `samples` per pixel: the reference times `1 + bias` plus noise of relative
/// standard deviation 0.5 per sample.
fn draw(rng: &mut Pcg64, samples: u64, bias: f64) -> Vec<f64> {
    let sd = 0.5 / (samples as f64).sqrt();
    reference().iter().flat_map(|p| *p).map(|r| r * (1.0 + bias) + r * sd * normal(rng)).collect()
}

/// Writes a manifest and the files of an unbiased and a +1% biased estimator; `exr` picks the
/// image format. Returns the manifest's path.
fn produce(dir: &Path, seed: u64, exr: bool) -> std::path::PathBuf {
    let mut rng = <Pcg64 as rand::SeedableRng>::seed_from_u64(seed);
    let ext = if exr { "exr" } else { "npy" };
    let mut m = String::from("name = \"mine\"\n[reference]\ntestbed = \"gradient-plane\"\nvariant = \"diffuse\"\nparams = { resolution = 4 }\n");
    for (id, claim, bias) in [("good", "unbiased", 0.0), ("high", "biased", 0.01)] {
        m += &format!("[[estimators]]\nid = \"{id}\"\nbias = \"{claim}\"\n");
        for spp in BUDGETS {
            let sub = dir.join(format!("{id}/spp{spp}"));
            std::fs::create_dir_all(&sub).expect("folder");
            for rep in 0..REPS {
                let v = draw(&mut rng, spp, bias);
                let path = sub.join(format!("rep-{rep:03}.{ext}"));
                if exr {
                    exr::prelude::write_rgb_file(&path, SIDE, SIDE, |x, y| {
                        let i = 3 * (y * SIDE + x);
                        (v[i] as f32, v[i + 1] as f32, v[i + 2] as f32)
                    })
                    .expect("exr");
                } else {
                    std::fs::write(&path, encode_f64(SIDE, SIDE, 3, &v)).expect("npy");
                }
            }
            m += &format!("[[estimators.budgets]]\nsamples = {spp}\nfiles = \"{id}/spp{spp}/rep-{{rep:03}}.{ext}\"\nreps = {REPS}\n");
        }
    }
    std::fs::write(dir.join("manifest.toml"), m).expect("manifest");
    dir.join("manifest.toml")
}

/// The `combined` verdict per estimator in a results folder's tests.csv.
fn combined(results: &Path) -> Vec<(String, String)> {
    let text = std::fs::read_to_string(results.join("tests.csv")).expect("tests.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name| header.iter().position(|c| *c == name).expect("column");
    lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .filter(|f| f[col("test")] == "combined")
        .map(|f| (f[col("estimator")].to_string(), f[col("verdict")].to_string()))
        .collect()
}

fn ingest_and_judge(exr: bool) {
    let tmp = tempfile::tempdir().expect("tempdir");
    let manifest = produce(&tmp.path().join("data"), 1, exr);
    let out = mcbench(tmp.path(), &["ingest", manifest.to_str().expect("utf-8"), "--no-plots"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let results = tmp.path().join("results/mine");
    let verdicts = combined(&results);
    assert_eq!(verdicts, [("good".into(), "pass".into()), ("high".into(), "biased".into())], "{verdicts:?}");
    let summary = std::fs::read_to_string(results.join("summary.csv")).expect("summary.csv");
    assert_eq!(summary.lines().count(), 1 + 2 * BUDGETS.len(), "one row per estimator and budget");
    assert!(results.join("cells.store").is_file());
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("good: declared Unbiased, unbiasedness test pass: as declared"), "{stdout}");
}

#[test]
fn npy_series_of_a_builtin_bed_pass_and_the_biased_one_is_flagged() {
    ingest_and_judge(false);
}

#[test]
fn exr_series_of_a_builtin_bed_pass_and_the_biased_one_is_flagged() {
    ingest_and_judge(true);
}

#[test]
fn two_ingested_runs_of_one_bed_compare_with_two_sample() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    for (side, seed) in [("a", 1), ("b", 2)] {
        let manifest = produce(&d.join(format!("data-{side}")), seed, false);
        let results = format!("res-{side}");
        let out = mcbench(d, &["ingest", manifest.to_str().expect("utf-8"), "--no-plots", "--results", &results]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    for b in ["good", "high"] {
        let out = mcbench(d, &["compare", "res-a/mine", "res-b/mine", "--two-sample", "good", b, "--results", "cmp"]);
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let text = std::fs::read_to_string(d.join("cmp/compare/mine-vs-mine/two_sample.csv")).expect("two_sample.csv");
        let mut lines = text.lines();
        let col = lines.next().expect("header").split(',').position(|c| c == "verdict").expect("verdict");
        let verdicts: Vec<&str> = lines.map(|l| l.split(',').nth(col).expect("verdict")).collect();
        assert_eq!(verdicts.len(), BUDGETS.len(), "one row per budget");
        // Two unbiased series never read `differ`; the +1% series always does.
        let differ = verdicts.iter().filter(|v| **v == "differ").count();
        assert_eq!(differ, if b == "good" { 0 } else { BUDGETS.len() }, "good vs {b}: {verdicts:?}");
    }
}

/// A manifest's `[[claims]]` are judged on the ingested run as a config's are: a slope claim the
/// series meets holds, one it misses does not, and the +1% control is flagged.
#[test]
fn claims_of_the_manifest_are_judged_on_the_ingested_run() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let data = tmp.path().join("data");
    let manifest = produce(&data, 1, false);
    edit(&data, "name = \"mine\"\n", "name = \"mine\"\nbaseline = \"good\"\n");
    let claims = [("-0.5", "matches"), ("-0.8", "steeper")]
        .map(|(v, t)| format!("[[claims]]\nkind = \"slope\"\ntestbed = \"gradient-plane/diffuse\"\nestimator = \"good\"\nvalue = {v}\ntext = \"{t}\"\n"))
        .concat();
    let m = std::fs::read_to_string(&manifest).expect("manifest");
    std::fs::write(&manifest, format!("{m}{claims}[[claims]]\nkind = \"control_flagged\"\nestimator = \"high\"\n"))
        .expect("w");
    let out = mcbench(tmp.path(), &["ingest", manifest.to_str().expect("utf-8"), "--no-plots"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(tmp.path().join("results/mine/claims.csv")).expect("claims.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name| header.iter().position(|c| *c == name).expect("column");
    let verdicts: Vec<(String, String)> = lines
        .map(|l| l.split(',').collect::<Vec<_>>())
        .map(|f| (f[col("claim")].to_string(), f[col("verdict")].to_string()))
        .collect();
    let verdict = |claim: &str| verdicts.iter().find(|(c, _)| c.contains(claim)).map(|(_, v)| v.as_str());
    assert_eq!(verdict("matches"), Some("held"), "{verdicts:?}");
    assert_eq!(verdict("steeper"), Some("not held"), "{verdicts:?}");
    assert_eq!(verdict("biased control high"), Some("held"), "{verdicts:?}");
}

/// Each hostile change to a good set of files: exit 2, one line naming `file` and `field`, and no
/// results folder.
#[test]
fn malformed_manifests_and_files_are_refused_naming_file_and_field() {
    type Break = fn(&Path);
    let cases: Vec<(&str, Break, &str, &str)> = vec![
        (
            "missing file",
            |d| std::fs::remove_file(d.join("good/spp16/rep-005.npy")).expect("rm"),
            "manifest.toml",
            "estimators[0].budgets[0].files",
        ),
        (
            "wrong shape",
            |d| std::fs::write(d.join("good/spp16/rep-003.npy"), encode_f64(2, 4, 3, &[0.5; 24])).expect("w"),
            "rep-003.npy",
            "estimators[0].budgets[0].files",
        ),
        (
            "NaN",
            |d| std::fs::write(d.join("high/spp64/rep-010.npy"), encode_f64(4, 4, 1, &[f64::NAN; 16])).expect("w"),
            "rep-010.npy",
            "estimators[1].budgets[1].files",
        ),
        (
            "extra repetition",
            |d| {
                std::fs::copy(d.join("good/spp16/rep-000.npy"), d.join("good/spp16/rep-064.npy"))
                    .map(|_| ())
                    .expect("cp")
            },
            "rep-064.npy",
            "estimators[0].budgets[0].reps",
        ),
        ("unknown field", |d| edit(d, "reps = 64", "reps = 64\ncolour = 1"), "manifest.toml", "colour"),
        (
            "path escaping",
            |d| edit(d, "files = \"good/spp16", "files = \"../good/spp16"),
            "manifest.toml",
            "estimators[0].budgets[0].files",
        ),
        (
            "absolute path",
            |d| edit(d, "files = \"good/spp16/rep-{rep:03}.npy", "files = \"/etc/passwd"),
            "manifest.toml",
            "estimators[0].budgets[0].files",
        ),
        (
            "symlink leading out",
            |d| {
                std::fs::remove_file(d.join("good/spp64/rep-001.npy")).expect("rm");
                std::os::unix::fs::symlink("/etc/hostname", d.join("good/spp64/rep-001.npy")).expect("ln");
            },
            "manifest.toml",
            "estimators[0].budgets[1].files",
        ),
        (
            "non-EXR bytes named .exr",
            |d| {
                edit(d, "rep-{rep:03}.npy", "rep-{rep:03}.exr");
                for rep in 0..REPS {
                    std::fs::copy(
                        d.join(format!("good/spp16/rep-{rep:03}.npy")),
                        d.join(format!("good/spp16/rep-{rep:03}.exr")),
                    )
                    .expect("cp");
                }
            },
            "rep-000.exr",
            "estimators[0].budgets[0].files",
        ),
        (
            "truncated .npy",
            |d| {
                let p = d.join("high/spp16/rep-007.npy");
                let bytes = std::fs::read(&p).expect("r");
                std::fs::write(&p, &bytes[..bytes.len() - 5]).expect("w");
            },
            "rep-007.npy",
            "estimators[1].budgets[0].files",
        ),
        ("unknown bed", |d| edit(d, "gradient-plane", "gradient-plain"), "gradient-plain", ""),
        ("bias word", |d| edit(d, "\"biased\"", "\"slightly\""), "manifest.toml", "slightly"),
        (
            "budgets differ",
            |d| edit(d, "samples = 64\nfiles = \"high", "samples = 32\nfiles = \"high"),
            "manifest.toml",
            "estimators[1].budgets",
        ),
        (
            "claim naming no estimator",
            |d| append(d, "[[claims]]\nkind = \"control_flagged\"\nestimator = \"nobody\"\n"),
            "manifest.toml",
            "claims[0].estimator",
        ),
        (
            "claim on another bed",
            |d| {
                append(d, "[[claims]]\nkind = \"slope\"\ntestbed = \"gradient-box/thick\"\nestimator = \"good\"\nvalue = -0.5\ntext = \"t\"\n")
            },
            "manifest.toml",
            "claims[0].testbed",
        ),
        (
            "baseline naming no estimator",
            |d| edit(d, "name = \"mine\"\n", "name = \"mine\"\nbaseline = \"nobody\"\n"),
            "manifest.toml",
            "baseline",
        ),
    ];
    for (name, break_it, file, field) in cases {
        let tmp = tempfile::tempdir().expect("tempdir");
        let data = tmp.path().join("data");
        let manifest = produce(&data, 3, false);
        break_it(&data);
        let out = mcbench(tmp.path(), &["ingest", manifest.to_str().expect("utf-8")]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: one line: {err}");
        assert!(err.contains(file) && err.contains(field), "{name}: names {file} and {field}: {err}");
        assert!(!tmp.path().join("results").exists() && !tmp.path().join("plots").exists(), "{name}: nothing written");
    }
}

fn edit(d: &Path, from: &str, to: &str) {
    let m = std::fs::read_to_string(d.join("manifest.toml")).expect("manifest");
    assert!(m.contains(from), "{from}");
    std::fs::write(d.join("manifest.toml"), m.replacen(from, to, 1)).expect("manifest");
}

fn append(d: &Path, text: &str) {
    let m = std::fs::read_to_string(d.join("manifest.toml")).expect("manifest");
    std::fs::write(d.join("manifest.toml"), m + text).expect("manifest");
}
