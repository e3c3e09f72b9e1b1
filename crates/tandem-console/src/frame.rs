//! What the page shows, one [`Frame`] per update (docs/formats.md, "Console frames"), and the
//! fixed-size [`RawFrame`] a control loop publishes, from which the server derives it with the
//! plan's [`Geometry`] (the attention robot's time left, the next handover, the upcoming
//! low-confidence stretches).
//!
//! Time frames: `t_s` and every `*_s` of a frame are real seconds; `in_s`/`start_s`/`end_s`
//! count from the frame's tick; `ref_time` is reference samples of the robot's current task.
//! Robots are 1-based in a frame (as on the page and in the DOM), 0-based in Rust indices.

use serde::{Deserialize, Serialize};
use tandem_planner::AnyController;
use tandem_realtime::{Controller, MAX_ROBOTS, PreAlert, Tick, Timeline};

/// A robot's state on the page (`data-state` in the DOM), by precedence: a robot held by the
/// fault monitor is `fault`; a robot done with its task in a round is `done`; the robot the
/// coordinator supervises now (`Controller::low_conf_now`) is `lc`; a robot at a hold point of
/// a round is `hold`; a robot that does not move in the next tick for another reason (before
/// its start, at its gate waiting for the operator's token) is `wait`; any other robot runs
/// on its own, `hc`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RobotState {
    /// Low-confidence: the robot the operator supervises now (the red indicator of Fig. 1).
    Lc,
    /// High-confidence: runs without the operator.
    #[default]
    Hc,
    /// Waits at a hold point of a round for the other robots.
    Hold,
    /// Does not move now: before its start, or at its gate for the operator's token.
    Wait,
    /// Held by the fault monitor (two robots were low-confidence in one tick).
    Fault,
    /// Done with its task (rounds only).
    Done,
}

impl RobotState {
    /// Every state, in the order of the docs.
    pub const ALL: [RobotState; 6] = [
        RobotState::Lc,
        RobotState::Hc,
        RobotState::Hold,
        RobotState::Wait,
        RobotState::Fault,
        RobotState::Done,
    ];

    /// Its text form (`data-state`): `lc`, `hc`, `hold`, `wait`, `fault`, `done`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            RobotState::Lc => "lc",
            RobotState::Hc => "hc",
            RobotState::Hold => "hold",
            RobotState::Wait => "wait",
            RobotState::Fault => "fault",
            RobotState::Done => "done",
        }
    }

    fn code(self) -> u64 {
        RobotState::ALL
            .iter()
            .position(|s| *s == self)
            .expect("every state is in ALL") as u64
    }

    fn from_code(code: u64) -> RobotState {
        RobotState::ALL
            .get(code as usize)
            .copied()
            .unwrap_or_default()
    }
}

/// One robot's snapshot as a control loop publishes it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RawRobot {
    /// Its state ([`RobotState`]).
    pub state: RobotState,
    /// Its schedule clock (s) in its current task ([`Controller::clock_s`]).
    pub clock_s: f64,
    /// Its fractional reference time (reference samples) in its current task.
    pub ref_time: f64,
    /// Tasks it completed ([`Controller::tasks_now`]).
    pub tasks: u64,
    /// Corrections the operator gave it in its current execution (task; rounds: this round):
    /// runs of consecutive ticks whose input was a correction while it was the supervised
    /// robot. Counted by [`ConsoleHandle::publish_corrected`](crate::ConsoleHandle::publish_corrected);
    /// meaningful only when [`RawFrame::corrections_known`].
    pub corrections: u64,
}

/// The fixed-size snapshot a control loop publishes each tick
/// ([`ConsoleHandle::publish`](crate::ConsoleHandle::publish)): no heap, `Copy`, written
/// through the lock-free slot word by word.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RawFrame {
    /// Robots `N` (`1..=MAX_ROBOTS`).
    pub n: usize,
    /// Ticks the controller has run ([`Controller::ticks`]).
    pub tick: u64,
    /// Control period (real s).
    pub tick_s: f64,
    /// Rounds completed so far (rounds cells driven round after round; 0 otherwise).
    pub rounds_done: u64,
    /// Whether the loop has stopped ticking (pause, or a hold that took effect).
    pub paused: bool,
    /// The robot (0-based) at whose next hold point or gate the cell will pause, if armed.
    pub hold_armed: Option<usize>,
    /// Whether a fault is latched.
    pub fault: bool,
    /// When the loop published it: milliseconds since the Unix epoch (for the latency from a
    /// tick to the page). Stamped by [`ConsoleHandle::publish`](crate::ConsoleHandle::publish)
    /// only for a snapshot the server asked for, never per tick.
    pub published_unix_ms: f64,
    /// The coordinator's pre-alert after the tick ([`Tick::next`]): the robot whose next
    /// low-confidence stretch can start soonest and the worst-case bounds on that start (real
    /// s from the end of the tick). The page's countdown.
    pub next: Option<PreAlert>,
    /// Snapshots the loop handed to the handle so far, this one included (the server sends
    /// at most `max_hz` of them a second: the rest are dropped).
    pub published: u64,
    /// Whether the loop reports its operator's corrections
    /// ([`ConsoleHandle::publish_corrected`](crate::ConsoleHandle::publish_corrected)): the
    /// robots' [`RawRobot::corrections`] count; otherwise the page shows none.
    pub corrections_known: bool,
    /// Each robot, robot `i` at index `i` (the first `n` are meaningful).
    pub robots: [RawRobot; MAX_ROBOTS],
}

