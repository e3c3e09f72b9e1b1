//! The control loop's side of the console: [`ConsoleHandle`] publishes each tick's snapshot
//! into a lock-free slot (a sequence lock over atomic words: the loop never waits, never
//! allocates; the server reads the newest snapshot and a snapshot it did not read in time is
//! dropped, never queued), and hands the operator's controls back through a bounded queue the
//! loop polls at its tick boundary ([`ConsoleHandle::poll_control`]), each confirmed with
//! [`ConsoleHandle::confirm`] into the frame stream.
//!
//! [`Driver`] is the loop-side rule of every control: it applies them at a tick boundary to a
//! [`ConsoleCell`] (any controller), so a user's loop is `driver.apply(..)`, tick unless
//! paused, `handle.publish(..)`.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering, fence};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError};
use std::time::{SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};
use tandem_planner::AnyController;
use tandem_realtime::{ContinuousCoordinator, Controller, Coordinator, MAX_ROBOTS, Tick};

use crate::frame::{Ack, Geometry, HEADER, ROBOT_WORDS, RawFrame, WORDS};
use crate::server::Update;

/// A single-writer sequence lock over the words of a [`RawFrame`]: the writer bumps the
/// sequence to odd, stores the words, bumps it to even; a reader retries while the sequence is
/// odd or changed under it. Safe code only (every word is an atomic).
#[derive(Debug)]
pub(crate) struct Slot {
    seq: AtomicU64,
    words: [AtomicU64; WORDS],
}

impl Slot {
    pub(crate) fn new() -> Slot {
        Slot {
            seq: AtomicU64::new(0),
            words: std::array::from_fn(|_| AtomicU64::new(0)),
        }
    }

    /// Writes `raw` (one writer at a time: [`ConsoleHandle`] is the only writer and takes
    /// `&mut self`). Wait-free.
    fn write(&self, raw: &RawFrame) {
        let mut buf = [0u64; WORDS];
        raw.encode(&mut buf);
        let s = self.seq.load(Ordering::Relaxed);
        self.seq.store(s.wrapping_add(1), Ordering::Relaxed);
        fence(Ordering::Release);
        // The words of the first `n` robots (a handle's `n` never changes).
        for (w, v) in self
            .words
            .iter()
            .zip(buf)
            .take(HEADER + ROBOT_WORDS * raw.n)
        {
            w.store(v, Ordering::Relaxed);
        }
        self.seq.store(s.wrapping_add(2), Ordering::Release);
    }

    /// The newest snapshot and the number of snapshots written so far, or `None` before the
    /// first. Lock-free: retries only while the writer is inside a write.
    pub(crate) fn read(&self) -> Option<(u64, RawFrame)> {
        loop {
            let s1 = self.seq.load(Ordering::Acquire);
            if s1 == 0 {
                return None;
            }
            if s1 % 2 == 1 {
                std::hint::spin_loop();
                continue;
            }
            let mut buf = [0u64; WORDS];
            for (b, w) in buf.iter_mut().zip(&self.words) {
                *b = w.load(Ordering::Relaxed);
            }
            fence(Ordering::Acquire);
            if self.seq.load(Ordering::Relaxed) == s1 {
                return Some((s1 / 2, RawFrame::decode(&buf)));
            }
        }
    }

    /// Snapshots written so far (a writer inside a write counts the one it writes).
    pub(crate) fn written(&self) -> u64 {
        self.seq.load(Ordering::Acquire).div_ceil(2)
    }
}

/// An operation of the operator (the `op` of a control message; docs/formats.md, "Console
/// controls").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Op {
    /// Become the controlling client (first to claim; the server answers it).
    Claim,
    /// Give control up (the server answers it).
    Release,
    /// Acknowledge the next handover (the operator has seen it).
    Acknowledge,
    /// Pause the cell when `robot` next waits at a hold point (rounds) or its gate (continuous
    /// cell): the run-time contract cannot hold one robot alone, so the whole cell pauses there.
    Hold,
    /// Clear the latched fault: the held robot moves again.
    ClearFault,
    /// Stop ticking at the next tick boundary.
    Pause,
    /// Tick again (also disarms a hold).
    Resume,
}

