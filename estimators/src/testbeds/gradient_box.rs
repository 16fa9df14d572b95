//! `gradient-box` (paper 000 §5, SPEC §3.2): a homogeneous cube `[-0.5, 0.5]^3` of participating
//! medium (`sigma_t = 2`, index-matched boundary, no emission) under the gradient background
//! `L_b(w) = max(0, c0 + c1 w_z + c2 w_x)` over the whole sphere, seen by an orthographic camera
//! looking along +y whose 16 x 16 pixels cover `x, z in [-0.5, 0.5]` (row `py = 0` at the top,
//! `z = +0.5`). Integral = pixel: the radiance reaching the camera along the pixel-centre ray,
//! multiple scattering included (paper 000 Eq. 6).
//!
//! Variants: `albedo-1`, `albedo-0.8`, `albedo-0.5` (isotropic phase), `hg-0.1` (albedo 0.8,
//! Henyey-Greenstein g = 0.1), `furnace` (albedo 1, `c1 = c2 = 0`: every path returns exactly `c0`,
//! so the reference is exact), `albedo-0` (single attenuation `exp(-sigma_t) c0`, exact) and `thick`
//! (`sigma_t = 1e4`, albedo 0.8: the optically thick stability case, SPEC §10).
//!
//! References of the other variants are stored long-run Monte Carlo values made by
//! `mcbench reference gradient-box --variant V` ([`compute_reference`]) and read from
//! `results/references/gradient-box_V.json` together with the resolution and `sigma_t` they were
//! made for.
//!
//! The whole image is one sequence ([`TestBed::sequence_length`] = pixels): estimators that share
//! one adaptive structure across the image (paper 000 §4.3) get every pixel's task at once.

use crate::error::ConfigError;
use crate::lighting::Gradient;
use crate::math::{Rgb, Vec3};
use crate::params::Params;
use crate::phase::Phase;
use crate::registry::TestBedEntry;
use crate::testbed::{MediumQuantity, MediumRay, MediumScene, Needs, Reference, ReferenceKind, TestBed};
use serde::Deserialize;
use std::path::PathBuf;

/// Registry entry.
pub static ENTRY: TestBedEntry = TestBedEntry {
    id: "gradient-box",
    variants: &["albedo-0.8", "albedo-1", "albedo-0.5", "hg-0.1", "furnace", "albedo-0", "thick"],
    provides: Needs::MEDIUM,
    summary: "homogeneous box under a gradient sky, orthographic 16x16, stored MC reference (paper 000 §5)",
    build: |variant, params| Ok(Box::new(GradientBox::new(variant, params)?)),
    compute_reference: Some(super::gradient_box_reference::compute_reference),
};

/// The parameters the test bed accepts.
pub const PARAMS: &[&str] = &["resolution", "sigma_t"];

/// What a variant fixes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxSetup {
    /// Single-scattering albedo.
    pub albedo: f64,
    /// Extinction (the default of the variant unless overridden).
    pub sigma_t: f64,
    /// Phase function.
    pub phase: Phase,
    /// Background.
    pub background: Gradient,
}

/// The setup of a variant (SPEC §3.2).
pub fn variant_setup(variant: &str) -> Result<BoxSetup, ConfigError> {
    let bg = Gradient { clamp: true, ..Gradient::papers() };
    let iso = |albedo: f64| BoxSetup { albedo, sigma_t: 2.0, phase: Phase::Isotropic, background: bg };
    Ok(match variant {
        "albedo-1" => iso(1.0),
        "albedo-0.8" => iso(0.8),
        "albedo-0.5" => iso(0.5),
        "albedo-0" => iso(0.0),
        "hg-0.1" => BoxSetup { phase: Phase::HenyeyGreenstein(0.1), ..iso(0.8) },
        "furnace" => BoxSetup { background: Gradient { c1: Rgb::ZERO, c2: Rgb::ZERO, ..bg }, ..iso(1.0) },
        "thick" => BoxSetup { sigma_t: 1e4, ..iso(0.8) },
        _ => {
            return Err(ConfigError::unknown(
                "variant",
                &format!("gradient-box/{variant}"),
                ENTRY.variants.iter().copied(),
            ))
        }
    })
}

/// The scene.
pub struct GradientBox {
    variant: String,
    size: usize,
    setup: BoxSetup,
    reference: Reference,
}

/// A stored reference file (written by the CLI's `reference` command).
#[derive(Deserialize)]
struct StoredFile {
    resolution: (usize, usize),
    reference: Reference,
    #[serde(default)]
    sigma_t: Option<f64>,
}

/// Where the stored reference of a variant lives.
pub fn stored_path(variant: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../results/references").join(format!("gradient-box_{variant}.json"))
}

impl GradientBox {
    /// Builds a variant with its reference (exact, or loaded from the stored file). Parameters:
    /// `resolution` (image side, default 16, thick: 4) and `sigma_t` (default 2, thick: 1e4).
    pub fn new(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        let bed = Self::without_reference(variant, params)?;
        let reference = match variant {
            "furnace" => bed.exact(bed.setup.background.c0, "white furnace: every path returns c0"),
            "albedo-0" => {
                let t = (-bed.setup.sigma_t).exp();
                bed.exact(bed.setup.background.c0 * t, "no scattering: exp(-sigma_t) L_b(+y)")
            }
            _ => bed.load_stored()?,
        };
        Ok(GradientBox { reference, ..bed })
    }

