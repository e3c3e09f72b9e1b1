//! The latched high-confidence state per reference sample (Eq. 12 + latch).

use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::beta::{check_len, check_variance, decide, prior_ab};
use crate::boundary::Boundary;
use crate::rates::{decide_with_rates, prob_need_below};
use crate::{ConfidenceParams, Error, ErrorRates, MIN_OBSERVATIONS, Observations, Result};

/// Fewest supervised votes (units of `Observations::supervised`, one per execution with
/// [`ConfidenceParams::one_vote_per_execution`]) on which a sample that has been supervised
/// is trusted ([`Confidence::update`], [`evaluate`]); a sample never observed is decided by
/// its prior alone, as before.
///
/// Why: the latch is final for a sample that nobody supervises again, and the prior of a
/// sample whose `σ²_D` lies near the prior's threshold ([`crate::prior_low_threshold`]) is
/// worth about nine clean observations already (`α₀ + β₀ = (2 − g)/(4σ²_MAX) − 1`), while
/// the model's update (Eq. 21) lowers `σ²_D` with every uncorrected execution, which replays
/// the mean: two clean votes passed Eq. 12 there. On the task zoo's screw driving, samples
/// needed on 30–80 % of the workpieces were latched after 2–8 clean votes and never
/// supervised again (docs/decisions.md, "Graded needs: the error rate's estimate and the
/// latch's evidence").
/// After ten votes a need of 30 % has shown itself with probability `1 − 0.7¹⁰ = 97 %`, one
/// of 50 % with `1 − 0.5¹⁰ = 99.9 %`: the same number as the estimate of the error rates
/// asks for ([`MIN_OBSERVATIONS`], by the same argument). The paper's counting (one unit
/// per control sample, [`ConfidenceParams::paper`]) is left as the paper has it.
pub const MIN_VOTES: f64 = MIN_OBSERVATIONS;

/// `conf(t)` per reference sample, latched: once a sample is high-confidence it stays so.
///
/// [`update`](Confidence::update) recomputes Eq. 12 from the current demonstration
/// variance (prior, Eq. 10–11) and observations (posterior, Eq. 9) for every sample that
/// is still low-confidence, and latches those that pass. A latched sample is never
/// re-evaluated, so a later variance increase (which moves its prior towards
/// `Beta(2, 2)`) or a later correction cannot turn it back to low confidence. The paper's
/// claim that "the previous scheduling solution will always remain valid" rests on this:
/// a schedule that was feasible for one confidence map is feasible for any map with
/// more high-confidence samples. [`update_round`](Confidence::update_round), which the
/// planner uses, keeps that latch against the prior and the error rates but not against
/// corrections recorded after it, so that the same rounds give the same map in any order.
///
/// **The prior's trust yields to a need on both sides** (with one vote per execution,
/// [`ConfidenceParams::one_vote_per_execution`]; the paper's counting has no yield):
/// [`conf`](Self::conf) is the latch ([`latched`](Self::latched)) except that each maximal
/// run of latched samples that rest on their prior alone (no correction, fewer than
/// [`MIN_VOTES`] votes) is low-confidence while the samples on both sides of it are not
/// latched and are needed by their totals: at least one correction and
/// `P(π < μ_c | data) < 1 − γ_c` (Eq. 12 mirrored, at `μ'_c` with non-zero error rates).
/// The run is then supervised; it keeps its latch, so it is trusted again once it has
/// [`MIN_VOTES`] clean votes (it no longer rests on its prior) or once a side is no longer
/// needed, and a correction decides it on its totals like any latched sample.
/// The yield is **not stored**: it is evaluated from the latch, `σ²_D`, the totals of the
/// observations and the error rates estimated from them whenever the confidence is
/// computed ([`update`](Self::update), [`update_round`](Self::update_round),
/// [`refresh`](Self::refresh)), so it adds no history: whatever the order of the rounds,
/// the confidence is the same function of the same latch and the same totals.
/// Why: the prior sees only where the demonstrations disagree. Where the operator is
/// needed although they agree (a search that the alignment pairs turn by turn), the prior
/// trusts a stretch inside a need that the operator corrects on both sides in every round,
/// and a trusted sample is never supervised, so nothing else reveals the need
/// (docs/decisions.md, "The prior's trust yields to a need on both sides, from the
/// totals"). A stretch with a need on one side only is left to its prior: the need may end
/// at the border as well as go on.
///
/// ```
/// use tandem_confidence::{Confidence, ConfidenceParams, Observations};
/// let sigma2_d = [0.0, 10.0, 10.0, 0.0];
/// let mut conf = Confidence::from_prior(&sigma2_d, ConfidenceParams::paper())?;
/// assert_eq!(conf.conf(), &[true, false, false, true]);
/// assert_eq!(conf.low_regions(), vec![1..3]);
/// assert_eq!(conf.high_share(), 0.5);
/// // 90 executions supervise samples 1 and 2 and only ever correct sample 2.
/// let mut obs = Observations::new(4)?;
/// for _ in 0..90 {
///     obs.record(&[1.0, 2.0], &[false, true])?;
/// }
/// assert_eq!(conf.update(&sigma2_d, &obs)?, 1); // one sample newly latched
/// assert_eq!(conf.conf(), &[true, true, false, true]);
/// # Ok::<(), tandem_confidence::Error>(())
/// ```
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(try_from = "ConfidenceData")]
pub struct Confidence {
    params: ConfidenceParams,
    /// The latch (what the state file stores).
    high: Vec<bool>,
    /// `conf`: the latch less the prior's trust that yields to a need on both sides (the
    /// type docs), evaluated from the totals at every update; equal to the latch until the
    /// first update or [`refresh`](Confidence::refresh).
    #[serde(skip)]
    view: Vec<bool>,
    /// Cache of certified points of the Eq. 12 boundary (speed only; see `boundary.rs`).
    #[serde(skip)]
    boundary: Boundary,
    /// The same at the shifted threshold `μ'_c` of the last update with non-zero error
    /// rates (speed only: it screens out samples that stay low).
    #[serde(skip)]
    shifted: Option<(f64, Boundary)>,
}

