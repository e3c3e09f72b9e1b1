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
}

impl ConsoleFeed {
    /// Feeds `handle` (of a [`tandem_console::Console`] started on the loop's controller's
    /// [`Geometry`](tandem_console::Geometry)).
    #[must_use]
    pub fn new(handle: ConsoleHandle) -> ConsoleFeed {
        ConsoleFeed {
            handle,
            finished: false,
        }
    }

    /// After each [`CellLoop::step`] or [`CellLoop::advance`]: answers the page's controls,
    /// counts a finished round, and publishes the loop's last tick. Never blocks; allocates
    /// only to answer a control message.
    pub fn publish(&mut self, cell_loop: &CellLoop) {
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
