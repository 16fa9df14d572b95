//! Stored references as data (book: testbeds.md): a test bed without a closed form looks its reference up
//! by a [`ReferenceKey`] (test bed, variant, and the parameters the values depend on) in a
//! [`ReferenceSource`] that the caller provides: the harness reads a folder (`<results>/references`
//! or `--references DIR`), a test can hand over a value. The library itself reads no file.

use crate::error::ConfigError;
use crate::testbed::Reference;
use serde::{Deserialize, Serialize};

/// What a stored reference is the reference of.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReferenceKey {
    /// Test-bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// The parameters its values depend on, with their values (every default filled in).
    pub params: serde_json::Map<String, serde_json::Value>,
    /// Whether these are the variant's default parameters (the file then has the plain name
    /// `<testbed>_<variant>.json`, else `<testbed>_<variant>_<digest of params>.json`).
    #[serde(skip)]
    pub default: bool,
}

impl ReferenceKey {
    /// A key from `(name, value)` pairs.
    pub fn new(testbed: &str, variant: &str, params: &[(&str, serde_json::Value)], default: bool) -> Self {
        ReferenceKey {
            testbed: testbed.into(),
            variant: variant.into(),
            params: params.iter().map(|(k, v)| (k.to_string(), v.clone())).collect(),
            default,
        }
    }

    /// The file name a reference under this key is stored as.
    pub fn file_name(&self) -> String {
        if self.default {
            format!("{}_{}.json", self.testbed, self.variant)
        } else {
            let text = serde_json::Value::Object(self.params.clone()).to_string();
            format!("{}_{}_{:016x}.json", self.testbed, self.variant, crate::rng::fnv1a(&text))
        }
    }

    /// The command that makes the reference of this key.
    pub fn command(&self) -> String {
        let mut cmd = format!("mcbench reference {} --variant {}", self.testbed, self.variant);
        if !self.default {
            for (k, v) in &self.params {
                let v = v.as_str().map(String::from).unwrap_or_else(|| v.to_string());
                cmd.push_str(&format!(" --param {k}={v}"));
            }
        }
        cmd
    }

    /// `testbed/variant {params}`, for messages.
    pub fn describe(&self) -> String {
        format!("{}/{} {}", self.testbed, self.variant, serde_json::Value::Object(self.params.clone()))
    }
}

/// A stored reference, as `mcbench reference` writes it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StoredReference {
    /// Test-bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// The parameters its values depend on ([`ReferenceKey::params`]).
    pub params: serde_json::Map<String, serde_json::Value>,
    /// How it was made (the command and what it ran).
    pub command: String,
    /// Image width and height it was made for.
    pub resolution: (usize, usize),
    /// The values.
    pub reference: Reference,
}

impl StoredReference {
    /// Whether this is the reference of `key`.
    pub fn matches(&self, key: &ReferenceKey) -> bool {
        self.testbed == key.testbed && self.variant == key.variant && self.params == key.params
    }
}

/// Where test beds find stored references.
///
/// ```
/// use estimators::math::Rgb;
/// use estimators::references::{load, InMemory, ReferenceKey, ReferenceSource, StoredReference};
/// use estimators::testbed::{Reference, ReferenceKind};
///
/// let key = ReferenceKey::new("my-bed", "default", &[("resolution", 1.into())], true);
/// let reference = Reference {
///     kind: ReferenceKind::Stored { command: "my long run".into(), samples: 64 },
///     value: vec![Rgb([0.5; 3])],
///     std_err: vec![Rgb([0.001; 3])],
/// };
/// let stored = StoredReference {
///     testbed: key.testbed.clone(),
///     variant: key.variant.clone(),
///     params: key.params.clone(),
///     command: "my long run".into(),
///     resolution: (1, 1),
///     reference,
/// };
/// let source = InMemory(vec![stored]);
/// assert_eq!(load(&source, &key, 1).unwrap().value[0][0], 0.5);
/// let other = ReferenceKey::new("my-bed", "default", &[("resolution", 2.into())], false);
/// assert!(load(&source, &other, 4).unwrap_err().to_string().contains("--param resolution=2"));
/// assert!(source.stored(&other).unwrap().is_none());
/// ```
pub trait ReferenceSource: Send + Sync {
    /// The stored reference of `key`, or `None` when there is none. A reference that is there but
    /// cannot be read, does not parse, or is of another key is an error naming it.
    fn stored(&self, key: &ReferenceKey) -> Result<Option<StoredReference>, ConfigError>;
    /// Where it looks (for messages).
    fn location(&self) -> String;
}

