//! `single-scatter` (paper 002 Fig. 12, §4.3): point-light single scattering in the Eq. 21 medium
//! (and the Perlin medium at its reduced 4x4 resolution), every method at equal fetch budgets of
//! about 50 and 300 per pixel (plus 100 for the RMSE-vs-fetches plot; full mode adds 1000): ray
//! marching (biased control), Woodcock tracking, attenuation-driven, attenuation-driven SIR,
//! source-driven, scattering-driven and MIS, plus the paper's noise-free marcher
//! `ray_marching[jitter=0]` and the coarse ray-marching control `ray_marching[step=5]` for the
//! unbiasedness tests. The post hook writes the equal-fetch table (primary
//! rays the budget buys, shadow rays, fetches, RMSE, rank) and puts the paper's ordering beside
//! ours in the `paper` block ([`crate::single_scatter_post`]).

use crate::ExperimentDef;
use mcbench::claims;
use mcbench::output::{Claim, RunReport};

/// Every id the experiment runs, in the order of paper 002 Fig. 12.
pub const IDS: &[&str] = &[
    "ray_marching",
    "delta_tracking",
    "attenuation_driven",
    "attenuation_driven_sir",
    "source_driven",
    "scattering_driven",
    "mis",
];

/// The two budgets of Fig. 12 (fetches per pixel).
pub const PAPER_BUDGETS: [u64; 2] = [50, 300];

/// Definition.
pub static DEF: ExperimentDef =
    ExperimentDef { toml: include_str!("single_scatter.toml"), claims, post: Some(crate::single_scatter_post::post) };

/// The paper's "noise free but biased" marcher: one ray spending the budget, offsets fixed at 1/2.
pub const NOISE_FREE: &str = "ray_marching[jitter=0]";

/// The harness's biased control (SPEC §6): ray marching with a coarse fixed step, which a
/// fetch budget buys several rays of. The Fig. 12 marcher (one ray spending the budget) is in the
/// ranking; its bias is far below what a quick run detects on the smooth Eq. 21 medium.
pub const CONTROL: &str = "ray_marching[step=5]";

/// RMSE of an estimator at a budget on a test bed (single-scatter variant).
pub fn rmse(r: &RunReport, tb: &str, est: &str, budget: u64) -> Option<f64> {
    r.rows
        .iter()
        .find(|x| x.testbed == tb && x.variant == "single-scatter" && x.estimator == est && x.budget == budget)
        .map(|x| x.rmse)
}

