//! Schedules, `T_total` (Eq. 13) and the global timeline (Eq. 15, 16, 19).
//!
//! Every time here is read from the one Eq. 15 clock of `tandem_realtime` ([`clock_end_s`],
//! the breakpoints of a [`Timeline`]): durations, ends, `T_total` and the low-confidence
//! intervals agree to the last bit with what the margin check and the coordinator use.

use serde::{Deserialize, Serialize};
use tandem_realtime::{Hold, LcInterval, Timeline, clock_end_s, holds, tol};

use crate::problem::Problem;
use crate::validate::Violation;
use crate::{Error, Result};

/// A schedule of `N` robots (`1 ≤ N ≤` [`MAX_ROBOTS`](tandem_realtime::MAX_ROBOTS)) doing the same task under one
/// operator: one execution warp per robot, the start offsets of robots 2..N (§II-B4; robot 1
/// starts at 0) and the control tick it was checked with.
///
/// Robot index 0 is the first robot (`τ_1 = 0`), index `i ≥ 1` starts at
/// `τ_{i+1} = offsets_s[i − 1]`; for two robots `offsets_s = [τ]`. Check a schedule against a
/// [`Problem`] with [`crate::validate`] (at its own tick); [`Schedule::check`] does the same
/// and returns the [`crate::CheckedSchedule`] whose coordinator runs it (at its own tick).
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// Execution warp gradients `ψ̇_Ei[n]` per robot `i` (`N ≥ 1` warps, each of length `T_ref`)
    /// and reference sample `n` (execution samples per reference sample; robot `i` spends
    /// `ψ̇_Ei[n]·Δt_s` seconds on reference sample `n`).
    pub grad_exec: Vec<Vec<f64>>,
    /// Start offsets `τ_i` (s, global time) of robots 2..N (length `N − 1`; robot 1 starts at
    /// 0), each finite with `0 ≤ τ_i ≤ max_{j<i}(τ_j + |ψ_Ej|)` (Eq. 20 constraint 2: for two
    /// robots `0 ≤ τ ≤ |ψ_E1|`).
    pub offsets_s: Vec<f64>,
    /// Control tick (real s, finite and > 0) of the margin check (Alg. 2, Eq. 20 constraint
    /// 5) that accepted the schedule, and so the only period at which the `tandem_realtime::Coordinator` may
    /// run it: the check's guarantee (never two robots low-confidence in one tick) holds for
    /// this tick, not for another.
    pub tick_s: f64,
    /// Hold points per robot (§II-C, "stop certain robots"; `tandem_realtime::holds`): empty
    /// for a schedule without holds (serialized exactly as before holds existed), otherwise
    /// one list per robot (`N` lists, robot `i` at index `i`), each strictly increasing in
    /// [`Hold::ref_idx`]. Robot `i` stops at the start of each listed reference sample, dwells
    /// there for [`Hold::dwell_s`] on schedule (every later time of that robot is that much
    /// later) and leaves as a robot starts: once every running robot has reached its leg's
    /// start and every robot named in [`Hold::after`] has passed the named sample. The holds
    /// must be on the problem's active holds ([`Problem::active_holds`]) with a
    /// high-confidence sample before them.
    pub holds: Vec<Vec<Hold>>,
}

/// The serialized form of a [`Schedule`] in text formats (JSON, TOML): `holds` only when
/// present, so a schedule without holds reads and writes exactly as before holds existed.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScheduleText {
    grad_exec: Vec<Vec<f64>>,
    offsets_s: Vec<f64>,
    tick_s: f64,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    holds: Vec<Vec<Hold>>,
}

/// The serialized form of a [`Schedule`] in binary formats (the state file's postcard, which
/// has no optional fields): the layout of before holds existed, **without the holds**. A
/// schedule with holds read back from a binary format has lost them; this build's check then
/// rejects it (its margins relied on the holds) and the planner replaces it, never runs it.
/// Storing holds in the state file is a change of its format.
#[derive(Serialize, Deserialize)]
struct ScheduleBinary {
    grad_exec: Vec<Vec<f64>>,
    offsets_s: Vec<f64>,
    tick_s: f64,
}

impl Serialize for Schedule {
    fn serialize<S: serde::Serializer>(
        &self,
        serializer: S,
    ) -> std::result::Result<S::Ok, S::Error> {
        let (grad_exec, offsets_s, tick_s) =
            (self.grad_exec.clone(), self.offsets_s.clone(), self.tick_s);
        if serializer.is_human_readable() {
            ScheduleText {
                grad_exec,
                offsets_s,
                tick_s,
                holds: self.holds.clone(),
            }
            .serialize(serializer)
        } else {
            ScheduleBinary {
                grad_exec,
                offsets_s,
                tick_s,
            }
            .serialize(serializer)
        }
    }
}

