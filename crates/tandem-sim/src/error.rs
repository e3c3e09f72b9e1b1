//! The crate's error type.

/// Everything that can go wrong in `tandem-sim`.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
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
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
