//! The test-bed plug-in trait (book: extending.md): a deterministic scene defining integrals to estimate and
//! their references, and what it provides to estimators.

use crate::brdf::Phong;
use crate::math::{Rgb, Vec3};
use serde::{Deserialize, Serialize};

pub use crate::needs::Needs;

/// How a reference was obtained.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum ReferenceKind {
    /// Closed form or deterministic quadrature with a stated absolute error bound.
    Exact {
        /// How it was computed.
        method: String,
        /// The largest absolute error bound over integrals and channels.
        bound: f64,
    },
    /// A stored long-run Monte Carlo value with per-integral standard errors.
    Stored {
        /// The command that made it.
        command: String,
        /// Independent samples behind each stored value (for Welch's degrees of freedom).
        samples: u64,
    },
}

/// The reference values of a test bed's integrals (one RGB per integral).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Reference {
    /// How it was obtained.
    pub kind: ReferenceKind,
    /// Value per integral.
    pub value: Vec<Rgb>,
    /// Standard error per integral (zero for exact references).
    pub std_err: Vec<Rgb>,
}

impl Reference {
    /// A placeholder with no values (filled in by the test bed's constructor).
    pub fn empty() -> Self {
        Reference {
            kind: ReferenceKind::Exact { method: String::new(), bound: 0.0 },
            value: Vec::new(),
            std_err: Vec::new(),
        }
    }
    /// True for closed-form or quadrature references.
    pub fn is_exact(&self) -> bool {
        matches!(self.kind, ReferenceKind::Exact { .. })
    }

    /// The largest magnitude of a value or standard error a reference read back may hold
    /// ([`Reference::check`]): squares and their sums over any test bed stay finite, so every
    /// metric computed against it (the MSE subtracts the squared standard errors) does.
    pub const LARGEST: f64 = 1e150;

    /// Checks a reference read back from a file against the test bed it is for: `integrals`
    /// values and as many standard errors, every number finite and at most [`Reference::LARGEST`]
    /// in magnitude, standard errors non-negative (and zero for an exact reference, whose bound
    /// must be finite and non-negative), a stored reference made of at least two samples. `Err`
    /// says what is wrong, naming the field (`value`, `std_err`, with the index).
    pub fn check(&self, integrals: usize) -> Result<(), String> {
        if self.value.len() != integrals || self.std_err.len() != integrals {
            return Err(format!(
                "{} values and {} standard errors for a test bed of {integrals} integrals",
                self.value.len(),
                self.std_err.len()
            ));
        }
        let bounded = |x: f64| x.is_finite() && x.abs() <= Self::LARGEST;
        if let Some(i) = self.value.iter().position(|v| !v.0.iter().all(|&x| bounded(x))) {
            return Err(format!(
                "value[{i}] = {:?} is not finite or beyond {:e} in magnitude",
                self.value[i].0,
                Self::LARGEST
            ));
        }
        if let Some(i) = self.std_err.iter().position(|s| !s.0.iter().all(|&x| bounded(x) && x >= 0.0)) {
            return Err(format!(
                "std_err[{i}] = {:?}: a standard error is finite, not negative and at most {:e}",
                self.std_err[i].0,
                Self::LARGEST
            ));
        }
        match &self.kind {
            ReferenceKind::Exact { bound, .. } => {
                if !(bound.is_finite() && *bound >= 0.0) {
                    return Err(format!("exact bound {bound} is negative or not finite"));
                }
                if self.std_err.iter().any(|s| s.0 != [0.0; 3]) {
                    return Err("an exact reference with non-zero standard errors".into());
                }
            }
            ReferenceKind::Stored { samples, .. } => {
                if *samples < 2 {
                    return Err(format!("stored from {samples} samples (at least 2 are needed for a standard error)"));
                }
            }
        }
        Ok(())
    }
}

/// The local shading setup of one surface integral.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingPoint {
    /// Hit point.
    pub position: Vec3,
    /// Unit shading normal.
    pub normal: Vec3,
    /// Unit direction towards the viewer.
    pub wo: Vec3,
    /// The surface BRDF.
    pub brdf: Phong,
}

