//! The parameters of the cache SMC ids: [`SurfaceSmcParams`] (`brdf_is1_cv2`, surfaces only) and
//! [`CacheSmcParams`] (`is0_cv1`, `is0_cv2`, `is1_cv0`, `is1_cv1`, `is1_cv2`, which serve surfaces
//! with paper 001's per-pixel cache and media with paper 000's octree,
//! [`crate::media_smc::SurfaceOrMedium`]).

use crate::cache::{Storage, MAX_DEPTH_LIMIT};
use crate::media_smc::params::MediaSmcParams;
use mcbench_core::error::ConfigError;
use mcbench_core::params::{check_count, check_range, ParamSet};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Checks a cache's refinement parameters: `criterion` in `[1, 1e9]`, `max_depth` in `[1, 12]`.
pub fn check_refinement(criterion: f64, max_depth: usize) -> Result<(), ConfigError> {
    check_range("criterion", criterion, 1.0, 1e9)?;
    check_count("max_depth", max_depth, MAX_DEPTH_LIMIT as usize)?;
    Ok(())
}

/// Parameters of the surface SMC cache (`brdf_is1_cv2`, and the surface half of the cache SMC ids).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SurfaceSmcParams {
    /// Mean records per cache cell at which the cache refines (1 to 1e9; paper 001 Table 1: 8).
    pub criterion: f64,
    /// Most refinements of a cell (1 to 12).
    pub max_depth: usize,
    /// Precision the cache cells are stored in: `f64` (the paper's) or `f32` (half the memory).
    pub storage: Storage,
}

impl Default for SurfaceSmcParams {
    fn default() -> Self {
        SurfaceSmcParams { criterion: 8.0, max_depth: 8, storage: Storage::F64 }
    }
}

impl ParamSet for SurfaceSmcParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_refinement(self.criterion, self.max_depth)
    }
}

/// Parameters of `is0_cv1`, `is0_cv2`, `is1_cv0`, `is1_cv1` and `is1_cv2`: the surface cache's and
/// the medium octree's, whose defaults differ.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct CacheSmcParams {
    /// Mean records per cache cell at which the cache refines (1 to 1e9; unset: 8 on a surface,
    /// paper 001 Table 1, and 32 in a medium).
    pub criterion: Option<f64>,
    /// Most refinements of a cell (1 to 12; unset: 8 on a surface, 5 octree levels in a medium).
    pub max_depth: Option<usize>,
    /// Precision the cache cells are stored in: `f64` (the paper's) or `f32` (half the memory).
    pub storage: Storage,
    /// In a medium: one structure for the whole image (1, the default, or any value >= 0.5) or one
    /// per pixel (0, or any value < 0.5); 0 to 1. Unused on a surface.
    pub shared: f64,
}

impl Default for CacheSmcParams {
    fn default() -> Self {
        CacheSmcParams { criterion: None, max_depth: None, storage: Storage::F64, shared: 1.0 }
    }
}

impl CacheSmcParams {
    /// The parameters of the surface half (`shared` belongs to the medium only).
    pub fn surface(&self) -> SurfaceSmcParams {
        let d = SurfaceSmcParams::default();
        SurfaceSmcParams {
            criterion: self.criterion.unwrap_or(d.criterion),
            max_depth: self.max_depth.unwrap_or(d.max_depth),
            storage: self.storage,
        }
    }
    /// The parameters of the medium half.
    pub fn medium(&self) -> MediaSmcParams {
        let d = MediaSmcParams::default();
        MediaSmcParams {
            criterion: self.criterion.unwrap_or(d.criterion),
            max_depth: self.max_depth.unwrap_or(d.max_depth),
            storage: self.storage,
            shared: self.shared,
        }
    }
}

impl ParamSet for CacheSmcParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        self.medium().validate(owner)?;
        self.surface().validate(owner)
    }
}
