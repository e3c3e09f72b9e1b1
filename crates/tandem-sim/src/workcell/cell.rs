//! The continuous cell in the simulated workcell (issue 21): `N` robots repeat the task
//! without rounds under a [`ContinuousCoordinator`] (the token rule), while the simulated
//! operator of the rounds supervises the one robot inside a low-confidence group, and a new
//! plan can take over while the cell runs ([`CellSim::replan`]).
//!
//! Per control tick, as for rounds (module docs of [`crate::workcell`]): every robot that the
//! coordinator will move (not waiting at its gate, not held by a fault) gets the operator's
//! decision and logs one execution sample at its reference time; the operator's input drives
//! the low-confidence robot; a robot that completes its task in the tick hands back its
//! execution ([`FinishedTask`]) and starts the next at the task start. A robot waiting at its
//! gate logs nothing (its clock does not move), as a robot at a hold of a round.

use rand::Rng;
use serde::{Deserialize, Serialize};
use tandem_lfd::TaskModel;
use tandem_realtime::Tick;
use tandem_realtime::continuous::ContinuousCoordinator;

use super::operator::OperatorParams;
use super::record::RobotRun;
use super::run::{Operate, Robots, Tasks, check_n_ref, check_tick, step};
use crate::{Error, Result};

/// What a continuous cell did so far (control ticks of `tick_s`).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CellStats {
    /// Control ticks run.
    pub ticks: u64,
    /// Ticks in which more robots traversed a low-confidence sample than the cell has
    /// operators (`M`; one operator: two or more robots) (must be 0).
    pub overlap_ticks: u64,
    /// Ticks in which a robot traversed a low-confidence sample: an operator was busy.
    pub busy_ticks: u64,
    /// Faults latched by the coordinator's monitor (must be 0), each cleared once no robot
    /// was low-confidence.
    pub faults: u64,
    /// New plans that took over the running cell ([`CellSim::replan`]).
    pub hand_overs: u64,
    /// Per robot, ticks it waited at a gate for the operator's token.
    pub gate_ticks: Vec<u64>,
}

/// A task a robot completed in a tick of [`CellSim::tick`].
#[derive(Clone, Debug, PartialEq)]
pub struct FinishedTask {
    /// The robot (0-based).
    pub robot: usize,
    /// Ticks run when it finished (the tick it finished in is the `tick`-th, 1-based).
    pub tick: u64,
    /// Its execution ([`RobotRun::record`] makes the planner's record of it); `start_tick`
    /// is the cell's tick of its first sample.
    pub run: RobotRun,
}

/// A simulated continuous cell: the coordinator, the operator, each robot's task in progress.
#[derive(Debug)]
pub struct CellSim {
    coord: ContinuousCoordinator,
    pending: Option<ContinuousCoordinator>,
    /// A sectored cell taking a sectored `pending` of the same sectors: per sector, whether
    /// it has taken that plan already (one hand-over per sector,
    /// [`ContinuousCoordinator::take_over_sector`]).
    taken: Vec<bool>,
    op: Operate,
    robots: Robots,
    /// Each robot's completed tasks at the end of the last tick.
    tasks: Vec<u64>,
    n_ref: usize,
    stats: CellStats,
    /// Whether the operator's input in the last tick was a correction.
    corrected: bool,
}

impl CellSim {
    /// A cell running `coord` with the operator `params` on `model`'s task; every robot where
    /// the coordinator has it (at the task start for a new one).
    ///
    /// # Errors
    /// Invalid parameters; a model without the force channel; a coordinator for another
    /// number of reference samples ([`Error::Mismatch`]) or another control tick than the
    /// model's `Δt_s` ([`Error::TickMismatch`]).
    pub fn new(
        model: &TaskModel,
        coord: ContinuousCoordinator,
        params: &OperatorParams,
    ) -> Result<CellSim> {
        params.validate()?;
        check(model, &coord)?;
        let op = Operate::new(model, params, coord.tick_s())?;
        let n = coord.n_robots();
        let n_ref = model.n_ref();
        let ref_now = ref_times(&coord);
        Ok(CellSim {
            robots: Robots {
                runs: (0..n).map(|_| op.empty_run(n_ref)).collect(),
                in_episode: vec![false; n],
                ref_now,
            },
            op,
            tasks: coord.tasks_completed().to_vec(),
            n_ref,
            stats: CellStats {
                gate_ticks: vec![0; n],
                ..CellStats::default()
            },
            coord,
            pending: None,
            taken: Vec::new(),
            corrected: false,
        })
    }

