//! The conformance suite (issue 9 item 2): every registered estimator goes through
//! `mcbench::conformance::conformance` (builds, finite output or a clean refusal on the SPEC
//! §10 stability beds, determinism for a seed, chi-square of its samplers, unbiasedness at a small
//! budget), so a new plug-in is covered without new test code.

use estimators::registry::{self, ESTIMATORS};
use mcbench::analysis::UNBIASEDNESS_ALPHA;
use mcbench::conformance::{conformance, small_budget_unbiasedness};

#[test]
fn every_registered_estimator_conforms() {
    let failures: Vec<String> = ESTIMATORS.iter().flat_map(|e| conformance(e)).map(|f| f.to_string()).collect();
    assert!(failures.is_empty(), "{} conformance failures:\n{}", failures.len(), failures.join("\n"));
}

/// Teeth: the small-budget unbiasedness check flags the known-biased control (clamping the
/// integrand of independent MC) on the same kind of bed and budget the suite uses.
#[test]
fn the_small_budget_check_flags_the_biased_control() {
    let entry = registry::estimator("clamped_is0_cv0").expect("registered");
    let est = (entry.build)(&Default::default()).expect("builds");
    let bed = (registry::testbed("gradient-plane").expect("registered").build)(
        "default",
        &estimators::params::Params::new().with("resolution", 2.0),
    )
    .expect("builds");
    let row = small_budget_unbiasedness(entry, est.as_ref(), bed.as_ref()).expect("the control runs");
    assert!(row.p_value < UNBIASEDNESS_ALPHA, "the biased control was not flagged: {} p = {}", row.test, row.p_value);
}

/// A registry entry that names a sampler the sampler registry does not have fails the suite: the
/// sampler check cannot pass vacuously.
#[test]
fn an_unregistered_sampler_name_fails_the_suite() {
    let real = registry::estimator("is0_cv0").expect("registered");
    let entry = registry::EstimatorEntry { samplers: &["no_such_sampler"], ..*real };
    let failures = conformance(&entry);
    assert!(
        failures.iter().any(|f| f.check == "samplers" && f.detail.contains("no_such_sampler")),
        "{:?}",
        failures.iter().map(|f| format!("{}: {}", f.check, f.detail)).collect::<Vec<_>>()
    );
}
