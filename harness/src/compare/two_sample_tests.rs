//! Unit tests of the two-sample comparison of two cells.

use super::*;
use mcbench_core::stats::Moments;
use rand::Rng;

/// A cell of `reps` repetitions of `integrals` integrals (one channel used, two always zero, as a
/// scalar integrand stores them): integral `i` has mean `(1 + shift) (1 + i / 10)`, relative
/// spread `sd`.
fn cell(seed: u64, integrals: usize, reps: usize, shift: f64, sd: f64) -> CellMoments {
    let mut rng = mcbench_core::rng::stream(seed, "two-sample cell");
    let mut c = CellMoments { per_integral: vec![Default::default(); integrals], rep_sum: Moments::new() };
    for _ in 0..reps {
        let mut sum = 0.0;
        for (i, m) in c.per_integral.iter_mut().enumerate() {
            let u: f64 = rng.gen::<f64>() - 0.5;
            let x = (1.0 + shift) * (1.0 + i as f64 / 10.0) * (1.0 + sd * 12f64.sqrt() * u);
            m[0].push(x);
            m[1].push(0.0);
            m[2].push(0.0);
            sum += x;
        }
        // The stored sum is a deviation from a reference: a constant offset, the same spread.
        c.rep_sum.push(sum - 5.0);
    }
    c
}

#[test]
fn one_distribution_is_same_and_a_shift_differs() {
    let (same, tests) = test_cell(&cell(1, 16, 256, 0.0, 0.02), &cell(2, 16, 256, 0.0, 0.02));
    assert_eq!(same.verdict, TwoSampleVerdict::Same, "{same:?}");
    assert!(same.detectable_rel_diff < SAME_WITHIN && same.pooled_p > ALPHA, "{same:?}");
    // The zero channels are no tests: 16 tested of 48.
    assert_eq!((same.tested, tests.len(), same.integrals), (16, 48, 16));
    assert_eq!(same.p_histogram.iter().sum::<u64>(), 16);
    let (shifted, _) = test_cell(&cell(1, 16, 256, 0.0, 0.02), &cell(3, 16, 256, 0.01, 0.02));
    assert_eq!(shifted.verdict, TwoSampleVerdict::Differ, "{shifted:?}");
    assert!((shifted.rel_diff + 0.01).abs() < 0.003, "{shifted:?}");
    // Too few repetitions to resolve 1%: inconclusive, not same.
    let (few, _) = test_cell(&cell(4, 4, 8, 0.0, 0.2), &cell(5, 4, 8, 0.0, 0.2));
    assert_eq!(few.verdict, TwoSampleVerdict::Inconclusive, "{few:?}");
    assert!(few.detectable_rel_diff > SAME_WITHIN);
}

#[test]
fn the_csv_has_one_line_per_row_and_the_histogram_in_one_field() {
    let (row, tests) = test_cell(&cell(1, 4, 32, 0.0, 0.1), &cell(2, 4, 32, 0.0, 0.1));
    let t = TwoSample { estimator_a: "a".into(), estimator_b: "b".into(), rows: vec![row.clone()], integrals: tests };
    let text = String::from_utf8(csv_bytes(&t).expect("csv")).expect("utf-8");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2);
    assert!(lines[0].starts_with("estimator_a,estimator_b,") && lines[0].ends_with(",verdict,p_histogram"));
    let hist: Vec<String> = row.p_histogram.iter().map(u64::to_string).collect();
    assert!(lines[1].ends_with(&format!("{},{}", row.verdict.word(), hist.join(" "))), "{}", lines[1]);
    let per = String::from_utf8(integrals_csv_bytes(&t).expect("csv")).expect("utf-8");
    assert_eq!(per.lines().count(), 1 + 12);
}
