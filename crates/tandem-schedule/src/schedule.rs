//! Schedules, `T_total` (Eq. 13) and the global timeline (Eq. 15, 16, 19).

use serde::{Deserialize, Serialize};
use tandem_realtime::{Error as RtError, Timeline};

use crate::problem::Problem;
use crate::{Error, Result};

/// `|ψ_E| = Σ_n ψ̇_E[n]·Δt_s` (s): the duration of an execution warp given by its gradients.
pub(crate) fn execution_s(grad_exec: &[f64], dt_s: f64) -> f64 {
    grad_exec.iter().sum::<f64>() * dt_s
}

/// A two-robot schedule: one execution warp per robot and the offset of robot 2 (§II-B4).
///
/// Robot index 0 is the first robot (`τ_1 = 0`), index 1 the second (`τ_2 = offset_s`).
/// Check a schedule against a [`Problem`] with [`crate::validate`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Schedule {
    /// Execution warp gradients `ψ̇_Ei[n]` per robot and reference sample `n` (execution samples
    /// per reference sample; robot `i` spends `ψ̇_Ei[n]·Δt_s` seconds on reference sample `n`).
    pub grad_exec: [Vec<f64>; 2],
    /// Offset `τ` (s, global time) at which robot 2 starts; `0 ≤ τ ≤ |ψ_E1|` (Eq. 20).
    pub offset_s: f64,
}

impl Schedule {
    /// Each robot's [`Timeline`] (schedule-clock plan for the real-time coordinator and the
    /// margin check, Eq. 15–16) on `problem`. Gradients are clamped into `[ψ̇min, ψ̇max]`
    /// first: [`crate::validate`] lets values through within a relative `1e-9` of the bounds,
    /// and the realtime crate checks them exactly.
    ///
    /// # Errors
    /// The realtime crate's error for a warp whose length is not `T_ref`, or non-finite values.
    pub fn timelines(&self, problem: &Problem) -> std::result::Result<[Timeline; 2], RtError> {
        let (gmin, gmax) = (problem.grad_min(), problem.grad_max());
        let build = |robot: usize| {
            let raw = &self.grad_exec[robot];
            // Clamp only a warp of the right length; the realtime crate names the mismatch.
            let grad: Vec<f64> = if raw.len() == gmin.len() {
                raw.iter()
                    .zip(gmin.iter().zip(gmax))
                    .map(|(g, (lo, hi))| g.clamp(*lo, *hi))
                    .collect()
            } else {
                raw.clone()
            };
            Timeline::new(
                problem.conf(),
                &grad,
                gmin,
                gmax,
                self.starts_s()[robot],
                problem.dt_s(),
            )
        };
        Ok([build(0)?, build(1)?])
    }

    /// Start time of each robot in global time (s): `[0, τ]`.
    pub fn starts_s(&self) -> [f64; 2] {
        [0.0, self.offset_s]
    }

    /// Execution durations `[|ψ_E1|, |ψ_E2|]` (s) for reference sample period `dt_s` (s).
    pub fn durations_s(&self, dt_s: f64) -> [f64; 2] {
        [
            execution_s(&self.grad_exec[0], dt_s),
            execution_s(&self.grad_exec[1], dt_s),
        ]
    }

    /// `T_total = max(|ψ_E1|, τ + |ψ_E2|)` (Eq. 13), global time (s), for sample period `dt_s`.
    pub fn t_total_s(&self, dt_s: f64) -> f64 {
        let [d0, d1] = self.durations_s(dt_s);
        d0.max(self.offset_s + d1)
    }
}

/// A maximal low-confidence stretch of one robot, in both time frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LcInterval {
    /// Robot index (0 = first robot, 1 = second).
    pub robot: usize,
    /// Reference samples `ref_start..ref_end` (end exclusive) of the low-confidence run.
    pub ref_start: usize,
    /// One past the last reference sample of the run.
    pub ref_end: usize,
    /// Global time (s) at which the robot enters the run (scheduled, Eq. 15).
    pub start_s: f64,
    /// Global time (s) at which the robot leaves the run (scheduled); the interval is
    /// `[start_s, end_s)`.
    pub end_s: f64,
}

