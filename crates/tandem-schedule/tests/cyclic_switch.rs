//! The continuous cell's chain bound with the operator's switch time (issue 41;
//! docs/decisions.md, "The continuous cell's chain bound with the switch time (issue 41)"): by
//! hand on a two-stretch task with a hold between its stretches, and against the exhaustive
//! order search on random small problems (the bound never above the best plan).

use rand::{Rng, SeedableRng};
use tandem_schedule::{CyclicParams, Problem, cyclic_plan, period_lower_bound_with_switch_s};

/// `[HC 1 s, LC 1 s, HC 1 s with a hold at its middle, LC 1 s, HC 1 s]` at 10 ms, `ψ̇̄ = 1`,
/// high-confidence samples at `ψ̇min = 0.5` (0.5 s per gap at the fastest) and `ψ̇max = 2`.
fn two_stretches() -> Problem {
    let conf: Vec<bool> = (0..500)
        .map(|n| !((100..200).contains(&n) || (300..400).contains(&n)))
        .collect();
    Problem::new(conf, vec![1.0; 500], vec![0.5; 500], vec![2.0; 500], 0.01)
        .unwrap()
        .with_holds(vec![250])
        .unwrap()
}

/// Per robot the interval before stretch 0 is the tail and the head (`G_0 = 1` s) or a switch
/// (`δ`), the one before stretch 1 the gap (`G_1 = 0.5` s) or a switch; each robot is entered
/// from another at least once. So `P ≥ N·(2 + min(δ, 1) + min(δ, 0.5) + max(0, min(δ − 1,
/// δ − 0.5)))`, and the exhaustive search reaches it: round robin at `δ = 0.3` s (every
/// interval a switch), the robots' two stretches back to back at 0.7 and 2 s.
#[test]
fn the_chain_bound_by_hand() {
    let p = two_stretches();
    for (switch_s, per_robot) in [(0.3, 2.6), (0.7, 3.2), (2.0, 4.5)] {
        for n in [2usize, 3] {
            let params = CyclicParams {
                switch_s,
                ..CyclicParams::default()
            };
            let plan = cyclic_plan(&p, n, &params).unwrap();
            let want = n as f64 * per_robot;
            assert!(plan.order_exhaustive);
            assert!(
                (plan.period_s - want).abs() < 1e-9,
                "N = {n}, δ = {switch_s}: period {}",
                plan.period_s
            );
            assert!(
                (plan.lower_bound_s - want).abs() < 1e-9,
                "N = {n}, δ = {switch_s}: bound {}",
                plan.lower_bound_s
            );
            // The bound of one switch per robot (no forced idle gap here) is lower:
            // N·(2 + δ).
            let old = period_lower_bound_with_switch_s(&p, n, switch_s).unwrap();
            assert!((old - n as f64 * (2.0 + switch_s)).abs() < 1e-9);
            assert!(old < want - 0.1);
        }
    }
    // δ = 0: the plan and its bound as without a switch time, bit for bit.
    let zero = cyclic_plan(
        &p,
        3,
        &CyclicParams {
            switch_s: 0.0,
            handover_tick_s: Some(0.01),
            ..CyclicParams::default()
        },
    )
    .unwrap();
    let none = cyclic_plan(
        &p,
        3,
        &CyclicParams {
            handover_tick_s: Some(0.01),
            ..CyclicParams::default()
        },
    )
    .unwrap();
    assert_eq!(zero.lower_bound_s.to_bits(), none.lower_bound_s.to_bits());
    assert_eq!(zero, none);
}

/// A random small problem: `m` low-confidence stretches between high-confidence gaps with
/// random bounds, and a hold in a gap with probability `hold_p` (as in `tests/cyclic.rs`).
fn random_problem(rng: &mut impl Rng, m_max: usize, hold_p: f64) -> Problem {
    let m = rng.random_range(1..=m_max);
    let (mut conf, mut lo, mut hi, mut holds) = (vec![], vec![], vec![], vec![]);
    for k in 0..=m {
        let len = rng.random_range(2..6);
        let (a, b) = (rng.random_range(0.3..1.0), rng.random_range(1.0..3.0));
        if rng.random_bool(hold_p) {
            holds.push(conf.len() + 1);
        }
        for _ in 0..len {
            conf.push(true);
            lo.push(a);
            hi.push(b);
        }
        if k < m {
            for _ in 0..rng.random_range(1..8) {
                conf.push(false);
                lo.push(0.5);
                hi.push(2.0);
            }
        }
    }
    let n = conf.len();
    Problem::new(conf, vec![1.0; n], lo, hi, 0.1)
        .unwrap()
        .with_holds(holds)
        .unwrap()
}

/// The bound is a lower bound on every order's period: the exhaustive search's best plan is
/// never below it, with and without the hand-overs, among runnable orders and among all, at
/// random switch times from a fraction of a tick to several stretches; and it is reached
/// often (not vacuous).
#[test]
fn the_chain_bound_is_never_above_the_best_plan() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(41);
    let (mut cases, mut tight) = (0, 0);
    for _ in 0..120 {
        let p = random_problem(&mut rng, 3, 0.5);
        let n = if rng.random_bool(0.5) { 2 } else { 3 };
        let switch_s = [0.05, 0.3, 0.8, 2.0][rng.random_range(0..4)];
        let params = CyclicParams {
            switch_s,
            handover_tick_s: rng.random_bool(0.5).then_some(0.1),
            runnable_only: rng.random_bool(0.5),
            ..CyclicParams::default()
        };
        let plan = match cyclic_plan(&p, n, &params) {
            Ok(plan) => plan,
            Err(e) => panic!("{e}"),
        };
        assert!(plan.order_exhaustive);
        assert!(
            plan.period_s >= plan.lower_bound_s * (1.0 - 1e-12),
            "{params:?}, N = {n}: period {} below its bound {}",
            plan.period_s,
            plan.lower_bound_s
        );
        cases += 1;
        tight += usize::from(plan.gap < 1e-9);
    }
    assert!(tight * 4 >= cases, "{tight} of {cases} at the bound");
}
