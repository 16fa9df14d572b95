//! The post hook of `pmc-hi`: paper 003 Table 2 in its own layout (`table2.csv`: the paper's rows
//! (`source` = paper; the Plant beside our `occluded` variant) and ours per estimator and budget:
//! spp, image time, Err, P-Eff and our plain efficiency `1/(MSE x s)`), and
//! Fig. 7: the PMC-HI mixture weights of every pixel after one estimate of `FIG7_SPP` samples
//! (the paper's "16 total samples per estimate", two populations of 8), as maps (bright = high
//! weight) and in `alpha_maps.csv`.

use mcbench::error::{HarnessError, Result};
use mcbench::output::plot::maps::{write_maps, Map, Scale};
use mcbench::output::RunReport;
use mcbench::registry::PostContext;
use mcbench_core::budget::Budget;
use mcbench_core::rng::StreamKey;
use mcbench_core::task::Task;
use serde::Serialize;
use std::path::PathBuf;

/// Samples per estimate of the Fig. 7 maps.
pub const FIG7_SPP: u64 = 16;

/// The paper's Table 2: (image, method, spp, T seconds, Err, P-Eff).
const PAPER: [(&str, &str, u64, f64, f64, f64); 5] = [
    ("Checks", "MIS", 12, 46.0, 0.379, 0.057),
    ("Checks", "MIS", 48, 183.0, 0.153, 0.035),
    ("Checks", "PMC-HI", 12, 54.0, 0.146, 0.127),
    ("Plant", "MIS", 27, 53.0, 0.403, 0.047),
    ("Plant", "PMC-HI", 27, 64.0, 0.128, 0.122),
];

/// The weights mapped, in the order of paper Fig. 7, with their labels.
const WEIGHTS: [(&str, &str); 4] = [
    ("alpha_light0", "alpha, large light"),
    ("alpha_light1", "alpha, small light"),
    ("alpha_brdf", "alpha, BRDF"),
    ("alpha_cone", "alpha, cone"),
];

/// One row of `table2.csv`: a row of the paper's Table 2 or one of ours.
#[derive(Serialize)]
struct Table2Row<'a> {
    /// `paper` (the paper's numbers) or `ours`.
    source: &'a str,
    /// The paper's image (Checks, Plant), or our test bed.
    image: &'a str,
    /// Our variant (the paper's rows: the one standing in for their image).
    variant: &'a str,
    /// The paper's method (MIS, PMC-HI), or our estimator.
    method: &'a str,
    /// Samples per pixel.
    spp: u64,
    /// Seconds for the whole image (the paper's T; ours: CPU seconds per estimate x pixels, the T
    /// of our P-Eff).
    image_seconds: f64,
    /// Perceptual error Err (ours: mean over pixels of MSE / tvi(reference luminance)).
    err: f64,
    /// P-Eff = 1 / (image seconds x Err) (empty when ours has no timing).
    p_eff: Option<f64>,
    /// Our plain efficiency 1 / (MSE x CPU seconds per estimate) (empty for the paper's rows and
    /// without timing).
    efficiency_mse: Option<f64>,
    /// Our RMSE (empty for the paper's rows).
    rmse: Option<f64>,
    /// Ours: wall-clock seconds per estimate x pixels, which machine load inflates (empty for the
    /// paper's rows).
    image_seconds_wall: Option<f64>,
}

/// One row of `alpha_maps.csv`: the PMC-HI mixture weights of one pixel after one estimate of
/// [`FIG7_SPP`] samples (NaN where the estimate reports no such weight).
#[derive(Serialize)]
struct AlphaRow<'a> {
    /// The test bed variant.
    variant: &'a str,
    /// Pixel column.
    px: usize,
    /// Pixel row.
    py: usize,
    /// Weight of the large light's sampler.
    alpha_light0: f64,
    /// Weight of the small light's sampler.
    alpha_light1: f64,
    /// Weight of BRDF sampling.
    alpha_brdf: f64,
    /// Weight of the adapted cone sampler.
    alpha_cone: f64,
}

