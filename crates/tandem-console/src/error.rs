//! The console's one error type.

/// What can go wrong starting or feeding a console.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The server could not listen where asked.
    #[error(
        "cannot listen on {addr}: {source} (is another console on that port? `--port 0` picks a free one)"
    )]
    Bind {
        /// The address asked for.
        addr: String,
        /// The system's error.
        source: std::io::Error,
    },
    /// The server's runtime could not start.
    #[error("cannot start the console's server: {0}")]
    Runtime(std::io::Error),
    /// A parameter out of range.
    #[error("console parameter `{name}` {why}")]
    BadParam {
        /// The parameter.
        name: &'static str,
        /// What it must be.
        why: &'static str,
    },
    /// A console recording (a replay's file) could not be read or written.
    #[error("{path}: {why}")]
    Recording {
        /// The file, with `:LINE` where one line is at fault.
        path: String,
        /// What is wrong and what to do.
        why: String,
    },
    /// The planner could not make the cell's plan or controller.
    #[error(transparent)]
    Planner(#[from] tandem_planner::Error),
    /// The simulated cell failed.
    #[error(transparent)]
    Sim(#[from] tandem_sim::Error),
}

/// The console's result.
pub type Result<T, E = Error> = std::result::Result<T, E>;
