//! The operator in a rounds schedule (issue 41): the switch time `δ` of the serial fallback,
//! and the load cap `u_max` (docs/decisions.md, "Rounds schedules with the switch time and the
//! load cap (issue 41)").
//!
//! **The busy share** of a schedule ([`busy_share`]) is what the operator spends of one round:
//! the robots' scheduled low-confidence time plus `δ` for every change of robot between two
//! consecutive low-confidence intervals (the intervals of all robots merged in time), over the
//! round's `T_total`. The window is the round (its own `T_total`), not a rolling window: a
//! rounds cell starts a round only when the last one has ended, so the share of a shift is the
//! `T_total`-weighted mean of its rounds' shares, and a cap on every round caps the shift.
//!
//! **The cap in the schedule** ([`capped`]): a schedule whose share exceeds `u_max` lasts
//! longer, `T_total ≥ (busy + switches·δ)/u_max`, by running the high-confidence tail (the
//! samples after its last low-confidence one) of one robot slower, never faster than its
//! largest fast rate `F = ψ̇_E/ψ̇min` elsewhere: the margin check's step `M = tick·max F` of that
//! robot stays, its low-confidence intervals stay, and its end moves later, which only delays
//! the robots that start after it (docs/decisions.md). The result is checked again.
//!
//! **The bound with the cap** ([`cap_bound_s`]): every robot of a round has low-confidence
//! intervals of total length `L` (Eq. 20 constraint 4), so `busy ≥ N·L` and there are at least
//! `N − 1` changes of robot: `T_total ≥ (N·L + (N − 1)·δ)/u_max` for every schedule that keeps
//! the cap.

use crate::problem::Problem;
use crate::schedule::{GlobalTimeline, Schedule};
use crate::validate::{Violation, validate_with_switch};
use crate::{Error, Result};

/// The operator's busy share of one round (dimensionless): `(Σ_i Σ LC interval lengths +
/// c·switch_s)/T_total`, with `c` the number of changes of robot between consecutive
/// low-confidence intervals of all robots merged by start (global time, as
/// [`crate::validate_with_switch`] merges them), `switch_s` the switch time (s, ≥ 0) and
/// `T_total` (Eq. 13, dwells included). 0 for a schedule without low-confidence samples.
///
/// # Errors
/// [`Error::Shape`] or [`Error::Timeline`] when the schedule cannot be laid out on `problem`;
/// [`Error::BadParam`] for a `switch_s` not finite and ≥ 0.
pub fn busy_share(schedule: &Schedule, problem: &Problem, switch_s: f64) -> Result<f64> {
    if !(switch_s.is_finite() && switch_s >= 0.0) {
        return Err(Error::BadParam {
            name: "switch_s",
            why: "must be finite and >= 0 (the operator's switch time in seconds; 0 for none)",
        });
    }
    let timeline = GlobalTimeline::new(problem, schedule)?;
    let (busy_s, changes) = busy_of(&timeline);
    Ok(share(busy_s, changes, switch_s, timeline.t_total_s()))
}

/// `(busy + changes·switch_s)/t_total_s`; 0 without busy time.
fn share(busy_s: f64, changes: usize, switch_s: f64, t_total_s: f64) -> f64 {
    if busy_s <= 0.0 {
        return 0.0;
    }
    (busy_s + changes as f64 * switch_s) / t_total_s
}

/// The scheduled low-confidence time of all robots (s) and the number of changes of robot
/// between consecutive intervals merged by start.
fn busy_of(timeline: &GlobalTimeline) -> (f64, usize) {
    let all = crate::validate::lc_by_start(timeline);
    let busy_s = all.iter().map(|&(s, e, _)| e - s).sum();
    let changes = all.windows(2).filter(|w| w[0].2 != w[1].2).count();
    (busy_s, changes)
}

