//! A cell of different tasks in the simulated workcell and study (issue 45), on the committed
//! cell file `fixtures/mixed/cell_1_1.toml` (1 sanding robot + 1 deburring robot): rounds run
//! and are recorded into each task, never two robots low-confidence in one tick, the learned
//! confidence never trusts where the truth can need the operator (the latch may give a
//! sample back after a correction on it, `Confidence::update_round`, so no monotony is asked), deterministic, and a
//! one-task cell is the single-task round bit for bit.

use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_planner::CellPlanner;
use tandem_sim::study::{
    Cell, CellFile, MixedTask, StudyConfig, StudyOperator, run_mixed_cell_study,
    run_mixed_cell_trial, run_mixed_study, run_mixed_trial,
};
use tandem_sim::workcell::{OperatorParams, run_cell_round, run_round_with};

fn mixed_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/mixed")
}

fn cell_file(name: &str) -> CellFile {
    let text = std::fs::read_to_string(mixed_dir().join(name)).unwrap();
    toml::from_str(&text).unwrap()
}

fn config(executions: usize, robots: usize) -> StudyConfig {
    StudyConfig {
        trials: 2,
        executions,
        robots,
        samples: 100,
        ..StudyConfig::default()
    }
}

fn tasks(file: &CellFile, config: &StudyConfig) -> Vec<MixedTask> {
    file.tasks(&mixed_dir(), config).unwrap()
}

#[test]
fn mixed_rounds_learn_each_task_without_overlap_and_deterministically() {
    let file = cell_file("cell_1_1.toml");
    assert_eq!(file.n_robots(), 2);
    let config = config(8, 2);
    let tasks = tasks(&file, &config);
    let result = run_mixed_study(&config, &tasks, &|_| {}).unwrap();
    assert_eq!(result.tasks, ["sanding", "deburring"]);
    assert_eq!(result.robot_task, [0, 1]);
    assert_eq!(result.overlaps_and_faults(), (0, 0));
    for trial in &result.trials {
        assert_eq!(trial.iterations.len(), 5, "iterations 0..=4");
        for (k, it) in trial.iterations.iter().enumerate() {
            assert_eq!(it.iteration, k);
            assert_eq!(it.round.is_some(), k < 4);
            assert!(it.lower_bound_s <= it.t_total_s + 1e-9);
            for t in &it.tasks {
                // Never trusted where a workpiece can need the operator.
                assert_eq!(t.falsely_trusted_samples, 0);
                assert!(t.high_conf_pct <= t.truth_never_needed_pct + 1e-9);
                // The operator-seconds of a task are part of its fastest duration.
                assert!(t.lc_s > 0.0 && t.lc_s <= t.fastest_s, "{t:?}");
            }
            if let Some(r) = &it.round {
                // The round ran the whole cell: at least the slower robot's planned time.
                assert!(r.duration_s >= 0.99 * r.planned_t_total_s, "{r:?}");
                assert!(r.supervised_ticks > 0);
            }
        }
        // The operator corrected where the sanding and the burr need it.
        assert!(trial.tally.needed > 0 && trial.tally.missed < trial.tally.needed);
    }
    // Deterministic: the same trial again gives the same record.
    let again = run_mixed_trial(&config, &tasks, 1, &|_| {}).unwrap();
    assert_eq!(again, result.trials[1]);
}

#[test]
fn the_study_refuses_a_robot_count_other_than_the_cells() {
    let file = cell_file("cell_1_1.toml");
    let config = config(6, 3);
    let tasks = tasks(&file, &config);
    let e = run_mixed_trial(&config, &tasks, 0, &|_| {}).unwrap_err();
    assert!(e.to_string().contains("robots"), "{e}");
}

#[test]
fn a_bad_correction_channel_is_named() {
    let mut file = cell_file("cell_1_1.toml");
    if let tandem_sim::study::CellTruth::Need { channel, .. } = &mut file.task[1].truth {
        *channel = "torque".into();
    }
    let e = file.tasks(&mixed_dir(), &config(6, 2)).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("torque") && msg.contains("deburring"), "{msg}");
}

