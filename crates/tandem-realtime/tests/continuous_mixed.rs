//! The continuous cell of different tasks (issue 45, `ContinuousCoordinator::mixed`): robot
//! `k` repeats its own task `r_k` times per pass of the operator's order. A one-task cell
//! built through the per-robot path ticks identically to `ContinuousCoordinator::new`; by
//! hand, a short task done twice per pass of a long one; and random mixed cells (N = 2…4,
//! each robot its own random task shape, holds and ratio 1–3, a random runnable order,
//! switch time 0 or a few ticks) under every adversary of `adversary_set`: 0 overlapping
//! ticks, no robot moving backwards, every robot completing its tasks.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_realtime::adversary::adversary_set;
use tandem_realtime::continuous::{ContinuousCoordinator, groups, run_cell};
use tandem_realtime::testkit::{CellHolds, random_cell_task, random_mixed_order, random_order};
use tandem_realtime::{Error, Operator, Timeline};

/// A task of confidence `conf` at Δt_s = 1 s, ψ̇ = 1, bounds [½, 2].
fn task(conf: &[bool]) -> Timeline {
    let n = conf.len();
    Timeline::new(conf, &vec![1.0; n], &vec![0.5; n], &vec![2.0; n], 0.0, 1.0).unwrap()
}

#[test]
fn a_one_task_cell_through_the_mixed_path_ticks_as_the_one_task_cell() {
    // Random tasks with holds, N = 2…5, random runnable orders, a switch time of 0 or 4
    // ticks: every tick's `Tick` (positions, flags, operators, pre-alert) equal over a whole
    // period's worth of tasks (every robot ≥ 3 tasks) under the scheduled and a random
    // operator.
    let mut rng = ChaCha8Rng::seed_from_u64(45);
    for case in 0..24 {
        let n = 2 + case % 4;
        let (t, holds) = random_cell_task(&mut rng, 40, CellHolds::Uniform);
        let gs = groups(t.conf(), &holds).unwrap();
        let order = random_order(&gs, n, &mut rng);
        let switch_s = if case % 2 == 0 { 0.0 } else { 0.12 };
        let mut old = ContinuousCoordinator::new(t.clone(), &holds, &order, n, 0.03)
            .unwrap()
            .with_switch_s(switch_s)
            .unwrap();
        let mut new =
            ContinuousCoordinator::mixed(&[(t, holds)], &vec![0; n], &vec![1; n], &order, 0.03)
                .unwrap()
                .with_switch_s(switch_s)
                .unwrap();
        assert_eq!(old.tokens(), new.tokens(), "{case}");
        let mut ticks = 0;
        while old.tasks_completed().iter().any(|&k| k < 3) {
            let op = if case % 3 == 0 {
                Operator::Scheduled
            } else {
                Operator::Gradient(rng.random_range(0.2..5.0))
            };
            assert_eq!(old.tick(op).unwrap(), new.tick(op).unwrap(), "{case}");
            assert_eq!(old.clock_s(), new.clock_s(), "{case}");
            ticks += 1;
            assert!(ticks < 2_000_000, "{case}: no progress");
        }
    }
}

#[test]
fn a_short_task_runs_twice_per_pass_of_a_long_one() {
    // Robot 0: [HC, LC, HC, HC, HC, HC] (6 s, one 1 s stretch); robot 1: [HC, LC, HC]
    // (3 s), twice per pass. Order: robot 0's stretch, robot 1's first task's, its second's.
    let long = task(&[true, false, true, true, true, true]);
    let short = task(&[true, false, true]);
    let order = [(0, 0), (1, 0), (1, 1)];
    let mut c = ContinuousCoordinator::mixed(
        &[(long, vec![]), (short, vec![])],
        &[0, 1],
        &[1, 2],
        &order,
        1.0,
    )
    .unwrap();
    assert_eq!(c.tokens().len(), 3);
    assert_eq!(c.task_of(0).n_ref(), 6);
    assert_eq!(c.task_of(1).n_ref(), 3);
    // Tick 0: both move to 1 s (robot 1 to its gate-capped next LC sample), robot 0 holds
    // the token; tick 1: robot 0 on its stretch, robot 1 waits at its gate (sample 0).
    let mut lc_ticks = [0u32; 2];
    for _ in 0..60 {
        let t = c.tick(Operator::Scheduled).unwrap();
        assert!(!t.overlap());
        for (i, n) in lc_ticks.iter_mut().enumerate() {
            *n += u32::from(t.low_conf[i]);
        }
    }
    // Per pass robot 0 completes one task and robot 1 two: after 60 ticks, twice as many.
    let done = c.tasks_completed();
    assert!(done[0] >= 5, "{done:?}");
    assert!(
        done[1] + 1 >= 2 * done[0] && done[1] <= 2 * done[0] + 2,
        "{done:?}"
    );
    assert!(lc_ticks[0] > 0 && lc_ticks[1] > 0);
    // Bad input: a robot naming no task, a task without a robot, a zero ratio.
    let two = [
        (task(&[true, false, true]), vec![]),
        (task(&[false]), vec![]),
    ];
    for (robot_task, ratios) in [
        (&[0, 2][..], &[1, 1][..]),
        (&[0, 0], &[1, 1]),
        (&[0, 1], &[1, 0]),
    ] {
        assert!(matches!(
            ContinuousCoordinator::mixed(&two, robot_task, ratios, &order, 1.0),
            Err(Error::BadParam { .. })
        ));
    }
}

