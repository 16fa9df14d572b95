//! The round-off bound: how far apart two evaluations of the same deterministic estimate may lie
//! through floating-point rounding alone, and so how small a spread or an error must be to say
//! nothing about an estimator but that it is exact.
//!
//! An estimate that averages `n` terms of magnitude about `m` in double precision rounds each
//! partial sum by up to half an ulp of it; when the terms are nearly equal, as they are exactly
//! when an estimator has no variance, those roundings share a sign and add up: the mean drifts by
//! up to `(n - 1) eps / 2` relative (the classical bound of recursive summation of terms of one
//! sign), on top of a few ulps from the arithmetic of each term. The bound of one integral and
//! channel is twice that, plus [`ROUNDOFF_ULPS`] ulps:
//!
//! `u = eps x max(|mean|, |reference|) x (ROUNDOFF_ULPS + n)`
//!
//! with `eps` the machine epsilon (2.2e-16) and `n` the operations behind one estimate: the largest
//! of its samples, fetches, rays and target evaluations per estimate, and of its sample or fetch
//! budget. On a furnace (cosine-weighted sampling of a constant sky) the mean drifted by 0.09 n
//! ulps at 256 samples, a twelfth of the bound. It stays far below anything statistical: 2.2e-10
//! relative at a million operations per estimate, and an estimator whose spread is below it has a
//! mean whose noise is below it too. The magnitudes are the mean's and the reference's: an
//! estimator whose terms cancel to a much smaller mean can round beyond the bound. An integral
//! whose value and reference are both zero has `u = 0`: only exactly equal repetitions are
//! zero-variance there.

use crate::run::cell::CellResult;
use mcbench_core::budget::BudgetKind;
use mcbench_core::testbed::{Reference, ReferenceKind};

/// Ulps of the magnitude that round-off may account for beyond the summation's one ulp per
/// operation.
pub const ROUNDOFF_ULPS: f64 = 16.0;

/// The round-off bound of a mean of magnitude `magnitude` made from `operations` operations per
/// estimate (see the module documentation).
pub fn bound(magnitude: f64, operations: f64) -> f64 {
    f64::EPSILON * magnitude.abs() * (ROUNDOFF_ULPS + operations.max(0.0))
}

/// The operations behind one estimate of `cell`: the largest of its counted samples, fetches, rays
/// and target evaluations per estimate and of its sample or fetch budget (at least 1).
pub fn operations(cell: &CellResult) -> f64 {
    let per = |x: u64| x as f64 / cell.estimates.max(1) as f64;
    let c = &cell.costs;
    let budget = match cell.key.budget.kind {
        BudgetKind::Samples | BudgetKind::Fetches => cell.key.budget.amount as f64,
        BudgetKind::Micros => 0.0,
    };
    [per(c.samples), per(c.fetches), per(c.rays), per(c.target_evals), budget].into_iter().fold(1.0, f64::max)
}

/// Per integral and channel of `cell`, the round-off bound of its mean against `reference`.
pub fn bounds(cell: &CellResult, reference: &Reference) -> Vec<[f64; 3]> {
    let ops = operations(cell);
    cell.moments
        .iter()
        .zip(&reference.value)
        .map(|(m, r)| [0, 1, 2].map(|c| bound(m[c].mean().abs().max(r[c].abs()), ops)))
        .collect()
}

/// The RMSE a cell may show through round-off and its exact reference's stated error alone:
/// `sqrt(mean over integrals and channels of (u + B)^2 + u^2)`, with `u` the round-off bound and
/// `B` the reference's absolute error bound (its mean within `u + B` of the reference, its spread
/// within `u`). NaN against a stored reference with a standard error: its own noise dwarfs
/// round-off, so no cell of it is exact.
pub fn rmse_bound(cell: &CellResult, reference: &Reference) -> f64 {
    let b = match &reference.kind {
        ReferenceKind::Exact { bound, .. } => bound.max(0.0),
        ReferenceKind::Stored { .. } if reference.std_err.iter().flat_map(|s| s.0).all(|s| s == 0.0) => 0.0,
        ReferenceKind::Stored { .. } => return f64::NAN,
    };
    let u = bounds(cell, reference);
    let n = (u.len() * 3).max(1) as f64;
    let sum: f64 = u.iter().flatten().map(|u| (u + b).powi(2) + u * u).sum();
    (sum / n).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::bias::tests::{cell_from, exact};

    #[test]
    fn the_bound_grows_with_the_magnitude_and_the_operations() {
        assert_eq!(bound(0.0, 1e6), 0.0);
        assert_eq!(bound(2.0, 0.0), 2.0 * bound(1.0, 0.0));
        assert_eq!(bound(1.0, 0.0), ROUNDOFF_ULPS * f64::EPSILON);
        assert!((bound(1.0, 48.0) / bound(1.0, 0.0) - 4.0).abs() < 1e-12);
        // Far below any statistical resolution: under 3e-10 relative at a million operations.
        assert!(bound(1.0, 1e6) < 3e-10);
    }

    /// The drift it must cover: the mean of `n` nearly equal terms summed one by one, as an
    /// estimator does, against the exact value, at up to a million terms.
    #[test]
    fn it_covers_the_drift_of_a_sum_of_nearly_equal_terms() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(5);
        for &x in &[0.3, 0.7, 1.0 / 3.0, 0.9, 123.456] {
            for n in [4usize, 256, 4096, 65536, 1 << 20] {
                // Terms off by a few ulps, like `f(w) / pdf(w)` of a furnace.
                let mut sum = 0.0;
                for _ in 0..n {
                    sum += x * (1.0 + 4.0 * f64::EPSILON * (rng.gen::<f64>() - 0.5));
                }
                let drift = (sum / n as f64 - x).abs();
                assert!(drift <= bound(x, n as f64), "x {x} n {n}: drift {drift:e} vs {:e}", bound(x, n as f64));
            }
        }
    }

    #[test]
    fn a_cell_counts_its_budget_as_operations() {
        let r = exact(&[[0.5; 3]]);
        let cell = cell_from(&[vec![[0.5; 3]], vec![[0.5; 3]]], &r);
        // The test cell has a budget of 4 samples and counted none.
        assert_eq!(operations(&cell), 4.0);
        assert_eq!(bounds(&cell, &r)[0][0], bound(0.5, 4.0));
        let u = bound(0.5, 4.0);
        assert!((rmse_bound(&cell, &r) - (u * u * 2.0).sqrt()).abs() < 1e-30);
        let mut stored = r.clone();
        stored.kind = ReferenceKind::Stored { command: "x".into(), samples: 10 };
        assert_eq!(rmse_bound(&cell, &stored), (u * u * 2.0).sqrt(), "a stored reference without error");
        stored.std_err = vec![mcbench_core::math::Rgb::splat(1e-3)];
        assert!(rmse_bound(&cell, &stored).is_nan());
    }
}
