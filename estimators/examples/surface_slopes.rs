//! Quick convergence measurement of the surface estimators on `gradient-plane` (paper 001 Fig. 4),
//! independent of the harness: RMSE over all pixels and channels at spp = 4^k, `reps` repetitions,
//! the fitted log-log slope with its 95% interval, and the mean cache diagnostics per estimate.
//!
//! ```text
//! cargo run --release -p mcbench-papers --example surface_slopes -- [variant] [reps] [kmax] [res] [ids...]
//! cargo run --release -p mcbench-papers --example surface_slopes -- long [id] [spp] [variant]
//! ```
//! Defaults: `default 8 6 32 is0_cv0 is1_cv2` (spp 4 .. 4096 on 32x32). `long` runs one estimate
//! of pixel 0 with a huge budget (default `is1_cv2`, 1e7 samples): the stability case.

use mcbench_core::budget::Budget;
use mcbench_core::params::Params;
use mcbench_core::rng::{stream, StreamKey};
use mcbench_core::stats::log_log_fit;
use mcbench_core::task::Task;
use mcbench_core::testbed::TestBed;
use mcbench_papers::builtins;
use mcbench_papers::testbeds::gradient_plane::GradientPlane;
use std::collections::BTreeMap;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("long") {
        return long(&args[1..]);
    }
    let variant = args.first().cloned().unwrap_or_else(|| "default".into());
    let reps: u64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(8);
    let kmax: u32 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(6);
    let res: f64 = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(32.0);
    let ids: Vec<String> = if args.len() > 4 { args[4..].to_vec() } else { vec!["is0_cv0".into(), "is1_cv2".into()] };
    let bed = GradientPlane::new(&variant, &Params::new().with("resolution", res)).expect("test bed");
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!("gradient-plane/{variant} {res}x{res}, {reps} reps, {threads} threads");
    for id in &ids {
        let est = (builtins::estimator(id).expect("id").build)(&Params::new()).expect("build");
        let (mut spps, mut rmses) = (Vec::new(), Vec::new());
        for k in 1..=kmax {
            let spp = 4u64.pow(k);
            let start = Instant::now();
            let n = bed.integrals();
            let (sq, notes) = std::thread::scope(|scope| {
                let handles: Vec<_> = (0..threads)
                    .map(|t| {
                        let (est, bed, id, variant) = (&est, &bed, id.as_str(), variant.as_str());
                        scope.spawn(move || {
                            let (mut sum, mut notes) = (0.0, BTreeMap::<&'static str, f64>::new());
                            for i in (t..n).step_by(threads) {
                                let reference = bed.reference().value[i];
                                for rep in 0..reps {
                                    let key = StreamKey {
                                        seed: 1,
                                        testbed: variant,
                                        estimator: id,
                                        budget: spp,
                                        rep,
                                        integral: i as u64,
                                    };
                                    let task = Task::new(bed, i, Budget::samples(spp).expect("spp"));
                                    let v = est.estimate(&task, &mut key.rng()).expect("estimate");
                                    for ch in 0..3 {
                                        sum += (v[ch] - reference[ch]).powi(2);
                                    }
                                    for (name, value) in task.diagnostics() {
                                        *notes.entry(name).or_default() += value;
                                    }
                                }
                            }
                            (sum, notes)
                        })
                    })
                    .collect();
                let mut total = (0.0, BTreeMap::<&'static str, f64>::new());
                for h in handles {
                    let (s, m) = h.join().expect("thread");
                    total.0 += s;
                    for (k, v) in m {
                        *total.1.entry(k).or_default() += v;
                    }
                }
                total
            });
            let estimates = (n as u64 * reps) as f64;
            let rmse = (sq / (estimates * 3.0)).sqrt();
            let per_sample = start.elapsed().as_secs_f64() * threads as f64 / (estimates * spp as f64);
            let notes: Vec<String> = notes.iter().map(|(k, v)| format!("{k} {:.4}", v / estimates)).collect();
            println!(
                "{id:>14} spp {spp:>6}  rmse {rmse:.4e}  {:>5.0} ns/sample  {}",
                per_sample * 1e9,
                notes.join(", ")
            );
            spps.push(spp as f64);
            rmses.push(rmse);
        }
        match log_log_fit(&spps, &rmses) {
            Ok(f) => println!(
                "{id:>14} slope {:.3}  95% CI [{:.3}, {:.3}]  r2 {:.4}",
                f.slope, f.slope_ci_low, f.slope_ci_high, f.r2
            ),
            Err(e) => println!("{id:>14} fit failed: {e}"),
        }
    }
}

/// One estimate with a huge budget into one cache (stability: counters, precision, finiteness).
fn long(args: &[String]) {
    let id = args.first().map_or("is1_cv2", String::as_str);
    let spp: u64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(10_000_000);
    let variant = args.get(2).map_or("default", String::as_str);
    let bed = GradientPlane::new(variant, &Params::new().with("resolution", 4.0)).expect("test bed");
    let est = (builtins::estimator(id).expect("id").build)(&Params::new()).expect("build");
    let start = Instant::now();
    let task = Task::new(&bed, 5, Budget::samples(spp).expect("spp"));
    let v = est.estimate(&task, &mut stream(9, "long")).expect("estimate");
    let r = bed.reference().value[5];
    println!(
        "{id} on {variant}, pixel 5, {spp} samples in {:.1} s: estimate {:?}, reference {:?}, rel. error {:.2e}",
        start.elapsed().as_secs_f64(),
        v.0,
        r.0,
        (0..3).map(|c| ((v[c] - r[c]) / r[c]).abs()).fold(0.0, f64::max)
    );
    println!("diagnostics {:?}, costs {:?}", task.diagnostics(), task.costs());
}
