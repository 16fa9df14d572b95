//! `smc_path` (paper 004 §5): as `smc_bridge`, but `log(L_ns,n / L_ns,n-1)` by path sampling,
//! `(1/P) sum_k sum_j W^k_j log(p~_n / p~_{n-1})(w^k_j)` (Eq. 15, the right Riemann sum of Eq. 13),
//! accumulated over frames (Eq. 16) and exponentiated. The exponential of an estimated log (and
//! the Riemann sum) makes it consistent, not unbiased: the claim is `consistent` and the test
//! decides. Parameters: `bridges` (P, default 5), `recompute` (every that many frames `L_ns` is
//! estimated afresh by bidirectional importance sampling with M candidates, paper 004 §7; default
//! 0, never),
//! `drift` (tau of the drift rule, [`super::drift`]: `L_ns` estimated afresh from
//! `recompute_candidates` M, default 1024, whenever the carried estimate moves more than
//! `e^tau` from the last explicit one; default 0, never; above 0 consistent) and the common ones.

use super::engine::Transition;
use super::params::SmcBridgeParams;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::estimator::Bias;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "smc_path",
    paper: "004",
    label: "SMC, P intermediate distributions (path sampling)",
    bias: Bias::Consistent,
    needs: Needs::ENV_SEQUENCE,
    samplers: &[],
    summary: "Algorithm 2 with L_ns by path sampling (Eq. 15-16): P bridges (`bridges`, default 5), exponentiated log estimate",
    build: |p| {
        let p = parse::<SmcBridgeParams>("smc_path", p)?;
        let transition = Transition::Bridged { bridges: p.bridges, path: true };
        Ok(Box::new(super::SmcEstimator(p.config("smc_path", transition)?)))
    },
    params: ParamSpec::of::<SmcBridgeParams>().display("SMC, path sampling").words(crate::words::param),
    checks: Checks::DEFAULT,
};
