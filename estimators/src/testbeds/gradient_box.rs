//! `gradient-box` (paper 000 §5, book: testbeds.md): a homogeneous cube `[-0.5, 0.5]^3` of participating
//! medium (`sigma_t = 2`, index-matched boundary, no emission) under the gradient background
//! `L_b(w) = max(0, c0 + c1 w_z + c2 w_x)` over the whole sphere, seen by an orthographic camera
//! looking along +y whose 16 x 16 pixels cover `x, z in [-0.5, 0.5]` (row `py = 0` at the top,
//! `z = +0.5`). Integral = pixel: the radiance reaching the camera along the pixel-centre ray,
//! multiple scattering included (paper 000 Eq. 6).
//!
//! Variants: `albedo-1`, `albedo-0.8`, `albedo-0.5` (isotropic phase), `hg-0.1` (albedo 0.8,
//! Henyey-Greenstein g = 0.1), `furnace` (albedo 1, `c1 = c2 = 0`: every path returns exactly `c0`,
//! so the reference is exact), `albedo-0` (single attenuation `exp(-sigma_t) c0`, exact) and `thick`
//! (`sigma_t = 1e4`, albedo 0.8: the optically thick stability case, book: stability.md).
//!
//! References of the other variants are stored long-run Monte Carlo values of Eq. 6 made by
//! `mcbench reference gradient-box --variant V` with an integrator that shares no sampling code
//! with any estimator ([`super::gradient_box_independent::compute_reference`]: analytic
//! transmittance, forced collisions, uniform-sphere directions weighted by the phase function),
//! looked up by variant, resolution and `sigma_t` ([`GradientBox::reference_key`]) in the
//! reference source the caller gives.
//!
//! The whole image is one sequence ([`TestBed::sequence_length`] = pixels): estimators that share
//! one adaptive structure across the image (paper 000 §4.3) get every pixel's task at once.

use mcbench_core::entry::{BedCase, CaseRole, TestBedEntry};
use mcbench_core::error::ConfigError;
use mcbench_core::lighting::Gradient;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::{check_count, check_range, parse, ParamSet, ParamSpec, Params};
use mcbench_core::phase::Phase;
use mcbench_core::references::{ReferenceKey, ReferenceSource};
use mcbench_core::testbed::{MediumQuantity, MediumRay, MediumScene, Needs, Reference, ReferenceKind, TestBed};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The gradient-box part of the `unbiasedness` experiment: 16 paths per pixel over the whole image,
/// 256 repetitions (quick, enough for the marching control on `albedo-1`) or 1024 (full).
const BOX_PART: CaseRole = CaseRole::Unbiasedness { samples: 16, reps: (256, 1024) };

/// Registry entry.
pub static ENTRY: TestBedEntry = TestBedEntry {
    id: "gradient-box",
    variants: &["albedo-0.8", "albedo-1", "albedo-0.5", "hg-0.1", "furnace", "albedo-0", "thick"],
    provides: Needs::MEDIUM,
    summary: "homogeneous box under a gradient sky, orthographic 16x16, stored MC reference (paper 000 §5)",
    build: |variant, params, refs| Ok(Box::new(GradientBox::new(variant, params, refs)?)),
    compute_reference: Some(super::gradient_box_independent::compute_reference),
    params: ParamSpec::of::<GradientBoxParams>().display("gradient box (paper 000)").words(crate::words::variant),
    cases: &[
        BedCase { variant: "furnace", params: &[("resolution", 2.0)], role: CaseRole::Stability },
        BedCase { variant: "albedo-0", params: &[("resolution", 2.0)], role: CaseRole::Stability },
        BedCase { variant: "thick", params: &[], role: CaseRole::Stability },
        BedCase { variant: "furnace", params: &[("resolution", 2.0)], role: CaseRole::Check },
        BedCase { variant: "albedo-0.8", params: &[], role: BOX_PART },
        BedCase { variant: "albedo-1", params: &[], role: BOX_PART },
        BedCase { variant: "albedo-0.5", params: &[], role: BOX_PART },
        BedCase { variant: "hg-0.1", params: &[], role: BOX_PART },
        BedCase { variant: "furnace", params: &[], role: BOX_PART },
        BedCase { variant: "albedo-0", params: &[], role: BOX_PART },
        BedCase { variant: "thick", params: &[], role: BOX_PART },
    ],
};

/// Parameters of `gradient-box`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct GradientBoxParams {
    /// Side of the square image in pixels (1 to 256; unset: 16, and 4 for `thick`).
    pub resolution: Option<usize>,
    /// Extinction of the box (1e-6 to 1e6; unset: 2, and 1e4 for `thick`).
    pub sigma_t: Option<f64>,
}

impl ParamSet for GradientBoxParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        if let Some(r) = self.resolution {
            check_count("resolution", r, 256)?;
        }
        if let Some(s) = self.sigma_t {
            check_range("sigma_t", s, 1e-6, 1e6)?;
        }
        Ok(())
    }
}

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

/// The setup of a variant (book: testbeds.md).
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

impl GradientBox {
    /// Builds a variant with its reference (exact, or the stored one `refs` holds for its
    /// [`GradientBox::reference_key`]).
    pub fn new(variant: &str, params: &Params, refs: &dyn ReferenceSource) -> Result<Self, ConfigError> {
        let bed = Self::without_reference(variant, params)?;
        let reference = match variant {
            "furnace" => bed.exact(bed.setup.background.c0, "white furnace: every path returns c0"),
            "albedo-0" => {
                let t = (-bed.setup.sigma_t).exp();
                bed.exact(bed.setup.background.c0 * t, "no scattering: exp(-sigma_t) L_b(+y)")
            }
            _ => mcbench_core::references::load(refs, &bed.reference_key(), bed.size * bed.size, bed.resolution())?,
        };
        Ok(GradientBox { reference, ..bed })
    }

