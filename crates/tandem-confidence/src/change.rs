//! How `conf` changed from one state of a task to a later one, sample by sample and by
//! cause ([`TrustChange`]): the claim "learning takes back only the prior's trust" made
//! countable.

use serde::{Deserialize, Serialize};

use crate::beta::check_len;
use crate::{Confidence, Error, MIN_VOTES, Observations, Result};

/// How [`Confidence::conf`] changed between two states of one task (the same reference), by
/// cause. Counts of reference samples.
///
/// A high-confidence sample turns low for one of two reasons only (the [`Confidence`] type
/// docs, [`Confidence::update_round`]):
/// - **the prior's trust yields** ([`TrustChange::yielded`]): the sample is still latched and
///   rests on its prior alone (no correction, fewer than [`MIN_VOTES`] votes), and a need the
///   operator's corrections confirmed lies beside its run (on both sides, or on one side within
///   [`one_sided_yield`](crate::one_sided_yield)); it never earned its trust by votes;
/// - **the corrections reached it** ([`TrustChange::reopened`]): the observations recorded in
///   between gave it correction mass (the split of Eq. 9's times at the edge of a supervised
///   stretch, or rounds recorded out of order) and its totals no longer pass Eq. 12, so its
///   latch was taken back.
///
/// So a sample trusted on its own votes (latched, with a correction or at least
/// [`MIN_VOTES`] votes) falls only with a correction of it ([`TrustChange::voted_fell`] counts
/// those, all within [`TrustChange::reopened`]), and `n_high` falls by exactly
/// `yielded + reopened − rose`. [`TrustChange::other`] counts any fall that is neither: none by
/// construction, which callers assert.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct TrustChange {
    /// Low before, high after.
    pub rose: usize,
    /// High before, low after: latched and resting on the prior after, its trust yielding to a
    /// confirmed need.
    pub yielded: usize,
    /// High before, low after: no longer latched, its correction total grew in between.
    pub reopened: usize,
    /// Of the falls, samples that were high on their own votes before (latched, with a
    /// correction or at least [`MIN_VOTES`] votes): all within [`TrustChange::reopened`].
    pub voted_fell: usize,
    /// Any other fall (high before, low after, neither yielded nor reopened): 0 by
    /// construction.
    pub other: usize,
}

impl TrustChange {
    /// Samples that turned low: `yielded + reopened + other`.
    #[must_use]
    pub fn fell(&self) -> usize {
        self.yielded + self.reopened + self.other
    }

    /// The two changes as one (counts added), e.g. over the rounds of a run.
    #[must_use]
    pub fn merged(self, o: TrustChange) -> TrustChange {
        TrustChange {
            rose: self.rose + o.rose,
            yielded: self.yielded + o.yielded,
            reopened: self.reopened + o.reopened,
            voted_fell: self.voted_fell + o.voted_fell,
            other: self.other + o.other,
        }
    }
}