impl<'de> Deserialize<'de> for Schedule {
    fn deserialize<D: serde::Deserializer<'de>>(
        deserializer: D,
    ) -> std::result::Result<Self, D::Error> {
        if deserializer.is_human_readable() {
            let t = ScheduleText::deserialize(deserializer)?;
            Ok(Schedule {
                grad_exec: t.grad_exec,
                offsets_s: t.offsets_s,
                tick_s: t.tick_s,
                holds: t.holds,
            })
        } else {
            let b = ScheduleBinary::deserialize(deserializer)?;
            Ok(Schedule {
                grad_exec: b.grad_exec,
                offsets_s: b.offsets_s,
                tick_s: b.tick_s,
                holds: Vec::new(),
            })
        }
    }
}

impl Schedule {
    /// The holds of robot `robot` (empty when the schedule has none).
    pub fn holds_of(&self, robot: usize) -> &[Hold] {
        self.holds.get(robot).map_or(&[], Vec::as_slice)
    }

    /// Whether any robot has a hold.
    pub fn has_holds(&self) -> bool {
        self.holds.iter().any(|h| !h.is_empty())
    }

    /// Planned dwell (s) of robot `robot` over all its holds.
    pub fn dwell_s(&self, robot: usize) -> f64 {
        self.holds_of(robot).iter().map(|h| h.dwell_s).sum()
    }

    /// Number of robots `N` (the number of warps).
    pub fn n_robots(&self) -> usize {
        self.grad_exec.len()
    }

    /// Start time `τ_i` (s, global time) of robot `robot` (0-based): 0 for robot 0,
    /// `offsets_s[robot − 1]` otherwise; NaN for a robot without an offset (which
    /// [`Schedule::check_shape`] rejects).
    pub fn start_s(&self, robot: usize) -> f64 {
        match robot {
            0 => 0.0,
            i => self.offsets_s.get(i - 1).copied().unwrap_or(f64::NAN),
        }
    }

    /// Checks the schedule's shape: `1 ≤ N ≤` [`MAX_ROBOTS`](tandem_realtime::MAX_ROBOTS) warps and `N − 1` offsets (the
    /// offsets' range, Eq. 20 constraint 2, and the warps' lengths are [`crate::validate`]'s).
    ///
    /// # Errors
    /// [`Violation::RobotCount`] or [`Violation::OffsetCount`].
    pub fn check_shape(&self) -> std::result::Result<(), Violation> {
        let n = self.n_robots();
        tandem_realtime::RobotCount::new(n).map_err(Violation::RobotCount)?;
        if self.offsets_s.len() + 1 != n {
            return Err(Violation::OffsetCount {
                found: self.offsets_s.len(),
                expected: n - 1,
            });
        }
        if !self.holds.is_empty() && self.holds.len() != n {
            return Err(Violation::HoldCount {
                found: self.holds.len(),
                expected: n,
            });
        }
        Ok(())
    }

    /// Each robot's [`Timeline`] (schedule-clock plan for the real-time coordinator and the
    /// margin check, Eq. 15–16) on `problem`, built from the schedule's own gradients: the
    /// realtime crate accepts gradients within [`tol::GRADIENT_REL`] of the bounds, as
    /// [`crate::validate`] does.
    ///
    /// # Errors
    /// [`Error::Shape`] for a schedule that fails [`Schedule::check_shape`];
    /// [`Error::Timeline`] naming the robot, for a warp whose length is not `T_ref`, a
    /// non-finite value or a gradient outside its bounds.
    pub fn timelines(&self, problem: &Problem) -> Result<Vec<Timeline>> {
        self.check_shape().map_err(Error::Shape)?;
        self.timelines_of(problem)
            .map_err(|(robot, source)| Error::Timeline { robot, source })
    }

    /// [`Schedule::timelines`] of a schedule of valid shape, with the failing robot's index
    /// beside the realtime error.
    pub(crate) fn timelines_of(
        &self,
        problem: &Problem,
    ) -> std::result::Result<Vec<Timeline>, (usize, tandem_realtime::Error)> {
        (0..self.n_robots())
            .map(|robot| {
                Timeline::new(
                    problem.conf(),
                    &self.grad_exec[robot],
                    problem.grad_min(),
                    problem.grad_max(),
                    self.start_s(robot),
                    problem.dt_s(),
                )
                .map_err(|e| (robot, e))
            })
            .collect()
    }

