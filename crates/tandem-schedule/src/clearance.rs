//! Per-pair clearances for `N ≥ 3` robots with hold points: the margin-free optimum re-timed
//! until the margin check passes, each clearance raised only where the check fails
//! (docs/decisions.md, "Per-pair clearances for N ≥ 3 (issue 38)").
//!
//! The optimum packs low-confidence (LC) runs back to back, which the margin check rejects.
//! With its release rules (`Problem::with_release_rules`) every switch of robots waits at the
//! latest usable hold before the next robot's run until the other robot has left its run, and
//! those planned waits cost the whole way from the hold to the run at every switch (on random
//! three-robot problems with holds the optimum with its rules was 1.2–3.6× its bound).
//! Raising every clearance between consecutive runs of different robots by the same amount
//! (`choose::cleared_optimum`) pays the largest deficit at every switch, and on most such
//! problems no uniform clearance below the serial schedule passes at all. Here the optimum
//! *without* release rules is the start, and the check's own per-pair slacks
//! (`tandem_realtime::pair_slacks_with_holds`: for every region of robot `p` and every other
//! robot `c`, how much room `c`'s next region has to spare, negative when it lacks) say which
//! pairs lack room and by how much; only those pairs get a clearance (a difference constraint
//! of the re-timing network, [`retime_with_pairs`], whose gaps may dwell at any usable hold),
//! grown by their deficit plus a tenth of the check's maximal step `M` per iteration, until
//! every slack is positive, the re-timing is no longer below the cap, it has no solution, or
//! the budget of checks is spent. The check stays the only oracle: a candidate is returned
//! only when [`validate`] accepts it.

use std::collections::BTreeMap;

use tandem_realtime::{Timeline, pair_slacks, pair_slacks_with_holds};

use crate::choose::max_step_s;
use crate::problem::Problem;
use crate::retime::{PairClearance, retime_with_pairs, retime_with_set_pairs};
use crate::schedule::Schedule;
use crate::validate::validate_with_switch;

/// A pair of LC runs the check measured: `(robot, LC run)` before and after, its slack
/// (schedule-clock s, `> 0` when the pair has room) and its room on schedule (s: the later
/// run's start less the earlier run's end).
type Measured = ((usize, usize), (usize, usize), f64, f64);

/// A pair of LC runs of different robots: `(robot, LC run)` before and after.
type RunPair = ((usize, usize), (usize, usize));

/// Margin checks [`pair_cleared`] may spend on one re-schedule (each iteration costs one
/// measurement of every pair's slack; the final [`validate_with_switch`] one more).
pub(crate) const MAX_PAIR_CHECKS: usize = 12;

/// `optimum` (the margin-free optimum of `N ≥ 3` robots, its holds without release rules)
/// re-timed with per-pair clearances (see the module docs): the first re-timing that passes
/// [`validate_with_switch`] at the operator's switch time `switch_s` (s; the pairs' slacks are
/// measured without it, so with `switch_s > 0` a re-timing the final check refuses ends the
/// search, never a schedule that breaks it) with `T_total` below `cap_s` (s), and the margin
/// checks used (at most
/// `max_checks + 1`). `None` when a pair cannot be named by its runs, the re-timing has no
/// solution (the optimum interleaves robots between LC runs whose HC gaps have neither room
/// nor a usable hold), or no re-timing below `cap_s` passes within the budget.
pub(crate) fn pair_cleared(
    problem: &Problem,
    optimum: &Schedule,
    tick_s: f64,
    cap_s: f64,
    max_checks: usize,
    switch_s: f64,
) -> (Option<(Schedule, f64)>, usize) {
    let grow_s = max_step_s(problem, tick_s) / 10.0;
    let retime =
        |pairs: &[PairClearance]| retime_with_pairs(problem, optimum, tick_s, 0.0, pairs, true);
    retime_until_clear(
        problem,
        tick_s,
        cap_s,
        max_checks,
        switch_s,
        retime,
        |extra, measured| {
            let failing: Vec<&Measured> = measured.iter().filter(|m| m.2 <= 0.0).collect();
            if failing.is_empty() {
                return Next::Check;
            }
            if failing.iter().any(|m| !m.2.is_finite()) {
                return Next::Stop;
            }
            for &&(prev, cur, slack_s, _) in &failing {
                *extra.entry((prev, cur)).or_insert(0.0) += -slack_s + grow_s;
            }
            Next::Retime
        },
    )
}

/// Margin checks [`pair_traded`] may spend on one re-schedule (as [`MAX_PAIR_CHECKS`]).
pub(crate) const MAX_TRADE_CHECKS: usize = 12;

