//! The study with a continuous cell of different tasks (issue 45, `cargo xtask study --cell
//! continuous --cell-file FILE`): each robot repeats its own task under the mixed cyclic
//! plan's coordinator ([`tandem_planner::CellPlanner::continuous_plan`],
//! [`crate::workcell::MixedCellSim`]), robot `k` doing `r_k` tasks per period, and every
//! task learns from its own robots' executions.
//!
//! **The learning rule.** A task's unit of learning is a round of that task: as many
//! executions as it has robots ([`CellPlanner::record_task_rounds`]; its planner updates its
//! model and confidence from each execution alike, whichever of its robots ran it). In a
//! mixed cell the robots complete tasks in the ratios `r_k`, so each task's finished
//! executions wait in the task's queue, in completion order. Once every task has a round
//! complete, *every* complete round of every task is recorded — for each task, oldest first,
//! as many rounds as its queue holds executions of its robot count —, the cell is
//! re-planned on the new problems and the new plan takes over the running cell at its next
//! hand-over point ([`ContinuousCoordinator::take_over`](tandem_realtime::continuous::ContinuousCoordinator::take_over)).
//! So a robot of ratio `r_k` gives its task about `r_k` executions per period, and a higher
//! ratio never slows its task's learning per execution: at every re-plan each task has
//! recorded every execution its robots finished but fewer than its robot count. The plans
//! are made as often as before (once per completion of the slowest task): a plan searches
//! the ratio vectors and orders, so one per execution of the fast robot would multiply the
//! cost of a trial by its ratio. docs/decisions.md, "Mixed cells: every execution recorded,
//! and the two bounds (issue 45)".
//! *Why it is unbiased:* which executions of a robot are recorded is fixed by the counts
//! alone (the task's `j`-th recorded execution is the `j`-th its robots finished), never by
//! what an execution held; so each task's recorded executions are a prefix of its executions
//! in completion order,
//! each drawn from its task's truth like any other. Taking the newest instead, or the one in
//! progress when the slowest robot finishes, would favour the executions that ran long
//! (length-biased: the ones with more corrections).
//!
//! Workpieces are drawn from each robot's task truth ([`crate::truth::TaskTruth`]) on the
//! trial's one random stream (ChaCha8 of [`trial_seed`], stream 1): every robot's first in
//! robot order, then each robot's next when it finishes a task, on the stream the ticks also
//! draw from.
//! A trial is deterministic for its seed.
//!
//! The steady throughput ([`MixedSteady`]) is taken over the last tasks, at least 10 % of
//! them and two periods of the last plan, rounded up to whole periods (`Σ r_k` tasks).

use std::collections::VecDeque;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::Serialize;
use tandem_lfd::TaskModel;
use tandem_planner::{CellPlanner, ExecutionRecord};
use tandem_realtime::continuous::ContinuousCoordinator;
use tandem_schedule::cyclic::MixedCyclicPlan;

use super::config::StudyConfig;
use super::mixed::{MixedTask, MixedTaskState, operators, run_trials, task_states, trial_cell};
use super::run::{Progress, trial_seed};
use crate::workcell::{CellStats, MixedCellSim, mixed_record};
use crate::{Error, Result};

/// The cell's continuous plan after some records: one per re-plan of a trial.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MixedCellIteration {
    /// Record steps before the plan was made (0: demonstrations only); each records every
    /// complete round of every task (module docs).
    pub records: usize,
    /// Per task (the cell's order), the rounds it had recorded when the plan was made: each
    /// as many executions as it has robots ([`CellPlanner::task_rounds`]).
    pub task_rounds: Vec<usize>,
    /// The cell's tick (control ticks from the trial start) at which it was made.
    pub tick: u64,
    /// `r_k` per robot: tasks per period.
    pub ratios: Vec<usize>,
    /// The plan's least period `P` (s).
    pub period_s: f64,
    /// `3600·Σ r_k / P`.
    pub tasks_per_hour: f64,
    /// The plan's operator busy share `Σ r_k L_k / P`.
    pub operator_share: f64,
    /// The period's lower bound (s) for these ratios, over every order.
    pub lower_bound_s: f64,
    /// The mixed operator-limited bound of these ratios (tasks/h):
    /// `3600 / (Σ r_k L_k / Σ r_k)`, 3600 over the mean operator-seconds per task of the mix.
    pub operator_limited_per_hour: f64,
    /// The best bound over every ratio vector searched (tasks/h): the most tasks per hour
    /// any plan the token rule can run (ratios `≤ R`, the hand-overs counted) can complete,
    /// `max_r 3600·Σ r_k / P_min(r)` with `P_min(r) ≥ max(operator time, max_k r_k·D_k)`:
    /// the robot-limited and operator-limited bounds together.
    pub best_bound_per_hour: f64,
    /// The largest share of its ratios' operator-limited bound any such plan can reach
    /// (`MixedCyclicPlan::best_operator_limited_share`): below 0.95 no plan of ratios `≤ R`
    /// reaches 95 % of it.
    pub best_operator_limited_share: f64,
    /// `R`, the largest ratio searched.
    pub max_ratio: usize,
    /// Per task, the low-confidence groups the token rule hands the operator per task
    /// (split by the task's usable holds).
    pub groups: Vec<usize>,
    /// Per task (the cell's order), its learning against its truth.
    pub tasks: Vec<MixedTaskState>,
}

