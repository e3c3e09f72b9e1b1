//! Parameters of the Beta prior (Eq. 10–11) and of the confidence threshold (Eq. 12).

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// Parameters of the confidence model (paper §II-B3).
///
/// All quantities are dimensionless: `σ²_D` is the weighted demonstration variance of
/// Eq. 6 with `W = diag(1/r_j²)` normalizing each coordinate by its range over all
/// demonstrations (`tandem_lfd::FitParams::ranges`; docs/decisions.md, "Channel weights and
/// kinds"), and `p_{c|t}` is a probability. Why the defaults: docs/decisions.md, "Defaults".
///
/// # Why `σ²_MAX < 1/4`
///
/// Write `g = 1 − exp(−γ_p (σ²_D + ε)) ∈ (0, 1)`. Eq. 11 sets the prior mean `μ = g/2`
/// and variance `σ² = σ²_MAX·g`, so the common factor of Eq. 10 is
///
/// ```text
/// k = μ(1 − μ)/σ² − 1 = (g/2)(1 − g/2)/(σ²_MAX·g) − 1 = (2 − g)/(4·σ²_MAX) − 1,
/// α₀ = μ·k = (g/2)·k,    β₀ = (1 − μ)·k = (1 − g/2)·k.
/// ```
///
/// Since `g/2 > 0` and `1 − g/2 > 0`, `α₀, β₀ > 0` holds exactly when `k > 0`, i.e.
/// `σ²_MAX < (2 − g)/4` — the familiar requirement that a Beta variance be below
/// `μ(1 − μ)`. As `σ²_D` grows, `g → 1` (in `f64`, `g == 1` once `γ_p(σ²_D + ε) ≳ 37`),
/// and the bound tends to `1/4`. So the prior is well posed for *every* `σ²_D ≥ 0` if and
/// only if `0 < σ²_MAX < 1/4`; with the default `σ²_MAX = 0.05`, a high-variance sample
/// gets `k = 4` and the prior `Beta(2, 2)`.
///
/// ```
/// use tandem_confidence::ConfidenceParams;
/// assert!(ConfidenceParams::default().validate().is_ok());
/// let bad = ConfidenceParams { sigma2_max: 0.25, ..Default::default() };
/// assert!(bad.validate().is_err());
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ConfidenceParams {
    /// `γ_p` (Eq. 11): how fast the prior moves from "confident" to "uncertain" as the
    /// demonstration variance `σ²_D` grows (per unit of dimensionless variance).
    /// Must be finite and > 0. Default: 10.
    pub gamma_p: f64,
    /// `σ²_MAX` (Eq. 11): prior variance of `p_{c|t}` reached for large `σ²_D`; sets how
    /// weak the prior is where demonstrations vary. Must be in (0, 0.25) (see the type
    /// docs). Default: 0.05 (prior `Beta(2, 2)` for large `σ²_D`).
    pub sigma2_max: f64,
    /// `ε` (Eq. 11): small variance added to `σ²_D` so that the prior is well posed
    /// (`α₀ > 0`) even where `σ²_D = 0`. Must be finite and > 0. Default: 1e-6.
    pub epsilon: f64,
    /// `μ_c` (Eq. 12): probability of a correction below which the robot may run
    /// unsupervised. Must be in (0, 1). Default: 0.05.
    pub mu_c: f64,
    /// `γ_c` (Eq. 12): posterior mass `P(p_{c|t} < μ_c)` that must be exceeded for high
    /// confidence. Must be in (0, 1). Default: 0.95.
    pub gamma_c: f64,
    /// `f`, the operator's false-correction rate: the probability that a supervised sample
    /// that needs no correction is corrected anyway (per control sample). With
    /// [`estimate_error_rates`](Self::estimate_error_rates) it is the prior mean (and the
    /// value without data) of the estimate, otherwise the rate used as is. Must be in
    /// `[0, 0.5)`. Default: 0.01 (§III's simulated operator). The paper's model: 0.
    pub false_correction_rate: f64,
    /// `m`, the operator's miss rate: the probability that a needed correction is not given
    /// (per control sample). As for `false_correction_rate`. Must be in `[0, 0.5)`.
    /// Default: 0.01 (§III). The paper's model: 0.
    pub miss_rate: f64,
    /// Whether `f` and `m` are estimated from the recorded executions at every update
    /// ([`crate::estimate_error_rates`]: `f` by EM over every sample's latent "needs
    /// help", `m` from the gaps inside correction stretches) instead of used as given.
    /// Default: `true`. The paper's model: `false` (with both rates 0 it is exactly
    /// Eq. 8–12; docs/decisions.md, "The operator's error rates in the confidence").
    pub estimate_error_rates: bool,
    /// Whether one execution counts exactly once per reference sample it passed
    /// ([`Observations::record_votes`](crate::Observations::record_votes)): the control
    /// samples one execution spends on a reference sample share one decision of the
    /// operator. Read by whoever records the observations (the planner). Default: `true`.
    /// The paper's model: `false` (every control sample one observation, Eq. 9 with the
    /// fractional split).
    pub one_vote_per_execution: bool,
}

