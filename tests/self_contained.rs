//! The product speaks of itself alone: no citation of a document it does not ship. The mark such
//! citations carried, the word spelled in the four capitals S, P, E, C ([`WORD`]; assembled from
//! two halves so that this file does not carry it either), must not appear in anything a user
//! reads:
//!
//! - what a run writes: a small custom sweep with claims run through the binary, then split into
//!   two shards and merged, then redrawn, every file under its results and plots folders (the
//!   cell store decoded, `integrals.csv.gz` decompressed) and the stdout and stderr of each command;
//! - the help of the binary and of every subcommand, and what `mcbench list` prints;
//! - the book (`docs/src/**/*.md`), `README.md` and `CHANGELOG.md`.
//!
//! The check is case-sensitive, so words such as `specular` or `spectral` pass; each failure names
//! the file (or command) and the line.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The mark of a citation of an outside document.
const WORD: &str = concat!("SP", "EC");

const SWEEP: &str = r#"
name = "tiny"
reps = 16
budgets = [4, 16, 64]
baseline = "is0_cv0"

[[testbeds]]
id = "gradient-plane"
params = { resolution = 4 }

[[estimators]]
id = "is0_cv0"

[[estimators]]
id = "brdf_is0_cv0"

[[estimators]]
id = "clamped_is0_cv0"
params = { clamp = 1.5 }

[[claims]]
kind = "slope"
testbed = "gradient-plane/default"
estimator = "is0_cv0"
value = -0.5
text = "independent MC converges at -1/2"

[[claims]]
kind = "control_flagged"
estimator = "clamped_is0_cv0[clamp=1.5]"
"#;

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench"))
        .current_dir(dir)
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .expect("the mcbench binary runs")
}

/// Runs `args`, requires success, and returns the command's stdout and stderr as one text.
fn ok(dir: &Path, args: &[&str]) -> String {
    let o = mcbench(dir, args);
    let text = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "mcbench {args:?} failed: {text}");
    text
}

/// Every `file:line: text` of `text` that holds [`WORD`], labelled with `source`.
fn hits(source: &str, text: &str) -> Vec<String> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| l.contains(WORD))
        .map(|(n, l)| format!("{source}:{}: {}", n + 1, l.trim().chars().take(160).collect::<String>()))
        .collect()
}

/// Every regular file under `dir`, recursively (hidden files included).
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).unwrap_or_else(|e| panic!("{}: {e}", d.display())) {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                stack.push(path);
            } else {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// The text a user can read from a written file: a cell or block store decoded to JSON,
/// `integrals.csv.gz` decompressed, anything else as (lossy) UTF-8. PNGs hold only pixels (their text is
/// drawn, and the SVG twin holding the same text is checked), so they are left out (None).
fn readable(path: &Path) -> Option<String> {
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default();
    if name.ends_with(".png") {
        return None;
    }
    if name.ends_with(".store") {
        let store = mcbench::store::Store::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut text = String::new();
        for r in store.records() {
            text += &r.name;
            text.push('\n');
            text += &String::from_utf8_lossy(&r.payload);
            text.push('\n');
            if let Ok(cell) = mcbench::store::packed::decode_cell(&r.payload) {
                text += &serde_json::to_string(&cell).expect("a cell serialises");
                text.push('\n');
            }
        }
        return Some(text);
    }
    if name.ends_with(".gz") {
        assert_eq!(name, "integrals.csv.gz", "a compressed file this test cannot read: {}", path.display());
        let folder = path.parent().expect("a results folder");
        return mcbench::output::integrals::read_text(folder).expect("integrals.csv.gz decodes");
    }
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Some(String::from_utf8_lossy(&bytes).into_owned())
}

/// The written files of a finished run, its commands' output and the help texts.
#[test]
fn runs_write_and_print_nothing_that_cites_an_outside_document() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("tiny.toml"), SWEEP).expect("config");
    let mut found = Vec::new();
    let mut run = |label: &str, args: &[&str]| found.extend(hits(label, &ok(d, args)));
    run("run", &["run", "--config", "tiny.toml", "--threads", "2"]);
    run("run --integrals csv", &["run", "--config", "tiny.toml", "--integrals", "csv", "--results", "plain"]);
    for shard in ["1/2", "2/2"] {
        run("run --shard", &["run", "--config", "tiny.toml", "--shard", shard, "--results", "sharded"]);
    }
    run("merge", &["merge", "sharded/tiny", "--results", "merged", "--plots", "merged-plots"]);
    run("plot", &["plot", "results/tiny", "--plots", "redrawn"]);
    // The conformance suite builds every test bed's cases, some from stored references: a copy of
    // the repository's, so that nothing is written beside the originals.
    let stored = Path::new(env!("CARGO_MANIFEST_DIR")).join("../estimators/references");
    std::fs::create_dir(d.join("stored")).expect("mkdir");
    for f in std::fs::read_dir(&stored).expect("the repository's references") {
        let f = f.expect("entry").path();
        if f.extension().is_some_and(|e| e == "json") {
            std::fs::copy(&f, d.join("stored").join(f.file_name().expect("name"))).expect("copy");
        }
    }
    run("conformance", &["conformance", "is0_cv0", "clamped_is0_cv0", "--references", "stored"]);
    run("reference", &["reference", "gradient-plane", "--variant", "diffuse", "--references", "refs"]);
    for what in ["testbeds", "estimators", "experiments"] {
        run("list", &["list", what]);
        run("list --params", &["list", what, "--params"]);
    }
    let top = ok(d, &["--help"]);
    found.extend(hits("mcbench --help", &top));
    let subcommands: Vec<String> = top
        .lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|s| s != "help")
        .collect();
    assert!(subcommands.len() >= 6 && subcommands.contains(&"merge".to_string()), "{subcommands:?}");
    for sub in &subcommands {
        found.extend(hits(&format!("mcbench {sub} --help"), &ok(d, &[sub, "--help"])));
    }
    let mut checked = 0;
    for f in files(d) {
        if let Some(text) = readable(&f) {
            checked += 1;
            found.extend(hits(&f.strip_prefix(d).unwrap_or(&f).display().to_string(), &text));
        }
    }
    // The folders above hold at least the contract files of four result folders and two plots
    // folders; a run that wrote nothing would pass the scan vacuously.
    for f in
        ["results/tiny/claims.csv", "merged/tiny/summary.json", "plain/tiny/integrals.csv", "redrawn/tiny/report.md"]
    {
        assert!(d.join(f).is_file(), "{f} was not written");
    }
    assert!(checked > 40, "only {checked} files were checked");
    let claims = std::fs::read_to_string(d.join("results/tiny/claims.csv")).expect("claims.csv");
    assert!(claims.contains("biased control clamped_is0_cv0"), "the control claim is among the checked texts");
    assert!(found.is_empty(), "`{WORD}` in what mcbench wrote or printed:\n{}", found.join("\n"));
}

/// The book, the README and the changelog.
#[test]
fn the_book_speaks_of_itself_alone() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut pages: Vec<PathBuf> =
        files(&root.join("docs/src")).into_iter().filter(|p| p.extension().is_some_and(|e| e == "md")).collect();
    pages.push(root.join("README.md"));
    pages.push(root.join("CHANGELOG.md"));
    assert!(pages.len() > 20, "the book's chapters are found: {pages:?}");
    let mut found = Vec::new();
    for p in &pages {
        let text = std::fs::read_to_string(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        found.extend(hits(&p.strip_prefix(&root).unwrap_or(p).display().to_string(), &text));
    }
    assert!(found.is_empty(), "`{WORD}` in the book:\n{}", found.join("\n"));
}
