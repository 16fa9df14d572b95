//! Harness errors and their exit codes (SPEC §9: 0 success, 2 bad input, 1 internal failure).

use estimators::error::ConfigError;
use std::path::PathBuf;
use thiserror::Error;

/// Everything the harness can fail with.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum HarnessError {
    /// A bad name, value or combination in flags or config (exit 2).
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A config or result file that cannot be read or parsed (exit 2).
    #[error("{path}: {reason}")]
    BadFile {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// An estimator failed while running (exit 1).
    #[error("estimator {estimator} on {testbed}: {source}")]
    Estimate {
        /// Estimator name.
        estimator: String,
        /// Test bed and variant.
        testbed: String,
        /// The failure.
        source: estimators::error::EstimateError,
    },
    /// Writing outputs failed (exit 1).
    #[error("cannot write {path}: {reason}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        reason: String,
    },
}

impl HarnessError {
    /// The process exit code for this error.
    pub fn exit_code(&self) -> i32 {
        match self {
            HarnessError::Config(_) | HarnessError::BadFile { .. } => 2,
            HarnessError::Estimate { .. } | HarnessError::Write { .. } => 1,
        }
    }
    /// A bad-file error.
    pub fn bad_file(path: impl Into<PathBuf>, reason: impl ToString) -> Self {
        HarnessError::BadFile { path: path.into(), reason: reason.to_string() }
    }
    /// A write error.
    pub fn write(path: impl Into<PathBuf>, reason: impl ToString) -> Self {
        HarnessError::Write { path: path.into(), reason: reason.to_string() }
    }
}

/// Shorthand result type.
pub type Result<T, E = HarnessError> = std::result::Result<T, E>;
