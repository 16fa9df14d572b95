//! Chi-square goodness-of-fit support for direction samplers (book: conformance.md): bin samples on a grid of
//! cells in `(cos(theta), phi)` and compare with the cell probabilities obtained by integrating the
//! sampler's reported pdf with product Gauss-Legendre quadrature.
//!
//! The family of sampler tests shares one significance level: alpha = 0.01 with the Sidak
//! correction over [`SAMPLER_TESTS`] tests.

use crate::math::Vec3;
use crate::quadrature::gauss_legendre;
use crate::rng::{stream, StreamRng};
use crate::stats::{chi_square_gof, sidak_alpha, ChiSquare};
use std::f64::consts::PI;

/// How many sampler chi-square tests the workspace runs (the Sidak family size). Raise it when
/// adding a sampler test.
pub const SAMPLER_TESTS: usize = 61;

/// The per-test significance level: Sidak-corrected 0.01 over [`SAMPLER_TESTS`].
pub fn sampler_alpha() -> f64 {
    sidak_alpha(0.01, SAMPLER_TESTS)
}

/// A grid of cells on the sphere: edges in `cos(theta)` (increasing) times equal `phi` slices.
#[derive(Clone, Debug)]
pub struct SphereGrid {
    cos_edges: Vec<f64>,
    phi_cells: usize,
}

impl SphereGrid {
    /// `nc` equal slices of `cos(theta)` in [0, 1] times `np` slices of `phi`.
    pub fn upper(nc: usize, np: usize) -> Self {
        Self::with_cos_edges((0..=nc).map(|k| k as f64 / nc as f64).collect(), np)
    }
    /// `nc` equal slices of `cos(theta)` in [-1, 1] times `np` slices of `phi`.
    pub fn full(nc: usize, np: usize) -> Self {
        Self::with_cos_edges((0..=nc).map(|k| -1.0 + 2.0 * k as f64 / nc as f64).collect(), np)
    }
    /// Explicit increasing `cos(theta)` edges; directions outside them fall in no cell.
    pub fn with_cos_edges(cos_edges: Vec<f64>, phi_cells: usize) -> Self {
        SphereGrid { cos_edges, phi_cells }
    }
    /// Number of cells.
    pub fn cells(&self) -> usize {
        (self.cos_edges.len() - 1) * self.phi_cells
    }
    /// The cell of a unit direction, if any.
    pub fn cell(&self, d: Vec3) -> Option<usize> {
        let (lo, hi) = (self.cos_edges[0], *self.cos_edges.last()?);
        if !(lo..=hi).contains(&d.z) {
            return None;
        }
        let ic = self.cos_edges.partition_point(|&e| e <= d.z).clamp(1, self.cos_edges.len() - 1) - 1;
        let phi = d.y.atan2(d.x).rem_euclid(2.0 * PI);
        let ip = ((phi / (2.0 * PI) * self.phi_cells as f64) as usize).min(self.phi_cells - 1);
        Some(ic * self.phi_cells + ip)
    }
    /// Probability of each cell under `pdf` (per solid angle), by `order`-point Gauss-Legendre in
    /// `cos(theta)` and `phi` per cell.
    pub fn probabilities(&self, pdf: impl Fn(Vec3) -> f64, order: usize) -> Vec<f64> {
        let (x, w) = gauss_legendre(order);
        let dphi = 2.0 * PI / self.phi_cells as f64;
        let mut out = Vec::with_capacity(self.cells());
        for pair in self.cos_edges.windows(2) {
            let (c0, c1) = (pair[0], pair[1]);
            for ip in 0..self.phi_cells {
                let mut p = 0.0;
                for (xi, wi) in x.iter().zip(&w) {
                    let c = 0.5 * (c0 + c1) + 0.5 * (c1 - c0) * xi;
                    for (xj, wj) in x.iter().zip(&w) {
                        let phi = dphi * (ip as f64 + 0.5 + 0.5 * xj);
                        p += wi * wj * pdf(super::spherical_direction(c, phi));
                    }
                }
                out.push(p * 0.25 * (c1 - c0) * dphi);
            }
        }
        out
    }
}