impl Op {
    /// Its text form.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Op::Claim => "claim",
            Op::Release => "release",
            Op::Acknowledge => "acknowledge",
            Op::Hold => "hold",
            Op::ClearFault => "clear_fault",
            Op::Pause => "pause",
            Op::Resume => "resume",
        }
    }
}

/// A control message the server accepted from the controlling client, for the loop.
#[derive(Clone, Debug, PartialEq)]
pub struct ControlMsg {
    /// The client that sent it.
    pub client: String,
    /// Its id (increasing per client).
    pub id: u64,
    /// What to do.
    pub op: Op,
    /// The robot (0-based) of a [`Op::Hold`].
    pub robot: Option<usize>,
}

/// What the server and the loop share: the slot, the server's request for a snapshot and the
/// counters.
#[derive(Debug)]
pub(crate) struct Shared {
    pub(crate) slot: Slot,
    /// Set by the server when it wants the next snapshot (at most `max_hz` times a second),
    /// cleared by the handle when it writes one: the loop's other ticks only count.
    pub(crate) want: AtomicBool,
    /// Control messages the server queued for the loop so far (the handle polls its queue only
    /// when this moved: one load per tick otherwise).
    pub(crate) controls_sent: AtomicU64,
    pub(crate) acks_lost: AtomicU64,
}

impl Shared {
    pub(crate) fn new() -> Shared {
        Shared {
            slot: Slot::new(),
            want: AtomicBool::new(true),
            controls_sent: AtomicU64::new(0),
            acks_lost: AtomicU64::new(0),
        }
    }
}

/// The control loop's end of a console ([`crate::Console::start`]).
#[derive(Debug)]
pub struct ConsoleHandle {
    shared: Arc<Shared>,
    controls: Receiver<ControlMsg>,
    acks: SyncSender<Ack>,
    /// The plan and notice updates to the server ([`ConsoleHandle::set_plan`]).
    updates: SyncSender<Update>,
    rounds: bool,
    n_robots: usize,
    can_hold: bool,
    /// Whether the loop has stopped ticking.
    paused: bool,
    /// The robot at whose next wait the cell pauses.
    hold_armed: Option<usize>,
    rounds_done: u64,
    /// Snapshots handed to [`ConsoleHandle::publish`] so far.
    published: u64,
    /// Control messages taken from the queue so far.
    controls_taken: u64,
    /// Whether the loop reports corrections ([`ConsoleHandle::publish_corrected`]).
    corrections_known: bool,
    /// Per robot, corrections in the execution `count_key` names.
    corrections: [u64; MAX_ROBOTS],
    /// Per robot, the execution its count is of: (rounds done, tasks done).
    count_key: [(u64, u64); MAX_ROBOTS],
    /// The robot the last tick's correction went to (a correction spans consecutive ticks).
    last_corrected: Option<usize>,
}

impl ConsoleHandle {
    pub(crate) fn new(
        shared: Arc<Shared>,
        controls: Receiver<ControlMsg>,
        acks: SyncSender<Ack>,
        updates: SyncSender<Update>,
        rounds: bool,
        n_robots: usize,
        can_hold: bool,
    ) -> ConsoleHandle {
        ConsoleHandle {
            shared,
            controls,
            acks,
            updates,
            rounds,
            n_robots,
            can_hold,
            paused: false,
            hold_armed: None,
            rounds_done: 0,
            published: 0,
            controls_taken: 0,
            corrections_known: false,
            corrections: [0; MAX_ROBOTS],
            count_key: [(0, 0); MAX_ROBOTS],
            last_corrected: None,
        }
    }

    /// The cell's plan changed (a controller that re-planned: the next round's schedule after a
    /// recorded one): the server builds the page's frames on `geometry` from its next period
    /// on (with the console's configured lead and horizon), and its strips start afresh. Give it
    /// before publishing the first tick of the new controller: snapshots the server reads in
    /// the same period are read on the new plan. Of the same cell and robots as the console's
    /// (the handle keeps its cell kind and robot count). Never blocks; `false` when the
    /// server's queue of updates is full (it is not taken then: give it again).
    pub fn set_plan(&mut self, geometry: Geometry) -> bool {
        self.updates
            .try_send(Update::Plan(Box::new(geometry)))
            .is_ok()
    }

