//! Typed errors of the library (bad input names its field).

use thiserror::Error;

/// A configuration the library refuses: unknown names, out-of-range or non-finite values,
/// incompatible combinations. The harness maps every variant to exit code 2.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ConfigError {
    /// A name that is not registered.
    #[error("unknown {kind} '{name}' (valid: {valid})")]
    UnknownName {
        /// What kind of name (test bed, estimator, variant, parameter, ...).
        kind: &'static str,
        /// The name given.
        name: String,
        /// The valid names, comma separated.
        valid: String,
    },
    /// A value outside its domain.
    #[error("invalid {field} = {value}: {reason}")]
    InvalidValue {
        /// The field (parameter) name.
        field: String,
        /// The offending value, as text.
        value: String,
        /// Why it is refused.
        reason: String,
    },
}

impl ConfigError {
    /// Shorthand for [`ConfigError::InvalidValue`].
    pub fn invalid(field: impl Into<String>, value: impl ToString, reason: impl Into<String>) -> Self {
        ConfigError::InvalidValue { field: field.into(), value: value.to_string(), reason: reason.into() }
    }
    /// Shorthand for [`ConfigError::UnknownName`] listing the valid names.
    pub fn unknown<'a>(kind: &'static str, name: &str, valid: impl IntoIterator<Item = &'a str>) -> Self {
        ConfigError::UnknownName {
            kind,
            name: name.to_string(),
            valid: valid.into_iter().collect::<Vec<_>>().join(", "),
        }
    }
}

/// A failure while estimating one integral.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum EstimateError {
    /// The estimator refuses this configuration (e.g. a terminating particle model where it is
    /// invalid); reported, never silently replaced by another estimate.
    #[error("refused: {0}")]
    Refused(String),
    /// The estimator produced a non-finite value.
    #[error("non-finite estimate {value:?} for integral {integral}")]
    NonFinite {
        /// The integral index.
        integral: usize,
        /// The offending value.
        value: [f64; 3],
    },
}