    /// Each robot's plan split at its holds into legs ([`holds::legs`]; one leg per robot
    /// without holds, its [`Timeline`] as [`Schedule::timelines`] gives it): robot `i`'s legs
    /// at index `i`, in order, each starting after the planned dwell of its hold.
    ///
    /// # Errors
    /// As [`Schedule::timelines`].
    pub fn legs(&self, problem: &Problem) -> Result<Vec<Vec<Timeline>>> {
        self.timelines(problem)?
            .iter()
            .enumerate()
            .map(|(robot, tl)| {
                holds::legs(tl, self.holds_of(robot))
                    .map_err(|source| Error::Timeline { robot, source })
            })
            .collect()
    }

    /// Every robot's low-confidence intervals in global time (s) as the robot runs them: from
    /// its [`Schedule::legs`], each leg after its planned dwell, with reference samples counted
    /// from the task start (a leg counts from its hold). Without holds these are the
    /// intervals of each robot's [`Timeline`], bit for bit. The same as
    /// [`GlobalTimeline::lc_intervals`].
    ///
    /// # Errors
    /// As [`Schedule::legs`].
    pub fn lc_intervals(&self, problem: &Problem) -> Result<Vec<Vec<LcInterval>>> {
        Ok(GlobalTimeline::new(problem, self)?.lc_intervals())
    }

    /// Robot `robot`'s legs ([`holds::legs`]) with the reference sample each starts at (0,
    /// then each hold's); `None` when the schedule plans no dwell, so that the legs run
    /// exactly as the robot's timeline (a hold lies on high-confidence samples, so no
    /// low-confidence interval is ever cut at one).
    fn legs_from(
        &self,
        timelines: &[Timeline],
    ) -> std::result::Result<Option<Vec<Vec<Leg>>>, (usize, tandem_realtime::Error)> {
        if !self.holds.iter().flatten().any(|h| h.dwell_s > 0.0) {
            return Ok(None);
        }
        timelines
            .iter()
            .enumerate()
            .map(|(robot, tl)| {
                let holds = self.holds_of(robot);
                let from =
                    std::iter::once(0).chain(holds.iter().map(|h| h.ref_idx).filter(|&n| n > 0));
                Ok(holds::legs(tl, holds)
                    .map_err(|e| (robot, e))?
                    .into_iter()
                    .zip(from)
                    .map(|(tl, from)| Leg { from, tl })
                    .collect())
            })
            .collect::<std::result::Result<Vec<_>, _>>()
            .map(Some)
    }

    /// Checks this schedule on `problem` ([`validate`](crate::validate): every constraint of
    /// Eq. 20, with this build's margin check of Alg. 2 at [`Schedule::tick_s`]) and, if it
    /// passes, returns it as a [`CheckedSchedule`](crate::CheckedSchedule), the only form
    /// the runtime coordinator is built from.
    ///
    /// # Errors
    /// [`Error::Invalid`] with the first broken constraint.
    pub fn check(&self, problem: &Problem) -> Result<crate::CheckedSchedule> {
        crate::CheckedSchedule::new(problem, self.clone(), 0.0, 1.0)
    }

    /// [`Schedule::check`] for a schedule planned for an operator with switch time `switch_s`
    /// (s, ≥ 0) and load cap `max_busy_share` (`SamplerParams::{switch_s, max_busy_share}`):
    /// [`validate_with_operator`](crate::validate_with_operator) — Eq. 20 constraint 2 relaxed
    /// by [`crate::start_allowance_s`] (a robot may start that long after every robot before it
    /// has ended: the idle gaps of the serial schedule with a switch time or a cap), no planned
    /// switch shorter than `switch_s` (3δ), and the margin check *with the switch time*
    /// (`tandem_realtime::check_margins` at `switch_s`, 5δ), so a schedule that keeps the
    /// operator's switch time only at `δ = 0` is refused. `switch_s = 0` with
    /// `max_busy_share = 1` is [`Schedule::check`]. Run the coordinator with the same switch
    /// time (`Coordinator::with_switch_s`): the check with holds assumes its wait.
    ///
    /// # Errors
    /// As [`Schedule::check`]; [`Violation::SwitchTooShort`] or
    /// [`Violation::InsufficientSwitchTime`] inside [`Error::Invalid`] for a schedule that does
    /// not keep `switch_s`.
    pub fn check_with_operator(
        &self,
        problem: &Problem,
        switch_s: f64,
        max_busy_share: f64,
    ) -> Result<crate::CheckedSchedule> {
        crate::CheckedSchedule::new(problem, self.clone(), switch_s, max_busy_share)
    }

