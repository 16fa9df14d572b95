//! The estimator plug-in trait (book: extending.md) and the exact moments of one estimate an
//! estimator may report ([`EstimateMoments`]).

use crate::error::EstimateError;
use crate::math::Rgb;
use crate::rng::StreamRng;
use crate::task::Task;
use crate::testbed::TestBed;
use serde::{Deserialize, Serialize};

/// What the papers claim of an estimator's expectation (and what the harness then tests).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Bias {
    /// Expectation equals the integral at every budget.
    Unbiased,
    /// Only consistent (self-normalised ratios, exponentiated log estimates).
    Consistent,
    /// Biased by construction (controls such as ray marching or clamping).
    Biased,
}

impl Bias {
    /// The name used in tables.
    pub fn name(self) -> &'static str {
        match self {
            Bias::Unbiased => "unbiased",
            Bias::Consistent => "consistent",
            Bias::Biased => "biased",
        }
    }
}

/// An estimator: given a [`Task`] (one integral, one budget, counted access to the scene) and its
/// own random stream, return an estimate. Adaptive state lives inside one call.
///
/// A minimal estimator, the independent uniform-hemisphere average:
/// ```
/// use mcbench_core::{estimator::Estimator, error::EstimateError, math::{Frame, Rgb}, rng::StreamRng,
///                  samplers::uniform_hemisphere, task::Task};
///
/// struct Uniform;
/// impl Estimator for Uniform {
///     fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
///         let probe = task.hemisphere().ok_or(EstimateError::Refused("needs a surface".into()))?;
///         let frame = Frame::around(probe.point().normal);
///         let (mut sum, mut n) = (Rgb::ZERO, 0.0);
///         while task.more() {
///             let wi = frame.to_world(uniform_hemisphere::sample_local(rng));
///             sum += probe.integrand(wi) / uniform_hemisphere::pdf(1.0);
///             n += 1.0;
///         }
///         Ok(sum / n)
///     }
/// }
/// ```
pub trait Estimator: Send + Sync {
    /// One estimate of `task.integral()` spending `task.budget()` (loop while `task.more()`).
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError>;

    /// Estimates of a whole sequence of integrals (the frames of one pixel, see
    /// [`TestBed::sequence_length`]), in order, from one random stream: estimators that carry state
    /// from frame to frame (paper 004's SMC) override this. Each task still counts its own costs.
    /// The default estimates each task independently with [`Estimator::estimate`].
    fn estimate_sequence(&self, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
        tasks.iter().map(|t| self.estimate(t, rng)).collect()
    }

    /// What this configured estimator's expectation is, when a parameter changes it from the
    /// registry entry's `bias` (a reading of the paper that a parameter selects and that is biased,
    /// say); `None`, the default, keeps the entry's. The unbiasedness tests judge the estimator
    /// against this declaration.
    fn bias(&self) -> Option<Bias> {
        None
    }

    /// Whether the estimates of one sequence's integrals are independent of each other: no state
    /// (an adaptive structure, a sample allocation, particles) carried from one task to the next,
    /// as with the default [`Estimator::estimate_sequence`]. The unbiasedness tests then count
    /// each integral's test as an independent chance of finding a bias spread over the image
    /// (integrals of different sequences always are: each sequence has its own stream). The
    /// default, `false`, treats a sequence as one chance, which is never wrong, only less powerful.
    fn integrals_independent(&self) -> bool {
        false
    }

    /// Whether this configured estimator can run on `bed` beyond the static needs of its registry
    /// entry; `Err(reason)` makes the harness skip the pair and report the reason.
    fn supports(&self, _bed: &dyn TestBed) -> Result<(), String> {
        Ok(())
    }

    /// The exact moments of one sample (channel 0) of this configured estimator on `task`'s
    /// integral under `task`'s budget, where a theory gives them (paper 002 §3.4 for the
    /// transmittance trackers); `None` (the default) otherwise. An estimate averaging `n`
    /// independent samples has the moments [`EstimateMoments::mean_of`] of these.
    fn sample_moments(&self, _task: &Task<'_>) -> Option<EstimateMoments> {
        None
    }

    /// Whether this configuration is *valid* on `bed` (e.g. a terminating particle model whose
    /// sampling density makes `r > 2/(a+1)` somewhere): an error here is bad input (exit 2), not a
    /// skipped pair, because the user asked for something that cannot be computed.
    fn validate(&self, _bed: &dyn TestBed) -> Result<(), crate::error::ConfigError> {
        Ok(())
    }
}

/// Moments of one estimate: its mean and, relative to powers of the mean, its central second,
/// third, fourth and sixth moments (the fourth gives the error bar of a sample variance, the third
/// and sixth that sample variance's own skewness).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateMoments {
    /// `E[X]`.
    pub mean: f64,
    /// `Var[X] / E[X]^2`.
    pub rel_variance: f64,
    /// `E[(X - E X)^4] / E[X]^4`.
    pub rel_central4: f64,
    /// `E[(X - E X)^3] / E[X]^3`.
    pub rel_central3: f64,
    /// `E[(X - E X)^6] / E[X]^6`.
    pub rel_central6: f64,
}

