//! The parameters of the paper 004 estimators. Every one takes the [`Common`] ones (`candidates`,
//! `cone`, `p_independent`, `resampling`, `threshold`), listed in each struct, plus its own.

use super::engine::{Config, Transition};
use super::mh::MhKernel;
use super::resampling::Scheme;
use mcbench_core::error::ConfigError;
use mcbench_core::params::{check_count, check_range, ParamSet};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The parameters every paper 004 estimator takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Common {
    /// Environment-map candidates per frame (M).
    pub candidates: usize,
    /// Half-angle of the MH kernel's local move, in degrees.
    pub cone: f64,
    /// Share of MH proposals drawn from the environment map.
    pub p_independent: f64,
    /// Resampling scheme: 0 multinomial, 1 residual, 2 stratified, 3 systematic.
    pub resampling: u32,
    /// Resample when the ESS falls below this share of the particles.
    pub threshold: f64,
}

impl Common {
    /// The defaults, with `candidates` M.
    pub const fn defaults(candidates: usize) -> Self {
        Common { candidates, cone: 3.0, p_independent: 0.5, resampling: 3, threshold: 0.5 }
    }

    /// The resampling scheme, or why the code names none.
    fn scheme(&self, owner: &str) -> Result<Scheme, ConfigError> {
        Scheme::from_code(self.resampling as usize).ok_or_else(|| {
            ConfigError::invalid(
                format!("{owner}.resampling"),
                self.resampling,
                "0 multinomial, 1 residual, 2 stratified, 3 systematic",
            )
        })
    }

    /// Checks the ranges: `candidates` 1 to 2^20, `cone` 1e-3 to 90, `p_independent` and
    /// `threshold` 0 to 1, `resampling` 0 to 3.
    pub fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        check_count("candidates", self.candidates, 1 << 20)?;
        check_range("cone", self.cone, 1e-3, 90.0)?;
        check_range("p_independent", self.p_independent, 0.0, 1.0)?;
        self.scheme(owner)?;
        check_range("threshold", self.threshold, 0.0, 1.0)?;
        Ok(())
    }

    /// The engine's configuration with this `transition` between frames (`None`: every frame by
    /// itself); refuses only a `resampling` code naming no scheme (the rest is [`Common::validate`]'s).
    pub fn config(&self, owner: &str, transition: Option<Transition>) -> Result<Config, ConfigError> {
        Ok(Config {
            candidates: self.candidates,
            kernel: MhKernel::new(self.cone, self.p_independent),
            scheme: self.scheme(owner)?,
            threshold: self.threshold,
            transition,
            recompute: 0,
            drift: 0.0,
            recompute_candidates: super::drift::DEFAULT_RECOMPUTE_CANDIDATES,
        })
    }
}

/// `recompute`: 0 (never) to 1000 frames (the longest sequence `envmap-sequence` makes).
fn check_recompute(k: usize) -> Result<(), ConfigError> {
    if k > 1000 {
        return Err(ConfigError::invalid("recompute", k, "must be a whole number in [0, 1000] (0: never)"));
    }
    Ok(())
}

/// `drift` 0 (never) to 50 and `recompute_candidates` 1 to 2^20.
fn check_drift(tau: f64, m: usize) -> Result<(), ConfigError> {
    check_range("drift", tau, 0.0, 50.0)?;
    check_count("recompute_candidates", m, 1 << 20)?;
    Ok(())
}

/// `common()`, the parameters every paper 004 estimator shares, for a parameter set that has them
/// as fields.
macro_rules! common_params {
    ($params:ty) => {
        impl $params {
            /// The common parameters.
            pub fn common(&self) -> Common {
                Common {
                    candidates: self.candidates,
                    cone: self.cone,
                    p_independent: self.p_independent,
                    resampling: self.resampling,
                    threshold: self.threshold,
                }
            }
        }
    };
}

/// Parameters of `bidirectional_is`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct BidirectionalParams {
    /// Environment-map candidates per frame, M (1 to 2^20).
    pub candidates: usize,
    /// Half-angle of the MH kernel's local move in degrees (1e-3 to 90; unused here: no MH moves).
    pub cone: f64,
    /// Share of MH proposals drawn from the environment map (0 to 1; unused here: no MH moves).
    pub p_independent: f64,
    /// Resampling scheme code, 0 to 3 (unused here: the N particles are drawn multinomially).
    pub resampling: u32,
    /// ESS share below which to resample, 0 to 1 (unused here: every frame resamples).
    pub threshold: f64,
}

impl Default for BidirectionalParams {
    fn default() -> Self {
        let c = Common::defaults(128);
        BidirectionalParams {
            candidates: c.candidates,
            cone: c.cone,
            p_independent: c.p_independent,
            resampling: c.resampling,
            threshold: c.threshold,
        }
    }
}

