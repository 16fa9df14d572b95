//! Named numeric or text parameters of test beds and estimators (from config files or the CLI),
//! validated once at construction.

use crate::error::ConfigError;
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

/// A set of named parameters. Getters check types and finiteness and name the field on error.
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
    /// A finite number, or `default` when absent.
    pub fn f64(&self, name: &str, default: f64) -> Result<f64, ConfigError> {
        match self.0.get(name) {
            None => Ok(default),
            Some(ParamValue::Number(v)) if v.is_finite() => Ok(*v),
            Some(ParamValue::Number(v)) => Err(ConfigError::invalid(name, v, "must be a finite number")),
            Some(ParamValue::Text(t)) => Err(ConfigError::invalid(name, t, "must be a number")),
        }
    }
    /// A number in `[lo, hi]`, or `default` when absent.
    pub fn f64_in(&self, name: &str, default: f64, lo: f64, hi: f64) -> Result<f64, ConfigError> {
        let v = self.f64(name, default)?;
        if !(lo..=hi).contains(&v) {
            return Err(ConfigError::invalid(name, v, format!("must lie in [{lo}, {hi}]")));
        }
        Ok(v)
    }
    /// A positive whole number, or `default` when absent.
    pub fn count(&self, name: &str, default: usize, max: usize) -> Result<usize, ConfigError> {
        let v = self.f64(name, default as f64)?;
        if v < 1.0 || v.fract() != 0.0 || v > max as f64 {
            return Err(ConfigError::invalid(name, v, format!("must be a whole number in [1, {max}]")));
        }
        Ok(v as usize)
    }
    /// Refuses names outside `known` (catches typos in config files).
    pub fn reject_unknown(&self, owner: &str, known: &[&str]) -> Result<(), ConfigError> {
        match self.0.keys().find(|k| !known.contains(&k.as_str())) {
            None => Ok(()),
            Some(k) => Err(ConfigError::UnknownName {
                kind: "parameter",
                name: format!("{owner}.{k}"),
                valid: if known.is_empty() { "none".into() } else { known.join(", ") },
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn getters_validate_and_name_the_field() {
        let p = Params::new().with("clamp", f64::NAN).with("n", 2.5);
        assert!(p.f64("clamp", 1.0).unwrap_err().to_string().contains("clamp"));
        assert_eq!(p.f64("absent", 3.0), Ok(3.0));
        assert!(p.count("n", 1, 10).is_err());
        assert!(p.f64_in("n", 0.0, 0.0, 1.0).unwrap_err().to_string().contains("[0, 1]"));
        assert!(p.reject_unknown("x", &["n"]).unwrap_err().to_string().contains("x.clamp"));
    }
}
