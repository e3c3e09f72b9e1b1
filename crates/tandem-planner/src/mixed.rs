//! A cell of task models (issue 45): different tasks on different robots under one operator.
//!
//! A [`CellPlanner`] holds one [`Planner`] per named task (its demonstrations' model, its
//! observations, its latched confidence and its recorded rounds, for the robots that do
//! that task) and a robot → task map. Robots that share a task share its learning: a
//! round's executions of the robots of task `t` are recorded into `t`'s one planner
//! ([`Planner::record_round`]). A cell of one task *is* its planner: schedule, coordinator,
//! rounds and saved bytes (format 11) are exactly the [`Planner`]'s. A cell of two or more
//! tasks is scheduled here ([`CellSchedule`]: robot by robot at the least offset the margin
//! check accepts that the placement finds, on its task's fastest warp or its task schedule's) and saved as format 12
//! ([`crate::state::v12`]). docs/decisions.md, "Different tasks on different robots: the
//! cell of task models (issue 45)".

use std::path::Path;

use tandem_lfd::Demonstration;
use tandem_realtime::{Coordinator, MarginParams, Timeline, check_margins, pair_slacks};
use tandem_schedule::Problem;

use crate::planner::Origin;
use crate::state::{self, StateLock, Stored, v12};
use crate::{Error, Planner, PlannerParams, RecordReport, Result};

/// The name of the task of a one-task cell read from a format 11 file (which stores no name).
pub const DEFAULT_TASK_NAME: &str = "task";

/// Most margin checks a placement spends per robot on the windows below its tail (the serial
/// start and the bisected tail are checked first and do not count).
const MAX_CHECKS_PER_ROBOT: usize = 400;

/// How often a candidate offset that the margin check rejects is pushed by its missing
/// clearance ([`tandem_realtime::pair_slacks`]) and checked again.
const PUSHES_PER_CANDIDATE: usize = 3;

/// One task of a cell to fit: its name, demonstrations, parameters and number of robots.
#[derive(Clone, Debug)]
pub struct TaskSpec {
    /// The task's name: letters, digits, `_` and `-`, unique in the cell.
    pub name: String,
    /// Its demonstrations (as [`Planner::with_robots`] takes them).
    pub demos: Vec<Demonstration>,
    /// Its planner's parameters.
    pub params: PlannerParams,
    /// How many robots of the cell do this task (≥ 1).
    pub robots: usize,
}

/// One task of a [`CellPlanner`]: its name and its planner (model, confidence, rounds).
#[derive(Clone, Debug)]
pub struct CellTask {
    name: String,
    planner: Planner,
}

impl CellTask {
    /// The task's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The task's planner: its model, observations, confidence and recorded rounds, for the
    /// robots of the cell that do this task ([`Planner::n_robots`] of them).
    pub fn planner(&self) -> &Planner {
        &self.planner
    }
}

/// The rounds schedule of a cell of two or more tasks: one execution warp per robot on its
/// own task's reference samples, the start offsets, the control tick, and the certificate's
/// lower bound.
#[derive(Clone, Debug, PartialEq)]
pub struct CellSchedule {
    /// Robot `i`'s execution warp gradients `ψ̇_Ei[n]` (execution samples per reference
    /// sample of its task): its task's fastest admissible warp (`Problem::fastest_warp`), or,
    /// for the robots of a task of two or more robots when that places them better, the
    /// warps of the task's own schedule ([`Planner::schedule`]).
    pub grad_exec: Vec<Vec<f64>>,
    /// Start offsets `τ_i` (s, global time) of robots 2..N; robot 1 starts at 0.
    pub offsets_s: Vec<f64>,
    /// The control tick (real s) the margin check accepted the schedule at.
    pub tick_s: f64,
    /// `T_total` (s): the last robot's planned end.
    pub t_total_s: f64,
    /// A lower bound (s) on `T_total` of every rounds schedule of these robots and
    /// confidences: the longest robot's fastest execution, and the low-confidence time of
    /// all robots at the operator's mean rate plus one switch time between robots.
    pub lower_bound_s: f64,
    /// Margin checks run to place the robots.
    pub margin_checks: usize,
}

impl CellSchedule {
    /// `T_total − lower_bound` (s, ≥ 0): how far the schedule may be from the optimum.
    pub fn gap_s(&self) -> f64 {
        (self.t_total_s - self.lower_bound_s).max(0.0)
    }

    /// Robot `i`'s start (s, global time): 0 for robot 0, else `offsets_s[i − 1]`.
    pub fn start_s(&self, robot: usize) -> f64 {
        if robot == 0 {
            0.0
        } else {
            self.offsets_s[robot - 1]
        }
    }
}

/// What [`CellPlanner::record_round`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct CellRecordReport {
    /// Per task (in the cell's order), what its planner's [`Planner::record_round`] did.
    pub tasks: Vec<RecordReport>,
    /// The cell's `T_total` before the round (s).
    pub previous_t_total_s: f64,
    /// The cell's `T_total` after it (s).
    pub t_total_s: f64,
}

/// A cell of task models: one planner per task, a robot → task map and, for two or more
/// tasks, one rounds schedule over all robots (module docs).
#[derive(Clone, Debug)]
pub struct CellPlanner {
    tasks: Vec<CellTask>,
    robot_task: Vec<usize>,
    /// `None` for a one-task cell (its planner's schedule is the cell's).
    schedule: Option<CellSchedule>,
    /// Where a cell of two or more tasks was loaded from (a one-task cell's is its
    /// planner's).
    origin: Origin,
}

/// Checks a task name: non-empty, at most 64 characters, letters, digits, `_` and `-`.
fn check_name(name: &str) -> Result<()> {
    let ok = !name.is_empty()
        && name.len() <= 64
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if ok {
        Ok(())
    } else {
        Err(Error::BadCell {
            what: format!("task name `{name}`"),
            why: "a task name is 1 to 64 letters, digits, `_` or `-`: rename it".into(),
        })
    }
}

impl CellPlanner {
    /// Fits every task ([`Planner::with_robots`] with its robot count) and makes the cell:
    /// the robots are numbered task by task in the order given (the first task's robots
    /// first).
    ///
    /// # Errors
    /// As [`CellPlanner::from_planners`], and each task's fit error, named by task.
    pub fn fit(specs: &[TaskSpec]) -> Result<Self> {
        let mut tasks = Vec::with_capacity(specs.len());
        let mut robot_task = Vec::new();
        for (t, spec) in specs.iter().enumerate() {
            check_name(&spec.name)?;
            if spec.robots == 0 {
                return Err(Error::BadCell {
                    what: format!("robots of task `{}`", spec.name),
                    why: "0 robots: give each task at least one robot".into(),
                });
            }
            let planner = Planner::with_robots(&spec.demos, spec.params.clone(), spec.robots)
                .map_err(|e| Error::BadCell {
                    what: format!("task `{}`", spec.name),
                    why: e.to_string(),
                })?;
            tasks.push((spec.name.clone(), planner));
            robot_task.extend(std::iter::repeat_n(t, spec.robots));
        }
        Self::from_planners(tasks, robot_task)
    }

    /// The one-task cell of `planner`, its task named `name`.
    ///
    /// # Errors
    /// [`Error::BadCell`] for a bad name.
    pub fn from_planner(name: &str, planner: Planner) -> Result<Self> {
        let n = planner.n_robots();
        Self::from_planners(vec![(name.to_string(), planner)], vec![0; n])
    }

