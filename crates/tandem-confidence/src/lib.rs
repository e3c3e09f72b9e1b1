//! When may a robot run unsupervised? Beta-Bernoulli estimate of the probability that the
//! operator corrects the robot at each reference sample, and the latched high-confidence
//! map `conf(t)` the scheduler works with (Hagenow et al. 2023, §II-B3, Eq. 8–12).
//!
//! Everything is indexed by **reference sample** `n ∈ 0..T_ref` of the reference
//! demonstration and takes plain slices; nothing depends on other tandem crates.
//!
//! 1. **Prior** (Eq. 10–11, [`prior`]): from the dimensionless demonstration variance
//!    `σ²_D(n)` (Eq. 6), `g = 1 − exp(−γ_p(σ²_D + ε))`, mean `μ = g/2`, variance
//!    `σ²_MAX·g`, converted to `Beta(α₀, β₀)`. Near-zero variance → confident prior;
//!    large variance → `Beta(2, 2)` with the defaults ([`ConfidenceParams`]).
//! 2. **Observations** ([`Observations`]): each execution reports the fractional reference
//!    times of the samples the operator *supervised* and whether a correction was given
//!    there; each observation is split linearly between the two neighbouring reference
//!    samples, so `corrections[n]` and `supervised[n]` are real-valued.
//! 3. **Posterior** (Eq. 9, [`posterior`]): `Beta(α₀ + corrections, β₀ + supervised −
//!    corrections)`, i.e. `supervised[n]` plays the role of `n_e`.
//! 4. **Decision** (Eq. 12): high confidence iff `P(p_{c|t} < μ_c) = I_{μ_c}(α, β) > γ_c`,
//!    with the regularized incomplete beta function of `statrs`.
//! 5. **Latch** ([`Confidence`]): a sample that became high-confidence stays so, even if a
//!    later variance update moves its prior, so a previous schedule stays valid;
//!    [`Confidence::update_round`] decides a latched sample again when a round brings
//!    corrections of it, so the same rounds give the same confidence in any order.
//!
//! # Worked example: how long until a variable but never-corrected sample is trusted?
//!
//! Take a sample whose demonstrations vary a lot (`σ²_D ≳ 3.7`, so that
//! `γ_p(σ²_D + ε) ≳ 37` and `g = 1` in `f64`) with the default parameters. Then `μ = 1/2`,
//! `σ² = σ²_MAX = 0.05`, `k = μ(1 − μ)/σ² − 1 = 0.25/0.05 − 1 = 4` and
//! `α₀ = β₀ = μ·k = 2`: the prior is `Beta(2, 2)` and `P(p < 0.05) = I_{0.05}(2, 2) =
//! 0.00725`, far below `γ_c = 0.95`.
//!
//! Each execution supervises the sample once without correcting it, so after `n`
//! executions the posterior is `Beta(2, 2 + n)`. For integer `α`,
//! `I_x(α, β) = P(Binomial(α + β − 1, x) ≥ α)`, hence
//! `I_x(2, b) = 1 − (1 − x)^b (1 + b·x)`, and high confidence needs
//! `0.95^{n+2} (1 + 0.05(n + 2)) < 0.05`:
//!
//! | n  | `0.95^{n+2}(1 + 0.05(n+2))` | `I_{0.05}(2, 2 + n)` |
//! |----|-----------------------------|----------------------|
//! | 89 | 0.052136                    | 0.947864 (low)       |
//! | 90 | 0.049976                    | 0.950024 (high)      |
//!
//! So it takes **90 clean supervised executions** (45 iterations of the two-robot study
//! loop, if both robots supervise it each time). One correction on the way (`α = 3`)
//! pushes this to 120 clean executions, two to 148.
//!
//! With moderate variance the prior starts closer to `p = 0` and fewer executions are
//! needed (values from mpmath at 30 digits; see `tests/reference_values.rs`):
//!
//! | `σ²_D` | `α₀`   | `β₀`  | `I_{0.05}(α₀, β₀)` | clean executions to high |
//! |--------|--------|-------|--------------------|--------------------------|
//! | 0.001  | 0.0446 | 8.906 | 0.9705             | 0 (high from the prior)  |
//! | 0.01   | 0.4056 | 8.119 | 0.6981             | 25                       |
//! | 0.05   | 1.384  | 5.649 | 0.1292             | 67                       |
//! | 0.1    | 1.846  | 3.994 | 0.0317             | 84                       |
//! | 0.5    | 2.003  | 2.030 | 0.0074             | 91                       |
//! | ≥ 3.7  | 2      | 2     | 0.00725            | 90                       |
//!
//! (At `σ²_D = 0.5`, `g = 0.9933 < 1` makes `k = 4.03` slightly larger than 4, so the
//! prior is slightly *stronger* than `Beta(2, 2)` and needs one execution more.)
//!
//! ```
//! use tandem_confidence::{Confidence, ConfidenceParams, Observations};
//!
//! let sigma2_d = [10.0]; // one reference sample with large demonstration variance
//! // The paper's model: every correction is evidence of need (no operator errors).
//! let mut conf = Confidence::from_prior(&sigma2_d, ConfidenceParams::paper())?;
//! let mut obs = Observations::new(1)?;
//! let mut executions = 0;
//! while !conf.conf()[0] {
//!     obs.record(&[0.0], &[false])?; // supervised at reference time 0, not corrected
//!     executions += 1;
//!     conf.update(&sigma2_d, &obs)?;
//! }
//! assert_eq!(executions, 90);
//! // The posterior is Beta(2, 92) and I_{0.05}(2, 92) = 0.95002... (mpmath).
//! let post = tandem_confidence::posterior(&sigma2_d, &obs, conf.params())?[0];
//! assert!((post.cdf(0.05)? - 0.950_024_204_757_383_5).abs() < 1e-12);
//! // The latch: more variance or later corrections cannot undo it.
//! obs.record(&[0.0; 10], &[true; 10])?;
//! conf.update(&[100.0], &obs)?;
//! assert!(conf.conf()[0]);
//! # Ok::<(), tandem_confidence::Error>(())
//! ```

mod beta;
mod boundary;
mod confidence;
mod error;
mod observations;
mod params;
mod rates;
mod runs;

pub use beta::{BetaParams, posterior, prior};
pub use confidence::{Confidence, MIN_VOTES, RoundUpdate, evaluate, prob_need_below_mu_c};
pub use error::{Error, Result};
pub use observations::{MissEvidence, Observations};
pub use params::ConfidenceParams;
pub use rates::{
    ErrorRates, MIN_OBSERVATIONS, RATE_PRIOR_SAMPLES, estimate_error_rates, prior_low_threshold,
};
pub use runs::{Run, low_regions, runs};
