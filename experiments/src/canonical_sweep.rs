//! `canonical-sweep`: every transmittance estimator on `canonical-1d` — seven analytic
//! extinction profiles x target transmittance {0.01, 0.1, 0.5, 0.9, 0.99} x sampling density
//! ratio `sigma_samp / max sigma_t` in {0.25, 0.5, 0.75, 1, 1.5, 2, 4, 8} — with the measured
//! variance beside paper 002's Eq. 16-20 prediction in every cell. The public harness of Georgiev
//! et al. 2019 sweeps majorants only and runs no statistical test; below ratio 1 the density is
//! not a majorant: the particle models take it, delta and ratio tracking refuse it (skipped pairs
//! with the reason), the terminating model refuses `r > 2/(a+1)`.
//!
//! Fixed-sample mode (the default): every estimate averages `N` rays, so variance x fetches per
//! estimate is the cost-normalised variance and the prediction is exact (`Var = V_ray / N`).
//! Equal-cost mode: a config file with `budget_kind = "fetches"` (see docs/src/paper-002.md); the harness buys
//! each estimate a fixed, pilot-calibrated number of rays, for which the prediction is exact too.
//!
//! Estimators (family key: what runs): `delta`, `ratio`, `double` (double particle), `double-cv-linear`
//! and `double-cv-mean` (control variate through explorer points: piecewise-linear fit, or the
//! constant at its mean, paper 002 §3.4's L2-optimal constant), `single-term`, `single-nonterm`,
//! each at every ratio; `residual-cv-linear` / `residual-cv-mean` (residual ratio tracking, its own
//! adaptive sigma_samp) and `ray-marching` (the biased control, step 0.5) once per test bed.

use crate::ExperimentDef;
use mcbench::config::{EstimatorSpec, Mode};
use mcbench_core::params::{ParamValue, Params};

/// Sampling density ratios `sigma_samp / max sigma_t`.
pub const RATIOS: [f64; 8] = [0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0, 8.0];

/// Step of the ray-marching control: two steps on the segment in both modes.
pub const RAY_MARCHING_STEP: f64 = 0.5;

/// Albedo of the test bed (its default; it only matters to the single particle models).
pub const ALBEDO: f64 = 0.7;

/// Every id the experiment runs.
pub const IDS: &[&str] = &[
    "delta_tracking",
    "ratio_tracking",
    "double_particle",
    "single_particle_terminating",
    "single_particle_nonterminating",
    "residual_ratio_tracking",
    "ray_marching",
];

/// One estimator family of the sweep (an id with its control variate).
pub struct Family {
    /// Stable key (file names, tables).
    pub key: &'static str,
    /// Short label for heat-map cells.
    pub short: &'static str,
    /// Registered id.
    pub id: &'static str,
    /// `control` parameter (None: not set).
    pub control: Option<f64>,
    /// Runs at every ratio (false: its own sigma_samp, one cell per test bed).
    pub swept: bool,
}

/// The families, in the order of the heat-map panels.
pub const FAMILIES: [Family; 10] = [
    Family { key: "delta", short: "DT", id: "delta_tracking", control: None, swept: true },
    Family { key: "ratio", short: "RT", id: "ratio_tracking", control: None, swept: true },
    Family { key: "double", short: "DP", id: "double_particle", control: None, swept: true },
    Family { key: "double-cv-linear", short: "DP+L", id: "double_particle", control: Some(1.0), swept: true },
    Family { key: "double-cv-mean", short: "DP+M", id: "double_particle", control: Some(2.0), swept: true },
    Family { key: "single-term", short: "ST", id: "single_particle_terminating", control: None, swept: true },
    Family { key: "single-nonterm", short: "SN", id: "single_particle_nonterminating", control: None, swept: true },
    Family {
        key: "residual-cv-linear",
        short: "RR+L",
        id: "residual_ratio_tracking",
        control: Some(1.0),
        swept: false,
    },
    Family { key: "residual-cv-mean", short: "RR+M", id: "residual_ratio_tracking", control: Some(2.0), swept: false },
    Family { key: "ray-marching", short: "RM", id: "ray_marching", control: None, swept: false },
];

/// The lowest ratio at which the terminating model is valid: `r = 1/ratio <= 2/(a+1)`.
pub fn terminating_min_ratio() -> f64 {
    (ALBEDO + 1.0) / 2.0
}

/// The spec of a family at a ratio (`None` for the unswept families).
pub fn spec(f: &Family, ratio: Option<f64>) -> EstimatorSpec {
    let mut params = Params::new();
    if let Some(c) = f.control {
        params = params.with("control", c);
    }
    if let Some(r) = ratio {
        params = params.with("sigma_samp_ratio", r);
    }
    if f.id == "ray_marching" {
        // Two steps on the segment, also under a fetch budget (an explicit step is kept there).
        params = params.with("step", RAY_MARCHING_STEP);
    }
    EstimatorSpec { id: f.id.to_string(), params }
}

/// The family index and ratio of a spec of this sweep.
pub fn family_of(spec: &EstimatorSpec) -> Option<(usize, Option<f64>)> {
    let num = |k: &str| match spec.params.0.get(k) {
        Some(ParamValue::Number(x)) => Some(*x),
        _ => None,
    };
    let f = FAMILIES.iter().position(|f| f.id == spec.id && f.control == num("control"))?;
    Some((f, num("sigma_samp_ratio")))
}

/// Rays per estimate and repetitions per mode.
pub fn sizes(mode: Mode) -> (u64, usize) {
    match mode {
        Mode::Quick => (32, 400),
        Mode::Full => (64, 2000),
    }
}

/// Definition.
pub static DEF: ExperimentDef = ExperimentDef {
    toml: include_str!("canonical_sweep.toml"),
    claims: None,
    post: Some(crate::canonical_sweep_post::post),
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sweep_names_every_family_and_ratio_once() {
        let s = DEF.experiment().sweep(&mcbench::Registry::empty(), Mode::Quick);
        assert_eq!(s.testbeds.len(), 35);
        let mut names: Vec<String> = s.estimators.iter().map(|e| e.name()).collect();
        // 6 swept families x 8 ratios + the terminating model at 5 ratios + 3 unswept.
        assert_eq!(names.len(), 6 * 8 + 5 + 3);
        names.sort();
        names.dedup();
        assert_eq!(names.len(), 6 * 8 + 5 + 3);
        for e in &s.estimators {
            let (f, r) = family_of(e).unwrap();
            assert_eq!(FAMILIES[f].swept, r.is_some(), "{}", e.name());
            assert_eq!(spec(&FAMILIES[f], r), *e);
        }
    }
}
