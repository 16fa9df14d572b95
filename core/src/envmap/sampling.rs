//! Environment-map importance sampling by a 2D piecewise-constant CDF (paper 004 §3
//! "independent proposal moves from the EM"): a marginal CDF over rows and a conditional CDF over
//! the columns of each row. Texel mass is `value * solid angle`, the solid angle of row `i` being
//! `(cos theta_i - cos theta_{i+1}) 2 pi / W` (the `sin theta` weighting), and a direction is
//! uniform in solid angle inside its texel, so the density is `value / sum(value * solid angle)`.

use super::LatLong;
use crate::error::ConfigError;
use rand::Rng;
use std::f64::consts::TAU;

/// The sampler of a lat-long table of non-negative scalar values.
#[derive(Clone, Debug)]
pub struct PiecewiseConstant2D {
    grid: LatLong,
    values: Vec<f64>,
    /// Cumulative row masses, `height + 1` entries from 0.
    row_cdf: Vec<f64>,
    /// Per row, cumulative column values, `width + 1` entries each from 0.
    col_cdf: Vec<f64>,
    /// Total mass `sum(value * solid angle)`.
    total: f64,
}

impl PiecewiseConstant2D {
    /// Builds the CDFs; refuses negative or non-finite values and an all-zero table.
    pub fn new(width: usize, height: usize, values: &[f64]) -> Result<Self, ConfigError> {
        let grid = LatLong { width, height };
        if values.iter().any(|v| !v.is_finite() || *v < 0.0) {
            return Err(ConfigError::invalid("envmap", "values", "must be finite and >= 0"));
        }
        let mut row_cdf = Vec::with_capacity(height + 1);
        let mut col_cdf = Vec::with_capacity(height * (width + 1));
        row_cdf.push(0.0);
        for i in 0..height {
            let mut acc = 0.0;
            col_cdf.push(0.0);
            for j in 0..width {
                acc += values[i * width + j];
                col_cdf.push(acc);
            }
            let last = row_cdf[i];
            row_cdf.push(last + acc * grid.solid_angle(i));
        }
        let total = row_cdf[height];
        if total <= 0.0 || !total.is_finite() {
            return Err(ConfigError::invalid("envmap", total, "the map has no mass to sample"));
        }
        Ok(PiecewiseConstant2D { grid, values: values.to_vec(), row_cdf, col_cdf, total })
    }

    /// Total mass `sum(value * solid angle)` (the integral of the channel-mean radiance).
    pub fn total(&self) -> f64 {
        self.total
    }

    /// Draws `(cos theta, phi, pdf)` of an unrotated direction.
    pub fn sample<R: Rng + ?Sized>(&self, rng: &mut R) -> (f64, f64, f64) {
        let (w, h) = (self.grid.width, self.grid.height);
        // Marginal: the first row whose upper cumulative mass exceeds u * total (zero-mass rows
        // have equal bounds and are never chosen).
        let target = rng.gen::<f64>() * self.total;
        let row = self.row_cdf[1..].partition_point(|&c| c <= target).min(h - 1);
        let cdf = &self.col_cdf[row * (w + 1)..(row + 1) * (w + 1)];
        let target = rng.gen::<f64>() * cdf[w];
        let col = cdf[1..].partition_point(|&c| c <= target).min(w - 1);
        let (c0, c1) = (self.grid.cos_edge(row), self.grid.cos_edge(row + 1));
        let cos_theta = c1 + (c0 - c1) * (1.0 - rng.gen::<f64>());
        let phi = (col as f64 + rng.gen::<f64>()) * TAU / w as f64;
        (cos_theta, phi, self.values[row * w + col] / self.total)
    }

    /// Density per unit solid angle of texel `t`.
    pub fn pdf_of_texel(&self, t: usize) -> f64 {
        self.values[t] / self.total
    }
}

#[cfg(test)]
mod tests {
    use super::super::{EnvFrame, EnvMap};
    use crate::math::{Rgb, Vec3};

    /// A sky-like map: a dim gradient, a ground, and one bright lobe of peak `sun` (a dynamic
    /// range like the test beds' skies).
    fn sky(sun: f64) -> impl Fn(Vec3) -> Rgb {
        let d = Vec3::new(0.3, 0.4, 0.866).normalize();
        move |w: Vec3| {
            let base = if w.z >= 0.0 { 0.3 + 0.7 * w.z } else { 0.05 };
            Rgb([base + sun * (200.0 * (w.dot(d) - 1.0)).exp(), base, base + 0.1 * w.x.abs()])
        }
    }

