//! Unit tests of [`super`].

use super::*;
use mcbench_core::task::Costs;

/// A cell of `blocks` blocks of `per` repetitions each, each repetition's squared error from
/// `draw`, and `seconds(k)` CPU seconds per estimate in block `k` (one integral).
fn cell(blocks: usize, per: u64, mut draw: impl FnMut(usize) -> f64, seconds: impl Fn(usize) -> f64) -> RowBlocks {
    let blocks = (0..blocks)
        .map(|k| {
            let sq: f64 = (0..per).map(|_| draw(k)).sum();
            RepBlock {
                reps: per,
                sq,
                p_err: sq,
                display_sq: Some(sq),
                cpu_seconds: seconds(k) * per as f64,
                wall_seconds: seconds(k) * per as f64,
                costs: Costs { samples: per * 4, fetches: per * 10, ..Default::default() },
            }
        })
        .collect();
    RowBlocks { blocks, integrals: 1, mse_offset: 0.0, p_err_offset: 0.0 }
}

fn mse_ratio(a: &CellSample<'_>, b: &CellSample<'_>, _: f64) -> Option<f64> {
    Some(a.mse().ln() - b.mse().ln())
}

/// A lognormal squared error: `exp(s N)`, mean `exp(s^2 / 2)`.
fn lognormal(rng: &mut Pcg64, s: f64) -> f64 {
    (s * standard_normal(rng)).exp()
}

/// The share of `trials` seeds whose 95% interval of the MSE ratio of two independent skewed
/// cells (lognormal squared errors, the second scaled by 3: true ratio 1/3) holds the truth: the
/// percentile interval before the heavy-tail allowance, the delta method's, and the ratio's
/// interval (with the allowance).
fn coverage(trials: u64, blocks: usize, per: u64, s: f64) -> (f64, f64, f64) {
    let (mut held, mut held_delta, mut held_widened) = (0, 0, 0);
    // The delta method on the block means, for comparison.
    let delta = |c: &RowBlocks| {
        let m: Vec<f64> = c.blocks.iter().map(|b| b.sq / b.reps as f64).collect();
        let mean = m.iter().sum::<f64>() / m.len() as f64;
        let var = m.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (m.len() - 1) as f64;
        (mean.ln(), var / m.len() as f64 / (mean * mean))
    };
    for t in 0..trials {
        let mut rng = Pcg64::seed_from_u64(1000 + t);
        let a = cell(blocks, per, |_| lognormal(&mut rng, s), |_| 1.0);
        let b = cell(blocks, per, |_| 3.0 * lognormal(&mut rng, s), |_| 1.0);
        let boot = log_ratio(&a, &b, t, mse_ratio).expect("bootstrap");
        let truth = (1.0f64 / 3.0).ln();
        let (lo, hi) = boot.log_interval_at(0.95).expect("replicates");
        held += u64::from(lo <= truth && truth <= hi);
        let (lo, hi) = boot.log95;
        held_widened += u64::from(lo <= truth && truth <= hi);
        let ((la, va), (lb, vb)) = (delta(&a), delta(&b));
        let half = t_quantile(0.975, blocks as f64 - 1.0) * (va + vb).sqrt();
        held_delta += u64::from((la - lb - truth).abs() <= half);
    }
    let share = |n: u64| n as f64 / trials as f64;
    (share(held), share(held_delta), share(held_widened))
}