    /// Start time of each robot in global time (s): `[0, τ_2, …, τ_N]`.
    pub fn starts_s(&self) -> Vec<f64> {
        (0..self.n_robots()).map(|i| self.start_s(i)).collect()
    }

    /// Execution durations `|ψ_Ei|` (s) per robot for reference sample period `dt_s` (s): the
    /// end of each warp's clock started at 0 ([`clock_end_s`]).
    pub fn durations_s(&self, dt_s: f64) -> Vec<f64> {
        (0..self.n_robots())
            .map(|i| self.clock_end_of(i, 0.0, dt_s))
            .collect()
    }

    /// The end of robot `robot`'s clock started at `start_s`: [`clock_end_s`], or with holds
    /// [`holds::held_clock_end_s`] (which adds the dwells; the same sum without them).
    fn clock_end_of(&self, robot: usize, start_s: f64, dt_s: f64) -> f64 {
        let holds = self.holds_of(robot);
        if holds.is_empty() {
            clock_end_s(&self.grad_exec[robot], start_s, dt_s)
        } else {
            holds::held_clock_end_s(&self.grad_exec[robot], start_s, dt_s, holds)
        }
    }

    /// Global time (s) at which each robot ends on schedule, `τ_i + |ψ_Ei|`, for sample period
    /// `dt_s` (s): the end of its clock started at its start ([`clock_end_s`]), exactly
    /// [`Timeline::end_s`] of [`Schedule::timelines`].
    pub fn ends_s(&self, dt_s: f64) -> Vec<f64> {
        (0..self.n_robots()).map(|i| self.end_s(i, dt_s)).collect()
    }

    /// Global time (s) at which robot `robot` ends on schedule, `τ_i + |ψ_Ei|`, for sample
    /// period `dt_s` (s) (one entry of [`Schedule::ends_s`]).
    pub fn end_s(&self, robot: usize, dt_s: f64) -> f64 {
        self.clock_end_of(robot, self.start_s(robot), dt_s)
    }

    /// `T_total = max_i(τ_i + |ψ_Ei|)` (Eq. 13), global time (s), for sample period `dt_s`:
    /// the latest of [`Schedule::ends_s`].
    pub fn t_total_s(&self, dt_s: f64) -> f64 {
        (0..self.n_robots())
            .map(|i| self.end_s(i, dt_s))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// The global timeline of a schedule (Eq. 15–16, 19): where each robot is in the reference
/// at any global time, its confidence then, and every low-confidence interval in global time,
/// as the robots run the schedule: with planned dwells at hold points, each robot's plan is
/// its legs ([`Schedule::legs`]), each starting after its dwell, and a robot dwelling at a
/// hold stays at the hold's reference sample (high confidence).
///
/// Reference sample `n` of robot `i` occupies global time `[c_n, c_{n+1})` of its clock
/// ([`tandem_realtime::clock_s`], started at `τ_i`, and after a hold at the end of its dwell).
#[derive(Clone, Debug)]
pub struct GlobalTimeline {
    /// Every robot's plan as one timeline without the dwells (the margin check's input).
    robots: Vec<Timeline>,
    /// With planned dwells, every robot's legs as run; `None` without dwells (the legs are
    /// then `robots` themselves).
    legs: Option<Vec<Vec<Leg>>>,
}

/// One leg of a robot's plan: its timeline (reference samples counted from the leg's first)
/// and the reference sample of the task it starts at.
#[derive(Clone, Debug)]
struct Leg {
    from: usize,
    tl: Timeline,
}

impl From<Vec<Timeline>> for GlobalTimeline {
    /// The timelines as robots without dwells.
    fn from(robots: Vec<Timeline>) -> Self {
        GlobalTimeline { robots, legs: None }
    }
}

/// Two robots scheduled low-confidence at once (Eq. 20 constraint 3): robot `robots[0]` in
/// `intervals[0]` and robot `robots[1]` in `intervals[1]` (global time), `robots[0] <
/// robots[1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LcOverlap {
    /// The two robots (0-based, ascending).
    pub robots: [usize; 2],
    /// Their overlapping low-confidence intervals (global time, s), in the order of `robots`.
    pub intervals: [LcInterval; 2],
}

impl LcOverlap {
    /// Global time (s) at which the overlap starts.
    pub fn start_s(&self) -> f64 {
        self.intervals[0].start_s.max(self.intervals[1].start_s)
    }

