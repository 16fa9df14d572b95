//! `checker-image` (paper 003 §4.4, Table 1; book: testbeds.md): the `checker-direct` scene (each of its
//! variants: `default`, `occluded`, `soft-shadow`) with pixel integrals over each pixel's
//! footprint (box filter, paper 003 Eq. 2),
//! `I_p = int_{pixel p} L(x(u, v)) du dv`, where `L(x)` is the direct lighting at the floor point
//! seen through image position `(u, v)` (zero where the ray misses the board).
//!
//! One *pixel sample* is a position in the footprint plus one MIS direct-lighting estimate with
//! `light_samples` (default 8, paper 003's Buddha: "8 lighting samples for each pixel sample")
//! light samples, each paired with a BRDF sample and combined by the balance heuristic (the
//! `mis` baseline's round, [`mcbench_core::lighting::mis_round`]). Its expectation over the MIS
//! randomness is `L(x)`, so the mean over uniform footprint positions is `I_p`: image-plane
//! samplers (`uniform_image`, `pmc_ip`) only choose where the pixel samples go.
//!
//! Costs: a pixel sample counts one sample and its rays (the camera ray, one per BRDF sample
//! above the horizon, one per light sample).
//!
//! Reference: stored long-run values with standard errors (no closed form: the footprint
//! integral of a glossy checkerboard under area lights), made by `mcbench reference
//! checker-image --variant V` ([`super::checker_image_reference`]) and looked up by variant and
//! resolution in the reference source the caller gives.

use super::checker::CheckerGeometry;
use mcbench_core::entry::{BedCase, CaseRole, TestBedEntry};
use mcbench_core::error::ConfigError;
use mcbench_core::lighting::{light_selection, mis_round, MisStrategy};
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::{check_count, parse, ParamSet, ParamSpec, Params};
use mcbench_core::phong_at::PhongAt;
use mcbench_core::references::{ReferenceKey, ReferenceSource};
use mcbench_core::rng::StreamRng;
use mcbench_core::testbed::{ImagePlaneScene, Needs, Reference, ShadingPoint, TestBed};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The image part of the `unbiasedness` experiment: 4 samples per pixel (PMC-IP's schedule scaled
/// down from its 2 + 4 + 4), 256 repetitions (quick) or 1024 (full). The control `threshold_image`
/// has a bias of a few percent; at 10 samples and 32 repetitions the row could not detect it, and
/// more repetitions of fewer samples resolve it at less cost (its bias falls with the samples, the
/// row's standard error with samples x repetitions).
const IMAGE_PART: CaseRole = CaseRole::Unbiasedness { samples: 4, reps: (256, 1024) };

/// Registry entry.
pub static ENTRY: TestBedEntry = TestBedEntry {
    id: "checker-image",
    variants: &["default", "occluded", "soft-shadow"],
    provides: Needs::IMAGE_PLANE,
    summary: "checker scene, pixel-footprint integrals; a pixel sample = jittered position + MIS with 8 light samples (paper 003 Table 1)",
    build: |variant, params, refs| Ok(Box::new(CheckerImage::new(variant, params, refs)?)),
    compute_reference: Some(super::checker_image_reference::compute_reference),
    params: ParamSpec::of::<CheckerImageParams>().display("checker image (paper 003 Table 1)").words(crate::words::variant),
    cases: &[
        BedCase { variant: "default", params: &[], role: CaseRole::Check },
        BedCase { variant: "default", params: &[], role: IMAGE_PART },
        BedCase { variant: "occluded", params: &[], role: IMAGE_PART },
        BedCase { variant: "soft-shadow", params: &[], role: IMAGE_PART },
    ],
};

/// Parameters of `checker-image`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct CheckerImageParams {
    /// Side of the square image in pixels (1 to 512; the stored references are 48).
    pub resolution: usize,
    /// MIS light samples of one pixel sample (1 to 1024; paper 003's Buddha: 8).
    pub light_samples: usize,
}

impl Default for CheckerImageParams {
    fn default() -> Self {
        CheckerImageParams { resolution: 48, light_samples: 8 }
    }
}

impl ParamSet for CheckerImageParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_count("resolution", self.resolution, 512)?;
        check_count("light_samples", self.light_samples, 1024).map(|_| ())
    }
}

/// The `checker-image` scene.
pub struct CheckerImage {
    variant: String,
    size: usize,
    light_samples: usize,
    geometry: CheckerGeometry,
    select: Vec<f64>,
    reference: Reference,
}

impl CheckerImage {
    /// Builds a variant with the stored reference `refs` holds for its
    /// [`CheckerImage::reference_key`] (variant and resolution; the light samples of one pixel
    /// sample change its variance, not its expectation).
    pub fn new(variant: &str, params: &Params, refs: &dyn ReferenceSource) -> Result<Self, ConfigError> {
        let bed = Self::without_reference(variant, params)?;
        let reference =
            mcbench_core::references::load(refs, &bed.reference_key(), bed.size * bed.size, bed.resolution())?;
        Ok(CheckerImage { reference, ..bed })
    }

    /// What the stored reference is looked up by: variant and resolution.
    pub fn reference_key(&self) -> ReferenceKey {
        ReferenceKey::new(ENTRY.id, &self.variant, &[("resolution", self.size.into())], self.size == 48)
    }

