//! `mis`: the paper 003 baseline (§5, Table 2): multiple importance sampling (Veach 1997) with one
//! BRDF sample and one light sample per round (the light chosen with probability proportional to
//! its power, a uniform point on it), combined with the balance heuristic (`power` = 2 selects the
//! power heuristic). A round's estimate is `f(x_b) w_b(x_b) / p_b(x_b) + f(x_l) w_l(x_l) / p_l(x_l)`;
//! an odd budget ends with a BRDF-only round `f / p_b`. The estimate averages the rounds. On
//! point-light single scattering in a medium the same id is paper 002's MIS
//! ([`crate::single_scatter::mis`]).

use crate::error::{ConfigError, EstimateError};
use crate::estimator::{Bias, Estimator};
use crate::lighting::RectLight;
use crate::math::{Rgb, Vec3};
use crate::registry::EstimatorEntry;
use crate::rng::StreamRng;
use crate::samplers::mixture::pick;
use crate::samplers::rect_light;
use crate::task::{HemisphereProbe, Task};
use crate::testbed::Needs;

/// Registry entry.
pub static ENTRY: EstimatorEntry = EstimatorEntry {
    id: "mis",
    paper: "003",
    label: "MIS",
    bias: Bias::Unbiased,
    needs: Needs::NONE,
    summary: "one BRDF + one light sample per round, balance heuristic (power = 2: power heuristic); on point-light single scattering (paper 002), source- + scattering-driven points, balance heuristic",
    build: |p| {
        crate::single_scatter::SingleScatterOr::build(
            "mis",
            p,
            (&["power"], |p| {
                let power = p.f64("power", 1.0)?;
                if power != 1.0 && power != 2.0 {
                    return Err(ConfigError::invalid("mis.power", power, "must be 1 (balance) or 2 (power heuristic)"));
                }
                Ok(Box::new(Mis { power }))
            }),
            (crate::single_scatter::mis::PARAMS, |p| Ok(Box::new(crate::single_scatter::mis::MisScatter::from_params(p)?))),
        )
    },
};

/// The estimator.
pub struct Mis {
    /// Heuristic exponent: 1 balance, 2 power.
    pub power: f64,
}

/// Light selection probabilities proportional to power (radiance x area).
pub fn light_selection(lights: &[RectLight]) -> Vec<f64> {
    let w: Vec<f64> = lights.iter().map(|l| l.radiance.mean() * l.area()).collect();
    let t: f64 = w.iter().sum();
    w.iter().map(|x| x / t).collect()
}

/// The density of the light strategy at `w`: `sum_j P_j pdf_j(w)`.
pub fn light_pdf(lights: &[RectLight], select: &[f64], x: Vec3, w: Vec3) -> f64 {
    lights.iter().zip(select).map(|(l, s)| s * rect_light::pdf(l, x, w)).sum()
}

impl Mis {
    fn weight(&self, a: f64, b: f64) -> f64 {
        // The MIS weight of a strategy with density `a` against one with `b`, divided by `a`.
        if self.power == 1.0 {
            1.0 / (a + b)
        } else {
            a / (a * a + b * b)
        }
    }

    /// One round: a BRDF sample and (when `light` is set) a light sample.
    pub fn round(&self, probe: &HemisphereProbe<'_>, select: &[f64], light: bool, rng: &mut StreamRng) -> Rgb {
        let p = *probe.point();
        let lights = probe.lights();
        let b = p.brdf.sample(p.wo, p.normal, rng);
        let fb = probe.integrand(b.w);
        if !light {
            return if b.pdf > 0.0 { fb / b.pdf } else { Rgb::ZERO };
        }
        let mut est = fb * self.weight(b.pdf, light_pdf(lights, select, p.position, b.w));
        let j = pick(select, rng);
        let ls = rect_light::sample(&lights[j], p.position, rng);
        let fl = probe.integrand(ls.w);
        let pl = light_pdf(lights, select, p.position, ls.w);
        if pl > 0.0 {
            est += fl * self.weight(pl, p.brdf.pdf(ls.w, p.wo, p.normal));
        }
        est
    }
}

impl Estimator for Mis {
    fn estimate(&self, task: &Task<'_>, rng: &mut StreamRng) -> Result<Rgb, EstimateError> {
        let probe = task.hemisphere().ok_or_else(|| EstimateError::Refused("mis needs a surface".into()))?;
        if probe.lights().is_empty() {
            return Err(EstimateError::Refused("mis needs area lights".into()));
        }
        let select = light_selection(probe.lights());
        let (mut sum, mut rounds) = (Rgb::ZERO, 0u64);
        let budget = task.budget();
        while task.more() {
            let left = match budget.kind {
                crate::budget::BudgetKind::Samples => budget.amount - task.costs().samples,
                _ => 2,
            };
            sum += self.round(&probe, &select, left >= 2, rng);
            rounds += 1;
        }
        Ok(if rounds > 0 { sum / rounds as f64 } else { Rgb::ZERO })
    }
    fn supports(&self, bed: &dyn crate::testbed::TestBed) -> Result<(), String> {
        match bed.hemisphere() {
            Some(h) if !h.lights().is_empty() => Ok(()),
            _ => Err("mis needs a surface with area lights (paper 003) or point-light single scattering in a medium (paper 002)".into()),
        }
    }
}
