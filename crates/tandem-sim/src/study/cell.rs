//! The study in a continuous cell (issue 21, `cargo xtask study --cell continuous`): the
//! learning loop of §III without rounds.
//!
//! A trial fits the planner as for rounds, plans the cell (`Planner::cyclic_plan`, the
//! planner's plan of a continuous cell: the operator's cyclic order of low-confidence
//! stretches and its least period, counting the token rule's hand-overs at the cell's tick,
//! the schedule's: `CyclicParams::handover_tick_s`) and runs it
//! through the continuous coordinator ([`crate::workcell::CellSim`]). Every robot draws a new
//! workpiece for every task. Each completed task's execution is kept; every `N` completed
//! tasks (whichever robots did them) the planner records them as one round of `N`
//! executions (Eq. 21, Eq. 9–12: the planner's unit of learning, the same number of
//! executions per update as rounds), the cell is re-planned on the new problem, and the new
//! plan takes over the running cell at the next hand-over point (at the latest when the
//! operator's token next moves; `ContinuousCoordinator::take_over`). So the robots never
//! stop for a re-plan, and a trial of `executions` tasks makes `executions / N` plans after
//! the first, as many as the rounds study makes schedules.
//!
//! Why every `N` tasks and not after every task: a re-plan after one task would record
//! "rounds" of one execution, which the planner does not take (`Planner::record_round`
//! records one execution per robot), and the plan a single execution changes differs little;
//! every `N` tasks is once per period of the cell in steady state, so the plan is never more
//! than a period behind what was learnt.
//!
//! The steady throughput ([`Steady`]) is measured over the last 10 % of tasks, rounded up to
//! a multiple of `N` (whole periods): tasks completed in that window per hour of cell time,
//! with the operator's busy share and the robots' waiting share over the same ticks.

use std::time::Instant;

use serde::{Deserialize, Serialize};
use tandem_lfd::TaskModel;
use tandem_planner::{ExecutionRecord, FleetPick, Planner};
use tandem_realtime::Timeline;
use tandem_realtime::cell::ContinuousCoordinator;
use tandem_schedule::{CheckedCyclicPlan, CyclicParams};

use super::config::StudyConfig;
use super::inputs::StudyInputs;
use super::record::mean_std;
use super::run::{PhaseTimes, Progress, fit_study_model, par_trials};
use super::trial::{TrialKind, TrialState, run_trial_loop};
use crate::task::{self, Label};
use crate::truth::{SandingTruth, TaskTruth, falsely_trusted_where};
use crate::workcell::{CellSim, CellStats, FinishedTask, PlanGap, RobotPlan, RobotRun};
use crate::{Error, Result};

/// The cell's plan after some recorded tasks: one per re-plan of a trial.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellIteration {
    /// Tasks recorded into the planner when the plan was made (0: demonstrations only).
    pub tasks_recorded: usize,
    /// The cell's tick (control ticks of `Δt_s` from the trial start) at which it was made.
    pub tick: u64,
    /// The plan's least period `P` (s) for its operator order: `N` tasks per period.
    pub period_s: f64,
    /// The plan's throughput `3600·N/P` (tasks per hour per operator).
    pub tasks_per_hour: f64,
    /// The plan's operator busy share `N·L/P`, in `[0, 1]`.
    pub operator_share: f64,
    /// The period's lower bound (s) over every order (`CyclicPlan::lower_bound_s`).
    pub lower_bound_s: f64,
    /// `period_s / lower_bound_s − 1`.
    pub gap: f64,
    /// Whether every operator order was enumerated (the period is the least of every
    /// 1-periodic plan).
    pub order_exhaustive: bool,
    /// Percent of reference samples of high confidence.
    pub high_conf_pct: f64,
    /// Low-confidence stretches `m` of the task.
    pub lc_stretches: usize,
    /// The stretches as reference-sample intervals `[start, end)`, in order.
    pub lc_ref: Vec<[usize; 2]>,
    /// The usable hold points (reference samples) the cell waits at.
    pub holds: Vec<usize>,
    /// Reference samples that truly need help but are high-confidence ([`crate::truth::falsely_trusted`]).
    pub falsely_trusted_samples: usize,
    /// `M > 1` operators (issue 44): which cell ran this plan, pooled or sectored, and the
    /// throughputs it was picked by (`Planner::fleet_coordinator`). `None` (not written) for
    /// one operator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fleet: Option<FleetPick>,
}

