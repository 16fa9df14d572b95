//! The cell storage of a radiance cache (paper 001 §4.1-4.3, paper 000 §4.1-4.3).
//!
//! A regular `ns x nt` grid over the `(s, t)` square of a [`Domain`] (cells of equal solid angle),
//! cell `j * ns + i` covering `s in [i, i + 1) / ns`, `t in [j, j + 1) / nt`; row 0 touches the
//! pole `t = 0`. Per cell:
//! - the RGB running mean of the cached integrand samples, the B-spline coefficients of `g`
//!   (weights `1/(C+1)` and `C/(C+1)`, §4.1);
//! - the scalar PDF coefficient, the running mean of the mean over channels of `|f - g|` (§4.2);
//! - the record counter `C` (`u32`, saturating: 1e7 records into one cell are far from overflow).
//!
//! Layout: the RGB coefficients and the counter of a cell sit together (one `Cell`: a record
//! reads and writes both, and `g` reads the RGB of the cells around the drawn one), the PDF
//! coefficients in an array of their own (the cell sampler scans runs of them).
//!
//! The sum of all coefficients and the sums of the first and last rows (the polar values, §4.1)
//! are kept current on every write with compensated sums (adding the new value and subtracting the
//! old one as separate terms), so the reconstruction reads `G` and the polar values in `O(1)`.
//! Refinement (§4.3) doubles both resolutions, duplicates the records into the four children and
//! divides the counters by a divisor (4 on surfaces), never rounding a counter down to zero.

use super::domain::{Domain, St};
use super::huge_pages::{span_of, Span};
use super::storage::Scalar;
use mcbench_core::math::Rgb;
use mcbench_core::stats::NeumaierSum;

/// Which maintained coefficient sum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Sum {
    All = 0,
    FirstRow = 1,
    LastRow = 2,
}

/// The RGB coefficient and the counter of one cell: 16 bytes in single precision, 28 in double
/// (packed to 4-byte alignment, so the double-precision cell keeps paper 001's 36 bytes with its
/// PDF coefficient; fields are read and written by copy, never by reference).
#[derive(Clone, Copy, Debug, Default)]
#[repr(C, packed(4))]
struct Cell<S: Scalar> {
    rgb: [S; 3],
    count: u32,
}

/// The cells of one directional cache (fields in a fixed order, the polar sums last: see
/// [`super::RadianceCache`]).
#[derive(Clone, Debug)]
#[repr(C)]
pub struct Grid<S: Scalar> {
    ns: usize,
    nt: usize,
    cells: Vec<Cell<S>>,
    pdf: Vec<S>,
    records: u64,
    /// `log2(ns)` when `ns` is a power of two (always, for the domains' grids): rows by shifts.
    ns_shift: Option<u32>,
    refinements: u32,
    domain: Domain,
    sums: [[NeumaierSum; 3]; 3],
}

impl<S: Scalar> Grid<S> {
    /// An empty grid at the domain's initial resolution, every coefficient and counter zero.
    pub fn new(domain: Domain) -> Self {
        let (ns, nt) = domain.initial_resolution();
        Self::with_resolution(domain, ns, nt)
    }

    /// An empty grid of `ns x nt` cells (for tests and for caches that start finer).
    pub fn with_resolution(domain: Domain, ns: usize, nt: usize) -> Self {
        assert!(ns >= 1 && nt >= 1, "a grid needs at least one cell");
        let n = ns * nt;
        Grid {
            domain,
            ns,
            nt,
            refinements: 0,
            ns_shift: ns.is_power_of_two().then(|| ns.trailing_zeros()),
            cells: vec![Cell::default(); n],
            pdf: vec![S::default(); n],
            records: 0,
            sums: Default::default(),
        }
    }

    /// The domain.
    pub fn domain(&self) -> Domain {
        self.domain
    }
    /// Resolution `(ns, nt)`.
    pub fn resolution(&self) -> (usize, usize) {
        (self.ns, self.nt)
    }
    /// Number of cells.
    pub fn cells(&self) -> usize {
        self.ns * self.nt
    }
    /// How many times the grid was refined (the paper's depth).
    pub fn refinements(&self) -> u32 {
        self.refinements
    }
    /// Sum of the record counters.
    pub fn records(&self) -> u64 {
        self.records
    }
    /// Mean record count per cell (the refinement criterion's quantity, §4.4).
    pub fn mean_count(&self) -> f64 {
        self.records as f64 / self.cells() as f64
    }