/// A completed task of a mixed continuous trial.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MixedCellCompletion {
    /// The robot (0-based).
    pub robot: usize,
    /// Cell ticks run when it finished.
    pub tick: u64,
    /// Ticks with the operator busy until then (cumulative).
    pub busy_ticks: u64,
}

/// The steady state of a mixed continuous trial: its last tasks (module docs).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MixedSteady {
    /// Tasks in the window.
    pub tasks: usize,
    /// Its length (s of cell time), from the completion before the window.
    pub duration_s: f64,
    /// Tasks per hour over the window.
    pub throughput_per_h: f64,
    /// Share of the window's ticks with a robot low-confidence.
    pub operator_busy_share: f64,
    /// The window's tasks per robot.
    pub tasks_per_robot: Vec<usize>,
}

/// One trial of the mixed continuous study.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MixedCellTrialResult {
    /// Trial index.
    pub trial: usize,
    /// Its seed ([`trial_seed`]).
    pub seed: u64,
    /// The plans, the first one (demonstrations only) first.
    pub iterations: Vec<MixedCellIteration>,
    /// Every completed task, in completion order.
    pub completions: Vec<MixedCellCompletion>,
    /// Executions finished but not recorded at the end, per robot: the completions of task
    /// `t`'s robots are its recorded rounds (the last plan's `task_rounds[t]`) times its robot
    /// count plus these, fewer than its robot count, unless the trial ended between a
    /// completion and the next record.
    pub unrecorded: Vec<usize>,
    /// What the cell did (ticks, overlaps, faults, hand-overs, waiting per robot).
    pub stats: CellStats,
    /// Groups run nested inside another robot's group over the trial, every plan's
    /// coordinator together (`ContinuousCoordinator::nested_grants`; 0 without
    /// [`crate::study::StudyOperator::nested_groups`]).
    pub nested_groups: u64,
    /// The last tasks' throughput.
    pub steady: MixedSteady,
}

/// The mixed continuous study: every trial, the task names and the robot → task map.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MixedCellStudyResult {
    /// The tasks' names, in the cell's order.
    pub tasks: Vec<String>,
    /// Robot `i` does task `robot_task[i]`.
    pub robot_task: Vec<usize>,
    /// Every trial, in order.
    pub trials: Vec<MixedCellTrialResult>,
}

impl MixedCellStudyResult {
    /// Overlapping ticks and faults over every trial (both must be 0).
    #[must_use]
    pub fn overlaps_and_faults(&self) -> (u64, u64) {
        self.trials.iter().fold((0, 0), |(o, f), t| {
            (o + t.stats.overlap_ticks, f + t.stats.faults)
        })
    }
}

/// Each task's model, in the cell's order.
fn models(cell: &CellPlanner) -> Vec<&TaskModel> {
    cell.tasks().iter().map(|t| t.planner().model()).collect()
}

fn plan_record(
    cell: &CellPlanner,
    tasks: &[MixedTask],
    plan: &MixedCyclicPlan,
    records: usize,
    tick: u64,
) -> MixedCellIteration {
    MixedCellIteration {
        records,
        task_rounds: cell.task_rounds(),
        tick,
        ratios: plan.ratios.clone(),
        period_s: plan.period_s,
        tasks_per_hour: plan.tasks_per_hour,
        operator_share: plan.operator_share,
        lower_bound_s: plan.lower_bound_s,
        operator_limited_per_hour: plan.operator_limited_per_hour,
        best_bound_per_hour: plan.best_bound_per_hour,
        best_operator_limited_share: plan.best_operator_limited_share,
        max_ratio: plan.max_ratio,
        groups: cell
            .tasks()
            .iter()
            .map(|t| {
                let p = t.planner().problem();
                tandem_realtime::cell::groups(p.conf(), &p.usable_holds()).map_or(0, |g| g.len())
            })
            .collect(),
        tasks: task_states(cell, tasks),
    }
}

