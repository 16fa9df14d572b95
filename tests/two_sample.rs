//! `mcbench compare A B --two-sample EA EB` (book: compare.md): two estimators against each other
//! without a reference. Two small runs at different seeds: two unbiased estimators of one test bed
//! do not read `differ`, an unbiased estimator against the biased control does; bad input is
//! refused with exit code 2 and nothing written.

use std::path::Path;
use std::process::{Command, Output};

fn mcbench(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mcbench")).current_dir(dir).args(args).output().expect("binary runs")
}

/// The verdicts of `two_sample.csv` in `out`, and its header.
fn verdicts(out: &Path) -> (String, Vec<String>) {
    let text = std::fs::read_to_string(out.join("two_sample.csv")).expect("two_sample.csv");
    let mut lines = text.lines();
    let header = lines.next().expect("a header").to_string();
    let col = header.split(',').position(|c| c == "verdict").expect("a verdict column");
    (header, lines.map(|l| l.split(',').nth(col).expect("a verdict").to_string()).collect())
}

#[test]
fn two_unbiased_estimators_do_not_differ_and_the_control_does() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let d = tmp.path();
    let config =
        "name = 'pair'\nreps = 64\nbudgets = [16]\n[[testbeds]]\nid = 'gradient-plane'\nparams = { resolution = 4 }\n\
                  [[estimators]]\nid = 'is0_cv0'\n[[estimators]]\nid = 'is1_cv2'\n\
                  [[estimators]]\nid = 'clamped_is0_cv0'\nparams = { clamp = 1.5 }\n";
    std::fs::write(d.join("pair.toml"), config).expect("config");
    // Run A writes its integrals (the pixels' places for the maps), run B none.
    for (seed, results, integrals) in [("1", "one", "gz"), ("2", "two", "none")] {
        let o = mcbench(
            d,
            &[
                "run",
                "--config",
                "pair.toml",
                "--no-plots",
                "--integrals",
                integrals,
                "--seed",
                seed,
                "--results",
                results,
            ],
        );
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let compare = |ea: &str, eb: &str, out: &str| {
        let o = mcbench(d, &["compare", "one/pair", "two/pair", "--out", out, "--two-sample", ea, eb]);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        let stdout = String::from_utf8_lossy(&o.stdout).to_string();
        assert!(stdout.contains(&format!("two-sample {ea} (A) vs {eb}")) && stdout.contains(": 1 cells"), "{stdout}");
        for f in
            ["two_sample.csv", "two_sample.json", "two_sample_integrals.csv", "two_sample_tiles.csv", "compare.html"]
        {
            assert!(d.join(out).join(f).is_file(), "{f}");
        }
        verdicts(&d.join(out))
    };
    let (header, same) = compare("is0_cv0", "is1_cv2", "unbiased");
    eprintln!("{}", std::fs::read_to_string(d.join("unbiased/two_sample.csv")).unwrap_or_default());
    assert_eq!(same.len(), 1);
    assert!(same[0] == "same" || same[0] == "inconclusive", "{same:?}");
    assert_eq!(Some(header), listed("two_sample.csv"), "two_sample.csv's header is the contract chapter's");
    let (_, differ) = compare("is0_cv0", "clamped_is0_cv0", "control");
    eprintln!("{}", std::fs::read_to_string(d.join("control/two_sample.csv")).unwrap_or_default());
    assert_eq!(differ, vec!["differ".to_string()]);
    let html = std::fs::read_to_string(d.join("control/compare.html")).expect("page");
    assert!(
        html.contains("is0_cv0 (A) against clamped_is0_cv0[clamp=1.5] (B), without a reference"),
        "the page's section"
    );
    // The per-integral tests: 16 pixels, 3 channels.
    let per = std::fs::read_to_string(d.join("control/two_sample_integrals.csv")).expect("csv");
    assert_eq!(per.lines().count(), 1 + 16 * 3);
    assert_eq!(per.lines().next().map(String::from), listed("two_sample_integrals.csv"));
    // 4 x 4 pixels: one map, one tile of 16 pixels.
    assert!(
        html.contains("gradient-plane/default at 16 samples: per pixel, A against B")
            && html.contains("data:image/png")
    );
    let tiles = std::fs::read_to_string(d.join("control/two_sample_tiles.csv")).expect("tiles");
    let lines: Vec<&str> = tiles.lines().collect();
    assert_eq!(Some(lines[0].to_string()), listed("two_sample_tiles.csv"));
    assert_eq!(lines.len(), 2);
    assert!(lines[1].starts_with("gradient-plane,default,16,0,0,0,16,"), "{}", lines[1]);

    // Bad input: exit 2, one line naming the flag, nothing written.
    let bad = |ea: &str, eb: &str, needle: &str| {
        let o = mcbench(d, &["compare", "one/pair", "two/pair", "--out", "refused", "--two-sample", ea, eb]);
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains("--two-sample") && err.contains(needle), "{err}");
        assert!(!d.join("refused").exists(), "nothing written");
    };
    bad("nope", "is0_cv0", "its estimators: clamped_is0_cv0[clamp=1.5], is0_cv0, is1_cv2");
    bad("is0_cv0", "missing_id", "missing_id");
    // No shared (test bed, variant, budget): another budget in B.
    let other = config.replace("budgets = [16]", "budgets = [8]");
    std::fs::write(d.join("other.toml"), other).expect("config");
    let o = mcbench(d, &["run", "--config", "other.toml", "--no-plots", "--integrals", "none", "--results", "three"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let o =
        mcbench(d, &["compare", "one/pair", "three/pair", "--out", "refused", "--two-sample", "is0_cv0", "is1_cv2"]);
    let err = String::from_utf8_lossy(&o.stderr).to_string();
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--two-sample") && err.contains("share no"), "{err}");
    assert!(!d.join("refused").exists(), "nothing written");
}

/// The list after `<!-- contract: NAME -->` in the contract chapter.
fn listed(name: &str) -> Option<String> {
    let doc = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/src/contract.md")).ok()?;
    let after = doc.split_once(&format!("<!-- contract: {name} -->"))?.1;
    after.lines().nth(2).map(String::from)
}
