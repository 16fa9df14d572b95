//! The heat maps of `canonical-sweep`, three figures: variance x cost of every estimator over
//! (target T, sigma_samp ratio), one row of panels per profile on one colour scale; the
//! measured-over-predicted variance in every cell (colour: z, the distance in error bars), laid
//! out alike; and the best estimator per cell for every profile, with and without control
//! variates.

use crate::canonical_cells::{Agreement, CellRow};
use crate::canonical_sweep::{FAMILIES, RATIOS};
use crate::canonical_sweep_post::Analysis;
use crate::canonical_winners::cell_win;
use mcbench::error::Result;
use mcbench::output::plot::heatmap::{write_heatmap, Fill, HeatCell, HeatFigure, Panel, Scale};
use mcbench::output::report::sig;
use mcbench_papers::testbeds::canonical_1d::TARGETS;
use mcbench_papers::testbeds::canonical_profiles::Profile;
use std::path::{Path, PathBuf};

/// Relative variance x cost below this is drawn as an exact (zero-variance) estimator.
const ZERO: f64 = 1e-20;

fn rows() -> Vec<String> {
    TARGETS.iter().map(|t| format!("T={t}")).collect()
}

fn columns(swept: bool) -> Vec<String> {
    if swept {
        RATIOS.iter().map(|r| r.to_string()).collect()
    } else {
        vec!["own".into()]
    }
}

/// A panel per family of `profile`, each cell from `cell` (or a refusal / blank).
fn panels(a: &Analysis, profile: Profile, cell: &dyn Fn(&CellRow) -> HeatCell) -> Vec<Panel> {
    FAMILIES
        .iter()
        .enumerate()
        .map(|(f, fam)| {
            let ratios: Vec<Option<f64>> = if fam.swept { RATIOS.map(Some).to_vec() } else { vec![None] };
            let cells = TARGETS
                .iter()
                .map(|&t| {
                    ratios
                        .iter()
                        .map(|&r| match a.find(profile, t, f, r) {
                            Some(row) if row.measured.is_some() => cell(row),
                            Some(_) => HeatCell { fill: Fill::Empty, text: "refused".into() },
                            None => HeatCell { fill: Fill::Empty, text: String::new() },
                        })
                        .collect()
                })
                .collect();
            let title = if fam.key == "ray-marching" { "ray marching (MSE)".into() } else { fam.key.to_string() };
            let heading = if f == 0 { format!("profile: {}", profile.name()) } else { String::new() };
            Panel { heading, title, columns: columns(fam.swept), cells }
        })
        .collect()
}

fn cost_value(r: &CellRow) -> Option<f64> {
    if FAMILIES[r.family].key == "ray-marching" {
        r.rel_mse_cost()
    } else {
        r.rel_var_cost()
    }
}

/// The profiles the sweep ran.
fn profiles(a: &Analysis) -> Vec<Profile> {
    Profile::ALL.into_iter().filter(|p| a.rows.iter().any(|r| r.profile == *p)).collect()
}

fn var_cost_figure(a: &Analysis) -> HeatFigure {
    let cell = |r: &CellRow| match cost_value(r) {
        Some(v) if v < ZERO => HeatCell { fill: Fill::Empty, text: "0".into() },
        Some(v) if v.is_finite() => HeatCell { fill: Fill::Value(v.log10()), text: sig(v, 2) },
        _ => HeatCell { fill: Fill::Empty, text: "-".into() },
    };
    let all: Vec<Panel> = profiles(a).into_iter().flat_map(|p| panels(a, p, &cell)).collect();
    let logs = all.iter().flat_map(|p| p.cells.iter().flatten()).filter_map(|c| match c.fill {
        Fill::Value(v) => Some(v),
        _ => None,
    });
    let (lo, hi) = logs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    HeatFigure {
        title: "canonical-sweep: variance x cost / T^2 per profile".into(),
        rows: rows(),
        axes: "rows: target transmittance; columns: sigma_samp / max sigma_t (own: the estimator's density); cell: variance of one estimate x fetches per estimate / T^2 (lower is better); one colour scale for every profile".into(),
        panels: all,
        scale: Scale::Sequential { lo: lo.min(hi), hi: hi.max(lo), label: "log10(variance x fetches / T^2)".into() },
    }
}

