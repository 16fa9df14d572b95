//! Compensated running sums of RGB samples, for long accumulations (book: stability.md).

use crate::math::Rgb;
use crate::stats::NeumaierSum;

/// The mean of a stream of RGB samples with Neumaier-compensated sums per channel.
#[derive(Clone, Debug, Default)]
pub struct RgbMean {
    sums: [NeumaierSum; 3],
    n: u64,
}

impl RgbMean {
    /// An empty accumulator.
    pub fn new() -> Self {
        Self::default()
    }
    /// Adds one sample.
    #[inline]
    pub fn push(&mut self, x: Rgb) {
        for (s, v) in self.sums.iter_mut().zip(x.0) {
            s.add(v);
        }
        self.n += 1;
    }
    /// Number of samples.
    pub fn count(&self) -> u64 {
        self.n
    }
    /// The mean (zero when empty: an estimator that drew no sample estimates nothing).
    pub fn mean(&self) -> Rgb {
        if self.n == 0 {
            return Rgb::ZERO;
        }
        Rgb([self.sums[0].value(), self.sums[1].value(), self.sums[2].value()]) / self.n as f64
    }
}
