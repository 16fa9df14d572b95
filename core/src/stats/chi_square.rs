//! Chi-square goodness of fit with merged low-expectation cells, histograms, and the error type
//! shared by the fallible routines of [`crate::stats`](super).

use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

use super::moments::NeumaierSum;

/// Smallest expected count a (merged) cell may have in [`chi_square_gof`].
pub const MIN_EXPECTED_COUNT: f64 = 5.0;

/// Errors of the fallible statistics routines.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StatsError {
    /// Two slices that must pair up element by element have different lengths.
    #[error("length mismatch: {what} has {left} entries but {right} were expected")]
    LengthMismatch {
        /// Which input is mismatched.
        what: &'static str,
        /// Length of the offending input.
        left: usize,
        /// Length it should have had.
        right: usize,
    },
    /// A probability is negative, infinite or NaN.
    #[error("invalid probability {value} at index {index}: must be finite and >= 0")]
    InvalidProbability {
        /// Index of the offending probability.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The probabilities do not sum to a finite positive number.
    #[error("probabilities sum to {total}: the total must be finite and > 0")]
    BadTotalProbability {
        /// The sum of the probabilities.
        total: f64,
    },
    /// There are no observations to test.
    #[error("no observations: the total observed count is 0")]
    NoObservations,
    /// After merging low-expectation cells fewer than two cells remain.
    #[error("only {cells} cell(s) remain after merging to expected count >= 5; need at least 2 (more samples or finer bins)")]
    TooFewCells {
        /// Number of merged cells.
        cells: usize,
    },
    /// A fit has too few points.
    #[error("too few points for a fit: {got} given, at least {needed} needed")]
    TooFewPoints {
        /// Points given.
        got: usize,
        /// Points needed.
        needed: usize,
    },
    /// A fit input is infinite or NaN.
    #[error("non-finite {axis} value {value} at index {index}")]
    NonFinite {
        /// `"x"`, `"y"` or `"var"` (a weighted fit's variances).
        axis: &'static str,
        /// Index of the point.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A log-log fit input (its logarithm is taken) or a weighted fit's variance is zero or negative.
    #[error("{axis} value {value} at index {index} is not > 0 (a logarithm or a weight needs it)")]
    NonPositive {
        /// `"x"`, `"y"` or `"var"`.
        axis: &'static str,
        /// Index of the point.
        index: usize,
        /// The value.
        value: f64,
    },
    /// All x values are equal, so the slope is undefined.
    #[error("all x values are equal: the slope is undefined")]
    DegenerateX,
}

/// Result of a chi-square goodness-of-fit test.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChiSquare {
    /// Pearson statistic `sum (O - E)^2 / E` over the merged cells (`inf` for an impossible cell).
    pub statistic: f64,
    /// Degrees of freedom, `cells - 1`.
    pub dof: usize,
    /// Upper-tail p-value of the statistic.
    pub p_value: f64,
    /// Number of cells after merging.
    pub cells: usize,
    /// Number of cells before merging (the input length).
    pub merged_from: usize,
}

