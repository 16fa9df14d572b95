//! The post hook of `particle-sweep`: paper 002 Fig. 6-7 as a table and a plot. `fom.csv` holds,
//! per medium, model and sigma_samp, the fetches, samples (particles) per pixel, RMSE and
//! FoM = 1 / (MSE x fetches) at every budget; the plot shows FoM against sigma_samp at the largest
//! budget, one series per model, with delta tracking (which has no sigma_samp: it samples with the
//! majorant 1) as a flat reference series.

use crate::particle_sweep::{IDS, SIGMAS};
use mcbench::analysis::metrics::SummaryRow;
use mcbench::error::Result;
use mcbench::output::plot::{write_panels, Figure, Line, Panels, Series};
use mcbench::output::query::Query;
use mcbench::registry::PostContext;
use serde::Serialize;
use std::path::PathBuf;

/// One row of `fom.csv`: one cell of the summary.
#[derive(Serialize)]
struct FomRow<'a> {
    /// The test bed (medium).
    testbed: &'a str,
    /// The estimator id without its parameters.
    model: &'a str,
    /// The estimator's sigma_samp (empty for delta tracking, which has none).
    sigma_samp: Option<f64>,
    /// The budget (fetches per estimate).
    budget: u64,
    /// Mean fetches per estimate.
    fetches: f64,
    /// Mean samples (particles) per estimate.
    samples: f64,
    /// Root mean squared error against the reference.
    rmse: f64,
    /// Figure of merit 1 / (MSE x fetches) (empty where undefined).
    fom: Option<f64>,
}

/// The sigma_samp an estimator name carries (`spm_adaptive[sigma_samp=0.8]` -> 0.8).
fn sigma_of(name: &str) -> Option<f64> {
    name.split("sigma_samp=").nth(1)?.trim_end_matches(']').split(',').next()?.parse().ok()
}

fn model_of(name: &str) -> &str {
    name.split('[').next().unwrap_or(name)
}

/// Writes `fom.csv` and one FoM-vs-sigma_samp plot per medium.
pub fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    let PostContext { report, out: results, plots, registry, .. } = cx;
    let names = registry.display_names();
    let rows: Vec<FomRow<'_>> = report
        .rows
        .iter()
        .map(|r| FomRow {
            testbed: &r.testbed,
            model: model_of(&r.estimator),
            sigma_samp: sigma_of(&r.estimator),
            budget: r.budget,
            fetches: r.fetches,
            samples: r.samples,
            rmse: r.rmse,
            fom: r.fom,
        })
        .collect();
    results.write_csv("fom.csv", &rows)?;
    let Some(dir) = plots else { return Ok(Vec::new()) };
    let budget = report.query().largest_budget().unwrap_or(0);
    let mut panels = Vec::new();
    for tb in ["eq21-medium", "perlin-medium"] {
        let rows: Vec<&SummaryRow> = report.query().testbed(tb).at(budget).iter().collect();
        let mut series = Vec::new();
        for (style, model) in IDS.iter().enumerate() {
            let name = names.named_estimator(model).unwrap_or_else(|| model.to_string());
            if *model == "delta_tracking" {
                let f = Query::new(&rows).estimator(model).first().and_then(|r| r.fom);
                let points = f.map(|f| vec![(SIGMAS[0], f), (SIGMAS[SIGMAS.len() - 1], f)]).unwrap_or_default();
                let label = format!("{name} (majorant 1, no σ_samp)");
                series.push(Series::new(label, style, points).with_line(Line::Dashed).without_markers());
                continue;
            }
            let mut points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| model_of(&r.estimator) == *model)
                .filter_map(|r| Some((sigma_of(&r.estimator)?, r.fom?)))
                .filter(|(s, f)| *s > 0.0 && *f > 0.0)
                .collect();
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            series.push(Series::new(name, style, points));
        }
        let bed = names.named_testbed(tb, "multiple").unwrap_or_else(|| tb.to_string());
        panels.push(Figure::new(
            bed,
            "sampling density σ_samp (max extinction = 1)",
            "FoM = 1 / (MSE × fetches)",
            series,
        ));
    }
    let fig = Panels {
        title: format!("particle-sweep: paper 002 Fig. 6-7, FoM vs σ_samp at {budget} fetches"),
        panels,
        keys: Vec::new(),
        note: String::new(),
    };
    write_panels(dir, "fom_vs_sigma_samp", &fig)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse() {
        assert_eq!(sigma_of("spm_adaptive[sigma_samp=0.8]"), Some(0.8));
        assert_eq!(sigma_of("double_particle[control=1,sigma_samp=0.4]"), Some(0.4));
        assert_eq!(sigma_of("delta_tracking"), None);
        assert_eq!(model_of("spm_adaptive[sigma_samp=0.8]"), "spm_adaptive");
    }
}
