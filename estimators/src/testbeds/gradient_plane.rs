//! `gradient-plane` (paper 001 §5, book: testbeds.md): a modified-Phong plane under a gradient sky, seen
//! by a pinhole camera; one hemispherical integral per pixel with an exact reference.
//!
//! Reference per pixel and channel: the diffuse part in closed form, `kd (c0 + 2 c1 / 3)`; the
//! glossy part `ks (c0 I0 + c1 Iz + c2 Ix)` with the horizon-clipped lobe moments of
//! [`super::phong_lobe::clipped_lobe_moments`] (deterministic adaptive quadrature, relative error
//! <= 1e-9 shown by its tests).

use super::phong_lobe::clipped_lobe_moments;
use super::pinhole::Pinhole;
use mcbench_core::brdf::Phong;
use mcbench_core::entry::{BedCase, CaseRole, TestBedEntry};
use mcbench_core::error::ConfigError;
use mcbench_core::lighting::Gradient;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::{check_count, parse, ParamSet, ParamSpec, Params};
use mcbench_core::testbed::{HemisphereScene, Needs, Reference, ReferenceKind, ShadingPoint, TestBed};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The surface part of the `unbiasedness` experiment: 64 samples per estimate, 512 repetitions
/// (quick) or 8192 (full).
pub const SURFACE_PART: CaseRole = CaseRole::Unbiasedness { samples: 64, reps: (512, 8192) };

/// Registry entry.
///
/// ```
/// use mcbench_papers::builtins::testbed;
/// use mcbench_core::params::Params;
/// let bed = testbed("gradient-plane").unwrap().build_exact("diffuse", &Params::new().with("resolution", 4.0)).unwrap();
/// assert_eq!(bed.integrals(), 16);
/// assert!(bed.reference().is_exact());
/// // A diffuse pixel integrates to kd (c0 + 2 c1 / 3) in closed form (red: 0.8 * (1 + 2/3)).
/// assert!((bed.reference().value[0][0] - 0.8 * (1.0 + 2.0 / 3.0)).abs() < 1e-12);
/// ```
pub static ENTRY: TestBedEntry = TestBedEntry {
    id: "gradient-plane",
    variants: &["default", "diffuse", "glossy", "stiff"],
    provides: Needs::SURFACE,
    summary: "Phong plane under a gradient sky, pinhole 32x32, exact reference (paper 001 §5)",
    build: |variant, params, _| Ok(Box::new(GradientPlane::new(variant, params)?)),
    compute_reference: None,
    params: ParamSpec::of::<GradientPlaneParams>().display("gradient plane (paper 001)").words(crate::words::variant),
    cases: &[
        BedCase { variant: "stiff", params: &[("resolution", 2.0)], role: CaseRole::Stability },
        BedCase { variant: "default", params: &[("resolution", 2.0)], role: CaseRole::Check },
        BedCase { variant: "default", params: &[("resolution", 4.0)], role: SURFACE_PART },
        BedCase { variant: "diffuse", params: &[("resolution", 4.0)], role: SURFACE_PART },
        BedCase { variant: "glossy", params: &[("resolution", 4.0)], role: SURFACE_PART },
        BedCase { variant: "stiff", params: &[("resolution", 4.0)], role: SURFACE_PART },
    ],
};

/// Parameters of `gradient-plane`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct GradientPlaneParams {
    /// Side of the square image in pixels (1 to 512); every primary ray hits the plane.
    pub resolution: usize,
}

impl Default for GradientPlaneParams {
    fn default() -> Self {
        GradientPlaneParams { resolution: 32 }
    }
}

impl ParamSet for GradientPlaneParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_count("resolution", self.resolution, 512).map(|_| ())
    }
}

/// Relative tolerance of the glossy quadrature (the test bed promises 1e-9).
const LOBE_REL_TOL: f64 = 1e-11;

/// The scene.
pub struct GradientPlane {
    variant: String,
    size: usize,
    background: Gradient,
    points: Vec<ShadingPoint>,
    reference: Reference,
}

/// The BRDF of a variant (book: testbeds.md).
pub fn variant_brdf(variant: &str) -> Result<Phong, ConfigError> {
    let phong = |kd: f64, ks: f64, n: f64| Phong { kd: Rgb::splat(kd), ks: Rgb::splat(ks), n };
    match variant {
        "default" => Ok(phong(0.5, 0.3, 20.0)),
        "diffuse" => Ok(phong(0.8, 0.0, 20.0)),
        "glossy" => Ok(phong(0.5, 0.3, 200.0)),
        "stiff" => Ok(phong(0.05, 0.9, 10_000.0)),
        _ => Err(ConfigError::unknown("variant", &format!("gradient-plane/{variant}"), ENTRY.variants.iter().copied())),
    }
}

