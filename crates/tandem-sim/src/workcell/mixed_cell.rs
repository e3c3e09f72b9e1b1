//! The continuous cell of different tasks in the simulated workcell (issue 45): each robot
//! repeats its own task under the cell's [`ContinuousCoordinator::mixed`] (the token rule on
//! per-robot timelines, robot `k` doing `r_k` tasks per pass of the operator's order), while
//! one simulated operator supervises the robot inside a low-confidence group.
//!
//! The tick is [`CellSim`](super::CellSim)'s with every per-task part taken per robot, as in
//! [`run_cell_round`](super::run_cell_round): robot `i`'s reference time, commands,
//! correction inputs and gradient bounds are those of its task `robot_task[i]`, the operator
//! on task `t` is `params[t]` (its correction channel), and the operator's attention (its
//! switch time) is one for all robots. The control tick is the cell's (the shortest task
//! period), so a robot of a task with a longer period logs several samples per reference
//! sample; [`mixed_record`] gives a finished execution at the control tick and
//! [`tandem_planner::Planner::record_round`] resamples it to its task's period. As in the
//! one-task cell, no crossings are observed: the token rule stops a robot at the gate of
//! every low-confidence group it does not hold.

use rand::Rng;
use tandem_lfd::{Demonstration, Execution, TaskModel};
use tandem_planner::ExecutionRecord;
use tandem_realtime::continuous::ContinuousCoordinator;

use super::cell::{CellStats, FinishedTask, completed, count_gates, count_tick, hand_over};
use super::operator::OperatorParams;
use super::record::RobotRun;
use super::run::{Operate, Robots, Tasks, check_tick, step};
use crate::{Error, Result};

/// A simulated continuous cell of different tasks (module docs).
#[derive(Debug)]
pub struct MixedCellSim {
    coord: ContinuousCoordinator,
    pending: Option<ContinuousCoordinator>,
    /// The operator on each task.
    ops: Vec<Operate>,
    robot_task: Vec<usize>,
    /// Each robot's execution in progress, episode, and fractional reference time (its own
    /// task's samples) at the tick start.
    robots: Robots,
    /// Each robot's completed tasks at the end of the last tick.
    tasks: Vec<u64>,
    /// Each task's reference samples.
    n_ref: Vec<usize>,
    stats: CellStats,
}

/// Checks `coord` against the models of the tasks (`models[t]`, robot `i` doing
/// `robot_task[i]`): each robot's timeline on its task's reference samples, the control tick
/// no coarser than any task's period.
fn check(models: &[&TaskModel], robot_task: &[usize], coord: &ContinuousCoordinator) -> Result<()> {
    if coord.n_robots() != robot_task.len() {
        return Err(Error::Mismatch {
            what: "robots of the cell's coordinator (one per robot of the cell)",
            expected: robot_task.len(),
            found: coord.n_robots(),
        });
    }
    for (i, &t) in robot_task.iter().enumerate() {
        let model = models.get(t).ok_or(Error::Mismatch {
            what: "task models of the cell (one per task)",
            expected: t + 1,
            found: models.len(),
        })?;
        if coord.task_of(i).n_ref() != model.n_ref() {
            return Err(Error::Mismatch {
                what: "reference samples of a robot's task in the cell's coordinator",
                expected: model.n_ref(),
                found: coord.task_of(i).n_ref(),
            });
        }
        // The cell's tick is its shortest task period: never coarser than a task's.
        if coord.tick_s() > model.dt_s() * (1.0 + 1e-9) {
            check_tick(coord.tick_s(), model.dt_s())?;
        }
    }
    Ok(())
}

impl MixedCellSim {
    /// A cell running `coord` (made by `tandem_planner::CellPlanner::continuous_coordinator`)
    /// with robot `i` on task `robot_task[i]` of `models` and `params[t]` the operator on task
    /// `t`; every robot where the coordinator has it.
    ///
    /// # Errors
    /// [`Error::Mismatch`] for operators that are not one per task or a coordinator of other
    /// robots or tasks; invalid parameters; a model without its correction channel; a
    /// control tick coarser than a task's period ([`Error::TickMismatch`]).
    pub fn new(
        models: &[&TaskModel],
        robot_task: &[usize],
        coord: ContinuousCoordinator,
        params: &[OperatorParams],
    ) -> Result<MixedCellSim> {
        if params.len() != models.len() {
            return Err(Error::Mismatch {
                what: "operators (one per task of the cell)",
                expected: models.len(),
                found: params.len(),
            });
        }
        check(models, robot_task, &coord)?;
        let tick_s = coord.tick_s();
        let ops = params
            .iter()
            .zip(models)
            .map(|(p, m)| {
                p.validate()?;
                Operate::new(m, p, tick_s)
            })
            .collect::<Result<Vec<_>>>()?;
        let n_ref: Vec<usize> = models.iter().map(|m| m.n_ref()).collect();
        let mut sim = MixedCellSim {
            robots: Robots {
                runs: Vec::new(),
                in_episode: vec![false; robot_task.len()],
                ref_now: Vec::new(),
            },
            tasks: coord.tasks_completed().to_vec(),
            stats: CellStats {
                gate_ticks: vec![0; robot_task.len()],
                ..CellStats::default()
            },
            ops,
            robot_task: robot_task.to_vec(),
            n_ref,
            coord,
            pending: None,
        };
        sim.robots.runs = (0..robot_task.len())
            .map(|i| empty_run(&sim.ops, &sim.robot_task, &sim.n_ref, &sim.coord, i))
            .collect();
        sim.robots.ref_now = sim.ref_times();
        Ok(sim)
    }

