//! The per-pixel variance tracker of paper 001 §4.5: which of the BRDF importance sampling
//! estimator (MCMC, constant variance) and the SMC estimator (`is1_cv2`, variance falling as the
//! cache adapts) currently has the lower variance.
//!
//! Both estimates of every sample are compared with the accumulated integral estimate (the running
//! mean of the contributed estimates). The BRDF estimator's squared deviations are averaged with
//! weights `1/n`; the SMC estimator's with weights `1/min(n, threshold)` — "clamping the total
//! number of estimates to a threshold value, hence making recent variance estimates more
//! influential" — with the threshold equal to the refinement criterion, as the paper recommends.
//! Squared deviations are averaged over the colour channels. Start-up uses the BRDF estimator
//! ("preferable upon start-up") until two samples have been seen.

use mcbench_core::accumulate::RgbMean;
use mcbench_core::math::Rgb;

/// Running variance estimates of the two estimators of one pixel.
#[derive(Clone, Debug)]
pub struct VarianceTracker {
    threshold: f64,
    integral: RgbMean,
    var_mcmc: f64,
    var_smc: f64,
}

impl VarianceTracker {
    /// A tracker whose SMC weights are clamped at `threshold` (>= 1) estimates.
    pub fn new(threshold: f64) -> Self {
        VarianceTracker { threshold: threshold.max(1.0), integral: RgbMean::new(), var_mcmc: 0.0, var_smc: 0.0 }
    }
    /// True when the next sample should come from the SMC estimator.
    pub fn prefers_smc(&self) -> bool {
        self.integral.count() >= 2 && self.var_smc < self.var_mcmc
    }
    /// Feeds both estimates of one sample and the one that contributed.
    pub fn update(&mut self, smc: Rgb, mcmc: Rgb, contributed: Rgb) {
        self.integral.push(contributed);
        let i = self.integral.mean();
        let dev = |x: Rgb| {
            let d = x - i;
            (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) / 3.0
        };
        let n = self.integral.count() as f64;
        self.var_mcmc += (dev(mcmc) - self.var_mcmc) / n;
        self.var_smc += (dev(smc) - self.var_smc) / n.min(self.threshold);
    }
    /// The current variance estimates `(mcmc, smc)`.
    pub fn variances(&self) -> (f64, f64) {
        (self.var_mcmc, self.var_smc)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn switches_to_the_lower_variance_and_forgets_old_smc_variance() {
        let mut t = VarianceTracker::new(8.0);
        assert!(!t.prefers_smc(), "BRDF sampling on start-up");
        // SMC noisy at first, then exact; MCMC steadily noisy.
        for k in 0..200 {
            let noise = if k % 2 == 0 { 1.0 } else { -1.0 };
            let smc = if k < 20 { Rgb::splat(1.0 + 5.0 * noise) } else { Rgb::splat(1.0) };
            t.update(smc, Rgb::splat(1.0 + noise), Rgb::splat(1.0 + noise));
            if k == 19 {
                assert!(!t.prefers_smc());
            }
        }
        assert!(t.prefers_smc(), "{:?}", t.variances());
        let (mcmc, smc) = t.variances();
        assert!((mcmc - 1.0).abs() < 0.2 && smc < 0.1, "{mcmc} {smc}");
    }
}
