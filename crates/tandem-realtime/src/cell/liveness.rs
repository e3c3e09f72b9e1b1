//! Liveness of the continuous cell under hand-overs (docs/decisions.md, "Hand-over
//! liveness"): however often a running cell is handed over to a plan of the same task and
//! groups ([`ContinuousCoordinator::take_over`]), whatever the operator does, every robot
//! keeps completing tasks, within the proven bounds:
//! - between two consecutive services of robot `i` (its token moving on after it left a
//!   group), another robot is served at most `(2N − 1)·G` times (`G` groups per task);
//! - in a run of ticks in which robot `i` completes no task (up to and including the tick of
//!   its next completion), another robot completes at most `(G + 1)(2N − 1) + 1` tasks.
//!
//! The property test runs random cells (N = 2…6, tasks with and without holds, three random
//! runnable orders of the same task to switch between) under every policy of the adversary
//! set with re-plans every tick, after every completed task, after every `N` completed tasks
//! and every 25 ticks, and asserts both bounds at every tick, no overlap and no fault. In
//! the crate because it drives the adversary set's policies ([`PolicyState`]) tick by tick
//! and reads each robot's service stamp. The starving case of issue 40 is a regression test.

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::adversary::{Adversary, PolicyState, adversary_set};
use crate::cell::{ContinuousCoordinator, groups};
use crate::testkit::{CellHolds, random_cell_task, random_order};
use crate::{MAX_ROBOTS, Operator, Timeline};

/// When the cell is handed over to a new plan (tried each tick until it succeeds: a robot
/// inside a group blocks it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Replan {
    /// Never (the plan's own sequence).
    Never,
    /// After every tick.
    EveryTick,
    /// After every tick in which some robot completed a task.
    EveryTask,
    /// After every `N` completed tasks (whichever robots did them).
    EveryNTasks,
    /// Every `k` ticks.
    EveryTicks(u64),
}

/// What [`run`] saw.
#[derive(Clone, Debug, Default)]
struct Seen {
    /// Each robot's completed tasks at the end.
    tasks: Vec<u64>,
    /// Hand-overs made.
    hand_overs: u64,
    /// The most services of another robot between two consecutive services of a robot (or
    /// from the start to its first).
    worst_services: u64,
    /// The most tasks another robot completed in a run of ticks in which a robot completed
    /// none (up to and including the tick of its next completion).
    worst_tasks: u64,
}

/// Runs `plans[0]` for `ticks` ticks under the policy `adversary` (the beam search runs as a
/// switching favourite, as in [`crate::cell::run_cell`]), handing it over to a plan
/// drawn from `plans` as `replan` says, and asserts at every tick: no overlap, no fault, and
/// the two bounds of the module docs (`g` groups per task).
fn run(
    plans: &[ContinuousCoordinator],
    g: usize,
    replan: Replan,
    adversary: Adversary,
    rng: &mut ChaCha8Rng,
    ticks: u64,
) -> Result<Seen, TestCaseError> {
    let mut cell = plans[0].clone();
    let n = cell.n_robots();
    let (n64, g64) = (n as u64, g as u64);
    let service_bound = (2 * n64 - 1) * g64;
    let task_bound = (g64 + 1) * (2 * n64 - 1) + 1;
    let policy_of = match adversary {
        Adversary::Beam { .. } => Adversary::SwitchFavourite { max_hold: 50 },
        other => other,
    };
    let mut policy = PolicyState::new(n);
    // services[i][j]: services of robot j since robot i's last one; tasks[i][j] likewise.
    let mut services = [[0_u64; MAX_ROBOTS]; MAX_ROBOTS];
    let mut tasks = [[0_u64; MAX_ROBOTS]; MAX_ROBOTS];
    let mut seen = Seen::default();
    let mut pending = false;
    let mut done_since = 0;
    for k in 0..ticks {
        let lc = cell.low_conf_now().first();
        let op = policy.next(policy_of, k, lc, rng);
        let (served, done) = (cell.served, cell.tasks);
        let t = cell.tick(op).expect("admissible operator");
        prop_assert!(
            !t.overlap() && t.fault.is_none(),
            "{replan:?} {adversary:?}, tick {k}: {t:?}"
        );
        for j in 0..n {
            if cell.served[j] != served[j] {
                for (i, row) in services.iter_mut().enumerate().take(n) {
                    row[j] += u64::from(i != j);
                    seen.worst_services = seen.worst_services.max(row[j]);
                    prop_assert!(
                        row[j] <= service_bound,
                        "{replan:?} {adversary:?}, tick {k}: robot {j} served {} times since \
                         robot {i} was (bound (2N − 1)·G = {service_bound})",
                        row[j]
                    );
                }
                services[j] = [0; MAX_ROBOTS];
            }
        }
        let mut completed = false;
        for j in 0..n {
            if cell.tasks[j] != done[j] {
                prop_assert_eq!(cell.tasks[j], done[j] + 1);
                completed = true;
                done_since += 1;
                for (i, row) in tasks.iter_mut().enumerate().take(n) {
                    row[j] += u64::from(i != j);
                    seen.worst_tasks = seen.worst_tasks.max(row[j]);
                    prop_assert!(
                        row[j] <= task_bound,
                        "{replan:?} {adversary:?}, tick {k}: robot {j} completed {} tasks \
                         while robot {i} completed none (bound (G + 1)(2N − 1) + 1 = \
                         {task_bound}); tasks {:?}",
                        row[j],
                        cell.tasks_completed()
                    );
                }
            }
        }
        // A row is reset after the tick's increments: a task completed in the tick of
        // robot i's completion belongs to the run of ticks that this tick ends.
        for j in 0..n {
            if cell.tasks[j] != done[j] {
                tasks[j] = [0; MAX_ROBOTS];
            }
        }
        pending |= match replan {
            Replan::Never => false,
            Replan::EveryTick => true,
            Replan::EveryTask => completed,
            Replan::EveryNTasks => done_since >= n,
            Replan::EveryTicks(every) => k % every == every - 1,
        };
        if pending {
            let mut next = plans[rng.random_range(0..plans.len())].clone();
            if next.take_over(&cell).is_ok() {
                cell = next;
                pending = false;
                done_since = 0;
                seen.hand_overs += 1;
            }
        }
    }
    seen.tasks = cell.tasks_completed().to_vec();
    Ok(seen)
}