/// Words of a [`RawFrame`]'s header in the slot.
pub(crate) const HEADER: usize = 11;
/// Words of one robot of a [`RawFrame`] in the slot.
pub(crate) const ROBOT_WORDS: usize = 5;
/// Words of a [`RawFrame`] in the slot: [`HEADER`], then [`ROBOT_WORDS`] per robot.
pub(crate) const WORDS: usize = HEADER + ROBOT_WORDS * MAX_ROBOTS;

impl RawFrame {
    /// The snapshot of `ctl` after `tick` (`rounds`: the cell runs in rounds, where a robot
    /// that finished its task is `done`). O(N); never allocates.
    pub fn from_controller<C: Controller + ?Sized>(tick: &Tick, ctl: &C, rounds: bool) -> Self {
        let n = ctl.n_robots().min(MAX_ROBOTS);
        let low = ctl.low_conf_now();
        // The tick's own flags where they are the controller's now (`Tick::waiting` is
        // `waiting_now`, the contract's test checks it); only the supervised robot is read
        // from the controller: one O(N) call instead of three.
        let (running, waiting) = (tick.running, tick.waiting);
        let held = tick.fault.map(|f| f.stopped);
        let clocks = ctl.clock_s();
        let mut robots = [RawRobot::default(); MAX_ROBOTS];
        for (i, r) in robots.iter_mut().enumerate().take(n) {
            let state = if held == Some(i) {
                RobotState::Fault
            } else if rounds && tick.tasks[i] >= 1 {
                RobotState::Done
            } else if low[i] {
                RobotState::Lc
            } else if waiting[i] && rounds {
                RobotState::Hold
            } else if waiting[i] || !running[i] {
                RobotState::Wait
            } else {
                RobotState::Hc
            };
            *r = RawRobot {
                state,
                clock_s: clocks.get(i).copied().unwrap_or(0.0),
                ref_time: tick.ref_time[i],
                tasks: tick.tasks[i],
                corrections: 0,
            };
        }
        RawFrame {
            n,
            tick: ctl.ticks(),
            tick_s: ctl.tick_s(),
            fault: tick.fault.is_some(),
            next: tick.next,
            robots,
            ..RawFrame::default()
        }
    }

    pub(crate) fn encode(&self, out: &mut [u64; WORDS]) {
        let flags = u64::from(self.paused)
            | u64::from(self.fault) << 1
            | u64::from(self.hold_armed.is_some()) << 2
            | u64::from(self.next.is_some()) << 3
            | u64::from(self.corrections_known) << 4;
        let next = self.next.unwrap_or(PreAlert {
            robot: 0,
            earliest_s: 0.0,
            latest_s: 0.0,
        });
        out[0] = self.n as u64;
        out[1] = self.tick;
        out[2] = self.tick_s.to_bits();
        out[3] = self.rounds_done;
        out[4] = flags;
        out[5] = self.hold_armed.unwrap_or(0) as u64;
        out[6] = self.published_unix_ms.to_bits();
        out[7] = next.robot as u64;
        out[8] = next.earliest_s.to_bits();
        out[9] = next.latest_s.to_bits();
        out[10] = self.published;
        for (i, r) in self.robots.iter().enumerate().take(self.n) {
            let w = &mut out[HEADER + ROBOT_WORDS * i..HEADER + ROBOT_WORDS * (i + 1)];
            w[0] = r.state.code();
            w[1] = r.clock_s.to_bits();
            w[2] = r.ref_time.to_bits();
            w[3] = r.tasks;
            w[4] = r.corrections;
        }
    }

    pub(crate) fn decode(w: &[u64; WORDS]) -> RawFrame {
        let n = (w[0] as usize).min(MAX_ROBOTS);
        let mut robots = [RawRobot::default(); MAX_ROBOTS];
        for (i, r) in robots.iter_mut().enumerate().take(n) {
            let w = &w[HEADER + ROBOT_WORDS * i..HEADER + ROBOT_WORDS * (i + 1)];
            *r = RawRobot {
                state: RobotState::from_code(w[0]),
                clock_s: f64::from_bits(w[1]),
                ref_time: f64::from_bits(w[2]),
                tasks: w[3],
                corrections: w[4],
            };
        }
        RawFrame {
            n,
            tick: w[1],
            tick_s: f64::from_bits(w[2]),
            rounds_done: w[3],
            paused: w[4] & 1 != 0,
            fault: w[4] & 2 != 0,
            hold_armed: (w[4] & 4 != 0).then_some(w[5] as usize),
            published_unix_ms: f64::from_bits(w[6]),
            next: (w[4] & 8 != 0).then(|| PreAlert {
                robot: w[7] as usize,
                earliest_s: f64::from_bits(w[8]),
                latest_s: f64::from_bits(w[9]),
            }),
            published: w[10],
            corrections_known: w[4] & 16 != 0,
            robots,
        }
    }
}

