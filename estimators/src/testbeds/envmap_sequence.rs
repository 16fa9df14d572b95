//! `envmap-sequence` (paper 004; book: testbeds.md): an orthographic view of a unit sphere (one shading
//! point per pixel, default 32x32, view along +y; the image covers the square inscribed in the
//! sphere's disc so every pixel centre hits it) with a modified-Phong BRDF, lit by a lat-long
//! environment map (256x128 texels tabulated from [`crate::testbeds::sky::Sky`]) rotating by
//! 1.5 degrees a frame about +z for F = 10 frames; an infinite ground plane at z = -1 gives
//! `V = 1` iff `w_z >= 0`.
//!
//! Integral `pixel * F + frame` is `L_r` (variants `specular`, `mixed`, `moving`, `moving-wall`,
//! `moving-specular-wall`) or `L_ns`
//! (variants `specular-lns`, `mixed-lns`, `moving-lns`) of that pixel in that frame; references
//! are exact per texel ([`super::envmap_reference`]).
//!
//! The `moving` variants keep the `mixed` BRDF under a map closer to paper 004 §7's
//! ([`crate::testbeds::moving_sky::MovingSky`]): five narrow bright lobes off the rotation axis at
//! elevations 8 to 62 degrees over a dim background brighter on one side, so the rotation moves
//! the target's mass (under the default sky only the sun moves it). The expected share of pixels
//! the SMC reweighting must resample is computed exactly in [`super::envmap_ess`].
//!
//! `moving-wall` is `moving` with real visibility: a black wall beside the sphere (the plane
//! `x = 1.5` from the ground up to `z = 1`, [`WALL_X`], [`WALL_TOP`]) hides, from each shading
//! point, the sky on one side of a great circle that differs from pixel to pixel (up to about 50
//! degrees of elevation towards +x on the pixels nearest the wall). Paper 004 §7's scenes are
//! lit through such occlusion: every sample's visibility is a shadow ray, and the rotating lobes
//! pass behind the wall.
//!
//! `moving-specular-wall` is `moving-wall` with the `specular` BRDF (paper 004 Fig. 4's case: no
//! diffuse part, Phong exponent 50), so the target is a narrow lobe the SMC particles can follow.
//!
//! Parameters: `resolution` (32), `frames` (10), `rotation` (degrees per frame, 1.5), `sun` (peak
//! radiance of the sun, or of the `moving` map's key lobe, 1e3: dynamic range > 1e4), `dawn_dusk`
//! (0 or 1: a slow intensity change over the sequence, one map per frame), `env_width` (256),
//! `env_height` (128, even).

use super::envmap_reference::{PixelReference, TexelTable};
use crate::testbeds::moving_sky::MovingSky;
use crate::testbeds::sky::{Sky, SkyModel};
use mcbench_core::brdf::Phong;
use mcbench_core::entry::{BedCase, CaseRole, TestBedEntry};
use mcbench_core::envmap::{EnvFrame, EnvMap};
use mcbench_core::error::ConfigError;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::{check_count, check_range, parse, ParamSet, ParamSpec, Params};
use mcbench_core::references::{ReferenceKey, ReferenceSource};
use mcbench_core::testbed::{EnvQuantity, EnvSequenceScene, Needs, Reference, ReferenceKind, ShadingPoint, TestBed};
use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The environment-map part of the `unbiasedness` experiment: 4 particles per frame, 1500
/// repetitions (quick) or 20000 (full).
const ENVMAP_PART: CaseRole = CaseRole::Unbiasedness { samples: 4, reps: (1500, 20_000) };

/// The same part's cases that run in the full mode only: at 1500 repetitions no row of them can
/// decide. `specular-lns`: the unbiased rows detect 3-6% and would need 12,000-55,000 repetitions
/// to resolve 1%; `moving-specular-wall`: 4-9%, 25,000-130,000. The control is exempt on both
/// (on `specular-lns` its `L_ns` estimate is the unbiased one; on `moving-specular-wall` 1500
/// repetitions detect only about 24%). Their ingredients are decided on `specular`, `mixed-lns`
/// and `moving-wall`.
const ENVMAP_FULL_ONLY: CaseRole = CaseRole::Unbiasedness { samples: 4, reps: (0, 20_000) };

