//! The registries of test beds and estimators: adding a plug-in is one new file plus one line in
//! [`ESTIMATORS`] or [`TESTBEDS`].

use crate::error::ConfigError;
use crate::estimator::{Bias, Estimator};
use crate::params::Params;
use crate::testbed::{Needs, TestBed};

/// Builds a configured estimator from its parameters.
pub type BuildEstimator = fn(&Params) -> Result<Box<dyn Estimator>, ConfigError>;

/// Builds a test-bed variant from its parameters.
pub type BuildTestBed = fn(&str, &Params) -> Result<Box<dyn TestBed>, ConfigError>;

/// The static description of an estimator and how to build it from parameters.
pub struct EstimatorEntry {
    /// Stable id used in files and plots.
    pub id: &'static str,
    /// The paper it comes from (`000`..`004`) or `harness` for controls.
    pub paper: &'static str,
    /// The label the paper's plots use.
    pub label: &'static str,
    /// What the paper claims of its expectation.
    pub bias: Bias,
    /// What it needs from a test bed.
    pub needs: Needs,
    /// The registered samplers it draws from (ids of `samplers::registry::SAMPLERS`): the
    /// conformance suite runs their chi-square tests for it (SPEC §6). Adaptive samplers internal
    /// to the estimator (cache cells, texel tables, PMC kernels, MH moves) are tested beside their
    /// code and not listed.
    pub samplers: &'static [&'static str],
    /// One line for `mcbench list estimators`.
    pub summary: &'static str,
    /// Builds a configured instance (validates the parameters).
    pub build: BuildEstimator,
}

/// The static description of a test bed.
pub struct TestBedEntry {
    /// Stable id.
    pub id: &'static str,
    /// Its variants; the first is the default.
    pub variants: &'static [&'static str],
    /// What it provides.
    pub provides: Needs,
    /// One line for `mcbench list testbeds`.
    pub summary: &'static str,
    /// Builds a variant (computes or loads its reference).
    pub build: BuildTestBed,
    /// Computes a stored long-run reference for a variant (`mcbench reference`), for variants
    /// without a closed form; `None` when every variant is exact.
    pub compute_reference: Option<ComputeReference>,
}

/// Computes a stored reference: `(variant, params, worker threads)` to a reference whose kind is
/// [`crate::testbed::ReferenceKind::Stored`], plus the resolution it was computed at.
pub type ComputeReference =
    fn(&str, &Params, usize) -> Result<(crate::testbed::Reference, (usize, usize)), ConfigError>;

/// Every registered estimator.
pub static ESTIMATORS: &[&EstimatorEntry] = &[
    &crate::independent::is0_cv0::ENTRY,
    &crate::independent::brdf_is0_cv0::ENTRY,
    &crate::independent::clamped_is0_cv0::ENTRY,
    &crate::smc_surface::is0_cv1::ENTRY,
    &crate::smc_surface::is0_cv2::ENTRY,
    &crate::smc_surface::is1_cv0::ENTRY,
    &crate::smc_surface::is1_cv1::ENTRY,
    &crate::smc_surface::is1_cv2::ENTRY,
    &crate::smc_surface::brdf_is1_cv2::ENTRY,
    &crate::media_smc::rm_is1_cv2::ENTRY,
    &crate::smc::bidirectional_is::ENTRY,
    &crate::smc::bidirectional_is_sn::ENTRY,
    &crate::smc::smc::ENTRY,
    &crate::smc::smc_bridge::ENTRY,
    &crate::smc::smc_path::ENTRY,
    &crate::smc::smc_adaptive::ENTRY,
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
];

/// Every registered test bed.
pub static TESTBEDS: &[&TestBedEntry] = &[
    &crate::testbeds::gradient_plane::ENTRY,
    &crate::testbeds::envmap_sequence::ENTRY,
    &crate::testbeds::checker::ENTRY,
    &crate::testbeds::checker_image::ENTRY,
    &crate::media::EQ21,
    &crate::media::PERLIN,
    &crate::testbeds::gradient_box::ENTRY,
    &crate::testbeds::canonical_1d::ENTRY,
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

impl TestBedEntry {
    /// Checks a variant name.
    pub fn check_variant(&self, variant: &str) -> Result<(), ConfigError> {
        if self.variants.contains(&variant) {
            Ok(())
        } else {
            Err(ConfigError::unknown("variant", &format!("{}/{variant}", self.id), self.variants.iter().copied()))
        }
    }
}

impl EstimatorEntry {
    /// Why this estimator cannot run on a test bed providing `provided`, if it cannot.
    pub fn skip_reason(&self, provided: Needs) -> Option<String> {
        self.needs.missing_from(provided).map(|m| format!("{} needs {m}, which the test bed does not provide", self.id))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