/// Pearson chi-square goodness of fit of `observed` counts against cell probabilities.
///
/// `expected_prob` is normalised by its sum; expected counts are `N * p` with `N` the total
/// observed count. Adjacent cells are merged greedily in order until each merged cell has an
/// expected count of at least [`MIN_EXPECTED_COUNT`]; a trailing remainder below that joins the
/// previous merged cell. Degrees of freedom are `cells - 1` (no fitted parameters).
///
/// Any observation in a cell of probability exactly 0 is impossible under the hypothesis and
/// gives `statistic = inf`, `p_value = 0` regardless of the rest.
///
/// # Errors
/// Mismatched lengths, a negative or non-finite probability, a non-positive or non-finite total,
/// no observations, or fewer than two merged cells.
pub fn chi_square_gof(observed: &[u64], expected_prob: &[f64]) -> Result<ChiSquare, StatsError> {
    if observed.len() != expected_prob.len() {
        return Err(StatsError::LengthMismatch { what: "observed", left: observed.len(), right: expected_prob.len() });
    }
    let mut total_p = NeumaierSum::new();
    for (index, &value) in expected_prob.iter().enumerate() {
        if !value.is_finite() || value < 0.0 {
            return Err(StatsError::InvalidProbability { index, value });
        }
        total_p.add(value);
    }
    let total_p = total_p.value();
    if !(total_p > 0.0 && total_p.is_finite()) {
        return Err(StatsError::BadTotalProbability { total: total_p });
    }
    let n_obs: u64 = observed.iter().sum();
    if n_obs == 0 {
        return Err(StatsError::NoObservations);
    }
    let scale = n_obs as f64 / total_p;

    // Greedy merge, in order, to expected count >= MIN_EXPECTED_COUNT.
    let mut cells: Vec<(u64, f64)> = Vec::new();
    let (mut acc_o, mut acc_e, mut pending) = (0u64, 0.0f64, false);
    for (&o, &p) in observed.iter().zip(expected_prob) {
        acc_o += o;
        acc_e += p * scale;
        pending = true;
        if acc_e >= MIN_EXPECTED_COUNT {
            cells.push((acc_o, acc_e));
            (acc_o, acc_e, pending) = (0, 0.0, false);
        }
    }
    if pending {
        match cells.last_mut() {
            Some(last) => {
                last.0 += acc_o;
                last.1 += acc_e;
            }
            None => cells.push((acc_o, acc_e)),
        }
    }

    let impossible = observed.iter().zip(expected_prob).any(|(&o, &p)| o > 0 && p == 0.0);
    if impossible {
        return Ok(ChiSquare {
            statistic: f64::INFINITY,
            dof: cells.len().saturating_sub(1),
            p_value: 0.0,
            cells: cells.len(),
            merged_from: observed.len(),
        });
    }
    if cells.len() < 2 {
        return Err(StatsError::TooFewCells { cells: cells.len() });
    }

    let mut statistic = NeumaierSum::new();
    for &(o, e) in &cells {
        let d = o as f64 - e;
        statistic.add(d * d / e);
    }
    let statistic = statistic.value();
    let dof = cells.len() - 1;
    let p_value = ChiSquared::new(dof as f64).map(|d| d.sf(statistic)).unwrap_or(f64::NAN);
    Ok(ChiSquare { statistic, dof, p_value, cells: cells.len(), merged_from: observed.len() })
}

