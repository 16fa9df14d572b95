//! `canonical-1d`: the transmittance of the segment `[0, 1]` through the canonical extinction
//! profiles of [`super::canonical_profiles`], scaled to a target transmittance (paper 002
//! §3.4 studies the same one-dimensional problem analytically).
//!
//! Variants `<profile>-T<t>` for the seven profiles and the target transmittances
//! `t` in {0.01, 0.1, 0.5, 0.9, 0.99}: `sigma_t(x) = tau f(x)` with `tau = -ln t` inside the slab
//! `0 <= x <= 1` (zero outside), so `T(1) = t`. The declared majorant is the tight one,
//! `tau max f`, so a tracker's `sigma_samp_ratio` is `sigma_samp / max sigma_t`.
//!
//! Integral `k` (of `points`, default 1) is `T(s_k)`, `s_k = k / points`, along the ray from the
//! origin in +x, one channel replicated to RGB; the reference is the closed form
//! `exp(-tau F(s_k))`. Parameters: `points`, `albedo` (default 0.7, as paper 002's Eq. 21 medium:
//! it only matters to the single particle models, whose scattered particle leaves the ray) and
//! `tau` (the optical depth of the whole segment, overriding `-ln t`: `tau = 0` is an empty
//! medium, `tau = 1e4` the optically thick stability case). The
//! scene has no approximate extinction, so explorer points of control variates cost full fetches.

use super::canonical_profiles::Profile;
use mcbench_core::entry::{BedCase, CaseRole, TestBedEntry};
use mcbench_core::error::ConfigError;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::{check_count, check_range, parse, ParamSet, ParamSpec, Params};
use mcbench_core::testbed::{MediumQuantity, MediumRay, MediumScene, Needs, Reference, ReferenceKind, TestBed};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The target transmittances of the variants.
pub const TARGETS: [f64; 5] = [0.01, 0.1, 0.5, 0.9, 0.99];

macro_rules! grid {
    ($($p:literal),*) => {
        &[$(
            concat!($p, "-T0.01"),
            concat!($p, "-T0.1"),
            concat!($p, "-T0.5"),
            concat!($p, "-T0.9"),
            concat!($p, "-T0.99"),
        )*]
    };
}

/// Every variant: profile x target transmittance.
pub const VARIANTS: &[&str] = grid!("constant", "cosine", "gaussian", "hole", "linear-up", "linear-down", "step");

/// The canonical part of the `unbiasedness` experiment: 4 samples per estimate, 16384 repetitions
/// (quick) or 65536 (full).
const CANONICAL_PART: CaseRole = CaseRole::Unbiasedness { samples: 4, reps: (16_384, 65_536) };

/// The checks' cases: the stability extremes (optical depth 1e4 and 0, albedo 0 and 1), a small
/// check, and every variant in the `unbiasedness` experiment.
macro_rules! cases {
    ($($p:literal),*) => {
        &[
            BedCase { variant: "constant-T0.5", params: &[("tau", 1e4)], role: CaseRole::Stability },
            BedCase { variant: "constant-T0.5", params: &[("tau", 0.0)], role: CaseRole::Stability },
            BedCase { variant: "hole-T0.1", params: &[("albedo", 0.0)], role: CaseRole::Stability },
            BedCase { variant: "hole-T0.1", params: &[("albedo", 1.0)], role: CaseRole::Stability },
            BedCase { variant: "hole-T0.1", params: &[("points", 2.0)], role: CaseRole::Check },
            $(
                BedCase { variant: concat!($p, "-T0.01"), params: &[], role: CANONICAL_PART },
                BedCase { variant: concat!($p, "-T0.1"), params: &[], role: CANONICAL_PART },
                BedCase { variant: concat!($p, "-T0.5"), params: &[], role: CANONICAL_PART },
                BedCase { variant: concat!($p, "-T0.9"), params: &[], role: CANONICAL_PART },
                BedCase { variant: concat!($p, "-T0.99"), params: &[], role: CANONICAL_PART },
            )*
        ]
    };
}

/// Registry entry.
pub static ENTRY: TestBedEntry = TestBedEntry {
    id: "canonical-1d",
    variants: VARIANTS,
    provides: Needs::MEDIUM,
    summary: "T of [0, 1] through 7 analytic extinction profiles x 5 target T, closed-form references",
    build: |variant, params, _| Ok(Box::new(Canonical1d::new(variant, params)?)),
    compute_reference: None,
    params: ParamSpec::of::<Canonical1dParams>().display("canonical 1D segment").words(crate::words::canonical_variant),
    cases: cases!("constant", "cosine", "gaussian", "hole", "linear-up", "linear-down", "step"),
};

