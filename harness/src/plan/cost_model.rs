//! The cost model: what an estimate costs, in two regimes.
//!
//! The test beds are analytic: a ray or an extinction lookup costs a few nanoseconds of arithmetic,
//! where the renderers the papers ran in paid on the order of a hundred nanoseconds to a
//! microsecond for each. Equal-time comparisons measured in CPU time alone therefore price the
//! papers' methods differently from the papers. Every efficiency and speed-up is reported in two
//! regimes:
//!
//! - `measured`: the estimating thread's CPU seconds, nothing added;
//! - `renderer`: the CPU seconds plus each counted operation priced at a unit cost measured in a
//!   real renderer on a real scene (`docs/src/cost_model_source.md` says where the defaults come from).
//!
//! A sweep may set the unit costs in a `[cost_model]` table:
//!
//! ```toml
//! [cost_model]
//! ray_ns = 268.0          # one closest-hit segment: camera or free flight (default 91)
//! shadow_ray_ns = 59.0    # one shadow (any-hit) ray (default 41)
//! fetch_ns = 39.0         # one medium extinction lookup (default 4.6)
//! cheap_fetch_ns = 4.6    # one lookup of the approximate (cheap) extinction (default 4.6)
//! target_eval_ns = 0.0    # one evaluation of an adaptive sampler's target (default 0)
//! cache_op_ns = 0.0       # one radiance-cache read, record or refinement (default 0)
//! ```
//!
//! Target evaluations and cache operations are CPU work of the estimator itself, already in its
//! measured CPU seconds; their default price is 0 so that the `renderer` regime does not count
//! them twice. A non-zero price models a renderer where they cost more than here (a target with a
//! measured BRDF, a cache whose cells miss the processor's caches).

use crate::analysis::metrics::SummaryRow;
use mcbench_core::error::ConfigError;
use serde::{Deserialize, Serialize};

/// Unit costs of counted operations, in nanoseconds of one CPU thread.
///
/// The defaults are Mitsuba 3.9 (`llvm_ad_rgb`, one thread, AMD EPYC) on its Cornell box: 91 ns
/// for a closest-hit ray with its hit record, 41 ns for a shadow ray, 4.6 ns for a trilinear
/// lookup in a 64³ grid volume;
/// the cheap approximate extinction is priced as a fetch (`docs/src/cost_model_source.md`, measured by
/// `scripts/peer/ray_cost.sh`). Heavier scenes cost more: 268 ns per ray at 10⁶ triangles, 39 ns
/// per fetch from a 256³ grid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CostModel {
    /// One traced segment that finds its closest hit (`rays` less `shadow_rays`: camera,
    /// incident-radiance and free-flight segments).
    pub ray_ns: f64,
    /// One shadow (any-hit visibility) ray (`shadow_rays`).
    pub shadow_ray_ns: f64,
    /// One medium extinction lookup (`fetches`).
    pub fetch_ns: f64,
    /// One lookup of the cheap approximate extinction (`cheap_fetches`).
    pub cheap_fetch_ns: f64,
    /// One evaluation of an adaptive sampler's target density (`target_evals`: paper 004's
    /// `p~`, paper 003's PMC population members), beyond the rays it traces. Default 0: the
    /// evaluation is CPU work already in `cpu_seconds`.
    pub target_eval_ns: f64,
    /// One radiance-cache operation (`cache_ops`: a read, a record or a refinement of papers 000
    /// and 001's caches). Default 0: the operation is CPU work already in `cpu_seconds`.
    pub cache_op_ns: f64,
}

/// Default unit cost of a traced ray, ns (see [`CostModel`]).
pub const RENDERER_RAY_NS: f64 = 91.0;
/// Default unit cost of a shadow ray, ns (see [`CostModel`]).
pub const RENDERER_SHADOW_RAY_NS: f64 = 41.0;
/// Default unit cost of an extinction lookup, ns (see [`CostModel`]).
pub const RENDERER_FETCH_NS: f64 = 4.6;
/// Default unit cost of a target evaluation, ns: 0, since its work is in the measured CPU seconds
/// (see [`CostModel`]).
pub const RENDERER_TARGET_EVAL_NS: f64 = 0.0;
/// Default unit cost of a radiance-cache operation, ns: 0, since its work is in the measured CPU
/// seconds (see [`CostModel`]).
pub const RENDERER_CACHE_OP_NS: f64 = 0.0;

