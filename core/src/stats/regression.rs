//! Least-squares line fits with a Student t confidence interval on the slope, used for
//! convergence-order fits (log RMSE on log budget, book: slope-fits.md).

use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, StudentsT};

use super::chi_square::StatsError;

/// Result of an ordinary least-squares line fit `y = intercept + slope * x`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SlopeFit {
    /// Fitted slope (for [`log_log_fit`], the exponent; the convergence order is `-slope`).
    pub slope: f64,
    /// Fitted intercept (for [`log_log_fit`], on the log scale: `y ≈ exp(intercept) x^slope`).
    pub intercept: f64,
    /// Lower end of the two-sided 95% confidence interval of the slope.
    pub slope_ci_low: f64,
    /// Upper end of the two-sided 95% confidence interval of the slope.
    pub slope_ci_high: f64,
    /// Standard error of the slope (0 for exactly collinear points).
    pub slope_se: f64,
    /// Coefficient of determination (1 when all y are equal and the fit is exact).
    pub r2: f64,
    /// Number of points used.
    pub points: usize,
}

impl SlopeFit {
    /// The fitted line at `x`, in the coordinates of the fit (log-log fits: `ln y` at `ln x`).
    pub fn predict(&self, x: f64) -> f64 {
        self.intercept + self.slope * x
    }
}

/// Validates that every value is finite, naming the first one that is not.
fn check_finite(axis: &'static str, v: &[f64]) -> Result<(), StatsError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(StatsError::NonFinite { axis, index, value: v[index] }),
        None => Ok(()),
    }
}