#[test]
fn random_mixed_cells_never_overlap_under_the_adversaries() {
    // N = 2…4, each robot its own random task (different lengths, stretches, holds and
    // rates), ratios 1–3, random runnable orders, switch time 0 or 3 ticks, at a 30 ms tick;
    // every policy of `adversary_set` until each robot has done 20 tasks.
    let mut rng = ChaCha8Rng::seed_from_u64(4545);
    let mut runs = 0;
    for case in 0..18 {
        let n = 2 + case % 3;
        let tasks: Vec<(Timeline, Vec<usize>)> = (0..n)
            .map(|_| random_cell_task(&mut rng, 50, CellHolds::NoneOneThird))
            .collect();
        let gs: Vec<_> = tasks
            .iter()
            .map(|(t, h)| groups(t.conf(), h).unwrap())
            .collect();
        let per_robot: Vec<&[_]> = gs.iter().map(|g| &g[..]).collect();
        let ratios: Vec<usize> = (0..n).map(|_| rng.random_range(1..=3)).collect();
        let order = random_mixed_order(&per_robot, &ratios, &mut rng);
        let robot_task: Vec<usize> = (0..n).collect();
        let switch_s = if case % 2 == 0 { 0.0 } else { 0.09 };
        let cell = ContinuousCoordinator::mixed(&tasks, &robot_task, &ratios, &order, 0.03)
            .unwrap()
            .with_switch_s(switch_s)
            .unwrap();
        for a in adversary_set(n, [0.1, 6.0], 5000, &mut rng) {
            let mut c = cell.clone();
            let run = run_cell(&mut c, a, &mut rng, 20, 50_000_000).unwrap();
            assert!(run.finished && run.min_tasks >= 20, "{case} {a:?} {run:?}");
            assert_eq!(run.overlap_ticks, 0, "{case} {a:?}");
            assert_eq!(
                run.backward_steps, 0,
                "{case} {a:?}: a robot moved backwards"
            );
            if switch_s > 0.0 {
                assert!(
                    run.min_switch_gap_ticks.is_none_or(|g| g >= 3),
                    "{case} {a:?}: {run:?}"
                );
            }
            runs += 1;
        }
    }
    assert!(runs >= 18 * 5);
}

/// Robot 0: one group of two 1 s stretches around a `gap` s high-confidence gap with no hold;
/// robot 1: [HC, LC, HC] (its group: 1 s from its gate, then 1 s of low confidence). Order:
/// robot 0's group, then robot 1's. At a tick of ¼ s.
fn nest_cell(gap: usize) -> ContinuousCoordinator {
    let mut long = vec![true, false];
    long.extend(std::iter::repeat_n(true, gap));
    long.extend([false, true]);
    ContinuousCoordinator::mixed(
        &[(task(&long), vec![]), (task(&[true, false, true]), vec![])],
        &[0, 1],
        &[1, 1],
        &[(0, 0), (0, 1), (1, 0)],
        0.25,
    )
    .unwrap()
}

#[test]
fn a_short_group_is_nested_in_a_long_gap_and_never_overlaps() {
    // Robot 1's group needs at most W = (⌈1/¼⌉ + 1) + (⌈1/(½·¼)⌉ + 1) + 1 = 15 ticks (its
    // 1 s of high confidence, its 1 s stretch at the slowest rate S = ½, the tolerance);
    // robot 0 left its first stretch at 2 s and reaches the next at 8 s: 24 ticks at the
    // most ≥ W + k + 1 for k = 0 and k = 2 (½ s). So the group is nested in every pass.
    for switch_s in [0.0, 0.5] {
        let cell = nest_cell(6).with_switch_s(switch_s).unwrap();
        let nested = cell.clone().with_nesting();
        assert!(nested.nesting() && !cell.nesting());
        // Under the planned operator: 200 ticks (50 s), robot 1 done at least as often, and
        // both robots more tasks than without nesting (robot 1 no longer waits for robot
        // 0's whole group).
        let (mut a, mut b) = (cell.clone(), nested.clone());
        for _ in 0..200 {
            assert!(!a.tick(Operator::Scheduled).unwrap().overlap());
            let t = b.tick(Operator::Scheduled).unwrap();
            assert!(!t.overlap() && t.next.is_none());
        }
        assert!(b.nested_grants() >= 4, "{switch_s}: {}", b.nested_grants());
        let (da, db) = (a.tasks_completed(), b.tasks_completed());
        assert!(db[0] > da[0] && db[1] > da[1], "{switch_s}: {da:?} {db:?}");
        // Every adversary, the beam search among them: 0 overlapping ticks, the switch time.
        let mut rng = ChaCha8Rng::seed_from_u64(4501);
        for adv in adversary_set(2, [0.1, 6.0], 4000, &mut rng) {
            let mut c = nested.clone();
            let run = run_cell(&mut c, adv, &mut rng, 12, 5_000_000).unwrap();
            assert!(run.finished && run.min_tasks >= 12, "{adv:?} {run:?}");
            assert_eq!(run.overlap_ticks, 0, "{switch_s} {adv:?}");
            assert_eq!(run.backward_steps, 0, "{adv:?}");
            if switch_s > 0.0 {
                assert!(
                    run.min_switch_gap_ticks.is_none_or(|g| g >= 2),
                    "{adv:?} {run:?}"
                );
            }
        }
    }
}

