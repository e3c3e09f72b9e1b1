//! The node's control loop without the network: one [`CellLoop`] owned by the tick thread,
//! fed [`Inbound`] messages and producing a [`Snapshot`] per tick and [`Reply`]s to requests.
//!
//! Nothing here waits: the DDS side hands messages over through bounded queues that are
//! drained with `try_recv` at the start of each tick, and every decision that needs the
//! network's data (a robot's liveness, the operator's input) is taken on the last value that
//! arrived, with a timeout for each (docs/decisions.md, "tandem in a live ROS 2 graph").

use std::time::{Duration, Instant};

use tandem_console::{Geometry, tick_now};
use tandem_lfd::{Demonstration, Execution, TaskModel};
use tandem_planner::{AnyController, Cell, ExecutionRecord};
use tandem_realtime::{
    Controller, Fault, MAX_ROBOTS, Operator, PerRobot, PreAlert, RobotFlags, Tick,
};

use crate::error::{Error, Result};

/// The control loop's parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct LoopParams {
    /// A robot whose progress has not arrived for this long (real s) while a round or the
    /// cell runs is stalled: the loop latches [`NodeFault::Stalled`] and holds the whole cell
    /// (no robot's schedule clock moves) until the fault is cleared. Default: 0.25 s.
    pub stall_s: f64,
    /// The operator's last input counts for this long (real s); after it the input is
    /// [`Operator::Scheduled`] (a dead man's switch). Default: 0.25 s.
    pub operator_timeout_s: f64,
    /// Axis values with `|a|` below this are no correction of the timing. Default: 0.05.
    pub deadband: f64,
}

impl Default for LoopParams {
    fn default() -> Self {
        LoopParams {
            stall_s: 0.25,
            operator_timeout_s: 0.25,
            deadband: 0.05,
        }
    }
}

impl LoopParams {
    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, why: &str| {
            Err(Error::BadParam {
                name,
                why: why.to_owned(),
            })
        };
        if !(self.stall_s.is_finite() && self.stall_s > 0.0) {
            return bad("stall_s", "must be finite and > 0 (seconds)");
        }
        if !(self.operator_timeout_s.is_finite() && self.operator_timeout_s > 0.0) {
            return bad("operator_timeout_s", "must be finite and > 0 (seconds)");
        }
        if !(self.deadband.is_finite() && (0.0..1.0).contains(&self.deadband)) {
            return bad("deadband", "must be in [0, 1)");
        }
        Ok(())
    }
}

/// What the DDS side hands the tick thread.
#[derive(Debug)]
pub enum Inbound {
    /// Robot `robot` (0-based) reports the reference time it has reached (reference samples).
    Progress {
        /// The robot.
        robot: usize,
        /// Its reference time.
        ref_time: f64,
    },
    /// The operator's input device: the timing axis in `[−1, 1]` ([`operator_input`]) and
    /// whether the operator is correcting (a held button).
    Operator {
        /// The axis.
        axis: f64,
        /// Whether the operator corrects the supervised robot now.
        correcting: bool,
    },
    /// A service request, answered by a [`Reply`] with the same token.
    Request {
        /// The DDS side's key for the answer.
        token: u64,
        /// What is asked.
        what: Request,
    },
    /// A round was recorded: the planner's new controller and its plan as the console draws it
    /// (built off the tick thread), run from the next started round.
    Replace(Box<AnyController>, Box<Geometry>),
    /// Recording the round failed: its log back, to record again after the fix.
    Restore(RoundLog),
}

/// The node's services.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Request {
    /// Start a round (rounds) or run the cell (continuous).
    Start,
    /// Abort the round (every robot back to its start) or pause the cell.
    Stop,
    /// Clear the latched fault.
    ClearFault,
    /// Hand the finished round's log over for recording ([`Reply::Round`]).
    TakeRound,
}

/// Why the loop refused a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Refusal {
    /// Start while running.
    #[error("a round is running; stop it first (service stop_round)")]
    Running,
    /// Stop while not running.
    #[error("nothing runs; start a round first (service start_round)")]
    NotRunning,
    /// Clear without a fault.
    #[error("no fault is latched")]
    NoFault,
    /// Record without a finished round.
    #[error("no finished round to record: start one and let every robot finish it")]
    NoFinishedRound,
    /// Record in a continuous cell.
    #[error("a continuous cell records no rounds; run the node with --cell rounds to record")]
    Continuous,
    /// Start before the operator's rest after the last round has passed (the load cap
    /// `max_busy_share` < 1 of the state file; [`CellLoop::rest_left_ticks`]).
    #[error(
        "the operator rests after the last round (load cap max_busy_share): {} s left \
         ({left_ticks} ticks); call start_round again then",
        fmt_ms(*left_ms)
    )]
    Resting {
        /// The rest left (ms, rounded up).
        left_ms: u64,
        /// The rest left (control ticks).
        left_ticks: u64,
    },
}

