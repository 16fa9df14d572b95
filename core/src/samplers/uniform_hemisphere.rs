//! Uniform sampling of the hemisphere about local +z: the `is0` density `1 / (2 pi)` of papers
//! 000/001 (their independent-sample "MCMC" baseline).

use super::spherical_direction;
use crate::math::Vec3;
use rand::Rng;
use std::f64::consts::PI;

/// The density per unit solid angle for a direction with `cos(theta) = cos_theta`.
pub fn pdf(cos_theta: f64) -> f64 {
    if cos_theta >= 0.0 {
        1.0 / (2.0 * PI)
    } else {
        0.0
    }
}

/// A direction in local coordinates (+z is the normal): `cos(theta) = 1 - u1` so it is never 0.
pub fn sample_local<R: Rng + ?Sized>(rng: &mut R) -> Vec3 {
    let cos_theta = 1.0 - rng.gen::<f64>();
    spherical_direction(cos_theta, 2.0 * PI * rng.gen::<f64>())
}
