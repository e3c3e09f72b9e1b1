//! The constraints of Eq. 20, checked in the paper's order.

use tandem_realtime::tol;

use crate::problem::Problem;
use crate::schedule::{GlobalTimeline, Schedule};

/// The first constraint of Eq. 20 that a schedule breaks.
///
/// Robot indices: 0 = first robot (starts at 0), `i ≥ 1` starts at `τ_{i+1}` (for two robots
/// 1 = the second robot, starting at `τ`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Violation {
    /// The schedule has no robot or more than `MAX_ROBOTS` (`tandem_realtime::MAX_ROBOTS`):
    /// the one robot-count error, `tandem_realtime::Error::RobotCount`, with the number of
    /// warps in the schedule.
    #[error("the schedule's warps: {0}")]
    RobotCount(tandem_realtime::Error),
    /// The schedule does not have one start offset per robot after the first.
    #[error(
        "the schedule has {found} start offsets, expected {expected} (one per robot after the first)"
    )]
    OffsetCount {
        /// Number of offsets in the schedule.
        found: usize,
        /// `N − 1`.
        expected: usize,
    },
    /// The schedule has holds ([`Schedule::holds`]) but not one list per robot.
    #[error(
        "the schedule has hold lists for {found} robots, expected {expected} (one per robot, or none)"
    )]
    HoldCount {
        /// Number of hold lists.
        found: usize,
        /// `N`.
        expected: usize,
    },
    /// A hold of the schedule is not on an active hold of the problem, is next to a
    /// low-confidence sample, has a bad dwell or a release rule naming no valid robot or
    /// sample (the realtime crate's check, `tandem_realtime::holds::check_holds`).
    #[error("{source}")]
    Hold {
        /// What is wrong, naming the robot and the hold.
        source: tandem_realtime::Error,
    },
    /// A warp does not have one gradient per reference sample.
    #[error(
        "robot {robot}: execution warp has {len} gradients, the problem has {expected} reference samples"
    )]
    Length {
        /// Robot index.
        robot: usize,
        /// Number of gradients in the schedule.
        len: usize,
        /// `T_ref`.
        expected: usize,
    },
    /// Constraint 1: `ψ̇min[n] ≤ ψ̇_Ei[n] ≤ ψ̇max[n]` (also raised for a non-finite gradient).
    #[error(
        "robot {robot}, reference sample {ref_idx}: gradient {value} outside [{min}, {max}] (Eq. 20, constraint 1)"
    )]
    GradientOutOfBounds {
        /// Robot index.
        robot: usize,
        /// Reference sample.
        ref_idx: usize,
        /// Scheduled gradient (execution samples per reference sample).
        value: f64,
        /// `ψ̇min[n]`.
        min: f64,
        /// `ψ̇max[n]`.
        max: f64,
    },
    /// Constraint 2: `0 ≤ τ_i ≤ max_{j<i}(τ_j + |ψ_Ej|)` — for two robots `0 ≤ τ ≤ |ψ_E1|`
    /// (also raised for a non-finite offset).
    #[error(
        "robot {}: offset τ = {offset_s} s outside [0, {max_s} s] (the latest end of the robots before it; for two robots |ψ_E1|) (Eq. 20, constraint 2)",
        .robot + 1
    )]
    Offset {
        /// Robot index (≥ 1).
        robot: usize,
        /// The robot's offset `τ_i` (s).
        offset_s: f64,
        /// `max_{j<i}(τ_j + |ψ_Ej|)` (s; `|ψ_E1|` for two robots).
        max_s: f64,
    },
    /// Constraint 3: two robots are scheduled low-confidence at once (global time).
    #[error(
        "robots {} and {} both low-confidence from global time {start_s} s to {end_s} s (reference samples {:?} of robot {}, {:?} of robot {}) (Eq. 20, constraint 3)",
        .robots[0] + 1, .robots[1] + 1, .ref_ranges[0], .robots[0] + 1, .ref_ranges[1], .robots[1] + 1
    )]
    BothLowConfidence {
        /// The two robots (0-based, ascending).
        robots: [usize; 2],
        /// Global time (s) at which the overlap starts.
        start_s: f64,
        /// Global time (s) at which the overlap ends.
        end_s: f64,
        /// The overlapping low-confidence runs, as reference sample ranges `(start, end)` of
        /// the two robots, in the order of `robots`.
        ref_ranges: [(usize, usize); 2],
    },
    /// Constraint 4: a low-confidence sample does not follow the mean gradient.
    #[error(
        "robot {robot}, low-confidence reference sample {ref_idx}: gradient {value} is not the mean {mean} (Eq. 20, constraint 4)"
    )]
    NotMeanGradient {
        /// Robot index.
        robot: usize,
        /// Reference sample.
        ref_idx: usize,
        /// Scheduled gradient.
        value: f64,
        /// `ψ̇̄[n]`.
        mean: f64,
    },
    /// Constraint 5: `SUFFICIENT_MARGINS` (Alg. 2, the conservative single-pass check of
    /// `tandem_realtime::sufficient_margins`) rejects the schedule at this control tick.
    #[error(
        "insufficient margins between low-confidence regions at control tick {tick_s} s (Eq. 20, constraint 5)"
    )]
    InsufficientMargins {
        /// Control tick (s) the check ran with.
        tick_s: f64,
    },
    /// With the operator's switch time ([`validate_with_switch`]): one robot's scheduled
    /// low-confidence interval starts less than `switch_s` after another robot's ended
    /// (global time).
    #[error(
        "robot {} starts a low-confidence run at global time {start_s} s, only {} s after robot {} left its own at {end_s} s; the operator needs {switch_s} s to switch (schedule with a smaller switch time or later offsets)",
        .robots[1] + 1, .start_s - .end_s, .robots[0] + 1
    )]
    SwitchTooShort {
        /// The robot that left its interval, then the robot that enters its own (0-based).
        robots: [usize; 2],
        /// Global time (s) at which the first robot's interval ends.
        end_s: f64,
        /// Global time (s) at which the second robot's interval starts.
        start_s: f64,
        /// The switch time (s).
        switch_s: f64,
    },
    /// With the operator's switch time ([`validate_with_switch`]): the margin check accepts the
    /// schedule without a switch time but not with `switch_s`: some admissible operator can
    /// make one robot low-confidence within `switch_s` of another
    /// (`tandem_realtime::check_margins`).
    #[error(
        "insufficient margins for the operator's switch time of {switch_s} s at control tick {tick_s} s: an operator can make two robots need them within {switch_s} s (Eq. 20, constraint 5 with a switch time)"
    )]
    InsufficientSwitchTime {
        /// Control tick (s) the check ran with.
        tick_s: f64,
        /// The switch time (s).
        switch_s: f64,
    },
    /// The schedule's control tick ([`Schedule::tick_s`]) is not finite and > 0.
    #[error("control tick {tick_s} s must be finite and > 0")]
    InvalidTick {
        /// The tick (s).
        tick_s: f64,
    },
    /// A robot's plan cannot be laid out in schedule-clock time (e.g. its end overflows), so
    /// neither constraint 3 nor the margin check can be evaluated.
    #[error("robot {}: cannot lay out the schedule: {source}", .robot + 1)]
    Timeline {
        /// Robot index (0 = first robot).
        robot: usize,
        /// What the realtime crate rejected.
        source: tandem_realtime::Error,
    },
    /// Constraint 5 could not be evaluated: the margin check rejected its input (e.g. a tick
    /// so small that its simulation would need more than 1e8 ticks).
    #[error(
        "the margin check at control tick {tick_s} s cannot run: {source} (Eq. 20, constraint 5)"
    )]
    MarginCheck {
        /// Control tick (s) the check was asked to run with.
        tick_s: f64,
        /// What the realtime crate rejected.
        source: tandem_realtime::Error,
    },
}