fn table2(report: &RunReport) -> Vec<Table2Row<'_>> {
    let mut rows = Vec::new();
    for (image, method, spp, image_seconds, err, p_eff) in PAPER {
        let variant = if image == "Checks" { "default" } else { "occluded" };
        rows.push(Table2Row {
            source: "paper",
            image,
            variant,
            method,
            spp,
            image_seconds,
            err,
            p_eff: Some(p_eff),
            efficiency_mse: None,
            rmse: None,
            image_seconds_wall: None,
        });
    }
    for r in report.query().testbed("checker-direct") {
        rows.push(Table2Row {
            source: "ours",
            image: "checker-direct",
            variant: &r.variant,
            method: &r.estimator,
            spp: r.budget,
            image_seconds: r.metric_seconds() * r.integrals as f64,
            err: r.p_err,
            p_eff: r.p_eff,
            efficiency_mse: r.efficiency_mse,
            rmse: Some(r.rmse),
            image_seconds_wall: Some(r.seconds * r.integrals as f64),
        });
    }
    rows
}

/// Writes `table2.csv`, `alpha_maps.csv` and the Fig. 7 maps.
pub fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    let PostContext { plan, report, out: results, plots, registry, .. } = cx;
    let names = registry.display_names();
    results.write_csv("table2.csv", &table2(report))?;
    let Some(est) = plan.estimators.iter().find(|e| e.name == "pmc_hi") else { return Ok(Vec::new()) };
    let budget = Budget::samples(FIG7_SPP).map_err(|e| HarnessError::write("fig7", e))?;
    let mut alphas = Vec::new();
    let mut panels: Vec<Map> = Vec::new();
    for bed in plan.beds.iter().filter(|b| b.bed.hemisphere().is_some_and(|h| h.lights().len() == 2)) {
        let (w, h) = bed.bed.resolution();
        let label = bed.label();
        let mut maps: Vec<Vec<f64>> = vec![Vec::with_capacity(w * h); WEIGHTS.len()];
        for i in 0..w * h {
            let key = StreamKey {
                seed: plan.sweep.seed,
                testbed: &label,
                estimator: "pmc_hi/fig7",
                budget: FIG7_SPP,
                rep: 0,
                integral: i as u64,
            };
            let task = Task::new(bed.bed.as_ref(), i, budget);
            est.estimator.estimate(&task, &mut key.rng()).map_err(|e| HarnessError::write("fig7", e))?;
            let d = task.diagnostics();
            for (k, (name, _)) in WEIGHTS.iter().enumerate() {
                maps[k].push(d.iter().find(|(n, _)| n == name).map_or(f64::NAN, |x| x.1));
            }
            alphas.push(AlphaRow {
                variant: &bed.variant,
                px: i % w,
                py: i / w,
                alpha_light0: maps[0][i],
                alpha_light1: maps[1][i],
                alpha_brdf: maps[2][i],
                alpha_cone: maps[3][i],
            });
        }
        let heading = names.named_testbed(&bed.spec.id, &bed.variant).unwrap_or_else(|| bed.label());
        panels.extend(maps.into_iter().zip(WEIGHTS).enumerate().map(|(k, (values, (_, label)))| Map {
            heading: if k == 0 { heading.clone() } else { String::new() },
            label: label.into(),
            width: w,
            height: h,
            values,
            scale: Scale::Linear(0.0, 1.0),
        }));
    }
    results.write_csv("alpha_maps.csv", &alphas)?;
    match plots {
        Some(dir) if !panels.is_empty() => {
            let title = format!("pmc-hi: paper 003 Fig. 7, PMC-HI weights after {FIG7_SPP} samples");
            write_maps(dir, "fig7", &title, &panels)
        }
        _ => Ok(Vec::new()),
    }
}
