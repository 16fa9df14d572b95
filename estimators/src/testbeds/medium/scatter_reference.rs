//! Exact reference of the `single-scatter` variant (paper 002 §4.3 Eq. 22, book: testbeds.md): the
//! radiance a pixel ray receives from the point light by one scattering event,
//!
//! `L = int_{t0}^{t1} T(t) a sigma_t(p(t)) rho(cos) I T_l(p(t)) / (D^2 + (t - t_l)^2) dt`,
//!
//! by nested adaptive Gauss-Kronrod quadrature:
//! - outer, along the camera ray in the equiangular angle `theta = atan((t - t_l) / D)`, which
//!   turns the peak `1 / (D^2 + (t - t_l)^2)` into the constant `1 / D`
//!   (`dt = (D^2 + (t - t_l)^2) / D dtheta`), with initial panels at the images of a uniform grid
//!   in `t` (`per_unit` per unit length) so the extinction's variation along the ray is resolved;
//! - inner, the optical depths: along the camera ray from a cumulative table at the same grid
//!   (each step and the remainder up to `t` by adaptive quadrature), and towards the light from
//!   `p(t)` over the part of the shadow ray inside the sphere.
//!
//! Error bound per pixel: the outer error estimate plus the first-order propagation of the inner
//! errors, `int |G| (e_cam + e_light) dtheta` (a second component of the same outer quadrature,
//! plus its own error estimate), since `|d exp(-tau)| = exp(-tau) |d tau|`.
//!
//! Cost: Eq. 21 (smooth, 25 ns per fetch) takes about a millisecond per pixel, so its reference is
//! computed when the test bed is built; the Perlin stack (0.5 us per fetch, features 1/512 wide)
//! needs about 1e7 fetches per pixel, so its default reference ([`PERLIN_RESOLUTION`]) is stored in
//! `estimators/references/perlin-medium_single-scatter.json` (made by
//! `mcbench reference perlin-medium --variant single-scatter`) and other settings compute theirs.

use super::reference::optical_depth_with;
use super::{clip_sphere, Field, MediumBed};
use mcbench_core::error::ConfigError;
use mcbench_core::lighting::PointLight;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::quadrature::gauss_kronrod_multi;
use mcbench_core::references::ReferenceSource;
use mcbench_core::testbed::{MediumQuantity, MediumRay, MediumScene, Reference, ReferenceKind, TestBed};

/// Default image side of `eq21-medium/single-scatter` (camera b, full resolution).
pub const EQ21_RESOLUTION: usize = 32;
/// Default image side of `perlin-medium/single-scatter` (reduced from 32: see the module doc).
pub const PERLIN_RESOLUTION: usize = 4;

/// Quadrature settings of one medium.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Initial panels per unit length (outer grid in `t` and inner optical depths).
    pub per_unit: f64,
    /// Absolute tolerance of each optical depth.
    pub tau_tol: f64,
    /// Relative tolerance of the outer integral.
    pub rel_tol: f64,
}

impl Settings {
    /// The settings of a field: Eq. 21 is smooth (one panel per unit, tau to 1e-12, outer to
    /// 1e-10: about 1 ms per pixel); Perlin needs initial panels 32 finest-octave cells wide
    /// (coarser ones miss clamped bumps, see the tests) and looser tolerances (tau and outer to
    /// 1e-4: still about 100 s per pixel).
    pub fn of(field: Field) -> Settings {
        match field {
            Field::Eq21 => Settings { per_unit: 1.0, tau_tol: 1e-12, rel_tol: 1e-10 },
            Field::Perlin => Settings { per_unit: 16.0, tau_tol: 1e-4, rel_tol: 1e-4 },
        }
    }
    /// The method text of a reference made with these settings.
    pub fn method(&self) -> String {
        format!(
            "nested adaptive Gauss-Kronrod: outer in the equiangular angle (relative tolerance {:e}), optical depths to the camera and the light ({} initial panels per unit, absolute tolerance {:e}); bound = outer estimate + propagated inner errors",
            self.rel_tol, self.per_unit, self.tau_tol
        )
    }
}

/// One pixel's single-scattered radiance and its error bound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelQuadrature {
    /// The radiance.
    pub value: f64,
    /// Absolute error bound.
    pub bound: f64,
}

/// The optical depth along the camera ray from `t0`: a cumulative table at a uniform grid, and
/// the remainder up to `t` by adaptive quadrature.
struct CameraDepth {
    t0: f64,
    h: f64,
    tau: Vec<f64>,
    err: Vec<f64>,
}

impl CameraDepth {
    fn new(bed: &MediumBed, ray: &MediumRay, (t0, t1): (f64, f64), s: &Settings) -> Self {
        let n = ((t1 - t0) * s.per_unit).ceil().max(1.0) as usize;
        let h = (t1 - t0) / n as f64;
        let (mut tau, mut err) = (vec![0.0], vec![0.0]);
        for k in 0..n {
            let a = t0 + h * k as f64;
            // One initial panel per grid step (per_unit 0), refined adaptively; the steps share
            // the tolerance so the cumulative depth stays within it.
            let q = optical_depth_with(bed, ray.origin, ray.dir, (a, a + h), 0.0, s.tau_tol / n as f64);
            tau.push(tau[k] + q.value);
            err.push(err[k] + q.error);
        }
        CameraDepth { t0, h, tau, err }
    }
    fn at(&self, bed: &MediumBed, ray: &MediumRay, t: f64, s: &Settings) -> (f64, f64) {
        let k = (((t - self.t0) / self.h).floor().max(0.0) as usize).min(self.tau.len() - 1);
        let a = self.t0 + self.h * k as f64;
        let q = optical_depth_with(bed, ray.origin, ray.dir, (a, t), 0.0, s.tau_tol);
        (self.tau[k] + q.value, self.err[k] + q.error)
    }
}

