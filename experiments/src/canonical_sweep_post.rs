//! The post hook of `canonical-sweep`: the per-cell table `cells.csv` (mean, variance, cost,
//! variance x cost, predicted variance and its error bar, agreement, unbiasedness verdict, or why
//! the pair did not run), the tables of which estimator wins where (`canonical_winners`), the
//! claims (`canonical_sweep_claims`) and the heat maps (`canonical_sweep_plots`).

use crate::canonical_cells::{cell_rows, refused_terminating, z_crit, Agreement, CellRow};
use crate::canonical_sweep::FAMILIES;
use estimators::budget::BudgetKind;
use estimators::testbeds::canonical_profiles::Profile;
use mcbench::error::Result;
use mcbench::folder::OutputDir;
use mcbench::output::RunReport;
use mcbench::plan::Plan;
use mcbench::runner::RunResults;
use std::path::{Path, PathBuf};

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

fn csv_text(a: &Analysis) -> String {
    let mut out = String::from(
        "profile,target,family,ratio,estimator,claim,reps,rays,fetches,reference,mean,variance,var_cost,rel_var_cost,rel_mse_cost,predicted_mean,predicted_variance,variance_sd,z,agreement,test,p_value,verdict,detectable_rel_bias,skipped\n",
    );
    let opt = |x: Option<f64>| x.map(|v| format!("{v:e}")).unwrap_or_default();
    for r in &a.rows {
        let m = r.measured.as_ref();
        let test = m.and_then(|m| m.test.as_ref());
        let fields = [
            r.profile.name().to_string(),
            r.target.to_string(),
            FAMILIES[r.family].key.to_string(),
            r.ratio.map(|x| x.to_string()).unwrap_or_else(|| "own".into()),
            format!("\"{}\"", r.estimator),
            r.claim.name().to_string(),
            m.map(|m| m.reps.to_string()).unwrap_or_default(),
            opt(m.map(|m| m.rays)),
            opt(m.map(|m| m.fetches)),
            format!("{:e}", r.reference),
            opt(m.map(|m| m.mean)),
            opt(m.map(|m| m.variance)),
            opt(r.var_cost()),
            opt(r.rel_var_cost()),
            opt(r.rel_mse_cost()),
            opt(r.predicted.map(|p| p.mean)),
            opt(r.predicted.map(|p| p.variance())),
            opt(r.predicted.zip(m).map(|(p, m)| p.sample_variance_sd(m.reps as f64))),
            opt(r.z()),
            r.agreement(a.z_crit).name().to_string(),
            test.map(|t| t.test.clone()).unwrap_or_default(),
            opt(test.map(|t| t.p)),
            test.map(|t| t.verdict.clone()).unwrap_or_default(),
            opt(test.map(|t| t.detectable)),
            r.skipped.as_ref().map(|s| format!("\"{}\"", s.replace('"', "'"))).unwrap_or_default(),
        ];
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// The experiment's post-run analysis (see the module doc).
pub fn post(
    plan: &Plan,
    run: &RunResults,
    report: &mut RunReport,
    results: &OutputDir,
    plots: Option<&Path>,
    _registry: &mcbench::registry::Registry,
) -> Result<Vec<PathBuf>> {
    report.skipped.extend(refused_terminating(plan));
    let equal_cost = plan.sweep.budgets.iter().any(|b| b.kind == BudgetKind::Fetches);
    let analysis = Analysis::new(cell_rows(plan, run, report), equal_cost);
    results.write("cells.csv", csv_text(&analysis).as_bytes())?;
    let (csv, md) = crate::canonical_winners::tables(&analysis);
    results.write("winners.csv", csv.as_bytes())?;
    results.write("winners.md", md.as_bytes())?;
    report.paper.extend(crate::canonical_sweep_claims::claims(&analysis));
    match plots {
        Some(dir) => crate::canonical_sweep_plots::heat_maps(&analysis, dir),
        None => Ok(Vec::new()),
    }
}
