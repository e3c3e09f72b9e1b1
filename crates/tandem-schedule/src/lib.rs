//! Scheduling two robots around low confidence (paper §II-B4, §II-B6, §II-C).
//!
//! A [`Problem`] holds, per reference sample `n` (period `Δt_s`), whether the learned model is
//! high-confidence (Eq. 12) and the mean, minimum and maximum demonstration warp gradients
//! (Eq. 14). A [`Schedule`] gives each robot an execution warp (one gradient per reference
//! sample) and robot 2 a start offset `τ`. [`GlobalTimeline`] lays a schedule out in global
//! time (Eq. 15, 16, 19), [`Schedule::t_total_s`] is Eq. 13, [`validate`] checks every
//! constraint of Eq. 20 (the margin check of Alg. 2 through `tandem_realtime`), and
//! [`sample_schedule`] is the paper's anytime sampler — by default robot 1's speeds are sampled
//! and `τ` and robot 2's speeds fitted to them exactly ([`OffsetSampling::Fitted`]) —
//! parallel, and deterministic for a seed whatever the thread count.
//!
//! ```
//! use tandem_schedule::{Problem, SamplerParams, Source, sample_schedule, validate};
//!
//! // 30 reference samples at 10 ms: low confidence on samples 10..15, loose bounds elsewhere.
//! let conf: Vec<bool> = (0..30).map(|n| !(10..15).contains(&n)).collect();
//! let problem = Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01)?;
//! let params = SamplerParams { samples: 500, seed: 7, ..SamplerParams::default() };
//! let out = sample_schedule(&problem, &params, None)?;
//! assert!(validate(&problem, &out.schedule).is_ok());
//! // Serial: each robot takes 25·0.5 + 5·1 = 17.5 samples, 0.35 s in all; overlapping the
//! // robots does better.
//! assert!(out.t_total_s < problem.serial_schedule().t_total_s(0.01));
//! assert!(matches!(out.source, Source::Sampled { .. }));
//! # Ok::<(), tandem_schedule::Error>(())
//! ```

pub mod exact;
mod problem;
mod sampler;
mod schedule;
mod validate;

pub use exact::{
    Certificate, CertifiedSource, ExactParams, MarginFree, SearchStats, certify, earliest_schedule,
    solve_exact,
};
pub use problem::{Problem, Run};
pub use sampler::{
    Distribution, OffsetSampling, Outcome, SamplerParams, SamplerStats, Source, sample_schedule,
};
pub use schedule::{GlobalTimeline, LcInterval, Schedule};
pub use validate::{MarginCheck, Violation, validate, validate_with_tick};

/// Errors of this crate.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The problem has no reference sample.
    #[error("the problem has no reference sample")]
    Empty,
    /// A per-sample vector does not have `T_ref` entries.
    #[error("`{name}` has {len} entries, expected {expected} (one per reference sample)")]
    LengthMismatch {
        /// Which vector.
        name: &'static str,
        /// Its length.
        len: usize,
        /// `T_ref`.
        expected: usize,
    },
    /// A value is not finite (or a gradient not > 0).
    #[error("`{name}` is not finite (and > 0 for gradients) at reference sample {ref_idx}")]
    NonFinite {
        /// Which vector or value.
        name: &'static str,
        /// First offending reference sample (0 for scalars).
        ref_idx: usize,
    },
    /// The gradient bounds are not `0 < ψ̇min ≤ ψ̇̄ ≤ ψ̇max` at a reference sample.
    #[error(
        "reference sample {ref_idx}: need 0 < min ≤ mean ≤ max, got min {min}, mean {mean}, max {max}"
    )]
    BadBounds {
        /// Reference sample.
        ref_idx: usize,
        /// `ψ̇min`.
        min: f64,
        /// `ψ̇̄`.
        mean: f64,
        /// `ψ̇max`.
        max: f64,
    },
    /// A parameter is out of range.
    #[error("parameter `{name}` {why}")]
    BadParam {
        /// Field name.
        name: &'static str,
        /// What is required.
        why: &'static str,
    },
    /// No schedule satisfies Eq. 20, not even the serial one.
    #[error("no feasible schedule: even the serial schedule fails: {serial}")]
    NoFeasibleSchedule {
        /// Why the serial schedule failed.
        serial: Violation,
    },
}

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