    /// The cell of `tasks` (name, planner) with robot `i` doing task `robot_task[i]`. Task
    /// `t`'s planner runs the robots mapped to it, in robot order, so its robot count is
    /// theirs. A cell of two or more tasks is scheduled at once ([`CellPlanner::schedule`]).
    ///
    /// # Errors
    /// [`Error::BadCell`] for no task, a bad or repeated name, a robot mapped to no task, a
    /// task without robots or with another robot count than its planner's, more than
    /// `MAX_ROBOTS` robots, and, for two or more tasks, tasks whose operators differ
    /// (`switch_s`) or a load cap below 1; the realtime crate's error when no placement
    /// passes the margin check. Declared hold points are kept per task (used by the
    /// continuous cell; the rounds placement runs without waiting at them).
    pub fn from_planners(tasks: Vec<(String, Planner)>, robot_task: Vec<usize>) -> Result<Self> {
        if tasks.is_empty() {
            return Err(Error::BadCell {
                what: "tasks".into(),
                why: "no task: give at least one task".into(),
            });
        }
        for (k, (name, _)) in tasks.iter().enumerate() {
            check_name(name)?;
            if tasks[..k].iter().any(|(n, _)| n == name) {
                return Err(Error::BadCell {
                    what: format!("task name `{name}`"),
                    why: "given twice: give each task its own name".into(),
                });
            }
        }
        tandem_realtime::RobotCount::new(robot_task.len())?;
        if let Some(i) = robot_task.iter().position(|&t| t >= tasks.len()) {
            return Err(Error::BadCell {
                what: "robots".into(),
                why: format!(
                    "robot {} is mapped to task {} of {}: map every robot to a task",
                    i + 1,
                    robot_task[i] + 1,
                    tasks.len()
                ),
            });
        }
        for (t, (name, planner)) in tasks.iter().enumerate() {
            let k = robot_task.iter().filter(|&&x| x == t).count();
            if k != planner.n_robots() {
                return Err(Error::BadCell {
                    what: format!("robots of task `{name}`"),
                    why: format!(
                        "{k} robots of the cell do it but its planner runs {}: give the task \
                         as many robots as its planner",
                        planner.n_robots()
                    ),
                });
            }
        }
        let mut cell = CellPlanner {
            tasks: tasks
                .into_iter()
                .map(|(name, planner)| CellTask { name, planner })
                .collect(),
            robot_task,
            schedule: None,
            origin: Origin::default(),
        };
        cell.check_mixed()?;
        cell.reschedule()?;
        Ok(cell)
    }

    /// For two or more tasks: one operator (the same `switch_s` in every task) and no load
    /// cap. Each task keeps its declared hold points: the continuous cell waits at its
    /// usable ones ([`CellPlanner::continuous_plan`]); the rounds placement does not
    /// ([`CellSchedule`]).
    fn check_mixed(&self) -> Result<()> {
        if self.tasks.len() < 2 {
            return Ok(());
        }
        let switch_s = self.tasks[0].planner.params().sampler.switch_s;
        for task in &self.tasks {
            let p = task.planner.params();
            let bad = |what: &str, why: &str| Error::BadCell {
                what: format!("{what} of task `{}`", task.name),
                why: why.into(),
            };
            if p.sampler.switch_s.to_bits() != switch_s.to_bits() {
                return Err(bad(
                    "switch_s",
                    "the tasks of one cell share one operator: give every task the same switch time",
                ));
            }
            if p.sampler.max_busy_share != 1.0 {
                return Err(bad(
                    "max_busy_share",
                    "a load cap is not supported in a cell of several tasks yet: leave it at 1",
                ));
            }
        }
        Ok(())
    }

    /// Re-schedules a cell of two or more tasks from its tasks' current problems (a one-task
    /// cell keeps its planner's schedule).
    fn reschedule(&mut self) -> Result<()> {
        if self.tasks.len() < 2 {
            self.schedule = None;
            return Ok(());
        }
        let problems: Vec<&Problem> = self
            .robot_task
            .iter()
            .map(|&t| self.tasks[t].planner.problem())
            .collect();
        let tick_s = self
            .tasks
            .iter()
            .map(|t| t.planner.schedule().tick_s)
            .fold(f64::INFINITY, f64::min);
        let switch_s = self.tasks[0].planner.params().sampler.switch_s;
        let schedules: Vec<&tandem_schedule::Schedule> =
            self.tasks.iter().map(|t| t.planner.schedule()).collect();
        let hints = shared_hints(&self.robot_task, &schedules);
        self.schedule = Some(schedule_mixed(&problems, &hints, tick_s, switch_s)?);
        Ok(())
    }

    /// The tasks, in the cell's order.
    pub fn tasks(&self) -> &[CellTask] {
        &self.tasks
    }

    /// `robot_task()[i]`: the index of robot `i`'s task in [`CellPlanner::tasks`].
    pub fn robot_task(&self) -> &[usize] {
        &self.robot_task
    }

    /// The task named `name`, if any.
    pub fn task(&self, name: &str) -> Option<&CellTask> {
        self.tasks.iter().find(|t| t.name == name)
    }

    /// The number of robots `N`.
    pub fn n_robots(&self) -> usize {
        self.robot_task.len()
    }

    /// The cyclic plan of this cell run continuously (issue 45): robot `i` repeats its task,
    /// `r_i` times per period, on its task's current problem
    /// ([`tandem_schedule::cyclic::mixed_cyclic_plan`]: the best ratios `r ∈ {1..6}^N` and
    /// operator order found, the period of its event graph and the bound of every plan with
    /// those ratios), with the token rule's hand-overs counted at the cell's control tick
    /// (the shortest of the tasks' schedule ticks, real s, as in rounds) and the operator's
    /// switch time. A one-task cell's continuous plan is its planner's
    /// ([`Planner::cyclic_plan`]); this one is for comparing a cell of tasks with its bound.
    ///
    /// # Errors
    /// The scheduler's error when no searched order admits a period.
    pub fn continuous_plan(&self) -> Result<tandem_schedule::cyclic::MixedCyclicPlan> {
        let problems: Vec<&Problem> = self
            .robot_task
            .iter()
            .map(|&t| self.tasks[t].planner.problem())
            .collect();
        let tick_s = self
            .tasks
            .iter()
            .map(|t| t.planner.schedule().tick_s)
            .fold(f64::INFINITY, f64::min);
        let params = tandem_schedule::cyclic::MixedParams {
            handover_tick_s: (tick_s.is_finite() && tick_s > 0.0).then_some(tick_s),
            switch_s: self.tasks[0].planner.params().sampler.switch_s,
            ..tandem_schedule::cyclic::MixedParams::default()
        };
        Ok(tandem_schedule::cyclic::mixed_cyclic_plan(
            &problems, &params,
        )?)
    }

    /// The control tick (real s) of the cell run continuously: the shortest of its tasks'
    /// schedule ticks (as in rounds), the tick [`CellPlanner::continuous_plan`] counts the
    /// hand-overs at.
    pub fn continuous_tick_s(&self) -> f64 {
        self.tasks
            .iter()
            .map(|t| t.planner.schedule().tick_s)
            .fold(f64::INFINITY, f64::min)
    }

    /// The run-time coordinator of the continuous `plan` of this cell
    /// ([`CellPlanner::continuous_plan`], made on the tasks' current problems): robot `i` on
    /// its own task's fastest warp and holds, `r_i` tasks per pass of the plan's operator
    /// order (`MixedCyclicPlan::coordinator`), at [`CellPlanner::continuous_tick_s`], with the
    /// operator's switch time of the planner's parameters (the token passes to another
    /// robot no sooner than that after a stretch ended). Sound for any operator (the token
    /// rule, per robot's own timeline).
    ///
    /// # Errors
    /// The scheduler's error for a plan made on other problems (plan the cell again), the
    /// realtime crate's for a bad switch time.
    pub fn continuous_coordinator(
        &self,
        plan: &tandem_schedule::cyclic::MixedCyclicPlan,
    ) -> Result<tandem_realtime::ContinuousCoordinator> {
        let problems: Vec<&Problem> = self.tasks.iter().map(|t| t.planner.problem()).collect();
        let switch_s = self.tasks[0].planner.params().sampler.switch_s;
        Ok(plan
            .coordinator(&problems, &self.robot_task, self.continuous_tick_s())?
            .with_switch_s(switch_s)?)
    }