/// Checks every constraint of Eq. 20 at the schedule's own control tick
/// ([`Schedule::tick_s`]) and names the first one broken, in this order: the tick (finite,
/// positive), the shape ([`Schedule::check_shape`]: `1 ≤ N ≤ MAX_ROBOTS` warps, `N − 1`
/// offsets), warp lengths, (1) gradient bounds (robot by robot, in reference order),
/// (2) offsets `0 ≤ τ_i ≤ max_{j<i}(τ_j + |ψ_Ej|)` (for two robots `0 ≤ τ ≤ |ψ_E1|`), the
/// layout of every robot in schedule-clock time, (3) no global time with two robots
/// low-confidence, (4) mean gradient on low-confidence samples, (5)
/// `tandem_realtime::sufficient_margins` for all `N` robots at the schedule's tick.
///
/// To re-check a schedule at another tick, set its `tick_s` first (the sampler does so for a
/// previous schedule handed to it at a new tick): a schedule is valid *at its tick*.
///
/// Gradient bounds, the mean and the offset bound are tested up to [`tol::GRADIENT_REL`];
/// overlaps shorter than [`tol::overlap_tolerance_s`]`(T_total)` are ignored (see
/// `tandem_realtime::tol` for the policy).
///
/// # Errors
/// The first [`Violation`] found: a broken constraint, or [`Violation::Timeline`] /
/// [`Violation::MarginCheck`] with the realtime crate's error when a check cannot run.
pub fn validate(problem: &Problem, schedule: &Schedule) -> Result<(), Violation> {
    validate_full(problem, schedule, MarginCheck::SinglePass)
}

