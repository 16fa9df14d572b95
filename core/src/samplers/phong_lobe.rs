//! Sampling of the normalised Phong lobe about a local axis +z: density
//! `(n + 1) / (2 pi) cos(alpha)^n` over the hemisphere around the axis (Lafortune and Willems
//! 1994), `cos(alpha) = u^(1 / (n + 1))`.

use super::spherical_direction;
use crate::math::Vec3;
use rand::Rng;
use std::f64::consts::PI;

/// The density per unit solid angle for `cos(alpha) = cos_alpha` (angle to the lobe axis).
pub fn pdf(cos_alpha: f64, n: f64) -> f64 {
    if cos_alpha <= 0.0 {
        return 0.0;
    }
    pdf_of_power(cos_alpha, n, cos_alpha.powf(n))
}

/// [`pdf`] given `power = cos_alpha^n` (any value where `cos_alpha <= 0`, where the density is
/// zero): for a caller that needs the same power elsewhere (the Phong BRDF's value).
pub fn pdf_of_power(cos_alpha: f64, n: f64, power: f64) -> f64 {
    if cos_alpha <= 0.0 {
        return 0.0;
    }
    (n + 1.0) / (2.0 * PI) * power
}

/// A direction about the lobe axis (+z) in local coordinates.
pub fn sample_local<R: Rng + ?Sized>(n: f64, rng: &mut R) -> Vec3 {
    // 1 - u lies in (0, 1], so cos(alpha) > 0 and the pdf never vanishes at the sample.
    let cos_alpha = (1.0 - rng.gen::<f64>()).powf(1.0 / (n + 1.0));
    spherical_direction(cos_alpha, 2.0 * PI * rng.gen::<f64>())
}