    /// Whether the cell has two or more tasks (scheduled by [`CellSchedule`], saved as
    /// format 12).
    pub fn is_mixed(&self) -> bool {
        self.tasks.len() > 1
    }

    /// The rounds schedule of a cell of two or more tasks; `None` for one task (its
    /// planner's [`Planner::schedule`] is the cell's).
    pub fn schedule(&self) -> Option<&CellSchedule> {
        self.schedule.as_ref()
    }

    /// The cell's planned `T_total` (s).
    pub fn t_total_s(&self) -> f64 {
        match &self.schedule {
            Some(s) => s.t_total_s,
            None => self.tasks[0].planner.outcome().t_total_s,
        }
    }

    /// Rounds recorded (the same in every task: a round is one execution of every robot).
    pub fn rounds_recorded(&self) -> usize {
        self.tasks[0].planner.rounds_recorded()
    }

    /// Robot `i`'s timeline on the cell's schedule (its task's confidence and gradient
    /// bounds, its warp, its start): what the coordinator runs. For a one-task cell, the
    /// planner's schedule on its problem.
    ///
    /// # Errors
    /// The realtime crate's error for a timeline it refuses (never for a cell this type
    /// built).
    pub fn timelines(&self) -> Result<Vec<Timeline>> {
        let Some(s) = &self.schedule else {
            let planner = &self.tasks[0].planner;
            let p = planner.problem();
            let sch = planner.schedule();
            return (0..sch.n_robots())
                .map(|i| {
                    let start = if i == 0 { 0.0 } else { sch.offsets_s[i - 1] };
                    timeline(p, &sch.grad_exec[i], start)
                })
                .collect();
        };
        self.robot_task
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                timeline(
                    self.tasks[t].planner.problem(),
                    &s.grad_exec[i],
                    s.start_s(i),
                )
            })
            .collect()
    }

    /// The run-time coordinator of the cell's schedule at its tick and switch time: for one
    /// task exactly [`Planner::coordinator`]; for two or more tasks
    /// [`Coordinator::with_margins`] on [`CellPlanner::timelines`] (the margin check runs
    /// again on the very plans it runs).
    ///
    /// # Errors
    /// The realtime crate's `Unsafe` if the margin check rejects the plans (never for a cell
    /// this type scheduled).
    pub fn coordinator(&self) -> Result<Coordinator> {
        let Some(s) = &self.schedule else {
            return self.tasks[0].planner.coordinator();
        };
        let switch_s = self.tasks[0].planner.params().sampler.switch_s;
        Ok(Coordinator::with_margins(
            self.timelines()?,
            &[],
            &MarginParams::new(s.tick_s).with_switch_s(switch_s),
        )?)
    }

    /// Records one round: `executions[i]` is robot `i`'s execution of its own task. Each
    /// task's planner records its robots' executions in robot order
    /// ([`Planner::record_round`]: model, observations, confidence, its own schedule); a cell
    /// of two or more tasks is then re-scheduled. A failure in any task leaves the whole
    /// cell as it was.
    ///
    /// # Errors
    /// [`Error::BadCell`] for a number of executions other than `N`; each task's
    /// [`Planner::record_round`] error, named by task.
    pub fn record_round(
        &mut self,
        executions: &[crate::ExecutionRecord],
    ) -> Result<CellRecordReport> {
        if executions.len() != self.n_robots() {
            return Err(Error::BadCell {
                what: "executions".into(),
                why: format!(
                    "{} execution records for a round of {} robots: give one per robot",
                    executions.len(),
                    self.n_robots()
                ),
            });
        }
        let previous_t_total_s = self.t_total_s();
        let mut next = self.clone();
        let mut reports = Vec::with_capacity(self.tasks.len());
        let single = !self.is_mixed();
        for (t, task) in next.tasks.iter_mut().enumerate() {
            let mine: Vec<crate::ExecutionRecord> = executions
                .iter()
                .zip(&self.robot_task)
                .filter(|&(_, &rt)| rt == t)
                .map(|(e, _)| e.clone())
                .collect();
            let report = task.planner.record_round(&mine).map_err(|e| {
                if single {
                    e
                } else {
                    Error::BadCell {
                        what: format!("round of task `{}`", task.name),
                        why: format!("{e}; nothing was recorded"),
                    }
                }
            })?;
            reports.push(report);
        }
        next.reschedule()?;
        let t_total_s = next.t_total_s();
        *self = next;
        Ok(CellRecordReport {
            tasks: reports,
            previous_t_total_s,
            t_total_s,
        })
    }

    /// Sets the operator's switch time and load cap of every task ([`Planner::set_operator`])
    /// and, for two or more tasks, re-schedules the cell with them. On error the cell is as
    /// before.
    ///
    /// # Errors
    /// As [`Planner::set_operator`]; for two or more tasks as [`CellPlanner::from_planners`].
    pub fn set_operator(&mut self, switch_s: f64, max_busy_share: f64) -> Result<()> {
        let mut next = self.clone();
        for task in &mut next.tasks {
            task.planner.set_operator(switch_s, max_busy_share)?;
        }
        next.check_mixed()?;
        next.reschedule()?;
        *self = next;
        Ok(())
    }

    /// Saves the cell to `path` under the file's lock ([`CellPlanner::save_locked`]).
    ///
    /// # Errors
    /// As [`CellPlanner::save_locked`], and [`Error::Locked`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let lock = StateLock::acquire(path.as_ref(), state::DEFAULT_LOCK_TIMEOUT)?;
        self.save_locked(&lock)
    }

    /// Saves the cell to the state file `lock` protects, atomically: a one-task cell as its
    /// planner ([`Planner::save_locked`], format 11, the same bytes), a cell of two or more
    /// tasks as format 12. Like the planner's save, it refuses to replace a file that is not
    /// a state file, a file another process saved into since this cell was loaded from it,
    /// and one holding rounds this cell does not hold.
    ///
    /// # Errors
    /// [`Error::WouldOverwrite`], [`Error::Changed`], [`Error::WouldDiscardRounds`],
    /// [`Error::Io`], [`Error::Encode`].
    pub fn save_locked(&self, lock: &StateLock) -> Result<()> {
        if !self.is_mixed() {
            return self.tasks[0].planner.save_locked(lock);
        }
        self.origin
            .save_guarded(
                lock,
                false,
                |path| Self::rounds_at(path),
                || state::encode_cell(&self.to_payload()?),
            )
            .map(|_| ())
    }

    /// The format 12 payload of a cell of two or more tasks.
    fn to_payload(&self) -> Result<v12::CellPayload> {
        Ok(v12::CellPayload {
            tasks: self
                .tasks
                .iter()
                .map(|t| v12::TaskPayload::from_state(&t.name, &t.planner.to_state()))
                .collect::<Result<_>>()?,
            robot_task: self.robot_task.iter().map(|&t| t as u32).collect(),
            extras: state::Extras::default(),
        })
    }

    /// Loads a cell: a format 12 file as its tasks, a file of formats 4 to 11 as a one-task
    /// cell named [`DEFAULT_TASK_NAME`] ([`Planner::load`]).
    ///
    /// # Errors
    /// As [`Planner::load`]; [`Error::Corrupt`] naming the file (and the task) when the
    /// parts of a cell do not fit together.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = state::read(path)?;
        let cell = match state::decode_stored(&bytes, path)? {
            Stored::Task(_) => {
                return Self::from_planner(DEFAULT_TASK_NAME, Planner::load(path)?);
            }
            Stored::Cell(cell) => cell,
        };
        let corrupt = |why: String| Error::Corrupt {
            path: path.to_path_buf(),
            why,
        };
        if cell.tasks.len() < 2 {
            return Err(corrupt(format!(
                "a cell file of {} task(s): format 12 holds two or more",
                cell.tasks.len()
            )));
        }
        cell.extras
            .clone()
            .finish()
            .map_err(|e| corrupt(e.to_string()))?;
        let mut tasks = Vec::with_capacity(cell.tasks.len());
        for task in cell.tasks {
            let name = task.name.clone();
            let st = task.into_state(path)?;
            let planner = Planner::from_loaded(st, path).map_err(|e| Error::Corrupt {
                path: path.to_path_buf(),
                why: format!("task `{name}`: {e}"),
            })?;
            tasks.push((name, planner));
        }
        let rounds = tasks[0].1.rounds_recorded();
        if let Some((name, p)) = tasks.iter().find(|(_, p)| p.rounds_recorded() != rounds) {
            return Err(corrupt(format!(
                "task `{name}` holds {} rounds, task `{}` {rounds}: every task records every round",
                p.rounds_recorded(),
                tasks[0].0
            )));
        }
        let robot_task = cell.robot_task.iter().map(|&t| t as usize).collect();
        let out = Self::from_planners(tasks, robot_task).map_err(|e| corrupt(e.to_string()))?;
        if let Some(stamp) = state::stamp_of(&bytes) {
            out.origin.set(state::resolved(path), stamp);
        }
        Ok(out)
    }

    /// The rounds recorded in the state file at `path`, a task's or a cell's; 0 when there is
    /// no file or an empty one.
    ///
    /// # Errors
    /// As [`CellPlanner::load`] for a file that is there but cannot be read.
    pub fn rounds_at(path: impl AsRef<Path>) -> Result<usize> {
        let path = path.as_ref();
        match std::fs::read(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(0),
            Ok(b) if b.is_empty() => return Ok(0),
            _ => {}
        }
        let bytes = state::read(path)?;
        match state::decode_stored(&bytes, path)? {
            Stored::Task(st) => Ok(st.rounds_recorded),
            Stored::Cell(cell) => {
                let Some(first) = cell.tasks.into_iter().next() else {
                    return Ok(0);
                };
                Ok(first.payload(path)?.0.rounds_recorded)
            }
        }
    }
}

