//! Criterion benches of the surface radiance cache hot paths (book: benches.md): one cache sample
//! (partial-sum tree + uniform in the cell), one record (running means, maintained sums, tree
//! update), one refinement, one reconstruction of g, and one whole `is1_cv2` estimate.
//! Run with `cargo bench -p mcbench-papers --bench cache`.

use criterion::{black_box, criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput};
use mcbench_core::budget::Budget;
use mcbench_core::math::Rgb;
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::task::Task;
use mcbench_papers::builtins;
use mcbench_papers::cache::{CacheConfig, ControlVariate, RadianceCache, Scalar, St};

/// A cache refined exactly `depth` times by uniform records of a smooth integrand.
fn cache_at_depth<S: Scalar>(depth: u32) -> RadianceCache<S> {
    let mut cache = RadianceCache::<S>::new(CacheConfig { max_depth: depth, ..CacheConfig::surface(true) });
    let mut rng = stream(7, "bench cache");
    while cache.grid().refinements() < depth || cache.grid().mean_count() < 4.0 {
        let s = cache.sample(&mut rng);
        let v = 1.0 + s.st.t * (6.0 * s.st.s).sin();
        let g = cache.g(ControlVariate::Bilinear, s.st);
        cache.add_record(s.cell, Rgb([v, 0.5 * v, 0.2]), g);
    }
    cache
}

fn cache_ops(c: &mut Criterion) {
    let mut group = c.benchmark_group("cache");
    for depth in [4u32, 6] {
        let cache = cache_at_depth::<f64>(depth);
        let mut rng = stream(1, "bench sample");
        group.bench_function(BenchmarkId::new("sample_f64", depth), |b| b.iter(|| black_box(cache.sample(&mut rng))));
        let st = St { s: 0.37, t: 0.61 };
        group.bench_function(BenchmarkId::new("g_cv2_and_G", depth), |b| {
            b.iter(|| {
                black_box(cache.g(ControlVariate::Bilinear, black_box(st)) + cache.integral(ControlVariate::Bilinear))
            })
        });
        // max_depth is reached, so a record never triggers a refinement here.
        let mut updated = cache.clone();
        let mut rng = stream(2, "bench update");
        group.bench_function(BenchmarkId::new("update_f64", depth), |b| {
            b.iter(|| {
                let s = updated.sample_uniform(&mut rng);
                updated.add_record(s.cell, black_box(Rgb([1.0, 0.5, 0.25])), Rgb::ZERO)
            })
        });
        let mut updated32 = cache_at_depth::<f32>(depth);
        group.bench_function(BenchmarkId::new("update_f32", depth), |b| {
            b.iter(|| {
                let s = updated32.sample_uniform(&mut rng);
                updated32.add_record(s.cell, black_box(Rgb([1.0, 0.5, 0.25])), Rgb::ZERO)
            })
        });
        group.bench_function(BenchmarkId::new("refine_f64_from_depth", depth), |b| {
            b.iter_batched(|| cache.clone(), |mut c| c.refine(), BatchSize::LargeInput)
        });
    }
    group.finish();
}

fn is1_cv2_estimate(c: &mut Criterion) {
    let bed = (builtins::testbed("gradient-plane").unwrap().build)(
        "default",
        &Params::new().with("resolution", 8.0),
        &mcbench_core::references::NoReferences,
    )
    .expect("test bed");
    let mut group = c.benchmark_group("is1_cv2_estimate");
    for spp in [64u64, 1024, 4096] {
        group.throughput(Throughput::Elements(spp));
        for id in ["is0_cv0", "is1_cv2"] {
            let est = (builtins::estimator(id).unwrap().build)(&Params::new()).expect("estimator");
            let mut rng = stream(3, id);
            let mut i = 0;
            group.bench_function(BenchmarkId::new(id, spp), |b| {
                b.iter(|| {
                    i = (i + 1) % bed.integrals();
                    let task = Task::new(bed.as_ref(), i, Budget::samples(spp).expect("spp"));
                    est.estimate(&task, &mut rng).expect("estimate")
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, cache_ops, is1_cv2_estimate);
criterion_main!(benches);