    /// Global time (s) at which the overlap ends.
    pub fn end_s(&self) -> f64 {
        self.intervals[0].end_s.min(self.intervals[1].end_s)
    }
}

impl GlobalTimeline {
    /// Lays `schedule` out in global time for `problem` ([`Schedule::timelines`], split into
    /// [`Schedule::legs`] when it plans dwells).
    ///
    /// # Errors
    /// As [`Schedule::timelines`]: a schedule of the wrong shape, or [`Error::Timeline`]
    /// naming the robot whose warp has the wrong length, a non-finite value, or a gradient
    /// outside its bounds.
    pub fn new(problem: &Problem, schedule: &Schedule) -> Result<Self> {
        schedule.check_shape().map_err(Error::Shape)?;
        Self::of(problem, schedule).map_err(|(robot, source)| Error::Timeline { robot, source })
    }

    /// [`GlobalTimeline::new`] of a schedule of valid shape, with the failing robot's index
    /// beside the realtime error.
    pub(crate) fn of(
        problem: &Problem,
        schedule: &Schedule,
    ) -> std::result::Result<Self, (usize, tandem_realtime::Error)> {
        let robots = schedule.timelines_of(problem)?;
        let legs = schedule.legs_from(&robots)?;
        Ok(GlobalTimeline { robots, legs })
    }

    /// Number of robots `N`.
    pub fn n_robots(&self) -> usize {
        self.robots.len()
    }

    /// Every robot's plan as one timeline (robot 1 first), *without* the planned dwells: the
    /// input of the margin check, which adds the dwells itself (`tandem_realtime::holds`).
    /// Without dwells it is exactly how the robots run.
    pub fn timelines(&self) -> &[Timeline] {
        &self.robots
    }

    /// The timelines, by value.
    pub(crate) fn into_timelines(self) -> Vec<Timeline> {
        self.robots
    }

    /// Robot `robot`'s legs as run, each with the reference sample it starts at.
    fn legs_of(&self, robot: usize) -> impl Iterator<Item = (usize, &Timeline)> + '_ {
        let (one, many) = match &self.legs {
            None => (Some((0, &self.robots[robot])), None),
            Some(legs) => (None, Some(legs[robot].iter().map(|l| (l.from, &l.tl)))),
        };
        one.into_iter().chain(many.into_iter().flatten())
    }

    /// The leg of robot `robot` that is current at global time `t_global_s`: the last one
    /// that has started, or the first before the robot starts.
    fn leg_at(&self, robot: usize, t_global_s: f64) -> (usize, &Timeline) {
        let mut legs = self.legs_of(robot);
        let mut cur = legs.next().expect("a robot has at least one leg");
        for leg in legs {
            if leg.1.start_s() > t_global_s {
                break;
            }
            cur = leg;
        }
        cur
    }

    /// Each robot's `[start, end]` in global time (s), dwells included.
    pub fn spans_s(&self) -> Vec<(f64, f64)> {
        (0..self.robots.len())
            .map(|i| {
                let start = self.robots[i].start_s();
                let end = self.legs_of(i).last().map_or(start, |(_, l)| l.end_s());
                (start, end)
            })
            .collect()
    }

