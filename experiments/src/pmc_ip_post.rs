//! The post hook of `pmc-ip`: paper 003 Table 1 in its own layout (`table1.csv`: method,
//! spp schedule, image time, Err, P-Eff, our plain efficiency, and the paper's numbers beside),
//! the check that the stored references are precise enough (every RMSE at the largest budget at
//! least 3x the reference's RMS standard error), and Fig. 4 as maps: one PMC-IP 2+4+4 run's
//! initial image, its weights `alpha^(1)` (x pixels: 1 = the uniform share) and samples per
//! pixel, the result beside one uniform 10-spp image, and both per-pixel variance images over the
//! run's repetitions (`pixels.csv` holds the same per pixel).

use crate::pmc_ip::{row, PMC_IP_4};
use mcbench::error::{HarnessError, Result};
use mcbench::output::plot::maps::{write_maps, Map, Scale};
use mcbench::output::RunReport;
use mcbench::plan::{Plan, PreparedBed};
use mcbench::registry::PostContext;
use mcbench::run::runner::RunResults;
use mcbench_core::budget::Budget;
use mcbench_core::math::Rgb;
use mcbench_core::rng::StreamKey;
use mcbench_core::task::Task;
use mcbench_papers::pmc::ip::{image_probes, PmcIp, Trace};
use serde::Serialize;
use std::path::PathBuf;

/// The paper's Table 1: (image, method, spp schedule, T seconds, Err, P-Eff).
const PAPER: [(&str, &str, &str, f64, f64, f64); 5] = [
    ("Buddha", "Uniform", "10", 58.1, 0.625, 0.027),
    ("Buddha", "PMC-IP", "2+4+4", 62.4, 0.116, 0.138),
    ("Box", "Uniform", "16", 163.0, 0.545, 0.011),
    ("Box", "Uniform", "32", 328.0, 0.255, 0.012),
    ("Box", "PMC-IP", "4+6+6", 169.0, 0.182, 0.033),
];

/// Our rows matching the paper's: (estimator, budget).
const OURS: [(&str, u64); 5] =
    [("uniform_image", 10), ("pmc_ip", 10), ("uniform_image", 16), ("uniform_image", 32), (PMC_IP_4, 16)];

/// The spp schedule of a PMC-IP configuration at `budget`: "initial+per iteration...".
fn schedule(ip: &PmcIp, budget: u64) -> String {
    let s0 = ip.initial.min(budget);
    let rest = budget - s0;
    let t = if rest > 0 { ip.iterations as u64 } else { 0 };
    let mut parts = vec![s0.to_string()];
    for _ in 0..t {
        let share = rest as f64 / t as f64;
        parts.push(if share.fract() == 0.0 { format!("{share}") } else { format!("{share:.2}") });
    }
    parts.join("+")
}

fn pmc_ip_of(plan: &Plan, name: &str) -> Option<PmcIp> {
    let e = plan.estimators.iter().find(|e| e.name == name && e.spec.id == "pmc_ip")?;
    PmcIp::from_params(&e.spec.params).ok()
}

/// One row of `table1.csv`: one of our rows matching the paper's Table 1, with the paper's
/// numbers beside.
#[derive(Serialize)]
struct Table1Row<'a> {
    /// The test bed variant.
    variant: &'a str,
    /// `Uniform` or `PMC-IP`.
    method: &'a str,
    /// Our estimator.
    estimator: &'a str,
    /// Samples per pixel.
    spp: u64,
    /// The spp schedule: `initial+per iteration...` for PMC-IP, the spp for uniform.
    schedule: String,
    /// CPU seconds for the whole image (CPU seconds per estimate x pixels), the T of P-Eff.
    image_seconds: f64,
    /// Perceptual error Err (mean over pixels of MSE / tvi(reference luminance)).
    err: f64,
    /// P-Eff = 1 / (image seconds x Err) (empty without timing).
    p_eff: Option<f64>,
    /// Our plain efficiency 1 / (MSE x CPU seconds per estimate) (empty without timing).
    efficiency_mse: Option<f64>,
    /// RMSE against the reference.
    rmse: f64,
    /// The paper's image of the matching row.
    paper_image: &'a str,
    /// The paper's spp schedule.
    paper_schedule: &'a str,
    /// The paper's image time T in seconds.
    paper_seconds: f64,
    /// The paper's Err.
    paper_err: f64,
    /// The paper's P-Eff.
    paper_p_eff: f64,
    /// Wall-clock seconds for the whole image, which machine load inflates.
    image_seconds_wall: f64,
}