    /// Whether the operator's input in the last [`tick`](Self::tick) was a correction (the
    /// console's per-robot count of corrections).
    #[must_use]
    pub fn corrected(&self) -> bool {
        self.corrected
    }

    /// The coordinator running the cell.
    pub fn coordinator(&self) -> &ContinuousCoordinator {
        &self.coord
    }

    /// Releases the robot held by a latched fault now
    /// ([`ContinuousCoordinator::clear_fault`]); [`tick`](Self::tick) also releases it after
    /// the first tick in which no robot is low-confidence.
    pub fn clear_fault(&mut self) {
        self.coord.clear_fault();
    }

    /// What the cell did so far.
    pub fn stats(&self) -> &CellStats {
        &self.stats
    }

    /// Whether a new plan waits to take over ([`replan`](Self::replan)).
    pub fn has_pending(&self) -> bool {
        self.pending.is_some()
    }

    /// Gives the cell a new plan: it takes over
    /// ([`ContinuousCoordinator::take_over`]) now if the robots are at a hand-over point of
    /// it, else at the end of the first tick at which they are (for a plan refined by
    /// recorded executions, at the latest when the operator's token next moves). A plan
    /// still waiting is replaced. Returns whether it took over now.
    ///
    /// # Errors
    /// As [`CellSim::new`] for a coordinator that does not match the model.
    pub fn replan(&mut self, model: &TaskModel, next: ContinuousCoordinator) -> Result<bool> {
        check(model, &next)?;
        if next.n_robots() != self.coord.n_robots() {
            return Err(Error::Mismatch {
                what: "robots of the new plan",
                expected: self.coord.n_robots(),
                found: next.n_robots(),
            });
        }
        self.pending = Some(next);
        self.taken.clear();
        Ok(self.try_hand_over())
    }

    /// Hands the cell over to the pending plan where the robots allow: a sectored cell to a
    /// plan of the same sectors sector by sector, each sector when its own robots are at a
    /// hand-over point ([`ContinuousCoordinator::take_over_sector`]; the plan counts as taken
    /// over, [`CellStats::hand_overs`], once every sector has it); any other cell all robots
    /// at once ([`ContinuousCoordinator::take_over`]).
    fn try_hand_over(&mut self) -> bool {
        let Some(next) = self.pending.as_mut() else {
            return false;
        };
        let same_sectors = self.coord.operators() == next.operators()
            && self
                .coord
                .sector_of()
                .is_some_and(|s| next.sector_of().is_some_and(|t| s == t));
        if same_sectors {
            let of = self.coord.sector_of().expect("checked above");
            let m = self.coord.operators();
            if self.taken.len() != m {
                // Operators without robots have nothing to take over.
                self.taken = (0..m)
                    .map(|o| !of.iter().any(|&s| usize::from(s) == o))
                    .collect();
            }
            for o in 0..m {
                if !self.taken[o] {
                    self.taken[o] = self.coord.take_over_sector(next, o).is_ok();
                }
            }
            if self.taken.iter().any(|t| !t) {
                return false;
            }
            self.pending = None;
            self.taken.clear();
            self.stats.hand_overs += 1;
            return true;
        }
        hand_over(&mut self.coord, &mut self.pending, &mut self.stats)
    }

