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