/// Draws `n` directions from `sample` with a fixed seed, bins them on `grid`, and runs the
/// chi-square test against the probabilities of `pdf` (the remainder outside the grid is one more
/// cell). Returns the test outcome.
pub fn sampler_chi_square(
    grid: &SphereGrid,
    n: usize,
    seed: u64,
    mut sample: impl FnMut(&mut StreamRng) -> Vec3,
    pdf: impl Fn(Vec3) -> f64,
) -> ChiSquare {
    let mut rng = stream(seed, "sampler chi-square");
    let mut counts = vec![0u64; grid.cells() + 1];
    for _ in 0..n {
        let d = sample(&mut rng);
        counts[grid.cell(d).unwrap_or(grid.cells())] += 1;
    }
    let probs = grid.probabilities(pdf, 12);
    gof_with_outside(&counts, probs)
}

/// Asserts that `sample` follows `pdf` at the family's significance level.
pub fn assert_sampler_fits(
    name: &str,
    grid: &SphereGrid,
    n: usize,
    seed: u64,
    sample: impl FnMut(&mut StreamRng) -> Vec3,
    pdf: impl Fn(Vec3) -> f64,
) {
    assert_fits(name, &sampler_chi_square(grid, n, seed, sample, pdf));
}

/// Draws `n` values of a one-dimensional sampler (distances along a ray) with a fixed seed, bins
/// them on the increasing `edges` (values outside them fall in one more cell), and runs the
/// chi-square test against the cell probabilities of the reported density `pdf`, integrated by
/// 12-point Gauss-Legendre per cell.
pub fn interval_chi_square(
    edges: &[f64],
    n: usize,
    seed: u64,
    mut sample: impl FnMut(&mut StreamRng) -> f64,
    pdf: impl Fn(f64) -> f64,
) -> ChiSquare {
    let mut rng = stream(seed, "interval chi-square");
    let cells = edges.len() - 1;
    let mut counts = vec![0u64; cells + 1];
    for _ in 0..n {
        let t = sample(&mut rng);
        let inside = t >= edges[0] && t < edges[cells];
        counts[if inside { edges.partition_point(|&e| e <= t) - 1 } else { cells }] += 1;
    }
    let (x, w) = gauss_legendre(12);
    let probs: Vec<f64> = edges
        .windows(2)
        .map(|e| {
            let (c, h) = (0.5 * (e[0] + e[1]), 0.5 * (e[1] - e[0]));
            x.iter().zip(&w).map(|(xi, wi)| wi * pdf(c + h * xi)).sum::<f64>() * h
        })
        .collect();
    gof_with_outside(&counts, probs)
}

/// Asserts that a one-dimensional sampler follows `pdf` at the family's significance level
/// ([`interval_chi_square`]).
pub fn assert_interval_sampler_fits(
    name: &str,
    edges: &[f64],
    n: usize,
    seed: u64,
    sample: impl FnMut(&mut StreamRng) -> f64,
    pdf: impl Fn(f64) -> f64,
) {
    assert_fits(name, &interval_chi_square(edges, n, seed, sample, pdf));
}

/// The chi-square test of `counts` whose last cell holds everything outside the binned cells:
/// its probability is what `probs` (the binned cells) leaves.
fn gof_with_outside(counts: &[u64], mut probs: Vec<f64>) -> ChiSquare {
    let inside: f64 = probs.iter().sum();
    probs.push((1.0 - inside).max(0.0));
    match chi_square_gof(counts, &probs) {
        Ok(c) => c,
        Err(e) => panic!("chi-square could not run: {e}"),
    }
}

/// Asserts a sampler's chi-square passes at the family's significance level.
pub fn assert_fits(name: &str, c: &ChiSquare) {
    let alpha = sampler_alpha();
    assert!(
        c.p_value > alpha,
        "{name}: chi-square {} on {} dof, p = {:e} < alpha {alpha:e}",
        c.statistic,
        c.dof,
        c.p_value
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::samplers::{cosine_hemisphere, uniform_hemisphere};

    /// Teeth: the test rejects a sampler whose reported pdf is wrong (cosine samples checked
    /// against the uniform density).
    #[test]
    fn chi_square_rejects_a_mismatched_pdf() {
        let grid = SphereGrid::upper(16, 16);
        let c =
            sampler_chi_square(&grid, 200_000, 5, cosine_hemisphere::sample_local, |d| uniform_hemisphere::pdf(d.z));
        assert!(c.p_value < 1e-12, "p = {}", c.p_value);
    }

    #[test]
    fn grid_probabilities_of_uniform_sum_to_one() {
        let grid = SphereGrid::upper(8, 8);
        let s: f64 = grid.probabilities(|d| uniform_hemisphere::pdf(d.z), 4).iter().sum();
        assert!((s - 1.0).abs() < 1e-12);
    }
}
