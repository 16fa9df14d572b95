//! The plan of an ingested run: the reference (a built-in test bed, or an image of the reference's
//! mean with its variance) and one estimator per manifest entry that replays its files. The
//! plan is what a run's analysis and outputs take ([`crate::run::execute::finish`]); its
//! estimators are never asked to estimate.

use super::image::Image;
use super::manifest::{BiasClaim, IngestEstimator, Manifest};
use crate::config::{EstimatorSpec, Mode, Sweep, TestBedSpec};
use crate::error::Result;
use crate::plan::{Plan, PreparedBed, PreparedEstimator};
use crate::registry::Registry;
use mcbench_core::budget::{Budget, BudgetKind};
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::error::EstimateError;
use mcbench_core::estimator::{Bias, Estimator};
use mcbench_core::math::Rgb;
use mcbench_core::params::ParamSpec;
use mcbench_core::rng::StreamRng;
use mcbench_core::task::Task;
use mcbench_core::testbed::{Needs, Reference, ReferenceKind, TestBed};

/// The test bed id of an image reference.
pub const IMAGE_BED: &str = "reference-image";

/// A reference given as an image of its mean and the per-pixel variance of that mean.
pub struct ImageBed {
    variant: String,
    width: usize,
    height: usize,
    reference: Reference,
}

impl ImageBed {
    /// The bed of `mean` with `variance` (same shape, checked by the caller); `name` is the image's
    /// path in the manifest (the bed's variant); `samples` are those the mean averaged (`None`:
    /// the variance is exact).
    pub fn new(name: &str, mean: Image, variance: &Image, samples: Option<u64>) -> ImageBed {
        let std_err = variance.pixels.iter().map(|v| Rgb(v.0.map(|x| x.max(0.0).sqrt()))).collect();
        let reference = Reference {
            kind: ReferenceKind::Stored {
                command: format!("the reference image {name}"),
                samples: samples.unwrap_or(u64::MAX),
            },
            value: mean.pixels,
            std_err,
        };
        ImageBed { variant: name.to_string(), width: mean.width, height: mean.height, reference }
    }
}

impl TestBed for ImageBed {
    fn id(&self) -> &'static str {
        IMAGE_BED
    }
    fn variant(&self) -> &str {
        &self.variant
    }
    fn provides(&self) -> Needs {
        Needs::NONE
    }
    fn resolution(&self) -> (usize, usize) {
        (self.width, self.height)
    }
    fn reference(&self) -> &Reference {
        &self.reference
    }
}

/// The estimator of an ingested series: its values come from files, so it never estimates.
struct Replay;

impl Estimator for Replay {
    fn estimate(&self, _task: &Task<'_>, _rng: &mut StreamRng) -> std::result::Result<Rgb, EstimateError> {
        Err(EstimateError::Refused("an ingested estimator's values are read from files".into()))
    }
}

fn build_replay(
    _: &mcbench_core::params::Params,
) -> std::result::Result<Box<dyn Estimator>, mcbench_core::error::ConfigError> {
    Ok(Box::new(Replay))
}

/// The registry entry of an ingested estimator (made once per estimator and process).
fn entry(e: &IngestEstimator) -> &'static EstimatorEntry {
    let bias = match e.bias {
        BiasClaim::Unbiased => Bias::Unbiased,
        BiasClaim::Biased => Bias::Biased,
        // Tested with no expectation: the tests' tables show it as `consistent`.
        BiasClaim::Unknown => Bias::Consistent,
    };
    Box::leak(Box::new(EstimatorEntry {
        id: Box::leak(e.id.clone().into_boxed_str()),
        paper: "ingested",
        label: Box::leak(format!("{} (read from files)", e.id).into_boxed_str()),
        bias,
        needs: Needs::NONE,
        samplers: &[],
        summary: "estimates another program wrote, read by `mcbench ingest`",
        build: build_replay,
        params: ParamSpec::NONE,
        checks: Checks::DEFAULT,
    }))
}

/// The bed of a manifest's built-in reference, built as a run builds it.
pub fn builtin_bed(m: &Manifest, registry: &Registry) -> Result<PreparedBed> {
    let r = &m.reference;
    let id = r.testbed.clone().unwrap_or_default();
    let spec = TestBedSpec { id: id.clone(), variant: r.variant.clone(), params: r.params.clone() };
    let entry = registry.test_bed(&id)?;
    let variant = spec.variant.clone().unwrap_or_else(|| entry.variants[0].to_string());
    entry.check_variant(&variant)?;
    let bed = (entry.build)(&variant, &spec.params, registry.references())?;
    let params_json = (entry.params.resolve)(entry.id, &spec.params)?.to_string();
    Ok(PreparedBed { spec, variant, bed, params_json })
}

/// The bed of an image reference.
pub fn image_bed(name: &str, bed: ImageBed) -> PreparedBed {
    let spec = TestBedSpec { id: IMAGE_BED.into(), variant: Some(name.into()), params: Default::default() };
    PreparedBed { spec, variant: name.into(), bed: Box::new(bed), params_json: "{}".into() }
}

/// The plan of a manifest over its bed: every estimator on the bed at the manifest's budgets.
pub fn plan(m: &Manifest, bed: PreparedBed) -> Plan {
    let estimators: Vec<PreparedEstimator> = m
        .estimators
        .iter()
        .map(|e| {
            let spec = EstimatorSpec::new(&e.id);
            PreparedEstimator {
                name: spec.name(),
                spec,
                entry: entry(e),
                estimator: Box::new(Replay),
                params_json: "{}".into(),
            }
        })
        .collect();
    let budgets = m.estimators[0].budgets.iter().map(|b| Budget { kind: BudgetKind::Samples, amount: b.samples });
    let sweep = Sweep {
        experiment: m.name.clone(),
        testbeds: vec![bed.spec.clone()],
        estimators: estimators.iter().map(|e| e.spec.clone()).collect(),
        budgets: budgets.collect(),
        reps: m.estimators.iter().flat_map(|e| e.budgets.iter().map(|b| b.reps)).max().unwrap_or(2),
        seed: 0,
        mode: Mode::Quick,
        baseline: m.baseline.clone(),
        claims: m.claims.clone(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    };
    let pairs = (0..estimators.len()).map(|ei| (0, ei)).collect();
    Plan { sweep, beds: vec![bed], estimators, pairs, skipped: Vec::new() }
}
