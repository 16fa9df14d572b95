//! The sphere both media test beds fill, its point light, and which extinction field fills it.

use mcbench_core::lighting::PointLight;
use mcbench_core::math::Vec3;

/// Sphere centre.
pub const CENTRE: Vec3 = Vec3::new(0.0, 0.0, 10.0);
/// Sphere radius.
pub const RADIUS: f64 = 10.0;
/// The variants of both media.
pub const VARIANTS: &[&str] = &["central-ray", "transmittance", "multiple", "single-scatter"];
/// The point light of the media test beds: intensity 100 (power 400 pi) at the sphere's centre.
pub const LIGHT: PointLight = PointLight { position: CENTRE, intensity: 100.0 };
/// Closest a pixel ray may pass the light: the single-scattered radiance grows like `1 / D`.
pub const MIN_LIGHT_DISTANCE: f64 = 1e-9;

/// Which extinction field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    /// Paper 002 Eq. 21, albedo 0.7.
    Eq21,
    /// 12-octave Perlin fbm, albedo 0.9.
    Perlin,
}

impl Field {
    /// Test bed id.
    pub fn id(self) -> &'static str {
        match self {
            Field::Eq21 => "eq21-medium",
            Field::Perlin => "perlin-medium",
        }
    }
    /// Albedo (paper 002 §4).
    pub fn albedo(self) -> f64 {
        match self {
            Field::Eq21 => 0.7,
            Field::Perlin => 0.9,
        }
    }
}

/// Ray-sphere clip of the medium's sphere for unit `dir`, clamped to `t >= 0`.
pub fn clip_sphere(origin: Vec3, dir: Vec3) -> Option<(f64, f64)> {
    let oc = origin - CENTRE;
    let b = oc.dot(dir);
    let c = oc.dot(oc) - RADIUS * RADIUS;
    let disc = b * b - c;
    if disc <= 0.0 {
        return None;
    }
    let q = disc.sqrt();
    let (t0, t1) = ((-b - q).max(0.0), -b + q);
    (t1 > t0).then_some((t0, t1))
}
