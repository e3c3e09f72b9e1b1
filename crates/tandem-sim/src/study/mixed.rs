//! The simulated study with a cell of different tasks in rounds (issue 45): each robot does
//! its own task, a round is one execution of every robot ([`crate::workcell::run_cell_round`]),
//! each task learns from its own robots' executions ([`CellPlanner::record_round`]) and the
//! cell is re-scheduled after every round.
//!
//! Every task has its own ground truth ([`TaskTruth`]); every robot's workpiece of every
//! round is drawn from its task's truth, robot 1 first, from the trial's one random stream
//! (ChaCha8 of [`trial_seed`], stream 1), then the round runs on the same stream: a trial is
//! deterministic for its seed and independent of the thread count.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;
use tandem_lfd::TaskModel;
use tandem_planner::{CellPlanner, Planner, PlannerParams};

use super::config::StudyConfig;
use super::run::{Progress, trial_seed};
use crate::truth::{OperatorTally, TaskTruth, falsely_trusted_where};
use crate::workcell::{self, OperatorParams, RoundRun};
use crate::{Error, Result};

/// One task of a mixed study: its name, fitted model, planner parameters, ground truth and
/// number of robots.
pub struct MixedTask {
    /// The task's name (letters, digits, `_`, `-`; unique in the cell).
    pub name: String,
    /// Its fitted model (on its own demonstrations).
    pub model: TaskModel,
    /// Its planner's parameters (the sampler's seed is set per trial; the operator's switch
    /// time and load cap are the study's, [`StudyConfig::operator`]).
    pub params: PlannerParams,
    /// Where its workpieces need the operator, on its model's reference samples.
    pub truth: Box<dyn TaskTruth>,
    /// How many robots of the cell do it (≥ 1).
    pub robots: usize,
}

impl std::fmt::Debug for MixedTask {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MixedTask")
            .field("name", &self.name)
            .field("n_ref", &self.model.n_ref())
            .field("robots", &self.robots)
            .finish_non_exhaustive()
    }
}

/// One task's learning after some rounds, against its truth.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MixedTaskState {
    /// Share of its reference samples that are high-confidence (%).
    pub high_conf_pct: f64,
    /// Share of its reference samples where no workpiece ever needs the operator (%): the
    /// most the confidence can truthfully trust.
    pub truth_never_needed_pct: f64,
    /// High-confidence samples where some workpiece can need the operator.
    pub falsely_trusted_samples: usize,
    /// The task's fastest admissible duration `D` (s) on its current problem
    /// ([`tandem_schedule::cyclic::MixTask::fastest_s`]).
    pub fastest_s: f64,
    /// Its low-confidence time per task at the operator's mean rate `L` (s)
    /// ([`tandem_schedule::cyclic::MixTask::lc_s`]): the operator-seconds one task needs.
    pub lc_s: f64,
}

/// What one round of a mixed cell did.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MixedRoundStats {
    /// Ticks in which two or more robots were low-confidence (must be 0).
    pub overlap_ticks: usize,
    /// Faults of the run-time monitor (must be 0).
    pub faults: usize,
    /// The round's duration (s).
    pub duration_s: f64,
    /// The schedule's planned `T_total` (s).
    pub planned_t_total_s: f64,
    /// Share of the round in which the operator supervised a robot.
    pub operator_busy_share: f64,
    /// Supervised samples (control ticks), over all robots.
    pub supervised_ticks: usize,
    /// Corrected samples, over all robots.
    pub corrected_ticks: usize,
}

/// The cell's schedule after `iteration` recorded rounds and the round run under it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MixedIteration {
    /// Rounds recorded before this schedule (0: demonstrations only).
    pub iteration: usize,
    /// The schedule's `T_total` (s): the last robot's planned end.
    pub t_total_s: f64,
    /// The mixed lower bound on `T_total` of every rounds schedule (s,
    /// [`tandem_planner::CellSchedule::lower_bound_s`]).
    pub lower_bound_s: f64,
    /// Start offsets of robots 2..N (s).
    pub offsets_s: Vec<f64>,
    /// Per task (the cell's order), its learning against its truth.
    pub tasks: Vec<MixedTaskState>,
    /// The round run under this schedule (none for the last iteration).
    pub round: Option<MixedRoundStats>,
}