/// Registry entry.
///
/// ```
/// use mcbench_papers::builtins::testbed;
/// use mcbench_core::params::Params;
///
/// let params = Params::new().with("resolution", 2.0).with("frames", 3.0).with("env_width", 16.0).with("env_height", 8.0);
/// let bed = testbed("envmap-sequence").unwrap().build_exact("mixed", &params).unwrap();
/// let env = bed.env_sequence().unwrap();
/// assert_eq!((env.frames(), bed.integrals()), (3, 2 * 2 * 3));
/// let sun_side = env.environment(0).radiance(mcbench_core::math::Vec3::new(0.0, 0.0, 1.0));
/// assert!(sun_side.is_finite());
/// ```
pub static ENTRY: TestBedEntry = TestBedEntry {
    id: "envmap-sequence",
    variants: &["specular", "mixed", "specular-lns", "mixed-lns", "moving", "moving-lns", "moving-wall", "moving-specular-wall"],
    // Not `SURFACE`: its integrals are per-frame environment integrals reached through
    // `env_sequence()`, not the hemisphere probe the surface estimators need.
    provides: Needs::ENV_SEQUENCE,
    summary:
        "Phong sphere under a rotating HDR sky (`moving`: narrow bright lobes that move with it; `moving-wall`: and a wall that hides part of it; `moving-specular-wall`: that with the specular BRDF), L_r or L_ns per pixel and frame, exact per-texel reference (paper 004)",
    build: |variant, params, refs| Ok(Box::new(EnvmapSequence::with_references(variant, params, refs)?)),
    compute_reference: None,
    params: ParamSpec::of::<EnvmapSequenceParams>().display("environment-map sequence (paper 004)").words(crate::words::variant),
    cases: &[
        BedCase {
            variant: "mixed",
            params: &[("resolution", 2.0), ("frames", 2.0), ("sun", 1e6)],
            role: CaseRole::Stability,
        },
        BedCase { variant: "mixed", params: &[("resolution", 2.0), ("frames", 2.0)], role: CaseRole::Check },
        BedCase { variant: "specular", params: &[("resolution", 2.0), ("frames", 4.0)], role: ENVMAP_PART },
        BedCase { variant: "mixed", params: &[("resolution", 2.0), ("frames", 4.0)], role: ENVMAP_PART },
        BedCase { variant: "specular-lns", params: &[("resolution", 2.0), ("frames", 4.0)], role: ENVMAP_FULL_ONLY },
        BedCase { variant: "mixed-lns", params: &[("resolution", 2.0), ("frames", 4.0)], role: ENVMAP_PART },
        BedCase { variant: "moving", params: &[("resolution", 2.0), ("frames", 4.0)], role: ENVMAP_PART },
        BedCase { variant: "moving-lns", params: &[("resolution", 2.0), ("frames", 4.0)], role: ENVMAP_PART },
        BedCase { variant: "moving-wall", params: &[("resolution", 2.0), ("frames", 4.0)], role: ENVMAP_PART },
        BedCase { variant: "moving-specular-wall", params: &[("resolution", 2.0), ("frames", 4.0)], role: ENVMAP_FULL_ONLY },
    ],
};

/// Parameters of `envmap-sequence` (book: testbeds.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct EnvmapSequenceParams {
    /// Side of the square image of the sphere in pixels (1 to 512).
    pub resolution: usize,
    /// Frames per pixel (1 to 1000).
    pub frames: usize,
    /// Rotation of the map about +z per frame, in degrees (-360 to 360).
    pub rotation: f64,
    /// Peak radiance of the sun lobe, or of the `moving` map's key lobe (0 to 1e12; the sky's
    /// dynamic range follows it).
    pub sun: f64,
    /// 1: the sky's intensity changes slowly over the frames (dawn to dusk); 0: constant.
    pub dawn_dusk: f64,
    /// Width of the lat-long map in texels (4 to 8192).
    pub env_width: usize,
    /// Height of the lat-long map in texels (even, 2 to 4096).
    pub env_height: usize,
}

