//! Parameters of test beds and estimators. Config files and the command line give them as named
//! numbers or texts ([`Params`]); each estimator and test bed declares one typed serde struct
//! ([`ParamSet`]: defaults, doc comments, unknown names refused) that those are parsed into once, at
//! construction ([`parse`]), and that documents them ([`describe`], `mcbench list --params`).
//!
//! ```
//! use mcbench_core::params::{parse, ParamSet, Params};
//! use serde::{Deserialize, Serialize};
//!
//! /// Parameters of a clamping estimator.
//! #[derive(Clone, Debug, Serialize, Deserialize, schemars::JsonSchema)]
//! #[serde(deny_unknown_fields, default)]
//! struct Clamp {
//!     /// Largest value an integrand sample may take.
//!     clamp: f64,
//! }
//! impl Default for Clamp {
//!     fn default() -> Self { Clamp { clamp: 4.0 } }
//! }
//! impl ParamSet for Clamp {}
//!
//! let p: Clamp = parse("clamped", &Params::new().with("clamp", 2.0)).unwrap();
//! assert_eq!(p.clamp, 2.0);
//! let typo = parse::<Clamp>("clamped", &Params::new().with("clmap", 2.0)).unwrap_err();
//! assert!(typo.to_string().contains("clamped.clmap"));
//! ```

use crate::error::ConfigError;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One parameter value.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    /// A number.
    Number(f64),
    /// A string.
    Text(String),
}

/// A set of named parameters, as config files and the command line give them; estimators and test
/// beds read them only through [`parse`] into their typed [`ParamSet`].
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Params(pub BTreeMap<String, ParamValue>);

impl Params {
    /// An empty set.
    pub fn new() -> Self {
        Params::default()
    }
    /// Builder: sets a number.
    pub fn with(mut self, name: &str, v: f64) -> Self {
        self.0.insert(name.to_string(), ParamValue::Number(v));
        self
    }
}

/// The typed parameters of one estimator or test bed: a serde struct with `deny_unknown_fields`
/// and `default`, a [`Default`] that holds the documented defaults, and doc comments on every field
/// (they are what `mcbench list --params` prints).
pub trait ParamSet:
    Serialize + DeserializeOwned + schemars::JsonSchema + Default + Clone + Send + Sync + 'static
{
    /// Checks ranges and combinations, once, after parsing; `owner` is the estimator or test-bed
    /// id the parameters were given to (for messages naming `owner.field`).
    fn validate(&self, _owner: &str) -> Result<(), ConfigError> {
        Ok(())
    }
}

/// `v` as a count: a whole number in `[1, max]`.
pub fn check_count(name: &str, v: usize, max: usize) -> Result<usize, ConfigError> {
    if v < 1 || v > max {
        return Err(ConfigError::invalid(name, v, format!("must be a whole number in [1, {max}]")));
    }
    Ok(v)
}

/// `v` in `[lo, hi]`.
pub fn check_range(name: &str, v: f64, lo: f64, hi: f64) -> Result<f64, ConfigError> {
    if !(lo..=hi).contains(&v) {
        return Err(ConfigError::invalid(name, v, format!("must lie in [{lo}, {hi}]")));
    }
    Ok(v)
}

/// No parameters at all: any name given is refused.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct NoParams {}

impl ParamSet for NoParams {}

impl Params {
    /// The parameters as a JSON object: whole numbers as integers (so they parse into integer
    /// fields), other numbers as floats; a non-finite number is refused naming `owner.name`.
    pub fn to_json(&self, owner: &str) -> Result<serde_json::Value, ConfigError> {
        let mut map = serde_json::Map::new();
        for (k, v) in &self.0 {
            let value = match v {
                ParamValue::Number(x) if !x.is_finite() => {
                    return Err(ConfigError::invalid(format!("{owner}.{k}"), x, "must be a finite number"))
                }
                ParamValue::Number(x) if x.fract() == 0.0 && x.abs() < 9.0e15 => serde_json::Value::from(*x as i64),
                ParamValue::Number(x) => serde_json::Value::from(*x),
                ParamValue::Text(t) => serde_json::Value::from(t.clone()),
            };
            map.insert(k.clone(), value);
        }
        Ok(serde_json::Value::Object(map))
    }
}

