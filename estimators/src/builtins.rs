//! The built-in estimators and test beds: the one list of them. Adding one is one new file plus
//! one line here (book: extending.md).

use mcbench_core::entry::{EstimatorEntry, TestBedEntry};
use mcbench_core::error::ConfigError;
use mcbench_core::Catalog;

/// The built-in estimators and test beds with their stored references
/// ([`crate::built_in_references`]) and exported scenes ([`crate::export`]), to hand to a registry (`Registry::with_catalog`).
pub fn catalog() -> Catalog {
    Catalog::new(ESTIMATORS, TESTBEDS)
        .with_references(&crate::built_in_references::BUILT_IN)
        .with_exports(crate::export::EXPORTS)
}

/// Every built-in estimator, in the order `mcbench list estimators` shows them.
pub static ESTIMATORS: &[&EstimatorEntry] = &[
    &crate::independent::is0_cv0::ENTRY,
    &crate::independent::brdf_is0_cv0::ENTRY,
    &crate::independent::clamped_is0_cv0::ENTRY,
    &crate::surface_smc::is0_cv1::ENTRY,
    &crate::surface_smc::is0_cv2::ENTRY,
    &crate::surface_smc::is1_cv0::ENTRY,
    &crate::surface_smc::is1_cv1::ENTRY,
    &crate::surface_smc::is1_cv2::ENTRY,
    &crate::surface_smc::brdf_is1_cv2::ENTRY,
    &crate::media_smc::rm_is1_cv2::ENTRY,
    &crate::envmap_smc::bidirectional_is::ENTRY,
    &crate::envmap_smc::bidirectional_is_sn::ENTRY,
    &crate::envmap_smc::smc::ENTRY,
    &crate::envmap_smc::smc_bridge::ENTRY,
    &crate::envmap_smc::smc_path::ENTRY,
    &crate::envmap_smc::smc_adaptive::ENTRY,
    &crate::pmc::mis::ENTRY,
    &crate::pmc::hi::ENTRY,
    &crate::pmc::hi::FEEDBACK,
    &crate::pmc::uniform_image::ENTRY,
    &crate::pmc::ip::ENTRY,
    &crate::pmc::threshold_image::ENTRY,
    &crate::tracking::ray_marching::ENTRY,
    &crate::tracking::delta_tracking::ENTRY,
    &crate::tracking::ratio_tracking::ENTRY,
    &crate::tracking::residual_ratio_tracking::ENTRY,
    &crate::tracking::double_particle::ENTRY,
    &crate::tracking::single_particle::TERMINATING,
    &crate::tracking::single_particle::NONTERMINATING,
    &crate::tracking::spm::TERMINATING,
    &crate::tracking::spm::NONTERMINATING,
    &crate::tracking::spm::ADAPTIVE,
    &crate::single_scatter::attenuation_driven::ENTRY,
    &crate::single_scatter::attenuation_driven_sir::ENTRY,
    &crate::single_scatter::source_driven::ENTRY,
    &crate::single_scatter::scattering_driven::ENTRY,
    &crate::integrand_mc::MC,
    &crate::integrand_mc::ANTITHETIC,
    &crate::integrand_mc::CLAMPED,
];

/// Every built-in test bed.
pub static TESTBEDS: &[&TestBedEntry] = &[
    &crate::testbeds::gradient_plane::ENTRY,
    &crate::testbeds::envmap_sequence::ENTRY,
    &crate::testbeds::checker::ENTRY,
    &crate::testbeds::checker_image::ENTRY,
    &crate::testbeds::medium::EQ21,
    &crate::testbeds::medium::PERLIN,
    &crate::testbeds::gradient_box::ENTRY,
    &crate::testbeds::canonical_1d::ENTRY,
    &crate::testbeds::product_peak::ENTRY,
    &crate::testbeds::cosine_power::ENTRY,
];

/// Looks an estimator up by id.
pub fn estimator(id: &str) -> Result<&'static EstimatorEntry, ConfigError> {
    ESTIMATORS
        .iter()
        .copied()
        .find(|e| e.id == id)
        .ok_or_else(|| ConfigError::unknown("estimator", id, ESTIMATORS.iter().map(|e| e.id)))
}

/// Looks a test bed up by id.
pub fn testbed(id: &str) -> Result<&'static TestBedEntry, ConfigError> {
    TESTBEDS
        .iter()
        .copied()
        .find(|e| e.id == id)
        .ok_or_else(|| ConfigError::unknown("test bed", id, TESTBEDS.iter().map(|e| e.id)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::params::{ParamValue, Params};

    #[test]
    fn ids_are_unique_and_lookups_list_valid_names() {
        let mut ids: Vec<_> = ESTIMATORS.iter().map(|e| e.id).collect();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), ESTIMATORS.len());
        let err = estimator("nope").err().map(|e| e.to_string()).unwrap_or_default();
        assert!(err.contains("is0_cv0"), "{err}");
        assert!(testbed("gradient-plane").is_ok());
    }

    /// Every parameter of every estimator and test bed is documented, the defaults are valid, and
    /// an estimator builds from its resolved defaults given explicitly (its `params` spec is the
    /// one its `build` parses).
    #[test]
    fn parameters_are_documented_and_their_defaults_valid() {
        let specs = ESTIMATORS.iter().map(|e| (e.id, e.params)).chain(TESTBEDS.iter().map(|t| (t.id, t.params)));
        for (id, spec) in specs {
            for doc in (spec.describe)() {
                assert!(!doc.doc.trim().is_empty(), "{id}.{} has no doc", doc.name);
            }
            let resolved = (spec.resolve)(id, &Params::new());
            assert!(resolved.is_ok(), "{id}: {resolved:?}");
        }
        for e in ESTIMATORS {
            let resolved = (e.params.resolve)(e.id, &Params::new()).unwrap_or_default();
            let mut explicit = Params::new();
            for (name, v) in resolved.as_object().into_iter().flatten() {
                let value = match v {
                    serde_json::Value::Number(x) => ParamValue::Number(x.as_f64().unwrap_or(f64::NAN)),
                    serde_json::Value::String(t) => ParamValue::Text(t.clone()),
                    _ => continue,
                };
                explicit.0.insert(name.clone(), value);
            }
            let described: Vec<String> = (e.params.describe)().into_iter().map(|d| d.name).collect();
            assert!(explicit.0.keys().all(|k| described.contains(k)), "{}: {explicit:?} vs {described:?}", e.id);
            let built = (e.build)(&explicit).err();
            assert!(built.is_none(), "{} refuses its defaults {explicit:?}: {built:?}", e.id);
            let typo = (e.build)(&Params::new().with("no_such_parameter", 1.0)).err().map(|x| x.to_string());
            assert!(typo.is_some_and(|t| t.contains(&format!("{}.no_such_parameter", e.id))), "{}", e.id);
        }
    }
}
