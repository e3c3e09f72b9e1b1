//! The operator's error rates (§III's future work): estimated from the recorded
//! executions, and the decision of Eq. 12 with them.
//!
//! # The model
//!
//! Let `π_n` be the probability that an execution *needs* a correction at reference sample
//! `n` (the task's own need, e.g. paint on half the sections of a pass). The operator
//! corrects a sample that needs it with probability `1 − m` and one that does not with
//! probability `f`, so a supervised observation at `n` is corrected with probability
//!
//! ```text
//! p_n = f + (1 − f − m)·π_n.
//! ```
//!
//! The paper's `p_{c|t}` is `p_n` with `f = m = 0`. Its Beta prior (Eq. 10–11) and
//! posterior (Eq. 9) stay on the observable `p_n`, whose likelihood is binomial in the
//! recorded counts whatever `f` and `m` are. The question of Eq. 12, "is the need below
//! `μ_c`?", becomes `π_n < μ_c ⇔ p_n < μ'_c = f + (1 − f − m)·μ_c`:
//!
//! ```text
//! P(π_n < μ_c | data) = P(p_n < μ'_c | data) = I_{μ'_c}(α, β) > γ_c.
//! ```
//!
//! With `f = m = 0` this is Eq. 12 exactly (`μ'_c = μ_c`). Posterior mass below `f` (which
//! the operator model excludes) is read as "no need" (`π_n = 0`), as the paper's prior
//! means it: a sample whose demonstrations agree starts confident, whatever the operator's
//! errors. (Conditioning on `p_n ≥ f` instead would turn exactly those samples low: their
//! prior lies almost entirely below `f`.) Few observations leave the posterior at the
//! prior, as in the paper: the rates change how much one correction weighs — `c`
//! corrections in `s` observations are now compared with the `f·s` an operator makes by
//! mistake — not whether evidence is needed.
//!
//! # The estimates
//!
//! * `f`, by EM over a latent "needs help" `z_n` per reference sample: a sample with
//!   `z_n = 0` is corrected at rate `f`, one with `z_n = 1` at a common rate `q`; the
//!   counts are the fractional `(corrections[n], supervised[n])` of [`Observations`].
//!   The E step gives each sample's posterior `P(z_n = 1 | data)`; the M step pools the
//!   counts weighted by it. Only samples with at least [`MIN_OBSERVATIONS`] supervised
//!   observations take part: with two or three, a sample that needs help half the time is
//!   often clean (`0.5² = 25 %` for two), so the mixture cannot tell the classes apart and
//!   puts the needed corrections into `f` (measured: `f = 11–14 %` after the first round of
//!   the study against 1 % simulated, which trusted 74 samples that need help); with ten,
//!   such a sample is clean with probability `0.5¹⁰ ≈ 0.1 %`. `f`'s estimate carries [`RATE_PRIOR_SAMPLES`] pseudo-samples at
//!   the configured rate, so that it is the configured rate before any data and moves to
//!   the data's as they come.
//! * `m`, from the gaps inside correction stretches of each execution
//!   ([`MissEvidence`](crate::MissEvidence)), with the same pseudo-samples: the per-sample
//!   counts cannot tell a miss from a smaller need (`(1 − m)·π` is all they see), the time
//!   structure of one execution can.

use serde::{Deserialize, Serialize};

use crate::{ConfidenceParams, Observations, Result};

/// Pseudo-samples (control samples) at the configured rate in each estimate: the weight of
/// the configured rate against the data. 100 samples are one second of supervision at
/// 100 Hz, so one round of the study (thousands of supervised samples) outweighs it.
pub const RATE_PRIOR_SAMPLES: f64 = 100.0;

/// Fewest supervised observations (units of `supervised[n]`) a reference sample needs to
/// take part in the EM estimate of `f` (see the module docs).
pub const MIN_OBSERVATIONS: f64 = 10.0;

/// EM iterations at most; it stops earlier when `f` moves by less than 1e-12.
const EM_ITERATIONS: usize = 200;

/// The operator's error rates, per supervised control sample (probabilities).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ErrorRates {
    /// `f`: probability of a correction where none is needed, in `[0, 0.5)`.
    pub false_correction_rate: f64,
    /// `m`: probability that a needed correction is missed, in `[0, 0.5)`.
    pub miss_rate: f64,
}