/// The ids that ran on `tb` at `budget`, best (smallest RMSE) first.
pub fn ranking(r: &RunReport, tb: &str, budget: u64) -> Vec<(&'static str, f64)> {
    let mut v: Vec<(&'static str, f64)> =
        IDS.iter().filter_map(|id| rmse(r, tb, id, budget).map(|e| (*id, e))).collect();
    v.sort_by(|a, b| a.1.total_cmp(&b.1));
    v
}

fn rank_of(order: &[(&str, f64)], id: &str) -> Option<usize> {
    order.iter().position(|(i, _)| *i == id).map(|p| p + 1)
}

fn claims(r: &RunReport) -> Vec<Claim> {
    let mut out = Vec::new();
    for tb in ["eq21-medium", "perlin-medium"] {
        for budget in PAPER_BUDGETS {
            let all = ranking(r, tb, budget);
            if all.is_empty() {
                continue;
            }
            let unbiased: Vec<(&str, f64)> = all.iter().copied().filter(|(id, _)| *id != "ray_marching").collect();
            let listed = all.iter().map(|(id, e)| format!("{id} {e:.3e}")).collect::<Vec<_>>().join(" < ");
            let testbed = format!("{tb}/single-scatter");
            let mis = rank_of(&unbiased, "mis");
            let others = unbiased.iter().filter(|(id, _)| *id != "mis").map(|x| x.1).fold(f64::INFINITY, f64::min);
            let mis_ratio = rmse(r, tb, "mis", budget).map(|m| m / others);
            out.push(Claim {
                testbed: testbed.clone(),
                claim: format!("paper 002 Fig. 12: at ~{budget} fetches per pixel MIS (source + scattering-driven) has the lowest error of the unbiased methods (rank, 1 = best)"),
                paper_value: Some(1.0),
                our_value: mis.map(|m| m as f64),
                held: mis.map(|m| m == 1),
                note: format!(
                    "RMSE of MIS / best other unbiased {}; RMSE, best first: {listed}",
                    mis_ratio.map_or("-".into(), |x| format!("{x:.3}"))
                ),
                ..Default::default()
            });
            let (src, sct) = (rank_of(&unbiased, "source_driven"), rank_of(&unbiased, "scattering_driven"));
            let worse = src.zip(sct).map(|(a, b)| a.max(b));
            out.push(Claim {
                testbed: testbed.clone(),
                claim: format!("paper 002 Fig. 12: at ~{budget} fetches scattering- and source-driven sampling come next (both within the best 3 of the unbiased methods; worse rank of the two)"),
                paper_value: Some(3.0),
                our_value: worse.map(|w| w as f64),
                held: worse.map(|w| w <= 3),
                note: format!(
                    "ranks among the {} unbiased: source-driven {}, scattering-driven {}",
                    unbiased.len(),
                    src.map_or("-".into(), |r| r.to_string()),
                    sct.map_or("-".into(), |r| r.to_string())
                ),
                ..Default::default()
            });
            let new = ["source_driven", "scattering_driven", "mis"]
                .iter()
                .filter_map(|id| rmse(r, tb, id, budget))
                .fold(f64::INFINITY, f64::min);
            for (marcher, what) in
                [("ray_marching", "jittered offsets"), (NOISE_FREE, "offsets 1/2, noise free as the paper's")]
            {
                let ratio = rmse(r, tb, marcher, budget).map(|m| m / new).filter(|x| x.is_finite());
                out.push(Claim {
                    testbed: testbed.clone(),
                    claim: format!("paper 002 Fig. 12: at ~{budget} fetches the new methods (best of source-driven, scattering-driven, MIS) have lower error than ray marching, {marcher} ({what}; RMSE ratio marching / best new)"),
                    paper_value: (budget == 300).then_some(104.0 / 52.0),
                    our_value: ratio,
                    held: ratio.map(|x| x > 1.0),
                    note: "one primary ray spends the budget; its RMSE includes its bias; the paper's ratio is from its ~300-fetch row".into(),
                    ..Default::default()
                });
            }
            let wood = rank_of(&all, "delta_tracking");
            out.push(Claim {
                testbed: testbed.clone(),
                claim: format!("paper 002 Fig. 12: at ~{budget} fetches Woodcock (delta) tracking has the highest error of all methods (rank of {})", all.len()),
                paper_value: Some(all.len() as f64),
                our_value: wood.map(|w| w as f64),
                held: wood.map(|w| w == all.len()),
                note: "paper at ~300: ray marching 104, Woodcock 128, attenuation-driven 114, SIR 72, source-driven 54, scattering-driven 52 (MIS's number is lost in the text extraction; the text calls MIS the winner)".into(),
                ..Default::default()
            });
        }
    }
    if let (Some(w), Some(s)) =
        (rmse(r, "eq21-medium", "delta_tracking", 300), rmse(r, "eq21-medium", "scattering_driven", 300))
    {
        out.push(Claim {
            testbed: "eq21-medium/single-scatter".into(),
            claim: "paper 002 Fig. 12 (~300 fetches): Err ratio Woodcock / scattering-driven".into(),
            paper_value: Some(128.0 / 52.0),
            our_value: Some(w / s),
            held: Some(w / s > 1.0),
            note: "held if Woodcock's RMSE is the larger (the factor depends on the scene's light and image scale)"
                .into(),
            ..Default::default()
        });
    }
    out.push(claims::control_flagged(r, CONTROL));
    out
}