/// One row of `pixels.csv`: one pixel of the Fig. 4 maps (channel 0).
#[derive(Serialize)]
struct PixelRow<'a> {
    /// The test bed variant.
    variant: &'a str,
    /// Pixel column.
    px: usize,
    /// Pixel row.
    py: usize,
    /// The stored reference.
    reference: f64,
    /// The reference's standard error.
    reference_se: f64,
    /// The PMC-IP weight alpha^(1) after the initial image, x pixels (1 = the uniform share).
    alpha_1: f64,
    /// Samples the PMC-IP run spent on the pixel.
    samples: f64,
    /// Variance of the uniform 10-spp estimate over the run's repetitions (NaN without the cell).
    var_uniform_10: f64,
    /// Variance of the PMC-IP 10-spp estimate over the run's repetitions (NaN without the cell).
    var_pmc_ip_10: f64,
}

fn table1<'a>(plan: &'a Plan, report: &RunReport) -> Vec<Table1Row<'a>> {
    let mut rows = Vec::new();
    for b in &plan.beds {
        for ((est, budget), paper) in OURS.iter().zip(PAPER) {
            let Some(r) = row(report, &b.variant, est, *budget) else { continue };
            let (method, schedule) = match pmc_ip_of(plan, est) {
                Some(ip) => ("PMC-IP", schedule(&ip, *budget)),
                None => ("Uniform", budget.to_string()),
            };
            rows.push(Table1Row {
                variant: &b.variant,
                method,
                estimator: est,
                spp: *budget,
                schedule,
                image_seconds: r.metric_seconds() * r.integrals as f64,
                err: r.p_err,
                p_eff: r.p_eff,
                efficiency_mse: r.efficiency_mse,
                rmse: r.rmse,
                paper_image: paper.0,
                paper_schedule: paper.2,
                paper_seconds: paper.3,
                paper_err: paper.4,
                paper_p_eff: paper.5,
                image_seconds_wall: r.seconds * r.integrals as f64,
            });
        }
    }
    rows
}

/// Per-pixel variance (channel 0) of an estimator's cell at a budget.
fn variance_image(plan: &Plan, run: &RunResults, bi: usize, estimator: &str, budget: u64) -> Option<Vec<f64>> {
    run.cells
        .iter()
        .find(|(b, e, c)| *b == bi && plan.estimators[*e].name == estimator && c.key.budget.amount == budget)
        .map(|(_, _, c)| c.moments.iter().map(|m| m[0].variance()).collect())
}

/// One PMC-IP run and one uniform run over the whole image at `budget` (dedicated streams).
fn one_run(plan: &Plan, bed: &PreparedBed, ip: &PmcIp, budget: u64) -> Result<(Trace, Vec<Rgb>)> {
    let b = Budget::samples(budget).map_err(|e| HarnessError::write("pmc-ip maps", e))?;
    let n = bed.bed.integrals();
    let label = bed.label();
    let key = |estimator: &'static str| StreamKey {
        seed: plan.sweep.seed,
        testbed: &label,
        estimator,
        budget,
        rep: 0,
        integral: 0,
    };
    let tasks: Vec<Task<'_>> = (0..n).map(|i| Task::new(bed.bed.as_ref(), i, b)).collect();
    let (probes, spp) = image_probes(&tasks, "pmc_ip").map_err(|e| HarnessError::write("pmc-ip maps", e))?;
    let trace = ip.run(&probes, spp, &mut key("pmc_ip/fig4").rng());
    let tasks: Vec<Task<'_>> = (0..n).map(|i| Task::new(bed.bed.as_ref(), i, b)).collect();
    let uniform = mcbench_papers::pmc::uniform_image::UniformImage;
    let image = mcbench_core::estimator::Estimator::estimate_sequence(&uniform, &tasks, &mut key("uniform/fig4").rng())
        .map_err(|e| HarnessError::write("pmc-ip maps", e))?;
    Ok((trace, image))
}

