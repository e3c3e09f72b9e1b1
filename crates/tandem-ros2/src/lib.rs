//! tandem as a live ROS 2 node (issue 43): a planner's coordinator ticking on its own thread
//! at the schedule's tick, the ROS 2 graph on another (the pure-Rust `ros2-client` on RustDDS,
//! pinned and wrapped here: no ROS install), joined by bounded queues that the tick thread
//! only ever uses without waiting. A robot that stops reporting is a fault the loop holds the
//! cell on, never a blocked tick.
//!
//! - [`core`]: the control loop without the network ([`CellLoop`]), testable alone;
//! - [`node`]: the threads and the topics and services ([`Node`]; the table is in its docs);
//! - [`console`]: the tick thread's feed of an operator console ([`ConsoleFeed`]);
//! - [`msg`]: the standard message types, as serde structs;
//! - [`pose`]: which of the model's channels form the setpoint's pose;
//! - [`link`]: the tick thread's wait-free links to the DDS thread (commands, state, progress);
//! - [`probe`]: a client of the node over DDS (robots, operator, services) for tests.

pub mod console;
pub mod core;
mod error;
pub mod link;
pub mod msg;
pub mod node;
pub mod pose;
pub mod probe;

pub use crate::core::{
    CellLoop, Command, Inbound, LoopParams, NodeFault, Reply, Request, RoundLog, Snapshot,
};
pub use console::{ConsoleFeed, FINISHED_NOTICE, IDLE_NOTICE, rest_notice};
pub use error::{Error, Result};
pub use node::{Node, NodeParams, NodeStats, Priority, set_thread_nice};
pub use pose::{PoseChannels, PoseMap};
pub use probe::Probe;