    /// The scene with an empty reference (the reference computation runs estimators on it).
    pub fn without_reference(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        params.reject_unknown("gradient-box", PARAMS)?;
        let mut setup = variant_setup(variant)?;
        let default_size = if variant == "thick" { 4 } else { 16 };
        let size = params.count("resolution", default_size, 256)?;
        setup.sigma_t = params.f64_in("sigma_t", setup.sigma_t, 1e-6, 1e6)?;
        Ok(GradientBox { variant: variant.to_string(), size, setup, reference: Reference::empty() })
    }

    /// The variant's setup.
    pub fn setup(&self) -> &BoxSetup {
        &self.setup
    }

    fn exact(&self, v: Rgb, method: &str) -> Reference {
        let n = self.size * self.size;
        Reference {
            kind: ReferenceKind::Exact {
                method: method.into(),
                bound: 1e-15 * v.0.iter().fold(1.0f64, |a, b| a.max(*b)),
            },
            value: vec![v; n],
            std_err: vec![Rgb::ZERO; n],
        }
    }

    fn load_stored(&self) -> Result<Reference, ConfigError> {
        let path = stored_path(&self.variant);
        let hint = format!("run `mcbench reference gradient-box --variant {}`", self.variant);
        let text = std::fs::read_to_string(&path).map_err(|e| {
            ConfigError::invalid("reference", path.display(), format!("no stored reference ({e}); {hint}"))
        })?;
        let file: StoredFile = serde_json::from_str(&text)
            .map_err(|e| ConfigError::invalid("reference", path.display(), format!("malformed ({e}); {hint}")))?;
        let default_sigma = variant_setup(&self.variant)?.sigma_t;
        let sigma_ok = file.sigma_t.unwrap_or(default_sigma) == self.setup.sigma_t;
        if file.resolution != (self.size, self.size) || !sigma_ok || file.reference.value.len() != self.size * self.size
        {
            let msg = format!(
                "stored for {:?} pixels and sigma_t {:?}; {hint} with matching parameters",
                file.resolution, file.sigma_t
            );
            return Err(ConfigError::invalid("reference", path.display(), msg));
        }
        file.reference
            .check(self.size * self.size)
            .map_err(|e| ConfigError::invalid("reference", path.display(), format!("malformed ({e}); {hint}")))?;
        Ok(file.reference)
    }

    /// The unit direction of the camera rays.
    pub const VIEW: Vec3 = Vec3 { x: 0.0, y: 1.0, z: 0.0 };

    /// The pixel-centre ray of pixel `i` (origin on the plane y = -1, in front of the box).
    pub fn pixel_ray(&self, i: usize) -> MediumRay {
        let (px, py) = (i % self.size, i / self.size);
        let n = self.size as f64;
        let x = -0.5 + (px as f64 + 0.5) / n;
        let z = 0.5 - (py as f64 + 0.5) / n;
        MediumRay {
            origin: Vec3::new(x, -1.0, z),
            dir: Self::VIEW,
            length: f64::INFINITY,
            quantity: MediumQuantity::Radiance,
        }
    }
}

/// Slab clipping against the cube `[-0.5, 0.5]^3`.
pub fn clip_box(origin: Vec3, dir: Vec3) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    for (o, d) in [(origin.x, dir.x), (origin.y, dir.y), (origin.z, dir.z)] {
        if d == 0.0 {
            if !(-0.5..=0.5).contains(&o) {
                return None;
            }
            continue;
        }
        let (a, b) = ((-0.5 - o) / d, (0.5 - o) / d);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    (t0 <= t1).then_some((t0, t1))
}

impl MediumScene for GradientBox {
    fn sigma_t(&self, p: Vec3) -> f64 {
        if p.x.abs() <= 0.5 && p.y.abs() <= 0.5 && p.z.abs() <= 0.5 {
            self.setup.sigma_t
        } else {
            0.0
        }
    }
    fn majorant(&self) -> f64 {
        self.setup.sigma_t
    }
    fn albedo(&self) -> f64 {
        self.setup.albedo
    }
    fn clip(&self, origin: Vec3, dir: Vec3) -> Option<(f64, f64)> {
        clip_box(origin, dir)
    }
    fn environment(&self, w: Vec3) -> Rgb {
        self.setup.background.eval(w)
    }
    fn ray(&self, i: usize) -> MediumRay {
        self.pixel_ray(i)
    }
    fn phase(&self) -> Phase {
        self.setup.phase
    }
}

impl TestBed for GradientBox {
    fn id(&self) -> &'static str {
        ENTRY.id
    }
    fn variant(&self) -> &str {
        &self.variant
    }
    fn provides(&self) -> Needs {
        Needs::MEDIUM
    }
    fn resolution(&self) -> (usize, usize) {
        (self.size, self.size)
    }
    fn reference(&self) -> &Reference {
        &self.reference
    }
    fn geometry(&self, i: usize) -> Vec<(&'static str, f64)> {
        let r = self.pixel_ray(i);
        vec![("x", r.origin.x), ("z", r.origin.z)]
    }
    fn medium(&self) -> Option<&dyn MediumScene> {
        Some(self)
    }
    /// The whole image is one sequence: estimators that share their adaptive structure across the
    /// image (paper 000) receive every pixel's task in one call.
    fn sequence_length(&self) -> usize {
        self.size * self.size
    }
    fn integrals(&self) -> usize {
        self.size * self.size
    }
}
