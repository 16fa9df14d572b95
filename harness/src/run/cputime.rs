//! CPU time of estimates (time-based metrics use CPU seconds, which machine load from other
//! processes does not inflate the way it inflates wall-clock time), measured so that measuring
//! costs the estimates almost nothing.
//!
//! The thread CPU clock (`CLOCK_THREAD_CPUTIME_ID`) is a system call on Linux (about 0.7 us on the
//! VMs of the book), as long as a cheap estimate; the monotonic clock behind
//! [`std::time::Instant`] is read in user space (about 30 ns). So the CPU clock is read once at
//! each end of a work item (one repetition of a batch of integrals, [`crate::run::interleave`]) and
//! the monotonic clock around each estimate: an estimate's CPU time is its monotonic time times
//! the item's CPU fraction (CPU seconds over monotonic seconds of the whole item, at most 1). A
//! thread that waits for a core during an item has a fraction below 1, so load from other processes
//! still does not inflate the CPU times; it is spread over the item's estimates rather than taken
//! from the one it interrupted.

use std::time::Instant;

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

/// The two clocks at the start of a work item, read on the thread that runs it.
pub struct ItemClock {
    cpu: f64,
    wall: Instant,
}

impl ItemClock {
    /// Reads both clocks: the CPU clock first, so that the monotonic interval lies inside the CPU
    /// interval and a thread that never waited gets a fraction of (at least, then exactly) 1.
    pub fn start() -> Self {
        let cpu = thread_seconds();
        ItemClock { cpu, wall: Instant::now() }
    }

    /// The item's CPU fraction: CPU seconds the thread used since [`Self::start`] over the
    /// monotonic seconds that passed, clamped to `[0, 1]` (a thread cannot run longer than the time
    /// that passed; the CPU interval also holds half of each CPU clock read). 1 when no monotonic
    /// time passed.
    pub fn cpu_fraction(self) -> f64 {
        let wall = self.wall.elapsed().as_secs_f64();
        let cpu = thread_seconds() - self.cpu;
        cpu_fraction(cpu, wall)
    }
}

/// `cpu / wall` clamped to `[0, 1]`; 1 when `wall` is not positive.
pub fn cpu_fraction(cpu: f64, wall: f64) -> f64 {
    if wall > 0.0 && cpu.is_finite() {
        (cpu / wall).clamp(0.0, 1.0)
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::{cpu_fraction, thread_seconds, ItemClock};
    use std::time::Duration;

    #[test]
    fn thread_cpu_time_advances_with_work_and_not_with_sleep() {
        let t0 = thread_seconds();
        let mut x = 0u64;
        for i in 0..20_000_000u64 {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(i);
        }
        std::hint::black_box(x);
        let t1 = thread_seconds();
        std::thread::sleep(Duration::from_millis(50));
        let t2 = thread_seconds();
        assert!(t1 > t0, "work uses CPU time");
        assert!(t2 - t1 < 0.02, "sleeping uses (almost) none: {}", t2 - t1);
    }

    #[test]
    fn the_fraction_is_cpu_over_wall_within_zero_and_one() {
        assert_eq!(cpu_fraction(0.5, 1.0), 0.5);
        assert_eq!(cpu_fraction(1.2, 1.0), 1.0);
        assert_eq!(cpu_fraction(-1e-9, 1.0), 0.0);
        assert_eq!(cpu_fraction(1e-6, 0.0), 1.0);
        assert_eq!(cpu_fraction(f64::NAN, 1.0), 1.0);
    }

    /// An item that only waits (here: sleeps 40 ms) has a fraction near 0, whatever the load:
    /// a thread that is not running uses no CPU time, so waiting lowers the fraction.
    #[test]
    fn waiting_lowers_the_fraction() {
        let clock = ItemClock::start();
        std::thread::sleep(Duration::from_millis(40));
        let sleeper = clock.cpu_fraction();
        assert!((0.0..0.25).contains(&sleeper), "{sleeper}");
    }
}
