//! The parameters of the single-scatter estimators. Their rays are tracked by residual ratio
//! tracking, so each struct lists [`ResidualParams`]' fields (`attenuation_driven` takes exactly
//! those) beside its own; `mis` fixes `control` at its default.

use crate::tracking::params::ResidualParams;
use crate::tracking::residual_ratio_tracking::ResidualRatioTracking;
use mcbench_core::error::ConfigError;
use mcbench_core::params::{check_count, ParamSet};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Checks `points` (1 to 1000).
fn check_points(points: usize) -> Result<usize, ConfigError> {
    check_count("points", points, 1000)
}

/// Checks `scatter_floor` (> 0), naming `owner`.
pub fn check_scatter_floor(v: f64, owner: &str) -> Result<f64, ConfigError> {
    if v <= 0.0 {
        return Err(ConfigError::invalid(
            format!("{owner}.scatter_floor"),
            v,
            "must be > 0 (the density must cover every sigma_t > 0)",
        ));
    }
    Ok(v)
}

/// Parameters of `attenuation_driven_sir`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct AttenuationSirParams {
    /// Candidates resampled per primary ray, each tracing a shadow ray (1 to 1000).
    pub shadow_rays: usize,
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

impl Default for AttenuationSirParams {
    fn default() -> Self {
        let r = ResidualParams::default();
        AttenuationSirParams {
            shadow_rays: 1,
            explorer_spacing: r.explorer_spacing,
            recent: r.recent,
            sigma_floor: r.sigma_floor,
            sigma_samp0: r.sigma_samp0,
            control: r.control,
        }
    }
}

impl AttenuationSirParams {
    /// The tracking parameters.
    pub fn residual(&self) -> ResidualParams {
        ResidualParams {
            explorer_spacing: self.explorer_spacing,
            recent: self.recent,
            sigma_floor: self.sigma_floor,
            sigma_samp0: self.sigma_samp0,
            control: self.control,
        }
    }
}

impl ParamSet for AttenuationSirParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        ResidualRatioTracking::from_params(&self.residual(), owner)?;
        check_count("shadow_rays", self.shadow_rays, 1000)?;
        Ok(())
    }
}

/// Parameters of `source_driven`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SourceDrivenParams {
    /// Equiangular scattering points per primary ray (1 to 1000).
    pub points: usize,
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

impl Default for SourceDrivenParams {
    fn default() -> Self {
        let r = ResidualParams::default();
        SourceDrivenParams {
            points: 1,
            explorer_spacing: r.explorer_spacing,
            recent: r.recent,
            sigma_floor: r.sigma_floor,
            sigma_samp0: r.sigma_samp0,
            control: r.control,
        }
    }
}

impl SourceDrivenParams {
    /// The tracking parameters.
    pub fn residual(&self) -> ResidualParams {
        ResidualParams {
            explorer_spacing: self.explorer_spacing,
            recent: self.recent,
            sigma_floor: self.sigma_floor,
            sigma_samp0: self.sigma_samp0,
            control: self.control,
        }
    }
}

impl ParamSet for SourceDrivenParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        ResidualRatioTracking::from_params(&self.residual(), owner)?;
        check_points(self.points)?;
        Ok(())
    }
}

/// Parameters of `scattering_driven`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct ScatteringDrivenParams {
    /// Scattering points per primary ray (1 to 1000).
    pub points: usize,
    /// Smallest sampling extinction of the scattering-driven density (> 0, so that it covers
    /// every `sigma_t > 0`).
    pub scatter_floor: f64,
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

impl Default for ScatteringDrivenParams {
    fn default() -> Self {
        let r = ResidualParams::default();
        ScatteringDrivenParams {
            points: 1,
            scatter_floor: 0.01,
            explorer_spacing: r.explorer_spacing,
            recent: r.recent,
            sigma_floor: r.sigma_floor,
            sigma_samp0: r.sigma_samp0,
            control: r.control,
        }
    }
}

