//! One file is enough: an estimator defined here (a throw-away one, registered with one call) is
//! planned from a config, runs, is in the `unbiasedness` experiment's parts on every test-bed case
//! whose needs it meets, goes through the conformance suite, and is listed with its parameters:
//! no id list anywhere has to name it.

use mcbench::config::{EstimatorSpec, Mode, Sweep, TestBedSpec};
use mcbench::{
    Bias, Checks, ConfigError, EstimateError, Estimator, EstimatorEntry, Needs, Registry, Rgb, StreamRng, Task,
};
use mcbench_core::math::{Frame, Vec3};
use mcbench_core::params::{check_range, parse, ParamSet, ParamSpec, Params};
use serde::{Deserialize, Serialize};

/// Uniform hemisphere sampling whose samples are weighted by `1 + tilt * z`: unbiased for any tilt
/// in [0, 1) since the weights are renormalised (a deliberately odd but correct estimator).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields, default)]
struct ThrowAwayParams {
    /// Strength of the polar tilt of the sampling density (0 to 0.9).
    tilt: f64,
}

impl ParamSet for ThrowAwayParams {
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        check_range("tilt", self.tilt, 0.0, 0.9).map(|_| ())
    }
}

struct ThrowAway(f64);

impl Estimator for ThrowAway {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        use rand::Rng;
        let probe = task.hemisphere().ok_or_else(|| EstimateError::Refused("needs a surface".into()))?;
        let frame = Frame::around(probe.point().normal);
        let (mut sum, mut n) = (Rgb::ZERO, 0.0);
        let norm = 2.0 * std::f64::consts::PI * (1.0 + self.0 / 2.0);
        while task.more() {
            // Density (1 + tilt z) / norm over the hemisphere, drawn by rejection from uniform.
            let local = loop {
                let (z, phi): (f64, f64) = (rng.gen(), std::f64::consts::TAU * rng.gen::<f64>());
                if rng.gen::<f64>() * (1.0 + self.0) <= 1.0 + self.0 * z {
                    let r = (1.0 - z * z).max(0.0).sqrt();
                    break Vec3::new(r * phi.cos(), r * phi.sin(), z);
                }
            };
            sum += probe.integrand(frame.to_world(local)) / ((1.0 + self.0 * local.z) / norm);
            n += 1.0;
        }
        Ok(sum / n)
    }
}

static THROW_AWAY: EstimatorEntry = EstimatorEntry {
    id: "throw_away",
    paper: "tests",
    label: "throw-away tilted sampling",
    bias: Bias::Unbiased,
    needs: Needs::SURFACE,
    samplers: &[],
    summary: "uniform-in-z hemisphere sampling tilted by 1 + tilt z",
    build: |p: &Params| Ok(Box::new(ThrowAway(parse::<ThrowAwayParams>("throw_away", p)?.tilt))),
    checks: Checks::DEFAULT,
    params: ParamSpec::of::<ThrowAwayParams>(),
};

fn registry() -> Registry {
    Registry::new().with_catalog(mcbench_papers::catalog()).with_estimator(&THROW_AWAY).with_references(
        mcbench::store::references::ReferenceDir::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../results/references")),
    )
}

#[test]
fn one_file_and_one_registration_are_enough() {
    let registry = registry();
    // Planned from a sweep naming it, with a typed parameter; a wrong one is refused by name.
    let sweep = |params: Params| Sweep {
        experiment: "throw-away".into(),
        testbeds: vec![TestBedSpec {
            id: "gradient-plane".into(),
            variant: Some("diffuse".into()),
            params: Params::new().with("resolution", 2.0),
        }],
        estimators: vec![EstimatorSpec { id: "throw_away".into(), params }],
        budgets: mcbench::config::powers_of_four(1..=3),
        reps: 8,
        seed: 1,
        mode: Mode::Quick,
        baseline: None,
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
    };
    let plan = mcbench::plan::Plan::prepare(sweep(Params::new().with("tilt", 0.5)), &registry).expect("plans");
    let bad = mcbench::plan::Plan::prepare(sweep(Params::new().with("tlit", 0.5)), &registry);
    assert!(bad.err().map(|e| e.to_string()).unwrap_or_default().contains("throw_away.tlit"));
    let opts =
        mcbench::run::runner::RunOptions { threads: Some(1), store: None, observer: &mcbench::run::runner::Silent };
    let run = mcbench::run::runner::run(&plan, &opts).expect("runs");
    assert_eq!(run.cells.len(), 3);
    // In the unbiasedness experiment wherever a case provides a surface, with nothing listing it.
    let parts = mcbench::unbiasedness::parts(&registry, Mode::Quick);
    let with_it: Vec<&str> = parts
        .iter()
        .filter(|p| p.sweep.estimators.iter().any(|e| e.id == "throw_away"))
        .flat_map(|p| p.sweep.testbeds.iter().map(|t| t.id.as_str()))
        .collect();
    assert!(with_it.contains(&"gradient-plane") && with_it.contains(&"checker-direct"), "{with_it:?}");
    // Through the conformance suite (its small-budget unbiasedness check included).
    let suite = mcbench::conformance::Conformance::new(&registry).expect("the cases build");
    let failures = suite.check(&THROW_AWAY);
    assert!(failures.is_empty(), "{failures:?}");
    // Listed with its parameter.
    let text = mcbench::output::listing::list(Some(mcbench::output::listing::What::Estimators), true, &registry);
    assert!(text.contains("throw_away") && text.contains("Strength of the polar tilt"), "{text}");
}
