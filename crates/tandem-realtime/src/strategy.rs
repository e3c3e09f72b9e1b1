//! The real-time timing strategy of §II-B5: the response of Eq. 18, `HIGH-CONF` (Alg. 1), and
//! their N-robot form `advance`, which the [`Coordinator`](crate::Coordinator) runs and the
//! margin check simulates (one owner of the rules).
//!
//! All quantities are schedule-clock seconds (the global time at which the schedule planned a
//! robot's current reference position). A robot's step `δt` is how far its schedule clock
//! advances during one control tick of `tick_s` real seconds; a rate `r` gives `δt = r·tick_s`.
//!
//! # N robots
//! `advance` moves every robot's schedule clock by one tick (the argument that these rules
//! are Eq. 17–18 and Alg. 1 when `N = 2` is in docs/decisions.md, "N robots at run time"):
//!
//! 1. **The pace.** If a robot is low-confidence (LC) its new clock is set by the operator (the
//!    caller computes it); it sets the *pace* `x`. With no LC robot and at least two running
//!    high-confidence (HC) robots, `HIGH-CONF` for N: the leader `a` is the robot furthest ahead
//!    (the first in slice order on a tie), `b` the other robot that can reach least far this
//!    tick (smallest `s_j + F_j·tick`, the first on a tie); `(δt_a, δt_b)` is Alg. 1 for
//!    `(a, b)`, and the pace is `x = min(s_a + δt_a, s_b + δt_b)`, the furthest clock that every
//!    running robot can reach. A robot running alone and HC runs on schedule (`δt = tick`).
//! 2. **Responses.** Every other running HC robot responds to the pace with Eq. 18 (its lead
//!    `s_i − x` measured after the pace's step): it lands on `x` when it can, else goes as
//!    slowly or as fast as it can towards it.
//! 3. **Start shift.** A robot not yet started has its clock moved to the new clock of the
//!    running robot furthest behind (the caller caps it at its start `τ_i` and at the earliest
//!    start of the robots waiting, `first_waiting_start`): it starts once every running robot
//!    has reached its start and every robot due before it has started, so its start shifts by
//!    the deviation of the slowest one; with nobody running its clock runs on schedule.
//! 4. **Finished** robots do not move and set nothing.

use crate::timeline::Rates;

/// Eq. 18, `δt_resp(ΔT, ·)`: the step (schedule-clock s) of a responding robot whose lead over
/// the other robot, measured *after* the other robot's step, is `lead_s = s_self − s_other`.
///
/// - `−ΔT < S·tick`: even the slowest step keeps it level or ahead → go slowest, `S·tick`;
/// - `S·tick ≤ −ΔT < F·tick`: match the other robot exactly, `−ΔT`;
/// - otherwise it cannot catch up → go fastest, `F·tick`.
pub fn response_step(lead_s: f64, rates: Rates, tick_s: f64) -> f64 {
    let slow = rates.slow * tick_s;
    let fast = rates.fast * tick_s;
    let gap = -lead_s;
    if gap < slow {
        slow
    } else if gap < fast {
        gap
    } else {
        fast
    }
}

/// Alg. 1, `HIGH-CONF`: steps `(δt_a, δt_b)` (schedule-clock s) of two high-confidence robots,
/// `a` ahead and `b` behind with `lead_s = s_a − s_b ≥ 0` (either may be `a` when level).
///
/// If the behind robot can reach the ahead robot's fastest step (`F_b·tick ≥ F_a·tick + ΔT`),
/// `a` goes fastest and `b` lands level with it. Otherwise `b` goes at its *own* fastest rate
/// (line 9 prints `ψ̇^F_{i_a}(t_b)`, read as `b`'s own `F`: docs/decisions.md, "Typos of
/// Eq. 17 and Alg. 1") and `a` responds with Eq. 18 to the lead left after `b`'s step.
pub fn high_conf_steps(lead_s: f64, rates_a: Rates, rates_b: Rates, tick_s: f64) -> (f64, f64) {
    let fast_a = rates_a.fast * tick_s;
    let fast_b = rates_b.fast * tick_s;
    if fast_b >= fast_a + lead_s {
        (fast_a, fast_a + lead_s)
    } else {
        let step_b = fast_b;
        (response_step(lead_s - step_b, rates_a, tick_s), step_b)
    }
}