common_params!(BidirectionalParams);

impl ParamSet for BidirectionalParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        self.common().validate(owner)
    }
}

/// Parameters of `bidirectional_is_sn` (few candidates by default, to show its bias).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct BidirectionalSnParams {
    /// Environment-map candidates of each of the two sets, M (1 to 2^20; the self-normalisation bias
    /// shrinks like 1/M).
    pub candidates: usize,
    /// Half-angle of the MH kernel's local move in degrees (1e-3 to 90; unused: no MH moves).
    pub cone: f64,
    /// Share of MH proposals drawn from the environment map (0 to 1; unused: no MH moves).
    pub p_independent: f64,
    /// Resampling scheme code, 0 to 3 (unused: the control resamples multinomially).
    pub resampling: u32,
    /// ESS share below which to resample, 0 to 1 (unused: the control always resamples).
    pub threshold: f64,
}

impl Default for BidirectionalSnParams {
    fn default() -> Self {
        let c = Common::defaults(4);
        BidirectionalSnParams {
            candidates: c.candidates,
            cone: c.cone,
            p_independent: c.p_independent,
            resampling: c.resampling,
            threshold: c.threshold,
        }
    }
}

common_params!(BidirectionalSnParams);

impl ParamSet for BidirectionalSnParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        self.common().validate(owner)
    }
}

/// Parameters of `smc` (Algorithm 1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SmcParams {
    /// MH moves per frame, K (1 to 10000).
    pub moves: usize,
    /// Frames between re-estimates of `L_ns` from scratch by bidirectional importance sampling with
    /// the `candidates` M, instead of the carried product of ratios (paper 004 §7 recomputes it
    /// explicitly when the carried estimate drifts); the particles stay. 0 (the default): never;
    /// 0 to 1000. Above 0 the estimate is consistent, not unbiased (the self-normalised particle
    /// mean times an independent normaliser), and each re-estimate costs M target evaluations.
    pub recompute: usize,
    /// The drift rule's threshold tau: on any frame where the carried `L_ns` estimate is more than a
    /// factor `e^tau` from the last one computed explicitly (the first frame's, or the last
    /// re-estimate's), `L_ns` is estimated afresh from `recompute_candidates` environment-map
    /// candidates (paper 004 §7: "whenever the ratio L_ns,n / L_ns,1 altered significantly"); the
    /// particles stay. 0 (the default): never; 0 to 50. Above 0 the estimate is consistent, not
    /// unbiased (the decision reads the carried estimate itself; book: paper-004.md).
    pub drift: f64,
    /// Environment-map candidates M of a re-estimate the drift rule calls for (1 to 2^20, default
    /// 1024): M target evaluations each.
    pub recompute_candidates: usize,
    /// Environment-map candidates, M, of the bidirectional step that starts a pixel's sequence (and
    /// restarts it when every particle weight is zero); 1 to 2^20.
    pub candidates: usize,
    /// Half-angle of the MH kernel's local move in degrees (1e-3 to 90).
    pub cone: f64,
    /// Share of MH proposals drawn from the environment map (0 to 1).
    pub p_independent: f64,
    /// Resampling scheme: 0 multinomial, 1 residual, 2 stratified, 3 systematic.
    pub resampling: u32,
    /// Resample when the ESS falls below this share of the particles (0 to 1).
    pub threshold: f64,
}

impl Default for SmcParams {
    fn default() -> Self {
        let c = Common::defaults(128);
        SmcParams {
            moves: 5,
            recompute: 0,
            drift: 0.0,
            recompute_candidates: super::drift::DEFAULT_RECOMPUTE_CANDIDATES,
            candidates: c.candidates,
            cone: c.cone,
            p_independent: c.p_independent,
            resampling: c.resampling,
            threshold: c.threshold,
        }
    }
}

/// The engine's configuration (and the common parameters) of the SMC estimators' parameter sets
/// (the same fields but for their transition's own).
macro_rules! smc_config {
    ($params:ty) => {
        impl $params {
            /// The engine's configuration with this `transition`: the common parameters and both
            /// rules that estimate `L_ns` afresh (every `recompute` frames, and on drift).
            pub fn config(&self, owner: &str, transition: Transition) -> Result<Config, ConfigError> {
                let c = self.common().config(owner, Some(transition))?;
                Ok(Config {
                    recompute: self.recompute,
                    drift: self.drift,
                    recompute_candidates: self.recompute_candidates,
                    ..c
                })
            }
        }
        common_params!($params);
    };
}

smc_config!(SmcParams);
smc_config!(SmcBridgeParams);

