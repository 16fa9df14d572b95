//! Slope claims: a convergence slope's 95% interval holds, or lies below, the paper's value, over
//! the whole budget range or its right end (where a paper's "reaches" is judged).

use super::{fit, not_measured};
use crate::analysis::{SlopeOutcome, SlopeRange};
use crate::output::{Claim, RunReport};
use crate::verdict::Verdict;

/// The log-log slope between the last two budgets of a series (the local order at the right end).
pub fn last_segment_slope(report: &RunReport, testbed: &str, variant: &str, estimator: &str) -> Option<f64> {
    let rows: Vec<_> =
        report.query().testbed(testbed).variant(variant).estimator(estimator).iter().filter(|r| r.rmse > 0.0).collect();
    let [.., a, b] = rows.as_slice() else { return None };
    Some((b.rmse / a.rmse).ln() / (b.budget as f64 / a.budget as f64).ln())
}

/// The half-width of a slope interval that can tell a claimed slope from one `SLOPE_TOLERANCE` away:
/// "converges with slope s" holds only when the 95% interval holds `s` and is no wider than
/// `s ± SLOPE_TOLERANCE` (a wide interval holds every slope and decides nothing).
pub const SLOPE_TOLERANCE: f64 = 0.05;

/// A claim judged on an estimator's slope over `range`: `judge` gets (CI low, CI high, slope) and
/// gives (held, note), `None` for inconclusive; not measured without a fit or without a slope over
/// that range (a right-end slope needs 3 budgets); inconclusive for an estimator exact at every
/// budget ([`SlopeOutcome::Exact`]).
fn slope_claim(
    report: &RunReport,
    tb: (&str, &str),
    (estimator, range): (&str, SlopeRange),
    paper: f64,
    claim: &str,
    judge: impl Fn(f64, f64, f64) -> (Option<bool>, String),
) -> Claim {
    match fit(report, tb.0, tb.1, estimator) {
        None => not_measured(tb.0, claim, paper, format!("{estimator} did not run (not available or skipped)")),
        Some(f) if f.outcome == SlopeOutcome::Exact => Claim {
            testbed: format!("{}/{}", tb.0, tb.1),
            claim: claim.into(),
            paper_value: Some(paper),
            our_value: None,
            held: None,
            note: format!("{estimator} is exact at every budget ({:?}): its RMSE is round-off", f.budgets),
            verdict: Some(Verdict::Inconclusive),
            reason: "exact at every budget: no slope to judge, an error of rounding alone has no order of \
                     convergence"
                .into(),
            ..Default::default()
        },
        Some(f) => {
            let (slope, lo, hi) = f.range(range);
            if !(slope.is_finite() && lo.is_finite() && hi.is_finite()) {
                return not_measured(
                    tb.0,
                    claim,
                    paper,
                    format!("no {} slope of {estimator} (too few budgets)", range.describe()),
                );
            }
            let (held, note) = judge(lo, hi, slope);
            let budgets = f.budgets_of(range);
            let over = format!(
                "{} fit over budgets {}..{} ({})",
                range.describe(),
                budgets.first().copied().unwrap_or(0),
                budgets.last().copied().unwrap_or(0),
                if f.method.is_empty() { "ols" } else { &f.method }
            );
            let beside = match range {
                SlopeRange::Whole if f.slope_right.is_finite() => format!(
                    "; right-end slope {:.3} [{:.3}, {:.3}]",
                    f.slope_right, f.slope_right_ci_low, f.slope_right_ci_high
                ),
                SlopeRange::Right => {
                    format!("; whole-range slope {:.3} [{:.3}, {:.3}]", f.slope, f.slope_ci_low, f.slope_ci_high)
                }
                _ => String::new(),
            };
            let verdict = match held {
                Some(true) => Verdict::Held,
                Some(false) => Verdict::NotHeld,
                None => Verdict::Inconclusive,
            };
            Claim {
                testbed: format!("{}/{}", tb.0, tb.1),
                claim: claim.into(),
                paper_value: Some(paper),
                our_value: Some(slope),
                held,
                note: format!("{over}{beside}"),
                verdict: Some(verdict),
                interval: Some([lo, hi]),
                reason: note,
                ..Default::default()
            }
        }
    }
}

