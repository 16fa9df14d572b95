//! The calibration of `mcbench compare` (book: statistics.md, "Comparing runs, measured"): over
//! seed pairs, runs of `experiments::planted::CONFIG` compared as `mcbench compare` compares them.
//!
//! Per pair `k`: A at seed `2k + 1` and, at seed `2k + 2`, the same code (B), a planted 2% bias and
//! a planted 20% variance increase. The false rates count every row of A against B (the same
//! code at another seed) that reads improved or regressed, per metric; the power counts the pairs
//! where `planted_mc` reads regressed: the bias in its unbiasedness row, the variance in its RMSE
//! at the largest budget (and in its MSE-based efficiency, a timing row).
//!
//! `cargo run --release -p experiments --example compare_calibration -- [pairs] [folder]`
//! (default 50 pairs, in a temporary folder that is removed at the end).

use experiments::planted::{run, BIASED, NOISY, PLAIN};
use mcbench::compare::change::{ChangeVerdict, Metric};
use mcbench::compare::{compare, load, Comparison, Margins};
use std::collections::BTreeMap;
use std::path::Path;

fn side(dir: &Path, name: &str) -> load::Side {
    load::read_side(name, &dir.join(name)).expect("reads")
}

fn cmp(dir: &Path, a: &str, b: &str) -> Comparison {
    compare(&side(dir, a), &side(dir, b), Margins::default()).expect("compares")
}

fn regressed(c: &Comparison, metric: Metric, budget: Option<u64>) -> bool {
    c.changes.iter().any(|r| {
        r.estimator == "planted_mc"
            && r.metric == metric
            && (budget.is_none() || r.budget == budget)
            && r.verdict == ChangeVerdict::Regressed
    })
}

fn main() {
    let mut args = std::env::args().skip(1);
    let pairs: u64 = args.next().map(|a| a.parse().expect("pairs: a number")).unwrap_or(50);
    let tmp = tempfile::tempdir().expect("tempdir");
    let dir = args.next().map(std::path::PathBuf::from).unwrap_or_else(|| tmp.path().to_path_buf());
    // metric -> (rows, improved, regressed, no change)
    let mut counts: BTreeMap<&'static str, [u64; 4]> = BTreeMap::new();
    let (mut bias_hits, mut var_hits, mut var_eff_hits, mut bias_rmse_hits) = (0, 0, 0, 0);
    let t0 = std::time::Instant::now();
    for k in 0..pairs {
        let d = dir.join(format!("pair-{k}"));
        std::fs::create_dir_all(&d).expect("mkdir");
        run(&d, "a", &PLAIN, 2 * k + 1);
        run(&d, "same", &PLAIN, 2 * k + 2);
        run(&d, "biased", &BIASED, 2 * k + 2);
        run(&d, "noisy", &NOISY, 2 * k + 2);
        let same = cmp(&d, "a", "same");
        for r in &same.changes {
            let c = counts.entry(r.metric.name()).or_default();
            c[0] += 1;
            match r.verdict {
                ChangeVerdict::Improved => c[1] += 1,
                ChangeVerdict::Regressed => c[2] += 1,
                ChangeVerdict::NoChange => c[3] += 1,
                ChangeVerdict::Inconclusive => {}
            }
        }
        let biased = cmp(&d, "a", "biased");
        bias_hits += u64::from(regressed(&biased, Metric::Unbiasedness, None));
        bias_rmse_hits += u64::from(regressed(&biased, Metric::Rmse, None));
        let noisy = cmp(&d, "a", "noisy");
        var_hits += u64::from(regressed(&noisy, Metric::Rmse, Some(256)));
        var_eff_hits += u64::from(regressed(&noisy, Metric::EfficiencyMse, Some(256)));
        std::fs::remove_dir_all(&d).expect("clean up");
        eprintln!("pair {k}: {:.0} s", t0.elapsed().as_secs_f64());
        if (k + 1) % 10 == 0 || k + 1 == pairs {
            let hits = [bias_hits, bias_rmse_hits, var_hits, var_eff_hits];
            eprint!("{}", table(k + 1, &counts, hits, t0.elapsed().as_secs_f64()));
        }
    }
    print!(
        "{}",
        table(pairs, &counts, [bias_hits, bias_rmse_hits, var_hits, var_eff_hits], t0.elapsed().as_secs_f64())
    );
}

/// The measured rates as a markdown table and the power lines.
fn table(pairs: u64, counts: &BTreeMap<&'static str, [u64; 4]>, hits: [u64; 4], seconds: f64) -> String {
    let [bias_hits, bias_rmse_hits, var_hits, var_eff_hits] = hits;
    let mut out = String::new();
    let m = Margins::default();
    out.push_str(&format!(
        "{pairs} seed pairs, margins: RMSE ±{:.1}%, FoM ±{:.2}%, efficiencies (CPU time) ±{:.1}%, slopes ±{}\n",
        100.0 * m.of(Metric::Rmse),
        100.0 * m.of(Metric::Fom),
        100.0 * m.of(Metric::EfficiencyMse),
        m.slope
    ));
    out.push_str("| metric | rows | false improved | false regressed | no change |\n|---|---|---|---|---|\n");
    let pct = |n: u64, d: u64| format!("{:.1}%", 100.0 * n as f64 / d.max(1) as f64);
    for (m, c) in counts {
        out.push_str(&format!(
            "| {m} | {} | {} ({}) | {} ({}) | {} |\n",
            c[0],
            c[1],
            pct(c[1], c[0]),
            c[2],
            pct(c[2], c[0]),
            pct(c[3], c[0])
        ));
    }
    out.push_str(&format!("planted 2% bias: unbiasedness regressed in {bias_hits} of {pairs} pairs; RMSE regressed at some budget in {bias_rmse_hits}\n"));
    out.push_str(&format!("planted 20% variance: RMSE at 256 regressed in {var_hits} of {pairs} pairs; MSE-based efficiency at 256 in {var_eff_hits}\n"));
    out.push_str(&format!("{seconds:.0} s\n"));
    out
}
