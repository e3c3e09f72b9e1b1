//! Schedules, `T_total` (Eq. 13) and the global timeline (Eq. 15, 16, 19).
//!
//! Every time here is read from the one Eq. 15 clock of `tandem_realtime` ([`clock_end_s`],
//! the breakpoints of a [`Timeline`]): durations, ends, `T_total` and the low-confidence
//! intervals agree to the last bit with what the margin check and the coordinator use.

use serde::{Deserialize, Serialize};
use tandem_realtime::{Coordinator, LcInterval, Timeline, clock_end_s, tol};

use crate::problem::Problem;
use crate::{Error, Result};

/// A two-robot schedule: one execution warp per robot, the offset of robot 2 (§II-B4) and
/// the control tick it was checked with.
///
/// Robot index 0 is the first robot (`τ_1 = 0`), index 1 the second (`τ_2 = offset_s`).
/// Check a schedule against a [`Problem`] with [`crate::validate`] (at its own tick), run
/// it with [`Schedule::coordinator`] (at its own tick).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Schedule {
    /// Execution warp gradients `ψ̇_Ei[n]` per robot and reference sample `n` (execution samples
    /// per reference sample; robot `i` spends `ψ̇_Ei[n]·Δt_s` seconds on reference sample `n`).
    pub grad_exec: [Vec<f64>; 2],
    /// Offset `τ` (s, global time) at which robot 2 starts; `0 ≤ τ ≤ |ψ_E1|` (Eq. 20).
    pub offset_s: f64,
    /// Control tick (real s, finite and > 0) of the margin check (Alg. 2, Eq. 20 constraint
    /// 5) that accepted the schedule, and so the only period at which the [`Coordinator`] may
    /// run it: the check's guarantee (never both robots low-confidence in one tick) holds for
    /// this tick, not for another.
    pub tick_s: f64,
}

impl Schedule {
    /// Each robot's [`Timeline`] (schedule-clock plan for the real-time coordinator and the
    /// margin check, Eq. 15–16) on `problem`, built from the schedule's own gradients: the
    /// realtime crate accepts gradients within [`tol::GRADIENT_REL`] of the bounds, as
    /// [`crate::validate`] does.
    ///
    /// # Errors
    /// [`Error::Timeline`] naming the robot, for a warp whose length is not `T_ref`, a
    /// non-finite value or a gradient outside its bounds.
    pub fn timelines(&self, problem: &Problem) -> Result<[Timeline; 2]> {
        self.timelines_of(problem)
            .map_err(|(robot, source)| Error::Timeline { robot, source })
    }

    /// [`Schedule::timelines`] with the failing robot's index beside the realtime error.
    pub(crate) fn timelines_of(
        &self,
        problem: &Problem,
    ) -> std::result::Result<[Timeline; 2], (usize, tandem_realtime::Error)> {
        let build = |robot: usize| {
            Timeline::new(
                problem.conf(),
                &self.grad_exec[robot],
                problem.grad_min(),
                problem.grad_max(),
                self.starts_s()[robot],
                problem.dt_s(),
            )
            .map_err(|e| (robot, e))
        };
        Ok([build(0)?, build(1)?])
    }

    /// The runtime coordinator of this schedule on `problem` (§II-B5): both robots'
    /// [`Timeline`]s, advanced one control tick of [`Schedule::tick_s`] real seconds per
    /// [`Coordinator::tick`].
    ///
    /// # Errors
    /// [`Error::Timeline`] as [`Schedule::timelines`]; [`Error::Realtime`] for a tick that is
    /// not finite and > 0.
    pub fn coordinator(&self, problem: &Problem) -> Result<Coordinator> {
        Ok(Coordinator::new(self.timelines(problem)?, self.tick_s)?)
    }

    /// Start time of each robot in global time (s): `[0, τ]`.
    pub fn starts_s(&self) -> [f64; 2] {
        [0.0, self.offset_s]
    }

    /// Execution durations `[|ψ_E1|, |ψ_E2|]` (s) for reference sample period `dt_s` (s): the
    /// end of each warp's clock started at 0 ([`clock_end_s`]).
    pub fn durations_s(&self, dt_s: f64) -> [f64; 2] {
        [
            clock_end_s(&self.grad_exec[0], 0.0, dt_s),
            clock_end_s(&self.grad_exec[1], 0.0, dt_s),
        ]
    }

    /// Global time (s) at which each robot ends on schedule, `[|ψ_E1|, τ + |ψ_E2|]`, for
    /// sample period `dt_s` (s): the end of its clock started at its start ([`clock_end_s`]),
    /// exactly [`Timeline::end_s`] of [`Schedule::timelines`].
    pub fn ends_s(&self, dt_s: f64) -> [f64; 2] {
        let starts = self.starts_s();
        [0, 1].map(|i| clock_end_s(&self.grad_exec[i], starts[i], dt_s))
    }