/// A completed task of a trial.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellCompletion {
    /// The robot (0-based).
    pub robot: usize,
    /// Cell ticks run when it finished.
    pub tick: u64,
    /// Ticks with the operator busy until then (cumulative).
    pub busy_ticks: u64,
    /// Ticks the robots waited at gates until then (cumulative, summed over robots).
    pub gate_ticks: u64,
    /// Where the task's time went against the plan in force ([`task_gap`]): its realized
    /// duration (since the robot's previous completion) against the plan's period, split
    /// into corrections, waits at gates (`holds_s`), response strategy, tick grid and faults.
    /// All 0 in files written before it was recorded.
    #[serde(default)]
    pub plan_gap: PlanGap,
    /// The task's samples run at high confidence where the truth needed the operator.
    #[serde(default)]
    pub needed_unsupervised: usize,
    /// Needed corrections of the task the simulated operator missed because it was still
    /// switching its attention from another robot (its switch time `δ_true`, issue 41;
    /// [`RobotRun::switch_missed`](crate::workcell::RobotRun::switch_missed)). Left out of the
    /// JSON when 0, as it always is without a switch time, so files without one are unchanged.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub switch_missed: usize,
}

#[expect(
    clippy::trivially_copy_pass_by_ref,
    reason = "serde passes the field by reference"
)]
fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// Where one task of a continuous cell spent its time against the plan
/// (docs/decisions.md, "Plans that say how optimistic they are"): the task took
/// `realized_ticks` ticks of `tick_s` (from the robot's previous completion, or the cell's
/// start, to this one), of which `gate_ticks` waiting at gates for the operator's token; the
/// plan in force gives every robot one task per `period_s` (s) and runs it on `task`'s
/// clock. The [`PlanGap`] has `realized_s = realized_ticks·τ`, `planned_s = period_s`, and
/// the parts, which add up to their difference exactly:
///
/// - each running tick, from the logged reference time `t` to the next (or `T_ref`):
///   `τ − (P(t') − P(t))` with `P` the task's planned clock, to corrections when the robot
///   was corrected in it, to the grid for the task's last tick, else to the strategy (the
///   coordinator's own rates);
/// - gates (`holds_s`): the waiting ticks minus the plan's waiting per task, `P − |task|`;
/// - faults: ticks neither running nor at a gate (held by the fault monitor);
/// - grid also takes `−P(t_first)`: what the task had covered before its first logged
///   sample (carried over from the previous task's last tick).
///
/// A plan that took over while the task ran is charged for the whole task (the plan in force
/// at the completion).
#[must_use]
pub fn task_gap(
    run: &RobotRun,
    realized_ticks: u64,
    gate_ticks: u64,
    tick_s: f64,
    period_s: f64,
    task: &Timeline,
) -> PlanGap {
    let plan = RobotPlan {
        start_s: task.start_s(),
        end_s: task.start_s() + period_s,
        sample_clock_s: task.sample_clock_s().to_vec(),
    };
    let n_ref = task.n_ref() as f64;
    let mut gap = PlanGap {
        realized_s: realized_ticks as f64 * tick_s,
        planned_s: period_s,
        ..PlanGap::default()
    };
    let log = &run.ref_time_log;
    for (j, &t) in log.iter().enumerate() {
        let next = log.get(j + 1).copied().unwrap_or(n_ref);
        let d = tick_s - (plan.clock_at(next) - plan.clock_at(t));
        if j + 1 == log.len() {
            gap.grid_s += d;
        } else if run.corrected.get(j).copied().unwrap_or(false) {
            gap.corrections_s += d;
        } else {
            gap.strategy_s += d;
        }
    }
    let run_s = plan.clock_at(n_ref);
    gap.holds_s = gate_ticks as f64 * tick_s - (period_s - run_s);
    let held = realized_ticks.saturating_sub(gate_ticks + log.len() as u64);
    gap.faults_s = held as f64 * tick_s;
    gap.grid_s -= plan.clock_at(log.first().copied().unwrap_or(n_ref));
    gap
}

/// The steady state of a continuous cell: the last 10 % of its tasks, rounded up to whole
/// periods.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Steady {
    /// Tasks in the window: `⌈10 % of the tasks⌉` rounded up to a multiple of `N` (at most
    /// all tasks). In a periodic steady state the robots complete `N` tasks per period, in
    /// bunches; a window of whole periods spans the same time wherever it starts, while one
    /// of, say, 24 tasks of 7 robots spans 3 or 4 periods depending on where the bunches fall
    /// (±15 % on the throughput).
    pub tasks: usize,
    /// Its length (s of cell time): from the completion before the window (or the start)
    /// to the last completion.
    pub duration_s: f64,
    /// Tasks per hour per operator over the window.
    pub throughput_per_h: f64,
    /// Share of the window's ticks in which a robot was low-confidence, in `[0, 1]`.
    pub operator_busy_share: f64,
    /// Share of the robots' time in the window spent waiting at a gate for the operator's
    /// token, in `[0, 1]` (robot-ticks waiting over `N ×` the window's ticks).
    pub robot_wait_share: f64,
    /// The window's tasks' [`CellCompletion::plan_gap`]s summed: realized task time against
    /// the planned periods and its causes (s). Planned over realized throughput of the
    /// robots is `planned_s / realized_s`, and each cause's share of the difference is its
    /// share of the lost throughput. All 0 in older files.
    #[serde(default)]
    pub plan_gap: PlanGap,
    /// The window's samples run at high confidence where the truth needed the operator.
    #[serde(default)]
    pub needed_unsupervised: usize,
}