/// `optimum` (the margin-free optimum of two robots, its holds without release rules)
/// re-timed with every switch at the room the check asks, room traded between switches: each
/// iteration measures every pair's slack ([`measure`]) and sets the pair's clearance (the
/// later run's start less the earlier run's end, [`retime_with_set_pairs`]) to its room on
/// schedule less its slack plus a tenth of the check's maximal step `M` where the pair fails,
/// and to its room less half of its slack beyond `M/10` where it has more to spare, until
/// every slack is positive and [`validate_with_switch`] accepts the re-timing at the switch
/// time `switch_s` (s), the re-timing is no longer below `cap_s` (s) or has no solution, or
/// `max_checks` measurements are spent. Returns the re-timing with its `T_total` (s) and the
/// margin checks used (at most `max_checks + 1`).
///
/// Why beside [`pair_cleared`]: its clearances only grow from the optimum's, and the optimum
/// can keep more room at one switch than the check needs while a robot's HC gap without a
/// usable hold cannot absorb the room another switch lacks (two robots alternating two runs
/// each: `c₁ + c₂` must fit in one HC gap's slowing range, and the optimum gives `c₁` all of
/// it), so growing the failing switch's clearance has no solution; here the first switch gives
/// back what it does not need (docs/decisions.md, "Two robots with holds: clearances traded
/// between switches (issue 38)").
pub(crate) fn pair_traded(
    problem: &Problem,
    optimum: &Schedule,
    tick_s: f64,
    cap_s: f64,
    max_checks: usize,
    switch_s: f64,
) -> (Option<(Schedule, f64)>, usize) {
    let grow_s = max_step_s(problem, tick_s) / 10.0;
    let retime =
        |pairs: &[PairClearance]| retime_with_set_pairs(problem, optimum, tick_s, pairs, true);
    retime_until_clear(
        problem,
        tick_s,
        cap_s,
        max_checks,
        switch_s,
        retime,
        |clear, measured| {
            if measured.iter().all(|m| m.2 > 0.0) {
                return Next::Check;
            }
            if measured
                .iter()
                .any(|m| !m.2.is_finite() || !m.3.is_finite())
            {
                return Next::Stop;
            }
            for &(prev, cur, slack_s, room_s) in measured {
                let set_s = if slack_s <= 0.0 {
                    room_s - slack_s + grow_s
                } else if slack_s > grow_s {
                    room_s - 0.5 * (slack_s - grow_s)
                } else {
                    room_s
                };
                clear.insert((prev, cur), set_s.max(0.0));
            }
            Next::Retime
        },
    )
}

/// What [`retime_until_clear`] does after a measurement.
enum Next {
    /// Every measured pair has room: the final check decides.
    Check,
    /// Give up (a slack or room that is not finite).
    Stop,
    /// Re-time with the clearances as updated.
    Retime,
}

/// The loop [`pair_cleared`] and [`pair_traded`] share: re-time `optimum` with the per-pair
/// clearances of the map (`retime`: empty map first), stop when the re-timing has no solution
/// or is not below `cap_s` (s), measure every pair's slack ([`measure`]) and let `update`
/// decide: [`Next::Check`] runs [`validate_with_switch`] at `switch_s` (s) and returns the
/// re-timing with its `T_total` (s) if it passes (else nothing), [`Next::Retime`] goes round
/// again with the map `update` changed, [`Next::Stop`] gives up; at most `max_checks`
/// measurements. Returns the result and the margin checks used (at most `max_checks + 1`).
fn retime_until_clear(
    problem: &Problem,
    tick_s: f64,
    cap_s: f64,
    max_checks: usize,
    switch_s: f64,
    retime: impl Fn(&[PairClearance]) -> Option<Schedule>,
    mut update: impl FnMut(&mut BTreeMap<RunPair, f64>, &[Measured]) -> Next,
) -> (Option<(Schedule, f64)>, usize) {
    let dt_s = problem.dt_s();
    let lc_starts: Vec<usize> = problem
        .runs()
        .iter()
        .filter(|r| !r.high_conf)
        .map(|r| r.start)
        .collect();
    let mut clear: BTreeMap<RunPair, f64> = BTreeMap::new();
    let mut checks = 0;
    while checks < max_checks {
        let pairs: Vec<PairClearance> = clear
            .iter()
            .map(|(&(prev, cur), &extra_s)| PairClearance { prev, cur, extra_s })
            .collect();
        let Some(s) = retime(&pairs) else {
            break;
        };
        let t = s.t_total_s(dt_s);
        if t >= cap_s {
            break;
        }
        checks += 1;
        let Some(measured) = measure(problem, &s, tick_s, &lc_starts) else {
            break;
        };
        match update(&mut clear, &measured) {
            Next::Check => {
                checks += 1;
                if validate_with_switch(problem, &s, switch_s).is_ok() {
                    return (Some((s, t)), checks);
                }
                break;
            }
            Next::Stop => break,
            Next::Retime => {}
        }
    }
    (None, checks)
}

