//! Per-thread CPU time of whole estimates (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), the
//! load-proof numbers of docs/src/performance.md: the time one thread spent, not wall time, so a busy
//! machine slows the run but does not change the ratios much. Not a criterion bench: it prints one
//! line per measurement and ignores criterion's options.
//!
//! ```text
//! cargo bench -p mcbench-papers --bench cpu -- media 1024 is0_cv0 is1_cv2      # gradient-box albedo 0.8, 16x16
//! cargo bench -p mcbench-papers --bench cpu -- surface 1024 brdf_is0_cv0 is1_cv2 brdf_is1_cv2   # gradient-plane 16x16
//! cargo bench -p mcbench-papers --bench cpu -- envmap 10 bidirectional_is smc smc_bridge   # envmap-sequence mixed 16x16, 10 frames, N = 16
//! cargo bench -p mcbench-papers --bench cpu -- image 4 uniform_image pmc_ip threshold_image   # checker-image default 48x48, CPU per pixel sample
//! cargo bench -p mcbench-papers --bench cpu -- tracking 20000 bare bare_chained delta_tracking ratio_tracking   # eq21-medium, CPU per fetch
//! ```
//! Options after the ids: `storage=f32` (the caches' cell precision), `reps=K` (repeat K times,
//! each line its own measurement), `res=R` (the image side of gradient-plane and envmap-sequence,
//! default 16; checker-image default 48), `variant=V` (of envmap-sequence, default `mixed`; of
//! checker-image, default `default`), any other `name=number` (an estimator parameter, e.g.
//! `candidates=256`). Media report CPU per path, surfaces and images per (pixel) sample, envmap per pixel and frame
//! (with `samples` = target evaluations).

use mcbench_core::budget::Budget;
use mcbench_core::params::{ParamValue, Params};
use mcbench_core::rng::stream;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use mcbench_papers::builtins;
use mcbench_papers::testbeds::checker_image::CheckerImage;
use mcbench_papers::testbeds::gradient_box::GradientBox;

