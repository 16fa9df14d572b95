//! Integration tests of the `mcbench` binary (book: cli.md): exit codes, one-line errors naming the
//! field, no files written on bad input, and a small custom sweep end to end.

use std::path::Path;

mod common;
use common::deterministic_csv;
use std::process::{Command, Output};

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// Exit code 2, exactly one line on stderr containing `needle`, and nothing under results/ or plots/;
/// the line.
fn assert_bad_input(dir: &Path, args: &[&str], needle: &str) -> String {
    let o = mcbench(dir, args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: not one line: {err}");
    assert!(err.contains(needle), "{args:?}: '{err}' lacks '{needle}'");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!dir.join("results").exists() && !dir.join("plots").exists(), "{args:?} wrote files");
    err
}

const SMALL: &str = "name = 'tiny'\nreps = 3\nbudgets = [4, 16, 64]\n[[testbeds]]\nid = 'gradient-plane'\nparams = { resolution = 4 }\n[[estimators]]\nid = 'is0_cv0'\n[[estimators]]\nid = 'clamped_is0_cv0'\nparams = { clamp = 1.5 }\n";

#[test]
fn bad_input_exits_2_with_one_line_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    assert_bad_input(d, &["run", "no-such-experiment"], "surface-smc");
    assert_bad_input(d, &["run", "surface-smc", "--reps", "0"], "--reps");
    assert_bad_input(d, &["run", "surface-smc", "--seed", "abc"], "--seed");
    assert_bad_input(d, &["run", "surface-smc", "--threads", "0"], "--threads");
    // A pattern of --estimators or --testbeds that matches nothing is named, with the valid ids.
    assert_bad_input(d, &["run", "unbiasedness", "--estimators", "integrand_mc,nope*"], "--estimators = nope*");
    assert_bad_input(d, &["run", "unbiasedness", "--testbeds", "peak"], "product-peak");
    // Rounds are for unbiasedness alone, and a shard cannot follow them.
    assert_bad_input(
        d,
        &["run", "unbiasedness", "--repetitions", "rounds", "--shard", "1/2"],
        "--repetitions = rounds",
    );
    assert_bad_input(d, &["run", "surface-smc", "--repetitions", "rounds"], "only the unbiasedness experiment");
    assert_bad_input(d, &["run", "unbiasedness", "--repetitions", "sometimes"], "--repetitions");
    // A share of the rounds' budget: a number in (0, 1], with the rounds, not for calibration.
    let rounds = ["run", "unbiasedness", "--repetitions", "rounds", "--rounds-budget"];
    assert_bad_input(d, &[&rounds[..], &["abc"]].concat(), "--rounds-budget");
    assert_bad_input(d, &[&rounds[..], &["nan"]].concat(), "--rounds-budget = NaN");
    assert_bad_input(d, &[&rounds[..], &["0"]].concat(), "--rounds-budget = 0: must lie in (0, 1]");
    assert_bad_input(d, &[&rounds[..], &["-0.5"]].concat(), "--rounds-budget = -0.5");
    assert_bad_input(d, &[&rounds[..], &["1.5"]].concat(), "--rounds-budget = 1.5");
    assert_bad_input(d, &[&rounds[..], &["inf"]].concat(), "--rounds-budget = inf");
    assert_bad_input(d, &["run", "unbiasedness", "--rounds-budget", "0.3"], "needs --repetitions rounds");
    assert_bad_input(
        d,
        &["run", "unbiasedness", "--repetitions", "fixed", "--rounds-budget", "0.3"],
        "--rounds-budget = 0.3: a budget of the rounds needs --repetitions rounds",
    );
    assert_bad_input(
        d,
        &["run", "calibration", "--repetitions", "rounds", "--rounds-budget", "0.5"],
        "--rounds-budget = 0.5: calibration measures the rule of the rounds without a shared budget",
    );
    assert_bad_input(d, &["conformance", "--testbeds", "no-such-bed"], "--testbeds = no-such-bed");
    assert_bad_input(d, &["conformance", "no_such_estimator"], "integrand_mc");
    assert_bad_input(d, &["run"], "experiment");
    assert_bad_input(d, &["frobnicate"], "frobnicate");
    assert_bad_input(d, &["reference", "gradient-plane", "--variant", "shiny"], "gradient-plane/shiny");
    assert_bad_input(d, &["plot", "nowhere"], "nowhere");
    let cases = [
        ("malformed.toml", "name = 'x'\nreps = [".to_string(), "malformed.toml"),
        ("unknown_field.toml", "name = 'x'\nrep = 3\n".to_string(), "rep"),
        ("bad_reps.toml", SMALL.replace("reps = 3", "reps = 0"), "reps"),
        ("bad_budget.toml", SMALL.replace("[4, 16, 64]", "[4, 0]"), "budget"),
        ("bad_param.toml", SMALL.replace("clamp = 1.5", "clamp = -1.0"), "clamp"),
        ("typo_param.toml", SMALL.replace("clamp = 1.5", "clmap = 1.5"), "clmap"),
        ("bad_estimator.toml", SMALL.replace("'is0_cv0'", "'is9_cv9'"), "is9_cv9"),
        (
            "bad_testbed.json",
            r#"{"name":"x","budgets":[4],"testbeds":[{"id":"nope"}],"estimators":[{"id":"is0_cv0"}]}"#.to_string(),
            "nope",
        ),
        ("bad_kind.toml", "name='x'\nbudget_kind='parsecs'\n".to_string(), "parsecs"),
        ("bad_cost.toml", format!("{SMALL}\n[cost_model]\nray_ns = -1.0\n"), "cost_model.ray_ns"),
        ("bad_eval_cost.toml", format!("{SMALL}\n[cost_model]\ntarget_eval_ns = -1.0\n"), "cost_model.target_eval_ns"),
        ("bad_cache_cost.toml", format!("{SMALL}\n[cost_model]\ncache_op_ns = nan\n"), "cost_model.cache_op_ns"),
        ("typo_cost.toml", format!("{SMALL}\n[cost_model]\nray = 90.0\n"), "ray"),
        ("notes.txt", "name = 'x'".to_string(), ".toml or .json"),
    ];
    for (name, text, needle) in cases {
        let path = d.join(name);
        std::fs::write(&path, text).expect("write config");
        assert_bad_input(d, &["run", "--config", path.to_str().expect("utf8")], needle);
    }
    assert_bad_input(d, &["run", "--config", "missing.toml"], "missing.toml");
}

