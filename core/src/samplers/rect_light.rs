//! Uniform points on a rectangular area light converted to a density per unit solid angle at the
//! shading point (paper 003's light component `h_light`, Eq. 7): a point `y` with area density
//! `1 / A` seen from `x` at distance `d` under `cos(theta_y)` has solid-angle density
//! `d^2 / (A cos(theta_y))`.

use crate::brdf::DirectionSample;
use crate::lighting::RectLight;
use crate::math::Vec3;
use rand::Rng;

/// A direction from `p` towards a uniform point on `light`, with its solid-angle density.
/// `p` must lie below the light's plane (every point of the floor scenes does).
pub fn sample<R: Rng + ?Sized>(light: &RectLight, p: Vec3, rng: &mut R) -> DirectionSample {
    let w = sample_direction(light, p, rng);
    DirectionSample { w, pdf: pdf(light, p, w) }
}

/// The direction of [`sample`] without its density (the same draws and the same bits), for a
/// caller that needs the density of a mixture of lights at it instead.
pub fn sample_direction<R: Rng + ?Sized>(light: &RectLight, p: Vec3, rng: &mut R) -> Vec3 {
    let (u, v): (f64, f64) = (rng.gen(), rng.gen());
    let y = Vec3::new(
        light.min[0] + u * (light.max[0] - light.min[0]),
        light.min[1] + v * (light.max[1] - light.min[1]),
        light.z,
    );
    let d = y - p;
    d.normalize()
}

/// The solid-angle density of [`sample`] at the unit direction `w` (zero off the light).
pub fn pdf(light: &RectLight, p: Vec3, w: Vec3) -> f64 {
    match light.hit(p, w) {
        // The light faces -z, so cos(theta_y) = w.z > 0 wherever the ray hits it.
        Some(t) => t * t / (light.area() * w.z),
        None => 0.0,
    }
}
