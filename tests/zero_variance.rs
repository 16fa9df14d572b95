//! Zero and round-off variance as a case of its own: on a furnace-like plug-in test bed (a
//! constant sky over diffuse patches, exact reference `kd`), an estimator that returns the
//! reference at every repetition passes with a note that says so, one with a constant +2% error is
//! `biased`, their slopes read "exact at every budget" rather than a slope fitted to round-off, and
//! the exact estimator's speed-up over a noisy baseline is unbounded rather than a huge number.
//! A noisy unbiased estimator (uniform hemisphere sampling) keeps its ordinary verdict and slope.

use mcbench::analysis::{SlopeOutcome, SpeedUpOutcome, Spread};
use mcbench::config::{powers_of_four, EstimatorSpec, Mode, Sweep, TestBedSpec};
use mcbench::run::execute::{execute, ExecOptions};
use mcbench::run::runner::Silent;
use mcbench::{
    Bias, Checks, EstimateError, Estimator, EstimatorEntry, Needs, Reference, Registry, Rgb, StreamRng, Task, TestBed,
    TestBedEntry,
};
use mcbench_core::brdf::Phong;
use mcbench_core::math::{Frame, Vec3};
use mcbench_core::params::{ParamSpec, Params};
use mcbench_core::references::ReferenceSource;
use mcbench_core::samplers::{cosine_hemisphere, uniform_hemisphere};
use mcbench_core::testbed::{HemisphereScene, ReferenceKind, ShadingPoint};

/// Albedo of patch `i`.
fn albedo(i: usize) -> f64 {
    0.3 + 0.1 * i as f64
}

const PATCHES: usize = 6;

/// Diffuse patches of albedo 0.3, 0.4, ... under a sky of radiance 1 everywhere: each integral is
/// exactly its albedo.
struct Furnace {
    points: Vec<ShadingPoint>,
    reference: Reference,
}

static FURNACE: TestBedEntry = TestBedEntry {
    id: "furnace-patches",
    variants: &["white"],
    provides: Needs::SURFACE,
    summary: "diffuse patches under a constant sky, exact reference kd",
    build: |_variant: &str, _p: &Params, _refs: &dyn ReferenceSource| {
        let points: Vec<ShadingPoint> = (0..PATCHES)
            .map(|i| {
                let tilt = 0.2 * i as f64;
                let normal = Vec3::new(0.0, -f64::sin(tilt), f64::cos(tilt));
                let brdf = Phong { kd: Rgb([albedo(i); 3]), ks: Rgb::ZERO, n: 1.0 };
                ShadingPoint { position: Vec3::new(i as f64, 0.0, 0.0), normal, wo: normal, brdf }
            })
            .collect();
        let reference = Reference {
            kind: ReferenceKind::Exact { method: "constant sky: kd".into(), bound: 0.0 },
            value: (0..PATCHES).map(|i| Rgb([albedo(i); 3])).collect(),
            std_err: vec![Rgb::ZERO; PATCHES],
        };
        Ok(Box::new(Furnace { points, reference }) as Box<dyn TestBed>)
    },
    compute_reference: None,
    params: ParamSpec::NONE,
    cases: &[],
};

impl HemisphereScene for Furnace {
    fn shading(&self, i: usize) -> ShadingPoint {
        self.points[i]
    }
    fn incident(&self, _i: usize, _wi: Vec3) -> Rgb {
        Rgb([1.0; 3])
    }
}

impl TestBed for Furnace {
    fn id(&self) -> &'static str {
        FURNACE.id
    }
    fn variant(&self) -> &str {
        "white"
    }
    fn provides(&self) -> Needs {
        FURNACE.provides
    }
    fn resolution(&self) -> (usize, usize) {
        (PATCHES, 1)
    }
    fn reference(&self) -> &Reference {
        &self.reference
    }
    fn hemisphere(&self) -> Option<&dyn HemisphereScene> {
        Some(self)
    }
}

/// How a furnace estimator draws its directions and what it does with the mean.
#[derive(Clone, Copy)]
enum Kind {
    /// Returns the reference itself at every repetition (the integrand along the normal over its
    /// density there is `kd` for a diffuse patch under a constant sky).
    Exact,
    /// Cosine-weighted sampling: every sample is `kd` up to round-off, the mean too.
    Cosine,
    /// Cosine-weighted sampling off by a constant +2%.
    Off,
    /// Uniform hemisphere sampling: unbiased, with a spread.
    Uniform,
}