/// Coverage of the 95% interval over 400 synthetic pairs of cells with known MSE ratio, at
/// the block counts of a quick run (16 blocks of 1 repetition) and of a full one (32 blocks of
/// 8), squared errors lognormal with sigma 1 (skewness 6.2). The binomial standard error of a
/// coverage of 0.95 over 400 trials is 0.011: the tolerance [0.92, 0.98] of the percentile
/// interval is about 3 of them. The heavy-tail allowance makes these (fully sampled) tails'
/// intervals conservative, but not by so much that they would hold any ratio: below 99.5%.
#[test]
fn intervals_cover_the_true_ratio_of_skewed_errors() {
    let (quick, quick_delta, quick_w) = coverage(400, 16, 1, 1.0);
    let (full, full_delta, full_w) = coverage(400, 32, 8, 1.0);
    let (mild, mild_delta, mild_w) = coverage(400, 16, 1, 0.5);
    eprintln!(
        "coverage (percentile / delta method / with the allowance): 16 blocks of 1 repetition {quick:.3} / {quick_delta:.3} / {quick_w:.3}, 32 blocks of 8 {full:.3} / {full_delta:.3} / {full_w:.3}, 16 blocks sigma 0.5 {mild:.3} / {mild_delta:.3} / {mild_w:.3}"
    );
    assert!((0.92..=0.98).contains(&full), "32 blocks: coverage {full}");
    assert!((0.92..=0.98).contains(&mild), "16 blocks, sigma 0.5: coverage {mild}");
    assert!((0.92..=0.98).contains(&quick), "16 blocks: coverage {quick}");
    // No worse than the delta method where it can be computed (MSE ratios).
    assert!(quick >= quick_delta - 0.01 && full >= full_delta - 0.01, "{quick} {quick_delta} {full} {full_delta}");
    for (c, w) in [(quick, quick_w), (full, full_w), (mild, mild_w)] {
        assert!(w >= c && (0.95..=0.995).contains(&w), "with the allowance {w}, without {c}");
    }
}

/// Two cells whose blocks share a factor (the same load or the same hard stretch of work):
/// their ratio is nearly constant block by block. The paired interval is much narrower than
/// one from resampling them apart, and still holds the true ratio 2.
#[test]
fn paired_cells_give_narrower_intervals_that_still_cover() {
    let mut rng = Pcg64::seed_from_u64(7);
    let shared: Vec<f64> = (0..32).map(|_| lognormal(&mut rng, 1.0)).collect();
    let mut own = Pcg64::seed_from_u64(8);
    let a = cell(32, 1, |k| 2.0 * shared[k] * (1.0 + 0.05 * standard_normal(&mut own)), |_| 1.0);
    let b = cell(32, 1, |k| shared[k], |_| 1.0);
    let paired = log_ratio(&a, &b, 1, mse_ratio).expect("paired");
    assert!(paired.paired);
    // The same cells with the second's last two blocks as one are resampled apart.
    let mut b2 = b.clone();
    let last = b2.blocks.pop().expect("block");
    b2.blocks.last_mut().expect("block").merge(&last);
    let unpaired = log_ratio(&a, &b2, 1, mse_ratio).expect("unpaired");
    assert!(!unpaired.paired);
    let width = |b: &Bootstrap| b.log95.1 - b.log95.0;
    assert!(width(&paired) * 5.0 < width(&unpaired), "{:?} {:?}", paired.log95, unpaired.log95);
    assert!(paired.log95.0 < 2f64.ln() && 2f64.ln() < paired.log95.1, "{:?}", paired.log95);
}

fn efficiency_ratio(a: &CellSample<'_>, b: &CellSample<'_>, _: f64) -> Option<f64> {
    Some(
        (b.mse() * b.seconds(Regime::Measured, &CostModel::default())).ln()
            - (a.mse() * a.seconds(Regime::Measured, &CostModel::default())).ln(),
    )
}

