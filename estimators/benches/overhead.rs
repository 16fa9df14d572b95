//! Criterion benches of the adaptive estimators' overhead over their plain counterparts (book: benches.md),
//! each a pair timed in one run so their ratio is read from one report:
//! - `overhead_media_vertex/<structure>/{is0_cv0,is1_cv2}`: one scattering vertex in
//!   `gradient-box` albedo 0.8 with the free flight it leaves by. `is0_cv0`: phase sampling and the
//!   flight (paper 000's path tracer); `is1_cv2`: the octree vertex of paper 000 Fig. 2 (leaf, cell
//!   drawn from the cache PDF, `G`, bilinear `g`, the flight, the estimate and the record). The
//!   vertices are real collision points of the box's paths, cycled; the octree is `grown_1024spp`
//!   (the structure `is1_cv2` builds for a 16x16 image at 1024 spp, 65 536 cells) or `depth4`
//!   (4096 leaves, 2.1 M cells: the size of the 16 384-spp structure).
//! - `overhead_surface_sample/{brdf_is0_cv0,is1_cv2}`: one sample of a `gradient-plane` pixel's
//!   estimate at 1024 spp (paper 001: BRDF sampling against the per-pixel cache's `is1_cv2`).
//! - `overhead_smc_frame/{bidirectional_is,smc}`: one frame of one pixel of `envmap-sequence`
//!   `mixed` (paper 004, N = 16, a 10-frame sequence reported per frame).
//!
//! Times are the CPU time of the bench's thread ([`ThreadCpu`]), not wall time: on a shared machine
//! the neighbours' load slows the run (and moves the memory-bound vertex more than the others)
//! but is not counted. Run with `cargo bench -p mcbench-papers --bench overhead` (about 20 s of
//! measurement).

use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{black_box, criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use mcbench_core::budget::Budget;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::params::Params;
use mcbench_core::rng::stream;
use mcbench_core::task::{MediumProbe, Task};
use mcbench_papers::builtins;
use mcbench_papers::cache::{CacheConfig, ControlVariate, Domain, St};
use mcbench_papers::media_smc::octree::{self, Octree};
use mcbench_papers::media_smc::walk::{self, Flight, Vertex};
use mcbench_papers::media_smc::{Sampling, Transport};
use mcbench_papers::testbeds::gradient_box::GradientBox;
use rand::Rng;
use std::time::Duration;

/// Criterion's measurement in CPU nanoseconds of the calling thread
/// (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`).
struct ThreadCpu;

fn thread_cpu_ns() -> u64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime");
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

impl Measurement for ThreadCpu {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns()
    }
    fn end(&self, start: u64) -> u64 {
        thread_cpu_ns() - start
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &CpuNanos
    }
}

/// Formats CPU nanoseconds (and throughputs as elements per CPU second).
struct CpuNanos;

impl ValueFormatter for CpuNanos {
    fn scale_values(&self, typical: f64, values: &mut [f64]) -> &'static str {
        let (factor, unit) = match typical {
            t if t < 1e3 => (1.0, "ns cpu"),
            t if t < 1e6 => (1e-3, "us cpu"),
            _ => (1e-6, "ms cpu"),
        };
        values.iter_mut().for_each(|v| *v *= factor);
        unit
    }
    fn scale_throughputs(&self, _typical: f64, throughput: &Throughput, values: &mut [f64]) -> &'static str {
        let n = match *throughput {
            Throughput::Elements(n) | Throughput::Bytes(n) | Throughput::BytesDecimal(n) => n as f64,
        };
        values.iter_mut().for_each(|v| *v = n * 1e3 / *v);
        "elem/cpu us"
    }
    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

fn short<M: Measurement>(group: &mut BenchmarkGroup<'_, M>) {
    group.warm_up_time(Duration::from_millis(500));
    group.measurement_time(Duration::from_secs(2));
}

/// Collision points (and the directions they were reached along) of independent paths through
/// the box, from every pixel in turn: where the vertices of both estimators sit.
fn collisions(probes: &[MediumProbe<'_>], n: usize) -> Vec<(Vec3, Vec3)> {
    let mut rng = stream(6, "bench collisions");
    let mut out = Vec::with_capacity(n);
    'paths: for k in 0.. {
        let probe = &probes[k % probes.len()];
        let (mut pos, mut dir) = (probe.ray().origin, probe.ray().dir);
        while let Flight::Collided(x) = walk::free_flight(probe, pos, dir, &mut rng) {
            out.push((x, dir));
            if out.len() == n {
                break 'paths;
            }
            pos = x;
            dir = probe.phase().sample(dir, &mut rng).0;
        }
    }
    out
}