/// One trial of a mixed study.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MixedTrialResult {
    /// Trial index.
    pub trial: usize,
    /// Its seed ([`trial_seed`]).
    pub seed: u64,
    /// Iteration 0 (demonstrations only) to the last.
    pub iterations: Vec<MixedIteration>,
    /// The simulated operator's decisions over the trial.
    pub tally: OperatorTally,
    /// The cell run continuously on the last iteration's problems: the best task ratios and
    /// operator order found and their period against the bound
    /// (`tandem_planner::CellPlanner::continuous_plan`; a plan, not a run).
    pub continuous_plan: tandem_schedule::cyclic::MixedCyclicPlan,
}

/// A mixed study: every trial, the task names and the robot → task map.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MixedStudyResult {
    /// The tasks' names, in the cell's order.
    pub tasks: Vec<String>,
    /// Robot `i` does task `robot_task[i]`.
    pub robot_task: Vec<usize>,
    /// Every trial, in order.
    pub trials: Vec<MixedTrialResult>,
}

impl MixedStudyResult {
    /// Overlapping ticks and faults over every round of every trial (both must be 0).
    #[must_use]
    pub fn overlaps_and_faults(&self) -> (usize, usize) {
        self.trials
            .iter()
            .flat_map(|t| &t.iterations)
            .filter_map(|i| i.round.as_ref())
            .fold((0, 0), |(o, f), r| (o + r.overlap_ticks, f + r.faults))
    }
}

/// The simulated operator on each task: the study's rates, corrections that raise the task
/// truth's [`TaskTruth::correction_channel`].
pub(super) fn operators(config: &StudyConfig, tasks: &[MixedTask]) -> Vec<OperatorParams> {
    tasks
        .iter()
        .map(|t| OperatorParams {
            force_channel: t.truth.correction_channel().to_string(),
            ..config.operator()
        })
        .collect()
}

/// The cell of a trial: each task's planner on its model (its parameters with the study's
/// operator, the sampler seeded with `seed`), the robots numbered task by task.
pub(super) fn trial_cell(
    config: &StudyConfig,
    tasks: &[MixedTask],
    seed: u64,
) -> Result<CellPlanner> {
    let mut planners = Vec::with_capacity(tasks.len());
    let mut robot_task = Vec::new();
    for (t, task) in tasks.iter().enumerate() {
        if task.truth.n_ref() != task.model.n_ref() {
            return Err(Error::Mismatch {
                what: "ground truth of a task (one value per reference sample)",
                expected: task.model.n_ref(),
                found: task.truth.n_ref(),
            });
        }
        let mut params = task.params.clone();
        params.sampler.samples = config.samples;
        params.sampler.seed = seed;
        params.sampler.switch_s = config.operator.switch_s;
        params.sampler.max_busy_share = config.operator.max_busy_share;
        let planner = Planner::from_model_with_robots(task.model.clone(), params, task.robots)?;
        planners.push((task.name.clone(), planner));
        robot_task.extend(std::iter::repeat_n(t, task.robots));
    }
    Ok(CellPlanner::from_planners(planners, robot_task)?)
}

/// The record of the cell's current schedule (its round not run yet).
fn iteration(cell: &CellPlanner, tasks: &[MixedTask]) -> MixedIteration {
    let (t_total_s, lower_bound_s, offsets_s) = match cell.schedule() {
        Some(s) => (s.t_total_s, s.lower_bound_s, s.offsets_s.clone()),
        None => {
            let p = cell.tasks()[0].planner();
            (
                p.outcome().t_total_s,
                p.outcome().lower_bound_s,
                p.schedule().offsets_s.clone(),
            )
        }
    };
    MixedIteration {
        iteration: cell.rounds_recorded(),
        t_total_s,
        lower_bound_s,
        offsets_s,
        tasks: task_states(cell, tasks),
        round: None,
    }
}

/// Each task's learning in `cell` against its truth (the cell's task order).
pub(super) fn task_states(cell: &CellPlanner, tasks: &[MixedTask]) -> Vec<MixedTaskState> {
    cell.tasks()
        .iter()
        .zip(tasks)
        .map(|(c, t)| {
            let conf = c.planner().confidence();
            let mix = tandem_schedule::cyclic::MixTask::of(c.planner().problem());
            MixedTaskState {
                fastest_s: mix.fastest_s,
                lc_s: mix.lc_s,
                high_conf_pct: 100.0 * conf.high_share(),
                truth_never_needed_pct: 100.0 * t.truth.never_needed_share(),
                falsely_trusted_samples: falsely_trusted_where(conf.conf(), t.truth.can_need()),
            }
        })
        .collect()
}