/// Parameters of `canonical-1d`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct Canonical1dParams {
    /// Ray lengths evaluated: `T(k / points)` for `k = 1..=points` (1 to 10000).
    pub points: usize,
    /// Single-scattering albedo (0 to 1; what the particle models' weights see).
    pub albedo: f64,
    /// Optical depth of the whole ray (0 to 1e6; unset: `-ln` of the variant's target T).
    pub tau: Option<f64>,
}

impl Default for Canonical1dParams {
    fn default() -> Self {
        Canonical1dParams { points: 1, albedo: 0.7, tau: None }
    }
}

impl ParamSet for Canonical1dParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_count("points", self.points, 10_000)?;
        check_range("albedo", self.albedo, 0.0, 1.0)?;
        if let Some(t) = self.tau {
            check_range("tau", t, 0.0, 1e6)?;
        }
        Ok(())
    }
}

/// Relative error bound of the closed-form references (f64 evaluation of `exp(-tau F(s))`;
/// the closed forms agree with quadrature to 1e-13, see the profiles' tests).
pub const REFERENCE_REL_BOUND: f64 = 1e-13;

/// The variant name of a profile and target.
pub fn variant_name(profile: Profile, target: f64) -> String {
    format!("{}-T{target}", profile.name())
}

/// The profile and target transmittance of a variant name.
pub fn parse_variant(variant: &str) -> Option<(Profile, f64)> {
    let (p, t) = variant.rsplit_once("-T")?;
    let target: f64 = t.parse().ok()?;
    (VARIANTS.contains(&variant)).then_some(())?;
    Some((Profile::parse(p)?, target))
}

/// The scene.
pub struct Canonical1d {
    variant: String,
    profile: Profile,
    tau: f64,
    albedo: f64,
    rays: Vec<MediumRay>,
    reference: Reference,
}

impl Canonical1d {
    /// Builds a variant (validates the parameters; the reference is the closed form).
    pub fn new(variant: &str, params: &Params) -> Result<Self, ConfigError> {
        let p = parse::<Canonical1dParams>("canonical-1d", params)?;
        let (profile, target) = parse_variant(variant).ok_or_else(|| {
            ConfigError::unknown("variant", &format!("canonical-1d/{variant}"), VARIANTS.iter().copied())
        })?;
        let (points, albedo, tau) = (p.points, p.albedo, p.tau.unwrap_or(-target.ln()));
        let rays: Vec<MediumRay> = (1..=points)
            .map(|k| MediumRay {
                origin: Vec3::default(),
                dir: Vec3::new(1.0, 0.0, 0.0),
                length: k as f64 / points as f64,
                quantity: MediumQuantity::Transmittance { weight: Rgb::splat(1.0) },
            })
            .collect();
        let value: Vec<Rgb> = rays.iter().map(|r| Rgb::splat((-tau * profile.cumulative(r.length)).exp())).collect();
        let bound = value.iter().map(|v| v[0] * REFERENCE_REL_BOUND).fold(0.0, f64::max);
        let reference = Reference {
            kind: ReferenceKind::Exact {
                method: format!("closed form exp(-tau F(s)), {} profile", profile.name()),
                bound,
            },
            std_err: vec![Rgb::ZERO; value.len()],
            value,
        };
        Ok(Canonical1d { variant: variant.to_string(), profile, tau, albedo, rays, reference })
    }

    /// The profile.
    pub fn profile(&self) -> Profile {
        self.profile
    }

    /// The optical depth of the whole segment.
    pub fn tau(&self) -> f64 {
        self.tau
    }

    /// The extinction at `x` along the segment (zero outside `[0, 1]`).
    pub fn extinction(&self, x: f64) -> f64 {
        if (0.0..=1.0).contains(&x) {
            self.tau * self.profile.shape(x)
        } else {
            0.0
        }
    }
}

impl TestBed for Canonical1d {
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
        (self.rays.len(), 1)
    }
    fn reference(&self) -> &Reference {
        &self.reference
    }
    fn geometry(&self, i: usize) -> Vec<(&'static str, f64)> {
        vec![("s", self.rays[i].length)]
    }
    fn medium(&self) -> Option<&dyn MediumScene> {
        Some(self)
    }
}

