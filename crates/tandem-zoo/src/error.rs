//! The crate's error type.

/// Everything that can go wrong in the zoo: an unknown family, a demonstration index out of
/// range, a generated task that breaks its own invariants (a bug, reported rather than
/// panicking), reading the generated CSV back, writing a task's folder.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// No family has this name.
    #[error("no task family named `{name}`; the families are: {}", known.join(", "))]
    UnknownFamily {
        /// The name asked for.
        name: String,
        /// Every family's name, in [`crate::families`] order.
        known: Vec<&'static str>,
    },
    /// A demonstration index past the task's demonstrations.
    #[error("demonstration {index} does not exist: the task has {n_demos} (0..{n_demos})")]
    DemoIndex {
        /// The index asked for.
        index: usize,
        /// How many demonstrations the task has.
        n_demos: usize,
    },
    /// A generator's description of a task is inconsistent (a family's definition is wrong).
    #[error("family `{family}`: {why}")]
    BadFamily {
        /// The family.
        family: &'static str,
        /// What is inconsistent.
        why: String,
    },
    /// The generated CSV did not read back through `tandem_lfd`'s loader, or a fit failed.
    #[error(transparent)]
    Lfd(#[from] tandem_lfd::Error),
    /// Writing a task's folder failed.
    #[error("{path}: cannot write: {source}")]
    Io {
        /// The file or folder.
        path: String,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// Encoding the truth file failed.
    #[error("truth.json: cannot encode: {0}")]
    Json(#[from] serde_json::Error),
    /// The evaluation's simulated rounds or cell failed ([`crate::eval`]).
    #[error(transparent)]
    Sim(#[from] tandem_sim::Error),
    /// The evaluation's planner failed ([`crate::eval`]).
    #[error(transparent)]
    Planner(#[from] tandem_planner::Error),
    /// The evaluation was asked for something it cannot do ([`crate::eval`]): what and why.
    #[error("zoo evaluation: {what}: {why}")]
    Eval {
        /// The parameter or task.
        what: String,
        /// What is wrong and how to fix it.
        why: String,
    },
}

/// The crate's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
