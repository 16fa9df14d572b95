//! Claims declared as data: what a run is expected to show, written in an experiment file or a
//! config file (`[[claims]]` tables) and judged on the finished run by [`ClaimSpec::judge`].
//!
//! ```toml
//! [[claims]]
//! kind = "slope"                       # the fitted convergence slope's 95% interval holds `value`
//! testbed = "gradient-plane/diffuse"
//! estimator = "my_estimator"
//! value = -0.5
//! text = "my estimator converges like independent MC"
//!
//! [[claims]]
//! kind = "slope_below"                 # the interval lies below `value`: faster than it
//! testbed = "gradient-plane/diffuse"
//! estimator = "my_estimator"
//! value = -0.5
//! text = "my estimator converges faster than independent MC"
//!
//! [[claims]]
//! kind = "speedup"                     # against the sweep's baseline at the largest budget
//! testbed = "gradient-plane/diffuse"
//! estimator = "my_estimator"
//! value = 2.0
//! text = "twice as efficient as the baseline"
//!
//! [[claims]]
//! kind = "control_flagged"             # the unbiasedness test flags a biased control
//! estimator = "clamped_is0_cv0"
//! ```

use crate::claims;
use crate::output::{Claim, RunReport};
use serde::{Deserialize, Serialize};

/// One claim about a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ClaimSpec {
    /// The convergence slope of `estimator` on `testbed` is `value`: held when its 95% interval
    /// holds it.
    Slope {
        /// `id/variant`.
        testbed: String,
        /// Estimator name (id with parameters).
        estimator: String,
        /// The claimed slope.
        value: f64,
        /// The claim in words.
        text: String,
    },
    /// `estimator` converges faster than slope `value`: held when its interval lies below.
    SlopeBelow {
        /// `id/variant`.
        testbed: String,
        /// Estimator name.
        estimator: String,
        /// The slope it beats.
        value: f64,
        /// The claim in words.
        text: String,
    },
    /// `estimator` is `value` times as efficient as the sweep's baseline at the largest budget
    /// (the papers' speed-up).
    Speedup {
        /// `id/variant`.
        testbed: String,
        /// Estimator name.
        estimator: String,
        /// The claimed speed-up.
        value: f64,
        /// The claim in words.
        text: String,
    },
    /// The biased control `estimator` is flagged by the unbiasedness tests.
    ControlFlagged {
        /// Estimator name.
        estimator: String,
    },
}

fn split(testbed: &str) -> (&str, &str) {
    testbed.split_once('/').unwrap_or((testbed, ""))
}

impl ClaimSpec {
    /// Judges the claim on a finished run.
    pub fn judge(&self, report: &RunReport) -> Claim {
        match self {
            ClaimSpec::Slope { testbed, estimator, value, text } => {
                claims::slope_matches(report, split(testbed), estimator, *value, text)
            }
            ClaimSpec::SlopeBelow { testbed, estimator, value, text } => {
                claims::slope_steeper_than(report, split(testbed), estimator, *value, text)
            }
            ClaimSpec::Speedup { testbed, estimator, value, text } => {
                claims::speedup_claim(report, split(testbed), estimator, *value, text)
            }
            ClaimSpec::ControlFlagged { estimator } => claims::control_flagged(report, estimator),
        }
    }
}