fn round_stats(run: &RoundRun) -> MixedRoundStats {
    let count = |pick: fn(&workcell::RobotRun) -> &Vec<bool>| {
        run.robots
            .iter()
            .map(|r| pick(r).iter().filter(|b| **b).count())
            .sum()
    };
    MixedRoundStats {
        overlap_ticks: run.overlap_ticks,
        faults: run.faults,
        duration_s: run.duration_s(),
        planned_t_total_s: run.planned_t_total_s,
        operator_busy_share: run.operator_busy_share(),
        supervised_ticks: count(|r| &r.supervised),
        corrected_ticks: count(|r| &r.corrected),
    }
}

/// Runs trial `trial` of a mixed study in rounds (module docs): `config.n_rounds()` rounds,
/// where `config.robots` must be the cell's robot count. Reports `progress` after every
/// recorded round.
///
/// # Errors
/// [`Error::Mismatch`] for `config.robots` other than the tasks' robots together or a truth
/// on another number of reference samples than its model; invalid configuration; any
/// stage's error, named by trial and round ([`Error::InTrial`]).
pub fn run_mixed_trial(
    config: &StudyConfig,
    tasks: &[MixedTask],
    trial: usize,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<MixedTrialResult> {
    config.validate()?;
    let n: usize = tasks.iter().map(|t| t.robots).sum();
    if n != config.robots {
        return Err(Error::Mismatch {
            what: "robots of the study (the cell's robots, every task's together)",
            expected: n,
            found: config.robots,
        });
    }
    let seed = trial_seed(config.seed, trial);
    let mut cell = trial_cell(config, tasks, seed)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(1);
    let ops = operators(config, tasks);
    let mut tally = OperatorTally::default();
    let mut iterations = vec![iteration(&cell, tasks)];
    for round in 1..=config.n_rounds() {
        let in_round = |e: Error| Error::InTrial {
            trial,
            round,
            source: Box::new(e),
        };
        let needed = cell
            .robot_task()
            .iter()
            .map(|&t| tasks[t].truth.draw(&mut rng))
            .collect::<Result<Vec<_>>>()?;
        let run = workcell::run_cell_round(&cell, |i, k| needed[i][k], &ops, &mut rng)
            .map_err(in_round)?;
        tally.add(&run);
        let records = run.cell_records(&cell).map_err(in_round)?;
        cell.record_round(&records)
            .map_err(|e| in_round(e.into()))?;
        iterations
            .last_mut()
            .expect("the first schedule's record is pushed first")
            .round = Some(round_stats(&run));
        iterations.push(iteration(&cell, tasks));
        progress(Progress {
            trial,
            rounds_done: round,
        });
    }
    let continuous_plan = cell.continuous_plan().map_err(|e| Error::InTrial {
        trial,
        round: config.n_rounds(),
        source: Box::new(e.into()),
    })?;
    Ok(MixedTrialResult {
        trial,
        seed,
        iterations,
        tally,
        continuous_plan,
    })
}

/// Runs every trial of a mixed study ([`run_mixed_trial`]) in parallel; the result does not
/// depend on the thread count.
///
/// # Errors
/// The first failing trial's error (in trial order).
pub fn run_mixed_study(
    config: &StudyConfig,
    tasks: &[MixedTask],
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<MixedStudyResult> {
    let (tasks_named, robot_task, trials) = run_trials(config, tasks, |k| {
        run_mixed_trial(config, tasks, k, progress)
    })?;
    Ok(MixedStudyResult {
        tasks: tasks_named,
        robot_task,
        trials,
    })
}

/// The trials `0..config.trials` of a mixed study run in parallel by `trial` (the result in
/// trial order, so it does not depend on the thread count; the first failing trial's error),
/// with the tasks' names and each robot's task index (robots of task 0 first) beside them:
/// what the rounds and the continuous mixed studies both report.
pub(super) fn run_trials<T: Send>(
    config: &StudyConfig,
    tasks: &[MixedTask],
    trial: impl Fn(usize) -> Result<T> + Sync + Send,
) -> Result<(Vec<String>, Vec<usize>, Vec<T>)> {
    let trials = (0..config.trials)
        .into_par_iter()
        .map(&trial)
        .collect::<Vec<_>>()
        .into_iter()
        .collect::<Result<Vec<_>>>()?;
    let mut robot_task = Vec::new();
    for (t, task) in tasks.iter().enumerate() {
        robot_task.extend(std::iter::repeat_n(t, task.robots));
    }
    Ok((
        tasks.iter().map(|t| t.name.clone()).collect(),
        robot_task,
        trials,
    ))
}
