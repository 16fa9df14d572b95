//! The post hook of `canonical-sweep`: the per-cell table `cells.csv` (mean, variance, cost,
//! variance x cost, predicted variance and its error bar, agreement, unbiasedness verdict, or why
//! the pair did not run), the tables of which estimator wins where (`canonical_winners`), the
//! claims (`canonical_sweep_claims`) and the heat maps (`canonical_sweep_plots`).

use crate::canonical_cells::{cell_rows, refused_terminating, z_crit, Agreement, CellRow};
use crate::canonical_sweep::FAMILIES;
use mcbench::error::Result;
use mcbench::registry::PostContext;
use mcbench_core::budget::BudgetKind;
use mcbench_papers::testbeds::canonical_profiles::Profile;
use serde::Serialize;
use std::path::PathBuf;

/// The finished cells with the sweep's critical value for the variance checks.
pub struct Analysis {
    /// Every cell (run or skipped).
    pub rows: Vec<CellRow>,
    /// Two-sided critical value of the agreement checks (Bonferroni over the resolved cells).
    pub z_crit: f64,
    /// Equal-cost mode (a fetch budget) rather than fixed-sample mode.
    pub equal_cost: bool,
}

impl Analysis {
    /// Builds the analysis: a first pass counts the resolved cells, which sets `z_crit`.
    pub fn new(rows: Vec<CellRow>, equal_cost: bool) -> Analysis {
        let resolved = rows
            .iter()
            .filter(|r| matches!(r.agreement(f64::INFINITY), Agreement::Agrees | Agreement::Disagrees))
            .count();
        Analysis { z_crit: z_crit(resolved), rows, equal_cost }
    }
    /// The cell of a family at a profile, target and ratio.
    pub fn find(&self, p: Profile, t: f64, family: usize, ratio: Option<f64>) -> Option<&CellRow> {
        self.rows.iter().find(|r| r.profile == p && r.target == t && r.family == family && r.ratio == ratio)
    }
}

/// The short name of a cell's estimator: family label, `@ratio` for swept families.
pub fn short(r: &CellRow) -> String {
    match r.ratio {
        Some(x) => format!("{}@{x}", FAMILIES[r.family].short),
        None => FAMILIES[r.family].short.to_string(),
    }
}

/// One row of `cells.csv`: one cell of the sweep (run or skipped; the measured and predicted
/// columns are empty where there is nothing to report).
#[derive(Serialize)]
struct CellsRow<'a> {
    /// The extinction profile.
    profile: &'static str,
    /// The target transmittance T.
    target: f64,
    /// The estimator family's key.
    family: &'static str,
    /// sigma_samp / max sigma_t, or `own` for a family with its own sampling density.
    ratio: String,
    /// The estimator name in result files.
    estimator: &'a str,
    /// What the paper claims of its expectation.
    claim: &'static str,
    /// Repetitions.
    reps: Option<usize>,
    /// Rays (samples) per estimate.
    rays: Option<f64>,
    /// Fetches per estimate.
    fetches: Option<f64>,
    /// The exact reference of the analysed integral.
    reference: f64,
    /// Mean of the estimates.
    mean: Option<f64>,
    /// Sample variance of one estimate.
    variance: Option<f64>,
    /// Variance x fetches per estimate.
    var_cost: Option<f64>,
    /// Variance x fetches relative to T^2.
    rel_var_cost: Option<f64>,
    /// MSE x fetches relative to T^2 (includes bias).
    rel_mse_cost: Option<f64>,
    /// Predicted mean of one estimate.
    predicted_mean: Option<f64>,
    /// Predicted variance of one estimate.
    predicted_variance: Option<f64>,
    /// Predicted standard deviation of the measured (sample) variance.
    variance_sd: Option<f64>,
    /// (measured - predicted variance) / variance_sd.
    z: Option<f64>,
    /// How the measured variance compares with the prediction.
    agreement: &'static str,
    /// The deciding unbiasedness test (`holm_t` or `pooled_z`).
    test: Option<&'a str>,
    /// Its p-value.
    p_value: Option<f64>,
    /// Its verdict (`pass`, `biased` or `untested`).
    verdict: Option<&'a str>,
    /// The relative bias the test detects with 80% power.
    detectable_rel_bias: Option<f64>,
    /// Why the cell did not run.
    skipped: Option<&'a str>,
}

fn cells_rows(a: &Analysis) -> Vec<CellsRow<'_>> {
    a.rows
        .iter()
        .map(|r| {
            let m = r.measured.as_ref();
            let test = m.and_then(|m| m.test.as_ref());
            CellsRow {
                profile: r.profile.name(),
                target: r.target,
                family: FAMILIES[r.family].key,
                ratio: r.ratio.map_or_else(|| "own".into(), |x| x.to_string()),
                estimator: &r.estimator,
                claim: r.claim.name(),
                reps: m.map(|m| m.reps),
                rays: m.map(|m| m.rays),
                fetches: m.map(|m| m.fetches),
                reference: r.reference,
                mean: m.map(|m| m.mean),
                variance: m.map(|m| m.variance),
                var_cost: r.var_cost(),
                rel_var_cost: r.rel_var_cost(),
                rel_mse_cost: r.rel_mse_cost(),
                predicted_mean: r.predicted.map(|p| p.mean),
                predicted_variance: r.predicted.map(|p| p.variance()),
                variance_sd: r.predicted.zip(m).map(|(p, m)| p.sample_variance_sd(m.reps as f64)),
                z: r.z(),
                agreement: r.agreement(a.z_crit).name(),
                test: test.map(|t| t.test.as_str()),
                p_value: test.map(|t| t.p),
                verdict: test.map(|t| t.verdict.as_str()),
                detectable_rel_bias: test.map(|t| t.detectable),
                skipped: r.skipped.as_deref(),
            }
        })
        .collect()
}

/// The experiment's post-run analysis (see the module doc).
pub fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    let PostContext { plan, results: run, report, out: results, plots, .. } = cx;
    report.skipped.extend(refused_terminating(plan));
    let equal_cost = plan.sweep.budgets.iter().any(|b| b.kind == BudgetKind::Fetches);
    let analysis = Analysis::new(cell_rows(plan, run, report), equal_cost);
    results.write_csv("cells.csv", &cells_rows(&analysis))?;
    let (winners, md) = crate::canonical_winners::tables(&analysis);
    results.write_csv("winners.csv", &winners)?;
    results.write("winners.md", md.as_bytes())?;
    report.paper.extend(crate::canonical_sweep_claims::claims(&analysis));
    match plots {
        Some(dir) => crate::canonical_sweep_plots::heat_maps(&analysis, dir),
        None => Ok(Vec::new()),
    }
}