struct FurnaceEstimator(Kind);

impl Estimator for FurnaceEstimator {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.hemisphere().ok_or_else(|| EstimateError::Refused("needs a surface".into()))?;
        let normal = probe.point().normal;
        let frame = Frame::around(normal);
        let (mut sum, mut n) = (Rgb::ZERO, 0.0);
        while task.more() {
            let v = match self.0 {
                Kind::Exact => {
                    probe.integrand(normal);
                    probe.point().brdf.kd
                }
                Kind::Cosine | Kind::Off => {
                    let local = cosine_hemisphere::sample_local(rng);
                    probe.integrand(frame.to_world(local)) / cosine_hemisphere::pdf(local.z)
                }
                Kind::Uniform => {
                    let local = uniform_hemisphere::sample_local(rng);
                    probe.integrand(frame.to_world(local)) / uniform_hemisphere::pdf(local.z)
                }
            };
            sum += v;
            n += 1.0;
        }
        let mean = sum / n;
        Ok(match self.0 {
            Kind::Exact => probe.point().brdf.kd,
            Kind::Off => mean * 1.02,
            _ => mean,
        })
    }
}

const fn entry(id: &'static str, bias: Bias, build: mcbench_core::entry::BuildEstimator) -> EstimatorEntry {
    EstimatorEntry {
        id,
        paper: "tests",
        label: id,
        bias,
        needs: Needs::SURFACE,
        samplers: &[],
        summary: "a furnace estimator",
        build,
        checks: Checks::DEFAULT,
        params: ParamSpec::NONE,
    }
}

static EXACT: EstimatorEntry = entry("furnace_exact", Bias::Unbiased, |_| Ok(Box::new(FurnaceEstimator(Kind::Exact))));
static COSINE: EstimatorEntry =
    entry("furnace_cosine", Bias::Unbiased, |_| Ok(Box::new(FurnaceEstimator(Kind::Cosine))));
static OFF: EstimatorEntry = entry("furnace_off", Bias::Biased, |_| Ok(Box::new(FurnaceEstimator(Kind::Off))));
static UNIFORM: EstimatorEntry =
    entry("furnace_uniform", Bias::Unbiased, |_| Ok(Box::new(FurnaceEstimator(Kind::Uniform))));

fn registry() -> Registry {
    Registry::new()
        .with_catalog(mcbench_papers::catalog())
        .with_test_bed(&FURNACE)
        .with_estimator(&EXACT)
        .with_estimator(&COSINE)
        .with_estimator(&OFF)
        .with_estimator(&UNIFORM)
}

/// The summary.json text of a part of a report (NaN and the infinities are `null` there).
fn json<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).expect("serialises")
}

/// Runs the sweep into a temporary folder: its report, and the text of its `report.md`.
fn run() -> (mcbench::output::RunReport, String) {
    let registry = registry();
    let sweep = Sweep {
        experiment: "furnace".into(),
        testbeds: vec![TestBedSpec { id: FURNACE.id.into(), variant: Some("white".into()), params: Params::new() }],
        estimators: ["furnace_exact", "furnace_cosine", "furnace_off", "furnace_uniform"]
            .iter()
            .map(|id| EstimatorSpec::new(id))
            .collect(),
        budgets: powers_of_four(1..=4),
        reps: 16,
        seed: 7,
        mode: Mode::Quick,
        baseline: Some("furnace_uniform".into()),
        claims: Vec::new(),
        bias_tolerance: None,
        cost_model: Default::default(),
        repetitions: Default::default(),
    };
    let plan = mcbench::plan::Plan::prepare(sweep, &registry).expect("plans");
    let dir = tempfile::tempdir().expect("tempdir");
    let opts = ExecOptions {
        results_root: dir.path().join("results"),
        plots_root: dir.path().join("plots"),
        threads: Some(2),
        observer: &Silent,
        plots: true,
        wait: false,
        registry: &registry,
        integrals: Default::default(),
    };
    let out = execute(&plan, None, &opts).expect("runs");
    // What was written reads back with the same outcomes.
    let back = mcbench::output::read_results(&out.results_dir).expect("reads back");
    assert_eq!(json(&back.fits), json(&out.report.fits));
    assert_eq!(json(&back.speedups), json(&out.report.speedups));
    assert_eq!(json(&back.tests), json(&out.report.tests));
    let md = std::fs::read_to_string(out.plots_dir.join("report.md")).expect("report.md");
    (out.report, md)
}

