//! The suite's names in plots: estimator ids and test beds in the papers' vocabulary, with their
//! parameters spelled out (`smc_path[bridges=5]` -> "SMC, path sampling, 5 bridges",
//! `is1_cv2` -> "IS1 CV2 (SMC cache)"), handed to the harness as its display-name hook
//! ([`DISPLAY`], registered by [`crate::registry`]). An id or parameter not listed here is left to
//! the harness's fallback (the registered label, or the id).

use mcbench::output::plot::DisplayNames;

/// The hook the suite's registry carries.
pub const DISPLAY: DisplayNames = DisplayNames { estimator: Some(estimator), testbed: Some(testbed) };

/// The base name of an estimator id.
fn base(id: &str) -> Option<&'static str> {
    Some(match id {
        // Paper 001 (surfaces) and paper 000 (media): the SMC radiance cache.
        // The papers call it "MCMC"; the legend says what it is (book: testbeds.md).
        "is0_cv0" => "independent MC (papers' MCMC)",
        "brdf_is0_cv0" => "BRDF sampling (IS0 CV0)",
        "clamped_is0_cv0" => "clamped independent MC (biased control)",
        "is0_cv1" => "IS0 CV1 (SMC cache)",
        "is0_cv2" => "IS0 CV2 (SMC cache)",
        "is1_cv0" => "IS1 CV0 (SMC cache)",
        "is1_cv1" => "IS1 CV1 (SMC cache)",
        "is1_cv2" => "IS1 CV2 (SMC cache)",
        "brdf_is1_cv2" => "BRDF or IS1 CV2 by variance (SMC cache)",
        "rm_is1_cv2" => "ray marching + IS1 CV2 (biased control)",
        // Paper 002: transmittance and particle tracing in media.
        "delta_tracking" => "delta tracking",
        "ratio_tracking" => "ratio tracking",
        "residual_ratio_tracking" => "residual ratio tracking",
        "ray_marching" => "ray marching (biased control)",
        "double_particle" => "double particle",
        "single_particle_terminating" => "single particle, terminating",
        "single_particle_nonterminating" => "single particle, non-terminating",
        "spm_terminating" => "SPM terminating",
        "spm_nonterminating" => "SPM non-terminating",
        "spm_adaptive" => "SPM adaptive",
        "source_driven" => "source-driven",
        "attenuation_driven" => "attenuation-driven",
        "attenuation_driven_sir" => "attenuation-driven SIR",
        "scattering_driven" => "scattering-driven",
        // Paper 003: population Monte Carlo.
        "mis" => "MIS",
        "pmc_hi" => "PMC-HI",
        "pmc_hi_feedback" => "PMC-HI with feedback",
        "pmc_ip" => "PMC-IP",
        "uniform_image" => "uniform image sampling",
        "threshold_image" => "threshold stopping (biased control)",
        // Paper 004: SMC over environment-map sequences.
        "smc" => "SMC, one distribution",
        "smc_bridge" => "SMC, ratio",
        "smc_path" => "SMC, path sampling",
        "smc_adaptive" => "SMC, adaptive bridges",
        "bidirectional_is" => "bidirectional IS",
        "bidirectional_is_sn" => "self-normalised SIR (biased control)",
        _ => return None,
    })
}

/// One parameter in words (`bridges=5` -> "5 bridges").
fn param(key: &str, value: &str) -> String {
    let plural = |one: &str, many: &str| format!("{value} {}", if value == "1" { one } else { many });
    match (key, value) {
        ("bridges", _) => plural("bridge", "bridges"),
        ("moves", _) => plural("MH move", "MH moves"),
        ("candidates", _) => format!("M = {value}"),
        ("sigma_samp", _) => format!("σ_samp {value}"),
        ("sigma_samp_ratio", _) => format!("σ_samp / max σ_t {value}"),
        ("control", "1") => "linear CV".into(),
        ("control", "2") => "mean CV".into(),
        ("step", _) => format!("step {value}"),
        ("jitter", "0") => "no jitter".into(),
        ("initial", _) => format!("{value} initial spp"),
        ("threshold", _) => format!("threshold {value}"),
        _ => format!("{key} = {value}"),
    }
}

