//! Criterion bench: one estimate of each registered estimator on each test bed it runs on, at a
//! small sample budget (book: benches.md). Run with `cargo bench -p mcbench-papers`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mcbench_core::budget::Budget;
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::task::Task;
use mcbench_papers::builtins::{ESTIMATORS, TESTBEDS};

fn one_estimate(c: &mut Criterion) {
    let budget = Budget::samples(64).expect("64 >= 1");
    for bed_entry in TESTBEDS {
        let variant = bed_entry.variants[0];
        // Test beds with stored references exist only at the stored resolution (benches/media.rs).
        let Ok(bed) =
            (bed_entry.build)(variant, &Params::new().with("resolution", 8.0), &mcbench_core::references::NoReferences)
        else {
            continue;
        };
        let mut group = c.benchmark_group(format!("estimate_{}_{}spp", bed_entry.id, budget.amount));
        group.throughput(Throughput::Elements(budget.amount));
        for e in ESTIMATORS.iter().filter(|e| e.skip_reason(bed.provides()).is_none()) {
            let est = (e.build)(&Params::new()).expect("default estimator builds");
            if est.supports(bed.as_ref()).is_err() {
                continue;
            }
            let mut rng = stream(1, e.id);
            // A pair the registry admits but whose estimate refuses (e.g. a surface estimator on
            // a test bed whose integrals are not hemispherical) is reported, not benched.
            if let Err(err) = est.estimate(&Task::new(bed.as_ref(), 0, budget), &mut rng) {
                eprintln!("skipped {} on {}/{}: {err}", e.id, bed_entry.id, variant);
                continue;
            }
            let mut i = 0usize;
            group.bench_function(BenchmarkId::from_parameter(e.id), |b| {
                b.iter(|| {
                    i = (i + 1) % bed.integrals();
                    let task = Task::new(bed.as_ref(), i, budget);
                    est.estimate(&task, &mut rng).expect("estimate")
                })
            });
        }
        group.finish();
    }
}

criterion_group!(benches, one_estimate);
criterion_main!(benches);
