//! Unit tests of the round-based repetitions: the level of a look under continuous monitoring, the
//! first round's size, when a row stays open, and cells grown round by round against cells run
//! whole.

use super::*;
use crate::analysis::TestRow;
use crate::config::Mode;
use crate::registry::Registry;
use mcbench_core::stats::{t_test, Moments};
use rand::Rng;

/// Whether a run of normal observations of mean 0, looked at `LOOKS` times at doubling counts
/// from `n0`, is ever flagged by a two-sided t-test at level `level`.
fn ever_flagged(rng: &mut impl Rng, n0: usize, level: f64) -> bool {
    let mut m = Moments::default();
    let mut n = n0;
    for _ in 0..LOOKS {
        while (m.count() as usize) < n {
            // Box-Muller.
            let (u, v): (f64, f64) = (rng.gen::<f64>().max(1e-300), rng.gen());
            m.push((-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos());
        }
        let se = (m.variance() / m.count() as f64).sqrt();
        if t_test(m.mean(), se, m.count() as f64 - 1.0).p_value < level {
            return true;
        }
        n *= 2;
    }
    false
}

#[test]
fn looks_at_their_share_of_alpha_keep_the_false_flags_under_continuous_monitoring() {
    // The rule at a level large enough to measure with a few thousand runs: each look at
    // alpha / LOOKS. A plain t at alpha on every look flags a correct row far more often.
    let alpha = 0.05;
    let trials = 3000;
    let mut rng = mcbench_core::rng::StreamKey {
        seed: 7,
        testbed: "rounds",
        estimator: "monitoring",
        budget: 0,
        rep: 0,
        integral: 0,
    }
    .rng();
    let (mut shared, mut plain) = (0usize, 0usize);
    for _ in 0..trials {
        shared += usize::from(ever_flagged(&mut rng, 16, alpha / LOOKS as f64));
        plain += usize::from(ever_flagged(&mut rng, 16, alpha));
    }
    let (shared, plain) = (shared as f64 / trials as f64, plain as f64 / trials as f64);
    assert!(shared <= alpha, "looks at alpha/LOOKS flag {shared} > {alpha}");
    // The plain boundary's false flags exceed alpha by many standard errors (sd ~0.004 here).
    assert!(plain > alpha + 0.03, "a plain t at every look flags only {plain}: the test could not tell them apart");
    assert!((look_alpha() * LOOKS as f64 - crate::analysis::UNBIASEDNESS_ALPHA).abs() < 1e-18);
}

#[test]
fn first_rounds_are_a_quarter_in_whole_blocks_and_at_least_the_minimum() {
    assert_eq!(first_round(256), MIN_FIRST_REPS);
    assert_eq!(first_round(512), 128);
    assert_eq!(first_round(1500), 384);
    assert_eq!(first_round(16_384), 4096);
    assert_eq!(first_round(2), MIN_FIRST_REPS);
    assert!([100, 1000, 4097].iter().all(|&r| first_round(r).is_multiple_of(REP_BLOCK)));
}

fn combined(verdict: &str, reps_needed: Option<f64>) -> Vec<TestRow> {
    vec![TestRow { test: "combined".into(), verdict: verdict.into(), reps_needed, ..Default::default() }]
}

#[test]
fn a_row_stays_open_only_while_another_look_could_decide_it() {
    let open = combined("inconclusive", Some(500.0));
    assert!(stays_open(&open, 64, 1, true));
    assert!(!stays_open(&open, 64, LOOKS, true), "no look left");
    assert!(!stays_open(&open, 64, 1, false), "a row that cannot pass");
    assert!(!stays_open(&combined("pass", None), 64, 1, true));
    assert!(!stays_open(&combined("biased", None), 64, 1, true));
    assert!(!stays_open(&combined("inconclusive", None), 64, 1, true), "no repetitions resolve it");
    // At look 4 of 5 with 512 repetitions, one more look reaches 1024.
    assert!(stays_open(&combined("inconclusive", Some(1024.0)), 512, 4, true));
    assert!(!stays_open(&combined("inconclusive", Some(1025.0)), 512, 4, true), "beyond the last look");
}

/// A small plan: the first part's first test bed with two of its estimators at `reps`.
fn small_plan(registry: &Registry, reps: usize, seed: u64) -> Plan {
    let mut sweep = crate::unbiasedness::parts(registry, Mode::Quick).swap_remove(0).sweep;
    sweep.testbeds.truncate(1);
    sweep.estimators.truncate(2);
    sweep.reps = reps;
    sweep.seed = seed;
    Plan::prepare(sweep, registry).expect("plan")
}

/// Grows the cells of a plan at `reps` for `rounds` rounds on `threads` threads (every row kept
/// open), returning the grown cells.
fn grown(registry: &Registry, reps: usize, rounds: usize, threads: usize) -> Vec<CellResult> {
    let (plan, pilot_plan) = (small_plan(registry, reps, 1), small_plan(registry, reps, 2));
    let cells = crate::run::runner::run(
        &plan,
        &crate::run::runner::RunOptions { threads: Some(threads), store: None, observer: &crate::run::runner::Silent },
    )
    .expect("run");
    let pilots = crate::run::runner::run(
        &pilot_plan,
        &crate::run::runner::RunOptions { threads: Some(threads), store: None, observer: &crate::run::runner::Silent },
    )
    .expect("pilot");
    let mut entries: Vec<Entry<'_>> = cells
        .cells
        .iter()
        .zip(&pilots.cells)
        .map(|((bi, ei, c), (_, _, p))| Entry {
            plan: &plan,
            pilot_plan: &pilot_plan,
            bi: *bi,
            ei: *ei,
            fixed: reps,
            cell: c.clone(),
            pilot: p.clone(),
            looks: 1,
            open: true,
        })
        .collect();
    let budget = entries.iter().map(Entry::spent).sum::<u64>() << rounds;
    let ran = grow(&mut entries, budget, threads, |e| {
        e.open = e.looks <= rounds;
        Ok(())
    })
    .expect("grow");
    assert_eq!(ran, rounds);
    entries.into_iter().map(|e| e.cell).collect()
}

#[test]
fn a_grown_cell_is_the_cell_run_whole_at_its_repetitions_whatever_the_threads() {
    let registry = Registry::new().with_catalog(mcbench_papers::catalog());
    let one = grown(&registry, 32, 2, 1);
    let two = grown(&registry, 32, 2, 2);
    let whole = small_plan(&registry, 128, 1);
    let run = crate::run::runner::run(
        &whole,
        &crate::run::runner::RunOptions { threads: Some(2), store: None, observer: &crate::run::runner::Silent },
    )
    .expect("whole");
    assert_eq!(one.len(), 2);
    for ((a, b), (_, _, w)) in one.iter().zip(&two).zip(&run.cells) {
        assert_eq!(a.key, w.key, "keyed as a cell of 128 repetitions");
        for c in [a, b] {
            assert_eq!(c.moments, w.moments, "{}", c.key.estimator);
            assert_eq!((&c.rep_dev, &c.rep_sq), (&w.rep_dev, &w.rep_sq));
            assert_eq!((c.estimates, c.costs), (w.estimates, w.costs));
        }
    }
}

#[test]
fn the_budget_stops_the_rounds() {
    let registry = Registry::new().with_catalog(mcbench_papers::catalog());
    let plan = small_plan(&registry, 64, 1);
    let run = crate::run::runner::run(
        &plan,
        &crate::run::runner::RunOptions { threads: Some(1), store: None, observer: &crate::run::runner::Silent },
    )
    .expect("run");
    let mut entries: Vec<Entry<'_>> = run
        .cells
        .iter()
        .map(|(bi, ei, c)| Entry {
            plan: &plan,
            pilot_plan: &plan,
            bi: *bi,
            ei: *ei,
            fixed: 64,
            cell: c.clone(),
            pilot: c.clone(),
            looks: 1,
            open: true,
        })
        .collect();
    let first: u64 = entries.iter().map(Entry::spent).sum();
    // Room for one row's doubling only: the cheaper (or the first of equals) grows, once.
    let room = first + entries[0].spent();
    let ran = grow(&mut entries, room, 1, |_| Ok(())).expect("grow");
    assert_eq!(ran, 1);
    assert_eq!(entries.iter().map(|e| e.cell.key.reps).collect::<Vec<_>>(), vec![128, 64]);
    assert!(entries.iter().all(|e| !e.open), "a doubling that does not fit closes its row");
}