/// What one robot does in a tick, as [`advance`] sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Mode {
    /// Not started: its clock follows the pace.
    Waiting,
    /// Running and high-confidence: responds to the pace.
    High,
    /// Running and low-confidence: its new clock is set by the operator (filled in by the
    /// caller).
    Low,
    /// Finished: does not move.
    Finished,
}

/// One robot at the start of a tick: its schedule clock (s), mode and Eq. 17 rates (read at its
/// current sample; ignored unless it is running).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Member {
    /// Schedule clock `s_i` (s).
    pub(crate) clock_s: f64,
    /// What it does this tick.
    pub(crate) mode: Mode,
    /// `F`, `S` at its sample.
    pub(crate) rates: Rates,
}

impl Member {
    /// A robot that is not running (its rates are never read).
    pub(crate) const fn idle(clock_s: f64, mode: Mode) -> Self {
        Member {
            clock_s,
            mode,
            rates: Rates {
                fast: 1.0,
                slow: 1.0,
            },
        }
    }
}

/// One tick of the N-robot strategy (the [module docs](self)): writes each robot's new,
/// uncapped schedule clock into `next_s` and returns the clock that robots not yet started
/// follow — the smallest new clock of a running robot (s) — or `None` when no robot waits or
/// none runs.
///
/// `next_s[i]` must already hold the operator-set new clock of every [`Mode::Low`] robot;
/// `pace_robot` is the LC robot that sets the pace (`None` when none is LC). O(N), no
/// allocation. Each new clock is computed as `s_i + δt_i` (so that `N = 2` gives Alg. 1 and
/// Eq. 18 to the last bit); a waiting robot's new clock is the followed clock itself.
pub(crate) fn advance(
    members: &[Member],
    pace_robot: Option<usize>,
    tick_s: f64,
    next_s: &mut [f64],
) -> Option<f64> {
    let respond = |m: &Member, x: f64| m.clock_s + response_step(m.clock_s - x, m.rates, tick_s);
    let pace = if let Some(l) = pace_robot {
        let x = next_s[l];
        for (next, m) in next_s.iter_mut().zip(members) {
            if m.mode == Mode::High {
                *next = respond(m, x);
            }
        }
        Some(x)
    } else {
        let mut leader: Option<usize> = None;
        let mut running = 0;
        for (i, m) in members.iter().enumerate() {
            if m.mode == Mode::High {
                running += 1;
                if leader.is_none_or(|a| m.clock_s > members[a].clock_s) {
                    leader = Some(i);
                }
            }
        }
        match leader {
            None => None,
            Some(a) if running == 1 => {
                next_s[a] = members[a].clock_s + tick_s;
                Some(next_s[a])
            }
            Some(a) => {
                let mut limit: Option<(usize, f64)> = None;
                for (j, m) in members.iter().enumerate() {
                    if j != a && m.mode == Mode::High {
                        let reach = m.clock_s + m.rates.fast * tick_s;
                        if limit.is_none_or(|(_, r)| reach < r) {
                            limit = Some((j, reach));
                        }
                    }
                }
                let (b, _) = limit.expect("at least two running high-confidence robots");
                let (ma, mb) = (members[a], members[b]);
                let (da, db) = high_conf_steps(ma.clock_s - mb.clock_s, ma.rates, mb.rates, tick_s);
                next_s[a] = ma.clock_s + da;
                next_s[b] = mb.clock_s + db;
                let x = next_s[a].min(next_s[b]);
                for (j, m) in members.iter().enumerate() {
                    if j != a && j != b && m.mode == Mode::High {
                        next_s[j] = respond(m, x);
                    }
                }
                Some(x)
            }
        }
    };
    let waiting = members.iter().any(|m| m.mode == Mode::Waiting);
    let follow = pace.filter(|_| waiting).map(|_| {
        next_s
            .iter()
            .zip(members)
            .filter(|(_, m)| matches!(m.mode, Mode::High | Mode::Low))
            .map(|(&next, _)| next)
            .fold(f64::INFINITY, f64::min)
    });
    for (next, m) in next_s.iter_mut().zip(members) {
        match m.mode {
            Mode::Waiting => *next = follow.unwrap_or(m.clock_s + tick_s),
            Mode::Finished => *next = m.clock_s,
            Mode::High | Mode::Low => {}
        }
    }
    follow
}

