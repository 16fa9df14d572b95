//! The repository's stored references (`results/references`), for the crate's own tests.

use mcbench_core::error::ConfigError;
use mcbench_core::references::{ReferenceKey, ReferenceSource, StoredReference};

/// Reads `<repository>/results/references/<key's file name>`.
pub struct Repository;

impl ReferenceSource for Repository {
    fn stored(&self, key: &ReferenceKey) -> Result<Option<StoredReference>, ConfigError> {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../results/references").join(key.file_name());
        let Ok(text) = std::fs::read_to_string(&path) else { return Ok(None) };
        let s: StoredReference = serde_json::from_str(&text)
            .map_err(|e| ConfigError::invalid("reference", path.display(), e.to_string()))?;
        Ok(s.matches(key).then_some(s))
    }
    fn location(&self) -> String {
        "results/references".into()
    }
}