impl Default for EnvmapSequenceParams {
    fn default() -> Self {
        EnvmapSequenceParams {
            resolution: 32,
            frames: 10,
            rotation: 1.5,
            sun: 1e3,
            dawn_dusk: 0.0,
            env_width: 256,
            env_height: 128,
        }
    }
}

impl ParamSet for EnvmapSequenceParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_count("resolution", self.resolution, 512)?;
        check_count("frames", self.frames, 1000)?;
        check_range("rotation", self.rotation, -360.0, 360.0)?;
        check_range("sun", self.sun, 0.0, 1e12)?;
        check_range("dawn_dusk", self.dawn_dusk, 0.0, 1.0)?;
        check_count("env_width", self.env_width, 8192)?;
        check_count("env_height", self.env_height, 4096)?;
        if !self.env_height.is_multiple_of(2) || self.env_width < 4 || self.env_height < 2 {
            return Err(ConfigError::invalid(
                "env_height",
                self.env_height,
                "must be even (the horizon is a row edge) with env_width >= 4",
            ));
        }
        Ok(())
    }
}

/// How the exact references are computed (a stored reference of another method is not read).
const METHOD: &str = "per-texel exact solid angles; closed-form diffuse moments and Gauss-Legendre of the Phong lobe per texel, horizon-split panels";

/// Half-width of the orthographic image (inside the unit disc's inscribed square).
const HALF_WIDTH: f64 = 0.7;

/// The `-wall` variants' occluder: a black wall in the plane `x = WALL_X`, infinite in `y`,
/// from the ground (`z = -1`) up to `z = WALL_TOP`: beside the sphere (radius 1) and as tall.
pub const WALL_X: f64 = 1.5;
/// Top edge of the `-wall` variants' wall.
pub const WALL_TOP: f64 = 1.0;

/// The wall's silhouette seen from `position` (below the wall's top, in front of its plane): a
/// direction `w` above the ground is blocked iff it hits the wall's plane below the top edge,
/// `w_x > 0` and `w_z (WALL_X - x) < (WALL_TOP - z) w_x`, that is iff `w . m < 0` for the `m`
/// returned: the silhouette is a great circle, as the shading horizon is.
pub fn wall_normal(position: Vec3) -> Vec3 {
    Vec3::new(-(WALL_TOP - position.z), 0.0, WALL_X - position.x).normalize()
}

/// The scene.
pub struct EnvmapSequence {
    variant: String,
    size: usize,
    frames: usize,
    rotation: f64,
    quantity: EnvQuantity,
    maps: Vec<EnvMap>,
    points: Vec<ShadingPoint>,
    /// Per pixel, the wall's silhouette ([`wall_normal`]) in the `-wall` variants.
    walls: Option<Vec<Vec3>>,
    /// Everything the exact pixel references depend on (parameters and BRDF), for the memo.
    setup: String,
    reference: Reference,
    /// What a stored reference of it is found by (variant and every parameter).
    key: ReferenceKey,
}