/// `ms` milliseconds as seconds with three decimals.
fn fmt_ms(ms: u64) -> String {
    format!("{}.{:03}", ms / 1000, ms % 1000)
}

/// The tick thread's answer to a [`Inbound::Request`].
#[derive(Debug)]
pub enum Reply {
    /// Done (`Ok`) or refused.
    Done {
        /// The request's token.
        token: u64,
        /// The request.
        what: Request,
        /// Whether it was done.
        result: std::result::Result<(), Refusal>,
    },
    /// The finished round's log, for [`Request::TakeRound`].
    Round {
        /// The request's token.
        token: u64,
        /// The log.
        log: RoundLog,
    },
}

/// A fault the loop latched, until [`Request::ClearFault`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NodeFault {
    /// The coordinator's monitor: two robots were low-confidence in one tick.
    Overlap(Fault),
    /// No progress from `robot` for `silent_s` (real s) while the cell ran: the cell holds.
    Stalled {
        /// The silent robot (0-based).
        robot: usize,
        /// How long it had been silent when the fault latched (s).
        silent_s: f64,
    },
}

impl std::fmt::Display for NodeFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NodeFault::Overlap(x) => write!(
                f,
                "overlap at tick {}: {} robots low-confidence at once; robot {} held \
                 (clear with service clear_fault)",
                x.tick,
                x.low_conf.count(),
                x.stopped + 1
            ),
            NodeFault::Stalled { robot, silent_s } => write!(
                f,
                "robot {} stalled: no progress for {silent_s:.3} s; the cell holds (clear with \
                 service clear_fault once it reports again)",
                robot + 1
            ),
        }
    }
}

/// The cell after one tick of the loop: what the node publishes. `Copy`, no heap.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Snapshot {
    /// The loop's tick count since it started (every tick, running or not).
    pub tick: u64,
    /// Whether a round (or the cell) runs.
    pub active: bool,
    /// Whether the last round finished and waits to be recorded (rounds).
    pub finished: bool,
    /// Each robot's reference time to follow (reference samples, in its current task).
    pub ref_time: PerRobot<f64>,
    /// Each robot's speed scale over the last tick: reference samples advanced per
    /// reference sample period (1 = the reference demonstration's pace; 0 stopped).
    pub speed: PerRobot<f64>,
    /// Each robot that the next tick moves at the operator's rate (`needs_operator`).
    pub needs_operator: RobotFlags,
    /// Whether two robots traversed a low-confidence sample in this tick.
    pub overlap: bool,
    /// The latched fault.
    pub fault: Option<NodeFault>,
    /// The next handover ([`PreAlert`], real s from the end of this tick).
    pub next: Option<PreAlert>,
    /// The operator's rest left before the next round may start (s, whole ticks: the load
    /// cap's rest after a round, [`CellLoop::rest_left_ticks`]); 0 when none (always in a
    /// continuous cell and without a cap).
    pub rest_s: f64,
}

/// What the node publishes every tick (`/tandem/robotK/command`, and `needs_operator` on
/// change): the part of a [`Snapshot`] that costs the tick nothing to produce. `Copy`, no heap;
/// it crosses to the DDS thread as a fixed-size record ([`crate::link::CommandRing`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Command {
    /// The loop's tick count since it started ([`Snapshot::tick`]).
    pub tick: u64,
    /// Whether a round (or the cell) runs.
    pub active: bool,
    /// Whether the last round finished and waits to be recorded (rounds).
    pub finished: bool,
    /// Whether a fault is latched (its text is the [`Snapshot`]'s).
    pub fault: bool,
    /// Each robot's reference time to follow (reference samples).
    pub ref_time: PerRobot<f64>,
    /// Each robot's speed scale over the last tick ([`Snapshot::speed`]).
    pub speed: PerRobot<f64>,
    /// Each robot that the next tick moves at the operator's rate.
    pub needs_operator: RobotFlags,
}