impl Steady {
    /// The steady state of `completions` (in completion order) of `n_robots` robots at a
    /// control tick of `tick_s` (s); `None` without completions.
    #[must_use]
    pub fn of(completions: &[CellCompletion], n_robots: usize, tick_s: f64) -> Option<Steady> {
        Steady::of_last(
            completions,
            n_robots,
            tick_s,
            completions.len().div_ceil(10),
        )
    }

    /// The steady state over the last `tasks` of `completions` instead of the last 10 %
    /// (`cargo xtask capacity --steady-tasks`: the tasks before them are a warm-up that
    /// learns but is not measured), rounded up to a multiple of `N` (whole periods, as
    /// [`Steady::of`]) and at most all of them; `None` without completions.
    #[must_use]
    pub fn of_last(
        completions: &[CellCompletion],
        n_robots: usize,
        tick_s: f64,
        tasks: usize,
    ) -> Option<Steady> {
        let total = completions.len();
        if total == 0 {
            return None;
        }
        let k = tasks
            .max(1)
            .div_ceil(n_robots.max(1))
            .saturating_mul(n_robots.max(1))
            .min(total);
        let last = completions[total - 1];
        let before = (total > k).then(|| completions[total - k - 1]);
        let (t0, b0, g0) = before.map_or((0, 0, 0), |c| (c.tick, c.busy_ticks, c.gate_ticks));
        let ticks = (last.tick - t0).max(1) as f64;
        let duration_s = ticks * tick_s;
        Some(Steady {
            tasks: k,
            duration_s,
            throughput_per_h: k as f64 * 3600.0 / duration_s,
            operator_busy_share: (last.busy_ticks - b0) as f64 / ticks,
            robot_wait_share: (last.gate_ticks - g0) as f64 / (ticks * n_robots as f64),
            plan_gap: PlanGap::sum(completions[total - k..].iter().map(|c| &c.plan_gap)),
            needed_unsupervised: completions[total - k..]
                .iter()
                .map(|c| c.needed_unsupervised)
                .sum(),
        })
    }
}

/// One trial of the continuous study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellTrialResult {
    /// Trial index `k`.
    pub trial: usize,
    /// Seed of the trial ([`trial_seed`](super::trial_seed)).
    pub seed: u64,
    /// The plans, the first one (demonstrations only) first.
    pub iterations: Vec<CellIteration>,
    /// Every completed task, in completion order.
    pub completions: Vec<CellCompletion>,
    /// What the cell did (ticks, overlaps, faults, hand-overs, waiting per robot).
    pub stats: CellStats,
    /// The last 10 % of the tasks.
    pub steady: Steady,
}

/// The continuous study: everything its JSON output holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellStudyResult {
    /// The configuration it ran with.
    pub config: StudyConfig,
    /// Reference samples of the task (`T_ref`).
    pub n_ref: usize,
    /// Reference sample period `Δt_s` (s), the cell's control tick.
    pub dt_s: f64,
    /// Ground truth (§III): percent of reference samples outside the sanding of passes 1–3.
    pub ground_truth_pct: f64,
    /// The trials, in trial order.
    pub trials: Vec<CellTrialResult>,
}

/// The continuous study across trials.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CellSummary {
    /// Mean steady throughput across trials (tasks per hour per operator, [`Steady`]).
    pub steady_throughput_per_h: f64,
    /// Its sample standard deviation across trials.
    pub steady_throughput_std_per_h: f64,
    /// Mean operator busy share in the steady window, in `[0, 1]`.
    pub steady_operator_busy_share: f64,
    /// Mean share of the robots' time spent waiting at gates in the steady window.
    pub steady_robot_wait_share: f64,
    /// Mean planned throughput of the last plan (tasks per hour per operator).
    pub last_plan_tasks_per_hour: f64,
    /// Mean operator-limited bound of the last plan, `3600·N / lower_bound_s` (tasks per hour).
    pub last_plan_bound_tasks_per_hour: f64,
    /// Mean low-confidence stretches of the last plan's task.
    pub last_plan_lc_stretches: f64,
    /// Overlap ticks over every trial (must be 0).
    pub overlap_ticks: u64,
    /// Faults over every trial (must be 0).
    pub faults: u64,
    /// Plans that took over a running cell, over every trial.
    pub hand_overs: u64,
    /// The steady windows' [`Steady::plan_gap`] per task, averaged over trials (s): how much
    /// longer a task took than the plan's period, and why.
    #[serde(default)]
    pub steady_plan_gap_per_task: PlanGap,
    /// The steady windows' needed-but-unsupervised samples per task, averaged over trials.
    #[serde(default)]
    pub steady_needed_unsupervised_per_task: f64,
}

