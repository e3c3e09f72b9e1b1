//! M operators in the continuous cell (issue 44; docs/decisions.md, "M operators: the
//! invariant and the continuous cell (issue 44)"): at most `M` robots low-confidence in any
//! tick, every low-confidence robot assigned to one operator that never changes while it is
//! inside a group, each operator's stretches of different robots `k` ticks apart, every robot
//! progressing — under random plans and random operators, one input per operator.

use std::collections::HashMap;

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_realtime::cell::{ContinuousCoordinator, groups};
use tandem_realtime::testkit::{CellHolds, random_cell_task, random_order};
use tandem_realtime::{Controller, Error, Operator, OperatorCount, Timeline};

/// Each operator's policy of the property test.
#[derive(Clone, Copy, Debug)]
enum Policy {
    Rush,
    Drag,
    RandomExtreme,
    RandomGradient,
    /// Per operator: rush on even ticks of a random phase, drag otherwise.
    Mixed,
}

fn input(policy: Policy, o: usize, tick: u64, rng: &mut ChaCha8Rng) -> Operator {
    match policy {
        Policy::Rush => Operator::Fastest,
        Policy::Drag => Operator::Slowest,
        Policy::RandomExtreme if rng.random_bool(0.5) => Operator::Fastest,
        Policy::RandomExtreme => Operator::Slowest,
        Policy::RandomGradient => Operator::Gradient(rng.random_range(0.1..6.0)),
        Policy::Mixed if (tick / 7 + o as u64) % 2 == 0 => Operator::Fastest,
        Policy::Mixed => Operator::Slowest,
    }
}

/// Runs a random cell of `n` robots and `m` operators until every robot has done 30 tasks,
/// checking the invariant at every tick; returns the most robots low-confidence in one tick.
fn m_operators_sound(
    seed: u64,
    n: usize,
    m: usize,
    policy: Policy,
    switch: bool,
) -> Result<usize, TestCaseError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (task, holds) = random_cell_task(&mut rng, 60, CellHolds::Uniform);
    let gs = groups(task.conf(), &holds).unwrap();
    let order = random_order(&gs, n, &mut rng);
    let tick_s = 0.05 * rng.random_range(0.2..2.0);
    let switch_s = if switch {
        rng.random_range(0.0..0.5)
    } else {
        0.0
    };
    let mut c = ContinuousCoordinator::new(task.clone(), &holds, &order, n, tick_s)
        .unwrap()
        .with_switch_s(switch_s)
        .unwrap()
        .with_operators(OperatorCount::new(m).unwrap());
    let k = c.switch_ticks();
    prop_assert_eq!(Controller::operators(&c), m);
    // A generous deadlock bound: every robot's 30 tasks one after the other at the slowest.
    let slow_s: f64 = (0..task.n_ref())
        .map(|q| {
            if task.conf()[q] {
                task.grad_exec()[q]
            } else {
                task.grad_max()[q]
            }
        })
        .sum::<f64>()
        * task.dt_s();
    let per_task = (slow_s + switch_s) / tick_s + (task.n_ref() + 2 * gs.len() + 2) as f64 + 1.0;
    let bound = (35.0 * n as f64 * per_task) as u64 + 1000;
    // Each granted entry (its (pos, passes)) and the operator it was granted: never changes.
    let mut granted: HashMap<(usize, u64), (usize, usize)> = HashMap::new();
    // Per operator: the robot and tick of its last low-confidence tick.
    let mut last_lc: Vec<Option<(usize, u64)>> = vec![None; m];
    let mut ticks = 0_u64;
    let mut most = 0;
    let mut inputs = vec![Operator::Scheduled; m];
    while c.tasks_completed().iter().any(|&t| t < 30) {
        prop_assert!(
            ticks < bound,
            "deadlock? {ticks} ticks, {:?}",
            c.tasks_completed()
        );
        let held: Vec<_> = c.held_tokens().to_vec();
        prop_assert_eq!(held.len(), m);
        for (o, h) in held.iter().enumerate() {
            if let Some((t, pos, passes)) = h {
                let was = granted.insert((*pos, *passes), (t.robot, o));
                prop_assert!(
                    was.is_none_or(|w| w == (t.robot, o)),
                    "tick {ticks}: entry {pos}/{passes} moved from {was:?} to ({}, {o})",
                    t.robot
                );
            }
        }
        for (o, x) in inputs.iter_mut().enumerate() {
            *x = input(policy, o, ticks, &mut rng);
        }
        let t = c.tick_many(&inputs).unwrap();
        prop_assert!(!t.over(m) && t.fault.is_none(), "tick {ticks}: {t:?}");
        most = most.max(t.low_conf.count());
        let mut seen = vec![false; m];
        for i in 0..n {
            if !t.low_conf[i] {
                prop_assert_eq!(t.operator[i], None);
                continue;
            }
            // The low-confidence robot's operator is the one that held its entry at the tick
            // start: assigned before it entered, never handed over mid-way.
            let o = usize::from(t.operator[i].expect("a low-confidence robot has an operator"));
            prop_assert!(o < m && !seen[o], "tick {ticks}: operator {o} twice");
            seen[o] = true;
            prop_assert!(
                held[o].is_some_and(|(tok, _, _)| tok.robot == i),
                "tick {ticks}: robot {i} low-confidence under operator {o}, which held {:?}",
                held[o]
            );
            // The switch time: k ticks with neither robot low-confidence between two robots'
            // stretches of one operator.
            if let Some((r, at)) = last_lc[o] {
                prop_assert!(
                    r == i || ticks - at > k,
                    "tick {ticks}: operator {o} from robot {r} (tick {at}) to {i}, k = {k}"
                );
            }
            last_lc[o] = Some((i, ticks));
        }
        ticks += 1;
    }
    Ok(most)
}