/// One robot of a [`Frame`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotFrame {
    /// The robot, 1-based.
    pub robot: usize,
    /// Its state.
    pub state: RobotState,
    /// Its reference time (reference samples of its current task).
    pub ref_time: f64,
    /// Its progress through its current task, `ref_time / T_ref` in `[0, 1]`.
    pub progress: f64,
    /// Tasks it completed.
    pub tasks: u64,
    /// The per-robot strip ([`crate::RobotStrip`]): warp rate within its bounds, confidence
    /// at the current sample, supervision this execution. Filled by the server from
    /// successive snapshots; default in [`build_frame`]'s output.
    #[serde(default)]
    pub strip: crate::RobotStrip,
}

/// The robot that may need the operator now (the banner).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Attention {
    /// The robot, 1-based.
    pub robot: usize,
    /// Worst-case time left in its low-confidence stretch (real s): the rest of the stretch at
    /// the slowest demonstrated speed `ψ̇max`.
    pub left_s: f64,
}

/// The next handover: the coordinator's pre-alert ([`Tick::next`], [`PreAlert`]), the robot
/// whose next low-confidence stretch can start soonest, with the worst-case bounds on its start.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NextHandover {
    /// The robot, 1-based.
    pub robot: usize,
    /// The countdown: the earliest its stretch can start under every admissible operator
    /// (`PreAlert::earliest_s`, real s from the frame's tick).
    pub in_s: f64,
    /// The latest it can start (`PreAlert::latest_s`); `None` when the start waits on another
    /// robot (a hold's rules, a leg's start, the continuous cell's token) and has no bound.
    pub latest_s: Option<f64>,
    /// Its planned duration (real s, at the schedule's speeds).
    pub duration_s: f64,
}

/// An upcoming (or current) low-confidence stretch of one robot, planned, for the timeline
/// and the queue.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stretch {
    /// The robot, 1-based.
    pub robot: usize,
    /// Planned start, real s from the frame's tick (0 for the current stretch).
    pub start_s: f64,
    /// Planned end, real s from the frame's tick.
    pub end_s: f64,
}

/// The confirmation of one control message (docs/formats.md, "Console controls").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ack {
    /// The client that sent it.
    pub client: String,
    /// The message's id.
    pub id: u64,
    /// The operation (`pause`, `hold`, …).
    pub op: String,
    /// Whether it took effect.
    pub ok: bool,
    /// What happened, in words.
    pub message: String,
}

/// Health of the link from the control loop to the page.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Health {
    /// Snapshots the loop published so far.
    pub published: u64,
    /// Snapshots the server did not send (newer ones replaced them before the next push: the
    /// page gets at most `max_hz` frames per second).
    pub dropped: u64,
    /// Age of the newest snapshot when this frame was sent (real s).
    pub source_age_s: f64,
    /// Controls waiting in the loop's queue are not counted; confirmations the loop could not
    /// queue (the server was slower than the loop) are.
    pub acks_lost: u64,
    /// The schedule the cell runs and its certificate, in words, as the source gave it
    /// ([`crate::ConsoleConfig::schedule`]), e.g. whether it is the certified plan or a
    /// fallback.
    #[serde(default)]
    pub schedule: Option<String>,
}

/// One update of the page (server-sent event `frame`; docs/formats.md, "Console frames").
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// Frames the server sent so far (1 for the first).
    pub seq: u64,
    /// The controller's tick count.
    pub tick: u64,
    /// Cell time: `tick · tick_s` (real s).
    pub t_s: f64,
    /// `rounds` or `continuous`.
    pub cell: String,
    /// Rounds completed (rounds cells).
    pub rounds_done: u64,
    /// Whether the cell does not tick.
    pub paused: bool,
    /// The robot (1-based) at whose next hold point or gate the cell will pause, if armed.
    pub hold_armed: Option<usize>,
    /// Whether a fault is latched.
    pub fault: bool,
    /// Every robot, robot 1 first.
    pub robots: Vec<RobotFrame>,
    /// The robot that may need the operator now, if any.
    pub attention: Option<Attention>,
    /// The next handover, the coordinator's pre-alert ([`next_handover`]), if it announces one.
    pub next: Option<NextHandover>,
    /// Whether the next handover can start within `lead_s` by the page's next frame
    /// (`prealert_on`: `next.in_s ≤ lead_s + tick_s + 1/RECORDING_HZ`, so that the alert,
    /// raised at a frame, is up at least `lead_s` before a start at the worst-case earliest).
    pub prealert: bool,
    /// The pre-alert's lead (real s).
    pub lead_s: f64,
    /// Low-confidence stretches within `horizon_s`, by start time.
    pub stretches: Vec<Stretch>,
    /// The timeline's horizon (real s).
    pub horizon_s: f64,
    /// The controlling client, if one has claimed control.
    pub controller: Option<String>,
    /// The most recent confirmations, oldest first (at most 16).
    pub acks: Vec<Ack>,
    /// Link health.
    pub health: Health,
    /// When the loop published the snapshot (ms since the Unix epoch).
    pub published_unix_ms: f64,
    /// The operator's strip ([`crate::OperatorStrip`]): busy share, switches per hour,
    /// longest busy stretch, time on shift. Filled by the server.
    #[serde(default)]
    pub operator: crate::OperatorStrip,
    /// A message about the source the page must show (a replay's corrupt or truncated file,
    /// a replay that ended), if any.
    #[serde(default)]
    pub notice: Option<String>,
}

