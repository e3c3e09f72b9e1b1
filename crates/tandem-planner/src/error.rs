//! The crate's error type.

use std::path::PathBuf;

/// Everything that can go wrong in `tandem-planner`: state files, execution records, and the
/// lower crates' errors.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A file system operation failed.
    #[error("{}: cannot {op}: {source}", path.display())]
    Io {
        /// The file or directory concerned.
        path: PathBuf,
        /// What was being done, e.g. "read state file".
        op: &'static str,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The file does not start with the state file's magic bytes.
    #[error("{}: not a tandem state file (missing magic bytes \"TANDEMST\")", path.display())]
    NotAStateFile {
        /// The file concerned.
        path: PathBuf,
    },
    /// The file was written by a build with another state format version.
    #[error(
        "{}: state format version {found}, this build reads versions {} to {expected} only ({})",
        path.display(),
        crate::state::OLDEST_READABLE_VERSION,
        version_advice(*found, *expected)
    )]
    UnsupportedVersion {
        /// The file concerned.
        path: PathBuf,
        /// The version in the file.
        found: u32,
        /// The newest version this build reads ([`crate::state::NEWEST_READABLE_VERSION`]).
        expected: u32,
    },
    /// The file is shorter than its header announces.
    #[error("{}: truncated state file: {found_bytes} bytes, expected {expected_bytes}", path.display())]
    Truncated {
        /// The file concerned.
        path: PathBuf,
        /// The length the header announces (bytes), or the header length if the header is cut.
        expected_bytes: u64,
        /// The actual length (bytes).
        found_bytes: u64,
    },
    /// The file has the right length but its content is damaged.
    #[error("{}: corrupt state file: {why}", path.display())]
    Corrupt {
        /// The file concerned.
        path: PathBuf,
        /// What is wrong (checksum, decoding, trailing bytes).
        why: String,
    },
    /// Another writer has held the state file's lock for longer than the caller waits.
    #[error(
        "{}: another process has been writing this state file for {waited_s:.0} s (lock file \
         {}): let it finish and try again; nothing was written",
        path.display(),
        lock_path.display()
    )]
    Locked {
        /// The state file.
        path: PathBuf,
        /// Its lock file.
        lock_path: PathBuf,
        /// How long this process waited, seconds.
        waited_s: f64,
    },
    /// A save would replace a file that is not a state file.
    #[error("{}: refusing to overwrite: {why}; give another file name", path.display())]
    WouldOverwrite {
        /// The file that would have been replaced.
        path: PathBuf,
        /// What it is.
        why: String,
    },
    /// The state file changed on disk since this planner was loaded from it (another process
    /// saved into it): saving would lose what that process recorded.
    #[error(
        "{}: the state file changed since this planner was loaded from it (another process \
         saved into it); nothing was written: load it again and repeat the change, or save \
         this planner under another name",
        path.display()
    )]
    Changed {
        /// The state file.
        path: PathBuf,
    },
    /// A save would replace a state file holding recorded rounds that this planner does not
    /// hold (a fresh fit saved over a cell's state): the operator's corrections would be lost.
    #[error(
        "{}: holds {rounds} recorded round(s) (the operator's corrections) that this planner \
         does not hold; nothing was written: refit keeping them (`tandem fit --keep-rounds`, \
         Python `Planner.refit`), save under another name, or replace the file and discard them \
         on purpose (`tandem fit --force`, Python `save(path, force=True)`)",
        path.display()
    )]
    WouldDiscardRounds {
        /// The state file.
        path: PathBuf,
        /// Rounds it holds.
        rounds: usize,
    },
    /// A refit cannot replay the recorded rounds ([`crate::Planner::refit`]).
    #[error(
        "cannot keep the recorded rounds: {why}; nothing was written: keep the state as it is, \
         or fit without the rounds on purpose (`tandem fit --force`, Python \
         `save(path, force=True)`)"
    )]
    CannotReplay {
        /// What cannot be replayed and why.
        why: String,
    },
    /// The round was recorded before (the same executions, logs and flags).
    #[error(
        "this round was already recorded as round {round} (the same executions, logs and \
         flags): nothing was recorded; record each round once"
    )]
    DuplicateRound {
        /// The earlier round (1-based).
        round: usize,
    },
    /// An execution record is malformed.
    #[error("bad execution record: `{what}`: {why}")]
    BadExecution {
        /// Which part.
        what: &'static str,
        /// What is wrong.
        why: String,
    },
    /// A hold point declared inside a low-confidence stretch that the recorded corrections
    /// show needs the operator (`LowCause::Corrections`).
    #[error(
        "{hold} falls at {at_s:.3} s (reference time), inside the low-confidence stretch \
         {start_s:.3}–{end_s:.3} s, which the operator corrected ({corrections:.0} corrections \
         in {supervised:.0} supervised samples, more than their false corrections explain): a \
         robot must not wait where the operator is needed; declare the hold before or after \
         that stretch"
    )]
    HoldInLowConfidence {
        /// The declaration (`the hold at 3.2 s`, ``the hold rule `tool<0.5` ``).
        hold: String,
        /// Reference time of the refused hold sample, seconds.
        at_s: f64,
        /// Start of the stretch (reference time, s, inclusive).
        start_s: f64,
        /// End of the stretch (reference time, s, exclusive).
        end_s: f64,
        /// Corrected observation mass in the stretch (control samples).
        corrections: f64,
        /// Supervised observation mass in the stretch (control samples).
        supervised: f64,
    },
    /// A hold rule that holds on no reference sample of the task (after the start).
    #[error("hold rule `{rule}` holds nowhere in the task ({why}): change its threshold")]
    HoldMatchesNothing {
        /// The rule as written.
        rule: String,
        /// What the channel does instead.
        why: String,
    },
    /// Parts of a loaded state do not fit together.
    #[error("inconsistent state: `{what}`: {why}")]
    Inconsistent {
        /// Which part.
        what: &'static str,
        /// What is wrong.
        why: String,
    },
    /// A cell kind that is neither `rounds` nor `continuous` ([`crate::Cell`]).
    #[error("unknown cell `{given}`: give `rounds` or `continuous`")]
    UnknownCell {
        /// The name given.
        given: String,
    },
    /// A fleet cell that is none of `auto`, `pooled`, `sectored` ([`crate::FleetCell`]).
    #[error("unknown fleet cell `{given}`: give `auto`, `pooled` or `sectored`")]
    UnknownFleetCell {
        /// The name given.
        given: String,
    },
    /// A state file of format 12 (a cell of several tasks, [`crate::CellPlanner`]) given
    /// where one task's planner is expected.
    #[error(
        "{}: this state file holds a cell of {} tasks ({}), not one task's planner: load it as a \
         cell (`CellPlanner::load`, Python's `tandem.CellPlanner.load`; on the command line \
         `tandem inspect`, `tandem schedule` and `tandem record` read cells), or fit one task into its own state file",
        path.display(),
        tasks.len(),
        tasks.join(", ")
    )]
    CellFile {
        /// The state file.
        path: PathBuf,
        /// The cell's task names, in order.
        tasks: Vec<String>,
    },
    /// A cell of task models that cannot be built or used as asked ([`crate::CellPlanner`]):
    /// a task name, a robot map, a round's size, a parameter mixed cells do not support yet.
    #[error("cell of tasks: {what}: {why}")]
    BadCell {
        /// Which part (a task's name, `robots`, `executions`, a parameter).
        what: String,
        /// What is wrong and the fix.
        why: String,
    },
    /// Demonstrations, executions or the task model (§II-B1/2), alignment included.
    #[error(transparent)]
    Lfd(#[from] tandem_lfd::Error),
    /// Confidence (§II-B3).
    #[error(transparent)]
    Confidence(#[from] tandem_confidence::Error),
    /// Real-time coordination (§II-B5): the coordinator of the current schedule.
    #[error(transparent)]
    Realtime(#[from] tandem_realtime::Error),
    /// Scheduling (§II-B4/6).
    #[error(transparent)]
    Schedule(#[from] tandem_schedule::Error),
    /// The state could not be serialized.
    #[error("cannot encode state: {source}")]
    Encode {
        /// The serializer's error.
        source: postcard::Error,
    },
}

/// What to do about a state file of format `found` in a build that reads `expected`.
fn version_advice(found: u32, expected: u32) -> &'static str {
    if found < expected {
        "written by an older build: fit again with this build, or keep using the build that wrote it"
    } else {
        "written by a newer build: use that build"
    }
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
