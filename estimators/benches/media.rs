//! Criterion benches of the medium SMC hot paths (book: benches.md): one independent path in the
//! gradient box (free flights + phase sampling), one octree leaf lookup at depth 3, one path
//! vertex of the octree cache (`is1_cv2`: leaf lookup, cell sample, `G` and the bilinear `g`, the
//! estimate and the record; paper 000 Fig. 2) on a full octree of depth 3 (512 leaves, 65 536
//! cells: the structure of a 16x16 image at 1024 spp) and depth 4 (4096 leaves, 2.1 M cells: at
//! 16 384 spp), and one `is1_cv2` estimate of a 16 x 16 gradient-box image at 4 spp (shared
//! octree, 1024 paths). Run with `cargo bench -p mcbench-papers --bench media`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use mcbench_core::budget::Budget;
use mcbench_core::estimator::Estimator;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::Params;
use mcbench_core::phase::Phase;
use mcbench_core::rng::stream;
use mcbench_core::task::Task;
use mcbench_papers::cache::{CacheConfig, ControlVariate, Domain};
use mcbench_papers::media_smc::octree::Octree;
use mcbench_papers::media_smc::params::MediaSmcParams;
use mcbench_papers::media_smc::walk::Vertex;
use mcbench_papers::media_smc::{walk, MediaSmc, Sampling};
use mcbench_papers::testbeds::gradient_box::GradientBox;
use rand::Rng;

fn media(c: &mut Criterion) {
    let bed = GradientBox::without_reference("albedo-0.8", &Params::new()).expect("builds");
    let mut group = c.benchmark_group("media");
    let task = Task::new(&bed, 136, Budget::samples(u64::MAX).expect("budget"));
    let probe = task.medium().expect("medium");
    let mut rng = stream(1, "bench path");
    group.bench_function("independent_path", |b| b.iter(|| black_box(walk::independent_path(&probe, &mut rng))));

    let config =
        CacheConfig { domain: Domain::Sphere, criterion: 1.0, max_depth: 3, counter_divisor: 32, importance: true };
    let mut tree = Octree::<f64>::new(Vec3::default(), 0.5, config);
    let mut r = stream(2, "bench octree");
    while tree.stats().depth < 3 || tree.stats().leaves < 512 {
        let p = Vec3::new(r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5);
        let st = mcbench_papers::cache::St { s: r.gen(), t: r.gen() };
        tree.add_record(p, st, Rgb::splat(1.0 + st.t), Rgb::ZERO);
    }
    group.bench_function("octree_lookup_depth3", |b| {
        b.iter(|| {
            let p = Vec3::new(r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5);
            black_box(tree.leaf_of(p))
        })
    });

    for depth in [3u32, 4] {
        let mut tree = full_octree(depth);
        let mut r = stream(4, "bench vertex");
        let dir = Vec3::new(0.0, 1.0, 0.0);
        group.bench_function(format!("vertex_is1_cv2_depth{depth}"), |b| {
            b.iter(|| {
                let p = Vec3::new(r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5);
                let (v, w) = Vertex::read(
                    &tree,
                    p,
                    dir,
                    Sampling::Cache,
                    ControlVariate::Bilinear,
                    Phase::Isotropic,
                    0.8,
                    &mut r,
                );
                black_box(v.estimate_and_record(&mut tree, Rgb::splat(0.5 + 0.25 * w.z)))
            })
        });
    }

    let est = MediaSmc::from_params(Sampling::Cache, ControlVariate::Bilinear, &MediaSmcParams::default());
    group.throughput(Throughput::Elements(256 * 4));
    group.sample_size(20);
    let mut rng = stream(3, "bench is1_cv2");
    group.bench_function("is1_cv2_image_16x16_4spp", |b| {
        b.iter(|| {
            let tasks: Vec<Task<'_>> = (0..256).map(|i| Task::new(&bed, i, Budget::samples(4).expect("4"))).collect();
            black_box(est.estimate_sequence(&tasks, &mut rng).expect("finite"))
        })
    });
    group.finish();
}

/// An octree split down to `depth` everywhere (criterion 1, `max_depth = depth`, so the vertex
/// bench's records no longer refine it), with smooth records in every cell.
fn full_octree(depth: u32) -> Octree<f64> {
    let config =
        CacheConfig { domain: Domain::Sphere, criterion: 1.0, max_depth: depth, counter_divisor: 32, importance: true };
    let mut tree = Octree::<f64>::new(Vec3::default(), 0.5, config);
    let mut r = stream(5, "bench full octree");
    let leaves = 8usize.pow(depth);
    while tree.stats().leaves < leaves {
        for _ in 0..4096 {
            let p = Vec3::new(r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5);
            let st = mcbench_papers::cache::St { s: r.gen(), t: r.gen() };
            tree.add_record(p, st, Rgb::splat(1.0 + st.t), Rgb::splat(0.5));
        }
    }
    tree
}

criterion_group!(benches, media);
criterion_main!(benches);
