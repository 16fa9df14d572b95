//! `smc_adaptive` (beyond paper 004): bridges as `smc_bridge`, but each next exponent chosen by
//! bisection so the conditional ESS of the incremental weights stays at `cess * N` (Zhou, Johansen
//! and Aston 2016), at most `max_bridges` per frame; the number used is noted as `bridges`. The
//! schedule depends on the particles, which makes the ratio estimate consistent rather than
//! exactly unbiased (the claim is `consistent`; the test decides). Parameters: `cess` (0.9),
//! `max_bridges` (32) and the common ones.

use super::engine::Transition;
use crate::estimator::Bias;
use crate::registry::{Checks, EstimatorEntry};
use crate::testbed::Needs;

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
        let cess = p.f64_in("cess", 0.9, 0.01, 0.9999)?;
        let max = p.count("max_bridges", 32, 10_000)?;
        Ok(Box::new(super::SmcEstimator(super::config(
            p,
            "smc_adaptive",
            &["cess", "max_bridges"],
            128,
            Some(Transition::Adaptive { cess, max }),
        )?)))
    },
    checks: Checks::DEFAULT,
};
