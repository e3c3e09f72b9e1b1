//! The crate's error type.

/// Everything that can go wrong in `tandem-lfd`.
///
/// Input errors name the file (or the in-memory source label of a [`crate::Demonstration`]),
/// the 1-based line and the 1-based column where the problem is.
/// For CSV files the column is the 1-based field number; for JSON files it is the
/// 1-based character column reported by the parser.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading a file failed at the operating-system level.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The file.
        file: String,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file holds no header (CSV) or no document (JSON).
    #[error("{file}:1:1: empty file")]
    EmptyFile {
        /// The file.
        file: String,
    },
    /// The header is malformed (empty or repeated column name, no data channel).
    #[error("{file}:{line}:{column}: bad header: {why}")]
    BadHeader {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (field number).
        column: usize,
        /// What is wrong.
        why: String,
    },
    /// A row has a different number of fields than the header.
    #[error("{file}:{line}:{column}: ragged row: expected {expected} fields, found {found}")]
    RaggedRow {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column of the first missing or surplus field.
        column: usize,
        /// Number of fields in the header.
        expected: usize,
        /// Number of fields in this row.
        found: usize,
    },
    /// A CSV field is not a number.
    #[error("{file}:{line}:{column}: column `{name}`: not a number: `{text}`")]
    NotNumeric {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Name of the column (the channel, in a demonstration).
        name: String,
        /// The offending text.
        text: String,
    },
    /// A CSV field is NaN or infinite.
    #[error("{file}:{line}:{column}: column `{name}`: non-finite value `{text}`")]
    NonFinite {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Name of the column (the channel, in a demonstration).
        name: String,
        /// The offending text.
        text: String,
    },
    /// A CSV value of a demonstration is beyond `±`[`crate::MAX_ABS_VALUE`].
    #[error(
        "{file}:{line}:{column}: channel `{channel}`: value `{text}` is beyond ±{max:e} \
         (squared differences would overflow; check the units)",
        max = crate::MAX_ABS_VALUE
    )]
    TooLarge {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Channel name of the column.
        channel: String,
        /// The offending text.
        text: String,
    },
    /// The time column is not strictly increasing or not evenly spaced within 1 %.
    #[error("{file}:{line}:{column}: time column `t`: {why}")]
    BadTime {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        why: String,
    },
    /// A CSV file separated by `;` or tabs instead of commas (its header is one column).
    #[error(
        "{file}:{line}:1: the header is one column, but it holds {columns} fields separated by \
         {separator}: tandem reads comma-separated files; save the file as CSV with commas{}",
        if *decimal_comma {
            " and decimal points (its numbers seem to use decimal commas)"
        } else {
            " (e.g. `tr ';\\t' ',,' < in.csv > out.csv`)"
        }
    )]
    Separator {
        /// The file.
        file: String,
        /// 1-based line of the header.
        line: usize,
        /// The separator found: `"semicolons"` or `"tabs"`.
        separator: &'static str,
        /// Number of fields the header would have with that separator.
        columns: usize,
        /// Whether the data rows also hold commas (decimal commas, `1,5;2,0`).
        decimal_comma: bool,
    },
    /// A JSON document could not be parsed or has the wrong shape.
    #[error("{file}:{line}:{column}: {why}")]
    Json {
        /// The file.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What is wrong.
        why: String,
    },
    /// A demonstration has fewer than 2 samples.
    #[error("{at}: {found} sample(s); at least 2 are required")]
    TooFewSamples {
        /// Where: `file:line:column` of the end of the CSV data or of the JSON `samples`
        /// array, or the source label of an in-memory demonstration.
        at: String,
        /// Number of samples found.
        found: usize,
    },
    /// Fewer than 2 demonstrations where a variance (Eq. 6) is asked for.
    #[error("{found} demonstration(s); at least 2 are required for a variance")]
    TooFewDemonstrations {
        /// Number of demonstrations given.
        found: usize,
    },
    /// A demonstration's channel set differs from the reference demonstration's.
    #[error(
        "{}: channels {found:?} differ from the reference channels {expected:?} (every \
         demonstration needs the same channel names, in any order: rename the columns or \
         leave the file out)",
        at(file, *line, *column)
    )]
    ChannelMismatch {
        /// The file or source label of the offending demonstration.
        file: String,
        /// 1-based line of its header, where known (CSV).
        line: Option<usize>,
        /// 1-based column of its first channel the reference does not have, where known.
        column: Option<usize>,
        /// The reference channel names.
        expected: Vec<String>,
        /// This demonstration's channel names.
        found: Vec<String>,
    },
    /// A quaternion block of the schema has some but not all of its four channels.
    #[error(
        "{}: quaternion block `{block}` is incomplete: {missing:?} missing, {present:?} \
         present (give all four channels, or none, or change `schema.quaternions`)",
        at(file, *line, None)
    )]
    PartialQuaternionBlock {
        /// The file or source label of the demonstration whose channels are checked.
        file: String,
        /// 1-based line of its header, where known (CSV); the channels are named.
        line: Option<usize>,
        /// Name of the block.
        block: String,
        /// Its channels that are present.
        present: Vec<String>,
        /// Its channels that are missing.
        missing: Vec<String>,
    },
    /// A channel has the name of a coordinate the model derives (`rate`, or
    /// `<block>.rx|ry|rz` of a quaternion block).
    #[error(
        "{}: channel `{channel}` has the name of a coordinate the model derives: \
         {derived}; rename the channel",
        at(file, *line, *column)
    )]
    ReservedChannelName {
        /// The file or source label of the demonstration whose channels are checked.
        file: String,
        /// 1-based line of its header, where known (CSV).
        line: Option<usize>,
        /// 1-based column of the channel, where known (CSV).
        column: Option<usize>,
        /// The channel name.
        channel: String,
        /// What the model derives under that name.
        derived: String,
    },
    /// A channel is named like a time column other than `t` (see [`crate::time_like`]).
    #[error(
        "{}: column `{channel}` looks like a time column, but tandem reads time only from a \
         column named `t` (seconds): rename it to `t` (converted to seconds) or remove it; \
         as a channel it would be aligned and averaged like a measurement",
        located(file, *line, *column)
    )]
    TimeLikeChannel {
        /// The file or source label.
        file: String,
        /// 1-based line of the header, where known (CSV).
        line: Option<usize>,
        /// 1-based column (field number), where known (CSV).
        column: Option<usize>,
        /// The column's name.
        channel: String,
    },
    /// A demonstration's length is an outlier of the set ([`crate::check_lengths`]).
    #[error(
        "{file}: {duration_s:.2} s long, {ratio:.2}× the median demonstration \
         ({median_s:.2} s); a demonstration outside 0.5–2× the median is a partial task, a \
         recording left running or a long pause, and would widen the speed bounds and the \
         variance of the whole model: leave it out, trim it, or demonstrate the whole task again"
    )]
    DemonstrationLength {
        /// The file or source label.
        file: String,
        /// Its duration `(T_i − 1)·Δt_s`, seconds.
        duration_s: f64,
        /// The median duration of the demonstrations, seconds.
        median_s: f64,
        /// `duration_s / median_s`.
        ratio: f64,
    },
    /// A demonstration does not reach the end of the task: its alignment to the reference
    /// ends pinned at a slope bound over a long run ([`crate::END_RUN_REFUSE_SHARE`]).
    #[error(
        "{file}: does not reach the end of the task (it ends about {ends_at_pct:.0} % of the \
         way through): {why}; a demonstration cut off before the end would teach the model a \
         wrong end and widen its variance and speed bounds: demonstrate the whole task again, \
         trim the recording to whole tasks, or leave it out"
    )]
    TruncatedDemonstration {
        /// The file or source label.
        file: String,
        /// Where on the reference (% of the task) its end is aligned.
        ends_at_pct: f64,
        /// What its alignment shows.
        why: String,
    },
    /// Sample periods differ by more than 1 %.
    #[error(
        "{}: sample period {} s differs from {} s, the period of {}, by more than 1 % \
         (resample every file onto that one grid: `tandem fit --resample --dt {}`, in Python \
         `fit(..., resample=True, dt_s={})`; for a file without a `t` column the period is \
         --dt, default 0.01 s)",
        at(file, *line, *column),
        (found_s * 1e9).round() / 1e9,
        (expected_s * 1e9).round() / 1e9,
        expected_from,
        (expected_s * 1e9).round() / 1e9,
        (expected_s * 1e9).round() / 1e9
    )]
    SamplePeriodMismatch {
        /// The file or source label.
        file: String,
        /// 1-based line of its header, where known (CSV).
        line: Option<usize>,
        /// 1-based column of its `t` column, where the period came from one (CSV).
        column: Option<usize>,
        /// The period the others share, seconds: the model's `Δt_s`, or at fit the period of
        /// most demonstrations (ties: the first file's).
        expected_s: f64,
        /// Whose period `expected_s` is, in words (`the model`, `2 of the 3 demonstrations
        /// (b.csv, c.csv)`).
        expected_from: String,
        /// This demonstration's period, seconds.
        found_s: f64,
    },
    /// In-memory data has an inconsistent shape or a bad value.
    #[error("{what}: {why}")]
    BadData {
        /// Which input.
        what: String,
        /// What is wrong.
        why: String,
    },
    /// A parameter is out of its valid range.
    #[error("parameter `{name}` {why}")]
    BadParam {
        /// Parameter name.
        name: &'static str,
        /// Why it is rejected.
        why: String,
    },
    /// A warp given to [`crate::TaskModel::fit_aligned`] is malformed.
    #[error("warp of demonstration {demo_idx}: {why}")]
    BadWarp {
        /// Index of the demonstration.
        demo_idx: usize,
        /// What is wrong.
        why: String,
    },
    /// An execution's reference-time log is malformed.
    #[error("execution `{file}`: reference-time log: {why}")]
    BadLog {
        /// Source label of the execution.
        file: String,
        /// What is wrong.
        why: String,
    },
    /// An execution does not cover the whole task: its reference-time log starts after the
    /// first reference sample or ends before the last (by more than one step of its pace).
    #[error(
        "execution `{file}`: the reference-time log {why}; an execution must cover the whole \
         task (record complete executions only: the model would extrapolate the missing part)"
    )]
    TruncatedExecution {
        /// Source label of the execution.
        file: String,
        /// Where the log starts or ends and what was expected.
        why: String,
    },
    /// An execution lasts far longer or shorter than any admissible speed allows: most likely
    /// it was logged at another rate than the one assumed for it.
    #[error(
        "execution `{file}`: {duration_s:.2} s long ({n_samples} samples {dt_s} s apart), but \
         the demonstrated speeds take {fastest_s:.2} to {slowest_s:.2} s and an execution \
         outside half the fastest to twice the slowest is refused: if it was logged at another \
         rate, give its sample period (a column `t` in seconds; `dt_s=` in Python) and it is \
         resampled to the model's"
    )]
    ExecutionDuration {
        /// Source label of the execution.
        file: String,
        /// `T_E·Δt_E`, seconds (the convention of `Σ_n ψ̇(n)·Δt_s`).
        duration_s: f64,
        /// Samples `T_E`.
        n_samples: usize,
        /// The execution's sample period `Δt_E`, seconds.
        dt_s: f64,
        /// `Σ_n ψ̇min(n)·Δt_s`: the fastest admissible execution, seconds.
        fastest_s: f64,
        /// `Σ_n ψ̇max(n)·Δt_s`: the slowest admissible execution, seconds.
        slowest_s: f64,
    },
    /// An execution was logged at a coarser period than the model's: resampling it would
    /// invent samples (and observations) between the logged ones.
    #[error(
        "execution `{file}`: sample period {found_s} s is coarser than the model's {model_s} s: \
         log executions at the model's period or finer (a finer log is resampled to it)"
    )]
    CoarseExecution {
        /// Source label of the execution.
        file: String,
        /// The execution's period, seconds.
        found_s: f64,
        /// The model's period `Δt_s`, seconds.
        model_s: f64,
    },
    /// A hold rule (`<channel><op><value>`, [`crate::HoldRule`]) is malformed or names a
    /// channel it cannot use.
    #[error("hold rule `{rule}`: {why}")]
    BadHoldRule {
        /// The rule as written.
        rule: String,
        /// What is wrong.
        why: String,
    },
    /// A hold's reference time ([`crate::HoldSpec::at_s`]) is not a time of the task.
    #[error("hold at {at_s} s (reference time): {why}")]
    BadHoldTime {
        /// The reference time given, seconds.
        at_s: f64,
        /// What is wrong.
        why: String,
    },
    /// The time-warping crate failed.
    #[error("alignment failed: {0}")]
    Warp(#[from] tandem_warp::Error),
}

/// `file:line:column`, or `file` alone where the position is unknown.
/// `file:line:column`, `file:line` or `file`, as much as is known.
fn at(file: &str, line: Option<usize>, column: Option<usize>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!("{file}:{l}:{c}"),
        (Some(l), None) => format!("{file}:{l}"),
        _ => file.to_owned(),
    }
}

fn located(file: &str, line: Option<usize>, column: Option<usize>) -> String {
    match (line, column) {
        (Some(l), Some(c)) => format!("{file}:{l}:{c}"),
        _ => file.to_owned(),
    }
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
