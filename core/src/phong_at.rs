//! A modified Phong BRDF ([`Phong`], Lafortune and Willems 1994) bound to one shading point's view
//! direction and normal: what every evaluation, density and draw at that point shares (the mirror
//! direction `w_r`, the diffuse weight `P_d`, `kd / pi`, the two sampling frames) is computed once,
//! so that many directions at one point (a pixel sample's light samples, an estimate's samples) do
//! not recompute it. Every result has the bits of the corresponding [`Phong`] method: the same
//! operations in the same order, only hoisted (the [`Phong`] methods are these, bound for one call).

use crate::brdf::Phong;
use crate::math::{Frame, Rgb, Vec3};
use crate::samplers::{cosine_hemisphere, phong_lobe};
use rand::Rng;
use std::f64::consts::PI;

/// A [`Phong`] BRDF at one shading point (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct PhongAt {
    brdf: Phong,
    normal: Vec3,
    /// `w_r`, the mirror of the view direction about the normal.
    mirror: Vec3,
    /// [`Phong::diffuse_weight`].
    pd: f64,
    kd_over_pi: Rgb,
    /// `ks` is zero and no channel of `kd / pi` is `-0` (see [`PhongAt::lobe_drops_from_value`]).
    diffuse_only: bool,
    normal_frame: Frame,
    mirror_frame: Frame,
}

impl PhongAt {
    /// `brdf` seen from `wo` (unit, towards the viewer) at a point with unit normal `normal`.
    #[inline]
    pub fn new(brdf: Phong, wo: Vec3, normal: Vec3) -> Self {
        let mirror = wo.reflect(normal);
        PhongAt {
            brdf,
            normal,
            mirror,
            pd: brdf.diffuse_weight(),
            kd_over_pi: brdf.kd / PI,
            diffuse_only: brdf.ks == Rgb::ZERO && brdf.kd.0.iter().all(|k| k.is_sign_positive()),
            normal_frame: Frame::around(normal),
            mirror_frame: Frame::around(mirror),
        }
    }

    /// The BRDF.
    pub fn brdf(&self) -> &Phong {
        &self.brdf
    }

    /// `max(0, c)^n (n + 2) / (2 pi)` is finite for `n` in `[0, 1e6]` and `c <= 1 + 1e-6`
    /// (unit vectors give `c <= 1` up to rounding): the power is below `e`.
    #[inline]
    fn lobe_is_finite(&self, c: f64) -> bool {
        (0.0..=1e6).contains(&self.brdf.n) && c <= 1.000_001
    }

    /// Whether the lobe's power `max(0, c)^n` cannot change the bits of `f`, so 0 may stand for it
    /// and the `powf` be skipped: `ks` is zero and the lobe finite, which makes `ks * lobe` a zero,
    /// and no channel of `kd / pi` is `-0`, so adding that zero leaves `kd / pi` as it is (the
    /// diffuse squares of the checker scenes).
    #[inline]
    pub(crate) fn lobe_drops_from_value(&self, c: f64) -> bool {
        self.diffuse_only && self.lobe_is_finite(c)
    }

    /// Whether the lobe's power cannot change the bits of the pdf: it is multiplied by
    /// `1 - P_d = 0` when `P_d = 1`, which gives `+0` for any finite lobe.
    #[inline]
    fn lobe_drops_from_pdf(&self, c: f64) -> bool {
        self.pd == 1.0 && self.lobe_is_finite(c)
    }

    /// `f` above the horizon given `power = max(0, w_r . w_i)^n`.
    #[inline]
    fn value_of_power(&self, power: f64) -> Rgb {
        let lobe = power * (self.brdf.n + 2.0) / (2.0 * PI);
        self.kd_over_pi + self.brdf.ks * lobe
    }

    /// [`Phong::eval`]: `f(w_i, w_o)`, zero below the horizon.
    #[inline]
    pub fn eval(&self, wi: Vec3) -> Rgb {
        if wi.dot(self.normal) <= 0.0 {
            return Rgb::ZERO;
        }
        let c = self.mirror.dot(wi);
        let power = if self.lobe_drops_from_value(c) { 0.0 } else { c.max(0.0).powf(self.brdf.n) };
        self.value_of_power(power)
    }

    /// [`Phong::pdf`]: the density of [`PhongAt::sample_direction`] per unit solid angle.
    #[inline]
    pub fn pdf(&self, wi: Vec3) -> f64 {
        let c = self.mirror.dot(wi);
        let lobe = if self.lobe_drops_from_pdf(c) { 0.0 } else { phong_lobe::pdf(c, self.brdf.n) };
        self.pd * cosine_hemisphere::pdf(wi.dot(self.normal)) + (1.0 - self.pd) * lobe
    }

    /// [`PhongAt::eval`] and [`PhongAt::pdf`] at one direction with one power of the lobe for
    /// both (or none where it changes neither).
    #[inline]
    pub fn eval_pdf(&self, wi: Vec3) -> (Rgb, f64) {
        let cos = wi.dot(self.normal);
        let c = self.mirror.dot(wi);
        let value_needs = cos > 0.0 && !self.lobe_drops_from_value(c);
        let pdf_needs = c > 0.0 && !self.lobe_drops_from_pdf(c);
        let power = if value_needs || pdf_needs { c.max(0.0).powf(self.brdf.n) } else { 0.0 };
        let value = if cos <= 0.0 { Rgb::ZERO } else { self.value_of_power(power) };
        let pdf =
            self.pd * cosine_hemisphere::pdf(cos) + (1.0 - self.pd) * phong_lobe::pdf_of_power(c, self.brdf.n, power);
        (value, pdf)
    }

    /// [`Phong::sample_direction`]: the cosine lobe with probability `P_d`, otherwise the Phong
    /// lobe around the mirror direction (which may fall below the horizon, where `f = 0`).
    #[inline]
    pub fn sample_direction<R: Rng + ?Sized>(&self, rng: &mut R) -> Vec3 {
        if rng.gen::<f64>() < self.pd {
            self.normal_frame.to_world(cosine_hemisphere::sample_local(rng))
        } else {
            self.mirror_frame.to_world(phong_lobe::sample_local(self.brdf.n, rng))
        }
    }
}