/// How `conf` changed from `before` (with the observation totals `obs_before` it was
/// evaluated on) to `after` (with `obs_after`, a later state of the same observations), by
/// cause ([`TrustChange`]). A pure function of the four states' public parts.
///
/// ```
/// use tandem_confidence::{Confidence, ConfidenceParams, Observations, trust_change};
/// let sigma2_d = [10.0];
/// let p = ConfidenceParams::paper();
/// // 90 clean observations latch the sample on its votes; then 10 corrected ones reach it.
/// let mut conf = Confidence::from_prior(&sigma2_d, p)?;
/// let mut obs = Observations::new(1)?;
/// obs.record(&[0.0; 90], &[false; 90])?;
/// conf.update(&sigma2_d, &obs)?;
/// let (trusted, obs_trusted) = (conf.clone(), obs.clone());
/// obs.record(&[0.0; 10], &[true; 10])?;
/// conf.update_round(&sigma2_d, &obs_trusted, &obs)?;
/// let change = trust_change(&trusted, &obs_trusted, &conf, &obs)?;
/// assert_eq!((change.reopened, change.voted_fell, change.yielded), (1, 1, 0));
/// # Ok::<(), tandem_confidence::Error>(())
/// ```
///
/// # Errors
/// [`Error::LengthMismatch`] when the four do not have the same number of samples;
/// [`Error::NotEarlier`] naming the first sample where `obs_before` holds more mass than
/// `obs_after`.
pub fn trust_change(
    before: &Confidence,
    obs_before: &Observations,
    after: &Confidence,
    obs_after: &Observations,
) -> Result<TrustChange> {
    let n = before.n_ref();
    check_len("the later confidence", after.n_ref(), "the earlier", n)?;
    check_len(
        "observations before",
        obs_before.n_ref(),
        "the confidence",
        n,
    )?;
    check_len("observations after", obs_after.n_ref(), "the confidence", n)?;
    let (c0, s0) = (obs_before.corrections(), obs_before.supervised());
    let (c1, s1) = (obs_after.corrections(), obs_after.supervised());
    for ref_idx in 0..n {
        for (what, b, a) in [
            ("correction", c0[ref_idx], c1[ref_idx]),
            ("supervised", s0[ref_idx], s1[ref_idx]),
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
    let (high0, high1) = (before.conf(), after.conf());
    let (latch0, latch1) = (before.latched(), after.latched());
    let mut out = TrustChange::default();
    for k in 0..n {
        match (high0[k], high1[k]) {
            (false, true) => out.rose += 1,
            (true, false) => {
                if latch0[k] && (c0[k] > 0.0 || s0[k] >= MIN_VOTES) {
                    out.voted_fell += 1;
                }
                if latch1[k] && c1[k] == 0.0 && s1[k] < MIN_VOTES {
                    out.yielded += 1;
                } else if !latch1[k] && c1[k] > c0[k] {
                    out.reopened += 1;
                } else {
                    out.other += 1;
                }
            }
            _ => {}
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ConfidenceParams;

    /// `count` executions each vote once at `ref_times`, all corrected or all clean.
    fn votes(obs: &mut Observations, ref_times: &[f64], corrected: bool, count: usize) {
        for _ in 0..count {
            obs.record_votes(ref_times, &vec![corrected; ref_times.len()])
                .unwrap();
        }
    }

    #[test]
    fn a_need_on_one_side_takes_back_the_prior_trust_of_the_near_half_only() {
        // The 60-sample task of `on_a_short_task_one_need_leaves_the_far_half_of_each_run_
        // trusted`: the demonstrations differ at 20..23 only; two corrected executions there
        // (Beta(3, 1), P(π < 0.05) = 1.25e-4 < 0.05: needed). ⌈20/2⌉ = 10 and ⌈37/2⌉ = 19
        // samples of the runs beside it yield: 29 falls, all of the prior's trust.
        let p = ConfidenceParams {
            estimate_error_rates: false,
            ..ConfidenceParams::default()
        };
        let sigma2_d: Vec<f64> = (0..60)
            .map(|n| if (20..23).contains(&n) { 10.0 } else { 0.0 })
            .collect();
        let fit = Confidence::from_prior(&sigma2_d, p).unwrap();
        assert_eq!(fit.n_high(), 57);
        let empty = Observations::new(60).unwrap();
        let mut obs = empty.clone();
        votes(&mut obs, &[20.0, 21.0, 22.0], true, 2);
        let mut conf = fit.clone();
        conf.update_round(&sigma2_d, &empty, &obs).unwrap();
        let change = trust_change(&fit, &empty, &conf, &obs).unwrap();
        assert_eq!(
            change,
            TrustChange {
                yielded: 29,
                ..TrustChange::default()
            }
        );
        assert_eq!(fit.n_high() - conf.n_high(), change.fell() - change.rose);
        // Ten clean votes on the 29 trust them on their votes again: 29 rise, none falls.
        let near: Vec<f64> = (10..20).chain(23..42).map(|n| n as f64).collect();
        let mut voted = obs.clone();
        votes(&mut voted, &near, false, 10);
        let mut again = conf.clone();
        again.update_round(&sigma2_d, &obs, &voted).unwrap();
        let change = trust_change(&conf, &obs, &again, &voted).unwrap();
        assert_eq!(
            change,
            TrustChange {
                rose: 29,
                ..TrustChange::default()
            }
        );
        // A state that did not change: nothing.
        assert_eq!(
            trust_change(&again, &voted, &again, &voted).unwrap(),
            TrustChange::default()
        );
    }

    #[test]
    fn observations_that_lose_mass_or_another_length_are_refused() {
        let p = ConfidenceParams::default();
        let conf = Confidence::from_prior(&[0.0, 0.0], p).unwrap();
        let mut later = Observations::new(2).unwrap();
        votes(&mut later, &[1.0], false, 1);
        let empty = Observations::new(2).unwrap();
        assert!(matches!(
            trust_change(&conf, &later, &conf, &empty),
            Err(Error::NotEarlier { ref_idx: 1, .. })
        ));
        let short = Observations::new(1).unwrap();
        assert!(matches!(
            trust_change(&conf, &short, &conf, &empty),
            Err(Error::LengthMismatch { .. })
        ));
    }
}
