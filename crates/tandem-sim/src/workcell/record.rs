//! What a round records: one [`RobotRun`] per robot and the round's tick counts
//! ([`RoundRun`]), and the execution records the planner takes from them (Eq. 21).

use serde::{Deserialize, Serialize};
use tandem_lfd::{Demonstration, Execution, TaskModel};
use tandem_planner::ExecutionRecord;

use crate::Result;

/// One robot's execution as the system records it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotRun {
    /// Commanded samples, sample-major (`m` channels in the model's channel order), one per
    /// control tick in which the robot ran.
    pub samples: Vec<f64>,
    /// Reference time (reference samples, fractional, in `[0, T_ref − 1]`) of each sample.
    pub ref_time_log: Vec<f64>,
    /// Whether the robot was low-confidence (supervised) at each sample.
    pub supervised: Vec<bool>,
    /// Whether the operator corrected each sample (only ever true where supervised).
    pub corrected: Vec<bool>,
    /// Supervised samples that needed a correction.
    pub needed: usize,
    /// Needed corrections the operator missed.
    pub missed: usize,
    /// Corrections given where none was needed.
    pub false_corrections: usize,
    /// The robot's schedule clock `s_i` (global schedule time, s) at the start of every
    /// control tick of the round, running or not (`RoundRun::ticks` entries): before the robot
    /// starts it follows the pace of the running robots (its start shifts), after it finishes
    /// it stays at its end.
    pub clock_s: Vec<f64>,
    /// The round's control tick (0-based) of the robot's first sample: ticks
    /// `0..start_tick` it waited for its start, ticks `start_tick..start_tick + n` it ran
    /// (`n` samples, minus its ticks at holds), later ticks it had finished. `RoundRun::ticks`
    /// when it never ran.
    pub start_tick: usize,
    /// Control ticks the robot stood at a hold point of the schedule (`Schedule::holds`),
    /// waiting for its release rules or for the robots behind it (0 without holds, and then
    /// not serialized).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub hold_ticks: usize,
    /// What the robot did in every control tick of the round (`RoundRun::ticks` entries, read
    /// at the tick start, beside [`RobotRun::clock_s`]): waiting for its start, running (one
    /// sample of [`RobotRun::ref_time_log`] per such tick), standing at a hold, held by the
    /// fault monitor, or finished. Where the round's time went, tick by tick; the waits at
    /// holds are the [`TickPhase::AtHold`] ticks ([`RobotRun::hold_ticks`] counts them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub phases: Vec<TickPhase>,
}

/// What one robot did in one control tick of a round ([`RobotRun::phases`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum TickPhase {
    /// Not started: it waits for its start (the start offset, shifted by the robots before
    /// it, and its start rules).
    Waiting,
    /// Running: it executed one sample.
    Running,
    /// Standing at a hold point: for its planned dwell, its release rules or the robots
    /// behind it.
    AtHold,
    /// Held by the coordinator's fault monitor (two robots were low-confidence at once).
    Held,
    /// Finished its task.
    Finished,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl RobotRun {
    /// Time (real s) the robot stood at hold points, for control tick `tick_s` (s).
    pub fn hold_wait_s(&self, tick_s: f64) -> f64 {
        self.hold_ticks as f64 * tick_s
    }

    /// Control ticks of the round the robot spent in `phase` ([`RobotRun::phases`]).
    #[must_use]
    pub fn ticks_in(&self, phase: TickPhase) -> usize {
        self.phases.iter().filter(|&&p| p == phase).count()
    }

    /// The round's control tick at whose start the robot had finished (the number of ticks
    /// it took, waits included), or the round's length if it never finished in it.
    #[must_use]
    pub fn end_tick(&self) -> usize {
        self.phases
            .iter()
            .position(|&p| p == TickPhase::Finished)
            .unwrap_or(self.phases.len())
    }

    /// The execution record for
    /// [`Planner::record_round`](tandem_planner::Planner::record_round) (Eq. 21): the
    /// samples as a demonstration with `model`'s channel names and sample period, the
    /// reference-time log, and the supervised and corrected flags.
    ///
    /// # Errors
    /// The model crate's error if the samples do not form a valid demonstration.
    pub fn record(&self, model: &TaskModel) -> Result<ExecutionRecord> {
        let demonstration = Demonstration::new(
            model.channel_names().to_vec(),
            self.samples.clone(),
            model.dt_s(),
        )?;
        Ok(ExecutionRecord {
            execution: Execution {
                demonstration,
                ref_time_log: self.ref_time_log.clone(),
            },
            supervised: self.supervised.clone(),
            corrected: self.corrected.clone(),
        })
    }
}

