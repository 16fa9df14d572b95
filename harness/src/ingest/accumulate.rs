//! A cell's sufficient statistics from repetitions read from files, reduced the way a run reduces
//! the repetitions it computes ([`crate::run::interleave`]): per integral and channel moments, each
//! repetition's summed and mean squared deviation from the reference, repetition blocks with their
//! errors, CPU seconds and costs. A repetition's seconds (when the producer measured them) are spread
//! evenly over its integrals; without them every time is 0 and the time-based metrics are empty.

use crate::run::cell::{rep_block_count, rep_block_size, CellKey, CellResult, RepBlock, TimeStats};
use mcbench_core::math::Rgb;
use mcbench_core::stats::{Moments, NeumaierSum};
use mcbench_core::task::Costs;
use mcbench_core::testbed::Reference;

/// Builds one cell repetition by repetition.
pub struct CellBuilder<'a> {
    cell: CellResult,
    reference: &'a Reference,
    inv_tvi: Vec<f64>,
    samples: u64,
    rep: usize,
    timed: bool,
}

impl<'a> CellBuilder<'a> {
    /// An empty cell under `key` for `reference`'s integrals at `samples` samples per integral.
    pub fn new(key: CellKey, reference: &'a Reference, samples: u64) -> Self {
        let n = reference.value.len();
        let blocks = vec![RepBlock::default(); rep_block_count(key.reps)];
        let inv_tvi = reference
            .value
            .iter()
            .map(|v| 1.0 / mcbench_core::perception::tvi(mcbench_core::perception::luminance(*v)))
            .collect();
        let cell = CellResult {
            key,
            moments: vec![[Moments::default(), Moments::default(), Moments::default()]; n],
            costs: Costs::default(),
            estimates: 0,
            time: TimeStats::default(),
            cpu_time: None,
            diagnostics: Vec::new(),
            rep_dev: Moments::default(),
            rep_sq: Moments::default(),
            blocks,
        };
        CellBuilder { cell, reference, inv_tvi, samples, rep: 0, timed: false }
    }

    /// Adds the next repetition: one value per integral (as many as the reference has) and its
    /// seconds when measured.
    pub fn push(&mut self, values: &[Rgb], seconds: Option<f64>) {
        let n = values.len().min(self.reference.value.len());
        let (mut dev, mut sq, mut p_err, mut display) =
            (NeumaierSum::new(), NeumaierSum::new(), NeumaierSum::new(), NeumaierSum::new());
        for (i, (&v, &r)) in values.iter().zip(&self.reference.value).enumerate() {
            let mut sq_i = 0.0;
            for c in 0..3 {
                self.cell.moments[i][c].push(v[c]);
                let d = v[c] - r[c];
                dev.add(d);
                sq.add(d * d);
                sq_i += d * d;
                let shown = v[c].clamp(0.0, 1.0) - r[c].clamp(0.0, 1.0);
                display.add(shown * shown);
            }
            p_err.add(sq_i / 3.0 * self.inv_tvi[i]);
        }
        let count = (3 * n).max(1) as f64;
        let rep_sq = sq.value() / count;
        self.cell.rep_dev.push(dev.value());
        self.cell.rep_sq.push(rep_sq);
        let costs = Costs { samples: self.samples.saturating_mul(n as u64), ..Costs::default() };
        let secs = seconds.unwrap_or(0.0);
        self.timed |= seconds.is_some();
        let block = self.rep / rep_block_size(self.cell.key.reps);
        if let Some(b) = self.cell.blocks.get_mut(block) {
            b.reps += 1;
            b.sq += rep_sq;
            b.p_err += p_err.value() / n.max(1) as f64;
            b.display_sq = Some(b.display_sq.unwrap_or(0.0) + display.value() / count);
            b.cpu_seconds += secs;
            b.wall_seconds += secs;
            b.costs += costs;
        }
        self.cell.costs += costs;
        self.cell.estimates += n as u64;
        match seconds {
            Some(s) => (0..n).for_each(|_| self.cell.time.push(s / n.max(1) as f64)),
            None => self.cell.time.count += n as u64,
        }
        self.rep += 1;
    }

    /// The finished cell. Its CPU times are the measured seconds; when no repetition had seconds
    /// the cell has only zero wall times, so every time-based metric is empty (`cpu_seconds` 0,
    /// efficiencies blank).
    pub fn finish(mut self) -> CellResult {
        self.cell.cpu_time = Some(self.cell.time.clone());
        if !self.timed {
            self.cell.time.hist.clear();
        }
        self.cell
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mcbench_core::budget::{Budget, BudgetKind};
    use mcbench_core::testbed::ReferenceKind;

    fn key(reps: usize) -> CellKey {
        CellKey {
            testbed: "t".into(),
            variant: "v".into(),
            testbed_params: "{}".into(),
            estimator: "e".into(),
            budget: Budget { kind: BudgetKind::Samples, amount: 4 },
            reps,
            seed: 0,
            version: "x".into(),
        }
    }

    #[test]
    fn a_cell_of_read_repetitions_passes_the_stored_cell_checks() {
        let reference = Reference {
            kind: ReferenceKind::Exact { method: "test".into(), bound: 0.0 },
            value: vec![Rgb([1.0; 3]); 2],
            std_err: vec![Rgb::ZERO; 2],
        };
        let mut b = CellBuilder::new(key(3), &reference, 4);
        for (k, v) in [0.5, 1.5, 1.0].into_iter().enumerate() {
            b.push(&[Rgb([v; 3]), Rgb([1.0; 3])], Some(k as f64));
        }
        let cell = b.finish();
        assert_eq!(cell.check_shape(2, 3), Ok(()));
        assert_eq!(cell.costs.samples, 3 * 2 * 4);
        assert_eq!(cell.moments[0][1].mean(), 1.0);
        assert_eq!(cell.rep_dev.mean(), 0.0, "deviations +-1.5 and 0 sum to zero");
        assert!((cell.rep_sq.mean() - (0.25 * 3.0 / 6.0) * 2.0 / 3.0).abs() < 1e-15);
        assert_eq!(cell.cpu_time.as_ref().unwrap().total, 3.0);
    }
}