impl ParamSet for SmcParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        check_count("moves", self.moves, 10_000)?;
        check_recompute(self.recompute)?;
        check_drift(self.drift, self.recompute_candidates)?;
        self.common().validate(owner)
    }
}

/// Parameters of `smc_bridge` and `smc_path` (Algorithm 2).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SmcBridgeParams {
    /// Intermediate distributions per frame, P, one MH move each (1 to 10000).
    pub bridges: usize,
    /// Frames between re-estimates of `L_ns` from scratch by bidirectional importance sampling with
    /// the `candidates` M, instead of the carried product of ratios (paper 004 §7 recomputes it
    /// explicitly when the carried estimate drifts); the particles stay. 0 (the default): never;
    /// 0 to 1000. Above 0 the estimate is consistent, not unbiased (the self-normalised particle
    /// mean times an independent normaliser), and each re-estimate costs M target evaluations.
    pub recompute: usize,
    /// The drift rule's threshold tau: on any frame where the carried `L_ns` estimate is more than a
    /// factor `e^tau` from the last one computed explicitly (the first frame's, or the last
    /// re-estimate's), `L_ns` is estimated afresh from `recompute_candidates` environment-map
    /// candidates (paper 004 §7: "whenever the ratio L_ns,n / L_ns,1 altered significantly"); the
    /// particles stay. 0 (the default): never; 0 to 50. Above 0 the estimate is consistent, not
    /// unbiased (the decision reads the carried estimate itself; book: paper-004.md).
    pub drift: f64,
    /// Environment-map candidates M of a re-estimate the drift rule calls for (1 to 2^20, default
    /// 1024): M target evaluations each.
    pub recompute_candidates: usize,
    /// Environment-map candidates, M, of the bidirectional step that starts a pixel's sequence (and
    /// restarts it when every particle weight is zero); 1 to 2^20.
    pub candidates: usize,
    /// Half-angle of the MH kernel's local move in degrees (1e-3 to 90).
    pub cone: f64,
    /// Share of MH proposals drawn from the environment map (0 to 1).
    pub p_independent: f64,
    /// Resampling scheme: 0 multinomial, 1 residual, 2 stratified, 3 systematic.
    pub resampling: u32,
    /// Resample when the ESS falls below this share of the particles (0 to 1).
    pub threshold: f64,
}

impl Default for SmcBridgeParams {
    fn default() -> Self {
        let c = Common::defaults(128);
        SmcBridgeParams {
            bridges: 5,
            recompute: 0,
            drift: 0.0,
            recompute_candidates: super::drift::DEFAULT_RECOMPUTE_CANDIDATES,
            candidates: c.candidates,
            cone: c.cone,
            p_independent: c.p_independent,
            resampling: c.resampling,
            threshold: c.threshold,
        }
    }
}

impl ParamSet for SmcBridgeParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        check_count("bridges", self.bridges, 10_000)?;
        check_recompute(self.recompute)?;
        check_drift(self.drift, self.recompute_candidates)?;
        self.common().validate(owner)
    }
}

/// Parameters of `smc_adaptive`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct SmcAdaptiveParams {
    /// Conditional ESS share each next exponent is chosen to keep (0.01 to 0.9999).
    pub cess: f64,
    /// Most bridges per frame (1 to 10000).
    pub max_bridges: usize,
    /// Environment-map candidates, M, of the bidirectional step that starts a pixel's sequence (and
    /// restarts it when every particle weight is zero); 1 to 2^20.
    pub candidates: usize,
    /// Half-angle of the MH kernel's local move in degrees (1e-3 to 90).
    pub cone: f64,
    /// Share of MH proposals drawn from the environment map (0 to 1).
    pub p_independent: f64,
    /// Resampling scheme: 0 multinomial, 1 residual, 2 stratified, 3 systematic.
    pub resampling: u32,
    /// Resample when the ESS falls below this share of the particles (0 to 1).
    pub threshold: f64,
}

impl Default for SmcAdaptiveParams {
    fn default() -> Self {
        let c = Common::defaults(128);
        SmcAdaptiveParams {
            cess: 0.9,
            max_bridges: 32,
            candidates: c.candidates,
            cone: c.cone,
            p_independent: c.p_independent,
            resampling: c.resampling,
            threshold: c.threshold,
        }
    }
}

common_params!(SmcAdaptiveParams);

impl ParamSet for SmcAdaptiveParams {
    fn validate(&self, owner: &str) -> Result<(), ConfigError> {
        check_range("cess", self.cess, 0.01, 0.9999)?;
        check_count("max_bridges", self.max_bridges, 10_000)?;
        self.common().validate(owner)
    }
}
