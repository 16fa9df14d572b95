//! The band drawn around a cell's RMSE: a 90% bootstrap interval over the cell's repetition blocks
//! ([`crate::run::cell::RepBlock`]), written to `summary.csv` as `rmse_lo` and `rmse_hi`.
//!
//! A resample draws as many blocks as the cell has, with replacement, and recomputes the RMSE
//! from their summed squared errors as the row does (`sqrt(max(sum sq / reps + offset, 0))`,
//! the offset carrying the stored reference's variance). The interval is the expanded percentile
//! interval of the ratio claims ([`crate::analysis::claims::bootstrap`]), which undoes the narrowness of a
//! bootstrap of few blocks. The resamples come from a generator seeded from the cell's key, so the
//! same cell gives the same band bit for bit, whatever the threads or shards that computed it.

use crate::analysis::claims::bootstrap::{seed_of, Bootstrap, RESAMPLES};
use crate::run::cell::{CellKey, RepBlock};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// The band's coverage.
pub const LEVEL: f64 = 0.90;

/// The seed of a cell's band: FNV-1a of its key.
pub fn seed(key: &CellKey) -> u64 {
    seed_of(&format!("rmse band {}", serde_json::to_string(key).unwrap_or_default()))
}

/// The [`LEVEL`] interval of the RMSE of a cell with `blocks`, whose MSE is the blocks' mean
/// squared error plus `mse_offset`; `None` with fewer than two blocks or an empty one.
pub fn rmse_band(blocks: &[RepBlock], mse_offset: f64, seed: u64) -> Option<(f64, f64)> {
    let n = blocks.len();
    if n < 2 || blocks.iter().any(|b| b.reps == 0) || !mse_offset.is_finite() {
        return None;
    }
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut replicates: Vec<f64> = (0..RESAMPLES)
        .map(|_| {
            let (mut sq, mut reps) = (0.0, 0u64);
            for _ in 0..n {
                let b = &blocks[rng.gen_range(0..n)];
                sq += b.sq;
                reps += b.reps;
            }
            (sq / reps as f64 + mse_offset).max(0.0).sqrt()
        })
        .filter(|v| v.is_finite())
        .collect();
    if replicates.len() < RESAMPLES {
        return None;
    }
    replicates.sort_by(f64::total_cmp);
    // The expanded percentile interval is a pair of quantiles of the replicates, whatever the
    // statistic (here the RMSE itself, not a log ratio).
    let boot = Bootstrap {
        estimate: f64::NAN,
        replicates,
        blocks: n,
        paired: false,
        log95: (f64::NAN, f64::NAN),
        method: String::new(),
    };
    boot.log_interval_at(LEVEL)
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::task::Costs;

    fn block(reps: u64, sq: f64) -> RepBlock {
        RepBlock {
            reps,
            sq,
            p_err: 0.0,
            cpu_seconds: 0.0,
            display_sq: None,
            wall_seconds: 0.0,
            costs: Costs::default(),
        }
    }

    #[test]
    fn the_band_brackets_the_rmse_and_repeats_bit_for_bit() {
        let blocks: Vec<RepBlock> = (0..16).map(|k| block(2, 0.02 * (1.0 + (k as f64).sqrt()))).collect();
        let rmse = (blocks.iter().map(|b| b.sq).sum::<f64>() / 32.0).sqrt();
        let (lo, hi) = rmse_band(&blocks, 0.0, 7).expect("a band");
        assert!(lo < rmse && rmse < hi, "{lo} {rmse} {hi}");
        assert!(hi / lo < 1.5, "16 blocks of moderate spread give a narrow band: {lo} {hi}");
        assert_eq!(rmse_band(&blocks, 0.0, 7), Some((lo, hi)));
        assert_ne!(rmse_band(&blocks, 0.0, 8), Some((lo, hi)), "another seed, other resamples");
        // A stored reference's variance (negative offset) lowers the band, never below 0.
        let (l2, h2) = rmse_band(&blocks, -0.01, 7).unwrap();
        assert!(l2 >= 0.0 && l2 < lo && h2 < hi);
    }

    #[test]
    fn too_few_or_empty_blocks_give_no_band() {
        assert_eq!(rmse_band(&[block(4, 1.0)], 0.0, 1), None);
        assert_eq!(rmse_band(&[block(4, 1.0), block(0, 0.0)], 0.0, 1), None);
        assert_eq!(rmse_band(&[], 0.0, 1), None);
    }
}
