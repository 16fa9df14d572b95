//! Unit tests of the unbiasedness tests and their verdicts.

use super::*;
use crate::analysis::reps_for;
use crate::run::cell::{CellKey, TimeStats};
use mcbench_core::budget::Budget;
use mcbench_core::math::Rgb;
use mcbench_core::stats::NeumaierSum;
use mcbench_core::testbed::ReferenceKind;
use rand::{Rng, SeedableRng};

/// A cell from per-repetition estimates of every integral (what the runner reduces).
pub(crate) fn cell_from(per_rep: &[Vec<[f64; 3]>], reference: &Reference) -> CellResult {
    let n = reference.value.len();
    let mut moments = vec![[Moments::default(), Moments::default(), Moments::default()]; n];
    let (mut rep_dev, mut rep_sq) = (Moments::default(), Moments::default());
    for v in per_rep {
        let (mut d, mut q) = (NeumaierSum::new(), NeumaierSum::new());
        for (i, x) in v.iter().enumerate() {
            for c in 0..3 {
                moments[i][c].push(x[c]);
                let e = x[c] - reference.value[i][c];
                d.add(e);
                q.add(e * e);
            }
        }
        rep_dev.push(d.value());
        rep_sq.push(q.value() / (3 * n) as f64);
    }
    let key = CellKey {
        testbed: "t".into(),
        variant: "v".into(),
        testbed_params: "{}".into(),
        estimator: "e".into(),
        budget: Budget::samples(4).unwrap(),
        reps: per_rep.len(),
        seed: 1,
        version: "0".into(),
    };
    CellResult {
        key,
        moments,
        costs: Default::default(),
        estimates: (per_rep.len() * n) as u64,
        time: TimeStats::default(),
        cpu_time: None,
        diagnostics: Vec::new(),
        rep_dev,
        rep_sq,
        blocks: Vec::new(),
    }
}

pub(crate) fn exact(values: &[[f64; 3]]) -> Reference {
    Reference {
        kind: ReferenceKind::Exact { method: "test".into(), bound: 0.0 },
        value: values.iter().map(|v| Rgb(*v)).collect(),
        std_err: vec![Rgb::ZERO; values.len()],
    }
}

/// `reps` repetitions of `n` integrals of value `mean + noise` (normal noise of `sd`), seeded.
pub(crate) fn normal_reps(seed: u64, n: usize, reps: usize, mean: f64, sd: f64) -> Vec<Vec<[f64; 3]>> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut normal = || {
        let (u, v): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    (0..reps).map(|_| (0..n).map(|_| [0; 3].map(|_| mean + sd * normal())).collect()).collect()
}

pub(crate) fn decision(rows: &[TestRow]) -> &TestRow {
    rows.iter().find(|t| t.test == "combined").expect("combined row")
}

#[test]
fn an_unbiased_cell_passes_behind_an_independent_gate_and_not_without_one() {
    let reference = exact(&[[1.0; 3]; 16]);
    let cell = cell_from(&normal_reps(1, 16, 256, 1.0, 0.05), &reference);
    let pilot = cell_from(&normal_reps(2, 16, 256, 1.0, 0.05), &reference);
    let gate = Gate::from_cell(&pilot, "pilot", 1.0);
    let with = unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), DEFAULT_TOLERANCE);
    let d = decision(&with);
    assert_eq!((d.verdict.as_str(), d.agrees), ("pass", true), "{d:?}");
    assert!(d.detectable_rel_bias < DEFAULT_TOLERANCE && d.detectable_rel_bias > 0.0);
    // The same cell with no independent gate cannot pass: it is inconclusive, never a pass.
    let without = unbiasedness(&cell, &reference, Bias::Unbiased, None, DEFAULT_TOLERANCE);
    let d = decision(&without);
    assert_eq!((d.verdict.as_str(), d.agrees), ("inconclusive", false), "{d:?}");
    assert!(d.reason.contains("no independent gate"));
}

#[test]
fn a_row_that_cannot_detect_the_tolerance_is_inconclusive_with_the_repetitions_it_needs() {
    let reference = exact(&[[1.0; 3]; 4]);
    let cell = cell_from(&normal_reps(3, 4, 64, 1.0, 0.5), &reference);
    let gate = Gate::from_cell(&cell_from(&normal_reps(4, 4, 64, 1.0, 0.5), &reference), "pilot", 1.0);
    let d = decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), 0.01)).clone();
    assert_eq!(d.verdict, "inconclusive", "{d:?}");
    assert!(d.detectable_rel_bias > 0.01);
    let needed = d.reps_needed.expect("repetitions that resolve 1%");
    // The detectable bias falls like 1/sqrt(R): about (d / 0.01)^2 x 64 repetitions.
    let expect = 64.0 * (d.detectable_rel_bias / 0.01).powi(2);
    assert!((needed / expect - 1.0).abs() < 0.3, "{needed} vs {expect}");
    // A looser tolerance that the row resolves makes it pass.
    let loose = decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), 0.5)).verdict.clone();
    assert_eq!(loose, "pass");
}