/// `[HC, LC, HC]` at Δt_s = 1 s, ψ̇ = 1, bounds [½, 2].
fn three_samples() -> Timeline {
    Timeline::new(
        &[true, false, true],
        &[1.0; 3],
        &[0.5; 3],
        &[2.0; 3],
        0.0,
        1.0,
    )
    .unwrap()
}

#[test]
fn a_plan_handed_over_to_itself_after_every_task_starves_no_robot() {
    // Issue 40: three robots on [HC, LC, HC], one group gated at the start, the order 0, 1,
    // 2; each robot takes 3 ticks per task (to the stretch, across it, to the end), one after
    // the other, so robot r completes at ticks 2 + 3r + 9k: 1111 tasks each in 10 000 ticks.
    // Handed over to the same plan after every completed task, the old rule gave the token
    // back to robot 0 every time (the lowest position of a tie): [3333, 0, 0]. The robot
    // whose turn it was gets it: the plan's own rhythm, tick for tick.
    let plan = ContinuousCoordinator::new(three_samples(), &[], &[(0, 0), (1, 0), (2, 0)], 3, 1.0)
        .unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(40);
    for replan in [Replan::Never, Replan::EveryTask, Replan::EveryTick] {
        let seen = run(
            std::slice::from_ref(&plan),
            1,
            replan,
            Adversary::Nominal,
            &mut rng,
            10_000,
        )
        .unwrap();
        assert_eq!(seen.tasks, [1111, 1111, 1111], "{replan:?}");
        // Between two of a robot's tasks each other robot completes one (and is served once).
        assert_eq!(
            (seen.worst_services, seen.worst_tasks),
            (1, 1),
            "{replan:?}"
        );
    }
    // After every task: 3333 hand-overs, every one at the tick the token moves.
    let seen = run(
        std::slice::from_ref(&plan),
        1,
        Replan::EveryTask,
        Adversary::Nominal,
        &mut rng,
        10_000,
    )
    .unwrap();
    assert_eq!(seen.hand_overs, 3333);
}

#[test]
fn alternating_orders_that_followed_only_the_old_turn_would_starve_robot_2() {
    // Two plans of the three-sample task with the orders 0, 1, 2 and 0, 2, 1, switched after
    // every task. Following the old plan's turn, robots 0 and 1 alternate for ever and robot
    // 2 never moves (after 0: turn 1 in the first plan; in the second, 1 then 0; in the
    // first, 0 then 1; …). Once robot 2 has seen (N − 1)·G = 2 services of others since its
    // last, the token goes to it as the least recently served robot: round robin.
    let task = three_samples();
    let a =
        ContinuousCoordinator::new(task.clone(), &[], &[(0, 0), (1, 0), (2, 0)], 3, 1.0).unwrap();
    let b = ContinuousCoordinator::new(task, &[], &[(0, 0), (2, 0), (1, 0)], 3, 1.0).unwrap();
    let mut cell = a.clone();
    let mut order = Vec::new();
    for _ in 0..900 {
        let before = cell.token().unwrap().robot;
        let pos = cell.token_position();
        cell.tick(Operator::Scheduled).unwrap();
        if cell.token_position() != pos {
            order.push(before);
            let mut next = if order.len() % 2 == 1 {
                b.clone()
            } else {
                a.clone()
            };
            next.take_over(&cell).unwrap();
            cell = next;
        }
    }
    // Every three consecutive services are of three different robots.
    assert!(order.len() >= 99, "{}", order.len());
    for w in order.windows(3) {
        assert!(w[0] != w[1] && w[1] != w[2] && w[0] != w[2], "{order:?}");
    }
    assert_eq!(cell.tasks_completed(), [100, 100, 100]);
}

