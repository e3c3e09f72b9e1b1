//! Beta prior (Eq. 10–11), posterior (Eq. 9) and the high-confidence test (Eq. 12).

use serde::{Deserialize, Serialize};

use crate::{ConfidenceParams, Error, Observations, Result};

/// Parameters `(α, β)` of a Beta distribution over `p_{c|t}`, the probability that the
/// operator corrects the robot at one reference sample (Eq. 8–9).
///
/// Both are finite and strictly positive (checked by [`BetaParams::new`] and on
/// deserialization). They are pseudo-counts: `α` of corrections, `β` of supervised
/// samples without one.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BetaData")]
pub struct BetaParams {
    alpha: f64,
    beta: f64,
}

/// Unchecked serde form of [`BetaParams`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BetaData {
    alpha: f64,
    beta: f64,
}

impl TryFrom<BetaData> for BetaParams {
    type Error = Error;
    fn try_from(d: BetaData) -> Result<Self> {
        Self::new(d.alpha, d.beta)
    }
}

impl BetaParams {
    /// `Beta(alpha, beta)`.
    ///
    /// # Errors
    /// [`Error::BadBeta`] unless both are finite and > 0.
    pub fn new(alpha: f64, beta: f64) -> Result<Self> {
        if alpha.is_finite() && beta.is_finite() && alpha > 0.0 && beta > 0.0 {
            Ok(Self { alpha, beta })
        } else {
            Err(Error::BadBeta { alpha, beta })
        }
    }

    /// `α` (pseudo-count of corrections).
    #[must_use]
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// `β` (pseudo-count of supervised samples without a correction).
    #[must_use]
    pub fn beta(&self) -> f64 {
        self.beta
    }

    /// Mean `α/(α + β)` of `p_{c|t}`.
    #[must_use]
    pub fn mean(&self) -> f64 {
        self.alpha / (self.alpha + self.beta)
    }

    /// Variance `αβ / ((α + β)²(α + β + 1))` of `p_{c|t}`.
    #[must_use]
    pub fn variance(&self) -> f64 {
        let s = self.alpha + self.beta;
        self.alpha * self.beta / (s * s * (s + 1.0))
    }

    /// CDF `P(p_{c|t} < x) = I_x(α, β)`, the regularized incomplete beta function
    /// (evaluated by `statrs::function::beta::checked_beta_reg`).
    ///
    /// # Errors
    /// [`Error::BadProbability`] unless `0 ≤ x ≤ 1`.
    pub fn cdf(&self, x: f64) -> Result<f64> {
        if !(0.0..=1.0).contains(&x) {
            return Err(Error::BadProbability { value: x });
        }
        statrs::function::beta::checked_beta_reg(self.alpha, self.beta, x).map_err(|_| {
            Error::BadBeta {
                alpha: self.alpha,
                beta: self.beta,
            }
        })
    }

    /// Posterior after `corrections` corrections among `supervised` supervised
    /// observations (Eq. 9 with per-sample, possibly fractional, counts):
    /// `Beta(α + corrections, β + supervised − corrections)`.
    ///
    /// # Errors
    /// [`Error::BadCounts`] (with `ref_idx` 0) unless `0 ≤ corrections ≤ supervised`, both
    /// finite; [`Error::BadBeta`] if the result overflows.
    pub fn posterior(&self, corrections: f64, supervised: f64) -> Result<Self> {
        if !(corrections.is_finite()
            && supervised.is_finite()
            && corrections >= 0.0
            && corrections <= supervised)
        {
            return Err(Error::BadCounts {
                ref_idx: 0,
                corrections,
                supervised,
            });
        }
        Self::new(
            self.alpha + corrections,
            self.beta + (supervised - corrections),
        )
    }

    /// Eq. 12: high confidence iff `P(p_{c|t} < μ_c) = I_{μ_c}(α, β) > γ_c`, evaluated
    /// directly with statrs (no shortcut).
    ///
    /// # Errors
    /// [`Error::BadParam`] if `params` is invalid.
    pub fn is_high_confidence(&self, params: &ConfidenceParams) -> Result<bool> {
        params.validate()?;
        Ok(decide_exact(
            self.alpha,
            self.beta,
            params.mu_c,
            params.gamma_c,
        ))
    }
}