#[test]
fn a_shift_is_flagged_and_a_control_agrees() {
    let reference = exact(&[[1.0; 3]; 8]);
    let cell = cell_from(&normal_reps(5, 8, 64, 1.05, 0.05), &reference);
    let rows = unbiasedness(&cell, &reference, Bias::Biased, None, DEFAULT_TOLERANCE);
    let d = decision(&rows);
    assert_eq!((d.verdict.as_str(), d.agrees), ("biased", true), "{d:?}");
    assert!((d.rel_bias - 0.05).abs() < 5.0 * d.rel_bias_se, "{} ± {}", d.rel_bias, d.rel_bias_se);
    let unbiased = unbiasedness(&cell, &reference, Bias::Unbiased, None, DEFAULT_TOLERANCE);
    assert!(!decision(&unbiased).agrees);
}

/// A rare-hit estimator (10 with probability 0.05 per repetition and integral, else 0; mean 0.5):
/// the repetitions of the tested cell never saw a hit, so its own spread is zero and a t-test on it
/// alone would call it biased; a pilot that saw the hits gates the test out (too skewed at this
/// many repetitions) and widens the spread, so the verdict is inconclusive, not biased.
#[test]
fn a_pilot_that_saw_the_tail_keeps_a_cell_that_missed_it_from_being_flagged() {
    let reference = exact(&[[0.5; 3]]);
    let missed: Vec<Vec<[f64; 3]>> = (0..16).map(|_| vec![[0.0; 3]]).collect();
    let cell = cell_from(&missed, &reference);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
    let pilot_reps: Vec<Vec<[f64; 3]>> =
        (0..64).map(|_| vec![[if rng.gen::<f64>() < 0.05 { 10.0 } else { 0.0 }; 3]]).collect();
    assert!(pilot_reps.iter().any(|r| r[0][0] > 0.0), "the pilot saw the tail");
    let gate = Gate::from_cell(&cell_from(&pilot_reps, &reference), "pilot", 1.0);
    let d = decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), 0.01)).clone();
    assert_eq!(d.verdict, "inconclusive", "{d:?}");
    assert!(d.reps_needed.is_some());
    // Without the pilot the same cell is (wrongly) flagged: the gate is what protects it.
    let alone = decision(&unbiasedness(&cell, &reference, Bias::Unbiased, None, 0.01)).verdict.clone();
    assert_eq!(alone, "biased");
}

/// A zero-variance estimator: inside an exact reference's bound it passes its tests' p-values (no
/// evidence of bias), outside it is flagged; its rows round-trip through summary.json.
#[test]
fn zero_variance_cells_and_the_exact_bound() {
    let mut reference = exact(&[[0.5; 3]]);
    let same: Vec<Vec<[f64; 3]>> = (0..8).map(|_| vec![[0.5 + 1e-16; 3]]).collect();
    let cell = cell_from(&same, &reference);
    reference.kind = ReferenceKind::Exact { method: "closed form".into(), bound: 1e-13 };
    let gate = Gate::from_cell(&cell, "pilot", 1.0);
    let ok = unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), DEFAULT_TOLERANCE);
    assert_eq!(decision(&ok).verdict, "pass", "{:?}", decision(&ok));
    let off = cell_from(&(0..8).map(|_| vec![[3.0; 3]]).collect::<Vec<_>>(), &exact(&[[0.5; 3]]));
    let rows = unbiasedness(&off, &exact(&[[0.5; 3]]), Bias::Biased, None, DEFAULT_TOLERANCE);
    let d = decision(&rows);
    assert_eq!((d.verdict.as_str(), d.p_value), ("biased", 0.0), "{d:?}");
    let back: TestRow = serde_json::from_str(&serde_json::to_string(&rows[0]).unwrap()).unwrap();
    assert_eq!(back.verdict, rows[0].verdict);
}

#[test]
fn a_stored_reference_adds_its_variance_and_uses_welch() {
    let mut reference = exact(&[[1.0; 3]; 4]);
    reference.kind = ReferenceKind::Stored { command: "x".into(), samples: 64 };
    reference.std_err = vec![Rgb::splat(0.01); 4];
    let cell = cell_from(&normal_reps(11, 4, 128, 1.0, 0.05), &reference);
    let rows = unbiasedness(&cell, &reference, Bias::Unbiased, None, DEFAULT_TOLERANCE);
    assert_eq!(rows[0].test, "holm_welch");
    let exact_rows = unbiasedness(&cell, &exact(&[[1.0; 3]; 4]), Bias::Unbiased, None, DEFAULT_TOLERANCE);
    // The reference's own error widens what the pooled test can detect.
    assert!(rows[1].detectable_rel_bias > exact_rows[1].detectable_rel_bias);
}