    /// The scene with an empty reference (the reference computation and the tests sample it).
    pub fn without_reference(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        let p = parse::<CheckerImageParams>("checker-image", params)?;
        let (size, light_samples) = (p.resolution, p.light_samples);
        // `checker-direct`'s `lattice` has no stored pixel-footprint reference: only this
        // bed's own variants are built.
        let unknown =
            || ConfigError::unknown("variant", &format!("{}/{variant}", ENTRY.id), ENTRY.variants.iter().copied());
        if !ENTRY.variants.contains(&variant) {
            return Err(unknown());
        }
        let geometry = CheckerGeometry::new(variant).map_err(|_| unknown())?;
        let select = light_selection(&geometry.lights);
        Ok(CheckerImage {
            variant: variant.to_string(),
            size,
            light_samples,
            geometry,
            select,
            reference: Reference::empty(),
        })
    }

    /// The scene geometry (shared with `checker-direct`).
    pub fn geometry(&self) -> &CheckerGeometry {
        &self.geometry
    }

    /// The floor point seen through the centre of pixel `i` (geometry columns), if any.
    fn centre(&self, i: usize) -> Option<ShadingPoint> {
        let (px, py) = (i % self.size, i / self.size);
        self.geometry.shade(px as f64 + 0.5, py as f64 + 0.5, self.size)
    }
}

impl TestBed for CheckerImage {
    fn reference_key(&self) -> Option<ReferenceKey> {
        Some(CheckerImage::reference_key(self))
    }
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
        match self.centre(i) {
            Some(p) => {
                vec![("hit_x", p.position.x), ("hit_y", p.position.y), ("phong_n", p.brdf.n), ("ks", p.brdf.ks[0])]
            }
            None => Vec::new(),
        }
    }
    fn image_plane(&self) -> Option<&dyn ImagePlaneScene> {
        Some(self)
    }
    /// The whole image is one sequence: image-plane samplers allocate samples across pixels, so
    /// they receive every pixel's task in one call.
    fn sequence_length(&self) -> usize {
        self.size * self.size
    }
    fn integrals(&self) -> usize {
        self.size * self.size
    }
}

impl ImagePlaneScene for CheckerImage {
    fn pixel_sample(&self, pixel: usize, u: f64, v: f64, rng: &mut StreamRng) -> (Rgb, u64) {
        let (px, py) = (pixel % self.size, pixel / self.size);
        let Some(point) = self.geometry.shade(px as f64 + u, py as f64 + v, self.size) else {
            return (Rgb::ZERO, 1);
        };
        let strategy = MisStrategy { lights: &self.geometry.lights, select: &self.select, power: 1.0 };
        let brdf = PhongAt::new(point.brdf, point.wo, point.normal);
        let mut rays = 1u64;
        let mut sum = Rgb::ZERO;
        for _ in 0..self.light_samples {
            // `f` is the BRDF value at `w` (`brdf.eval`, computed with its density).
            let integrand = |w: Vec3, f: Rgb| {
                if w.dot(point.normal) <= 0.0 {
                    return Rgb::ZERO;
                }
                rays += 1;
                self.geometry.incident(point.position, w) * f * w.z
            };
            sum += mis_round(point.position, &brdf, &strategy, true, integrand, rng);
        }
        (sum / self.light_samples as f64, rays)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testbeds::checker::CheckerDirect;
    use mcbench_core::rng::stream;
    use mcbench_core::stats::Moments;

    /// At a pixel centre, the mean of many pixel samples is the exact direct lighting of
    /// `checker-direct` at the same point (the MIS estimate is unbiased), for a diffuse, a glossy
    /// and an occluded pixel.
    #[test]
    fn pixel_samples_at_the_centre_average_to_the_direct_lighting() {
        for variant in ["default", "occluded"] {
            let params = Params::new().with("resolution", 8.0);
            let image = CheckerImage::without_reference(variant, &params).unwrap();
            let direct = CheckerDirect::new(variant, &params).unwrap();
            let mut rng = stream(4, "checker-image centre");
            for i in [27, 36, 44, 51] {
                let mut m = Moments::default();
                for _ in 0..4000 {
                    let (v, rays) = image.pixel_sample(i, 0.5, 0.5, &mut rng);
                    assert!((1..=17).contains(&rays));
                    m.push(v[0]);
                }
                let r = direct.reference().value[i][0];
                let z = (m.mean() - r) / m.std_err();
                assert!(z.abs() < 4.5, "{variant} pixel {i}: mean {} se {} exact {r}", m.mean(), m.std_err());
            }
        }
    }

    #[test]
    fn bad_parameters_and_missing_references_name_the_field() {
        let e = CheckerImage::without_reference("default", &Params::new().with("light_samples", 0.0));
        assert!(e.err().unwrap().to_string().contains("light_samples"));
        let e = CheckerImage::without_reference("nope", &Params::new());
        assert!(e.err().unwrap().to_string().contains("checker-image/nope"));
        // `checker-direct` builds `lattice`; this bed has no stored reference for it.
        let e = CheckerImage::without_reference("lattice", &Params::new()).err().unwrap().to_string();
        assert!(e.contains("checker-image/lattice") && e.contains("soft-shadow"), "{e}");
        // No reference is stored at resolution 7 (the error names the resolution, or the missing
        // file when no reference is stored at all).
        let e =
            CheckerImage::new("default", &Params::new().with("resolution", 7.0), &crate::built_in_references::BUILT_IN)
                .err()
                .unwrap()
                .to_string();
        assert!(e.contains("resolution") || e.contains("checker-image_default.json"), "{e}");
    }
}
