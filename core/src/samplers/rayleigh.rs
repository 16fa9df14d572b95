//! Rayleigh phase function `3/(16 pi) (1 + cos^2 theta)` (book: testbeds.md), sampled exactly by inverting
//! its cosine CDF `F(mu) = 1/2 + 3/8 (mu + mu^3 / 3)` with Cardano's formula.

use crate::math::{Frame, Vec3};
use crate::rng::StreamRng;
use rand::Rng;
use std::f64::consts::PI;

/// Phase function value per solid angle for `cos_theta` between the directions.
pub fn pdf(cos_theta: f64) -> f64 {
    3.0 / (16.0 * PI) * (1.0 + cos_theta * cos_theta)
}

/// The cosine with CDF value `xi`: the real root of `mu^3 + 3 mu = 8 xi - 4`.
pub fn sample_cos(xi: f64) -> f64 {
    let c = 8.0 * xi - 4.0;
    let a = (0.5 * c + (0.25 * c * c + 1.0).sqrt()).cbrt();
    (a - 1.0 / a).clamp(-1.0, 1.0)
}

/// A direction around `w` (unit) distributed by the Rayleigh phase function.
pub fn sample(w: Vec3, rng: &mut StreamRng) -> Vec3 {
    let mu = sample_cos(rng.gen::<f64>());
    let phi = 2.0 * PI * rng.gen::<f64>();
    Frame::around(w).to_world(super::spherical_direction(mu, phi))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdf_inverse_round_trips() {
        for xi in [0.0, 0.1, 0.5, 0.77, 1.0] {
            let mu = sample_cos(xi);
            assert!((0.5 + 0.375 * (mu + mu * mu * mu / 3.0) - xi).abs() < 1e-12);
        }
    }
}
