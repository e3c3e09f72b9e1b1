//! The room-aware candidate of `N ≥ 3` robots with a switch time, its rooms taken from what the
//! margin check asks (docs/decisions.md, "Three robots at δ ≥ 1 s: the room the check asks, per
//! stretch (issue 41)").

use tandem_realtime::{MarginParams, margin_slacks};

use super::{ROOM_NODES, settle_room_aware};
use crate::exact;
use crate::problem::Problem;
use crate::schedule::Schedule;

/// Bisection steps of [`room_from_slacks`] between the largest room tried that failed and the
/// least that passed.
pub(super) const ROOM_BISECTIONS: usize = 2;

/// The room-aware candidate with its extra rooms from the check. The room `e` (s) of
/// [`exact::room_aware_many`] (every switch into a stretch behind a high-confidence run
/// without a usable hold needs the robot's fastest arrival `δ + e` after the previous stretch
/// ends) is tried in increasing order over `0`, then the rooms the check asks, `m/4, m/2, m`
/// with `m` the largest room a stretch misses on the order of `e = 0` ([`missing_room`], its
/// dwelled form with release rules), and the ladder's `δ/2, δ, 2δ` ([`super::ROOM_STEPS`]),
/// rooms within a control tick `tick_s` (s) of a smaller one left out; each order is settled as
/// the ladder's ([`settle_room_aware`]: dwelled, release rules, checked with
/// [`crate::validate_with_switch`] at `switch_s`, re-timed with clearances if it fails, below
/// `cap_s`, s). The first room that passes, then [`ROOM_BISECTIONS`] bisections between it and
/// the room tried before it (a smaller room lets the search shorten the order); the shortest
/// schedule that passed, with its `T_total`. Counts the margin checks in `checks`.
///
/// Why (docs/decisions.md, "Three robots at δ ≥ 1 s: the room the check asks (issue 41)"):
/// the room the lead bound asks of such a switch is the approach at its fastest rates
/// (`M_c + (k − 1)·M_c'`), which scales with the approach's length and planned rate, not with
/// `δ`; rungs in multiples of `δ` are too coarse at large `δ` and too small at small `δ`.
/// Nothing is trusted: every schedule returned passed the unchanged check, and the arcs only
/// restrict the candidate's search, never the certificate's bound.
pub(super) fn room_from_slacks(
    problem: &Problem,
    n_robots: usize,
    tick_s: f64,
    cap_s: f64,
    switch_s: f64,
    checks: &mut usize,
) -> Option<(Schedule, f64)> {
    let order_at =
        |e: f64| exact::room_aware_many(problem, n_robots, switch_s, e, cap_s, ROOM_NODES, tick_s);
    let first = order_at(0.0)?;
    let mut best: Option<(Schedule, f64)> = None;
    let mut missing_s = None;
    match settle_room_aware(problem, first.clone(), tick_s, cap_s, switch_s, checks) {
        Some(found) => return Some(found),
        None => {
            let dwelled = if problem.usable_holds().is_empty() {
                first
            } else {
                exact::dwelled(problem, &first, tick_s).unwrap_or(first)
            };
            if let Ok(held) = problem.with_release_rules(&dwelled)
                && let Some(raises) = missing_room(problem, &held, switch_s)
            {
                missing_s = raises.iter().map(|&(_, m)| m).reduce(f64::max);
            }
        }
    }
    let mut rooms: Vec<f64> = super::ROOM_STEPS[1..]
        .iter()
        .map(|c| c * switch_s)
        .collect();
    if let Some(m) = missing_s {
        rooms.extend([m / 4.0, m / 2.0, m]);
    }
    rooms.sort_by(f64::total_cmp);
    rooms.dedup_by(|b, a| *b - *a < tick_s);
    let mut failed_s = 0.0;
    for e in rooms {
        if let Some(found) =
            order_at(e).and_then(|o| settle_room_aware(problem, o, tick_s, cap_s, switch_s, checks))
        {
            best = Some(found);
            let mut passed_s = e;
            for _ in 0..ROOM_BISECTIONS {
                let mid = 0.5 * (failed_s + passed_s);
                if passed_s - mid < tick_s {
                    break;
                }
                let cap = best.as_ref().map_or(cap_s, |b| b.1);
                match order_at(mid)
                    .and_then(|o| settle_room_aware(problem, o, tick_s, cap, switch_s, checks))
                {
                    Some(found) => {
                        best = Some(found);
                        passed_s = mid;
                    }
                    None => failed_s = mid,
                }
            }
            break;
        }
        failed_s = e;
    }
    best
}

