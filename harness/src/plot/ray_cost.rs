//! Speed-up against the cost of a ray (1 ns to 10 µs, [`crate::cost_model::RayCostCurve`]): one
//! figure per (test bed, variant) with a speed-up, a curve per compared pair (the sweep's baseline
//! and the pairs the paper claims name), the break-even line and each claimed factor.

use super::{label_of, sanitize, Figure, Series};
use crate::analysis::{speedups, SpeedUp};
use crate::output::RunReport;

/// Points per curve.
const POINTS: usize = 41;

/// The file stem of the speed-up figure of a (test bed, variant).
pub fn stem(testbed: &str, variant: &str) -> String {
    format!("{}_{}_speedup_vs_ray_cost", sanitize(testbed), sanitize(variant))
}

/// The figures (file stem, figure) of a run's speed-ups against the cost of a ray.
pub fn figures(report: &RunReport) -> Vec<(String, Figure)> {
    let mut all: Vec<SpeedUp> = report.speedups.clone();
    let mut claimed: Vec<(String, f64, String)> = Vec::new();
    for c in report.paper.iter().filter(|c| !c.pair.is_empty() && c.regime == "measured") {
        let Some((method, baseline)) = c.pair.split_once(" vs ") else { continue };
        if let Some(p) = c.paper_value {
            claimed.push((c.testbed.clone(), p, format!("{method} vs {baseline}")));
        }
        if all.iter().any(|s| s.estimator == method && s.baseline == baseline) {
            continue;
        }
        let extra = speedups(&report.rows, &report.fits, baseline, &report.meta.cost_model);
        all.extend(extra.into_iter().filter(|s| s.estimator == method));
    }
    let mut groups: Vec<(String, String)> = Vec::new();
    for s in &all {
        let g = (s.testbed.clone(), s.variant.clone());
        if !groups.contains(&g) {
            groups.push(g);
        }
    }
    let mut out = Vec::new();
    for (testbed, variant) in groups {
        let mut series = Vec::new();
        for (style, s) in all.iter().filter(|s| s.testbed == testbed && s.variant == variant).enumerate() {
            let Some(curve) = s.curve() else { continue };
            let points: Vec<(f64, f64)> =
                curve.points(POINTS).into_iter().filter(|p| p.1.is_finite() && p.1 > 0.0).collect();
            let label = format!(
                "{} vs {} at {} spp (limit {:.3})",
                label_of(report, &s.estimator),
                label_of(report, &s.baseline),
                s.budget,
                curve.limit()
            );
            series.push(Series { label, style, points });
        }
        if series.is_empty() {
            continue;
        }
        let flat = |y: f64| vec![(1.0, y), (1e4, y)];
        let n = series.len();
        series.push(Series { label: "break-even (1x)".into(), style: n, points: flat(1.0) });
        let tb = format!("{testbed}/{variant}");
        for (k, (_, paper, pair)) in claimed.iter().filter(|(t, ..)| *t == tb).enumerate() {
            series.push(Series { label: format!("paper: {paper}x ({pair})"), style: n + 1 + k, points: flat(*paper) });
        }
        let fig = Figure {
            title: format!("{}: speed-up vs ray cost — {testbed} / {variant}", report.meta.experiment),
            x_desc: "cost of one ray (ns), other costs as measured".into(),
            y_desc: "speed-up at equal error".into(),
            series,
        };
        out.push((stem(&testbed, &variant), fig));
    }
    out
}