/// A scene whose integrals are hemispherical: `integral of L_in(w) f(w, w_o) cos(theta) dw` at
/// one shading point per integral (papers 001, 003, 004).
///
/// ```
/// use mcbench_core::brdf::Phong;
/// use mcbench_core::math::{Rgb, Vec3};
/// use mcbench_core::testbed::{HemisphereScene, ShadingPoint};
///
/// /// A white sky over one diffuse point facing up.
/// struct Sky;
/// impl HemisphereScene for Sky {
///     fn shading(&self, _i: usize) -> ShadingPoint {
///         let brdf = Phong { kd: Rgb([0.5; 3]), ks: Rgb::ZERO, n: 1.0 };
///         ShadingPoint { position: Vec3::default(), normal: Vec3::Z, wo: Vec3::Z, brdf }
///     }
///     fn incident(&self, _i: usize, _wi: Vec3) -> Rgb {
///         Rgb([1.0; 3])
///     }
/// }
///
/// // One direction's integrand L f cos = 1 x 0.5 / pi x cos(theta).
/// let (p, wi) = (Sky.shading(0), Vec3::new(0.0, 0.6, 0.8));
/// let f = Sky.incident(0, wi) * p.brdf.eval(wi, p.wo, p.normal) * wi.dot(p.normal);
/// assert!((f[0] - 0.5 / std::f64::consts::PI * 0.8).abs() < 1e-12);
/// ```
pub trait HemisphereScene: Send + Sync {
    /// The shading point of integral `i`.
    fn shading(&self, i: usize) -> ShadingPoint;
    /// Radiance arriving at the shading point of integral `i` from direction `wi` (one ray).
    fn incident(&self, i: usize, wi: Vec3) -> Rgb;
    /// The area lights estimators may sample (paper 003's light components). Their geometry is
    /// known to the estimator for free; what they contribute is only learnt through the counted
    /// integrand, so a light sample costs one sample and one ray like a BRDF sample. Empty by
    /// default (scenes without emitters, or lit by a background).
    fn lights(&self) -> &[crate::lighting::RectLight] {
        &[]
    }
}

/// A scene whose integrals are pixel integrals over the image plane (paper 003 Eq. 2, book: testbeds.md):
/// `I_p = int_{pixel p} E[S(p, u, v)] du dv` with a box filter, where one *pixel sample*
/// `S(p, u, v)` is a random, unbiased estimate of the radiance seen through position `(u, v)` of
/// the pixel's footprint. Image-plane samplers (PMC-IP, §4) choose how many samples each pixel
/// gets and where; the scene decides what one sample costs.
///
/// ```
/// use mcbench_core::math::Rgb;
/// use mcbench_core::rng::{stream, StreamRng};
/// use mcbench_core::testbed::ImagePlaneScene;
///
/// /// A horizontal ramp: radiance u across every pixel's footprint (its pixel integral is 1/2).
/// struct Ramp;
/// impl ImagePlaneScene for Ramp {
///     fn pixel_sample(&self, _pixel: usize, u: f64, _v: f64, _rng: &mut StreamRng) -> (Rgb, u64) {
///         (Rgb([u; 3]), 1)
///     }
/// }
///
/// let mut rng = stream(1, "ramp");
/// let (value, rays) = Ramp.pixel_sample(0, 0.25, 0.5, &mut rng);
/// assert_eq!((value[0], rays), (0.25, 1));
/// ```
pub trait ImagePlaneScene: Send + Sync {
    /// One pixel sample of pixel `pixel` at footprint position `(u, v)` in `[0, 1)^2`, and the
    /// number of rays it traced.
    fn pixel_sample(&self, pixel: usize, u: f64, v: f64, rng: &mut crate::rng::StreamRng) -> (Rgb, u64);
}

/// What integral `i` of a medium scene asks for (book: testbeds.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MediumQuantity {
    /// `weight * T(length)`: the transmittance from `origin` along `dir` over `[0, length]`, times
    /// a known radiance (the environment behind the medium, or one for the central ray's T(s)).
    Transmittance {
        /// The factor multiplying the transmittance (per channel).
        weight: Rgb,
    },
    /// The radiance arriving at `origin` from `-dir` (multiple scattering under the environment).
    Radiance,
    /// The radiance arriving at `origin` from `-dir` scattered once from a point light (paper 002
    /// Eq. 22 without the background term): `int T(s) sigma_s(s) rho(cos) I T_l(s) / r(s)^2 ds`
    /// over the ray's medium segment, `r(s)` the distance to the light and `T_l` the
    /// transmittance towards it.
    SingleScatter {
        /// The light.
        light: crate::lighting::PointLight,
    },
}

