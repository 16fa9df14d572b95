//! `checker-direct` (paper 003 Fig. 6-8, Table 2; book: testbeds.md): an 8 x 8 checkerboard floor of
//! diffuse and modified-Phong squares under two rectangular area lights, seen by a pinhole camera;
//! one direct-lighting integral `int L_in f cos dw` per pixel (Eq. 4-5 without emission), with a
//! quadrature reference (see [`super::checker_reference`]).
//!
//! Geometry (all fixed, grey so the three channels are equal):
//! - floor `z = 0` over `[-2, 2]^2`, squares of side 0.5; square `(ix, iy)` is diffuse (kd 0.7)
//!   when `ix + iy` is even, else glossy (kd 0.05, ks 0.8) with `n = 10 * 500^(iy / 7)`, growing
//!   geometrically from 10 in the front row (`y` near -2) to 5000 in the back row; points off the
//!   board are black (their integrand is zero: the "zero pixel" stability case);
//! - a large dim light, 2 x 1 centred at (-1.0, 1.8) at height 2.0, radiance 3, and a small bright
//!   one, 0.15 x 0.15 centred at (1.0, 0.9) at height 1.2, radiance 400, both facing down; the
//!   small light can never hide the large one from the board (checked by a test), so each light's
//!   contribution is an integral over its own rectangle;
//! - variant `occluded`: an opaque 1 x 1 square centred at (0.5, 0.2) at height 0.6 casting
//!   partial shadows; it is a shadow caster only (primary rays see the floor), so both variants
//!   shade the same points;
//! - variant `soft-shadow` (paper 003 Fig. 8 and Table 2, the Plant: "complex soft shadows" on a
//!   table, where "the cone function" helps "in partially shadowed regions"): diffuse direct
//!   lighting with a wide penumbra over most of the image; see [`SOFT_SHADOW_LIGHT`] and
//!   [`SOFT_SHADOW_LEAVES`] for the constants and why;
//! - variant `lattice`: the light of `soft-shadow` seen through a lattice of wide bars (a screen
//!   with square openings) halfway up, so that each floor point sees one small, point-specific
//!   window of the light and most light samples are blocked; see [`LATTICE`];
//! - pinhole at (0, -3.2, 4.6) looking at (0, 0.1, 0), vertical field of view 44 degrees, square
//!   image (default 48 x 48), pixel centres; the top rows see past the board.

use super::checker_reference::reference;
use super::pinhole::Pinhole;
use mcbench_core::brdf::Phong;
use mcbench_core::entry::{BedCase, CaseRole, TestBedEntry};
use mcbench_core::error::ConfigError;
use mcbench_core::lighting::RectLight;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::{check_count, parse, ParamSet, ParamSpec, Params};
use mcbench_core::testbed::{HemisphereScene, Needs, Reference, ShadingPoint, TestBed};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Registry entry.
pub static ENTRY: TestBedEntry = TestBedEntry {
    id: "checker-direct",
    variants: &["default", "occluded", "soft-shadow", "lattice"],
    provides: Needs::SURFACE.and(Needs::AREA_LIGHTS),
    summary:
        "checkerboard of diffuse/glossy squares under two area lights, direct lighting (paper 003 Fig. 6, Table 2)",
    build: |variant, params, _| Ok(Box::new(CheckerDirect::new(variant, params)?)),
    compute_reference: None,
    params: ParamSpec::of::<CheckerDirectParams>()
        .display("checker, direct lighting (paper 003 Fig. 6)")
        .words(crate::words::variant),
    cases: &[
        BedCase { variant: "occluded", params: &[("resolution", 2.0)], role: CaseRole::Stability },
        BedCase { variant: "default", params: &[("resolution", 2.0)], role: CaseRole::Check },
        BedCase { variant: "default", params: &[("resolution", 4.0)], role: super::gradient_plane::SURFACE_PART },
        BedCase { variant: "occluded", params: &[("resolution", 4.0)], role: super::gradient_plane::SURFACE_PART },
        BedCase { variant: "soft-shadow", params: &[("resolution", 4.0)], role: super::gradient_plane::SURFACE_PART },
        BedCase { variant: "lattice", params: &[("resolution", 4.0)], role: super::gradient_plane::SURFACE_PART },
    ],
};

