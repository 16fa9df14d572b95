//! Per-thread CPU time of whole estimates (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), the
//! load-proof numbers of docs/performance.md: the time one thread spent, not wall time, so a busy
//! machine slows the run but does not change the ratios much. Not a criterion bench: it prints one
//! line per measurement and ignores criterion's options.
//!
//! ```text
//! cargo bench -p estimators --bench cpu -- media 1024 is0_cv0 is1_cv2      # gradient-box albedo 0.8, 16x16
//! cargo bench -p estimators --bench cpu -- surface 1024 brdf_is0_cv0 is1_cv2 brdf_is1_cv2   # gradient-plane 16x16
//! cargo bench -p estimators --bench cpu -- envmap 10 bidirectional_is smc smc_bridge       # envmap-sequence
//! ```
//! Options after the ids: `storage=f32` (the caches' cell precision), `reps=K` (repeat K times,
//! each line its own measurement).

use estimators::budget::Budget;
use estimators::params::{ParamValue, Params};
use estimators::registry;
use estimators::rng::stream;
use estimators::task::Task;
use estimators::testbed::TestBed;
use estimators::testbeds::gradient_box::GradientBox;

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
    let est = (registry::estimator(id).expect("registered").build)(params).expect("builds");
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
    let hash = values.iter().flat_map(|v| v.0).fold(0xcbf2_9ce4_8422_2325u64, |h, x| {
        (h ^ x.to_bits()).wrapping_mul(0x0100_0000_01b3)
    });
    let samples = tasks.iter().map(|t| t.costs().samples).sum();
    let diag = tasks.last().map(|t| t.diagnostics()).unwrap_or_default();
    (cpu, samples, diag, hash)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let Some(mode) = args.first() else {
        eprintln!("usage: cpu <media|surface|envmap> <spp|frames> <ids...> [storage=f32] [reps=K]");
        return;
    };
    let size: u64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1024);
    let mut params = Params::new();
    let mut reps = 1;
    let mut ids = Vec::new();
    for a in &args[2..] {
        match a.split_once('=') {
            Some(("storage", v)) => {
                params.0.insert("storage".into(), ParamValue::Text(v.into()));
            }
            Some(("reps", v)) => reps = v.parse().expect("reps"),
            _ => ids.push(a.clone()),
        }
    }
    let (bed, spp, per): (Box<dyn TestBed>, u64, &str) = match mode.as_str() {
        "media" => (Box::new(GradientBox::without_reference("albedo-0.8", &Params::new()).expect("bed")), size, "path"),
        "surface" => (
            (registry::testbed("gradient-plane").unwrap().build)("default", &Params::new().with("resolution", 16.0))
                .expect("bed"),
            size,
            "sample",
        ),
        "envmap" => (
            (registry::testbed("envmap-sequence").unwrap().build)(
                "mixed",
                &Params::new().with("resolution", 16.0).with("frames", size as f64),
            )
            .expect("bed"),
            64,
            "sample",
        ),
        other => panic!("unknown mode {other}"),
    };
    for rep in 0..reps {
        for id in &ids {
            let (cpu, samples, diag, hash) = run(bed.as_ref(), id, spp, &params, 1 + rep as u64);
            let extra: Vec<String> = diag
                .iter()
                .filter(|(k, _)| matches!(*k, "bytes" | "nodes" | "leaves" | "cells" | "cache_bytes"))
                .map(|(k, v)| format!("{k}={v}"))
                .collect();
            println!(
                "{mode} {id} spp={spp} cpu_s={cpu:.4} {per}s={samples} us_per_{per}={:.5} hash={hash:016x} {}",
                cpu * 1e6 / samples as f64,
                extra.join(" ")
            );
        }
    }
}