impl Default for ConfidenceParams {
    fn default() -> Self {
        Self {
            gamma_p: 10.0,
            sigma2_max: 0.05,
            epsilon: 1e-6,
            mu_c: 0.05,
            gamma_c: 0.95,
            false_correction_rate: 0.01,
            miss_rate: 0.01,
            estimate_error_rates: true,
            one_vote_per_execution: true,
        }
    }
}

impl ConfidenceParams {
    /// The paper's model (Eq. 8–12): the defaults with both error rates 0, nothing
    /// estimated and every control sample one observation, so that every recorded
    /// correction counts as evidence of need.
    #[must_use]
    pub fn paper() -> Self {
        Self {
            false_correction_rate: 0.0,
            miss_rate: 0.0,
            estimate_error_rates: false,
            one_vote_per_execution: false,
            ..Self::default()
        }
    }

    /// Whether this is the paper's model: both error rates 0, not estimated, every control
    /// sample an observation (then the decision is exactly Eq. 12).
    #[must_use]
    pub fn is_paper_model(&self) -> bool {
        self.false_correction_rate == 0.0
            && self.miss_rate == 0.0
            && !self.estimate_error_rates
            && !self.one_vote_per_execution
    }

    /// Checks every field against its documented domain.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the first offending field.
    pub fn validate(&self) -> Result<()> {
        let bad = |name, value, why| Err(Error::BadParam { name, value, why });
        if !(self.gamma_p.is_finite() && self.gamma_p > 0.0) {
            return bad("gamma_p", self.gamma_p, "must be finite and > 0");
        }
        if !(self.epsilon.is_finite() && self.epsilon > 0.0) {
            return bad("epsilon", self.epsilon, "must be finite and > 0");
        }
        if self.gamma_p * self.epsilon <= 0.0 {
            return bad(
                "epsilon",
                self.epsilon,
                "times gamma_p underflows to 0, which makes alpha_0 = 0 where sigma2_d = 0",
            );
        }
        if !(self.sigma2_max > 0.0 && self.sigma2_max < 0.25) {
            return bad(
                "sigma2_max",
                self.sigma2_max,
                "must be in (0, 0.25): alpha_0, beta_0 > 0 needs sigma2_max < (2 - g)/4 \
                 for every g = 1 - exp(-gamma_p (sigma2_d + epsilon)) in (0, 1)",
            );
        }
        if !(self.mu_c > 0.0 && self.mu_c < 1.0) {
            return bad("mu_c", self.mu_c, "must be in (0, 1)");
        }
        if !(self.gamma_c > 0.0 && self.gamma_c < 1.0) {
            return bad("gamma_c", self.gamma_c, "must be in (0, 1)");
        }
        if !(0.0..0.5).contains(&self.false_correction_rate) {
            return bad(
                "false_correction_rate",
                self.false_correction_rate,
                "must be in [0, 0.5): an operator who corrects at random half the time gives \
                 no evidence",
            );
        }
        if !(0.0..0.5).contains(&self.miss_rate) {
            return bad("miss_rate", self.miss_rate, "must be in [0, 0.5)");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name_of(p: &ConfidenceParams) -> &'static str {
        match p.validate() {
            Err(Error::BadParam { name, .. }) => name,
            other => panic!("expected BadParam, got {other:?}"),
        }
    }

    #[test]
    fn defaults_are_the_documented_values() {
        let p = ConfidenceParams::default();
        assert_eq!(
            (p.gamma_p, p.sigma2_max, p.epsilon, p.mu_c, p.gamma_c),
            (10.0, 0.05, 1e-6, 0.05, 0.95)
        );
        assert_eq!(
            (
                p.false_correction_rate,
                p.miss_rate,
                p.estimate_error_rates,
                p.one_vote_per_execution
            ),
            (0.01, 0.01, true, true)
        );
        p.validate().unwrap();
        assert!(!p.is_paper_model());
        let paper = ConfidenceParams::paper();
        assert!(paper.is_paper_model());
        assert_eq!(
            ConfidenceParams {
                false_correction_rate: 0.0,
                miss_rate: 0.0,
                estimate_error_rates: false,
                one_vote_per_execution: false,
                ..p
            },
            paper
        );
    }

    #[test]
    fn each_bad_field_is_rejected_by_name() {
        let d = ConfidenceParams::default;
        for v in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(name_of(&ConfidenceParams { gamma_p: v, ..d() }), "gamma_p");
            assert_eq!(name_of(&ConfidenceParams { epsilon: v, ..d() }), "epsilon");
        }
        for v in [0.0, -0.1, 0.25, 0.3, f64::NAN, f64::INFINITY] {
            assert_eq!(
                name_of(&ConfidenceParams {
                    sigma2_max: v,
                    ..d()
                }),
                "sigma2_max"
            );
        }
        for v in [0.5, 1.0, -0.01, f64::NAN, f64::INFINITY] {
            let f = ConfidenceParams {
                false_correction_rate: v,
                ..d()
            };
            assert_eq!(name_of(&f), "false_correction_rate");
            assert_eq!(
                name_of(&ConfidenceParams {
                    miss_rate: v,
                    ..d()
                }),
                "miss_rate"
            );
        }
        for v in [0.0, 1.0, -0.5, 1.5, f64::NAN] {
            assert_eq!(name_of(&ConfidenceParams { mu_c: v, ..d() }), "mu_c");
            assert_eq!(name_of(&ConfidenceParams { gamma_c: v, ..d() }), "gamma_c");
        }
        // gamma_p * epsilon underflows.
        let tiny = ConfidenceParams {
            gamma_p: 1e-200,
            epsilon: 1e-200,
            ..d()
        };
        assert_eq!(name_of(&tiny), "epsilon");
        // Just inside the domain is fine.
        ConfidenceParams {
            sigma2_max: 0.249_999,
            mu_c: 1e-9,
            gamma_c: 0.999_999,
            ..d()
        }
        .validate()
        .unwrap();
    }

    #[test]
    fn serde_fills_defaults_and_rejects_unknown_fields() {
        let p: ConfidenceParams = serde_json::from_str(r#"{"gamma_c": 0.9}"#).unwrap();
        assert_eq!(
            p,
            ConfidenceParams {
                gamma_c: 0.9,
                ..Default::default()
            }
        );
        let err = serde_json::from_str::<ConfidenceParams>(r#"{"gamma": 0.9}"#).unwrap_err();
        assert!(err.to_string().contains("unknown field"), "{err}");
        let p = ConfidenceParams::default();
        let back: ConfidenceParams =
            serde_json::from_str(&serde_json::to_string(&p).unwrap()).unwrap();
        assert_eq!(back, p);
    }
}
