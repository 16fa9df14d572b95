//! What one target evaluation of paper 004 costs against one shadow ray on `envmap-sequence`
//! (book: paper-004.md, "What a target evaluation costs"): times the counted probe's
//! `p~_n(w) = L_n(w) f(w, w_o) cos` (a texel lookup in the rotated map, the Phong BRDF, the cosine)
//! and its visibility test (`moving-specular-wall`: the ground and the wall, two dot products) at
//! the same directions, drawn from the map's sampler as the estimators draw their candidates, and
//! the draw itself. One thread; the best of five rounds of 2^20 calls each.
//!
//! Run: `cargo run --release -p experiments --example envmap_eval_cost`.

use mcbench_core::budget::Budget;
use mcbench_core::math::Vec3;
use mcbench_core::params::Params;
use mcbench_core::task::Task;
use mcbench_papers::builtins as registry;
use std::hint::black_box;
use std::time::Instant;

const CALLS: usize = 1 << 20;

/// The best of five rounds of `f` over the directions, in nanoseconds per call.
fn best_ns(dirs: &[Vec3], mut f: impl FnMut(Vec3) -> f64) -> f64 {
    (0..5)
        .map(|_| {
            let start = Instant::now();
            let mut acc = 0.0;
            for w in dirs {
                acc += f(*w);
            }
            black_box(acc);
            start.elapsed().as_nanos() as f64 / dirs.len() as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let params = Params::new().with("resolution", 10.0).with("frames", 6.0);
    let entry = registry::testbed("envmap-sequence").expect("envmap-sequence");
    let bed = (entry.build)("moving-specular-wall", &params, &mcbench_papers::built_in_references::BUILT_IN)
        .expect("the variant builds");
    // A pixel near the wall, frame 3 (the map rotated).
    let task = Task::new(bed.as_ref(), 5 * 6 + 3, Budget::samples(u64::MAX / 2).expect("budget"));
    let probe = task.env_sequence().expect("an environment sequence");
    let mut rng = mcbench_core::rng::stream(7, "envmap_eval_cost");
    let dirs: Vec<Vec3> = (0..CALLS).map(|_| probe.sample_environment(&mut rng).w).collect();
    let target = best_ns(&dirs, |w| probe.target(w).mean());
    let shadow = best_ns(&dirs, |w| if probe.visible(w) { 1.0 } else { 0.0 });
    let draw = best_ns(&dirs, |_| probe.sample_environment(&mut rng).pdf);
    println!("target evaluation: {target:.1} ns, shadow ray (ground and wall): {shadow:.1} ns, environment draw: {draw:.1} ns");
    println!("one target evaluation = {:.1} shadow rays of this scene", target / shadow);
}
