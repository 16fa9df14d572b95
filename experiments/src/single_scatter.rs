//! `single-scatter` (paper 002 Fig. 12, §4.3): point-light single scattering in the Eq. 21 medium
//! (and the Perlin medium at its reduced 4x4 resolution), every method at equal fetch budgets of
//! about 50 and 300 per pixel (plus 100 for the RMSE-vs-fetches plot; full mode adds 1000): ray
//! marching (biased control), Woodcock tracking, attenuation-driven, attenuation-driven SIR,
//! source-driven, scattering-driven and MIS, plus the paper's noise-free marcher
//! `ray_marching[jitter=0]` and the coarse ray-marching control `ray_marching[step=5]` for the
//! unbiasedness tests. The paper's ordering is claimed in `single_scatter.toml` (orderings and
//! optima judged on Bonferroni-adjusted RMSE-ratio intervals); the post hook writes the
//! equal-fetch table (primary rays the budget buys, shadow rays, fetches, RMSE, rank)
//! ([`crate::single_scatter_post`]).

use crate::ExperimentDef;
use mcbench::output::RunReport;

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
    claims: None,
    post: Some(crate::single_scatter_post::post),
};

/// The paper's "noise free but biased" marcher: one ray spending the budget, offsets fixed at 1/2.
pub const NOISE_FREE: &str = "ray_marching[jitter=0]";

/// The harness's biased control (book: statistics.md): ray marching with a coarse fixed step, which a
/// fetch budget buys several rays of. The Fig. 12 marcher (one ray spending the budget) is in the
/// ranking; its bias is far below what a quick run detects on the smooth Eq. 21 medium.
pub const CONTROL: &str = "ray_marching[step=5]";

/// RMSE of an estimator at a budget on a test bed (single-scatter variant).
pub fn rmse(r: &RunReport, tb: &str, est: &str, budget: u64) -> Option<f64> {
    r.query().testbed(tb).variant("single-scatter").estimator(est).at(budget).first().map(|x| x.rmse)
}

/// The ids that ran on `tb` at `budget`, best (smallest RMSE) first.
pub fn ranking(r: &RunReport, tb: &str, budget: u64) -> Vec<(&'static str, f64)> {
    let mut v: Vec<(&'static str, f64)> =
        IDS.iter().filter_map(|id| rmse(r, tb, id, budget).map(|e| (*id, e))).collect();
    v.sort_by(|a, b| a.1.total_cmp(&b.1));
    v
}