/// Ordinary least squares of `y` on `x` with a 95% Student t interval (`points - 2` dof) on the
/// slope.
///
/// # Errors
/// Mismatched lengths, fewer than 3 points, a non-finite value, or all `x` equal.
pub fn linear_fit(x: &[f64], y: &[f64]) -> Result<SlopeFit, StatsError> {
    if x.len() != y.len() {
        return Err(StatsError::LengthMismatch { what: "y", left: y.len(), right: x.len() });
    }
    let n = x.len();
    if n < 3 {
        return Err(StatsError::TooFewPoints { got: n, needed: 3 });
    }
    check_finite("x", x)?;
    check_finite("y", y)?;
    let nf = n as f64;
    let mx = x.iter().sum::<f64>() / nf;
    let my = y.iter().sum::<f64>() / nf;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for (&xi, &yi) in x.iter().zip(y) {
        let (dx, dy) = (xi - mx, yi - my);
        sxx += dx * dx;
        sxy += dx * dy;
        syy += dy * dy;
    }
    if sxx <= 0.0 {
        return Err(StatsError::DegenerateX);
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let sse: f64 = x
        .iter()
        .zip(y)
        .map(|(&xi, &yi)| {
            let r = yi - (intercept + slope * xi);
            r * r
        })
        .sum();
    let dof = nf - 2.0;
    let slope_se = (sse / dof / sxx).sqrt();
    let t = StudentsT::new(0.0, 1.0, dof).map(|d| d.inverse_cdf(0.975)).unwrap_or(f64::NAN);
    let half = if slope_se == 0.0 { 0.0 } else { t * slope_se };
    let r2 = if syy > 0.0 { (1.0 - sse / syy).clamp(0.0, 1.0) } else { 1.0 };
    Ok(SlopeFit { slope, intercept, slope_ci_low: slope - half, slope_ci_high: slope + half, slope_se, r2, points: n })
}

/// Weighted least squares of `y` on `x` when each `y[i]` has its own (estimated) variance `var[i]`:
/// weights `w_i = 1 / var[i]`, slope `sum w (x - xw)(y - yw) / S` with `S = sum w (x - xw)^2` and
/// `xw`, `yw` the weighted means.
///
/// The slope's variance is `1 / S` when the variances are right. The residual chi-square
/// `chi2 = sum w r^2` has `n - 2` degrees of freedom under that model; when the points scatter more
/// than their variances say (`chi2 / (n - 2) > 1`: variances underestimated, or the line is not
/// straight) the variance is inflated by that ratio, so the interval is never narrower than the
/// model's nor than the scatter's. The 95% interval takes the Student t quantile with `var_dof`
/// degrees of freedom (those of the variance estimates; `f64::INFINITY` for known variances) while
/// the variances explain the scatter, and `n - 2` once the scatter sets the width.
///
/// `r2` is the weighted coefficient of determination.
///
/// # Errors
/// Mismatched lengths, fewer than 3 points, a non-finite value, a variance that is not `> 0`
/// (reported as a non-positive `var` value), or all `x` equal.
pub fn weighted_linear_fit(x: &[f64], y: &[f64], var: &[f64], var_dof: f64) -> Result<SlopeFit, StatsError> {
    if x.len() != y.len() {
        return Err(StatsError::LengthMismatch { what: "y", left: y.len(), right: x.len() });
    }
    if x.len() != var.len() {
        return Err(StatsError::LengthMismatch { what: "var", left: var.len(), right: x.len() });
    }
    let n = x.len();
    if n < 3 {
        return Err(StatsError::TooFewPoints { got: n, needed: 3 });
    }
    check_finite("x", x)?;
    check_finite("y", y)?;
    check_finite("var", var)?;
    if let Some(index) = var.iter().position(|&v| v <= 0.0) {
        return Err(StatsError::NonPositive { axis: "var", index, value: var[index] });
    }
    let w: Vec<f64> = var.iter().map(|v| 1.0 / v).collect();
    let sw: f64 = w.iter().sum();
    let mx = w.iter().zip(x).map(|(w, x)| w * x).sum::<f64>() / sw;
    let my = w.iter().zip(y).map(|(w, y)| w * y).sum::<f64>() / sw;
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for ((&wi, &xi), &yi) in w.iter().zip(x).zip(y) {
        let (dx, dy) = (xi - mx, yi - my);
        sxx += wi * dx * dx;
        sxy += wi * dx * dy;
        syy += wi * dy * dy;
    }
    if sxx <= 0.0 {
        return Err(StatsError::DegenerateX);
    }
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let chi2: f64 = w
        .iter()
        .zip(x)
        .zip(y)
        .map(|((&wi, &xi), &yi)| {
            let r = yi - (intercept + slope * xi);
            wi * r * r
        })
        .sum();
    let dof = n as f64 - 2.0;
    let ratio = chi2 / dof;
    let (scale, t_dof) = if ratio > 1.0 { (ratio, dof) } else { (1.0, var_dof.max(1.0)) };
    let slope_se = (scale / sxx).sqrt();
    let t = if t_dof.is_finite() {
        StudentsT::new(0.0, 1.0, t_dof).map(|d| d.inverse_cdf(0.975)).unwrap_or(f64::NAN)
    } else {
        1.959_963_984_540_054
    };
    let half = t * slope_se;
    let r2 = if syy > 0.0 { (1.0 - chi2 / syy).clamp(0.0, 1.0) } else { 1.0 };
    Ok(SlopeFit { slope, intercept, slope_ci_low: slope - half, slope_ci_high: slope + half, slope_se, r2, points: n })
}

/// Least squares of `ln y` on `ln x` (a power law `y = C x^slope`), as [`linear_fit`] on the logs.
///
/// # Errors
/// As [`linear_fit`], plus any `x` or `y` that is not `> 0` (named by axis and index).
pub fn log_log_fit(x: &[f64], y: &[f64]) -> Result<SlopeFit, StatsError> {
    if x.len() != y.len() {
        return Err(StatsError::LengthMismatch { what: "y", left: y.len(), right: x.len() });
    }
    check_finite("x", x)?;
    check_finite("y", y)?;
    let logs = |axis: &'static str, v: &[f64]| -> Result<Vec<f64>, StatsError> {
        v.iter()
            .enumerate()
            .map(
                |(index, &value)| {
                    if value > 0.0 {
                        Ok(value.ln())
                    } else {
                        Err(StatsError::NonPositive { axis, index, value })
                    }
                },
            )
            .collect()
    };
    linear_fit(&logs("x", x)?, &logs("y", y)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_pcg::Pcg64;
    use statrs::distribution::Normal;

    #[test]
    fn exact_power_law() {
        let x: Vec<f64> = (0..12).map(|i| 2f64.powi(i) * 16.0).collect();
        let y: Vec<f64> = x.iter().map(|&v| 3.0 * v.powf(-0.5)).collect();
        let f = log_log_fit(&x, &y).unwrap();
        assert!((f.slope + 0.5).abs() < 1e-12, "{f:?}");
        assert!((f.intercept - 3f64.ln()).abs() < 1e-11, "{f:?}");
        assert!(f.slope_ci_high - f.slope_ci_low < 1e-10, "{f:?}");
        assert!(f.slope_ci_low <= f.slope && f.slope <= f.slope_ci_high);
        assert!((f.r2 - 1.0).abs() < 1e-12);
        assert_eq!(f.points, 12);
    }

    #[test]
    fn exactly_collinear_has_zero_se() {
        let f = linear_fit(&[1.0, 2.0, 3.0, 4.0], &[3.0, 5.0, 7.0, 9.0]).unwrap();
        assert_eq!((f.slope, f.intercept, f.slope_se), (2.0, 1.0, 0.0));
        assert_eq!((f.slope_ci_low, f.slope_ci_high), (2.0, 2.0));
        assert_eq!(f.r2, 1.0);
        assert_eq!(f.predict(10.0), 21.0);
        let flat = linear_fit(&[1.0, 2.0, 3.0], &[4.0, 4.0, 4.0]).unwrap();
        assert_eq!((flat.slope, flat.r2), (0.0, 1.0));
    }

    #[test]
    fn textbook_interval() {
        // x = 1..5, y = 1, 3, 2, 5, 4: slope 0.8, intercept 0.6, SSE 3.6, Sxx 10,
        // se = sqrt(3.6/3/10) = sqrt(0.12); t_{0.975,3} = 3.182446305284263.
        let f = linear_fit(&[1.0, 2.0, 3.0, 4.0, 5.0], &[1.0, 3.0, 2.0, 5.0, 4.0]).unwrap();
        assert!((f.slope - 0.8).abs() < 1e-14 && (f.intercept - 0.6).abs() < 1e-14);
        assert!((f.slope_se - 0.12f64.sqrt()).abs() < 1e-14);
        let half = 3.182_446_305_284_263 * 0.12f64.sqrt();
        assert!((f.slope_ci_high - (0.8 + half)).abs() < 1e-9, "{f:?}");
        assert!((f.slope_ci_low - (0.8 - half)).abs() < 1e-9, "{f:?}");
        assert!((f.r2 - 0.64).abs() < 1e-14);
    }

    #[test]
    fn noisy_fit_covers_true_slope() {
        use rand::distributions::Distribution;
        let mut rng = Pcg64::seed_from_u64(0x10_6106);
        let noise = Normal::new(0.0, 0.05).unwrap();
        let x: Vec<f64> = (0..16).map(|i| 2f64.powf(4.0 + 0.5 * i as f64)).collect();
        let y: Vec<f64> = x.iter().map(|&v| 2.0 * v.powf(-0.5) * noise.sample(&mut rng).exp()).collect();
        let f = log_log_fit(&x, &y).unwrap();
        assert!(f.slope_ci_low < -0.5 && -0.5 < f.slope_ci_high, "{f:?}");
        assert!(f.slope_se > 0.0 && f.slope_ci_high - f.slope_ci_low < 0.1, "{f:?}");
        assert!(f.r2 > 0.9 && f.r2 < 1.0, "{f:?}");
    }

    #[test]
    fn interval_coverage_is_about_95_percent() {
        use rand::distributions::Distribution;
        let mut rng = Pcg64::seed_from_u64(42);
        let noise = Normal::new(0.0, 1.0).unwrap();
        let x: Vec<f64> = (0..6).map(f64::from).collect();
        let trials = 4000;
        let covered = (0..trials)
            .filter(|_| {
                let y: Vec<f64> = x.iter().map(|&v| 1.0 - 0.7 * v + noise.sample(&mut rng)).collect();
                let f = linear_fit(&x, &y).unwrap();
                f.slope_ci_low <= -0.7 && -0.7 <= f.slope_ci_high
            })
            .count();
        let rate = covered as f64 / trials as f64;
        // Binomial sd at 4000 trials is 0.0034; allow about 5 sd.
        assert!((rate - 0.95).abs() < 0.018, "coverage {rate}");
    }

    #[test]
    fn weighted_fit_covers_with_known_variances_and_widens_with_excess_scatter() {
        use rand::distributions::Distribution;
        let x: Vec<f64> = (1..=6).map(|k| k as f64).collect();
        // Variances spanning 100x: the noisy points must not pull the fit.
        let var: Vec<f64> = (0..6).map(|k| 0.01 * 10f64.powf(-(k as f64) / 2.5)).collect();
        let mut rng = Pcg64::seed_from_u64(11);
        let z = Normal::new(0.0, 1.0).unwrap();
        let trials = 2000;
        let covered = (0..trials)
            .filter(|_| {
                let y: Vec<f64> =
                    x.iter().zip(&var).map(|(&v, s2)| 0.3 - 0.5 * v + s2.sqrt() * z.sample(&mut rng)).collect();
                let f = weighted_linear_fit(&x, &y, &var, f64::INFINITY).unwrap();
                f.slope_ci_low <= -0.5 && -0.5 <= f.slope_ci_high
            })
            .count();
        let rate = covered as f64 / trials as f64;
        // Known variances: 95% unless the scatter inflates the interval (then more).
        assert!((0.94..=0.99).contains(&rate), "coverage {rate}");
        // Exact line: the slope, and an interval of the model's width.
        let y: Vec<f64> = x.iter().map(|&v| 1.0 + 2.0 * v).collect();
        let f = weighted_linear_fit(&x, &y, &var, f64::INFINITY).unwrap();
        assert!((f.slope - 2.0).abs() < 1e-12 && (f.intercept - 1.0).abs() < 1e-12, "{f:?}");
        assert!(f.slope_se > 0.0 && f.r2 == 1.0);
        // Scatter far beyond the variances: the interval grows by sqrt(chi2 / dof) and t(n - 2).
        let bent: Vec<f64> =
            x.iter().map(|&v| 1.0 + 2.0 * v + if (v as u32).is_multiple_of(2) { 1.0 } else { -1.0 }).collect();
        let g = weighted_linear_fit(&x, &bent, &var, f64::INFINITY).unwrap();
        assert!(g.slope_se > 10.0 * f.slope_se, "{g:?} vs {f:?}");
        assert!(matches!(
            weighted_linear_fit(&x, &y, &[1.0, 1.0, 0.0, 1.0, 1.0, 1.0], 5.0),
            Err(StatsError::NonPositive { axis: "var", index: 2, .. })
        ));
    }

    #[test]
    fn errors_name_the_problem() {
        use StatsError::*;
        assert!(matches!(log_log_fit(&[1.0, 2.0], &[1.0, 2.0]), Err(TooFewPoints { got: 2, needed: 3 })));
        assert!(matches!(
            log_log_fit(&[1.0, 2.0, 0.0], &[1.0, 2.0, 3.0]),
            Err(NonPositive { axis: "x", index: 2, .. })
        ));
        assert!(matches!(
            log_log_fit(&[1.0, 2.0, 3.0], &[1.0, -2.0, 3.0]),
            Err(NonPositive { axis: "y", index: 1, .. })
        ));
        assert!(matches!(
            log_log_fit(&[1.0, 2.0, 3.0], &[1.0, f64::NAN, 3.0]),
            Err(NonFinite { axis: "y", index: 1, .. })
        ));
        assert!(matches!(linear_fit(&[1.0, 2.0, 3.0], &[1.0, 2.0]), Err(LengthMismatch { .. })));
        assert!(matches!(linear_fit(&[2.0, 2.0, 2.0], &[1.0, 2.0, 3.0]), Err(DegenerateX)));
        let msg = log_log_fit(&[1.0, 2.0, 3.0], &[1.0, 0.0, 3.0]).unwrap_err().to_string();
        assert!(msg.contains("y value 0") && msg.contains("index 1"), "{msg}");
    }
}