/// Equality of the model state (parameters, the latch and `conf`); the evaluation cache is
/// ignored.
impl PartialEq for Confidence {
    fn eq(&self, other: &Self) -> bool {
        self.params == other.params && self.high == other.high && self.view == other.view
    }
}

/// Unchecked serde form of [`Confidence`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConfidenceData {
    params: ConfidenceParams,
    high: Vec<bool>,
}

impl TryFrom<ConfidenceData> for Confidence {
    type Error = Error;
    fn try_from(d: ConfidenceData) -> Result<Self> {
        Self::from_parts(d.params, d.high)
    }
}

/// What [`Confidence::update_round`] changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RoundUpdate {
    /// Samples that became high-confidence ([`Confidence::conf`]) in this update: newly
    /// latched, or a latched run whose prior's trust no longer yields.
    pub newly_high: usize,
    /// High-confidence samples that turned low-confidence again: latched samples whose
    /// totals no longer pass Eq. 12 after the round's corrections, and latched samples that
    /// rest on their prior alone and now yield to a need on both sides.
    pub reopened: usize,
}

impl Confidence {
    /// All `n_ref` samples low-confidence (nothing latched yet). Call
    /// [`update`](Self::update) to evaluate the prior, or use
    /// [`from_prior`](Self::from_prior).
    ///
    /// # Errors
    /// [`Error::BadParam`] for invalid `params`; [`Error::EmptyReference`] if `n_ref == 0`.
    pub fn new(n_ref: usize, params: ConfidenceParams) -> Result<Self> {
        Self::from_parts(params, vec![false; n_ref])
    }

    /// State after evaluating the prior alone (no executions yet): high confidence where
    /// the demonstrations barely vary.
    ///
    /// # Errors
    /// As [`new`](Self::new) and [`update`](Self::update).
    pub fn from_prior(sigma2_d: &[f64], params: ConfidenceParams) -> Result<Self> {
        let mut conf = Self::new(sigma2_d.len(), params)?;
        // Without observations the rates are the configured ones.
        let rates = ErrorRates::configured(&conf.params);
        conf.latch(sigma2_d, &rates, |_| (0.0, 0.0))?;
        Ok(conf)
    }

    /// Restores a saved state: `high[n]` is the latch of reference sample `n`
    /// ([`latched`](Self::latched)); `conf` equals it until [`refresh`](Self::refresh) or an
    /// update evaluates the prior's yield on the totals.
    ///
    /// # Errors
    /// [`Error::BadParam`] for invalid `params`; [`Error::EmptyReference`] if `high` is
    /// empty.
    pub fn from_parts(params: ConfidenceParams, high: Vec<bool>) -> Result<Self> {
        params.validate()?;
        if high.is_empty() {
            return Err(Error::EmptyReference);
        }
        Ok(Self {
            params,
            view: high.clone(),
            high,
            boundary: Boundary::default(),
            shifted: None,
        })
    }