impl Command {
    /// The flags as one word: bit 0 active, 1 finished, 2 fault, 8 + k robot k needs the
    /// operator.
    #[must_use]
    pub fn flags_word(&self) -> u64 {
        flags_word(self.active, self.finished, self.fault, &self.needs_operator)
    }

    /// The command of a tick count, a [`flags_word`](Self::flags_word) and the robots' values
    /// (their count is the robots').
    #[must_use]
    pub fn from_words(
        tick: u64,
        flags: u64,
        ref_time: PerRobot<f64>,
        speed: PerRobot<f64>,
    ) -> Command {
        let mut cmd = Command {
            tick,
            active: false,
            finished: false,
            fault: false,
            ref_time,
            speed,
            needs_operator: RobotFlags::new(ref_time.len()),
        };
        cmd.set_flags_word(flags);
        cmd
    }

    /// A command of `n` robots (cut to [`MAX_ROBOTS`]) at tick 0: not active, every reference
    /// time and speed scale 0, no flag set; the buffer that
    /// [`CommandRing::pop_into`](crate::link::CommandRing::pop_into) overwrites.
    #[must_use]
    pub fn idle(n: usize) -> Command {
        Command {
            tick: 0,
            active: false,
            finished: false,
            fault: false,
            ref_time: PerRobot::new(n),
            speed: PerRobot::new(n),
            needs_operator: RobotFlags::new(n),
        }
    }

    /// Sets the flags from a [`flags_word`](Self::flags_word): `active`, `finished`, `fault`
    /// and `needs_operator` for the command's robots (its [`RobotFlags`]' length is kept).
    pub fn set_flags_word(&mut self, flags: u64) {
        self.active = flags & 1 == 1;
        self.finished = flags >> 1 & 1 == 1;
        self.fault = flags >> 2 & 1 == 1;
        for k in 0..self.needs_operator.len() {
            self.needs_operator.set(k, flags >> (8 + k) & 1 == 1);
        }
    }
}

/// [`Command::flags_word`] of the command's flags: bit 0 `active`, 1 `finished`, 2 `fault`,
/// 8 + k robot k needs the operator.
#[inline]
fn flags_word(active: bool, finished: bool, fault: bool, needs: &RobotFlags) -> u64 {
    let mut w = u64::from(active) | u64::from(finished) << 1 | u64::from(fault) << 2;
    for k in 0..needs.len() {
        w |= u64::from(needs.get(k)) << (8 + k);
    }
    w
}

/// One robot's log of a round: one entry per tick in which it ran.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RobotLog {
    /// Reference time at the tick's start (reference samples).
    pub ref_time: Vec<f64>,
    /// Whether it was supervised (low-confidence) in the tick.
    pub supervised: Vec<bool>,
    /// Whether the operator corrected it in the tick.
    pub corrected: Vec<bool>,
}

/// A round's log, one [`RobotLog`] per robot, at control tick `tick_s`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RoundLog {
    /// The control tick (s): the executions' sample period.
    pub tick_s: f64,
    /// Robot 1 first.
    pub robots: Vec<RobotLog>,
}

impl RoundLog {
    /// The execution records for
    /// [`Planner::record_round`](tandem_planner::Planner::record_round): each robot's
    /// commanded samples (the model's mean command, Eq. 7 with `u = 0`, at each logged
    /// reference time, one per control tick), the reference-time log, the flags.
    ///
    /// # Errors
    /// The model crate's error for a log it cannot command (a reference time outside the
    /// task) or samples that do not form a demonstration (an empty log).
    pub fn records(&self, model: &TaskModel) -> Result<Vec<ExecutionRecord>> {
        let m = model.channel_names().len();
        let last = model.n_ref().saturating_sub(1) as f64;
        let u0 = vec![0.0; model.n_components()];
        let mut cmd = vec![0.0; m + 1];
        self.robots
            .iter()
            .map(|r| {
                let mut samples = Vec::with_capacity(r.ref_time.len() * m);
                for &t in &r.ref_time {
                    model.command_into(&u0, t.clamp(0.0, last), &mut cmd)?;
                    samples.extend_from_slice(&cmd[..m]);
                }
                let demonstration =
                    Demonstration::new(model.channel_names().to_vec(), samples, self.tick_s)?;
                Ok(ExecutionRecord {
                    execution: Execution {
                        demonstration,
                        ref_time_log: r.ref_time.clone(),
                    },
                    supervised: r.supervised.clone(),
                    corrected: r.corrected.clone(),
                })
            })
            .collect()
    }
}