/// A config's `[[claims]]` are checked with the rest of the plan: a claim naming a test bed,
/// estimator or budget the sweep does not run, or a number that is not finite, is bad input (exit
/// 2, one line naming the file, the claim and the field, nothing written), not a verdict.
#[test]
fn claims_of_a_config_are_checked_before_anything_is_written() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let sweep = SMALL.replace(
        "[[estimators]]\nid = 'is0_cv0'\n",
        "[[estimators]]\nid = 'is0_cv0'\n[[estimators]]\nid = 'delta_tracking'\n",
    );
    let slope = |estimator: &str, value: &str| {
        format!("[[claims]]\nkind = 'slope'\ntestbed = 'gradient-plane/default'\nestimator = '{estimator}'\nvalue = {value}\ntext = 'converges'\n")
    };
    let ratio = |extra: &str| {
        format!("[[claims]]\nkind = 'ratio'\ntestbed = 'gradient-plane/default'\nestimator = 'clamped_is0_cv0[clamp=1.5]'\nbaseline = 'is0_cv0'\ntext = 'lower error'\n{extra}")
    };
    let good = slope("is0_cv0", "-0.5");
    let cases = [
        (slope("is0_cv", "-0.5"), "claims[0].estimator = is0_cv: names no estimator of the sweep"),
        (format!("{good}{}", slope("clamped_is0_cv0[clamp=2]", "-0.5")), "claims[1].estimator = clamped_is0_cv0[clamp=2]"),
        (slope("is0_cv0", "nan"), "claims[0].value = NaN: not a finite number"),
        (slope("is0_cv0", "-inf"), "claims[0].value = -inf"),
        (good.replace("gradient-plane/default", "gradient-plane/glossy"), "claims[0].testbed = gradient-plane/glossy"),
        (good.replace("gradient-plane/default", "gradient-plane"), "claims[0].testbed = gradient-plane:"),
        (slope("delta_tracking", "-0.5"), "claims[0].estimator = delta_tracking: does not run on gradient-plane/default"),
        (ratio("threshold = inf\n"), "claims[0].threshold = inf"),
        (ratio("value = nan\n"), "claims[0].value = NaN"),
        (ratio("budget = 8\n"), "claims[0].budget = 8: not a budget of the sweep"),
        (ratio("").replace("'is0_cv0'", "'is0_cv0[clamp=1.5]'"), "claims[0].baseline = is0_cv0[clamp=1.5]"),
        (
            "[[claims]]\nkind = 'speedup'\ntestbed = 'gradient-plane/default'\nestimator = 'is0_cv0'\nvalue = 2.0\ntext = 'x'\n".into(),
            "claims[0].baseline = (none)",
        ),
        ("[[claims]]\nkind = 'control_flagged'\nestimator = 'clamped'\n".into(), "claims[0].estimator = clamped"),
        (ratio("range = 'right'\n"), "unknown field `range`"),
        (good.replace("value = -0.5\n", ""), "missing field `value`"),
    ];
    for (i, (claims, needle)) in cases.iter().enumerate() {
        let path = d.join(format!("claims_{i}.toml"));
        std::fs::write(&path, format!("{sweep}{claims}")).expect("write config");
        let err = assert_bad_input(d, &["run", "--config", path.to_str().expect("utf8")], needle);
        assert!(err.contains(&format!("claims_{i}.toml: ")), "the file is not named: {err}");
    }
    let json = r#"{"name":"tiny","budgets":[4,16],"testbeds":[{"id":"gradient-plane"}],"estimators":[{"id":"is0_cv0"}],"claims":[{"kind":"control_flagged","estimator":"is0_cv1"}]}"#;
    std::fs::write(d.join("claims.json"), json).expect("write");
    assert_bad_input(d, &["run", "--config", "claims.json"], "claims.json: invalid claims[0].estimator = is0_cv1");
    // A config's claims replace a named experiment's, and are checked as strictly (the
    // experiment's own, kept by a config that reshapes it without claims, are not: see shards.rs).
    std::fs::write(d.join("reshape.toml"), "[[claims]]\nkind = 'control_flagged'\nestimator = 'no_such'\n")
        .expect("write");
    let args = ["run", "surface-smc", "--config", "reshape.toml"];
    assert_bad_input(d, &args, "reshape.toml: invalid claims[0].estimator = no_such: names no estimator");
    // The same sweep with its claims right runs (and names them in its summary).
    std::fs::write(d.join("right.toml"), format!("{sweep}{good}{}", ratio("budget = 16\n"))).expect("write");
    let o = mcbench(d, &["run", "--config", "right.toml", "--no-plots", "--verbose"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("lower error"));
}

