//! The per-cell analysis of `canonical-sweep`: for every (profile, target T, estimator, ratio) the
//! measured mean and variance of one estimate, its cost in fetches, variance x cost, the harness's
//! unbiasedness verdict (`analysis.rs`: Holm t-tests against the closed form), and the predicted
//! moments (paper 002 Eq. 16-20 and the higher moments of `mcbench_papers::tracking::moments`), from
//! which the error bar of the measured variance and the agreement verdict follow. Pairs that did
//! not run keep their reason.

use crate::canonical_sweep::{family_of, spec, terminating_min_ratio, FAMILIES, RATIOS};
use mcbench::analysis::claims::decisive_test;
use mcbench::output::RunReport;
use mcbench::plan::{Plan, Skipped};
use mcbench::run::runner::RunResults;
use mcbench_core::estimator::Bias;
use mcbench_core::estimator::EstimateMoments;
use mcbench_core::stats::detectable_shift;
use mcbench_core::task::Task;
use mcbench_papers::builtins;
use mcbench_papers::testbeds::canonical_1d::parse_variant;
use mcbench_papers::testbeds::canonical_profiles::Profile;

/// A measured variance is resolved when its predicted error bar (one standard deviation of the
/// sample variance, from the predicted fourth moment) is at most this fraction of the prediction.
pub const RESOLVED_REL_SD: f64 = 0.25;
/// A predicted relative variance below this is an exact (zero-variance) estimator up to rounding.
pub const ZERO_REL_VARIANCE: f64 = 1e-24;
/// Family-wise level of the variance-agreement checks (Bonferroni over the resolved cells).
pub const AGREEMENT_ALPHA: f64 = 1e-3;

/// How the measured variance of a cell compares with the prediction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Agreement {
    /// Within `z_crit` error bars (the interval shifted by the sample variance's skewness).
    Agrees,
    /// Outside.
    Disagrees,
    /// The error bar exceeds [`RESOLVED_REL_SD`] of the prediction, or the Cornish-Fisher shift
    /// of the acceptance interval exceeds half the critical value (heavy tails at this many
    /// repetitions): compared, but not judged.
    Unresolved,
    /// Predicted zero variance, and the measured one is rounding noise.
    ZeroVariance,
    /// No prediction (adaptive sigma_samp) or the cell did not run.
    NotPredicted,
}

impl Agreement {
    /// Name in `cells.csv`.
    pub fn name(self) -> &'static str {
        match self {
            Agreement::Agrees => "agrees",
            Agreement::Disagrees => "DISAGREES",
            Agreement::Unresolved => "unresolved",
            Agreement::ZeroVariance => "zero-variance",
            Agreement::NotPredicted => "-",
        }
    }
}

/// What was measured in a cell that ran.
#[derive(Clone, Debug)]
pub struct Measured {
    /// Repetitions.
    pub reps: usize,
    /// Rays (samples) per estimate.
    pub rays: f64,
    /// Fetches per estimate.
    pub fetches: f64,
    /// Mean of the estimates.
    pub mean: f64,
    /// Sample variance of one estimate.
    pub variance: f64,
    /// The harness's deciding unbiasedness test (`claims::decisive_test`).
    pub test: Option<Verdict>,
}

/// The deciding unbiasedness test of a cell: the harness's combined verdict (Holm per-integral
/// t-tests and the pooled t-test over repetitions, [`mcbench::analysis::unbiasedness`]).
#[derive(Clone, Debug)]
pub struct Verdict {
    /// `combined`.
    pub test: String,
    /// Its p-value (Bonferroni over the tests that ran).
    pub p: f64,
    /// `pass`, `inconclusive` or `biased`.
    pub verdict: String,
    /// The relative bias the test detects with 80% power.
    pub detectable: f64,
}

