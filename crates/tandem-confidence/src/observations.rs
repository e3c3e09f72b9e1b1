//! Empirical correction data per reference sample (the `z_t` of Eq. 8–9).

use serde::{Deserialize, Serialize};

use crate::beta::check_len;
use crate::{Error, Result};

/// Accumulated observations per reference sample: how much supervised execution time fell
/// on it and how much of that was corrected.
///
/// Both counts are real numbers because an execution visits fractional reference times:
/// an observation at reference time `t` is split linearly between samples `⌊t⌋` and
/// `⌊t⌋ + 1` (weights `1 − frac(t)` and `frac(t)`), so every observation adds exactly one
/// unit of mass in total. Only *supervised* (low-confidence) samples are observed; an
/// unsupervised execution sample says nothing about whether the operator would have
/// corrected it.
///
/// Invariant (checked on construction and deserialization): equal lengths `T_ref ≥ 1`,
/// and `0 ≤ corrections[n] ≤ supervised[n]`, all finite.
///
/// ```
/// use tandem_confidence::Observations;
/// let mut obs = Observations::new(4)?;
/// // One execution supervised reference times 0.5 (corrected) and 2.0 (not corrected).
/// obs.record(&[0.5, 2.0], &[true, false])?;
/// assert_eq!(obs.supervised(), &[0.5, 0.5, 1.0, 0.0]);
/// assert_eq!(obs.corrections(), &[0.5, 0.5, 0.0, 0.0]);
/// # Ok::<(), tandem_confidence::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ObservationsData")]
pub struct Observations {
    corrections: Vec<f64>,
    supervised: Vec<f64>,
    /// Evidence of missed corrections, summed over executions ([`MissEvidence`]).
    miss: MissEvidence,
}

/// Evidence of the operator's misses, from the time structure of each execution's
/// corrections: a needed correction lasts (a painted section, a slip of the tool), so a
/// *stretch* of corrections with short gaps is a stretch of need, and its gaps are misses.
///
/// A stretch is a maximal run of supervised control samples of one execution that starts
/// and ends corrected, whose uncorrected gaps are at most [`MissEvidence::MAX_GAP`] samples
/// long, and that holds at least [`MissEvidence::MIN_CORRECTED`] corrected samples.
/// Misses at a stretch's two ends cannot be told from its end, so `gap_samples /
/// stretch_samples` slightly underestimates the miss rate (by about two samples per
/// stretch of a hundred or more).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MissEvidence {
    /// Uncorrected control samples inside stretches (counts).
    pub gap_samples: f64,
    /// Control samples of the stretches, gaps included (counts).
    pub stretch_samples: f64,
}

impl MissEvidence {
    /// Longest run of uncorrected samples inside a stretch (control samples).
    pub const MAX_GAP: usize = 3;
    /// Fewest corrected samples of a stretch (control samples; 0.2 s at 100 Hz).
    pub const MIN_CORRECTED: usize = 20;

    /// The stretches of one execution's supervised samples (`corrected[k]` in time order).
    #[must_use]
    pub fn of_execution(corrected: &[bool]) -> Self {
        let mut total = Self::default();
        // The open stretch: (corrected, gaps, samples) and the uncorrected run after it.
        let mut open: Option<(usize, usize, usize)> = None;
        let mut pending = 0_usize;
        let close = |st: Option<(usize, usize, usize)>, total: &mut Self| {
            if let Some((c, g, n)) = st {
                if c >= Self::MIN_CORRECTED {
                    total.gap_samples += g as f64;
                    total.stretch_samples += n as f64;
                }
            }
        };
        for &c in corrected {
            if !c {
                pending += 1;
                continue;
            }
            open = match open {
                Some((nc, g, n)) if pending <= Self::MAX_GAP => {
                    Some((nc + 1, g + pending, n + pending + 1))
                }
                other => {
                    close(other, &mut total);
                    Some((1, 0, 1))
                }
            };
            pending = 0;
        }
        close(open, &mut total);
        total
    }
}

/// Unchecked serde form of [`Observations`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObservationsData {
    corrections: Vec<f64>,
    supervised: Vec<f64>,
    #[serde(default)]
    miss: MissEvidence,
}

impl TryFrom<ObservationsData> for Observations {
    type Error = Error;
    fn try_from(d: ObservationsData) -> Result<Self> {
        Self::from_counts(d.corrections, d.supervised)?.with_miss_evidence(d.miss)
    }
}

