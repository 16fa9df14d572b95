//! The one parallel map of the reference builders: independent per-integral work on `threads`
//! threads (rayon), results in index order, so a reference never depends on the thread count.

use rayon::prelude::*;

/// `f(0), f(1), ..., f(n - 1)` computed on `threads` threads (0: rayon's default), in order.
pub fn map_indices<T: Send>(n: usize, threads: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool.install(|| (0..n).into_par_iter().map(&f).collect()),
        Err(_) => (0..n).map(f).collect(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn results_come_in_index_order_whatever_the_thread_count() {
        for threads in [1, 2, 4] {
            assert_eq!(super::map_indices(100, threads, |i| i * i), (0..100).map(|i| i * i).collect::<Vec<_>>());
        }
    }
}
