//! Ground truth of the study: which reference samples truly need the operator, and how the
//! confidence and the simulated operator compare with it.
//!
//! A reference sample *needs help* when its label is sanding in passes 1–3: there half of
//! every workpiece's sections are painted, so an execution needs a correction there half the
//! time; transitions and pass 4 never need one ([`crate::workcell::needs_correction`];
//! [`crate::task::ground_truth_share`] is the share that does not).

use serde::{Deserialize, Serialize};
use tandem_confidence::ErrorRates;

use crate::task::{Label, N_PASSES, Phase};
use crate::workcell::{RobotRun, RoundRun};

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
