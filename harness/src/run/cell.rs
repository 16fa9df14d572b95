//! One cell of a sweep, (test bed, variant, estimator, budget), and its sufficient statistics:
//! per-integral moments over repetitions, cost totals, and log-histograms of estimate times (wall
//! clock and the thread's CPU clock).
//! Cells are what the harness stores for resuming and what shards will merge. Beside the totals, a
//! cell keeps a few contiguous blocks of repetitions ([`RepBlock`]) with the aggregates that
//! resampling needs: the intervals of ratio claims are a bootstrap over them
//! ([`crate::analysis::claims::bootstrap`]).

use mcbench_core::budget::Budget;
use mcbench_core::stats::Moments;
use mcbench_core::task::Costs;
use serde::{Deserialize, Serialize};

/// What identifies a cell's result: equal keys give equal results.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellKey {
    /// Test bed id.
    pub testbed: String,
    /// Variant.
    pub variant: String,
    /// Test-bed parameters as JSON text.
    pub testbed_params: String,
    /// Estimator name (id with parameters).
    pub estimator: String,
    /// Budget.
    pub budget: Budget,
    /// Repetitions.
    pub reps: usize,
    /// Seed.
    pub seed: u64,
    /// Harness version that made it.
    pub version: String,
}

impl CellKey {
    /// The cell's name in a store ([`crate::store`]): a short readable prefix (test bed, variant,
    /// estimator and budget, each cut to 32 characters) and a digest of the whole key, so that no
    /// parameter value can make the name long (the key itself is inside the record and checked on
    /// reading).
    pub fn name(&self) -> String {
        let text = serde_json::to_string(self).unwrap_or_default();
        let clean = |s: &str| {
            s.chars().take(32).map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect::<String>()
        };
        format!(
            "{}_{}_{}_{}{}_{:016x}",
            clean(&self.testbed),
            clean(&self.variant),
            clean(&self.estimator),
            self.budget.kind.name(),
            self.budget.amount,
            mcbench_core::rng::fnv1a(&text)
        )
    }
}

/// Estimate times: total and a histogram of `round(16 log2(seconds))` for medians.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TimeStats {
    /// Sum of seconds (one thread's, per estimate).
    pub total: f64,
    /// Number of timed estimates.
    pub count: u64,
    /// (bin, count) pairs, bins increasing.
    pub hist: Vec<(i32, u64)>,
}

impl TimeStats {
    const BINS_PER_OCTAVE: f64 = 16.0;
    /// Records one estimate's time.
    pub fn push(&mut self, seconds: f64) {
        self.total += seconds;
        self.count += 1;
        let bin = (seconds.max(1e-12).log2() * Self::BINS_PER_OCTAVE).round() as i32;
        match self.hist.binary_search_by_key(&bin, |p| p.0) {
            Ok(i) => self.hist[i].1 += 1,
            Err(i) => self.hist.insert(i, (bin, 1)),
        }
    }
    /// Merges another record.
    pub fn merge(&mut self, o: &TimeStats) {
        self.total += o.total;
        self.count += o.count;
        for &(bin, n) in &o.hist {
            match self.hist.binary_search_by_key(&bin, |p| p.0) {
                Ok(i) => self.hist[i].1 += n,
                Err(i) => self.hist.insert(i, (bin, n)),
            }
        }
    }
    /// Mean seconds per estimate.
    pub fn mean(&self) -> f64 {
        self.total / self.count.max(1) as f64
    }
    /// Median seconds per estimate (to the histogram's 4% resolution).
    pub fn median(&self) -> f64 {
        let half = self.count.div_ceil(2);
        let mut seen = 0;
        for &(bin, n) in &self.hist {
            seen += n;
            if seen >= half {
                return (bin as f64 / Self::BINS_PER_OCTAVE).exp2();
            }
        }
        f64::NAN
    }
}

/// At most this many repetition blocks per cell ([`CellResult::blocks`]).
pub const MAX_REP_BLOCKS: usize = 32;

/// Repetitions per block of a cell of `reps` repetitions: the fewest that make at most
/// [`MAX_REP_BLOCKS`] blocks. Block `k` holds repetitions `k * size .. (k + 1) * size` (the last may
/// be shorter), so the layout depends on `reps` alone, never on threads or shards.
pub fn rep_block_size(reps: usize) -> usize {
    reps.div_ceil(MAX_REP_BLOCKS).max(1)
}

/// The number of repetition blocks of a cell of `reps` repetitions.
pub fn rep_block_count(reps: usize) -> usize {
    reps.div_ceil(rep_block_size(reps))
}