/// One robot's plan as the page needs it: its low-confidence runs and clock.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct RobotGeometry {
    /// `c_n`, `n ∈ 0..=T_ref` (s): the schedule clock at which sample `n` starts.
    clock: Vec<f64>,
    /// Maximal low-confidence runs `[start, end)` in reference samples, in order.
    runs: Vec<(usize, usize)>,
    /// `W[n] = Σ_{k<n} ψ̇max[k]·Δt_s`: the slowest time to sample `n` (s).
    worst: Vec<f64>,
    /// `ψ̇min[n]`, `ψ̇max[n]`: the warp rate's bounds per reference sample (execution
    /// samples per reference sample). Empty in recordings without them.
    #[serde(default)]
    rate_bounds: Vec<(f64, f64)>,
    /// Reference sample period Δt_s (s); 0 in recordings without it.
    #[serde(default)]
    dt_s: f64,
}

impl RobotGeometry {
    fn new(t: &Timeline) -> Self {
        let conf = t.conf();
        // The timeline's low-confidence runs (Eq. 19), as reference-sample ranges.
        let runs: Vec<(usize, usize)> = t
            .lc_intervals()
            .iter()
            .map(|i| (i.ref_start, i.ref_end))
            .collect();
        let mut worst = Vec::with_capacity(conf.len() + 1);
        let mut acc = 0.0;
        worst.push(acc);
        for g in t.grad_max() {
            acc += g * t.dt_s();
            worst.push(acc);
        }
        RobotGeometry {
            clock: t.sample_clock_s().to_vec(),
            runs,
            worst,
            rate_bounds: t
                .grad_min()
                .iter()
                .zip(t.grad_max())
                .map(|(&lo, &hi)| (lo, hi))
                .collect(),
            dt_s: t.dt_s(),
        }
    }

    fn n_ref(&self) -> usize {
        self.worst.len() - 1
    }

    /// The slowest time (s) from reference time `r` to sample `to`.
    fn worst_between(&self, r: f64, to: usize) -> f64 {
        let n = (r.floor().max(0.0) as usize).min(self.n_ref().saturating_sub(1));
        let at =
            self.worst[n] + (r - n as f64).clamp(0.0, 1.0) * (self.worst[n + 1] - self.worst[n]);
        (self.worst[to.min(self.n_ref())] - at).max(0.0)
    }

    fn clock_at(&self, n: usize) -> f64 {
        self.clock[n.min(self.clock.len() - 1)]
    }
}

/// The plan of a cell as the console reads it: every robot's low-confidence runs, schedule
/// clock and slowest times (built once from the controller, before the loop starts), the
/// pre-alert's lead and the timeline's horizon. Serializable: a replay's recording carries it
/// (docs/formats.md, "Console recordings").
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Geometry {
    rounds: bool,
    robots: Vec<RobotGeometry>,
    /// Task start and end on its clock (continuous cell: one task plan for every robot).
    task_span_s: (f64, f64),
    can_hold: bool,
    /// The operator's switch time the controller keeps (real s: its whole ticks; 0: none).
    /// A recording written before it was kept reads as 0.
    #[serde(default)]
    switch_s: f64,
    /// Pre-alert lead (real s): [`Console::start`](crate::Console::start) sets the larger of
    /// the configured lead and the switch time.
    pub lead_s: f64,
    /// Timeline horizon (real s).
    pub horizon_s: f64,
}

/// The default pre-alert lead (s): take-over studies give an alert at least 7 s ahead.
pub const DEFAULT_LEAD_S: f64 = 7.0;
/// The default horizon of the timeline (s).
pub const DEFAULT_HORIZON_S: f64 = 90.0;

impl Geometry {
    /// The geometry of `ctl`'s plan (its timelines), with the default horizon and the default
    /// lead ([`DEFAULT_LEAD_S`], or the controller's switch time where that is larger).
    #[must_use]
    pub fn new(ctl: &AnyController) -> Geometry {
        match ctl {
            AnyController::Rounds(c) => Geometry {
                rounds: true,
                robots: c.robots().iter().map(RobotGeometry::new).collect(),
                task_span_s: (0.0, 0.0),
                can_hold: c.has_holds(),
                switch_s: c.switch_ticks() as f64 * c.tick_s(),
                lead_s: DEFAULT_LEAD_S.max(c.switch_ticks() as f64 * c.tick_s()),
                horizon_s: DEFAULT_HORIZON_S,
            },
            AnyController::Continuous(c) => {
                let t = c.task();
                Geometry {
                    rounds: false,
                    robots: vec![RobotGeometry::new(t); c.n_robots()],
                    task_span_s: (t.start_s(), t.end_s()),
                    can_hold: true,
                    switch_s: c.switch_ticks() as f64 * c.tick_s(),
                    lead_s: DEFAULT_LEAD_S.max(c.switch_ticks() as f64 * c.tick_s()),
                    horizon_s: DEFAULT_HORIZON_S,
                }
            }
        }
    }

    /// The operator's switch time the controller keeps (real s, whole ticks; 0: none): the
    /// least lead a pre-alert can have.
    #[must_use]
    pub fn switch_s(&self) -> f64 {
        self.switch_s
    }

    /// Whether the cell runs in rounds.
    #[must_use]
    pub fn is_rounds(&self) -> bool {
        self.rounds
    }

    /// Robots `N`.
    #[must_use]
    pub fn n_robots(&self) -> usize {
        self.robots.len()
    }

