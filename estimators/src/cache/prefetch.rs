//! Software prefetch of cache storage whose address is known before it is read.
//!
//! A vertex of paper 000 Fig. 2 follows a dependent chain through its leaf's cache: the cache's
//! header, the block sums of the cell sampler, the block's run of PDF coefficients, the cells
//! around the drawn direction. Once a buffer's address is known its lines can be requested
//! together instead of one level of the walk at a time; [`lines`] issues those requests
//! (`prefetcht0` on x86_64, nothing elsewhere). A prefetch never faults and never changes what
//! is read, so results are unaffected.

/// Bytes per cache line.
pub const LINE: usize = 64;

/// Requests every cache line of the first `max_bytes` bytes of `s` into L1.
#[inline(always)]
pub fn lines<T>(s: &[T], max_bytes: usize) {
    let start = s.as_ptr() as usize;
    let end = start + std::mem::size_of_val(s).min(max_bytes);
    let mut line = start & !(LINE - 1);
    while line < end {
        line_at(line);
        line += LINE;
    }
}

#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn line_at(address: usize) {
    use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
    // SAFETY: a prefetch is a hint: it reads nothing the program sees and never faults, whatever
    // the address (here one inside or at most 63 bytes before a live slice).
    unsafe { _mm_prefetch::<_MM_HINT_T0>(address as *const i8) }
}

#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn line_at(_address: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    /// Prefetching is only a hint: any slice, empty or unaligned, with any bound, is accepted and
    /// left as it was.
    #[test]
    fn prefetch_leaves_memory_as_it_was() {
        let v: Vec<u64> = (0..1000).collect();
        for (from, max) in [(0, usize::MAX), (3, 100), (999, 8), (1000, 64), (0, 0)] {
            lines(&v[from..], max);
        }
        lines::<u8>(&[], 64);
        assert!(v.iter().enumerate().all(|(i, &x)| x == i as u64));
    }
}