/// Load that comes and goes during a run: each block of the first cell ran 60% slower with
/// probability 1/2 (a memory-bound estimator slowed by a neighbour), the second's did not. The
/// efficiency ratio's interval then holds the ratio at the expected load, -ln 1.3 here, in
/// about 95% of runs, where an interval that takes each cell's mean seconds as exact (the same
/// blocks with their seconds evened out) misses it in about a quarter of them.
#[test]
fn time_noise_between_blocks_widens_the_interval_to_cover() {
    let truth = -(1.3f64.ln());
    let (mut held, mut held_exact) = (0, 0);
    let trials = 300;
    for t in 0..trials {
        let mut rng = Pcg64::seed_from_u64(5000 + t);
        let load: Vec<bool> = (0..32).map(|_| rng.gen::<bool>()).collect();
        let a = cell(32, 8, |_| lognormal(&mut rng, 0.3), |k| if load[k] { 1.6 } else { 1.0 });
        let b = cell(32, 8, |_| lognormal(&mut rng, 0.3), |_| 1.0);
        let mut a_exact = a.clone();
        let mean = a.blocks.iter().map(|b| b.cpu_seconds).sum::<f64>() / 32.0;
        a_exact.blocks.iter_mut().for_each(|b| b.cpu_seconds = mean);
        let noisy = log_ratio(&a, &b, t, efficiency_ratio).expect("noisy");
        let exact = log_ratio(&a_exact, &b, t, efficiency_ratio).expect("exact");
        assert!((noisy.estimate - exact.estimate).abs() < 1e-12);
        if t == 0 {
            let width = |b: &Bootstrap| b.log95.1 - b.log95.0;
            assert!(width(&noisy) > 1.5 * width(&exact), "{:?} vs {:?}", noisy.log95, exact.log95);
        }
        held += u64::from(noisy.log95.0 <= truth && truth <= noisy.log95.1);
        held_exact += u64::from(exact.log95.0 <= truth && truth <= exact.log95.1);
    }
    let (c, e) = (held as f64 / trials as f64, held_exact as f64 / trials as f64);
    eprintln!("coverage under varying load: blocks' seconds {c:.3}, seconds as exact {e:.3}");
    assert!((0.91..=0.99).contains(&c), "{c}");
    assert!(e < 0.85, "{e}");
}

#[test]
fn same_input_same_interval_and_unusable_blocks_give_none() {
    let mut rng = Pcg64::seed_from_u64(5);
    let a = cell(16, 1, |_| lognormal(&mut rng, 1.0), |_| 1.0);
    let b = cell(16, 1, |_| lognormal(&mut rng, 1.0), |_| 1.0);
    let x = log_ratio(&a, &b, 42, mse_ratio).expect("bootstrap");
    let y = log_ratio(&a, &b, 42, mse_ratio).expect("bootstrap");
    assert_eq!(x, y);
    assert_eq!(x.log95.0.to_bits(), y.log95.0.to_bits());
    // Another seed: another (close) interval.
    let z = log_ratio(&a, &b, 43, mse_ratio).expect("bootstrap");
    assert_ne!(x.log95, z.log95);
    assert!((x.log95.0 - z.log95.0).abs() < 0.2);
    // A cell without blocks (stored before them) or with one block has no bootstrap.
    assert!(log_ratio(&RowBlocks::default(), &b, 42, mse_ratio).is_none());
    let one = RowBlocks { blocks: a.blocks[..1].to_vec(), ..a.clone() };
    assert!(log_ratio(&one, &b, 42, mse_ratio).is_none());
}

#[test]
fn sums_of_all_blocks_give_the_cells_metrics() {
    let a = cell(4, 2, |k| k as f64 + 1.0, |k| 0.5 * (k + 1) as f64);
    let s = CellSample { rows: &a, sums: sums(&a.blocks, 0..4) };
    // Squared errors 1,1,2,2,3,3,4,4: MSE 2.5; seconds 0.5..2 per estimate: mean 1.25.
    assert!((s.mse() - 2.5).abs() < 1e-12 && (s.cpu_seconds() - 1.25).abs() < 1e-12);
    assert!((s.fetches() - 10.0).abs() < 1e-12 && (s.samples() - 4.0).abs() < 1e-12);
    let m = CostModel {
        ray_ns: 0.0,
        shadow_ray_ns: 0.0,
        fetch_ns: 1e9,
        cheap_fetch_ns: 0.0,
        target_eval_ns: 0.0,
        cache_op_ns: 0.0,
    };
    assert!((s.seconds(Regime::Renderer, &m) - 11.25).abs() < 1e-9);
}
