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
//! kind = "slope"
//! range = "right"                      # judged on the last three budgets (default "whole")
//! testbed = "gradient-plane/diffuse"
//! estimator = "my_estimator"
//! value = -0.94
//! text = "my estimator reaches slope -0.94"
//!
//! [[claims]]
//! kind = "diagnostic"                  # an estimator diagnostic's mean at a budget
//! testbed = "gradient-plane/default"
//! estimator = "is1_cv2"
//! budget = 1024
//! name = "cells"
//! value = 256.0
//! tolerance = 0.1                      # relative
//! text = "256 cells at 1024 spp"
//!
//! [[claims]]
//! kind = "speedup"                     # at the largest budget, judged on its 95% interval
//! testbed = "gradient-plane/diffuse"
//! estimator = "my_estimator"
//! baseline = "is0_cv0"                 # the pair as stated (default: the sweep's baseline)
//! regime = "renderer"                  # rays and fetches priced by [cost_model] (default "measured")
//! value = 2.0
//! text = "twice as efficient as the baseline"
//!
//! [[claims]]
//! kind = "ratio"                       # metric(estimator) / metric(baseline) at a budget
//! testbed = "eq21-medium/transmittance"
//! estimator = "delta_tracking"
//! baseline = "residual_ratio_tracking"
//! budget = 10                          # default: the largest budget of the test bed
//! metric = "rmse"                      # rmse (default) | mse | fom | efficiency_mse | p_eff | p_err | rmse_display | fom_display
//! side = "above"                       # its 95% interval lies above `threshold` (default 1)
//! value = 6.8                          # the paper's ratio (optional)
//! text = "Woodcock tracking has the larger error"
//!
//! [[claims]]
//! kind = "ordering"                    # each of `estimators` beats each of `others`
//! testbed = "eq21-medium/single-scatter"
//! estimators = ["mis"]
//! others = ["delta_tracking", "source_driven", "scattering_driven"]
//! budget = 300                         # default: the largest budget of the test bed
//! metric = "rmse"
//! order = "lowest"                     # lowest (default) | highest: of the metric itself
//! text = "MIS has the lowest error"    # judged at a Bonferroni level over the pairs
//!
//! [[claims]]
//! kind = "optimum"                     # the best of the candidates is one of `inside`
//! testbed = "eq21-medium/multiple"
//! inside = ["spm_adaptive[sigma_samp=0.5]", "spm_adaptive[sigma_samp=0.8]"]
//! outside = ["spm_adaptive[sigma_samp=1]", "spm_adaptive[sigma_samp=2]"]
//! metric = "fom"                       # best: lowest for errors, highest for fom and efficiencies
//! value = 0.8                          # the paper's optimum (optional, shown in the note)
//! text = "FoM peaks below sigma_samp = 1"
//!
//! [[claims]]
//! kind = "ratio_of_ratios"             # (m(n0) / m(n1)) / (m(d0) / m(d1)) against `threshold`
//! testbed = "envmap-sequence/mixed-lns"
//! numerator = ["smc[moves=1]", "smc[moves=10]"]
//! denominator = ["smc_bridge[bridges=1]", "smc_bridge[bridges=10]"]
//! side = "below"
//! text = "more moves reduce the error less than more bridges"
//!
//! [[claims]]
//! kind = "control_flagged"             # the unbiasedness test flags a biased control
//! estimator = "clamped_is0_cv0"
//! ```
//!
//! A claim is checked before anything runs ([`crate::analysis::claim_check`]): every number finite, every
//! test bed, estimator and budget it names one the sweep runs, no estimator compared with itself
//! (which [`ClaimSpec::judge`] refuses too, verdict `not measured`).

use crate::analysis::claims::{self, Family, RatioMetric, RatioSpec};
use crate::analysis::SlopeRange;
use crate::output::{Claim, RunReport};
use crate::plan::cost_model::Regime;
use serde::{Deserialize, Serialize};

