use super::*;
use crate::run::cell::RepBlock;
use rand::{Rng, SeedableRng};

#[test]
fn no_change_only_inside_the_margin_and_a_change_only_when_the_interval_excludes_none() {
    use ChangeVerdict::*;
    let m = 0.1;
    assert_eq!(decide_ratio(0.95, 1.05, m, false), NoChange);
    assert_eq!(decide_ratio(1.02, 1.08, m, false), NoChange, "significant but inside the margin");
    assert_eq!(decide_ratio(1.05, 1.3, m, false), Regressed, "an RMSE ratio above 1 is worse");
    assert_eq!(decide_ratio(1.05, 1.3, m, true), Improved, "an efficiency ratio above 1 is better");
    assert_eq!(decide_ratio(0.7, 0.95, m, false), Improved);
    assert_eq!(decide_ratio(0.85, 1.2, m, false), Inconclusive, "straddles 1 and leaves the margin");
    assert_eq!(decide_ratio(0.0, 1.2, m, false), Inconclusive);
    assert_eq!(decide_ratio(f64::NAN, 1.0, m, false), Inconclusive);
    assert_eq!(decide_ratio(1.0 / 1.1, 1.1, m, false), NoChange, "the band is [1/(1+m), 1+m]");
    assert_eq!(decide_difference(-0.05, 0.05, 0.1, false), NoChange);
    assert_eq!(decide_difference(-0.4, -0.05, 0.1, false), Improved, "a steeper slope is better");
    assert_eq!(decide_difference(0.02, 0.3, 0.1, false), Regressed);
    assert_eq!(decide_difference(-0.2, 0.3, 0.1, false), Inconclusive);
}

/// A cell of `n` blocks of one repetition with squared errors `scale x` lognormal draws and
/// `seconds` CPU seconds per repetition.
fn cell(n: usize, scale: f64, seconds: f64, seed: u64) -> CellData {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let blocks: Vec<RepBlock> = (0..n)
        .map(|_| {
            let z: f64 = (0..12).map(|_| rng.gen::<f64>()).sum::<f64>() - 6.0;
            RepBlock { reps: 1, sq: scale * (0.5 * z).exp(), cpu_seconds: seconds, ..Default::default() }
        })
        .collect();
    let mse = blocks.iter().map(|b| b.sq).sum::<f64>() / n as f64;
    let row = SummaryRow {
        reps: n,
        integrals: 1,
        mse,
        variance: mse,
        cpu_seconds: seconds,
        mse_se: f64::NAN,
        ..crate::output::plot::tests::row("e", 4, 1.0, seconds)
    };
    let rb = RowBlocks { blocks, integrals: 1, mse_offset: 0.0, p_err_offset: 0.0 };
    CellData { row, mse: rb.clone(), variance: rb }
}

#[test]
fn the_same_cells_paired_read_exactly_one_and_a_doubled_error_reads_regressed() {
    let a = cell(32, 1.0, 1e-3, 1);
    let same = ratio(Metric::Rmse, &a, &a.clone(), true, 9).expect("defined");
    assert_eq!((same.change, same.lo, same.hi, same.paired), (1.0, 1.0, 1.0, true));
    assert_eq!(decide_ratio(same.lo, same.hi, DEFAULT_MARGIN, false), ChangeVerdict::NoChange);
    let worse = cell(32, 4.0, 1e-3, 2);
    let r = ratio(Metric::Rmse, &a, &worse, false, 9).expect("defined");
    assert!(!r.paired && r.lo > 1.1, "{r:?}");
    assert_eq!(decide_ratio(r.lo, r.hi, DEFAULT_MARGIN, false), ChangeVerdict::Regressed);
    // The efficiency of the same error at half the CPU time doubles.
    let faster = cell(32, 1.0, 0.5e-3, 1);
    let e = ratio(Metric::EfficiencyMse, &a, &faster, true, 9).expect("defined");
    assert!((e.change - 2.0).abs() < 1e-12 && (e.lo - 2.0).abs() < 1e-12, "{e:?}");
    assert_eq!(decide_ratio(e.lo, e.hi, DEFAULT_MARGIN, true), ChangeVerdict::Improved);
}

#[test]
fn cells_without_blocks_fall_back_to_the_delta_method() {
    let mut a = cell(16, 1.0, 1e-3, 1);
    let mut b = cell(16, 1.0, 1e-3, 2);
    for c in [&mut a, &mut b] {
        c.mse.blocks.clear();
        c.variance.blocks.clear();
        c.row.mse_se = 0.05 * c.row.mse;
    }
    let r = ratio(Metric::Rmse, &a, &b, true, 9).expect("delta");
    assert!(r.method.starts_with("delta") && r.lo < r.change && r.change < r.hi, "{r:?}");
    let expected = (b.row.mse / a.row.mse).sqrt();
    assert!((r.change - expected).abs() < 1e-12);
}

#[test]
fn slopes_differ_by_their_intervals_combined_and_identical_paired_fits_by_zero() {
    let a = (-0.5, -0.6, -0.4);
    let same = slope_difference(a, a, true).expect("defined");
    assert_eq!((same.lo, same.hi), (0.0, 0.0));
    let d = slope_difference(a, (-1.0, -1.1, -0.9), false).expect("defined");
    assert!((d.change + 0.5).abs() < 1e-12);
    assert!((d.hi - d.lo - 2.0 * 0.1 * 2f64.sqrt()).abs() < 1e-9, "{d:?}");
    assert_eq!(decide_difference(d.lo, d.hi, DEFAULT_SLOPE_MARGIN, false), ChangeVerdict::Improved);
    assert!(slope_difference((f64::NAN, 0.0, 0.0), a, false).is_none());
}