fn fixed(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_seed: RngSeed::Fixed(44),
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(fixed(96))]

    #[test]
    fn at_most_m_robots_low_confidence_each_with_one_operator(
        seed in any::<u64>(),
        (n, m) in prop_oneof![
            Just((4_usize, 2_usize)),
            Just((8, 2)),
            Just((8, 4)),
            Just((3, 1)),
            Just((16, 4)),
        ],
        policy in prop_oneof![
            Just(Policy::Rush),
            Just(Policy::Drag),
            Just(Policy::RandomExtreme),
            Just(Policy::RandomGradient),
            Just(Policy::Mixed),
        ],
        switch in any::<bool>(),
    ) {
        m_operators_sound(seed, n, m, policy, switch)?;
    }
}

#[test]
fn the_random_cells_do_use_several_operators_at_once() {
    // The property test is not vacuous: with 8 robots and 4 operators rushing, random cells
    // have ticks with more than one robot low-confidence (up to 4), never more than 4.
    let most: Vec<usize> = (0..6)
        .map(|seed| m_operators_sound(seed, 8, 4, Policy::Rush, false).unwrap())
        .collect();
    assert!(most.iter().all(|&k| k <= 4), "{most:?}");
    assert!(most.iter().filter(|&&k| k >= 2).count() >= 3, "{most:?}");
}

/// `[LC, LC, HC, HC]` at Δt_s = 1 s, bounds [½, 2]: one group whose gate is the start.
fn lc_first() -> Timeline {
    Timeline::new(
        &[false, false, true, true],
        &[1.0; 4],
        &[0.5; 4],
        &[2.0; 4],
        0.0,
        1.0,
    )
    .unwrap()
}