#[test]
fn repetitions_for_a_tolerance() {
    assert_eq!(reps_for(0.02, 100, 1.0, 0.01), Some(400.0));
    assert_eq!(reps_for(0.005, 100, 1.0, 0.01), None, "already resolved");
    assert_eq!(reps_for(0.02, 100, 0.1, 0.01), None, "the reference alone is too noisy");
}

/// Without a gate the per-integral test does not choose its integrals by their own skewness: it
/// does not run, and the pooled test decides alone. With one, the decision is the weighted
/// Bonferroni of the two: the pooled p over `POOLED_SHARE`, the Holm p over the rest.
#[test]
fn the_holm_test_needs_a_gate_and_the_decision_splits_alpha_by_share() {
    let reference = exact(&[[1.0; 3]; 8]);
    // 1024 repetitions: normal estimates' sample skewness (sd 0.08) is under the per-integral
    // limit (0.98 at 24 tests); at 64 its noise (sd 0.3) exceeds the limit (0.26).
    let cell = cell_from(&normal_reps(11, 8, 1024, 1.0, 0.3), &reference);
    let ungated = unbiasedness(&cell, &reference, Bias::Unbiased, None, DEFAULT_TOLERANCE);
    assert!(ungated[0].p_value.is_nan() && ungated[0].untested == 24, "{:?}", ungated[0]);
    assert_eq!(ungated[2].p_value, ungated[1].p_value);
    let gate = Gate::from_cell(&cell_from(&normal_reps(12, 8, 1024, 1.0, 0.3), &reference), "pilot", 1.0);
    let rows = unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), DEFAULT_TOLERANCE);
    let want = (rows[0].p_value / (1.0 - super::POOLED_SHARE)).min(rows[1].p_value / super::POOLED_SHARE).min(1.0);
    assert_eq!(rows[2].p_value, want);
    assert!(!rows[0].p_value.is_nan() && rows[0].untested == 0, "{:?}", rows[0]);
}

/// A heavy-tailed image whose pilot is too skewed for a t-test in most integrals tests none of
/// them, not the few whose cell and pilot both happened to miss their rare values.
#[test]
fn no_integral_is_tested_below_the_pilots_median_skewness() {
    let reference = exact(&[[0.5; 3]; 16]);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(21);
    let mut rare = |n: usize| -> Vec<Vec<[f64; 3]>> {
        (0..n).map(|_| (0..16).map(|_| [if rng.gen::<f64>() < 0.02 { 25.0 } else { 0.0 }; 3]).collect()).collect()
    };
    let gate = Gate::from_cell(&cell_from(&rare(256), &reference), "pilot", 1.0);
    let rows = unbiasedness(&cell_from(&rare(256), &reference), &reference, Bias::Unbiased, Some(&gate), 0.01);
    assert!(rows[0].p_value.is_nan() && rows[0].untested == 48, "{:?}", rows[0]);
}

#[test]
fn a_pass_needs_the_tolerance_at_the_upper_bound_of_the_spread() {
    let reference = exact(&[[1.0; 3]; 16]);
    let cell = cell_from(&normal_reps(5, 16, 256, 1.0, 0.05), &reference);
    let gate = Gate::from_cell(&cell_from(&normal_reps(6, 16, 256, 1.0, 0.05), &reference), "pilot", 1.0);
    let d = decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), DEFAULT_TOLERANCE)).clone();
    // A tolerance just above the reported detectable bias is not enough: the spread is estimated
    // from 2 x 255 degrees of freedom, whose upper 95% bound is about 6% above the estimate.
    let just_above = d.detectable_rel_bias * 1.01;
    let at = decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), just_above)).verdict.clone();
    assert_eq!(at, "inconclusive");
    let with_margin = d.detectable_rel_bias * 1.1;
    let at = decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), with_margin)).verdict.clone();
    assert_eq!(at, "pass");
}

#[test]
fn the_detectable_bias_is_that_of_an_estimator_off_by_a_factor() {
    // A shift D detected at the unbiased spread is a factor (1 + b) with b = D / (1 - D), since
    // the spread scales with the estimate.
    assert!((super::multiplicative(0.2) - 0.25).abs() < 1e-15);
    assert!((super::multiplicative(0.01) - 0.01 / 0.99).abs() < 1e-15);
    assert_eq!(super::multiplicative(1.0), f64::INFINITY);
}