    /// Whether a robot ever waits where the cell can be held: rounds with hold points, or a
    /// continuous cell (its gates).
    #[must_use]
    pub fn can_hold(&self) -> bool {
        self.can_hold
    }

    /// Rounds: every robot's low-confidence runs `(robot, run)` (0-based) in the plan's order
    /// of a round, by the schedule clock at which each starts (robot first on a tie); `None`
    /// for a continuous cell, whose order is its token sequence, kept by its coordinator.
    /// The operator's queue of one round as the schedule planned it.
    pub(crate) fn plan_order(&self) -> Option<Vec<(usize, usize)>> {
        if !self.rounds {
            return None;
        }
        let mut runs: Vec<(f64, usize, usize)> = Vec::new();
        for (i, r) in self.robots.iter().enumerate() {
            for (k, &(start, _)) in r.runs.iter().enumerate() {
                runs.push((r.clock.get(start).copied().unwrap_or(f64::INFINITY), i, k));
            }
        }
        runs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        Some(runs.into_iter().map(|(_, i, k)| (i, k)).collect())
    }

    /// The low-confidence run (index into robot `i`'s runs, 0-based robot) that a stretch
    /// reported at reference time `ref_time` (samples) is in: the first run ending after the
    /// sample holding `ref_time` (a robot reported low-confidence within the clock tolerance
    /// before its run counts as in it). `None` past the last run.
    pub(crate) fn run_at(&self, i: usize, ref_time: f64) -> Option<usize> {
        let n = ref_time.max(0.0).floor() as usize;
        self.robots
            .get(i)?
            .runs
            .iter()
            .position(|&(_, end)| end > n)
    }

    /// A geometry of no robot: the console of a source that could not be read (a replay
    /// whose header is corrupt) shows only its notice.
    #[must_use]
    pub fn empty(rounds: bool) -> Geometry {
        Geometry {
            rounds,
            robots: Vec::new(),
            task_span_s: (0.0, 0.0),
            can_hold: false,
            switch_s: 0.0,
            lead_s: DEFAULT_LEAD_S,
            horizon_s: DEFAULT_HORIZON_S,
        }
    }

    /// Whether robot `i` (0-based) is confident (high-confidence) at reference time
    /// `ref_time` of its task: the sample is outside its low-confidence runs.
    #[must_use]
    pub fn confident_at(&self, i: usize, ref_time: f64) -> bool {
        let n = ref_time.floor().max(0.0) as usize;
        self.robots
            .get(i)
            .is_none_or(|g| !g.runs.iter().any(|&(s, e)| s <= n && n < e))
    }

    /// Robot `i`'s warp-rate bounds `(ψ̇min, ψ̇max)` at reference time `ref_time` (execution
    /// samples per reference sample), if the plan carries them.
    #[must_use]
    pub fn rate_bounds_at(&self, i: usize, ref_time: f64) -> Option<(f64, f64)> {
        let g = self.robots.get(i)?;
        let n = (ref_time.floor().max(0.0) as usize).min(g.rate_bounds.len().checked_sub(1)?);
        g.rate_bounds.get(n).copied()
    }

    /// Robot `i`'s reference sample period Δt_s (s), if the plan carries it.
    #[must_use]
    pub fn dt_s(&self, i: usize) -> Option<f64> {
        self.robots.get(i).map(|g| g.dt_s).filter(|d| *d > 0.0)
    }

    /// The robot low-confidence now and the worst-case time left in its stretch.
    #[must_use]
    pub fn attention(&self, raw: &RawFrame) -> Option<Attention> {
        let i =
            (0..raw.n.min(self.robots.len())).find(|&i| raw.robots[i].state == RobotState::Lc)?;
        let g = &self.robots[i];
        let r = raw.robots[i].ref_time;
        let n = r.floor().max(0.0) as usize;
        let end = g
            .runs
            .iter()
            .find(|&&(s, e)| s <= n && n < e)
            .map_or(n, |&(_, e)| e);
        Some(Attention {
            robot: i + 1,
            left_s: g.worst_between(r, end),
        })
    }

    /// Robot `i`'s planned low-confidence stretches from now, as `(start, end)` real s from
    /// now, until `horizon_s` (at most `max` of them); the current one first if it is in one.
    fn stretches_of(
        &self,
        raw: &RawFrame,
        i: usize,
        horizon_s: f64,
        max: usize,
        out: &mut Vec<Stretch>,
    ) {
        let busy_until_s = self.attention(raw).map_or(0.0, |a| a.left_s);
        let g = &self.robots[i];
        let rr = &raw.robots[i];
        if matches!(rr.state, RobotState::Done) {
            return;
        }
        let n = rr.ref_time.floor().max(0.0) as usize;
        let c = rr.clock_s;
        let in_lc = rr.state == RobotState::Lc;
        let mut pushed = 0;
        // Task-plan offset of the copy of the task being looked at (continuous cell: the
        // next task starts when this one ends, ignoring gate waits: planned times).
        let mut offset = 0.0;
        let task_len = self.task_span_s.1 - self.task_span_s.0;
        for lap in 0..4 {
            for &(s, e) in &g.runs {
                if lap == 0 && e <= n {
                    continue;
                }
                let (start, end) = if lap == 0 && s <= n && in_lc {
                    (0.0, (g.clock_at(e) - c).max(0.0))
                } else if lap == 0 && s <= n {
                    // Inside or at the start of a stretch without being supervised (at its
                    // gate, or before its start): not before the current stretch ends.
                    let start = (g.clock_at(s) - c).max(busy_until_s);
                    (start, start + g.clock_at(e) - g.clock_at(s.max(n)))
                } else {
                    (offset + g.clock_at(s) - c, offset + g.clock_at(e) - c)
                };
                if start > horizon_s || pushed >= max {
                    return;
                }
                out.push(Stretch {
                    robot: i + 1,
                    start_s: start.max(0.0),
                    end_s: end.max(0.0),
                });
                pushed += 1;
            }
            if self.rounds || task_len <= 0.0 {
                return;
            }
            offset += task_len;
        }
    }