/// One claim about a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ClaimSpec {
    /// The convergence slope of `estimator` on `testbed` is `value`: held when its 95% interval
    /// holds it within ±[`claims::SLOPE_TOLERANCE`], not held when it misses it, inconclusive when
    /// it holds it but is wider.
    Slope {
        /// `id/variant`.
        testbed: String,
        /// Estimator name (id with parameters).
        estimator: String,
        /// The claimed slope.
        value: f64,
        /// The claim in words.
        text: String,
        /// `whole` (default: every budget) or `right` (the last three budgets: a slope a method
        /// "reaches").
        #[serde(default)]
        range: SlopeRange,
    },
    /// `estimator` converges faster than slope `value`: held when its interval lies below, not
    /// held when above, inconclusive when it holds `value`.
    SlopeBelow {
        /// `id/variant`.
        testbed: String,
        /// Estimator name.
        estimator: String,
        /// The slope it beats.
        value: f64,
        /// The paper's own slope, shown beside ours (the claim's value when absent).
        #[serde(default)]
        paper: Option<f64>,
        /// The claim in words.
        text: String,
        /// `whole` (default) or `right`, as for `slope`.
        #[serde(default)]
        range: SlopeRange,
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
        /// The estimator it is measured against (default: the sweep's baseline).
        #[serde(default)]
        baseline: Option<String>,
        /// `measured` (CPU time, the default) or `renderer` (counted operations priced by the
        /// sweep's `[cost_model]`).
        #[serde(default)]
        regime: Regime,
    },
    /// `metric(estimator) / metric(baseline)` at `budget` lies above (or below) `threshold`,
    /// judged on its 95% interval ([`claims::ratio_claim`]): an ordering ("lower error than") at
    /// threshold 1, or a factor.
    Ratio {
        /// `id/variant`.
        testbed: String,
        /// The numerator's estimator.
        estimator: String,
        /// The denominator's estimator.
        baseline: String,
        /// The budget both are compared at (default: the largest budget of the test bed).
        #[serde(default)]
        budget: Option<u64>,
        /// `rmse` (default), `mse`, `fom`, `efficiency_mse`, `p_eff`, `p_err`, `rmse_display` or
        /// `fom_display` (values clamped to `[0, 1]` as displayed).
        #[serde(default)]
        metric: RatioMetric,
        /// The level the ratio is claimed to clear (default 1).
        #[serde(default = "one")]
        threshold: f64,
        /// `above` (default) or `below` the threshold.
        #[serde(default)]
        side: Side,
        /// The paper's ratio, when it gives one.
        #[serde(default)]
        value: Option<f64>,
        /// The claim in words.
        text: String,
    },
    /// Each of `estimators` has the lowest (or highest, `order`) `metric` against each of
    /// `others` at `budget` ([`claims::ordering_claim`]): judged on the ratio intervals of every
    /// pair at a Bonferroni level over the pairs; held when all lie on the claimed side of 1, not
    /// held when one lies on the other side, inconclusive otherwise.
    Ordering {
        /// `id/variant`.
        testbed: String,
        /// The estimators claimed to rank first (as a group).
        estimators: Vec<String>,
        /// The estimators they are claimed to beat.
        others: Vec<String>,
        /// The budget (default: the largest budget of the test bed).
        #[serde(default)]
        budget: Option<u64>,
        /// The metric, as for `ratio`.
        #[serde(default)]
        metric: RatioMetric,
        /// `lowest` (default) or `highest` value of the metric.
        #[serde(default)]
        order: Order,
        /// The paper's ratio, when it gives one.
        #[serde(default)]
        value: Option<f64>,
        /// The claim in words.
        text: String,
    },
    /// The best of `inside` and `outside` (a parameter sweep) is one of `inside` (the stated
    /// range) ([`claims::optimum_claim`]): the best inside against the best outside, both picked
    /// from the data, so every interval is at a Bonferroni level over the inside x outside pairs.
    Optimum {
        /// `id/variant`.
        testbed: String,
        /// The candidates in the stated range.
        inside: Vec<String>,
        /// The candidates outside it.
        outside: Vec<String>,
        /// The budget (default: the largest budget of the test bed).
        #[serde(default)]
        budget: Option<u64>,
        /// The metric, as for `ratio`.
        #[serde(default)]
        metric: RatioMetric,
        /// What is best: `lowest` or `highest` (default: lowest for errors, highest for `fom`,
        /// `efficiency_mse` and `p_eff`).
        #[serde(default)]
        best: Option<Order>,
        /// The paper's number (e.g. its optimal parameter), shown in the note.
        #[serde(default)]
        value: Option<f64>,
        /// The claim in words.
        text: String,
    },
    /// `(metric(n0) / metric(n1)) / (metric(d0) / metric(d1))` lies above (or below) `threshold`
    /// ([`claims::ratio_of_ratios_claim`]): e.g. one change reduces the error less than another.
    RatioOfRatios {
        /// `id/variant`.
        testbed: String,
        /// The numerator's pair `[n0, n1]`.
        numerator: [String; 2],
        /// The denominator's pair `[d0, d1]`.
        denominator: [String; 2],
        /// The budget (default: the largest budget of the test bed).
        #[serde(default)]
        budget: Option<u64>,
        /// The metric, as for `ratio`.
        #[serde(default)]
        metric: RatioMetric,
        /// The level the ratio is claimed to clear (default 1).
        #[serde(default = "one")]
        threshold: f64,
        /// `above` (default) or `below` the threshold.
        #[serde(default)]
        side: Side,
        /// The paper's number, when it gives one.
        #[serde(default)]
        value: Option<f64>,
        /// The claim in words.
        text: String,
    },
    /// The mean per estimate of a diagnostic `name` of `estimator` at `budget` is `value` within a
    /// relative `tolerance` (e.g. a cache's cell count).
    Diagnostic {
        /// `id/variant`.
        testbed: String,
        /// Estimator name.
        estimator: String,
        /// The budget.
        budget: u64,
        /// The diagnostic's name.
        name: String,
        /// The paper's number.
        value: f64,
        /// Relative tolerance.
        tolerance: f64,
        /// The claim in words.
        text: String,
    },
    /// The biased control `estimator` is flagged by the unbiasedness tests.
    ControlFlagged {
        /// Estimator name.
        estimator: String,
    },
}

