//! The post hook of `transmittance`: paper 002 Fig. 8, the standard-deviation bands of the
//! transmittance estimators along the eq21 central ray. For each Eq. 16 case
//! ([`crate::variance_claims::CASES`]) and s = 1, 2, ..., 20 it writes the exact T(s), the predicted
//! standard deviation and the measured mean and standard deviation of 4000 one-ray estimates to
//! `fig8_bands.csv`, and plots the relative standard deviation sd / T against s (log-log: the
//! band T +- sd has a negative lower edge where sd > T): one colour per case, measured solid with
//! markers, Eq. 16's prediction dashed.

use crate::variance_claims::{build, central_ray, measure, Measured, CASES};
use mcbench::error::Result;
use mcbench::output::plot::{write_panels, Figure, Key, Line, Panels, Series};
use mcbench::output::Claim;
use mcbench::registry::PostContext;
use mcbench_core::math::Vec3;
use mcbench_papers::tracking::variance::predicted;
use serde::Serialize;
use std::path::PathBuf;

/// Points along the central ray (s = 20 k / POINTS).
const POINTS: usize = 20;
/// One-ray estimates per point and case.
const RAYS: usize = 4000;

/// One row of `fig8_bands.csv`: one estimator case at one point of the central ray.
#[derive(Serialize)]
struct BandRow {
    /// The transmittance estimator id.
    estimator: &'static str,
    /// Its sampling density sigma_samp.
    sigma_samp: f64,
    /// Distance along the ray.
    s: f64,
    /// The exact transmittance T(s).
    t_exact: f64,
    /// Standard deviation of a one-ray estimate predicted by paper 002 Eq. 16.
    predicted_sd: f64,
    /// Mean of the one-ray estimates.
    measured_mean: f64,
    /// Standard deviation of the one-ray estimates.
    measured_sd: f64,
    /// Standard error of the measured variance (from the sample second and fourth moments).
    measured_variance_se: f64,
}

/// Writes `fig8_bands.csv` and the band plot, and adds the band agreement to the `paper` block.
pub fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    let PostContext { report, out: results, plots, registry, .. } = cx;
    let names = registry.display_names();
    let Some((bed, grid)) = central_ray(POINTS) else { return Ok(Vec::new()) };
    let sigma = |t: f64| bed.extinction(Vec3::new(0.0, 0.0, t));
    let mut rows = Vec::new();
    let mut series = Vec::new();
    for (ci, (id, model, samp)) in CASES.into_iter().enumerate() {
        let Some(est) = build(id, samp) else { continue };
        let pred = predicted(sigma, model, samp, &grid);
        let (mut within, mut worst) = (0, 0.0f64);
        let (mut p_pts, mut m_pts) = (Vec::new(), Vec::new());
        for (k, &s) in grid.iter().enumerate() {
            let Measured { mean, variance, variance_se } =
                measure(est.as_ref(), &bed, k, RAYS, 1000 + (ci * POINTS + k) as u64);
            let (t, v) = pred[k];
            rows.push(BandRow {
                estimator: id,
                sigma_samp: samp,
                s,
                t_exact: t,
                predicted_sd: v.sqrt(),
                measured_mean: mean,
                measured_sd: variance.sqrt(),
                measured_variance_se: variance_se,
            });
            let z = (variance - v).abs() / variance_se.max(f64::MIN_POSITIVE);
            within += usize::from(z <= 4.0);
            worst = worst.max(z);
            p_pts.push((s, v.sqrt() / t));
            m_pts.push((s, variance.sqrt() / t));
        }
        let name = names.named_estimator(&format!("{id}[sigma_samp={samp}]")).unwrap_or_else(|| id.to_string());
        series.push(Series::new(name, ci, m_pts));
        series.push(Series::new("", ci, p_pts).with_line(Line::Dashed).without_markers());
        report.paper.push(Claim {
            testbed: "eq21-medium/central-ray".into(),
            claim: format!("paper 002 Fig. 8 ({id}, sigma_samp {samp}): the measured standard-deviation band of T(s) matches Eq. 16 along the ray"),
            paper_value: Some(POINTS as f64),
            our_value: Some(within as f64),
            held: Some(within == POINTS),
            note: format!("points s = 1..20 whose measured variance lies within 4 SE of Eq. 16 ({RAYS} one-ray estimates each; SE from the sample second and fourth moments, exact in n; itself unreliable for heavy tails); worst |z| {worst:.2}; data in fig8_bands.csv"),
            ..Default::default()
        });
    }
    results.write_csv("fig8_bands.csv", &rows)?;
    let Some(dir) = plots else { return Ok(Vec::new()) };
    let chart = Figure::new(
        "",
        "distance s along the ray",
        "relative standard deviation sd[T̂(s)] / T(s) of a one-ray estimate",
        series,
    );
    let fig = Panels {
        title: "transmittance: paper 002 Fig. 8, Eq. 21 medium, central ray".into(),
        panels: vec![chart],
        keys: vec![
            Key {
                label: format!("solid: measured ({RAYS} one-ray estimates per point)"),
                line: Line::Solid,
                marker: true,
            },
            Key { label: "dashed: predicted by Eq. 16".into(), line: Line::Dashed, marker: false },
        ],
        note: String::new(),
    };
    write_panels(dir, "fig8_bands", &fig)
}