    /// `T_total = max(|ψ_E1|, τ + |ψ_E2|)` (Eq. 13), global time (s), for sample period `dt_s`:
    /// the later of [`Schedule::ends_s`].
    pub fn t_total_s(&self, dt_s: f64) -> f64 {
        let [e0, e1] = self.ends_s(dt_s);
        e0.max(e1)
    }
}

/// The global timeline of a schedule (Eq. 15–16, 19): a view of both robots' [`Timeline`]s
/// (built once by [`Schedule::timelines`]) that says where each robot is in the reference at
/// any global time, its confidence then, and every low-confidence interval in global time.
///
/// Reference sample `n` of robot `i` occupies global time `[c_n, c_{n+1})` of its clock
/// ([`tandem_realtime::clock_s`], started at `τ_i`).
#[derive(Clone, Debug)]
pub struct GlobalTimeline {
    robots: [Timeline; 2],
}

impl From<[Timeline; 2]> for GlobalTimeline {
    fn from(robots: [Timeline; 2]) -> Self {
        GlobalTimeline { robots }
    }
}

impl GlobalTimeline {
    /// Lays `schedule` out in global time for `problem` ([`Schedule::timelines`]).
    ///
    /// # Errors
    /// [`Error::Timeline`] naming the robot whose warp has the wrong length, a non-finite
    /// value, or a gradient outside its bounds.
    pub fn new(problem: &Problem, schedule: &Schedule) -> Result<Self> {
        Ok(schedule.timelines(problem)?.into())
    }

    /// Both robots' timelines (robot 1, robot 2).
    pub fn timelines(&self) -> &[Timeline; 2] {
        &self.robots
    }

    /// Each robot's `[start, end]` in global time (s).
    pub fn spans_s(&self) -> [(f64, f64); 2] {
        self.robots.each_ref().map(|r| (r.start_s(), r.end_s()))
    }

    /// `T_total` (Eq. 13), global time (s): the later end.
    pub fn t_total_s(&self) -> f64 {
        self.robots[0].end_s().max(self.robots[1].end_s())
    }

    /// Eq. 15: robot `robot`'s fractional reference time (reference samples, in `[0, T_ref]`)
    /// at global time `t_global_s`: 0 before its start, `T_ref` after its end, linear within
    /// each reference sample in between. `robot` > 1 is treated as robot 1.
    pub fn ref_time(&self, robot: usize, t_global_s: f64) -> f64 {
        self.robots[robot.min(1)].ref_time_at(t_global_s)
    }

    /// Eq. 16: `[conf_1(t), conf_2(t)]` at global time `t_global_s` (`true` = high confidence;
    /// a robot that is not running, `t < τ_i` or `t ≥ τ_i + |ψ_Ei|`, counts as high).
    pub fn conf_at(&self, t_global_s: f64) -> [bool; 2] {
        self.robots.each_ref().map(|r| r.conf_at(t_global_s))
    }

    /// Each robot's low-confidence intervals in global time, in time order (Eq. 19: their
    /// union is `T_lc`).
    pub fn lc_intervals(&self) -> [&[LcInterval]; 2] {
        self.robots.each_ref().map(Timeline::lc_intervals)
    }

