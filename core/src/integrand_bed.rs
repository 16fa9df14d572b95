//! A test bed made of an [`Integrand`] (book: extending.md): implement [`IntegrandBed`] (an id,
//! the variants and how each is built) and register [`entry`]; every estimator that needs only
//! [`Needs::INTEGRAND`] runs on it. A variant with an exact value is checked against it; one
//! without is checked against a stored reference that `mcbench reference <id> --variant <v>`
//! computes ([`compute`]: plain Monte Carlo at a fixed seed) and the run finds through
//! `--references`.
//!
//! ```
//! use mcbench_core::entry::TestBedEntry;
//! use mcbench_core::integrand::{Domain, Integrand};
//! use mcbench_core::integrand_bed::{self, IntegrandBed};
//!
//! /// `exp(-a |x|^2)` on the unit square; the stiff variant is a narrow peak.
//! struct Bump(f64);
//! impl Integrand for Bump {
//!     fn domain(&self) -> Domain { Domain::UnitCube(2) }
//!     fn eval(&self, x: &[f64]) -> f64 { (-self.0 * (x[0] * x[0] + x[1] * x[1])).exp() }
//! }
//! impl IntegrandBed for Bump {
//!     const ID: &'static str = "bump";
//!     const VARIANTS: &'static [&'static str] = &["smooth", "stiff"];
//!     const SUMMARY: &'static str = "a Gaussian bump in a corner of the unit square";
//!     fn variant(name: &str) -> Option<Self> {
//!         match name { "smooth" => Some(Bump(1.0)), "stiff" => Some(Bump(400.0)), _ => None }
//!     }
//! }
//! static BED: TestBedEntry = integrand_bed::entry::<Bump>(&integrand_bed::cases("smooth", 16));
//!
//! // No exact value: the reference is computed and stored, then found by key.
//! let (key, stored) = integrand_bed::compute::<Bump>("smooth", &Default::default(), Some(1 << 16), 1).unwrap();
//! let refs = mcbench_core::references::InMemory(vec![stored]);
//! let bed = (BED.build)("smooth", &Default::default(), &refs).unwrap();
//! assert!((bed.reference().value[0][0] - 0.5577).abs() < 0.01, "{:?}", bed.reference().value);
//! assert!(BED.build_exact("smooth", &Default::default()).is_err(), "no stored reference: refused");
//! assert_eq!(key.file_name(), "bump_smooth.json");
//! ```

use crate::entry::{BedCase, CaseRole, TestBedEntry};
use crate::error::ConfigError;
use crate::integrand::Integrand;
use crate::math::Rgb;
use crate::params::{parse, NoParams, ParamSpec, Params};
use crate::references::{load, ReferenceKey, ReferenceSource, StoredReference};
use crate::rng::StreamKey;
use crate::testbed::{Needs, Reference, ReferenceKind, TestBed};

/// An integrand family registered as a test bed: its id, its variants and how each is built.
pub trait IntegrandBed: Integrand + Sized + 'static {
    /// The test bed's id.
    const ID: &'static str;
    /// Its variants (the first is the default).
    const VARIANTS: &'static [&'static str];
    /// One line for `mcbench list testbeds`.
    const SUMMARY: &'static str;
    /// The integrand of a variant (`None`: not one of [`IntegrandBed::VARIANTS`]).
    fn variant(name: &str) -> Option<Self>;
}

/// The registry entry of an integrand family, with the cases the harness's checks run
/// (for example [`cases`] of a variant, or several variants' cases in one list).
pub const fn entry<T: IntegrandBed>(cases: &'static [BedCase]) -> TestBedEntry {
    TestBedEntry {
        id: T::ID,
        variants: T::VARIANTS,
        provides: Needs::INTEGRAND,
        summary: T::SUMMARY,
        build: build::<T>,
        compute_reference: Some(compute::<T>),
        params: ParamSpec::NONE,
        cases,
    }
}

/// Repetitions (quick, full) of the `unbiasedness` cases of [`cases`].
pub const CASE_REPS: (usize, usize) = (4096, 16384);

/// The usual cases of one variant: the conformance suite's small check and a case of the
/// `unbiasedness` experiment at `samples` per estimate and [`CASE_REPS`] repetitions. A stiff
/// integrand needs more samples per estimate: the mean of a repetition must be near enough to
/// normal for the t-tests (its skewness falls like one over the square root of the samples).
pub const fn cases(variant: &'static str, samples: u64) -> [BedCase; 2] {
    [
        BedCase { variant, params: &[], role: CaseRole::Check },
        BedCase { variant, params: &[], role: CaseRole::Unbiasedness { samples, reps: CASE_REPS } },
    ]
}

/// Samples behind a computed reference unless told otherwise.
pub const DEFAULT_REFERENCE_SAMPLES: u64 = 1 << 24;

/// Samples per block of a computed reference (one random stream each).
const BLOCK: u64 = 1 << 16;

