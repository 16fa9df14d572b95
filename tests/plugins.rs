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
        mcbench::store::references::ReferenceDir::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../estimators/references")),
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
        repetitions: Default::default(),
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

/// A diffuse point (albedo 0.8) under a white sky: `f / p = 1.6 cos(theta)` under uniform
/// hemisphere sampling never reaches the clamp 2 of the built-in control `clamped_is0_cv0`, which
/// is therefore unbiased here. Exact reference 0.8.
struct WhiteSky(mcbench::Reference);

impl mcbench_core::testbed::HemisphereScene for WhiteSky {
    fn shading(&self, _i: usize) -> mcbench_core::testbed::ShadingPoint {
        let brdf = mcbench_core::brdf::Phong { kd: Rgb([0.8; 3]), ks: Rgb::ZERO, n: 1.0 };
        mcbench_core::testbed::ShadingPoint { position: Vec3::default(), normal: Vec3::Z, wo: Vec3::Z, brdf }
    }
    fn incident(&self, _i: usize, _wi: Vec3) -> Rgb {
        Rgb([1.0; 3])
    }
}

impl mcbench::TestBed for WhiteSky {
    fn id(&self) -> &'static str {
        "white-sky"
    }
    fn variant(&self) -> &str {
        "default"
    }
    fn provides(&self) -> Needs {
        Needs::SURFACE
    }
    fn resolution(&self) -> (usize, usize) {
        (1, 1)
    }
    fn reference(&self) -> &mcbench::Reference {
        &self.0
    }
    fn hemisphere(&self) -> Option<&dyn mcbench_core::testbed::HemisphereScene> {
        Some(self)
    }
}

static WHITE_SKY: mcbench::TestBedEntry = mcbench::TestBedEntry {
    id: "white-sky",
    variants: &["default"],
    provides: Needs::SURFACE,
    summary: "a diffuse point under a white sky, exact",
    build: |_, _, _| {
        let exact = mcbench_core::testbed::ReferenceKind::Exact { method: "closed form".into(), bound: 1e-15 };
        Ok(Box::new(WhiteSky(mcbench::Reference { kind: exact, value: vec![Rgb([0.8; 3])], std_err: vec![Rgb::ZERO] })))
    },
    compute_reference: None,
    params: ParamSpec::NONE,
    cases: &[mcbench_core::entry::BedCase {
        variant: "default",
        params: &[],
        role: mcbench_core::entry::CaseRole::Unbiasedness { samples: 16, reps: (256, 2048) },
    }],
};

/// The control claim of a run of the built-in control on the built-in `gradient-plane` (where it is
/// biased) and a user's bed on which it is not: red without an exemption, held with one, whose
/// reason the table and the report show.
#[test]
fn an_exemption_from_the_users_crate_keeps_the_control_claim_honest() {
    const REASON: &str = "f/p never reaches the clamp under a white sky";
    let claim = |registry: Registry| {
        let dir = tempfile::tempdir().expect("tempdir");
        let root = dir.path();
        let (results, plots) = (root.join("results"), root.join("plots"));
        let args = [
            "mcbench",
            "run",
            "unbiasedness",
            "--estimators",
            "clamped_is0_cv0",
            "--testbeds",
            "white-sky,gradient-plane",
            "--threads",
            "2",
            "--results",
            results.to_str().expect("utf8"),
            "--plots",
            plots.to_str().expect("utf8"),
        ];
        assert_eq!(mcbench::cli::main_with_args(registry, args), 0);
        let csv = std::fs::read_to_string(results.join("unbiasedness/unbiasedness.csv")).expect("table");
        let report = std::fs::read_to_string(plots.join("unbiasedness/report.md")).expect("report");
        let line =
            report.lines().find(|l| l.contains("the biased control clamped_is0_cv0")).expect("claim").to_string();
        (csv, report, line)
    };
    let (csv, _, line) = claim(Registry::new().with_catalog(mcbench_papers::catalog()).with_test_bed(&WHITE_SKY));
    assert!(line.contains("not held") && line.contains("white-sky/default"), "{line}\n{csv}");
    let exempted = Registry::new().with_catalog(mcbench_papers::catalog()).with_test_bed(&WHITE_SKY).with_exemption(
        "clamped_is0_cv0",
        "white-sky",
        &["*"],
        REASON,
    );
    let (csv, report, line) = claim(exempted);
    assert!(line.contains(" held ") && !line.contains("not held"), "{line}\n{csv}");
    let row = csv.lines().find(|l| l.contains("white-sky")).expect("row");
    assert!(row.contains(REASON), "{row}");
    assert!(report.contains(REASON), "{report}");
}