/// The lower bound (s) the load cap `max_busy_share` puts on the `T_total` of every schedule
/// of `n_robots` robots that keeps it with switch time `switch_s` (s): `(N·L + (N − 1)·δ)/u_max`
/// with `L` the low-confidence time of one execution (`Σ ψ̇̄·Δt_s` over the LC samples), 0
/// without LC samples. Why: see the module docs.
pub(crate) fn cap_bound_s(
    problem: &Problem,
    n_robots: usize,
    switch_s: f64,
    max_busy_share: f64,
) -> f64 {
    let dt = problem.dt_s();
    let lc_s: f64 = (0..problem.n_ref())
        .filter(|&n| !problem.conf()[n])
        .map(|n| problem.grad_mean()[n] * dt)
        .sum();
    if lc_s <= 0.0 {
        return 0.0;
    }
    (n_robots as f64 * lc_s + (n_robots - 1) as f64 * switch_s) / max_busy_share
}

/// `schedule` (valid at its tick with `switch_s`) made to keep the load cap `max_busy_share`
/// ([`busy_share`] ≤ `u_max`): itself when it does, else with one robot's high-confidence
/// tail slowed so that `T_total` reaches `(busy + c·δ)/u_max` (see the module docs), the
/// robots tried latest end first; `None` when no robot's tail can reach it or the slowed
/// schedule fails [`validate_with_switch`]. With its `T_total` (s).
pub(crate) fn capped(
    problem: &Problem,
    schedule: &Schedule,
    switch_s: f64,
    max_busy_share: f64,
) -> Option<(Schedule, f64)> {
    let dt = problem.dt_s();
    let timeline = GlobalTimeline::of(problem, schedule).ok()?;
    let (busy_s, changes) = busy_of(&timeline);
    let t_total = timeline.t_total_s();
    if share(busy_s, changes, switch_s, t_total) <= max_busy_share {
        return Some((schedule.clone(), t_total));
    }
    let target_s = (busy_s + changes as f64 * switch_s) / max_busy_share;
    let ends = schedule.ends_s(dt);
    let mut robots: Vec<usize> = (0..schedule.n_robots()).collect();
    robots.sort_by(|&a, &b| ends[b].total_cmp(&ends[a]).then(a.cmp(&b)));
    let last_lc = (0..problem.n_ref()).rev().find(|&n| !problem.conf()[n]);
    let tail = last_lc.map_or(0, |n| n + 1)..problem.n_ref();
    for r in robots {
        // With planned dwells after the last low-confidence sample the tail is not one leg.
        if schedule
            .holds_of(r)
            .iter()
            .any(|h| h.ref_idx >= tail.start && h.ref_idx > 0)
        {
            continue;
        }
        for keep_step in [true, false] {
            let Some(slowed) = slowed_tail(problem, schedule, r, tail.clone(), target_s, keep_step)
            else {
                continue;
            };
            let t = slowed.t_total_s(dt);
            if let Ok(tl) = GlobalTimeline::of(problem, &slowed) {
                let (b, c) = busy_of(&tl);
                if share(b, c, switch_s, t) <= max_busy_share
                    && validate_with_switch(problem, &slowed, switch_s).is_ok()
                {
                    return Some((slowed, t));
                }
            }
        }
    }
    None
}

/// `schedule` with robot `r`'s samples `tail` slowed (uniformly towards their limit: with
/// `keep_step` `min(ψ̇max, F_r·ψ̇min)`, `F_r` the robot's largest fast rate over its other
/// samples, so the margin check's step `M_r` stays; else `ψ̇max`) so that its end reaches
/// `target_s` (s, global); `None` when the limit does not reach it.
fn slowed_tail(
    problem: &Problem,
    schedule: &Schedule,
    r: usize,
    tail: std::ops::Range<usize>,
    target_s: f64,
    keep_step: bool,
) -> Option<Schedule> {
    let (gmin, gmax) = (problem.grad_min(), problem.grad_max());
    let dt = problem.dt_s();
    let warp = &schedule.grad_exec[r];
    let f_max = (0..problem.n_ref())
        .filter(|n| !tail.contains(n))
        .map(|n| warp[n] / gmin[n])
        .fold(1.0, f64::max);
    let limit = |n: usize| {
        if keep_step {
            gmax[n].min(f_max * gmin[n]).max(warp[n])
        } else {
            gmax[n]
        }
    };
    let room_s: f64 = tail.clone().map(|n| (limit(n) - warp[n]) * dt).sum();
    let need_s = target_s - schedule.end_s(r, dt);
    if need_s <= 0.0 || room_s < need_s {
        return None;
    }
    // A hair more than needed, so that the clock's sum reaches the target despite rounding.
    let u = (need_s / room_s * (1.0 + 1e-9)).min(1.0);
    let mut out = schedule.clone();
    for n in tail {
        out.grad_exec[r][n] = (warp[n] + u * (limit(n) - warp[n])).min(limit(n));
    }
    Some(out)
}

