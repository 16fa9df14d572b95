//! Text that comes from outside the harness reaches the markdown it writes escaped: a claim's
//! text and diagnostic name from a config, a plug-in's label from its registry entry and a stored
//! reference's command from its file, each holding an HTML tag, show in `report.md` as text
//! (`&lt;script&gt;`), and no `.md` file of the run holds a raw tag a markdown viewer would render.

use mcbench::config::{Mode, SweepFile};
use mcbench::run::execute::{execute, prepare, ExecOptions};
use mcbench::{EstimatorEntry, Registry};
use std::path::{Path, PathBuf};

const SCRIPT: &str = "<script>alert(1)</script>";
const IMG: &str = "<img src=x onerror=alert(1)>";
const SCRIPT_ESCAPED: &str = "&lt;script&gt;alert(1)&lt;/script&gt;";
const IMG_ESCAPED: &str = "&lt;img src=x onerror=alert(1)&gt;";

/// A plug-in whose label holds both tags (the built-in independent estimator under another id).
static HOSTILE: EstimatorEntry = EstimatorEntry {
    id: "hostile_label",
    label: "tracer <script>alert(1)</script> <img src=x onerror=alert(1)>",
    ..mcbench_papers::independent::is0_cv0::ENTRY
};

/// The repository's stored reference of `gradient-box/albedo-0.8` with both tags in its command.
fn planted_references(dir: &Path) -> PathBuf {
    let name = "gradient-box_albedo-0.8.json";
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("../estimators/references").join(name);
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(source).expect("stored reference")).expect("json");
    let command = format!("mcbench reference {SCRIPT} | {IMG}");
    v["command"] = serde_json::json!(command);
    v["reference"]["kind"]["command"] = serde_json::json!(command);
    let refs = dir.join("refs");
    std::fs::create_dir_all(&refs).expect("mkdir");
    std::fs::write(refs.join(name), serde_json::to_string(&v).expect("json")).expect("write");
    refs
}

/// Every `.md` file under `root`.
fn markdown_files(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).expect("readable").flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "md") {
                out.push(p);
            }
        }
    }
    out
}

#[test]
fn text_from_configs_labels_and_stored_files_is_escaped_in_every_markdown_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let registry = Registry::new()
        .with_catalog(mcbench_papers::catalog())
        .with_estimator(&HOSTILE)
        .with_references(mcbench::store::references::ReferenceDir::new(planted_references(dir.path())));
    let config = format!(
        "name = 'escaping'\nreps = 2\nbudgets = [1, 2, 4]\n\
         [[testbeds]]\nid = 'gradient-box'\nvariant = 'albedo-0.8'\n\
         [[estimators]]\nid = 'hostile_label'\n\
         [[claims]]\nkind = 'slope'\ntestbed = 'gradient-box/albedo-0.8'\nestimator = 'hostile_label'\nvalue = -0.5\n\
         text = '{SCRIPT} converges | {IMG}'\n\
         [[claims]]\nkind = 'diagnostic'\ntestbed = 'gradient-box/albedo-0.8'\nestimator = 'hostile_label'\n\
         budget = 4\nname = '{IMG}'\nvalue = 1.0\ntolerance = 0.1\ntext = 'a diagnostic named {SCRIPT}'\n"
    );
    let sweep = toml::from_str::<SweepFile>(&config).expect("config").apply(None, Mode::Quick).expect("sweep");
    let opts = ExecOptions {
        results_root: dir.path().join("results"),
        plots_root: dir.path().join("plots"),
        threads: Some(1),
        observer: &mcbench::run::runner::Silent,
        plots: true,
        wait: false,
        registry: &registry,
        integrals: Default::default(),
    };
    let out = execute(&prepare(sweep, &registry).expect("plans"), None, &opts).expect("runs");
    // The run holds the raw text (summary.json keeps what it was given) ...
    let notes = out.report.meta.notes.join("\n");
    assert!(notes.contains(SCRIPT) && notes.contains(IMG), "the planted command reaches the notes: {notes}");
    assert!(out.report.labels.iter().any(|(_, l)| l.contains(SCRIPT)), "the plug-in's label is the run's");
    // ... and every markdown file shows it as text.
    let files = markdown_files(dir.path());
    assert!(files.iter().any(|f| f.ends_with("plots/escaping/report.md")), "{files:?}");
    for f in &files {
        let text = std::fs::read_to_string(f).expect("readable").to_lowercase();
        for tag in ["<script", "<img"] {
            assert!(!text.contains(tag), "{} holds a raw {tag}", f.display());
        }
    }
    let report = std::fs::read_to_string(out.plots_dir.join("report.md")).expect("report.md");
    let escaped = |what: &str, needle: &str| assert!(report.contains(needle), "{what} lacks {needle}:\n{report}");
    escaped("the claim's text", &format!("{SCRIPT_ESCAPED} converges \\| {IMG_ESCAPED}"));
    escaped("the diagnostic's name", &format!("no `{IMG_ESCAPED}` diagnostic of hostile_label"));
    escaped("the plug-in's label", &format!("hostile_label: tracer {SCRIPT_ESCAPED} {IMG_ESCAPED}"));
    escaped("the stored reference's command", &format!("`mcbench reference {SCRIPT_ESCAPED} \\| {IMG_ESCAPED}`"));
}
