//! Analytic lighting shared by the test beds.

use crate::math::{Rgb, Vec3};
use crate::phong_at::PhongAt;
use crate::samplers::{mixture::pick, rect_light};
use rand::Rng;
use serde::{Deserialize, Serialize};

/// The gradient background of papers 000/001: `L_b(w) = c0 + c1 w_z + c2 w_x` per channel
/// (book: testbeds.md), optionally clamped at zero per channel (as `gradient-box` does, over the
/// whole sphere).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gradient {
    /// Constant term per channel.
    pub c0: Rgb,
    /// Coefficient of `w_z` per channel.
    pub c1: Rgb,
    /// Coefficient of `w_x` per channel.
    pub c2: Rgb,
    /// Clamp negative radiance to zero (needed where `w_z < 0` is seen).
    pub clamp: bool,
}

impl Gradient {
    /// The default coefficients of `gradient-plane`: R (1.0, 1.0, 0.5), G (0.8, 1.2, 0.0), B (0.6, 1.5, -0.4).
    pub const fn papers() -> Gradient {
        Gradient { c0: Rgb([1.0, 0.8, 0.6]), c1: Rgb([1.0, 1.2, 1.5]), c2: Rgb([0.5, 0.0, -0.4]), clamp: false }
    }
    /// Radiance arriving from direction `w` (unit vector leaving the scene).
    pub fn eval(&self, w: Vec3) -> Rgb {
        let l = self.c0 + self.c1 * w.z + self.c2 * w.x;
        if self.clamp {
            l.map(|c| c.max(0.0))
        } else {
            l
        }
    }
}

/// An isotropic point light (paper 002 §4.3, book: testbeds.md): radiant intensity `intensity` (power
/// `4 pi intensity`) at `position`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PointLight {
    /// Where the light is.
    pub position: Vec3,
    /// Radiant intensity (W/sr); the power is `4 pi intensity`.
    pub intensity: f64,
}

impl PointLight {
    /// The closest approach of the ray `origin + t dir` (unit `dir`) to the light: the ray
    /// parameter `t_l` where it is closest and the distance `D` there (paper 002 Fig. 11), so the
    /// squared distance at `t` is `D^2 + (t - t_l)^2`.
    pub fn closest_approach(&self, origin: Vec3, dir: Vec3) -> (f64, f64) {
        let to = self.position - origin;
        let t_l = to.dot(dir);
        let perp = to - dir * t_l;
        (t_l, perp.length())
    }
}

/// A rectangular area light facing down (emitting towards `-z`), axis-aligned in `x` and `y`:
/// `[x0, x1] x [y0, y1]` at height `z` with constant radiance (paper 003 Fig. 6, book: testbeds.md).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RectLight {
    /// Lower corner `(x0, y0)`.
    pub min: [f64; 2],
    /// Upper corner `(x1, y1)`.
    pub max: [f64; 2],
    /// Height of the light's plane.
    pub z: f64,
    /// Emitted radiance (towards `-z` only).
    pub radiance: Rgb,
}

impl RectLight {
    /// A `wx x wy` light centred at `(cx, cy, z)`.
    pub fn centred(cx: f64, cy: f64, z: f64, wx: f64, wy: f64, radiance: Rgb) -> RectLight {
        RectLight { min: [cx - 0.5 * wx, cy - 0.5 * wy], max: [cx + 0.5 * wx, cy + 0.5 * wy], z, radiance }
    }
    /// Area.
    #[inline]
    pub fn area(&self) -> f64 {
        (self.max[0] - self.min[0]) * (self.max[1] - self.min[1])
    }
    /// Ray parameter `t` where the ray `p + t w` (unit `w`) crosses the light's rectangle from
    /// below, if it does (`p.z < z`).
    #[inline]
    pub fn hit(&self, p: Vec3, w: Vec3) -> Option<f64> {
        if w.z <= 0.0 || p.z >= self.z {
            return None;
        }
        let t = (self.z - p.z) / w.z;
        let (x, y) = (p.x + t * w.x, p.y + t * w.y);
        (self.min[0] <= x && x <= self.max[0] && self.min[1] <= y && y <= self.max[1]).then_some(t)
    }
}