impl EstimateMoments {
    /// `Var[X]`.
    pub fn variance(&self) -> f64 {
        self.rel_variance * self.mean * self.mean
    }
    /// A constant estimate (zero variance).
    pub fn constant(mean: f64) -> EstimateMoments {
        EstimateMoments { mean, rel_variance: 0.0, rel_central4: 0.0, rel_central3: 0.0, rel_central6: 0.0 }
    }
    /// The moments of the mean of `n` independent copies (the cumulant of order k scales as
    /// `n^(1 - k)`).
    pub fn mean_of(&self, n: f64) -> EstimateMoments {
        let (c2, c3, c4, c6) = (self.rel_variance, self.rel_central3, self.rel_central4, self.rel_central6);
        let k4 = c4 - 3.0 * c2 * c2;
        let k6 = c6 - 15.0 * c4 * c2 - 10.0 * c3 * c3 + 30.0 * c2 * c2 * c2;
        let (k2, k3, k4, k6) = (c2 / n, c3 / (n * n), k4 / n.powi(3), k6 / n.powi(5));
        EstimateMoments {
            mean: self.mean,
            rel_variance: k2,
            rel_central3: k3,
            rel_central4: (self.rel_central4 + 3.0 * (n - 1.0) * c2 * c2) / (n * n * n),
            rel_central6: k6 + 15.0 * k4 * k2 + 10.0 * k3 * k3 + 15.0 * k2 * k2 * k2,
        }
    }
    /// The skewness of the sample variance of `reps` independent copies, to leading order in
    /// `1/reps`: third cumulant `(mu6 - 3 mu4 mu2 - 6 mu3^2 + 2 mu2^3) / reps^2` over the variance
    /// `(mu4 - mu2^2) / reps` to the power 3/2 (`sqrt(8 / reps)` for normal estimates: the
    /// chi-square's skewness). 0 without spread.
    pub fn sample_variance_skewness(&self, reps: f64) -> f64 {
        let (m2, m3, m4, m6) = (self.rel_variance, self.rel_central3, self.rel_central4, self.rel_central6);
        let k3 = (m6 - 3.0 * m4 * m2 - 6.0 * m3 * m3 + 2.0 * m2 * m2 * m2) / (reps * reps);
        let var = ((m4 - m2 * m2) / reps).max(0.0);
        if var > 0.0 && k3.is_finite() {
            k3 / var.powf(1.5)
        } else {
            0.0
        }
    }
    /// The standard deviation of the (unbiased) sample variance of `reps` independent copies:
    /// `sqrt(mu4 / R - sigma^4 (R - 3) / (R (R - 1)))` (absolute units).
    pub fn sample_variance_sd(&self, reps: f64) -> f64 {
        let v = self.rel_variance;
        let rel = (self.rel_central4 / reps - v * v * (reps - 3.0) / (reps * (reps - 1.0))).max(0.0);
        rel.sqrt() * self.mean * self.mean
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sample variance's standard deviation against the normal case (mu4 = 3 sigma^4):
    /// `sigma^2 sqrt(2 / (R - 1))`; and averaging n copies divides the variance by n.
    #[test]
    fn sample_variance_error_bar_reduces_to_the_normal_case() {
        let normal = EstimateMoments {
            mean: 2.0,
            rel_variance: 0.01,
            rel_central4: 3e-4,
            rel_central3: 0.0,
            rel_central6: 15e-6,
        };
        let sd = normal.sample_variance_sd(101.0);
        assert!((sd / (0.04 * (2.0f64 / 100.0).sqrt()) - 1.0).abs() < 1e-12, "{sd}");
        let m = normal.mean_of(4.0);
        assert!((m.variance() - 0.01).abs() < 1e-15 && (m.rel_central4 - 3.0 * 0.0025f64.powi(2)).abs() < 1e-15);
    }

    /// The mean of n exponential estimates is Gamma(n)/n: its relative central moments are
    /// 1/n, 2/n^2, (3n + 6)/n^3 and (15 n^3 + 130 n^2 + 120 n)/n^6 (cumulants (j-1)! n / n^j);
    /// the sample variance of normal estimates has the chi-square's skewness sqrt(8 / R).
    #[test]
    fn higher_moments_of_a_mean_and_of_a_sample_variance() {
        let exp =
            EstimateMoments { mean: 1.0, rel_variance: 1.0, rel_central3: 2.0, rel_central4: 9.0, rel_central6: 265.0 };
        let n = 4.0;
        let g = exp.mean_of(n);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs();
        assert!(close(g.rel_variance, 1.0 / n));
        assert!(close(g.rel_central3, 2.0 / (n * n)));
        assert!(close(g.rel_central4, (3.0 * n + 6.0) / n.powi(3)));
        assert!(
            close(g.rel_central6, (15.0 * n.powi(3) + 130.0 * n * n + 120.0 * n) / n.powi(6)),
            "{}",
            g.rel_central6
        );
        let v: f64 = 0.01;
        let normal = EstimateMoments {
            mean: 3.0,
            rel_variance: v,
            rel_central3: 0.0,
            rel_central4: 3.0 * v * v,
            rel_central6: 15.0 * v.powi(3),
        };
        for reps in [16.0, 400.0] {
            assert!(close(normal.sample_variance_skewness(reps), (8.0 / reps).sqrt()));
        }
        // Heavy tails skew the sample variance far more: exponential estimates at 400 repetitions.
        assert!(exp.sample_variance_skewness(400.0) > 3.0 * normal.sample_variance_skewness(400.0));
        assert_eq!(EstimateMoments::constant(2.0).sample_variance_skewness(10.0), 0.0);
    }
}