    /// `T_total` (Eq. 13), global time (s): the latest end, dwells included.
    pub fn t_total_s(&self) -> f64 {
        self.spans_s()
            .iter()
            .map(|&(_, end)| end)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Eq. 15: robot `robot`'s fractional reference time (reference samples, in `[0, T_ref]`)
    /// at global time `t_global_s`: 0 before its start, `T_ref` after its end, linear within
    /// each reference sample in between, and a hold's sample while the robot dwells there.
    /// `robot ≥ N` is treated as the last robot.
    pub fn ref_time(&self, robot: usize, t_global_s: f64) -> f64 {
        let (from, leg) = self.leg_at(robot.min(self.robots.len() - 1), t_global_s);
        from as f64 + leg.ref_time_at(t_global_s)
    }

    /// Eq. 16: `conf_i(t)` of every robot at global time `t_global_s` (`true` = high
    /// confidence; a robot that is not running, `t < τ_i` or `t ≥ τ_i + |ψ_Ei|`, or that
    /// dwells at a hold, counts as high).
    pub fn conf_at(&self, t_global_s: f64) -> Vec<bool> {
        (0..self.robots.len())
            .map(|i| self.leg_at(i, t_global_s).1.conf_at(t_global_s))
            .collect()
    }

    /// Each robot's low-confidence intervals in global time, in time order (Eq. 19: their
    /// union is `T_lc`), reference samples counted from the task start.
    pub fn lc_intervals(&self) -> Vec<Vec<LcInterval>> {
        (0..self.robots.len())
            .map(|i| {
                self.legs_of(i)
                    .flat_map(|(from, leg)| {
                        leg.lc_intervals().iter().map(move |iv| LcInterval {
                            ref_start: iv.ref_start + from,
                            ref_end: iv.ref_end + from,
                            ..*iv
                        })
                    })
                    .collect()
            })
            .collect()
    }

    /// The first stretch of global time in which two robots are scheduled low-confidence
    /// (Eq. 20 constraint 3), or `None`: of every pair of robots the first overlap in time,
    /// and of those the one starting earliest (the lower pair of robots on a tie).
    ///
    /// Intervals are half-open, so one robot may enter a low-confidence run exactly when
    /// another leaves one. An overlap shorter than [`tol::overlap_tolerance_s`]`(T_total)` is
    /// treated as rounding and ignored.
    pub fn first_lc_overlap(&self) -> Option<LcOverlap> {
        let eps = tol::overlap_tolerance_s(self.t_total_s());
        let owned;
        let intervals: Vec<&[LcInterval]> = if self.legs.is_some() {
            owned = self.lc_intervals();
            owned.iter().map(Vec::as_slice).collect()
        } else {
            self.robots.iter().map(Timeline::lc_intervals).collect()
        };
        let mut first: Option<LcOverlap> = None;
        for i in 0..intervals.len() {
            for j in i + 1..intervals.len() {
                if let Some((a, b)) = first_overlap_of(intervals[i], intervals[j], eps) {
                    let o = LcOverlap {
                        robots: [i, j],
                        intervals: [a, b],
                    };
                    if first.is_none_or(|f| o.start_s() < f.start_s()) {
                        first = Some(o);
                    }
                }
            }
        }
        first
    }
}

/// The first pair of intervals of `a` and `b` (each disjoint and in time order) that overlap
/// by more than `eps` (s).
fn first_overlap_of(
    a: &[LcInterval],
    b: &[LcInterval],
    eps: f64,
) -> Option<(LcInterval, LcInterval)> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// [HC, LC, LC, HC], gradients 1 in [0.5, 2], dt = 0.5 s.
    fn problem() -> Problem {
        crate::problem::hllh(0.5)
    }

    fn schedule(offset_s: f64) -> Schedule {
        Schedule {
            grad_exec: vec![vec![2.0, 1.0, 1.0, 0.5], vec![0.5, 1.0, 1.0, 2.0]],
            offsets_s: vec![offset_s],
            tick_s: 0.5,
            holds: Vec::new(),
        }
    }

    /// The check of a schedule planned with a switch time runs the margin check *with* it
    /// (regression: `check_with_operator` relaxed constraint 2 but checked margins at `δ = 0`,
    /// and the study's workcell ran its rounds on that check). The fastest serial schedule of
    /// [HC, LC, LC, HC] at 0.5 s (HC samples at `ψ̇min`, 0.25 s each, LC at 0.5 s; robot 1's
    /// stretch [0.25, 1.25) s, robot 2 from 1.5 s, its stretch [1.75, 2.75) s: 0.5 s apart on
    /// schedule) passes the check without a switch time. At `δ = 1` s the planned gap is short
    /// (3δ). At `δ = 0.5` s (`k = 1` tick) the planned gap is enough but the worst case is not:
    /// robot 2 starts in the tick robot 1 reaches its end, no tick is idle, and a robot's 0.25 s
    /// head or tail fits in the tick that leaves or enters its stretch (5δ). Both fail only with
    /// `δ` in the check. Robot 2 at 2.75 s (after the allowance's idle time: `⌈(2.75 − 1.5 −
    /// M)/h⌉ = 1` idle tick with `M = h·F = 1` s) keeps `k` and passes at `δ`; constraint 2 as
    /// printed refuses it.
    #[test]
    fn the_check_with_an_operator_keeps_its_switch_time() {
        let p = problem();
        let serial = p.serial_schedule(0.5).unwrap();
        assert_eq!(serial.offsets_s, vec![1.5]);
        serial.check(&p).unwrap();
        serial.check_with_operator(&p, 0.0, 1.0).unwrap();
        let short = serial.check_with_operator(&p, 1.0, 1.0).unwrap_err();
        assert!(
            matches!(
                short,
                Error::Invalid(Violation::SwitchTooShort { robots: [0, 1], end_s, start_s, .. })
                    if end_s == 1.25 && start_s == 1.75
            ),
            "{short}"
        );
        let worst = serial.check_with_operator(&p, 0.5, 1.0).unwrap_err();
        assert!(
            matches!(
                worst,
                Error::Invalid(Violation::InsufficientSwitchTime { switch_s, .. }) if switch_s == 0.5
            ),
            "{worst}"
        );
        let idle = Schedule {
            offsets_s: vec![2.75],
            ..serial.clone()
        };
        let checked = idle.check_with_operator(&p, 0.5, 1.0).unwrap();
        assert_eq!(checked.schedule(), &idle);
        let too_soon = Schedule {
            offsets_s: vec![2.5],
            ..serial.clone()
        };
        assert!(too_soon.check_with_operator(&p, 0.5, 1.0).is_err());
        assert!(
            idle.check(&p).is_err(),
            "constraint 2 as printed refuses the idle gap"
        );
    }