/// Robot timeline of `problem` at `grad_exec` starting at `start_s`.
fn timeline(problem: &Problem, grad_exec: &[f64], start_s: f64) -> Result<Timeline> {
    Ok(Timeline::new(
        problem.conf(),
        grad_exec,
        problem.grad_min(),
        problem.grad_max(),
        start_s,
        problem.dt_s(),
    )?)
}

/// The low-confidence time (s) of `problem` at the operator's mean rate.
fn lc_time_s(problem: &Problem) -> f64 {
    let sum: f64 = problem
        .conf()
        .iter()
        .zip(problem.grad_mean())
        .filter(|&(&c, _)| !c)
        .map(|(_, &g)| g)
        .sum();
    sum * problem.dt_s()
}

/// What a robot's task planner suggests for its place in a mixed cell: robot `i` is robot
/// `j ≥ 1` of its task, whose robot 0 is robot `anchor` of the cell, and the task's own
/// schedule ([`Planner::schedule`], the single-task scheduler's result for that task's `K_t`
/// robots) runs it on `warp` at `rel_offset_s` after its robot 0.
#[derive(Clone, Debug)]
pub(crate) struct SharedHint {
    /// The cell's robot that is robot 0 of the same task (placed before this one).
    pub anchor: usize,
    /// The task schedule's start of this robot relative to its robot 0 (s).
    pub rel_offset_s: f64,
    /// The task schedule's warp of this robot.
    pub warp: Vec<f64>,
    /// The task schedule's warp of its robot 0.
    pub anchor_warp: Vec<f64>,
}

/// The hints of `robot_task` from each task's own schedule (`schedules[t]`): robot `j ≥ 1`
/// of a task of `K_t ≥ 2` robots gets one, every other robot `None`.
pub(crate) fn shared_hints(
    robot_task: &[usize],
    schedules: &[&tandem_schedule::Schedule],
) -> Vec<Option<SharedHint>> {
    let mut seen: Vec<Option<usize>> = vec![None; schedules.len()];
    let mut count = vec![0usize; schedules.len()];
    robot_task
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            let j = count[t];
            count[t] += 1;
            let anchor = *seen[t].get_or_insert(i);
            let sch = schedules[t];
            if j == 0 || j >= sch.n_robots() {
                return None;
            }
            Some(SharedHint {
                anchor,
                rel_offset_s: sch.offsets_s[j - 1],
                warp: sch.grad_exec[j].clone(),
                anchor_warp: sch.grad_exec[0].clone(),
            })
        })
        .collect()
}

/// One placement of robots `1..N` (robot 0 at 0 on `warps[0]`), robot by robot on the given
/// warps, each at the least offset found by [`place_robot`]. The check of three or more
/// robots (the lead bound) can refuse every start of a later robot, the serial one included,
/// behind two robots that the two-robot check accepted close together; then the placement is
/// made again with the robots from the one before the refused robot on placed at their serial
/// starts, and so on down to every robot serial.
fn place_all(
    problems: &[&Problem],
    warps: &[Vec<f64>],
    hints: &[Option<SharedHint>],
    params: &MarginParams,
    switch_s: f64,
) -> Result<Placement> {
    let mut serial_from = problems.len();
    let mut checks = 0;
    loop {
        match place_from(problems, warps, hints, params, switch_s, serial_from) {
            Ok((placed, offsets, n)) => return Ok((placed, offsets, checks + n)),
            Err((i, n)) => {
                checks += n;
                if serial_from <= 1 || i == 0 {
                    return Err(tandem_realtime::Error::Unsafe {
                        tick_s: params.tick_s,
                    }
                    .into());
                }
                serial_from = (i - 1).max(1).min(serial_from - 1);
            }
        }
    }
}

/// A placement: every robot's timeline, the offsets of robots `1..N` (s) and the margin
/// checks it took.
type Placement = (Vec<Timeline>, Vec<f64>, usize);

/// [`place_all`] with robots `serial_from..N` at their serial starts: the robots, offsets and
/// checks, or the first robot no start of which passes, and the checks spent.
fn place_from(
    problems: &[&Problem],
    warps: &[Vec<f64>],
    hints: &[Option<SharedHint>],
    params: &MarginParams,
    switch_s: f64,
    serial_from: usize,
) -> std::result::Result<Placement, (usize, usize)> {
    let mut placed = vec![timeline(problems[0], &warps[0], 0.0).map_err(|_| (0, 0))?];
    let mut offsets_s = Vec::with_capacity(problems.len().saturating_sub(1));
    let mut checks = 0;
    for i in 1..problems.len() {
        let hint = hints
            .get(i)
            .and_then(Option::as_ref)
            .map(|h| placed[h.anchor].start_s() + h.rel_offset_s);
        let (c, robots, n) = place_robot(
            &placed,
            &problems[..=i],
            &warps[i],
            hint,
            params,
            switch_s,
            i >= serial_from,
        )
        .map_err(|n| (i, checks + n))?;
        checks += n;
        offsets_s.push(c);
        placed = robots;
    }
    Ok((placed, offsets_s, checks))
}