impl Observations {
    /// No observations yet for a reference of `n_ref` samples.
    ///
    /// # Errors
    /// [`Error::EmptyReference`] if `n_ref == 0`.
    pub fn new(n_ref: usize) -> Result<Self> {
        if n_ref == 0 {
            return Err(Error::EmptyReference);
        }
        Ok(Self {
            corrections: vec![0.0; n_ref],
            supervised: vec![0.0; n_ref],
            miss: MissEvidence::default(),
        })
    }

    /// The same observations with `miss` as their evidence of misses (e.g. a saved state).
    ///
    /// # Errors
    /// [`Error::BadCounts`] (with `ref_idx` 0) unless `0 ≤ gap_samples ≤ stretch_samples`,
    /// both finite.
    pub fn with_miss_evidence(mut self, miss: MissEvidence) -> Result<Self> {
        let (g, n) = (miss.gap_samples, miss.stretch_samples);
        if !(g.is_finite() && n.is_finite() && g >= 0.0 && g <= n) {
            return Err(Error::BadCounts {
                ref_idx: 0,
                corrections: g,
                supervised: n,
            });
        }
        self.miss = miss;
        Ok(self)
    }

    /// Evidence of missed corrections over every execution recorded ([`MissEvidence`]).
    #[must_use]
    pub fn miss_evidence(&self) -> MissEvidence {
        self.miss
    }

    /// Observations from stored per-sample counts (e.g. a saved state).
    ///
    /// # Errors
    /// [`Error::EmptyReference`], [`Error::LengthMismatch`], or [`Error::BadCounts`]
    /// naming the first sample where `0 ≤ corrections ≤ supervised` (finite) fails.
    pub fn from_counts(corrections: Vec<f64>, supervised: Vec<f64>) -> Result<Self> {
        check_len(
            "corrections",
            corrections.len(),
            "supervised",
            supervised.len(),
        )?;
        if corrections.is_empty() {
            return Err(Error::EmptyReference);
        }
        for (ref_idx, (&c, &s)) in corrections.iter().zip(&supervised).enumerate() {
            if !(c.is_finite() && s.is_finite() && c >= 0.0 && c <= s) {
                return Err(Error::BadCounts {
                    ref_idx,
                    corrections: c,
                    supervised: s,
                });
            }
        }
        Ok(Self {
            corrections,
            supervised,
            miss: MissEvidence::default(),
        })
    }

    /// Number of reference samples `T_ref`.
    #[must_use]
    pub fn n_ref(&self) -> usize {
        self.supervised.len()
    }

    /// Correction mass per reference sample (`Σ z_t` of Eq. 9, fractional).
    #[must_use]
    pub fn corrections(&self) -> &[f64] {
        &self.corrections
    }

    /// Supervised mass per reference sample (replaces `n_e` in Eq. 9, fractional).
    #[must_use]
    pub fn supervised(&self) -> &[f64] {
        &self.supervised
    }

    /// Total correction mass over all samples (= number of corrected observations
    /// recorded, up to rounding).
    #[must_use]
    pub fn total_corrections(&self) -> f64 {
        self.corrections.iter().sum()
    }

    /// Total supervised mass over all samples (= number of observations recorded, up to
    /// rounding).
    #[must_use]
    pub fn total_supervised(&self) -> f64 {
        self.supervised.iter().sum()
    }

    /// Records one execution.
    ///
    /// `supervised_ref_times[k]` is the reference time (in reference samples, fractional,
    /// in `[0, T_ref − 1]`) of the execution's `k`-th *supervised* control sample, and
    /// `corrected[k]` says whether the operator gave a correction there. Each observation
    /// is split linearly between the two neighbouring reference samples. Samples the robot
    /// ran unsupervised (high confidence) must not be passed: they carry no information.
    ///
    /// The supervised samples must be in the execution's time order: their corrections also
    /// add to the evidence of misses ([`MissEvidence::of_execution`]).
    ///
    /// All inputs are checked before anything is added, so an error leaves `self`
    /// unchanged.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] if the slices differ in length;
    /// [`Error::RefTimeOutOfRange`] naming the first non-finite or out-of-range time.
    pub fn record(&mut self, supervised_ref_times: &[f64], corrected: &[bool]) -> Result<()> {
        self.record_with(supervised_ref_times, None, corrected, false)
    }

