//! The pooled unbiasedness test over repetitions, for test beds whose whole image is one sequence
//! sharing adaptive state (`gradient-box`: one octree per image; `checker-image`: one image-plane
//! sample allocation). Integrals of one repetition are correlated there, so the harness's
//! `pooled_z` (independent integrals) is anti-conservative and the worst-case `pooled_z_seq` has
//! little power. Repetitions are independent, though: the summed deviation of one repetition,
//! `D_r = sum over integrals and channels of (estimate - reference)`, has a sample variance over
//! the repetitions that includes every correlation inside an image, so
//! `z = mean(D) / sqrt(var(D) / R + var(reference))` is valid whatever the estimator shares.
//!
//! The cells keep per-integral moments only, so the estimates are recomputed here through the
//! runner's own [`sequence_estimates`] (same streams, same tasks: the values are those of the
//! cell) to get the per-repetition sums; this costs one more pass over these small parts.

use crate::analysis::{TestRow, POWER, UNBIASEDNESS_ALPHA};
use crate::error::{HarnessError, Result};
use crate::plan::Plan;
use crate::runner::sequence_estimates;
use estimators::budget::BudgetKind;
use estimators::stats::{detectable_shift, z_test, Moments};
use estimators::testbed::{Reference, ReferenceKind};
use rayon::prelude::*;

/// The per-repetition summed deviations of one (test bed, estimator) pair of a one-budget sample
/// sweep, in repetition order; `None` for other budget kinds (a fetch budget's pilot is not redone).
pub fn deviations(plan: &Plan, bi: usize, ei: usize, threads: usize) -> Result<Option<Vec<f64>>> {
    let budget = plan.sweep.budgets[0];
    if budget.kind != BudgetKind::Samples {
        return Ok(None);
    }
    let bed = plan.beds[bi].bed.as_ref();
    let frames = bed.sequence_length().max(1);
    let reference = &bed.reference().value;
    let one_rep = |rep: usize| -> Result<f64> {
        let mut d = 0.0;
        for first in (0..bed.integrals()).step_by(frames) {
            let values = sequence_estimates(plan, bi, ei, budget, rep as u64, first)?;
            for (k, v) in values.iter().enumerate() {
                d += (0..3).map(|c| v[c] - reference[first + k][c]).sum::<f64>();
            }
        }
        Ok(d)
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|err| HarnessError::write("thread pool", err))?;
    let d: Result<Vec<f64>> = pool.install(|| (0..plan.sweep.reps).into_par_iter().map(one_rep).collect());
    d.map(Some)
}

/// The test from per-repetition deviations `d` against the reference `r`: (z, p, detectable
/// relative bias) of `pooled_z_rep`.
/// An exact reference is known to within its bound, so the summed deviation is measured from the
/// interval `[-B, B]`, `B` the bound summed over integrals and channels (the harness's composite
/// null); a stored one adds its variance (integrals independent, channels fully correlated).
pub fn test_from_deviations(d: &[f64], r: &Reference) -> Option<(f64, f64, f64)> {
    let mut m = Moments::default();
    d.iter().for_each(|&x| m.push(x));
    let n = (r.value.len() * 3) as f64;
    let (dev, ref_var) = match &r.kind {
        ReferenceKind::Exact { bound, .. } => {
            let total = bound.max(0.0) * n;
            (m.mean() - m.mean().clamp(-total, total), 0.0)
        }
        ReferenceKind::Stored { .. } => (m.mean(), r.std_err.iter().map(|s| (s[0] + s[1] + s[2]).powi(2)).sum()),
    };
    let ref_sum: f64 = r.value.iter().flat_map(|v| v.0).map(f64::abs).sum();
    let var = m.std_err() * m.std_err() + ref_var;
    if !(var > 0.0 && ref_sum > 0.0) {
        return None;
    }
    let z = z_test(dev, var.sqrt(), 0.0);
    Some((z.statistic, z.p_value, detectable_shift(var.sqrt(), UNBIASEDNESS_ALPHA, POWER) / ref_sum))
}