/// Writes `table1.csv`, `pixels.csv` and the Fig. 4 maps; adds the reference-precision claims.
pub fn post(cx: PostContext<'_>) -> Result<Vec<PathBuf>> {
    let PostContext { plan, results: run, report, out: results, plots, registry, .. } = cx;
    let names = registry.display_names();
    results.write_csv("table1.csv", &table1(plan, report))?;
    report.paper.extend(mcbench::analysis::claims::reference_precision(plan, report));
    let budget = 10;
    let Some(ip) = pmc_ip_of(plan, "pmc_ip") else { return Ok(Vec::new()) };
    let mut rows = Vec::new();
    let mut all: Vec<Map> = Vec::new();
    for (bi, bed) in plan.beds.iter().enumerate() {
        let (w, h) = bed.bed.resolution();
        let pixels = w * h;
        let (trace, uniform) = one_run(plan, bed, &ip, budget)?;
        let reference: Vec<f64> = bed.bed.reference().value.iter().map(|v| v[0]).collect();
        let alpha: Vec<f64> =
            trace.alpha.first().map_or(vec![1.0; pixels], |a| a.iter().map(|x| x * pixels as f64).collect());
        let samples: Vec<f64> = (0..pixels).map(|p| trace.counts.iter().map(|c| c[p] as f64).sum()).collect();
        let nan = vec![f64::NAN; pixels];
        let var_u = variance_image(plan, run, bi, "uniform_image", budget).unwrap_or_else(|| nan.clone());
        let var_p = variance_image(plan, run, bi, "pmc_ip", budget).unwrap_or(nan);
        rows.extend((0..pixels).map(|p| PixelRow {
            variant: &bed.variant,
            px: p % w,
            py: p / w,
            reference: reference[p],
            reference_se: bed.bed.reference().std_err[p][0],
            alpha_1: alpha[p],
            samples: samples[p],
            var_uniform_10: var_u[p],
            var_pmc_ip_10: var_p[p],
        }));
        if plots.is_none() {
            continue;
        }
        let channel = |img: &[Rgb]| img.iter().map(|v| v[0]).collect::<Vec<f64>>();
        let images = [reference.clone(), channel(&trace.initial_image), channel(&trace.estimate), channel(&uniform)];
        let radiance = Scale::log_of(images.iter().map(|v| v.as_slice()));
        let variance = Scale::log_of([var_u.as_slice(), var_p.as_slice()]);
        let map = |label: &str, values: Vec<f64>, scale: Scale| Map {
            heading: String::new(),
            label: label.into(),
            width: w,
            height: h,
            values,
            scale,
        };
        let [r0, r1, r2, r3] = images;
        let sched = schedule(&ip, budget);
        let mut maps = vec![
            map("reference", r0, radiance),
            map(&format!("initial image ({} spp)", ip.initial.min(budget)), r1, radiance),
            map("alpha(1) x pixels", alpha.clone(), Scale::log_of([alpha.as_slice()])),
            map("samples per pixel", samples.clone(), Scale::log_of([samples.as_slice()])),
            map(&format!("PMC-IP {sched}"), r2, radiance),
            map(&format!("uniform {budget} spp"), r3, radiance),
            map(&format!("variance, PMC-IP {sched}"), var_p, variance),
            map(&format!("variance, uniform {budget} spp"), var_u, variance),
        ];
        maps[0].heading = names.named_testbed(&bed.spec.id, &bed.variant).unwrap_or_else(|| bed.label());
        all.extend(maps);
    }
    results.write_csv("pixels.csv", &rows)?;
    match plots {
        Some(dir) if !all.is_empty() => {
            let title = format!("pmc-ip: paper 003 Fig. 4 ({} reps for variances)", plan.sweep.reps);
            write_maps(dir, "fig4", &title, &all)
        }
        _ => Ok(Vec::new()),
    }
}
