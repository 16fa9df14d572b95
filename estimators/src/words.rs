//! The papers' parameters and variants in words, for the entries' [`ParamSpec::words`]
//! (`bridges=5` -> "5 bridges", `albedo-0.8` -> "albedo 0.8"). A key not listed is shown as
//! `key = value`.
//!
//! [`ParamSpec::words`]: mcbench_core::ParamSpec::words

/// One estimator parameter in words.
pub fn param(key: &str, value: &str) -> Option<String> {
    let plural = |one: &str, many: &str| format!("{value} {}", if value == "1" { one } else { many });
    Some(match (key, value) {
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
        ("clamp", _) => format!("clamp {value}x the mean"),
        _ => return None,
    })
}

/// A test bed's variant in words (key `variant`).
pub fn variant(key: &str, value: &str) -> Option<String> {
    (key == "variant").then(|| match value {
        "central-ray" => "central ray".to_string(),
        "transmittance" => "transmittance image".to_string(),
        "multiple" => "multiple scattering".to_string(),
        "single-scatter" => "single scattering".to_string(),
        "mixed-lns" => "mixed BRDF, L_ns".to_string(),
        "specular-lns" => "specular BRDF, L_ns".to_string(),
        "mixed" | "specular" => format!("{value} BRDF"),
        v if v.starts_with("albedo-") => format!("albedo {}", &v["albedo-".len()..]),
        v => v.replace('-', " "),
    })
}

/// A canonical 1D segment's variant in words (`linear-up-T0.5` -> "linear-up profile, T = 0.5").
pub fn canonical_variant(key: &str, value: &str) -> Option<String> {
    match value.rsplit_once("-T") {
        Some((profile, t)) if key == "variant" => Some(format!("{profile} profile, T = {t}")),
        _ => variant(key, value),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::builtins::{ESTIMATORS, TESTBEDS};

    #[test]
    fn parameters_and_variants_in_words() {
        assert_eq!(param("bridges", "5").as_deref(), Some("5 bridges"));
        assert_eq!(param("moves", "1").as_deref(), Some("1 MH move"));
        assert_eq!(param("control", "1").as_deref(), Some("linear CV"));
        assert_eq!(param("control", "0"), None);
        assert_eq!(variant("variant", "albedo-0.8").as_deref(), Some("albedo 0.8"));
        assert_eq!(variant("variant", "mixed").as_deref(), Some("mixed BRDF"));
        assert_eq!(canonical_variant("variant", "linear-up-T0.5").as_deref(), Some("linear-up profile, T = 0.5"));
        assert_eq!(canonical_variant("variant", "hole-T0.1").as_deref(), Some("hole profile, T = 0.1"));
    }

    #[test]
    fn every_built_in_has_a_display_name() {
        for e in ESTIMATORS {
            assert!(e.params.display.is_some(), "{} has no display name", e.id);
            let has_params = !(e.params.describe)().is_empty();
            assert!(e.params.words.is_some() || !has_params, "{} puts no parameter in words", e.id);
        }
        for b in TESTBEDS {
            assert!(b.params.display.is_some(), "{} has no display name", b.id);
            assert!(b.params.words.is_some(), "{} puts no variant in words", b.id);
        }
    }
}