/// The operator's timing input from an axis `a ∈ [−1, 1]` (a joystick's, or a Twist's
/// `linear.x` clamped): `|a| < deadband` no correction ([`Operator::Scheduled`]); `a ≥ 1 −
/// deadband` [`Operator::Fastest`], `a ≤ −(1 − deadband)` [`Operator::Slowest`]; between, the
/// execution gradient `2^(−a)` (execution samples per reference sample: forward halves the
/// time per sample at full throw, back doubles it), which the coordinator clamps to the
/// demonstrations' `[ψ̇min, ψ̇max]` (§II-B5). A non-finite axis is no correction.
#[must_use]
pub fn operator_input(axis: f64, deadband: f64) -> Operator {
    if !axis.is_finite() || axis.abs() < deadband {
        Operator::Scheduled
    } else if axis >= 1.0 - deadband {
        Operator::Fastest
    } else if axis <= -(1.0 - deadband) {
        Operator::Slowest
    } else {
        Operator::Gradient((-axis).exp2())
    }
}

/// The tick thread's state: the coordinator, the round's log, the last network values.
#[derive(Debug)]
pub struct CellLoop {
    ctl: AnyController,
    pending: Option<(Box<AnyController>, Box<Geometry>)>,
    /// Controllers swapped in so far ([`CellLoop::plan_generation`]).
    generation: u64,
    /// The plan of the controller swapped in last (`None` while it is the first one).
    plan: Option<Box<Geometry>>,
    params: LoopParams,
    dt_s: f64,
    last_ref: f64,
    active: bool,
    /// `params.stall_s` as a duration (compared without floating point each tick).
    stall_after: Duration,
    /// `params.operator_timeout_s` as a duration.
    operator_timeout: Duration,
    finished: bool,
    /// Each robot's last progress, or the round's start when it has not reported since.
    last_progress: [Instant; MAX_ROBOTS],
    /// No robot can be stalled before this instant: the earliest `last_progress[k] +
    /// stall_after` when it was last computed, a lower bound of it since (a robot's progress
    /// only moves later). `None`: compute it at the next tick (after a start, a cleared fault,
    /// a progress dated earlier than the last, or a bound too far to represent). So the tick's
    /// liveness check is one comparison, the loop over robots once per `stall_s`.
    stall_due: Option<Instant>,
    /// The operator's last input as the coordinator takes it ([`operator_input`] of its axis,
    /// computed when it arrives) and whether the operator corrects.
    operator: Operator,
    correcting: bool,
    /// Whether an operator input arrived at all, and until when it counts (its arrival plus
    /// `operator_timeout`; `None`: for ever, a timeout too long to represent).
    operator_heard: bool,
    operator_until: Option<Instant>,
    /// Reference samples per control tick (`tick_s / dt_s`), of the controller it runs.
    per_tick: f64,
    stall: Option<NodeFault>,
    log: RoundLog,
    capacity: usize,
    ticks: u64,
    /// The controller's last [`Tick`], or its state as one while it has not ticked since a
    /// start, stop or fault clearance ([`CellLoop::last_tick`]).
    last: Tick,
    /// The controller's `low_conf_now()`, kept from the end of the last tick or request.
    low_now: RobotFlags,
    /// The last tick's speed scales and whether two robots were low-confidence in it.
    speed: PerRobot<f64>,
    overlap: bool,
    /// The loop's tick count from which a round may start again: the tick that ended (or
    /// stopped) the last round plus the rest the load cap asks after it
    /// ([`tandem_realtime::Coordinator::rest_ticks`]); 0 before any round.
    rest_until: u64,
}

