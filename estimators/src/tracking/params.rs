//! The parameters of paper 002's trackers and particle models.

use super::residual_ratio_tracking::{MainPart, ResidualRatioTracking};
use super::SigmaSamp;
use mcbench_core::error::ConfigError;
use mcbench_core::params::ParamSet;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Parameters of `delta_tracking`, `ratio_tracking`, `single_particle_terminating` and
/// `single_particle_nonterminating`: the constant sampling extinction.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SigmaSampParams {
    /// Constant sampling extinction (> 0; not together with `sigma_samp_ratio`). Unset: the
    /// declared majorant for `delta_tracking` and `ratio_tracking` (which need one: a smaller value
    /// is refused as a skipped pair), 1 for the single particle models.
    pub sigma_samp: Option<f64>,
    /// Sampling extinction as a multiple of the scene's declared majorant (> 0; below 1 it is not
    /// a majorant). Unset: `sigma_samp` decides. `delta_tracking` ignores it on point-light single
    /// scattering.
    pub sigma_samp_ratio: Option<f64>,
}

impl ParamSet for SigmaSampParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        SigmaSamp::from_params(self, owner, SigmaSamp::Majorant).map(|_| ())
    }
}

/// Parameters of `spm_terminating`, `spm_nonterminating` and `spm_adaptive`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SpmParams {
    /// Constant sampling extinction of the free flights (> 0; a majorant or not).
    pub sigma_samp: f64,
}

impl Default for SpmParams {
    fn default() -> Self {
        SpmParams { sigma_samp: 1.0 }
    }
}

impl ParamSet for SpmParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        super::sigma_samp_param(Some(self.sigma_samp), owner).map(|_| ())
    }
}

/// Parameters of `residual_ratio_tracking` and `attenuation_driven` (whose rays are tracked the
/// same way).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ResidualParams {
    /// Spacing of the explorer points the main part is fitted through (> 0).
    pub explorer_spacing: f64,
    /// Rays whose largest `|sigma_diff|` sets the next ray's `sigma_samp` (1 to 1000).
    pub recent: usize,
    /// Smallest `sigma_samp` (> 0).
    pub sigma_floor: f64,
    /// `sigma_samp` of the first ray (unset, or <= 0: 0.3 times the declared majorant).
    pub sigma_samp0: Option<f64>,
    /// The main part: 1 the piecewise-linear fit through the explorer points, 2 the constant at its
    /// mean (0, none, is refused: the estimator needs one).
    pub control: u32,
}

impl Default for ResidualParams {
    fn default() -> Self {
        ResidualParams { explorer_spacing: 0.5, recent: 4, sigma_floor: 0.05, sigma_samp0: None, control: 1 }
    }
}

impl ParamSet for ResidualParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        ResidualRatioTracking::from_params(self, owner).map(|_| ())
    }
}

/// Parameters of `double_particle`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct DoubleParticleParams {
    /// Constant sampling extinction (> 0, a majorant or not; not together with
    /// `sigma_samp_ratio`; unset: 1 unless `sigma_samp_ratio` is given).
    pub sigma_samp: Option<f64>,
    /// Sampling extinction as a multiple of the scene's declared majorant (> 0; unset:
    /// `sigma_samp` decides).
    pub sigma_samp_ratio: Option<f64>,
    /// Control variate: 0 none, 1 a piecewise-linear main part through explorer points, 2 the
    /// constant at its mean.
    pub control: u32,
    /// Spacing of the explorer points of the main part (> 0; used with `control` 1 or 2).
    pub explorer_spacing: f64,
}

impl Default for DoubleParticleParams {
    fn default() -> Self {
        DoubleParticleParams { sigma_samp: None, sigma_samp_ratio: None, control: 0, explorer_spacing: 0.5 }
    }
}

impl DoubleParticleParams {
    /// The sampling extinction's parameters.
    pub fn sigma(&self) -> SigmaSampParams {
        SigmaSampParams { sigma_samp: self.sigma_samp, sigma_samp_ratio: self.sigma_samp_ratio }
    }
}

impl ParamSet for DoubleParticleParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        SigmaSamp::from_params(&self.sigma(), owner, SigmaSamp::Absolute(1.0))?;
        MainPart::from_control(self.control, owner)?;
        if self.explorer_spacing <= 0.0 {
            return Err(ConfigError::invalid(
                format!("{owner}.explorer_spacing"),
                self.explorer_spacing,
                "must be > 0",
            ));
        }
        Ok(())
    }
}

/// Parameters of `ray_marching`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RayMarchingParams {
    /// Step length (> 0). Unset: 0.9 (paper 002 Fig. 9) under a sample budget, and under a fetch
    /// budget one ray spends the whole budget; given, the rays keep it under a fetch budget too.
    pub step: Option<f64>,
    /// On point-light single scattering: 1 draws each ray's offset at random, 0 fixes it at 1/2
    /// (the paper's noise-free marcher).
    pub jitter: u32,
}

impl Default for RayMarchingParams {
    fn default() -> Self {
        RayMarchingParams { step: None, jitter: 1 }
    }
}

impl RayMarchingParams {
    /// The step when none is given.
    pub const DEFAULT_STEP: f64 = 0.9;

    /// The step length.
    pub fn step(&self) -> f64 {
        self.step.unwrap_or(Self::DEFAULT_STEP)
    }
}

impl ParamSet for RayMarchingParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        if self.jitter > 1 {
            return Err(ConfigError::invalid(format!("{owner}.jitter"), self.jitter, "must be 0 or 1"));
        }
        if self.step() <= 0.0 {
            return Err(ConfigError::invalid(format!("{owner}.step"), self.step(), "must be > 0"));
        }
        Ok(())
    }
}
