//! Cosine-weighted hemisphere sampling (Malley's method): density `cos(theta) / pi`.

use super::spherical_direction;
use crate::math::Vec3;
use rand::Rng;
use std::f64::consts::PI;

/// The density per unit solid angle for a direction with `cos(theta) = cos_theta`.
pub fn pdf(cos_theta: f64) -> f64 {
    cos_theta.max(0.0) / PI
}

/// A direction in local coordinates (+z is the normal): `cos^2(theta) = 1 - u1`.
pub fn sample_local<R: Rng + ?Sized>(rng: &mut R) -> Vec3 {
    let cos_theta = (1.0 - rng.gen::<f64>()).sqrt();
    spherical_direction(cos_theta, 2.0 * PI * rng.gen::<f64>())
}
