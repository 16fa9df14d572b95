//! Uniform sampling of the directions within a cone of half-angle `beta` about a local +z axis:
//! paper 003's cone component `h_cone(w | d, beta)` (Eq. 7), density
//! `1 / (2 pi (1 - cos(beta)))` inside the cone and zero outside.

use super::spherical_direction;
use crate::math::Vec3;
use rand::Rng;
use std::f64::consts::PI;

/// The density per unit solid angle for `cos(angle to the axis) = cos_alpha` and
/// `cos(beta) = cos_max` (`cos_max < 1`).
pub fn pdf(cos_alpha: f64, cos_max: f64) -> f64 {
    if cos_alpha >= cos_max {
        1.0 / (2.0 * PI * (1.0 - cos_max))
    } else {
        0.0
    }
}

/// A direction inside the cone, in local coordinates: `cos(alpha) = 1 - u (1 - cos_max)`.
pub fn sample_local<R: Rng + ?Sized>(cos_max: f64, rng: &mut R) -> Vec3 {
    let cos_alpha = 1.0 - rng.gen::<f64>() * (1.0 - cos_max);
    spherical_direction(cos_alpha, 2.0 * PI * rng.gen::<f64>())
}