/// Light selection probabilities proportional to power (radiance x area): the light strategy of
/// paper 003's MIS baseline (§5.3) and of `checker-image`'s pixel samples (book: testbeds.md).
pub fn light_selection(lights: &[RectLight]) -> Vec<f64> {
    let w: Vec<f64> = lights.iter().map(|l| l.radiance.mean() * l.area()).collect();
    let t: f64 = w.iter().sum();
    w.iter().map(|x| x / t).collect()
}

/// The solid-angle density at `w` of the light strategy that picks light `j` with probability
/// `select[j]` and a uniform point on it, seen from `x`: `sum_j P_j pdf_j(w)`.
pub fn light_pdf(lights: &[RectLight], select: &[f64], x: Vec3, w: Vec3) -> f64 {
    lights.iter().zip(select).map(|(l, s)| s * rect_light::pdf(l, x, w)).sum()
}

/// The light and BRDF strategies of paper 003's MIS baseline (Veach 1997): light `j` picked with
/// probability `select[j]` and a uniform point on it, combined with BRDF sampling by the balance
/// heuristic (`power` 1) or the power heuristic (`power` 2).
#[derive(Clone, Copy, Debug)]
pub struct MisStrategy<'a> {
    /// The lights.
    pub lights: &'a [RectLight],
    /// Selection probability of each light ([`light_selection`]).
    pub select: &'a [f64],
    /// Heuristic exponent: 1 balance, 2 power.
    pub power: f64,
}

impl MisStrategy<'_> {
    /// The MIS weight of a strategy with density `a` against one with density `b`, divided by `a`
    /// (0 when both densities are 0, where the sample cannot have been drawn).
    fn weight(&self, a: f64, b: f64) -> f64 {
        let w = if self.power == 1.0 { 1.0 / (a + b) } else { a / (a * a + b * b) };
        if w.is_finite() {
            w
        } else {
            0.0
        }
    }
}

/// One MIS round at `position`, where the surface's BRDF is `brdf` (bound to the point's view
/// direction and normal): a BRDF sample and, when `light` is set, a light sample, each weighted by
/// the heuristic: `f(x_b) w_b / p_b + f(x_l) w_l / p_l`, an unbiased estimate of the direct
/// lighting. Without the light sample it is the BRDF-only estimate `f / p_b`. `integrand` gives
/// `L_in f cos` of a direction given the BRDF value `f` there (zero below the horizon; the caller
/// counts it): the round evaluates the BRDF and its density together ([`PhongAt::eval_pdf`], one
/// power of the lobe for both).
pub fn mis_round<R: Rng + ?Sized>(
    position: Vec3,
    brdf: &PhongAt,
    strategy: &MisStrategy<'_>,
    light: bool,
    mut integrand: impl FnMut(Vec3, Rgb) -> Rgb,
    rng: &mut R,
) -> Rgb {
    let (lights, select) = (strategy.lights, strategy.select);
    let wb = brdf.sample_direction(rng);
    let (f_b, pdf_b) = brdf.eval_pdf(wb);
    let fb = integrand(wb, f_b);
    if !light {
        return if pdf_b > 0.0 { fb / pdf_b } else { Rgb::ZERO };
    }
    let mut est = fb * strategy.weight(pdf_b, light_pdf(lights, select, position, wb));
    let j = pick(select, rng);
    let wl = rect_light::sample_direction(&lights[j], position, rng);
    let (f_l, pdf_bl) = brdf.eval_pdf(wl);
    let fl = integrand(wl, f_l);
    let pl = light_pdf(lights, select, position, wl);
    if pl > 0.0 {
        est += fl * strategy.weight(pl, pdf_bl);
    }
    est
}