    /// Re-evaluates Eq. 12 for every sample that is not yet latched, from the current
    /// demonstration variance `sigma2_d` (Eq. 6, dimensionless, one per reference sample)
    /// and all observations so far, and latches the samples that pass.
    /// Returns how many samples became high-confidence in this call. The prior's trust then
    /// yields to a need on both sides on these totals (the type docs).
    ///
    /// With non-zero operator error rates (estimated from `obs` when
    /// [`ConfidenceParams::estimate_error_rates`], [`crate::estimate_error_rates`]) the test
    /// is `P(π < μ_c | data) > γ_c` for the need `π` behind the corrections
    /// ([`crate::rates`](crate::estimate_error_rates) module docs); with zero rates it is
    /// Eq. 12 exactly.
    ///
    /// Every input is checked before the state changes: on error nothing is latched.
    ///
    /// Cost: latched samples are skipped; for the others the incomplete beta function is
    /// evaluated only when neither a Cantelli bound on the Beta CDF nor a cached, certified
    /// bracket of the Eq. 12 boundary (monotonicity of `I_{μ_c}(α, β)` in `α` and `β`)
    /// settles the comparison with `γ_c`. The decision is identical to evaluating statrs
    /// everywhere; the cache fills on first use (a few ms once) and is not serialized.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if `sigma2_d` or `obs` do not have
    /// [`n_ref`](Self::n_ref) samples; [`Error::BadVariance`] naming the first bad `σ²_D`;
    /// [`Error::DegeneratePrior`] if a prior is not representable.
    pub fn update(&mut self, sigma2_d: &[f64], obs: &Observations) -> Result<usize> {
        check_len(
            "observations",
            obs.n_ref(),
            "the confidence state",
            self.n_ref(),
        )?;
        let rates = crate::estimate_error_rates(obs, &self.params)?;
        let (c, s) = (obs.corrections(), obs.supervised());
        Ok(self
            .latch_reopening(sigma2_d, &rates, |n| (c[n], s[n]), |_| false)?
            .0)
    }

    /// Evaluates `conf` again from the latch and the totals `obs` (the prior's trust that
    /// yields to a need on both sides, the type docs) without changing the latch: what
    /// [`update`](Self::update) ends with. Call it on a state restored with
    /// [`from_parts`](Self::from_parts) with the `σ²_D` and the observations it was last
    /// updated with, so that `conf` is the one it had when it was saved. Returns how many
    /// latched samples yield.
    ///
    /// # Errors
    /// As [`update`](Self::update); on error nothing changes.
    pub fn refresh(&mut self, sigma2_d: &[f64], obs: &Observations) -> Result<usize> {
        check_len(
            "observations",
            obs.n_ref(),
            "the confidence state",
            self.n_ref(),
        )?;
        self.check_sigma2_d(sigma2_d)?;
        let (c, s) = (obs.corrections(), obs.supervised());
        // Without a correction nothing is needed, and the rates need no estimate.
        let view = if self.params.one_vote_per_execution && c.iter().any(|&c| c > 0.0) {
            let rates = crate::estimate_error_rates(obs, &self.params)?;
            self.yielded(sigma2_d, &rates, |n| (c[n], s[n]))
        } else {
            self.high.clone()
        };
        let n_yield = self
            .high
            .iter()
            .zip(&view)
            .filter(|(h, v)| **h && !**v)
            .count();
        self.view = view;
        Ok(n_yield)
    }