impl Default for CostModel {
    fn default() -> Self {
        CostModel {
            ray_ns: RENDERER_RAY_NS,
            shadow_ray_ns: RENDERER_SHADOW_RAY_NS,
            fetch_ns: RENDERER_FETCH_NS,
            cheap_fetch_ns: RENDERER_FETCH_NS,
            target_eval_ns: RENDERER_TARGET_EVAL_NS,
            cache_op_ns: RENDERER_CACHE_OP_NS,
        }
    }
}

/// A cost regime: which costs an estimate's seconds include.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Regime {
    /// CPU seconds only.
    #[default]
    Measured,
    /// CPU seconds plus the counted operations at the [`CostModel`]'s unit costs.
    Renderer,
}

impl Regime {
    /// Both regimes, in report order.
    pub const ALL: [Regime; 2] = [Regime::Measured, Regime::Renderer];

    /// The regime's name in files.
    pub fn name(self) -> &'static str {
        match self {
            Regime::Measured => "measured",
            Regime::Renderer => "renderer",
        }
    }
}

impl CostModel {
    /// Refuses unit costs that are negative or not finite, naming the field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for (field, v) in [
            ("cost_model.ray_ns", self.ray_ns),
            ("cost_model.shadow_ray_ns", self.shadow_ray_ns),
            ("cost_model.fetch_ns", self.fetch_ns),
            ("cost_model.cheap_fetch_ns", self.cheap_fetch_ns),
            ("cost_model.target_eval_ns", self.target_eval_ns),
            ("cost_model.cache_op_ns", self.cache_op_ns),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ConfigError::invalid(field, v, "a unit cost must be a finite number of nanoseconds >= 0"));
            }
        }
        Ok(())
    }

    /// The priced seconds per estimate of the counted operations (no CPU time).
    pub fn priced_seconds(&self, row: &SummaryRow) -> f64 {
        let shadow = row.shadow_rays.min(row.rays);
        1e-9 * (self.ray_ns * (row.rays - shadow)
            + self.shadow_ray_ns * shadow
            + self.fetch_ns * row.fetches
            + self.cheap_fetch_ns * row.cheap_fetches
            + self.target_eval_ns * row.target_evals
            + self.cache_op_ns * row.cache_ops)
    }

    /// Seconds per estimate of `row` in `regime`.
    pub fn seconds(&self, regime: Regime, row: &SummaryRow) -> f64 {
        match regime {
            Regime::Measured => row.metric_seconds(),
            Regime::Renderer => row.metric_seconds() + self.priced_seconds(row),
        }
    }
}

/// A speed-up as a function of the cost of a ray, the other costs as measured:
/// `s(c) = sample_ratio · (t_b + c·r_b) / (t_m + c·r_m)` with `t` CPU seconds and `r` rays per
/// estimate of the baseline (`b`) and the method (`m`). It is monotone in `c`, from the measured
/// speed-up at `c = 0` to `sample_ratio · r_b / r_m` as rays dominate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCostCurve {
    /// Baseline samples needed for the method's error over the method's samples.
    pub sample_ratio: f64,
    /// (CPU seconds, rays) per estimate of the method.
    pub method: (f64, f64),
    /// (CPU seconds, rays) per estimate of the baseline.
    pub baseline: (f64, f64),
}

/// Where a [`RayCostCurve`] reaches a level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reach {
    /// At every ray cost (already at zero cost, and the limit stays on the same side).
    Always,
    /// Above this ray cost, ns (the curve rises through the level there).
    Above(f64),
    /// Below this ray cost, ns (the curve falls through the level there).
    Below(f64),
    /// At no ray cost.
    Never,
}

impl RayCostCurve {
    /// The speed-up at a ray cost of `ns` nanoseconds.
    pub fn at(&self, ns: f64) -> f64 {
        let c = ns * 1e-9;
        self.sample_ratio * (self.baseline.0 + c * self.baseline.1) / (self.method.0 + c * self.method.1)
    }

