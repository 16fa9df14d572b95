//! The console summary of a finished run (every run prints a summary table): fits with
//! their unbiasedness verdicts, the paper's claims beside ours, and what was skipped.

use crate::output::query::Query;
use crate::output::report::{markdown_table, sig};
use crate::verdict::Verdict;

/// Prints the summary of one experiment's run that took `seconds`.
pub fn print_summary(r: &crate::output::RunReport, seconds: f64) {
    println!(
        "\n== {} ({} mode, seed {}, {} reps, {:.1} s) ==",
        r.meta.experiment, r.meta.mode, r.meta.seed, r.meta.reps, seconds
    );
    let fits: Vec<Vec<String>> = r
        .fits
        .iter()
        .map(|f| {
            let find = |prefix: &str| {
                Query::new(&r.tests)
                    .bed((&f.testbed, &f.variant))
                    .estimator(&f.estimator)
                    .iter()
                    .find(|t| t.test.starts_with(prefix))
            };
            let (holm, pooled) = (find("holm"), find("pooled"));
            let p = |t: Option<&crate::analysis::TestRow>| {
                t.filter(|t| !t.p_value.is_nan()).map(|t| sig(t.p_value, 3)).unwrap_or_else(|| "-".into())
            };
            vec![
                format!("{}/{}", f.testbed, f.variant),
                f.estimator.clone(),
                f.describe(crate::analysis::SlopeRange::Whole),
                f.describe(crate::analysis::SlopeRange::Right),
                p(holm),
                holm.map(|t| format!("{} ({})", t.verdict, t.claim)).unwrap_or_else(|| "-".into()),
                p(pooled),
                pooled.map(|t| t.verdict.clone()).unwrap_or_else(|| "-".into()),
            ]
        })
        .collect();
    println!(
        "{}",
        markdown_table(
            &[
                "test bed",
                "estimator",
                "slope [95% CI]",
                "right-end slope [95% CI]",
                "Holm p",
                "Holm verdict (claim)",
                "pooled p",
                "pooled verdict"
            ],
            &fits
        )
    );
    let claims: Vec<Vec<String>> = r
        .paper
        .iter()
        .map(|c| {
            let held = match c.verdict() {
                Verdict::NotHeld => "did NOT hold",
                v => v.as_str(),
            };
            vec![
                c.claim.clone(),
                c.paper_value.map(|v| sig(v, 3)).unwrap_or_default(),
                match (c.our_value, c.interval) {
                    (Some(v), Some([lo, hi])) => format!("{} [{}, {}]", sig(v, 3), sig(lo, 3), sig(hi, 3)),
                    (Some(v), None) => sig(v, 3),
                    (None, _) => "-".into(),
                },
                held.into(),
            ]
        })
        .collect();
    println!("{}", markdown_table(&["paper claim", "paper", "ours", "verdict"], &claims));
    if !r.unavailable.is_empty() {
        println!("not available yet: {}", r.unavailable.join(", "));
    }
    for s in &r.skipped {
        println!("skipped {} on {}/{}: {}", s.estimator, s.testbed, s.variant, s.reason);
    }
}
