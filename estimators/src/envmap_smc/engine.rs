//! The particle machinery shared by the paper 004 estimators: bidirectional importance sampling
//! (SIR, the first frame), the SMC reweight / resample / move step of Algorithm 1 (Eq. 3-4, 6-8),
//! the bridged step of Algorithm 2 (Eq. 11-12) with the standard ratio (Eq. 10) or path sampling
//! (Eq. 15-16) for `L_ns`, the adaptive bridge schedule, and the periodic re-estimate of `L_ns`
//! from scratch (paper 004 §7). Weights live in log space.
//!
//! Colour: the target is the channel mean `p~ = mean_c(L_c f_c cos)` (paper 004 §3); per-channel
//! estimates use `L_c = L_ns * E_p[(p~_c / p~) V]` (Eq. 9 per channel), which is the same estimator
//! when the channels agree.

use super::drift;
use super::mh::{MhKernel, State};
use super::resampling::{effective_sample_size, log_sum_exp, normalise_log_weights, resample, Scheme};
use mcbench_core::error::EstimateError;
use mcbench_core::math::{Rgb, Vec3};
use mcbench_core::rng::StreamRng;
use mcbench_core::task::{EnvProbe, Task};
use mcbench_core::testbed::EnvQuantity;

/// How `L_ns` is carried from frame to frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Transition {
    /// Algorithm 1: reweight by `p~_n / p~_{n-1}`, resample, then `moves` MH moves for `p~_n`.
    Single {
        /// MH moves per particle and frame (K).
        moves: usize,
    },
    /// Algorithm 2: `bridges` intermediate distributions, one MH move each; `path` selects the
    /// path-sampling estimate of `log(L_ns,n / L_ns,n-1)` (Eq. 15) over the standard ratio.
    Bridged {
        /// Number of intermediate distributions (P).
        bridges: usize,
        /// Path sampling (Eq. 15) instead of the ratio (Eq. 10).
        path: bool,
    },
    /// Beyond the paper: the next exponent chosen by bisection so the conditional ESS of the
    /// incremental weights is `cess * N` (Zhou, Johansen and Aston 2016), at most `max` bridges.
    Adaptive {
        /// Target conditional ESS as a share of N.
        cess: f64,
        /// Largest number of bridges per frame.
        max: usize,
    },
}

/// A configured SMC (or, with `smc: None`, independent bidirectional sampling every frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// Environment candidates M of the bidirectional (SIR) step.
    pub candidates: usize,
    /// The MH kernel.
    pub kernel: MhKernel,
    /// Resampling scheme.
    pub scheme: Scheme,
    /// Resample when ESS < threshold * N.
    pub threshold: f64,
    /// The frame-to-frame transition; `None` runs `bidirectional_is` on every frame.
    pub transition: Option<Transition>,
    /// Every `recompute` frames (frame indices divisible by it), `L_ns` is estimated afresh by
    /// bidirectional importance sampling with `candidates` M instead of carried forward as a
    /// product of ratios; the particles stay. 0: never.
    pub recompute: usize,
    /// The drift rule's threshold tau ([`super::drift`]): `L_ns` is estimated afresh from
    /// `recompute_candidates` candidates on any frame where the carried estimate is more than a
    /// factor `e^tau` from the last one computed explicitly. 0: never.
    pub drift: f64,
    /// Environment-map candidates M of a re-estimate the drift rule calls for.
    pub recompute_candidates: usize,
}

/// Weighted particles approximating `p_n`, with `log L_ns,n` (the normaliser estimate).
struct Population {
    w: Vec<Vec3>,
    t: Vec<Rgb>,
    log_w: Vec<f64>,
    log_z: f64,
    /// `log L_ns` as last computed explicitly (bidirectionally, at the start or at a re-estimate):
    /// the drift rule's reference.
    log_ref: f64,
}

fn ln(x: f64) -> f64 {
    if x > 0.0 {
        x.ln()
    } else {
        f64::NEG_INFINITY
    }
}

/// `(1 - g) ln a + g ln b` with the end points exact (no `0 * -inf`).
fn bridge_log(g: f64, la: f64, lb: f64) -> f64 {
    if g <= 0.0 {
        la
    } else if g >= 1.0 {
        lb
    } else if la == f64::NEG_INFINITY || lb == f64::NEG_INFINITY {
        f64::NEG_INFINITY
    } else {
        (1.0 - g) * la + g * lb
    }
}

