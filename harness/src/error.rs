//! Harness errors and the one exit-code table every subcommand uses (0 success, 1 internal
//! failure, 2 bad input, 3 busy; book: contract.md).
//!
//! | code | meaning | examples |
//! |---|---|---|
//! | 0 | success | |
//! | 1 | failure while running or writing, or a failed check | an estimator failed, the disk filled up, an estimator failed `mcbench conformance` |
//! | 2 | bad input: nothing was run or written | unknown names, values out of bounds, a config, stored cell, reference, manifest or summary file that is malformed or inconsistent, an output path that is not a writable folder, a symbolic link in place of a lock file or of an experiment's folder |
//! | 3 | busy: another mcbench holds the results folder | a second run into the same folder (`--wait` waits instead) |

use mcbench_core::error::ConfigError;
use std::path::PathBuf;
use thiserror::Error;

/// Exit code of a successful run.
pub const EXIT_OK: i32 = 0;
/// Exit code of an internal failure (an estimator failed, a write failed).
pub const EXIT_FAILURE: i32 = 1;
/// Exit code of bad input (nothing was run or written).
pub const EXIT_BAD_INPUT: i32 = 2;
/// Exit code when another process holds the results folder's lock.
pub const EXIT_BUSY: i32 = 3;

/// Everything the harness can fail with.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum HarnessError {
    /// A bad name, value or combination in flags or config (exit 2).
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A config or result file that cannot be read, parsed or trusted (exit 2).
    #[error("{path}: {reason}")]
    BadFile {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
    /// An output path that cannot be used: not a folder, or not writable (exit 2).
    #[error("{field} {path}: {reason}")]
    BadOutput {
        /// The flag or field that named it (`--results`, `--plots`).
        field: &'static str,
        /// The path.
        path: PathBuf,
        /// Why it cannot be used.
        reason: String,
    },
    /// Another process holds the folder's lock (exit 3).
    #[error("{path} is in use by another mcbench run (pid {holder}); wait for it, or pass --wait")]
    Busy {
        /// The locked folder.
        path: PathBuf,
        /// What the lock file says of its holder.
        holder: String,
    },
    /// An estimator failed while running (exit 1).
    #[error("estimator {estimator} on {testbed}: {source}")]
    Estimate {
        /// Estimator name.
        estimator: String,
        /// Test bed and variant.
        testbed: String,
        /// The failure.
        source: mcbench_core::error::EstimateError,
    },
    /// A check failed (exit 1): an estimator that does not pass the conformance suite.
    #[error("{0}")]
    Failed(String),
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
    /// The process exit code for this error (the table in the module docs).
    pub fn exit_code(&self) -> i32 {
        match self {
            HarnessError::Config(_) | HarnessError::BadFile { .. } | HarnessError::BadOutput { .. } => EXIT_BAD_INPUT,
            HarnessError::Busy { .. } => EXIT_BUSY,
            HarnessError::Estimate { .. } | HarnessError::Write { .. } | HarnessError::Failed(_) => EXIT_FAILURE,
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
    /// A bad-output-path error.
    pub fn bad_output(field: &'static str, path: impl Into<PathBuf>, reason: impl ToString) -> Self {
        HarnessError::BadOutput { field, path: path.into(), reason: reason.to_string() }
    }
}

/// Shorthand result type.
pub type Result<T, E = HarnessError> = std::result::Result<T, E>;