impl CellStudyResult {
    /// Needed corrections missed while the simulated operator was switching its attention
    /// (issue 41), summed over every completed task of every trial
    /// ([`CellCompletion::switch_missed`]; 0 without a switch time), and the tasks completed.
    #[must_use]
    pub fn switch_missed_total(&self) -> (usize, usize) {
        let tasks = self.trials.iter().flat_map(|t| &t.completions);
        tasks.fold((0, 0), |(missed, n), c| (missed + c.switch_missed, n + 1))
    }

    /// The summary across trials.
    #[must_use]
    pub fn summary(&self) -> CellSummary {
        let last: Vec<&CellIteration> = self
            .trials
            .iter()
            .filter_map(|t| t.iterations.last())
            .collect();
        let (steady, steady_std) = mean_std(self.trials.iter().map(|t| t.steady.throughput_per_h));
        let n = self.config.robots as f64;
        let per_task: Vec<(PlanGap, f64)> = self
            .trials
            .iter()
            .map(|t| {
                let k = t.steady.tasks.max(1) as f64;
                (
                    t.steady.plan_gap.scaled(1.0 / k),
                    t.steady.needed_unsupervised as f64 / k,
                )
            })
            .collect();
        CellSummary {
            steady_throughput_per_h: steady,
            steady_throughput_std_per_h: steady_std,
            steady_operator_busy_share: mean_std(
                self.trials.iter().map(|t| t.steady.operator_busy_share),
            )
            .0,
            steady_robot_wait_share: mean_std(
                self.trials.iter().map(|t| t.steady.robot_wait_share),
            )
            .0,
            last_plan_tasks_per_hour: mean_std(last.iter().map(|i| i.tasks_per_hour)).0,
            last_plan_bound_tasks_per_hour: mean_std(
                last.iter().map(|i| 3600.0 * n / i.lower_bound_s),
            )
            .0,
            last_plan_lc_stretches: mean_std(last.iter().map(|i| i.lc_stretches as f64)).0,
            overlap_ticks: self.trials.iter().map(|t| t.stats.overlap_ticks).sum(),
            faults: self.trials.iter().map(|t| t.stats.faults).sum(),
            hand_overs: self.trials.iter().map(|t| t.stats.hand_overs).sum(),
            steady_plan_gap_per_task: PlanGap::mean(
                per_task.iter().map(|(g, _)| g).collect::<Vec<_>>(),
            )
            .unwrap_or_default(),
            steady_needed_unsupervised_per_task: mean_std(per_task.iter().map(|(_, u)| *u)).0,
        }
    }
}

/// The run-time coordinator of the cell's `plan` with the planner's operators
/// (`Planner::fleet_coordinator`: the switch time, the load cap and `M` tokens, issues 41
/// and 44; no-ops at their defaults), the cell of `M > 1` operators chosen as the study's
/// `[operator] fleet_cell` says, and what ran.
fn coordinator_of(
    planner: &Planner,
    plan: &CheckedCyclicPlan,
    config: &StudyConfig,
) -> Result<(ContinuousCoordinator, Option<FleetPick>)> {
    Ok(planner.fleet_coordinator(plan, config.operator.fleet_cell)?)
}

/// The cell's plan on the planner's problem and its record: the planner's plan of a
/// continuous cell (`Planner::cyclic_plan`, what `Planner::plan` gives: the token rule's hand-overs counted at the schedule's
/// tick, the cell's, so its period is what the cell does with the planned operator).
fn plan_of(
    planner: &Planner,
    can_need: &[bool],
    tasks_recorded: usize,
    tick: u64,
) -> Result<(CheckedCyclicPlan, CellIteration)> {
    // The operator's switch time and load cap of the planner (issue 41; defaults: none).
    let sampler = &planner.params().sampler;
    let params = CyclicParams {
        switch_s: sampler.switch_s,
        max_busy_share: sampler.max_busy_share,
        ..CyclicParams::default()
    };
    let checked = planner.cyclic_plan(&params, None)?;
    let plan = checked.plan();
    let iteration = CellIteration {
        tasks_recorded,
        tick,
        period_s: plan.period_s,
        tasks_per_hour: plan.tasks_per_hour,
        operator_share: plan.operator_share,
        lower_bound_s: plan.lower_bound_s,
        gap: plan.gap,
        order_exhaustive: plan.order_exhaustive,
        high_conf_pct: 100.0 * planner.confidence().high_share(),
        lc_stretches: plan.lc_s.len(),
        lc_ref: tandem_confidence::runs(planner.problem().conf())
            .iter()
            .filter(|r| !r.high_conf)
            .map(|r| [r.start, r.end])
            .collect(),
        holds: planner.problem().usable_holds(),
        falsely_trusted_samples: falsely_trusted_where(planner.confidence().conf(), can_need),
        fleet: None,
    };
    Ok((checked, iteration))
}

