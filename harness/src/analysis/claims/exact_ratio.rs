//! Ratio claims where a cell is exact: its error is round-off ([`SummaryRow::at_roundoff`]), so a
//! ratio of errors (or of inverse errors) with it is zero or unbounded, not a number about
//! rounding errors, and which side of any positive threshold it lies on is known.

use super::ratio::RatioMetric;
use crate::analysis::metrics::SummaryRow;
use crate::verdict::Verdict;

/// A ratio `metric(a) / metric(b)` with an exact cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExactRatio {
    /// The numerator's error (or the denominator's inverse error) is round-off: the ratio is 0.
    Zero,
    /// The denominator's error (or the numerator's inverse error) is round-off: unbounded.
    Unbounded,
    /// Both cells are exact: no ratio.
    BothExact,
}

impl ExactRatio {
    /// The outcome when `a` or `b` is exact; `None` when neither is (the ratio is measured).
    pub fn of(metric: RatioMetric, a: &SummaryRow, b: &SummaryRow) -> Option<ExactRatio> {
        let zero_if_a = if metric.is_error() { ExactRatio::Zero } else { ExactRatio::Unbounded };
        match (a.at_roundoff(), b.at_roundoff()) {
            (true, true) => Some(ExactRatio::BothExact),
            (true, false) => Some(zero_if_a),
            (false, true) => Some(if zero_if_a == ExactRatio::Zero { ExactRatio::Unbounded } else { ExactRatio::Zero }),
            (false, false) => None,
        }
    }

    /// The verdict of "the ratio lies above `threshold`" (`above`, else below), with the reason.
    pub fn verdict(self, threshold: f64, above: bool) -> (Verdict, Option<bool>, String) {
        let high = match self {
            ExactRatio::BothExact => {
                return (
                    Verdict::Inconclusive,
                    None,
                    "both cells are exact (their errors are round-off): no ratio".into(),
                )
            }
            ExactRatio::Zero => false,
            ExactRatio::Unbounded => true,
        };
        let held = high == above;
        let side = if high { "unbounded, above" } else { "zero, below" };
        (
            if held { Verdict::Held } else { Verdict::NotHeld },
            Some(held),
            format!("exact: the ratio is {side} {threshold}"),
        )
    }

    /// How notes give it.
    pub fn describe(self) -> &'static str {
        match self {
            ExactRatio::Zero => "0 (the numerator is exact: its error is round-off)",
            ExactRatio::Unbounded => "unbounded (an exact cell: its error is round-off)",
            ExactRatio::BothExact => "undefined (both cells exact)",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(rmse: f64, bound: f64) -> SummaryRow {
        let mut r = crate::output::plot::tests::row("x", 64, rmse, 1.0);
        r.rmse_roundoff = bound;
        r
    }

    #[test]
    fn an_exact_cell_makes_a_ratio_zero_or_unbounded_and_decides_its_side() {
        let (exact, noisy, old) = (row(1e-17, 1e-15), row(0.1, 1e-15), row(0.1, f64::NAN));
        assert_eq!(ExactRatio::of(RatioMetric::Rmse, &noisy, &exact), Some(ExactRatio::Unbounded));
        assert_eq!(ExactRatio::of(RatioMetric::Rmse, &exact, &noisy), Some(ExactRatio::Zero));
        assert_eq!(ExactRatio::of(RatioMetric::Fom, &exact, &noisy), Some(ExactRatio::Unbounded));
        assert_eq!(ExactRatio::of(RatioMetric::Fom, &noisy, &exact), Some(ExactRatio::Zero));
        assert_eq!(ExactRatio::of(RatioMetric::Mse, &exact, &exact), Some(ExactRatio::BothExact));
        // Rows without a round-off bound (stored references, older files) are measured.
        assert_eq!(ExactRatio::of(RatioMetric::Rmse, &noisy, &old), None);
        assert_eq!(ExactRatio::Unbounded.verdict(2.0, true).1, Some(true));
        assert_eq!(ExactRatio::Unbounded.verdict(2.0, false).1, Some(false));
        assert_eq!(ExactRatio::Zero.verdict(1.0, false).0, Verdict::Held);
        assert_eq!(
            ExactRatio::BothExact.verdict(1.0, true),
            (Verdict::Inconclusive, None, ExactRatio::BothExact.verdict(1.0, true).2)
        );
    }
}