    /// [`update`](Self::update) after one round of executions, whose observations took the
    /// totals from `before` to `after`: the decision is the one the totals `after` give
    /// (Eq. 9–12 on `sigma2_d` and the error rates estimated from `after`), and the latch
    /// holds against everything but the operator's corrections. A latched sample that the
    /// round gave correction mass (`after.corrections()[n] > before.corrections()[n]`) is
    /// decided again on the totals, and is low-confidence again if they do not pass.
    ///
    /// Why (docs/decisions.md, "The same rounds in any order: the latch yields to
    /// corrections"): the paper latches because "high-confidence time steps cannot transition
    /// back to low-confidence time steps (i.e., cannot be given corrections)". The premise
    /// fails twice: rounds recorded out of order (several cells or processes running the
    /// schedules of older states) bring corrections of samples latched since they ran, and in
    /// order the observation of a supervised sample reaches a latched neighbour at the edge of
    /// a supervised stretch (the split of Eq. 9's fractional times, the sweep of
    /// [`Observations::record_votes_swept`]). A latch that ignored those corrections kept a
    /// sample trusted by the luck of having its clean rounds recorded first. With the latch
    /// yielding to corrections, the confidence after a set of rounds is the totals' decision
    /// whatever their order, except where the prior (`σ²_D`, which Eq. 21 moves) or the
    /// estimated error rates were more favourable at an earlier round at which the sample's
    /// whole correction record already passed: there the latch still holds, as the paper
    /// wants it to against a widening `σ²_D`.
    ///
    /// With `before == after` this is [`update`](Self::update).
    ///
    /// ```
    /// use tandem_confidence::{Confidence, ConfidenceParams, Observations};
    /// let sigma2_d = [10.0];
    /// let p = ConfidenceParams::paper();
    /// let clean = |obs: &mut Observations| obs.record(&[0.0; 90], &[false; 90]);
    /// // 90 clean observations latch the sample; then 10 corrected ones arrive.
    /// let (mut a, mut obs) = (Confidence::from_prior(&sigma2_d, p.clone())?, Observations::new(1)?);
    /// let before = obs.clone();
    /// clean(&mut obs)?;
    /// assert_eq!(a.update_round(&sigma2_d, &before, &obs)?.newly_high, 1);
    /// let before = obs.clone();
    /// obs.record(&[0.0; 10], &[true; 10])?;
    /// assert_eq!(a.update_round(&sigma2_d, &before, &obs)?.reopened, 1);
    /// assert!(!a.conf()[0]);
    /// // The other order ends the same: the corrections first, then the clean rounds.
    /// let (mut b, mut obs) = (Confidence::from_prior(&sigma2_d, p)?, Observations::new(1)?);
    /// for step in 0..2 {
    ///     let before = obs.clone();
    ///     if step == 0 { obs.record(&[0.0; 10], &[true; 10])? } else { clean(&mut obs)? }
    ///     b.update_round(&sigma2_d, &before, &obs)?;
    /// }
    /// assert_eq!(a, b);
    /// # Ok::<(), tandem_confidence::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`update`](Self::update); [`Error::LengthMismatch`] if `before` has another
    /// length; [`Error::NotEarlier`] naming the first sample where `before` holds more mass
    /// than `after` (it is not an earlier state of the same observations).
    pub fn update_round(
        &mut self,
        sigma2_d: &[f64],
        before: &Observations,
        after: &Observations,
    ) -> Result<RoundUpdate> {
        check_len(
            "observations",
            after.n_ref(),
            "the confidence state",
            self.n_ref(),
        )?;
        check_len(
            "observations before the round",
            before.n_ref(),
            "observations after it",
            after.n_ref(),
        )?;
        let (c0, s0) = (before.corrections(), before.supervised());
        let (c, s) = (after.corrections(), after.supervised());
        for ref_idx in 0..c.len() {
            for (what, b, a) in [
                ("correction", c0[ref_idx], c[ref_idx]),
                ("supervised", s0[ref_idx], s[ref_idx]),
            ] {
                if b > a {
                    return Err(Error::NotEarlier {
                        ref_idx,
                        what,
                        before: b,
                        after: a,
                    });
                }
            }
        }
        let rates = crate::estimate_error_rates(after, &self.params)?;
        let (newly_high, reopened) =
            self.latch_reopening(sigma2_d, &rates, |n| (c[n], s[n]), |n| c[n] > c0[n])?;
        Ok(RoundUpdate {
            newly_high,
            reopened,
        })
    }

    /// Shared body of [`from_prior`](Self::from_prior) and the updates:
    /// `counts(n)` gives `(corrections[n], supervised[n])`, with `0 ≤ c ≤ s` finite.
    fn latch(
        &mut self,
        sigma2_d: &[f64],
        rates: &ErrorRates,
        counts: impl Fn(usize) -> (f64, f64),
    ) -> Result<usize> {
        Ok(self.latch_reopening(sigma2_d, rates, counts, |_| false)?.0)
    }

    /// Checks `sigma2_d` against this state: its length and every value.
    fn check_sigma2_d(&self, sigma2_d: &[f64]) -> Result<()> {
        self.params.validate()?;
        check_len(
            "sigma2_d",
            sigma2_d.len(),
            "the confidence state",
            self.n_ref(),
        )?;
        for (ref_idx, &v) in sigma2_d.iter().enumerate() {
            check_variance(ref_idx, v)?;
        }
        Ok(())
    }