/// Runs trial `trial` of the continuous study from a fitted model (module docs). Seeds as
/// for rounds ([`super::run_trial`]): the planner's sampler `derive_seed(trial seed, k)`,
/// workpieces and the operator a ChaCha8 stream of the trial seed.
///
/// # Errors
/// Invalid configuration, or any stage's error; [`Error::DidNotFinish`] for a cell that does
/// not complete its tasks within a generous tick budget (a bug).
pub fn run_cell_trial(
    config: &StudyConfig,
    model: &TaskModel,
    labels: &[Label],
    trial: usize,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<(CellTrialResult, PhaseTimes)> {
    let truth = SandingTruth::new(labels.to_vec(), config.task.clone());
    let run = run_cell_trial_on(config, model, &truth, trial, progress, &|_| {})?;
    Ok((run.result, run.times))
}

/// A continuous trial as it ended ([`run_cell_trial_on`]): its record, the time spent in each
/// phase, and the planner after the last recorded round.
#[derive(Debug)]
pub struct CellTrialRun {
    /// The trial's record.
    pub result: CellTrialResult,
    /// Wall time per phase.
    pub times: PhaseTimes,
    /// The planner after the last recorded round of `N` tasks.
    pub planner: Planner,
}

/// [`run_cell_trial`] on any task: every workpiece is drawn from `truth`
/// ([`TaskTruth::draw`]; the first `N` in robot order, then one for each completed task),
/// the operator corrects [`TaskTruth::correction_channel`], falsely trusted samples are
/// counted against [`TaskTruth::can_need`]. On the sanding task ([`SandingTruth`]) it is the
/// continuous study's trial, bit for bit. `observe` sees every completed task as it
/// completes (in completion order, the tasks completed in the tick of the last counted one
/// included), before it is recorded; the result is the same as without.
///
/// # Errors
/// As [`run_cell_trial`], and [`Error::Mismatch`] for a truth on another number of
/// reference samples than the model's.
pub fn run_cell_trial_on(
    config: &StudyConfig,
    model: &TaskModel,
    truth: &dyn TaskTruth,
    trial: usize,
    progress: &(dyn Fn(Progress) + Sync),
    observe: &(dyn Fn(&FinishedTask) + Sync),
) -> Result<CellTrialRun> {
    run_trial_loop(config, model, truth, trial, progress, |state| {
        ContinuousTrial::start(state, observe)
    })
}

/// The continuous cell in the one trial loop ([`run_trial_loop`]): a batch is the next `N`
/// tasks completed in a running [`CellSim`], whichever robots did them; the next plan takes
/// over the running cell at its next hand-over point (module docs).
struct ContinuousTrial<'a> {
    /// Where the truth can need the operator (falsely trusted samples are counted on it).
    can_need: &'a [bool],
    /// Sees every completed task before it is recorded.
    observe: &'a (dyn Fn(&FinishedTask) + Sync),
    /// The running cell.
    sim: CellSim,
    /// Each robot's workpiece of its current task: where it needs the operator.
    needed: Vec<Vec<bool>>,
    /// Robots `N`.
    n: usize,
    /// Tasks per trial (`config.executions`).
    total: usize,
    /// Ticks after which the trial is a bug ([`Error::DidNotFinish`]).
    budget: f64,
    /// The cell's tick (s): the first plan's, the schedule's.
    dt_s: f64,
    /// The plans so far, the first one first.
    iterations: Vec<CellIteration>,
    /// Every completed task so far, in completion order.
    completions: Vec<CellCompletion>,
    /// Records of the completed tasks not yet recorded into the planner.
    batch: Vec<ExecutionRecord>,
    /// Tasks recorded into the planner.
    recorded: usize,
    /// The period (s) of the plan in force.
    period_s: f64,
    /// The period (s) of a new plan waiting for its hand-over.
    pending_period_s: Option<f64>,
    /// Each robot's last completion tick and its gate ticks then (for each task's PlanGap).
    last_done: Vec<u64>,
    gates_then: Vec<u64>,
    /// Tasks completed in the last tick not yet taken (a batch can end inside a tick: the
    /// rest are taken after the re-plan, under the new model and plan).
    finished: std::vec::IntoIter<FinishedTask>,
}

