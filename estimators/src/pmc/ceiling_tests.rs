//! Tests of the image-plane ceiling: closed cases, no allocation beating it, the caps of the
//! constant combinations, and its value on the stored `checker-image` references.

use super::*;
use crate::built_in_references::BUILT_IN;
use crate::testbeds::checker_image::CheckerImage;
use crate::testbeds::checker_image_reference::sample_variances;
use mcbench_core::params::Params;
use rand::Rng;

/// A constant luminance: every pixel weighs the same in `Err`.
const L: f64 = 1.0;

#[test]
fn equal_variances_gain_nothing_and_one_noisy_pixel_of_two_gains_two() {
    let c = allocation_ceiling(&[2.0; 5], &[L; 5], 10.0, 0.0);
    assert!((c.gain - 1.0).abs() < 1e-12 && c.samples.iter().all(|n| (n - 10.0).abs() < 1e-12), "{c:?}");
    // All samples to the noisy pixel: Err halves.
    let c = allocation_ceiling(&[1.0, 0.0], &[L, L], 10.0, 0.0);
    assert!((c.gain - 2.0).abs() < 1e-12 && c.samples == vec![20.0, 0.0], "{c:?}");
    // With a floor of one sample the quiet pixel keeps it.
    let c = allocation_ceiling(&[1.0, 0.0], &[L, L], 10.0, 1.0);
    assert!((c.gain - 1.9).abs() < 1e-12 && c.samples == vec![19.0, 1.0], "{c:?}");
    // Standard deviations 1 and 3: samples 1 : 3, gain (1 + 9) / 2 / ((1 + 3) / 2)^2 = 1.25.
    let c = allocation_ceiling(&[1.0, 9.0], &[L, L], 8.0, 0.0);
    assert!((c.gain - 1.25).abs() < 1e-12 && (c.samples[1] - 12.0).abs() < 1e-12, "{c:?}");
}

/// Random allocations of the same total (each with at least the floor) never do better.
#[test]
fn no_allocation_beats_the_ceiling() {
    let mut rng = mcbench_core::rng::stream(5, "ceiling");
    let variance: Vec<f64> = (0..40).map(|i| if i % 7 == 0 { 0.0 } else { rng.gen::<f64>().powi(4) * 100.0 }).collect();
    let luminance: Vec<f64> = (0..40).map(|i| 0.01 * (i as f64 + 1.0).powi(2)).collect();
    let (spp, floor) = (6.0, 1.0);
    let c = allocation_ceiling(&variance, &luminance, spp, floor);
    assert!((c.samples.iter().sum::<f64>() - spp * 40.0).abs() < 1e-9);
    assert!(c.samples.iter().all(|n| *n >= floor - 1e-12));
    let a = perceptual_variances(&variance, &luminance);
    for _ in 0..2000 {
        let raw: Vec<f64> = (0..40).map(|_| rng.gen::<f64>() + 1e-3).collect();
        let t: f64 = raw.iter().sum();
        let n: Vec<f64> = raw.iter().map(|r| floor + (spp - floor) * 40.0 * r / t).collect();
        assert!(err(&a, &n) >= c.err_best * (1.0 - 1e-12));
    }
    // Nudging the best allocation (moving samples between two free pixels) does not help.
    let free: Vec<usize> = (0..40).filter(|&p| c.samples[p] > floor + 0.1).collect();
    let (i, j) = (free[0], free[1]);
    for d in [-0.05, 0.05] {
        let mut n = c.samples.clone();
        n[i] += d;
        n[j] -= d;
        assert!(err(&a, &n) >= c.err_best);
    }
}

/// A constant initial weight `c_0` over `s_0` of `spp` samples caps the gain at `s_0 / (spp c_0^2)`
/// (5 for the fixed 2/10 at 2+4+4, 1.8 for the unweighted 1/3): an image with one pixel far
/// noisier than the rest comes close to the cap and never passes it; pooling does not stop there.
#[test]
fn constant_initial_weights_cap_the_gain() {
    let mut variance = vec![1e-6; 400];
    variance[0] = 1.0;
    let luminance = vec![L; 400];
    for (c0, cap) in [(0.2, 5.0), (1.0 / 3.0, 1.8)] {
        let c = schedule_ceiling(&variance, &luminance, 10.0, 2.0, Some(c0), 0.0);
        eprintln!("c_0 = {c0:.3}: gain {:.3} (cap {cap})", c.gain);
        assert!(c.gain < cap && c.gain > 0.95 * cap, "{}", c.gain);
    }
    let pooled = schedule_ceiling(&variance, &luminance, 10.0, 2.0, None, 0.0);
    assert!(pooled.gain > 50.0, "{}", pooled.gain);
    // The free allocation is the pooled one without the initial image.
    let free = allocation_ceiling(&variance, &luminance, 10.0, 0.0);
    assert!(free.gain >= pooled.gain);
}

/// The ceilings on the stored `checker-image` references (48 x 48, variances of one pixel sample
/// from the references' own spread), beside the caps of the constant combinations.
#[test]
fn ceilings_on_the_stored_checker_image_references() {
    for variant in ["default", "occluded", "soft-shadow"] {
        let bed = CheckerImage::new(variant, &Params::new(), &BUILT_IN).unwrap();
        let reference = mcbench_core::testbed::TestBed::reference(&bed);
        let variance = sample_variances(reference).unwrap();
        let luminance: Vec<f64> = reference.value.iter().map(|v| mcbench_core::perception::luminance(*v)).collect();
        let any = allocation_ceiling(&variance, &luminance, 10.0, 1.0);
        let pooled = schedule_ceiling(&variance, &luminance, 10.0, 2.0, None, 2.0);
        let fixed = schedule_ceiling(&variance, &luminance, 10.0, 2.0, Some(0.2), 2.0);
        let unweighted = schedule_ceiling(&variance, &luminance, 10.0, 2.0, Some(1.0 / 3.0), 2.0);
        eprintln!(
            "checker-image/{variant} at 10 spp: Err gain ceiling {:.3} (any allocation, >= 1 per pixel); after a 2-spp initial image with >= 1 per pixel and iteration: pooled {:.3}, fixed 0.2 {:.3}, unweighted {:.3}",
            any.gain, pooled.gain, fixed.gain, unweighted.gain
        );
        assert!(any.gain >= pooled.gain && pooled.gain >= fixed.gain && fixed.gain >= unweighted.gain);
        assert!(fixed.gain < 5.0 && unweighted.gain < 1.8 && any.gain > 1.0);
    }
}