/// [`validate`] with the operator's switch time `switch_s` (real s, ≥ 0; docs/decisions.md,
/// "The operator's switch time in the margin check (issue 41)"): after constraints 1–4,
/// (3δ) no robot's scheduled low-confidence interval starts less than `switch_s` after another
/// robot's ended (global time; consecutive intervals of one robot need no switch time; up to
/// `CLOCK_REL·switch_s` plus rounding, accepting), and (5δ) the margin check with the switch
/// time, `tandem_realtime::check_margins`, at the schedule's tick: no admissible operator can
/// make one robot low-confidence within `switch_ticks(switch_s, tick_s)` ticks of another. A
/// schedule that fails only (5δ) is [`Violation::InsufficientSwitchTime`]; one that fails the
/// check without the switch time too, [`Violation::InsufficientMargins`]. `switch_s = 0` is
/// [`validate`].
///
/// # Errors
/// As [`validate`], and [`Violation::SwitchTooShort`], [`Violation::InsufficientSwitchTime`];
/// [`Violation::MarginCheck`] for a `switch_s` not finite and ≥ 0.
pub fn validate_with_switch(
    problem: &Problem,
    schedule: &Schedule,
    switch_s: f64,
) -> Result<(), Violation> {
    validate_with_operator(problem, schedule, switch_s, 1.0)
}

/// [`validate_with_switch`] for an operator with switch time `switch_s` (s, ≥ 0) and load cap
/// `max_busy_share` (in `(0, 1]`): the same checks, with Eq. 20 constraint 2 relaxed by
/// [`crate::start_allowance_s`] — `τ_i ≤ max_{j<i}(τ_j + |ψ_Ej|) + A` — so that a robot may
/// start after every robot before it has ended, by the idle time the operator's switch and
/// busy share need (docs/decisions.md, "A schedule always exists with a switch time: constraint
/// 2 relaxed (issue 41)"). The busy share itself is not checked here
/// ([`crate::busy_share`]). `switch_s = 0` with `max_busy_share = 1` is [`validate`]; with
/// `max_busy_share < 1` and no switch time, constraint 2 is relaxed and the margin check is
/// [`validate`]'s.
///
/// # Errors
/// As [`validate_with_switch`] ([`Violation::Offset`] names the relaxed bound).
pub fn validate_with_operator(
    problem: &Problem,
    schedule: &Schedule,
    switch_s: f64,
    max_busy_share: f64,
) -> Result<(), Violation> {
    validated_timeline_with_operator(problem, schedule, switch_s, max_busy_share).map(drop)
}