    /// [`latch`](Self::latch) where the latched samples with `reopen(n)` are decided again
    /// too, then `conf` evaluated on the same totals (the prior's yield):
    /// `(samples that turned high, samples that turned low)` in `conf`.
    fn latch_reopening(
        &mut self,
        sigma2_d: &[f64],
        rates: &ErrorRates,
        counts: impl Fn(usize) -> (f64, f64),
        reopen: impl Fn(usize) -> bool,
    ) -> Result<(usize, usize)> {
        self.check_sigma2_d(sigma2_d)?;
        let Self {
            params: p,
            high: latched,
            boundary,
            shifted,
            ..
        } = self;
        let mu_shifted = rates.shifted_mu_c(p.mu_c);
        if !rates.is_zero() && shifted.as_ref().is_none_or(|(mu, _)| *mu != mu_shifted) {
            *shifted = Some((mu_shifted, Boundary::default()));
        }
        let (mut newly, mut lowered) = (Vec::new(), Vec::new());
        for (ref_idx, (&high, &s2)) in latched.iter().zip(sigma2_d).enumerate() {
            if high && !reopen(ref_idx) {
                continue;
            }
            let (alpha0, beta0) = prior_ab(s2, p);
            if !(alpha0 > 0.0 && beta0 > 0.0 && alpha0.is_finite() && beta0.is_finite()) {
                return Err(Error::DegeneratePrior {
                    ref_idx,
                    alpha: alpha0,
                    beta: beta0,
                });
            }
            let (c, s) = counts(ref_idx);
            let (alpha, beta) = (alpha0 + c, beta0 + (s - c));
            if !(alpha.is_finite() && beta.is_finite()) {
                return Err(Error::DegeneratePrior {
                    ref_idx,
                    alpha,
                    beta,
                });
            }
            let was_high = high;
            let mut decide = |alpha: f64, beta: f64| match shifted {
                // `P(π < μ_c | data) = I_{μ'_c}(α, β)`: Eq. 12 at `μ'_c`, with its own cache.
                Some((mu, cache)) if !rates.is_zero() => cache.decide(alpha, beta, *mu, p.gamma_c),
                _ => boundary.decide(alpha, beta, p.mu_c, p.gamma_c),
            };
            // The latch's evidence: with one vote per execution, a sample once supervised is
            // trusted on `MIN_VOTES` votes at least (unobserved, the prior decides).
            let high =
                decide(alpha, beta) && (!p.one_vote_per_execution || s == 0.0 || s >= MIN_VOTES);
            match (was_high, high) {
                (false, true) => newly.push(ref_idx),
                (true, false) => lowered.push(ref_idx),
                _ => {}
            }
        }
        // Every prior was representable: nothing below can fail, so the state changes only
        // now.
        for &ref_idx in &newly {
            self.high[ref_idx] = true;
        }
        for &ref_idx in &lowered {
            self.high[ref_idx] = false;
        }
        let view = if self.params.one_vote_per_execution {
            self.yielded(sigma2_d, rates, &counts)
        } else {
            self.high.clone()
        };
        let turned_high = self.view.iter().zip(&view).filter(|(b, a)| !**b && **a);
        let turned_low = self.view.iter().zip(&view).filter(|(b, a)| **b && !**a);
        let counted = (turned_high.count(), turned_low.count());
        self.view = view;
        Ok(counted)
    }

    /// `conf` from the latch and the totals: the latch less every maximal run of latched
    /// samples that rest on their prior alone (`c = 0`, `s <` [`MIN_VOTES`]) whose
    /// neighbours on both sides are not latched and are needed by their totals (`c > 0` and
    /// `P(π < μ_c | data) < 1 − γ_c`, Eq. 12 mirrored at `μ'_c`; the type docs). A pure
    /// function of `(latch, σ²_D, counts, rates)`: nothing of it is stored.
    fn yielded(
        &self,
        sigma2_d: &[f64],
        rates: &ErrorRates,
        counts: impl Fn(usize) -> (f64, f64),
    ) -> Vec<bool> {
        let p = &self.params;
        let needed = |n: usize| -> bool {
            let (c, s) = counts(n);
            if self.high[n] || c <= 0.0 {
                return false;
            }
            let (alpha0, beta0) = prior_ab(sigma2_d[n], p);
            prob_need_below(alpha0 + c, beta0 + (s - c), rates, p.mu_c)
                .is_some_and(|below| below < 1.0 - p.gamma_c)
        };
        let on_prior = |n: usize| {
            let (c, s) = counts(n);
            self.high[n] && c == 0.0 && s < MIN_VOTES
        };
        let mut view = self.high.clone();
        let n_ref = view.len();
        let mut n = 0;
        while n < n_ref {
            if !on_prior(n) {
                n += 1;
                continue;
            }
            let start = n;
            while n < n_ref && on_prior(n) {
                n += 1;
            }
            if start > 0 && n < n_ref && needed(start - 1) && needed(n) {
                view[start..n].fill(false);
            }
        }
        view
    }

    /// The latch per reference sample (what the state file stores): `conf` before the
    /// prior's trust yields to a need on both sides (the type docs). A sample high in
    /// [`conf`](Self::conf) is high here.
    #[must_use]
    pub fn latched(&self) -> &[bool] {
        &self.high
    }

    /// The parameters this state was built with.
    #[must_use]
    pub fn params(&self) -> &ConfidenceParams {
        &self.params
    }

    /// Number of reference samples `T_ref`.
    #[must_use]
    pub fn n_ref(&self) -> usize {
        self.high.len()
    }

    /// `conf` per reference sample: `true` = high confidence (may run unsupervised). The
    /// latch less the prior's trust that yields to a need on both sides, as of the last
    /// update or [`refresh`](Self::refresh) (the type docs).
    #[must_use]
    pub fn conf(&self) -> &[bool] {
        &self.view
    }

    /// Number of high-confidence reference samples.
    #[must_use]
    pub fn n_high(&self) -> usize {
        self.view.iter().filter(|&&h| h).count()
    }

