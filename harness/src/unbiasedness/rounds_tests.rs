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
fn first_rounds_are_an_eighth_in_whole_steps_and_at_least_the_minimum() {
    assert_eq!(first_round(256), MIN_FIRST_REPS);
    assert_eq!(first_round(512), 64);
    assert_eq!(first_round(1024), 128);
    assert_eq!(first_round(1500), 192);
    assert_eq!(first_round(16_384), 2048);
    assert_eq!(first_round(2), MIN_FIRST_REPS);
    assert_eq!(first_round(720), 96, "90 rounded up to three steps of 32");
    assert!([100, 1000, 4097, 720].iter().all(|&r| first_round(r).is_multiple_of(FIRST_ROUND_STEP)));
    assert!(FIRST_ROUND_STEP.is_multiple_of(REP_BLOCK) && FIRST_ROUND_STEP.is_multiple_of(MAX_REP_BLOCKS));
}

#[test]
fn a_budget_is_its_share_of_the_fixed_work_in_exact_integers() {
    let fixed = 327_780_000_u64;
    assert_eq!(budget(fixed, 1.0), fixed, "the whole share is the fixed work itself");
    assert_eq!(budget(fixed, 0.3), 98_334_000);
    assert_eq!(budget(fixed, 0.45), 147_501_000);
    // Beyond f64's exact integers the whole share stays exact.
    let huge = u64::MAX - 7;
    assert_eq!(budget(huge, 1.0), huge);
    assert!(budget(huge, 0.5) <= huge / 2 + 1);
    assert_eq!(budget(0, 0.3), 0);
}

fn combined(verdict: &str, reps_needed: Option<f64>) -> Vec<TestRow> {
    let pooled = TestRow { test: "pooled_t".into(), p_value: 0.5, ..Default::default() };
    vec![pooled, TestRow { test: "combined".into(), verdict: verdict.into(), reps_needed, ..Default::default() }]
}

/// The tests of a row whose pooled test the skewness gate kept from running.
fn untested(reps_needed: Option<f64>) -> Vec<TestRow> {
    let mut tests = combined("inconclusive", reps_needed);
    tests[0].p_value = f64::NAN;
    tests
}

#[test]
fn a_row_stays_open_only_while_another_look_could_decide_it() {
    let open = combined("inconclusive", Some(500.0));
    assert!(stays_open(&open, 64, 1, true, false));
    assert!(!stays_open(&open, 64, LOOKS, true, false), "no look left");
    assert!(!stays_open(&open, 64, 1, false, false), "a row that cannot pass");
    assert!(!stays_open(&combined("pass", None), 64, 1, true, false));
    assert!(!stays_open(&combined("biased", None), 64, 1, true, false));
    assert!(!stays_open(&combined("inconclusive", None), 64, 1, true, false), "no repetitions resolve it");
    // At the look before the last with 512 repetitions, one more look reaches 1024.
    assert!(stays_open(&combined("inconclusive", Some(1024.0)), 512, LOOKS - 1, true, false));
    assert!(!stays_open(&combined("inconclusive", Some(1025.0)), 512, LOOKS - 1, true, false), "beyond the last look");
}

#[test]
fn a_control_grows_past_a_pass_until_flagged() {
    assert!(stays_open(&combined("pass", None), 64, 1, true, true), "a control that passes grows");
    assert!(stays_open(&combined("inconclusive", Some(1e9)), 64, 1, true, true), "beyond reach, still a control");
    assert!(stays_open(&combined("pass", None), 64, 1, false, true), "flagging needs no pass");
    assert!(!stays_open(&combined("biased", None), 64, 1, true, true), "flagged: decided");
    assert!(!stays_open(&combined("pass", None), 64, LOOKS, true, true), "no look left");
}