impl GradientPlane {
    /// Builds a variant; parameter `resolution` (default 32) sets the square image size.
    pub fn new(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        let size = parse::<GradientPlaneParams>("gradient-plane", params)?.resolution;
        let brdf = variant_brdf(variant)?;
        let background = Gradient::papers();
        let camera = Pinhole::look_at(Vec3::new(0.0, -3.0, 2.0), Vec3::default(), Vec3::Z, 40.0);
        let mut points = Vec::with_capacity(size * size);
        for py in 0..size {
            for px in 0..size {
                let d = camera.pixel_direction(px, py, size);
                let t = -camera.eye.z / d.z;
                points.push(ShadingPoint { position: camera.eye + d * t, normal: Vec3::Z, wo: -d, brdf });
            }
        }
        let reference = Self::reference_for(&points, &background);
        Ok(GradientPlane { variant: variant.to_string(), size, background, points, reference })
    }

    fn reference_for(points: &[ShadingPoint], bg: &Gradient) -> Reference {
        let mut bound = 0.0f64;
        let value = points
            .iter()
            .map(|p| {
                let b = &p.brdf;
                let diffuse = b.kd * (bg.c0 + bg.c1 * (2.0 / 3.0));
                let m = clipped_lobe_moments(p.wo.reflect(p.normal), b.n, LOBE_REL_TOL);
                let glossy = b.ks * (bg.c0 * m.i0 + bg.c1 * m.iz + bg.c2 * m.ix);
                for c in 0..3 {
                    bound = bound.max(b.ks[c] * (bg.c0[c].abs() + bg.c1[c].abs() + bg.c2[c].abs()) * m.error);
                }
                diffuse + glossy
            })
            .collect::<Vec<_>>();
        let std_err = vec![Rgb::ZERO; value.len()];
        let method = "diffuse closed form + adaptive Gauss-Kronrod of the clipped Phong lobe moments".to_string();
        Reference { kind: ReferenceKind::Exact { method, bound }, value, std_err }
    }
}

impl TestBed for GradientPlane {
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
        vec![("hit_x", p.position.x), ("hit_y", p.position.y), ("wo_x", p.wo.x), ("wo_y", p.wo.y), ("wo_z", p.wo.z)]
    }
    fn hemisphere(&self) -> Option<&dyn HemisphereScene> {
        Some(self)
    }
}

impl HemisphereScene for GradientPlane {
    fn shading(&self, i: usize) -> ShadingPoint {
        self.points[i]
    }
    fn incident(&self, _i: usize, wi: Vec3) -> Rgb {
        self.background.eval(wi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::quadrature::gauss_legendre;

    /// Every primary ray hits the plane in front of the camera.
    #[test]
    fn every_pixel_sees_the_plane() {
        let bed = GradientPlane::new("default", &Params::new()).unwrap();
        assert_eq!(bed.integrals(), 1024);
        assert!(bed.points.iter().all(|p| p.position.z.abs() < 1e-12 && p.wo.z > 0.0));
    }

    /// Independent check of the full pixel value (diffuse + glossy, all channels) by brute-force
    /// product Gauss-Legendre over the hemisphere in (cos theta, phi) with many panels.
    #[test]
    fn reference_matches_brute_force_quadrature() {
        let bed = GradientPlane::new("default", &Params::new().with("resolution", 4.0)).unwrap();
        let (x, w) = gauss_legendre(20);
        for i in [0, 5, 15] {
            let p = bed.shading(i);
            let mut sum = Rgb::ZERO;
            let (nc, np) = (64, 128);
            for a in 0..nc {
                for b in 0..np {
                    for (xi, wi) in x.iter().zip(&w) {
                        let c = (a as f64 + 0.5 + 0.5 * xi) / nc as f64;
                        for (xj, wj) in x.iter().zip(&w) {
                            let phi = (b as f64 + 0.5 + 0.5 * xj) / np as f64 * std::f64::consts::TAU;
                            let d = mcbench_core::samplers::spherical_direction(c, phi);
                            let f = bed.incident(i, d) * p.brdf.eval(d, p.wo, p.normal) * c;
                            sum += f * (wi * wj * 0.25 / nc as f64 * std::f64::consts::TAU / np as f64);
                        }
                    }
                }
            }
            let r = bed.reference().value[i];
            for c in 0..3 {
                assert!((sum[c] - r[c]).abs() <= 1e-9 * r[c].abs(), "pixel {i} ch {c}: {} vs {}", sum[c], r[c]);
            }
        }
    }

    #[test]
    fn bad_variant_and_resolution_are_refused_naming_the_field() {
        assert!(GradientPlane::new("shiny", &Params::new())
            .err()
            .unwrap()
            .to_string()
            .contains("gradient-plane/shiny"));
        assert!(GradientPlane::new("default", &Params::new().with("resolution", 0.0))
            .err()
            .unwrap()
            .to_string()
            .contains("resolution"));
    }
}