/// [`validate_with_operator`]; on success, the schedule's global timeline (what
/// [`crate::CheckedSchedule`] keeps). `switch_s = 0` with `max_busy_share = 1` is
/// [`validated_timeline`] with the single-pass check, the same float operations.
pub(crate) fn validated_timeline_with_operator(
    problem: &Problem,
    schedule: &Schedule,
    switch_s: f64,
    max_busy_share: f64,
) -> Result<GlobalTimeline, Violation> {
    if switch_s == 0.0 && max_busy_share >= 1.0 {
        return validated_timeline(problem, schedule, MarginCheck::SinglePass);
    }
    let tick_s = schedule.tick_s;
    if !(tick_s.is_finite() && tick_s > 0.0) {
        return Err(Violation::InvalidTick { tick_s });
    }
    let params = tandem_realtime::MarginParams::new(tick_s).with_switch_s(switch_s);
    params
        .switch_ticks()
        .map_err(|source| Violation::MarginCheck { tick_s, source })?;
    let allowance_s = crate::operator::start_allowance_s(
        problem,
        schedule.n_robots(),
        tick_s,
        switch_s,
        max_busy_share,
    );
    if switch_s == 0.0 {
        return validated_timeline_with(problem, schedule, MarginCheck::SinglePass, allowance_s);
    }
    let timeline = validate_cheap_with(problem, schedule, allowance_s)?;
    if let Some(v) = first_short_switch(&timeline, switch_s) {
        return Err(v);
    }
    let robots = timeline.timelines();
    match tandem_realtime::check_margins(robots, &schedule.holds, &params) {
        Ok(true) => Ok(timeline),
        Ok(false) => {
            match validated_timeline_with(problem, schedule, MarginCheck::SinglePass, allowance_s) {
                Ok(_) => Err(Violation::InsufficientSwitchTime { tick_s, switch_s }),
                Err(v) => Err(v),
            }
        }
        Err(source) => Err(Violation::MarginCheck { tick_s, source }),
    }
}

/// Every robot's scheduled LC intervals as `(start_s, end_s, robot)` (global s), merged by
/// start (ties by robot): the one scan of the operator's stretches in time order, for the
/// switch check and the operator's busy share ([`crate::operator::busy_share`]).
pub(crate) fn lc_by_start(timeline: &GlobalTimeline) -> Vec<(f64, f64, usize)> {
    let mut all: Vec<(f64, f64, usize)> = timeline
        .lc_intervals()
        .iter()
        .enumerate()
        .flat_map(|(r, ivs)| ivs.iter().map(move |iv| (iv.start_s, iv.end_s, r)))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
    all
}

/// The first place (in time) where one robot's scheduled LC interval starts less than
/// `switch_s` after another robot's ended: the intervals of all robots merged by start
/// (disjoint, constraint 3), each next to the one before it when their robots differ. Pairs
/// further apart are implied: between an interval `A` and a later `B` of another robot, the
/// first interval of a robot other than `A`'s starts at least `switch_s` after the one before
/// it, which ends no earlier than `A`.
fn first_short_switch(timeline: &GlobalTimeline, switch_s: f64) -> Option<Violation> {
    let all = lc_by_start(timeline);
    let slack = tol::CLOCK_REL * switch_s + 4.0 * f64::EPSILON * timeline.t_total_s();
    all.windows(2).find_map(|w| {
        let ((_, end_s, a), (start_s, _, b)) = (w[0], w[1]);
        (a != b && start_s - end_s < switch_s - slack).then_some(Violation::SwitchTooShort {
            robots: [a, b],
            end_s,
            start_s,
            switch_s,
        })
    })
}

/// Every constraint of Eq. 20 (see [`validate`]) with margin-check implementation `check`.
pub(crate) fn validate_full(
    problem: &Problem,
    schedule: &Schedule,
    check: MarginCheck,
) -> Result<(), Violation> {
    validated_timeline(problem, schedule, check).map(drop)
}