    /// One control tick (module docs): `needs(robot, ref_idx)` says whether robot `robot`
    /// needs the operator at reference sample `ref_idx`, asked once per supervised sample just
    /// before the operator's draw from `rng`. `model` is the one that commands the robots
    /// now (the planner's latest). Returns the tasks completed in this tick.
    ///
    /// # Errors
    /// A model of another size than the cell's, or a degenerate command.
    pub fn tick(
        &mut self,
        model: &TaskModel,
        mut needs: impl FnMut(usize, usize) -> bool,
        rng: &mut impl Rng,
    ) -> Result<Vec<FinishedTask>> {
        if model.n_ref() != self.n_ref {
            return Err(Error::Mismatch {
                what: "model reference samples",
                expected: self.n_ref,
                found: model.n_ref(),
            });
        }
        count_gates(&mut self.stats, &self.coord);
        // The cell observes no crossings (`None`): its token rule stops a robot at the gate
        // of every low-confidence group it does not hold (docs/decisions.md).
        let (t, corrected) = step(
            &mut self.coord,
            Tasks {
                models: &[model],
                ops: std::slice::from_mut(&mut self.op),
                robot_task: &[],
            },
            |c, i, n| {
                let task = c.task_of(i);
                (task.grad_min()[n], task.grad_max()[n])
            },
            None,
            &mut self.robots,
            self.stats.ticks as usize,
            &mut needs,
            rng,
        )?;
        self.corrected = corrected;
        count_tick(&mut self.stats, &mut self.coord, &t);
        let (op, n_ref) = (&self.op, self.n_ref);
        let done = completed(
            &mut self.tasks,
            &t,
            self.stats.ticks,
            &mut self.robots.runs,
            |_| op.empty_run(n_ref),
        );
        self.try_hand_over();
        Ok(done)
    }
}

/// Counts the robots waiting at their gate before a tick of a continuous cell into `stats`
/// (the one-task [`CellSim`] and [`MixedCellSim`](super::MixedCellSim)).
pub(super) fn count_gates(stats: &mut CellStats, coord: &ContinuousCoordinator) {
    let at_gate = coord.at_gate_now();
    for (i, k) in stats.gate_ticks.iter_mut().enumerate() {
        *k += u64::from(at_gate[i]);
    }
}

/// Counts the coordinator's tick `t` of a continuous cell into `stats`: one tick, busy when a
/// robot was low-confidence, overlapping when more were than the cell has operators
/// ([`Tick::over`]; one operator: two or more, issue 44), a fault latched in it; a fault
/// latched before is released once no robot is low-confidence.
pub(super) fn count_tick(stats: &mut CellStats, coord: &mut ContinuousCoordinator, t: &Tick) {
    stats.ticks += 1;
    if t.low_conf.count() > 0 {
        stats.busy_ticks += 1;
    }
    if t.over(coord.operators()) {
        stats.overlap_ticks += 1;
    }
    match t.fault {
        Some(f) if f.tick + 1 == coord.ticks() => stats.faults += 1,
        Some(_) if t.low_conf.count() == 0 => coord.clear_fault(),
        _ => {}
    }
}

/// The tasks completed in tick `t` (the `tick`-th): each robot whose count in `t.tasks` rose
/// above `counts` hands back its run, replaced by `fresh(robot)`.
pub(super) fn completed(
    counts: &mut [u64],
    t: &Tick,
    tick: u64,
    runs: &mut [RobotRun],
    fresh: impl Fn(usize) -> RobotRun,
) -> Vec<FinishedTask> {
    let mut done = Vec::new();
    for (i, k) in counts.iter_mut().enumerate() {
        if t.tasks[i] > *k {
            *k = t.tasks[i];
            let run = std::mem::replace(&mut runs[i], fresh(i));
            done.push(FinishedTask {
                robot: i,
                tick,
                run,
            });
        }
    }
    done
}

/// The plan `pending` takes over the running `coord` if the robots are at a hand-over point
/// of it ([`ContinuousCoordinator::take_over`]), counted in `stats`; returns whether it did.
pub(super) fn hand_over(
    coord: &mut ContinuousCoordinator,
    pending: &mut Option<ContinuousCoordinator>,
    stats: &mut CellStats,
) -> bool {
    let Some(next) = pending.as_mut() else {
        return false;
    };
    if next.take_over(coord).is_err() {
        return false;
    }
    *coord = pending.take().expect("checked above");
    stats.hand_overs += 1;
    true
}

/// Each robot's reference time at its clock.
fn ref_times(coord: &ContinuousCoordinator) -> Vec<f64> {
    coord
        .clock_s()
        .iter()
        .enumerate()
        .map(|(i, &c)| {
            let task = coord.task_of(i);
            task.ref_time_at(c).min(task.n_ref() as f64)
        })
        .collect()
}

fn check(model: &TaskModel, coord: &ContinuousCoordinator) -> Result<()> {
    check_n_ref(
        model.n_ref(),
        [("reference samples of the cell's task", coord.task().n_ref())],
    )?;
    check_tick(coord.tick_s(), model.dt_s())
}