/// The room (schedule-clock s, > 0) each failing stretch of `schedule` misses under the margin
/// check with the switch time `switch_s` (s): per pair `(p, c)` with a negative finite slack,
/// `(k, −slack)` with `k` the index of `c`'s stretch among its low-confidence runs (the chain's
/// run `k`: the problem's runs, all robots the same); the largest per `k`, by `k`. `None` when
/// the check cannot run or a stretch cannot be told.
pub(super) fn missing_room(
    problem: &Problem,
    schedule: &Schedule,
    switch_s: f64,
) -> Option<Vec<(usize, f64)>> {
    let timelines = schedule.timelines(problem).ok()?;
    let legs = schedule.legs(problem).ok()?;
    let params = MarginParams::new(schedule.tick_s).with_switch_s(switch_s);
    let slacks = margin_slacks(&timelines, &schedule.holds, &params).ok()?;
    let mut out: Vec<(usize, f64)> = Vec::new();
    for s in slacks {
        if !(s.slack_s < 0.0 && s.slack_s.is_finite()) {
            continue;
        }
        // The robot's stretches in order over its legs (holds lie in high-confidence runs, so
        // no stretch is split); `c`'s region is the one whose start is nearest.
        let starts: Vec<f64> = legs
            .get(s.cur_robot)?
            .iter()
            .flat_map(|leg| leg.lc_intervals().iter().map(|i| i.start_s))
            .collect();
        let k = starts
            .iter()
            .enumerate()
            .min_by(|a, b| {
                (a.1 - s.cur.start_s)
                    .abs()
                    .total_cmp(&(b.1 - s.cur.start_s).abs())
            })?
            .0;
        match out.iter_mut().find(|(j, _)| *j == k) {
            Some((_, m)) => *m = m.max(-s.slack_s),
            None => out.push((k, -s.slack_s)),
        }
    }
    out.sort_by_key(|&(k, _)| k);
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::super::ROOM_STEPS;
    use super::*;
    use crate::validate::validate_with_switch;

    /// `[LC ×10, HC ×40, LC ×10, HC ×80, LC ×10]` at 0.1 s, gradients 1 in `[0.5, 2]`, one
    /// usable hold at sample 30.
    fn shape() -> Problem {
        let lc = || std::iter::repeat_n(false, 10);
        let conf: Vec<bool> = lc()
            .chain(std::iter::repeat_n(true, 40))
            .chain(lc())
            .chain(std::iter::repeat_n(true, 80))
            .chain(lc())
            .collect();
        let n = conf.len();
        Problem::new(conf, vec![1.0; n], vec![0.5; n], vec![2.0; n], 0.1)
            .unwrap()
            .with_holds(vec![30])
            .unwrap()
    }

    /// At `δ = 0.1` s the room the lead bound asks before the last stretch (about 1 s, the
    /// approach at its fastest rates) is more than the ladder's largest, `2δ`: every rung's
    /// order fails the check and its clearances find nothing below serial; the rooms from the
    /// check pass below serial.
    #[test]
    fn the_room_the_check_asks_where_the_ladder_fails() {
        let p = shape();
        let (tick, sw) = (p.dt_s(), 0.1);
        let serial = crate::operator::serial_with_switch(&p, 3, tick, sw).unwrap();
        let cap = serial.t_total_s(p.dt_s());
        // Three fastest executions of 9 s (3 s of stretches, 12 s of HC at ψ̇ = 2) and 0.4 s
        // for the two switches.
        assert!((cap - 27.4).abs() < 1e-3, "{cap}");
        for c in ROOM_STEPS {
            let mut checks = 0;
            let settled = exact::room_aware_many(&p, 3, sw, c * sw, cap, ROOM_NODES, tick)
                .and_then(|o| settle_room_aware(&p, o, tick, cap, sw, &mut checks));
            assert!(settled.is_none(), "rung {c}: {:?}", settled.map(|s| s.1));
        }
        let mut checks = 0;
        let (s, t) = room_from_slacks(&p, 3, tick, cap, sw, &mut checks).expect("a schedule");
        validate_with_switch(&p, &s, sw).unwrap();
        assert!(s.has_holds());
        assert!(t < cap - 1.0, "T_total {t} s against serial {cap} s");
        assert!((t - s.t_total_s(p.dt_s())).abs() < 1e-12);
        // The first order's dwelled form misses more than 2δ before a stretch.
        let first = exact::room_aware_many(&p, 3, sw, 0.0, cap, ROOM_NODES, tick).unwrap();
        let held = p
            .with_release_rules(&exact::dwelled(&p, &first, tick).unwrap())
            .unwrap();
        let missing = missing_room(&p, &held, sw).unwrap();
        let m = missing.iter().map(|x| x.1).fold(0.0, f64::max);
        assert!(m > 2.0 * sw, "{missing:?}");
    }
}
