//! Speed-up against the cost of a ray (1 ns to 10 µs, [`crate::plan::cost_model::RayCostCurve`]): the
//! last panel of a (test bed, variant)'s figure when it has a speed-up. A curve per compared pair
//! (the sweep's baseline and the pairs the paper claims name) in the method's colour, dashed for
//! a baseline other than the sweep's; the break-even line and each claimed factor as guides.

use super::figure::{Figure, Guide, Line, Series};
use super::sanitize;
use crate::analysis::{speedups, SpeedUp};
use crate::output::query::Query;
use crate::output::RunReport;

/// Points per curve.
const POINTS: usize = 41;

/// The file stem the speed-up figure of a (test bed, variant) had when it was a figure of its own.
/// It is now a panel of the test bed's figure ([`super::plot_stem`]), so no file has this stem;
/// readers that look for it find nothing.
pub fn stem(testbed: &str, variant: &str) -> String {
    format!("{}_{}_speedup_vs_ray_cost", sanitize(testbed), sanitize(variant))
}

/// A factor a paper claims: (test bed/variant, factor, method, baseline).
type Claimed = (String, f64, String, String);

/// Every speed-up of a run with a curve: the report's (against the sweep's baseline) and those of
/// the pairs its measured claims name, and the claimed factors.
fn pairs(report: &RunReport) -> (Vec<SpeedUp>, Vec<Claimed>) {
    let mut all: Vec<SpeedUp> = report.speedups.clone();
    let mut claimed = Vec::new();
    for c in report.paper.iter().filter(|c| !c.pair.is_empty() && c.regime == "measured") {
        let Some((method, baseline)) = c.pair.split_once(" vs ") else { continue };
        if let Some(p) = c.paper_value {
            claimed.push((c.testbed.clone(), p, method.to_string(), baseline.to_string()));
        }
        if all.iter().any(|s| s.estimator == method && s.baseline == baseline) {
            continue;
        }
        let extra = speedups(&report.rows, &report.fits, baseline, &report.meta.cost_model);
        all.extend(extra.into_iter().filter(|s| s.estimator == method));
    }
    (all, claimed)
}

/// The speed-up panel of a (test bed, variant), `None` without a speed-up curve. `legend(name)`
/// is the legend text and `style(name)` the style of an estimator, as in the other panels, so a
/// method's curve shares its entry; `display(name)` names a baseline; `unit` is the budget's.
pub fn panel(
    report: &RunReport,
    (testbed, variant, unit): (&str, &str, &str),
    legend: &dyn Fn(&str) -> String,
    style: &dyn Fn(&str) -> usize,
    display: &dyn Fn(&str) -> String,
) -> Option<Figure> {
    let (all, claimed) = pairs(report);
    let mine: Vec<&SpeedUp> = Query::new(&all).testbed(testbed).variant(variant).iter().collect();
    let main = mine.first().map(|s| s.baseline.clone())?;
    let budget = mine.first().map(|s| s.budget)?;
    let mut series = Vec::new();
    for s in &mine {
        let Some(curve) = s.curve() else { continue };
        let points: Vec<(f64, f64)> =
            curve.points(POINTS).into_iter().filter(|p| p.1.is_finite() && p.1 > 0.0).collect();
        let (label, line) = if s.baseline == main {
            (legend(&s.estimator), Line::Solid)
        } else {
            (format!("speed-up of {} over {}", display(&s.estimator), display(&s.baseline)), Line::Dashed)
        };
        series.push(Series::new(label, style(&s.estimator), points).with_line(line).without_markers());
    }
    if series.is_empty() {
        return None;
    }
    let flat = |y: f64| vec![(1.0, y), (1e4, y)];
    let mut guides = vec![Guide::grey("break-even (speed-up 1)", flat(1.0))];
    let tb = format!("{testbed}/{variant}");
    for (_, paper, method, baseline) in claimed.iter().filter(|(t, ..)| *t == tb) {
        guides.push(Guide {
            label: format!("paper: {paper}x ({} vs {})", display(method), display(baseline)),
            points: flat(*paper),
            style: Some(style(method)),
            line: Line::Dotted,
        });
    }
    Some(Figure {
        title: format!("speed-up over {} at equal error ({budget} {unit})", display(&main)),
        x_desc: "cost of one ray (ns), other costs as measured".into(),
        y_desc: "speed-up at equal error".into(),
        series,
        guides,
    })
}