#[test]
fn a_furnace_is_judged_by_direct_comparison() {
    let (report, md) = run();
    let decision = |est: &str| {
        report.tests.iter().find(|t| t.test == "combined" && t.estimator == est).expect("a combined row").clone()
    };
    let exact = decision("furnace_exact");
    assert_eq!(exact.verdict, "pass", "{exact:?}");
    assert_eq!(exact.spread, Spread::ZeroVariance, "{exact:?}");
    assert!(exact.reason.starts_with("zero variance: every repetition equal"), "{}", exact.reason);
    let cosine = decision("furnace_cosine");
    assert_eq!(cosine.verdict, "pass", "{cosine:?}");
    assert_eq!(cosine.spread, Spread::ZeroVariance, "{cosine:?}");
    assert!(cosine.reason.starts_with("zero variance: repetitions equal to round-off"), "{}", cosine.reason);
    let off = decision("furnace_off");
    assert_eq!((off.verdict.as_str(), off.agrees), ("biased", true), "{off:?}");
    assert_eq!(off.spread, Spread::ZeroVariance, "{off:?}");
    assert!((off.rel_bias - 0.02).abs() < 1e-9, "{off:?}");
    let uniform = decision("furnace_uniform");
    assert_eq!(uniform.spread, Spread::Sampled, "{uniform:?}");
    assert_ne!(uniform.verdict, "biased", "{uniform:?}");

    let fit = |est: &str| report.fits.iter().find(|f| f.estimator == est).cloned();
    // The exact estimator's RMSE is zero at every budget: no slope, an exact outcome.
    let exact_fit = fit("furnace_exact").expect("an exact outcome is listed");
    assert_eq!(exact_fit.outcome, SlopeOutcome::Exact, "{exact_fit:?}");
    assert!(exact_fit.slope.is_nan() && exact_fit.slope_right.is_nan(), "{exact_fit:?}");
    // Cosine sampling's RMSE is round-off at every budget: exact too, not a slope fitted to it.
    let cosine_fit = fit("furnace_cosine").expect("an exact outcome is listed");
    assert_eq!(cosine_fit.outcome, SlopeOutcome::Exact, "{cosine_fit:?}");
    assert!(cosine_fit.slope.is_nan(), "{cosine_fit:?}");
    // The constant error is a bias that does not fall: a slope of zero, fitted.
    let off_fit = fit("furnace_off").expect("fitted");
    assert_eq!(off_fit.outcome, SlopeOutcome::Fitted, "{off_fit:?}");
    assert!(off_fit.slope.abs() < 0.01, "{off_fit:?}");
    let uniform_fit = fit("furnace_uniform").expect("fitted");
    assert_eq!(uniform_fit.outcome, SlopeOutcome::Fitted);
    assert!((uniform_fit.slope + 0.5).abs() < 0.2, "{uniform_fit:?}");

    let speedup = |est: &str| report.speedups.iter().find(|s| s.estimator == est).cloned();
    for est in ["furnace_exact", "furnace_cosine"] {
        let s = speedup(est).expect("an unbounded speed-up is listed");
        assert_eq!(s.outcome, SpeedUpOutcome::Unbounded, "{s:?}");
        assert!(s.speedup.is_infinite() || s.speedup.is_nan(), "{s:?}");
    }
    // The report prints the outcomes, not numbers made of rounding errors.
    assert!(md.contains("exact at every budget") && md.contains("unbounded (exact)"), "{md}");
    let mut cells = md.lines().flat_map(|l| l.split('|')).map(str::trim);
    assert!(!cells.any(|c| c == "inf" || c.parse::<f64>().is_ok_and(|x| x > 1e12)), "{md}");
    let off = speedup("furnace_off").expect("measured");
    assert_eq!(off.outcome, SpeedUpOutcome::Measured, "{off:?}");
    assert!(off.speedup.is_finite() && off.speedup < 1e3, "{off:?}");
}