/// Every constraint of Eq. 20 (see [`validate`]) with margin-check implementation `check`;
/// on success, the schedule's global timeline (what [`crate::CheckedSchedule`] keeps).
pub(crate) fn validated_timeline(
    problem: &Problem,
    schedule: &Schedule,
    check: MarginCheck,
) -> Result<GlobalTimeline, Violation> {
    validated_timeline_with(problem, schedule, check, 0.0)
}

/// [`validated_timeline`] with constraint 2 relaxed by `allowance_s` (s, ≥ 0; 0: as printed,
/// [`validate_cheap_with`]).
pub(crate) fn validated_timeline_with(
    problem: &Problem,
    schedule: &Schedule,
    check: MarginCheck,
    allowance_s: f64,
) -> Result<GlobalTimeline, Violation> {
    let tick_s = schedule.tick_s;
    if !(tick_s.is_finite() && tick_s > 0.0) {
        return Err(Violation::InvalidTick { tick_s });
    }
    let timeline = validate_cheap_with(problem, schedule, allowance_s)?;
    let robots = timeline.timelines();
    let decided = if schedule.has_holds() {
        // The lead bound on the robots' legs with their release rules (one implementation).
        tandem_realtime::sufficient_margins_with_holds(robots, &schedule.holds, tick_s)
    } else {
        match check {
            MarginCheck::SinglePass => tandem_realtime::sufficient_margins(robots, tick_s),
            MarginCheck::PerPair => tandem_realtime::sufficient_margins_per_pair(robots, tick_s),
        }
    };
    match decided {
        Ok(true) => Ok(timeline),
        Ok(false) => Err(Violation::InsufficientMargins { tick_s }),
        Err(source) => Err(Violation::MarginCheck { tick_s, source }),
    }
}

/// Which implementation of `SUFFICIENT_MARGINS` (Alg. 2) to run; both decide identically
/// (a benchmark-only choice, see `SamplerBaselines`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MarginCheck {
    /// `tandem_realtime::sufficient_margins`: for two robots two worst-case simulations
    /// decide every pair of consecutive low-confidence regions; for three or more the lead
    /// bound with sliding window extremes.
    #[default]
    SinglePass,
    /// `tandem_realtime::sufficient_margins_per_pair`, the same decisions computed the
    /// straightforward way: for two robots one simulation per pair of consecutive
    /// low-confidence regions (the plain reading of Alg. 2), for three or more the lead bound
    /// with every window scanned sample by sample. A speed baseline, as safe as `SinglePass`.
    PerPair,
}

/// Constraints 1–4 (everything but the margins), constraint 2 relaxed by `allowance_s` (s,
/// ≥ 0; 0: as printed): `τ_i ≤ max_{j<i}(τ_j + |ψ_Ej|) + allowance_s`
/// ([`crate::operator::start_allowance_s`]); on success, the schedule's global timeline (built
/// once, for the margin check to reuse).
pub(crate) fn validate_cheap_with(
    problem: &Problem,
    schedule: &Schedule,
    allowance_s: f64,
) -> Result<GlobalTimeline, Violation> {
    schedule.check_shape()?;
    let n_ref = problem.n_ref();
    for (robot, grad) in schedule.grad_exec.iter().enumerate() {
        if grad.len() != n_ref {
            return Err(Violation::Length {
                robot,
                len: grad.len(),
                expected: n_ref,
            });
        }
    }
    let (gmin, gmax, gmean) = (problem.grad_min(), problem.grad_max(), problem.grad_mean());
    for (robot, grad) in schedule.grad_exec.iter().enumerate() {
        for (ref_idx, &value) in grad.iter().enumerate() {
            let (min, max) = (gmin[ref_idx], gmax[ref_idx]);
            if !tol::within_bounds(value, min, max) {
                return Err(Violation::GradientOutOfBounds {
                    robot,
                    ref_idx,
                    value,
                    min,
                    max,
                });
            }
        }
    }
    let dt_s = problem.dt_s();
    let mut latest_end_s = schedule.end_s(0, dt_s);
    for (i, &offset_s) in schedule.offsets_s.iter().enumerate() {
        let robot = i + 1;
        // Without an allowance the bound is the latest end itself (no added operation).
        let max_s = if allowance_s > 0.0 {
            latest_end_s + allowance_s
        } else {
            latest_end_s
        };
        if !tol::within_bounds(offset_s, 0.0, max_s) {
            return Err(Violation::Offset {
                robot,
                offset_s,
                max_s,
            });
        }
        latest_end_s = latest_end_s.max(schedule.end_s(robot, dt_s));
    }
    let timeline = GlobalTimeline::of(problem, schedule)
        .map_err(|(robot, source)| Violation::Timeline { robot, source })?;
    check_holds(problem, schedule, &timeline)?;
    // With planned dwells the robots' later regions move: the timeline lays out their legs.
    if let Some(o) = timeline.first_lc_overlap() {
        let [a, b] = o.intervals;
        return Err(Violation::BothLowConfidence {
            robots: o.robots,
            start_s: o.start_s(),
            end_s: o.end_s(),
            ref_ranges: [(a.ref_start, a.ref_end), (b.ref_start, b.ref_end)],
        });
    }
    for (robot, grad) in schedule.grad_exec.iter().enumerate() {
        for (ref_idx, &value) in grad.iter().enumerate() {
            let mean = gmean[ref_idx];
            if !problem.conf()[ref_idx] && !tol::close_to(value, mean) {
                return Err(Violation::NotMeanGradient {
                    robot,
                    ref_idx,
                    value,
                    mean,
                });
            }
        }
    }
    Ok(timeline)
}

