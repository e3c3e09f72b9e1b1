//! A cell of different tasks on the committed fixtures (issue 45): two sanding robots
//! (`fixtures/sanding`) and one robot of the task zoo's deburring (`fixtures/mixed/deburring`),
//! and one of each: fitted, scheduled in rounds, and run by the coordinator against every
//! adversary without two robots low-confidence in one tick; and run continuously
//! (`CellPlanner::continuous_coordinator`, issue 45): at the plan's period under the planned
//! operator, without overlap under the adversaries.

use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_lfd::Demonstration;
use tandem_planner::{CellPlanner, PlannerParams, TaskSpec};
use tandem_realtime::Operator;
use tandem_realtime::adversary::{Adversary, adversary_set, run_adversary, run_adversary_on};

fn fixtures(dir: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures")
        .join(dir)
}

fn demos(dir: &str, n: usize) -> Vec<Demonstration> {
    (0..n)
        .map(|i| {
            Demonstration::from_csv_path(fixtures(dir).join(format!("demo_{i}.csv")), None).unwrap()
        })
        .collect()
}

fn cell(sanding_robots: usize) -> CellPlanner {
    let params = PlannerParams::default();
    CellPlanner::fit(&[
        TaskSpec {
            name: "sanding".into(),
            demos: demos("sanding", 6),
            params: params.clone(),
            robots: sanding_robots,
        },
        TaskSpec {
            name: "deburring".into(),
            demos: demos("mixed/deburring", 4),
            params,
            robots: 1,
        },
    ])
    .unwrap()
}

fn check(cell: &CellPlanner) {
    let s = cell.schedule().unwrap();
    let n = cell.n_robots();
    assert_eq!(s.grad_exec.len(), n);
    let timelines = cell.timelines().unwrap();
    // Each robot runs its own task's reference: sanding at 100 Hz, deburring at 200–250 Hz.
    for (i, t) in timelines.iter().enumerate() {
        let task = cell.tasks()[cell.robot_task()[i]].planner();
        assert_eq!(t.n_ref(), task.model().n_ref());
    }
    assert!(s.lower_bound_s <= s.t_total_s);
    // Never slower than the robots one after the other on their planned warps.
    let serial: f64 = timelines.iter().map(|t| t.end_s() - t.start_s()).sum();
    assert!(s.t_total_s <= serial + n as f64 * s.tick_s + 1e-9);
    let coordinator = cell.coordinator().unwrap();
    let ticks = (s.t_total_s / s.tick_s) as u64;
    let mut rng = ChaCha8Rng::seed_from_u64(45);
    for adversary in adversary_set(n, [1.0, 1.0], ticks, &mut rng) {
        // The beam search runs over every progress cell of a 50,000-tick round: covered by
        // the realtime crate's tests, left out here.
        if matches!(
            adversary,
            Adversary::Beam { .. } | Adversary::Random { .. } | Adversary::RandomHeld { .. }
        ) {
            continue;
        }
        let run =
            run_adversary(coordinator.clone(), adversary, &mut rng, 4 * ticks + 1000).unwrap();
        assert!(run.finished, "{adversary:?}");
        assert_eq!(run.overlap_ticks, 0, "{adversary:?}");
        assert_eq!(run.backward_steps, 0, "{adversary:?}");
    }
}

/// The continuous cell of `cell`'s plan: under the planned operator, the realized period
/// over the passes after the first two (robot 0's tasks `2·r_0..8·r_0`) within 2 % of the
/// plan's, every robot's tasks in the plan's ratios; every adversary but the beam search and
/// the random-gradient ones (per task ranges) until each robot has done `2·r` tasks: 0
/// overlapping ticks, no backward step.
fn check_continuous(cell: &CellPlanner) {
    let plan = cell.continuous_plan().unwrap();
    let mut c = cell.continuous_coordinator(&plan).unwrap();
    let (tick_s, r0) = (c.tick_s(), plan.ratios[0] as u64);
    let mut from = None;
    let limit = (20.0 * plan.period_s / tick_s) as u64;
    for tick in 1..=limit {
        let t = c.tick(Operator::Scheduled).unwrap();
        assert!(!t.overlap());
        let done = c.tasks_completed().to_vec();
        if from.is_none() && done[0] == 2 * r0 {
            from = Some((tick, done.clone()));
        }
        if done[0] == 8 * r0 {
            let (t2, d2) = from.unwrap();
            let period_s = (tick - t2) as f64 * tick_s / 6.0;
            eprintln!(
                "continuous {:?}: plan {:.2} s ({:.1} tasks/h, operator-limited {:.1}), \
                 realized {period_s:.2} s ({:.1} tasks/h)",
                plan.ratios,
                plan.period_s,
                plan.tasks_per_hour,
                plan.operator_limited_per_hour,
                3600.0 * plan.ratios.iter().sum::<usize>() as f64 / period_s
            );
            assert!((period_s - plan.period_s).abs() <= 0.02 * plan.period_s);
            for (k, &r) in plan.ratios.iter().enumerate() {
                let got = done[k] - d2[k];
                assert!(
                    got + 1 >= 6 * r as u64 && got <= 6 * r as u64 + 1,
                    "{k}: {got}"
                );
            }
            break;
        }
        assert!(tick < limit, "robot 0 did not complete {} tasks", 8 * r0);
    }
    let min_tasks = 2 * plan.ratios.iter().max().copied().unwrap_or(1) as u64;
    let budget = (10.0 * min_tasks as f64 * plan.period_s / tick_s) as u64;
    let mut rng = ChaCha8Rng::seed_from_u64(4545);
    for adversary in adversary_set(cell.n_robots(), [1.0, 1.0], budget, &mut rng) {
        if matches!(
            adversary,
            Adversary::Beam { .. } | Adversary::Random { .. } | Adversary::RandomHeld { .. }
        ) {
            continue;
        }
        let mut cell = cell.continuous_coordinator(&plan).unwrap();
        let run = run_adversary_on(&mut cell, adversary, &mut rng, min_tasks, budget).unwrap();
        assert!(run.finished, "{adversary:?} {run:?}");
        assert_eq!(run.overlap_ticks, 0, "{adversary:?}");
        assert_eq!(run.backward_steps, 0, "{adversary:?}");
    }
}

#[test]
fn two_sanding_robots_and_one_deburring_robot() {
    let c = cell(2);
    assert_eq!(c.robot_task(), [0, 0, 1]);
    check(&c);
    check_continuous(&c);
}

#[test]
fn one_sanding_robot_and_one_deburring_robot() {
    let c = cell(1);
    assert_eq!(c.robot_task(), [0, 1]);
    check(&c);
    check_continuous(&c);
}