    /// Sets (or clears, `None`) the notice every frame carries from the server's next period
    /// on, from the loop's side ([`Console::set_notice`](crate::Console::set_notice) from the
    /// console's owner); queued in order with [`set_plan`](Self::set_plan). Never blocks;
    /// `false` when the server's queue of updates is full (not taken then).
    pub fn set_notice(&mut self, notice: Option<String>) -> bool {
        self.updates.try_send(Update::Notice(notice)).is_ok()
    }

    /// Hands the snapshot of `ctl` after `tick` to the page. Lock-free and wait-free, never
    /// allocates, never blocks. Most ticks only count: the snapshot is taken (O(N), with the
    /// wall-clock stamp of [`RawFrame::published_unix_ms`]) only when the server has asked for
    /// one since the last (at most `max_hz` times a second); a snapshot the server has not read
    /// before the next one is dropped.
    pub fn publish<C: Controller + ?Sized>(&mut self, tick: &Tick, ctl: &C) {
        self.publish_inner(tick, ctl);
    }

    /// [`publish`](Self::publish) for a loop that knows its operator's input: `corrected`
    /// says whether the input of this tick was a correction (anything but
    /// `Operator::Scheduled`, or the loop's own joystick off its rest). It goes to the robot
    /// supervised in the tick (the first robot of `tick.low_conf`; none: it changed nothing and
    /// is not counted), and the page's strip shows each robot's corrections in its current
    /// execution: runs of consecutive corrected ticks on one robot, so one held correction
    /// counts once. Same costs as [`publish`](Self::publish): O(1) on an uncorrected tick,
    /// O(N) on a corrected one; never allocates.
    pub fn publish_corrected<C: Controller + ?Sized>(
        &mut self,
        tick: &Tick,
        ctl: &C,
        corrected: bool,
    ) {
        self.corrections_known = true;
        let to = if corrected {
            tick.low_conf.first().filter(|&i| i < MAX_ROBOTS)
        } else {
            None
        };
        if let Some(i) = to {
            let key = (self.rounds_done, tick.tasks[i]);
            if self.count_key[i] != key {
                self.count_key[i] = key;
                self.corrections[i] = 0;
            }
            if self.last_corrected != Some(i) {
                self.corrections[i] += 1;
            }
        }
        self.last_corrected = to;
        self.publish_inner(tick, ctl);
    }

    fn publish_inner<C: Controller + ?Sized>(&mut self, tick: &Tick, ctl: &C) {
        self.published += 1;
        if !self.shared.want.load(Ordering::Relaxed) {
            return;
        }
        self.shared.want.store(false, Ordering::Relaxed);
        let mut raw = RawFrame::from_controller(tick, ctl, self.rounds);
        raw.paused = self.paused;
        raw.hold_armed = self.hold_armed;
        raw.rounds_done = self.rounds_done;
        raw.published = self.published;
        raw.corrections_known = self.corrections_known;
        if self.corrections_known {
            for (i, r) in raw.robots.iter_mut().enumerate().take(raw.n) {
                // A count of an earlier execution is 0 of this one.
                if self.count_key[i] == (self.rounds_done, r.tasks) {
                    r.corrections = self.corrections[i];
                }
            }
        }
        raw.published_unix_ms = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0.0, |d| d.as_secs_f64() * 1e3);
        self.shared.slot.write(&raw);
    }

    /// Snapshots handed to [`publish`](Self::publish) so far.
    #[must_use]
    pub fn published(&self) -> u64 {
        self.published
    }

    /// Publishes a snapshot as it is (a replay's recorded tick): the same slot as
    /// [`publish`](Self::publish).
    pub(crate) fn publish_raw(&mut self, raw: &RawFrame) {
        self.shared.slot.write(raw);
    }

    /// The next control message the operator sent, if any (never blocks). Apply it at a tick
    /// boundary and [`confirm`](Self::confirm) it; [`Driver::apply`] does both. With no message
    /// waiting it costs one atomic load.
    pub fn poll_control(&mut self) -> Option<ControlMsg> {
        if self.shared.controls_sent.load(Ordering::Acquire) == self.controls_taken {
            return None;
        }
        let msg = self.controls.try_recv().ok()?;
        self.controls_taken += 1;
        Some(msg)
    }

    /// Confirms `msg` into the frame stream: `ok` whether it took effect, `message` what
    /// happened. Never blocks: a confirmation the server has no room for is counted lost
    /// ([`crate::Health::acks_lost`]).
    pub fn confirm(&mut self, msg: &ControlMsg, ok: bool, message: impl Into<String>) {
        let ack = Ack {
            client: msg.client.clone(),
            id: msg.id,
            op: msg.op.name().to_string(),
            ok,
            message: message.into(),
        };
        if let Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) = self.acks.try_send(ack)
        {
            self.shared.acks_lost.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Counts a finished round (rounds cells run round after round), shown on the page.
    pub fn round_done(&mut self) {
        self.rounds_done += 1;
    }

    /// Whether the loop should not tick now (paused, or a hold took effect).
    #[must_use]
    pub fn is_paused(&self) -> bool {
        self.paused
    }
}