    /// Share of high-confidence reference samples, in `[0, 1]` (Fig. 5, bottom).
    #[must_use]
    pub fn high_share(&self) -> f64 {
        // Lossless for any reference shorter than 2^53 samples.
        self.n_high() as f64 / self.n_ref() as f64
    }

    /// Maximal runs of low-confidence reference samples, in increasing order.
    #[must_use]
    pub fn low_regions(&self) -> Vec<Range<usize>> {
        crate::low_regions(&self.view)
    }
}

/// Eq. 12 per reference sample without any latch: `I_{μ_c}(α, β) > γ_c` for the
/// posterior of [`posterior`](crate::posterior), or with non-zero operator error rates
/// `P(π < μ_c | data) > γ_c` ([`Confidence::update`]). The decision is exactly statrs'
/// (a Cantelli bound only skips evaluations it provably cannot change).
///
/// # Errors
/// As [`posterior`](crate::posterior).
pub fn evaluate(
    sigma2_d: &[f64],
    obs: &Observations,
    params: &ConfidenceParams,
) -> Result<Vec<bool>> {
    let rates = crate::estimate_error_rates(obs, params)?;
    Ok(crate::posterior(sigma2_d, obs, params)?
        .iter()
        .zip(obs.supervised())
        .map(|(b, &s)| {
            (if rates.is_zero() {
                decide(b.alpha(), b.beta(), params.mu_c, params.gamma_c)
            } else {
                decide_with_rates(b.alpha(), b.beta(), &rates, params.mu_c, params.gamma_c)
            }) && (!params.one_vote_per_execution || s == 0.0 || s >= MIN_VOTES)
        })
        .collect())
}

