//! The registry entries of estimators and test beds: the static description of a plug-in and how
//! to build it from parameters. A crate hands a set of them over as a [`crate::Catalog`].

use crate::error::ConfigError;
use crate::estimator::{Bias, Estimator};
use crate::params::{ParamSpec, Params};
use crate::references::{ReferenceKey, ReferenceSource, StoredReference};
use crate::testbed::{Needs, TestBed};

/// Builds a configured estimator from its parameters.
pub type BuildEstimator = fn(&Params) -> Result<Box<dyn Estimator>, ConfigError>;

/// Builds a test-bed variant from its parameters, looking a stored reference up in the source
/// given when it has no closed form.
pub type BuildTestBed = fn(&str, &Params, &dyn ReferenceSource) -> Result<Box<dyn TestBed>, ConfigError>;

/// The static description of an estimator and how to build it from parameters.
pub struct EstimatorEntry {
    /// Stable id used in files and plots.
    pub id: &'static str,
    /// The paper it comes from (`000`..`004`) or `harness` for controls.
    pub paper: &'static str,
    /// The label the paper's plots use.
    pub label: &'static str,
    /// What the paper claims of its expectation.
    pub bias: Bias,
    /// What it needs from a test bed.
    pub needs: Needs,
    /// The registered samplers it draws from (ids of `samplers::registry::SAMPLERS`): the
    /// conformance suite runs their chi-square tests for it (book: conformance.md). Adaptive samplers internal
    /// to the estimator (cache cells, texel tables, PMC kernels, MH moves) are tested beside their
    /// code and not listed.
    pub samplers: &'static [&'static str],
    /// One line for `mcbench list estimators`.
    pub summary: &'static str,
    /// Builds a configured instance (validates the parameters).
    pub build: BuildEstimator,
    /// Its parameters (`mcbench list estimators --params`).
    pub params: ParamSpec,
    /// How the harness's unbiasedness checks run it.
    pub checks: Checks,
}

/// How the unbiasedness checks (the `unbiasedness` experiment) run an estimator.
#[derive(Clone, Copy, Debug)]
pub struct Checks {
    /// Its parameters there, as (name, value) pairs (empty: its defaults). A biased control is
    /// given parameters that make its bias large enough to be found (ray marching with a coarse
    /// step, a self-normalised estimator with few candidates).
    pub params: &'static [(&'static str, f64)],
    /// For a biased control: the test beds on which it is unbiased by construction, or biased too
    /// little to be required to be flagged, with why.
    pub exempt: &'static [Exemption],
}

impl Checks {
    /// Default parameters, no exemption.
    pub const DEFAULT: Checks = Checks { params: &[], exempt: &[] };
}

/// Variants of a test bed on which a biased control need not be flagged, and why.
#[derive(Clone, Copy, Debug)]
pub struct Exemption {
    /// Test-bed id.
    pub testbed: &'static str,
    /// Variants it covers (`prefix*`, `*suffix` or an exact name).
    pub variants: &'static [&'static str],
    /// Why (shown in the unbiasedness table).
    pub reason: &'static str,
}

impl Exemption {
    /// Whether it covers `testbed/variant`.
    pub fn covers(&self, testbed: &str, variant: &str) -> bool {
        self.testbed == testbed
            && self.variants.iter().any(|v| match (v.strip_suffix('*'), v.strip_prefix('*')) {
                (Some(prefix), _) => variant.starts_with(prefix),
                (_, Some(suffix)) => variant.ends_with(suffix),
                _ => *v == variant,
            })
    }
}

/// A small configuration of a test bed that the harness's checks run estimators on.
#[derive(Clone, Copy, Debug)]
pub struct BedCase {
    /// Variant.
    pub variant: &'static str,
    /// Parameters, as (name, value) pairs.
    pub params: &'static [(&'static str, f64)],
    /// What it is for.
    pub role: CaseRole,
}

