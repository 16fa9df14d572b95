//! The conformance suite: every registered estimator goes through
//! `mcbench::conformance::Conformance` (builds, finite output or a clean refusal on the test beds'
//! stability cases, determinism for a seed, chi-square of its samplers, unbiasedness at a
//! small budget), so a new plug-in is covered without new test code.

use mcbench::analysis::UNBIASEDNESS_ALPHA;
use mcbench::conformance::{small_budget_unbiasedness, Conformance};
use mcbench_core::entry::EstimatorEntry;
use mcbench_papers::builtins;

#[test]
fn every_registered_estimator_conforms() {
    let suite = Conformance::new(registry()).expect("every test bed's cases build");
    let failures: Vec<String> =
        registry().estimators().iter().flat_map(|e| suite.check(e)).map(|f| f.to_string()).collect();
    assert!(failures.is_empty(), "{} conformance failures:\n{}", failures.len(), failures.join("\n"));
}

/// Teeth: the small-budget unbiasedness check flags the known-biased control (clamping the
/// integrand of independent MC) on the same kind of bed and budget the suite uses.
#[test]
fn the_small_budget_check_flags_the_biased_control() {
    let entry = builtins::estimator("clamped_is0_cv0").expect("registered");
    let est = (entry.build)(&Default::default()).expect("builds");
    let bed = (builtins::testbed("gradient-plane").expect("registered").build)(
        "default",
        &mcbench_core::params::Params::new().with("resolution", 2.0),
        &mcbench_core::references::NoReferences,
    )
    .expect("builds");
    let row = small_budget_unbiasedness(entry, est.as_ref(), bed.as_ref()).expect("the control runs");
    assert!(row.p_value < UNBIASEDNESS_ALPHA, "the biased control was not flagged: {} p = {}", row.test, row.p_value);
}

/// Teeth on the generic integrands: the same check flags their biased control
/// (`integrand_clamped_mc`) on every variant of both built-in integrand beds.
#[test]
fn the_small_budget_check_flags_the_integrand_control_on_every_integrand_bed() {
    let entry = builtins::estimator("integrand_clamped_mc").expect("registered");
    let est = (entry.build)(&Default::default()).expect("builds");
    for id in ["product-peak", "cosine-power"] {
        let bed_entry = builtins::testbed(id).expect("registered");
        for variant in bed_entry.variants {
            let bed = bed_entry.build_exact(variant, &Default::default()).expect("builds");
            let row = small_budget_unbiasedness(entry, est.as_ref(), bed.as_ref()).expect("the control runs");
            assert!(row.p_value < UNBIASEDNESS_ALPHA, "{id}/{variant}: not flagged, {} p = {}", row.test, row.p_value);
        }
    }
}

/// A registry entry that names a sampler the sampler registry does not have fails the suite: the
/// sampler check cannot pass vacuously.
#[test]
fn an_unregistered_sampler_name_fails_the_suite() {
    let real = builtins::estimator("is0_cv0").expect("registered");
    let entry = EstimatorEntry { samplers: &["no_such_sampler"], ..*real };
    let failures = Conformance::new(registry()).expect("builds").check(&entry);
    assert!(
        failures.iter().any(|f| f.check == "samplers" && f.detail.contains("no_such_sampler")),
        "{:?}",
        failures.iter().map(|f| format!("{}: {}", f.check, f.detail)).collect::<Vec<_>>()
    );
}

/// An estimator that carries state through a sequence (PMC-IP allocates an image's samples across
/// its pixels) but declares its integrals independent fails the suite: the declaration, which
/// gives the unbiasedness tests more power, is checked.
#[test]
fn a_false_independence_declaration_fails_the_suite() {
    use mcbench_core::estimator::Estimator;
    struct Claims(Box<dyn Estimator>);
    impl Estimator for Claims {
        fn estimate(
            &self,
            task: &mcbench_core::task::Task<'_>,
            rng: &mut mcbench_core::rng::StreamRng,
        ) -> Result<mcbench_core::math::Rgb, mcbench_core::error::EstimateError> {
            self.0.estimate(task, rng)
        }
        fn estimate_sequence(
            &self,
            tasks: &[mcbench_core::task::Task<'_>],
            rng: &mut mcbench_core::rng::StreamRng,
        ) -> Result<Vec<mcbench_core::math::Rgb>, mcbench_core::error::EstimateError> {
            self.0.estimate_sequence(tasks, rng)
        }
        fn integrals_independent(&self) -> bool {
            true
        }
        fn supports(&self, bed: &dyn mcbench_core::testbed::TestBed) -> Result<(), String> {
            self.0.supports(bed)
        }
    }
    let real = builtins::estimator("pmc_ip").expect("registered");
    let entry = EstimatorEntry {
        build: |p| Ok(Box::new(Claims((builtins::estimator("pmc_ip").expect("registered").build)(p)?))),
        samplers: &[],
        ..*real
    };
    let failures = Conformance::new(registry()).expect("builds").check(&entry);
    assert!(
        failures.iter().any(|f| f.check == "independence"),
        "{:?}",
        failures.iter().map(|f| format!("{}: {}", f.check, f.detail)).collect::<Vec<_>>()
    );
}

/// The registry of the `mcbench` binary, reading the repository's stored references.
fn registry() -> &'static mcbench::Registry {
    static REGISTRY: std::sync::OnceLock<mcbench::Registry> = std::sync::OnceLock::new();
    REGISTRY.get_or_init(|| {
        experiments::registry().with_references(mcbench::store::references::ReferenceDir::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../estimators/references"
        )))
    })
}

/// A sampler registered from a user's crate (`Registry::with_sampler`) is what the suite tests for
/// an estimator that names it: its failing chi-square check fails the estimator, its passing one
/// does not, and without the registration the name is unknown.
#[test]
fn a_users_sampler_gets_the_chi_square_check() {
    use mcbench_core::samplers::registry::SamplerEntry;
    use mcbench_core::stats::ChiSquare;
    fn outcome(p_value: f64) -> Vec<(String, ChiSquare)> {
        let c = ChiSquare { statistic: 1.0, dof: 9, p_value, cells: 10, merged_from: 10 };
        vec![("grid".to_string(), c)]
    }
    static BAD: SamplerEntry = SamplerEntry { id: "my_sampler", summary: "a wrong density", check: || outcome(1e-9) };
    static GOOD: SamplerEntry = SamplerEntry { id: "my_sampler", summary: "a right density", check: || outcome(0.4) };
    let real = builtins::estimator("is0_cv0").expect("registered");
    let entry = EstimatorEntry { samplers: &["my_sampler"], ..*real };
    let failures = |r: mcbench::Registry| -> Vec<String> {
        let suite = Conformance::new(&r).expect("builds");
        suite.check(&entry).into_iter().filter(|f| f.check == "samplers").map(|f| f.detail).collect()
    };
    let bad = failures(registry().clone().with_sampler(&BAD));
    assert!(bad.len() == 1 && bad[0].contains("my_sampler: grid"), "{bad:?}");
    assert!(failures(registry().clone().with_sampler(&GOOD)).is_empty());
    let unknown = failures(registry().clone());
    assert!(unknown.len() == 1 && unknown[0].contains("Registry::with_sampler"), "{unknown:?}");
}
