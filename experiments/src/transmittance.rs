//! `transmittance` (paper 002 Fig. 8-10): equal fetch budgets (10 and 20 per pixel, plus 40 and
//! 80 for slopes) on the eq21 and Perlin transmittance images and the eq21 central ray: ray
//! marching (biased control), delta, ratio and residual ratio tracking, and the double particle
//! model with a control variate at sigma_samp = 0.4 (Fig. 8); the biased control is ray marching
//! with a coarse fixed step (`ray_marching[step=5]`). Claims: the paper's error ratios at 10 and 20
//! fetches with their intervals (declared in `transmittance.toml`), and Eq. 16 predicted vs
//! measured variance on the central ray.

use crate::ExperimentDef;
use mcbench::output::{Claim, RunReport};

/// Every id the experiment runs.
pub const IDS: &[&str] =
    &["ray_marching", "delta_tracking", "ratio_tracking", "residual_ratio_tracking", "double_particle"];

/// Definition.
pub static DEF: ExperimentDef = ExperimentDef {
    toml: include_str!("transmittance.toml"),
    claims: Some(claims),
    post: Some(crate::transmittance_post::post),
};

fn claims(_: &RunReport) -> Vec<Claim> {
    crate::variance_claims::eq16_claims()
}