    /// The scene with an empty reference (the reference computation runs estimators on it).
    pub fn without_reference(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        let p = parse::<GradientBoxParams>("gradient-box", params)?;
        let mut setup = variant_setup(variant)?;
        let size = p.resolution.unwrap_or(if variant == "thick" { 4 } else { 16 });
        setup.sigma_t = p.sigma_t.unwrap_or(setup.sigma_t);
        Ok(GradientBox { variant: variant.to_string(), size, setup, reference: Reference::empty() })
    }

    /// What the stored reference of this scene is looked up by: variant, resolution and `sigma_t`.
    pub fn reference_key(&self) -> ReferenceKey {
        let default_size = if self.variant == "thick" { 4 } else { 16 };
        let default = variant_setup(&self.variant).map(|s| s.sigma_t == self.setup.sigma_t).unwrap_or(false)
            && self.size == default_size;
        ReferenceKey::new(
            ENTRY.id,
            &self.variant,
            &[("resolution", self.size.into()), ("sigma_t", self.setup.sigma_t.into())],
            default,
        )
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

/// Slab clipping against the cube `[-0.5, 0.5]^3`: the parameter interval `[t0, t1]` (from
/// `t0 >= 0`) of the ray inside the cube, `None` when it misses.
///
/// Per axis the two plane distances `(-0.5 - o) / d` and `(0.5 - o) / d` narrow the interval; an
/// axis the ray is parallel to (`d == 0`) only tests that the origin lies within its slab. The
/// selections are plain comparisons, `if y < x { y } else { x }`, the values of `x.min(y)` and
/// `x.max(y)` on every non-NaN pair (on a tie of zeros of opposite sign, where those leave the
/// sign open, the first operand is kept, as they compile here). A NaN distance (a NaN input, or
/// an infinite origin on an infinite direction, which makes both distances of the axis NaN) fails
/// every comparison, so the axis leaves the interval as it is, as `min`/`max` would: the bits of
/// the textbook form without its NaN masks.
#[inline]
pub fn clip_box(origin: Vec3, dir: Vec3) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (0.0f64, f64::INFINITY);
    slab(origin.x, dir.x, &mut t0, &mut t1)?;
    slab(origin.y, dir.y, &mut t0, &mut t1)?;
    slab(origin.z, dir.z, &mut t0, &mut t1)?;
    (t0 <= t1).then_some((t0, t1))
}

/// One axis of [`clip_box`]: narrows `[t0, t1]` to the slab `[-0.5, 0.5]`, `None` when a ray
/// parallel to the slab starts outside it.
#[inline(always)]
fn slab(o: f64, d: f64, t0: &mut f64, t1: &mut f64) -> Option<()> {
    if d == 0.0 {
        return (-0.5..=0.5).contains(&o).then_some(());
    }
    let (a, b) = ((-0.5 - o) / d, (0.5 - o) / d);
    let (near, far) = (if b < a { b } else { a }, if b > a { b } else { a });
    if near > *t0 {
        *t0 = near;
    }
    if far < *t1 {
        *t1 = far;
    }
    Some(())
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
    fn reference_key(&self) -> Option<ReferenceKey> {
        Some(GradientBox::reference_key(self))
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::rng::StreamKey;
    use rand::Rng;

    /// The textbook slab form with `min`/`max`, which [`clip_box`] must reproduce bit for bit.
    fn clip_min_max(origin: Vec3, dir: Vec3) -> Option<(f64, f64)> {
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

    fn bits(r: Option<(f64, f64)>) -> Option<(u64, u64)> {
        r.map(|(a, b)| (a.to_bits(), b.to_bits()))
    }

    /// Same bits as the `min`/`max` form on random rays and on every combination of the special
    /// values per axis: faces, signed zeros, infinities, NaN, huge and tiny components.
    #[test]
    fn clip_box_is_the_min_max_form_bit_for_bit() {
        let mut rng = StreamKey { seed: 3, testbed: "t", estimator: "e", budget: 0, rep: 0, integral: 0 }.rng();
        for _ in 0..100_000 {
            let o = Vec3::new(rng.gen::<f64>() * 3.0 - 1.5, rng.gen::<f64>() * 3.0 - 1.5, rng.gen::<f64>() * 3.0 - 1.5);
            let d = Vec3::new(rng.gen::<f64>() * 2.0 - 1.0, rng.gen::<f64>() * 2.0 - 1.0, rng.gen::<f64>() * 2.0 - 1.0);
            assert_eq!(bits(clip_box(o, d)), bits(clip_min_max(o, d)), "{o:?} {d:?}");
        }
        let special = [
            0.0,
            -0.0,
            0.5,
            -0.5,
            0.25,
            -0.75,
            1.0,
            -1.0,
            1e-300,
            -1e-300,
            1e300,
            -1e300,
            1e17,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let pick = |rng: &mut mcbench_core::rng::StreamRng| special[rng.gen_range(0..special.len())];
        for _ in 0..200_000 {
            let o = Vec3::new(pick(&mut rng), pick(&mut rng), pick(&mut rng));
            let d = Vec3::new(pick(&mut rng), pick(&mut rng), pick(&mut rng));
            assert_eq!(bits(clip_box(o, d)), bits(clip_min_max(o, d)), "{o:?} {d:?}");
        }
    }
}