    /// [`record`](Self::record) with *one vote per execution*: the execution's mass at each
    /// reference sample it touched is scaled to exactly one unit (corrections in
    /// proportion), so that one execution passing a reference sample is one observation of
    /// the operator there, however many control samples it spent on it.
    ///
    /// Why: the operator's decision at a reference sample holds for every control sample
    /// the robot spends there — an unneeded correction is an episode of the joystick held
    /// for a while, a needed one lasts the painted section — so where the robot moves
    /// slower than the reference (and a correction slows it further) the paper's split
    /// counts one decision several times, and a single slip weighs like several
    /// independent ones. Where it moves faster, one control sample spans several reference
    /// samples and the split gives each a fraction of an observation, although the
    /// operator watched the robot pass each of them: such samples needed several times
    /// more executions to become high-confidence (measured in the study: the last
    /// low-confidence islands at the tool's lift-off after pass 1). Executions are
    /// independent of each other; control samples of one execution at one reference sample
    /// are not.
    ///
    /// ```
    /// use tandem_confidence::Observations;
    /// let mut obs = Observations::new(4)?;
    /// // Four control samples on reference sample 1 (a slow robot), two of them corrected;
    /// // then one at 2.5 (a fast robot), corrected.
    /// obs.record_votes(&[1.0, 1.0, 1.0, 1.0, 2.5], &[true, true, false, false, true])?;
    /// assert_eq!(obs.supervised(), &[0.0, 1.0, 1.0, 1.0]);
    /// assert_eq!(obs.corrections(), &[0.0, 0.5, 1.0, 1.0]);
    /// # Ok::<(), tandem_confidence::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`record`](Self::record).
    pub fn record_votes(&mut self, supervised_ref_times: &[f64], corrected: &[bool]) -> Result<()> {
        self.record_with(supervised_ref_times, None, corrected, true)
    }

    /// [`record_votes`](Self::record_votes) where each supervised control sample also covers
    /// the reference samples its robot swept during the control tick: `swept_to[k] ≥
    /// supervised_ref_times[k]` is the reference time at which the robot ended the tick of
    /// observation `k` (the next logged sample's time). Every reference sample after
    /// `⌊t_k⌋` and before `⌊swept_to[k]⌋` (those no control sample starts on) is touched too,
    /// with observation `k`'s correction flag, and gets its vote. Where a robot moves at most
    /// one reference sample per tick nothing changes; a fast robot no longer leaves the
    /// samples it passed under supervision without a vote (a one-sample low-confidence island
    /// crossed inside one tick, say).
    ///
    /// ```
    /// use tandem_confidence::Observations;
    /// let mut obs = Observations::new(6)?;
    /// // One control sample at 0.5 whose tick ended at 4.2: samples 0 to 3 are touched.
    /// obs.record_votes_swept(&[0.5], &[4.2], &[false])?;
    /// assert_eq!(obs.supervised(), &[1.0, 1.0, 1.0, 1.0, 0.0, 0.0]);
    /// # Ok::<(), tandem_confidence::Error>(())
    /// ```
    ///
    /// # Errors
    /// As [`record`](Self::record), and [`Error::LengthMismatch`] or
    /// [`Error::RefTimeOutOfRange`] for `swept_to` (each must lie in `[t_k, T_ref − 1]`).
    pub fn record_votes_swept(
        &mut self,
        supervised_ref_times: &[f64],
        swept_to: &[f64],
        corrected: &[bool],
    ) -> Result<()> {
        check_len(
            "supervised_ref_times",
            supervised_ref_times.len(),
            "swept_to",
            swept_to.len(),
        )?;
        self.record_with(supervised_ref_times, Some(swept_to), corrected, true)
    }