    #[test]
    fn timelines_accept_rounding_and_name_the_robot_of_a_wrong_length() {
        // 2.0 + 1e-12 is just above ψ̇max = 2: within the gradient tolerance, kept as it is.
        let mut s = schedule(1.0);
        s.grad_exec[0][0] = 2.0 + 1e-12;
        let [r1, r2]: [Timeline; 2] = s.timelines(&problem()).unwrap().try_into().unwrap();
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
        assert_eq!((s.n_robots(), s.start_s(0), s.start_s(1)), (2, 0.0, 1.0));
        assert_eq!(s.ends_s(0.5), [2.25, 3.25]);
        assert_eq!(s.t_total_s(0.5), 3.25);
        assert_eq!(schedule(0.0).t_total_s(0.5), 2.25);
    }

    #[test]
    fn lc_intervals_by_hand() {
        // Robot 1: sample 0 takes 1 s, LC samples 1..3 take 0.5 s each → [1, 2).
        // Robot 2 (τ = 1.25): sample 0 takes 0.25 s → LC [1.5, 2.5).
        let g = GlobalTimeline::new(&problem(), &schedule(1.25)).unwrap();
        let ivs = g.lc_intervals();
        let [a, b] = &ivs[..] else {
            panic!("two robots")
        };
        assert_eq!((a[0].start_s, a[0].end_s), (1.0, 2.0));
        assert_eq!((b[0].start_s, b[0].end_s), (1.5, 2.5));
        assert_eq!((b[0].ref_start, b[0].ref_end), (1, 3));
        assert_eq!(
            g.first_lc_overlap(),
            Some(LcOverlap {
                robots: [0, 1],
                intervals: [a[0], b[0]]
            })
        );
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
    fn holds_serialize_only_when_present_and_add_their_dwell() {
        let s = schedule(2.25);
        let json = serde_json::to_string(&s).unwrap();
        assert!(!json.contains("holds"), "{json}");
        let mut h = s.clone();
        h.holds = vec![
            vec![],
            vec![Hold {
                dwell_s: 0.5,
                after: vec![tandem_realtime::After {
                    robot: 0,
                    ref_idx: 3,
                }],
                ..Hold::at(3)
            }],
        ];
        let json = serde_json::to_string(&h).unwrap();
        assert!(
            json.contains("\"holds\":[[],[{\"ref_idx\":3,\"dwell_s\":0.5"),
            "{json}"
        );
        let back: Schedule = serde_json::from_str(&json).unwrap();
        assert_eq!(back, h);
        // Robot 2's end moves by its dwell; robot 1's does not.
        assert_eq!(h.ends_s(0.5), [2.25, 5.0]);
        assert_eq!(h.t_total_s(0.5), s.t_total_s(0.5) + 0.5);
        assert_eq!(h.dwell_s(1), 0.5);
        let p = problem().with_holds(vec![3]).unwrap();
        let legs = h.legs(&p).unwrap();
        assert_eq!(legs[1].len(), 2);
        assert_eq!(legs[1][1].start_s(), legs[1][0].end_s() + 0.5);
        assert_eq!(legs[1][1].end_s(), h.end_s(1, 0.5));
        // Holds must be one list per robot.
        h.holds.pop();
        assert!(matches!(
            h.check_shape(),
            Err(Violation::HoldCount {
                found: 1,
                expected: 2
            })
        ));
    }

    #[test]
    fn only_a_checked_schedule_gets_a_coordinator_at_its_tick() {
        // τ = 1.25: robot 2's low-confidence samples (clock 1.5–2.5) meet robot 1's (1–2).
        let mut s = schedule(1.25);
        s.tick_s = 0.125;
        assert!(matches!(
            s.check(&problem()),
            Err(Error::Invalid(Violation::BothLowConfidence { .. }))
        ));
        // Serial (τ = |ψ_E1| = 2.25 s) passes; the coordinator runs the checked plans at the
        // schedule's tick.
        s.offsets_s = vec![2.25];
        let checked = s.check(&problem()).unwrap();
        let c = checked.coordinator().unwrap();
        assert_eq!(c.tick_s(), 0.125);
        assert_eq!(c.robots()[1].start_s(), 2.25);
        assert_eq!(checked.schedule(), &s);
        s.tick_s = f64::NAN;
        assert!(matches!(
            s.check(&problem()),
            Err(Error::Invalid(Violation::InvalidTick { .. }))
        ));
    }

    /// [HC, HC, LC, HC], gradients 1 in [0.5, 2], dt = 0.5 s, a hold point at sample 1.
    fn held_problem() -> Problem {
        Problem::new(
            vec![true, true, false, true],
            vec![1.0; 4],
            vec![0.5; 4],
            vec![2.0; 4],
            0.5,
        )
        .unwrap()
        .with_holds(vec![1])
        .unwrap()
    }

    /// Robot 1 dwells `dwell_s` at sample 1; robot 2 starts with it and never dwells.
    fn held_schedule(dwell_s: f64) -> Schedule {
        Schedule {
            grad_exec: vec![vec![1.0; 4], vec![1.0; 4]],
            offsets_s: vec![0.0],
            tick_s: 0.5,
            holds: vec![
                vec![Hold {
                    ref_idx: 1,
                    dwell_s,
                    after: Vec::new(),
                }],
                Vec::new(),
            ],
        }
    }

    #[test]
    fn the_global_timeline_runs_the_planned_dwells() {
        // Robot 1: sample 0 in [0, 0.5), the dwell at sample 1 in [0.5, 1.5), sample 1 in
        // [1.5, 2), its LC sample 2 in [2, 2.5), sample 3 in [2.5, 3). Robot 2: LC in [1, 1.5).
        let (p, s) = (held_problem(), held_schedule(1.0));
        let g = GlobalTimeline::new(&p, &s).unwrap();
        assert_eq!(g.spans_s(), [(0.0, 3.0), (0.0, 2.0)]);
        assert_eq!(g.t_total_s(), 3.0);
        assert_eq!(g.t_total_s(), s.t_total_s(0.5));
        assert_eq!(g.spans_s()[0].1, s.ends_s(0.5)[0]);
        // Eq. 15 while dwelling: the hold's sample; after it, one sample per 0.5 s again.
        for (t, r) in [
            (0.25, 0.5),
            (0.5, 1.0),
            (1.0, 1.0),
            (1.75, 1.5),
            (2.25, 2.5),
        ] {
            assert_eq!(g.ref_time(0, t), r, "robot 1 at {t} s");
        }
        assert_eq!(g.ref_time(0, 10.0), 4.0);
        assert_eq!(g.ref_time(1, 1.25), 2.5);
        // Eq. 16: dwelling counts as high confidence; robot 1 is low in [2, 2.5).
        assert_eq!(g.conf_at(1.25), [true, false]);
        assert_eq!(g.conf_at(2.25), [false, true]);
        // Eq. 19: robot 1's interval after its dwell, counted from the task start.
        let ivs = g.lc_intervals();
        assert_eq!(
            (ivs[0].len(), ivs[0][0].ref_start, ivs[0][0].ref_end),
            (1, 2, 3)
        );
        assert_eq!((ivs[0][0].start_s, ivs[0][0].end_s), (2.0, 2.5));
        assert_eq!((ivs[1][0].start_s, ivs[1][0].end_s), (1.0, 1.5));
        assert_eq!(s.lc_intervals(&p).unwrap(), ivs);
        // The dwell moves robot 1's region out of robot 2's: no overlap; without it, one.
        assert_eq!(g.first_lc_overlap(), None);
        let o = GlobalTimeline::new(&p, &held_schedule(0.0))
            .unwrap()
            .first_lc_overlap()
            .unwrap();
        assert_eq!((o.robots, o.start_s(), o.end_s()), ([0, 1], 1.0, 1.5));
        // The margin check's input stays the plan without the dwells.
        assert_eq!(g.timelines()[0].end_s(), 2.0);
    }
}
