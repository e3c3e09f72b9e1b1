//! Hold points of a robot's plan (§II-C: "stop certain robots"): where a robot may wait, for
//! any time, without harm, and the rules that release it.
//!
//! A [`Hold`] at reference sample `n` stops the robot with its schedule clock at the start of
//! sample `n` (it has done samples `0..n`). The hold splits the robot's plan into *legs*: leg
//! `k` runs from the `k`-th hold to the next one (leg 0 from the task start, the hold that is
//! always there and is not listed: the start offset `τ_i`). A leg starts exactly as a robot
//! starts (the coordinator's rule 3): its schedule clock follows the running robot furthest
//! behind, capped at the leg's start, and it moves once every running robot has reached its
//! start, every leg due to start before it has started, and every robot named in its
//! [`Hold::after`] has passed the named reference sample. So a hold re-synchronizes the robot
//! with the others (the worst-case drift of the clocks is reset there, as at a start), and a
//! release rule enforces the order of two low-confidence stretches at run time, whatever the
//! operator does. The argument is in docs/decisions.md, "Hold points: a wait instead of a
//! margin".
//!
//! The leg's start (schedule clock) is the previous leg's end plus the planned dwell
//! [`Hold::dwell_s`]; [`legs`] builds each leg's [`Timeline`] from the robot's timeline, so
//! that a plan without dwell keeps the robot's clock breakpoints bit for bit.

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};
use crate::timeline::Timeline;

/// A release condition of a [`Hold`]: robot `robot` (0-based) has passed reference sample
/// `ref_idx`, i.e. its schedule clock is at least `tol` past the start of sample `ref_idx`
/// (it can no longer traverse samples `0..ref_idx` in a tick), or its plan is finished.
///
/// `ref_idx` is typically the end (exclusive) of a low-confidence run of that robot: "robot
/// `b` leaves its hold once robot `a` has left its low-confidence stretch".
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct After {
    /// The robot awaited (0-based; not the held robot).
    pub robot: usize,
    /// The reference sample it must have passed (`1..=T_ref`; `T_ref` means: finished).
    pub ref_idx: usize,
}

/// One hold of a robot's plan: the robot stops at the start of reference sample `ref_idx`
/// (schedule clock `c_n` of its plan, plus the dwells of the holds before it), may dwell there
/// for any time, and leaves as a robot starts (module docs) once every [`After`] condition
/// holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hold {
    /// Reference sample `n` (`1 ≤ n < T_ref`) at whose start the robot stops. Samples `n − 1`
    /// and `n` must be high-confidence: a robot that needs the operator is never stopped, and
    /// a robot waiting at the boundary of a low-confidence sample would be reported
    /// low-confidence in the tick in which it leaves.
    pub ref_idx: usize,
    /// Planned dwell (schedule-clock s, finite, ≥ 0): how long the schedule plans the robot to
    /// wait here. Every later breakpoint of the robot's clock is this much later. Default 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub dwell_s: f64,
    /// Release rules: the robot leaves only once each of these holds (all of them). Empty: it
    /// leaves as soon as the start rule allows (the clocks re-synchronize).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub after: Vec<After>,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl Hold {
    /// A hold at the start of sample `ref_idx` with no planned dwell and no release rule.
    #[must_use]
    pub fn at(ref_idx: usize) -> Hold {
        Hold {
            ref_idx,
            dwell_s: 0.0,
            after: Vec::new(),
        }
    }
}

/// Checks the holds of robot `robot` (of `n_robots`) on its timeline `tl`: strictly increasing
/// `ref_idx` in `1..T_ref` with samples `n − 1` and `n` high-confidence, finite dwells ≥ 0,
/// release rules naming another robot and a sample in `1..=n_ref_of(robot)`.
///
/// # Errors
/// [`Error::BadHold`] naming the robot, the hold and what is wrong.
pub fn check_holds(
    robot: usize,
    holds: &[Hold],
    tl: &Timeline,
    n_robots: usize,
    n_ref_of: impl Fn(usize) -> usize,
) -> Result<()> {
    let bad = |ref_idx: usize, why: &'static str| Error::BadHold {
        robot,
        ref_idx,
        why,
    };
    let n_ref = tl.n_ref();
    let conf = tl.conf();
    for (k, h) in holds.iter().enumerate() {
        let n = h.ref_idx;
        if n == 0 || n >= n_ref {
            return Err(bad(n, "must be in 1..T_ref (the start is always a hold)"));
        }
        if k > 0 && holds[k - 1].ref_idx >= n {
            return Err(bad(n, "is not after the hold before it"));
        }
        if !(conf[n - 1] && conf[n]) {
            return Err(bad(
                n,
                "is next to a low-confidence sample (samples n − 1 and n must be high-confidence)",
            ));
        }
        if !(h.dwell_s.is_finite() && h.dwell_s >= 0.0) {
            return Err(bad(n, "has a dwell that is not finite and ≥ 0"));
        }
        for a in &h.after {
            if a.robot == robot || a.robot >= n_robots {
                return Err(bad(
                    n,
                    "waits for itself or for a robot that does not exist",
                ));
            }
            if a.ref_idx == 0 || a.ref_idx > n_ref_of(a.robot) {
                return Err(bad(
                    n,
                    "waits for a reference sample outside 1..=T_ref of the robot awaited",
                ));
            }
        }
    }
    Ok(())
}

