//! Criterion bench of the single-scatter estimators (paper 002 §4.3): one estimate of a
//! pixel near the light (4 spp, i.e. 4 primary rays) of `eq21-medium/single-scatter` by each of
//! the seven ids of Fig. 12, and the nested-quadrature reference of that pixel.
//! Run with `cargo bench -p mcbench-papers --bench single_scatter`.

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use mcbench_core::budget::Budget;
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::task::Task;
use mcbench_core::testbed::{MediumQuantity, MediumScene};
use mcbench_papers::builtins;
use mcbench_papers::testbeds::medium::scatter_reference::{single_scatter, Settings};
use mcbench_papers::testbeds::medium::{Field, MediumBed};

const IDS: [&str; 7] = [
    "ray_marching",
    "delta_tracking",
    "attenuation_driven",
    "attenuation_driven_sir",
    "source_driven",
    "scattering_driven",
    "mis",
];

fn bench(c: &mut Criterion) {
    let bed = MediumBed::without_reference(Field::Eq21, "single-scatter", &Params::new().with("resolution", 8.0))
        .expect("builds");
    let pixel = 3 * 8 + 3;
    let mut group = c.benchmark_group("single_scatter_4spp");
    for id in IDS {
        let est = (builtins::estimator(id).expect("registered").build)(&Params::new()).expect("builds");
        let mut rng = stream(1, id);
        group.bench_function(id, |b| {
            b.iter(|| {
                let task = Task::new(&bed, pixel, Budget::samples(4).expect("budget"));
                black_box(est.estimate(&task, &mut rng).expect("estimate"))
            })
        });
    }
    group.finish();
    let ray = bed.ray(pixel);
    let MediumQuantity::SingleScatter { light } = ray.quantity else { return };
    c.bench_function("single_scatter_reference_pixel_eq21", |b| {
        b.iter(|| black_box(single_scatter(&bed, &ray, &light, &Settings::of(Field::Eq21))))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
