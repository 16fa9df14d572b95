//! The parameters of the medium SMC octree ([`MediaSmcParams`], the medium half of the cache SMC
//! ids) and of `rm_is1_cv2` ([`RmIs1Cv2Params`]).

use crate::cache::Storage;
use crate::surface_smc::params::check_refinement;
use mcbench_core::error::ConfigError;
use mcbench_core::params::{check_range, ParamSet};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Parameters of the medium SMC octree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct MediaSmcParams {
    /// Mean records per cache cell at which a leaf splits (1 to 1e9).
    pub criterion: f64,
    /// Octree depth limit (1 to 12).
    pub max_depth: usize,
    /// Precision the cache cells are stored in: `f64` (the paper's) or `f32` (half the memory).
    pub storage: Storage,
    /// One structure for the whole image (1, the default, or any value >= 0.5) or one per pixel (0,
    /// or any value < 0.5); 0 to 1.
    pub shared: f64,
}

impl Default for MediaSmcParams {
    fn default() -> Self {
        MediaSmcParams { criterion: 32.0, max_depth: 5, storage: Storage::F64, shared: 1.0 }
    }
}

impl ParamSet for MediaSmcParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_refinement(self.criterion, self.max_depth)?;
        check_range("shared", self.shared, 0.0, 1.0)?;
        Ok(())
    }
}

/// Parameters of `rm_is1_cv2`: the octree's and the marching step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct RmIs1Cv2Params {
    /// Ray-marching step length (1e-6 to 10; the default 0.5 is one optical depth in
    /// `gradient-box`).
    pub step: f64,
    /// Mean records per cache cell at which a leaf splits (1 to 1e9).
    pub criterion: f64,
    /// Octree depth limit (1 to 12).
    pub max_depth: usize,
    /// Precision the cache cells are stored in: `f64` (the paper's) or `f32` (half the memory).
    pub storage: Storage,
    /// One structure for the whole image (1, the default, or any value >= 0.5) or one per pixel (0,
    /// or any value < 0.5); 0 to 1.
    pub shared: f64,
}

impl Default for RmIs1Cv2Params {
    fn default() -> Self {
        let d = MediaSmcParams::default();
        RmIs1Cv2Params {
            step: 0.5,
            criterion: d.criterion,
            max_depth: d.max_depth,
            storage: d.storage,
            shared: d.shared,
        }
    }
}

impl RmIs1Cv2Params {
    /// The octree's parameters.
    pub fn octree(&self) -> MediaSmcParams {
        MediaSmcParams {
            criterion: self.criterion,
            max_depth: self.max_depth,
            storage: self.storage,
            shared: self.shared,
        }
    }
}

impl ParamSet for RmIs1Cv2Params {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        check_range("step", self.step, 1e-6, 10.0)?;
        self.octree().validate(owner)
    }
}