/// The aggregates of one contiguous block of a cell's repetitions: what a bootstrap over
/// repetitions needs to recompute every ratio metric (MSE, paper 003's `Err`, CPU seconds and
/// counted costs per estimate) from a resample of blocks. Sums run in repetition order.
///
/// Two cells of one (test bed, budget) computed by one run were interleaved repetition by
/// repetition ([`crate::run::interleave`]), so their block `k` covers the same stretch of time: load
/// that slowed one slowed the other in the same block, which a paired resample keeps.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RepBlock {
    /// Repetitions in the block.
    pub reps: u64,
    /// Sum over the block's repetitions of each repetition's mean squared deviation from the
    /// reference over integrals and channels (the values of [`CellResult::rep_sq`]).
    pub sq: f64,
    /// Sum over the block's repetitions of each repetition's paper 003 error: the mean over
    /// integrals of the channel-mean squared deviation over `tvi(L_ref)`.
    pub p_err: f64,
    /// CPU seconds of the block's estimates (the clock of [`CellResult::metric_time`]; timing).
    pub cpu_seconds: f64,
    /// Sum over the block's repetitions of each repetition's mean squared deviation of the
    /// display-clamped values: every estimate and the reference clamped to `[0, 1]`, as an image
    /// is shown (paper 002 §4.2 clips negative estimates for display). `None` in cells stored
    /// before it was kept.
    #[serde(default)]
    pub display_sq: Option<f64>,
    /// Wall-clock seconds of the block's estimates (timing).
    pub wall_seconds: f64,
    /// Counted costs of the block's estimates.
    pub costs: Costs,
}

impl RepBlock {
    /// Adds another part of the same block (repetitions in order).
    pub fn merge(&mut self, o: &RepBlock) {
        self.display_sq = match (self.reps, o.reps) {
            (0, _) => o.display_sq,
            (_, 0) => self.display_sq,
            _ => self.display_sq.zip(o.display_sq).map(|(a, b)| a + b),
        };
        self.reps += o.reps;
        self.sq += o.sq;
        self.p_err += o.p_err;
        self.cpu_seconds += o.cpu_seconds;
        self.wall_seconds += o.wall_seconds;
        self.costs += o.costs;
    }
}

/// The sufficient statistics of one cell.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellResult {
    /// What it is.
    pub key: CellKey,
    /// Per integral, per channel: moments of the estimates over repetitions.
    pub moments: Vec<[Moments; 3]>,
    /// Cost totals over all estimates.
    pub costs: Costs,
    /// Number of estimates (reps x integrals).
    pub estimates: u64,
    /// Estimate times on the wall clock.
    pub time: TimeStats,
    /// Estimate times on the estimating thread's CPU clock, read per work item and spread over its
    /// estimates by their wall-clock times ([`crate::run::cputime`]): what time-based metrics use,
    /// since load from other processes does not inflate it. `None`
    /// in cells stored before it was measured (their metrics fall back to [`Self::time`]).
    #[serde(default)]
    pub cpu_time: Option<TimeStats>,
    /// Sums over estimates of each diagnostic the estimator noted (name, sum).
    #[serde(default)]
    pub diagnostics: Vec<(String, f64)>,
    /// Over repetitions: each repetition's summed deviation from the reference, over every integral
    /// and channel (`sum (estimate - reference)`). Repetitions are independent even where the
    /// integrals of one repetition share adaptive state or channels are correlated, so tests and
    /// error bars over these are valid everywhere.
    #[serde(default)]
    pub rep_dev: Moments,
    /// Over repetitions: each repetition's mean squared deviation from the reference over integrals
    /// and channels (their mean is the cell's MSE before the reference-variance correction).
    #[serde(default)]
    pub rep_sq: Moments,
    /// The repetitions in [`rep_block_count`] contiguous blocks ([`rep_block_size`] each), with
    /// what a bootstrap over repetitions resamples. A part of a cell (a shard's block of
    /// repetitions) has every block, empty ones where it holds none of their repetitions. Empty
    /// in cells stored before blocks were kept: their ratio intervals use the delta method.
    #[serde(default)]
    pub blocks: Vec<RepBlock>,
}

impl CellResult {
    /// The times time-based metrics use: CPU times, or wall times for a cell stored before CPU
    /// times were measured (the second value says which: `true` for CPU).
    pub fn metric_time(&self) -> (&TimeStats, bool) {
        match &self.cpu_time {
            Some(t) => (t, true),
            None => (&self.time, false),
        }
    }

    /// Merges another part's CPU times into this one's; a part without them (stored before they
    /// were measured) leaves the merged cell without them, so it falls back to wall time as a whole.
    pub fn merge_cpu_time(&mut self, other: &CellResult) {
        match (&mut self.cpu_time, &other.cpu_time) {
            (Some(a), Some(b)) => a.merge(b),
            _ => self.cpu_time = None,
        }
    }