/// Parameters of `checker-direct`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct CheckerDirectParams {
    /// Side of the square image in pixels (1 to 512).
    pub resolution: usize,
}

impl Default for CheckerDirectParams {
    fn default() -> Self {
        CheckerDirectParams { resolution: 48 }
    }
}

impl ParamSet for CheckerDirectParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_count("resolution", self.resolution, 512).map(|_| ())
    }
}

/// An axis-aligned opaque rectangle parallel to the floor (the square of `occluded`, a leaf of
/// `soft-shadow`): `[x0, x1] x [y0, y1]` at height `z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Occluder {
    /// Lower corner.
    pub min: [f64; 2],
    /// Upper corner.
    pub max: [f64; 2],
    /// Height.
    pub z: f64,
}

impl Occluder {
    /// True when the ray `p + t w` crosses the square (from below, `p.z < z`).
    pub fn blocks(&self, p: Vec3, w: Vec3) -> bool {
        if w.z <= 0.0 || p.z >= self.z {
            return false;
        }
        let t = (self.z - p.z) / w.z;
        let (x, y) = (p.x + t * w.x, p.y + t * w.y);
        self.min[0] <= x && x <= self.max[0] && self.min[1] <= y && y <= self.max[1]
    }
}

/// The one light of `soft-shadow`: 1.2 x 1.2 centred at (0, 0.4) at height 2.4, radiance 30,
/// facing down.
///
/// - One light, as over the Plant's table, so that a partly shadowed point sees a single visible
///   patch of it: the cone component of PMC-HI (paper 003 Eq. 7, axis the weighted mean of the
///   previous population's directions, §5.2) then points at that patch, not between two lights.
/// - Centred over the middle of the visible board and high enough that every board point sees
///   it at a moderate angle; its side against the leaves' heights sets the penumbra: a leaf at
///   height `h` casts a penumbra of width `1.2 h / (2.4 - h)` on the floor, 0.86 at `h = 1`,
///   wider than the leaves themselves, so most shadows have no umbra at all.
/// - Radiance 30 puts the brightest unshadowed floor near 1 (the range of the other variants' diffuse
///   squares, where `tvi` is in its mid branch).
pub const SOFT_SHADOW_LIGHT: (f64, f64, f64, f64, f64, f64) = (0.0, 0.4, 2.4, 1.2, 1.2, 30.0);

/// The leaves of `soft-shadow`: opaque squares `(centre x, centre y, side, height)`.
///
/// Five leaves of sides 0.6-0.7 at heights 0.8-1.3, spread over the board like the foliage of
/// the Plant (paper 003 Fig. 8) above its table: their penumbrae (see [`SOFT_SHADOW_LIGHT`])
/// overlap, so about four in five of the pixels that see the board see the light partly hidden
/// (a test checks more than three in five), with visible fractions spread from near 0 to near 1.
/// Like the square of `occluded` they are shadow casters only (primary rays see the floor).
pub const SOFT_SHADOW_LEAVES: [(f64, f64, f64, f64); 5] =
    [(-0.9, -0.6, 0.6, 1.0), (0.6, -0.8, 0.6, 0.8), (0.0, 0.3, 0.7, 1.3), (-0.8, 1.0, 0.6, 1.1), (0.9, 0.9, 0.6, 0.9)];

/// The lattice of `lattice`: `(height, pitch, opening, x of an opening's centre, y of an
/// opening's centre)`; the light is [`SOFT_SHADOW_LIGHT`] and every square is diffuse.
///
/// - Bars parallel to the light (so the exact reference applies) at height 1.2, half the light's
///   2.4: from a floor point the lattice's shadow on the light's plane is the lattice scaled by
///   `s = 2.4 / 1.2 = 2`, its openings `0.3 s = 0.6` wide at pitch `0.9 s = 1.8`.
/// - That pitch is the light's side plus an opening (1.2 + 0.6): along each axis exactly one
///   opening's image overlaps the light whatever the point, so each point sees one rectangle of
///   it (a whole 0.6 x 0.6 window or a part clipped by the light's edge), which moves across the
///   light as the point moves (one period per 1.8 / (s - 1) = 1.8 of floor). A single window is
///   what the cone component of PMC-HI (paper 003 Eq. 7: one axis and one half-angle, §5.2) can
///   learn; thin bars at a fine pitch would leave several strips spread over the light in view,
///   and a cone covering them all is no narrower than the light.
/// - On average a point sees `(0.6 / 1.8)^2 = 1/9` of the light's area, so about nine in ten
///   uniform light samples are blocked (a test measures the share over the pixels).
/// - The bars span `[-2.5, 2.5]` at both axes, past every ray from the board to the light.
pub const LATTICE: (f64, f64, f64, f64, f64) = (1.2, 0.9, 0.3, 0.0, 0.4);