/// Which side of its threshold a ratio claim puts the ratio.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// Above the threshold.
    #[default]
    Above,
    /// Below the threshold.
    Below,
}

/// Which end of a metric an ordering or optimum claim is about.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Order {
    /// The smallest value.
    #[default]
    Lowest,
    /// The largest value.
    Highest,
}

fn one() -> f64 {
    1.0
}

fn names(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

fn split(testbed: &str) -> (&str, &str) {
    testbed.split_once('/').unwrap_or((testbed, ""))
}

impl ClaimSpec {
    /// The `id/variant` the claim is about (none for `control_flagged`).
    pub fn testbed(&self) -> Option<&str> {
        match self {
            ClaimSpec::Slope { testbed, .. }
            | ClaimSpec::SlopeBelow { testbed, .. }
            | ClaimSpec::Speedup { testbed, .. }
            | ClaimSpec::Ratio { testbed, .. }
            | ClaimSpec::Ordering { testbed, .. }
            | ClaimSpec::Optimum { testbed, .. }
            | ClaimSpec::RatioOfRatios { testbed, .. }
            | ClaimSpec::Diagnostic { testbed, .. } => Some(testbed),
            ClaimSpec::ControlFlagged { .. } => None,
        }
    }

    /// Every estimator the claim names.
    pub fn estimators(&self) -> Vec<&str> {
        match self {
            ClaimSpec::Slope { estimator, .. }
            | ClaimSpec::SlopeBelow { estimator, .. }
            | ClaimSpec::Diagnostic { estimator, .. }
            | ClaimSpec::ControlFlagged { estimator } => vec![estimator],
            ClaimSpec::Speedup { estimator, baseline, .. } => {
                std::iter::once(estimator.as_str()).chain(baseline.as_deref()).collect()
            }
            ClaimSpec::Ratio { estimator, baseline, .. } => vec![estimator, baseline],
            ClaimSpec::Ordering { estimators: a, others: b, .. } | ClaimSpec::Optimum { inside: a, outside: b, .. } => {
                a.iter().chain(b).map(String::as_str).collect()
            }
            ClaimSpec::RatioOfRatios { numerator, denominator, .. } => {
                numerator.iter().chain(denominator).map(String::as_str).collect()
            }
        }
    }

    /// Judges the claim on a finished run.
    pub fn judge(&self, report: &RunReport) -> Claim {
        match self {
            ClaimSpec::Slope { testbed, estimator, value, text, range } => {
                claims::slope_matches_over(report, split(testbed), (estimator, *range), *value, text)
            }
            ClaimSpec::SlopeBelow { testbed, estimator, value, paper, text, range } => {
                let mut c = claims::slope_steeper_than(report, split(testbed), (estimator, *range), *value, text);
                if let Some(p) = paper {
                    c.reason = format!("{}; the paper's slope is {p}", c.reason);
                    c.paper_value = Some(*p);
                }
                c
            }
            ClaimSpec::Diagnostic { testbed, estimator, budget, name, value, tolerance, text } => {
                claims::diagnostic_claim(report, split(testbed), (estimator, *budget, name), *value, *tolerance, text)
            }
            ClaimSpec::Speedup { testbed, estimator, value, text, baseline, regime } => {
                claims::speedup_claim(report, split(testbed), (estimator, baseline.as_deref()), *value, text, *regime)
            }
            ClaimSpec::Ratio { testbed, estimator, baseline, budget, metric, threshold, side, value, text } => {
                let tb = split(testbed);
                let budget = budget.or_else(|| claims::ordering::largest_budget(report, tb)).unwrap_or(0);
                let spec = RatioSpec {
                    tb,
                    estimator,
                    baseline,
                    budget,
                    metric: *metric,
                    threshold: *threshold,
                    above: *side == Side::Above,
                    paper: *value,
                };
                if estimator == baseline {
                    let base = Claim {
                        testbed: testbed.clone(),
                        claim: text.clone(),
                        paper_value: *value,
                        pair: format!("{estimator} vs {baseline}"),
                        ..Default::default()
                    };
                    return claims::ordering::refused(base, estimator);
                }
                claims::ratio_claim(report, &spec, text, "")
            }
            ClaimSpec::Ordering { testbed, estimators, others, budget, metric, order, value, text } => {
                let family = Family { tb: split(testbed), budget: *budget, metric: *metric, paper: *value };
                let (e, o) = (names(estimators), names(others));
                claims::ordering_claim(report, &family, (&e, &o), *order == Order::Lowest, text)
            }
            ClaimSpec::Optimum { testbed, inside, outside, budget, metric, best, value, text } => {
                let family = Family { tb: split(testbed), budget: *budget, metric: *metric, paper: None };
                let lowest = best.map_or(claims::ordering::lower_is_better(*metric), |b| b == Order::Lowest);
                let (i, o) = (names(inside), names(outside));
                let mut c = claims::optimum_claim(report, &family, (&i, &o), lowest, text);
                if let Some(v) = value {
                    c.note = format!("{}; the paper's optimum: {v}", c.note);
                }
                c
            }
            ClaimSpec::RatioOfRatios {
                testbed,
                numerator,
                denominator,
                budget,
                metric,
                threshold,
                side,
                value,
                text,
            } => {
                let family = Family { tb: split(testbed), budget: *budget, metric: *metric, paper: *value };
                let n = [numerator[0].as_str(), numerator[1].as_str()];
                let d = [denominator[0].as_str(), denominator[1].as_str()];
                let claimed = (*threshold, *side == Side::Above);
                claims::ratio_of_ratios_claim(report, &family, (n, d), claimed, text)
            }
            ClaimSpec::ControlFlagged { estimator } => claims::control_flagged(report, estimator),
        }
    }
}

#[cfg(test)]
#[path = "claim_spec_tests.rs"]
mod tests;
