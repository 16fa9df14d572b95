//! The post hook of `pmc-ip`: paper 003 Table 1 in its own layout (`table1.csv`: method,
//! spp schedule, image time, Err, P-Eff, our plain efficiency, and the paper's numbers beside),
//! the check that the stored references are precise enough (every RMSE at the largest budget at
//! least 3x the reference's RMS standard error), and Fig. 4 as maps: one PMC-IP 2+4+4 run's
//! initial image, its weights `alpha^(1)` (x pixels: 1 = the uniform share) and samples per
//! pixel, the result beside one uniform 10-spp image, and both per-pixel variance images over the
//! run's repetitions (`pixels.csv` holds the same per pixel).

use crate::pmc_ip::{row, PMC_IP_4};
use estimators::budget::Budget;
use estimators::math::Rgb;
use estimators::pmc::ip::{image_probes, PmcIp, Trace};
use estimators::rng::StreamKey;
use estimators::task::Task;
use mcbench::error::{HarnessError, Result};
use mcbench::folder::OutputDir;
use mcbench::output::RunReport;
use mcbench::plan::{Plan, PreparedBed};
use mcbench::plot::maps::{write_maps, Map, Scale};
use mcbench::runner::RunResults;
use std::path::{Path, PathBuf};

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

fn table1(plan: &Plan, report: &RunReport) -> String {
    let mut csv = String::from(
        "variant,method,estimator,spp,schedule,image_seconds,err,p_eff,efficiency_mse,rmse,paper_image,paper_schedule,paper_seconds,paper_err,paper_p_eff\n",
    );
    for b in &plan.beds {
        for ((est, budget), paper) in OURS.iter().zip(PAPER) {
            let Some(r) = row(report, &b.variant, est, *budget) else { continue };
            let (method, sched) = match pmc_ip_of(plan, est) {
                Some(ip) => ("PMC-IP", schedule(&ip, *budget)),
                None => ("Uniform", budget.to_string()),
            };
            let opt = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:.6e}"));
            csv.push_str(&format!(
                "{},{method},\"{est}\",{budget},{sched},{:.6},{:.6},{},{},{:.6},{},{},{},{},{}\n",
                b.variant,
                r.seconds * r.integrals as f64,
                r.p_err,
                opt(r.p_eff),
                opt(r.efficiency_mse),
                r.rmse,
                paper.0,
                paper.2,
                paper.3,
                paper.4,
                paper.5
            ));
        }
    }
    csv
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
    let uniform = estimators::pmc::uniform_image::UniformImage;
    let image = estimators::estimator::Estimator::estimate_sequence(&uniform, &tasks, &mut key("uniform/fig4").rng())
        .map_err(|e| HarnessError::write("pmc-ip maps", e))?;
    Ok((trace, image))
}

/// Writes `table1.csv`, `pixels.csv` and the Fig. 4 maps; adds the reference-precision claims.
pub fn post(
    plan: &Plan,
    run: &RunResults,
    report: &mut RunReport,
    results: &OutputDir,
    plots: Option<&Path>,
    _registry: &mcbench::registry::Registry,
) -> Result<Vec<PathBuf>> {
    results.write("table1.csv", table1(plan, report).as_bytes())?;
    report.paper.extend(mcbench::claims::reference_precision(plan, report));
    let budget = 10;
    let Some(ip) = pmc_ip_of(plan, "pmc_ip") else { return Ok(Vec::new()) };
    let mut csv = String::from("variant,px,py,reference,reference_se,alpha_1,samples,var_uniform_10,var_pmc_ip_10\n");
    let mut files = Vec::new();
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
        for p in 0..pixels {
            csv.push_str(&format!(
                "{},{},{},{},{},{},{},{},{}\n",
                bed.variant,
                p % w,
                p / w,
                reference[p],
                bed.bed.reference().std_err[p][0],
                alpha[p],
                samples[p],
                var_u[p],
                var_p[p]
            ));
        }
        let Some(dir) = plots else { continue };
        let channel = |img: &[Rgb]| img.iter().map(|v| v[0]).collect::<Vec<f64>>();
        let images = [reference.clone(), channel(&trace.initial_image), channel(&trace.estimate), channel(&uniform)];
        let radiance = Scale::log_of(images.iter().map(|v| v.as_slice()));
        let variance = Scale::log_of([var_u.as_slice(), var_p.as_slice()]);
        let map = |label: &str, values: Vec<f64>, scale: Scale| Map {
            label: label.into(),
            width: w,
            height: h,
            values,
            scale,
        };
        let [r0, r1, r2, r3] = images;
        let sched = schedule(&ip, budget);
        let maps = vec![
            map("reference", r0, radiance),
            map(&format!("initial image ({} spp)", ip.initial.min(budget)), r1, radiance),
            map("alpha(1) x pixels", alpha.clone(), Scale::log_of([alpha.as_slice()])),
            map("samples per pixel", samples.clone(), Scale::log_of([samples.as_slice()])),
            map(&format!("PMC-IP {sched}"), r2, radiance),
            map(&format!("uniform {budget} spp"), r3, radiance),
            map(&format!("variance, PMC-IP {sched}"), var_p, variance),
            map(&format!("variance, uniform {budget} spp"), var_u, variance),
        ];
        let title = format!(
            "pmc-ip: paper 003 Fig. 4 on checker-image / {} ({} reps for variances)",
            bed.variant, plan.sweep.reps
        );
        files.extend(write_maps(dir, &format!("fig4_{}", bed.variant), &title, &maps)?);
    }
    results.write("pixels.csv", csv.as_bytes())?;
    Ok(files)
}
