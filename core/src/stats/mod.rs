//! Statistics for the convergence harness (book: statistics.md, slope-fits.md).
//!
//! - [`moments`]: compensated sums and exactly mergeable running mean/variance;
//! - [`hypothesis`]: one-sample t, z and Welch tests, Holm–Bonferroni, Šidák;
//! - [`power`]: the smallest shift a test detects (detectable bias), the t-test's skewness limit;
//! - [`chi_square`]: chi-square goodness of fit with merged low-expectation cells, histograms, and
//!   the shared [`StatsError`];
//! - [`two_sample`]: two estimators' means against each other (Welch per integral, a pooled test,
//!   the p-value histogram);
//! - [`regression`]: least-squares line and power-law (log-log) fits with a 95% slope interval.
//!
//! The commonly used items are re-exported here.

pub mod chi_square;
pub mod hypothesis;
pub mod moments;
pub mod power;
pub mod regression;
pub mod two_sample;

pub use chi_square::{chi_square_gof, histogram, ChiSquare, StatsError, MIN_EXPECTED_COUNT};
pub use hypothesis::{
    detectable_shift, detectable_shift_any, detectable_shift_t, holm_bonferroni, holm_bonferroni_finite, one_sample_t,
    sidak_alpha, t_quantile, t_test, t_test_skewness_limit, welch, z_test, TestOutcome,
};
pub use moments::{Moments, NeumaierSum};
pub use regression::{linear_fit, log_log_fit, weighted_linear_fit, SlopeFit};