/// Eq. 10–11 for one sample, without input checks: returns `(α₀, β₀)`.
///
/// With `g = 1 − exp(−γ_p(σ²_D + ε))` (computed with `expm1`, accurate for tiny `g`),
/// `μ = g/2`, `σ² = σ²_MAX·g` and `k = μ(1 − μ)/σ² − 1 = (2 − g)/(4σ²_MAX) − 1`
/// (the `g` cancels), `α₀ = μ·k`, `β₀ = (1 − μ)·k`.
#[inline]
pub(crate) fn prior_ab(sigma2_d: f64, params: &ConfidenceParams) -> (f64, f64) {
    let g = -(-params.gamma_p * (sigma2_d + params.epsilon)).exp_m1();
    let mu = 0.5 * g;
    let k = (2.0 - g) / (4.0 * params.sigma2_max) - 1.0;
    (mu * k, (1.0 - mu) * k)
}

/// Checks one `σ²_D` value.
#[inline]
pub(crate) fn check_variance(ref_idx: usize, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(Error::BadVariance { ref_idx, value })
    }
}

/// Checked prior for one sample.
pub(crate) fn prior_one(
    ref_idx: usize,
    sigma2_d: f64,
    params: &ConfidenceParams,
) -> Result<BetaParams> {
    check_variance(ref_idx, sigma2_d)?;
    let (alpha, beta) = prior_ab(sigma2_d, params);
    BetaParams::new(alpha, beta).map_err(|_| Error::DegeneratePrior {
        ref_idx,
        alpha,
        beta,
    })
}

/// Beta prior `Beta(α₀, β₀)` per reference sample from the demonstration variance
/// `σ²_D` (Eq. 10–11).
///
/// `sigma2_d[n]` is the dimensionless weighted variance of Eq. 6 at reference sample `n`.
/// Zero variance gives a prior concentrated near `p = 0` (mean `≈ γ_p·ε/2`); large
/// variance gives mean `1/2` and variance `σ²_MAX`.
///
/// # Errors
/// [`Error::BadParam`] for invalid `params`; [`Error::BadVariance`] naming the first
/// sample whose `σ²_D` is negative, NaN or infinite; [`Error::DegeneratePrior`] if a prior
/// parameter is not representable.
pub fn prior(sigma2_d: &[f64], params: &ConfidenceParams) -> Result<Vec<BetaParams>> {
    params.validate()?;
    sigma2_d
        .iter()
        .enumerate()
        .map(|(n, &s)| prior_one(n, s, params))
        .collect()
}

/// Posterior `Beta(α₀ + corrections[n], β₀ + supervised[n] − corrections[n])` per
/// reference sample (Eq. 9 with the per-sample observation counts of `obs`).
///
/// # Errors
/// As [`prior`], plus [`Error::LengthMismatch`] if `sigma2_d` and `obs` differ in length.
pub fn posterior(
    sigma2_d: &[f64],
    obs: &Observations,
    params: &ConfidenceParams,
) -> Result<Vec<BetaParams>> {
    params.validate()?;
    check_len("sigma2_d", sigma2_d.len(), "observations", obs.n_ref())?;
    sigma2_d
        .iter()
        .zip(obs.corrections().iter().zip(obs.supervised()))
        .enumerate()
        .map(|(n, (&s, (&c, &sup)))| {
            let p = prior_one(n, s, params)?;
            // `Observations` guarantees 0 <= c <= sup, both finite.
            let (alpha, beta) = (p.alpha + c, p.beta + (sup - c));
            BetaParams::new(alpha, beta).map_err(|_| Error::DegeneratePrior {
                ref_idx: n,
                alpha,
                beta,
            })
        })
        .collect()
}

/// Length check naming both sides.
pub(crate) fn check_len(
    left_name: &'static str,
    left: usize,
    right_name: &'static str,
    right: usize,
) -> Result<()> {
    if left == right {
        Ok(())
    } else {
        Err(Error::LengthMismatch {
            left_name,
            left,
            right_name,
            right,
        })
    }
}