/// The bars of [`LATTICE`]: strips along `y` between the openings' columns, strips along `x`
/// between their rows (they overlap at the crossings).
fn lattice_bars() -> Vec<Occluder> {
    let (z, pitch, opening, ox, oy) = LATTICE;
    let (lo, hi) = (-2.5, 2.5);
    let mut bars = Vec::new();
    for k in -4..4 {
        let (x0, x1) = (ox + k as f64 * pitch + 0.5 * opening, ox + (k + 1) as f64 * pitch - 0.5 * opening);
        bars.push(Occluder { min: [x0.max(lo), lo], max: [x1.min(hi), hi], z });
        let (y0, y1) = (oy + k as f64 * pitch + 0.5 * opening, oy + (k + 1) as f64 * pitch - 0.5 * opening);
        bars.push(Occluder { min: [lo, y0.max(lo)], max: [hi, y1.min(hi)], z });
    }
    bars.retain(|b| b.min[0] < b.max[0] && b.min[1] < b.max[1]);
    bars
}

/// The static geometry of the checker scene (shared with `checker-image`).
#[derive(Clone, Debug, PartialEq)]
pub struct CheckerGeometry {
    /// The lights (`default` and `occluded`: the large dim one first, then the small bright one).
    pub lights: Vec<RectLight>,
    /// The shadow casters: none (`default`), the square of `occluded`, the leaves of
    /// `soft-shadow`, the bars of `lattice`.
    pub occluders: Vec<Occluder>,
    /// Whether the board alternates diffuse and glossy squares (`soft-shadow` and `lattice`:
    /// every square diffuse).
    pub glossy: bool,
    /// The camera.
    pub camera: Pinhole,
}

impl CheckerGeometry {
    /// The geometry of a variant (`default`, `occluded`, `soft-shadow` or `lattice`).
    pub fn new(variant: &str) -> Result<Self, ConfigError> {
        let two_lights = || {
            vec![
                RectLight::centred(-1.0, 1.8, 2.0, 2.0, 1.0, Rgb::splat(3.0)),
                RectLight::centred(1.0, 0.9, 1.2, 0.15, 0.15, Rgb::splat(400.0)),
            ]
        };
        let soft_light = || {
            let (cx, cy, z, wx, wy, radiance) = SOFT_SHADOW_LIGHT;
            vec![RectLight::centred(cx, cy, z, wx, wy, Rgb::splat(radiance))]
        };
        let (lights, occluders, glossy) = match variant {
            "default" => (two_lights(), Vec::new(), true),
            "occluded" => (two_lights(), vec![Occluder { min: [0.0, -0.3], max: [1.0, 0.7], z: 0.6 }], true),
            "soft-shadow" => {
                let leaves = SOFT_SHADOW_LEAVES
                    .iter()
                    .map(|&(x, y, side, z)| Occluder {
                        min: [x - 0.5 * side, y - 0.5 * side],
                        max: [x + 0.5 * side, y + 0.5 * side],
                        z,
                    })
                    .collect();
                (soft_light(), leaves, false)
            }
            "lattice" => (soft_light(), lattice_bars(), false),
            _ => {
                return Err(ConfigError::unknown(
                    "variant",
                    &format!("checker/{variant}"),
                    ENTRY.variants.iter().copied(),
                ))
            }
        };
        let camera = Pinhole::look_at(Vec3::new(0.0, -3.2, 4.6), Vec3::new(0.0, 0.1, 0.0), Vec3::Z, 44.0);
        Ok(CheckerGeometry { lights, occluders, glossy, camera })
    }

    /// The material at a floor point of this geometry: the checker of [`CheckerGeometry::material`],
    /// or its diffuse squares everywhere when the board is not glossy (black off the board).
    pub fn material_at(&self, x: f64, y: f64) -> Phong {
        let m = Self::material(x, y);
        if self.glossy || (m.ks[0] == 0.0 && m.kd[0] == 0.0) {
            return m;
        }
        Phong { kd: Rgb::splat(0.7), ks: Rgb::ZERO, n: 1.0 }
    }

