//! `smc_bridge` (paper 004 Algorithm 2): P intermediate distributions
//! `p~_{n-1}^(1-g) p~_n^g`, g = k/P (Eq. 11), one MH move each, incremental weights the product of
//! Eq. 12 (annealed importance sampling per particle), `L_ns` by the standard ratio (Eq. 10):
//! unbiased. Parameters: `bridges` (P, default 5), `recompute` (every that many frames `L_ns` is
//! estimated afresh by bidirectional importance sampling with M candidates, paper 004 §7; default
//! 0, never: above 0 the estimate is consistent, the claim holds for the default),
//! `drift` (tau of the drift rule, [`super::drift`]: `L_ns` estimated afresh from
//! `recompute_candidates` M, default 1024, whenever the carried estimate moves more than
//! `e^tau` from the last explicit one; default 0, never; above 0 consistent) and the common
//! ones.

use super::engine::Transition;
use super::params::SmcBridgeParams;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::estimator::Bias;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "smc_bridge",
    paper: "004",
    label: "SMC, P intermediate distributions (ratio)",
    bias: Bias::Unbiased,
    needs: Needs::ENV_SEQUENCE,
    samplers: &[],
    summary: "Algorithm 2: P bridges (`bridges`, default 5) with one MH move each, L_ns by the standard ratio (Eq. 10)",
    build: |p| {
        let p = parse::<SmcBridgeParams>("smc_bridge", p)?;
        let transition = Transition::Bridged { bridges: p.bridges, path: false };
        Ok(Box::new(super::SmcEstimator(p.config("smc_bridge", transition)?)))
    },
    params: ParamSpec::of::<SmcBridgeParams>().display("SMC, ratio").words(crate::words::param),
    checks: Checks::DEFAULT,
};