/// Parses `raw` into the typed parameters `P` of `owner` (an estimator or test-bed id): unknown
/// names, wrong types and non-finite numbers are refused naming `owner.field`, then
/// [`ParamSet::validate`] checks ranges.
pub fn parse<P: ParamSet>(owner: &str, raw: &Params) -> Result<P, ConfigError> {
    let value = raw.to_json(owner)?;
    let p: P = serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        let inner = e.into_inner().to_string();
        if let Some(rest) = inner.strip_prefix("unknown field `") {
            let name = rest.split('`').next().unwrap_or("");
            let valid = describe::<P>().iter().map(|d| d.name.clone()).collect::<Vec<_>>().join(", ");
            return ConfigError::UnknownName {
                kind: "parameter",
                name: format!("{owner}.{name}"),
                valid: if valid.is_empty() { "none".into() } else { valid },
            };
        }
        let field = if path == "." { owner.to_string() } else { format!("{owner}.{path}") };
        let given = raw.0.get(&path).map(|v| match v {
            ParamValue::Number(x) => x.to_string(),
            ParamValue::Text(t) => t.clone(),
        });
        ConfigError::invalid(field, given.unwrap_or_default(), inner)
    })?;
    p.validate(owner)?;
    Ok(p)
}

/// One documented parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamDoc {
    /// Its name.
    pub name: String,
    /// Its type (`number`, `integer`, `string`, `one of` its names, ...; `or none` when it may be left
    /// unset).
    pub kind: String,
    /// Its default, as JSON text (`null`: chosen by the variant or computed).
    pub default: String,
    /// Its doc comment.
    pub doc: String,
}

/// The documentation of `P`'s parameters, from its JSON schema (names in alphabetical order).
pub fn describe<P: ParamSet>() -> Vec<ParamDoc> {
    let schema = schemars::schema_for!(P);
    let value = serde_json::to_value(&schema).unwrap_or_default();
    let Some(props) = value.get("properties").and_then(|p| p.as_object()) else { return Vec::new() };
    props
        .iter()
        .map(|(name, p)| {
            let kind = match p.get("type") {
                Some(serde_json::Value::String(t)) => t.clone(),
                Some(serde_json::Value::Array(ts)) => {
                    let named: Vec<&str> = ts.iter().filter_map(|t| t.as_str()).filter(|t| *t != "null").collect();
                    format!("{} or none", named.join(" or "))
                }
                _ if !value_names(p).is_empty() => format!("one of {}", value_names(p).join(", ")),
                _ if p.get("enum").is_some() || p.get("oneOf").is_some() => "one of the listed names".into(),
                _ => "value".into(),
            };
            ParamDoc {
                name: name.clone(),
                kind,
                default: p.get("default").map(|d| d.to_string()).unwrap_or_else(|| "-".into()),
                doc: p.get("description").and_then(|d| d.as_str()).unwrap_or("").replace('\n', " "),
            }
        })
        .collect()
}

/// The values a text parameter may take (a unit enum's names), from its JSON schema.
fn value_names(schema: &serde_json::Value) -> Vec<String> {
    let name = |v: &serde_json::Value| v.as_str().map(str::to_string);
    match (schema.get("enum"), schema.get("oneOf")) {
        (Some(serde_json::Value::Array(values)), _) => values.iter().filter_map(name).collect(),
        (_, Some(serde_json::Value::Array(options))) => {
            options.iter().filter_map(|o| o.get("const").and_then(name)).collect()
        }
        _ => Vec::new(),
    }
}