    /// The material of the checker at a floor point (black off the board).
    pub fn material(x: f64, y: f64) -> Phong {
        if !(-2.0..=2.0).contains(&x) || !(-2.0..=2.0).contains(&y) {
            return Phong { kd: Rgb::ZERO, ks: Rgb::ZERO, n: 1.0 };
        }
        let ix = (((x + 2.0) / 0.5) as usize).min(7);
        let iy = (((y + 2.0) / 0.5) as usize).min(7);
        if (ix + iy) & 1 == 0 {
            Phong { kd: Rgb::splat(0.7), ks: Rgb::ZERO, n: 1.0 }
        } else {
            Phong { kd: Rgb::splat(0.05), ks: Rgb::splat(0.8), n: 10.0 * 500f64.powf(iy as f64 / 7.0) }
        }
    }

    /// The floor point seen through image position `(sx, sy)` in `[0, size)^2` (pixel `(px, py)`
    /// covers `[px, px + 1) x [py, py + 1)`), or `None` when the ray misses the floor.
    pub fn shade(&self, sx: f64, sy: f64, size: usize) -> Option<ShadingPoint> {
        let d = self.camera.image_direction(sx, sy, size);
        if d.z >= 0.0 {
            return None;
        }
        let t = -self.camera.eye.z / d.z;
        let p = self.camera.eye + d * t;
        Some(ShadingPoint { position: p, normal: Vec3::Z, wo: -d, brdf: self.material_at(p.x, p.y) })
    }

    /// Radiance arriving at floor point `p` from `w`: the nearest light hit unless an occluder
    /// is crossed first (they lie below the lights).
    pub fn incident(&self, p: Vec3, w: Vec3) -> Rgb {
        if self.occluders.iter().any(|o| o.blocks(p, w)) {
            return Rgb::ZERO;
        }
        let mut best: Option<(f64, Rgb)> = None;
        for l in &self.lights {
            if let Some(t) = l.hit(p, w) {
                if !matches!(best, Some((bt, _)) if bt <= t) {
                    best = Some((t, l.radiance));
                }
            }
        }
        best.map_or(Rgb::ZERO, |(_, r)| r)
    }
}

/// The `checker-direct` scene.
pub struct CheckerDirect {
    variant: String,
    size: usize,
    geometry: CheckerGeometry,
    points: Vec<ShadingPoint>,
    reference: Reference,
}

impl CheckerDirect {
    /// Builds a variant; parameter `resolution` (default 48) sets the square image size.
    pub fn new(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        let size = parse::<CheckerDirectParams>("checker-direct", params)?.resolution;
        let geometry = CheckerGeometry::new(variant)?;
        let mut points = Vec::with_capacity(size * size);
        for py in 0..size {
            for px in 0..size {
                let p = geometry.shade(px as f64 + 0.5, py as f64 + 0.5, size);
                // Every pixel centre sees the floor with this camera (a test checks it).
                points.push(p.ok_or_else(|| ConfigError::invalid("resolution", size, "a pixel misses the floor"))?);
            }
        }
        let reference = reference(&geometry, &points);
        Ok(CheckerDirect { variant: variant.to_string(), size, geometry, points, reference })
    }
    /// The geometry.
    pub fn geometry(&self) -> &CheckerGeometry {
        &self.geometry
    }
}

impl TestBed for CheckerDirect {
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
    fn geometry(&self, i: usize) -> Vec<(&'static str, f64)> {
        let p = &self.points[i];
        vec![("hit_x", p.position.x), ("hit_y", p.position.y), ("phong_n", p.brdf.n), ("ks", p.brdf.ks[0])]
    }
    fn hemisphere(&self) -> Option<&dyn HemisphereScene> {
        Some(self)
    }
}

impl HemisphereScene for CheckerDirect {
    fn shading(&self, i: usize) -> ShadingPoint {
        self.points[i]
    }
    fn incident(&self, i: usize, wi: Vec3) -> Rgb {
        self.geometry.incident(self.points[i].position, wi)
    }
    fn lights(&self) -> &[RectLight] {
        &self.geometry.lights
    }
}