#[test]
fn a_group_too_long_for_the_gap_is_not_nested() {
    // A gap of 2 s (at most 8 ticks before robot 0 is low-confidence again) is shorter than
    // robot 1's W = 15 ticks; a gap of 6 s (24 ticks) with a switch time of 2½ s (k = 10) is
    // too (24 < 15 + 10 + 1). Nothing is nested, and the cell ticks exactly as without
    // nesting (but for the pre-alert, not computed with nesting).
    for (gap, switch_s) in [(2, 0.0), (6, 2.5)] {
        let plain = nest_cell(gap).with_switch_s(switch_s).unwrap();
        let mut a = plain.clone();
        let mut b = plain.with_nesting();
        for op in [Operator::Scheduled, Operator::Fastest, Operator::Slowest] {
            for _ in 0..300 {
                let (mut ta, tb) = (a.tick(op).unwrap(), b.tick(op).unwrap());
                ta.next = None;
                assert_eq!(ta, tb, "gap {gap} switch {switch_s}");
            }
        }
        assert_eq!(b.nested_grants(), 0);
        assert!(b.tasks_completed().iter().all(|&k| k > 5));
    }
}

#[test]
fn random_mixed_cells_with_nesting_never_overlap_under_the_adversaries() {
    // N = 2…8, each robot its own random task (holds on none or a third of the gaps), ratios
    // 1–3, random runnable orders, switch time 0 or 3 ticks, 30 ms tick, nesting on: every
    // policy of `adversary_set` (the beam search among them) until each robot has done 8
    // tasks: 0 overlapping ticks, the switch time kept; and groups are nested (not vacuous).
    let mut rng = ChaCha8Rng::seed_from_u64(4546);
    let (mut runs, mut nested) = (0, 0);
    for case in 0..14 {
        let n = 2 + case % 7;
        let tasks: Vec<(Timeline, Vec<usize>)> = (0..n)
            .map(|_| random_cell_task(&mut rng, 50, CellHolds::NoneOneThird))
            .collect();
        let gs: Vec<_> = tasks
            .iter()
            .map(|(t, h)| groups(t.conf(), h).unwrap())
            .collect();
        let per_robot: Vec<&[_]> = gs.iter().map(|g| &g[..]).collect();
        let ratios: Vec<usize> = (0..n).map(|_| rng.random_range(1..=3)).collect();
        let order = random_mixed_order(&per_robot, &ratios, &mut rng);
        let robot_task: Vec<usize> = (0..n).collect();
        let switch_s = if case % 2 == 0 { 0.0 } else { 0.09 };
        let cell = ContinuousCoordinator::mixed(&tasks, &robot_task, &ratios, &order, 0.03)
            .unwrap()
            .with_switch_s(switch_s)
            .unwrap()
            .with_nesting();
        for a in adversary_set(n, [0.1, 6.0], 5000, &mut rng) {
            let mut c = cell.clone();
            let run = run_cell(&mut c, a, &mut rng, 8, 50_000_000).unwrap();
            assert!(run.finished && run.min_tasks >= 8, "{case} {a:?} {run:?}");
            assert_eq!(run.overlap_ticks, 0, "{case} {a:?}");
            assert_eq!(run.backward_steps, 0, "{case} {a:?}");
            if switch_s > 0.0 {
                assert!(
                    run.min_switch_gap_ticks.is_none_or(|g| g >= 3),
                    "{case} {a:?}: {run:?}"
                );
            }
            nested += c.nested_grants();
            runs += 1;
        }
    }
    assert!(runs >= 14 * 5);
    assert!(nested > 0, "no group was nested in {runs} runs");
    eprintln!("{runs} runs, {nested} nested grants");
}