/// The number of particles N: the sample budget.
pub fn particles(task: &Task<'_>) -> Result<usize, EstimateError> {
    let b = task.budget();
    if b.kind != mcbench_core::budget::BudgetKind::Samples {
        return Err(EstimateError::Refused(
            "paper 004 estimators take a sample budget: N particles per pixel and frame".into(),
        ));
    }
    Ok(b.amount.min(1 << 20) as usize)
}

fn probe<'a>(task: &'a Task<'a>) -> Result<EnvProbe<'a>, EstimateError> {
    task.env_sequence().ok_or_else(|| EstimateError::Refused("the test bed has no environment sequence".into()))
}

/// Bidirectional importance sampling (Burke et al. 2005, SIR): M candidates from the environment
/// map weighted `p~ / q`, N resampled multinomially. Returns the population (equal weights, with
/// the unbiased `L_ns` estimate `mean(p~ / q)` as its normaliser) and the Rao-Blackwellised
/// per-channel `L_ns` estimate `mean(p~_c / q)`; `None` when every candidate weight is zero.
fn bidirectional(probe: &EnvProbe<'_>, n: usize, m: usize, rng: &mut StreamRng) -> (Option<Population>, Rgb) {
    let (cand, targets, log_w, lns) = candidates(probe, m, rng);
    let Some((weights, lse)) = normalise_log_weights(&log_w) else {
        return (None, lns);
    };
    let idx = resample(Scheme::Multinomial, &weights, n, rng);
    let log_z = lse - (m as f64).ln();
    let pop = Population {
        w: idx.iter().map(|&i| cand[i]).collect(),
        t: idx.iter().map(|&i| targets[i]).collect(),
        log_w: vec![-(n as f64).ln(); n],
        log_z,
        log_ref: log_z,
    };
    (Some(pop), lns)
}

/// M candidates from the environment map with their targets `p~`, log weights `ln(p~ / q)` and
/// the per-channel estimate `mean(p~_c / q)` of `L_ns`.
#[allow(clippy::type_complexity)]
pub(super) fn candidates(probe: &EnvProbe<'_>, m: usize, rng: &mut StreamRng) -> (Vec<Vec3>, Vec<Rgb>, Vec<f64>, Rgb) {
    let (mut cand, mut targets, mut log_w) = (Vec::with_capacity(m), Vec::with_capacity(m), Vec::with_capacity(m));
    let mut lns = Rgb::ZERO;
    for _ in 0..m {
        let s = probe.sample_environment(rng);
        let t = probe.target(s.w);
        // The sampler reports pdf > 0 for every direction it draws.
        lns += t / s.pdf;
        log_w.push(ln(t.mean()) - s.pdf.ln());
        cand.push(s.w);
        targets.push(t);
    }
    (cand, targets, log_w, lns / m as f64)
}

/// Eq. 9 per channel: `L_ns * sum_j W_j (p~_c / p~)(w_j) [V(w_j)]` (one ray per particle with
/// non-zero weight for `L_r`).
fn estimate(pop: &Population, probe: &EnvProbe<'_>) -> Rgb {
    let Some((weights, _)) = normalise_log_weights(&pop.log_w) else {
        return Rgb::ZERO;
    };
    let with_v = probe.quantity() == EnvQuantity::Reflected;
    let mut sum = Rgb::ZERO;
    for ((w, t), wj) in pop.w.iter().zip(&pop.t).zip(&weights) {
        let s = t.mean();
        if *wj == 0.0 || s <= 0.0 || (with_v && !probe.visible(*w)) {
            continue;
        }
        sum += *t * (wj / s);
    }
    sum * pop.log_z.exp()
}

