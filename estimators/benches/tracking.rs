//! Criterion benches of the null-collision hot paths (paper 002; book: benches.md):
//! one fetch of each medium (the floor: a tight loop of extinction evaluations along the central
//! ray), and one
//! transmittance estimate (16 rays) of each tracker on the full central ray s = 20 of each medium.
//!
//! Every bench times itself through `iter_custom` and counts the fetches its estimates made, so
//! after the criterion run the bench prints, per tracker, its fetch steps per second as a ratio to
//! the bare fetch rate (target >= 0.7: the fetch is the work). The floor of each ratio is the bare
//! loop timed for 0.3 s just before and just after that tracker's bench (their mean), so a change
//! of machine load during the run does not leak into the ratios. Cheap (approximate-extinction)
//! fetches are shown apart and are not counted as steps.
//! Run with `cargo bench -p mcbench-papers --bench tracking`.

use criterion::{black_box, Criterion, Throughput};
use mcbench_core::budget::Budget;
use mcbench_core::math::Vec3;
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use mcbench_papers::builtins;
use rand::Rng;
use std::cell::RefCell;
use std::time::{Duration, Instant};

/// One benched tracker: label, id and parameters.
type Tracker = (&'static str, &'static str, &'static [(&'static str, f64)]);

/// The trackers benched.
const TRACKERS: &[Tracker] = &[
    ("ray_marching", "ray_marching", &[]),
    ("delta_tracking", "delta_tracking", &[]),
    ("ratio_tracking", "ratio_tracking", &[]),
    ("residual_ratio_tracking", "residual_ratio_tracking", &[]),
    ("double_particle[sigma_samp=1]", "double_particle", &[("sigma_samp", 1.0)]),
    ("double_particle[sigma_samp=0.4]", "double_particle", &[("sigma_samp", 0.4)]),
    ("single_particle_terminating", "single_particle_terminating", &[]),
    ("single_particle_nonterminating", "single_particle_nonterminating", &[]),
];

/// Rays per benched estimate.
const RAYS: u64 = 16;

/// Time and fetch totals of one bench over all its criterion iterations.
#[derive(Default)]
struct Tally {
    time: Duration,
    fetches: u64,
    cheap: u64,
}

impl Tally {
    fn ns_per_fetch(&self) -> f64 {
        self.time.as_nanos() as f64 / self.fetches.max(1) as f64
    }
}

fn bed(id: &str, variant: &str) -> Box<dyn TestBed> {
    let entry = builtins::testbed(id).expect("registered medium");
    (entry.build)(variant, &Params::new(), &mcbench_core::references::NoReferences).expect("builds")
}

/// 1024 random points along the central ray (where the trackers step, so the bare loop and the
/// trackers see the same noise-table and branch behaviour).
fn fetch_points() -> Vec<Vec3> {
    let mut rng = stream(7, "bench fetch points");
    (0..1024).map(|_| Vec3::new(0.0, 0.0, rng.gen_range(0.0..20.0))).collect()
}

/// Nanoseconds per bare fetch over about 0.3 s of the tight loop (the floor beside one tracker).
fn floor_ns(bed: &dyn TestBed) -> f64 {
    let (scene, points) = (bed.medium().expect("medium"), fetch_points());
    let (t0, mut n) = (Instant::now(), 0u64);
    while t0.elapsed() < Duration::from_millis(300) {
        let mut s = 0.0;
        for p in &points {
            s += scene.sigma_t(black_box(*p));
        }
        black_box(s);
        n += points.len() as u64;
    }
    t0.elapsed().as_nanos() as f64 / n as f64
}

/// Bare fetches: `sigma_t` at the [`fetch_points`] in a tight loop.
fn bare_fetch(c: &mut Criterion, medium: &str, bed: &dyn TestBed, tally: &mut Tally) {
    let scene = bed.medium().expect("medium");
    let points = fetch_points();
    let mut group = c.benchmark_group(format!("fetch/{medium}"));
    group.throughput(Throughput::Elements(points.len() as u64));
    group.bench_function("sigma_t_x1024", |b| {
        b.iter_custom(|iters| {
            let t0 = Instant::now();
            for _ in 0..iters {
                let mut s = 0.0;
                for p in &points {
                    s += scene.sigma_t(black_box(*p));
                }
                black_box(s);
            }
            let d = t0.elapsed();
            tally.time += d;
            tally.fetches += iters * points.len() as u64;
            d
        })
    });
    group.finish();
}

/// One estimate of `RAYS` rays on the last central-ray integral (s = 20).
fn tracker(c: &mut Criterion, medium: &str, bed: &dyn TestBed, label: &str, id: &str, params: &[(&str, f64)]) -> Tally {
    let params = params.iter().fold(Params::new(), |p, (k, v)| p.with(k, *v));
    let estimator = (builtins::estimator(id).expect("registered").build)(&params).expect("builds");
    let integral = bed.integrals() - 1;
    let budget = Budget::samples(RAYS).expect("budget");
    let mut rng = stream(11, label);
    let tally = RefCell::new(Tally::default());
    let mut group = c.benchmark_group(format!("tracker/{medium}"));
    group.bench_function(label, |b| {
        b.iter_custom(|iters| {
            let (mut fetches, mut cheap) = (0, 0);
            let t0 = Instant::now();
            for _ in 0..iters {
                let task = Task::new(bed, integral, budget);
                black_box(estimator.estimate(&task, &mut rng).expect("estimates"));
                fetches += task.costs().fetches;
                cheap += task.costs().cheap_fetches;
            }
            let d = t0.elapsed();
            let mut t = tally.borrow_mut();
            t.time += d;
            t.fetches += fetches;
            t.cheap += cheap;
            d
        })
    });
    group.finish();
    tally.into_inner()
}

fn main() {
    let mut c = Criterion::default().configure_from_args();
    let mut table = Vec::new();
    for medium in ["eq21-medium", "perlin-medium"] {
        let bed = bed(medium, "central-ray");
        let mut floor = Tally::default();
        bare_fetch(&mut c, medium, bed.as_ref(), &mut floor);
        println!("{medium}: bare fetch {:.2} ns (criterion run)", floor.ns_per_fetch());
        for (label, id, params) in TRACKERS {
            let before = floor_ns(bed.as_ref());
            let t = tracker(&mut c, medium, bed.as_ref(), label, id, params);
            let after = floor_ns(bed.as_ref());
            table.push((medium, *label, 0.5 * (before + after), t));
        }
    }
    c.final_summary();
    if table.iter().all(|(_, _, floor, t)| floor.is_finite() && t.fetches > 0) {
        println!("\ntracker fetch steps per second vs bare fetches per second (floor timed beside each tracker; target >= 0.70)");
        println!(
            "{:<15} {:<32} {:>12} {:>12} {:>10} {:>8}",
            "medium", "tracker", "ns/fetch", "bare ns", "cheap/fch", "ratio"
        );
        for (medium, label, floor, t) in &table {
            let ratio = floor / t.ns_per_fetch();
            let cheap = t.cheap as f64 / t.fetches as f64;
            println!("{medium:<15} {label:<32} {:>12.2} {floor:>12.2} {cheap:>10.3} {ratio:>8.3}", t.ns_per_fetch());
        }
    }
}