/// What a [`BedCase`] is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CaseRole {
    /// An extreme case (book: stability.md) of the conformance suite: every estimate is finite or a clean
    /// one-line refusal.
    Stability,
    /// A small case with an exact or stored reference for the conformance suite's quick
    /// unbiasedness check (4 samples per estimate, about 8000 estimates).
    Check,
    /// A case of the `unbiasedness` experiment: every estimator that runs on it, at `samples` per
    /// estimate, with `reps` repetitions (quick, full). Cases of equal samples and repetitions run
    /// as one part. Quick repetitions of 0 leave the case out of the quick mode (for a case no
    /// row of which can decide at a quick size; the declaring constant says why): it runs in
    /// the full mode only.
    Unbiasedness {
        /// Samples per estimate.
        samples: u64,
        /// Repetitions: (quick, full); 0 quick repetitions: the full mode only.
        reps: (usize, usize),
    },
}

impl CaseRole {
    /// Whether an `unbiasedness` case runs in the full mode only (0 quick repetitions).
    pub fn full_only(&self) -> bool {
        matches!(self, CaseRole::Unbiasedness { reps: (0, _), .. })
    }
}

impl BedCase {
    /// Its parameters as [`Params`].
    pub fn params(&self) -> Params {
        self.params.iter().fold(Params::new(), |p, (k, v)| p.with(k, *v))
    }
}

/// The static description of a test bed.
pub struct TestBedEntry {
    /// Stable id.
    pub id: &'static str,
    /// Its variants; the first is the default.
    pub variants: &'static [&'static str],
    /// What it provides.
    pub provides: Needs,
    /// One line for `mcbench list testbeds`.
    pub summary: &'static str,
    /// Builds a variant (computes or loads its reference).
    pub build: BuildTestBed,
    /// Computes the reference of a variant to store (`mcbench reference`), for variants without a
    /// closed form (or too costly to compute at every run); `None` when every variant is exact.
    pub compute_reference: Option<ComputeReference>,
    /// Its parameters (`mcbench list testbeds --params`).
    pub params: ParamSpec,
    /// The small configurations the harness's checks run estimators on.
    pub cases: &'static [BedCase],
}

/// Computes a reference to store: `(variant, params, samples per value (None: the test bed's
/// default), worker threads)` to its key and the reference with the command that made it and the
/// resolution. The result does not depend on the thread count.
pub type ComputeReference =
    fn(&str, &Params, Option<u64>, usize) -> Result<(ReferenceKey, StoredReference), ConfigError>;

impl TestBedEntry {
    /// The name shown in titles and tables: [`ParamSpec::display`], else the id.
    pub fn display_name(&self) -> &'static str {
        self.params.display.unwrap_or(self.id)
    }

    /// Builds a variant whose reference needs no stored file (closed forms and quadratures): `build`
    /// with [`crate::references::NoReferences`].
    pub fn build_exact(&self, variant: &str, params: &Params) -> Result<Box<dyn TestBed>, ConfigError> {
        (self.build)(variant, params, &crate::references::NoReferences)
    }

    /// Checks a variant name.
    pub fn check_variant(&self, variant: &str) -> Result<(), ConfigError> {
        if self.variants.contains(&variant) {
            Ok(())
        } else {
            Err(ConfigError::unknown("variant", &format!("{}/{variant}", self.id), self.variants.iter().copied()))
        }
    }
}

impl EstimatorEntry {
    /// The name shown in legends and tables: [`ParamSpec::display`], else the label.
    pub fn display_name(&self) -> &'static str {
        self.params.display.unwrap_or(self.label)
    }

    /// Why this estimator cannot run on a test bed providing `provided`, if it cannot.
    pub fn skip_reason(&self, provided: Needs) -> Option<String> {
        self.needs.missing_from(provided).map(|m| format!("{} needs {m}, which the test bed does not provide", self.id))
    }
}