/// The steady window of `completions` (module docs): at least `⌈10 %⌉` of them and two
/// periods of `per_period` tasks, rounded up to whole periods, at most all.
fn steady(
    completions: &[MixedCellCompletion],
    per_period: usize,
    n: usize,
    tick_s: f64,
) -> MixedSteady {
    let total = completions.len();
    let per = per_period.max(1);
    let k = total
        .div_ceil(10)
        .max(2 * per)
        .div_ceil(per)
        .saturating_mul(per)
        .min(total);
    let last = completions.last().copied().unwrap_or(MixedCellCompletion {
        robot: 0,
        tick: 0,
        busy_ticks: 0,
    });
    let (t0, b0) = (total > k)
        .then(|| completions[total - k - 1])
        .map_or((0, 0), |c| (c.tick, c.busy_ticks));
    let ticks = (last.tick.saturating_sub(t0)).max(1) as f64;
    let duration_s = ticks * tick_s;
    let mut tasks_per_robot = vec![0; n];
    for c in &completions[total - k..] {
        tasks_per_robot[c.robot] += 1;
    }
    MixedSteady {
        tasks: k,
        duration_s,
        throughput_per_h: k as f64 * 3600.0 / duration_s,
        operator_busy_share: (last.busy_ticks - b0) as f64 / ticks,
        tasks_per_robot,
    }
}

/// The plan's coordinator with nested groups when the study's `[operator]` asks for them
/// ([`crate::study::StudyOperator::nested_groups`], `ContinuousCoordinator::with_nesting`).
fn nesting(config: &StudyConfig, coord: ContinuousCoordinator) -> ContinuousCoordinator {
    if config.operator.nested_groups {
        coord.with_nesting()
    } else {
        coord
    }
}

