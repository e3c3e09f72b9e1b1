//! The crate's error type and the Python exceptions it becomes.
//!
//! Every Rust error becomes a subclass of `tandem.TandemError`:
//!
//! | exception | raised for | attributes |
//! |---|---|---|
//! | `InputError` | demonstrations, executions, arrays, CSV/JSON files, ROS 2 bags, labels, operator input | `file`, `line`, `column` (`None` where unknown; `file` is the argument, e.g. `demos[2]`, for an array) |
//! | `ParamError` | a parameter out of range, an unknown or ill-typed key | `name` |
//! | `StateFileError` | a state file that is missing, foreign, truncated, corrupt, of another version, inconsistent, or cannot be written | `path` |
//! | `ScheduleError` | an infeasible problem, a schedule that violates Eq. 20, a schedule run at another tick, an operator order the continuous coordinator cannot run | `violation` (the broken rule's name, `NotRunnable`, or `None`) |
//! | `InternalError` | a panic caught at the boundary: a bug in tandem, never the user's input | — |
//!
//! A Rust panic never unwinds into Python: [`guard`] turns it into an `InternalError`.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;

use pyo3::exceptions::{PyException, PyUserWarning};
use pyo3::prelude::*;

use crate::facade::{TandemError as Facade, Violation, errors};

pyo3::create_exception!(
    tandem,
    TandemError,
    PyException,
    "Base class of every error tandem raises (never a panic or an abort)."
);
pyo3::create_exception!(
    tandem,
    InputError,
    TandemError,
    "Bad input data: a demonstration, execution, array, CSV/JSON file, labels or operator input.\n\n\
     Attributes: ``file`` (the file, or the argument such as ``demos[2]`` for an array),\n\
     ``line`` and ``column`` (1-based), each ``None`` where unknown."
);
pyo3::create_exception!(
    tandem,
    ParamError,
    TandemError,
    "A parameter out of its documented range, or an unknown or ill-typed key.\n\n\
     Attribute: ``name`` (the parameter, or ``None``)."
);
pyo3::create_exception!(
    tandem,
    StateFileError,
    TandemError,
    "A state file that is missing, foreign, truncated, corrupt, of another format version,\n\
     inconsistent, or cannot be written. The file on disk is left as it was.\n\n\
     Attribute: ``path``."
);
pyo3::create_exception!(
    tandem,
    ScheduleError,
    TandemError,
    "An infeasible scheduling problem, a schedule that violates Eq. 20, a schedule run at\n\
     another control tick than the one its margins were checked at, or an operator order the\n\
     continuous coordinator cannot run.\n\n\
     Attribute: ``violation`` (name of the broken rule, e.g. ``GradientOutOfBounds``, or ``None``)."
);
pyo3::create_exception!(
    tandem,
    DataWarning,
    PyUserWarning,
    "Data that was taken in, but not as given or not without doubt: a file without a time\n\
     column (the sample period it was assumed to have), an execution resampled to the model's\n\
     period, a demonstration of unusual length, a stored schedule that failed this build's\n\
     check and was replaced on load. The message names the file and the fix."
);
pyo3::create_exception!(
    tandem,
    InternalError,
    TandemError,
    "A bug in tandem (a Rust panic caught at the Python boundary), never the user's input."
);