/// The test bed of one variant of an integrand family: one integral, no parameters.
pub struct IntegrandTestBed<T: IntegrandBed> {
    variant: &'static str,
    f: T,
    reference: Reference,
}

fn integrand_of<T: IntegrandBed>(variant: &str) -> Result<(&'static str, T), ConfigError> {
    let unknown = || ConfigError::unknown("variant", &format!("{}/{variant}", T::ID), T::VARIANTS.iter().copied());
    let name = T::VARIANTS.iter().copied().find(|v| *v == variant).ok_or_else(unknown)?;
    let f = T::variant(name).ok_or_else(unknown)?;
    f.domain().check(&format!("{}/{name}", T::ID))?;
    Ok((name, f))
}

fn key<T: IntegrandBed>(variant: &str) -> ReferenceKey {
    ReferenceKey::new(T::ID, variant, &[], true)
}

/// Builds a variant: its exact value, or the stored reference `refs` holds for it.
pub fn build<T: IntegrandBed>(
    variant: &str,
    params: &Params,
    refs: &dyn ReferenceSource,
) -> Result<Box<dyn TestBed>, ConfigError> {
    parse::<NoParams>(T::ID, params)?;
    let (name, f) = integrand_of::<T>(variant)?;
    let reference = match f.exact() {
        Some(v) if v.is_finite() => Reference {
            kind: ReferenceKind::Exact { method: "closed form".into(), bound: 8.0 * f64::EPSILON * v.abs() },
            value: vec![Rgb([v; 3])],
            std_err: vec![Rgb::ZERO],
        },
        Some(v) => return Err(ConfigError::invalid(format!("{}/{name} exact value", T::ID), v, "must be finite")),
        None => load(refs, &key::<T>(name), 1, (1, 1))?,
    };
    Ok(Box::new(IntegrandTestBed { variant: name, f, reference }))
}

/// Computes the reference of a variant to store: the plain Monte Carlo mean of `samples`
/// (default [`DEFAULT_REFERENCE_SAMPLES`]) evaluations in blocks of 65536, each on a random
/// stream of its own, combined in block order (the result does not depend on `threads`).
pub fn compute<T: IntegrandBed>(
    variant: &str,
    params: &Params,
    samples: Option<u64>,
    threads: usize,
) -> Result<(ReferenceKey, StoredReference), ConfigError> {
    parse::<NoParams>(T::ID, params)?;
    let (name, f) = integrand_of::<T>(variant)?;
    let samples = samples.unwrap_or(DEFAULT_REFERENCE_SAMPLES);
    if samples < 2 {
        return Err(ConfigError::invalid("--samples", samples, "at least 2 samples make a standard error"));
    }
    let domain = f.domain();
    let blocks = samples.div_ceil(BLOCK);
    let sums = crate::parallel::map_indices(blocks as usize, threads, |b| {
        let key = StreamKey { seed: 7, testbed: T::ID, estimator: name, budget: samples, rep: b as u64, integral: 0 };
        let mut rng = key.rng();
        let mut x = vec![0.0; domain.dim()];
        let (mut s, mut s2) = (0.0, 0.0);
        for _ in (b as u64 * BLOCK)..((b as u64 + 1) * BLOCK).min(samples) {
            domain.sample(&mut rng, &mut x);
            let v = domain.measure() * f.eval(&x);
            s += v;
            s2 += v * v;
        }
        (s, s2)
    });
    let (s, s2) = sums.iter().fold((0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    let n = samples as f64;
    let mean = s / n;
    let var = ((s2 - n * mean * mean) / (n - 1.0)).max(0.0);
    let key = key::<T>(name);
    let command = key.command() + &format!(" --samples {samples}");
    let reference = Reference {
        kind: ReferenceKind::Stored { command: command.clone(), samples },
        value: vec![Rgb([mean; 3])],
        std_err: vec![Rgb([(var / n).sqrt(); 3])],
    };
    reference.check(1).map_err(|e| ConfigError::invalid(format!("{}/{name} reference", T::ID), "computed", e))?;
    let stored = StoredReference {
        testbed: T::ID.into(),
        variant: name.into(),
        params: Default::default(),
        command,
        resolution: (1, 1),
        reference,
    };
    Ok((key, stored))
}

impl<T: IntegrandBed> TestBed for IntegrandTestBed<T> {
    fn id(&self) -> &'static str {
        T::ID
    }
    fn variant(&self) -> &str {
        self.variant
    }
    fn provides(&self) -> Needs {
        Needs::INTEGRAND
    }
    fn resolution(&self) -> (usize, usize) {
        (1, 1)
    }
    fn reference(&self) -> &Reference {
        &self.reference
    }
    fn reference_key(&self) -> Option<ReferenceKey> {
        (!self.reference.is_exact()).then(|| key::<T>(self.variant))
    }
    fn integrand(&self) -> Option<&dyn Integrand> {
        Some(&self.f)
    }
}