/// No stored reference anywhere (test beds with exact references need none).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoReferences;

impl ReferenceSource for NoReferences {
    fn stored(&self, _key: &ReferenceKey) -> Result<Option<StoredReference>, ConfigError> {
        Ok(None)
    }
    fn location(&self) -> String {
        "no reference folder".into()
    }
}

/// Stored references held in memory (tests; references computed in the same process).
#[derive(Clone, Debug, Default)]
pub struct InMemory(pub Vec<StoredReference>);

impl ReferenceSource for InMemory {
    fn stored(&self, key: &ReferenceKey) -> Result<Option<StoredReference>, ConfigError> {
        Ok(self.0.iter().find(|s| s.matches(key)).cloned())
    }
    fn location(&self) -> String {
        "references in memory".into()
    }
}

/// The reference of `key` from `source`, checked against the `integrals` of the test bed: absent
/// is an error that says how to make it.
pub fn load(source: &dyn ReferenceSource, key: &ReferenceKey, integrals: usize) -> Result<Reference, ConfigError> {
    let field = format!("{}/{} reference", key.testbed, key.variant);
    let stored = source.stored(key)?.ok_or_else(|| {
        ConfigError::invalid(
            field.clone(),
            key.describe(),
            format!(
                "no stored reference in {} (make it with `{}`, or point --references at a folder that has it)",
                source.location(),
                key.command()
            ),
        )
    })?;
    stored
        .reference
        .check(integrals)
        .map_err(|e| ConfigError::invalid(field, key.file_name(), format!("malformed ({e})")))?;
    Ok(stored.reference)
}

/// The stored exact reference of `key` in `source` when there is one made by `method` (a
/// quadrature worth storing: it is then read instead of computed at every build; a stored one of
/// another method is ignored, so a change of the quadrature never reads stale values); checked
/// against the `integrals` of the test bed.
pub fn stored_exact(
    source: &dyn ReferenceSource,
    key: &ReferenceKey,
    method: &str,
    integrals: usize,
) -> Result<Option<Reference>, ConfigError> {
    let Some(stored) = source.stored(key)? else { return Ok(None) };
    let r = stored.reference;
    if !matches!(&r.kind, crate::testbed::ReferenceKind::Exact { method: m, .. } if m == method) {
        return Ok(None);
    }
    r.check(integrals).map_err(|e| {
        ConfigError::invalid(format!("{} reference", key.describe()), key.file_name(), format!("malformed ({e})"))
    })?;
    Ok(Some(r))
}

/// The repository's stored references (`results/references`), for the library's own tests.
#[cfg(test)]
pub(crate) mod repository {
    use super::*;

    /// Reads `<repository>/results/references/<key's file name>`.
    pub struct Repository;

    impl ReferenceSource for Repository {
        fn stored(&self, key: &ReferenceKey) -> Result<Option<StoredReference>, ConfigError> {
            let path =
                std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../results/references").join(key.file_name());
            let Ok(text) = std::fs::read_to_string(&path) else { return Ok(None) };
            let s: StoredReference = serde_json::from_str(&text)
                .map_err(|e| ConfigError::invalid("reference", path.display(), e.to_string()))?;
            Ok(s.matches(key).then_some(s))
        }
        fn location(&self) -> String {
            "results/references".into()
        }
    }
}