/// A round of executions, one per robot, run under one schedule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoundRun {
    /// Robot 1, robot 2, …: one run per robot of the schedule.
    pub robots: Vec<RobotRun>,
    /// Control ticks until every robot finished.
    pub ticks: usize,
    /// Control period (s).
    pub tick_s: f64,
    /// Ticks in which two or more robots traversed a low-confidence sample (must be 0).
    pub overlap_ticks: usize,
    /// Ticks in which no robot traversed a low-confidence sample.
    pub idle_ticks: usize,
    /// Faults latched by the coordinator's run-time monitor (two robots low-confidence in one
    /// tick; `tandem_realtime::Fault`), each released by the simulated operator once no robot
    /// was low-confidence (must be 0: a checked schedule never has one).
    #[serde(default)]
    pub faults: usize,
    /// The schedule's planned `T_total` (s, Eq. 13, planned dwells included), measured from
    /// the earliest start as the round's ticks are: [`RoundRun::duration_s`] is what the
    /// cell did against it ([`RoundRun::over_plan_s`]). 0 in records written before it was
    /// kept.
    #[serde(default)]
    pub planned_t_total_s: f64,
    /// Each robot's planned end (s, from the earliest start, planned dwells included): its
    /// realized end is [`RobotRun::end_tick`] times the tick. Empty in older records.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub planned_ends_s: Vec<f64>,
}

/// The two-robot round of the paper: a [`RoundRun`] with two robots ([`run_pair`](super::run_pair)).
pub type PairRun = RoundRun;

impl RoundRun {
    /// Every robot's execution record, robot 1 first, for
    /// [`Planner::record_round`](tandem_planner::Planner::record_round) (see
    /// [`RobotRun::record`]); `model` is the planner's model the round ran with.
    ///
    /// # Errors
    /// The model crate's error if a robot's samples do not form a valid demonstration.
    pub fn records(&self, model: &TaskModel) -> Result<Vec<ExecutionRecord>> {
        self.robots.iter().map(|r| r.record(model)).collect()
    }

    /// Whether two or more robots were ever low-confidence in the same tick.
    #[must_use]
    pub fn overlapped(&self) -> bool {
        self.overlap_ticks > 0
    }

    /// Operator idle time as a share of the round's duration (ticks), in `[0, 1]`.
    #[must_use]
    pub fn operator_idle_share(&self) -> f64 {
        if self.ticks == 0 {
            return 1.0;
        }
        self.idle_ticks as f64 / self.ticks as f64
    }

    /// Operator busy share, in `[0, 1]`: the share of the round's ticks in which at least
    /// one robot traversed a low-confidence sample (`1 − idle share`, counted in ticks).
    #[must_use]
    pub fn operator_busy_share(&self) -> f64 {
        if self.ticks == 0 {
            return 0.0;
        }
        (self.ticks - self.idle_ticks) as f64 / self.ticks as f64
    }

    /// Share of the robots' time in the round spent not moving along their tasks, in
    /// `[0, 1]`: waiting for a start offset, standing at a hold point, or done before the
    /// round's last robot (robot-ticks without a sample over `N ×` the round's ticks). The
    /// rounds counterpart of the continuous cell's gate waiting
    /// ([`CellStats`](super::CellStats)).
    #[must_use]
    pub fn robot_wait_share(&self) -> f64 {
        let n = self.robots.len();
        if self.ticks == 0 || n == 0 {
            return 0.0;
        }
        let moving: usize = self.robots.iter().map(|r| r.ref_time_log.len()).sum();
        1.0 - moving as f64 / (n * self.ticks) as f64
    }

    /// Actual duration of the round (s): ticks times the control period.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        self.ticks as f64 * self.tick_s
    }

    /// How much longer the round took than planned (s): [`RoundRun::duration_s`] minus
    /// [`RoundRun::planned_t_total_s`] (negative when it ended early, e.g. when the robots
    /// ran high-confidence stretches faster than planned, Alg. 1).
    #[must_use]
    pub fn over_plan_s(&self) -> f64 {
        self.duration_s() - self.planned_t_total_s
    }
}