impl CellLoop {
    /// A loop on `ctl` (every robot at its start, not running) of a planner whose model is
    /// `model` (its sample period and reference length).
    ///
    /// # Errors
    /// [`Error::BadParam`] for bad `params`.
    pub fn new(ctl: AnyController, model: &TaskModel, params: LoopParams) -> Result<CellLoop> {
        params.validate()?;
        let dt_s = model.dt_s();
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(Error::BadParam {
                name: "dt_s",
                why: "must be finite and > 0 (the model's sample period, s)".into(),
            });
        }
        let n = ctl.n_robots();
        let capacity = round_capacity(&ctl);
        let log = RoundLog {
            tick_s: ctl.tick_s(),
            robots: (0..n)
                .map(|_| RobotLog {
                    ref_time: Vec::with_capacity(capacity),
                    supervised: Vec::with_capacity(capacity),
                    corrected: Vec::with_capacity(capacity),
                })
                .collect(),
        };
        // Validated finite and > 0; a duration too long to represent is "never".
        let stall_after = Duration::try_from_secs_f64(params.stall_s).unwrap_or(Duration::MAX);
        let operator_timeout =
            Duration::try_from_secs_f64(params.operator_timeout_s).unwrap_or(Duration::MAX);
        Ok(CellLoop {
            pending: None,
            generation: 0,
            plan: None,
            params,
            dt_s,
            last_ref: model.n_ref().saturating_sub(1) as f64,
            active: false,
            stall_after,
            operator_timeout,
            finished: false,
            last_progress: [Instant::now(); MAX_ROBOTS],
            stall_due: None,
            operator: Operator::Scheduled,
            correcting: false,
            operator_heard: false,
            operator_until: None,
            per_tick: ctl.tick_s() / dt_s,
            stall: None,
            log,
            capacity,
            ticks: 0,
            low_now: ctl.low_conf_now(),
            speed: PerRobot::new(n),
            overlap: false,
            rest_until: 0,
            last: tick_now(&ctl),
            ctl,
        })
    }

    /// The controller it runs.
    #[must_use]
    pub fn controller(&self) -> &AnyController {
        &self.ctl
    }

    /// The controller's last tick: the one [`step`](Self::step) ran, or, while the controller
    /// has not ticked since the loop began or a request changed it (start, stop, clear fault),
    /// its state now as a tick. What a console's [`publish`](tandem_console::ConsoleHandle::publish)
    /// takes beside [`controller`](Self::controller).
    #[must_use]
    pub fn last_tick(&self) -> &Tick {
        &self.last
    }

    /// Takes one message from the DDS side in at `now`; a request's answer goes to `reply`.
    pub fn handle(&mut self, msg: Inbound, now: Instant, reply: &mut impl FnMut(Reply)) {
        match msg {
            Inbound::Progress { robot, ref_time } => {
                if ref_time.is_finite() {
                    self.heard(robot, now);
                }
            }
            Inbound::Operator { axis, correcting } => {
                self.operator = operator_input(axis, self.params.deadband);
                self.correcting = correcting;
                self.operator_heard = true;
                self.operator_until = now.checked_add(self.operator_timeout);
            }
            Inbound::Replace(ctl, plan) => self.pending = Some((ctl, plan)),
            Inbound::Restore(log) => {
                self.log = log;
                self.finished = true;
            }
            Inbound::Request { token, what } => {
                if what == Request::TakeRound {
                    match self.take_round() {
                        Ok(log) => reply(Reply::Round { token, log }),
                        Err(e) => reply(Reply::Done {
                            token,
                            what,
                            result: Err(e),
                        }),
                    }
                } else {
                    let result = self.request(what, now);
                    self.last = tick_now(&self.ctl);
                    self.low_now = self.last.low_conf;
                    reply(Reply::Done {
                        token,
                        what,
                        result,
                    });
                }
            }
        }
    }

    /// Robot `robot` (0-based; others ignored) reported progress at `now`: it is alive.
    pub fn heard(&mut self, robot: usize, now: Instant) {
        if robot < self.ctl.n_robots() {
            if now < self.last_progress[robot] {
                // Earlier than before: the stall bound may be earlier too.
                self.stall_due = None;
            }
            self.last_progress[robot] = now;
        }
    }

    /// Whether the last round finished and waits to be recorded (rounds).
    #[must_use]
    pub fn is_finished(&self) -> bool {
        self.finished
    }

    /// Whether a round (or the cell) runs: between a `start_round` and the round's end, a
    /// `stop_round` or the node's stop.
    #[must_use]
    pub fn is_active(&self) -> bool {
        self.active
    }

    /// How many times the controller was replaced (a recorded round's new schedule, swapped
    /// in at the next `start_round`); 0 while the loop runs the controller it began with.
    #[must_use]
    pub fn plan_generation(&self) -> u64 {
        self.generation
    }

    /// The plan of the controller it runs when that replaced the first one
    /// ([`Inbound::Replace`]); `None` while it runs the controller it began with.
    #[must_use]
    pub fn plan(&self) -> Option<&Geometry> {
        self.plan.as_deref()
    }

    /// The operator's rest left, in control ticks of the loop, before a round may start
    /// (issue 41; docs/decisions.md, "The operator's rest in the node, Python and the console
    /// (issue 41)"): when a round ends (or is stopped) the loop takes the rounds coordinator's
    /// [`rest_ticks`](tandem_realtime::Coordinator::rest_ticks) — the least rest that keeps
    /// the operator's busy share of the round and its rest at most the state file's
    /// `max_busy_share` — and a `start_round` before that many ticks have passed since the
    /// round's last tick is refused ([`Refusal::Resting`]). So at least `rest` ticks without a
    /// round lie between the round's last tick and the next round's first. 0 without a cap, in
    /// a continuous cell, and once the rest has passed.
    #[must_use]
    pub fn rest_left_ticks(&self) -> u64 {
        self.rest_until.saturating_sub(self.ticks)
    }

    /// [`rest_left_ticks`](Self::rest_left_ticks) in seconds (ticks times the control tick).
    #[must_use]
    pub fn rest_left_s(&self) -> f64 {
        self.rest_left_ticks() as f64 * self.ctl.tick_s()
    }

    /// The round ended or was stopped at the loop's tick `self.ticks`: the rest its operators
    /// get before the next round (read before the controller is reset).
    #[cold]
    fn rest_after_round(&mut self) {
        let rest = self.ctl.as_rounds().map_or(0, |c| c.rest_ticks());
        self.rest_until = self.ticks.saturating_add(rest);
    }

    fn take_round(&mut self) -> std::result::Result<RoundLog, Refusal> {
        if self.ctl.cell() == Cell::Continuous {
            return Err(Refusal::Continuous);
        }
        if !self.finished {
            return Err(Refusal::NoFinishedRound);
        }
        self.finished = false;
        let empty = RoundLog {
            tick_s: self.log.tick_s,
            robots: vec![RobotLog::default(); self.log.robots.len()],
        };
        Ok(std::mem::replace(&mut self.log, empty))
    }

    fn request(&mut self, what: Request, now: Instant) -> std::result::Result<(), Refusal> {
        match what {
            Request::Start => {
                if self.active {
                    return Err(Refusal::Running);
                }
                let left_ticks = self.rest_left_ticks();
                if left_ticks > 0 {
                    let left_s = left_ticks as f64 * self.ctl.tick_s();
                    return Err(Refusal::Resting {
                        left_ms: (left_s * 1000.0).ceil() as u64,
                        left_ticks,
                    });
                }
                if let Some((ctl, plan)) = self.pending.take() {
                    self.capacity = round_capacity(&ctl);
                    self.log.tick_s = ctl.tick_s();
                    self.per_tick = ctl.tick_s() / self.dt_s;
                    self.ctl = *ctl;
                    self.plan = Some(plan);
                    self.generation += 1;
                }
                // Rounds: a new round from the start; the continuous cell resumes.
                if self.ctl.cell() == Cell::Rounds {
                    self.ctl.reset();
                    for r in &mut self.log.robots {
                        r.ref_time.clear();
                        r.supervised.clear();
                        r.corrected.clear();
                        r.ref_time.reserve(self.capacity);
                        r.supervised.reserve(self.capacity);
                        r.corrected.reserve(self.capacity);
                    }
                }
                self.finished = false;
                self.stall = None;
                self.last_progress = [now; MAX_ROBOTS];
                self.stall_due = None;
                self.active = true;
                Ok(())
            }
            Request::Stop => {
                if !self.active {
                    return Err(Refusal::NotRunning);
                }
                self.active = false;
                if self.ctl.cell() == Cell::Rounds {
                    // The operator worked the stopped round's part: its rest too.
                    self.rest_after_round();
                    self.ctl.reset();
                    for r in &mut self.log.robots {
                        r.ref_time.clear();
                        r.supervised.clear();
                        r.corrected.clear();
                    }
                }
                Ok(())
            }
            Request::ClearFault => {
                if self.stall.is_none() && self.ctl.fault().is_none() {
                    return Err(Refusal::NoFault);
                }
                if let Some(NodeFault::Stalled { robot, .. }) = self.stall.take() {
                    // A fresh grace period: stalled again if it stays silent.
                    self.last_progress[robot] = now;
                    self.stall_due = None;
                }
                self.ctl.clear_fault();
                Ok(())
            }
            Request::TakeRound => Err(Refusal::NoFinishedRound),
        }
    }

    /// The latched fault: a stall first, else the coordinator's.
    #[must_use]
    pub fn fault(&self) -> Option<NodeFault> {
        self.stall.or(self.ctl.fault().map(NodeFault::Overlap))
    }

    /// One control tick at `now` ([`advance`](Self::advance)) and the cell after it
    /// ([`snapshot`](Self::snapshot)).
    ///
    /// # Errors
    /// None in practice: the operator's input is always a valid [`Operator`].
    pub fn step(&mut self, now: Instant) -> Result<Snapshot> {
        self.advance(now)?;
        Ok(self.snapshot())
    }

    /// The cell after the last tick: the [`Command`]'s values and the state topics' (the
    /// fault's text, the next handover). Reads the controller's latched fault; the pre-alert is
    /// the last tick's ([`Tick::next`]).
    #[must_use]
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            tick: self.ticks,
            active: self.active,
            finished: self.finished,
            ref_time: self.last.ref_time,
            speed: self.speed,
            needs_operator: self.needs_operator(),
            overlap: self.overlap,
            fault: self.fault(),
            next: self.last.next,
            rest_s: self.rest_left_s(),
        }
    }

    fn needs_operator(&self) -> RobotFlags {
        if self.active {
            self.low_now
        } else {
            RobotFlags::new(self.ctl.n_robots())
        }
    }

    /// One control tick at `now`: checks every robot's liveness, then, if running and not
    /// stalled, logs each moving robot's sample and advances the coordinator with the
    /// operator's input; returns what goes out every tick. No allocation once the round's log
    /// has its capacity; no reader of the controller but `running_now` and `low_conf_now`
    /// (the reference times and the pre-alert are the [`Tick`]'s).
    ///
    /// # Errors
    /// None in practice: the operator's input is always a valid [`Operator`].
    pub fn advance(&mut self, now: Instant) -> Result<Command> {
        self.tick_at(now)?;
        Ok(Command {
            tick: self.ticks,
            active: self.active,
            finished: self.finished,
            fault: self.stall.is_some() || self.last.fault.is_some(),
            ref_time: self.last.ref_time,
            speed: self.speed,
            needs_operator: self.needs_operator(),
        })
    }

    /// The last tick's [`Command`] as the node's ring stores it, read from the loop's state
    /// without building the command: its tick count, its [`Command::flags_word`], each robot's
    /// reference time and speed scale. Valid right after [`tick_at`](Self::tick_at) (a request
    /// handled since changes the reference times to the controller's state).
    ///
    /// The flags word is [`flags_word`]'s of [`needs_operator`](Self::needs_operator), built
    /// from the set flags only (none or one robot low-confidence in most ticks: one test, or
    /// one bit more, instead of a test per robot).
    #[inline]
    pub(crate) fn command_words(&self) -> (u64, u64, &PerRobot<f64>, &PerRobot<f64>) {
        let fault = self.stall.is_some() || self.last.fault.is_some();
        let mut flags =
            u64::from(self.active) | u64::from(self.finished) << 1 | u64::from(fault) << 2;
        if self.active {
            let mut low = self.low_now;
            while let Some(k) = low.first() {
                if k >= low.len() {
                    break;
                }
                flags |= 1 << (8 + k);
                low.set(k, false);
            }
        }
        (self.ticks, flags, &self.last.ref_time, &self.speed)
    }

    /// [`advance`](Self::advance) without its [`Command`]: the node's tick thread takes the
    /// command's words from the loop ([`command_words`](Self::command_words)) straight into the
    /// ring, so no command is built and copied on the tick thread. Inlined into both callers,
    /// so that `advance` (a user's own loop, the benchmark's `loop_only`) and the tick thread
    /// run the same code, neither with a call more.
    #[inline(always)]
    pub(crate) fn tick_at(&mut self, now: Instant) -> Result<()> {
        let n = self.ctl.n_robots();
        self.ticks += 1;
        if self.active && self.stall.is_none() && self.stall_due.is_none_or(|d| now > d) {
            self.check_stall(now);
        }
        // The controller's reference times now: its last tick's (the contract: `Tick::ref_time`
        // is `ref_time_now()` after the tick; `last` is refreshed whenever a request changes
        // the controller), read from there instead of the controller, twice a tick.
        let before = self.last.ref_time;
        let mut overlap = false;
        if self.active && self.stall.is_none() {
            // The input counts while `now ≤ arrival + timeout` (an input stamped after `now`
            // counts too, as the silence of a negative duration is 0).
            let fresh = self.operator_heard && self.operator_until.is_none_or(|u| now <= u);
            let (operator, correcting) = if fresh {
                (self.operator, self.correcting)
            } else {
                (Operator::Scheduled, false)
            };
            let corrected = correcting || operator != Operator::Scheduled;
            let running = self.ctl.running_now();
            let low = self.low_now;
            debug_assert_eq!(low, self.ctl.low_conf_now());
            let tick = self.ctl.tick(operator)?;
            self.last = tick;
            self.low_now = self.ctl.low_conf_now();
            overlap = tick.overlap();
            if self.ctl.cell() == Cell::Rounds {
                // One entry per robot that ran: its reference time at the tick's start (the
                // last reference sample is the task's end: the timeline runs to T_ref, one
                // sample period past it, as the simulated cell logs it); supervised when it was
                // low-confidence at the start or traversed a low-confidence sample inside the
                // tick (the coordinator reports the tick low-confidence), as the simulated cell
                // records it; corrected when supervised and the operator corrected.
                for (i, r) in self.log.robots.iter_mut().enumerate() {
                    if running[i] {
                        let supervised = low[i] || tick.low_conf[i];
                        r.ref_time.push(before[i].min(self.last_ref));
                        r.supervised.push(supervised);
                        r.corrected.push(supervised && corrected);
                    }
                }
            }
            if self.ctl.is_finished() {
                self.active = false;
                self.finished = true;
                self.rest_after_round();
            }
        }
        let after = self.last.ref_time;
        debug_assert_eq!(after, self.ctl.ref_time_now());
        let per_tick = self.per_tick;
        for (i, s) in self.speed.as_mut_slice().iter_mut().enumerate().take(n) {
            *s = ((after[i] - before[i]) / per_tick).max(0.0);
        }
        self.overlap = overlap;
        Ok(())
    }
}