    /// The first stretch of global time in which both robots are scheduled low-confidence
    /// (Eq. 20 constraint 3), as `(robot 1's interval, robot 2's interval)`, or `None`.
    ///
    /// Intervals are half-open, so one robot may enter a low-confidence run exactly when the
    /// other leaves one. An overlap shorter than [`tol::overlap_tolerance_s`]`(T_total)` is
    /// treated as rounding and ignored.
    pub fn first_lc_overlap(&self) -> Option<(LcInterval, LcInterval)> {
        let eps = tol::overlap_tolerance_s(self.t_total_s());
        let [a, b] = self.lc_intervals();
        let (mut i, mut j) = (0, 0);
        // Two-pointer merge: each robot's intervals are disjoint and in time order, so the
        // intersections come out in time order and the first one found is the earliest.
        while i < a.len() && j < b.len() {
            if a[i].overlap_s(&b[j]) > eps {
                return Some((a[i], b[j]));
            }
            if a[i].end_s <= b[j].end_s {
                i += 1;
            } else {
                j += 1;
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [HC, LC, LC, HC], gradients 1 in [0.5, 2], dt = 0.5 s.
    fn problem() -> Problem {
        crate::problem::hllh(0.5)
    }

    fn schedule(offset_s: f64) -> Schedule {
        Schedule {
            grad_exec: [vec![2.0, 1.0, 1.0, 0.5], vec![0.5, 1.0, 1.0, 2.0]],
            offset_s,
            tick_s: 0.5,
        }
    }

    #[test]
    fn timelines_accept_rounding_and_name_the_robot_of_a_wrong_length() {
        // 2.0 + 1e-12 is just above ψ̇max = 2: within the gradient tolerance, kept as it is.
        let mut s = schedule(1.0);
        s.grad_exec[0][0] = 2.0 + 1e-12;
        let [r1, r2] = s.timelines(&problem()).unwrap();
        assert_eq!((r1.start_s(), r2.start_s()), (0.0, 1.0));
        assert_eq!(r1.grad_exec()[0], 2.0 + 1e-12);
        assert_eq!(r1.end_s(), s.ends_s(0.5)[0]);
        // A warp one sample short is an error naming robot 2, not a panic.
        s.grad_exec[1].pop();
        let err = s.timelines(&problem()).unwrap_err();
        assert!(
            matches!(
                err,
                Error::Timeline {
                    robot: 1,
                    source: tandem_realtime::Error::LengthMismatch { .. }
                }
            ),
            "{err}"
        );
        assert!(err.to_string().starts_with("robot 2: "), "{err}");
    }

    #[test]
    fn t_total_by_hand() {
        // |ψ_E1| = 4.5·0.5 = 2.25 s, |ψ_E2| = 2.25 s.
        let s = schedule(1.0);
        assert_eq!(s.durations_s(0.5), [2.25, 2.25]);
        assert_eq!(s.ends_s(0.5), [2.25, 3.25]);
        assert_eq!(s.t_total_s(0.5), 3.25);
        assert_eq!(schedule(0.0).t_total_s(0.5), 2.25);
    }

    #[test]
    fn lc_intervals_by_hand() {
        // Robot 1: sample 0 takes 1 s, LC samples 1..3 take 0.5 s each → [1, 2).
        // Robot 2 (τ = 1.25): sample 0 takes 0.25 s → LC [1.5, 2.5).
        let g = GlobalTimeline::new(&problem(), &schedule(1.25)).unwrap();
        let [a, b] = g.lc_intervals();
        assert_eq!((a[0].start_s, a[0].end_s), (1.0, 2.0));
        assert_eq!((b[0].start_s, b[0].end_s), (1.5, 2.5));
        assert_eq!((b[0].ref_start, b[0].ref_end), (1, 3));
        assert_eq!(g.first_lc_overlap(), Some((a[0], b[0])));
        // Touching is not overlapping: τ = 1.75 puts robot 2's LC at [2, 3).
        let g = GlobalTimeline::new(&problem(), &schedule(1.75)).unwrap();
        assert_eq!(g.lc_intervals()[1][0].start_s, 2.0);
        assert!(g.first_lc_overlap().is_none());
        assert_eq!(g.spans_s(), [(0.0, 2.25), (1.75, 4.0)]);
        assert_eq!(g.t_total_s(), 4.0);
    }

    #[test]
    fn eq15_and_eq16_by_hand() {
        let g = GlobalTimeline::new(&problem(), &schedule(1.25)).unwrap();
        // Robot 1 at t = 0.5 s: halfway through sample 0 (which lasts 1 s).
        assert_eq!(g.ref_time(0, 0.5), 0.5);
        assert_eq!(g.ref_time(0, 1.25), 1.5);
        assert_eq!(g.ref_time(0, 99.0), 4.0);
        // Robot 2 before τ is at 0, then sample 0 lasts 0.25 s.
        assert_eq!(g.ref_time(1, 1.0), 0.0);
        assert_eq!(g.ref_time(1, 1.375), 0.5);
        assert_eq!(g.conf_at(0.5), [true, true]);
        assert_eq!(g.conf_at(1.6), [false, false]);
        assert_eq!(g.conf_at(2.1), [true, false]);
        // Not running counts as high confidence.
        assert_eq!(g.conf_at(-1.0), [true, true]);
        assert_eq!(g.conf_at(10.0), [true, true]);
    }

    #[test]
    fn shape_errors() {
        let mut s = schedule(0.0);
        s.grad_exec[1].pop();
        assert!(matches!(
            GlobalTimeline::new(&problem(), &s),
            Err(Error::Timeline {
                robot: 1,
                source: tandem_realtime::Error::LengthMismatch {
                    what: "grad_exec",
                    expected: 4,
                    found: 3
                }
            })
        ));
        let mut s = schedule(0.0);
        s.grad_exec[0][2] = f64::NAN;
        assert!(matches!(
            GlobalTimeline::new(&problem(), &s),
            Err(Error::Timeline {
                robot: 0,
                source: tandem_realtime::Error::NonFinite {
                    what: "grad_exec",
                    index: 2
                }
            })
        ));
    }

    #[test]
    fn schedule_serde_round_trip_keeps_the_tick() {
        let s = schedule(0.125);
        let json = serde_json::to_string(&s).unwrap();
        assert!(json.contains("\"tick_s\":0.5"), "{json}");
        let back: Schedule = serde_json::from_str(&json).unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn the_coordinator_runs_at_the_schedule_tick() {
        let mut s = schedule(1.25);
        s.tick_s = 0.125;
        let c = s.coordinator(&problem()).unwrap();
        assert_eq!(c.tick_s(), 0.125);
        assert_eq!(c.robots()[1].start_s(), 1.25);
        s.tick_s = f64::NAN;
        assert!(matches!(
            s.coordinator(&problem()),
            Err(Error::Realtime(tandem_realtime::Error::BadParam {
                name: "tick_s",
                ..
            }))
        ));
    }
}
