//! A schedule this build has checked: the only form the runtime coordinator is built from.

use tandem_realtime::{Coordinator, Timeline};

use crate::problem::Problem;
use crate::schedule::Schedule;
use crate::validate::validated_timeline_with_operator;
use crate::{Error, Result};

/// A [`Schedule`] that passed [`validate`](crate::validate) on one problem — every constraint
/// of Eq. 20, with this build's margin check of Alg. 2 (`tandem_realtime::sufficient_margins`)
/// at the schedule's own tick [`Schedule::tick_s`] — together with its robots' plans on that
/// problem ([`Timeline`]s, schedule-clock time in s).
///
/// Its fields are private: the only way to make one is [`Schedule::check`], so holding a
/// `CheckedSchedule` means the check ran in this build, and [`CheckedSchedule::coordinator`]
/// runs exactly what was checked. A raw [`Schedule`] (from JSON, a state file of an older
/// build, or made by hand) stays unchecked until then.
///
/// ```
/// use tandem_schedule::{Problem, Schedule};
///
/// // Two samples of 1 s, the first low-confidence; bounds [½, 2] around gradient 1.
/// let problem = Problem::new(vec![false, true], vec![1.0; 2], vec![0.5; 2], vec![2.0; 2], 1.0)?;
/// // Robot 2 starting at 0 would be low-confidence together with robot 1: refused.
/// let together = Schedule { grad_exec: vec![vec![1.0; 2]; 2], offsets_s: vec![0.0], tick_s: 1.0, holds: vec![] };
/// assert!(together.check(&problem).is_err());
/// // Serial (robot 2 starts where robot 1 ends) passes, and runs at its tick.
/// let serial = Schedule { offsets_s: vec![2.0], ..together };
/// let checked = serial.check(&problem)?;
/// assert_eq!(checked.coordinator()?.tick_s(), 1.0);
/// assert_eq!(checked.schedule(), &serial);
/// # Ok::<(), tandem_schedule::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct CheckedSchedule {
    schedule: Schedule,
    timelines: Vec<Timeline>,
}

impl CheckedSchedule {
    /// Checks `schedule` on `problem` for an operator with switch time `switch_s` (s) and load
    /// cap `max_busy_share` ([`Schedule::check_with_operator`];
    /// [`validate_with_operator`](crate::validate_with_operator)); `0` and `1` are
    /// [`Schedule::check`].
    pub(crate) fn new(
        problem: &Problem,
        schedule: Schedule,
        switch_s: f64,
        max_busy_share: f64,
    ) -> Result<Self> {
        let timeline =
            validated_timeline_with_operator(problem, &schedule, switch_s, max_busy_share)
                .map_err(Error::Invalid)?;
        Ok(CheckedSchedule {
            schedule,
            timelines: timeline.into_timelines(),
        })
    }

    /// The schedule that was checked.
    pub fn schedule(&self) -> &Schedule {
        &self.schedule
    }

    /// The schedule, by value (unchecked again once it leaves).
    pub fn into_schedule(self) -> Schedule {
        self.schedule
    }

    /// Every robot's plan on the checked problem (robot 1 first; schedule-clock time, s).
    pub fn timelines(&self) -> &[Timeline] {
        &self.timelines
    }

    /// The runtime coordinator (§II-B5, Eq. 17–18, Alg. 1) of the checked plans: every
    /// schedule clock at the earliest start, advanced one control tick of
    /// [`Schedule::tick_s`] real seconds per [`Coordinator::tick`] — the tick the margin
    /// check accepted, the only one its guarantee holds for. The check is not run again.
    ///
    /// # Errors
    /// None in practice (the tick was checked); [`Error::Realtime`] is kept for the
    /// coordinator's own argument checks.
    pub fn coordinator(&self) -> Result<Coordinator> {
        if self.schedule.has_holds() {
            return Ok(Coordinator::with_holds_unchecked(
                self.timelines.clone(),
                &self.schedule.holds,
                self.schedule.tick_s,
            )?);
        }
        Ok(Coordinator::new_unchecked(
            self.timelines.clone(),
            self.schedule.tick_s,
        )?)
    }
}