    /// Each robot's reference time at its clock, on its own task.
    fn ref_times(&self) -> Vec<f64> {
        self.coord
            .clock_s()
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                let task = self.coord.task_of(i);
                task.ref_time_at(c).min(task.n_ref() as f64)
            })
            .collect()
    }

    /// The coordinator running the cell.
    pub fn coordinator(&self) -> &ContinuousCoordinator {
        &self.coord
    }

    /// What the cell did so far.
    pub fn stats(&self) -> &CellStats {
        &self.stats
    }

    /// Whether a new plan waits to take over ([`replan`](Self::replan)).
    pub fn has_pending(&self) -> bool {
        self.pending.is_some()
    }

    /// Gives the cell a new plan, as [`CellSim::replan`](super::CellSim::replan): it takes
    /// over ([`ContinuousCoordinator::take_over`]) now if the robots are at a hand-over
    /// point of it, else at the end of the first tick at which they are. Returns whether it
    /// took over now.
    ///
    /// # Errors
    /// As [`MixedCellSim::new`] for a coordinator that does not match the models.
    pub fn replan(&mut self, models: &[&TaskModel], next: ContinuousCoordinator) -> Result<bool> {
        check(models, &self.robot_task, &next)?;
        self.pending = Some(next);
        Ok(self.try_hand_over())
    }

    fn try_hand_over(&mut self) -> bool {
        hand_over(&mut self.coord, &mut self.pending, &mut self.stats)
    }

    /// One control tick (module docs): `needs(robot, ref_idx)` says whether robot `robot`
    /// needs the operator at reference sample `ref_idx` of its own task, asked once per
    /// supervised sample just before the operator's draw from `rng`. `models[t]` commands the
    /// robots of task `t` now (its planner's latest). Returns the tasks completed in this
    /// tick.
    ///
    /// # Errors
    /// Models of other sizes than the cell's, or a degenerate command.
    pub fn tick(
        &mut self,
        models: &[&TaskModel],
        mut needs: impl FnMut(usize, usize) -> bool,
        rng: &mut impl Rng,
    ) -> Result<Vec<FinishedTask>> {
        if models.len() != self.n_ref.len() {
            return Err(Error::Mismatch {
                what: "task models of the cell (one per task)",
                expected: self.n_ref.len(),
                found: models.len(),
            });
        }
        for (m, &n) in models.iter().zip(&self.n_ref) {
            if m.n_ref() != n {
                return Err(Error::Mismatch {
                    what: "model reference samples",
                    expected: n,
                    found: m.n_ref(),
                });
            }
        }
        count_gates(&mut self.stats, &self.coord);
        // No crossings (`None`), as in the one-task cell (module docs).
        let (t, _) = step(
            &mut self.coord,
            Tasks {
                models,
                ops: &mut self.ops,
                robot_task: &self.robot_task,
            },
            |c, i, n| (c.task_of(i).grad_min()[n], c.task_of(i).grad_max()[n]),
            None,
            &mut self.robots,
            self.stats.ticks as usize,
            &mut needs,
            rng,
        )?;
        count_tick(&mut self.stats, &mut self.coord, &t);
        let (ops, robot_task, n_ref, coord) =
            (&self.ops, &self.robot_task, &self.n_ref, &self.coord);
        let done = completed(
            &mut self.tasks,
            &t,
            self.stats.ticks,
            &mut self.robots.runs,
            |i| empty_run(ops, robot_task, n_ref, coord, i),
        );
        self.try_hand_over();
        Ok(done)
    }
}

/// An empty run for robot `robot`: room for its task's samples at the cell's control tick
/// (a task of a longer period logs several samples per reference sample).
fn empty_run(
    ops: &[Operate],
    robot_task: &[usize],
    n_ref: &[usize],
    coord: &ContinuousCoordinator,
    robot: usize,
) -> RobotRun {
    let t = robot_task[robot];
    let per_ref = (coord.task_of(robot).dt_s() / coord.tick_s())
        .ceil()
        .max(1.0) as usize;
    ops[t].empty_run(n_ref[t] * per_ref)
}

/// The planner's record of `run`, an execution of `model`'s task logged at the control tick
/// `tick_s` (s) of a cell of different tasks ([`MixedCellSim`],
/// [`run_cell_round`](super::run_cell_round)): its samples with the task's channel names at `tick_s`, its reference-time log and flags
/// ([`tandem_planner::Planner::record_round`] resamples it to the task's period).
///
/// # Errors
/// The model crate's error if the samples do not form a valid demonstration.
pub fn mixed_record(run: &RobotRun, model: &TaskModel, tick_s: f64) -> Result<ExecutionRecord> {
    let demonstration =
        Demonstration::new(model.channel_names().to_vec(), run.samples.clone(), tick_s)?;
    Ok(ExecutionRecord {
        execution: Execution {
            demonstration,
            ref_time_log: run.ref_time_log.clone(),
        },
        supervised: run.supervised.clone(),
        corrected: run.corrected.clone(),
    })
}
