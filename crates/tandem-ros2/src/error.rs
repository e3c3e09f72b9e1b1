//! The crate's one error type.

/// What went wrong starting or running a ROS 2 node.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is out of its range.
    #[error("parameter `{name}` {why}")]
    BadParam {
        /// The parameter.
        name: &'static str,
        /// What is wrong and the fix.
        why: String,
    },
    /// The state file plans another number of robots than the node was asked to run.
    #[error(
        "the state file plans {state} robots but --robots {given} was given; leave --robots out \
         or give {state}"
    )]
    RobotCount {
        /// Robots of the state file's schedule.
        state: usize,
        /// Robots asked for.
        given: usize,
    },
    /// The DDS layer (ros2-client on RustDDS) refused to create or use an entity.
    #[error("DDS: cannot {what}: {why}")]
    Dds {
        /// What was being done (names the topic or service).
        what: String,
        /// The library's message.
        why: String,
    },
    /// A thread of the node could not be started or ended in a panic.
    #[error("node thread `{name}`: {why}")]
    Thread {
        /// The thread.
        name: &'static str,
        /// What happened.
        why: String,
    },
    /// The planner or its state file.
    #[error(transparent)]
    Planner(#[from] tandem_planner::Error),
    /// The run-time coordinator.
    #[error(transparent)]
    Realtime(#[from] tandem_realtime::Error),
    /// The operator console (`--console`): its settings or its address.
    #[error("the console: {0}")]
    Console(#[from] tandem_console::Error),
    /// The task model.
    #[error(transparent)]
    Lfd(#[from] tandem_lfd::Error),
    /// The stage trace ([`crate::NodeParams::stage_trace`]) could not be written.
    #[error("cannot write the stage trace {}: {why}; give a path in a writable folder", path.display())]
    Trace {
        /// The file.
        path: std::path::PathBuf,
        /// The OS's message.
        why: String,
    },
}

/// The crate's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// An [`Error::Dds`] for `what` from any library error.
pub(crate) fn dds(what: impl Into<String>, e: impl std::fmt::Debug) -> Error {
    Error::Dds {
        what: what.into(),
        why: format!("{e:?}"),
    }
}