/// A cell the console's controls act on: a controller, and how to clear its fault.
pub trait ConsoleCell {
    /// The controller (read only).
    fn controller(&self) -> &dyn Controller;
    /// Clears the latched fault ([`Controller::clear_fault`]).
    fn clear_fault(&mut self);
}

macro_rules! console_cell {
    ($($t:ty),*) => {$(
        impl ConsoleCell for $t {
            fn controller(&self) -> &dyn Controller {
                self
            }
            fn clear_fault(&mut self) {
                Controller::clear_fault(self);
            }
        }
    )*};
}
console_cell!(AnyController, Coordinator, ContinuousCoordinator);

impl ConsoleCell for Box<dyn Controller> {
    fn controller(&self) -> &dyn Controller {
        self.as_ref()
    }
    fn clear_fault(&mut self) {
        self.as_mut().clear_fault();
    }
}

/// The loop-side rule of the controls, applied at a tick boundary.
#[derive(Debug, Default)]
pub struct Driver;

impl Driver {
    /// Applies every control waiting in `handle`'s queue to `cell` and confirms each, then
    /// takes an armed hold into effect when its robot waits. Returns whether the loop may tick
    /// (not paused). Call it before each tick; it allocates only for a control message.
    pub fn apply(handle: &mut ConsoleHandle, cell: &mut impl ConsoleCell) -> bool {
        while let Some(msg) = handle.poll_control() {
            let (ok, text) = Self::one(handle, cell, &msg);
            handle.confirm(&msg, ok, text);
        }
        if let Some(k) = handle.hold_armed {
            if cell.controller().waiting_now()[k] {
                handle.hold_armed = None;
                handle.paused = true;
            }
        }
        !handle.paused
    }

    fn one(
        handle: &mut ConsoleHandle,
        cell: &mut impl ConsoleCell,
        msg: &ControlMsg,
    ) -> (bool, String) {
        match msg.op {
            Op::Claim | Op::Release => (true, "answered by the server".to_string()),
            Op::Acknowledge => (true, "handover acknowledged".to_string()),
            Op::Pause => {
                handle.paused = true;
                (true, "paused at a tick boundary".to_string())
            }
            Op::Resume => {
                handle.paused = false;
                handle.hold_armed = None;
                (true, "resumed".to_string())
            }
            Op::ClearFault => {
                if cell.controller().fault().is_some() {
                    cell.clear_fault();
                    (
                        true,
                        "fault cleared: the held robot moves again".to_string(),
                    )
                } else {
                    (false, "no fault is latched".to_string())
                }
            }
            Op::Hold => match msg.robot {
                Some(k) if k < handle.n_robots && handle.can_hold => {
                    handle.hold_armed = Some(k);
                    (
                        true,
                        format!(
                            "hold armed: the cell pauses when robot {} next waits at a hold \
                             point or gate (the run-time contract holds no single robot)",
                            k + 1
                        ),
                    )
                }
                Some(_) if !handle.can_hold => {
                    (false, "this plan has no hold points: use pause".to_string())
                }
                _ => (
                    false,
                    format!("hold needs a robot in 1..={}", handle.n_robots),
                ),
            },
        }
    }
}