/// The BRDF and quantity of a variant (book: testbeds.md); the `moving` ones have the `mixed` BRDF
/// but `moving-specular-wall`, which has the `specular` one.
pub fn variant_setup(variant: &str) -> Result<(Phong, EnvQuantity), ConfigError> {
    let phong = |kd: f64, ks: f64| Phong { kd: Rgb::splat(kd), ks: Rgb::splat(ks), n: 50.0 };
    match variant {
        "specular" => Ok((phong(0.0, 1.0), EnvQuantity::Reflected)),
        "mixed" => Ok((phong(0.5, 0.5), EnvQuantity::Reflected)),
        "specular-lns" => Ok((phong(0.0, 1.0), EnvQuantity::Unoccluded)),
        "mixed-lns" => Ok((phong(0.5, 0.5), EnvQuantity::Unoccluded)),
        "moving" => Ok((phong(0.5, 0.5), EnvQuantity::Reflected)),
        "moving-lns" => Ok((phong(0.5, 0.5), EnvQuantity::Unoccluded)),
        "moving-wall" => Ok((phong(0.5, 0.5), EnvQuantity::Reflected)),
        "moving-specular-wall" => Ok((phong(0.0, 1.0), EnvQuantity::Reflected)),
        _ => {
            Err(ConfigError::unknown("variant", &format!("envmap-sequence/{variant}"), ENTRY.variants.iter().copied()))
        }
    }
}

impl EnvmapSequence {
    /// Builds a variant and computes its exact reference (parallel over pixels).
    pub fn new(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        Self::with_references(variant, params, &mcbench_core::references::NoReferences)
    }

    /// Builds a variant with its exact reference: the one stored in `refs` under its key when it
    /// was made by the current quadrature ([`mcbench_core::references::stored_exact`]: the quadrature
    /// over every texel takes seconds per setup at every run), else computed.
    pub fn with_references(variant: &str, params: &Params, refs: &dyn ReferenceSource) -> Result<Self, ConfigError> {
        let mut bed = Self::without_reference(variant, params)?;
        bed.reference = match mcbench_core::references::stored_exact(
            refs,
            &bed.key,
            METHOD,
            bed.points.len() * bed.frames,
            bed.resolution(),
        )? {
            Some(r) => r,
            None => bed.compute_reference(),
        };
        Ok(bed)
    }

    /// The scene alone, its reference left empty (for computations on the maps and the BRDF).
    pub(super) fn without_reference(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        let p = parse::<EnvmapSequenceParams>("envmap-sequence", params)?;
        let json =
            serde_json::to_value(&p).map_err(|e| ConfigError::invalid("envmap-sequence", variant, e.to_string()))?;
        let key = ReferenceKey {
            testbed: ENTRY.id.into(),
            variant: variant.into(),
            params: json.as_object().cloned().unwrap_or_default(),
            default: p == EnvmapSequenceParams::default(),
        };
        let (size, frames, rotation, sun) = (p.resolution, p.frames, p.rotation.to_radians(), p.sun);
        let (dawn_dusk, ew, eh) = (p.dawn_dusk != 0.0, p.env_width, p.env_height);
        let (brdf, quantity) = variant_setup(variant)?;
        let moving = variant.starts_with("moving");
        let maps = if moving {
            tabulate(&MovingSky::with_key(sun), frames, dawn_dusk, (ew, eh))?
        } else {
            tabulate(&Sky::default_with_sun(sun), frames, dawn_dusk, (ew, eh))?
        };
        let mut points = Vec::with_capacity(size * size);
        for py in 0..size {
            for px in 0..size {
                let x = (2.0 * (px as f64 + 0.5) / size as f64 - 1.0) * HALF_WIDTH;
                let z = (1.0 - 2.0 * (py as f64 + 0.5) / size as f64) * HALF_WIDTH;
                let p = Vec3::new(x, -(1.0 - x * x - z * z).sqrt(), z);
                points.push(ShadingPoint { position: p, normal: p, wo: Vec3::new(0.0, -1.0, 0.0), brdf });
            }
        }
        let walls = variant.ends_with("-wall").then(|| points.iter().map(|p| wall_normal(p.position)).collect());
        Ok(EnvmapSequence {
            variant: variant.to_string(),
            size,
            frames,
            rotation,
            quantity,
            maps,
            points,
            setup: format!(
                "{p:?}|{brdf:?}|{}|{}",
                if moving { "moving" } else { "sky" },
                if walls.is_some() { "wall" } else { "open" }
            ),
            walls,
            reference: empty(),
            key,
        })
    }

