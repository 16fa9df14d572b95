//! The post hook of `pmc-hi`: paper 003 Table 2 in its own layout (`table2.csv`: the paper's rows
//! (`source` = paper; the Plant beside our `occluded` variant) and ours per estimator and budget:
//! spp, image time, Err, P-Eff and our plain efficiency `1/(MSE x s)`), and
//! Fig. 7: the PMC-HI mixture weights of every pixel after one estimate of `FIG7_SPP` samples
//! (the paper's "16 total samples per estimate", two populations of 8), as maps (bright = high
//! weight) and in `alpha_maps.csv`.

use estimators::budget::Budget;
use estimators::rng::StreamKey;
use estimators::task::Task;
use mcbench::error::{HarnessError, Result};
use mcbench::folder::OutputDir;
use mcbench::output::RunReport;
use mcbench::plan::Plan;
use mcbench::plot::maps::{write_maps, Map, Scale};
use mcbench::runner::RunResults;
use std::path::{Path, PathBuf};

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

fn table2(report: &RunReport) -> String {
    let mut csv = String::from("source,image,variant,method,spp,image_seconds,err,p_eff,efficiency_mse,rmse\n");
    for p in PAPER {
        let variant = if p.0 == "Checks" { "default" } else { "occluded" };
        csv.push_str(&format!("paper,{},{variant},{},{},{},{},{},,\n", p.0, p.1, p.2, p.3, p.4, p.5));
    }
    for r in report.rows.iter().filter(|r| r.testbed == "checker-direct") {
        let opt = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:.6e}"));
        csv.push_str(&format!(
            "ours,checker-direct,{},\"{}\",{},{:.6},{:.6},{},{},{:.6}\n",
            r.variant,
            r.estimator,
            r.budget,
            r.seconds * r.integrals as f64,
            r.p_err,
            opt(r.p_eff),
            opt(r.efficiency_mse),
            r.rmse
        ));
    }
    csv
}

/// Writes `table2.csv`, `alpha_maps.csv` and the Fig. 7 maps.
pub fn post(
    plan: &Plan,
    _run: &RunResults,
    report: &mut RunReport,
    results: &OutputDir,
    plots: Option<&Path>,
    _registry: &mcbench::registry::Registry,
) -> Result<Vec<PathBuf>> {
    results.write("table2.csv", table2(report).as_bytes())?;
    let Some(est) = plan.estimators.iter().find(|e| e.name == "pmc_hi") else { return Ok(Vec::new()) };
    let budget = Budget::samples(FIG7_SPP).map_err(|e| HarnessError::write("fig7", e))?;
    let mut csv = String::from("variant,px,py,alpha_light0,alpha_light1,alpha_brdf,alpha_cone\n");
    let mut files = Vec::new();
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
            let v: Vec<String> = maps.iter().map(|m| m[i].to_string()).collect();
            csv.push_str(&format!("{},{},{},{}\n", bed.variant, i % w, i / w, v.join(",")));
        }
        if let Some(dir) = plots {
            let panels: Vec<Map> = maps
                .into_iter()
                .zip(WEIGHTS)
                .map(|(values, (_, label))| Map {
                    label: label.into(),
                    width: w,
                    height: h,
                    values,
                    scale: Scale::Linear(0.0, 1.0),
                })
                .collect();
            let title = format!(
                "pmc-hi: paper 003 Fig. 7, PMC-HI weights after {FIG7_SPP} samples, checker-direct / {}",
                bed.variant
            );
            files.extend(write_maps(dir, &format!("fig7_{}", bed.variant), &title, &panels)?);
        }
    }
    results.write("alpha_maps.csv", csv.as_bytes())?;
    Ok(files)
}
