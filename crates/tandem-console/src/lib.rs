//! The operator's console (issue 42): a web page that tells one person which robot needs
//! them now (the red indicator of the paper's Fig. 1), and which will next, fed live by a
//! control loop.
//!
//! - [`Console::start`] serves one static page (no external resource: it works in a cell
//!   without internet) on 127.0.0.1 by default, the state as server-sent events, the
//!   operator's controls by POST (docs/formats.md, "The operator's console").
//! - [`ConsoleHandle`] is the loop's side: [`ConsoleHandle::publish`] after each tick
//!   (lock-free, allocation-free, never blocking: a slow page drops frames, the robot is never
//!   delayed) and the controls back through a bounded queue the loop polls
//!   ([`Driver::apply`] at a tick boundary).
//! - [`simulate`] runs a simulated cell from a planner in real time through the same handle
//!   (`tandem console STATE --simulate`).
//! - [`replay`] plays a recorded run ([`Recorder`], [`read_recording`]; `tandem console
//!   --replay FILE|DIR`) through the same server and page; [`check_recording`] measures what
//!   the page showed against the coordinator on every tick.
//! - [`read_run_bag`] rebuilds a run bag's ticks (`tandem simulate --bag`) against the state
//!   file's plan as a recording (`tandem console STATE --replay RUN.mcap`).
//! - [`Tracker`] derives the page's per-robot and operator strips from successive snapshots.
//! - [`Frame`] is what the page receives; the page's machine-checkable DOM
//!   (`data-robot`, `data-state`, `data-attention`, `data-next-robot`, `data-next-s`) is
//!   documented in docs/formats.md.

mod error;
mod frame;
mod handle;
mod replay;
mod run_bag;
mod server;
mod sim;
mod strip;

pub use error::{Error, Result};
pub use frame::{
    Ack, Attention, DEFAULT_HORIZON_S, DEFAULT_LEAD_S, Frame, Geometry, Health, NextHandover,
    RawFrame, RawRobot, RobotFrame, RobotState, Stretch, build_frame, next_handover,
};
pub use handle::{ConsoleCell, ConsoleHandle, ControlMsg, Driver, Op};
pub use replay::{
    RECORDING_FILE, RECORDING_FORMAT, RECORDING_HZ, RECORDING_VERSION, RecordedPreAlert,
    RecordedRobot, RecordedTick, Recorder, Recording, ReplayCheck, check_recording, looks_like_bag,
    read_recording, replay,
};
pub use run_bag::{read_run_bag, recording_from_rounds};
pub use server::{Console, ConsoleConfig, PAGE};
pub use sim::{SimParams, Until, record_sim, rest_notice, simulate, simulate_recorded, tick_now};
pub use strip::{OperatorStrip, RobotStrip, Tracker};
