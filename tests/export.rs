//! `mcbench export` (book: exported-beds.md): a built-in test bed as a Mitsuba 3 scene with its
//! reference. The scene files and `reference.npy` are written (atomically: a link in a file's
//! place is replaced, never written through); the reference read back is the bed's, bit for bit,
//! with `reference_var.npy` the squared standard errors of a stored reference; a bad test bed,
//! variant, format, parameter or output folder is refused with exit code 2, one line naming the
//! field, and nothing written.

use mcbench_core::params::Params;
use std::path::Path;
use std::process::{Command, Output};

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("binary runs")
}

fn read_npy(path: &Path) -> Vec<[f64; 3]> {
    let bytes = std::fs::read(path).expect("written");
    let img = mcbench::ingest::npy::parse(&bytes).expect("a valid .npy");
    img.pixels.iter().map(|p| p.0).collect()
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("folder")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn the_plane_is_written_with_its_exact_reference_bit_for_bit() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = mcbench(
        dir.path(),
        &["export", "gradient-plane", "--variant", "diffuse", "--param", "resolution=3", "--out", "scene"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let scene = dir.path().join("scene");
    assert_eq!(names(&scene), ["bed.md", "reference.npy", "scene.xml", "sky.pfm"]);
    let entry = mcbench_papers::builtins::testbed("gradient-plane").expect("bed");
    let bed = entry.build_exact("diffuse", &Params::new().with("resolution", 3.0)).expect("builds");
    let want: Vec<[f64; 3]> = bed.reference().value.iter().map(|v| v.0).collect();
    assert_eq!(read_npy(&scene.join("reference.npy")), want);
    let npy = mcbench::ingest::npy::parse(&std::fs::read(scene.join("reference.npy")).expect("read")).expect("npy");
    assert_eq!((npy.width, npy.height), (3, 3));
    let xml = std::fs::read_to_string(scene.join("scene.xml")).expect("xml");
    assert_eq!(xml.matches("<sensor type=\"radiancemeter\">").count(), 9);
    assert!(std::fs::read_to_string(scene.join("bed.md")).expect("notes").contains("pinhole"));
}

#[test]
fn a_stored_reference_comes_with_its_variance() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = mcbench(dir.path(), &["export", "gradient-box", "--variant", "albedo-0.8", "--out", "box"]);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let entry = mcbench_papers::builtins::testbed("gradient-box").expect("bed");
    let bed =
        (entry.build)("albedo-0.8", &Params::new(), &mcbench_papers::built_in_references::BUILT_IN).expect("builds");
    let r = bed.reference();
    assert!(!r.is_exact());
    let box_dir = dir.path().join("box");
    assert_eq!(read_npy(&box_dir.join("reference.npy")), r.value.iter().map(|v| v.0).collect::<Vec<_>>());
    let var: Vec<[f64; 3]> = r.std_err.iter().map(|s| s.0.map(|e| e * e)).collect();
    assert_eq!(read_npy(&box_dir.join("reference_var.npy")), var);
    assert_eq!(std::fs::read_to_string(box_dir.join("scene.xml")).expect("xml").matches("radiancemeter").count(), 256);
}

#[test]
fn files_are_replaced_not_written_through_a_link() {
    let dir = tempfile::tempdir().expect("tempdir");
    let outside = dir.path().join("outside.txt");
    std::fs::write(&outside, "keep").expect("write");
    let scene = dir.path().join("scene");
    std::fs::create_dir(&scene).expect("mkdir");
    std::os::unix::fs::symlink(&outside, scene.join("scene.xml")).expect("link");
    std::fs::write(scene.join("bed.md"), "old").expect("write");
    let out = mcbench(
        dir.path(),
        &["export", "gradient-plane", "--variant", "diffuse", "--param", "resolution=2", "--out", "scene"],
    );
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(std::fs::read_to_string(&outside).expect("read"), "keep");
    assert!(std::fs::symlink_metadata(scene.join("scene.xml")).expect("meta").is_file());
    assert!(std::fs::read_to_string(scene.join("bed.md")).expect("read").starts_with("# gradient-plane"));
    // No temporary file is left beside the files.
    assert_eq!(names(&scene), ["bed.md", "reference.npy", "scene.xml", "sky.pfm"]);
}

#[test]
fn bad_input_is_one_line_naming_the_field_exit_2_and_nothing_written() {
    let cases: &[(&[&str], &str)] = &[
        (&["export", "no-such-bed", "--out", "o"], "no-such-bed"),
        (&["export", "checker-direct", "--out", "o"], "testbed"),
        (&["export", "gradient-plane", "--variant", "glossy", "--out", "o"], "--variant"),
        (&["export", "gradient-plane", "--variant", "shiny", "--out", "o"], "variant"),
        (&["export", "gradient-plane", "--variant", "diffuse", "--format", "pbrt", "--out", "o"], "--format"),
        (&["export", "gradient-plane", "--variant", "diffuse", "--param", "resolution=0", "--out", "o"], "resolution"),
        (
            &["export", "gradient-box", "--variant", "albedo-0.8", "--param", "resolution=5", "--out", "o"],
            "gradient-box",
        ),
        (&["export", "gradient-plane", "--variant", "diffuse", "--out", "file/o"], "--out"),
    ];
    for (args, field) in cases {
        let dir = tempfile::tempdir().expect("tempdir");
        std::fs::write(dir.path().join("file"), "x").expect("write");
        let out = mcbench(dir.path(), args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(field), "{args:?} names {field}: {err}");
        assert_eq!(names(dir.path()), ["file"], "{args:?} wrote nothing");
    }
}
