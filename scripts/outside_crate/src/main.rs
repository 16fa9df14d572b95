//! A researcher's crate outside the mcbench workspace: one estimator, a biased copy of it and one
//! generic-integrand test bed, with the whole `mcbench` command line for them.
use mcbench::{Bias, Checks, EstimateError, Estimator, EstimatorEntry, Needs, Registry, Rgb, StreamRng, Task};
use mcbench_core::entry::TestBedEntry;
use mcbench_core::integrand::{Domain, Integrand};
use mcbench_core::integrand_bed::{self, IntegrandBed};
use mcbench_core::params::{parse, NoParams, ParamSpec};

/// On the unit cube, stratified sampling of the first coordinate (one point per stratum of the
/// sample budget); elsewhere plain MC. Times `scale` (1: unbiased; the biased copy: 2% too high).
struct Stratified(f64);
impl Estimator for Stratified {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let f = task.integrand().ok_or_else(|| EstimateError::Refused("needs an integrand".into()))?;
        let (domain, strata) = (f.domain(), task.budget().amount.max(1) as f64);
        let (mut x, mut sum, mut n) = (vec![0.0; domain.dim()], 0.0, 0.0);
        while task.more() {
            domain.sample(rng, &mut x);
            if let Domain::UnitCube(_) = domain {
                x[0] = (n % strata + x[0]) / strata;
            }
            sum += domain.measure() * f.eval(&x);
            n += 1.0;
        }
        Ok(Rgb([self.0 * sum / n; 3]))
    }
}

static STRATIFIED: EstimatorEntry = EstimatorEntry {
    id: "my_stratified",
    paper: "mine",
    label: "stratified MC",
    bias: Bias::Unbiased,
    needs: Needs::INTEGRAND,
    samplers: &[],
    summary: "stratified in the first coordinate",
    build: |p| parse::<NoParams>("my_stratified", p).map(|_| Box::new(Stratified(1.0)) as Box<dyn Estimator>),
    params: ParamSpec::NONE,
    checks: Checks::DEFAULT,
};

static BIASED: EstimatorEntry = EstimatorEntry {
    id: "my_stratified_biased",
    bias: Bias::Biased,
    label: "stratified MC, 2% too high",
    build: |p| parse::<NoParams>("my_stratified_biased", p).map(|_| Box::new(Stratified(1.02)) as Box<dyn Estimator>),
    ..STRATIFIED
};

/// `exp(x + y)` on the unit square: `(e - 1)^2`.
struct Exp;
impl Integrand for Exp {
    fn domain(&self) -> Domain {
        Domain::UnitCube(2)
    }
    fn eval(&self, x: &[f64]) -> f64 {
        (x[0] + x[1]).exp()
    }
    fn exact(&self) -> Option<f64> {
        Some((std::f64::consts::E - 1.0).powi(2))
    }
}

impl IntegrandBed for Exp {
    const ID: &'static str = "my-exp";
    const VARIANTS: &'static [&'static str] = &["default"];
    const SUMMARY: &'static str = "exp(x + y) on the unit square, exact";
    fn variant(_name: &str) -> Option<Self> {
        Some(Exp)
    }
}

static EXP: TestBedEntry = integrand_bed::entry::<Exp>(&integrand_bed::cases("default", 16));

fn main() {
    let registry = Registry::new().with_catalog(mcbench_papers::catalog());
    let registry = registry.with_estimator(&STRATIFIED).with_estimator(&BIASED).with_test_bed(&EXP);
    std::process::exit(mcbench::cli::main_with(registry));
}