impl ScatteringDrivenParams {
    /// The tracking parameters.
    pub fn residual(&self) -> ResidualParams {
        ResidualParams {
            explorer_spacing: self.explorer_spacing,
            recent: self.recent,
            sigma_floor: self.sigma_floor,
            sigma_samp0: self.sigma_samp0,
            control: self.control,
        }
    }
}

impl ParamSet for ScatteringDrivenParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        ResidualRatioTracking::from_params(&self.residual(), owner)?;
        check_points(self.points)?;
        check_scatter_floor(self.scatter_floor, owner)?;
        Ok(())
    }
}

/// Parameters of `mis`: paper 003's heuristic exponent (on surfaces) and paper 002's point counts
/// and tracking (on point-light single scattering).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct MisParams {
    /// Heuristic exponent on surfaces: 1 the balance heuristic, 2 the power heuristic.
    pub power: f64,
    /// On single scattering: points of each technique (source- and scattering-driven) per
    /// primary ray (1 to 1000).
    pub points: usize,
    /// On single scattering: smallest sampling extinction of the scattering-driven density (> 0,
    /// so that it covers every `sigma_t > 0`).
    pub scatter_floor: f64,
    /// On single scattering: spacing of the explorer points the main part is fitted through (> 0).
    pub explorer_spacing: f64,
    /// On single scattering: rays whose largest `|sigma_diff|` sets the next ray's `sigma_samp` (1
    /// to 1000).
    pub recent: usize,
    /// On single scattering: smallest `sigma_samp` (> 0).
    pub sigma_floor: f64,
    /// On single scattering: `sigma_samp` of the first ray (unset, or <= 0: 0.3 times the declared
    /// majorant).
    pub sigma_samp0: Option<f64>,
}

impl Default for MisParams {
    fn default() -> Self {
        let r = ResidualParams::default();
        MisParams {
            power: 1.0,
            points: 1,
            scatter_floor: 0.01,
            explorer_spacing: r.explorer_spacing,
            recent: r.recent,
            sigma_floor: r.sigma_floor,
            sigma_samp0: r.sigma_samp0,
        }
    }
}

impl MisParams {
    /// The tracking parameters (the piecewise-linear main part).
    pub fn residual(&self) -> ResidualParams {
        ResidualParams {
            explorer_spacing: self.explorer_spacing,
            recent: self.recent,
            sigma_floor: self.sigma_floor,
            sigma_samp0: self.sigma_samp0,
            ..ResidualParams::default()
        }
    }
}

impl ParamSet for MisParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        ResidualRatioTracking::from_params(&self.residual(), owner)?;
        check_points(self.points)?;
        check_scatter_floor(self.scatter_floor, owner)?;
        if self.power != 1.0 && self.power != 2.0 {
            return Err(ConfigError::invalid(
                format!("{owner}.power"),
                self.power,
                "must be 1 (balance) or 2 (power heuristic)",
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::params::describe;

    /// The tracking fields every struct lists read as [`ResidualParams`]' do: same docs (up to
    /// `mis`'s "On single scattering: " prefix), same defaults.
    #[test]
    fn the_tracking_fields_match_residual_params() {
        let residual = describe::<ResidualParams>();
        let others = [
            describe::<AttenuationSirParams>(),
            describe::<SourceDrivenParams>(),
            describe::<ScatteringDrivenParams>(),
            describe::<MisParams>(),
        ];
        for (k, docs) in others.iter().enumerate() {
            for r in &residual {
                let Some(d) = docs.iter().find(|d| d.name == r.name) else {
                    assert!(k == 3 && r.name == "control", "{k}: {} missing", r.name);
                    continue;
                };
                let doc = d.doc.strip_prefix("On single scattering: ").unwrap_or(&d.doc);
                assert_eq!((d.kind.as_str(), d.default.as_str()), (r.kind.as_str(), r.default.as_str()), "{}", r.name);
                assert_eq!(doc.to_lowercase(), r.doc.to_lowercase(), "{k}: {}", r.name);
            }
        }
    }
}