    fn record_with(
        &mut self,
        supervised_ref_times: &[f64],
        swept_to: Option<&[f64]>,
        corrected: &[bool],
        one_vote: bool,
    ) -> Result<()> {
        check_len(
            "supervised_ref_times",
            supervised_ref_times.len(),
            "corrected",
            corrected.len(),
        )?;
        let n_ref = self.n_ref();
        // Lossless for any reference shorter than 2^53 samples.
        let t_max = (n_ref - 1) as f64;
        for (obs_idx, &ref_time) in supervised_ref_times.iter().enumerate() {
            if !(ref_time >= 0.0 && ref_time <= t_max) {
                return Err(Error::RefTimeOutOfRange {
                    obs_idx,
                    ref_time,
                    n_ref,
                });
            }
        }
        if let Some(ends) = swept_to {
            for (obs_idx, (&end, &t)) in ends.iter().zip(supervised_ref_times).enumerate() {
                if !(end >= t && end <= t_max) {
                    return Err(Error::RefTimeOutOfRange {
                        obs_idx,
                        ref_time: end,
                        n_ref,
                    });
                }
            }
        }
        if one_vote {
            // This execution's own counts, then one unit per sample it touched.
            let (mut c_e, mut s_e) = (vec![0.0; n_ref], vec![0.0; n_ref]);
            add_split(&mut c_e, &mut s_e, supervised_ref_times, corrected);
            if let Some(ends) = swept_to {
                for ((&t, &end), &c) in supervised_ref_times.iter().zip(ends).zip(corrected) {
                    // Checked above: 0 ≤ t ≤ end ≤ T_ref − 1.
                    for j in (t.floor() as usize + 1)..(end.floor() as usize) {
                        s_e[j] += 1.0;
                        if c {
                            c_e[j] += 1.0;
                        }
                    }
                }
            }
            for ((c, s), (ce, se)) in self
                .corrections
                .iter_mut()
                .zip(&mut self.supervised)
                .zip(c_e.iter().zip(&s_e))
            {
                if *se > 0.0 {
                    // ce ≤ se, so the vote keeps 0 ≤ c ≤ s.
                    *s += 1.0;
                    *c += (ce / se).min(1.0);
                }
            }
        } else {
            add_split(
                &mut self.corrections,
                &mut self.supervised,
                supervised_ref_times,
                corrected,
            );
        }
        let miss = MissEvidence::of_execution(corrected);
        self.miss.gap_samples += miss.gap_samples;
        self.miss.stretch_samples += miss.stretch_samples;
        Ok(())
    }
}

/// Adds checked observations to `corrections` and `supervised`, each split linearly
/// between its two neighbouring reference samples.
fn add_split(corrections: &mut [f64], supervised: &mut [f64], times: &[f64], corrected: &[bool]) {
    let n_ref = supervised.len();
    for (&t, &c) in times.iter().zip(corrected) {
        let (lo, w) = split(t, n_ref);
        let w_lo = 1.0 - w;
        supervised[lo] += w_lo;
        if c {
            corrections[lo] += w_lo;
        }
        if w > 0.0 {
            supervised[lo + 1] += w;
            if c {
                corrections[lo + 1] += w;
            }
        }
    }
}