impl ErrorRates {
    /// The rates `params` gives (no estimate).
    #[must_use]
    pub fn configured(params: &ConfidenceParams) -> Self {
        Self {
            false_correction_rate: params.false_correction_rate,
            miss_rate: params.miss_rate,
        }
    }

    /// `μ'_c = f + (1 − f − m)·μ_c`: the correction probability at which the need is `μ_c`.
    #[must_use]
    pub fn shifted_mu_c(&self, mu_c: f64) -> f64 {
        let (f, m) = (self.false_correction_rate, self.miss_rate);
        f + (1.0 - f - m) * mu_c
    }

    /// Whether both rates are 0 (the paper's Eq. 12).
    #[must_use]
    pub fn is_zero(&self) -> bool {
        self.false_correction_rate == 0.0 && self.miss_rate == 0.0
    }
}

/// The operator's error rates to decide with: estimated from `obs` (see the module docs)
/// when `params.estimate_error_rates`, otherwise [`ErrorRates::configured`].
/// Deterministic; every estimate lies in `[0, 0.5)`.
///
/// ```
/// use tandem_confidence::{ConfidenceParams, Observations, estimate_error_rates};
/// // 200 reference samples that never need help, observed 100 times each, with every
/// // 50th observation corrected (2 %).
/// let mut obs = Observations::new(200)?;
/// for k in 0..100 {
///     let times: Vec<f64> = (0..200).map(f64::from).collect();
///     let corrected: Vec<bool> = (0..200).map(|n| (n + k) % 50 == 0).collect();
///     obs.record(&times, &corrected)?;
/// }
/// let rates = estimate_error_rates(&obs, &ConfidenceParams::default())?;
/// // 400 corrections in 20 000 samples, plus 100 pseudo-samples at 1 %.
/// assert!((rates.false_correction_rate - 401.0 / 20_100.0).abs() < 1e-9);
/// assert_eq!(rates.miss_rate, 0.01); // no correction stretches: the configured rate
/// # Ok::<(), tandem_confidence::Error>(())
/// ```
///
/// # Errors
/// [`Error::BadParam`](crate::Error::BadParam) for invalid `params`.
pub fn estimate_error_rates(obs: &Observations, params: &ConfidenceParams) -> Result<ErrorRates> {
    params.validate()?;
    if !params.estimate_error_rates {
        return Ok(ErrorRates::configured(params));
    }
    let miss = obs.miss_evidence();
    let miss_rate = (miss.gap_samples + RATE_PRIOR_SAMPLES * params.miss_rate)
        / (miss.stretch_samples + RATE_PRIOR_SAMPLES);
    Ok(ErrorRates {
        false_correction_rate: em_false_rate(obs, params.false_correction_rate),
        miss_rate: miss_rate.min(MAX_RATE),
    })
}

/// Largest estimate returned (just below the parameters' bound 0.5).
const MAX_RATE: f64 = 0.499;

/// `ln P(c of s | rate)` up to the binomial coefficient, for `rate ∈ (0, 1)`.
fn log_lik(c: f64, s: f64, rate: f64) -> f64 {
    c * rate.ln() + (s - c) * (-rate).ln_1p()
}

