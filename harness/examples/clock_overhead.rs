//! What an empty estimate is charged, per estimate over 160 000 of them in one run: reading the
//! thread CPU clock around each estimate, against what the runner does (the CPU clock per item of
//! 16 estimates, apportioned by the monotonic clock read around each). Prints both; the book's
//! performance chapter quotes them. `cargo run --release -p mcbench --example clock_overhead`.

use mcbench::run::cputime::{thread_seconds, ItemClock};
use std::time::Instant;

const ITEMS: usize = 10_000;
const PER_ITEM: usize = 16;

fn main() {
    let n = (ITEMS * PER_ITEM) as f64;
    let mut per_estimate_clock = 0.0;
    for _ in 0..ITEMS * PER_ITEM {
        let c0 = thread_seconds();
        std::hint::black_box(());
        per_estimate_clock += thread_seconds() - c0;
    }
    let mut apportioned = 0.0;
    for _ in 0..ITEMS {
        let clock = ItemClock::start();
        let mut wall = 0.0;
        for _ in 0..PER_ITEM {
            let t0 = Instant::now();
            std::hint::black_box(());
            wall += t0.elapsed().as_secs_f64();
        }
        apportioned += wall * clock.cpu_fraction();
    }
    let (before, after) = (per_estimate_clock / n, apportioned / n);
    println!(
        "empty estimate: {:.1} ns per estimate with the CPU clock around each, {:.1} ns apportioned per item ({:.1}x less)",
        before * 1e9,
        after * 1e9,
        before / after.max(1e-12)
    );
}