/// `(⌊t⌋, t − ⌊t⌋)` for a checked `t ∈ [0, n_ref − 1]`; the weight is 0 at `t = n_ref − 1`
/// so `⌊t⌋ + 1` is only touched when it exists.
#[inline]
fn split(t: f64, n_ref: usize) -> (usize, f64) {
    let lo = (t.floor() as usize).min(n_ref - 1);
    (lo, t - lo as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_linearly_between_neighbours() {
        let mut obs = Observations::new(5).unwrap();
        obs.record(&[1.25, 3.0, 4.0, 0.0], &[true, false, true, false])
            .unwrap();
        assert_eq!(obs.supervised(), &[1.0, 0.75, 0.25, 1.0, 1.0]);
        assert_eq!(obs.corrections(), &[0.0, 0.75, 0.25, 0.0, 1.0]);
        assert_eq!(obs.total_supervised(), 4.0);
        assert_eq!(obs.total_corrections(), 2.0);
    }

    #[test]
    fn bad_times_are_rejected_by_index_and_leave_state_unchanged() {
        let mut obs = Observations::new(3).unwrap();
        obs.record(&[0.5], &[true]).unwrap();
        let before = obs.clone();
        for bad in [-1e-9, 2.000_001, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let err = obs
                .record(&[1.0, 0.2, bad], &[false, true, true])
                .unwrap_err();
            assert!(
                matches!(
                    err,
                    Error::RefTimeOutOfRange {
                        obs_idx: 2,
                        n_ref: 3,
                        ..
                    }
                ),
                "{err:?}"
            );
            assert!(err.to_string().contains("supervised sample 2"), "{err}");
            assert_eq!(obs, before);
        }
        let err = obs.record(&[1.0, 0.2], &[false]).unwrap_err();
        assert_eq!(
            err,
            Error::LengthMismatch {
                left_name: "supervised_ref_times",
                left: 2,
                right_name: "corrected",
                right: 1
            }
        );
        assert_eq!(obs, before);
    }

    #[test]
    fn single_sample_reference() {
        let mut obs = Observations::new(1).unwrap();
        obs.record(&[0.0, 0.0], &[true, false]).unwrap();
        assert_eq!(
            (obs.supervised(), obs.corrections()),
            (&[2.0][..], &[1.0][..])
        );
        assert!(obs.record(&[0.1], &[false]).is_err());
        assert_eq!(Observations::new(0).unwrap_err(), Error::EmptyReference);
    }

    #[test]
    fn from_counts_checks_invariant() {
        assert!(Observations::from_counts(vec![0.0, 1.0], vec![1.0, 1.0]).is_ok());
        assert!(matches!(
            Observations::from_counts(vec![0.0, 1.5], vec![1.0, 1.0]),
            Err(Error::BadCounts { ref_idx: 1, .. })
        ));
        assert!(matches!(
            Observations::from_counts(vec![-0.1], vec![1.0]),
            Err(Error::BadCounts { ref_idx: 0, .. })
        ));
        assert!(matches!(
            Observations::from_counts(vec![0.0], vec![f64::NAN]),
            Err(Error::BadCounts { ref_idx: 0, .. })
        ));
        assert!(matches!(
            Observations::from_counts(vec![0.0], vec![1.0, 2.0]),
            Err(Error::LengthMismatch {
                left: 1,
                right: 2,
                ..
            })
        ));
        assert_eq!(
            Observations::from_counts(vec![], vec![]),
            Err(Error::EmptyReference)
        );
    }

    #[test]
    fn gaps_inside_correction_stretches_are_misses() {
        let run = |pattern: &str| {
            let flags: Vec<bool> = pattern.chars().map(|c| c == '#').collect();
            let e = MissEvidence::of_execution(&flags);
            (e.gap_samples, e.stretch_samples)
        };
        let c20 = "#".repeat(20);
        // 20 corrected samples in a row: a stretch without misses.
        assert_eq!(run(&format!("..{c20}..")), (0.0, 20.0));
        // Gaps of 1 and 3 inside are misses; a gap of 4 ends the stretch.
        assert_eq!(run(&format!("{c20}.{c20}...#")), (4.0, 45.0));
        assert_eq!(run(&format!("{c20}....{c20}")), (0.0, 40.0));
        // Too few corrected samples: isolated (unneeded) corrections are no stretch.
        assert_eq!(run("#.#.#.#.#.#.#.#.#.#"), (0.0, 0.0));
        assert_eq!(run(""), (0.0, 0.0));
        // Recorded executions add up; a stretch never spans two executions.
        let mut obs = Observations::new(2).unwrap();
        let flags: Vec<bool> = format!("{c20}.#").chars().map(|c| c == '#').collect();
        let times = vec![0.5; flags.len()];
        obs.record(&times, &flags).unwrap();
        obs.record(&times, &flags).unwrap();
        assert_eq!(
            obs.miss_evidence(),
            MissEvidence {
                gap_samples: 2.0,
                stretch_samples: 44.0
            }
        );
        let bad = MissEvidence {
            gap_samples: 2.0,
            stretch_samples: 1.0,
        };
        assert!(obs.clone().with_miss_evidence(bad).is_err());
    }

    #[test]
    fn serde_round_trip_and_validation() {
        let mut obs = Observations::new(3).unwrap();
        obs.record(&[0.3, 1.9], &[true, false]).unwrap();
        let json = serde_json::to_string(&obs).unwrap();
        let back: Observations = serde_json::from_str(&json).unwrap();
        assert_eq!(back, obs);
        let bad = r#"{"corrections":[2.0],"supervised":[1.0]}"#;
        let err = serde_json::from_str::<Observations>(bad).unwrap_err();
        assert!(err.to_string().contains("reference sample 0"), "{err}");
        let unknown = r#"{"corrections":[0.0],"supervised":[1.0],"x":1}"#;
        assert!(serde_json::from_str::<Observations>(unknown).is_err());
    }
}