/// The octree `is1_cv2` grows over a 16x16 image at 1024 paths per pixel (pixels interleaved,
/// default criterion 32): 512 leaves at depth 3. Its `max_depth` is 3, which changes nothing in
/// that growth (no leaf reached the criterion at depth 3) but keeps the bench's own records from
/// growing it further while it is timed.
fn grown_1024spp(probes: &[MediumProbe<'_>]) -> Octree<f64> {
    let config =
        CacheConfig { domain: Domain::Sphere, criterion: 32.0, max_depth: 3, counter_divisor: 32, importance: true };
    let mut tree = Octree::<f64>::new(Vec3::default(), 0.5, config);
    let (mut rng, mut vertices) = (stream(7, "bench grown octree"), Vec::new());
    for _ in 0..1024 {
        for probe in probes {
            let (s, cv, t) = (Sampling::Cache, ControlVariate::Bilinear, Transport::FreeFlight);
            walk::smc_path(&mut tree, probe, s, cv, t, &mut rng, &mut vertices);
        }
    }
    assert_eq!((tree.stats().leaves, tree.stats().depth), (512, 3), "the 1024-spp structure");
    tree
}

/// An octree split down to depth 4 everywhere (criterion 1, `max_depth` 4, so the bench's records
/// no longer refine it), with smooth records in every cell.
fn depth4() -> Octree<f64> {
    let config =
        CacheConfig { domain: Domain::Sphere, criterion: 1.0, max_depth: 4, counter_divisor: 32, importance: true };
    let mut tree = Octree::<f64>::new(Vec3::default(), 0.5, config);
    let mut r = stream(5, "bench full octree");
    while tree.stats().leaves < 4096 {
        for _ in 0..4096 {
            let p = Vec3::new(r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5, r.gen::<f64>() - 0.5);
            let st = St { s: r.gen(), t: r.gen() };
            tree.add_record(p, st, Rgb::splat(1.0 + st.t), Rgb::splat(0.5));
        }
    }
    tree
}

fn media_vertex(c: &mut Criterion<ThreadCpu>) {
    let bed = GradientBox::without_reference("albedo-0.8", &Params::new()).expect("builds");
    let tasks: Vec<Task<'_>> =
        (0..256).map(|i| Task::new(&bed, i, Budget::samples(u64::MAX).expect("budget"))).collect();
    let probes: Vec<MediumProbe<'_>> = tasks.iter().map(|t| t.medium().expect("medium")).collect();
    let points = collisions(&probes, 1 << 16);
    let probe = &probes[0];
    let (albedo, phase) = (probe.albedo(), probe.phase());
    let mut group = c.benchmark_group("overhead_media_vertex");
    short(&mut group);
    for (name, mut tree) in [("grown_1024spp", grown_1024spp(&probes)), ("depth4", depth4())] {
        assert_eq!(octree::SPLIT_DIVISOR, 32);
        let (mut rng, mut k) = (stream(8, "bench vertex"), 0);
        group.bench_function(format!("{name}/is0_cv0"), |b| {
            b.iter(|| {
                let (x, dir) = points[k];
                k = (k + 1) % points.len();
                let w = phase.sample(dir, &mut rng).0;
                black_box(walk::free_flight(probe, x, w, &mut rng))
            })
        });
        group.bench_function(format!("{name}/is1_cv2"), |b| {
            b.iter(|| {
                let (x, dir) = points[k];
                k = (k + 1) % points.len();
                let (s, cv) = (Sampling::Cache, ControlVariate::Bilinear);
                let (v, w) = Vertex::read(&tree, x, dir, s, cv, phase, albedo, &mut rng);
                // The radiance the flight ends in: the background, or a constant at a collision.
                let radiance = match walk::free_flight(probe, x, w, &mut rng) {
                    Flight::Escaped(l) => l,
                    Flight::Collided(_) => Rgb::splat(0.5),
                };
                black_box(v.estimate_and_record(&mut tree, radiance))
            })
        });
    }
    group.finish();
}

fn surface_sample(c: &mut Criterion<ThreadCpu>) {
    const SPP: u64 = 1024;
    let entry = builtins::testbed("gradient-plane").expect("registered");
    let bed = (entry.build)("default", &Params::new(), &mcbench_core::references::NoReferences).expect("bed");
    let mut group = c.benchmark_group("overhead_surface_sample");
    short(&mut group);
    group.throughput(Throughput::Elements(SPP));
    for id in ["brdf_is0_cv0", "is1_cv2"] {
        let est = (builtins::estimator(id).expect("registered").build)(&Params::new()).expect("builds");
        let (mut rng, mut i) = (stream(3, id), 0);
        group.bench_function(id, |b| {
            b.iter(|| {
                i = (i + 1) % bed.integrals();
                let task = Task::new(bed.as_ref(), i, Budget::samples(SPP).expect("spp"));
                black_box(est.estimate(&task, &mut rng).expect("estimate"))
            })
        });
    }
    group.finish();
}

fn smc_frame(c: &mut Criterion<ThreadCpu>) {
    const FRAMES: usize = 10;
    let entry = builtins::testbed("envmap-sequence").expect("registered");
    let params = Params::new().with("resolution", 4.0).with("frames", FRAMES as f64);
    let bed = (entry.build)("mixed", &params, &mcbench_core::references::NoReferences).expect("bed");
    let budget = Budget::samples(16).expect("budget");
    // The sequence of the pixel at the image centre (integrals are pixel-major, frames inner).
    let first = (2 * 4 + 2) * FRAMES;
    let mut group = c.benchmark_group("overhead_smc_frame");
    short(&mut group);
    group.throughput(Throughput::Elements(FRAMES as u64));
    for id in ["bidirectional_is", "smc"] {
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

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(ThreadCpu);
    targets = media_vertex, surface_sample, smc_frame
}
criterion_main!(benches);
