//! The crate's error type.

/// Everything that can go wrong in `tandem-sim`: the task generator ([`crate::task`]), the
/// simulated workcell ([`crate::workcell`]) and the study ([`crate::study`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A parameter is out of its documented range.
    #[error("parameter `{name}` {why}")]
    BadParam {
        /// Name of the offending field (e.g. `"n_sections"`).
        name: &'static str,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A workpiece does not match the task parameters (wrong number of passes or sections).
    #[error("workpiece: {why} (pass {pass}: expected {expected}, found {found})")]
    BadWorkpiece {
        /// What is wrong.
        why: &'static str,
        /// 1-based pass the problem was found in (0 when it concerns the number of passes).
        pass: usize,
        /// Expected count.
        expected: usize,
        /// Count found.
        found: usize,
    },
    /// A demonstration would exceed [`crate::task::MAX_SAMPLES`] samples.
    #[error("demonstration exceeds {limit} samples (speeds too low for the plate length?)")]
    TooLong {
        /// The limit that was hit, in samples.
        limit: usize,
    },
    /// Workcell: two inputs that must agree in size do not.
    #[error("{what}: expected {expected}, found {found}")]
    Mismatch {
        /// What was compared.
        what: &'static str,
        /// The size required.
        expected: usize,
        /// The size given.
        found: usize,
    },
    /// Workcell: the model has no channel of the name the operator corrects.
    #[error(
        "the task model has no channel `{name}` for the simulated operator to correct (its \
         channels: {channels}): name one of them (`--channel NAME` of `tandem simulate` and \
         `tandem console`, `OperatorParams::force_channel`)"
    )]
    NoForceChannel {
        /// The channel asked for.
        name: String,
        /// The model's tangent coordinates, comma-separated.
        channels: String,
    },
    /// Workcell: the robots did not finish within the tick budget (a bug or a degenerate
    /// schedule).
    #[error("the round did not finish within {ticks} control ticks")]
    DidNotFinish {
        /// The tick budget.
        ticks: usize,
    },
    /// Workcell: the schedule was checked at a control tick other than the workcell's period
    /// (one tick per reference sample period `Δt_s`); running it would void its margin check.
    #[error(
        "the schedule was checked at a control tick of {schedule_tick_s} s but the workcell \
         runs one tick per reference sample period, {workcell_tick_s} s: re-schedule at that tick"
    )]
    TickMismatch {
        /// The schedule's tick (`Schedule::tick_s`, real s).
        schedule_tick_s: f64,
        /// The workcell's control period (`Δt_s`, real s).
        workcell_tick_s: f64,
    },
    /// Study: an input file or data set is unusable.
    #[error("{}: {why}", path.display())]
    BadInput {
        /// The file or folder concerned (or a description such as `<study inputs>`).
        path: std::path::PathBuf,
        /// What is wrong.
        why: String,
    },
    /// Need profile (`crate::needs`): a region, level or need-file row is unusable.
    #[error("{at}: {why}")]
    Need {
        /// Where: `file:line:column` of a need file, or `region K (…)` of a region list.
        at: String,
        /// What is wrong and how to fix it.
        why: String,
    },
    /// Study: a stage failed in a trial's round; says where, wraps what.
    #[error("trial {trial}, round {round}: {source}")]
    InTrial {
        /// Trial index `k` (0-based).
        trial: usize,
        /// The round (1-based) whose run or record failed.
        round: usize,
        /// The stage's error.
        #[source]
        source: Box<Error>,
    },
    /// Workcell and study: the task model (commands, corrections, executions, the fit).
    #[error(transparent)]
    Lfd(#[from] tandem_lfd::Error),
    /// Study: the planner (model update, confidence, re-scheduling; Fig. 2).
    #[error(transparent)]
    Planner(#[from] tandem_planner::Error),
    /// Workcell: timelines or the coordinator.
    #[error(transparent)]
    Realtime(#[from] tandem_realtime::Error),
    /// Workcell: the schedule cannot be laid out on the problem (a robot's timeline).
    #[error(transparent)]
    Schedule(#[from] tandem_schedule::Error),
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
