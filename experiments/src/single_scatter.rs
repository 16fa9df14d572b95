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
use mcbench::claims::{self, RatioMetric, RatioSpec};
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
pub static DEF: ExperimentDef = ExperimentDef {
    toml: include_str!("single_scatter.toml"),
    claims: Some(claims),
    post: Some(crate::single_scatter_post::post),
};

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

/// A ratio claim between two methods on `testbed` (single-scatter variant) at `budget`.
fn judged(
    r: &RunReport,
    (tb, budget): (&str, u64),
    (a, b): (&str, &str),
    below: bool,
    claim: String,
    note: &str,
) -> Claim {
    let spec = RatioSpec {
        tb: (tb, "single-scatter"),
        estimator: a,
        baseline: b,
        budget,
        metric: RatioMetric::Rmse,
        threshold: 1.0,
        above: !below,
        paper: None,
    };
    claims::ratio_claim(r, &spec, &claim, note)
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
            let at = (tb, budget);
            // Orderings are judged between the method and the competitor the point estimates put
            // next to it, on the interval of their RMSE ratio.
            if let Some((best_other, _)) = unbiased.iter().find(|(id, _)| *id != "mis") {
                out.push(judged(
                    r,
                    at,
                    ("mis", best_other),
                    true,
                    format!("paper 002 Fig. 12: at ~{budget} fetches per pixel MIS (source + scattering-driven) has the lowest error of the unbiased methods (RMSE ratio MIS / best other unbiased, below 1)"),
                    &format!("RMSE, best first: {listed}"),
                ));
            }
            let pair = ["source_driven", "scattering_driven"];
            let worse = pair.iter().filter_map(|id| all.iter().find(|x| x.0 == *id)).max_by(|a, b| a.1.total_cmp(&b.1));
            let rest: Vec<&(&str, f64)> = unbiased.iter().filter(|(id, _)| !pair.contains(id)).collect();
            if let (Some((w, _)), Some((second, _))) = (worse, rest.get(1)) {
                out.push(judged(
                    r,
                    at,
                    (w, second),
                    true,
                    format!("paper 002 Fig. 12: at ~{budget} fetches scattering- and source-driven sampling come next (both within the best 3 of the unbiased methods: RMSE ratio of the worse of the two / the second best other method, below 1)"),
                    "",
                ));
            }
            let new = ["source_driven", "scattering_driven", "mis"]
                .iter()
                .filter_map(|id| rmse(r, tb, id, budget).map(|e| (*id, e)))
                .min_by(|a, b| a.1.total_cmp(&b.1));
            for (marcher, what) in
                [("ray_marching", "jittered offsets"), (NOISE_FREE, "offsets 1/2, noise free as the paper's")]
            {
                let Some((best_new, _)) = new else { continue };
                let mut c = judged(
                    r,
                    at,
                    (marcher, best_new),
                    false,
                    format!("paper 002 Fig. 12: at ~{budget} fetches the new methods (best of source-driven, scattering-driven, MIS) have lower error than ray marching, {marcher} ({what}; RMSE ratio marching / best new, above 1)"),
                    "one primary ray spends the budget; its RMSE includes its bias; the paper's ratio is from its ~300-fetch row",
                );
                c.paper_value = (budget == 300).then_some(104.0 / 52.0);
                out.push(c);
            }
            let worst_other = all.iter().filter(|(id, _)| *id != "delta_tracking").max_by(|a, b| a.1.total_cmp(&b.1));
            if let Some((w, _)) = worst_other {
                out.push(judged(
                    r,
                    at,
                    ("delta_tracking", w),
                    false,
                    format!("paper 002 Fig. 12: at ~{budget} fetches Woodcock (delta) tracking has the highest error of all methods (RMSE ratio Woodcock / the worst other, above 1)"),
                    "paper at ~300: ray marching 104, Woodcock 128, attenuation-driven 114, SIR 72, source-driven 54, scattering-driven 52 (MIS's number is lost in the text extraction; the text calls MIS the winner)",
                ));
            }
        }
    }
    let mut c = judged(
        r,
        ("eq21-medium", 300),
        ("delta_tracking", "scattering_driven"),
        false,
        "paper 002 Fig. 12 (~300 fetches): Err ratio Woodcock / scattering-driven".into(),
        "held if Woodcock's RMSE is the larger (the factor depends on the scene's light and image scale)",
    );
    c.paper_value = Some(128.0 / 52.0);
    out.push(c);
    out.push(claims::control_flagged(r, CONTROL));
    out
}