    /// The exact references of every pixel and frame (both quantities), computed once per process
    /// and setup (the quadrature over every texel takes seconds; an experiment builds the bed per
    /// plan and seed).
    pub fn pixel_references(&self) -> Vec<PixelReference> {
        static COMPUTED: mcbench_core::memo::Memo<Vec<PixelReference>> = mcbench_core::memo::Memo::new();
        COMPUTED.get_or_compute(self.setup.clone(), || self.compute_pixel_references())
    }

    fn compute_pixel_references(&self) -> Vec<PixelReference> {
        let g = self.maps[0].grid();
        let table = TexelTable::new(g.width, g.height);
        (0..self.points.len() * self.frames)
            .into_par_iter()
            .map(|i| {
                let (p, f) = (&self.points[i / self.frames], i % self.frames);
                let wall = self.walls.as_ref().map(|w| w[i / self.frames]);
                table.reflect(self.environment(f), p, wall)
            })
            .collect()
    }

    fn compute_reference(&self) -> Reference {
        let refs = self.pixel_references();
        let bound = refs.iter().map(|r| r.bound).fold(0.0, f64::max);
        let value =
            refs.iter().map(|r| if self.quantity == EnvQuantity::Reflected { r.lr } else { r.lns }).collect::<Vec<_>>();
        let method = METHOD.into();
        Reference { kind: ReferenceKind::Exact { method, bound }, std_err: vec![Rgb::ZERO; value.len()], value }
    }
}

/// The maps of a sequence: one, or with `dawn_dusk` one per frame, frame n at time (n + 1/2) / F.
fn tabulate<S: SkyModel>(
    sky: &S,
    frames: usize,
    dawn_dusk: bool,
    (ew, eh): (usize, usize),
) -> Result<Vec<EnvMap>, ConfigError> {
    if dawn_dusk {
        (0..frames)
            .map(|n| EnvMap::tabulate(ew, eh, |w| sky.at_time((n as f64 + 0.5) / frames as f64).radiance(w)))
            .collect()
    } else {
        Ok(vec![EnvMap::tabulate(ew, eh, |w| sky.radiance(w))?])
    }
}

fn empty() -> Reference {
    Reference {
        kind: ReferenceKind::Exact { method: String::new(), bound: 0.0 },
        value: Vec::new(),
        std_err: Vec::new(),
    }
}

impl TestBed for EnvmapSequence {
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
        (self.size, self.size)
    }
    fn reference(&self) -> &Reference {
        &self.reference
    }
    fn reference_key(&self) -> Option<ReferenceKey> {
        Some(self.key.clone())
    }
    fn geometry(&self, i: usize) -> Vec<(&'static str, f64)> {
        let p = &self.points[i / self.frames];
        vec![
            ("frame", (i % self.frames) as f64),
            ("normal_x", p.normal.x),
            ("normal_y", p.normal.y),
            ("normal_z", p.normal.z),
        ]
    }
    fn env_sequence(&self) -> Option<&dyn EnvSequenceScene> {
        Some(self)
    }
    fn sequence_length(&self) -> usize {
        self.frames
    }
}

impl EnvSequenceScene for EnvmapSequence {
    fn frames(&self) -> usize {
        self.frames
    }
    fn quantity(&self) -> EnvQuantity {
        self.quantity
    }
    fn shading(&self, pixel: usize) -> ShadingPoint {
        self.points[pixel]
    }
    fn environment(&self, frame: usize) -> EnvFrame<'_> {
        let map = &self.maps[frame.min(self.maps.len() - 1)];
        EnvFrame { map, rotation: frame as f64 * self.rotation, scale: 1.0 }
    }
    fn visible(&self, pixel: usize, wi: Vec3) -> bool {
        wi.z >= 0.0 && self.walls.as_ref().is_none_or(|w| wi.dot(w[pixel]) >= 0.0)
    }
}

#[cfg(test)]
#[path = "envmap_sequence_tests.rs"]
mod tests;
