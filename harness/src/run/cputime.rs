//! The calling thread's CPU time (time-based metrics use CPU seconds, which machine load
//! from other processes does not inflate the way it inflates wall-clock time).

/// Seconds of CPU the calling thread has used (`CLOCK_THREAD_CPUTIME_ID`); 0 where the clock is
/// unavailable.
pub fn thread_seconds() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; clock_gettime only writes it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return 0.0;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

#[cfg(test)]
mod tests {
    #[test]
    fn thread_cpu_time_advances_with_work_and_not_with_sleep() {
        let t0 = super::thread_seconds();
        let mut x = 0u64;
        for i in 0..20_000_000u64 {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(i);
        }
        std::hint::black_box(x);
        let t1 = super::thread_seconds();
        std::thread::sleep(std::time::Duration::from_millis(50));
        let t2 = super::thread_seconds();
        assert!(t1 > t0, "work uses CPU time");
        assert!(t2 - t1 < 0.02, "sleeping uses (almost) none: {}", t2 - t1);
    }
}