    /// Chi-square of the environment sampler (rotated frame) against its reported density, on a
    /// grid of cells in `(cos theta, phi)` that does not align with the texels. Cell probabilities
    /// are exact: texels and cells are both rectangles in `(cos theta, phi)`, where solid angle is
    /// area, so each texel adds `pdf * overlap area`.
    #[test]
    fn chi_square_environment_map_sampler() {
        use crate::stats::chi_square_gof;
        use std::f64::consts::TAU;
        let map = EnvMap::tabulate(64, 32, sky(50.0)).unwrap();
        let frame = EnvFrame { map: &map, rotation: 0.3, scale: 2.0 };
        let (nc, np) = (20usize, 28usize);
        let cell = |d: Vec3| {
            let ic = (((d.z + 1.0) / 2.0 * nc as f64) as usize).min(nc - 1);
            let ip = ((d.y.atan2(d.x).rem_euclid(TAU) / TAU * np as f64) as usize).min(np - 1);
            ic * np + ip
        };
        let overlap = |a0: f64, a1: f64, b0: f64, b1: f64| (a1.min(b1) - a0.max(b0)).max(0.0);
        let g = map.grid();
        let mut probs = vec![0.0; nc * np];
        for t in 0..g.width * g.height {
            let (i, j) = (t / g.width, t % g.width);
            let (c_lo, c_hi) = (g.cos_edge(i + 1), g.cos_edge(i));
            let p0 = (j as f64 * TAU / g.width as f64 + frame.rotation).rem_euclid(TAU);
            let p1 = p0 + TAU / g.width as f64;
            for ic in 0..nc {
                let oc =
                    overlap(c_lo, c_hi, -1.0 + 2.0 * ic as f64 / nc as f64, -1.0 + 2.0 * (ic + 1) as f64 / nc as f64);
                if oc == 0.0 {
                    continue;
                }
                for ip in 0..np {
                    let (q0, q1) = (ip as f64 * TAU / np as f64, (ip + 1) as f64 * TAU / np as f64);
                    let op = overlap(p0, p1, q0, q1) + overlap(p0 - TAU, p1 - TAU, q0, q1);
                    probs[ic * np + ip] += map.sampler().pdf_of_texel(t) * oc * op;
                }
            }
        }
        assert!((probs.iter().sum::<f64>() - 1.0).abs() < 1e-9);
        let mut rng = crate::rng::stream(41, "environment map chi-square");
        let mut counts = vec![0u64; nc * np];
        for _ in 0..300_000 {
            counts[cell(frame.sample(&mut rng).w)] += 1;
        }
        let c = chi_square_gof(&counts, &probs).unwrap();
        let alpha = crate::samplers::testing::sampler_alpha();
        assert!(c.p_value > alpha, "chi-square {} on {} dof, p = {:e}", c.statistic, c.dof, c.p_value);
    }

    /// The density integrates to one (sum over texels of pdf * solid angle) and the sample's
    /// reported pdf equals the pdf lookup at the sample.
    #[test]
    fn density_is_normalised_and_consistent() {
        let map = EnvMap::tabulate(32, 16, sky(100.0)).unwrap();
        let g = map.grid();
        let s: f64 = (0..g.height * g.width).map(|t| map.sampler().pdf_of_texel(t) * g.solid_angle(t / g.width)).sum();
        assert!((s - 1.0).abs() < 1e-12, "{s}");
        let frame = EnvFrame { map: &map, rotation: 1.0, scale: 1.0 };
        let mut rng = crate::rng::stream(3, "env");
        for _ in 0..1000 {
            let d = frame.sample(&mut rng);
            assert!((d.pdf - frame.pdf(d.w)).abs() <= 1e-12 * d.pdf && d.pdf > 0.0);
            assert!((d.w.length() - 1.0).abs() < 1e-12);
        }
        assert!(EnvMap::new(2, 2, vec![crate::math::Rgb::ZERO; 4]).is_err());
        let _ = Vec3::Z;
    }
}