/// The worst case [`cell_is_fair`] saw: services and tasks of another robot, as fractions
/// of their bounds, and the runs.
#[derive(Clone, Copy, Debug, Default)]
struct Worst {
    services: f64,
    tasks: f64,
    runs: u64,
    hand_overs: u64,
}

/// One random cell under every policy of the adversary set, each with one of the re-plan
/// frequencies (cycling through them from `seed`); every robot completes tasks.
fn cell_is_fair(seed: u64, n: usize, worst: &mut Worst) -> Result<(), TestCaseError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (task, holds) = random_cell_task(&mut rng, 40, CellHolds::NoneOneThird);
    let gs = groups(task.conf(), &holds).unwrap();
    let g = gs.len() as f64;
    let tick_s = 0.05 * rng.random_range(0.3..2.0);
    let plans: Vec<ContinuousCoordinator> = (0..3)
        .map(|_| {
            let order = random_order(&gs, n, &mut rng);
            ContinuousCoordinator::new(task.clone(), &holds, &order, n, tick_s).unwrap()
        })
        .collect();
    // Ticks for about 10 tasks per robot when the operator drags every stretch and the
    // robots take turns: per task of a robot, its samples at their slowest plus a tick per
    // sample, times N.
    let slow_s: f64 = (0..task.n_ref())
        .map(|k| task.grad_exec()[k].max(task.grad_max()[k]))
        .sum::<f64>()
        * task.dt_s();
    let per_task = slow_s / tick_s + task.n_ref() as f64;
    let ticks = (10.0 * n as f64 * per_task) as u64;
    let modes = [
        Replan::EveryTick,
        Replan::EveryTask,
        Replan::EveryNTasks,
        Replan::EveryTicks(25),
        Replan::Never,
    ];
    let nf = n as f64;
    for (k, a) in adversary_set(n, [0.1, 6.0], 5000, &mut rng)
        .into_iter()
        .enumerate()
    {
        let replan = modes[(k as u64).wrapping_add(seed) as usize % modes.len()];
        let seen = run(&plans, gs.len(), replan, a, &mut rng, ticks)?;
        // Not vacuous: the re-plans happened, and every robot kept completing tasks.
        prop_assert!(
            replan == Replan::Never || seen.hand_overs > 0,
            "{replan:?} {a:?}: no hand-over"
        );
        let min = seen.tasks.iter().copied().min().unwrap_or(0);
        prop_assert!(min >= 1, "{replan:?} {a:?}: {:?}", seen.tasks);
        worst.services = worst
            .services
            .max(seen.worst_services as f64 / ((2.0 * nf - 1.0) * g));
        worst.tasks = worst
            .tasks
            .max(seen.worst_tasks as f64 / ((g + 1.0) * (2.0 * nf - 1.0) + 1.0));
        worst.runs += 1;
        worst.hand_overs += seen.hand_overs;
    }
    Ok(())
}

#[test]
fn every_robot_keeps_completing_tasks_however_often_the_plan_is_handed_over() {
    let cases: u32 = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(32);
    for n in 2..=6_usize {
        let worst = std::cell::Cell::new(Worst::default());
        let config = Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        };
        let mut runner =
            TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
        let result = runner.run(&any::<u64>(), |seed| {
            let mut w = worst.get();
            cell_is_fair(seed, n, &mut w)?;
            worst.set(w);
            Ok(())
        });
        if let Err(e) = result {
            panic!("N = {n}: {e}");
        }
        let w = worst.get();
        assert!(w.runs >= u64::from(cases) * 14, "{w:?}");
        eprintln!(
            "N = {n}: {} runs, {} hand-overs; worst services {:.0} % and tasks {:.0} % of the bounds",
            w.runs,
            w.hand_overs,
            100.0 * w.services,
            100.0 * w.tasks
        );
    }
}