/// One cell of the sweep.
#[derive(Clone, Debug)]
pub struct CellRow {
    /// Profile.
    pub profile: Profile,
    /// Target transmittance (the reference of the integral analysed).
    pub target: f64,
    /// Exact reference of the analysed integral.
    pub reference: f64,
    /// Index into [`FAMILIES`].
    pub family: usize,
    /// sigma_samp / max sigma_t (None: the estimator's own density).
    pub ratio: Option<f64>,
    /// Estimator name in result files.
    pub estimator: String,
    /// What the paper claims of its expectation.
    pub claim: Bias,
    /// Measurements (None: did not run).
    pub measured: Option<Measured>,
    /// Predicted moments of one estimate.
    pub predicted: Option<EstimateMoments>,
    /// Why it did not run.
    pub skipped: Option<String>,
}

impl CellRow {
    /// Variance of one estimate x fetches per estimate.
    pub fn var_cost(&self) -> Option<f64> {
        self.measured.as_ref().map(|m| m.variance * m.fetches)
    }
    /// Variance x cost relative to `T^2` (comparable across targets).
    pub fn rel_var_cost(&self) -> Option<f64> {
        self.var_cost().map(|v| v / (self.reference * self.reference))
    }
    /// MSE x cost relative to `T^2` (includes ray marching's bias).
    pub fn rel_mse_cost(&self) -> Option<f64> {
        let m = self.measured.as_ref()?;
        let d = m.mean - self.reference;
        Some((d * d + m.variance * (m.reps as f64 - 1.0) / m.reps as f64) * m.fetches / self.reference.powi(2))
    }
    /// (measured - predicted) / error bar of the measured variance.
    pub fn z(&self) -> Option<f64> {
        let (m, p) = (self.measured.as_ref()?, self.predicted.as_ref()?);
        let sd = p.sample_variance_sd(m.reps as f64);
        (sd > 0.0).then(|| (m.variance - p.variance()) / sd)
    }
    /// The predicted relative error bar of the measured variance.
    pub fn rel_sd(&self) -> Option<f64> {
        let (m, p) = (self.measured.as_ref()?, self.predicted.as_ref()?);
        Some(p.sample_variance_sd(m.reps as f64) / p.variance())
    }
    /// The agreement verdict at critical value `z_crit`.
    pub fn agreement(&self, z_crit: f64) -> Agreement {
        let (Some(m), Some(p)) = (self.measured.as_ref(), self.predicted.as_ref()) else {
            return Agreement::NotPredicted;
        };
        if p.rel_variance < ZERO_REL_VARIANCE {
            return if m.variance < ZERO_REL_VARIANCE * p.mean * p.mean {
                Agreement::ZeroVariance
            } else {
                Agreement::Disagrees
            };
        }
        // The sample variance of skewed estimates is itself skewed (a chi-square for normal
        // ones), so the acceptance interval is the Cornish-Fisher one: both ends shift by
        // g (z^2 - 1) / 6 for the predicted skewness g of the sample variance; where that shift
        // exceeds half the critical value the expansion is not trusted and the cell is unresolved.
        let shift = if z_crit.is_finite() {
            p.sample_variance_skewness(m.reps as f64) * (z_crit * z_crit - 1.0) / 6.0
        } else {
            0.0
        };
        match (self.rel_sd(), self.z()) {
            (Some(rel), _) if rel > RESOLVED_REL_SD => Agreement::Unresolved,
            _ if shift.is_nan() || shift.abs() > 0.5 * z_crit => Agreement::Unresolved,
            (_, Some(z)) if (z - shift).abs() <= z_crit => Agreement::Agrees,
            _ => Agreement::Disagrees,
        }
    }
    /// The deciding test's verdict (`pass`, `biased`, `untested`), when the cell ran.
    pub fn verdict(&self) -> Option<&str> {
        self.measured.as_ref().and_then(|m| m.test.as_ref()).map(|t| t.verdict.as_str())
    }
}

/// The two-sided critical value of the agreement checks over `m` resolved cells (Bonferroni).
pub fn z_crit(m: usize) -> f64 {
    // detectable_shift(1, alpha, 0.5) = z_{1 - alpha/2} + z_{0.5} = z_{1 - alpha/2}.
    detectable_shift(1.0, AGREEMENT_ALPHA / m.max(1) as f64, 0.5)
}

