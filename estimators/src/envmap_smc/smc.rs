//! `smc` (paper 004 Algorithm 1): the first frame by `bidirectional_is` (equal weights, normaliser
//! `mean(p~ / q)`), then per frame: incremental weights `p~_n / p~_{n-1}` (Eq. 3-4, log space),
//! `L_ns,n = L_ns,n-1 sum_j W_{n-1,j} w~_j` (Eq. 10), resampling when ESS < N/2, K MH moves of the
//! Eq. 6-8 mixture kernel, and `L_r` by Eq. 9. The product of Eq. 10 increments times the weighted
//! mean is the unbiased SMC estimate (Del Moral, Doucet and Jasra 2006), so the claim is unbiased.
//! Parameters: `moves` (K, default 5), `recompute` (every that many frames `L_ns` is estimated
//! afresh by bidirectional importance sampling with M candidates, paper 004 §7; default 0, never:
//! above 0 the estimate is consistent, the claim holds for the default),
//! `drift` (tau of the drift rule, [`super::drift`]: `L_ns` estimated afresh from
//! `recompute_candidates` M, default 1024, whenever the carried estimate moves more than
//! `e^tau` from the last explicit one; default 0, never; above 0 consistent) and the common ones
//! ([`super::params::SmcParams`]).

use super::engine::Transition;
use super::params::SmcParams;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::estimator::Bias;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "smc",
    paper: "004",
    label: "SMC (single distribution, K MH moves)",
    bias: Bias::Unbiased,
    needs: Needs::ENV_SEQUENCE,
    samplers: &[],
    summary: "Algorithm 1: propagate, reweight p~_n/p~_{n-1}, resample at ESS < N/2, K MH moves (`moves`, default 5)",
    build: |p| {
        let p = parse::<SmcParams>("smc", p)?;
        let transition = Transition::Single { moves: p.moves };
        Ok(Box::new(super::SmcEstimator(p.config("smc", transition)?)))
    },
    params: ParamSpec::of::<SmcParams>().display("SMC, one distribution").words(crate::words::param),
    checks: Checks::DEFAULT,
};
