//! A round of a cell of different tasks (issue 45): each robot runs its own task's model
//! under the cell's coordinator ([`tandem_planner::CellPlanner::coordinator`]) while one
//! simulated operator supervises the low-confidence robot.
//!
//! The tick is the one of the module docs of [`crate::workcell`] with every per-task part
//! taken per robot: robot `i`'s reference time, commands, correction inputs, gradient bounds
//! and confidence (for the crossings of step 5) are those of its task `robot_task[i]`. The
//! control tick is the cell's (the shortest sample period of its tasks, at which the margin
//! check accepted the schedule), so a robot of a task with a longer period logs several
//! samples per reference sample; [`RoundRun::cell_records`] gives each execution at the
//! control tick, and [`tandem_planner::Planner::record_round`] resamples it to its task's
//! period ([`tandem_lfd::TaskModel::resample_execution`]). The operator's attention (its own
//! switch time) is one for all robots. A one-task cell runs [`run_round_with`] on its
//! planner: bit for bit the single-task round.

use rand::Rng;
use tandem_lfd::{Demonstration, Execution, TaskModel};
use tandem_planner::{CellPlanner, ExecutionRecord};
use tandem_realtime::{Operator, Timeline};

use super::operator::OperatorParams;
use super::record::{RobotRun, RoundRun, TickPhase};
use super::run::{
    Operate, RoundCounts, check_tick, crossed_lc_samples, finished_round, run_round_with,
};
use crate::{Error, Result};

/// Runs one round of `cell` (every robot one execution of its own task) with a simulated
/// operator: `needs(robot, ref_idx)` says whether robot `robot` needs the operator at
/// reference sample `ref_idx` of its own task, asked once per supervised sample before the
/// operator's draw from `rng`; `params[t]` is the operator on task `t` of the cell (its
/// rates and the channel its corrections raise; the rates of task 0 set the unneeded
/// episodes and the switch time). A one-task cell is [`run_round_with`] on its planner.
/// Deterministic for the state of `rng`.
///
/// # Errors
/// [`Error::Mismatch`] for operators that are not one per task; invalid parameters, a
/// task's model without its correction channel, a degenerate command, or a round that does
/// not finish ([`Error::DidNotFinish`]).
pub fn run_cell_round(
    cell: &CellPlanner,
    mut needs: impl FnMut(usize, usize) -> bool,
    params: &[OperatorParams],
    rng: &mut impl Rng,
) -> Result<RoundRun> {
    let tasks = cell.tasks();
    if params.len() != tasks.len() {
        return Err(Error::Mismatch {
            what: "operators (one per task of the cell)",
            expected: tasks.len(),
            found: params.len(),
        });
    }
    if !cell.is_mixed() {
        return run_round_with(tasks[0].planner(), needs, &params[0], rng);
    }
    for p in params {
        p.validate()?;
    }
    let mut coord = cell.coordinator()?;
    let tick_s = coord.tick_s();
    let robot_task = cell.robot_task();
    let n = robot_task.len();
    let models: Vec<&TaskModel> = robot_task
        .iter()
        .map(|&t| tasks[t].planner().model())
        .collect();
    for m in &models {
        // The cell's tick is its shortest task period: never coarser than a task's.
        if tick_s > m.dt_s() * (1.0 + 1e-9) {
            check_tick(tick_s, m.dt_s())?;
        }
    }
    let mut ops = params
        .iter()
        .zip(tasks)
        .map(|(p, t)| Operate::new(t.planner().model(), p, tick_s))
        .collect::<Result<Vec<_>>>()?;
    let problems: Vec<_> = robot_task
        .iter()
        .map(|&t| tasks[t].planner().problem())
        .collect();
    let mut runs: Vec<RobotRun> = robot_task
        .iter()
        .map(|&t| {
            let m = tasks[t].planner().model();
            let per_ref = (m.dt_s() / tick_s).ceil() as usize;
            ops[t].empty_run(m.n_ref() * per_ref)
        })
        .collect();
    let mut in_episode = vec![false; n];
    let mut ref_now = coord.ref_time_now().to_vec();
    let max_end_s = coord
        .robots()
        .iter()
        .map(Timeline::end_s)
        .fold(0.0, f64::max);
    let max_ratio = problems
        .iter()
        .flat_map(|p| {
            p.grad_max()
                .iter()
                .zip(p.grad_min())
                .map(|(hi, lo)| hi / lo)
        })
        .fold(1.0, f64::max);
    let budget = ((max_end_s / tick_s) * max_ratio * 2.0) as usize + 1000;
    let mut counts = RoundCounts::default();
    let mut corrected_tick: Vec<bool> = Vec::new();
    while !coord.is_finished() {
        if counts.ticks >= budget {
            return Err(Error::DidNotFinish { ticks: budget });
        }
        // Step 0 (as `RoundSim::record_phases`): each robot's clock and phase.
        let held = coord.fault().map(|f| f.stopped);
        let clocks = coord.clock_s();
        let running = coord.running_now();
        let low_conf = coord.low_conf_now();
        for (i, run) in runs.iter_mut().enumerate() {
            run.clock_s.push(clocks[i]);
            run.phases.push(if held == Some(i) {
                TickPhase::Held
            } else if running[i] {
                TickPhase::Running
            } else if ref_now[i] >= models[i].n_ref() as f64 {
                TickPhase::Finished
            } else {
                TickPhase::Waiting
            });
        }
        // Steps 1–4: every running robot logs its sample; the supervised one may be corrected.
        let mut operator = Operator::Scheduled;
        let mut unsupervised_at = [None; tandem_realtime::MAX_ROBOTS];
        for i in 0..n {
            if !running[i] {
                continue;
            }
            let t = robot_task[i];
            let run = &mut runs[i];
            if run.start_tick == usize::MAX {
                run.start_tick = counts.ticks;
            }
            let model = models[i];
            let k = (ref_now[i].floor() as usize).min(model.n_ref() - 1);
            let supervised =
                low_conf[i].then(|| (problems[i].grad_min()[k], problems[i].grad_max()[k]));
            if supervised.is_none() {
                unsupervised_at[i] = Some(ref_now[i]);
            }
            let switching = low_conf[i] && ops[0].attend(i, counts.ticks);
            if let Some(input) = ops[t].robot_tick(
                model,
                run,
                &mut in_episode[i],
                ref_now[i],
                supervised,
                switching,
                |idx| needs(i, idx),
                rng,
            )? {
                operator = input;
            }
        }
        let corrected = !matches!(operator, Operator::Scheduled);
        let tick = coord.tick(operator)?;
        // Step 5: a robot that crossed whole low-confidence samples of its task in the tick.
        for (i, t0) in unsupervised_at.iter().enumerate().take(n) {
            if let (Some(t0), true) = (*t0, tick.low_conf[i]) {
                let conf = problems[i].conf();
                let mut crossed = crossed_lc_samples(conf, t0, tick.ref_time[i]);
                if let Some(first) = crossed.next() {
                    let needed = needs(i, first) | crossed.fold(false, |a, j| a | needs(i, j));
                    let switching = ops[0].attend(i, counts.ticks);
                    ops[robot_task[i]].supervise_crossing(
                        &mut runs[i],
                        &mut in_episode[i],
                        needed,
                        switching,
                        rng,
                    );
                }
            }
        }
        ref_now.copy_from_slice(&tick.ref_time);
        corrected_tick.push(corrected);
        if counts.count(&tick) {
            // The operator has dealt with the robot that kept running: release the held one.
            coord.clear_fault();
        }
    }
    Ok(finished_round(
        &coord,
        runs,
        counts,
        tick_s,
        &corrected_tick,
    ))
}

