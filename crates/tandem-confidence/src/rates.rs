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
//!   `z_n = 0` is corrected at rate `f`, one with `z_n = 1` at a rate of a grid `k/20`
//!   whose weights the EM estimates too (needs are graded; one common rate `q` put the
//!   rarely needed samples' corrections into `f`); the
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
        false_correction_rate: em_false_rate(obs, params.false_correction_rate, params.mu_c),
        miss_rate: miss_rate.min(MAX_RATE),
    })
}

/// Largest estimate returned (just below the parameters' bound 0.5).
const MAX_RATE: f64 = 0.499;

/// Rates of the "needs help" components of the EM ([`em_false_rate`]): a grid of correction
/// probabilities `k/10`, `k = 1..=10`, those at `2·μ_c` and above (all ten at the default
/// `μ_c`), each with a weight of its own. A component takes part only while its rate is
/// above twice the current `f` (help stays above the error).
const HELP_RATES: usize = 10;

/// The EM estimate of `f` (module docs) with `f0` as its prior mean.
///
/// The samples that need help are a mixture over the rates of [`HELP_RATES`], not one common
/// rate `q`: a task's needs are graded (a region needed on 20 % of the workpieces next to one
/// needed on 80 %), and with one common `q` between them the mixture explained the rarely
/// needed samples' corrections as the operator's slips: `f̂` = 6–26 % on the task zoo's screw
/// driving against 1 % simulated, which raised `μ'_c` to 10–30 % and trusted samples needed
/// on 20–30 % of the workpieces (docs/decisions.md, "Graded needs: the error rate's
/// estimate and the latch's evidence"). Each grid rate's weight is its own maximum-likelihood
/// share (the nonparametric estimate of the need distribution on the grid), so a need level
/// anywhere on it is explained by its own component.
fn em_false_rate(obs: &Observations, f0: f64, mu_c: f64) -> f64 {
    let (c, s) = (obs.corrections(), obs.supervised());
    let floor = 1e-9;
    let mut f = f0.clamp(floor, MAX_RATE);
    // Component 0 is "no help" (rate f); the others have the grid's rates k/10 from 2·μ_c
    // on (a rate below that is no need Eq. 12 asks about; lower components took the
    // clustered slips of the operator's episodes and drove `f̂` towards 0).
    let rates: Vec<f64> = (1..=HELP_RATES)
        .map(|k| k as f64 / HELP_RATES as f64)
        .filter(|&q| q >= 2.0 * mu_c)
        .map(|q| q.clamp(floor, 1.0 - floor))
        .collect();
    let n_help = rates.len();
    let mut w = vec![1.0 / (n_help + 1) as f64; n_help + 1];
    // The samples that take part, as distinct `(c, s)` pairs with their multiplicity (the
    // E step depends on the counts only; grouping keeps the cost at the pairs').
    let mut pairs: Vec<(f64, f64)> = c
        .iter()
        .zip(s)
        .filter(|&(_, &sn)| sn >= MIN_OBSERVATIONS)
        .map(|(&cn, &sn)| (cn, sn))
        .collect();
    if pairs.is_empty() {
        return f;
    }
    let n = pairs.len() as f64;
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut groups: Vec<(f64, f64, f64)> = Vec::new();
    for (cn, sn) in pairs {
        match groups.last_mut() {
            Some(g) if g.0 == cn && g.1 == sn => g.2 += 1.0,
            _ => groups.push((cn, sn, 1.0)),
        }
    }
    // The help components' log-likelihoods do not change between iterations.
    let help_lik: Vec<Vec<f64>> = groups
        .iter()
        .map(|&(cn, sn, _)| {
            rates
                .iter()
                .map(|&q| cn * q.ln() + (sn - cn) * (-q).ln_1p())
                .collect()
        })
        .collect();
    let mut r = vec![0.0; n_help + 1];
    let mut lik = vec![0.0; n_help + 1];
    for _ in 0..EM_ITERATIONS {
        let (ln_f, ln_1f) = (f.ln(), (-f).ln_1p());
        let ln_w: Vec<f64> = w
            .iter()
            .enumerate()
            .map(|(k, &wk)| {
                if wk > 0.0 && (k == 0 || rates[k - 1] > 2.0 * f) {
                    wk.ln()
                } else {
                    f64::NEG_INFINITY
                }
            })
            .collect();
        let (mut c0, mut s0) = (0.0, 0.0);
        let mut w_new = vec![0.0; n_help + 1];
        for (&(cn, sn, mult), help) in groups.iter().zip(&help_lik) {
            // E step: P(component k | c_n, s_n), in logs against the largest term.
            lik[0] = cn * ln_f + (sn - cn) * ln_1f + ln_w[0];
            let mut top = lik[0];
            for k in 1..=n_help {
                lik[k] = help[k - 1] + ln_w[k];
                top = top.max(lik[k]);
            }
            let mut total = 0.0;
            for k in 0..=n_help {
                let d = lik[k] - top;
                // exp(−50) ≈ 2e-22: nothing at f64's precision of the sum.
                r[k] = if d > -50.0 { d.exp() } else { 0.0 };
                total += r[k];
            }
            for k in 0..=n_help {
                let rk = mult * r[k] / total;
                w_new[k] += rk;
            }
            let r0 = mult * r[0] / total;
            c0 += r0 * cn;
            s0 += r0 * sn;
        }
        // M step.
        let f_new =
            ((c0 + RATE_PRIOR_SAMPLES * f0) / (s0 + RATE_PRIOR_SAMPLES)).clamp(floor, MAX_RATE);
        for (wk, wn) in w.iter_mut().zip(&w_new) {
            *wk = wn / n;
        }
        let done = (f_new - f).abs() < 1e-10;
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

    #[test]
    fn graded_needs_are_not_taken_for_slips() {
        // 300 samples that never need help, corrected 1 % of the time; 100 needed on 20 %
        // of the executions and 200 on 90 %; 100 observations each (deterministic
        // patterns). One common help rate (0.9) made the 20 % samples look like the
        // operator's slips: the former estimate was f = 5.7 % (docs/decisions.md, "Graded
        // needs: the error rate's estimate and the latch's evidence"); the grid of help rates
        // keeps them apart.
        let mut obs = Observations::new(600).unwrap();
        let times: Vec<f64> = (0..600).map(f64::from).collect();
        for k in 0..100_usize {
            let corrected: Vec<bool> = (0..600_usize)
                .map(|n| match n {
                    0..300 => (n + 7 * k) % 100 == 0,
                    300..400 => (n + k) % 5 == 0,
                    _ => (n + k) % 10 != 0,
                })
                .collect();
            obs.record_votes(&times, &corrected).unwrap();
        }
        let rates = estimate_error_rates(&obs, &ConfidenceParams::default()).unwrap();
        // 300 slips in 30 000 clean votes, plus the pseudo-samples at 1 %.
        let expected = (300.0 + 1.0) / (30_000.0 + 100.0);
        assert!(
            (rates.false_correction_rate - expected).abs() < 1e-4,
            "{rates:?} vs {expected}"
        );
        // With f right, a need of 20 % is far above μ'_c: no such sample is trusted.
        let conf = crate::evaluate(&[0.01; 600], &obs, &ConfidenceParams::default()).unwrap();
        assert!(conf[..300].iter().all(|&h| h));
        assert!(conf[300..].iter().all(|&h| !h));
    }
}
