//! The post hook of `particle-sweep`: paper 002 Fig. 6-7 as a table and a plot. `fom.csv` holds,
//! per medium, model and sigma_samp, the fetches, samples (particles) per pixel, RMSE and
//! FoM = 1 / (MSE x fetches) at every budget; the plot shows FoM against sigma_samp at the largest
//! budget, one series per model, with delta tracking (which has no sigma_samp: it samples with the
//! majorant 1) as a flat reference series.

use crate::particle_sweep::{IDS, SIGMAS};
use mcbench::error::Result;
use mcbench::folder::OutputDir;
use mcbench::metrics::SummaryRow;
use mcbench::output::RunReport;
use mcbench::plan::Plan;
use mcbench::plot::{write_figure, Figure, Series};
use mcbench::runner::RunResults;
use std::path::{Path, PathBuf};

/// The sigma_samp an estimator name carries (`spm_adaptive[sigma_samp=0.8]` -> 0.8).
fn sigma_of(name: &str) -> Option<f64> {
    name.split("sigma_samp=").nth(1)?.trim_end_matches(']').split(',').next()?.parse().ok()
}

fn model_of(name: &str) -> &str {
    name.split('[').next().unwrap_or(name)
}

/// Writes `fom.csv` and one FoM-vs-sigma_samp plot per medium.
pub fn post(
    _: &Plan,
    _: &RunResults,
    report: &mut RunReport,
    results: &OutputDir,
    plots: Option<&Path>,
    _registry: &mcbench::registry::Registry,
) -> Result<Vec<PathBuf>> {
    let mut csv = String::from("testbed,model,sigma_samp,budget,fetches,samples,rmse,fom\n");
    for r in &report.rows {
        let sigma = sigma_of(&r.estimator).map_or(String::new(), |s| s.to_string());
        let fom = r.fom.map_or(String::new(), |f| format!("{f:e}"));
        csv.push_str(&format!(
            "{},{},{sigma},{},{},{},{:e},{fom}\n",
            r.testbed,
            model_of(&r.estimator),
            r.budget,
            r.fetches,
            r.samples,
            r.rmse
        ));
    }
    results.write("fom.csv", csv.as_bytes())?;
    let Some(dir) = plots else { return Ok(Vec::new()) };
    let budget = report.rows.iter().map(|r| r.budget).max().unwrap_or(0);
    let mut files = Vec::new();
    for tb in ["eq21-medium", "perlin-medium"] {
        let rows: Vec<&SummaryRow> = report.rows.iter().filter(|r| r.testbed == tb && r.budget == budget).collect();
        let mut series = Vec::new();
        for (style, model) in IDS.iter().enumerate() {
            let mut points: Vec<(f64, f64)> = if *model == "delta_tracking" {
                let f = rows.iter().find(|r| r.estimator == *model).and_then(|r| r.fom);
                f.map(|f| vec![(SIGMAS[0], f), (SIGMAS[SIGMAS.len() - 1], f)]).unwrap_or_default()
            } else {
                rows.iter()
                    .filter(|r| model_of(&r.estimator) == *model)
                    .filter_map(|r| Some((sigma_of(&r.estimator)?, r.fom?)))
                    .filter(|(s, f)| *s > 0.0 && *f > 0.0)
                    .collect()
            };
            points.sort_by(|a, b| a.0.total_cmp(&b.0));
            let label = if *model == "delta_tracking" { "delta_tracking (majorant 1, no sigma_samp)" } else { model };
            series.push(Series { label: label.to_string(), style, points });
        }
        let fig = Figure {
            title: format!("particle-sweep: paper 002 Fig. 6-7 — FoM vs σ_samp at {budget} fetches, {tb}"),
            x_desc: "sampling density σ_samp (max extinction = 1)".into(),
            y_desc: "FoM = 1 / (MSE × fetches)".into(),
            series,
        };
        files.extend(write_figure(dir, &format!("{tb}_fom_vs_sigma_samp"), &fig)?);
    }
    Ok(files)
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
