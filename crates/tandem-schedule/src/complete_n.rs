//! The margin-aware completion for `N ≥ 3` robots: the margin-free optimum's order of
//! low-confidence (LC) runs, re-timed with the runs the margin check finds too close held
//! back by what the check says they lack.
//!
//! The `N`-robot search (`exact::bound_many`) returns the best order of LC runs it found and
//! its earliest times: LC runs packed back to back, which the worst-case margin check
//! (constraint 5) rejects. The two-robot completion (`exact/complete.rs`) raises per-pair
//! clearances inside its dynamic program; for `N` robots there is no such program, but the
//! re-timing of a schedule ([`crate::retime::retime_delayed`]) solves the network this needs:
//! the order and clearances kept, the chain's gap ranges, chosen runs (and starts) held back
//! by a delay, the earliest solution. The check is the only oracle:
//! 1. **Raise.** Re-time with the delays (first none), validate; if it fails, read every
//!    pair's slack (`tandem_realtime::pair_slacks`, the same lead bound as the check) and hold
//!    back the current robot's run of each failing pair to where it is now plus its deficit
//!    and a tenth of `M` (the check's maximal step in one tick; a robot's first run holds
//!    back its start too). Until a re-timing passes, its `T_total` reaches the cap, or the
//!    budget ends. Delays only grow, and the network's earliest solution is monotone in them.
//! 2. **Lower.** Every failing pair was raised by its whole deficit, and a raised run delays
//!    the runs after it: the passing delays overshoot. Bisect between the last failing delays
//!    and the passing ones, to a tick, within the budget.
//!
//! Every candidate is validated before it is returned; nothing here is tuned to a task.
//! (docs/decisions.md, "An N-robot margin-aware completion".)

use crate::choose::max_step_s;
use crate::problem::Problem;
use crate::retime::retime_delayed;
use crate::schedule::Schedule;
use crate::validate::validate;

/// Per robot: how much later than in the optimum its start (entry 0) and each of its LC runs
/// (entry `1 + k`) start at the earliest (s); see [`retime_delayed`].
type Delays = Vec<Vec<f64>>;

/// Full checks one completion may use in all.
pub(crate) const MAX_COMPLETION_CHECKS: usize = 16;

