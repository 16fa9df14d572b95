//! When the SMC estimators replace the carried `L_ns` by an explicit estimate (paper 004 §7: "we
//! tracked the incremental estimate of `L_ns` and explicitly computed `L_ns,n` using a large
//! number of samples whenever the ratio `L_ns,n / L_ns,1` altered significantly").
//!
//! Two rules, both off by default:
//! - `recompute` K: on every frame whose index is a multiple of K, with the `candidates` M;
//! - `drift` tau: on any propagated frame where the carried estimate has moved more than a factor
//!   `e^tau` either way from `L_ns` as last computed explicitly, `|ln(L_ns,n / L_ns,ref)| > tau`,
//!   with `recompute_candidates` M (default 1024; the paper's high-quality first frame uses
//!   M = 800). `L_ns,ref` is the paper's `L_ns,1` (the bidirectional estimate of the first frame)
//!   until the first re-estimate, then that re-estimate: the ratio is read against the last value
//!   computed explicitly, so after one re-estimate the rule waits for the carried product of
//!   increments to drift again instead of firing on every later frame of a changing map.
//!
//! A re-estimate is the unbiased `mean(p~ / q)` over M fresh environment-map candidates (M
//! target evaluations, counted); the particles and their weights stay.
//!
//! Bias. The carried product of Eq. 10 increments times the weighted particle mean is the unbiased
//! SMC estimate (`smc`, `smc_bridge`). A re-estimate multiplies the self-normalised particle mean
//! (bias O(1/N)) by an independent normaliser, so the estimate becomes consistent, not unbiased,
//! whichever rule fires it. The drift rule adds a second bias: it decides from the carried estimate
//! itself, so the frames where it does not fire keep `L_ns,n` only when it lies within `e^tau` of
//! the reference, a truncated carried normaliser whose mean is no longer `L_ns,n` (the carried
//! estimate is unbiased over all its outcomes, partly through rare large ones the truncation
//! removes). An unbiased rule would have to decide independently of the particles (a fixed
//! schedule or an independent pilot) and restart the particles with the normaliser (a fresh
//! bidirectional step); that is not the paper's rule and is not built. `smc_path` is consistent
//! with or without either rule (the exponential of an estimated log).

use super::engine::{candidates, Config};
use super::resampling::log_sum_exp;
use mcbench_core::rng::StreamRng;
use mcbench_core::task::EnvProbe;

/// The default `recompute_candidates`: a large M for the explicit computation (the paper's
/// high-quality first frame uses M = 800).
pub const DEFAULT_RECOMPUTE_CANDIDATES: usize = 1024;

/// Whether `L_ns` is estimated afresh on a propagated `frame` whose carried estimate is
/// `exp(log_z)` and whose last explicit one is `exp(log_ref)`, and with how many candidates:
/// the fixed schedule first (`recompute`, with `candidates`), then the drift rule (`drift`, with
/// `recompute_candidates`).
pub fn re_estimate(cfg: &Config, frame: usize, log_z: f64, log_ref: f64) -> Option<usize> {
    if cfg.recompute > 0 && frame.is_multiple_of(cfg.recompute) {
        return Some(cfg.candidates);
    }
    drifted(cfg.drift, log_z, log_ref).then_some(cfg.recompute_candidates)
}

/// The drift rule: `tau > 0` and `|log_z - log_ref| > tau` (a carried estimate of zero, or one
/// that is not a number, has drifted).
pub fn drifted(tau: f64, log_z: f64, log_ref: f64) -> bool {
    let moved = (log_z - log_ref).abs();
    tau > 0.0 && (moved.is_nan() || moved > tau)
}

/// The unbiased `log mean(p~ / q)` of M fresh environment-map candidates, replacing the carried
/// product of Eq. 10 (or Eq. 16) increments.
pub fn recomputed_log_normaliser(probe: &EnvProbe<'_>, m: usize, rng: &mut StreamRng) -> f64 {
    let (_, _, log_w, _) = candidates(probe, m, rng);
    log_sum_exp(&log_w) - (m as f64).ln()
}

#[cfg(test)]
#[path = "drift_tests.rs"]
mod tests;