/// The schedule's holds: each robot's ([`tandem_realtime::holds::check_holds`]) on an active
/// hold of the problem ([`Problem::active_holds`]).
fn check_holds(
    problem: &Problem,
    schedule: &Schedule,
    timeline: &GlobalTimeline,
) -> Result<(), Violation> {
    let robots = timeline.timelines();
    for (robot, holds) in schedule.holds.iter().enumerate() {
        tandem_realtime::holds::check_holds(robot, holds, &robots[robot], robots.len(), |r| {
            robots[r].n_ref()
        })
        .map_err(|source| Violation::Hold { source })?;
        if let Some(h) = holds
            .iter()
            .find(|h| h.ref_idx > 0 && problem.holds().binary_search(&h.ref_idx).is_err())
        {
            return Err(Violation::Hold {
                source: tandem_realtime::Error::BadHold {
                    robot,
                    ref_idx: h.ref_idx,
                    why: "is not a hold point of the problem",
                },
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [HC, LC, LC, HC], gradients 1 in [0.5, 2], dt = 0.5 s.
    fn problem() -> Problem {
        crate::problem::hllh(0.5)
    }

    fn ok_schedule() -> Schedule {
        problem().serial_schedule(0.5).unwrap()
    }

    #[test]
    fn serial_schedule_is_valid() {
        assert_eq!(validate(&problem(), &ok_schedule()), Ok(()));
    }

    #[test]
    fn names_each_constraint() {
        let p = problem();
        let mut s = ok_schedule();
        s.grad_exec[1].push(1.0);
        assert_eq!(
            validate(&p, &s),
            Err(Violation::Length {
                robot: 1,
                len: 5,
                expected: 4
            })
        );

        let mut s = ok_schedule();
        s.grad_exec[1][3] = 2.5;
        assert!(matches!(
            validate(&p, &s),
            Err(Violation::GradientOutOfBounds {
                robot: 1,
                ref_idx: 3,
                ..
            })
        ));
        s.grad_exec[1][3] = f64::NAN;
        assert!(matches!(
            validate(&p, &s),
            Err(Violation::GradientOutOfBounds { robot: 1, .. })
        ));

        let mut s = ok_schedule();
        s.offsets_s[0] = -0.1;
        assert!(matches!(validate(&p, &s), Err(Violation::Offset { .. })));
        // |ψ_E1| = (0.5 + 1 + 1 + 0.5)·0.5 = 1.5 s.
        s.offsets_s[0] = 1.6;
        assert_eq!(
            validate(&p, &s),
            Err(Violation::Offset {
                robot: 1,
                offset_s: 1.6,
                max_s: 1.5
            })
        );

        // τ = 0: both robots reach the LC run at 0.25 s.
        let mut s = ok_schedule();
        s.offsets_s[0] = 0.0;
        let v = validate(&p, &s).unwrap_err();
        assert_eq!(
            v,
            Violation::BothLowConfidence {
                robots: [0, 1],
                start_s: 0.25,
                end_s: 1.25,
                ref_ranges: [(1, 3), (1, 3)]
            }
        );
        assert!(v.to_string().contains("(1, 3) of robot 1"), "{v}");

        let mut s = ok_schedule();
        s.grad_exec[0][2] = 1.5;
        assert_eq!(
            validate(&p, &s),
            Err(Violation::NotMeanGradient {
                robot: 0,
                ref_idx: 2,
                value: 1.5,
                mean: 1.0
            })
        );
        let mut s = ok_schedule();
        s.tick_s = 0.0;
        assert_eq!(
            validate(&p, &s),
            Err(Violation::InvalidTick { tick_s: 0.0 })
        );
    }

    #[test]
    fn names_the_shape_and_the_robot_of_n_robot_schedules() {
        let p = problem();
        // Serial, three robots: each starts when the one before ends (1.5 s each).
        let s = p.serial_schedule_n(3, 0.5).unwrap();
        assert_eq!(validate(&p, &s), Ok(()));
        let mut bad = s.clone();
        bad.offsets_s.pop();
        assert_eq!(
            validate(&p, &bad),
            Err(Violation::OffsetCount {
                found: 1,
                expected: 2
            })
        );
        let mut bad = s.clone();
        bad.grad_exec.clear();
        bad.offsets_s.clear();
        assert!(matches!(
            validate(&p, &bad),
            Err(Violation::RobotCount(tandem_realtime::Error::RobotCount {
                n: 0,
                ..
            }))
        ));
        let mut bad = s.clone();
        bad.grad_exec = vec![bad.grad_exec[0].clone(); 17];
        bad.offsets_s = vec![0.0; 16];
        assert!(matches!(
            validate(&p, &bad),
            Err(Violation::RobotCount(tandem_realtime::Error::RobotCount {
                n: 17,
                ..
            }))
        ));
        // Robot 3 may start no later than the latest end before it, 3 s (robot 2's end).
        let mut bad = s.clone();
        bad.offsets_s[1] = 3.25;
        assert_eq!(
            validate(&p, &bad),
            Err(Violation::Offset {
                robot: 2,
                offset_s: 3.25,
                max_s: 3.0
            })
        );
        bad.offsets_s[1] = f64::NAN;
        assert!(matches!(
            validate(&p, &bad),
            Err(Violation::Offset { robot: 2, .. })
        ));
        // Robot 3 at 1.5 s runs its LC stretch together with robot 2's: named by both robots.
        let mut bad = s.clone();
        bad.offsets_s[1] = 1.5;
        let v = validate(&p, &bad).unwrap_err();
        assert!(
            matches!(v, Violation::BothLowConfidence { robots: [1, 2], .. }),
            "{v}"
        );
        assert!(v.to_string().starts_with("robots 2 and 3 "), "{v}");
        // The layout errors of a wrong shape, from `timelines`, name it too.
        bad.offsets_s.pop();
        assert!(matches!(
            bad.timelines(&p),
            Err(crate::Error::Shape(Violation::OffsetCount { .. }))
        ));
    }

    #[test]
    fn tolerates_rounding_only() {
        let p = problem();
        let mut s = ok_schedule();
        s.grad_exec[0][0] = 0.5 * (1.0 - 1e-12);
        s.offsets_s[0] *= 1.0 + 1e-12;
        assert!(validate_cheap_with(&p, &s, 0.0).is_ok());
        s.grad_exec[0][0] = 0.5 * (1.0 - 1e-6);
        assert!(validate_cheap_with(&p, &s, 0.0).is_err());
    }
}