/// The terminating model at ratios where `r = 1/ratio > 2/(a+1)`, when the sweep runs it at all:
/// refused before the run by the estimator itself (`validate`); listed as skipped with its own
/// reason.
pub fn refused_terminating(plan: &Plan) -> Vec<Skipped> {
    let mut out = Vec::new();
    let Ok(entry) = builtins::estimator("single_particle_terminating") else { return out };
    if !plan.estimators.iter().any(|e| e.spec.id == entry.id) {
        return out;
    }
    let family = FAMILIES.iter().find(|f| f.id == entry.id);
    for b in plan.beds.iter().filter(|b| b.spec.id == "canonical-1d") {
        for r in RATIOS.into_iter().filter(|&r| r < terminating_min_ratio()) {
            let Some(spec) = family.map(|f| spec(f, Some(r))) else { continue };
            let refusal = (entry.build)(&spec.params).and_then(|e| e.validate(b.bed.as_ref()));
            if let Err(e) = refusal {
                out.push(Skipped {
                    testbed: b.spec.id.clone(),
                    variant: b.variant.clone(),
                    estimator: spec.name(),
                    reason: e.to_string(),
                });
            }
        }
    }
    out
}

/// Every cell of the run (and every skipped pair) on `canonical-1d`, analysed at the last integral
/// (`s = 1`, the target transmittance) and the last budget.
pub fn cell_rows(plan: &Plan, run: &RunResults, report: &RunReport) -> Vec<CellRow> {
    let last = plan.sweep.budgets.last().copied();
    let mut rows = Vec::new();
    for (bi, ei, cell) in &run.cells {
        let (b, e) = (&plan.beds[*bi], &plan.estimators[*ei]);
        let (Some((profile, target)), Some((family, ratio))) = (parse_variant(&b.variant), family_of(&e.spec)) else {
            continue;
        };
        if b.spec.id != "canonical-1d" || Some(cell.key.budget) != last {
            continue;
        }
        let i = cell.moments.len() - 1;
        let mc = &cell.moments[i][0];
        let per = |x: u64| x as f64 / cell.estimates.max(1) as f64;
        let rays = per(cell.costs.samples);
        let test = decisive_test(&report.tests, &b.variant, &e.name, "").map(|t| Verdict {
            test: t.test.clone(),
            p: t.p_value,
            verdict: t.verdict.clone(),
            detectable: t.detectable_rel_bias,
        });
        let task = Task::new(b.bed.as_ref(), i, cell.key.budget);
        rows.push(CellRow {
            profile,
            target,
            reference: b.bed.reference().value[i][0],
            family,
            ratio,
            estimator: e.name.clone(),
            claim: e.bias(),
            measured: Some(Measured {
                reps: cell.key.reps,
                rays,
                fetches: per(cell.costs.fetches),
                mean: mc.mean(),
                variance: mc.variance(),
                test,
            }),
            predicted: e.estimator.sample_moments(&task).map(|m| m.mean_of(rays)),
            skipped: None,
        });
    }
    // Skipped pairs (the plan's, plus the terminating refusals the post hook adds to the report).
    for s in &report.skipped {
        let mut specs =
            FAMILIES.iter().flat_map(|f| RATIOS.map(Some).into_iter().chain([None]).map(move |r| spec(f, r)));
        let Some(spec) = specs.find(|c| c.name() == s.estimator) else { continue };
        let (Some((profile, target)), Some((family, ratio))) = (parse_variant(&s.variant), family_of(&spec)) else {
            continue;
        };
        rows.push(CellRow {
            profile,
            target,
            reference: target,
            family,
            ratio,
            estimator: s.estimator.clone(),
            claim: builtins::estimator(&spec.id).map_or(Bias::Unbiased, |e| e.bias),
            measured: None,
            predicted: None,
            skipped: Some(s.reason.clone()),
        });
    }
    rows
}
