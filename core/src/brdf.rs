//! The energy-normalised modified Phong BRDF (Lafortune and Willems 1994) used by papers 001, 003
//! and 004, and its importance sampling.
//!
//! `f(w_i, w_o) = kd / pi + ks (n + 2) / (2 pi) max(0, w_r . w_i)^n`, with `w_r = 2 (n . w_o) n - w_o`
//! the mirror of the view direction about the normal (book: testbeds.md).

use crate::math::{Frame, Rgb, Vec3};
use crate::samplers::{cosine_hemisphere, phong_lobe};
use rand::Rng;
use std::f64::consts::PI;

/// Modified Phong parameters (per channel kd and ks, one exponent).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Phong {
    /// Diffuse albedo per channel.
    pub kd: Rgb,
    /// Specular coefficient per channel.
    pub ks: Rgb,
    /// Phong exponent.
    pub n: f64,
}

/// A direction drawn from a sampler together with the density it was drawn with (solid angle).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionSample {
    /// The sampled unit direction (world space).
    pub w: Vec3,
    /// Its probability density per unit solid angle.
    pub pdf: f64,
}

impl Phong {
    /// Evaluates `f(w_i, w_o)` for the unit normal `normal` (zero below the horizon).
    pub fn eval(&self, wi: Vec3, wo: Vec3, normal: Vec3) -> Rgb {
        if wi.dot(normal) <= 0.0 {
            return Rgb::ZERO;
        }
        let r = wo.reflect(normal);
        let lobe = r.dot(wi).max(0.0).powf(self.n) * (self.n + 2.0) / (2.0 * PI);
        self.kd / PI + self.ks * lobe
    }

    /// Probability of choosing the diffuse component in [`Phong::sample`]: the share of the
    /// channel-mean diffuse albedo in `kd + ks` (1 when both are zero).
    pub fn diffuse_weight(&self) -> f64 {
        let (d, s) = (self.kd.mean(), self.ks.mean());
        if d + s > 0.0 {
            d / (d + s)
        } else {
            1.0
        }
    }

    /// Density of [`Phong::sample`] per unit solid angle: the exact mixture
    /// `P_d cos(theta) / pi + (1 - P_d) (n + 1) / (2 pi) max(0, w_r . w)^n`.
    pub fn pdf(&self, wi: Vec3, wo: Vec3, normal: Vec3) -> f64 {
        let pd = self.diffuse_weight();
        let r = wo.reflect(normal);
        pd * cosine_hemisphere::pdf(wi.dot(normal)) + (1.0 - pd) * phong_lobe::pdf(r.dot(wi), self.n)
    }

    /// BRDF importance sampling: the cosine lobe with probability `P_d`, otherwise the Phong lobe
    /// around the mirror direction (which may fall below the horizon, where `f = 0`).
    pub fn sample<R: Rng + ?Sized>(&self, wo: Vec3, normal: Vec3, rng: &mut R) -> DirectionSample {
        let pd = self.diffuse_weight();
        let w = if rng.gen::<f64>() < pd {
            Frame::around(normal).to_world(cosine_hemisphere::sample_local(rng))
        } else {
            Frame::around(wo.reflect(normal)).to_world(phong_lobe::sample_local(self.n, rng))
        };
        DirectionSample { w, pdf: self.pdf(w, wo, normal) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::gauss_legendre;

    fn glossy() -> (Phong, Vec3) {
        let brdf = Phong { kd: Rgb::splat(0.5), ks: Rgb::splat(0.3), n: 20.0 };
        (brdf, Vec3::new(0.0, -0.8, 0.6).normalize())
    }

    /// The mixture pdf integrates to one over the sphere (product Gauss-Legendre in (cos theta, phi)).
    #[test]
    fn mixture_pdf_integrates_to_one() {
        let (brdf, wo) = glossy();
        let (x, w) = gauss_legendre(64);
        let mut total = 0.0;
        for panel in 0..16 {
            let (c0, c1) = (-1.0 + panel as f64 / 8.0, -1.0 + (panel + 1) as f64 / 8.0);
            for (xi, wi) in x.iter().zip(&w) {
                let c = 0.5 * (c0 + c1) + 0.5 * (c1 - c0) * xi;
                for (xj, wj) in x.iter().zip(&w) {
                    let phi = PI * (1.0 + xj);
                    let s = (1.0 - c * c).max(0.0).sqrt();
                    let dir = Vec3::new(s * phi.cos(), s * phi.sin(), c);
                    total += wi * wj * 0.5 * (c1 - c0) * PI * brdf.pdf(dir, wo, Vec3::Z);
                }
            }
        }
        assert!((total - 1.0).abs() < 1e-6, "integral of pdf = {total}");
    }

    #[test]
    fn eval_is_zero_below_the_horizon_and_reciprocal_above() {
        let (brdf, wo) = glossy();
        assert_eq!(brdf.eval(Vec3::new(0.0, 0.6, -0.8), wo, Vec3::Z), Rgb::ZERO);
        let wi = Vec3::new(0.3, 0.5, 0.8).normalize();
        let a = brdf.eval(wi, wo, Vec3::Z);
        let b = brdf.eval(wo, wi, Vec3::Z);
        assert!((a - b).0.iter().all(|d| d.abs() < 1e-12));
    }
}
