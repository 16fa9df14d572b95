//! Criterion benches of the remaining hot paths (book: benches.md): one partial-sum-tree
//! sample and update (1024 leaves), one Metropolis-Hastings move of paper 004's mixture kernel on
//! an environment map x Phong target, one resampling of N = 16 and N = 1024 particles (each
//! scheme, from log weights: normalisation + ancestor draw), and one PMC-HI iteration (paper 003:
//! a `pmc_hi` estimate whose budget is exactly one population of `2 m` samples on
//! `checker-direct`), and one frame of one pixel of the paper 004 estimators (`bidirectional_is`,
//! `smc`, `smc_bridge`, `smc_path` at their defaults, N = 16: a 10-frame sequence of one pixel of
//! `envmap-sequence` `mixed`, reported per frame). Run with `cargo bench -p mcbench-papers --bench smc`.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mcbench_core::brdf::Phong;
use mcbench_core::budget::Budget;
use mcbench_core::envmap::{EnvFrame, EnvMap};
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::task::Task;
use mcbench_papers::builtins;
use mcbench_papers::cache::PartialSumTree;
use mcbench_papers::envmap_smc::mh::{MhKernel, State};
use mcbench_papers::envmap_smc::resampling::{normalise_log_weights, resample, Scheme};
use mcbench_papers::testbeds::sky::Sky;
use rand::Rng;

fn partial_sum_tree(c: &mut Criterion) {
    let mut rng = stream(1, "bench tree");
    let weights: Vec<u64> = (0..1024).map(|_| rng.gen_range(1..1000)).collect();
    let mut tree = PartialSumTree::from_weights(&weights);
    let mut group = c.benchmark_group("partial_sum_tree_1024");
    group.bench_function("sample", |b| b.iter(|| black_box(tree.sample(&mut rng))));
    group.bench_function("set", |b| {
        b.iter(|| {
            let i = rng.gen_range(0..1024);
            tree.set(i, black_box(rng.gen_range(1..1000)))
        })
    });
    group.finish();
}

fn mh_move(c: &mut Criterion) {
    let map = EnvMap::tabulate(64, 32, |w| Sky::default_with_sun(30.0).radiance(w)).expect("map");
    let frame = EnvFrame { map: &map, rotation: 0.0, scale: 1.0 };
    let brdf = Phong { kd: Rgb::splat(0.3), ks: Rgb::splat(0.6), n: 20.0 };
    let wo = Vec3::new(0.3, -0.5, 0.8).normalize();
    let mut eval = |d: Vec3| {
        let v = frame.radiance(d).mean() * brdf.eval(d, wo, Vec3::Z).mean() * d.z.max(0.0);
        (if v > 0.0 { v.ln() } else { f64::NEG_INFINITY }, ())
    };
    let kernel = MhKernel::new(5.0, 0.3);
    let mut rng = stream(2, "bench mh");
    let w = Vec3::new(0.1, 0.2, 0.9).normalize();
    let mut x = State { w, log_target: eval(w).0, payload: () };
    c.bench_function("mh_move_envmap_64x32_phong", |b| {
        b.iter(|| black_box(kernel.step(&mut x, &frame, &mut rng, &mut eval)))
    });
}

fn resampling(c: &mut Criterion) {
    let mut rng = stream(3, "bench resampling");
    for n in [16usize, 1024] {
        let log_w: Vec<f64> = (0..n).map(|_| -5.0 * rng.gen::<f64>()).collect();
        let mut group = c.benchmark_group(format!("resample_n{n}"));
        group.throughput(Throughput::Elements(n as u64));
        for (name, scheme) in [
            ("multinomial", Scheme::Multinomial),
            ("residual", Scheme::Residual),
            ("stratified", Scheme::Stratified),
            ("systematic", Scheme::Systematic),
        ] {
            group.bench_function(BenchmarkId::from_parameter(name), |b| {
                b.iter(|| {
                    let (w, _) = normalise_log_weights(black_box(&log_w)).expect("weights");
                    resample(scheme, &w, n, &mut rng)
                })
            });
        }
        group.finish();
    }
}

fn pmc_hi_iteration(c: &mut Criterion) {
    let entry = builtins::testbed("checker-direct").expect("registered");
    let bed = (entry.build)("default", &Params::new().with("resolution", 8.0), &mcbench_core::references::NoReferences)
        .expect("bed");
    let est = (builtins::estimator("pmc_hi").expect("registered").build)(&Params::new()).expect("builds");
    // m = lights + 2 mixture components; one population (one iteration) is 2 m samples.
    let m = bed.hemisphere().expect("surface").lights().len() + 2;
    let budget = Budget::samples(2 * m as u64).expect("budget");
    let mut rng = stream(4, "bench pmc_hi");
    let mut i = 0;
    let mut group = c.benchmark_group("pmc_hi");
    group.throughput(Throughput::Elements(2 * m as u64));
    group.bench_function(format!("one_iteration_{}_samples", 2 * m), |b| {
        b.iter(|| {
            i = (i + 1) % bed.integrals();
            est.estimate(&Task::new(bed.as_ref(), i, budget), &mut rng).expect("estimate")
        })
    });
    group.finish();
}

fn smc_frame(c: &mut Criterion) {
    const FRAMES: usize = 10;
    let entry = builtins::testbed("envmap-sequence").expect("registered");
    let params = Params::new().with("resolution", 4.0).with("frames", FRAMES as f64);
    let bed = (entry.build)("mixed", &params, &mcbench_core::references::NoReferences).expect("bed");
    let budget = Budget::samples(16).expect("budget");
    // The sequence of the pixel at the image centre (integrals are pixel-major, frames inner).
    let first = (2 * 4 + 2) * FRAMES;
    let mut group = c.benchmark_group("smc_frame_one_pixel");
    group.throughput(Throughput::Elements(FRAMES as u64));
    for id in ["bidirectional_is", "smc", "smc_bridge", "smc_path"] {
        let est = (builtins::estimator(id).expect("registered").build)(&Params::new()).expect("builds");
        let mut rng = stream(5, id);
        group.bench_function(id, |b| {
            b.iter(|| {
                let tasks: Vec<Task<'_>> =
                    (first..first + FRAMES).map(|i| Task::new(bed.as_ref(), i, budget)).collect();
                black_box(est.estimate_sequence(&tasks, &mut rng).expect("estimates"))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, partial_sum_tree, mh_move, resampling, pmc_hi_iteration, smc_frame);
criterion_main!(benches);