/// The completion (see the module docs) of `optimum`, a margin-free schedule of `N ≥ 3`
/// robots without planned dwells on `problem` (the `N`-robot search's best order), at control
/// tick `tick_s` (s): the first re-timing that passes [`crate::validate`], if its `T_total`
/// (s) is below `cap_s` (s), with that `T_total` and the full checks used (at most
/// [`MAX_COMPLETION_CHECKS`]). `None` for an optimum with dwells (the `Held` candidate's).
pub(crate) fn complete(
    problem: &Problem,
    optimum: &Schedule,
    tick_s: f64,
    cap_s: f64,
) -> (Option<(Schedule, f64)>, usize) {
    let n = optimum.n_robots();
    if optimum.has_holds() || n < 3 {
        return (None, 0);
    }
    let dt_s = problem.dt_s();
    let step_s = max_step_s(problem, tick_s);
    let Ok(old) = optimum.timelines(problem) else {
        return (None, 0);
    };
    let m = old[0].lc_intervals().len();
    let mut delays = vec![vec![0.0; m + 1]; n];
    let mut checks = 0;
    // The delays of the last failing re-timing, and the first passing one with its delays.
    let mut failed = delays.clone();
    let mut passed: Option<(Delays, (Schedule, f64))> = None;
    while checks < MAX_COMPLETION_CHECKS {
        let Some(s) = retime_delayed(problem, optimum, tick_s, 0.0, &delays) else {
            break;
        };
        let t = s.t_total_s(dt_s);
        if t >= cap_s {
            break;
        }
        checks += 1;
        if validate(problem, &s).is_ok() {
            passed = Some((delays, (s, t)));
            break;
        }
        let Ok(now) = s.timelines(problem) else {
            break;
        };
        let Ok(slacks) = tandem_realtime::pair_slacks(&now, tick_s) else {
            break;
        };
        let mut raised = false;
        failed = delays.clone();
        for pair in slacks
            .iter()
            .filter(|p| p.slack_s <= 0.0 || p.slack_s.is_nan())
        {
            let c = pair.cur_robot;
            let Some(k) = now[c]
                .lc_intervals()
                .iter()
                .position(|iv| iv.ref_start == pair.cur.ref_start)
            else {
                continue;
            };
            let deficit_s = if pair.slack_s.is_finite() {
                -pair.slack_s + 0.1 * step_s
            } else {
                8.0 * step_s
            };
            let late_s = pair.cur.start_s - old[c].lc_intervals()[k].start_s;
            let want = late_s.max(0.0) + deficit_s;
            if want > delays[c][1 + k] {
                delays[c][1 + k] = want;
                raised = true;
            }
            if k == 0 && c > 0 {
                let start_late_s = now[c].start_s() - old[c].start_s();
                delays[c][0] = delays[c][0].max(start_late_s.max(0.0) + deficit_s);
            }
        }
        if !raised {
            break;
        }
    }
    let Some((mut hi, mut best)) = passed else {
        return (None, checks);
    };
    // Every failing pair was raised by its whole deficit, and raising one run delays the runs
    // after it too: the passing delays overshoot. Bisect between the last failing delays and
    // them, within the budget.
    let mut lo = failed;
    while checks < MAX_COMPLETION_CHECKS {
        let spread_s = lo
            .iter()
            .flatten()
            .zip(hi.iter().flatten())
            .map(|(x, y)| y - x)
            .fold(0.0, f64::max);
        if spread_s <= tick_s {
            break;
        }
        let mid: Delays = lo
            .iter()
            .zip(&hi)
            .map(|(a, b)| a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect())
            .collect();
        let Some(s) = retime_delayed(problem, optimum, tick_s, 0.0, &mid) else {
            break;
        };
        let t = s.t_total_s(dt_s);
        checks += 1;
        if t < best.1 && validate(problem, &s).is_ok() {
            best = (s, t);
            hi = mid;
        } else {
            lo = mid;
        }
    }
    (Some(best), checks)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact;

    // `pegs`: the peg-in-hole problem the integration tests with hold points share.
    include!("../tests/common/pegs.rs");

    #[test]
    fn three_robots_complete_the_margin_free_optimum() {
        // Two 2 s inserts (bounds [0.7, 1.4] of the mean), 20 s in all at 20 Hz; tick 50 ms.
        let p = pegs(false);
        let tick_s = 0.05;
        let serial_s = p.serial_schedule_n(3, tick_s).unwrap().t_total_s(p.dt_s());
        let bound = exact::bound_many(&p, 3, &Default::default());
        let optimum = bound.schedule.as_ref().unwrap();
        // The optimum runs the inserts in the order 1 2 3 1 2 3, back to back: the check
        // rejects it.
        assert_eq!(bound.order, [0, 1, 2, 0, 1, 2]);
        let packed = Schedule {
            tick_s,
            ..optimum.clone()
        };
        assert!(validate(&p, &packed).is_err());
        let (found, checks) = complete(&p, optimum, tick_s, serial_s);
        let (s, t) = found.expect("a passing re-timing below serial");
        assert!(checks <= MAX_COMPLETION_CHECKS);
        validate(&p, &s).unwrap();
        assert_eq!((t, s.tick_s), (s.t_total_s(p.dt_s()), tick_s));
        // The order is kept: robots 2 and 3 start after robot 1 (0 s), in turn.
        assert!(0.0 < s.offsets_s[0] && s.offsets_s[0] < s.offsets_s[1]);
        // Above the margin-free bound, far below serial (50.64 s). (On this task the staggered schedule,
        // 22.485 s, is shorter: the completion raises every failing pair by its whole
        // deficit, 28.27 s in 11 checks.)
        assert!(t >= bound.lower_bound_s * (1.0 - 1e-9));
        assert!(t < 0.6 * serial_s, "{t} vs serial {serial_s}");
        // A cap below the bound: no re-timing beats it, and no check is spent.
        let below = bound.lower_bound_s * (1.0 - 1e-6);
        assert_eq!(complete(&p, optimum, tick_s, below), (None, 0));
        // An optimum with planned dwells is the `Held` candidate's, not the completion's.
        let held = exact::bound_many(&pegs(true), 3, &Default::default());
        if let Some(o) = held.schedule.as_ref().filter(|o| o.has_holds()) {
            assert_eq!(complete(&pegs(true), o, tick_s, serial_s), (None, 0));
        }
    }
}