/// `n` integrals of value 1 with independent noise, the first `loud` of them `loud_sd`, the rest
/// `quiet_sd`, scaled by `scale`.
fn image_reps(
    seed: u64,
    n: usize,
    reps: usize,
    (loud, loud_sd, quiet_sd): (usize, f64, f64),
    scale: f64,
) -> Vec<Vec<[f64; 3]>> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut normal = || {
        let (u, v): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    (0..reps)
        .map(|_| {
            (0..n)
                .map(|i| {
                    let sd = if i < loud { loud_sd } else { quiet_sd };
                    [0; 3].map(|_| scale * (1.0 + sd * normal()))
                })
                .collect()
        })
        .collect()
}

/// On an image whose spread sits in a few loud integrals the pooled sum resolves little, while the
/// quiet integrals each resolve a small bias: the decision detects what its per-integral test
/// does when the integrals are independent, and an estimator off by that factor is flagged in
/// about 80% of seeds. Integrals that may share state count as one chance.
#[test]
fn the_decision_detects_what_the_stronger_of_its_tests_detects() {
    let (n, reps, shape) = (32, 256, (2, 10.0, 0.05));
    let reference = exact(&vec![[1.0; 3]; n]);
    let pilot = |seed| Gate::from_cell(&cell_from(&image_reps(seed, n, reps, shape, 1.0), &reference), "pilot", 1.0);
    let cell = cell_from(&image_reps(2, n, reps, shape, 1.0), &reference);
    let rows = unbiasedness(&cell, &reference, Bias::Unbiased, Some(&pilot(1).with_group(1)), 0.01);
    let (pooled, combined) = (&rows[1], decision(&rows));
    assert!(
        combined.detectable_rel_bias < 0.5 * pooled.detectable_rel_bias,
        "{} vs {}",
        combined.detectable_rel_bias,
        pooled.detectable_rel_bias
    );
    // One group (the default): only the strongest integral counts, still above the pooled sum here.
    let one = decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(&pilot(1)), 0.01)).detectable_rel_bias;
    assert!(
        one > 1.3 * combined.detectable_rel_bias && one < pooled.detectable_rel_bias,
        "{one} {} {}",
        combined.detectable_rel_bias,
        pooled.detectable_rel_bias
    );
    // Power at the reported detectable bias, measured over seeds (each with its own pilot).
    let b = combined.detectable_rel_bias;
    let seeds = 60;
    let flagged = (0..seeds)
        .filter(|&s| {
            let cell = cell_from(&image_reps(2000 + s, n, reps, shape, 1.0 + b), &reference);
            let gate = pilot(1000 + s).with_group(1);
            decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(&gate), 0.01)).verdict == "biased"
        })
        .count();
    // 80% nominal; each integral counts with its strongest channel only, so the measured power
    // lies at or above it (binomial sd over 60 seeds: 5%).
    assert!(flagged as f64 >= 0.65 * seeds as f64, "{flagged} of {seeds} flagged at b = {b}");
}

#[test]
fn a_gate_of_fewer_repetitions_counts_fewer_degrees_of_freedom() {
    let reference = exact(&[[1.0; 3]; 16]);
    let cell = cell_from(&normal_reps(21, 16, 1024, 1.0, 0.05), &reference);
    let same = Gate::from_cell(&cell_from(&normal_reps(22, 16, 1024, 1.0, 0.05), &reference), "pilot", 1.0);
    assert_eq!((same.reps, same.mixed_dof(1024), same.t_dof(1024)), (1024, 2046.0, 1023.0));
    // The same spread and skewness from 64 repetitions: an even mean of two variance estimates of
    // 1023 and 63 degrees of freedom has about 237, fewer than the cell's own.
    let small = Gate { reps: 64, ..same.clone() };
    let dof = small.mixed_dof(1024);
    assert!((dof - 4.0 / (1.0 / 1023.0 + 1.0 / 63.0)).abs() < 1e-9 && dof < 1023.0, "{dof}");
    assert_eq!(small.t_dof(1024), dof);
    assert_eq!(small.mixed_dof(64), 126.0);
    // A pass asks the tolerance at the upper bound of the spread: 2046 degrees of freedom put it
    // about 2.6% above the estimate, 237 about 7.7%, so a tolerance 5% above the detectable bias
    // passes behind the gate of as many repetitions and not behind the smaller one.
    let d = decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(&same), DEFAULT_TOLERANCE)).clone();
    let tolerance = d.detectable_rel_bias * 1.05;
    let verdict =
        |g: &Gate| decision(&unbiasedness(&cell, &reference, Bias::Unbiased, Some(g), tolerance)).verdict.clone();
    assert_eq!((verdict(&same), verdict(&small)), ("pass".to_string(), "inconclusive".to_string()));
}