/// `pooled_z_rep` for a pair whose test bed is one whole-image sequence (`None` otherwise), built on
/// the cell's `pooled_z` row (`template`) so that names and the claim carry over.
pub fn pooled_over_repetitions(
    plan: &Plan,
    bi: usize,
    ei: usize,
    threads: usize,
    template: &TestRow,
) -> Result<Option<TestRow>> {
    let bed = plan.beds[bi].bed.as_ref();
    if bed.integrals() < 2 || bed.sequence_length() != bed.integrals() {
        return Ok(None);
    }
    let Some(d) = deviations(plan, bi, ei, threads)? else { return Ok(None) };
    Ok(test_from_deviations(&d, bed.reference()).map(|(statistic, p, detectable)| {
        let mut row = template.clone();
        row.test = "pooled_z_rep".into();
        row.statistic = statistic;
        row.p_value = p;
        row.verdict = if p < UNBIASEDNESS_ALPHA { "biased" } else { "pass" }.into();
        row.detectable_rel_bias = detectable;
        row
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{EstimatorSpec, Mode, Sweep, TestBedSpec};
    use crate::runner::{run, RunOptions, Silent};
    use estimators::budget::Budget;
    use estimators::math::Rgb;
    use estimators::params::Params;

    /// The recomputed per-repetition deviations are those of the runner's cell (same streams), on a
    /// whole-image sequence (`gradient-box`, one octree per image).
    #[test]
    fn recomputed_deviations_match_the_cell() {
        let sweep = Sweep {
            experiment: "reps-test".into(),
            testbeds: vec![TestBedSpec {
                id: "gradient-box".into(),
                variant: Some("albedo-0.8".into()),
                params: Params::new(),
            }],
            estimators: vec![EstimatorSpec::new("is1_cv2")],
            budgets: vec![Budget::samples(2).unwrap()],
            reps: 3,
            seed: 5,
            mode: Mode::Quick,
            baseline: None,
            claims: Vec::new(),
        };
        let plan = Plan::prepare(
            sweep,
            &crate::registry::Registry::builtin().with_references(crate::references::ReferenceDir::new(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../results/references"
            ))),
        )
        .unwrap();
        let cells = run(&plan, &RunOptions { threads: Some(2), cell_dir: None, observer: &Silent }).unwrap().cells;
        let d = deviations(&plan, 0, 0, 1).unwrap().unwrap();
        let r = plan.beds[0].bed.reference();
        let from_cell: f64 = cells[0]
            .2
            .moments
            .iter()
            .enumerate()
            .flat_map(|(i, m)| (0..3).map(move |c| (i, c, m[c].mean())))
            .map(|(i, c, mean)| mean - r.value[i][c])
            .sum();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        assert!((mean - from_cell).abs() <= 1e-9 * from_cell.abs().max(1.0), "{mean} vs {from_cell}");
    }

    /// Deviations that move together across integrals within a repetition: the test uses their
    /// spread over repetitions, so a common shift of every repetition is no evidence of bias,
    /// while a consistent offset is.
    #[test]
    fn the_repetition_spread_sets_the_standard_error() {
        let r = Reference {
            kind: ReferenceKind::Exact { method: "t".into(), bound: 0.0 },
            value: vec![Rgb::splat(1.0); 100],
            std_err: vec![Rgb::ZERO; 100],
        };
        // Each repetition shifts all 300 integral-channels by +-0.1 together: D_r = +-30.
        let centred: Vec<f64> = (0..64).map(|k| if k % 2 == 0 { 30.0 } else { -30.0 }).collect();
        let (_, p, detectable) = test_from_deviations(&centred, &r).unwrap();
        assert!(p > 0.5, "{p}");
        // se = 30 / 8 = 3.75 over a reference sum of 300: about 1.25% x (z_alpha + z_power).
        assert!(detectable > 0.04 && detectable < 0.06, "{detectable}");
        let offset: Vec<f64> = centred.iter().map(|d| d + 30.0).collect();
        assert!(test_from_deviations(&offset, &r).unwrap().1 < 1e-6);
        assert!(test_from_deviations(&[0.0; 8], &r).is_none());
    }
}