/// The ray of one medium integral: origin, unit direction, length and what is estimated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MediumRay {
    /// Ray origin.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
    /// Length of the segment `[0, length]` (transmittance integrals).
    pub length: f64,
    /// What is estimated.
    pub quantity: MediumQuantity,
}

/// A participating-medium scene (paper 002): extinction, the bound it declares, albedo,
/// environment radiance, and the ray of each integral. Estimators reach it only through the
/// counted [`crate::task::MediumProbe`]: every `sigma_t` counts one fetch.
///
/// ```
/// use mcbench_core::math::{Rgb, Vec3};
/// use mcbench_core::testbed::{MediumQuantity, MediumRay, MediumScene};
///
/// /// A slab 0 <= x <= 2 of constant extinction 0.5, seen along +x: T = exp(-1).
/// struct Slab;
/// impl MediumScene for Slab {
///     fn sigma_t(&self, p: Vec3) -> f64 {
///         if (0.0..=2.0).contains(&p.x) { 0.5 } else { 0.0 }
///     }
///     fn majorant(&self) -> f64 {
///         0.5
///     }
///     fn albedo(&self) -> f64 {
///         0.0
///     }
///     fn clip(&self, origin: Vec3, dir: Vec3) -> Option<(f64, f64)> {
///         let (t0, t1) = ((0.0 - origin.x) / dir.x, (2.0 - origin.x) / dir.x);
///         let (a, b) = (t0.min(t1).max(0.0), t0.max(t1));
///         (b > a).then_some((a, b))
///     }
///     fn environment(&self, _w: Vec3) -> Rgb {
///         Rgb([1.0; 3])
///     }
///     fn ray(&self, _i: usize) -> MediumRay {
///         let weight = Rgb([1.0; 3]);
///         MediumRay { origin: Vec3::new(-1.0, 0.0, 0.0), dir: Vec3::new(1.0, 0.0, 0.0), length: 4.0, quantity: MediumQuantity::Transmittance { weight } }
///     }
/// }
///
/// let r = Slab.ray(0);
/// assert_eq!(Slab.clip(r.origin, r.dir), Some((1.0, 3.0)));
/// ```
pub trait MediumScene: Send + Sync {
    /// Real extinction at `p` (the whole parameter stack: one fetch).
    fn sigma_t(&self, p: Vec3) -> f64;
    /// A cheap approximate extinction for control variates (counted as a cheap fetch), or `None`
    /// when the scene has none (then explorers must pay full fetches).
    fn sigma_approx(&self, _p: Vec3) -> Option<f64> {
        None
    }
    /// The majorant the scene declares: `sigma_t <= majorant` everywhere.
    fn majorant(&self) -> f64;
    /// Single-scattering albedo (constant in these scenes).
    fn albedo(&self) -> f64;
    /// The ray parameters `[t0, t1]` where `origin + t dir` (unit `dir`, `t >= 0`) is inside the
    /// medium's bounding volume, or `None` when the ray misses it.
    fn clip(&self, origin: Vec3, dir: Vec3) -> Option<(f64, f64)>;
    /// Environment radiance arriving from direction `w` (a unit vector leaving the scene).
    fn environment(&self, w: Vec3) -> Rgb;
    /// The ray of integral `i`.
    fn ray(&self, i: usize) -> MediumRay;
    /// The phase function (paper 000 Eq. 5); isotropic unless the scene says otherwise.
    fn phase(&self) -> crate::phase::Phase {
        crate::phase::Phase::Isotropic
    }
}