impl<'a> ContinuousTrial<'a> {
    /// The cell on the trial's first plan, every robot's first workpiece drawn (robot order).
    fn start(
        state: &mut TrialState<'a>,
        observe: &'a (dyn Fn(&FinishedTask) + Sync),
    ) -> Result<Self> {
        let can_need = state.truth.can_need();
        let planner = &state.planner;
        let n = planner.n_robots();
        let (plan, mut first) = plan_of(planner, can_need, 0, 0)?;
        // The cell's tick: the plan's, the schedule's (`Δt_s` unless the sampler sets a tick).
        let dt_s = plan.tick_s();
        let (coord, fleet) = coordinator_of(planner, &plan, state.config)?;
        first.fleet = fleet;
        let sim = CellSim::new(planner.model(), coord, &state.operator)?;
        let needed = (0..n)
            .map(|_| state.truth.draw(&mut state.rng))
            .collect::<Result<Vec<_>>>()?;
        let total = state.config.executions;
        // A task lasts at most Σ max(ψ̇min, ψ̇max) ticks plus one per sample (tick = Δt_s);
        // even one robot at a time, the cell does its tasks within twice that each.
        let problem = planner.problem();
        let slow_ticks: f64 = problem.grad_max().iter().sum::<f64>() + problem.n_ref() as f64;
        Ok(ContinuousTrial {
            can_need,
            observe,
            sim,
            needed,
            n,
            total,
            budget: (total as f64 + 2.0 * n as f64) * (slow_ticks + 10.0) * 2.0 + 10_000.0,
            dt_s,
            period_s: first.period_s,
            iterations: vec![first],
            completions: Vec::with_capacity(total + n),
            batch: Vec::with_capacity(n),
            recorded: 0,
            pending_period_s: None,
            last_done: vec![0; n],
            gates_then: vec![0; n],
            finished: Vec::new().into_iter(),
        })
    }

    /// Takes a completed task: its completion (with its [`task_gap`] against the plan in
    /// force), the observer, the robot's next workpiece, its record into the batch. Returns
    /// whether the batch is full and recordable (`N` tasks, within the trial's total).
    fn take(&mut self, state: &mut TrialState<'_>, f: FinishedTask) -> Result<bool> {
        let stats = self.sim.stats();
        let i = f.robot;
        let gates = stats.gate_ticks[i];
        let plan_gap = task_gap(
            &f.run,
            f.tick - self.last_done[i],
            gates - self.gates_then[i],
            self.dt_s,
            self.period_s,
            self.sim.coordinator().task_of(i),
        );
        (self.last_done[i], self.gates_then[i]) = (f.tick, gates);
        let needed = &self.needed[i];
        let unsupervised = f
            .run
            .ref_time_log
            .iter()
            .zip(&f.run.supervised)
            .filter(|&(&t, &sup)| !sup && needed[t.max(0.0).round() as usize])
            .count();
        self.completions.push(CellCompletion {
            robot: i,
            tick: f.tick,
            busy_ticks: stats.busy_ticks,
            gate_ticks: stats.gate_ticks.iter().sum(),
            plan_gap,
            needed_unsupervised: unsupervised,
            switch_missed: f.run.switch_missed,
        });
        (self.observe)(&f);
        self.needed[i] = state.truth.draw(&mut state.rng)?;
        self.batch.push(f.run.record(state.planner.model())?);
        Ok(self.batch.len() >= self.n && self.recorded + self.n <= self.total)
    }
}

impl TrialKind for ContinuousTrial<'_> {
    type Run = CellTrialRun;

    fn next_batch(
        &mut self,
        state: &mut TrialState<'_>,
        _round: usize,
    ) -> Result<Option<Vec<ExecutionRecord>>> {
        loop {
            while let Some(f) = self.finished.next() {
                if self.take(state, f)? {
                    return Ok(Some(std::mem::take(&mut self.batch)));
                }
            }
            if self.completions.len() >= self.total {
                return Ok(None);
            }
            if self.sim.stats().ticks as f64 >= self.budget {
                return Err(Error::DidNotFinish {
                    ticks: self.budget as usize,
                });
            }
            let t = Instant::now();
            let needed = &self.needed;
            let finished = self.sim.tick(
                state.planner.model(),
                |robot, idx| needed[robot][idx],
                &mut state.rng,
            )?;
            state.times.simulation += t.elapsed();
            if !self.sim.has_pending() {
                if let Some(p) = self.pending_period_s.take() {
                    self.period_s = p;
                }
            }
            self.finished = finished.into_iter();
        }
    }

    fn replan(&mut self, state: &mut TrialState<'_>) -> Result<()> {
        self.recorded += self.n;
        let t = Instant::now();
        let planner = &state.planner;
        let tick = self.sim.stats().ticks;
        let (plan, mut iteration) = plan_of(planner, self.can_need, self.recorded, tick)?;
        let (next, fleet) = coordinator_of(planner, &plan, state.config)?;
        iteration.fleet = fleet;
        state.times.scheduling += t.elapsed();
        if self.sim.replan(planner.model(), next)? {
            self.period_s = iteration.period_s;
            self.pending_period_s = None;
        } else {
            self.pending_period_s = Some(iteration.period_s);
        }
        self.iterations.push(iteration);
        Ok(())
    }

    fn finish(mut self, state: TrialState<'_>) -> Result<CellTrialRun> {
        self.completions.truncate(self.total);
        let steady = Steady::of(&self.completions, self.n, self.dt_s).expect("at least one task");
        Ok(CellTrialRun {
            result: CellTrialResult {
                trial: state.trial,
                seed: state.seed,
                iterations: self.iterations,
                completions: self.completions,
                stats: self.sim.stats().clone(),
                steady,
            },
            times: state.times,
            planner: state.planner,
        })
    }
}

