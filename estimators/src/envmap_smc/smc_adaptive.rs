//! `smc_adaptive` (beyond paper 004): bridges as `smc_bridge`, but each next exponent chosen by
//! bisection so the conditional ESS of the incremental weights stays at `cess * N` (Zhou, Johansen
//! and Aston 2016), at most `max_bridges` per frame; the number used is noted as `bridges`. The
//! schedule depends on the particles, which makes the ratio estimate consistent rather than
//! exactly unbiased (the claim is `consistent`; the test decides). Parameters: `cess` (0.9),
//! `max_bridges` (32) and the common ones.

use super::engine::Transition;
use super::params::SmcAdaptiveParams;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::estimator::Bias;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "smc_adaptive",
    paper: "004+",
    label: "SMC, adaptive bridges (conditional ESS)",
    bias: Bias::Consistent,
    needs: Needs::ENV_SEQUENCE,
    samplers: &[],
    summary: "bridges chosen by bisection on the conditional ESS (`cess`, default 0.9; `max_bridges`, 32), ratio L_ns",
    build: |p| {
        let p = parse::<SmcAdaptiveParams>("smc_adaptive", p)?;
        let transition = Transition::Adaptive { cess: p.cess, max: p.max_bridges };
        Ok(Box::new(super::SmcEstimator(p.common().config("smc_adaptive", Some(transition))?)))
    },
    params: ParamSpec::of::<SmcAdaptiveParams>().display("SMC, adaptive bridges").words(crate::words::param),
    checks: Checks::DEFAULT,
};