/// An estimator name (`id` or `id[k=v,...]`) in words; `None` for an id not listed.
pub fn estimator(name: &str) -> Option<String> {
    let (id, params) = match name.split_once('[') {
        Some((id, rest)) => (id, rest.strip_suffix(']')?),
        None => (name, ""),
    };
    let mut out = base(id)?.to_string();
    for kv in params.split(',').filter(|s| !s.is_empty()) {
        let (k, v) = kv.split_once('=')?;
        out.push_str(", ");
        out.push_str(&param(k.trim(), v.trim()));
    }
    Some(out)
}

/// A test bed and variant in words; `None` for a test bed not listed.
pub fn testbed(testbed: &str, variant: &str) -> Option<String> {
    let bed = match testbed {
        "gradient-plane" => "gradient plane (paper 001)",
        "gradient-box" => "gradient box (paper 000)",
        "eq21-medium" => "Eq. 21 medium (paper 002)",
        "perlin-medium" => "Perlin medium",
        "checker-direct" => "checker, direct lighting (paper 003 Fig. 6)",
        "checker-image" => "checker image (paper 003 Table 1)",
        "envmap-sequence" => "environment-map sequence (paper 004)",
        "canonical-1d" => "canonical 1D segment",
        _ => return None,
    };
    let v = match variant {
        "" | "default" => return Some(bed.to_string()),
        "central-ray" => "central ray".to_string(),
        "transmittance" => "transmittance image".to_string(),
        "multiple" => "multiple scattering".to_string(),
        "single-scatter" => "single scattering".to_string(),
        "occluded" => "occluded".to_string(),
        "furnace" => "furnace".to_string(),
        "mixed-lns" => "mixed BRDF, L_ns".to_string(),
        "specular-lns" => "specular BRDF, L_ns".to_string(),
        "mixed" | "specular" => format!("{variant} BRDF"),
        v if v.starts_with("albedo-") => format!("albedo {}", &v["albedo-".len()..]),
        v => match v.rsplit_once("-T") {
            Some((profile, t)) if testbed == "canonical-1d" => format!("{profile} profile, T = {t}"),
            _ => v.replace('-', " "),
        },
    };
    Some(format!("{bed}, {v}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn estimators_are_named_with_their_parameters() {
        assert_eq!(estimator("is1_cv2").as_deref(), Some("IS1 CV2 (SMC cache)"));
        assert_eq!(estimator("smc_path[bridges=5]").as_deref(), Some("SMC, path sampling, 5 bridges"));
        assert_eq!(estimator("smc[moves=1]").as_deref(), Some("SMC, one distribution, 1 MH move"));
        assert_eq!(
            estimator("double_particle[control=1,sigma_samp=0.4]").as_deref(),
            Some("double particle, linear CV, σ_samp 0.4")
        );
        assert_eq!(estimator("bidirectional_is[candidates=128]").as_deref(), Some("bidirectional IS, M = 128"));
        assert_eq!(estimator("my_own"), None);
        assert_eq!(estimator("smc[moves=5"), None, "malformed: left to the fallback");
    }

    #[test]
    fn every_registered_estimator_has_a_name() {
        for e in mcbench_papers::builtins::ESTIMATORS {
            assert!(estimator(e.id).is_some(), "{} has no display name", e.id);
        }
    }

    #[test]
    fn test_beds_are_named_with_their_variant() {
        assert_eq!(testbed("gradient-plane", "default").as_deref(), Some("gradient plane (paper 001)"));
        assert_eq!(testbed("gradient-box", "albedo-0.8").as_deref(), Some("gradient box (paper 000), albedo 0.8"));
        assert_eq!(
            testbed("canonical-1d", "linear-up-T0.5").as_deref(),
            Some("canonical 1D segment, linear-up profile, T = 0.5")
        );
        assert_eq!(testbed("somewhere", "default"), None);
        for bed in mcbench_papers::builtins::TESTBEDS {
            assert!(testbed(bed.id, "default").is_some(), "{} has no display name", bed.id);
        }
    }
}