/// Runs a configured estimator over the frames of one pixel.
pub fn run_sequence(cfg: &Config, tasks: &[Task<'_>], rng: &mut StreamRng) -> Result<Vec<Rgb>, EstimateError> {
    let mut out = Vec::with_capacity(tasks.len());
    let mut pop: Option<Population> = None;
    for task in tasks {
        let n = particles(task)?;
        let probe = probe(task)?;
        let carried = match (cfg.transition, pop.take()) {
            (Some(tr), Some(p)) if probe.frame() > 0 => transition(cfg, tr, p, &probe, n, rng),
            _ => None,
        };
        let estimate_now = match carried {
            Some(mut p) => {
                if let Some(m) = drift::re_estimate(cfg, probe.frame(), p.log_z, p.log_ref) {
                    p.log_z = drift::recomputed_log_normaliser(&probe, m, rng);
                    p.log_ref = p.log_z;
                    probe.note("recomputed", 1.0);
                }
                let e = estimate(&p, &probe);
                pop = Some(p);
                e
            }
            None => {
                if cfg.transition.is_some() && probe.frame() > 0 {
                    task.note("fallback", 1.0);
                }
                let (p, lns) = bidirectional(&probe, n, cfg.candidates, rng);
                let e = match (&p, probe.quantity()) {
                    (_, EnvQuantity::Unoccluded) if cfg.transition.is_none() => lns,
                    (Some(p), _) => estimate(p, &probe),
                    (None, _) => Rgb::ZERO,
                };
                pop = p;
                e
            }
        };
        out.push(estimate_now);
    }
    Ok(out)
}

/// One frame of SMC; `None` when every incremental weight is zero (the caller falls back).
fn transition(
    cfg: &Config,
    tr: Transition,
    mut pop: Population,
    probe: &EnvProbe<'_>,
    n: usize,
    rng: &mut StreamRng,
) -> Option<Population> {
    let frame = probe.frame();
    let env = probe.environment_frame();
    // p~_n at the carried particles (Eq. 3): one sample each.
    let cur: Vec<Rgb> = pop.w.iter().map(|w| probe.target(*w)).collect();
    let ratio: Vec<f64> = pop
        .t
        .iter()
        .zip(&cur)
        .map(|(p, c)| ln(c.mean()) - ln(p.mean()))
        .map(|r| if r.is_nan() { f64::NEG_INFINITY } else { r })
        .collect();
    let mut states: Vec<State<(Rgb, Rgb)>> = pop
        .w
        .iter()
        .zip(pop.t.iter().zip(&cur))
        .map(|(w, (p, c))| State { w: *w, log_target: ln(p.mean()), payload: (*p, *c) })
        .collect();
    let mut log_acc = vec![0.0; pop.w.len()];
    let mut path_log = 0.0;
    let mut bridges = 0usize;
    match tr {
        Transition::Single { .. } => {
            for (a, r) in log_acc.iter_mut().zip(&ratio) {
                *a = *r;
            }
        }
        Transition::Bridged { .. } | Transition::Adaptive { .. } => {
            let mut g = 0.0;
            while g < 1.0 {
                let next = match tr {
                    Transition::Bridged { bridges: p, .. } => ((bridges + 1) as f64 / p as f64).min(1.0),
                    Transition::Adaptive { cess, max } => {
                        next_exponent(g, &pop.log_w, &log_acc, &states, cess, max, bridges)
                    }
                    Transition::Single { .. } => 1.0,
                };
                // Eq. 12: w~^k = p~^{g'} / p~^{g} at the current states.
                for (a, s) in log_acc.iter_mut().zip(&states) {
                    let r = ln(s.payload.1.mean()) - ln(s.payload.0.mean());
                    *a += if r.is_nan() {
                        f64::NEG_INFINITY
                    } else if r == 0.0 {
                        0.0
                    } else {
                        (next - g) * r
                    };
                }
                // One MH move for the intermediate target (Eq. 11): both frames at the proposal.
                let mut eval = |w: Vec3| {
                    let (p, c) = (probe.target_in_frame(frame - 1, w), probe.target(w));
                    (bridge_log(next, ln(p.mean()), ln(c.mean())), (p, c))
                };
                for (s, a) in states.iter_mut().zip(&log_acc) {
                    if *a > f64::NEG_INFINITY {
                        s.log_target = bridge_log(next, ln(s.payload.0.mean()), ln(s.payload.1.mean()));
                        cfg.kernel.step(s, &env, rng, &mut eval);
                    }
                }
                if let Transition::Bridged { path: true, .. } = tr {
                    // Eq. 15: (g' - g) * sum_j W^k_j log(p~_n / p~_{n-1})(w^k_j).
                    let weights = normalise_log_weights(&combine(&pop.log_w, &log_acc))?;
                    let mut e = 0.0;
                    for (wj, s) in weights.0.iter().zip(&states) {
                        if *wj > 0.0 {
                            e += wj * (ln(s.payload.1.mean()) - ln(s.payload.0.mean()));
                        }
                    }
                    if !e.is_finite() {
                        return None;
                    }
                    path_log += (next - g) * e;
                }
                bridges += 1;
                g = next;
            }
            probe.note("bridges", bridges as f64);
        }
    }
    // Eq. 4 and Eq. 10 in log space: log(L_n / L_{n-1}) = log sum_j W_{n-1,j} w~_j.
    let lw = combine(&pop.log_w, &log_acc);
    let lse = log_sum_exp(&lw);
    if lse == f64::NEG_INFINITY || lse.is_nan() {
        return None;
    }
    let (weights, _) = normalise_log_weights(&lw)?;
    pop.log_z += if let Transition::Bridged { path: true, .. } = tr { path_log } else { lse };
    pop.log_w = weights.iter().map(|w| ln(*w)).collect();
    pop.w = states.iter().map(|s| s.w).collect();
    pop.t = states.iter().map(|s| s.payload.1).collect();
    let ess = effective_sample_size(&pop.log_w);
    probe.note("ess", ess);
    let resampled = ess < cfg.threshold * n as f64;
    probe.note("resampled", if resampled { 1.0 } else { 0.0 });
    if resampled {
        let idx = resample(cfg.scheme, &weights, n, rng);
        pop.w = idx.iter().map(|&i| pop.w[i]).collect();
        pop.t = idx.iter().map(|&i| pop.t[i]).collect();
        pop.log_w = vec![-(n as f64).ln(); n];
    }
    if let Transition::Single { moves } = tr {
        let mut eval = |w: Vec3| {
            let c = probe.target(w);
            (ln(c.mean()), c)
        };
        for (j, (w, t)) in pop.w.iter_mut().zip(pop.t.iter_mut()).enumerate() {
            if pop.log_w[j] == f64::NEG_INFINITY {
                continue;
            }
            let mut s = State { w: *w, log_target: ln(t.mean()), payload: *t };
            for _ in 0..moves {
                cfg.kernel.step(&mut s, &env, rng, &mut eval);
            }
            *w = s.w;
            *t = s.payload;
        }
    }
    Some(pop)
}

/// `log W_{n-1} + log w~` per particle; a particle of zero weight stays at zero whatever its
/// incremental weight (no `-inf + inf`).
fn combine(log_w: &[f64], log_acc: &[f64]) -> Vec<f64> {
    log_w
        .iter()
        .zip(log_acc)
        .map(|(a, b)| if *a == f64::NEG_INFINITY || b.is_nan() { f64::NEG_INFINITY } else { a + b })
        .collect()
}

/// The next bridge exponent: the largest `g' <= 1` whose incremental weights keep the conditional
/// ESS `(sum W u)^2 / sum W u^2` at `cess` (bisection in log space); jumps to 1 once that is within
/// reach or after `max - 1` bridges.
fn next_exponent(
    g: f64,
    log_w: &[f64],
    log_acc: &[f64],
    states: &[State<(Rgb, Rgb)>],
    cess: f64,
    max: usize,
    done: usize,
) -> f64 {
    let base = combine(log_w, log_acc);
    let r: Vec<f64> = states.iter().map(|s| ln(s.payload.1.mean()) - ln(s.payload.0.mean())).collect();
    let ratio_of = |d: f64| {
        let one: Vec<f64> = base
            .iter()
            .zip(&r)
            .map(|(b, r)| if *b == f64::NEG_INFINITY || r.is_nan() { f64::NEG_INFINITY } else { b + d * r })
            .collect();
        let two: Vec<f64> = base
            .iter()
            .zip(&r)
            .map(|(b, r)| if *b == f64::NEG_INFINITY || r.is_nan() { f64::NEG_INFINITY } else { b + 2.0 * d * r })
            .collect();
        let (a, b2) = (log_sum_exp(&one), log_sum_exp(&two));
        let lb = log_sum_exp(&base);
        // CESS / N with normalised W: exp(2 a - b2 - lb).
        if a == f64::NEG_INFINITY {
            0.0
        } else {
            (2.0 * a - b2 - lb).exp()
        }
    };
    if done + 1 >= max || ratio_of(1.0 - g) >= cess {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0, 1.0 - g);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if ratio_of(mid) >= cess {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (g + lo.max(1e-6)).min(1.0)
}
