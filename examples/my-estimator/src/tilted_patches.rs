//! `tilted-patches`: a row of diffuse patches under a linear sky `L(w) = c0 + c1 w_z` over the whole
//! sphere, patch `i` tilted by `max_tilt i / (patches - 1)` about the x axis and seen along its
//! normal. A diffuse patch of albedo `kd` with normal `n` reflects
//! `int L(w) kd / pi (w . n)+ dw = kd (c0 + 2/3 c1 n_z)` (the cosine lobe's mean direction is
//! `2/3 n`): the reference is exact.

use mcbench::{ConfigError, Needs, Reference, Rgb, TestBed, TestBedEntry};
use mcbench_core::brdf::Phong;
use mcbench_core::entry::{BedCase, CaseRole};
use mcbench_core::math::Vec3;
use mcbench_core::params::{check_count, check_range, parse, ParamSet, ParamSpec, Params};
use mcbench_core::references::ReferenceSource;
use mcbench_core::testbed::{HemisphereScene, ReferenceKind, ShadingPoint};
use serde::{Deserialize, Serialize};

/// Sky radiance at the horizon (and everywhere when `c1 = 0`).
const C0: f64 = 1.0;

/// Parameters of `tilted-patches`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct PatchParams {
    /// Patches in the row, one pixel each (1 to 256).
    pub patches: usize,
    /// Tilt of the last patch, in degrees (0 to 89).
    pub max_tilt: f64,
    /// Sky gradient `c1` of `L(w) = 1 + c1 w_z` (0 to 1: the sky stays non-negative).
    pub c1: f64,
}

impl Default for PatchParams {
    fn default() -> Self {
        PatchParams { patches: 8, max_tilt: 80.0, c1: 0.5 }
    }
}

impl ParamSet for PatchParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_count("patches", self.patches, 256)?;
        check_range("max_tilt", self.max_tilt, 0.0, 89.0)?;
        check_range("c1", self.c1, 0.0, 1.0).map(|_| ())
    }
}

/// The conformance and unbiasedness checks run on these cases.
const PART: CaseRole = CaseRole::Unbiasedness { samples: 16, reps: (256, 2048) };

/// The registry entry.
pub static ENTRY: TestBedEntry = TestBedEntry {
    id: "tilted-patches",
    variants: &["matte", "dark"],
    provides: Needs::SURFACE,
    summary: "diffuse patches of growing tilt under a linear sky, exact reference",
    build,
    compute_reference: None,
    params: ParamSpec::of::<PatchParams>(),
    cases: &[
        BedCase { variant: "matte", params: &[("patches", 4.0)], role: CaseRole::Check },
        BedCase { variant: "dark", params: &[("patches", 2.0), ("c1", 1.0)], role: CaseRole::Stability },
        BedCase { variant: "matte", params: &[], role: PART },
        BedCase { variant: "dark", params: &[], role: PART },
    ],
};

fn build(variant: &str, params: &Params, _refs: &dyn ReferenceSource) -> Result<Box<dyn TestBed>, ConfigError> {
    Ok(Box::new(TiltedPatches::new(variant, params)?))
}

/// The scene.
pub struct TiltedPatches {
    variant: String,
    c1: f64,
    points: Vec<ShadingPoint>,
    reference: Reference,
}

impl TiltedPatches {
    /// Builds a variant (`matte`: albedo 0.8, `dark`: 0.1).
    pub fn new(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        let p: PatchParams = parse(ENTRY.id, params)?;
        let kd = match variant {
            "matte" => 0.8,
            "dark" => 0.1,
            _ => {
                return Err(ConfigError::unknown(
                    "variant",
                    &format!("{}/{variant}", ENTRY.id),
                    ENTRY.variants.iter().copied(),
                ))
            }
        };
        let brdf = Phong { kd: Rgb([kd; 3]), ks: Rgb::ZERO, n: 1.0 };
        let points: Vec<ShadingPoint> = (0..p.patches)
            .map(|i| {
                let t = if p.patches > 1 { i as f64 / (p.patches - 1) as f64 } else { 0.0 };
                let tilt = (p.max_tilt * t).to_radians();
                let normal = Vec3::new(0.0, -tilt.sin(), tilt.cos());
                ShadingPoint { position: Vec3::new(i as f64, 0.0, 0.0), normal, wo: normal, brdf }
            })
            .collect();
        let value: Vec<Rgb> = points.iter().map(|s| Rgb([kd * (C0 + 2.0 / 3.0 * p.c1 * s.normal.z); 3])).collect();
        let reference = Reference {
            kind: ReferenceKind::Exact { method: "closed form kd (c0 + 2/3 c1 n_z)".into(), bound: 1e-15 },
            std_err: vec![Rgb::ZERO; value.len()],
            value,
        };
        Ok(TiltedPatches { variant: variant.into(), c1: p.c1, points, reference })
    }
}

impl HemisphereScene for TiltedPatches {
    fn shading(&self, i: usize) -> ShadingPoint {
        self.points[i]
    }
    fn incident(&self, _i: usize, wi: Vec3) -> Rgb {
        Rgb([C0 + self.c1 * wi.z; 3])
    }
}

impl TestBed for TiltedPatches {
    fn id(&self) -> &'static str {
        ENTRY.id
    }
    fn variant(&self) -> &str {
        &self.variant
    }
    fn provides(&self) -> Needs {
        ENTRY.provides
    }
    fn resolution(&self) -> (usize, usize) {
        (self.points.len(), 1)
    }
    fn reference(&self) -> &Reference {
        &self.reference
    }
    fn hemisphere(&self) -> Option<&dyn HemisphereScene> {
        Some(self)
    }
}