/// One robot's schedule in global time: start and cumulative execution times.
#[derive(Clone, Debug)]
struct RobotLine {
    start_s: f64,
    /// `cum_s[n]`: execution time (s) from the robot's start to entering reference sample `n`;
    /// length `T_ref + 1`.
    cum_s: Vec<f64>,
}

/// The global timeline of a schedule (Eq. 15–16, 19): where each robot is in the reference at
/// any global time, its confidence then, and every low-confidence interval in global time.
///
/// Reference sample `n` of robot `i` occupies global time
/// `[τ_i + Σ_{m<n} ψ̇_Ei[m]·Δt_s, τ_i + Σ_{m≤n} ψ̇_Ei[m]·Δt_s)`.
#[derive(Clone, Debug)]
pub struct GlobalTimeline {
    conf: Vec<bool>,
    robots: [RobotLine; 2],
    intervals: [Vec<LcInterval>; 2],
}

impl GlobalTimeline {
    /// Lays `schedule` out in global time for `problem`.
    ///
    /// Only shapes and finiteness are checked here (bounds and the other constraints are
    /// [`crate::validate`]'s job).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when a warp does not have `T_ref` gradients,
    /// [`Error::NonFinite`] for a non-finite or non-positive gradient or offset.
    pub fn new(problem: &Problem, schedule: &Schedule) -> Result<Self> {
        let n_ref = problem.n_ref();
        let dt_s = problem.dt_s();
        if !schedule.offset_s.is_finite() {
            return Err(Error::NonFinite {
                name: "offset_s",
                ref_idx: 0,
            });
        }
        let mut lines = Vec::with_capacity(2);
        for (robot, grad) in schedule.grad_exec.iter().enumerate() {
            let name = if robot == 0 {
                "grad_exec[0]"
            } else {
                "grad_exec[1]"
            };
            if grad.len() != n_ref {
                return Err(Error::LengthMismatch {
                    name,
                    len: grad.len(),
                    expected: n_ref,
                });
            }
            if let Some(ref_idx) = grad.iter().position(|g| !(g.is_finite() && *g > 0.0)) {
                return Err(Error::NonFinite { name, ref_idx });
            }
            let mut cum_s = Vec::with_capacity(n_ref + 1);
            let mut acc = 0.0;
            cum_s.push(0.0);
            for g in grad {
                acc += g;
                cum_s.push(acc * dt_s);
            }
            lines.push(RobotLine {
                start_s: schedule.starts_s()[robot],
                cum_s,
            });
        }
        let robots: [RobotLine; 2] = [lines.remove(0), lines.remove(0)];
        let intervals = [0, 1].map(|robot| {
            let line = &robots[robot];
            problem
                .runs()
                .iter()
                .filter(|r| !r.high_conf)
                .map(|r| LcInterval {
                    robot,
                    ref_start: r.start,
                    ref_end: r.end,
                    start_s: line.start_s + line.cum_s[r.start],
                    end_s: line.start_s + line.cum_s[r.end],
                })
                .collect()
        });
        Ok(GlobalTimeline {
            conf: problem.conf().to_vec(),
            robots,
            intervals,
        })
    }

    /// Each robot's `[start, end]` in global time (s).
    pub fn spans_s(&self) -> [(f64, f64); 2] {
        self.robots
            .each_ref()
            .map(|r| (r.start_s, r.start_s + r.cum_s[r.cum_s.len() - 1]))
    }

    /// `T_total` (Eq. 13), global time (s).
    pub fn t_total_s(&self) -> f64 {
        let [a, b] = self.spans_s();
        a.1.max(b.1)
    }

    /// Eq. 15: robot `robot`'s fractional reference time (reference samples, in `[0, T_ref]`)
    /// at global time `t_global_s`: 0 before its start, `T_ref` after its end, linear within
    /// each reference sample in between. `robot` > 1 is treated as robot 1.
    pub fn ref_time(&self, robot: usize, t_global_s: f64) -> f64 {
        let line = &self.robots[robot.min(1)];
        let n_ref = line.cum_s.len() - 1;
        let t = t_global_s - line.start_s;
        if t.is_nan() || t <= 0.0 {
            return 0.0;
        }
        if t >= line.cum_s[n_ref] {
            return n_ref as f64;
        }
        // Last n with cum_s[n] <= t.
        let n = line.cum_s.partition_point(|&c| c <= t) - 1;
        let width = line.cum_s[n + 1] - line.cum_s[n];
        n as f64 + ((t - line.cum_s[n]) / width).clamp(0.0, 1.0)
    }