/// The serial fallback with the switch time `switch_s` (s, > 0) for `n_robots` robots at
/// `tick_s`: the fastest serial schedule ([`Problem::serial_schedule_n`]) if it passes
/// [`validate_with_switch`]; else, when only its planned switches are too short (its
/// high-confidence tail and head together last less than `δ`), the same with every robot's
/// tail and head slowed by one common factor `u` towards `ψ̇max` until they last `δ` (the
/// margin check's worst case runs them at their fastest, so only the plan needs the room).
///
/// # Errors
/// The first violation of the slowed serial schedule (or of the fastest one when slowing
/// cannot help: no high-confidence tail or head, or the margin check fails).
pub(crate) fn serial_with_switch(
    problem: &Problem,
    n_robots: usize,
    tick_s: f64,
    switch_s: f64,
) -> Result<Schedule> {
    let fastest = problem.serial_schedule_n(n_robots, tick_s)?;
    let why = match validate_with_switch(problem, &fastest, switch_s) {
        Ok(()) => return Ok(fastest),
        Err(v) => v,
    };
    if !matches!(why, Violation::SwitchTooShort { .. }) || n_robots < 2 {
        return Err(Error::NoFeasibleSchedule { serial: why });
    }
    let conf = problem.conf();
    let (gmin, gmax) = (problem.grad_min(), problem.grad_max());
    let dt = problem.dt_s();
    let n_ref = problem.n_ref();
    let first_lc = (0..n_ref).find(|&n| !conf[n]).unwrap_or(n_ref);
    let last_lc = (0..n_ref).rev().find(|&n| !conf[n]).map_or(0, |n| n + 1);
    let ends: Vec<usize> = (0..first_lc).chain(last_lc..n_ref).collect();
    let fastest_s: f64 = ends.iter().map(|&n| gmin[n] * dt).sum();
    let span_s: f64 = ends.iter().map(|&n| (gmax[n] - gmin[n]) * dt).sum();
    if span_s <= 0.0 || fastest_s + span_s < switch_s {
        return Err(Error::NoFeasibleSchedule { serial: why });
    }
    let u = ((switch_s - fastest_s) / span_s * (1.0 + 1e-9)).clamp(0.0, 1.0);
    let mut warp = problem.fastest_warp();
    for &n in &ends {
        warp[n] = (gmin[n] + u * (gmax[n] - gmin[n])).min(gmax[n]);
    }
    let mut offsets_s = Vec::with_capacity(n_robots - 1);
    let duration_s = warp.iter().sum::<f64>() * dt;
    let mut start_s = 0.0;
    for _ in 1..n_robots {
        start_s = tandem_realtime::clock_end_s(&warp, start_s, dt).max(start_s + duration_s);
        offsets_s.push(start_s);
    }
    let slowed = Schedule {
        grad_exec: vec![warp; n_robots],
        offsets_s,
        tick_s,
        holds: Vec::new(),
    };
    validate_with_switch(problem, &slowed, switch_s)
        .map(|()| slowed)
        .map_err(|serial| Error::NoFeasibleSchedule { serial })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [HC ×10, LC ×10, HC ×10] at 0.1 s, gradients 1 in [0.5, 2]: fastest HC runs 0.5 s,
    /// LC 1 s.
    fn hlh() -> Problem {
        let conf: Vec<bool> = (0..30).map(|n| !(10..20).contains(&n)).collect();
        crate::problem::unit_gradients(conf, (0.5, 2.0), 0.1)
    }

    #[test]
    fn busy_share_by_hand() {
        let p = hlh();
        // Serial: each robot 0.5 + 1 + 0.5 = 2 s; LC [0.5, 1.5) and [2.5, 3.5); one change.
        let s = p.serial_schedule_n(2, 0.1).unwrap();
        assert!((busy_share(&s, &p, 0.0).unwrap() - 2.0 / 4.0).abs() < 1e-12);
        assert!((busy_share(&s, &p, 1.0).unwrap() - 3.0 / 4.0).abs() < 1e-12);
        assert!(busy_share(&s, &p, -1.0).is_err());
        // Bound with the cap 0.5 at δ = 1 s: (2·1 + 1)/0.5 = 6 s.
        assert!((cap_bound_s(&p, 2, 1.0, 0.5) - 6.0).abs() < 1e-12);
    }

    #[test]
    fn the_cap_slows_a_tail_to_the_share() {
        let p = hlh();
        let s = p.serial_schedule_n(2, 0.1).unwrap();
        // Share 0.5 at δ = 0; a cap of 0.45 needs T_total = 2/0.45 = 4.444 s: robot 2's tail
        // (0.5 s at its fastest, F = 2 on its LC samples) may run at F·ψ̇min = 1 keeping its
        // step: 1 s, 0.5 s more, of which 0.444 s are needed.
        let (c, t) = capped(&p, &s, 0.0, 0.45).unwrap();
        assert!((t - 2.0 / 0.45).abs() < 1e-6, "{t}");
        assert!(busy_share(&c, &p, 0.0).unwrap() <= 0.45);
        assert_eq!(c.grad_exec[0], s.grad_exec[0]);
        assert_eq!(c.grad_exec[1][..20], s.grad_exec[1][..20]);
        assert!(c.grad_exec[1][20..].iter().all(|&g| g <= 1.0));
        // A cap of 0.4 needs 5 s: only at ψ̇max (2 s of tail), which the check accepts here.
        let (c, t) = capped(&p, &s, 0.0, 0.4).unwrap();
        assert!((t - 5.0).abs() < 1e-6, "{t}");
        assert!(c.grad_exec[1][20..].iter().all(|&g| g > 1.0 && g <= 2.0));
        // A cap of 0.3 needs 6.67 s: beyond the tail's 1.5 s of room.
        assert!(capped(&p, &s, 0.0, 0.3).is_none());
        // Under the cap: unchanged.
        assert_eq!(capped(&p, &s, 0.0, 0.51).unwrap().0, s);
    }

    #[test]
    fn the_serial_fallback_slows_head_and_tail_for_the_switch() {
        let p = hlh();
        // δ = 0.6 s: tail + head at their fastest are 1 s, the serial schedule keeps it.
        let s = serial_with_switch(&p, 2, 0.01, 0.6).unwrap();
        assert_eq!(s, p.serial_schedule_n(2, 0.01).unwrap());
        // δ = 1.5 s: tail + head (1 s at their fastest, 4 s at their slowest) slowed by
        // u = 0.5/3 to 1.5 s (gradients 0.5 + 1.5·u = 0.75); every robot the same warp.
        match serial_with_switch(&p, 3, 0.01, 1.5) {
            Ok(s) => {
                assert!((s.grad_exec[0][0] - 0.75).abs() < 1e-6);
                assert_eq!(validate_with_switch(&p, &s, 1.5), Ok(()));
            }
            // The worst case (tail and head run at their fastest) may still refuse it.
            Err(Error::NoFeasibleSchedule { serial }) => assert!(
                matches!(serial, Violation::InsufficientSwitchTime { .. }),
                "{serial}"
            ),
            Err(e) => panic!("{e}"),
        }
        // δ = 5 s: more than the slowest tail and head (4 s): no serial schedule.
        assert!(matches!(
            serial_with_switch(&p, 2, 0.01, 5.0),
            Err(Error::NoFeasibleSchedule { .. })
        ));
    }
}