/// Counts `values` into the bins `[edges[i], edges[i+1])`, the last bin closed on the right.
///
/// `edges` must be sorted in increasing order; fewer than two edges give an empty histogram.
/// Values outside `[edges[0], edges[last]]` and NaNs are counted in no bin.
pub fn histogram(values: impl IntoIterator<Item = f64>, edges: &[f64]) -> Vec<u64> {
    if edges.len() < 2 {
        return Vec::new();
    }
    let bins = edges.len() - 1;
    let (first, last) = (edges[0], edges[bins]);
    let mut counts = vec![0u64; bins];
    for v in values {
        if !(v >= first && v <= last) {
            continue;
        }
        let idx = if v == last { bins - 1 } else { (edges.partition_point(|&e| e <= v) - 1).min(bins - 1) };
        counts[idx] += 1;
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    #[test]
    fn known_statistics_and_p_values() {
        // (60 - 50)^2/50 * 2 = 4, dof 1: p = 2 Phi(-2) = 0.0455002638963584.
        let r = chi_square_gof(&[60, 40], &[0.5, 0.5]).unwrap();
        assert!(close(r.statistic, 4.0, 1e-14));
        assert_eq!((r.dof, r.cells, r.merged_from), (1, 2, 2));
        assert!(close(r.p_value, 0.045_500_263_896_358_4, 1e-9), "{}", r.p_value);
        // Dice: statistic 13.4, dof 5, p = 0.0199052203347744 (closed form for odd dof).
        // Unnormalised weights are normalised.
        let r = chi_square_gof(&[5, 8, 9, 8, 10, 20], &[1.0; 6]).unwrap();
        assert!(close(r.statistic, 13.4, 1e-13));
        assert_eq!(r.dof, 5);
        assert!(close(r.p_value, 0.019_905_220_334_774_4, 1e-8), "{}", r.p_value);
        // Perfect agreement.
        assert_eq!(chi_square_gof(&[25, 75], &[0.25, 0.75]).unwrap().p_value, 1.0);
    }

    #[test]
    fn merges_low_expectation_cells_greedily() {
        // Expected 0.1, 0.2, 49.7, 50 -> cells {0,1,2} (50.0) and {3} (50).
        let r = chi_square_gof(&[1, 0, 49, 50], &[0.001, 0.002, 0.497, 0.5]).unwrap();
        assert_eq!((r.cells, r.merged_from, r.dof), (2, 4, 1));
        assert!(r.statistic.abs() < 1e-12, "{r:?}");
        // Trailing remainder (1 + 1 = 2 < 5) joins the previous cell: 49 | 49 + 1 + 1.
        let r = chi_square_gof(&[40, 55, 3, 2], &[0.49, 0.49, 0.01, 0.01]).unwrap();
        assert_eq!((r.cells, r.dof), (2, 1));
        let want = (40.0f64 - 49.0).powi(2) / 49.0 + (60.0f64 - 51.0).powi(2) / 51.0;
        assert!(close(r.statistic, want, 1e-12), "{} vs {want}", r.statistic);
    }

    #[test]
    fn impossible_cell_gives_zero_p() {
        let r = chi_square_gof(&[50, 49, 1], &[0.5, 0.5, 0.0]).unwrap();
        assert_eq!(r.p_value, 0.0);
        assert_eq!(r.statistic, f64::INFINITY);
        // Even when the cell would be merged away, and even with a single merged cell.
        assert_eq!(chi_square_gof(&[3, 1], &[1.0, 0.0]).unwrap().p_value, 0.0);
        // An empty zero-probability cell is harmless.
        let ok = chi_square_gof(&[50, 0, 50], &[0.5, 0.0, 0.5]).unwrap();
        assert_eq!(ok.p_value, 1.0);
    }

    #[test]
    fn input_errors() {
        use StatsError::*;
        assert!(matches!(chi_square_gof(&[1, 2], &[0.5]), Err(LengthMismatch { .. })));
        assert!(matches!(chi_square_gof(&[1, 2], &[0.5, -0.1]), Err(InvalidProbability { index: 1, .. })));
        assert!(matches!(chi_square_gof(&[1, 2], &[f64::NAN, 0.5]), Err(InvalidProbability { index: 0, .. })));
        assert!(matches!(chi_square_gof(&[1, 2], &[0.0, 0.0]), Err(BadTotalProbability { .. })));
        assert!(matches!(chi_square_gof(&[0, 0], &[0.5, 0.5]), Err(NoObservations)));
        assert!(matches!(chi_square_gof(&[1, 1, 1], &[1.0, 1.0, 1.0]), Err(TooFewCells { cells: 1 })));
        let msg = chi_square_gof(&[1, 1], &[0.5, 0.5]).unwrap_err().to_string();
        assert!(msg.contains("cell"), "{msg}");
    }

    #[test]
    fn accepts_correct_sampler_and_flags_biased_one() {
        let mut rng = Pcg64::seed_from_u64(0xC41_5002);
        let edges: Vec<f64> = (0..=20).map(|i| i as f64 / 20.0).collect();
        let probs = vec![1.0 / 20.0; 20];
        let good = histogram((0..100_000).map(|_| rng.gen::<f64>()), &edges);
        let r = chi_square_gof(&good, &probs).unwrap();
        assert!(r.p_value > 1e-3, "correct sampler rejected: {r:?}");
        let biased = histogram((0..100_000).map(|_| rng.gen::<f64>().powf(1.05)), &edges);
        let r = chi_square_gof(&biased, &probs).unwrap();
        assert!(r.p_value < 1e-6, "biased sampler accepted: {r:?}");
    }

    #[test]
    fn histogram_bins() {
        let edges = [0.0, 1.0, 2.0, 4.0];
        let v = [-0.1, 0.0, 0.5, 1.0, 1.999, 2.0, 3.5, 4.0, 4.1, f64::NAN];
        assert_eq!(histogram(v, &edges), vec![2, 2, 3]);
        assert!(histogram(v, &[1.0]).is_empty());
        assert_eq!(histogram(Vec::new(), &edges), vec![0, 0, 0]);
    }
}