fn thread_cpu_seconds() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime");
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// What one measurement returns: CPU seconds, samples, the last task's diagnostics and a hash of
/// the bits of every estimate (equal hashes: bit-identical results).
type Measured = (f64, u64, Vec<(&'static str, f64)>, u64);

/// One whole-image sequence of `id` at `spp` samples per integral.
fn run(bed: &dyn TestBed, id: &str, spp: u64, params: &Params, seed: u64) -> Measured {
    let est = (builtins::estimator(id).expect("registered").build)(params).expect("builds");
    let n = bed.integrals();
    let frames = bed.sequence_length().max(1);
    let tasks: Vec<Task<'_>> = (0..n).map(|i| Task::new(bed, i, Budget::samples(spp).expect("spp"))).collect();
    let mut rng = stream(seed, id);
    let mut values = Vec::with_capacity(n);
    let t0 = thread_cpu_seconds();
    for seq in tasks.chunks(frames) {
        values.extend(est.estimate_sequence(seq, &mut rng).expect("estimates"));
    }
    let cpu = thread_cpu_seconds() - t0;
    // FNV-1a over the bits of every channel of every estimate.
    let hash = values
        .iter()
        .flat_map(|v| v.0)
        .fold(0xcbf2_9ce4_8422_2325u64, |h, x| (h ^ x.to_bits()).wrapping_mul(0x0100_0000_01b3));
    let samples = tasks.iter().map(|t| t.costs().samples).sum();
    let diag = tasks.last().map(|t| t.diagnostics()).unwrap_or_default();
    (cpu, samples, diag, hash)
}

/// `tracking <estimates> <ids...>`: each tracker's CPU (and, under callgrind, instructions) per
/// fetch over `estimates` transmittance estimates of 16 rays on eq21-medium's central ray s = 20
/// (the tracking bench's setup); the id `bare` is the floor, `sigma_t` at 1024 points of that ray
/// in a tight loop, `estimates x 16` times over, and `bare_chained` the same loop with each point
/// made dependent on the previous fetch. A tracker's line ends with a hash of the bits of all its
/// estimates (equal hashes: bit-identical results).
fn tracking(estimates: u64, ids: &[String]) {
    use rand::Rng;
    let bed = (builtins::testbed("eq21-medium").unwrap().build)(
        "central-ray",
        &Params::new(),
        &mcbench_core::references::NoReferences,
    )
    .expect("bed");
    for id in ids {
        let mut hash = None;
        let (t0, fetches) = if id == "bare" || id == "bare_chained" {
            let scene = bed.medium().expect("medium");
            let mut rng = stream(7, "bench fetch points");
            let points: Vec<_> =
                (0..1024).map(|_| mcbench_core::math::Vec3::new(0.0, 0.0, rng.gen_range(0.0..20.0))).collect();
            // `bare_chained`: each point depends on the previous fetch's value (by a zero
            // offset the compiler cannot see through), as a tracker's next point depends on its
            // last step: the fetches run one after the other instead of overlapping.
            let chained = id == "bare_chained";
            let t0 = thread_cpu_seconds();
            for _ in 0..estimates * 16 {
                let mut s = 0.0;
                for p in &points {
                    let p = if chained { *p + mcbench_core::math::Vec3::new(0.0, 0.0, 0.0 * s) } else { *p };
                    s += scene.sigma_t(std::hint::black_box(p));
                }
                std::hint::black_box(s);
            }
            (t0, estimates * 16 * points.len() as u64)
        } else {
            let est = (builtins::estimator(id).expect("registered").build)(&Params::new()).expect("builds");
            let mut rng = stream(11, id);
            let (mut fetches, mut h) = (0, 0xcbf2_9ce4_8422_2325u64);
            let t0 = thread_cpu_seconds();
            for _ in 0..estimates {
                let task = Task::new(bed.as_ref(), bed.integrals() - 1, Budget::samples(16).expect("budget"));
                let value = std::hint::black_box(est.estimate(&task, &mut rng).expect("estimates"));
                h = value.0.iter().fold(h, |h, x| (h ^ x.to_bits()).wrapping_mul(0x0100_0000_01b3));
                fetches += task.costs().fetches;
            }
            hash = Some(h);
            (t0, fetches)
        };
        let cpu = thread_cpu_seconds() - t0;
        let hash = hash.map(|h| format!(" hash={h:016x}")).unwrap_or_default();
        println!("tracking {id} fetches={fetches} ns_per_fetch={:.3}{hash}", cpu * 1e9 / fetches as f64);
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    if args.first().map(String::as_str) == Some("tracking") {
        let n = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1000);
        return tracking(n, &args[2..]);
    }
    // Run by `cargo bench -p mcbench-papers -- <criterion options>` (no mode, or an option's value
    // first): nothing to measure.
    let Some(mode) = args.first().filter(|m| ["media", "surface", "envmap", "image"].contains(&m.as_str())) else {
        eprintln!(
            "usage: cpu <media|surface|envmap|image|tracking> <spp|frames|estimates> <ids...> [storage=f32] [reps=K]"
        );
        return;
    };
    let size: u64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1024);
    let mut params = Params::new();
    let mut reps = 1;
    let mut res = if mode == "image" { 48.0 } else { 16.0 };
    let mut variant = (if mode == "image" { "default" } else { "mixed" }).to_string();
    let mut ids = Vec::new();
    for a in &args[2..] {
        match a.split_once('=') {
            Some(("storage", v)) => {
                params.0.insert("storage".into(), ParamValue::Text(v.into()));
            }
            Some(("reps", v)) => reps = v.parse().expect("reps"),
            Some(("res", v)) => res = v.parse().expect("res"),
            Some(("variant", v)) => variant = v.to_string(),
            Some((k, v)) => params = params.with(k, v.parse::<f64>().expect("a numeric parameter")),
            None => ids.push(a.clone()),
        }
    }
    let (bed, spp, per): (Box<dyn TestBed>, u64, &str) = match mode.as_str() {
        "media" => (Box::new(GradientBox::without_reference("albedo-0.8", &Params::new()).expect("bed")), size, "path"),
        "surface" => (
            (builtins::testbed("gradient-plane").unwrap().build)(
                "default",
                &Params::new().with("resolution", res),
                &mcbench_core::references::NoReferences,
            )
            .expect("bed"),
            size,
            "sample",
        ),
        "envmap" => (
            (builtins::testbed("envmap-sequence").unwrap().build)(
                &variant,
                &Params::new().with("resolution", res).with("frames", size as f64),
                &mcbench_core::references::NoReferences,
            )
            .expect("bed"),
            16,
            "frame",
        ),
        "image" => (
            Box::new(CheckerImage::without_reference(&variant, &Params::new().with("resolution", res)).expect("bed")),
            size,
            "sample",
        ),
        other => panic!("unknown mode {other}"),
    };
    for rep in 0..reps {
        for id in &ids {
            let (cpu, samples, diag, hash) = run(bed.as_ref(), id, spp, &params, 1 + rep as u64);
            // Per pixel and frame for the sequences (samples = target evaluations), else per sample.
            let units = if per == "frame" { bed.integrals() as u64 } else { samples };
            let extra: Vec<String> = diag
                .iter()
                .filter(|(k, _)| matches!(*k, "bytes" | "nodes" | "leaves" | "cells" | "cache_bytes"))
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            println!(
                "{mode} {id} spp={spp} cpu_s={cpu:.4} samples={samples} {per}s={units} us_per_{per}={:.5} hash={hash:016x} {}",
                cpu * 1e6 / units as f64,
                extra.join(" ")
            );
        }
    }
}
