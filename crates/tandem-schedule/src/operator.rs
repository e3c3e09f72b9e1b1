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
use crate::validate::{Violation, validate_with_operator, validate_with_switch};
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
    let lc_s = lc_time_s(problem);
    if lc_s <= 0.0 {
        return 0.0;
    }
    (n_robots as f64 * lc_s + (n_robots - 1) as f64 * switch_s) / max_busy_share
}

/// The operator's allowance on Eq. 20 constraint 2 (s, ≥ 0): how long after every robot before
/// it has ended a robot may start, `τ_i ≤ max_{j<i}(τ_j + |ψ_Ej|) + A`, for `n_robots` robots at
/// control tick `tick_s` (real s) with switch time `switch_s` (`δ`, s) and load cap
/// `max_busy_share` (`u_max`): `A = max(A_δ, A_u)` with
/// - `A_δ = δ + h + M̂` for `δ > 0` (0 without): the idle gap the margin check needs between a
///   robot that ends in its stretch and the next one that starts in its own, `k·h + M` with
///   `k = ⌈δ/h⌉ < δ/h + 1` whole ticks and `M ≤ M̂ = h·max(1, max_n ψ̇max[n]/ψ̇min[n])` the
///   earlier robot's largest step (its clock may overshoot its end by one step in its last
///   tick; `tandem_realtime::margins`, rule 2 with the idle ticks);
/// - `A_u = δ/u_max + N·L·(1/u_max − 1)/(N − 1)` for `u_max < 1` (0 without): the gap the
///   serial schedule needs to keep the cap, `((N·L + (N − 1)·δ)/u_max − N·D)/(N − 1)` with `D`
///   its robots' duration, at most this since `D ≥ L` (`L` the LC time of one execution).
///
/// So the serial schedule with idle gaps (`serial_with_switch`, `serial_capped`) always
/// meets the relaxed constraint; a longer gap only lengthens `T_total`. 0 (constraint 2 as
/// printed) for `δ = 0`, `u_max = 1` or one robot.
pub fn start_allowance_s(
    problem: &Problem,
    n_robots: usize,
    tick_s: f64,
    switch_s: f64,
    max_busy_share: f64,
) -> f64 {
    if n_robots < 2 {
        return 0.0;
    }
    let a_switch = if switch_s > 0.0 {
        let f_max = (0..problem.n_ref())
            .map(|n| problem.grad_max()[n] / problem.grad_min()[n])
            .fold(1.0, f64::max);
        switch_s + tick_s + tick_s * f_max
    } else {
        0.0
    };
    let a_cap = if max_busy_share < 1.0 {
        let n = n_robots as f64;
        switch_s / max_busy_share
            + n * lc_time_s(problem) * (1.0 / max_busy_share - 1.0) / (n - 1.0)
    } else {
        0.0
    };
    a_switch.max(a_cap)
}

/// `L`: the low-confidence time of one execution (s), `Σ ψ̇̄·Δt_s` over the LC samples
/// (Eq. 20 constraint 4 fixes it).
fn lc_time_s(problem: &Problem) -> f64 {
    let dt = problem.dt_s();
    (0..problem.n_ref())
        .filter(|&n| !problem.conf()[n])
        .map(|n| problem.grad_mean()[n] * dt)
        .sum()
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
/// `tick_s`, which always exists (docs/decisions.md, "A schedule always exists with a switch
/// time: constraint 2 relaxed (issue 41)"): the fastest serial schedule
/// ([`Problem::serial_schedule_n`]) if it passes [`validate_with_switch`]; else the faster of
/// two repairs that pass it — the same with every robot's high-confidence head and tail slowed
/// by one factor towards `ψ̇max` until they last `δ` on schedule (when only its planned
/// switches are too short), and the fastest warps with one common idle gap `g` between each
/// robot's end and the next robot's start, the least that passes found by bisection in
/// `[0, A_δ]` ([`start_allowance_s`]; at `A_δ` every pair is decided by the margin check's rule
/// 2 with at least `k` idle ticks, so it passes).
///
/// # Errors
/// [`Error::NoFeasibleSchedule`] with the fastest serial schedule's violation only when even
/// the widest gap fails (a bug: not expected); [`Error::BadParam`] for a bad `tick_s`.
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
    if n_robots < 2 {
        return Err(Error::NoFeasibleSchedule { serial: why });
    }
    let dt = problem.dt_s();
    let slowed = matches!(why, Violation::SwitchTooShort { .. })
        .then(|| slowed_ends(problem, n_robots, tick_s, switch_s))
        .flatten()
        .filter(|s| validate_with_switch(problem, s, switch_s).is_ok());
    let widest = start_allowance_s(problem, n_robots, tick_s, switch_s, 1.0);
    let gapped = least_gap(&fastest, widest, |s| {
        validate_with_switch(problem, s, switch_s).is_ok()
    });
    match (slowed, gapped) {
        (Some(a), Some(b)) => Ok(if b.t_total_s(dt) < a.t_total_s(dt) {
            b
        } else {
            a
        }),
        (a, b) => a.or(b).ok_or(Error::NoFeasibleSchedule { serial: why }),
    }
}