/// Eq. 12 through statrs: `I_{μ_c}(α, β) > γ_c`.
///
/// `α, β > 0` finite and `μ_c ∈ (0, 1)` are established by the callers, so statrs cannot
/// return an error; if it ever did, the sample is reported low-confidence (the safe side).
#[inline]
pub(crate) fn decide_exact(alpha: f64, beta: f64, mu_c: f64, gamma_c: f64) -> bool {
    statrs::function::beta::checked_beta_reg(alpha, beta, mu_c).is_ok_and(|p| p > gamma_c)
}

/// How far (in probability) a bound must clear `γ_c` before it is trusted instead of
/// statrs at the sample itself. Much larger than the error of both the bound's arithmetic
/// (`~1e-15`) and statrs' continued fraction for the parameter ranges of a study, so the
/// shortcuts never change a decision.
pub(crate) const SHORTCUT_MARGIN: f64 = 1e-6;

/// Cantelli's one-sided inequality on the Beta CDF: `Some(decision)` when it settles
/// Eq. 12, `None` otherwise.
///
/// With mean `m` and variance `v` of `Beta(α, β)` and `d = m − μ_c`: for `d > 0`,
/// `P(p < μ_c) ≤ P(m − p ≥ d) ≤ v/(v + d²)`; for `d < 0`, `P(p ≥ μ_c) ≤ v/(v + d²)`.
/// This settles the samples whose corrections are frequent (`m ≫ μ_c`: painted regions)
/// and those with overwhelming evidence for a few flops.
#[inline]
pub(crate) fn cantelli(alpha: f64, beta: f64, mu_c: f64, gamma_c: f64) -> Option<bool> {
    let s = alpha + beta;
    let mean = alpha / s;
    let var = alpha * beta / (s * s * (s + 1.0));
    let d = mean - mu_c;
    let tail = var / (var + d * d);
    if d > 0.0 && tail < gamma_c - SHORTCUT_MARGIN {
        Some(false)
    } else if d < 0.0 && 1.0 - tail > gamma_c + SHORTCUT_MARGIN {
        Some(true)
    } else {
        None
    }
}