#[test]
fn a_one_task_cell_runs_the_single_task_round() {
    let file = cell_file("sanding_only.toml");
    let config = config(2, 2);
    let mut tasks = tasks(&file, &config);
    let task = tasks.remove(0);
    let planner =
        tandem_planner::Planner::from_model_with_robots(task.model, task.params, 2).unwrap();
    let cell = CellPlanner::from_planner("sanding", planner.clone()).unwrap();
    let op = OperatorParams::default();
    let needs = |robot: usize, k: usize| (k / 500 + robot) % 3 == 0;
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let a = run_cell_round(&cell, needs, std::slice::from_ref(&op), &mut rng).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let b = run_round_with(&planner, needs, &op, &mut rng).unwrap();
    assert_eq!(a, b);
    assert_eq!(
        a.cell_records(&cell).unwrap(),
        b.records(planner.model()).unwrap()
    );
    // One operator per task.
    let e = run_cell_round(&cell, needs, &[op.clone(), op], &mut rng).unwrap_err();
    assert!(e.to_string().contains("operators"), "{e}");
}

/// The continuous cell of different tasks (`cargo xtask study --cell continuous
/// --cell-file`): 1 sanding + 1 deburring robot, each task with the cell file's holds, until
/// the cell has completed 10 tasks. Never two robots low-confidence in one tick; a plan per
/// record, each at least its bound and at most the mixed operator-limited bound; every
/// completed task is either recorded (one per robot per record, the oldest first) or still
/// queued; never trusted where the truth can need the operator; deterministic.
#[test]
fn the_continuous_mixed_study_learns_each_task_and_never_overlaps() {
    let file = cell_file("cell_1_1.toml");
    let config = StudyConfig {
        cell: Cell::Continuous,
        trials: 1,
        ..config(10, 2)
    };
    let tasks = tasks(&file, &config);
    let result = run_mixed_cell_study(&config, &tasks, &|_| {}).unwrap();
    assert_eq!(result.tasks, ["sanding", "deburring"]);
    assert_eq!(result.overlaps_and_faults(), (0, 0));
    let trial = &result.trials[0];
    assert_eq!(trial.completions.len(), 10);
    let records = trial.iterations.last().unwrap().records;
    assert!(records >= 1, "no record in 10 tasks");
    assert_eq!(trial.iterations.len(), records + 1);
    assert!(trial.stats.hand_overs <= records as u64);
    for (k, it) in trial.iterations.iter().enumerate() {
        assert_eq!(it.records, k);
        assert!(it.period_s >= it.lower_bound_s - 1e-9, "{it:?}");
        assert!(
            it.tasks_per_hour <= it.operator_limited_per_hour + 1e-6,
            "{it:?}"
        );
        assert!(it.tasks_per_hour <= it.best_bound_per_hour + 1e-6, "{it:?}");
        for t in &it.tasks {
            assert_eq!(t.falsely_trusted_samples, 0);
            assert!(t.high_conf_pct <= t.truth_never_needed_pct + 1e-9);
        }
    }
    // Every execution a robot finished is recorded as a round of its task (one robot per
    // task here) except those still queued, whatever the ratios: the number of recorded
    // rounds per task equals its executions less its queue.
    let last = trial.iterations.last().unwrap();
    for robot in 0..2 {
        let done = trial
            .completions
            .iter()
            .filter(|c| c.robot == robot)
            .count();
        assert_eq!(
            done,
            last.task_rounds[robot] + trial.unrecorded[robot],
            "robot {robot}"
        );
    }
    // A record step records at least one round of every task, so the slower task (sanding,
    // one per period) has one per step; the faster one at least as many.
    for it in &trial.iterations {
        assert_eq!(it.task_rounds[0], it.records, "{it:?}");
        assert!(it.task_rounds[1] >= it.task_rounds[0], "{it:?}");
        assert!(it.best_operator_limited_share <= 1.0 + 1e-12, "{it:?}");
        assert!(
            it.operator_share <= it.best_operator_limited_share + 1e-9,
            "{it:?}"
        );
    }
    // The plans ran at ratios above 1 for deburring, so it recorded more rounds than sanding.
    assert!(
        last.task_rounds[1] > last.task_rounds[0],
        "{:?}",
        last.task_rounds
    );
    assert!(trial.completions.windows(2).all(|w| w[0].tick <= w[1].tick));
    assert_eq!(
        trial.steady.tasks_per_robot.iter().sum::<usize>(),
        trial.steady.tasks
    );
    let again = run_mixed_cell_trial(&config, &tasks, 0, &|_| {}).unwrap();
    assert_eq!(&again, trial);
    // More than one operator is refused by name.
    let two = StudyConfig {
        operator: StudyOperator {
            operators: 2,
            ..config.operator.clone()
        },
        ..config.clone()
    };
    let e = run_mixed_cell_trial(&two, &tasks, 0, &|_| {}).unwrap_err();
    assert!(e.to_string().contains("operator.operators"), "{e}");
}
