//! Criterion bench of paper 003's image-plane samplers (one PMC iteration, book: benches.md): a whole
//! 8x8 `checker-image` at 10 spp with `pmc_ip` (2+4+4) and `uniform_image` (the pixel samples
//! dominate both), and the adaptation overhead of one PMC-IP iteration alone (weights from the
//! pixel statistics plus the DMS allocation) on 48x48 pixels. Run with
//! `cargo bench -p mcbench-papers --bench pmc`.

use criterion::{black_box, criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mcbench_core::budget::Budget;
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::stats::Moments;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use mcbench_papers::builtins;
use mcbench_papers::pmc::ip::PmcIp;
use mcbench_papers::testbeds::checker_image::CheckerImage;

fn image(c: &mut Criterion) {
    let bed = CheckerImage::without_reference("occluded", &Params::new().with("resolution", 8.0)).expect("bed");
    let budget = Budget::samples(10).expect("10 >= 1");
    let mut group = c.benchmark_group("checker_image_8x8_10spp");
    group.throughput(Throughput::Elements(10 * bed.integrals() as u64));
    for id in ["uniform_image", "pmc_ip"] {
        let est = (builtins::estimator(id).expect("registered").build)(&Params::new()).expect("builds");
        let mut rng = stream(1, id);
        group.bench_function(BenchmarkId::from_parameter(id), |b| {
            b.iter(|| {
                let tasks: Vec<Task<'_>> = (0..bed.integrals()).map(|i| Task::new(&bed, i, budget)).collect();
                est.estimate_sequence(&tasks, &mut rng).expect("estimate")
            })
        });
    }
    group.finish();
}

fn adaptation(c: &mut Criterion) {
    let ip = PmcIp::from_params(&Params::new()).expect("defaults");
    let mut rng = stream(2, "pmc-ip adaptation");
    let pixels = 48 * 48;
    let stats: Vec<Moments> = (0..pixels)
        .map(|p| {
            let mut m = Moments::default();
            m.extend([0.1 * (p % 7) as f64, 0.3 + (p % 13) as f64 * (p % 3) as f64]);
            m
        })
        .collect();
    let mut group = c.benchmark_group("pmc_ip_adaptation_2304px");
    group.throughput(Throughput::Elements(pixels as u64));
    group.bench_function("weights_and_allocation_4spp", |b| {
        b.iter(|| {
            let alpha = ip.weights(black_box(&stats));
            ip.allocate(&alpha, 4 * pixels, &mut rng)
        })
    });
    group.finish();
}

criterion_group!(benches, image, adaptation);
criterion_main!(benches);