/// Runs trial `trial` of the mixed continuous study (module docs) until the cell has
/// completed `config.executions` tasks; `config.robots` must be the cell's robot count.
/// Reports `progress` after every record (`rounds_done`: records so far).
///
/// # Errors
/// [`Error::Mismatch`] for `config.robots` other than the tasks' robots together;
/// [`Error::BadParam`] for more than one operator; invalid configuration; any stage's
/// error, named by trial and record ([`Error::InTrial`], `round` the record being made);
/// [`Error::DidNotFinish`] if the cell stalls.
pub fn run_mixed_cell_trial(
    config: &StudyConfig,
    tasks: &[MixedTask],
    trial: usize,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<MixedCellTrialResult> {
    config.validate()?;
    let n: usize = tasks.iter().map(|t| t.robots).sum();
    if n != config.robots {
        return Err(Error::Mismatch {
            what: "robots of the study (the cell's robots, every task's together)",
            expected: n,
            found: config.robots,
        });
    }
    if config.operator.operators > 1 {
        return Err(Error::BadParam {
            name: "operator.operators",
            why: "must be 1 in a continuous cell of different tasks (one operator's token \
                  over the robots' own timelines; M operators there are not built): run it \
                  with one operator",
        });
    }
    let seed = trial_seed(config.seed, trial);
    let mut cell = trial_cell(config, tasks, seed)?;
    let robot_task = cell.robot_task().to_vec();
    let in_record = |round: usize| {
        move |e: Error| Error::InTrial {
            trial,
            round,
            source: Box::new(e),
        }
    };
    let plan = cell.continuous_plan().map_err(|e| in_record(0)(e.into()))?;
    let coord = nesting(
        config,
        cell.continuous_coordinator(&plan)
            .map_err(|e| in_record(0)(e.into()))?,
    );
    let tick_s = coord.tick_s();
    let ops = operators(config, tasks);
    let mut sim = MixedCellSim::new(&models(&cell), &robot_task, coord, &ops)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(1);
    let mut needed = robot_task
        .iter()
        .map(|&t| tasks[t].truth.draw(&mut rng))
        .collect::<Result<Vec<_>>>()?;
    let total = config.executions;
    // A task lasts at most Σ max(ψ̇) ticks of its period plus one per sample; even one robot
    // at a time, the cell does its tasks within twice the slowest task's that each.
    let slow_ticks = cell
        .tasks()
        .iter()
        .map(|t| {
            let p = t.planner().problem();
            (p.grad_max().iter().sum::<f64>() + p.n_ref() as f64) * p.dt_s() / tick_s
        })
        .fold(0.0, f64::max);
    let budget = (total as f64 + 2.0 * n as f64) * (slow_ticks + 10.0) * 2.0 + 10_000.0;
    // Per task, its robots' finished executions not yet recorded, in completion order.
    let mut queues: Vec<VecDeque<(usize, ExecutionRecord)>> = vec![VecDeque::new(); tasks.len()];
    let robots_of: Vec<usize> = tasks.iter().map(|t| t.robots).collect();
    let mut completions: Vec<MixedCellCompletion> = Vec::with_capacity(total + n);
    let mut iterations = vec![plan_record(&cell, tasks, &plan, 0, 0)];
    let mut last_ratios = plan.ratios.clone();
    let (mut nested_groups, mut seen) = (0u64, (0u64, sim.stats().hand_overs));
    while completions.len() < total {
        if sim.stats().ticks as f64 >= budget {
            return Err(Error::DidNotFinish {
                ticks: budget as usize,
            });
        }
        let finished = {
            let needed = &needed;
            sim.tick(&models(&cell), |robot, idx| needed[robot][idx], &mut rng)?
        };
        // A hand-over puts a coordinator whose count starts from 0 in place (grants of the
        // old one in the tick of the hand-over are not counted: a lower bound).
        let grants = sim.coordinator().nested_grants();
        let hand_overs = sim.stats().hand_overs;
        nested_groups += if hand_overs == seen.1 {
            grants - seen.0
        } else {
            grants
        };
        seen = (grants, hand_overs);
        // Tasks past the trial's total (several robots can finish in its last tick) are
        // neither counted nor queued.
        for f in finished.into_iter().take(total - completions.len()) {
            let t = robot_task[f.robot];
            completions.push(MixedCellCompletion {
                robot: f.robot,
                tick: f.tick,
                busy_ticks: sim.stats().busy_ticks,
            });
            needed[f.robot] = tasks[t].truth.draw(&mut rng)?;
            let model = cell.tasks()[t].planner().model();
            queues[t].push_back((f.robot, mixed_record(&f.run, model, tick_s)?));
        }
        // Per task, its complete rounds: as many as its queue holds executions of its robot
        // count.
        let complete: Vec<usize> = queues
            .iter()
            .zip(&robots_of)
            .map(|(q, &k)| q.len() / k)
            .collect();
        if completions.len() < total && complete.iter().all(|&k| k > 0) {
            let record = iterations.len();
            let rounds: Vec<Vec<Vec<ExecutionRecord>>> = complete
                .iter()
                .enumerate()
                .map(|(t, &k)| {
                    (0..k)
                        .map(|_| queues[t].drain(..robots_of[t]).map(|(_, e)| e).collect())
                        .collect()
                })
                .collect();
            cell.record_task_rounds(&rounds)
                .map_err(|e| in_record(record)(e.into()))?;
            let plan = cell
                .continuous_plan()
                .map_err(|e| in_record(record)(e.into()))?;
            let next = nesting(
                config,
                cell.continuous_coordinator(&plan)
                    .map_err(|e| in_record(record)(e.into()))?,
            );
            sim.replan(&models(&cell), next)
                .map_err(in_record(record))?;
            last_ratios = plan.ratios.clone();
            iterations.push(plan_record(&cell, tasks, &plan, record, sim.stats().ticks));
            progress(Progress {
                trial,
                rounds_done: record.min(config.n_rounds()),
            });
        }
    }
    let steady = steady(&completions, last_ratios.iter().sum(), n, tick_s);
    Ok(MixedCellTrialResult {
        trial,
        seed,
        iterations,
        completions,
        unrecorded: (0..n)
            .map(|i| {
                queues[robot_task[i]]
                    .iter()
                    .filter(|(r, _)| *r == i)
                    .count()
            })
            .collect(),
        stats: sim.stats().clone(),
        nested_groups,
        steady,
    })
}

/// Runs every trial of the mixed continuous study ([`run_mixed_cell_trial`]) in parallel;
/// the result does not depend on the thread count.
///
/// # Errors
/// The first failing trial's error (in trial order).
pub fn run_mixed_cell_study(
    config: &StudyConfig,
    tasks: &[MixedTask],
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<MixedCellStudyResult> {
    let (tasks_named, robot_task, trials) = run_trials(config, tasks, |k| {
        run_mixed_cell_trial(config, tasks, k, progress)
    })?;
    Ok(MixedCellStudyResult {
        tasks: tasks_named,
        robot_task,
        trials,
    })
}
