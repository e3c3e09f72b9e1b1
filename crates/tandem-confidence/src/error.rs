//! The crate's error type.

/// Everything that can go wrong in `tandem-confidence`.
///
/// Every variant names what was wrong and where (parameter name, reference-sample index,
/// observation index, or the two lengths that disagree).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A field of [`ConfidenceParams`](crate::ConfidenceParams) is out of its domain.
    #[error("parameter `{name}` = {value} {why}")]
    BadParam {
        /// Field name, e.g. `"sigma2_max"`.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The constraint it breaks.
        why: &'static str,
    },
    /// A demonstration variance `σ²_D` (Eq. 6) is negative, NaN or infinite.
    #[error("sigma2_d at reference sample {ref_idx} is {value}: it must be finite and >= 0")]
    BadVariance {
        /// Reference sample of the offending value.
        ref_idx: usize,
        /// The rejected value.
        value: f64,
    },
    /// Eq. 10–11 produced a Beta prior with a non-positive or non-finite parameter
    /// (only possible for parameters at the edge of floating point, e.g. `σ²_MAX` within
    /// one ulp of 0.25 together with a tiny `γ_p·ε`).
    #[error(
        "prior at reference sample {ref_idx} is degenerate: alpha = {alpha}, beta = {beta} \
         (both must be finite and > 0)"
    )]
    DegeneratePrior {
        /// Reference sample of the degenerate prior.
        ref_idx: usize,
        /// Computed `α₀`.
        alpha: f64,
        /// Computed `β₀`.
        beta: f64,
    },
    /// Beta parameters given directly are not finite and strictly positive.
    #[error("beta parameters alpha = {alpha}, beta = {beta} must both be finite and > 0")]
    BadBeta {
        /// The rejected `α`.
        alpha: f64,
        /// The rejected `β`.
        beta: f64,
    },
    /// A probability argument is outside `[0, 1]` or NaN.
    #[error("probability argument {value} must be in [0, 1]")]
    BadProbability {
        /// The rejected value.
        value: f64,
    },
    /// A supervised sample's reference time is non-finite or outside `[0, T_ref − 1]`.
    #[error(
        "supervised sample {obs_idx} has reference time {ref_time}: it must be finite and \
         in [0, {max}] (the reference has {n_ref} samples)",
        max = n_ref.saturating_sub(1)
    )]
    RefTimeOutOfRange {
        /// Index of the observation in the slice passed to
        /// [`Observations::record`](crate::Observations::record).
        obs_idx: usize,
        /// The rejected reference time (reference samples).
        ref_time: f64,
        /// Number of reference samples `T_ref`.
        n_ref: usize,
    },
    /// Observation counts given directly are inconsistent at one reference sample.
    #[error(
        "observations at reference sample {ref_idx}: corrections = {corrections}, \
         supervised = {supervised} (need finite 0 <= corrections <= supervised)"
    )]
    BadCounts {
        /// Reference sample of the inconsistent counts.
        ref_idx: usize,
        /// Correction mass at that sample.
        corrections: f64,
        /// Supervised mass at that sample.
        supervised: f64,
    },
    /// The observations given as "before the round" hold more mass at a sample than those
    /// after it ([`Confidence::update_round`](crate::Confidence::update_round)).
    #[error(
        "observations at reference sample {ref_idx}: {what} mass {before} before the round but \
         {after} after it: pass the observations as they were before this round"
    )]
    NotEarlier {
        /// Reference sample where the mass decreased.
        ref_idx: usize,
        /// `"correction"` or `"supervised"`.
        what: &'static str,
        /// Mass before the round.
        before: f64,
        /// Mass after it.
        after: f64,
    },
    /// Two per-sample inputs that must have the same length do not.
    #[error("length mismatch: {left_name} has {left} entries but {right_name} has {right}")]
    LengthMismatch {
        /// What the first length counts.
        left_name: &'static str,
        /// First length.
        left: usize,
        /// What the second length counts.
        right_name: &'static str,
        /// Second length.
        right: usize,
    },
    /// A reference demonstration must have at least one sample.
    #[error("the reference has no samples: n_ref must be >= 1")]
    EmptyReference,
}

/// `Result` with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