/// The open offsets `c` at which robot `local`'s nominal low-confidence runs (start 0) would
/// come within `switch_s` of a placed robot's: `(a.start − δ − b.end, a.end + δ − b.start)`
/// for each placed run `a` and each run `b` of the robot, merged and sorted. The margin check
/// rejects every such offset (two robots' runs overlap on schedule), so no check is spent
/// there.
fn forbidden_offsets(placed: &[Timeline], local: &Timeline, switch_s: f64) -> Vec<(f64, f64)> {
    let mut spans: Vec<(f64, f64)> = placed
        .iter()
        .flat_map(|t| t.lc_intervals())
        .flat_map(|a| {
            local.lc_intervals().iter().map(move |b| {
                (
                    a.start_s - switch_s - b.end_s,
                    a.end_s + switch_s - b.start_s,
                )
            })
        })
        .filter(|(lo, hi)| lo.is_finite() && hi.is_finite() && hi > lo)
        .collect();
    spans.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut merged: Vec<(f64, f64)> = Vec::with_capacity(spans.len());
    for (lo, hi) in spans {
        match merged.last_mut() {
            Some(last) if lo < last.1 => last.1 = last.1.max(hi),
            _ => merged.push((lo, hi)),
        }
    }
    merged
}

/// The least offset `≥ c` outside the forbidden spans (`forbidden` merged and sorted).
fn allowed_from(forbidden: &[(f64, f64)], c: f64) -> f64 {
    let k = forbidden.partition_point(|&(_, hi)| hi <= c);
    match forbidden.get(k) {
        Some(&(lo, hi)) if lo < c => hi,
        _ => c,
    }
}

/// Robot `i = problems.len() − 1` on `warp` placed after the robots `placed` (docs/decisions.md,
/// "The mixed rounds placement: windows, a bisected tail and the task's own schedule"):
/// 1. the serial start (after every placed robot's slowest end, plus `δ` and a tick), which
///    always passes;
/// 2. the tail: the least offset past which the robots' nominal low-confidence runs no longer
///    meet (`forbidden_offsets`' last end), and if the check rejects it, bisected against the
///    serial start to a tick (the check's acceptance grows with the offset there: a later
///    start only moves the robot's runs away from every earlier one);
/// 3. below the best so far, ascending: 0, the task schedule's own start (`hint`), and the
///    left end of every window between forbidden offsets; a rejected candidate is pushed by
///    its missing clearance ([`pair_slacks`]) up to [`PUSHES_PER_CANDIDATE`] times, to the next
///    window if it lands in a forbidden span, at most [`MAX_CHECKS_PER_ROBOT`] checks.
///
/// The least passing offset wins. Returns it, the robots with robot `i` there, and the checks.
fn place_robot(
    placed: &[Timeline],
    problems: &[&Problem],
    warp: &[f64],
    hint: Option<f64>,
    params: &MarginParams,
    switch_s: f64,
    serial_only: bool,
) -> std::result::Result<(f64, Vec<Timeline>, usize), usize> {
    let i = placed.len();
    let p = problems[i];
    let tick_s = params.tick_s;
    let local = timeline(p, warp, 0.0).map_err(|_| 0usize)?;
    let mut checks = 0;
    // A timeline or check the realtime crate refuses counts as a rejected start.
    let passes = |c: f64, checks: &mut usize| -> Option<Vec<Timeline>> {
        let mut robots = placed.to_vec();
        robots.push(timeline(p, warp, c).ok()?);
        *checks += 1;
        check_margins(&robots, &[], params).ok()?.then_some(robots)
    };
    // 1. The serial start: after every placed robot's end at its slowest pace.
    let serial = placed
        .iter()
        .zip(problems)
        .map(|(t, q)| t.start_s() + q.grad_max().iter().sum::<f64>() * q.dt_s())
        .fold(0.0, f64::max)
        + switch_s
        + tick_s;
    let Some(robots) = passes(serial, &mut checks) else {
        return Err(checks);
    };
    let mut best = (serial, robots);
    if serial_only {
        return Ok((best.0, best.1, checks));
    }
    // 2. The tail, bisected against the serial start.
    let forbidden = forbidden_offsets(placed, &local, switch_s);
    let tail = forbidden.last().map_or(0.0, |&(_, hi)| hi.max(0.0));
    if tail < best.0 {
        if let Some(robots) = passes(tail, &mut checks) {
            best = (tail, robots);
        } else {
            let (mut lo, mut hi) = (tail, best.0);
            while hi - lo > tick_s {
                let mid = 0.5 * (lo + hi);
                match passes(mid, &mut checks) {
                    Some(robots) => {
                        hi = mid;
                        best = (mid, robots);
                    }
                    None => lo = mid,
                }
            }
        }
    }
    // 3. The windows below the best, ascending; pushes stay in the list at their place.
    let mut candidates: Vec<f64> = vec![allowed_from(&forbidden, 0.0)];
    if let Some(h) = hint {
        candidates.push(allowed_from(&forbidden, h.max(0.0)));
    }
    candidates.extend(forbidden.iter().map(|&(_, hi)| hi).filter(|&hi| hi >= 0.0));
    candidates.retain(|c| c.is_finite() && *c < best.0);
    candidates.sort_by(f64::total_cmp);
    candidates.dedup();
    // Descending, so that `pop` gives the least pending offset.
    let mut pending: Vec<(f64, usize)> = candidates.into_iter().rev().map(|c| (c, 0)).collect();
    let mut window_checks = 0;
    while let Some((c, pushes)) = pending.pop() {
        if c >= best.0 || window_checks >= MAX_CHECKS_PER_ROBOT {
            break;
        }
        window_checks += 1;
        let Ok(t) = timeline(p, warp, c) else {
            continue;
        };
        let mut robots = placed.to_vec();
        robots.push(t);
        checks += 1;
        if matches!(check_margins(&robots, &[], params), Ok(true)) {
            best = (c, robots);
            break;
        }
        if pushes >= PUSHES_PER_CANDIDATE {
            continue;
        }
        // The clearance missing on the pairs with robot i, then that much later, out of
        // the forbidden spans.
        let Ok(slacks) = pair_slacks(&robots, tick_s) else {
            continue;
        };
        let missing = slacks
            .iter()
            .filter(|s| s.cur_robot == i || s.prev_robot == i)
            .map(|s| -s.slack_s)
            .filter(|m| m.is_finite() && *m > 0.0)
            .fold(0.0, f64::max);
        let next = allowed_from(&forbidden, c + missing + switch_s + tick_s);
        if next < best.0 && !pending.iter().any(|&(x, _)| x == next) {
            let at = pending.partition_point(|&(x, _)| x > next);
            pending.insert(at, (next, pushes + 1));
        }
    }
    Ok((best.0, best.1, checks))
}