impl MediumScene for Canonical1d {
    fn sigma_t(&self, p: Vec3) -> f64 {
        self.extinction(p.x)
    }
    fn majorant(&self) -> f64 {
        self.tau * self.profile.peak()
    }
    fn albedo(&self) -> f64 {
        self.albedo
    }
    /// The slab `0 <= x <= 1`.
    fn clip(&self, origin: Vec3, dir: Vec3) -> Option<(f64, f64)> {
        if dir.x == 0.0 {
            return (0.0..=1.0).contains(&origin.x).then_some((0.0, f64::INFINITY));
        }
        let (a, b) = ((0.0 - origin.x) / dir.x, (1.0 - origin.x) / dir.x);
        let (t0, t1) = (a.min(b).max(0.0), a.max(b));
        (t1 > t0).then_some((t0, t1))
    }
    /// A unit background (the scene is only used for transmittance).
    fn environment(&self, _w: Vec3) -> Rgb {
        Rgb::splat(1.0)
    }
    fn ray(&self, i: usize) -> MediumRay {
        self.rays[i]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtins;
    use mcbench_core::budget::Budget;
    use mcbench_core::rng::stream;
    use mcbench_core::stats::{holm_bonferroni, one_sample_t, Moments};
    use mcbench_core::task::Task;

    #[test]
    fn variants_parse_and_references_hit_their_targets() {
        assert_eq!(VARIANTS.len(), 35);
        for v in VARIANTS {
            let bed = Canonical1d::new(v, &Params::new().with("points", 4.0)).unwrap();
            let (p, t) = parse_variant(v).unwrap();
            assert_eq!(variant_name(p, t), *v);
            assert!((bed.reference().value[3][0] / t - 1.0).abs() < 1e-13, "{v}");
            assert!(bed.reference().value.windows(2).all(|w| w[1][0] <= w[0][0]), "{v}: T(s) must fall");
            assert!((bed.majorant() - bed.tau() * p.peak()).abs() == 0.0);
        }
        let err = |v: &str, p: Params| Canonical1d::new(v, &p).err().map(|e| e.to_string()).unwrap_or_default();
        assert!(err("hole-T0.2", Params::new()).contains("canonical-1d/hole-T0.2"));
        assert!(err("hole-T0.1", Params::new().with("albedo", 2.0)).contains("albedo"));
        assert!(err("hole-T0.1", Params::new().with("points", 0.0)).contains("points"));
        assert!(err("hole-T0.1", Params::new().with("scale", 1.0)).contains("canonical-1d.scale"));
    }

    /// Delta tracking at the declared majorant is unbiased on every profile (Holm over the
    /// profiles at T = 0.5, T(s) at 4 points), and a ray marcher with two steps is flagged on the
    /// linear profile; the same marcher is exact on the constant profile and on a step whose edge
    /// lies on its grid (checked on the constant profile: every estimate equals the reference).
    #[test]
    fn trackers_run_unchanged_and_ray_marching_is_exact_only_on_aligned_profiles() {
        let delta = (builtins::estimator("delta_tracking").unwrap().build)(&Params::new()).unwrap();
        let mut ps = Vec::new();
        for p in Profile::ALL {
            let bed = Canonical1d::new(&variant_name(p, 0.5), &Params::new().with("points", 4.0)).unwrap();
            for i in 0..4 {
                let mut m = Moments::default();
                let mut rng = stream(i as u64, p.name());
                for _ in 0..200 {
                    let task = Task::new(&bed, i, Budget::samples(16).unwrap());
                    m.push(delta.estimate(&task, &mut rng).unwrap()[0]);
                }
                ps.push(one_sample_t(m.mean(), m.std_err(), m.count(), bed.reference().value[i][0]).p_value);
            }
        }
        let min_p = holm_bonferroni(&ps).into_iter().fold(1.0, f64::min);
        assert!(min_p > 1e-3, "delta tracking flagged on canonical-1d: {min_p:e}");
        let marching = (builtins::estimator("ray_marching").unwrap().build)(&Params::new()).unwrap();
        let run = |v: &str| {
            let bed = Canonical1d::new(v, &Params::new()).unwrap();
            let mut m = Moments::default();
            let mut rng = stream(9, v);
            for _ in 0..400 {
                let task = Task::new(&bed, 0, Budget::samples(16).unwrap());
                m.push(marching.estimate(&task, &mut rng).unwrap()[0]);
            }
            (m, bed.reference().value[0][0])
        };
        let (m, r) = run("linear-up-T0.1");
        assert!(one_sample_t(m.mean(), m.std_err(), m.count(), r).p_value < 1e-6, "{} vs {r}", m.mean());
        let (m, r) = run("constant-T0.1");
        assert!(m.variance() < 1e-30 && (m.mean() - r).abs() < 1e-15, "{} vs {r}", m.mean());
    }
}
