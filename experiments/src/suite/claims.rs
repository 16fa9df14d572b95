//! Judging paper claims against a run: slope claims and speed-up claims.

use crate::analysis::Fit;
use crate::output::{Claim, RunReport};

/// The fit of an estimator on a test bed, if the run has one.
pub fn fit<'a>(report: &'a RunReport, testbed: &str, variant: &str, estimator: &str) -> Option<&'a Fit> {
    report.fits.iter().find(|f| f.testbed == testbed && f.variant == variant && f.estimator == estimator)
}

fn not_measured(testbed: &str, claim: &str, paper: f64, why: String) -> Claim {
    Claim {
        testbed: testbed.into(),
        claim: claim.into(),
        paper_value: Some(paper),
        our_value: None,
        held: None,
        note: why,
    }
}

/// "Estimator X converges with slope `paper`": held when our 95% CI contains the paper's slope.
pub fn slope_matches(report: &RunReport, tb: (&str, &str), estimator: &str, paper: f64, claim: &str) -> Claim {
    match fit(report, tb.0, tb.1, estimator) {
        None => not_measured(tb.0, claim, paper, format!("{estimator} did not run (not available or skipped)")),
        Some(f) => Claim {
            testbed: format!("{}/{}", tb.0, tb.1),
            claim: claim.into(),
            paper_value: Some(paper),
            our_value: Some(f.slope),
            held: Some(f.slope_ci_low <= paper && paper <= f.slope_ci_high),
            note: format!("held if the 95% CI [{:.3}, {:.3}] contains {paper}", f.slope_ci_low, f.slope_ci_high),
        },
    }
}

/// "Estimator X converges faster than independent MC, reaching slope `paper`": held when our CI
/// excludes -0.5 on the steep side; the paper's magnitude is compared in the note.
pub fn slope_steeper(report: &RunReport, tb: (&str, &str), estimator: &str, paper: f64, claim: &str) -> Claim {
    match fit(report, tb.0, tb.1, estimator) {
        None => not_measured(tb.0, claim, paper, format!("{estimator} did not run (not available or skipped)")),
        Some(f) => Claim {
            testbed: format!("{}/{}", tb.0, tb.1),
            claim: claim.into(),
            paper_value: Some(paper),
            our_value: Some(f.slope),
            held: Some(f.slope_ci_high < -0.5),
            note: format!(
                "held if the 95% CI [{:.3}, {:.3}] lies below -0.5; the paper's {paper} is {} our CI",
                f.slope_ci_low,
                f.slope_ci_high,
                if paper < f.slope_ci_low {
                    "steeper than"
                } else if paper > f.slope_ci_high {
                    "shallower than"
                } else {
                    "inside"
                }
            ),
        },
    }
}

/// "X beats the baseline by `paper` x at equal time": held when our speed-up is at least half the
/// paper's (budgets and machines differ; the ratio is in the note).
pub fn speedup_claim(report: &RunReport, tb: (&str, &str), estimator: &str, paper: f64, claim: &str) -> Claim {
    let s = report.speedups.iter().find(|s| s.testbed == tb.0 && s.variant == tb.1 && s.estimator == estimator);
    match s {
        None => not_measured(
            tb.0,
            claim,
            paper,
            format!("no speed-up for {estimator} (not available, skipped, or no baseline fit)"),
        ),
        Some(s) => Claim {
            testbed: format!("{}/{}", tb.0, tb.1),
            claim: claim.into(),
            paper_value: Some(paper),
            our_value: Some(s.speedup),
            held: Some(s.speedup >= 0.5 * paper),
            note: format!(
                "at {} spp: {:.3}x fewer samples, {:.3}x overhead; held if >= half the paper's factor",
                s.budget, s.sample_ratio, s.overhead
            ),
        },
    }
}

/// "The biased control is flagged by the unbiasedness test".
pub fn control_flagged(report: &RunReport, control: &str) -> Claim {
    let rows: Vec<_> = report.tests.iter().filter(|t| t.estimator == control && t.test.starts_with("holm")).collect();
    let min_p = rows.iter().map(|t| t.p_value).fold(f64::INFINITY, f64::min);
    Claim {
        testbed: rows.first().map(|t| format!("{}/{}", t.testbed, t.variant)).unwrap_or_default(),
        claim: format!("harness (SPEC §6): the biased control {control} is flagged at p < 1e-6"),
        paper_value: Some(1e-6),
        our_value: rows.first().map(|_| min_p),
        held: (!rows.is_empty()).then(|| min_p < 1e-6),
        note: "smallest Holm-adjusted p-value of the per-integral t-tests".into(),
    }
}