    /// The speed-up as rays get costly (NaN when the method traces no rays).
    pub fn limit(&self) -> f64 {
        if self.method.1 > 0.0 {
            self.sample_ratio * self.baseline.1 / self.method.1
        } else {
            f64::NAN
        }
    }

    /// The ray cost at which the speed-up reaches `level`, and on which side it stays there.
    pub fn reaching(&self, level: f64) -> Reach {
        let (s, (tm, rm), (tb, rb)) = (self.sample_ratio, self.method, self.baseline);
        if !(s.is_finite() && tm > 0.0 && tb > 0.0) {
            return Reach::Never;
        }
        let at_zero = self.at(0.0) >= level;
        // s (tb + c rb) = level (tm + c rm)  =>  c = (level tm - s tb) / (s rb - level rm).
        let den = s * rb - level * rm;
        let c = (level * tm - s * tb) / den;
        if den == 0.0 || !(c > 0.0 && c.is_finite()) {
            return if at_zero { Reach::Always } else { Reach::Never };
        }
        if at_zero {
            Reach::Below(c * 1e9)
        } else {
            Reach::Above(c * 1e9)
        }
    }

    /// Ray costs from 1 ns to 10 µs, `n` log-spaced points, with the speed-up at each.
    pub fn points(&self, n: usize) -> Vec<(f64, f64)> {
        let n = n.max(2);
        (0..n)
            .map(|i| {
                let ns = 10f64.powf(4.0 * i as f64 / (n - 1) as f64);
                (ns, self.at(ns))
            })
            .collect()
    }
}

impl Reach {
    /// The reach in words ("above 340 ns", "at every ray cost", "never").
    pub fn describe(&self) -> String {
        match self {
            Reach::Always => "at every ray cost".into(),
            Reach::Above(ns) => format!("for rays above {}", ns_text(*ns)),
            Reach::Below(ns) => format!("for rays below {}", ns_text(*ns)),
            Reach::Never => "at no ray cost".into(),
        }
    }

    /// The crossing cost in ns (0 for `Always`, NaN for `Never`).
    pub fn ns(&self) -> f64 {
        match self {
            Reach::Always => 0.0,
            Reach::Above(ns) | Reach::Below(ns) => *ns,
            Reach::Never => f64::NAN,
        }
    }
}