/// Everything that can go wrong in the bindings: the facade's and the lower crates' errors,
/// a schedule that violates Eq. 20, and the bindings' own checks of Python arguments.
#[derive(Debug, thiserror::Error)]
pub(crate) enum Error {
    /// The planner and its state file, and the crates below it.
    #[error(transparent)]
    Tandem(#[from] Facade),
    /// Demonstrations and the task model, called directly.
    #[error(transparent)]
    Lfd(#[from] errors::Lfd),
    /// Time warping, called directly.
    #[error(transparent)]
    Warp(#[from] errors::Warp),
    /// Confidence, called directly.
    #[error(transparent)]
    Confidence(#[from] errors::Confidence),
    /// The real-time coordinator, called directly.
    #[error(transparent)]
    Realtime(#[from] errors::Realtime),
    /// Scheduling, called directly.
    #[error(transparent)]
    Schedule(#[from] errors::Schedule),
    /// The simulated workcell, called directly.
    #[error(transparent)]
    Sim(#[from] errors::Sim),
    /// ROS 2 bags.
    #[error(transparent)]
    Bag(#[from] errors::Bag),
    /// A schedule breaks a constraint of Eq. 20.
    #[error("the schedule violates Eq. 20: {0}")]
    Violation(Violation),
    /// A schedule of the user's own was given to a coordinator before it was checked.
    #[error(
        "this schedule has not been checked: call schedule.validate() first (it checks every \
         constraint of Eq. 20, the margin check included); a coordinator runs only a schedule \
         this build has checked"
    )]
    Unchecked,
    /// A Python argument has the wrong type, shape, dtype or value.
    #[error("{what}: {why}")]
    Input {
        /// The argument, e.g. `demos[2]`, or a file.
        what: String,
        /// What is wrong.
        why: String,
        /// The file, when the argument is one.
        file: Option<String>,
    },
    /// A parameter (dictionary or TOML file) is malformed or out of range.
    #[error("{what}: {why}")]
    Param {
        /// Where: `params`, a file, or a key.
        what: String,
        /// What is wrong.
        why: String,
    },
    /// A Rust panic caught at the boundary.
    #[error("internal error (a bug in tandem, please report it): {0}")]
    Panic(String),
}

/// Result alias of the bindings.
pub(crate) type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// An [`Error::Input`] about argument `what` (not a file).
    pub(crate) fn input(what: impl Into<String>, why: impl Into<String>) -> Self {
        Error::Input {
            what: what.into(),
            why: why.into(),
            file: None,
        }
    }

    /// This error with the task it is about (`task "sanding", demos[2]`) put before the
    /// argument it names, for the per-task arguments of a cell of tasks; other errors name
    /// their file or parameter themselves and are returned as they are.
    pub(crate) fn in_task(self, task: &str) -> Self {
        match self {
            Error::Input { what, why, file } => Error::Input {
                what: format!("task {task:?}, {what}"),
                why,
                file,
            },
            other => other,
        }
    }

    /// An [`Error::Param`] about `what`.
    pub(crate) fn param(what: impl Into<String>, why: impl Into<String>) -> Self {
        Error::Param {
            what: what.into(),
            why: why.into(),
        }
    }
}

/// Which exception an error becomes, and its attributes.
enum Kind {
    Input {
        file: Option<String>,
        line: Option<usize>,
        column: Option<usize>,
    },
    Param {
        name: Option<String>,
    },
    StateFile {
        path: PathBuf,
    },
    Schedule {
        violation: Option<String>,
    },
    Internal,
}

/// An input error without a known position.
fn input_at(file: Option<&str>) -> Kind {
    Kind::Input {
        file: file.map(str::to_owned),
        line: None,
        column: None,
    }
}

/// An input error at `file:line:column`.
fn located(file: &str, line: usize, column: usize) -> Kind {
    Kind::Input {
        file: Some(file.to_owned()),
        line: Some(line),
        column: Some(column),
    }
}

/// An input error at a location given as text: `file:line:column` (a file read from disk,
/// [`errors::Lfd::TooFewSamples`]) split into its parts, so that `InputError.file` is the
/// path and `.line`/`.column` are set; any other label (`demos[1]`) is the file alone.
fn split_location(at: &str) -> Kind {
    let mut parts = at.rsplitn(3, ':');
    if let (Some(column), Some(line), Some(file)) = (parts.next(), parts.next(), parts.next())
        && let (Ok(line), Ok(column)) = (line.parse::<usize>(), column.parse::<usize>())
    {
        return located(file, line, column);
    }
    input_at(Some(at))
}

fn param(name: &str) -> Kind {
    Kind::Param {
        name: Some(name.to_owned()),
    }
}

const SCHEDULE: Kind = Kind::Schedule { violation: None };

fn classify_warp(e: &errors::Warp) -> Kind {
    match e {
        errors::Warp::BadParam { name, .. } => param(name),
        errors::Warp::InfeasibleSlopes { slope_min, .. } if *slope_min > 1.0 => param("slope_min"),
        errors::Warp::InfeasibleSlopes { .. } => param("slope_max"),
        _ => input_at(None),
    }
}

fn classify_lfd(e: &errors::Lfd) -> Kind {
    use errors::Lfd as E;
    match e {
        E::BadHeader {
            file, line, column, ..
        }
        | E::RaggedRow {
            file, line, column, ..
        }
        | E::NotNumeric {
            file, line, column, ..
        }
        | E::NonFinite {
            file, line, column, ..
        }
        | E::TooLarge {
            file, line, column, ..
        }
        | E::BadTime {
            file, line, column, ..
        }
        | E::Json {
            file, line, column, ..
        } => located(file, *line, *column),
        E::EmptyFile { file } => located(file, 1, 1),
        E::Separator { file, line, .. } => located(file, *line, 1),
        E::TimeLikeChannel {
            file, line, column, ..
        }
        | E::ChannelMismatch {
            file, line, column, ..
        }
        | E::ReservedChannelName {
            file, line, column, ..
        }
        | E::SamplePeriodMismatch {
            file, line, column, ..
        } => Kind::Input {
            file: Some(file.clone()),
            line: *line,
            column: *column,
        },
        E::Io { file, .. }
        | E::DemonstrationLength { file, .. }
        | E::TruncatedDemonstration { file, .. }
        | E::TruncatedExecution { file, .. }
        | E::ExecutionDuration { file, .. }
        | E::CoarseExecution { file, .. }
        | E::BadLog { file, .. } => input_at(Some(file)),
        E::PartialQuaternionBlock { file, line, .. } => Kind::Input {
            file: Some(file.clone()),
            line: *line,
            column: None,
        },
        E::BadData { what, .. } => input_at(Some(what)),
        E::TooFewSamples { at, .. } => split_location(at),
        E::BadParam { name, .. } => param(name),
        E::BadHoldRule { .. } | E::BadHoldTime { .. } => param("holds"),
        E::Warp(w) => classify_warp(w),
        _ => input_at(None),
    }
}

fn classify_confidence(e: &errors::Confidence) -> Kind {
    match e {
        errors::Confidence::BadParam { name, .. } => param(name),
        _ => input_at(None),
    }
}

fn classify_realtime(e: &errors::Realtime) -> Kind {
    match e {
        errors::Realtime::BadOperator { .. } => input_at(None),
        // One input per operator (issue 44): the wrong count is the caller's input.
        errors::Realtime::OperatorInputs { .. } => input_at(None),
        // The planner's and the simulator's robot counts are the argument `robots`.
        errors::Realtime::RobotCount { .. } => param("robots"),
        errors::Realtime::BadParam { name, .. } => param(name),
        _ => SCHEDULE,
    }
}

fn classify_schedule(e: &errors::Schedule) -> Kind {
    match e {
        errors::Schedule::BadParam { name, .. } => param(name),
        errors::Schedule::Empty
        | errors::Schedule::LengthMismatch { .. }
        | errors::Schedule::NonFinite { .. }
        | errors::Schedule::BadBounds { .. } => input_at(None),
        // The scheduling functions (e.g. `cyclic_plan`) take the robot count as `n_robots`.
        errors::Schedule::Realtime(errors::Realtime::RobotCount { .. }) => param("n_robots"),
        errors::Schedule::Realtime(r) => classify_realtime(r),
        errors::Schedule::Invalid(v) => Kind::Schedule {
            violation: Some(violation_name(v)),
        },
        errors::Schedule::NotRunnable { .. } => Kind::Schedule {
            violation: Some("NotRunnable".to_owned()),
        },
        // A wrong certificate bound is a bug in tandem, not in the caller's data.
        errors::Schedule::BoundAboveSchedule { .. } => Kind::Internal,
        _ => SCHEDULE,
    }
}

fn classify_sim(e: &errors::Sim) -> Kind {
    match e {
        errors::Sim::BadParam { name, .. } => param(name),
        errors::Sim::BadInput { path, .. } => input_at(Some(&path.display().to_string())),
        errors::Sim::Planner(p) => classify_facade(p),
        errors::Sim::Lfd(l) => classify_lfd(l),
        errors::Sim::Realtime(r) => classify_realtime(r),
        errors::Sim::Schedule(s) => classify_schedule(s),
        errors::Sim::TickMismatch { .. } | errors::Sim::DidNotFinish { .. } => SCHEDULE,
        _ => input_at(None),
    }
}

fn classify_bag(e: &errors::Bag) -> Kind {
    match e {
        errors::Bag::BadParam { name, .. } => param(name),
        errors::Bag::Lfd(l) => classify_lfd(l),
        errors::Bag::Schedule(s) => classify_schedule(s),
        other => input_at(other.file()),
    }
}

fn classify_facade(e: &Facade) -> Kind {
    match e {
        Facade::Io { path, .. }
        | Facade::NotAStateFile { path }
        | Facade::UnsupportedVersion { path, .. }
        | Facade::Truncated { path, .. }
        | Facade::Corrupt { path, .. }
        | Facade::Locked { path, .. }
        | Facade::WouldOverwrite { path, .. }
        | Facade::Changed { path }
        | Facade::WouldDiscardRounds { path, .. }
        | Facade::CellFile { path, .. } => Kind::StateFile { path: path.clone() },
        Facade::Inconsistent { .. } | Facade::Encode { .. } | Facade::CannotReplay { .. } => {
            Kind::StateFile {
                path: PathBuf::new(),
            }
        }
        Facade::BadExecution { .. } | Facade::DuplicateRound { .. } => input_at(None),
        Facade::UnknownCell { .. } => param("cell"),
        Facade::HoldInLowConfidence { .. } | Facade::HoldMatchesNothing { .. } => param("holds"),
        Facade::Lfd(l) => classify_lfd(l),
        Facade::Confidence(c) => classify_confidence(c),
        Facade::Realtime(r) => classify_realtime(r),
        Facade::Schedule(s) => classify_schedule(s),
        _ => input_at(None),
    }
}

/// The name of a violated rule: its variant name (`GradientOutOfBounds`, `Margins`, …).
fn violation_name(v: &Violation) -> String {
    let debug = format!("{v:?}");
    debug
        .split([' ', '{', '('])
        .next()
        .unwrap_or_default()
        .to_owned()
}

impl Error {
    fn kind(&self) -> Kind {
        match self {
            Error::Tandem(e) => classify_facade(e),
            Error::Lfd(e) => classify_lfd(e),
            Error::Warp(e) => classify_warp(e),
            Error::Confidence(e) => classify_confidence(e),
            Error::Realtime(e) => classify_realtime(e),
            Error::Schedule(e) => classify_schedule(e),
            Error::Sim(e) => classify_sim(e),
            Error::Bag(e) => classify_bag(e),
            Error::Violation(v) => Kind::Schedule {
                violation: Some(violation_name(v)),
            },
            Error::Unchecked => Kind::Schedule {
                violation: Some("Unchecked".to_owned()),
            },
            Error::Input { file, what, .. } => input_at(Some(file.as_deref().unwrap_or(what))),
            Error::Param { what, .. } => param(what),
            Error::Panic(_) => Kind::Internal,
        }
    }
}

/// Builds the exception and sets its attributes.
fn raise(py: Python<'_>, message: String, kind: Kind) -> PyResult<PyErr> {
    let err = match &kind {
        Kind::Input { .. } => InputError::new_err(message),
        Kind::Param { .. } => ParamError::new_err(message),
        Kind::StateFile { .. } => StateFileError::new_err(message),
        Kind::Schedule { .. } => ScheduleError::new_err(message),
        Kind::Internal => InternalError::new_err(message),
    };
    let value = err.value(py);
    match kind {
        Kind::Input { file, line, column } => {
            value.setattr("file", file)?;
            value.setattr("line", line)?;
            value.setattr("column", column)?;
        }
        Kind::Param { name } => value.setattr("name", name)?,
        Kind::StateFile { path } => {
            let path = (!path.as_os_str().is_empty()).then(|| path.display().to_string());
            value.setattr("path", path)?;
        }
        Kind::Schedule { violation } => value.setattr("violation", violation)?,
        Kind::Internal => {}
    }
    Ok(err)
}

impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        let kind = e.kind();
        let message = e.to_string();
        Python::attach(|py| {
            raise(py, message, kind).unwrap_or_else(|setattr_failed| setattr_failed)
        })
    }
}

/// Raises `message` as a `tandem.DataWarning` (Python's warning filters decide whether it is
/// shown, ignored or turned into an error).
pub(crate) fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    let text = std::ffi::CString::new(message.replace('\0', " ")).expect("no NUL left");
    PyErr::warn(py, &py.get_type::<DataWarning>(), &text, 1)
}

/// Emits a Python `DeprecationWarning` with `message` (an old name kept one release; the
/// message names its replacement).
pub(crate) fn deprecated(py: Python<'_>, message: &str) -> PyResult<()> {
    let text = std::ffi::CString::new(message.replace('\0', " ")).expect("no NUL left");
    PyErr::warn(
        py,
        &py.get_type::<pyo3::exceptions::PyDeprecationWarning>(),
        &text,
        1,
    )
}

/// Runs `f`, turning a panic into [`Error::Panic`] so that it reaches Python as
/// `tandem.InternalError` instead of unwinding through the interpreter.
pub(crate) fn guard<T>(f: impl FnOnce() -> Result<T>) -> Result<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "panic without a message".to_owned());
        Err(Error::Panic(what))
    })
}