    /// Eq. 16: `[conf_1(t), conf_2(t)]` at global time `t_global_s` (`true` = high confidence;
    /// a robot that is not running, `t < τ_i` or `t ≥ τ_i + |ψ_Ei|`, counts as high).
    pub fn conf_at(&self, t_global_s: f64) -> [bool; 2] {
        [0, 1].map(|robot| {
            let line = &self.robots[robot];
            let t = t_global_s - line.start_s;
            let n_ref = line.cum_s.len() - 1;
            if t.is_nan() || t < 0.0 || t >= line.cum_s[n_ref] {
                return true;
            }
            let n = line.cum_s.partition_point(|&c| c <= t) - 1;
            self.conf[n.min(n_ref - 1)]
        })
    }

    /// Each robot's low-confidence intervals in global time, in time order (Eq. 19: their
    /// union is `T_lc`).
    pub fn lc_intervals(&self) -> &[Vec<LcInterval>; 2] {
        &self.intervals
    }

    /// The first stretch of global time in which both robots are scheduled low-confidence
    /// (Eq. 20 constraint 3), as `(robot 1's interval, robot 2's interval)`, or `None`.
    ///
    /// Intervals are half-open, so one robot may enter a low-confidence run exactly when the
    /// other leaves one. An overlap shorter than `1e-9·max(1, T_total)` s is treated as
    /// rounding and ignored.
    pub fn first_lc_overlap(&self) -> Option<(LcInterval, LcInterval)> {
        let eps = 1e-9 * self.t_total_s().max(1.0);
        let (a, b) = (&self.intervals[0], &self.intervals[1]);
        let (mut i, mut j) = (0, 0);
        // Two-pointer merge: each robot's intervals are disjoint and in time order, so the
        // intersections come out in time order and the first one found is the earliest.
        while i < a.len() && j < b.len() {
            let lo = a[i].start_s.max(b[j].start_s);
            let hi = a[i].end_s.min(b[j].end_s);
            if hi - lo > eps {
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
        }
    }

    #[test]
    fn timelines_clamp_into_the_bounds_and_name_a_wrong_length() {
        // 2.0 + 1e-12 is just above ψ̇max = 2: clamped, so the realtime crate accepts it.
        let mut s = schedule(1.0);
        s.grad_exec[0][0] = 2.0 + 1e-12;
        let [r1, r2] = s.timelines(&problem()).unwrap();
        assert_eq!((r1.start_s(), r2.start_s()), (0.0, 1.0));
        assert_eq!(r1.end_s(), 2.25);
        // A warp one sample short is an error, not a panic.
        s.grad_exec[1].pop();
        assert!(matches!(
            s.timelines(&problem()),
            Err(tandem_realtime::Error::LengthMismatch { .. })
        ));
    }

    #[test]
    fn t_total_by_hand() {
        // |ψ_E1| = 4.5·0.5 = 2.25 s, |ψ_E2| = 2.25 s.
        let s = schedule(1.0);
        assert_eq!(s.durations_s(0.5), [2.25, 2.25]);
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
        assert_eq!((b[0].ref_start, b[0].ref_end, b[0].robot), (1, 3, 1));
        let (x, y) = g.first_lc_overlap().unwrap();
        assert_eq!((x.robot, y.robot), (0, 1));
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
            Err(Error::LengthMismatch {
                name: "grad_exec[1]",
                len: 3,
                expected: 4
            })
        ));
        let mut s = schedule(0.0);
        s.grad_exec[0][2] = f64::NAN;
        assert!(matches!(
            GlobalTimeline::new(&problem(), &s),
            Err(Error::NonFinite {
                name: "grad_exec[0]",
                ref_idx: 2
            })
        ));
    }

    #[test]
    fn schedule_serde_round_trip() {
        let s = schedule(0.125);
        let back: Schedule = serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
        assert_eq!(back, s);
    }
}