#[test]
fn a_row_without_a_valid_test_stays_open_only_while_a_look_could_test_it() {
    // From 64 repetitions at look 1, the last look reaches 64 x 2^(LOOKS - 1).
    let last = (64u64 << (LOOKS - 1)) as f64;
    assert!(stays_open(&untested(Some(last)), 64, 1, true, false), "the skewness limit within reach");
    assert!(!stays_open(&untested(Some(last + 1.0)), 64, 1, true, false), "too skewed for any look");
    assert!(!stays_open(&untested(Some(1e9)), 64, LOOKS - 1, true, false));
    assert!(!stays_open(&untested(None), 64, 1, true, false), "no estimate");
    assert!(!stays_open(&untested(Some(128.0)), 64, LOOKS, true, false), "no look left");
    assert!(!stays_open(&untested(Some(128.0)), 64, 1, false, false), "a row that cannot pass");
}

#[test]
fn blocks_regroup_into_the_layout_of_the_doubled_cell() {
    let block = |reps: u64, sq: f64| RepBlock { reps, sq, p_err: sq, ..Default::default() };
    // 64 repetitions: 32 blocks of 2; at 128: 32 blocks of 4, the first 16 holding the old ones.
    let old: Vec<RepBlock> = (0..32).map(|k| block(2, k as f64)).collect();
    let new = regroup(&old, 64, 128);
    assert_eq!(new.len(), 32);
    for (j, b) in new.iter().enumerate() {
        let expected = if j < 16 { block(4, (4 * j + 1) as f64) } else { RepBlock::default() };
        assert_eq!(b, &expected, "block {j}");
    }
    // 16 repetitions (16 blocks of 1) into 32 (32 blocks of 1): the same blocks, then empty ones.
    let small: Vec<RepBlock> = (0..16).map(|k| block(1, k as f64)).collect();
    assert_eq!(regroup(&small, 16, 32)[..16], small[..]);
    // 48 (24 blocks of 2) into 96 (32 blocks of 3) would split blocks: no bootstrap.
    let odd: Vec<RepBlock> = (0..24).map(|k| block(2, k as f64)).collect();
    assert!(regroup(&odd, 48, 96).is_empty());
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

/// The cells of `plan` on `threads` threads, stored nowhere.
fn run_silently(plan: &Plan, threads: usize) -> crate::run::runner::RunResults {
    let opts =
        crate::run::runner::RunOptions { threads: Some(threads), store: None, observer: &crate::run::runner::Silent };
    crate::run::runner::run(plan, &opts).expect("run")
}

/// Grows the cells of a plan at `reps` for `rounds` rounds on `threads` threads (every row kept
/// open), returning the grown cells.
fn grown(registry: &Registry, reps: usize, rounds: usize, threads: usize) -> Vec<CellResult> {
    let (plan, pilot_plan) = (small_plan(registry, reps, 1), small_plan(registry, reps, 2));
    let cells = run_silently(&plan, threads);
    let pilots = run_silently(&pilot_plan, threads);
    let mut entries: Vec<Entry<'_>> = cells
        .cells
        .iter()
        .zip(&pilots.cells)
        .map(|((bi, ei, c), (_, _, p))| Entry {
            plan: &plan,
            bi: *bi,
            ei: *ei,
            fixed: reps,
            cell: c.clone(),
            pilot: p.clone(),
            looks: 1,
            open: true,
            needed: None,
            control: false,
        })
        .collect();
    let budget = entries.iter().map(Entry::spent).sum::<u64>() << rounds;
    let ran = grow(&mut entries, budget, threads, |e| {
        e.open = e.looks <= rounds;
        Ok(())
    })
    .expect("grow");
    assert_eq!(ran, rounds);
    // The pilots stay at their first round: a doubling costs the cell's repetitions alone.
    for ((e, (_, _, p)), (_, _, c)) in entries.iter().zip(&pilots.cells).zip(&cells.cells) {
        assert_eq!((&e.pilot.key, &e.pilot.rep_dev), (&p.key, &p.rep_dev), "the pilot is not grown");
        let unit = (c.moments.len() as u64) * c.key.budget.amount;
        assert_eq!(e.spent(), ((reps << rounds) + reps) as u64 * unit);
        assert_eq!(e.doubling(), (reps << rounds) as u64 * unit);
    }
    entries.into_iter().map(|e| e.cell).collect()
}

#[test]
fn a_grown_cell_is_the_cell_run_whole_at_its_repetitions_whatever_the_threads() {
    let registry = Registry::new().with_catalog(mcbench_papers::catalog());
    let one = grown(&registry, 32, 2, 1);
    let two = grown(&registry, 32, 2, 2);
    let whole = small_plan(&registry, 128, 1);
    let run = run_silently(&whole, 2);
    assert_eq!(one.len(), 2);
    for ((a, b), (_, _, w)) in one.iter().zip(&two).zip(&run.cells) {
        assert_eq!(a.key, w.key, "keyed as a cell of 128 repetitions");
        for c in [a, b] {
            assert_eq!(c.moments, w.moments, "{}", c.key.estimator);
            assert_eq!((&c.rep_dev, &c.rep_sq), (&w.rep_dev, &w.rep_sq));
            assert_eq!((c.estimates, c.costs), (w.estimates, w.costs));
            // The bootstrap blocks in the fixed layout at 128: the same repetitions and counted
            // costs, the sums equal up to the order of their additions.
            assert_eq!(c.blocks.len(), w.blocks.len(), "{}", c.key.estimator);
            for (k, (g, f)) in c.blocks.iter().zip(&w.blocks).enumerate() {
                assert_eq!((g.reps, g.costs), (f.reps, f.costs), "block {k}");
                let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * a.abs().max(b.abs());
                assert!(close(g.sq, f.sq) && close(g.p_err, f.p_err), "block {k}: {g:?} against {f:?}");
                assert!(g.display_sq.zip(f.display_sq).is_some_and(|(a, b)| close(a, b)), "block {k}");
            }
        }
    }
}

/// Every cell of `run` as an open row after its first look (its own pilot), 64 repetitions fixed.
fn open_rows<'a>(plan: &'a Plan, run: &crate::run::runner::RunResults) -> Vec<Entry<'a>> {
    run.cells
        .iter()
        .map(|(bi, ei, c)| Entry {
            plan,
            bi: *bi,
            ei: *ei,
            fixed: 64,
            cell: c.clone(),
            pilot: c.clone(),
            looks: 1,
            open: true,
            needed: None,
            control: false,
        })
        .collect()
}

