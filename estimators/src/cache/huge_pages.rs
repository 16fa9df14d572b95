//! Backing large cache storage with 2 MiB pages.
//!
//! A medium's octree of caches (paper 000 §4.3) reaches tens of megabytes in thousands of small
//! heap buffers (cells, PDF coefficients and block sums of every leaf), and each vertex follows a
//! dependent chain through four of them. With 4 KiB pages each link also misses the TLB, and the
//! page walk is one more dependent load. [`back_with_huge_pages`] asks the kernel to map the 2 MiB
//! regions holding such buffers with huge pages now: `MADV_COLLAPSE` (Linux 6.1), independent of
//! the system-wide transparent-huge-page mode unless that is `never`. A region collapses only when
//! it lies within one mapping; `MADV_HUGEPAGE` is not used, because it sets a flag that keeps each
//! later growth of the heap a mapping of its own (with boundaries at no 2 MiB multiple), so the
//! regions across those boundaries could never collapse.
//!
//! Only the mapping changes, never the contents, so results are unaffected; failures (an older
//! kernel, huge pages disabled, no free 2 MiB page) leave the small pages in place and are ignored.
//! Other systems get a no-op.

/// The huge-page size this module aligns to (x86_64 and aarch64 with 4 KiB base pages).
pub const HUGE_PAGE: usize = 1 << 21;

/// A buffer as `(address, bytes)`.
pub type Span = (usize, usize);

/// The span of a slice's memory.
pub fn span_of<T>(s: &[T]) -> Span {
    (s.as_ptr() as usize, std::mem::size_of_val(s))
}

/// The [`HUGE_PAGE`]-aligned regions that hold any byte of `spans`, merged into sorted, disjoint
/// runs `(start, bytes)` (each a multiple of [`HUGE_PAGE`]); empty spans hold nothing.
pub fn regions(spans: impl IntoIterator<Item = Span>) -> Vec<Span> {
    let mut pages: Vec<(usize, usize)> = spans
        .into_iter()
        .filter(|&(_, len)| len > 0)
        .map(|(start, len)| (start / HUGE_PAGE, (start + len - 1) / HUGE_PAGE + 1))
        .collect();
    pages.sort_unstable();
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (first, end) in pages {
        match runs.last_mut() {
            Some(last) if first <= last.1 => last.1 = last.1.max(end),
            _ => runs.push((first, end)),
        }
    }
    runs.into_iter().map(|(first, end)| (first * HUGE_PAGE, (end - first) * HUGE_PAGE)).collect()
}

/// Asks for huge pages behind the regions of `spans` (see the module documentation); returns the
/// bytes of regions the kernel collapsed into huge pages (0 where that is unsupported).
///
/// One region at a time: a region that is not wholly anonymous memory (the first and last of a
/// heap usually share theirs with other mappings) makes `MADV_COLLAPSE` fail for the whole range
/// it is part of.
pub fn back_with_huge_pages(spans: impl IntoIterator<Item = Span>) -> usize {
    regions(spans)
        .into_iter()
        .flat_map(|(start, len)| (start..start + len).step_by(HUGE_PAGE))
        .map(|page| advise(page, HUGE_PAGE))
        .sum()
}

#[cfg(target_os = "linux")]
fn advise(start: usize, len: usize) -> usize {
    /// `MADV_COLLAPSE` of Linux's `<asm-generic/mman-common.h>` (the same on every architecture).
    const MADV_COLLAPSE: libc::c_int = 25;
    let ptr = start as *mut libc::c_void;
    // SAFETY: the advice changes how the pages are mapped, never their contents or the mapping's
    // address range, so no Rust object can observe it; a region that is not wholly anonymous
    // memory of one mapping makes `madvise` fail and changes nothing.
    if unsafe { libc::madvise(ptr, len, MADV_COLLAPSE) } == 0 {
        len
    } else {
        0
    }
}

#[cfg(not(target_os = "linux"))]
fn advise(_start: usize, _len: usize) -> usize {
    0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regions_cover_every_byte_and_merge_neighbours() {
        let h = HUGE_PAGE;
        assert_eq!(regions([(0, 0)]), vec![]);
        assert_eq!(regions([(h - 1, 1)]), vec![(0, h)]);
        assert_eq!(regions([(h - 1, 2)]), vec![(0, 2 * h)]);
        // Out of order, overlapping and adjacent spans: one run; a gap: two.
        assert_eq!(regions([(5 * h + 7, 10), (3 * h, h), (4 * h + 1, 3)]), vec![(3 * h, 3 * h)]);
        assert_eq!(regions([(9 * h, 1), (3 * h, h + 1)]), vec![(3 * h, 2 * h), (9 * h, h)]);
    }

    /// The advice never changes what the memory holds (whether or not the kernel collapses it).
    #[test]
    fn advice_keeps_the_contents() {
        let v: Vec<u64> = (0..(3 * HUGE_PAGE / 8) as u64).map(|i| i.wrapping_mul(0x9e37_79b9_7f4a_7c15)).collect();
        let collapsed = back_with_huge_pages([span_of(&v)]);
        assert!(collapsed <= 4 * HUGE_PAGE);
        assert!(v.iter().enumerate().all(|(i, &x)| x == (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)));
    }
}