/// The earliest start `τ_i` (schedule clock, s) of the robots waiting at the start of the tick
/// (`+∞` if none waits), `start_s(i)` giving robot `i`'s start. The caller caps every waiting
/// robot's new clock at it as well as at its own start (rule 3): robots start one start time at
/// a time, a robot only once every robot due to start before it runs and has reached its start.
/// Otherwise a robot finishing within a tick could carry two waiting robots past their starts
/// in the same tick, and executions shorter than a tick would start, and be low-confidence,
/// together. With two robots at most one waits and this is its own start.
pub(crate) fn first_waiting_start(members: &[Member], start_s: impl Fn(usize) -> f64) -> f64 {
    members
        .iter()
        .enumerate()
        .filter(|(_, m)| m.mode == Mode::Waiting)
        .map(|(i, _)| start_s(i))
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: Rates = Rates {
        fast: 2.0,
        slow: 0.5,
    };

    #[test]
    fn eq18_three_branches() {
        // tick 1 s: slowest step 0.5, fastest 2.
        // Ahead by 1 → slowest.
        assert_eq!(response_step(1.0, R, 1.0), 0.5);
        // Level → -ΔT = 0 < 0.5 → slowest.
        assert_eq!(response_step(0.0, R, 1.0), 0.5);
        // Behind by 0.5 → exactly S·tick is matched (second branch, same value).
        assert_eq!(response_step(-0.5, R, 1.0), 0.5);
        // Behind by 1.25 → match exactly.
        assert_eq!(response_step(-1.25, R, 1.0), 1.25);
        // Behind by exactly 2 → fastest.
        assert_eq!(response_step(-2.0, R, 1.0), 2.0);
        // Behind by 5 → fastest.
        assert_eq!(response_step(-5.0, R, 1.0), 2.0);
        // Tick 0.1 s scales the thresholds: behind by 0.1 → match.
        assert!((response_step(-0.1, R, 0.1) - 0.1).abs() < 1e-15);
    }

    #[test]
    fn alg1_behind_robot_can_catch_up() {
        // a: F = 2; b: F = 3; a ahead by 0.5, tick 1: 3 ≥ 2 + 0.5 → a goes 2, b goes 2.5 (level).
        let b = Rates {
            fast: 3.0,
            slow: 0.5,
        };
        assert_eq!(high_conf_steps(0.5, R, b, 1.0), (2.0, 2.5));
        // Level and equal rates: both fastest.
        assert_eq!(high_conf_steps(0.0, R, R, 1.0), (2.0, 2.0));
    }

    #[test]
    fn alg1_behind_robot_cannot_catch_up_uses_own_f() {
        // a ahead by 3, both F = 2: b goes its own F = 2; lead after b's step 1 > 0 → a slowest.
        assert_eq!(high_conf_steps(3.0, R, R, 1.0), (0.5, 2.0));
        // a: F = 4, S = 0.25; b: F = 1.5 (≠ a's F, line-9 fix matters), level:
        // 1.5 < 4 → b goes 1.5; a's lead after b's step is -1.5 → a matches, 1.5.
        let a = Rates {
            fast: 4.0,
            slow: 0.25,
        };
        let b = Rates {
            fast: 1.5,
            slow: 0.5,
        };
        assert_eq!(high_conf_steps(0.0, a, b, 1.0), (1.5, 1.5));
        // Same, a ahead by 1: b goes 1.5, a's lead after is -0.5 → a matches 0.5 (≥ S = 0.25).
        assert_eq!(high_conf_steps(1.0, a, b, 1.0), (0.5, 1.5));
        // a ahead by 1.4: b goes 1.5, a's lead after -0.1 < S·tick → a goes slowest 0.25.
        assert_eq!(high_conf_steps(1.4, a, b, 1.0), (0.25, 1.5));
    }

    fn hc(clock_s: f64, fast: f64, slow: f64) -> Member {
        Member {
            clock_s,
            mode: Mode::High,
            rates: Rates { fast, slow },
        }
    }

    #[test]
    fn two_robots_are_alg1_and_eq18() {
        // Both HC: exactly `high_conf_steps`, robot 0 the leader on a tie.
        let m = [hc(0.0, 4.0, 0.25), hc(0.0, 1.5, 0.5)];
        let mut next = [0.0; 2];
        // No robot waits: nothing to follow.
        assert_eq!(advance(&m, None, 1.0, &mut next), None);
        assert_eq!(next, [1.5, 1.5]);
        // Robot 1 LC, the operator steps it to 2: robot 0, at 3, leads by 3 − 2 = 1 after that
        // step → slowest.
        let m = [hc(3.0, 2.0, 0.5), Member::idle(0.0, Mode::Low)];
        let mut next = [0.0, 2.0];
        assert_eq!(advance(&m, Some(1), 1.0, &mut next), None);
        assert_eq!(next, [3.5, 2.0]);
    }

    #[test]
    fn three_high_confidence_robots_track_the_furthest_reachable_clock() {
        // tick 1 s. Robot 0 leads at 2 (F 2, S ½); robot 1 at 0 (F 1.5); robot 2 at 1 (F 3).
        // Reaches: 4, 1.5, 4 → b = robot 1; Alg. 1 for (0, 1): 1.5 < 2 + 2 → b goes 1.5, a
        // responds to its lead 2 − 1.5 = ½ → slowest (2.5). Pace x = min(2.5, 1.5) = 1.5;
        // robot 2 (at 1) matches it.
        let m = [hc(2.0, 2.0, 0.5), hc(0.0, 1.5, 0.5), hc(1.0, 3.0, 0.5)];
        let mut next = [0.0; 3];
        assert_eq!(advance(&m, None, 1.0, &mut next), None);
        assert_eq!(next, [2.5, 1.5, 1.5]);
        // A waiting robot follows the running robot furthest behind, a finished one stays.
        let m = [
            hc(2.0, 2.0, 0.5),
            hc(0.0, 1.5, 0.5),
            Member::idle(0.5, Mode::Waiting),
        ];
        let mut next = [0.0; 3];
        assert_eq!(advance(&m, None, 1.0, &mut next), Some(1.5));
        assert_eq!(next, [2.5, 1.5, 1.5]);
        // Alone and HC: on schedule.
        let m = [
            hc(5.0, 2.0, 0.5),
            Member::idle(3.0, Mode::Waiting),
            Member::idle(9.0, Mode::Finished),
        ];
        let mut next = [0.0; 3];
        assert_eq!(advance(&m, None, 0.5, &mut next), Some(5.5));
        assert_eq!(next, [5.5, 5.5, 9.0]);
        // Nobody running: a waiting clock runs on schedule.
        let m = [
            Member::idle(1.0, Mode::Waiting),
            Member::idle(2.0, Mode::Finished),
        ];
        let mut next = [0.0; 2];
        assert_eq!(advance(&m, None, 0.5, &mut next), None);
        assert_eq!(next, [1.5, 2.0]);
    }

    #[test]
    fn every_high_confidence_robot_responds_to_the_low_confidence_one() {
        // Robot 1 LC rushed to 2 (from 0); robot 0 at 0 (F 1.5) cannot keep up → fastest;
        // robot 2 at 0 (F 3) matches; robot 3 at 3 is ahead → slowest.
        let m = [
            hc(0.0, 1.5, 0.5),
            Member::idle(0.0, Mode::Low),
            hc(0.0, 3.0, 0.5),
            hc(3.0, 2.0, 0.25),
        ];
        let mut next = [0.0, 2.0, 0.0, 0.0, 0.0];
        let m = [m[0], m[1], m[2], m[3], Member::idle(0.0, Mode::Waiting)];
        // The returned clock, the one a robot not yet started follows, is the smallest: 1.5.
        assert_eq!(advance(&m, Some(1), 1.0, &mut next), Some(1.5));
        assert_eq!(next, [1.5, 2.0, 2.0, 3.25, 1.5]);
    }
}
