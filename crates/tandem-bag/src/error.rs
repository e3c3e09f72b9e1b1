//! The crate's error type.

/// Everything that can go wrong reading or writing a bag.
///
/// Input errors name the file, the topic and, where one message is at fault, its 1-based
/// index among that topic's messages in file order (`message 12`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading or writing a file failed at the operating-system level.
    #[error("{file}: {what}: {source}")]
    Io {
        /// The file.
        file: String,
        /// What was being done (`cannot read`, `cannot write`).
        what: &'static str,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file does not start with the MCAP magic bytes.
    #[error(
        "{file}: not an MCAP file (wrong magic bytes at the start; tandem reads rosbag2 MCAP \
         files, the default storage of `ros2 bag record` since Iron: record with `-s mcap`)"
    )]
    NotMcap {
        /// The file.
        file: String,
    },
    /// The file ends before its last record (an interrupted recording or copy).
    #[error(
        "{file}: truncated MCAP file ({why}); nothing was read from it (`mcap recover` can \
         salvage the complete chunks of an interrupted recording)"
    )]
    Truncated {
        /// The file.
        file: String,
        /// What the MCAP reader found.
        why: String,
    },
    /// The file's records are malformed (bad CRC, bad record, bad index).
    #[error("{file}: corrupt MCAP file: {why}")]
    Corrupt {
        /// The file.
        file: String,
        /// What the MCAP reader found.
        why: String,
    },
    /// A topic's channel has no schema record (schema ID 0 or an ID no schema record has).
    #[error("{file}: topic `{topic}`: missing schema (its channel names no schema record)")]
    MissingSchema {
        /// The file.
        file: String,
        /// The topic.
        topic: String,
    },
    /// A selected topic has a message type tandem does not read.
    #[error(
        "{file}: topic `{topic}`: unknown schema `{schema}` (encoding `{encoding}`); tandem reads \
         {supported}",
        supported = crate::read::supported_list()
    )]
    UnknownSchema {
        /// The file.
        file: String,
        /// The topic.
        topic: String,
        /// The schema name.
        schema: String,
        /// The schema (or message) encoding.
        encoding: String,
    },
    /// No topic of the file has a supported type (nothing to read).
    #[error(
        "{file}: no topic of a supported type (found: {found}); tandem reads {supported}",
        supported = crate::read::supported_list()
    )]
    NoSupportedTopics {
        /// The file.
        file: String,
        /// The topics found, with their types.
        found: String,
    },
    /// A topic named in the selection is not in the file.
    #[error("{file}: no topic `{topic}` (topics: {available})")]
    TopicNotFound {
        /// The file.
        file: String,
        /// The requested topic.
        topic: String,
        /// The topics of the file.
        available: String,
    },
    /// A selected topic has fewer than 2 messages.
    #[error(
        "{file}: topic `{topic}`: {found} message(s); a topic needs at least 2 (leave it out with \
         --topics)"
    )]
    TooFewMessages {
        /// The file.
        file: String,
        /// The topic.
        topic: String,
        /// Its message count.
        found: usize,
    },
    /// A message cannot be decoded.
    #[error("{file}: topic `{topic}`: message {index}: {why}")]
    BadMessage {
        /// The file.
        file: String,
        /// The topic.
        topic: String,
        /// 1-based index of the message in the topic (file order).
        index: usize,
        /// What is wrong.
        why: String,
    },
    /// A message holds a NaN or infinite value, or one beyond `±`[`tandem_lfd::MAX_ABS_VALUE`].
    #[error("{file}: topic `{topic}`: message {index}: field `{field}`: {why}")]
    BadValue {
        /// The file.
        file: String,
        /// The topic.
        topic: String,
        /// 1-based index of the message in the topic (file order).
        index: usize,
        /// The field (channel suffix, e.g. `qw`, `fz`, `data`).
        field: String,
        /// What is wrong with the value.
        why: String,
    },
    /// A message's time (header stamp, or log time) is not after the previous message's.
    #[error(
        "{file}: topic `{topic}`: message {index}: {clock} {this_s} s does not increase after \
         {previous_s} s of message {}",
        index - 1
    )]
    TimeNotIncreasing {
        /// The file.
        file: String,
        /// The topic.
        topic: String,
        /// 1-based index of the message in the topic (file order).
        index: usize,
        /// Which time: `header stamp` or `log time`.
        clock: &'static str,
        /// This message's time (s, bag time).
        this_s: f64,
        /// The previous message's time (s, bag time).
        previous_s: f64,
    },
    /// Consecutive messages of a topic are further apart than the gap limit.
    #[error(
        "{file}: topic `{topic}`: message {index}: a gap of {gap_s} s after message {} (the \
         topic's median period is {median_s} s; gaps over {factor}× the median are not \
         interpolated: cut the recording there or record again)",
        index - 1,
        factor = crate::GAP_FACTOR
    )]
    Gap {
        /// The file.
        file: String,
        /// The topic.
        topic: String,
        /// 1-based index of the message after the gap.
        index: usize,
        /// The gap (s).
        gap_s: f64,
        /// The topic's median period (s).
        median_s: f64,
    },
    /// A topic starts later (or ends earlier) than the others by more than the gap limit.
    #[error(
        "{file}: topic `{topic}` {} {by_s} s {} topic `{other}` (more than {factor}× its \
         median period of {median_s} s): the topics do not cover the same recording; trim the \
         bag or leave the topic out with --topics",
        if *starts_late { "starts" } else { "ends" },
        if *starts_late { "after" } else { "before" },
        factor = crate::GAP_FACTOR
    )]
    Coverage {
        /// The file.
        file: String,
        /// The late-starting or early-ending topic.
        topic: String,
        /// Whether it starts late (else it ends early).
        starts_late: bool,
        /// By how much (s).
        by_s: f64,
        /// The topic that starts first or ends last.
        other: String,
        /// The late topic's median period (s).
        median_s: f64,
    },
    /// Two topics give a channel of the same name.
    #[error("{file}: channel `{channel}` comes from both `{first}` and `{second}`")]
    ChannelClash {
        /// The file.
        file: String,
        /// The channel name.
        channel: String,
        /// The first topic.
        first: String,
        /// The second topic.
        second: String,
    },
    /// The bag's content does not fit what is asked of it (rounds, robots, execution topics).
    #[error("{file}: {why}")]
    Layout {
        /// The file.
        file: String,
        /// What is wrong.
        why: String,
    },
    /// An option is out of its valid range.
    #[error("{name}: {why}")]
    BadParam {
        /// The option (`rate`, `topics`).
        name: &'static str,
        /// Why it is rejected.
        why: String,
    },
    /// Writing the MCAP file failed.
    #[error("{file}: cannot write the bag: {why}")]
    Write {
        /// The file.
        file: String,
        /// What failed.
        why: String,
    },
    /// The demonstration or execution built from the bag is rejected by the model crate.
    #[error(transparent)]
    Lfd(#[from] tandem_lfd::Error),
    /// The schedule of a run cannot be laid out on the global timeline.
    #[error(transparent)]
    Schedule(#[from] tandem_schedule::Error),
}

impl Error {
    /// The file the error is about, if any (every input error names one).
    #[must_use]
    pub fn file(&self) -> Option<&str> {
        match self {
            Error::Io { file, .. }
            | Error::NotMcap { file }
            | Error::Truncated { file, .. }
            | Error::Corrupt { file, .. }
            | Error::MissingSchema { file, .. }
            | Error::UnknownSchema { file, .. }
            | Error::NoSupportedTopics { file, .. }
            | Error::TopicNotFound { file, .. }
            | Error::TooFewMessages { file, .. }
            | Error::BadMessage { file, .. }
            | Error::BadValue { file, .. }
            | Error::TimeNotIncreasing { file, .. }
            | Error::Gap { file, .. }
            | Error::Coverage { file, .. }
            | Error::ChannelClash { file, .. }
            | Error::Layout { file, .. }
            | Error::Write { file, .. } => Some(file),
            Error::BadParam { .. } | Error::Lfd(_) | Error::Schedule(_) => None,
        }
    }
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