    /// Every robot's planned low-confidence stretches (at most 8 per robot, any distance),
    /// in the order the operator takes them: by planned start, each pushed back until the
    /// one before it has ended (one operator takes one stretch at a time: the robots of a
    /// continuous cell wait at their gates for the token, which the plan's clocks alone do
    /// not show), a robot's later stretches pushed back with it. The current stretch (the
    /// attention robot's) ends at its planned end.
    fn queue(&self, raw: &RawFrame) -> Vec<Stretch> {
        let mut out = Vec::new();
        for i in 0..raw.n.min(self.robots.len()) {
            self.stretches_of(raw, i, f64::INFINITY, 8, &mut out);
        }
        out.sort_by(|a, b| a.start_s.total_cmp(&b.start_s).then(a.robot.cmp(&b.robot)));
        let mut delay = [0.0f64; MAX_ROBOTS];
        let mut free_at = 0.0f64;
        for s in &mut out {
            let d = &mut delay[s.robot - 1];
            let start = (s.start_s + *d).max(free_at);
            *d = start - s.start_s;
            s.end_s += *d;
            s.start_s = start;
            free_at = s.end_s;
        }
        out.sort_by(|a, b| a.start_s.total_cmp(&b.start_s).then(a.robot.cmp(&b.robot)));
        out
    }

    /// The operator's queue of planned low-confidence stretches that start within the
    /// horizon: in order of planned start, each pushed back until the one before it has ended
    /// (one operator, one stretch at a time), a robot's later stretches pushed back with it.
    #[must_use]
    pub fn stretches(&self, raw: &RawFrame) -> Vec<Stretch> {
        let mut q = self.queue(raw);
        q.retain(|s| s.start_s <= self.horizon_s);
        q
    }
}

/// The next handover of `raw`: the coordinator's pre-alert it carries ([`RawFrame::next`]),
/// 1-based, its countdown the worst-case earliest start and its planned duration that of the
/// robot's next low-confidence run in the plan (the first that starts after its current
/// sample; a continuous cell's next task's first when none is left in this one). `None` when
/// the coordinator announces none.
#[must_use]
pub fn next_handover(geometry: &Geometry, raw: &RawFrame) -> Option<NextHandover> {
    let p = raw.next?;
    let duration_s = geometry.robots.get(p.robot).map_or(0.0, |g| {
        let rr = &raw.robots[p.robot.min(MAX_ROBOTS - 1)];
        let n = rr.ref_time.floor().max(0.0) as usize;
        g.runs
            .iter()
            .find(|&&(s, _)| s > n)
            .or_else(|| g.runs.iter().find(|&&(_, e)| e > n))
            .or_else(|| g.runs.first())
            .map_or(0.0, |&(s, e)| g.clock_at(e) - g.clock_at(s))
    });
    Some(NextHandover {
        robot: p.robot + 1,
        in_s: p.earliest_s,
        latest_s: p.latest_s.is_finite().then_some(p.latest_s),
        duration_s,
    })
}

/// Whether a handover that can start in `in_s` real seconds at the earliest is pre-alerted
/// with lead `lead_s` at a control tick `tick_s` long (all real s): when `in_s ≤ lead_s +
/// tick_s + 1/RECORDING_HZ`. The alert can only rise at a frame the page (or a recording)
/// shows, and those come at most one page frame plus one tick apart (a frame per
/// `1/RECORDING_HZ` s, on the tick grid); raised when the notice left is within that spacing
/// of the lead, it errs early by at most that spacing, and a stretch that starts at its
/// earliest has had at least `lead_s` of notice on every frame the page shows (the rounding
/// the other way would give down to `lead_s − tick_s − 1/RECORDING_HZ`).
pub(crate) fn prealert_on(in_s: f64, lead_s: f64, tick_s: f64) -> bool {
    in_s <= lead_s + tick_s.max(0.0) + 1.0 / crate::RECORDING_HZ
}