/// A duration in ns as text with a readable unit.
pub fn ns_text(ns: f64) -> String {
    if ns >= 1e6 {
        format!("{:.3} ms", ns / 1e6)
    } else if ns >= 1e3 {
        format!("{:.3} µs", ns / 1e3)
    } else {
        format!("{ns:.3} ns")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve() -> RayCostCurve {
        // 4x fewer samples; the method costs 3x the CPU of the baseline and traces the same rays.
        RayCostCurve { sample_ratio: 4.0, method: (3e-6, 10.0), baseline: (1e-6, 10.0) }
    }

    #[test]
    fn the_curve_runs_from_the_measured_speedup_to_the_sample_ratio() {
        let c = curve();
        assert!((c.at(0.0) - 4.0 / 3.0).abs() < 1e-12);
        assert!((c.limit() - 4.0).abs() < 1e-12);
        assert!((c.at(1e9) - 4.0).abs() < 1e-3);
        let pts = c.points(9);
        assert_eq!(pts.len(), 9);
        assert!((pts[0].0 - 1.0).abs() < 1e-12 && (pts[8].0 - 1e4).abs() < 1e-6);
        assert!(pts.windows(2).all(|w| w[1].1 > w[0].1), "monotone: {pts:?}");
    }

    #[test]
    fn reaching_solves_for_the_ray_cost() {
        let c = curve();
        // 4 (1e-6 + c 10) = 2 (3e-6 + c 10)  =>  c = 2e-6 / 20 = 1e-7 s = 100 ns.
        match c.reaching(2.0) {
            Reach::Above(ns) => assert!((ns - 100.0).abs() < 1e-9, "{ns}"),
            r => panic!("{r:?}"),
        }
        assert!((c.at(100.0) - 2.0).abs() < 1e-12);
        assert_eq!(c.reaching(1.0), Reach::Always);
        assert_eq!(c.reaching(5.0), Reach::Never);
        // A method that wins in CPU but traces more rays loses as rays get costly.
        let heavy = RayCostCurve { sample_ratio: 2.0, method: (1e-6, 40.0), baseline: (1e-6, 10.0) };
        assert!(matches!(heavy.reaching(1.0), Reach::Below(ns) if (heavy.at(ns) - 1.0).abs() < 1e-9));
        assert!((heavy.limit() - 0.5).abs() < 1e-12);
    }

    #[test]
    fn the_renderer_regime_prices_each_count_at_its_unit_cost() {
        let mut row = crate::output::plot::tests::synthetic_report().rows[0].clone();
        (row.cpu_seconds, row.rays, row.shadow_rays, row.fetches, row.cheap_fetches) = (1e-6, 10.0, 4.0, 100.0, 50.0);
        (row.target_evals, row.cache_ops) = (30.0, 20.0);
        let m = CostModel {
            ray_ns: 100.0,
            shadow_ray_ns: 40.0,
            fetch_ns: 5.0,
            cheap_fetch_ns: 1.0,
            target_eval_ns: 0.0,
            cache_op_ns: 0.0,
        };
        // 6 closest-hit rays, 4 shadow rays, 100 fetches, 50 cheap ones: 600 + 160 + 500 + 50 ns;
        // target evaluations and cache operations are free at their unit costs of 0.
        assert!((m.priced_seconds(&row) - 1.31e-6).abs() < 1e-18);
        assert_eq!(m.seconds(Regime::Measured, &row), 1e-6);
        assert!((m.seconds(Regime::Renderer, &row) - 2.31e-6).abs() < 1e-18);
        // Priced: 30 evaluations at 10 ns and 20 cache operations at 2 ns add 340 ns.
        let priced = CostModel { target_eval_ns: 10.0, cache_op_ns: 2.0, ..m };
        assert!((priced.priced_seconds(&row) - 1.65e-6).abs() < 1e-18);
    }

    #[test]
    fn target_evaluations_and_cache_operations_are_free_by_default() {
        let mut row = crate::output::plot::tests::synthetic_report().rows[0].clone();
        let before = CostModel::default().priced_seconds(&row);
        (row.target_evals, row.cache_ops) = (1e6, 1e6);
        assert_eq!(CostModel::default().priced_seconds(&row), before, "the defaults price them at 0");
        let parsed: CostModel = toml::from_str("target_eval_ns = 12.5\ncache_op_ns = 3.0").expect("parses");
        assert_eq!(parsed, CostModel { target_eval_ns: 12.5, cache_op_ns: 3.0, ..CostModel::default() });
    }

    #[test]
    fn bad_unit_costs_name_their_field() {
        let m = CostModel { fetch_ns: -1.0, ..CostModel::default() };
        let e = m.validate().expect_err("negative");
        assert!(e.to_string().contains("cost_model.fetch_ns"), "{e}");
        assert!(CostModel::default().validate().is_ok());
        for (m, field) in [
            (CostModel { shadow_ray_ns: -1.0, ..CostModel::default() }, "cost_model.shadow_ray_ns"),
            (CostModel { target_eval_ns: -0.5, ..CostModel::default() }, "cost_model.target_eval_ns"),
            (CostModel { target_eval_ns: f64::INFINITY, ..CostModel::default() }, "cost_model.target_eval_ns"),
            (CostModel { cache_op_ns: f64::NAN, ..CostModel::default() }, "cost_model.cache_op_ns"),
            (CostModel { cache_op_ns: -2.0, ..CostModel::default() }, "cost_model.cache_op_ns"),
        ] {
            let e = m.validate().expect_err(field);
            assert!(e.to_string().contains(field), "{e}");
        }
        let parsed: CostModel = toml::from_str("ray_ns = 500.0").expect("parses");
        assert_eq!(parsed, CostModel { ray_ns: 500.0, ..CostModel::default() });
        assert!(toml::from_str::<CostModel>("ray = 500.0").is_err());
    }
}