/// Eq. 12 with the Cantelli shortcut; returns the same decision as [`decide_exact`].
#[inline]
pub(crate) fn decide(alpha: f64, beta: f64, mu_c: f64, gamma_c: f64) -> bool {
    cantelli(alpha, beta, mu_c, gamma_c).unwrap_or_else(|| decide_exact(alpha, beta, mu_c, gamma_c))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs().max(1e-300)
    }

    /// Eq. 10 and Eq. 11 written literally (no simplification), as an independent check
    /// of `prior_ab`'s simplified form.
    fn literal(sigma2_d: f64, p: &ConfidenceParams) -> (f64, f64, f64, f64) {
        let e = 1.0 - (-p.gamma_p * (sigma2_d + p.epsilon)).exp();
        let mu = 0.5 * e;
        let var = p.sigma2_max * e;
        let k = mu * (1.0 - mu) / var - 1.0;
        (mu * k, (1.0 - mu) * k, mu, var)
    }

    #[test]
    fn prior_matches_eq_10_11_by_hand() {
        let p = ConfidenceParams::default();
        // Large variance: g = 1 in f64, mu = 1/2, var = 0.05, k = 1/0.2 - 1 = 4,
        // alpha_0 = beta_0 = 2.
        let b = prior(&[10.0], &p).unwrap()[0];
        assert!(
            close(b.alpha(), 2.0, 1e-14) && close(b.beta(), 2.0, 1e-14),
            "{b:?}"
        );
        assert!(close(b.mean(), 0.5, 1e-14));
        assert!(close(b.variance(), 0.05, 1e-13));
        // sigma2_d = 0.05: gamma_p (sigma2_d + eps) = 0.50001, g = 1 - e^-0.50001.
        // Values from mpmath at 30 digits (see tests/reference_values.rs).
        let b = prior(&[0.05], &p).unwrap()[0];
        assert!(close(b.alpha(), 1.383_582_088_077_695_6, 1e-13), "{b:?}");
        assert!(close(b.beta(), 5.649_040_884_104_118, 1e-13), "{b:?}");
        assert!(close(b.mean(), 0.196_737_702_781_818_64, 1e-13));
        assert!(close(b.variance(), 0.019_673_770_278_181_864, 1e-12));
        // Against the literal formulas on a sweep.
        for s in [0.0, 1e-9, 1e-4, 0.003, 0.02, 0.1, 0.7, 3.0, 1e3] {
            let b = prior(&[s], &p).unwrap()[0];
            let (a, bb, mu, var) = literal(s, &p);
            assert!(close(b.alpha(), a, 1e-9), "{s}: {} vs {a}", b.alpha());
            assert!(close(b.beta(), bb, 1e-9), "{s}");
            assert!(close(b.mean(), mu, 1e-9), "{s}");
            assert!(close(b.variance(), var, 1e-8), "{s}");
        }
    }

    #[test]
    fn zero_variance_prior_is_confident() {
        // sigma2_d = 0: g ~ gamma_p eps = 1e-5, alpha_0 ~ g/2 (1/(4 sigma2_max)*2 - 1)
        // = 0.5e-5 * 9 = 4.5e-5, beta_0 ~ 9.
        let p = ConfidenceParams::default();
        let b = prior(&[0.0], &p).unwrap()[0];
        assert!(close(b.alpha(), 4.5e-5, 1e-4), "{b:?}");
        assert!(close(b.beta(), 9.0, 1e-4), "{b:?}");
        assert!(b.is_high_confidence(&p).unwrap());
    }

    #[test]
    fn bad_variance_names_the_sample() {
        let p = ConfidenceParams::default();
        for v in [-1e-12, f64::NAN, f64::INFINITY] {
            let err = prior(&[0.1, 0.2, v, 0.3], &p).unwrap_err();
            assert!(
                matches!(err, Error::BadVariance { ref_idx: 2, value } if value.to_bits() == v.to_bits()),
                "{err:?}"
            );
            assert!(err.to_string().contains("reference sample 2"), "{err}");
        }
    }

    #[test]
    fn posterior_adds_counts() {
        let b = BetaParams::new(2.0, 2.0).unwrap();
        let q = b.posterior(1.5, 4.0).unwrap();
        assert_eq!((q.alpha(), q.beta()), (3.5, 4.5));
        assert!(b.posterior(2.0, 1.0).is_err());
        assert!(b.posterior(-0.1, 1.0).is_err());
        assert!(b.posterior(f64::NAN, 1.0).is_err());
    }

    #[test]
    fn beta_params_are_checked() {
        assert!(BetaParams::new(0.0, 1.0).is_err());
        assert!(BetaParams::new(1.0, f64::INFINITY).is_err());
        assert!(BetaParams::new(f64::NAN, 1.0).is_err());
        let b = BetaParams::new(2.0, 3.0).unwrap();
        assert!(b.cdf(1.1).is_err());
        assert!(b.cdf(f64::NAN).is_err());
        assert_eq!(b.cdf(0.0).unwrap(), 0.0);
        assert!(serde_json::from_str::<BetaParams>(r#"{"alpha":-1,"beta":2}"#).is_err());
        let back: BetaParams = serde_json::from_str(&serde_json::to_string(&b).unwrap()).unwrap();
        assert_eq!(back, b);
    }

    #[test]
    fn shortcut_equals_statrs_on_a_grid() {
        // Dense grid over the ranges a study reaches, including the threshold region.
        let mut n = 0;
        for i in 0..200 {
            let alpha = 1e-5 * 1.09_f64.powi(i);
            for j in 0..200 {
                let beta = 0.05 * 1.05_f64.powi(j);
                for (mu_c, gamma_c) in [(0.05, 0.95), (0.1, 0.5), (0.02, 0.99)] {
                    assert_eq!(
                        decide(alpha, beta, mu_c, gamma_c),
                        decide_exact(alpha, beta, mu_c, gamma_c),
                        "alpha {alpha} beta {beta} mu_c {mu_c} gamma_c {gamma_c}"
                    );
                    n += 1;
                }
            }
        }
        assert_eq!(n, 120_000);
    }
}
