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

    /// Checks a stored reference read back for a test bed of `integrals` integrals at
    /// `resolution`: its `resolution` is the test bed's, and its [`Reference::check`] passes (one
    /// value and one standard error per integral, each bounded). `Err` says what is wrong, naming
    /// the field.
    pub fn check(&self, integrals: usize, resolution: (usize, usize)) -> Result<(), String> {
        if self.resolution != resolution {
            let ((w, h), (bw, bh)) = (self.resolution, resolution);
            return Err(format!(
                "resolution [{w}, {h}] is not the test bed's [{bw}, {bh}] ({} values and {} standard errors)",
                self.reference.value.len(),
                self.reference.std_err.len()
            ));
        }
        self.reference.check(integrals)
    }
}

/// Where test beds find stored references.
///
/// ```
/// use mcbench_core::math::Rgb;
/// use mcbench_core::references::{load, InMemory, ReferenceKey, ReferenceSource, StoredReference};
/// use mcbench_core::testbed::{Reference, ReferenceKind};
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
/// assert_eq!(load(&source, &key, 1, (1, 1)).unwrap().value[0][0], 0.5);
/// let other = ReferenceKey::new("my-bed", "default", &[("resolution", 2.into())], false);
/// assert!(load(&source, &other, 4, (2, 2)).unwrap_err().to_string().contains("--param resolution=2"));
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

/// Several sources asked in order, the first that holds a key winning: the harness puts the
/// folder `--references` names first and the references built into the plug-in crates
/// ([`crate::Catalog::with_references`]) after it, so a reference of your own overrides a built-in
/// one and a built-in bed needs no folder at all.
#[derive(Clone, Default)]
pub struct Chain(pub Vec<std::sync::Arc<dyn ReferenceSource>>);

impl ReferenceSource for Chain {
    fn stored(&self, key: &ReferenceKey) -> Result<Option<StoredReference>, ConfigError> {
        for source in &self.0 {
            if let Some(s) = source.stored(key)? {
                return Ok(Some(s));
            }
        }
        Ok(None)
    }
    fn location(&self) -> String {
        let places: Vec<String> = self.0.iter().map(|s| s.location()).collect();
        if places.is_empty() {
            "no reference folder".into()
        } else {
            places.join(", then ")
        }
    }
}

/// The reference of `key` from `source`, checked against the `integrals` and `resolution` of the
/// test bed ([`StoredReference::check`]): absent is an error that says how to make it.
pub fn load(
    source: &dyn ReferenceSource,
    key: &ReferenceKey,
    integrals: usize,
    resolution: (usize, usize),
) -> Result<Reference, ConfigError> {
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
        .check(integrals, resolution)
        .map_err(|e| ConfigError::invalid(field, key.file_name(), format!("malformed ({e})")))?;
    Ok(stored.reference)
}

/// The stored exact reference of `key` in `source` when there is one made by `method` (a
/// quadrature worth storing: it is then read instead of computed at every build; a stored one of
/// another method is ignored, so a change of the quadrature never reads stale values); checked
/// against the `integrals` and `resolution` of the test bed ([`StoredReference::check`]).
pub fn stored_exact(
    source: &dyn ReferenceSource,
    key: &ReferenceKey,
    method: &str,
    integrals: usize,
    resolution: (usize, usize),
) -> Result<Option<Reference>, ConfigError> {
    let Some(stored) = source.stored(key)? else { return Ok(None) };
    if !matches!(&stored.reference.kind, crate::testbed::ReferenceKind::Exact { method: m, .. } if m == method) {
        return Ok(None);
    }
    stored.check(integrals, resolution).map_err(|e| {
        ConfigError::invalid(format!("{} reference", key.describe()), key.file_name(), format!("malformed ({e})"))
    })?;
    Ok(Some(stored.reference))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rgb;
    use crate::testbed::ReferenceKind;

    fn stored(value: f64, std_err: f64) -> StoredReference {
        StoredReference {
            testbed: "bed".into(),
            variant: "default".into(),
            params: Default::default(),
            command: "made".into(),
            resolution: (2, 2),
            reference: Reference {
                kind: ReferenceKind::Stored { command: "made".into(), samples: 64 },
                value: vec![Rgb([value; 3]); 4],
                std_err: vec![Rgb([std_err; 3]); 4],
            },
        }
    }

    /// The first source that holds a key wins; the location names every source in order.
    #[test]
    fn a_chain_asks_its_sources_in_order() {
        use std::sync::Arc;
        let key = ReferenceKey::new("bed", "default", &[], true);
        let (mine, builtin) = (stored(1.0, 0.0), stored(2.0, 0.0));
        let chain = Chain(vec![Arc::new(InMemory(vec![mine])), Arc::new(InMemory(vec![builtin.clone()]))]);
        assert_eq!(chain.stored(&key).unwrap().unwrap().reference.value[0][0], 1.0);
        let fallback = Chain(vec![Arc::new(NoReferences), Arc::new(InMemory(vec![builtin]))]);
        assert_eq!(fallback.stored(&key).unwrap().unwrap().reference.value[0][0], 2.0);
        assert_eq!(fallback.location(), "no reference folder, then references in memory");
        assert!(Chain::default().stored(&key).unwrap().is_none());
    }

    #[test]
    fn stored_references_whose_numbers_break_a_metric_are_refused_naming_the_field() {
        assert_eq!(stored(0.5, 0.01).check(4, (2, 2)), Ok(()));
        assert_eq!(stored(-3.0, 0.0).check(4, (2, 2)), Ok(()), "negative values and zero errors are fine");
        assert_eq!(stored(Reference::LARGEST, Reference::LARGEST).check(4, (2, 2)), Ok(()));
        for (value, std_err, field) in [
            (0.5, 1e308, "std_err[0]"),
            (0.5, 1e151, "std_err[0]"),
            (0.5, f64::NAN, "std_err[0]"),
            (0.5, f64::INFINITY, "std_err[0]"),
            (0.5, -0.01, "std_err[0]"),
            (1e300, 0.01, "value[0]"),
            (f64::NAN, 0.01, "value[0]"),
            (-f64::INFINITY, 0.01, "value[0]"),
        ] {
            let e = stored(value, std_err).check(4, (2, 2)).expect_err("refused");
            assert!(e.starts_with(field), "{value} {std_err}: {e}");
        }
        // The standard error of the last integral alone.
        let mut s = stored(0.5, 0.01);
        s.reference.std_err[3].0[2] = 1e200;
        assert!(s.check(4, (2, 2)).expect_err("refused").starts_with("std_err[3]"));
        // The resolution is the test bed's, and the values are one per integral.
        let e = stored(0.5, 0.01).check(4, (4, 1)).expect_err("refused");
        assert!(e.starts_with("resolution [2, 2] is not the test bed's [4, 1]"), "{e}");
        let mut s = stored(0.5, 0.01);
        s.reference.std_err.pop();
        assert!(s.check(4, (2, 2)).expect_err("refused").contains("3 standard errors"));
    }
}
