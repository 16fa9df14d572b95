//! `bidirectional_is` (Burke, Ghosh and Heidrich 2005; paper 004 §2.1, the baseline of Fig. 1,
//! 4, 5): on every frame, M candidates from the environment map weighted `p~ / q`, N of them
//! resampled; `L_r = L^_ns * (1/N) sum (p~_c / p~) V` with `L^_ns = mean(p~ / q)`, and `L_ns` by
//! the Rao-Blackwellised `mean(p~_c / q)`. Both unbiased (the resampled set is properly weighted).

use super::params::BidirectionalParams;
use mcbench_core::entry::{Checks, EstimatorEntry};
use mcbench_core::estimator::Bias;
use mcbench_core::params::{parse, ParamSpec};
use mcbench_core::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "bidirectional_is",
    paper: "004",
    label: "bidirectional IS",
    bias: Bias::Unbiased,
    needs: Needs::ENV_SEQUENCE,
    samplers: &[],
    summary:
        "SIR: M environment-map candidates (`candidates`, default 128), N = budget resampled by BRDF cos, every frame",
    build: |p| {
        let p = parse::<BidirectionalParams>("bidirectional_is", p)?;
        Ok(Box::new(super::SmcEstimator(p.common().config("bidirectional_is", None)?)))
    },
    params: ParamSpec::of::<BidirectionalParams>().display("bidirectional IS").words(crate::words::param),
    checks: Checks::DEFAULT,
};
