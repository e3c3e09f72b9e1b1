//! Ground truth of the study: which reference samples truly need the operator, and how the
//! confidence and the simulated operator compare with it.
//!
//! A reference sample *needs help* when its label is sanding in passes 1–3: there half of
//! every workpiece's sections are painted, so an execution needs a correction there half the
//! time; transitions and pass 4 never need one ([`crate::workcell::needs_correction`];
//! [`crate::task::ground_truth_share`] is the share that does not).
//!
//! [`TaskTruth`] is the same truth for any task: the study's loops
//! ([`crate::study::run_trial_on`], [`crate::study::run_cell_trial_on`]) draw every
//! workpiece from it and count falsely trusted samples against it. [`SandingTruth`] is the
//! sanding task's (labels and painted sections), [`ProfileTruth`] any task's whose need is
//! a [`NeedProfile`] (the task zoo's, `tandem simulate --need`'s).

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use tandem_confidence::ErrorRates;

use crate::needs::NeedProfile;
use crate::task::{Label, N_PASSES, Phase, TaskParams, Workpiece};
use crate::workcell::{RobotRun, RoundRun, needs_correction};
use crate::{Error, Result};

/// Where the workpieces of a task need the operator, one reference sample at a time: the
/// ground truth a study runs on. Implementations are deterministic in `rng`.
pub trait TaskTruth: Sync {
    /// Reference samples `T_ref` the truth is given on (the model's reference).
    fn n_ref(&self) -> usize;
    /// Draws the next workpiece from `rng`: per reference sample (`n_ref` values), whether
    /// it needs the operator there.
    ///
    /// # Errors
    /// The task's own (e.g. invalid task parameters).
    fn draw(&self, rng: &mut ChaCha8Rng) -> Result<Vec<bool>>;
    /// Per reference sample, whether some workpiece can need the operator there: a
    /// high-confidence sample where this is true is *falsely trusted*.
    fn can_need(&self) -> &[bool];
    /// The channel whose increase the simulated operator's corrections aim at
    /// (`OperatorParams::force_channel`).
    fn correction_channel(&self) -> &str;
    /// Share of reference samples where no workpiece needs the operator, in `[0, 1]`.
    fn never_needed_share(&self) -> f64 {
        let can = self.can_need();
        if can.is_empty() {
            return 0.0;
        }
        can.iter().filter(|c| !**c).count() as f64 / can.len() as f64
    }
}

/// The sanding task's truth (module docs): a workpiece is [`Workpiece::random`] under
/// `task`, a sample needs the operator where [`needs_correction`] says so for the
/// reference label there; samples [`needs_help`] can need it; corrections raise `force`.
#[derive(Clone, Debug, PartialEq)]
pub struct SandingTruth {
    labels: Vec<Label>,
    task: TaskParams,
    can_need: Vec<bool>,
}

impl SandingTruth {
    /// The truth of a reference with these labels (one per reference sample) and workpieces
    /// drawn under `task`.
    #[must_use]
    pub fn new(labels: Vec<Label>, task: TaskParams) -> Self {
        Self {
            can_need: labels.iter().map(needs_help).collect(),
            labels,
            task,
        }
    }

    /// The reference's labels.
    #[must_use]
    pub fn labels(&self) -> &[Label] {
        &self.labels
    }
}

impl TaskTruth for SandingTruth {
    fn n_ref(&self) -> usize {
        self.labels.len()
    }

    fn draw(&self, rng: &mut ChaCha8Rng) -> Result<Vec<bool>> {
        let workpiece = Workpiece::random(&self.task, rng)?;
        Ok(self
            .labels
            .iter()
            .map(|l| needs_correction(l, &workpiece))
            .collect())
    }

    fn can_need(&self) -> &[bool] {
        &self.can_need
    }

    fn correction_channel(&self) -> &str {
        "force"
    }
}

/// A need profile's truth: every workpiece draws its needed regions as
/// [`NeedProfile::draw`] does for one robot; samples of positive need can need the operator.
#[derive(Clone, Debug, PartialEq)]
pub struct ProfileTruth {
    profile: NeedProfile,
    can_need: Vec<bool>,
    channel: String,
}

impl ProfileTruth {
    /// The truth of `profile` (one level per reference sample), with corrections that raise
    /// `channel`.
    ///
    /// # Errors
    /// [`Error::BadParam`] for an empty channel name.
    pub fn new(profile: NeedProfile, channel: impl Into<String>) -> Result<Self> {
        let channel = channel.into();
        if channel.is_empty() {
            return Err(Error::BadParam {
                name: "channel",
                why: "must name a channel of the model",
            });
        }
        Ok(Self {
            can_need: profile.p().iter().map(|p| *p > 0.0).collect(),
            profile,
            channel,
        })
    }

    /// The need profile.
    #[must_use]
    pub fn profile(&self) -> &NeedProfile {
        &self.profile
    }
}

impl TaskTruth for ProfileTruth {
    fn n_ref(&self) -> usize {
        self.profile.n_ref()
    }

    fn draw(&self, rng: &mut ChaCha8Rng) -> Result<Vec<bool>> {
        Ok(self.profile.draw(1, rng).pop().unwrap_or_default())
    }

    fn can_need(&self) -> &[bool] {
        &self.can_need
    }

    fn correction_channel(&self) -> &str {
        &self.channel
    }
}

/// Whether a reference sample with this label ever needs a correction: sanding in passes
/// 1–3 (on a painted section of the workpiece at hand, which half of them are).
#[must_use]
pub fn needs_help(label: &Label) -> bool {
    label.phase == Phase::Sanding && (1..N_PASSES).contains(&usize::from(label.pass))
}