/// Runs every trial of the continuous study from a fitted model, in parallel (rayon); the
/// result is the same for any number of threads.
///
/// # Errors
/// Invalid configuration, labels that do not match the model's reference, or any stage's
/// error (the first trial's in trial order).
pub fn run_cell_trials(
    config: &StudyConfig,
    model: &TaskModel,
    labels: &[Label],
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<(CellStudyResult, PhaseTimes)> {
    run_cell_trials_finished(config, model, labels, progress, &|_, _| {})
}

/// [`run_cell_trials`] handing every trial's planner after its last recorded batch of `N`
/// tasks to `finished` (the trial, 0-based, and the planner), from worker threads as the
/// trials end, in no particular order; the result is the same as without.
///
/// # Errors
/// As [`run_cell_trials`].
pub fn run_cell_trials_finished(
    config: &StudyConfig,
    model: &TaskModel,
    labels: &[Label],
    progress: &(dyn Fn(Progress) + Sync),
    finished: &(dyn Fn(usize, &Planner) + Sync),
) -> Result<(CellStudyResult, PhaseTimes)> {
    let truth = SandingTruth::new(labels.to_vec(), config.task.clone());
    let (trials, times) = par_trials(config, model, labels, |k| {
        let run = run_cell_trial_on(config, model, &truth, k, progress, &|_| {})?;
        finished(k, &run.planner);
        Ok((run.result, run.times))
    })?;
    Ok((
        CellStudyResult {
            config: config.clone(),
            n_ref: model.n_ref(),
            dt_s: model.dt_s(),
            ground_truth_pct: 100.0 * task::ground_truth_share(labels),
            trials,
        },
        times,
    ))
}

/// Runs the continuous study: fits the model once ([`super::run_study`]'s fit), then runs
/// the trials ([`run_cell_trials`]).
///
/// # Errors
/// As [`super::run_study`].
pub fn run_cell_study(
    config: &StudyConfig,
    inputs: &StudyInputs,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<(CellStudyResult, PhaseTimes)> {
    run_cell_study_finished(config, inputs, progress, &|_, _| {})
}

/// [`run_cell_study`] handing every trial's planner after its last batch to `finished`
/// ([`run_cell_trials_finished`]; `cargo xtask study --cell continuous --save-state`).
///
/// # Errors
/// As [`super::run_study`].
pub fn run_cell_study_finished(
    config: &StudyConfig,
    inputs: &StudyInputs,
    progress: &(dyn Fn(Progress) + Sync),
    finished: &(dyn Fn(usize, &Planner) + Sync),
) -> Result<(CellStudyResult, PhaseTimes)> {
    let (model, alignment) = fit_study_model(config, inputs)?;
    let labels = inputs.reference_labels(&model)?;
    let (result, mut times) =
        run_cell_trials_finished(config, &model, &labels, progress, finished)?;
    times.alignment = alignment;
    Ok((result, times))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Seven robots in a periodic steady state: a period of 700 ticks of 10 ms, in which the
    /// robots complete their tasks in a bunch, 10 ticks apart (task `i` at tick
    /// `700·(⌊i/7⌋ + 1) + 10·(i mod 7)`): 7 tasks per 7 s, 3600 tasks per hour.
    fn bunched(total: usize) -> Vec<CellCompletion> {
        (0..total)
            .map(|i| CellCompletion {
                robot: i % 7,
                tick: 700 * (i as u64 / 7 + 1) + 10 * (i as u64 % 7),
                busy_ticks: 0,
                gate_ticks: 0,
                plan_gap: PlanGap {
                    realized_s: 7.0,
                    planned_s: 6.0,
                    holds_s: 1.0,
                    ..PlanGap::default()
                },
                needed_unsupervised: i % 2,
                switch_missed: 0,
            })
            .collect()
    }

    #[test]
    fn a_task_gap_splits_the_task_time_against_the_period_exactly() {
        // A task of four reference samples at 1 s each (τ = 1 s), planned once per 6 s
        // period: 4 s running, 2 s waiting at its gate. It took 9 ticks: 5 running, 3 at
        // the gate, 1 held. Running 0 → 1 (on plan), 1 → 1.5 (0.5 s behind: strategy),
        // 1.5 → 2 corrected (0.5 s: corrections), 2 → 3.5 (0.5 s ahead: strategy), 3.5 → 4
        // and done (0.5 s of the last tick unused: grid). Gates 3 s against the planned 2 s:
        // +1 s; held 1 s. 9 − 6 = 3 = 0.5 + 0 + 0.5 + 1 + 1.
        let task = Timeline::new(&[true; 4], &[1.0; 4], &[0.5; 4], &[2.0; 4], 0.0, 1.0).unwrap();
        let log = vec![0.0, 1.0, 1.5, 2.0, 3.5];
        let run = RobotRun {
            samples: vec![0.0; 5],
            supervised: vec![false, false, true, false, false],
            corrected: vec![false, false, true, false, false],
            ref_time_log: log,
            needed: 1,
            missed: 0,
            switch_missed: 0,
            false_corrections: 0,
            clock_s: Vec::new(),
            start_tick: 0,
            hold_ticks: 0,
            phases: Vec::new(),
        };
        let gap = task_gap(&run, 9, 3, 1.0, 6.0, &task);
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert_eq!((gap.realized_s, gap.planned_s), (9.0, 6.0));
        assert!(close(gap.corrections_s, 0.5), "{gap:?}");
        assert!(close(gap.strategy_s, 0.0), "{gap:?}");
        assert!(close(gap.grid_s, 0.5), "{gap:?}");
        assert!(close(gap.holds_s, 1.0), "{gap:?}");
        assert!(close(gap.faults_s, 1.0), "{gap:?}");
        assert!(close(gap.parts_sum_s(), 3.0), "{gap:?}");
        // A task that began 0.25 samples in (carried over from the previous task's last
        // tick) got that for free: the grid takes −0.25 s.
        let mut carried = run.clone();
        carried.ref_time_log[0] = 0.25;
        let gap = task_gap(&carried, 9, 3, 1.0, 6.0, &task);
        assert!(close(gap.parts_sum_s(), 3.0), "{gap:?}");
        assert!(close(gap.grid_s, 0.25), "{gap:?}");
    }

    #[test]
    fn the_steady_window_is_whole_periods_so_bunches_do_not_bias_it() {
        // 238 tasks: 10 % is 24, rounded up to 28 (four periods of 7 s): 28 tasks in 28 s.
        let s = Steady::of(&bunched(238), 7, 0.01).unwrap();
        assert_eq!(s.tasks, 28);
        assert!((s.duration_s - 28.0).abs() < 1e-9, "{}", s.duration_s);
        assert!((s.throughput_per_h - 3600.0).abs() < 1e-9);
        // The window's gaps and unsupervised samples are its 28 tasks' sums.
        assert_eq!(
            (s.plan_gap.realized_s, s.plan_gap.planned_s),
            (196.0, 168.0)
        );
        assert_eq!(s.plan_gap.holds_s, 28.0);
        assert_eq!(s.needed_unsupervised, 14);
        // Wherever the last task falls in its bunch, whole periods measure the true rate
        // (24 tasks would span 21.3 s here: 4056 tasks per hour).
        for total in 8..=238 {
            let s = Steady::of(&bunched(total), 7, 0.01).unwrap();
            assert_eq!(s.tasks % 7, 0, "{total}");
            assert!((s.throughput_per_h - 3600.0).abs() < 1e-9, "{total}: {s:?}");
        }
        // A longer window (`of_last`): 60 of 238 tasks rounded up to 63 (nine periods).
        let s = Steady::of_last(&bunched(238), 7, 0.01, 60).unwrap();
        assert_eq!(s.tasks, 63);
        assert!((s.duration_s - 63.0).abs() < 1e-9, "{}", s.duration_s);
        assert!((s.throughput_per_h - 3600.0).abs() < 1e-9);
        assert_eq!(
            Steady::of_last(&bunched(20), 7, 0.01, 60).unwrap().tasks,
            20
        );
        // Fewer tasks than a period: all of them, from the start.
        let s = Steady::of(&bunched(5), 7, 0.01).unwrap();
        assert_eq!(s.tasks, 5);
        assert!((s.duration_s - 7.4).abs() < 1e-9);
        assert!(Steady::of(&[], 7, 0.01).is_none());
    }
}
