//! The crate's error type.

/// Everything that can go wrong when building signals, validating parameters or aligning.
///
/// Every variant names what was wrong and where (signal, sample, channel, parameter).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A signal was declared with zero channels.
    #[error("signal must have at least one channel (n_channels = 0)")]
    ZeroChannels,
    /// The flat sample-major buffer is not a whole number of samples.
    #[error("signal data length {len} is not a multiple of n_channels = {n_channels}")]
    RaggedData {
        /// Length of the flat buffer.
        len: usize,
        /// Declared channel count.
        n_channels: usize,
    },
    /// A signal has fewer than the two samples a warp needs.
    #[error("signal has {n_samples} samples; at least 2 are required")]
    TooShort {
        /// Number of samples found.
        n_samples: usize,
    },
    /// A sample value is NaN or infinite.
    #[error("{signal} signal: non-finite value at sample {sample}, channel {channel}")]
    NonFinite {
        /// Which signal (`"reference"` or `"query"`, or `"query #i"` in `align_many`).
        signal: String,
        /// Sample index (in that signal's own samples).
        sample: usize,
        /// Channel index.
        channel: usize,
    },
    /// A sample value is finite but larger in magnitude than [`crate::MAX_ABS_VALUE`].
    #[error(
        "{signal} signal: value {value:e} at sample {sample}, channel {channel} is too large (|value| must be <= 1e100)"
    )]
    TooLarge {
        /// Which signal (`"reference"` or `"query"`, or `"query #i"` in `align_many`).
        signal: String,
        /// Sample index (in that signal's own samples).
        sample: usize,
        /// Channel index.
        channel: usize,
        /// The offending value.
        value: f64,
    },
    /// Reference and query have different channel counts.
    #[error("channel count mismatch: reference has {reference}, query has {query}")]
    ChannelMismatch {
        /// Channels of the reference.
        reference: usize,
        /// Channels of the query.
        query: usize,
    },
    /// A parameter is out of its documented range.
    #[error("parameter `{name}` {why}")]
    BadParam {
        /// Field name in [`crate::WarpParams`].
        name: &'static str,
        /// What is wrong with it.
        why: String,
    },
    /// The slope bounds cannot join the pinned endpoints φ(0) = 0 and φ(1) = 1.
    #[error(
        "slope bounds [{slope_min}, {slope_max}] cannot join the endpoints: \
         need slope_min <= 1 <= slope_max in normalized time"
    )]
    InfeasibleSlopes {
        /// Requested s_min.
        slope_min: f64,
        /// Requested s_max.
        slope_max: f64,
    },
    /// A warp given to [`crate::objective_of`] (or deserialized) is not a valid warp.
    #[error("invalid warp: {why}")]
    BadWarp {
        /// What is wrong (length, non-finite value, range, monotonicity), with the index.
        why: String,
    },
}

/// Result alias with [`Error`] as the default error type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