/// `serial` (robots one after another, each on the same warp) with one common idle gap `g`
/// (s) added before every robot's start after the first (robot `i` moved `i·g` later).
fn with_gap(serial: &Schedule, gap_s: f64) -> Schedule {
    let mut out = serial.clone();
    for (i, o) in out.offsets_s.iter_mut().enumerate() {
        *o += (i + 1) as f64 * gap_s;
    }
    out
}

/// The least common idle gap `g ∈ [0, widest_s]` (to `2⁻¹⁶` of `widest_s`, rounded up) with
/// which `serial` passes `ok` ([`with_gap`]), by bisection (the checks are monotone in `g`:
/// a longer gap only adds idle ticks and time between the planned stretches); `None` if even
/// `widest_s` fails.
fn least_gap(serial: &Schedule, widest_s: f64, ok: impl Fn(&Schedule) -> bool) -> Option<Schedule> {
    let mut hi = with_gap(serial, widest_s);
    if !ok(&hi) {
        return None;
    }
    let (mut lo_s, mut hi_s) = (0.0, widest_s);
    for _ in 0..16 {
        let mid_s = 0.5 * (lo_s + hi_s);
        let s = with_gap(serial, mid_s);
        if ok(&s) {
            (hi_s, hi) = (mid_s, s);
        } else {
            lo_s = mid_s;
        }
    }
    Some(hi)
}

/// The serial schedule with the switch time and the load cap `max_busy_share` (`u_max < 1`),
/// which always exists: [`serial_with_switch`] (the fastest serial schedule without a switch
/// time), and when its busy share exceeds the cap, its idle gaps lengthened by one common
/// amount so that `T_total` reaches `(busy + (N − 1)·δ)/u_max` (its stretches and switches
/// stay; `N − 1` gaps; within [`start_allowance_s`] since `D ≥ L`). `None` for one robot above
/// the cap (no gap to lengthen) or if the result fails [`validate_with_operator`] (a bug).
pub(crate) fn serial_capped(
    problem: &Problem,
    n_robots: usize,
    tick_s: f64,
    switch_s: f64,
    max_busy_share: f64,
) -> Option<Schedule> {
    let base = if switch_s > 0.0 {
        serial_with_switch(problem, n_robots, tick_s, switch_s).ok()?
    } else {
        problem.serial_schedule_n(n_robots, tick_s).ok()?
    };
    let timeline = GlobalTimeline::of(problem, &base).ok()?;
    let (busy_s, changes) = busy_of(&timeline);
    let t_total = timeline.t_total_s();
    let out = if share(busy_s, changes, switch_s, t_total) <= max_busy_share {
        base
    } else {
        if n_robots < 2 {
            return None;
        }
        let target_s = (busy_s + changes as f64 * switch_s) / max_busy_share;
        // A hair more than needed, so that the clock's sums reach the target despite rounding.
        let extra_s = (target_s - t_total) / (n_robots - 1) as f64 * (1.0 + 1e-9);
        with_gap(&base, extra_s)
    };
    let t = out.t_total_s(problem.dt_s());
    let tl = GlobalTimeline::of(problem, &out).ok()?;
    let (b, c) = busy_of(&tl);
    (share(b, c, switch_s, t) <= max_busy_share
        && validate_with_operator(problem, &out, switch_s, max_busy_share).is_ok())
    .then_some(out)
}

