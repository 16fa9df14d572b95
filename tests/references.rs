//! Stored references as data, through the binary: a copy of the binary run from anywhere finds
//! every stored reference of the built-in test beds without any folder (they are compiled into
//! the papers' crate, not read through a path compiled into it) and through `--references`, a
//! reference made with parameters is found by a run that uses them, and a stored reference that
//! is malformed in the folder a run names is refused (the folder is asked before the built-in
//! ones) before anything is written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository's stored references.
const REFERENCES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../estimators/references");

/// Runs the copied binary. A freshly written executable can be "busy" for a moment when another
/// test thread forked while its file was open for writing (ETXTBSY): retried, not failed.
fn run(bin: &Path, dir: &Path, args: &[&str]) -> Output {
    for _ in 0..50 {
        match Command::new(bin).current_dir(dir).args(args).output() {
            Err(e) if e.kind() == std::io::ErrorKind::ExecutableFileBusy => {
                std::thread::sleep(std::time::Duration::from_millis(20))
            }
            r => return r.expect("binary runs"),
        }
    }
    panic!("{} stayed busy", bin.display())
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// A copy of the binary in its own folder, and an empty working folder elsewhere.
fn copied_binary() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let bin = dir.path().join("bin/mcbench");
    std::fs::create_dir_all(bin.parent().expect("parent")).expect("mkdir");
    std::fs::copy(env!("CARGO_BIN_EXE_mcbench"), &bin).expect("copy the binary");
    let work = dir.path().join("work");
    std::fs::create_dir_all(&work).expect("mkdir");
    (dir, bin, work)
}

/// Every variant whose reference is stored, at one cheap budget.
const EVERY_STORED: &str = "name = 'stored'\nreps = 2\nbudgets = [1]\n\
[[testbeds]]\nid = 'gradient-box'\nvariant = 'albedo-0.8'\n\
[[testbeds]]\nid = 'gradient-box'\nvariant = 'albedo-1'\n\
[[testbeds]]\nid = 'gradient-box'\nvariant = 'albedo-0.5'\n\
[[testbeds]]\nid = 'gradient-box'\nvariant = 'hg-0.1'\n\
[[testbeds]]\nid = 'gradient-box'\nvariant = 'thick'\n\
[[testbeds]]\nid = 'checker-image'\nvariant = 'default'\n\
[[testbeds]]\nid = 'checker-image'\nvariant = 'occluded'\n\
[[testbeds]]\nid = 'checker-image'\nvariant = 'soft-shadow'\n\
[[testbeds]]\nid = 'eq21-medium'\nvariant = 'multiple'\n\
[[testbeds]]\nid = 'perlin-medium'\nvariant = 'multiple'\n\
[[estimators]]\nid = 'is0_cv0'\n[[estimators]]\nid = 'uniform_image'\n[[estimators]]\nid = 'delta_tracking'\n";