/// The parameters of `owner` with every default filled in, as JSON (result files' `params`
/// columns); errors as [`parse`].
pub fn resolve<P: ParamSet>(owner: &str, raw: &Params) -> Result<serde_json::Value, ConfigError> {
    let p: P = parse(owner, raw)?;
    serde_json::to_value(p).map_err(|e| ConfigError::invalid(owner, "parameters", e.to_string()))
}

/// Puts one parameter in words (`("bridges", "5")` -> "5 bridges"); `None` leaves it as
/// `key = value`. A test bed's variant is handed over as the parameter `variant`.
pub type ParamWords = fn(&str, &str) -> Option<String>;

/// What a registry entry says of its parameters: how to document and resolve them, and how the
/// entry is named in legends, titles and tables.
#[derive(Clone, Copy)]
pub struct ParamSpec {
    /// The documentation of each parameter ([`describe`]).
    pub describe: fn() -> Vec<ParamDoc>,
    /// The parameters with defaults filled in ([`resolve`]).
    pub resolve: fn(&str, &Params) -> Result<serde_json::Value, ConfigError>,
    /// The name shown in legends, titles and tables ([`ParamSpec::display`]); `None`: the
    /// entry's label (an estimator) or its id (a test bed).
    pub display: Option<&'static str>,
    /// Its parameters (or a test bed's variant) in words ([`ParamSpec::words`]); `None`: each
    /// parameter as `key = value`, a variant as it is.
    pub words: Option<ParamWords>,
}

impl ParamSpec {
    /// The spec of the typed parameters `P`.
    pub const fn of<P: ParamSet>() -> Self {
        ParamSpec { describe: describe::<P>, resolve: resolve::<P>, display: None, words: None }
    }
    /// No parameters.
    pub const NONE: ParamSpec = ParamSpec::of::<NoParams>();

    /// With the name shown in legends, titles and tables.
    pub const fn display(self, name: &'static str) -> Self {
        ParamSpec { display: Some(name), ..self }
    }

    /// With its parameters (or a test bed's variant) put in words.
    pub const fn words(self, words: ParamWords) -> Self {
        ParamSpec { words: Some(words), ..self }
    }

    /// One parameter in words: the entry's [`ParamWords`], else `key = value`.
    pub fn word(&self, key: &str, value: &str) -> String {
        self.words.and_then(|f| f(key, value)).unwrap_or_else(|| format!("{key} = {value}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_name_the_field() {
        assert!(check_count("n", 0, 10).unwrap_err().to_string().contains("whole number in [1, 10]"));
        assert_eq!(check_count("n", 10, 10), Ok(10));
        assert!(check_range("x", 1.5, 0.0, 1.0).unwrap_err().to_string().contains("x = 1.5: must lie in [0, 1]"));
        let typo = parse::<NoParams>("owner", &Params::new().with("clamp", 1.0)).unwrap_err().to_string();
        assert!(typo.contains("owner.clamp") && typo.contains("valid: none"), "{typo}");
        let nan = parse::<NoParams>("owner", &Params::new().with("x", f64::NAN)).unwrap_err().to_string();
        assert!(nan.contains("owner.x") && nan.contains("finite"), "{nan}");
    }

    /// A parameter whose value is one of a few names.
    #[derive(Clone, Debug, Default, Serialize, Deserialize, schemars::JsonSchema)]
    #[serde(deny_unknown_fields, default)]
    struct Named {
        /// The precision.
        storage: Precision,
    }

    /// A parameter value that is one of two names.
    #[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, schemars::JsonSchema)]
    #[serde(rename_all = "lowercase")]
    #[schemars(inline)]
    enum Precision {
        /// Single precision.
        F32,
        /// Double precision.
        #[default]
        F64,
    }
    impl ParamSet for Named {}

    #[test]
    fn names_of_an_enum_parameter_are_listed() {
        let docs = describe::<Named>();
        assert_eq!((docs[0].kind.as_str(), docs[0].default.as_str()), ("one of f32, f64", "\"f64\""));
        assert_eq!(docs[0].doc, "The precision.");
    }
}
