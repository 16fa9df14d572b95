//! Direction samplers with the densities they report (per unit solid angle).
//!
//! Every sampler here (and the Phong BRDF mixture and the phase functions) is registered in
//! [`registry::SAMPLERS`] with its chi-square goodness-of-fit checks (book: conformance.md), built on
//! [`testing::sampler_chi_square`] / [`testing::interval_chi_square`]; a unit test runs them all and
//! checks that every module of this folder is registered, and the conformance suite runs the
//! checks of the samplers each estimator names.

pub mod cone;
pub mod cosine_hemisphere;
pub mod equiangular;
pub mod free_flight;
pub mod mixture;
pub mod phong_lobe;
pub mod rayleigh;
pub mod rect_light;
pub mod registry;
pub mod testing;
pub mod uniform_hemisphere;

use crate::math::Vec3;

/// A unit direction from `cos(theta)` and `phi` about the local +z axis.
pub fn spherical_direction(cos_theta: f64, phi: f64) -> Vec3 {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}