/// Every file under `root` with its bytes (an absent root is empty).
fn tree(root: &Path) -> std::collections::BTreeMap<std::path::PathBuf, Vec<u8>> {
    let mut out = std::collections::BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else { continue };
        for e in entries {
            let p = e.expect("dir entry").path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.clone(), std::fs::read(&p).expect("readable"));
            }
        }
    }
    out
}

/// Bad invocations against a folder that already holds a finished run exit 2 with
/// one line naming the flag or field, and leave every byte of `results/` and `plots/` as it was.
#[test]
fn bad_invocations_leave_existing_results_unchanged() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("tiny.toml"), SMALL).expect("write");
    let o = mcbench(d, &["run", "--config", "tiny.toml", "--threads", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let before = (tree(&d.join("results")), tree(&d.join("plots")));
    assert!(before.0.keys().any(|p| p.ends_with("tiny/summary.json")), "the run wrote its summary");
    std::fs::write(d.join("bad_param.toml"), SMALL.replace("clamp = 1.5", "clamp = -1.0")).expect("write");
    std::fs::write(d.join("bad_reps.toml"), SMALL.replace("reps = 3", "reps = 1")).expect("write");
    std::fs::write(d.join("bad_syntax.toml"), SMALL.replace("budgets = [4, 16, 64]", "budgets = [4, 16 64]"))
        .expect("w");
    let cases: [(&[&str], &str); 9] = [
        (&["run", "--config", "tiny.toml", "--reps", "0"], "--reps"),
        (&["run", "--config", "tiny.toml", "--seed", "-3"], "--seed"),
        (&["run", "--config", "tiny.toml", "--threads", "0"], "--threads"),
        (&["run", "--config", "tiny.toml", "--quick", "--full"], "--full"),
        (&["run", "--config", "bad_param.toml"], "clamp"),
        (&["run", "--config", "bad_reps.toml"], "reps"),
        (&["run", "--config", "bad_syntax.toml"], "(in `budgets = [4, 16 64]`)"),
        (&["run", "no-such-experiment", "--results", "results"], "no-such-experiment"),
        (&["plot", "results/no-such-run"], "no-such-run"),
    ];
    for (args, needle) in cases {
        let o = mcbench(d, args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: not one line: {err}");
        assert!(err.contains(needle), "{args:?}: '{err}' lacks '{needle}'");
        assert!(!err.contains("panicked"), "{err}");
        assert!(before == (tree(&d.join("results")), tree(&d.join("plots"))), "{args:?} changed results/ or plots/");
    }
}

#[test]
fn list_shows_what_runs_where() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = mcbench(dir.path(), &["list", "estimators"]);
    assert_eq!(o.status.code(), Some(0));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("is0_cv0") && out.contains("gradient-plane"), "{out}");
    let o = mcbench(dir.path(), &["list"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("surface-smc"));
}

#[test]
fn a_custom_sweep_runs_end_to_end_and_plots_can_be_redrawn() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    std::fs::write(d.join("tiny.toml"), SMALL).expect("write");
    let o = mcbench(d, &["run", "--config", "tiny.toml", "--threads", "2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for f in [
        "results/tiny/summary.csv",
        "results/tiny/integrals.csv.gz",
        "results/tiny/summary.json",
        "plots/tiny/report.md",
    ] {
        assert!(d.join(f).is_file(), "{f} missing");
    }
    // One screen: the experiment's line (claims and tests counted by verdict), the totals, what
    // did not hold, and where the report is; the tables only with --verbose.
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    let line = out.lines().find(|l| l.starts_with("tiny ")).unwrap_or_else(|| panic!("no line for tiny:\n{out}"));
    assert!(line.contains("claims ") && line.contains("tests ") && line.contains(" pass"), "{line}");
    assert!(out.contains("HTML report (open in a browser): plots/index.html"), "{out}");
    assert!(out.lines().count() <= 20 && !out.contains("clamped_is0_cv0[clamp=1.5]"), "{out}");
    let o = mcbench(d, &["run", "--config", "tiny.toml", "--threads", "2", "--verbose"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("clamped_is0_cv0[clamp=1.5]"));
    std::fs::remove_dir_all(d.join("plots")).expect("rm");
    let o = mcbench(d, &["plot", "results/tiny"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(d.join("plots/tiny/report.md").is_file());
    // A corrupt result file is bad input, not a panic.
    std::fs::write(d.join("results/tiny/summary.json"), "{").expect("write");
    let o = mcbench(d, &["plot", "results/tiny"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("summary.json"));
}

#[test]
fn a_selection_leaves_out_the_claims_on_what_it_leaves_out() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let claims = "[[claims]]\nkind = 'slope'\ntestbed = 'gradient-plane/default'\nestimator = 'is0_cv0'\nvalue = -0.5\ntext = 'plain'\n\
                  [[claims]]\nkind = 'control_flagged'\nestimator = 'clamped_is0_cv0[clamp=1.5]'\n";
    std::fs::write(d.join("tiny.toml"), format!("{SMALL}{claims}")).expect("write");
    // Without a selection both claims are judged; with one, the claim on the estimator left out
    // goes with it (one note), where it used to make the run refuse.
    let o = mcbench(d, &["run", "--config", "tiny.toml", "--estimators", "is0_cv0", "--no-plots"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let notes: Vec<String> = stderr(&o).lines().filter(|l| l.contains("left out")).map(String::from).collect();
    assert!(notes.len() == 1 && notes[0].contains("clamped_is0_cv0[clamp=1.5]"), "{notes:?}");
    let claims = std::fs::read_to_string(d.join("results/tiny/claims.csv")).expect("claims.csv");
    assert!(claims.contains("plain") && !claims.contains("clamped"), "{claims}");
}

#[test]
fn reference_command_stores_the_exact_reference() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = mcbench(dir.path(), &["reference", "gradient-plane", "--variant", "stiff"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(dir.path().join("results/references/gradient-plane_stiff.json").is_file());
    assert!(String::from_utf8_lossy(&o.stdout).contains("error bound"));
}

/// Runs resume: a run killed (SIGKILL) mid-way and run again with the same seed reuses
/// the cells it had finished, leaves no corrupt file, and ends with the same summary as a run that
/// was never interrupted (timing columns aside).
#[test]
fn a_killed_run_resumes_to_the_same_results() {
    const SLOW: &str = "name = 'slow'\nreps = 4\nbudgets = [4, 16, 64, 256, 1024, 4096, 16384]\n[[testbeds]]\nid = 'gradient-plane'\nparams = { resolution = 12 }\n[[estimators]]\nid = 'is0_cv0'\n[[estimators]]\nid = 'is1_cv2'\n[[estimators]]\nid = 'clamped_is0_cv0'\n";
    let (killed, clean) = (tempfile::tempdir().expect("tempdir"), tempfile::tempdir().expect("tempdir"));
    for d in [killed.path(), clean.path()] {
        std::fs::write(d.join("slow.toml"), SLOW).expect("write config");
    }
    let args = ["run", "--config", "slow.toml", "--threads", "2"];
    let mut child = Command::new(env!("CARGO_BIN_EXE_mcbench"))
        .current_dir(killed.path())
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("starts");
    let store = killed.path().join("results/slow/cells.store");
    // Cells whose records are whole (the store is read as a reader sees it while a writer appends:
    // a torn last record is not counted).
    let count = || mcbench::store::Store::open(&store).map(|s| s.records().len()).unwrap_or(0);
    let start = std::time::Instant::now();
    while count() < 3 && start.elapsed() < std::time::Duration::from_secs(120) {
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let still_running = child.try_wait().expect("status").is_none();
    child.kill().expect("SIGKILL");
    child.wait().expect("reaped");
    assert!(still_running, "the run finished before it could be killed: make the sweep slower");
    let stored = count();
    assert!((3..21).contains(&stored), "{stored} cells stored when killed");
    // Every stored cell decodes whole (records are appended with one write each and checksummed;
    // a torn last record would be dropped, never read).
    assert_eq!(common::stored_cells(&store).len(), stored);
    let resumed = mcbench(killed.path(), &[&args[..], &["--progress"]].concat());
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    let log = String::from_utf8_lossy(&resumed.stdout).to_string() + &stderr(&resumed);
    assert_eq!(log.matches("(resumed)").count(), stored, "{log}");
    let uninterrupted = mcbench(clean.path(), &args);
    assert!(uninterrupted.status.success(), "{}", stderr(&uninterrupted));
    let (a, b) = (killed.path().join("results/slow"), clean.path().join("results/slow"));
    assert_eq!(deterministic_csv(&a.join("summary.csv")), deterministic_csv(&b.join("summary.csv")));
    assert_eq!(common::integrals_text(&a), common::integrals_text(&b));
}