/// The EM estimate of `f` (module docs) with `f0` as its prior mean.
fn em_false_rate(obs: &Observations, f0: f64) -> f64 {
    let (c, s) = (obs.corrections(), obs.supervised());
    let floor = 1e-9;
    let mut f = f0.clamp(floor, MAX_RATE);
    let mut q = 0.5_f64.max(2.0 * f);
    let mut w = 0.5_f64;
    let mut r = vec![0.0; c.len()];
    for _ in 0..EM_ITERATIONS {
        // E step: P(z_n = 1 | c_n, s_n).
        let (lw1, lw0) = (w.ln(), (-w).ln_1p());
        for (rn, (&cn, &sn)) in r.iter_mut().zip(c.iter().zip(s)) {
            if sn < MIN_OBSERVATIONS {
                continue;
            }
            let d = (log_lik(cn, sn, f) + lw0) - (log_lik(cn, sn, q) + lw1);
            *rn = 1.0 / (1.0 + d.exp());
        }
        // M step.
        let (mut c0, mut s0, mut c1, mut s1, mut n1, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for (&rn, (&cn, &sn)) in r.iter().zip(c.iter().zip(s)) {
            if sn < MIN_OBSERVATIONS {
                continue;
            }
            c0 += (1.0 - rn) * cn;
            s0 += (1.0 - rn) * sn;
            c1 += rn * cn;
            s1 += rn * sn;
            n1 += rn;
            n += 1.0;
        }
        let f_new =
            ((c0 + RATE_PRIOR_SAMPLES * f0) / (s0 + RATE_PRIOR_SAMPLES)).clamp(floor, MAX_RATE);
        if n == 0.0 {
            return f_new;
        }
        // The help component stays above the error component (no label switching).
        q = if s1 > 0.0 { c1 / s1 } else { q }.clamp(2.0 * f_new, 1.0 - floor);
        w = (n1 / n).clamp(floor, 1.0 - floor);
        let done = (f_new - f).abs() < 1e-12;
        f = f_new;
        if done {
            break;
        }
    }
    f
}

/// `P(π < μ_c | data) > γ_c` for the posterior `Beta(α, β)` of the correction probability
/// and the operator's `rates` (module docs): Eq. 12 at `μ'_c`, evaluated with statrs.
/// `α, β > 0` finite.
pub(crate) fn decide_with_rates(
    alpha: f64,
    beta: f64,
    rates: &ErrorRates,
    mu_c: f64,
    gamma_c: f64,
) -> bool {
    crate::beta::decide_exact(alpha, beta, rates.shifted_mu_c(mu_c), gamma_c)
}

/// The posterior probability `P(π < μ_c | data) = I_{μ'_c}(α, β)` of the module docs (no
/// threshold), in `[0, 1]`: what Eq. 12 compares with `γ_c`.
pub(crate) fn prob_need_below(alpha: f64, beta: f64, rates: &ErrorRates, mu_c: f64) -> Option<f64> {
    statrs::function::beta::checked_beta_reg(alpha, beta, rates.shifted_mu_c(mu_c)).ok()
}

/// The demonstration variance `σ²*` at which the prior alone (Eq. 10–11, no observations)
/// turns low-confidence: samples with `σ²_D ≤ σ²*` are high-confidence from the prior,
/// those above need supervised evidence (dimensionless, like `σ²_D`). The decision uses
/// the configured error rates (no data to estimate them from). `None` when even
/// `σ²_D = 0` is low-confidence. Bisection to a relative width of 1e-9 on the decision
/// itself, which falls with `σ²_D` (the prior's mean `g/2` rises while `σ²_MAX·g` lets
/// it spread).
///
/// ```
/// use tandem_confidence::{ConfidenceParams, Confidence, prior_low_threshold};
/// let p = ConfidenceParams::paper();
/// let s = prior_low_threshold(&p)?.unwrap();
/// let conf = Confidence::from_prior(&[0.99 * s, 1.01 * s], p)?;
/// assert_eq!(conf.conf(), &[true, false]);
/// # Ok::<(), tandem_confidence::Error>(())
/// ```
///
/// # Errors
/// [`Error::BadParam`](crate::Error::BadParam) for invalid `params`.
pub fn prior_low_threshold(params: &ConfidenceParams) -> Result<Option<f64>> {
    params.validate()?;
    let rates = ErrorRates::configured(params);
    let mu = rates.shifted_mu_c(params.mu_c);
    let high = |s2: f64| {
        let (a, b) = crate::beta::prior_ab(s2, params);
        a > 0.0 && b > 0.0 && crate::beta::decide_exact(a, b, mu, params.gamma_c)
    };
    if !high(0.0) {
        return Ok(None);
    }
    let (mut lo, mut hi) = (0.0_f64, 1e-6_f64);
    while high(hi) {
        lo = hi;
        hi *= 2.0;
        if hi > 1e6 {
            return Ok(Some(f64::INFINITY));
        }
    }
    while hi - lo > 1e-9 * hi {
        let mid = 0.5 * (lo + hi);
        if high(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(Some(lo))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_prior_threshold_matches_the_front_page_table() {
        // Lib docs: sigma2_d = 0.001 is high from the prior, 0.01 is not (paper's model).
        let s = prior_low_threshold(&ConfidenceParams::paper())
            .unwrap()
            .unwrap();
        assert!(s > 0.001 && s < 0.01, "{s}");
        // The operator's errors raise the threshold mu'_c, so the prior trusts a little more.
        let with = prior_low_threshold(&ConfidenceParams::default())
            .unwrap()
            .unwrap();
        assert!(with > s, "{with} vs {s}");
    }

    #[test]
    fn zero_rates_are_eq_12() {
        let zero = ErrorRates::default();
        for (a, b) in [(2.0, 92.0), (2.0, 91.0), (0.04, 8.9), (5.0, 300.0)] {
            assert_eq!(
                decide_with_rates(a, b, &zero, 0.05, 0.95),
                crate::beta::decide_exact(a, b, 0.05, 0.95)
            );
        }
    }

    #[test]
    fn the_rates_change_how_much_a_correction_weighs() {
        // Beta(2, 2) prior, c corrections in s observations.
        let post = |c: f64, s: f64| (2.0 + c, 2.0 + s - c);
        let one = ErrorRates {
            false_correction_rate: 0.01,
            miss_rate: 0.01,
        };
        let first_high = |c: f64, rates: &ErrorRates| {
            (1..2000)
                .map(f64::from)
                .find(|&s| {
                    let (a, b) = post(c, s);
                    decide_with_rates(a, b, rates, 0.05, 0.95)
                })
                .unwrap()
        };
        let zero = ErrorRates::default();
        // The paper's model: 90 clean observations, 120 clean ones besides one correction
        // (lib docs).
        assert_eq!(first_high(0.0, &zero), 90.0);
        assert_eq!(first_high(1.0, &zero), 121.0);
        // With the operator's 1 % errors a correction costs fewer clean observations…
        let extra_paper = first_high(3.0, &zero) - first_high(0.0, &zero);
        let extra_rates = first_high(3.0, &one) - first_high(0.0, &one);
        assert!(extra_rates < extra_paper, "{extra_rates} vs {extra_paper}");
        // …but clean evidence is still needed: never high from the prior alone.
        assert!(!decide_with_rates(2.0, 2.0, &one, 0.05, 0.95));
        // The probability agrees with the decision.
        let (a, b) = post(1.0, 150.0);
        let p = prob_need_below(a, b, &one, 0.05).unwrap();
        assert_eq!(p > 0.95, decide_with_rates(a, b, &one, 0.05, 0.95));
    }

    #[test]
    fn samples_with_few_observations_do_not_enter_the_estimate() {
        // One round: 300 samples that never need help, clean; 100 that need help half the
        // time, corrected in one of two executions. The mixture would call the latter's
        // corrections slips; with fewer than MIN_OBSERVATIONS nothing is estimated.
        let mut obs = Observations::new(400).unwrap();
        let times: Vec<f64> = (0..400).map(f64::from).collect();
        for k in 0..2 {
            let corrected: Vec<bool> = (0..400_usize)
                .map(|n| n >= 300 && (n + k) % 2 == 0)
                .collect();
            obs.record(&times, &corrected).unwrap();
        }
        let rates = estimate_error_rates(&obs, &ConfidenceParams::default()).unwrap();
        assert_eq!(rates.false_correction_rate, 0.01);
    }

    #[test]
    fn em_recovers_the_false_correction_rate_next_to_samples_that_need_help() {
        // 300 samples never needing help (corrected 3 % of the time) and 100 that need it
        // half the time, 200 observations each, deterministic patterns.
        let mut obs = Observations::new(400).unwrap();
        let times: Vec<f64> = (0..400).map(f64::from).collect();
        for k in 0..200 {
            let corrected: Vec<bool> = (0..400_usize)
                .map(|n| {
                    if n < 300 {
                        (n + 7 * k) % 100 < 3
                    } else {
                        (n + k) % 2 == 0
                    }
                })
                .collect();
            obs.record(&times, &corrected).unwrap();
        }
        let rates = estimate_error_rates(&obs, &ConfidenceParams::default()).unwrap();
        // 1800 corrections in 60 000 samples plus the pseudo-samples at 1 %.
        let expected = (1800.0 + 1.0) / (60_000.0 + 100.0);
        assert!(
            (rates.false_correction_rate - expected).abs() < 1e-6,
            "{rates:?} vs {expected}"
        );
        // Fixed rates are returned as configured.
        let fixed = ConfidenceParams {
            estimate_error_rates: false,
            ..ConfidenceParams::default()
        };
        assert_eq!(
            estimate_error_rates(&obs, &fixed).unwrap(),
            ErrorRates::configured(&fixed)
        );
        // No data: the configured rates.
        let empty = Observations::new(3).unwrap();
        let r = estimate_error_rates(&empty, &ConfidenceParams::default()).unwrap();
        assert_eq!((r.false_correction_rate, r.miss_rate), (0.01, 0.01));
    }
}
