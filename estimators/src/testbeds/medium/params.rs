//! The parameters of `eq21-medium` and `perlin-medium` (book: testbeds.md).

use super::sphere::{Field, LIGHT};
use mcbench_core::error::ConfigError;
use mcbench_core::lighting::PointLight;
use mcbench_core::math::Vec3;
use mcbench_core::params::{check_count, check_range, ParamSet};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The default exponent `k` of Eq. 21's first factor (parameter `exponent` of `eq21-medium`; the
/// book's paper-002 chapter gives the evidence for the reading).
pub const DEFAULT_EXPONENT: i32 = 5;

/// Parameters of the medium test beds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct MediumParams {
    /// Side of the square image in pixels (1 to 512; unset: 32 for eq21 `transmittance`, 16 for
    /// Perlin and `multiple`, the stored-reference size for `single-scatter`).
    pub resolution: Option<usize>,
    /// Points `T(20 k / points)` on the central ray (`central-ray` only; 1 to 10000).
    pub points: usize,
    /// Factor on the extinction field (0 to 1e6, exclusive of 0).
    pub scale: f64,
    /// Single-scattering albedo (0 to 1; unset: 0.7 for Eq. 21, 0.9 for Perlin).
    pub albedo: Option<f64>,
    /// Point light x (`single-scatter` only; unset: 0, the sphere's centre).
    pub light_x: Option<f64>,
    /// Point light y (`single-scatter` only; unset: 0).
    pub light_y: Option<f64>,
    /// Point light z (`single-scatter` only; unset: 10).
    pub light_z: Option<f64>,
    /// Point light intensity (`single-scatter` only; 0 to 1e12, exclusive of 0; unset: 100).
    pub intensity: Option<f64>,
    /// The exponent k of Eq. 21's first factor, `((cos(1.5 (x + y + z)) + 1) / 2)^k`
    /// (`eq21-medium` only; 1 to 16; unset: [`DEFAULT_EXPONENT`]).
    pub exponent: Option<usize>,
}

impl Default for MediumParams {
    fn default() -> Self {
        MediumParams {
            resolution: None,
            points: 40,
            scale: 1.0,
            albedo: None,
            light_x: None,
            light_y: None,
            light_z: None,
            intensity: None,
            exponent: None,
        }
    }
}

impl ParamSet for MediumParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        if let Some(r) = self.resolution {
            check_count("resolution", r, 512)?;
        }
        check_count("points", self.points, 10_000)?;
        if let Some(a) = self.albedo {
            check_range("albedo", a, 0.0, 1.0)?;
        }
        if let Some(k) = self.exponent {
            check_count("exponent", k, 16)?;
        }
        Ok(())
    }
}

impl MediumParams {
    /// The light params given, for refusing them outside `single-scatter`.
    fn light_given(&self) -> Option<&'static str> {
        [
            ("light_x", self.light_x.is_some()),
            ("light_y", self.light_y.is_some()),
            ("light_z", self.light_z.is_some()),
            ("intensity", self.intensity.is_some()),
        ]
        .into_iter()
        .find(|(_, given)| *given)
        .map(|(name, _)| name)
    }

    /// Checks what depends on the field and the variant: the scale's range, the exponent only for
    /// `eq21-medium`, and light parameters only for `single-scatter` (elsewhere there is no light).
    pub fn check_for(&self, field: Field, variant: &str) -> Result<(), ConfigError> {
        if !(self.scale > 0.0 && self.scale <= 1e6) {
            return Err(ConfigError::invalid(format!("{}.scale", field.id()), self.scale, "must lie in (0, 1e6]"));
        }
        if field == Field::Perlin && self.exponent.is_some() {
            return Err(ConfigError::UnknownName {
                kind: "parameter",
                name: format!("{}.exponent", field.id()),
                valid: "resolution, points, scale, albedo, light_x, light_y, light_z, intensity (exponent is Eq. 21's, eq21-medium only)".into(),
            });
        }
        if variant != "single-scatter" {
            if let Some(name) = self.light_given() {
                return Err(ConfigError::UnknownName {
                    kind: "parameter",
                    name: format!("{}.{name}", field.id()),
                    valid: "resolution, points, scale, albedo, exponent (the light parameters apply to single-scatter only)"
                        .into(),
                });
            }
        }
        Ok(())
    }

    /// The exponent of Eq. 21 (unset: [`DEFAULT_EXPONENT`]).
    pub fn exponent(&self) -> i32 {
        self.exponent.map_or(DEFAULT_EXPONENT, |k| k as i32)
    }

    /// The point light (defaults: intensity 100 at the sphere's centre).
    pub fn light(&self, field: Field) -> Result<PointLight, ConfigError> {
        let p = LIGHT.position;
        let position = Vec3::new(self.light_x.unwrap_or(p.x), self.light_y.unwrap_or(p.y), self.light_z.unwrap_or(p.z));
        let intensity = self.intensity.unwrap_or(LIGHT.intensity);
        if !(intensity > 0.0 && intensity <= 1e12) {
            return Err(ConfigError::invalid(format!("{}.intensity", field.id()), intensity, "must lie in (0, 1e12]"));
        }
        Ok(PointLight { position, intensity })
    }
}