impl CellLoop {
    /// The liveness check of a tick at `now` whose `now` is past the stall bound
    /// (`stall_due`): latches [`NodeFault::Stalled`] for the first robot silent for more than
    /// `stall_s` (robot 1 first), else sets the bound to the earliest instant one can be.
    /// `silent > stall_after` is `now > last_progress + stall_after` in whole nanoseconds, so
    /// the bound decides exactly as the loop over robots each tick did.
    #[cold]
    fn check_stall(&mut self, now: Instant) {
        let mut due: Option<Instant> = None;
        for k in 0..self.ctl.n_robots() {
            let silent = now.saturating_duration_since(self.last_progress[k]);
            if silent > self.stall_after {
                self.stall = Some(NodeFault::Stalled {
                    robot: k,
                    silent_s: silent.as_secs_f64(),
                });
                return;
            }
            // A bound too far to represent: this robot never stalls; the others decide.
            if let Some(d) = self.last_progress[k].checked_add(self.stall_after) {
                due = Some(due.map_or(d, |e| e.min(d)));
            }
        }
        self.stall_due = due;
    }
}

impl CellLoop {
    /// The node is shutting down (`Node::stop`: a signal, `--stdin-stop`, the end of
    /// `--seconds`): a running round is aborted where it stands, as a stalled link holds the
    /// cell — no robot's schedule clock moves again, its log is discarded (an unfinished round is
    /// never recorded) — and the last command says so: not active, every robot at the
    /// reference time it reached with speed scale 0, none needing the operator. Unlike
    /// [`Request::Stop`] the controller is not reset, so a driver that follows the last command
    /// holds its robot where it is instead of sending it back to its start. A finished round
    /// that waits to be recorded stays finished (its log is the caller's to record).
    #[must_use]
    pub fn halt(&mut self) -> Command {
        let n = self.ctl.n_robots();
        self.ticks += 1;
        if self.active {
            self.active = false;
            for r in &mut self.log.robots {
                r.ref_time.clear();
                r.supervised.clear();
                r.corrected.clear();
            }
        }
        self.speed = PerRobot::new(n);
        self.overlap = false;
        Command {
            tick: self.ticks,
            active: false,
            finished: self.finished,
            fault: self.fault().is_some(),
            ref_time: self.last.ref_time,
            speed: self.speed,
            needs_operator: RobotFlags::new(n),
        }
    }
}

/// Log entries to reserve per robot: three times the planned round in ticks (rounds; the
/// operator may drag), at least 64.
fn round_capacity(ctl: &AnyController) -> usize {
    let planned = ctl.as_rounds().map_or(0.0, |c| {
        (0..c.n_robots())
            .map(|i| c.planned_end_s(i))
            .fold(0.0, f64::max)
    });
    let ticks = planned / ctl.tick_s();
    if ticks.is_finite() && ticks > 0.0 {
        (ticks * 3.0) as usize + 64
    } else {
        64
    }
}
