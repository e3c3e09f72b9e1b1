//! Learning from demonstration for tandem (paper §II-B1/B2).
//!
//! - [`Demonstration`]: one demonstration `X_i ∈ R^{m × T_i}` (Eq. 1), read from CSV or
//!   JSON with errors naming file, line and column; every value finite and within
//!   `±`[`MAX_ABS_VALUE`], whoever builds it. [`CsvTable`] is the one CSV tokenizer (the
//!   command line reads its other CSV files with it too).
//! - [`Demonstration::tangent_names`]: the coordinates a model fitted on the demonstrations
//!   will have; an incomplete quaternion block or a channel named like a derived
//!   coordinate (`rate`, `<block>.rx|ry|rz`) is a located error here and in the fit.
//! - [`TaskModel`]: every demonstration aligned to the reference (GDTW, `tandem-warp`):
//!   the medoid, or demo 0 ([`FitParams::reference`], [`Reference`]); then per
//!   reference sample the mean behaviour `μ̂`, the augmented mean `μ̂⁺` (Eq. 4–5), the
//!   weighted variance `σ²_D` (Eq. 6), the warp-gradient bounds `ψ̇min/ψ̇max` (Eq. 14), and
//!   the admissible corrections: principal components of the weighted augmented residuals,
//!   scaled so the commanded rate stays inside the bounds; the command
//!   `x_f⁺ = μ̂⁺ + δx⁺` (Eq. 7).
//! - [`TaskModel::update`]: adds an execution with its known reference-time log (Eq. 21)
//!   through per-sample sufficient statistics, without re-alignment.
//! - [`HoldSpec`]: hold points the user declares (reference times `at_s` and channel rules
//!   [`HoldRule`] such as `tool<0.5` on the mean trajectory), resolved to reference samples.
//!
//! Time frames: all per-time arrays are indexed by *reference sample* `n ∈ 0..n_ref()`
//! (the reference's samples, period `dt_s()`); warps map reference samples to demo samples.
//!
//! # Decisions
//!
//! - **Weights.** `W⁺ = diag(1/r_j²)` with `r_j` a per-coordinate range (default: the
//!   channel's range over all demonstrations; for the rate, `(s_max − 1)` times the mean
//!   warp gradient; ranges below `min_range` become 1), so `σ²_D` is dimensionless. The same
//!   ranges weight the alignment (`1/r_j²`, and `4/r_q²` on each quaternion component since
//!   a small rotation `δr` moves a unit quaternion by `|δr|/2`). Ranges are fixed at fit
//!   time; updates keep them so `σ²_D` stays comparable across iterations.
//! - **Quaternions.** Statistics use rotation vectors `log(q_a⁻¹ ⊗ q)` relative to a fixed
//!   per-sample anchor `q_a` (the reference's orientation there); the mean is `q_a ⊗ exp(r̄)`. This
//!   is sign-proof (`q ≡ −q`) and makes [`TaskModel::update`] equal a refit exactly. For
//!   alignment only, quaternion signs are made continuous and put in the reference's
//!   hemisphere.
//! - **Corrections.** Per reference sample, the eigen-decomposition of the range-scaled
//!   scatter matrix (equivalent to the SVD of the scaled residuals); `K = min(n − 1, k_max, d)`
//!   components, each stored as a ±3σ displacement `c_k = 3·s_k/√n · v_k ⊙ r`, signs kept
//!   continuous in time. The scale `a(t) ∈ [0, 1]` is uniform over the input box: the largest
//!   factor keeping `ψ̄̇ + a·Σ_k u_k c_k,rate` inside `[ψ̇min, ψ̇max]` for *every*
//!   `u ∈ [−1, 1]^K`, so the operator's input maps linearly to the correction. Where the
//!   demonstrated rate range is zero the components' rate entries are zero. The table is
//!   computed lazily on first use after a fit, load or update (an update alone stays cheap).
//! - **Executions.** An execution's warp is the inverse of its reference-time log
//!   ([`TaskModel::execution_warp`]); no re-alignment. All demonstrations and executions must
//!   share `Δt_s` within 1 %; a `t` column may jitter by up to 25 % of a period around its
//!   even grid.
//! - **Reference.** With [`Reference::Medoid`] (default) every demonstration is tried as
//!   the reference and the one whose model has the least median `σ²_D` wins, and the model
//!   does not depend on the order of the demonstrations; [`Reference::First`] keeps the
//!   user's choice (measured with `cargo xtask fit-defaults` and `cargo xtask
//!   reference-order`, see docs/decisions.md).
//! - **Rate.** The warp gradient's term of `σ²_D` weighs relative speed differences (its
//!   range counts at the mean pace and scales with the local one; default `(s_max − 1)` times
//!   the mean pace) and is opened over 13 reference samples, so that a change of speed the
//!   alignment places a few samples apart in different demonstrations leaves no island.
//! - **Eigendecompositions.** nalgebra's `SymmetricEigen`; faer gives the same results to
//!   1e-12 on the fixtures but was slower on these 9 × 9 matrices (`benches/eigen.rs`,
//!   docs/decisions.md).
//!
//! ```
//! use tandem_lfd::{Demonstration, FitParams, TaskModel};
//! let names = vec!["force".to_string()];
//! let a = Demonstration::new(names.clone(), vec![1.0, 2.0, 3.0], 0.01)?;
//! let b = Demonstration::new(names, vec![3.0, 4.0, 5.0], 0.01)?;
//! let identity = vec![0.0, 1.0, 2.0];
//! let model = TaskModel::fit_aligned(&[a, b], &[identity.clone(), identity], &FitParams::default())?;
//! assert_eq!(model.mean(), [2.0, 3.0, 4.0]);
//! // Residuals ±1 N over a 4 N range: σ²_D = 2·(1/4)² / (2 − 1) = 0.125.
//! assert!((model.sigma2_d()[1] - 0.125).abs() < 1e-12);
//! // One correction component: ±3σ along force (σ = 1 N), rate unchanged.
//! let cmd = model.command(&[1.0], 1.0)?;
//! assert!((cmd[0] - 6.0).abs() < 1e-12 && (cmd[1] - 1.0).abs() < 1e-12);
//! # Ok::<(), tandem_lfd::Error>(())
//! ```

mod checks;
mod csv;
mod demo;
mod error;
mod model;
mod quat;
pub mod resample;

pub use checks::{
    END_RUN_MOTION_SHARE, END_RUN_REFUSE_SHARE, END_RUN_SLOPE_TOLERANCE, LENGTH_REFUSE_RATIO,
    LENGTH_WARN_RATIO, check_lengths, length_warnings, time_like,
};
pub use csv::{CsvRow, CsvTable};
pub use demo::{
    ChannelKind, ChannelSchema, DEFAULT_DT_S, DRIFT_TOLERANCE, DT_TOLERANCE, Demonstration,
    JITTER_NOTE, JITTER_TOLERANCE, MAX_ABS_VALUE, MAX_RESAMPLE_GAP, PeriodSource, QuaternionBlock,
    Regridded, drifting_majority, logger_period, period_from_times,
};
pub use error::{Error, Result};
pub use model::{
    Comparison, Corrections, EXECUTION_DURATION_RATIO, Execution, FitParams, HoldRule, HoldSpec,
    RateTerm, Reference, Resampled, TaskModel,
};