/// The optical depth from `p` towards the light over the part inside the sphere, with its error.
pub fn light_depth(bed: &MediumBed, p: Vec3, light: &PointLight, s: &Settings) -> (f64, f64) {
    let to = light.position - p;
    let r = to.length();
    let w = to / r;
    match clip_sphere(p, w) {
        Some((a, b)) if b.min(r) > a => {
            let q = optical_depth_with(bed, p, w, (a, b.min(r)), s.per_unit, s.tau_tol);
            (q.value, q.error)
        }
        _ => (0.0, 0.0),
    }
}

/// The single-scattered radiance of `ray` from `light` (the module's nested quadrature).
pub fn single_scatter(bed: &MediumBed, ray: &MediumRay, light: &PointLight, s: &Settings) -> PixelQuadrature {
    let Some((t0, t1)) = clip_sphere(ray.origin, ray.dir).map(|(a, b)| (a, b.min(ray.length))).filter(|(a, b)| b > a)
    else {
        return PixelQuadrature { value: 0.0, bound: 0.0 };
    };
    let (t_l, d) = light.closest_approach(ray.origin, ray.dir);
    let camera = CameraDepth::new(bed, ray, (t0, t1), s);
    let (a, phase) = (MediumScene::albedo(bed), MediumScene::phase(bed));
    let theta = |t: f64| ((t - t_l) / d).atan();
    let n = ((t1 - t0) * s.per_unit).ceil().max(1.0) as usize;
    let mut breaks: Vec<f64> = (0..=n).map(|k| theta(t0 + (t1 - t0) * k as f64 / n as f64)).collect();
    breaks.dedup();
    let integrand = |th: f64| {
        let t = (t_l + d * th.tan()).clamp(t0, t1);
        let p = ray.origin + ray.dir * t;
        let sigma = bed.extinction(p);
        if sigma == 0.0 {
            return [0.0, 0.0];
        }
        let (tau_c, e_c) = camera.at(bed, ray, t, s);
        let (tau_l, e_l) = light_depth(bed, p, light, s);
        let from_light = (p - light.position).normalize();
        let g = (-tau_c - tau_l).exp() * a * sigma * phase.eval(from_light.dot(-ray.dir)) * light.intensity / d;
        [g, g.abs() * (e_c + e_l)]
    };
    let q = gauss_kronrod_multi(integrand, &breaks, 0.0, s.rel_tol, 40);
    PixelQuadrature { value: q.value[0], bound: q.error[0] + q.value[1] + q.error[1] }
}

/// The reference of a `single-scatter` bed: the stored Perlin default when it matches these
/// settings, otherwise computed in parallel over pixels.
pub fn reference(bed: &MediumBed, refs: &dyn ReferenceSource) -> Result<Reference, ConfigError> {
    if let Some(r) = load_stored(bed, refs)? {
        return Ok(r);
    }
    // The nested quadrature takes seconds per bed; a process that builds the same bed again (the
    // pilot and the main plan of an experiment, a sweep re-planned per estimator) reuses it.
    static COMPUTED: mcbench_core::memo::Memo<Reference> = mcbench_core::memo::Memo::new();
    let settings = Settings::of(bed.field());
    let key = format!("{:?}|{}", bed.reference_key(), settings.method());
    Ok(COMPUTED.get_or_compute(key, || compute(bed, &settings)))
}

/// Computes the reference of every pixel with `s` (threads over pixels).
pub fn compute(bed: &MediumBed, s: &Settings) -> Reference {
    let n = bed.integrals();
    let out = mcbench_core::parallel::map_indices(n, 0, |i| {
        let ray = MediumScene::ray(bed, i);
        match ray.quantity {
            MediumQuantity::SingleScatter { light } => single_scatter(bed, &ray, &light, s),
            _ => PixelQuadrature { value: f64::NAN, bound: f64::NAN },
        }
    });
    Reference {
        kind: ReferenceKind::Exact { method: s.method(), bound: out.iter().fold(0.0f64, |m, x| m.max(x.bound)) },
        value: out.iter().map(|x| Rgb::splat(x.value)).collect(),
        std_err: vec![Rgb::ZERO; n],
    }
}

/// The stored quadrature of `bed` from `refs` when there is one made with the current settings
/// (it saves the nested quadrature at every build); `None` otherwise (then it is computed). A
/// stored reference of the right key but another method is ignored; a malformed one is an error.
fn load_stored(bed: &MediumBed, refs: &dyn ReferenceSource) -> Result<Option<Reference>, ConfigError> {
    let key = bed.reference_key();
    let Some(stored) = refs.stored(&key)? else { return Ok(None) };
    let same_method = matches!(&stored.reference.kind,
        ReferenceKind::Exact { method, .. } if *method == Settings::of(bed.field()).method());
    if !same_method {
        return Ok(None);
    }
    stored.check(bed.integrals(), bed.resolution()).map_err(|e| {
        ConfigError::invalid(format!("{} reference", key.describe()), key.file_name(), format!("malformed ({e})"))
    })?;
    Ok(Some(stored.reference))
}

#[cfg(test)]
#[path = "scatter_reference_tests.rs"]
mod tests;