/// The page's frame of `raw` (server side; allocates).
#[must_use]
pub fn build_frame(geometry: &Geometry, raw: &RawFrame) -> Frame {
    let n_ref = geometry
        .robots
        .first()
        .map_or(1, RobotGeometry::n_ref)
        .max(1);
    let robots = (0..raw.n)
        .map(|i| {
            let r = &raw.robots[i];
            RobotFrame {
                robot: i + 1,
                state: r.state,
                ref_time: r.ref_time,
                progress: if r.state == RobotState::Done {
                    1.0
                } else {
                    (r.ref_time / n_ref as f64).clamp(0.0, 1.0)
                },
                tasks: r.tasks,
                strip: crate::RobotStrip::default(),
            }
        })
        .collect();
    let next = next_handover(geometry, raw);
    Frame {
        seq: 0,
        tick: raw.tick,
        t_s: raw.tick as f64 * raw.tick_s,
        cell: if geometry.rounds {
            "rounds"
        } else {
            "continuous"
        }
        .to_string(),
        rounds_done: raw.rounds_done,
        paused: raw.paused,
        hold_armed: raw.hold_armed.map(|i| i + 1),
        fault: raw.fault,
        robots,
        attention: geometry.attention(raw),
        prealert: next
            .as_ref()
            .is_some_and(|n| prealert_on(n.in_s, geometry.lead_s, raw.tick_s)),
        next,
        lead_s: geometry.lead_s,
        stretches: geometry.stretches(raw),
        horizon_s: geometry.horizon_s,
        controller: None,
        acks: Vec::new(),
        health: Health::default(),
        published_unix_ms: raw.published_unix_ms,
        operator: crate::OperatorStrip::default(),
        notice: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tandem_realtime::{Coordinator, Operator};

    /// Robots starting 4 s apart on a 10 s task (Δt_s = 0.1 s, gradient 1, bounds [½, 2]),
    /// low-confidence on samples 40..60: robot `i`'s stretch is planned at [4 + 4i, 6 + 4i) s.
    fn rounds(n: usize) -> AnyController {
        let conf: Vec<bool> = (0..100).map(|k| !(40..60).contains(&k)).collect();
        let (g, lo, hi) = (vec![1.0; 100], vec![0.5; 100], vec![2.0; 100]);
        let robots: Vec<Timeline> = (0..n)
            .map(|i| Timeline::new(&conf, &g, &lo, &hi, 4.0 * i as f64, 0.1).unwrap())
            .collect();
        AnyController::Rounds(Coordinator::new(robots, 0.1).unwrap())
    }

    #[test]
    fn a_raw_frame_survives_the_slot_words() {
        let mut raw = RawFrame {
            n: 3,
            tick: 77,
            tick_s: 0.01,
            rounds_done: 4,
            paused: true,
            hold_armed: Some(2),
            fault: true,
            published_unix_ms: 1.5e12,
            next: Some(PreAlert {
                robot: 2,
                earliest_s: 6.4,
                latest_s: f64::INFINITY,
            }),
            published: 123,
            corrections_known: true,
            ..RawFrame::default()
        };
        for (i, s) in [RobotState::Lc, RobotState::Fault, RobotState::Done]
            .into_iter()
            .enumerate()
        {
            raw.robots[i] = RawRobot {
                state: s,
                clock_s: 1.25 * i as f64,
                ref_time: 3.5 + i as f64,
                tasks: 10 + i as u64,
                corrections: 2 * i as u64 + 1,
            };
        }
        let mut words = [0; WORDS];
        raw.encode(&mut words);
        assert_eq!(RawFrame::decode(&words), raw);
        // Without a pre-alert it reads back as none.
        let none = RawFrame { next: None, ..raw };
        none.encode(&mut words);
        assert_eq!(RawFrame::decode(&words).next, None);
        // Every state's code reads back as itself; an unknown code reads as `hc`.
        for s in RobotState::ALL {
            assert_eq!(RobotState::from_code(s.code()), s);
        }
        assert_eq!(RobotState::from_code(99), RobotState::Hc);
    }

    #[test]
    fn attention_and_countdown_by_hand() {
        let mut ctl = rounds(3);
        let g = Geometry::new(&ctl);
        // At the start every robot is at clock 0: robot 1 runs (hc), robots 2 and 3 wait for
        // their starts; the next stretch is robot 1's at 4 s, for 2 s.
        let t = ctl.tick(Operator::Scheduled).unwrap();
        let raw = RawFrame::from_controller(&t, &ctl, true);
        let states: Vec<_> = raw.robots[..3].iter().map(|r| r.state).collect();
        assert_eq!(states, [RobotState::Hc, RobotState::Wait, RobotState::Wait]);
        assert!(g.attention(&raw).is_none());
        // The countdown is the coordinator's pre-alert: robot 1's clock (0.1 s) must reach its
        // stretch at 4 s; at the fastest rate (2× the schedule's) that takes 1.95 s, so the
        // 20th tick is the first that can reach it and it starts 19 ticks from now, 1.9 s; at
        // the slowest (½×) 7.8 s, so it starts at most 78 ticks from now, 7.8 s.
        let next = next_handover(&g, &raw).unwrap();
        assert_eq!(next.robot, 1);
        assert_eq!(raw.next, t.next);
        assert!((next.in_s - 1.9).abs() < 1e-9, "{next:?}");
        let latest = next
            .latest_s
            .expect("robot 1 runs alone: its start is bounded");
        assert!((latest - 7.8).abs() <= 0.1 + 1e-9, "{next:?}");
        assert!((next.duration_s - 2.0).abs() < 1e-9);
        // Run to robot 1's sample 45 (clock 4.5 s): it is supervised; the worst case left is
        // 15 samples at ψ̇max = 2, 0.1 s each: 3 s. The next stretch is robot 2's at 8 s.
        while ctl.ref_time_now()[0] < 45.0 {
            ctl.tick(Operator::Scheduled).unwrap();
        }
        let t = crate::tick_now(&ctl);
        let raw = RawFrame::from_controller(&t, &ctl, true);
        assert_eq!(raw.robots[0].state, RobotState::Lc);
        let a = g.attention(&raw).unwrap();
        assert_eq!(a.robot, 1);
        let r = raw.robots[0].ref_time;
        assert!((a.left_s - (60.0 - r) * 0.2).abs() < 1e-9, "{a:?} at {r}");
        // Robot 2's stretch at 8 s: at most twice the schedule's speed, its countdown is the
        // last whole tick before half the clock time left.
        let next = next_handover(&g, &raw).unwrap();
        assert_eq!(next.robot, 2);
        let p = ctl.pre_alert().unwrap();
        assert_eq!((p.robot + 1, p.earliest_s), (next.robot, next.in_s));
        let fastest = (8.0 - raw.robots[1].clock_s) / 2.0;
        assert!(
            next.in_s <= fastest + 1e-9 && next.in_s > fastest - 0.1 - 1e-9,
            "{next:?} against {fastest} s at the fastest"
        );
        assert!((next.in_s * 10.0 - (next.in_s * 10.0).round()).abs() < 1e-6);
        // The frame: one lc robot, the banner's robot, the pre-alert off (3.5 s > 7 s? no: on).
        let f = build_frame(&g, &raw);
        assert_eq!(
            f.robots
                .iter()
                .filter(|r| r.state == RobotState::Lc)
                .count(),
            1
        );
        assert_eq!(f.attention.as_ref().unwrap().robot, 1);
        assert!(f.prealert, "robot 2 in {} s ≤ 7 s", next.in_s);
        // Raised one tick early: at the last tick before the notice falls to the lead.
        // Raised early by one tick and one page frame (1/30 s): the notice on the first frame
        // that shows it is never below the lead.
        let early = 0.01 + 1.0 / 30.0;
        assert!(prealert_on(7.0 + early - 1e-9, 7.0, 0.01));
        assert!(!prealert_on(7.0 + early + 1e-9, 7.0, 0.01));
        assert!(prealert_on(6.0, 7.0, 0.01));
        assert_eq!(f.stretches[0].robot, 1);
        assert_eq!(f.stretches[0].start_s, 0.0);
        assert_eq!(f.stretches.len(), 3, "{:?}", f.stretches);
        // Robots finished in a round are done, and nothing is planned after.
        while !ctl.is_finished() {
            ctl.tick(Operator::Scheduled).unwrap();
        }
        let t = crate::tick_now(&ctl);
        let raw = RawFrame::from_controller(&t, &ctl, true);
        assert!(raw.robots[..3].iter().all(|r| r.state == RobotState::Done));
        assert!(next_handover(&g, &raw).is_none());
        assert!(build_frame(&g, &raw).stretches.is_empty());
    }

    #[test]
    fn the_queue_takes_one_stretch_at_a_time() {
        // A continuous cell of three robots on the same task: after one tick robot 1 runs
        // towards its stretch (planned at 4 s of its task) and robots 2 and 3 wait at their
        // gates with the same plan. The operator takes them one after the other: robot 1 at
        // 3.9 s, robot 2 when robot 1's ends (5.9 s), robot 3 at 7.9 s.
        let conf: Vec<bool> = (0..100).map(|k| !(40..60).contains(&k)).collect();
        let (g, lo, hi) = (vec![1.0; 100], vec![0.5; 100], vec![2.0; 100]);
        let task = Timeline::new(&conf, &g, &lo, &hi, 0.0, 0.1).unwrap();
        let order: Vec<(usize, usize)> = (0..3).map(|i| (i, 0)).collect();
        let mut ctl = AnyController::Continuous(
            tandem_realtime::ContinuousCoordinator::new(task, &[], &order, 3, 0.1).unwrap(),
        );
        let geometry = Geometry::new(&ctl);
        let t = ctl.tick(Operator::Scheduled).unwrap();
        let raw = RawFrame::from_controller(&t, &ctl, false);
        let states: Vec<_> = raw.robots[..3].iter().map(|r| r.state).collect();
        assert_eq!(states, [RobotState::Hc, RobotState::Wait, RobotState::Wait]);
        let q = geometry.stretches(&raw);
        let got: Vec<(usize, f64, f64)> = q
            .iter()
            .take(4)
            .map(|s| (s.robot, s.start_s, s.end_s))
            .collect();
        let want = [(1, 3.9, 5.9), (2, 5.9, 7.9), (3, 7.9, 9.9), (1, 13.9, 15.9)];
        for (g, w) in got.iter().zip(want) {
            assert_eq!(g.0, w.0, "{got:?}");
            assert!(
                (g.1 - w.1).abs() < 1e-9 && (g.2 - w.2).abs() < 1e-9,
                "{got:?}"
            );
        }
        // No two stretches of the queue overlap.
        assert!(
            q.windows(2).all(|w| w[1].start_s >= w[0].end_s - 1e-9),
            "{q:?}"
        );
        // The countdown is the coordinator's: a continuous cell's high-confidence robot runs
        // at the plan's pace, so robot 1 (clock 0.1 s) reaches its stretch at 4 s in the 39th
        // tick from now, which starts 38 ticks (3.8 s) from now.
        let next = next_handover(&geometry, &raw).unwrap();
        assert_eq!((next.robot, (next.in_s * 10.0).round()), (1, 38.0));
        assert_eq!(t.next.map(|p| p.earliest_s), Some(next.in_s));
    }
}