/// The legs of a robot's plan `tl` split at `holds` (checked with [`check_holds`]): leg `k`
/// covers reference samples `bounds[k]..bounds[k + 1]` (`bounds = [0, n_1, …, n_H, T_ref]`)
/// and starts at the end of leg `k − 1` plus the dwell of hold `k` (leg 0 at `τ_i`). Without
/// holds it is the robot's timeline itself; with holds of zero dwell each leg's breakpoints
/// are the robot's, bit for bit (the clock is summed in the same order from the same start).
///
/// # Errors
/// As [`Timeline::new`] (a leg's end that is not finite).
pub fn legs(tl: &Timeline, holds: &[Hold]) -> Result<Vec<Timeline>> {
    let mut out = Vec::with_capacity(holds.len() + 1);
    let mut from = 0;
    let mut start_s = tl.start_s();
    for bound in holds
        .iter()
        .map(|h| (h.ref_idx, h.dwell_s))
        .chain(std::iter::once((tl.n_ref(), 0.0)))
    {
        let (to, dwell_next) = bound;
        let leg = tl.sub(from, to, start_s)?;
        start_s = leg.end_s() + dwell_next;
        from = to;
        out.push(leg);
    }
    Ok(out)
}

/// The schedule-clock breakpoints (s) of a plan with holds: those of [`legs`] joined, one per
/// reference sample boundary `0..=T_ref`, where a hold's boundary carries the leg's *start*
/// (after the dwell). With no holds they are [`crate::clock_s`].
#[must_use]
pub fn held_clock_end_s(grad_exec: &[f64], start_s: f64, dt_s: f64, holds: &[Hold]) -> f64 {
    let mut c = start_s;
    let mut k = 0;
    for (n, &g) in grad_exec.iter().enumerate() {
        if k < holds.len() && holds[k].ref_idx == n {
            c += holds[k].dwell_s;
            k += 1;
        }
        c += g * dt_s;
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tl() -> Timeline {
        // HC everywhere but sample 3; 6 samples of 0.5 s at gradient 1, start 1 s.
        let conf = [true, true, true, false, true, true];
        Timeline::new(&conf, &[1.0; 6], &[0.5; 6], &[2.0; 6], 1.0, 0.5).unwrap()
    }

    #[test]
    fn legs_keep_the_clock_and_shift_by_the_dwell() {
        let t = tl();
        let l = legs(&t, &[Hold::at(2)]).unwrap();
        assert_eq!(l.len(), 2);
        assert_eq!((l[0].start_s(), l[0].end_s()), (1.0, 2.0));
        assert_eq!((l[1].start_s(), l[1].end_s()), (2.0, t.end_s()));
        assert_eq!(l[1].sample_clock_s(), &t.sample_clock_s()[2..]);
        let dwell = Hold {
            dwell_s: 1.25,
            ..Hold::at(2)
        };
        let l = legs(&t, std::slice::from_ref(&dwell)).unwrap();
        assert_eq!((l[1].start_s(), l[1].end_s()), (3.25, 5.25));
        assert_eq!(
            held_clock_end_s(t.grad_exec(), 1.0, 0.5, &[dwell]),
            l[1].end_s()
        );
        assert_eq!(held_clock_end_s(t.grad_exec(), 1.0, 0.5, &[]), t.end_s());
        assert_eq!(
            legs(&t, &[]).unwrap()[0].sample_clock_s(),
            t.sample_clock_s()
        );
    }

    #[test]
    fn bad_holds_are_named() {
        let t = tl();
        let n = |_| 6;
        let check = |h: &[Hold]| check_holds(1, h, &t, 2, n);
        assert!(check(&[Hold::at(1), Hold::at(5)]).is_ok());
        for (holds, at) in [
            (vec![Hold::at(0)], 0),
            (vec![Hold::at(6)], 6),
            (vec![Hold::at(2), Hold::at(2)], 2),
            (vec![Hold::at(3)], 3),
            (vec![Hold::at(4)], 4),
        ] {
            assert!(
                matches!(check(&holds), Err(Error::BadHold { robot: 1, ref_idx, .. }) if ref_idx == at),
                "{holds:?}"
            );
        }
        let rule = |robot, ref_idx| Hold {
            after: vec![After { robot, ref_idx }],
            ..Hold::at(2)
        };
        assert!(check(&[rule(0, 4)]).is_ok());
        assert!(check(&[rule(1, 4)]).is_err());
        assert!(check(&[rule(2, 4)]).is_err());
        assert!(check(&[rule(0, 0)]).is_err());
        assert!(check(&[rule(0, 7)]).is_err());
        let nan = Hold {
            dwell_s: f64::NAN,
            ..Hold::at(2)
        };
        assert!(check(&[nan]).is_err());
    }
}