    /// Merges another part's repetition blocks into this one's, block by block; a part without
    /// them (or with another layout) leaves the merged cell without them.
    pub fn merge_blocks(&mut self, other: &CellResult) {
        if self.blocks.len() == other.blocks.len() {
            self.blocks.iter_mut().zip(&other.blocks).for_each(|(a, b)| a.merge(b));
        } else {
            self.blocks.clear();
        }
    }

    /// Checks a cell read back from a file against what the plan expects of it: `integrals`
    /// integrals with `reps` repetitions each, `reps x integrals` estimates, finite statistics.
    /// `Err` says what is wrong, for a one-line refusal naming the file.
    pub fn check_shape(&self, integrals: usize, reps: usize) -> Result<(), String> {
        if self.moments.len() != integrals {
            return Err(format!("{} integrals, the test bed has {integrals}", self.moments.len()));
        }
        let expected = (integrals as u64).saturating_mul(reps as u64);
        if self.estimates != expected {
            return Err(format!(
                "{} estimates, {reps} repetitions of {integrals} integrals are {expected}",
                self.estimates
            ));
        }
        for (i, m) in self.moments.iter().enumerate() {
            for (c, mc) in m.iter().enumerate() {
                if mc.count() != reps as u64 {
                    return Err(format!("integral {i} channel {c} has {} repetitions, not {reps}", mc.count()));
                }
                if let Err(e) = mc.check() {
                    return Err(format!("integral {i} channel {c}: {e}"));
                }
            }
        }
        if self.time.count != self.estimates || !self.time.total.is_finite() || self.time.total < 0.0 {
            return Err("its estimate times do not match its estimates".into());
        }
        if let Some(t) = &self.cpu_time {
            if t.count != self.estimates || !t.total.is_finite() || t.total < 0.0 {
                return Err("its CPU times do not match its estimates".into());
            }
        }
        if let Some((name, _)) = self.diagnostics.iter().find(|(_, v)| !v.is_finite()) {
            return Err(format!("diagnostic `{name}` is not finite"));
        }
        for (name, m) in [("rep_dev", &self.rep_dev), ("rep_sq", &self.rep_sq)] {
            if m.count() != reps as u64 {
                return Err(format!("{name} holds {} repetitions, not {reps}", m.count()));
            }
            m.check().map_err(|e| format!("{name}: {e}"))?;
        }
        if !self.blocks.is_empty() {
            let expected = rep_block_count(self.key.reps);
            if self.blocks.len() != expected {
                return Err(format!(
                    "{} repetition blocks, {} repetitions make {expected}",
                    self.blocks.len(),
                    self.key.reps
                ));
            }
            let held: u64 = self.blocks.iter().map(|b| b.reps).sum();
            if held != reps as u64 {
                return Err(format!("its repetition blocks hold {held} repetitions, not {reps}"));
            }
            let bad = |b: &RepBlock| {
                [b.sq, b.p_err, b.cpu_seconds, b.wall_seconds, b.display_sq.unwrap_or(0.0)]
                    .iter()
                    .any(|v| !(v.is_finite() && *v >= 0.0))
            };
            if self.blocks.iter().any(bad) {
                return Err("a repetition block holds a negative or non-finite sum".into());
            }
        }
        Ok(())
    }
}

/// Adds `(name, value)` pairs into running sums, keeping first-appearance order.
pub fn add_diagnostics(sums: &mut Vec<(String, f64)>, add: &[(impl AsRef<str>, f64)]) {
    for (name, v) in add {
        match sums.iter_mut().find(|(n, _)| n == name.as_ref()) {
            Some(slot) => slot.1 += v,
            None => sums.push((name.as_ref().to_string(), *v)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_times_within_histogram_resolution() {
        let mut t = TimeStats::default();
        for s in [1e-6, 2e-6, 3e-6, 4e-6, 100e-6] {
            t.push(s);
        }
        assert!((t.median() / 3e-6 - 1.0).abs() < 0.03, "{}", t.median());
        let mut u = TimeStats::default();
        u.merge(&t);
        assert_eq!(u, t);
    }

    #[test]
    fn display_errors_merge_as_sums_and_a_block_without_them_leaves_none() {
        let block = |reps, d| RepBlock { reps, sq: 1.0, display_sq: d, ..Default::default() };
        let mut b = RepBlock::default();
        b.merge(&block(2, Some(0.5)));
        b.merge(&block(1, Some(0.25)));
        assert_eq!((b.reps, b.display_sq), (3, Some(0.75)));
        b.merge(&block(0, None));
        assert_eq!(b.display_sq, Some(0.75), "an empty part changes nothing");
        b.merge(&block(1, None));
        assert_eq!(b.display_sq, None, "a part stored before display errors were kept");
    }
}