    /// The cell containing `st` (the closed upper edges `s = 1`, `t = 1` belong to the last cells).
    #[inline]
    pub fn cell_at(&self, st: St) -> usize {
        let i = floor_index(st.s * self.ns as f64).min(self.ns - 1);
        let j = floor_index(st.t * self.nt as f64).min(self.nt - 1);
        j * self.ns + i
    }
    /// Column `i` and row `j` of a cell.
    #[inline]
    pub fn cell_ij(&self, cell: usize) -> (usize, usize) {
        let j = self.row_of(cell);
        (cell - j * self.ns, j)
    }
    #[inline]
    fn row_of(&self, cell: usize) -> usize {
        match self.ns_shift {
            Some(k) => cell >> k,
            None => cell / self.ns,
        }
    }
    /// The RGB coefficient of a cell.
    #[inline]
    pub fn radiance(&self, cell: usize) -> Rgb {
        let c = self.cells[cell].rgb;
        Rgb([c[0].get(), c[1].get(), c[2].get()])
    }
    /// The RGB coefficient of column `i` (taken modulo `ns`: periodic in `s`) and row `j`.
    pub fn radiance_ij(&self, i: usize, j: usize) -> Rgb {
        self.radiance(j * self.ns + i % self.ns)
    }
    /// The PDF coefficient of a cell.
    pub fn pdf_coefficient(&self, cell: usize) -> f64 {
        self.pdf[cell].get()
    }
    /// The PDF coefficients of every cell.
    pub fn pdf_coefficients(&self) -> impl ExactSizeIterator<Item = f64> + Clone + '_ {
        self.pdf.iter().map(|p| p.get())
    }
    /// The stored PDF coefficients, in cell order.
    pub fn pdf_slice(&self) -> &[S] {
        &self.pdf
    }
    /// Requests the lines of the RGB coefficients and counters of cells `first..first + count`
    /// (clamped to the grid: nothing when `first` is past its end).
    #[inline]
    pub fn prefetch_cells(&self, first: usize, count: usize) {
        if first < self.cells.len() {
            let end = first.saturating_add(count).min(self.cells.len());
            super::prefetch::lines(&self.cells[first..end], usize::MAX);
        }
    }
    /// The heap buffers of the cells (RGB and counters, PDF coefficients).
    pub fn storage_spans(&self) -> [Span; 2] {
        [span_of(&self.cells), span_of(&self.pdf)]
    }
    /// The record counter of a cell.
    pub fn count(&self, cell: usize) -> u32 {
        self.cells[cell].count
    }

    fn sum(&self, which: Sum) -> Rgb {
        let s = &self.sums[which as usize];
        Rgb([s[0].value(), s[1].value(), s[2].value()])
    }
    /// The average of all coefficients (the cv1 integral over `4 pi` or `2 pi`, divided by it).
    pub fn average(&self) -> Rgb {
        self.sum(Sum::All) / self.cells() as f64
    }
    /// The polar value at `t = 0`: the average of the first row (§4.1).
    pub fn first_polar(&self) -> Rgb {
        self.sum(Sum::FirstRow) / self.ns as f64
    }
    /// The polar value at `t = 1`: the average of the last row (§4.1).
    pub fn last_polar(&self) -> Rgb {
        self.sum(Sum::LastRow) / self.ns as f64
    }

    /// Adds one record to `cell`: the integrand sample `f` to the RGB running mean and `pdf_sample`
    /// (the mean over channels of `|f - g|`) to the PDF coefficient, then increments the counter.
    /// Returns the new PDF coefficient.
    pub fn record(&mut self, cell: usize, f: Rgb, pdf_sample: f64) -> f64 {
        let Cell { mut rgb, count: c } = self.cells[cell];
        let w = 1.0 / (f64::from(c) + 1.0);
        let j = self.row_of(cell);
        let (first, last) = (j == 0, j == self.nt - 1);
        for ch in 0..3 {
            let old = rgb[ch].get();
            let stored = S::put(old + (f[ch] - old) * w);
            rgb[ch] = stored;
            let new = stored.get();
            let sums = &mut self.sums;
            sums[Sum::All as usize][ch].add(new);
            sums[Sum::All as usize][ch].add(-old);
            if first {
                sums[Sum::FirstRow as usize][ch].add(new);
                sums[Sum::FirstRow as usize][ch].add(-old);
            }
            if last {
                sums[Sum::LastRow as usize][ch].add(new);
                sums[Sum::LastRow as usize][ch].add(-old);
            }
        }
        let old = self.pdf[cell].get();
        let new = S::put_positive(old + (pdf_sample - old) * w);
        self.pdf[cell] = new;
        let count = if c < u32::MAX {
            self.records += 1;
            c + 1
        } else {
            c
        };
        self.cells[cell] = Cell { rgb, count };
        new.get()
    }

    /// Doubles the resolution in `s` and `t`: each child copies its parent's coefficients and gets
    /// the parent's counter divided by `divisor`, but never less than 1 when the parent's was
    /// positive (the inheritance rule of §4.3). Recomputes the maintained sums from scratch.
    pub fn refine(&mut self, divisor: u32) {
        let (ns, nt) = (2 * self.ns, 2 * self.nt);
        let n = ns * nt;
        let mut cells = Vec::with_capacity(n);
        let mut pdf = Vec::with_capacity(n);
        for j in 0..nt {
            for i in 0..ns {
                let parent = (j / 2) * self.ns + i / 2;
                let Cell { rgb, count: c } = self.cells[parent];
                cells.push(Cell { rgb, count: if c == 0 { 0 } else { (c / divisor).max(1) } });
                pdf.push(self.pdf[parent]);
            }
        }
        (self.ns, self.nt, self.cells, self.pdf) = (ns, nt, cells, pdf);
        self.ns_shift = ns.is_power_of_two().then(|| ns.trailing_zeros());
        self.refinements += 1;
        self.resync();
    }

    /// Recomputes the counter total and the coefficient sums exactly from the cells, `O(N)`.
    pub fn resync(&mut self) {
        self.records = self.cells.iter().map(|c| u64::from(c.count)).sum();
        self.sums = Default::default();
        for (cell, c) in self.cells.iter().enumerate() {
            let j = cell / self.ns;
            let rgb = c.rgb;
            for (ch, v) in rgb.iter().map(|x| x.get()).enumerate() {
                self.sums[Sum::All as usize][ch].add(v);
                if j == 0 {
                    self.sums[Sum::FirstRow as usize][ch].add(v);
                }
                if j == self.nt - 1 {
                    self.sums[Sum::LastRow as usize][ch].add(v);
                }
            }
        }
    }

    /// Sets the RGB coefficient of a cell directly (tests of the reconstruction), keeping the sums
    /// current.
    pub fn set_radiance(&mut self, cell: usize, v: Rgb) {
        let j = cell / self.ns;
        for ch in 0..3 {
            let mut rgb = self.cells[cell].rgb;
            let old = rgb[ch].get();
            rgb[ch] = S::put(v[ch]);
            let new = rgb[ch].get();
            self.cells[cell].rgb = rgb;
            for (which, on) in [(Sum::All, true), (Sum::FirstRow, j == 0), (Sum::LastRow, j == self.nt - 1)] {
                if on {
                    self.sums[which as usize][ch].add(new);
                    self.sums[which as usize][ch].add(-old);
                }
            }
        }
    }

    /// Bytes of cell storage: RGB, PDF coefficient and counter per cell (the quantity of paper 001
    /// Table 1): 36 bytes per cell in double precision, 20 in single.
    pub fn cell_bytes(&self) -> usize {
        self.cells() * (std::mem::size_of::<Cell<S>>() + std::mem::size_of::<S>())
    }
}

