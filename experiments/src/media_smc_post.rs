//! The post hook of `media-smc`: the structure report of paper 000 Table 1 (criterion, depth,
//! nodes, leaves, cells, bytes of the octree at the largest budget, from the estimators'
//! diagnostics) written to `structure.csv` and beside the paper's numbers in the `paper` block,
//! and the check that the stored references are precise enough: every measured RMSE at the
//! largest budget must be at least 3x the reference's RMS standard error (SPEC §2, issue 4).

use mcbench::error::Result;
use mcbench::folder::OutputDir;
use mcbench::output::{Claim, RunReport};
use mcbench::plan::Plan;
use mcbench::runner::RunResults;
use std::path::{Path, PathBuf};

/// The refinement criterion the ids run with (their default).
const CRITERION: f64 = 32.0;

fn diag(r: &RunReport, variant: &str, estimator: &str, budget: u64, name: &str) -> Option<f64> {
    r.diagnostics
        .iter()
        .find(|d| d.variant == variant && d.estimator == estimator && d.budget == budget && d.name == name)
        .map(|d| d.mean)
}

/// Writes `structure.csv`, adds the Table 1 and reference-precision entries to the `paper` block.
pub fn post(
    plan: &Plan,
    _run: &RunResults,
    report: &mut RunReport,
    results: &OutputDir,
    _plots: Option<&Path>,
    _registry: &mcbench::registry::Registry,
) -> Result<Vec<PathBuf>> {
    let last = plan.sweep.budgets.last().map_or(0, |b| b.amount);
    let mut csv = String::from("variant,estimator,spp,criterion,depth,nodes,leaves,cells,bytes\n");
    let names = ["depth", "nodes", "leaves", "cells", "bytes"];
    let mut seen = Vec::new();
    for d in &report.diagnostics {
        if d.budget != last || d.name != "nodes" || seen.contains(&(d.variant.clone(), d.estimator.clone())) {
            continue;
        }
        seen.push((d.variant.clone(), d.estimator.clone()));
        let v: Vec<String> = names
            .iter()
            .map(|n| format!("{:.1}", diag(report, &d.variant, &d.estimator, last, n).unwrap_or(f64::NAN)))
            .collect();
        csv.push_str(&format!("{},{},{last},{CRITERION},{}\n", d.variant, d.estimator, v.join(",")));
    }
    results.write("structure.csv", csv.as_bytes())?;
    // Paper 000 Table 1 (Fig. 5 column: criterion 256, depth 7, 2489 nodes, 2178 leaves, 3887712
    // cells, 163.5 MB at 512 x 512 pixels): ours is the same structure at 16 x 16 pixels.
    let table1 = [("depth", 7.0), ("nodes", 2489.0), ("leaves", 2178.0), ("cells", 3_887_712.0), ("bytes", 163.5e6)];
    for (name, paper) in table1 {
        let ours = diag(report, "albedo-0.8", "is1_cv2", last, name);
        report.paper.push(Claim {
            testbed: "gradient-box/albedo-0.8".into(),
            claim: format!("paper 000 Table 1 (Fig. 5 scene, criterion 256, 512x512): octree {name}"),
            paper_value: Some(paper),
            our_value: ours,
            held: None,
            note: format!(
                "structure report, not a claim: is1_cv2 at {last} spp, criterion {CRITERION}, 16x16 pixels (mean over repetitions; every variant and id in structure.csv)"
            ),
        });
    }
    report.paper.extend(mcbench::claims::reference_precision(plan, report));
    Ok(Vec::new())
}