impl RoundRun {
    /// Every robot's execution record of a round of `cell` ([`run_cell_round`]), robot 1
    /// first, for [`CellPlanner::record_round`]: robot `i`'s samples with its task's channel
    /// names at the round's control tick (its task's planner resamples them to the task's
    /// period), its reference-time log and flags.
    ///
    /// # Errors
    /// [`Error::Mismatch`] for a round of another robot count; the model crate's error if a
    /// robot's samples do not form a valid demonstration.
    pub fn cell_records(&self, cell: &CellPlanner) -> Result<Vec<ExecutionRecord>> {
        if self.robots.len() != cell.n_robots() {
            return Err(Error::Mismatch {
                what: "robot runs (one per robot of the cell)",
                expected: cell.n_robots(),
                found: self.robots.len(),
            });
        }
        if !cell.is_mixed() {
            return self.records(cell.tasks()[0].planner().model());
        }
        self.robots
            .iter()
            .zip(cell.robot_task())
            .map(|(r, &t)| {
                let model = cell.tasks()[t].planner().model();
                let demonstration = Demonstration::new(
                    model.channel_names().to_vec(),
                    r.samples.clone(),
                    self.tick_s,
                )?;
                Ok(ExecutionRecord {
                    execution: Execution {
                        demonstration,
                        ref_time_log: r.ref_time_log.clone(),
                    },
                    supervised: r.supervised.clone(),
                    corrected: r.corrected.clone(),
                })
            })
            .collect()
    }
}
