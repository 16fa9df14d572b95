//! Estimators with a known, injected bias, built on any estimator: the material the `calibration`
//! experiment measures the unbiasedness tests' power with.
//!
//! - [`Scaled`] multiplies every estimate by `1 + b`: a relative bias of exactly `b` (a wrong
//!   normalisation constant, a pdf off by a constant factor);
//! - [`FireflyRejection`] sets every channel value above a threshold to zero: the "firefly
//!   rejection" bug of renderers that drop rare large contributions, a negative bias that depends
//!   on the estimator's tail (the threshold is taken from a pilot's quantile, so the bias is what
//!   such a renderer would have).
//!
//! Both act on the estimates only, so on the same stream they give exactly the inner estimator's
//! estimates transformed by [`Scaled::apply`] / [`FireflyRejection::apply`]; the calibration applies
//! those transforms to one set of estimates to measure every bias level on the same repetitions.

use mcbench_core::error::{ConfigError, EstimateError};
use mcbench_core::estimator::Estimator;
use mcbench_core::math::Rgb;
use mcbench_core::rng::StreamRng;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;

/// An estimator whose estimates are `1 + b` times `inner`'s.
///
/// ```
/// use mcbench_core::{estimator::Estimator, error::EstimateError, math::Rgb, rng::StreamRng, task::Task};
/// use mcbench::calibration::Scaled;
///
/// struct Half;
/// impl Estimator for Half {
///     fn estimate(&self, _task: &Task<'_>, _rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
///         Ok(Rgb([0.5; 3]))
///     }
/// }
/// let biased = Scaled::new(Box::new(Half), 0.02);
/// assert!((biased.apply([0.5; 3])[0] - 0.51).abs() < 1e-15);
/// ```
pub struct Scaled {
    inner: Box<dyn Estimator>,
    factor: f64,
}

impl Scaled {
    /// `inner` with a relative bias `b`.
    pub fn new(inner: Box<dyn Estimator>, b: f64) -> Self {
        Scaled { inner, factor: 1.0 + b }
    }

    /// The transform it applies to one estimate.
    pub fn apply(&self, v: [f64; 3]) -> [f64; 3] {
        v.map(|x| x * self.factor)
    }
}

impl Estimator for Scaled {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        self.inner.estimate(task, rng).map(|v| Rgb(self.apply(v.0)))
    }

    fn estimate_sequence(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        Ok(self.inner.estimate_sequence(tasks, rng)?.into_iter().map(|v| Rgb(self.apply(v.0))).collect())
    }

    fn integrals_independent(&self) -> bool {
        self.inner.integrals_independent()
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        self.inner.supports(bed)
    }

    fn validate(&self, bed: &dyn TestBed) -> Result<(), ConfigError> {
        self.inner.validate(bed)
    }
}

/// An estimator that drops (sets to zero) every channel value of `inner`'s estimates above
/// `threshold`.
pub struct FireflyRejection {
    inner: Box<dyn Estimator>,
    threshold: f64,
}

impl FireflyRejection {
    /// `inner` with values above `threshold` dropped.
    pub fn new(inner: Box<dyn Estimator>, threshold: f64) -> Self {
        FireflyRejection { inner, threshold }
    }

    /// The transform it applies to one estimate.
    pub fn apply(&self, v: [f64; 3]) -> [f64; 3] {
        drop_above(v, self.threshold)
    }
}

/// Every channel value above `threshold` set to zero.
pub fn drop_above(v: [f64; 3], threshold: f64) -> [f64; 3] {
    v.map(|x| if x > threshold { 0.0 } else { x })
}

impl Estimator for FireflyRejection {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        self.inner.estimate(task, rng).map(|v| Rgb(self.apply(v.0)))
    }

    fn estimate_sequence(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        Ok(self.inner.estimate_sequence(tasks, rng)?.into_iter().map(|v| Rgb(self.apply(v.0))).collect())
    }

    fn integrals_independent(&self) -> bool {
        self.inner.integrals_independent()
    }
    fn supports(&self, bed: &dyn TestBed) -> Result<(), String> {
        self.inner.supports(bed)
    }

    fn validate(&self, bed: &dyn TestBed) -> Result<(), ConfigError> {
        self.inner.validate(bed)
    }
}

/// The `q`-quantile (nearest rank) of every channel value of `estimates`: the threshold of a
/// firefly rejection taken from a pilot.
pub fn quantile_threshold(estimates: &[Vec<[f64; 3]>], q: f64) -> f64 {
    let mut all: Vec<f64> = estimates.iter().flatten().flatten().copied().filter(|x| x.is_finite()).collect();
    if all.is_empty() {
        return f64::INFINITY;
    }
    all.sort_by(f64::total_cmp);
    let k = ((q * all.len() as f64).ceil() as usize).clamp(1, all.len()) - 1;
    all[k]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registry::Registry;
    use mcbench_core::budget::Budget;
    use mcbench_core::rng::StreamKey;

    /// On the same stream, the wrapped estimator gives exactly the transformed estimates of the
    /// inner one: what lets the calibration apply the transform instead of re-running.
    #[test]
    fn the_wrappers_equal_their_transform_on_the_same_stream() {
        let registry = Registry::new().with_catalog(mcbench_papers::catalog());
        let bed = registry.test_bed("gradient-plane").unwrap();
        let bed = (bed.build)(
            "default",
            &mcbench_core::params::Params::new().with("resolution", 2.0),
            &mcbench_core::references::NoReferences,
        )
        .unwrap();
        let entry = registry.estimator("is0_cv0").unwrap();
        let build = || (entry.build)(&mcbench_core::params::Params::new()).unwrap();
        let budget = Budget::samples(8).unwrap();
        let key = StreamKey { seed: 3, testbed: "t", estimator: "e", budget: 8, rep: 0, integral: 1 };
        let task = Task::new(bed.as_ref(), 1, budget);
        let plain = build().estimate(&task, &mut key.rng()).unwrap().0;
        let scaled = Scaled::new(build(), 0.03);
        assert_eq!(
            scaled.estimate(&Task::new(bed.as_ref(), 1, budget), &mut key.rng()).unwrap().0,
            scaled.apply(plain)
        );
        let t = plain[1];
        let fire = FireflyRejection::new(build(), t);
        let got = fire.estimate(&Task::new(bed.as_ref(), 1, budget), &mut key.rng()).unwrap().0;
        assert_eq!(got, drop_above(plain, t));
        assert_eq!(got[1], plain[1], "a value at the threshold is kept");
    }

    #[test]
    fn quantile_threshold_is_nearest_rank() {
        let v: Vec<Vec<[f64; 3]>> = (0..100).map(|i| vec![[i as f64; 3]]).collect();
        assert_eq!(quantile_threshold(&v, 0.99), 98.0);
        assert_eq!(quantile_threshold(&v, 1.0), 99.0);
        assert_eq!(quantile_threshold(&[], 0.5), f64::INFINITY);
    }
}
