//! The node's operator console (issue 43, "the console and the node share one source"): the
//! tick thread hands each tick to a [`tandem_console::ConsoleHandle`] (a counter per tick, a
//! snapshot into its sequence lock only when the console's server asks: wait-free, never
//! blocking), so the page shows the live node: the same controller, the same tick.
//!
//! The node's cell is driven through its ROS 2 services, so the console shows it and does not
//! steer it: the page's controls are confirmed as refused, naming the service to call instead
//! (two places steering one cell, one of them unseen by the ROS 2 graph, would each surprise
//! the other).

use tandem_console::{ConsoleHandle, ControlMsg, Op};

use crate::core::CellLoop;

/// The tick thread's end of a console.
#[derive(Debug)]
pub struct ConsoleFeed {
    handle: ConsoleHandle,
    finished: bool,
    /// The loop's plan generation the page shows ([`CellLoop::plan_generation`]).
    generation: u64,
    /// The loop's state the page's notice says (`None` before the first publish).
    shown: Option<Phase>,
}

/// What the page's notice says of the node's cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Nothing runs and no round waits to be recorded.
    Idle,
    /// A finished round waits to be recorded (or a new one to start).
    Finished,
    /// The operator's rest after a round (the load cap, [`CellLoop::rest_left_ticks`]): whole
    /// seconds left, rounded up; whether the round waits to be recorded.
    Resting {
        /// The rest left (s, rounded up).
        left_s: u64,
        /// Whether a finished round waits to be recorded.
        finished: bool,
    },
    /// A round (or the cell) runs: no notice.
    Running,
}

impl Phase {
    fn of(cell_loop: &CellLoop) -> Phase {
        if cell_loop.is_active() {
            Phase::Running
        } else if cell_loop.rest_left_ticks() > 0 {
            Phase::Resting {
                left_s: cell_loop.rest_left_s().ceil() as u64,
                finished: cell_loop.is_finished(),
            }
        } else if cell_loop.is_finished() {
            Phase::Finished
        } else {
            Phase::Idle
        }
    }

    /// The page's notice.
    fn notice(self) -> Option<String> {
        match self {
            Phase::Idle => Some(IDLE_NOTICE.to_owned()),
            Phase::Finished => Some(FINISHED_NOTICE.to_owned()),
            Phase::Resting { left_s, finished } => Some(rest_notice(left_s, finished)),
            Phase::Running => None,
        }
    }
}

/// The page's notice during the operator's rest after a round (issue 41: the load cap
/// `max_busy_share` of the state file): `rest: N s` (whole seconds, rounded up, so the page
/// never shows less than is left), then what may be done meanwhile. It changes once a second
/// (a new notice, so one allocation a second on the tick thread while the rest lasts).
#[must_use]
pub fn rest_notice(left_s: u64, finished: bool) -> String {
    if finished {
        format!(
            "rest: {left_s} s before the next round (the operator's load cap) — record the \
             round with /tandem/record_round; /tandem/start_round is refused until then"
        )
    } else {
        format!(
            "rest: {left_s} s before the next round (the operator's load cap) — \
             /tandem/start_round is refused until then"
        )
    }
}

/// The page's notice while nothing runs (before the first `start_round`, after `stop_round`,
/// after a recorded round).
pub const IDLE_NOTICE: &str = "idle — waiting for start_round (service /tandem/start_round)";
/// The page's notice while a finished round waits.
pub const FINISHED_NOTICE: &str = "round finished — record it with /tandem/record_round, or start the \
                            next with /tandem/start_round";

impl ConsoleFeed {
    /// Feeds `handle` (of a [`tandem_console::Console`] started on the loop's controller's
    /// [`Geometry`](tandem_console::Geometry)).
    #[must_use]
    pub fn new(handle: ConsoleHandle) -> ConsoleFeed {
        ConsoleFeed {
            handle,
            finished: false,
            generation: 0,
            shown: None,
        }
    }

    /// After each [`CellLoop::step`] or [`CellLoop::advance`]: answers the page's controls,
    /// counts a finished round, hands the page a replaced controller's plan
    /// ([`CellLoop::plan`]) before its first tick, says on the page whether the cell is idle
    /// ([`IDLE_NOTICE`]), a round waits ([`FINISHED_NOTICE`]) or the operator rests
    /// ([`rest_notice`]), and publishes the loop's last tick. Never
    /// blocks; allocates only to answer a control message, and when the plan or the cell's
    /// state changed.
    pub fn publish(&mut self, cell_loop: &CellLoop) {
        let generation = cell_loop.plan_generation();
        if generation != self.generation {
            // A full queue of updates: given again at the next tick.
            if cell_loop
                .plan()
                .is_none_or(|g| self.handle.set_plan(g.clone()))
            {
                self.generation = generation;
            }
        }
        let phase = Phase::of(cell_loop);
        if self.shown != Some(phase) && self.handle.set_notice(phase.notice()) {
            self.shown = Some(phase);
        }
        let finished = cell_loop.is_finished();
        while let Some(msg) = self.handle.poll_control() {
            let (ok, text) = answer(&msg);
            self.handle.confirm(&msg, ok, text);
        }
        if finished && !self.finished {
            self.handle.round_done();
        }
        self.finished = finished;
        self.handle
            .publish(cell_loop.last_tick(), cell_loop.controller());
    }

    /// Ticks handed to the console so far.
    #[must_use]
    pub fn published(&self) -> u64 {
        self.handle.published()
    }
}

/// What a control of the page gets from a node: claiming and acknowledging work, steering is
/// the services' (the message names the one to call).
fn answer(msg: &ControlMsg) -> (bool, &'static str) {
    match msg.op {
        Op::Claim | Op::Release => (true, "answered by the server"),
        Op::Acknowledge => (true, "handover acknowledged"),
        Op::ClearFault => (
            false,
            "this console shows a ROS 2 node: call its service /tandem/clear_fault",
        ),
        Op::Pause | Op::Hold => (
            false,
            "this console shows a ROS 2 node: call its service /tandem/stop_round",
        ),
        Op::Resume => (
            false,
            "this console shows a ROS 2 node: call its service /tandem/start_round",
        ),
    }
}