#[test]
fn a_copied_binary_finds_every_stored_reference_through_references() {
    let (_dir, bin, work) = copied_binary();
    std::fs::write(work.join("stored.toml"), EVERY_STORED).expect("config");
    // Without a references folder it finds the built-in ones; the same through --references.
    for (args, folder) in [(vec![], "results"), (vec!["--references", REFERENCES, "--results", "named"], "named")] {
        let o = run(&bin, &work, &[&["run", "--config", "stored.toml", "--no-plots"][..], &args].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        let csv = std::fs::read_to_string(work.join(folder).join("stored/summary.csv")).expect("summary");
        for bed in [
            "albedo-0.8",
            "albedo-1",
            "albedo-0.5",
            "hg-0.1",
            "thick",
            "default",
            "occluded",
            "soft-shadow",
            "multiple",
        ] {
            assert!(csv.contains(&format!(",{bed},")), "{bed} missing from {csv}");
        }
    }
    // A reference of other parameters is in neither: refused, saying how to make it.
    let other = EVERY_STORED.replace("variant = 'albedo-1'\n", "variant = 'albedo-1'\nparams = { sigma_t = 0.7 }\n");
    std::fs::write(work.join("other.toml"), other).expect("config");
    let o = run(&bin, &work, &["run", "--config", "other.toml", "--no-plots"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("mcbench reference gradient-box --variant albedo-1"), "{}", stderr(&o));
    assert!(!work.join("results/other").exists(), "nothing written");
    // The same through --results: the references folder below a results root.
    let root = work.join("elsewhere");
    std::fs::create_dir_all(root.join("references")).expect("mkdir");
    for e in std::fs::read_dir(REFERENCES).expect("references") {
        let p = e.expect("entry").path();
        std::fs::copy(&p, root.join("references").join(p.file_name().expect("name"))).expect("copy");
    }
    let o = run(&bin, &work, &["run", "--config", "stored.toml", "--no-plots", "--results", "elsewhere"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_reference_made_with_parameters_is_found_by_a_run_that_uses_them() {
    let (_dir, bin, work) = copied_binary();
    let refs = work.join("refs");
    let o = run(
        &bin,
        &work,
        &[
            "reference",
            "gradient-box",
            "--variant",
            "albedo-0.8",
            "--param",
            "resolution=2",
            "--param",
            "sigma_t=0.5",
            "--samples",
            "4096",
            "--references",
            refs.to_str().expect("utf8"),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let made: Vec<String> = std::fs::read_dir(&refs)
        .expect("refs")
        .map(|e| e.expect("e").file_name().to_string_lossy().to_string())
        .filter(|n| n.ends_with(".json"))
        .collect();
    assert_eq!(made.len(), 1, "{made:?}");
    assert!(made[0].starts_with("gradient-box_albedo-0.8_") && made[0] != "gradient-box_albedo-0.8.json");
    let config = "name = 'thin'\nreps = 4\nbudgets = [4, 16]\n[[testbeds]]\nid = 'gradient-box'\nvariant = 'albedo-0.8'\nparams = { resolution = 2, sigma_t = 0.5 }\n[[estimators]]\nid = 'is0_cv0'\n";
    std::fs::write(work.join("thin.toml"), config).expect("config");
    let o = run(&bin, &work, &["run", "--config", "thin.toml", "--no-plots", "--references", "refs"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Other parameters have no reference: refused, naming the command that would make it.
    std::fs::write(work.join("thick.toml"), config.replace("sigma_t = 0.5", "sigma_t = 0.7")).expect("config");
    let o = run(&bin, &work, &["run", "--config", "thick.toml", "--no-plots", "--references", "refs"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--param sigma_t=0.7"), "{}", stderr(&o));
}

#[test]
fn a_malformed_stored_reference_is_refused_before_anything_is_written() {
    let (_dir, bin, work) = copied_binary();
    let refs = work.join("refs");
    std::fs::create_dir_all(&refs).expect("mkdir");
    let name = "gradient-box_albedo-0.8.json";
    let original: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(Path::new(REFERENCES).join(name)).expect("read")).expect("json");
    let config = "name = 'box'\nreps = 2\nbudgets = [1]\n[[testbeds]]\nid = 'gradient-box'\nvariant = 'albedo-0.8'\n[[estimators]]\nid = 'is0_cv0'\n";
    std::fs::write(work.join("box.toml"), config).expect("config");
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let edits: [(&str, Edit); 5] = [
        ("values", Box::new(|v| drop(v["reference"]["value"].as_array_mut().expect("values").pop()))),
        (
            "values",
            Box::new(|v| {
                let x = v["reference"]["value"][0].clone();
                v["reference"]["value"].as_array_mut().expect("values").push(x);
            }),
        ),
        ("negative", Box::new(|v| v["reference"]["std_err"][3][1] = serde_json::json!(-0.01))),
        ("holds the reference of", Box::new(|v| v["params"]["sigma_t"] = serde_json::json!(3.0))),
        ("malformed", Box::new(|v| v["reference"] = serde_json::json!("garbage"))),
    ];
    for (needle, edit) in edits.iter() {
        let mut v = original.clone();
        edit(&mut v);
        std::fs::write(refs.join(name), serde_json::to_string(&v).expect("json")).expect("write");
        let o = run(&bin, &work, &["run", "--config", "box.toml", "--references", "refs"]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{needle}: {err}");
        assert!(err.contains(needle) && err.contains(name) && err.trim_end().lines().count() == 1, "{needle}: {err}");
        assert!(!work.join("results").exists() && !work.join("plots").exists(), "{needle}: files written");
    }
}