/// Every pair's slack of `schedule`'s margin check (with its holds when it has any), each
/// named by its robots and LC runs (indices into `lc_starts`, the problem's LC runs' first
/// samples); pairs with slack `+∞` (accepted outright, or ordered by a release rule) left out.
/// `None` when the check cannot run or a region is not one of the problem's LC runs.
fn measure(
    problem: &Problem,
    schedule: &Schedule,
    tick_s: f64,
    lc_starts: &[usize],
) -> Option<Vec<Measured>> {
    let tl = schedule.timelines(problem).ok()?;
    let run = |ref_start: usize| lc_starts.binary_search(&ref_start).ok();
    let slacks = if schedule.has_holds() {
        pair_slacks_with_holds(&tl, &schedule.holds, tick_s).ok()?
    } else {
        pair_slacks(&tl, tick_s).ok()?
    };
    // With holds the check reports regions on the robots' legs (a leg counts its samples from
    // its hold): each found back by robot and schedule-clock start.
    let mut run_of: BTreeMap<(usize, u64), usize> = BTreeMap::new();
    for (r, t) in tl.iter().enumerate() {
        for (ref0, leg) in legs_from(t, schedule.holds_of(r))? {
            for iv in leg.lc_intervals() {
                if let Some(k) = run(iv.ref_start + ref0) {
                    run_of.insert((r, iv.start_s.to_bits()), k);
                }
            }
        }
    }
    slacks
        .iter()
        .filter(|s| s.slack_s < f64::INFINITY)
        .map(|s| {
            let prev = *run_of.get(&(s.prev_robot, s.prev.start_s.to_bits()))?;
            let cur = *run_of.get(&(s.cur_robot, s.cur.start_s.to_bits()))?;
            Some((
                (s.prev_robot, prev),
                (s.cur_robot, cur),
                s.slack_s,
                s.cur.start_s - s.prev.end_s,
            ))
        })
        .collect()
}

/// The legs of `tl` split at `holds` (the whole timeline without holds), each with the
/// reference index of its first sample.
fn legs_from(tl: &Timeline, holds: &[tandem_realtime::Hold]) -> Option<Vec<(usize, Timeline)>> {
    let mut ref0 = 0;
    let mut out = Vec::new();
    for leg in tandem_realtime::holds::legs(tl, holds).ok()? {
        let n = leg.n_ref();
        out.push((ref0, leg));
        ref0 += n;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;
    use crate::choose::cleared_optimum;
    use crate::exact::{ExactParams, bound_many_switch};
    use crate::testkit::{hold_points, random_problem};
    use crate::validate::validate;

    /// Three robots on the test kit's random problem of seed 5 (300–600 samples of 10 ms,
    /// a hold in the middle of every HC run), tick 20 ms. Measured when the per-pair
    /// clearances were made: proven bound 5.158 s; the optimum with its release rules 8.433 s
    /// (their planned waits) and failing the check; the uniform ladder re-timing it finds
    /// nothing below the serial 9.259 s; the per-pair clearances pass at 6.266 s (+21.5 %)
    /// in 3 checks.
    #[test]
    fn per_pair_clearances_pass_where_no_uniform_clearance_does() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let p = random_problem(&mut rng, 300..=600, 0.01).unwrap();
        let p = p.clone().with_holds(hold_points(p.conf())).unwrap();
        let (n, tick_s) = (3, 0.02);
        let bound = bound_many_switch(&p, n, &ExactParams::default(), 0.0);
        assert!(bound.proven_optimal);
        let optimum = Schedule {
            tick_s,
            ..bound.schedule.unwrap()
        };
        let held = p.with_release_rules(&optimum).unwrap();
        assert!(validate(&p, &held).is_err());
        let serial_s = p.serial_schedule_n(n, tick_s).unwrap().t_total_s(p.dt_s());
        assert!((serial_s - 9.259).abs() < 1e-3, "{serial_s}");
        assert!(
            cleared_optimum(&p, &held, tick_s, serial_s, 0.0)
                .0
                .is_none()
        );
        let (found, checks) = pair_cleared(&p, &optimum, tick_s, serial_s, MAX_PAIR_CHECKS, 0.0);
        let (s, t) = found.unwrap();
        validate(&p, &s).unwrap();
        assert!(checks <= MAX_PAIR_CHECKS + 1);
        assert!(
            t < 1.25 * bound.lower_bound_s && t < held.t_total_s(p.dt_s()),
            "{t} against the bound {}",
            bound.lower_bound_s
        );
    }
}