/// `P(π < μ_c | data)` per reference sample: the posterior probability that the need for
/// corrections is below `μ_c`, which Eq. 12 compares with `γ_c` (with zero error rates
/// `I_{μ_c}(α, β)`; [`Confidence::update`]). `NaN` where statrs cannot evaluate it.
///
/// # Errors
/// As [`posterior`](crate::posterior).
pub fn prob_need_below_mu_c(
    sigma2_d: &[f64],
    obs: &Observations,
    params: &ConfidenceParams,
) -> Result<Vec<f64>> {
    let rates = crate::estimate_error_rates(obs, params)?;
    Ok(crate::posterior(sigma2_d, obs, params)?
        .iter()
        .map(|b| prob_need_below(b.alpha(), b.beta(), &rates, params.mu_c).unwrap_or(f64::NAN))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latch_holds_when_variance_increases() {
        let p = ConfidenceParams::paper();
        // Near-zero variance: high from the prior alone.
        let mut conf = Confidence::from_prior(&[0.0, 0.0], p.clone()).unwrap();
        assert_eq!(conf.conf(), &[true, true]);
        // Variance jumps: the fresh prior Beta(2, 2) would be low-confidence...
        let obs = Observations::new(2).unwrap();
        assert_eq!(
            evaluate(&[10.0, 10.0], &obs, &p).unwrap(),
            vec![false, false]
        );
        // ...but the latched state keeps both samples high.
        assert_eq!(conf.update(&[10.0, 10.0], &obs).unwrap(), 0);
        assert_eq!(conf.conf(), &[true, true]);
        // Corrections after latching do not unlatch either.
        let mut obs = Observations::new(2).unwrap();
        obs.record(&[0.0; 50], &[true; 50]).unwrap();
        conf.update(&[10.0, 10.0], &obs).unwrap();
        assert_eq!(conf.conf(), &[true, true]);
    }

    #[test]
    fn errors_leave_state_unchanged_and_name_lengths() {
        let p = ConfidenceParams::paper();
        let mut conf = Confidence::new(3, p).unwrap();
        let obs = Observations::new(3).unwrap();
        let err = conf.update(&[0.0, 0.0], &obs).unwrap_err();
        assert_eq!(
            err,
            Error::LengthMismatch {
                left_name: "sigma2_d",
                left: 2,
                right_name: "the confidence state",
                right: 3
            }
        );
        assert!(
            err.to_string().contains("2") && err.to_string().contains("3"),
            "{err}"
        );
        let err = conf
            .update(&[0.0, 0.0, 0.0], &Observations::new(4).unwrap())
            .unwrap_err();
        assert!(
            matches!(
                err,
                Error::LengthMismatch {
                    left: 4,
                    right: 3,
                    ..
                }
            ),
            "{err:?}"
        );
        // Sample 0 would latch, but sample 2 is bad: nothing may change.
        let err = conf.update(&[0.0, 0.0, f64::NAN], &obs).unwrap_err();
        assert!(
            matches!(err, Error::BadVariance { ref_idx: 2, .. }),
            "{err:?}"
        );
        assert_eq!(conf.conf(), &[false, false, false]);
        assert_eq!(
            Confidence::new(0, ConfidenceParams::paper()),
            Err(Error::EmptyReference)
        );
        let bad = ConfidenceParams {
            gamma_c: 1.0,
            ..Default::default()
        };
        assert!(matches!(
            Confidence::new(3, bad),
            Err(Error::BadParam {
                name: "gamma_c",
                ..
            })
        ));
    }

    #[test]
    fn summaries() {
        let p = ConfidenceParams::paper();
        let conf = Confidence::from_parts(p, vec![true, false, false, true, false]).unwrap();
        assert_eq!(conf.n_high(), 2);
        assert_eq!(conf.high_share(), 0.4);
        assert_eq!(conf.low_regions(), vec![1..3, 4..5]);
        assert_eq!(crate::low_regions(&[false, false]), vec![0..2]);
        assert!(crate::low_regions(&[]).is_empty());
    }

    #[test]
    fn serde_round_trip() {
        let mut conf = Confidence::from_prior(&[0.0, 1.0, 0.001], Default::default()).unwrap();
        let mut obs = Observations::new(3).unwrap();
        obs.record(&[1.0, 1.5], &[false, true]).unwrap();
        conf.update(&[0.0, 1.0, 0.001], &obs).unwrap();
        let json = serde_json::to_string(&conf).unwrap();
        let back: Confidence = serde_json::from_str(&json).unwrap();
        assert_eq!(back, conf);
        let bad = r#"{"params":{"mu_c":2.0},"high":[true]}"#;
        let err = serde_json::from_str::<Confidence>(bad).unwrap_err();
        assert!(err.to_string().contains("mu_c"), "{err}");
        assert!(serde_json::from_str::<Confidence>(r#"{"params":{},"high":[]}"#).is_err());
    }

    #[test]
    fn a_supervised_sample_is_trusted_on_ten_votes_not_on_its_prior_and_two() {
        // σ²_D just above the prior's threshold: low from the prior, but worth about nine
        // clean observations already, so two clean votes passed Eq. 12 before MIN_VOTES
        // (docs/decisions.md, "Graded needs: the error rate's estimate and the latch's
        // evidence"). Fixed rates, so that only the votes move the decision.
        let p = ConfidenceParams {
            estimate_error_rates: false,
            ..ConfidenceParams::default()
        };
        let s2 = 1.05 * crate::prior_low_threshold(&p).unwrap().unwrap();
        let sigma2_d = [s2];
        let mut conf = Confidence::from_prior(&sigma2_d, p.clone()).unwrap();
        assert_eq!(conf.conf(), &[false]);
        let mut obs = Observations::new(1).unwrap();
        for vote in 1..=10 {
            obs.record_votes(&[0.0], &[false]).unwrap();
            conf.update(&sigma2_d, &obs).unwrap();
            // Without the rule the posterior alone passes from the second vote on.
            let posterior = crate::posterior(&sigma2_d, &obs, &p).unwrap()[0];
            if vote >= 2 {
                assert!(crate::beta::decide_exact(
                    posterior.alpha(),
                    posterior.beta(),
                    ErrorRates::configured(&p).shifted_mu_c(p.mu_c),
                    p.gamma_c
                ));
            }
            assert_eq!(conf.conf(), &[vote >= 10], "after {vote} votes");
            assert_eq!(
                evaluate(&sigma2_d, &obs, &p).unwrap(),
                vec![vote >= 10],
                "evaluate after {vote} votes"
            );
        }
        // The paper's counting (one unit per control sample) keeps the paper's rule: two
        // clean observations are enough there.
        let paper = ConfidenceParams::paper();
        let s2 = 1.05 * crate::prior_low_threshold(&paper).unwrap().unwrap();
        let mut conf = Confidence::from_prior(&[s2], paper).unwrap();
        let mut obs = Observations::new(1).unwrap();
        obs.record(&[0.0, 0.0], &[false, false]).unwrap();
        conf.update(&[s2], &obs).unwrap();
        assert_eq!(conf.conf(), &[true]);
    }

    /// Records `votes` clean (or corrected) votes at each of `samples`, `times` times.
    fn votes(obs: &mut Observations, samples: &[f64], corrected: bool, times: usize) {
        for _ in 0..times {
            let flags = vec![corrected; samples.len()];
            obs.record_votes(samples, &flags).unwrap();
        }
    }

    #[test]
    fn the_priors_trust_yields_to_a_need_on_both_sides_as_a_function_of_the_totals() {
        // The demonstrations disagree at samples 1, 4 and 8 only (low-confidence from the
        // prior); sample 6 earns its trust on twelve clean votes. Fixed rates, so that only
        // the votes count.
        let p = ConfidenceParams {
            estimate_error_rates: false,
            ..ConfidenceParams::default()
        };
        let sigma2_d = [0.0, 10.0, 0.0, 0.0, 10.0, 0.0, 0.0, 0.0, 10.0];
        let from_prior = [true, false, true, true, false, true, true, true, false];
        let mut conf = Confidence::from_prior(&sigma2_d, p.clone()).unwrap();
        assert_eq!(conf.conf(), &from_prior);
        let mut obs = Observations::new(9).unwrap();
        votes(&mut obs, &[6.0], false, 12);
        // No correction yet: the prior's trust stands.
        let before = obs.clone();
        conf.update_round(&sigma2_d, &before, &obs).unwrap();
        assert_eq!(conf.conf(), &from_prior);
        // Two corrected executions at samples 1, 4 and 8. σ²_D = 10 is far above σ²_MAX, so
        // the prior is Beta(1, 1) (g = 0, Eq. 10–11), and the posterior Beta(3, 1) gives
        // P(π < 0.05) = 0.05³ = 1.25e-4 < 1 − γ_c = 0.05: needed. Samples 2–3 lie between
        // two needs and yield; sample 0 has a need on one side only (the task's start on the
        // other), sample 5 a need and sample 6 (trusted on its votes), sample 7 sample 6 and
        // a need.
        let before = obs.clone();
        votes(&mut obs, &[1.0, 4.0, 8.0], true, 2);
        let round = conf.update_round(&sigma2_d, &before, &obs).unwrap();
        let yielded = [true, false, false, false, false, true, true, true, false];
        assert_eq!(conf.conf(), &yielded);
        // The latch is not touched: the yield is evaluated, not stored.
        assert_eq!(conf.latched(), &from_prior);
        assert_eq!(round.reopened, 2);
        assert_eq!(round.newly_high, 0);
        // `update` on the same totals decides the same, and a state restored from its latch
        // is refreshed to the same `conf`.
        let mut again = Confidence::from_prior(&sigma2_d, p.clone()).unwrap();
        again.update(&sigma2_d, &obs).unwrap();
        assert_eq!(again, conf);
        let mut restored = Confidence::from_parts(p.clone(), conf.latched().to_vec()).unwrap();
        assert_eq!(restored.conf(), &from_prior);
        assert_eq!(restored.refresh(&sigma2_d, &obs).unwrap(), 2);
        assert_eq!(restored, conf);
        // Supervised (they are low-confidence), samples 2–3 are trusted again on ten clean
        // votes, no earlier, while both sides are still needed.
        let mut supervised = obs.clone();
        for vote in 1..=10 {
            let before = supervised.clone();
            votes(&mut supervised, &[2.0, 3.0], false, 1);
            conf.update_round(&sigma2_d, &before, &supervised).unwrap();
            assert_eq!(&conf.conf()[2..4], &[vote >= 10; 2], "after {vote} votes");
        }
        // Five votes, then the need at 4 fades (200 clean executions): samples 2–3 return to
        // their latch although they have votes, and the same rounds in the other order (the
        // need faded before the corrections) end at the same confidence: nothing of the
        // yield is history.
        let rounds: [(&[f64], bool, usize); 4] = [
            (&[6.0], false, 12),
            (&[1.0, 4.0, 8.0], true, 2),
            (&[2.0, 3.0], false, 5),
            (&[4.0], false, 200),
        ];
        let run = |order: &[usize]| {
            let mut conf = Confidence::from_prior(&sigma2_d, p.clone()).unwrap();
            let mut obs = Observations::new(9).unwrap();
            let mut seen = Vec::new();
            for &k in order {
                let before = obs.clone();
                let (samples, corrected, times) = rounds[k];
                votes(&mut obs, samples, corrected, times);
                conf.update_round(&sigma2_d, &before, &obs).unwrap();
                seen.push(conf.conf().to_vec());
            }
            (conf, seen)
        };
        let (in_order, seen) = run(&[0, 1, 2, 3]);
        // After the third round the run still yields (5 votes < MIN_VOTES); after the
        // fourth, sample 4 is latched on its totals (2 corrections in 202 votes) and is no
        // longer needed.
        assert_eq!(&seen[2][2..4], &[false, false]);
        assert_eq!(
            in_order.conf(),
            &[true, false, true, true, true, true, true, true, false]
        );
        let (reversed, _) = run(&[3, 2, 1, 0]);
        assert_eq!(reversed, in_order);
        // The paper's counting keeps the paper's latch: nothing yields there.
        let paper = ConfidenceParams::paper();
        let mut conf = Confidence::from_prior(&sigma2_d, paper).unwrap();
        let mut obs = Observations::new(9).unwrap();
        obs.record(&[1.0, 1.0, 4.0, 4.0], &[true; 4]).unwrap();
        conf.update(&sigma2_d, &obs).unwrap();
        assert_eq!(conf.conf(), &from_prior);
    }
}