/// Reference samples that truly need help and are high-confidence in `conf` (`true` = high,
/// one per label): the samples an unsupervised robot would sand without the operator.
#[must_use]
pub fn falsely_trusted(conf: &[bool], labels: &[Label]) -> usize {
    conf.iter()
        .zip(labels)
        .filter(|(high, label)| **high && needs_help(label))
        .count()
}

/// Reference samples that can need the operator (`can_need`, one per reference sample) and
/// are high-confidence in `conf`: [`falsely_trusted`] for any [`TaskTruth`].
#[must_use]
pub fn falsely_trusted_where(conf: &[bool], can_need: &[bool]) -> usize {
    conf.iter()
        .zip(can_need)
        .filter(|(high, can)| **high && **can)
        .count()
}

/// The simulated operator's decisions, counted over rounds (control samples).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct OperatorTally {
    /// Supervised samples that needed a correction.
    pub needed: usize,
    /// Needed corrections missed.
    pub missed: usize,
    /// Supervised samples that needed none.
    pub unneeded: usize,
    /// Corrections given where none was needed.
    pub false_corrections: usize,
}

impl OperatorTally {
    /// Adds every robot of a round.
    pub fn add(&mut self, run: &RoundRun) {
        for r in &run.robots {
            self.add_run(r);
        }
    }

    /// Adds one robot's execution (a round's or a continuous cell's task).
    pub fn add_run(&mut self, r: &RobotRun) {
        let supervised = r.supervised.iter().filter(|&&s| s).count();
        self.needed += r.needed;
        self.missed += r.missed;
        self.unneeded += supervised - r.needed;
        self.false_corrections += r.false_corrections;
    }

    /// The rates the operator made: `missed / needed` and `false_corrections / unneeded`
    /// (0 where nothing was counted).
    #[must_use]
    pub fn rates(&self) -> ErrorRates {
        let ratio = |a: usize, b: usize| if b == 0 { 0.0 } else { a as f64 / b as f64 };
        ErrorRates {
            false_correction_rate: ratio(self.false_corrections, self.unneeded),
            miss_rate: ratio(self.missed, self.needed),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The sanding truth draws the workpiece the study drew before it existed, from the same
    /// stream: the same masks, and the stream left where `Workpiece::random` leaves it, so a
    /// study's operator draws what they drew before.
    #[test]
    fn the_sanding_truth_draws_the_studys_workpieces_from_the_same_stream() {
        let params = TaskParams::default();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let demo = crate::task::demonstrate(
            &params,
            &Workpiece::random(&params, &mut rng).unwrap(),
            &mut rng,
        )
        .unwrap();
        let truth = SandingTruth::new(demo.labels.clone(), params.clone());
        assert_eq!(truth.n_ref(), demo.labels.len());
        assert_eq!(truth.correction_channel(), "force");
        let (mut a, mut b) = (ChaCha8Rng::seed_from_u64(9), ChaCha8Rng::seed_from_u64(9));
        for _ in 0..4 {
            let mask = truth.draw(&mut a).unwrap();
            let wp = Workpiece::random(&params, &mut b).unwrap();
            let expected: Vec<bool> = demo
                .labels
                .iter()
                .map(|l| needs_correction(l, &wp))
                .collect();
            assert_eq!(mask, expected);
            assert!(mask.iter().zip(truth.can_need()).all(|(m, c)| !m || *c));
        }
        assert_eq!(
            a.random::<u64>(),
            b.random::<u64>(),
            "the same stream position"
        );
        let share = truth.never_needed_share();
        assert!((share - crate::task::ground_truth_share(&demo.labels)).abs() < 1e-12);
    }

    #[test]
    fn a_profile_truth_draws_one_robot_of_the_profile() {
        let profile = NeedProfile::from_levels(&[0.0, 0.0, 1.0, 1.0, 0.5, 0.0]).unwrap();
        let truth = ProfileTruth::new(profile.clone(), "flow").unwrap();
        assert_eq!(truth.can_need(), [false, false, true, true, true, false]);
        assert_eq!(truth.never_needed_share(), 0.5);
        assert_eq!(truth.correction_channel(), "flow");
        let (mut a, mut b) = (ChaCha8Rng::seed_from_u64(1), ChaCha8Rng::seed_from_u64(1));
        for _ in 0..8 {
            let mask = truth.draw(&mut a).unwrap();
            assert_eq!(mask, profile.draw(1, &mut b)[0]);
            assert!(mask[2] && mask[3] && !mask[0] && !mask[5]);
        }
        assert!(ProfileTruth::new(profile, "").is_err());
        assert_eq!(
            falsely_trusted_where(&[true, true, false], &[true, false, true]),
            1
        );
    }

    fn label(pass: u8, phase: Phase) -> Label {
        Label {
            pass,
            section: 0,
            painted: false,
            phase,
        }
    }

    #[test]
    fn only_sanding_of_passes_one_to_three_needs_help() {
        let labels = [
            label(1, Phase::Sanding),
            label(3, Phase::Sanding),
            label(4, Phase::Sanding),
            label(1, Phase::Transition),
        ];
        let needs: Vec<bool> = labels.iter().map(needs_help).collect();
        assert_eq!(needs, [true, true, false, false]);
        assert_eq!(falsely_trusted(&[true, false, true, true], &labels), 1);
        assert_eq!(falsely_trusted(&[true; 4], &labels), 2);
        assert_eq!(falsely_trusted(&[false; 4], &labels), 0);
        let t = OperatorTally {
            needed: 200,
            missed: 3,
            unneeded: 1000,
            false_corrections: 10,
        };
        assert_eq!(
            t.rates(),
            ErrorRates {
                false_correction_rate: 0.01,
                miss_rate: 0.015
            }
        );
        assert_eq!(OperatorTally::default().rates(), ErrorRates::default());
    }
}