#[test]
fn the_budget_stops_the_rounds() {
    let registry = Registry::new().with_catalog(mcbench_papers::catalog());
    let plan = small_plan(&registry, 64, 1);
    let run = run_silently(&plan, 1);
    let mut entries = open_rows(&plan, &run);
    let first: u64 = entries.iter().map(Entry::spent).sum();
    // Room for one row's doubling only: the cheaper (or the first of equals) grows, once.
    let room = first + entries[0].doubling();
    let ran = grow(&mut entries, room, 1, |_| Ok(())).expect("grow");
    assert_eq!(ran, 1);
    assert_eq!(entries.iter().map(|e| e.cell.key.reps).collect::<Vec<_>>(), vec![128, 64]);
    assert!(entries.iter().all(|e| !e.open), "a doubling that does not fit closes its row");
}

#[test]
fn rows_within_reach_of_a_decision_grow_before_the_others() {
    let registry = Registry::new().with_catalog(mcbench_papers::catalog());
    let plan = small_plan(&registry, 64, 1);
    let run = run_silently(&plan, 1);
    let mut entries = open_rows(&plan, &run);
    // The second row would be resolved by one doubling, the first has no estimate.
    entries[1].needed = Some(128.0);
    let first: u64 = entries.iter().map(Entry::spent).sum();
    let room = first + entries[0].doubling() + entries[1].doubling();
    let mut order = Vec::new();
    let ran = grow(&mut entries, room, 1, |e| {
        order.push(e.ei);
        e.needed = None;
        Ok(())
    })
    .expect("grow");
    // Round 1 grows the row within reach alone, round 2 the other with what is left.
    assert_eq!((ran, order), (2, vec![entries[1].ei, entries[0].ei]));
    assert_eq!(entries.iter().map(|e| e.cell.key.reps).collect::<Vec<_>>(), vec![128, 128]);
}