/// The rounds schedule of robots with their own problems (module docs): the better of two
/// placements ([`place_all`]), every robot on its task's fastest warp, and, when some task
/// has two or more robots, the robots of such tasks on their task schedule's warps (`hints`,
/// [`shared_hints`]); ties to the fastest warps. Every placement passes [`check_margins`].
///
/// # Errors
/// The realtime crate's errors; `Unsafe` when not even the serial start passes.
pub(crate) fn schedule_mixed(
    problems: &[&Problem],
    hints: &[Option<SharedHint>],
    tick_s: f64,
    switch_s: f64,
) -> Result<CellSchedule> {
    let params = MarginParams::new(tick_s).with_switch_s(switch_s);
    let fastest: Vec<Vec<f64>> = problems.iter().map(|p| p.fastest_warp()).collect();
    let end = |placed: &[Timeline]| {
        placed
            .iter()
            .map(Timeline::end_s)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    let (mut placed, mut offsets_s, mut checks) =
        place_all(problems, &fastest, hints, &params, switch_s)?;
    let mut warps = fastest.clone();
    if hints.iter().any(Option::is_some) {
        let mut shared = fastest.clone();
        for (i, h) in hints.iter().enumerate() {
            if let Some(h) = h {
                let n = problems[i].conf().len();
                if h.warp.len() == n && h.anchor_warp.len() == problems[h.anchor].conf().len() {
                    shared[i].clone_from(&h.warp);
                    shared[h.anchor].clone_from(&h.anchor_warp);
                }
            }
        }
        // A warp the realtime crate refuses (never one of a task's own schedule) leaves the
        // fastest placement.
        if let Ok((p2, o2, c2)) = place_all(problems, &shared, hints, &params, switch_s) {
            checks += c2;
            if end(&p2) < end(&placed) {
                (placed, offsets_s, warps) = (p2, o2, shared);
            }
        }
    }
    let t_total_s = end(&placed);
    let longest: f64 = problems
        .iter()
        .zip(&fastest)
        .map(|(p, w)| w.iter().sum::<f64>() * p.dt_s())
        .fold(0.0, f64::max);
    let lc: Vec<f64> = problems.iter().map(|p| lc_time_s(p)).collect();
    let with_lc = lc.iter().filter(|&&x| x > 0.0).count();
    let operator = lc.iter().sum::<f64>() + with_lc.saturating_sub(1) as f64 * switch_s;
    Ok(CellSchedule {
        grad_exec: warps,
        offsets_s,
        tick_s,
        t_total_s,
        lower_bound_s: longest.max(operator),
        margin_checks: checks,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ExecutionRecord;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use tandem_lfd::Execution;
    use tandem_realtime::adversary::{adversary_set, run_adversary};

    /// A task of `n` samples of one channel `force`, low-confidence exactly on `lc`, for
    /// `robots` robots (the planner's unit-test planner, seed 7).
    fn planner(n: usize, lc: std::ops::Range<usize>, robots: usize) -> Planner {
        crate::planner::test_planner(n, lc, robots, 7)
    }

    /// Two robots of task `a` (40 samples, low-confidence on 10..20) and one of task `b` (60
    /// samples, low-confidence on 30..45).
    fn mixed() -> CellPlanner {
        CellPlanner::from_planners(
            vec![
                ("a".into(), planner(40, 10..20, 2)),
                ("b".into(), planner(60, 30..45, 1)),
            ],
            vec![0, 0, 1],
        )
        .unwrap()
    }

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("tandem-mixed-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Robot execution of a task of `n` samples run at the reference rate, supervised on
    /// `lc`, every sample's force offset by `offset`.
    fn record(n: usize, lc: std::ops::Range<usize>, offset: f64) -> ExecutionRecord {
        let log: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let force = log
            .iter()
            .map(|&r| if lc.contains(&(r as usize)) { 5.0 } else { 1.0 } + offset)
            .collect();
        ExecutionRecord {
            execution: Execution {
                demonstration: Demonstration::new(vec!["force".into()], force, 0.01).unwrap(),
                ref_time_log: log.clone(),
            },
            supervised: log.iter().map(|&r| lc.contains(&(r as usize))).collect(),
            corrected: vec![false; n],
        }
    }

    #[test]
    fn a_mixed_cell_is_scheduled_per_robot_and_never_runs_two_robots_low_confidence() {
        let cell = mixed();
        let s = cell.schedule().unwrap();
        assert_eq!(s.grad_exec.len(), 3);
        assert_eq!(
            s.grad_exec.iter().map(Vec::len).collect::<Vec<_>>(),
            [40, 40, 60]
        );
        // Every gradient is 1 (identity warps): robot i runs 0.01 s per sample. The bound is
        // the longest robot (60 samples, 0.60 s) against the operator's load (0.10 + 0.10 +
        // 0.15 = 0.35 s): 0.60 s.
        assert!((s.lower_bound_s - 0.60).abs() < 1e-9, "{}", s.lower_bound_s);
        assert!(s.t_total_s >= s.lower_bound_s - 1e-9);
        // Faster than running the three one after the other (0.4 + 0.4 + 0.6 s).
        assert!(s.t_total_s < 1.4 - 1e-9, "T_total {}", s.t_total_s);
        assert_eq!(s.tick_s, 0.01);
        // The planned low-confidence runs of different robots are disjoint.
        let tl = cell.timelines().unwrap();
        let runs: Vec<(usize, f64, f64)> = tl
            .iter()
            .enumerate()
            .flat_map(|(i, t)| {
                t.lc_intervals()
                    .iter()
                    .map(move |r| (i, r.start_s, r.end_s))
            })
            .collect();
        assert_eq!(runs.len(), 3);
        for (k, a) in runs.iter().enumerate() {
            for b in &runs[k + 1..] {
                assert!(a.2 <= b.1 + 1e-12 || b.2 <= a.1 + 1e-12, "{a:?} {b:?}");
            }
        }
        assert!((s.t_total_s - tl.iter().map(Timeline::end_s).fold(0.0, f64::max)).abs() == 0.0);
        // The coordinator re-checks the plans, and no adversary makes two robots
        // low-confidence in one tick.
        let coordinator = cell.coordinator().unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(45);
        for adversary in adversary_set(3, [1.0, 1.0], 150, &mut rng) {
            let run = run_adversary(coordinator.clone(), adversary, &mut rng, 10_000).unwrap();
            assert!(run.finished, "{adversary:?}");
            assert_eq!(run.overlap_ticks, 0, "{adversary:?}");
        }
    }

    /// Robots that share a task get at least what the task's own scheduler finds for them: a
    /// cell of two robots of task `a` (its planner's two-robot schedule, `T_a`) and one robot
    /// of a task `b` that never needs the operator (40 samples at 0.01 s: starts at 0, ends at
    /// 0.40 s) ends by `max(T_a, 0.40 s)`, and every placement passes the margin check.
    #[test]
    fn robots_of_a_shared_task_are_placed_at_least_as_well_as_their_task_schedule() {
        let a = planner(40, 10..20, 2);
        let t_a = a.outcome().t_total_s;
        let cell = CellPlanner::from_planners(
            vec![("a".into(), a), ("b".into(), planner(40, 0..0, 1))],
            vec![0, 0, 1],
        )
        .unwrap();
        let s = cell.schedule().unwrap();
        assert_eq!(s.start_s(2), 0.0);
        assert!(
            s.t_total_s <= t_a.max(0.40) + 1e-9,
            "T_total {} against the task schedule's {t_a}",
            s.t_total_s
        );
        let switch_s = cell.tasks()[0].planner().params().sampler.switch_s;
        assert!(
            check_margins(
                &cell.timelines().unwrap(),
                &[],
                &MarginParams::new(s.tick_s).with_switch_s(switch_s)
            )
            .unwrap()
        );
    }

    /// The windows between forbidden offsets, by hand: a placed run at [1, 2) s and a robot's
    /// run at [0.5, 0.7) s with δ = 0.1 s forbid offsets in (1 − 0.1 − 0.7, 2 + 0.1 − 0.5) =
    /// (0.2, 1.6): the least allowed offset from 0.25 s is 1.6 s.
    #[test]
    fn forbidden_offsets_are_where_two_nominal_runs_meet() {
        let conf = |n: usize, lc: std::ops::Range<usize>| -> Vec<bool> {
            (0..n).map(|k| !lc.contains(&k)).collect()
        };
        let mk = |c: Vec<bool>, start: f64| {
            let n = c.len();
            Timeline::new(&c, &vec![1.0; n], &vec![0.5; n], &vec![2.0; n], start, 0.1).unwrap()
        };
        let placed = vec![mk(conf(30, 10..20), 0.0)];
        let local = mk(conf(10, 5..7), 0.0);
        let f = forbidden_offsets(&placed, &local, 0.1);
        assert_eq!(f.len(), 1);
        assert!(
            (f[0].0 - 0.2).abs() < 1e-9 && (f[0].1 - 1.6).abs() < 1e-9,
            "{f:?}"
        );
        assert_eq!(allowed_from(&f, 0.0), 0.0);
        assert_eq!(allowed_from(&f, 0.15), 0.15);
        assert!((allowed_from(&f, 0.25) - 1.6).abs() < 1e-9);
        assert_eq!(allowed_from(&f, 1.7), 1.7);
    }

    #[test]
    fn a_one_task_cell_is_its_planner_bit_for_bit() {
        let p = planner(40, 10..20, 2);
        let cell = CellPlanner::from_planner("sanding", p.clone()).unwrap();
        assert!(!cell.is_mixed() && cell.schedule().is_none());
        assert_eq!(cell.t_total_s(), p.outcome().t_total_s);
        let dir = scratch("one");
        cell.save(dir.join("cell.tandem")).unwrap();
        p.save(dir.join("planner.tandem")).unwrap();
        let a = std::fs::read(dir.join("cell.tandem")).unwrap();
        assert_eq!(a, std::fs::read(dir.join("planner.tandem")).unwrap());
        assert_eq!(u32::from_le_bytes(a[8..12].try_into().unwrap()), 11);
        // A format 11 file loads as a one-task cell named `task`.
        let back = CellPlanner::load(dir.join("planner.tandem")).unwrap();
        assert_eq!(back.tasks()[0].name(), DEFAULT_TASK_NAME);
        assert_eq!(back.robot_task(), [0, 0]);
        let ends = |c: &CellPlanner| -> Vec<(f64, f64)> {
            c.timelines()
                .unwrap()
                .iter()
                .map(|t| (t.start_s(), t.end_s()))
                .collect()
        };
        assert_eq!(ends(&back), ends(&cell));
        // Recording through the cell is recording through the planner.
        let round = [record(40, 10..20, 0.1), record(40, 10..20, 0.2)];
        let mut c = cell.clone();
        let mut q = p.clone();
        let rc = c.record_round(&round).unwrap();
        let rq = q.record_round(&round).unwrap();
        assert_eq!(rc.tasks.len(), 1);
        assert_eq!(
            (
                rc.tasks[0].t_total_s,
                rc.tasks[0].source,
                rc.tasks[0].newly_high
            ),
            (rq.t_total_s, rq.source, rq.newly_high)
        );
        c.save(dir.join("cell.tandem")).unwrap();
        q.save(dir.join("planner.tandem")).unwrap();
        assert_eq!(
            std::fs::read(dir.join("cell.tandem")).unwrap(),
            std::fs::read(dir.join("planner.tandem")).unwrap()
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_mixed_cell_saves_as_format_12_and_loads_back_the_same() {
        let mut cell = mixed();
        let round = [
            record(40, 10..20, 0.1),
            record(40, 10..20, 0.2),
            record(60, 30..45, 0.3),
        ];
        let report = cell.record_round(&round).unwrap();
        assert_eq!(report.tasks.len(), 2);
        assert_eq!(cell.tasks()[0].planner().rounds_recorded(), 1);
        assert_eq!(cell.tasks()[1].planner().rounds_recorded(), 1);
        assert_eq!(report.t_total_s, cell.t_total_s());
        let dir = scratch("twelve");
        let path = dir.join("cell.tandem");
        cell.save(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 12);
        let back = CellPlanner::load(&path).unwrap();
        assert_eq!(
            back.tasks().iter().map(CellTask::name).collect::<Vec<_>>(),
            ["a", "b"]
        );
        assert_eq!(back.robot_task(), [0, 0, 1]);
        assert_eq!(back.schedule(), cell.schedule());
        assert_eq!(back.rounds_recorded(), 1);
        for (x, y) in back.tasks().iter().zip(cell.tasks()) {
            assert_eq!(x.planner().confidence(), y.planner().confidence());
            assert_eq!(x.planner().observations(), y.planner().observations());
        }
        // Saved again, the same bytes; a second process's round in between is not lost.
        back.save(&path).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), bytes);
        assert_eq!(CellPlanner::rounds_at(&path).unwrap(), 1);
        let fresh = mixed();
        let err = fresh.save(&path).unwrap_err();
        assert!(
            matches!(err, Error::WouldDiscardRounds { rounds: 1, .. }),
            "{err}"
        );
        // A single task's planner refuses the cell file, naming its tasks and the fix.
        let err = Planner::load(&path).unwrap_err();
        assert!(matches!(err, Error::CellFile { .. }), "{err}");
        let msg = err.to_string();
        assert!(
            msg.contains("cell of 2 tasks (a, b)") && msg.contains("load it as a cell"),
            "{msg}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_round_that_fails_in_one_task_leaves_the_whole_cell_as_it_was() {
        let mut cell = mixed();
        let before = cell.schedule().cloned();
        // Task b's execution has the wrong channel.
        let mut bad = record(60, 30..45, 0.0);
        bad.execution.demonstration =
            Demonstration::new(vec!["torque".into()], vec![1.0; 60], 0.01).unwrap();
        let round = [record(40, 10..20, 0.1), record(40, 10..20, 0.2), bad];
        let err = cell.record_round(&round).unwrap_err();
        assert!(matches!(&err, Error::BadCell { what, .. } if what == "round of task `b`"));
        assert!(err.to_string().contains("nothing was recorded"), "{err}");
        assert_eq!(cell.rounds_recorded(), 0);
        assert_eq!(cell.tasks()[0].planner().rounds_recorded(), 0);
        assert_eq!(cell.schedule().cloned(), before);
        let err = cell.record_round(&round[..2]).unwrap_err();
        assert!(
            err.to_string()
                .contains("2 execution records for a round of 3 robots"),
            "{err}"
        );
    }

    #[test]
    fn bad_cells_are_refused_naming_what_and_the_fix() {
        let a = || planner(40, 10..20, 1);
        type Case = (Vec<(String, Planner)>, Vec<usize>, &'static str);
        let cases: Vec<Case> = vec![
            (vec![], vec![], "no task"),
            (
                vec![("a b".into(), a())],
                vec![0],
                "task name `a b`: a task name is 1 to 64 letters",
            ),
            (
                vec![("a".into(), a()), ("a".into(), a())],
                vec![0, 1],
                "given twice",
            ),
            (
                vec![("a".into(), a()), ("b".into(), a())],
                vec![0, 2],
                "robot 2 is mapped to task 3 of 2",
            ),
            (
                vec![("a".into(), a()), ("b".into(), a())],
                vec![0, 0],
                "robots of task `a`: 2 robots of the cell do it but its planner runs 1",
            ),
        ];
        for (tasks, map, want) in cases {
            let err = CellPlanner::from_planners(tasks, map)
                .unwrap_err()
                .to_string();
            assert!(err.contains(want), "`{want}` not in: {err}");
        }
        let mut b = a();
        b.set_operator(0.05, 1.0).unwrap();
        let err = CellPlanner::from_planners(vec![("a".into(), a()), ("b".into(), b)], vec![0, 1])
            .unwrap_err()
            .to_string();
        assert!(err.contains("switch_s of task `b`"), "{err}");
        // One operator for the whole cell: set on the cell, the switch time re-schedules it.
        let mut cell = mixed();
        let t0 = cell.t_total_s();
        cell.set_operator(0.05, 1.0).unwrap();
        assert!(cell.t_total_s() >= t0);
        let lb = cell.schedule().unwrap().lower_bound_s;
        assert!((lb - 0.60).abs() < 1e-9, "{lb}");
        assert!(cell.coordinator().is_ok());
        let err = cell.set_operator(0.0, 0.5).unwrap_err().to_string();
        assert!(err.contains("load cap"), "{err}");
        assert_eq!(cell.tasks()[0].planner().params().sampler.switch_s, 0.05);
    }

    /// Stress with mixed tasks (issue 45): for `N = 2..8` robots, each robot its own random
    /// task (the test kit's random problems: its own length, confidence runs, gradient bounds
    /// and sample period of 10, 5 or 4 ms; the cell's tick the shortest), at switch times 0
    /// and 50 ms, six cells per `N` from fixed seeds: the placement gives a schedule
    /// no shorter than its lower bound, and every adversary of `adversary_set` but the beam
    /// search and the two random-gradient ones (the gradient range is per robot) runs it to
    /// the end with 0 overlapping ticks and no backward step.
    #[test]
    fn random_mixed_cells_of_2_to_8_robots_never_run_two_robots_low_confidence() {
        use rand::Rng;
        use tandem_realtime::adversary::Adversary;
        use tandem_schedule::testkit::random_problem;
        let mut cells = 0;
        for n in 2..=8 {
            for case in 0..6u64 {
                let seed = 45_000 + 100 * n as u64 + case;
                let mut rng = ChaCha8Rng::seed_from_u64(seed);
                let problems: Vec<Problem> = (0..n)
                    .map(|_| {
                        let dt_s = [0.01, 0.005, 0.004][rng.random_range(0..3)];
                        random_problem(&mut rng, 40..=160, dt_s).unwrap()
                    })
                    .collect();
                let refs: Vec<&Problem> = problems.iter().collect();
                let tick_s = problems
                    .iter()
                    .map(Problem::dt_s)
                    .fold(f64::INFINITY, f64::min);
                let switch_s = if case % 2 == 0 { 0.0 } else { 0.05 };
                let s = schedule_mixed(&refs, &[], tick_s, switch_s).unwrap();
                assert!(s.lower_bound_s <= s.t_total_s + 1e-9, "seed {seed}");
                let timelines: Vec<Timeline> = refs
                    .iter()
                    .enumerate()
                    .map(|(i, p)| timeline(p, &s.grad_exec[i], s.start_s(i)).unwrap())
                    .collect();
                let coordinator = Coordinator::with_margins(
                    timelines,
                    &[],
                    &MarginParams::new(tick_s).with_switch_s(switch_s),
                )
                .unwrap();
                let ticks = (s.t_total_s / tick_s) as u64;
                for adversary in adversary_set(n, [1.0, 1.0], ticks, &mut rng) {
                    if matches!(
                        adversary,
                        Adversary::Beam { .. }
                            | Adversary::Random { .. }
                            | Adversary::RandomHeld { .. }
                    ) {
                        continue;
                    }
                    let run =
                        run_adversary(coordinator.clone(), adversary, &mut rng, 8 * ticks + 10_000)
                            .unwrap();
                    assert!(run.finished, "seed {seed}, N {n}: {adversary:?}");
                    assert_eq!(run.overlap_ticks, 0, "seed {seed}, N {n}: {adversary:?}");
                    assert_eq!(run.backward_steps, 0, "seed {seed}, N {n}: {adversary:?}");
                }
                cells += 1;
            }
        }
        assert_eq!(cells, 42);
    }

    /// A task of `n` samples of one channel `force`, low-confidence on each range of `lc`
    /// (the demonstrations differ there only), for `robots` robots (as the planner's
    /// unit-test planner).
    fn planner_runs(n: usize, lc: &[std::ops::Range<usize>], robots: usize) -> Planner {
        use tandem_lfd::{FitParams, TaskModel};
        let names = vec!["force".to_string()];
        let demo = |bump: f64| {
            let x = (0..n)
                .map(|i| {
                    if lc.iter().any(|r| r.contains(&i)) {
                        bump
                    } else {
                        1.0
                    }
                })
                .collect();
            Demonstration::new(names.clone(), x, 0.01).unwrap()
        };
        let demos = [demo(1.0), demo(5.0), demo(9.0)];
        let identity: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let model = TaskModel::fit_aligned(
            &demos,
            &[identity.clone(), identity.clone(), identity],
            &FitParams::default(),
        )
        .unwrap();
        let mut params = PlannerParams::default();
        params.sampler.samples = 50;
        params.sampler.seed = 7;
        Planner::from_model_with_robots(model, params, robots).unwrap()
    }

    /// Holds in a cell of different tasks (issue 45): each task keeps its own declared hold
    /// points, they round-trip through the format 12 file (a one-task cell with holds stays
    /// format 11), the continuous cell cuts each task's low-confidence groups at its usable
    /// holds (task `a`: two runs 10..20 and 40..50 split by its hold at sample 30, so two
    /// groups; task `b` without holds, one group), and the rounds placement still passes
    /// the margin check.
    #[test]
    fn each_task_keeps_its_holds_in_a_mixed_cell_and_its_file() {
        let mut a = planner_runs(60, &[10..20, 40..50], 1);
        a.set_holds(tandem_lfd::HoldSpec {
            at_s: vec![0.30],
            rules: Vec::new(),
        })
        .unwrap();
        assert_eq!(a.problem().usable_holds(), [30]);
        let b = planner(50, 20..30, 1);
        let cell =
            CellPlanner::from_planners(vec![("a".into(), a.clone()), ("b".into(), b)], vec![0, 1])
                .unwrap();
        let coordinator = cell.coordinator().unwrap();
        assert_eq!(coordinator.n_robots(), 2);
        let plan = cell.continuous_plan().unwrap();
        let c = cell.continuous_coordinator(&plan).unwrap();
        assert_eq!(c.groups_of(0).len(), 2, "task a split at its hold");
        assert_eq!(c.groups_of(1).len(), 1, "task b: one group");
        // Format 12 keeps each task's declared holds.
        let dir = scratch("holds");
        let path = dir.join("cell.tandem");
        cell.save(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()), 12);
        let back = CellPlanner::load(&path).unwrap();
        assert_eq!(back.tasks()[0].planner().params().holds.at_s, [0.30]);
        assert!(back.tasks()[1].planner().params().holds.at_s.is_empty());
        assert_eq!(back.tasks()[0].planner().problem().usable_holds(), [30]);
        assert_eq!(back.schedule(), cell.schedule());
        // A one-task cell with holds is its planner's format 11 file, byte for byte.
        let one = CellPlanner::from_planner("a", a.clone()).unwrap();
        one.save(dir.join("one.tandem")).unwrap();
        a.save(dir.join("planner.tandem")).unwrap();
        let one_bytes = std::fs::read(dir.join("one.tandem")).unwrap();
        assert_eq!(
            one_bytes,
            std::fs::read(dir.join("planner.tandem")).unwrap()
        );
        assert_eq!(u32::from_le_bytes(one_bytes[8..12].try_into().unwrap()), 11);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// What a mixed cell still refuses, by name and fix: a load cap, and operators of
    /// different switch times.
    #[test]
    fn a_mixed_cell_refuses_a_load_cap_naming_the_task_and_the_fix() {
        let mut b = planner(60, 30..45, 1);
        b.set_operator(0.0, 0.8).unwrap();
        let err = CellPlanner::from_planners(
            vec![("a".into(), planner(40, 10..20, 1)), ("b".into(), b)],
            vec![0, 1],
        )
        .unwrap_err()
        .to_string();
        assert!(
            err.contains("max_busy_share of task `b`") && err.contains("leave it at 1"),
            "{err}"
        );
    }
}