/// "Estimator X converges with slope `paper`": not held when our 95% CI over the whole range
/// misses the paper's slope, held when it holds it and is at most [`SLOPE_TOLERANCE`] wide on
/// either side, inconclusive otherwise (the right-end slope and the slope over the last two
/// budgets are in the note).
pub fn slope_matches(report: &RunReport, tb: (&str, &str), estimator: &str, paper: f64, claim: &str) -> Claim {
    slope_matches_over(report, tb, (estimator, SlopeRange::Whole), paper, claim)
}

/// "Estimator X reaches slope `paper`": [`slope_matches`] judged on the right-end fit (the last
/// [`crate::analysis::RIGHT_END_BUDGETS`] budgets), where a method's asymptotic order shows.
pub fn slope_reaches(report: &RunReport, tb: (&str, &str), estimator: &str, paper: f64, claim: &str) -> Claim {
    slope_matches_over(report, tb, (estimator, SlopeRange::Right), paper, claim)
}

/// [`slope_matches`] over a chosen range of budgets.
pub fn slope_matches_over(
    report: &RunReport,
    tb: (&str, &str),
    (estimator, range): (&str, SlopeRange),
    paper: f64,
    claim: &str,
) -> Claim {
    let last =
        last_segment_slope(report, tb.0, tb.1, estimator).map(|s| format!("{s:.3}")).unwrap_or_else(|| "-".into());
    slope_claim(report, tb, (estimator, range), paper, claim, |lo, hi, _| {
        let within = lo <= paper && paper <= hi;
        let narrow = (hi - lo) / 2.0 <= SLOPE_TOLERANCE;
        let held = if !within {
            Some(false)
        } else if narrow {
            Some(true)
        } else {
            None
        };
        let why = match held {
            Some(false) => format!("the 95% CI [{lo:.3}, {hi:.3}] misses {paper}"),
            Some(true) => format!("the 95% CI [{lo:.3}, {hi:.3}] holds {paper} within ±{SLOPE_TOLERANCE}"),
            None => format!(
                "the 95% CI [{lo:.3}, {hi:.3}] holds {paper} but is wider than ±{SLOPE_TOLERANCE}, so it cannot tell {paper} from slopes {SLOPE_TOLERANCE} away (more repetitions or budgets would narrow it)"
            ),
        };
        (held, format!("{why}; slope over the last two budgets {last}"))
    })
}

/// "Estimator X converges faster than independent MC": held when our whole-range CI lies below
/// -0.5, not held when above, inconclusive when it holds -0.5; the paper's slope `paper` is
/// compared in the note (and judged by [`slope_matches`]).
pub fn slope_steeper(report: &RunReport, tb: (&str, &str), estimator: &str, paper: f64, claim: &str) -> Claim {
    slope_claim(report, tb, (estimator, SlopeRange::Whole), paper, claim, |lo, hi, _| {
        let place = if paper < lo {
            "steeper than"
        } else if paper > hi {
            "shallower than"
        } else {
            "inside"
        };
        let note =
            format!("held if the 95% CI [{lo:.3}, {hi:.3}] lies below -0.5; the paper's {paper} is {place} our CI");
        (below(lo, hi, -0.5), note)
    })
}

/// Held when `[lo, hi]` lies below `x`, not held when above, inconclusive when it holds `x`.
fn below(lo: f64, hi: f64, x: f64) -> Option<bool> {
    if hi < x {
        Some(true)
    } else if lo > x {
        Some(false)
    } else {
        None
    }
}

/// "Estimator X converges faster than slope `threshold`": held when our CI over `range` lies below
/// it, not held when above, inconclusive when it holds it.
pub fn slope_steeper_than(
    report: &RunReport,
    tb: (&str, &str),
    (estimator, range): (&str, SlopeRange),
    threshold: f64,
    claim: &str,
) -> Claim {
    slope_claim(report, tb, (estimator, range), threshold, claim, |lo, hi, _| {
        (below(lo, hi, threshold), format!("held if the 95% CI [{lo:.3}, {hi:.3}] lies below {threshold}"))
    })
}
