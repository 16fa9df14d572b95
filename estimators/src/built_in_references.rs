//! The stored references of the built-in test beds, compiled into the crate ([`BUILT_IN`]): a
//! binary finds them without any folder, and a run's `--references` folder, asked first, overrides
//! them. The files are the package's `references/` folder (made by `mcbench reference ... --references estimators/references`).

use mcbench_core::error::ConfigError;
use mcbench_core::references::{ReferenceKey, ReferenceSource, StoredReference};
use std::sync::OnceLock;

/// Every stored reference of the built-in test beds: (file name, contents).
static FILES: &[(&str, &str)] = &[
    ("checker-image_default.json", include_str!("../references/checker-image_default.json")),
    ("checker-image_occluded.json", include_str!("../references/checker-image_occluded.json")),
    ("checker-image_soft-shadow.json", include_str!("../references/checker-image_soft-shadow.json")),
    (
        "envmap-sequence_mixed-lns_0b5d04e5a1dff920.json",
        include_str!("../references/envmap-sequence_mixed-lns_0b5d04e5a1dff920.json"),
    ),
    (
        "envmap-sequence_mixed_0b5d04e5a1dff920.json",
        include_str!("../references/envmap-sequence_mixed_0b5d04e5a1dff920.json"),
    ),
    (
        "envmap-sequence_specular_0b5d04e5a1dff920.json",
        include_str!("../references/envmap-sequence_specular_0b5d04e5a1dff920.json"),
    ),
    ("eq21-medium_multiple.json", include_str!("../references/eq21-medium_multiple.json")),
    (
        "eq21-medium_multiple_36cb30862c5be2b5.json",
        include_str!("../references/eq21-medium_multiple_36cb30862c5be2b5.json"),
    ),
    ("gradient-box_albedo-0.5.json", include_str!("../references/gradient-box_albedo-0.5.json")),
    ("gradient-box_albedo-0.8.json", include_str!("../references/gradient-box_albedo-0.8.json")),
    (
        "gradient-box_albedo-0.8_00b40f450a505d61.json",
        include_str!("../references/gradient-box_albedo-0.8_00b40f450a505d61.json"),
    ),
    (
        "gradient-box_albedo-0.8_2a5d4e544549f584.json",
        include_str!("../references/gradient-box_albedo-0.8_2a5d4e544549f584.json"),
    ),
    (
        "gradient-box_albedo-0.8_532d035989ee24ee.json",
        include_str!("../references/gradient-box_albedo-0.8_532d035989ee24ee.json"),
    ),
    (
        "gradient-box_albedo-0.8_6515b232c52478b9.json",
        include_str!("../references/gradient-box_albedo-0.8_6515b232c52478b9.json"),
    ),
    (
        "gradient-box_albedo-0.8_e83e002a82f860b1.json",
        include_str!("../references/gradient-box_albedo-0.8_e83e002a82f860b1.json"),
    ),
    ("gradient-box_albedo-1.json", include_str!("../references/gradient-box_albedo-1.json")),
    ("gradient-box_hg-0.1.json", include_str!("../references/gradient-box_hg-0.1.json")),
    ("gradient-box_thick.json", include_str!("../references/gradient-box_thick.json")),
    (
        "perlin-medium_central-ray_64684c84ff0fed7a.json",
        include_str!("../references/perlin-medium_central-ray_64684c84ff0fed7a.json"),
    ),
    ("perlin-medium_multiple.json", include_str!("../references/perlin-medium_multiple.json")),
    ("perlin-medium_single-scatter.json", include_str!("../references/perlin-medium_single-scatter.json")),
    ("perlin-medium_transmittance.json", include_str!("../references/perlin-medium_transmittance.json")),
    (
        "perlin-medium_transmittance_62726640a84e7326.json",
        include_str!("../references/perlin-medium_transmittance_62726640a84e7326.json"),
    ),
];

/// Each file of [`FILES`] parsed, at its first look-up (the parse error's text when it does not).
static PARSED: [OnceLock<Result<StoredReference, String>>; FILES.len()] = [const { OnceLock::new() }; FILES.len()];

/// The file named `name` parsed once for the process: `None` when no built-in file has that name.
fn parsed(name: &str) -> Option<Result<&'static StoredReference, ConfigError>> {
    let i = FILES.iter().position(|(n, _)| *n == name)?;
    let parsed = PARSED[i].get_or_init(|| serde_json::from_str(FILES[i].1).map_err(|e| e.to_string()));
    Some(parsed.as_ref().map_err(|e| ConfigError::invalid("built-in reference", name, e.clone())))
}

/// The built-in stored references, by their keys' file names.
pub struct BuiltIn;

/// The built-in stored references (handed to a registry with the [`crate::catalog`]).
pub static BUILT_IN: BuiltIn = BuiltIn;

impl ReferenceSource for BuiltIn {
    fn stored(&self, key: &ReferenceKey) -> Result<Option<StoredReference>, ConfigError> {
        let Some(stored) = parsed(&key.file_name()) else { return Ok(None) };
        let stored = stored?;
        Ok(stored.matches(key).then(|| stored.clone()))
    }
    fn location(&self) -> String {
        "the references built into mcbench-papers".into()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every file of the folder is compiled in (a reference made later is not forgotten), and
    /// each parses and is found by its own key.
    #[test]
    fn every_stored_reference_is_built_in_and_found_by_its_key() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("references");
        let mut on_disk: Vec<String> = std::fs::read_dir(dir)
            .expect("the folder")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        on_disk.sort();
        let built_in: Vec<String> = FILES.iter().map(|(n, _)| n.to_string()).collect();
        assert_eq!(built_in, on_disk);
        for (name, text) in FILES {
            let s: StoredReference = serde_json::from_str(text).expect("parses");
            let key = ReferenceKey {
                testbed: s.testbed.clone(),
                variant: s.variant.clone(),
                params: s.params.clone(),
                default: name.matches('_').count() == 1,
            };
            assert_eq!(&key.file_name(), name);
            assert!(BUILT_IN.stored(&key).expect("reads").is_some(), "{name}");
        }
    }

    /// A file is parsed once: two look-ups of one key return the same data, read from the one
    /// parsed value.
    #[test]
    fn a_file_is_parsed_once_and_every_look_up_returns_its_data() {
        let (name, text) = FILES[0];
        let first = parsed(name).expect("built in").expect("parses");
        let second = parsed(name).expect("built in").expect("parses");
        assert!(std::ptr::eq(first, second), "the second look-up parsed {name} again");
        let fresh: StoredReference = serde_json::from_str(text).expect("parses");
        assert_eq!(*first, fresh);
        let key = ReferenceKey {
            testbed: fresh.testbed.clone(),
            variant: fresh.variant.clone(),
            params: fresh.params.clone(),
            default: name.matches('_').count() == 1,
        };
        let (a, b) = (BUILT_IN.stored(&key).expect("reads"), BUILT_IN.stored(&key).expect("reads"));
        assert_eq!(a.as_ref(), Some(&fresh));
        assert_eq!(a, b);
        assert!(parsed("no-such-file.json").is_none());
    }
}