fn agreement_figure(a: &Analysis) -> HeatFigure {
    let limit = (1.5 * a.z_crit).max(1.0);
    let cell = |r: &CellRow| {
        let ratio = r.measured.as_ref().zip(r.predicted).map(|(m, p)| m.variance / p.variance());
        match r.agreement(a.z_crit) {
            Agreement::Agrees | Agreement::Disagrees => HeatCell {
                fill: r.z().map_or(Fill::Empty, Fill::Value),
                text: ratio.map(|x| sig(x, 2)).unwrap_or_default(),
            },
            Agreement::Unresolved => {
                HeatCell { fill: Fill::Empty, text: ratio.map(|x| format!("({})", sig(x, 1))).unwrap_or_default() }
            }
            Agreement::ZeroVariance => HeatCell { fill: Fill::Empty, text: "0=0".into() },
            Agreement::NotPredicted => HeatCell { fill: Fill::Empty, text: "n/a".into() },
        }
    };
    HeatFigure {
        title: "canonical-sweep: measured / predicted variance (paper 002 Eq. 16-20) per profile".into(),
        rows: rows(),
        axes: format!(
            "cell text: measured / predicted variance; colour: z = (measured - predicted) / error bar, |z| <= {} agrees; grey (x): error bar > 25% of the prediction (unresolved); 0=0: zero-variance; n/a: no prediction",
            sig(a.z_crit, 3)
        ),
        panels: profiles(a).into_iter().flat_map(|p| panels(a, p, &cell)).collect(),
        scale: Scale::Diverging { limit, label: "z (measured - predicted, in error bars)".into() },
    }
}

fn best_figure(a: &Analysis, with_cv: bool) -> HeatFigure {
    let mut panels = Profile::ALL
        .iter()
        .map(|&p| {
            let cells = TARGETS
                .iter()
                .map(|&t| {
                    RATIOS
                        .iter()
                        .map(|&r| match cell_win(a, p, t, r, with_cv) {
                            Some(w) => {
                                let mut text = w.label.clone();
                                if !w.resolved {
                                    text.push('?');
                                }
                                if w.tie.is_some() {
                                    text.push('≈');
                                }
                                HeatCell { fill: Fill::Category(w.colour_family()), text }
                            }
                            None => HeatCell { fill: Fill::Empty, text: "-".into() },
                        })
                        .collect()
                })
                .collect();
            Panel { heading: String::new(), title: p.name().into(), columns: columns(true), cells }
        })
        .collect::<Vec<_>>();
    if let Some(first) = panels.first_mut() {
        first.heading = if with_cv { "every estimator" } else { "without control variates" }.into();
    }
    HeatFigure {
        title: "canonical-sweep: lowest measured variance x cost per cell".into(),
        rows: rows(),
        axes: "rows: target transmittance; columns: sigma_samp / max sigma_t; ?: the winner's variance is not resolved (heavy tails); ≈: the runner-up is within two error bars; RT/DP and DT/ST: one estimator at ratio >= 1".into(),
        panels,
        // Every family in the legend, so a family has the same colour in both figures.
        scale: Scale::Categories(FAMILIES.iter().map(|f| format!("{} {}", f.short, f.key)).collect()),
    }
}

/// Writes the three heat-map figures into `dir` and returns the files.
pub fn heat_maps(a: &Analysis, dir: &Path) -> Result<Vec<PathBuf>> {
    let mut best = best_figure(a, true);
    best.panels.extend(best_figure(a, false).panels);
    let mut files = write_heatmap(dir, "heat_best_estimator", &best)?;
    if !profiles(a).is_empty() {
        files.extend(write_heatmap(dir, "heat_var_cost", &var_cost_figure(a))?);
        files.extend(write_heatmap(dir, "heat_agreement", &agreement_figure(a))?);
    }
    Ok(files)
}
