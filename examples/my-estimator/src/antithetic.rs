//! `antithetic_cosine`: cosine-weighted hemisphere sampling in antithetic pairs. Each direction
//! `(theta, phi)` is followed by `(theta, phi + 2 pi offset)`: both are cosine-distributed, so the
//! average of `f / p` over the budget is unbiased, and on integrands that vary smoothly with the
//! azimuth the pair's errors partly cancel.

use mcbench::{Bias, Checks, ConfigError, EstimateError, Estimator, EstimatorEntry, Needs, Rgb, StreamRng, Task};
use mcbench_core::math::{Frame, Vec3};
use mcbench_core::params::{check_range, parse, ParamSet, ParamSpec, Params};
use rand::Rng;
use serde::{Deserialize, Serialize};

/// Parameters of `antithetic_cosine`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
pub struct AntitheticParams {
    /// Azimuth offset of the second direction of a pair, in turns (0 to 1; 0.5 = opposite).
    pub offset: f64,
}

impl Default for AntitheticParams {
    fn default() -> Self {
        AntitheticParams { offset: 0.5 }
    }
}

impl ParamSet for AntitheticParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_range("offset", self.offset, 0.0, 1.0).map(|_| ())
    }
}

/// The registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "antithetic_cosine",
    paper: "example",
    label: "antithetic cosine sampling",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE,
    samplers: &["cosine_hemisphere"],
    summary: "cosine-weighted hemisphere sampling in antithetic azimuth pairs",
    build,
    checks: Checks::DEFAULT,
    params: ParamSpec::of::<AntitheticParams>(),
};

fn build(params: &Params) -> Result<Box<dyn Estimator>, ConfigError> {
    let p: AntitheticParams = parse(ENTRY.id, params)?;
    Ok(Box::new(Antithetic { offset: p.offset }))
}

/// The estimator.
pub struct Antithetic {
    offset: f64,
}

/// The cosine-distributed local direction of `(u, phi)`, and its density `cos(theta) / pi`.
fn cosine(u: f64, phi: f64) -> (Vec3, f64) {
    let r = u.sqrt();
    let cos = (1.0 - u).max(0.0).sqrt();
    (Vec3::new(r * phi.cos(), r * phi.sin(), cos), cos / std::f64::consts::PI)
}

impl Estimator for Antithetic {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.hemisphere().ok_or_else(|| EstimateError::Refused("needs a surface".into()))?;
        let frame = Frame::around(probe.point().normal);
        let (mut sum, mut n) = (Rgb::ZERO, 0u64);
        let tau = 2.0 * std::f64::consts::PI;
        'pairs: while task.more() {
            let (u, phi): (f64, f64) = (rng.gen(), tau * rng.gen::<f64>());
            for azimuth in [phi, phi + tau * self.offset] {
                if !task.more() {
                    break 'pairs;
                }
                // u < 1, so cos(theta) > 0 and the density is never zero.
                let (local, pdf) = cosine(u, azimuth);
                sum += probe.integrand(frame.to_world(local)) / pdf;
                n += 1;
            }
        }
        Ok(sum / n.max(1) as f64)
    }
}