/// The serial schedule with every robot's high-confidence head and tail slowed by one common
/// factor `u` towards `ψ̇max` until together they last `δ` on schedule (the margin check's
/// worst case runs them at their fastest, so only the plan gets the room); `None` when there
/// is no such room (no head or tail, or not enough of it).
fn slowed_ends(problem: &Problem, n_robots: usize, tick_s: f64, switch_s: f64) -> Option<Schedule> {
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
        return None;
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
    Some(Schedule {
        grad_exec: vec![warp; n_robots],
        offsets_s,
        tick_s,
        holds: Vec::new(),
    })
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
    fn the_serial_fallback_keeps_any_switch_time_with_an_idle_gap() {
        let p = hlh();
        // δ = 0.6 s: tail + head at their fastest are 1 s, the serial schedule keeps it.
        let s = serial_with_switch(&p, 2, 0.01, 0.6).unwrap();
        assert_eq!(s, p.serial_schedule_n(2, 0.01).unwrap());
        // δ = 1.5 s (k = 150 ticks of 0.01 s; M = 0.02 s, the LC samples' F = 2): robot 1 ends
        // at least 48 ticks after its exit tick starts (1 + ⌊(0.5 − ε − M)/0.01⌋: a last step
        // of M, then its tail at F = 1), robot 2's head (0.5 s at 0.01 s a tick, less ε) keeps
        // it out 49 ticks, so robot 2 must start 102 ticks after the exit tick: 54 idle ticks,
        // ⌈(g − M)/h⌉ ≥ 54, g > 0.55 s. Slowing head and tail to 1.5 s instead would cost
        // 0.5 s per robot (T_total 7.5 s against 6 + 2·0.55).
        let s = serial_with_switch(&p, 3, 0.01, 1.5).unwrap();
        assert_eq!(validate_with_switch(&p, &s, 1.5), Ok(()));
        let gap = |s: &Schedule| s.offsets_s[0] - s.end_s(0, 0.1);
        assert!(gap(&s) > 0.55 && gap(&s) < 0.5501, "{}", gap(&s));
        assert!((s.offsets_s[1] - s.offsets_s[0] - 2.0 - gap(&s)).abs() < 1e-9);
        assert!((s.t_total_s(0.1) - 7.1).abs() < 1e-3);
        // A gap one step shorter fails: the bisection found the edge.
        assert!(
            validate_with_switch(
                &p,
                &with_gap(&p.serial_schedule_n(3, 0.01).unwrap(), 0.549),
                1.5
            )
            .is_err()
        );
        // δ = 5 s: more than the slowest tail and head (4 s) could give; the idle gap still
        // can (k = 500: 404 idle ticks, g > 4.05 s), within the allowance A_δ = 5 + 0.01 +
        // 0.04 s.
        let s = serial_with_switch(&p, 2, 0.01, 5.0).unwrap();
        assert!(gap(&s) > 4.05 && gap(&s) < 4.0501, "{}", gap(&s));
        assert!((start_allowance_s(&p, 2, 0.01, 5.0, 1.0) - 5.05).abs() < 1e-12);
        assert_eq!(validate_with_switch(&p, &s, 5.0), Ok(()));
        // Constraint 2 as printed refuses it; the allowance is what admits it.
        assert!(matches!(
            crate::validate(&p, &s),
            Err(Violation::Offset { robot: 1, .. })
        ));
    }

    #[test]
    fn the_cap_s_serial_schedule_idles_to_its_share() {
        let p = hlh();
        // Serial: 2 s per robot, 1 s LC each; at δ = 0 its share is 2/4. A cap of 0.25 needs
        // T_total 8 s: the one gap 4 s (beyond any tail), within A_u = 2·1·(4 − 1)/1 = 6 s.
        let s = serial_capped(&p, 2, 0.01, 0.0, 0.25).unwrap();
        assert!(
            (s.t_total_s(0.1) - 8.0).abs() < 1e-6,
            "{}",
            s.t_total_s(0.1)
        );
        assert!(busy_share(&s, &p, 0.0).unwrap() <= 0.25);
        assert!((start_allowance_s(&p, 2, 0.01, 0.0, 0.25) - 6.0).abs() < 1e-12);
        assert_eq!(validate_with_operator(&p, &s, 0.0, 0.25), Ok(()));
        assert!(validate_with_switch(&p, &s, 0.0).is_err());
        // With δ = 1.5 s and three robots: (3 + 2·1.5)/0.5 = 12 s at a cap of 0.5.
        let s = serial_capped(&p, 3, 0.01, 1.5, 0.5).unwrap();
        assert!(
            (s.t_total_s(0.1) - 12.0).abs() < 1e-6,
            "{}",
            s.t_total_s(0.1)
        );
        assert_eq!(validate_with_operator(&p, &s, 1.5, 0.5), Ok(()));
        // Under the cap already: the switch-time fallback itself.
        let s = serial_capped(&p, 2, 0.01, 0.0, 0.9).unwrap();
        assert_eq!(s, p.serial_schedule_n(2, 0.01).unwrap());
    }
}
