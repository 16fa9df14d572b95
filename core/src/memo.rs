//! A process-wide memo for references computed by quadrature when a test bed is built.
//!
//! An experiment builds the same bed many times (the pilot and the main plan, a sweep planned per
//! estimator, every seed of a calibration family); a bed whose exact reference takes seconds of
//! quadrature computes it once per process and per settings. The key must name everything the
//! value depends on.

use std::sync::{Mutex, OnceLock};

/// Values by key, computed once per process.
pub struct Memo<T> {
    values: OnceLock<Mutex<Vec<(String, T)>>>,
}

impl<T: Clone> Memo<T> {
    /// An empty memo (for a `static`).
    pub const fn new() -> Self {
        Memo { values: OnceLock::new() }
    }

    /// The value of `key`, computing it with `compute` the first time. Two threads asking for the
    /// same new key at once may both compute it (the values are equal; the first stored is kept).
    pub fn get_or_compute(&self, key: String, compute: impl FnOnce() -> T) -> T {
        let values = self.values.get_or_init(Default::default);
        if let Some((_, v)) = values.lock().unwrap_or_else(|e| e.into_inner()).iter().find(|(k, _)| *k == key) {
            return v.clone();
        }
        let v = compute();
        let mut guard = values.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, kept)) = guard.iter().find(|(k, _)| *k == key) {
            return kept.clone();
        }
        guard.push((key, v.clone()));
        v
    }
}

impl<T: Clone> Default for Memo<T> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn computes_each_key_once() {
        static MEMO: Memo<u64> = Memo::new();
        let calls = AtomicUsize::new(0);
        let f = |v| {
            calls.fetch_add(1, Ordering::SeqCst);
            v
        };
        assert_eq!(MEMO.get_or_compute("a".into(), || f(1)), 1);
        assert_eq!(MEMO.get_or_compute("a".into(), || f(2)), 1);
        assert_eq!(MEMO.get_or_compute("b".into(), || f(3)), 3);
        assert_eq!(calls.load(Ordering::SeqCst), 2);
    }
}
