//! The figure of one (test bed, variant) of a run: (a) RMSE against the budget with its bootstrap
//! band and a slope -1/2 guide, (b) efficiency against the budget (1/(variance x CPU s) solid, the
//! MSE-based 1/(MSE x CPU s) dashed in the same colour, apart where the estimator is biased), (c) RMSE against CPU seconds
//! per estimate and, with speed-ups, (d) the speed-up against the cost of a ray. One series per
//! estimator in the same colour in every panel, its legend entry naming it and its fitted
//! convergence slope.

use super::figure::{Figure, Guide, Key, Line, Panels, Series};
use super::names::DisplayNames;
use super::{budget_axis_label, label_of, ray_cost};
use crate::analysis::metrics::SummaryRow;
use crate::output::query::Query;
use crate::output::RunReport;

/// The note under a legend with bands.
pub const BAND_NOTE: &str =
    "Shaded: 90% interval of the RMSE (bootstrap over the cell's repetition blocks; summary.csv rmse_lo, rmse_hi).";

fn positive(x: f64, y: f64) -> Option<(f64, f64)> {
    (x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite()).then_some((x, y))
}

/// The short unit of a budget kind, for titles (`spp`, `fetches`, `µs`).
pub fn budget_unit(kind: &str) -> &str {
    match kind {
        "samples" => "spp",
        "fetches" => "fetches",
        "micros" => "µs",
        other => other,
    }
}

/// The legend text of estimator `name` on a (test bed, variant): its display name and, when
/// fitted, its convergence slope with the 95% interval (and the slope over the right end when
/// that is a fit over fewer budgets).
pub fn legend(report: &RunReport, names: &DisplayNames, testbed: &str, variant: &str, name: &str) -> String {
    let mut label = names.estimator(name, Some(label_of(report, name)));
    let fit = Query::new(&report.fits).testbed(testbed).variant(variant).estimator(name).first();
    if fit.is_some_and(|f| f.outcome == crate::analysis::SlopeOutcome::Exact) {
        label.push_str(": exact at every budget");
    }
    if let Some(f) = fit.filter(|f| f.slope.is_finite()) {
        label.push_str(&format!(": slope {:.2} [{:.2}, {:.2}]", f.slope, f.slope_ci_low, f.slope_ci_high));
        if f.slope_right.is_finite() && f.budgets_right.len() < f.budgets.len() {
            label.push_str(&format!(
                ", right end {:.2} [{:.2}, {:.2}]",
                f.slope_right, f.slope_right_ci_low, f.slope_right_ci_high
            ));
        }
    }
    label
}

/// The slope -1/2 guide over the budgets of `series`: above every series at the smallest budget
/// (twice the largest RMSE there), so it runs beside the data instead of over it.
fn half_slope(series: &[Series]) -> Option<Guide> {
    let pts = series.iter().flat_map(|s| s.points.iter());
    let (x0, x1) = pts.clone().fold((f64::INFINITY, 0.0f64), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let top = pts.filter(|p| p.0 == x0).map(|p| p.1).fold(0.0f64, f64::max);
    (x0.is_finite() && x1 > x0 && top > 0.0).then(|| {
        let y0 = 2.0 * top;
        Guide::grey("slope -1/2 (guide)", vec![(x0, y0), (x1, y0 * (x1 / x0).powf(-0.5))])
    })
}

/// The figure of (test bed, variant); `estimators` fixes the style index of each estimator
/// across the run. `None` when no series has two budgets (a single-budget sweep draws no lines).
pub fn figure(
    report: &RunReport,
    testbed: &str,
    variant: &str,
    estimators: &[&str],
    names: &DisplayNames,
) -> Option<Panels> {
    let rows: Vec<&SummaryRow> = report.query().testbed(testbed).variant(variant).iter().collect();
    let kind = rows.first().map(|r| r.budget_kind.as_str()).unwrap_or("samples");
    let budget = budget_axis_label(kind);
    let (mut rmse, mut eff, mut time) = (Vec::new(), Vec::new(), Vec::new());
    for (style, name) in estimators.iter().enumerate() {
        let mut mine: Vec<&&SummaryRow> = Query::new(&rows).estimator(name).iter().collect();
        if mine.is_empty() {
            continue;
        }
        mine.sort_by_key(|r| r.budget);
        let label = legend(report, names, testbed, variant, name);
        let points = |f: &dyn Fn(&SummaryRow) -> Option<(f64, f64)>| {
            let mut p: Vec<(f64, f64)> = mine.iter().filter_map(|r| f(r)).collect();
            p.sort_by(|a, b| a.0.total_cmp(&b.0));
            p
        };
        let band: Vec<(f64, f64, f64)> = mine
            .iter()
            .filter_map(|r| Some((r.budget as f64, r.rmse_lo?, r.rmse_hi?)))
            .filter(|b| b.0 > 0.0 && b.2.is_finite())
            .collect();
        rmse.push(Series::new(label.clone(), style, points(&|r| positive(r.budget as f64, r.rmse))).with_band(band));
        eff.push(Series::new(
            label.clone(),
            style,
            points(&|r| r.efficiency.and_then(|e| positive(r.budget as f64, e))),
        ));
        let mse_based = points(&|r| r.efficiency_mse.and_then(|e| positive(r.budget as f64, e)));
        if mse_based.len() >= 2 {
            eff.push(Series { markers: false, ..Series::new("", style, mse_based).with_line(Line::Dashed) });
        }
        time.push(Series::new(label, style, points(&|r| positive(r.metric_seconds(), r.rmse))));
    }
    // The MSE-based twins (dashed) alone do not make a figure.
    if rmse.iter().chain(eff.iter().filter(|s| s.line == Line::Solid)).all(|s| s.points.len() < 2) {
        return None;
    }
    let mut a = Figure::new(format!("(a) RMSE vs {budget}"), budget.clone(), "RMSE", rmse);
    a.guides.extend(half_slope(&a.series));
    let twins = eff.iter().any(|s| s.line == Line::Dashed);
    let b = Figure::new(format!("(b) efficiency vs {budget}"), budget.clone(), "efficiency 1/(variance × CPU s)", eff);
    let c = Figure::new("(c) RMSE vs CPU time", "CPU seconds per estimate", "RMSE", time);
    let banded = a.series.iter().any(|s| !s.band.is_empty());
    let mut panels = vec![a, b, c];
    let style = |n: &str| estimators.iter().position(|e| *e == n).unwrap_or(estimators.len());
    let legend_of = |n: &str| legend(report, names, testbed, variant, n);
    let display = |n: &str| names.estimator(n, Some(label_of(report, n)));
    if let Some(mut d) = ray_cost::panel(report, (testbed, variant, budget_unit(kind)), &legend_of, &style, &display) {
        d.title = format!("(d) {}", d.title);
        panels.push(d);
    }
    Some(Panels {
        title: format!("{}: {}", report.meta.experiment, names.testbed(testbed, variant)),
        panels,
        keys: if twins {
            vec![
                Key { label: "(b) solid: 1/(variance × CPU s)".into(), line: Line::Solid, marker: true },
                Key { label: "(b) dashed: 1/(MSE × CPU s)".into(), line: Line::Dashed, marker: false },
            ]
        } else {
            Vec::new()
        },
        note: if banded { BAND_NOTE.to_string() } else { String::new() },
    })
}