/// `x as usize` (truncation, 0 for negative and NaN, saturating above) for the `x` of a cell
/// index: the same value below `2^63` in fewer instructions (a signed conversion, no unsigned
/// fix-up); callers clamp to the grid, where larger values end up too.
#[inline]
pub(crate) fn floor_index(x: f64) -> usize {
    x.max(0.0) as i64 as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    fn filled(records: usize) -> Grid<f64> {
        let mut g = Grid::new(Domain::Hemisphere);
        for k in 0..records {
            let v = 1.0 + (k % 5) as f64;
            g.record(0, Rgb([v, 2.0 * v, 0.5]), v);
        }
        g
    }

    #[test]
    fn running_means_and_sums_stay_current() {
        let g = filled(10);
        assert_eq!(g.count(0), 10);
        assert!((g.radiance(0)[0] - 3.0).abs() < 1e-15);
        assert!((g.average()[1] - 6.0).abs() < 1e-15 && (g.first_polar()[1] - 6.0).abs() < 1e-15);
        assert!((g.pdf_coefficient(0) - 3.0).abs() < 1e-15);
    }

    /// Refinement duplicates records, divides counters by 4 without rounding a positive counter to
    /// zero, and preserves the cv1 integral (the coefficient average) exactly.
    #[test]
    fn refinement_invariants() {
        let mut g = filled(9);
        g.refine(4);
        assert_eq!(g.resolution(), (2, 2));
        assert!((0..4).all(|c| g.count(c) == 2 && g.radiance(c) == g.radiance(0)));
        for c in 0..4 {
            g.record(c, Rgb([c as f64 * 10.0, 1.0, -3.0]), c as f64);
        }
        g.record(3, Rgb([7.0, 7.0, 7.0]), 0.0);
        let before = g.average();
        let (first, last) = (g.first_polar(), g.last_polar());
        g.refine(4);
        assert_eq!(g.refinements(), 2);
        assert!((0..16).all(|c| g.count(c) == 1), "3 / 4 and 4 / 4 both give 1, never 0");
        assert_eq!(g.records(), 16);
        for ch in 0..3 {
            assert!((g.average()[ch] - before[ch]).abs() <= 1e-15 * before[ch].abs().max(1.0));
            assert!((g.first_polar()[ch] - first[ch]).abs() <= 1e-15 * first[ch].abs().max(1.0));
            assert!((g.last_polar()[ch] - last[ch]).abs() <= 1e-15 * last[ch].abs().max(1.0));
        }
        // An untouched cell keeps counter 0 through refinement (nothing to inherit).
        let mut e = Grid::<f64>::with_resolution(Domain::Sphere, 2, 1);
        e.record(0, Rgb::splat(1.0), 1.0);
        e.refine(32);
        assert_eq!((0..8).map(|c| e.count(c)).collect::<Vec<_>>(), vec![1, 1, 0, 0, 1, 1, 0, 0]);
    }

    /// A positive PDF coefficient stays positive under any number of zero records (inheritance),
    /// in both precisions, and the compensated sums match a fresh resync after 1e6 writes.
    #[test]
    fn positivity_and_long_run_precision() {
        let mut g32 = Grid::<f32>::new(Domain::Hemisphere);
        let mut g64 = Grid::<f64>::new(Domain::Hemisphere);
        g32.record(0, Rgb::splat(1e-40), 1e-40);
        g64.record(0, Rgb::splat(1e-300), 1e-300);
        g32.refine(4);
        g64.refine(4);
        for k in 0..1_000_000u32 {
            let v = (k % 1000) as f64 * 1e-3;
            g32.record((k % 4) as usize, Rgb([v, 1.0 - v, 3.0]), 0.0);
            g64.record((k % 4) as usize, Rgb([v, 1.0 - v, 3.0]), 0.0);
        }
        assert!(g32.pdf_coefficients().all(|p| p > 0.0) && g64.pdf_coefficients().all(|p| p > 0.0));
        let kept = g64.average();
        g64.resync();
        for ch in 0..3 {
            assert!((kept[ch] - g64.average()[ch]).abs() <= 4.0 * f64::EPSILON * g64.average()[ch].abs());
        }
        assert_eq!(g32.cell_bytes(), 4 * 20);
        assert_eq!(g64.cell_bytes(), 4 * 36);
    }
}