#[test]
fn m_operators_let_exactly_m_robots_in_and_the_next_waits() {
    // Three robots at the gate of the one group, two operators: robots 0 and 1 (the order's
    // first two) enter at once, each with its own operator; robot 2 waits for the first to
    // leave. A rule that let M + 1 robots in would put all three in low confidence in tick 0.
    let order = [(0, 0), (1, 0), (2, 0)];
    let mut c = ContinuousCoordinator::new(lc_first(), &[], &order, 3, 1.0)
        .unwrap()
        .with_operators(OperatorCount::new(2).unwrap());
    let t = c.tick_many(&[Operator::Scheduled; 2]).unwrap();
    assert_eq!(t.low_conf, [true, true, false]);
    assert_eq!(t.operator, [Some(0), Some(1), None]);
    assert!(t.waiting[2] && !t.running[2] && !t.over(2) && t.fault.is_none());
    // Operator 0 rushes (robot 0 leaves its 2-sample group in one tick: ψ̇min = ½), operator
    // 1 drags: robot 2 gets operator 0 as soon as robot 0 has left, while robot 1 is still
    // inside with operator 1.
    let t = c
        .tick_many(&[Operator::Fastest, Operator::Slowest])
        .unwrap();
    assert_eq!(t.low_conf, [true, true, false]);
    let t = c
        .tick_many(&[Operator::Fastest, Operator::Slowest])
        .unwrap();
    assert_eq!(t.low_conf, [false, true, true]);
    assert_eq!(t.operator, [None, Some(1), Some(0)]);
    // One input per operator, or a clear error.
    assert!(matches!(
        c.tick(Operator::Scheduled),
        Err(Error::OperatorInputs { got: 1, want: 2 })
    ));
    // One operator: the same order lets one robot in at a time.
    let mut one = ContinuousCoordinator::new(lc_first(), &[], &order, 3, 1.0).unwrap();
    let t = one.tick(Operator::Scheduled).unwrap();
    assert_eq!(t.low_conf, [true, false, false]);
    assert_eq!(t.operator, [Some(0), None, None]);
}

#[test]
fn a_robot_keeps_its_last_operator_when_it_is_free() {
    // Two robots, two operators, a task with two groups split by a hold: a robot that leaves
    // its first group takes the operator it had for its second.
    let conf = [false, true, true, true, false, true, true];
    let task = Timeline::new(&conf, &[1.0; 7], &[0.5; 7], &[2.0; 7], 0.0, 1.0).unwrap();
    let order = [(0, 0), (1, 0), (0, 1), (1, 1)];
    let mut c = ContinuousCoordinator::new(task, &[3], &order, 2, 1.0)
        .unwrap()
        .with_operators(OperatorCount::new(2).unwrap());
    let mut ops_of = [Vec::new(), Vec::new()];
    for _ in 0..60 {
        let t = c.tick_many(&[Operator::Scheduled; 2]).unwrap();
        for (ops, o) in ops_of.iter_mut().zip(t.operator.iter()) {
            if let Some(o) = *o {
                if ops.last() != Some(&o) {
                    ops.push(o);
                }
            }
        }
    }
    assert!(c.tasks_completed().iter().all(|&k| k >= 5));
    assert_eq!(ops_of, [vec![0], vec![1]]);
}

#[test]
fn a_robot_on_its_way_holds_back_no_operator() {
    // Two robots, two operators, two groups per task split by a hold at sample 3 (gate of
    // group 1), the order (0, 0), (0, 1), (1, 0), (1, 1): robot 0's two groups come first.
    // Robot 0 takes operator 0 for its group 0; the sequence's next entry is robot 0's group
    // 1, which it reaches only after group 0 and two samples of travel. Robot 1 waits at its
    // gate (the task start) with its entry next among the waiting robots, so it takes the idle
    // operator 1 at once: both robots are low-confidence in tick 0. The strict in-order grant
    // (the one-operator rule run with M tokens) stopped at (0, 1) and left robot 1 waiting
    // and operator 1 idle until robot 0 had left group 0.
    let conf = [false, true, true, true, false, true, true];
    let task = Timeline::new(&conf, &[1.0; 7], &[0.5; 7], &[2.0; 7], 0.0, 1.0).unwrap();
    let order = [(0, 0), (0, 1), (1, 0), (1, 1)];
    let mut c = ContinuousCoordinator::new(task.clone(), &[3], &order, 2, 1.0)
        .unwrap()
        .with_operators(OperatorCount::new(2).unwrap());
    let t = c.tick_many(&[Operator::Scheduled; 2]).unwrap();
    assert_eq!(t.low_conf, [true, true]);
    assert_eq!(t.operator, [Some(0), Some(1)]);
    assert!(!t.waiting[1] && !t.over(2));
    // One operator: the same order serves robot 0's two groups, then robot 1's.
    let mut one = ContinuousCoordinator::new(task, &[3], &order, 2, 1.0).unwrap();
    let t = one.tick(Operator::Scheduled).unwrap();
    assert_eq!(t.low_conf, [true, false]);
    assert!(t.waiting[1]);
}
