//! The energy-normalised modified Phong BRDF (Lafortune and Willems 1994) used by papers 001, 003
//! and 004, and its importance sampling.
//!
//! `f(w_i, w_o) = kd / pi + ks (n + 2) / (2 pi) max(0, w_r . w_i)^n`, with `w_r = 2 (n . w_o) n - w_o`
//! the mirror of the view direction about the normal (book: testbeds.md).

use crate::math::{Rgb, Vec3};
pub use crate::phong_at::PhongAt;
use rand::Rng;

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
    #[inline]
    pub fn eval(&self, wi: Vec3, wo: Vec3, normal: Vec3) -> Rgb {
        PhongAt::new(*self, wo, normal).eval(wi)
    }

    /// `f(w_i, w_o)` and [`Phong::pdf`] at one direction, bit for bit as the two calls give them,
    /// computing the lobe's power `(w_r . w_i)^n` once (or not at all where it changes neither:
    /// `ks = 0`, or `P_d = 1` in the pdf; see [`PhongAt`]). At many directions from one point,
    /// [`PhongAt::eval_pdf`] also shares the point's constants.
    #[inline]
    pub fn eval_pdf(&self, wi: Vec3, wo: Vec3, normal: Vec3) -> (Rgb, f64) {
        PhongAt::new(*self, wo, normal).eval_pdf(wi)
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
    #[inline]
    pub fn pdf(&self, wi: Vec3, wo: Vec3, normal: Vec3) -> f64 {
        PhongAt::new(*self, wo, normal).pdf(wi)
    }

    /// BRDF importance sampling: the cosine lobe with probability `P_d`, otherwise the Phong lobe
    /// around the mirror direction (which may fall below the horizon, where `f = 0`).
    pub fn sample<R: Rng + ?Sized>(&self, wo: Vec3, normal: Vec3, rng: &mut R) -> DirectionSample {
        let at = PhongAt::new(*self, wo, normal);
        let w = at.sample_direction(rng);
        DirectionSample { w, pdf: at.pdf(w) }
    }

    /// The direction of [`Phong::sample`] without its density (the same draws and bits), for a
    /// caller that takes the density from [`Phong::eval_pdf`].
    #[inline]
    pub fn sample_direction<R: Rng + ?Sized>(&self, wo: Vec3, normal: Vec3, rng: &mut R) -> Vec3 {
        PhongAt::new(*self, wo, normal).sample_direction(rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::gauss_legendre;
    use crate::samplers::{cosine_hemisphere, phong_lobe};
    use std::f64::consts::PI;

    fn glossy() -> (Phong, Vec3) {
        let brdf = Phong { kd: Rgb::splat(0.5), ks: Rgb::splat(0.3), n: 20.0 };
        (brdf, Vec3::new(0.0, -0.8, 0.6).normalize())
    }

    /// The formulas of `f` and the pdf as written out, with the lobe's power always computed.
    fn formula_eval_pdf(b: &Phong, wi: Vec3, wo: Vec3, normal: Vec3) -> (Rgb, f64) {
        let r = wo.reflect(normal);
        let f = if wi.dot(normal) <= 0.0 {
            Rgb::ZERO
        } else {
            let lobe = r.dot(wi).max(0.0).powf(b.n) * (b.n + 2.0) / (2.0 * PI);
            b.kd / PI + b.ks * lobe
        };
        let pd = b.diffuse_weight();
        (f, pd * cosine_hemisphere::pdf(wi.dot(normal)) + (1.0 - pd) * phong_lobe::pdf(r.dot(wi), b.n))
    }

    fn bits(f: Rgb, pdf: f64) -> [u64; 4] {
        [f[0].to_bits(), f[1].to_bits(), f[2].to_bits(), pdf.to_bits()]
    }

    /// `eval`, `pdf` and `eval_pdf` give the bits of the written-out formulas (which skipping the
    /// lobe's power must not change) for diffuse, glossy, black and odd materials, at random
    /// directions over the whole sphere and at the mirror direction and the horizon; `sample` is
    /// `sample_direction` with `pdf`.
    #[test]
    fn shared_and_skipped_lobe_powers_keep_every_bit() {
        use rand::Rng;
        let materials = [
            Phong { kd: Rgb::splat(0.7), ks: Rgb::ZERO, n: 1.0 },
            Phong { kd: Rgb::splat(0.05), ks: Rgb::splat(0.8), n: 10.0 },
            Phong { kd: Rgb::splat(0.05), ks: Rgb::splat(0.8), n: 5000.0 },
            Phong { kd: Rgb::ZERO, ks: Rgb::ZERO, n: 1.0 },
            Phong { kd: Rgb([0.3, -0.0, 0.0]), ks: Rgb([0.0, -0.0, 0.0]), n: 3.0 },
            Phong { kd: Rgb::splat(0.4), ks: Rgb([0.2, 0.0, 0.1]), n: 123.4 },
            Phong { kd: Rgb::ZERO, ks: Rgb::splat(0.5), n: 0.0 },
        ];
        let mut rng = crate::rng::stream(5, "phong bits");
        let unit = |rng: &mut crate::rng::StreamRng| {
            let z: f64 = rng.gen_range(-1.0..1.0);
            crate::samplers::spherical_direction(z, rng.gen_range(0.0..2.0 * PI))
        };
        let mut skipped = 0;
        for b in &materials {
            for _ in 0..2000 {
                let wo = unit(&mut rng);
                let wo = Vec3::new(wo.x, wo.y, wo.z.abs());
                let r = wo.reflect(Vec3::Z);
                // One point's constants, shared by all its directions.
                let at = PhongAt::new(*b, wo, Vec3::Z);
                for wi in [unit(&mut rng), r, Vec3::new(r.x, r.y, 0.0), Vec3::new(wo.x, -0.0, -0.0)] {
                    let (f, pdf) = formula_eval_pdf(b, wi, wo, Vec3::Z);
                    let want = bits(f, pdf);
                    assert_eq!(bits(b.eval(wi, wo, Vec3::Z), b.pdf(wi, wo, Vec3::Z)), want, "{b:?} {wi:?} {wo:?}");
                    let (g, q) = b.eval_pdf(wi, wo, Vec3::Z);
                    assert_eq!(bits(g, q), want, "{b:?} {wi:?} {wo:?}");
                    assert_eq!(bits(at.eval(wi), at.pdf(wi)), want);
                    let (g, q) = at.eval_pdf(wi);
                    assert_eq!(bits(g, q), want);
                    skipped += usize::from(at.lobe_drops_from_value(r.dot(wi)));
                }
                let mut a = rng.clone();
                let s = b.sample(wo, Vec3::Z, &mut rng);
                assert_eq!(b.sample_direction(wo, Vec3::Z, &mut a.clone()), s.w);
                assert_eq!(at.sample_direction(&mut a), s.w);
                assert_eq!(s.pdf.to_bits(), b.pdf(s.w, wo, Vec3::Z).to_bits());
            }
        }
        // The diffuse and black materials skip the power (the -0 diffuse channel does not).
        assert_eq!(skipped, 2 * 2000 * 4);
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