/// A test bed (book: extending.md). Integrals are pixels in row-major order, `i = py * width + px`.
///
/// A minimal one: four integrals of known value and no view for any estimator yet (a real test
/// bed also returns a [`HemisphereScene`], [`MediumScene`], ... and says so in
/// [`TestBed::provides`]):
/// ```
/// use mcbench_core::math::Rgb;
/// use mcbench_core::testbed::{Needs, Reference, ReferenceKind, TestBed};
///
/// struct Flat(Reference);
/// impl TestBed for Flat {
///     fn id(&self) -> &'static str { "flat" }
///     fn variant(&self) -> &str { "default" }
///     fn provides(&self) -> Needs { Needs::NONE }
///     fn resolution(&self) -> (usize, usize) { (2, 2) }
///     fn reference(&self) -> &Reference { &self.0 }
/// }
///
/// let exact = ReferenceKind::Exact { method: "closed form".into(), bound: 0.0 };
/// let bed = Flat(Reference { kind: exact, value: vec![Rgb([0.5; 3]); 4], std_err: vec![Rgb::ZERO; 4] });
/// assert_eq!(bed.integrals(), 4);
/// assert!(bed.reference().is_exact());
/// assert_eq!(bed.reference().check(bed.integrals()), Ok(()));
/// ```
pub trait TestBed: Send + Sync {
    /// Registered id, e.g. `gradient-plane`.
    fn id(&self) -> &'static str;
    /// Variant name, e.g. `default`.
    fn variant(&self) -> &str;
    /// What the scene provides.
    fn provides(&self) -> Needs;
    /// Image width and height; the number of integrals is their product.
    fn resolution(&self) -> (usize, usize);
    /// The references of every integral.
    fn reference(&self) -> &Reference;
    /// What a stored reference of this scene is looked up by, for scenes whose reference can be
    /// stored ([`crate::references`]); `None` (the default) for closed forms.
    fn reference_key(&self) -> Option<crate::references::ReferenceKey> {
        None
    }
    /// Extra geometry columns for integral `i` in `integrals.csv` (name, value).
    fn geometry(&self, _i: usize) -> Vec<(&'static str, f64)> {
        Vec::new()
    }
    /// The hemispherical-integral view of the scene, when it has one.
    fn hemisphere(&self) -> Option<&dyn HemisphereScene> {
        None
    }
    /// The participating-medium view of the scene, when it has one.
    fn medium(&self) -> Option<&dyn MediumScene> {
        None
    }
    /// The image-plane view of the scene (paper 003 PMC-IP), when it has one.
    fn image_plane(&self) -> Option<&dyn ImagePlaneScene> {
        None
    }
    /// The generic integrand of the scene ([`crate::integrand`]), when it is one.
    fn integrand(&self) -> Option<&dyn crate::integrand::Integrand> {
        None
    }
    /// The environment-sequence view of the scene (paper 004), when it has one.
    fn env_sequence(&self) -> Option<&dyn EnvSequenceScene> {
        None
    }
    /// How many consecutive integrals form one sequence (frames of one pixel, paper 004): integral
    /// `i` is frame `i % F` of pixel `i / F`. The runner hands whole sequences to
    /// [`crate::estimator::Estimator::estimate_sequence`]. 1 (the default) for static scenes.
    fn sequence_length(&self) -> usize {
        1
    }
    /// Number of integrals: pixels times [`TestBed::sequence_length`].
    fn integrals(&self) -> usize {
        let (w, h) = self.resolution();
        w * h * self.sequence_length()
    }
}

/// Which quantity of paper 004 an environment-sequence integral asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum EnvQuantity {
    /// `L_r`: reflected radiance with visibility (paper 004 Eq. 1).
    Reflected,
    /// `L_ns`: unoccluded reflected radiance, the normaliser of the product distribution (Eq. 2).
    Unoccluded,
}

/// A scene whose integrals are per-pixel, per-frame reflections of a dynamic environment map
/// (paper 004): integral `pixel * frames + frame`.
///
/// (The papers' `envmap-sequence` test bed is one.)
pub trait EnvSequenceScene: Send + Sync {
    /// Frames per sequence.
    fn frames(&self) -> usize;
    /// The quantity every integral asks for.
    fn quantity(&self) -> EnvQuantity;
    /// The shading point of a pixel (the same in every frame: relighting mode).
    fn shading(&self, pixel: usize) -> ShadingPoint;
    /// The environment of a frame: radiance lookup and its importance sampler.
    fn environment(&self, frame: usize) -> crate::envmap::EnvFrame<'_>;
    /// Binary visibility of direction `wi` from the shading point of `pixel` (one shadow ray).
    fn visible(&self, pixel: usize, wi: Vec3) -> bool;
}
