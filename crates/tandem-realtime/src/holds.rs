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
    /// Reference sample `n` (`0 ≤ n < T_ref`) at whose start the robot stops. For `n ≥ 1`
    /// samples `n − 1` and `n` must be high-confidence: a robot that needs the operator is
    /// never stopped, and a robot waiting at the boundary of a low-confidence sample would be
    /// reported low-confidence in the tick in which it leaves. `n = 0` is the task start (a
    /// hold on any sample, since the robot has not moved): listed only to give the start
    /// release rules, with dwell 0 (the start offset `τ_i` is its planned dwell); it does not
    /// split the plan.
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
        if n >= n_ref {
            return Err(bad(
                n,
                "is past the last reference sample (must be < T_ref)",
            ));
        }
        if k > 0 && holds[k - 1].ref_idx >= n {
            return Err(bad(n, "is not after the hold before it"));
        }
        if n == 0 && h.dwell_s != 0.0 {
            return Err(bad(
                n,
                "is the start, whose dwell is the start offset (dwell must be 0)",
            ));
        }
        if n > 0 && !(conf[n - 1] && conf[n]) {
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
        .filter(|h| h.ref_idx > 0)
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

/// The hold samples of a plan usable for a [`Hold`]: those of `available` (e.g. a problem's
/// hold points) with samples `n − 1` and `n` high-confidence, `n ≥ 1`.
#[must_use]
pub fn usable_holds(conf: &[bool], available: &[usize]) -> Vec<usize> {
    available
        .iter()
        .copied()
        .filter(|&n| n >= 1 && n < conf.len() && conf[n - 1] && conf[n])
        .collect()
}

/// Release rules from the schedule's order of low-confidence stretches: the low-confidence
/// regions of all robots (`robots` split at the holds `base`, with their dwells; `base` empty
/// for none) merged by their scheduled start; for every two consecutive regions `X` of robot
/// `a` and `Y` of robot `b ≠ a`, robot `b` gets the latest of its usable holds `usable[b]`
/// (increasing; see [`usable_holds`]) after its own region before `Y` (or the start, when `Y`
/// is its first) and before `Y`, with the rule "once `a` has passed the end of `X`"
/// ([`After`]); a hold of `base` there keeps its dwell. A pair without such a hold gets no
/// rule (the margin check decides it). A rule whose awaited leg would not start strictly
/// before the held leg (it would wait forever: legs start in order) is dropped. Returns one
/// list per robot, or `base` itself when no rule was made.
#[must_use]
pub fn release_rules(
    robots: &[Timeline],
    base: &[Vec<Hold>],
    usable: &[Vec<usize>],
) -> Vec<Vec<Hold>> {
    let n = robots.len();
    let none: &[Hold] = &[];
    let base_of = |i: usize| base.get(i).map_or(none, Vec::as_slice);
    // Each robot's regions with their scheduled clock (dwells included).
    let mut regions: Vec<(f64, usize, crate::LcInterval)> = Vec::new();
    for (i, r) in robots.iter().enumerate() {
        let Ok(legs) = legs(r, base_of(i)) else {
            return base.to_vec();
        };
        let mut ref0 = 0;
        for leg in &legs {
            for iv in leg.lc_intervals() {
                let iv = crate::LcInterval {
                    ref_start: iv.ref_start + ref0,
                    ref_end: iv.ref_end + ref0,
                    ..*iv
                };
                regions.push((iv.start_s, i, iv));
            }
            ref0 += leg.n_ref();
        }
    }
    regions.sort_by(|x, y| {
        x.0.total_cmp(&y.0)
            .then((x.1, x.2.ref_start).cmp(&(y.1, y.2.ref_start)))
    });
    let no_usable: &[usize] = &[];
    // (held robot, hold sample, awaited robot, awaited sample)
    let mut wanted: Vec<(usize, usize, usize, usize)> = Vec::new();
    for w in regions.windows(2) {
        let ((_, a, x), (_, b, y)) = (w[0], w[1]);
        if a == b {
            continue;
        }
        let prev_end = regions
            .iter()
            .filter(|(_, r, iv)| *r == b && iv.ref_end <= y.ref_start)
            .map(|(_, _, iv)| iv.ref_end)
            .max();
        let cands = usable.get(b).map_or(no_usable, Vec::as_slice);
        let hold = cands
            .iter()
            .rev()
            .copied()
            .find(|&h| h < y.ref_start && prev_end.is_none_or(|e| h > e))
            .or(prev_end.is_none().then_some(0));
        if let Some(h) = hold {
            wanted.push((b, h, a, x.ref_end));
        }
    }
    if wanted.is_empty() {
        return base.to_vec();
    }
    let mut holds: Vec<Vec<Hold>> = (0..n).map(|i| base_of(i).to_vec()).collect();
    for &(b, h, _, _) in &wanted {
        if !holds[b].iter().any(|x| x.ref_idx == h) {
            holds[b].push(Hold::at(h));
        }
    }
    for list in &mut holds {
        list.sort_by_key(|h| h.ref_idx);
    }
    // Leg starts with these holds: the clock at which the leg holding a sample starts.
    let leg_starts: Vec<Vec<(usize, f64)>> = robots
        .iter()
        .zip(&holds)
        .map(|(r, h)| {
            let mut ref0 = 0;
            legs(r, h)
                .map(|ls| {
                    ls.iter()
                        .map(|l| {
                            let out = (ref0, l.start_s());
                            ref0 += l.n_ref();
                            out
                        })
                        .collect()
                })
                .unwrap_or_default()
        })
        .collect();
    let start_of_leg_with = |robot: usize, last_sample: usize| {
        leg_starts[robot]
            .iter()
            .rev()
            .find(|(r0, _)| *r0 <= last_sample)
            .map_or(f64::INFINITY, |&(_, s)| s)
    };
    for &(b, h, a, m) in &wanted {
        if start_of_leg_with(a, m - 1) >= start_of_leg_with(b, h) {
            continue;
        }
        let hold = holds[b]
            .iter_mut()
            .find(|x| x.ref_idx == h)
            .expect("pushed above");
        let rule = After {
            robot: a,
            ref_idx: m,
        };
        if !hold.after.contains(&rule) {
            hold.after.push(rule);
        }
    }
    plan_rule_waits(robots, &mut holds);
    holds
}

/// The clock (s) at which robot `robot`, on its legs `legs` (its plan split at its holds,
/// dwells included), is planned to reach the start of reference sample `ref_idx`
/// (`1..=T_ref`): the threshold of a release rule awaiting it ([`Plans::new`]).
fn planned_clock_at(legs: &[Timeline], ref_idx: usize) -> f64 {
    let mut ref0 = 0;
    for leg in legs {
        if ref_idx <= ref0 + leg.n_ref() {
            return leg.sample_clock_s()[ref_idx - ref0];
        }
        ref0 += leg.n_ref();
    }
    legs.last().map_or(f64::INFINITY, Timeline::end_s)
}

/// Plans the waits the release rules impose: raises the planned dwell of every hold (after
/// the start) to at least the time its robot must wait there on schedule, from its arrival
/// (the end of its previous leg) to the planned clock at which the last robot it awaits passes
/// the awaited sample — so that the schedule's times, and its `T_total`, are what a cell
/// whose operator works at the planned speed does (docs/decisions.md, "A plan is what the
/// cell does"). A dwell is never lowered. The awaited clocks move with the awaited robots'
/// own dwells, so this iterates to a fixed point (at most once per hold, plus one; dwells
/// only grow). A rule on the start hold (sample 0) cannot be planned by a dwell (the start
/// offset is the start's dwell) and is left as it is; a rule whose awaited leg no longer
/// starts strictly before the held leg once the waits are planned is dropped (it would wait
/// forever: legs start in order), as when the rules are made.
fn plan_rule_waits(robots: &[Timeline], holds: &mut [Vec<Hold>]) {
    let rounds = holds.iter().map(Vec::len).sum::<usize>() + 1;
    for _ in 0..rounds {
        let Ok(legs_of) = robots
            .iter()
            .zip(holds.iter())
            .map(|(r, h)| legs(r, h))
            .collect::<Result<Vec<_>>>()
        else {
            return;
        };
        let mut changed = false;
        for (b, list) in holds.iter_mut().enumerate() {
            let mut leg = 0;
            for h in list.iter_mut().filter(|h| h.ref_idx > 0) {
                leg += 1;
                let arrive_s = legs_of[b][leg - 1].end_s();
                let due_s = h
                    .after
                    .iter()
                    .map(|a| planned_clock_at(&legs_of[a.robot], a.ref_idx))
                    .fold(arrive_s + h.dwell_s, f64::max);
                // Raise only by more than rounding: `arrive + dwell` may differ from `due`
                // by an ulp once the legs are rebuilt.
                let eps = 1e-12 * due_s.abs().max(1.0);
                if due_s > arrive_s + h.dwell_s + eps {
                    h.dwell_s = due_s - arrive_s;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    // Rules whose awaited leg does not start strictly before the held leg any more.
    let Ok(legs_of) = robots
        .iter()
        .zip(holds.iter())
        .map(|(r, h)| legs(r, h))
        .collect::<Result<Vec<_>>>()
    else {
        return;
    };
    let start_of_leg_with = |robot: usize, sample: usize| {
        let mut ref0 = 0;
        for leg in &legs_of[robot] {
            if sample < ref0 + leg.n_ref() {
                return leg.start_s();
            }
            ref0 += leg.n_ref();
        }
        f64::INFINITY
    };
    for (b, list) in holds.iter_mut().enumerate() {
        for h in list.iter_mut() {
            let held_start = start_of_leg_with(b, h.ref_idx);
            h.after
                .retain(|a| start_of_leg_with(a.robot, a.ref_idx - 1) < held_start);
        }
    }
}

/// A release rule in clock terms: robot `robot` has passed `threshold_s` on its leg `leg`
/// (index into [`Plans::legs`]): its current leg is later, or it is on that leg with its
/// clock at the leg's end or at least `tol` past `threshold_s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rule {
    /// The robot awaited.
    pub(crate) robot: usize,
    /// Its leg containing the last sample it must have passed.
    pub(crate) leg: usize,
    /// The clock (s, on that leg) of the sample boundary it must have passed.
    pub(crate) threshold_s: f64,
}

/// The robots' plans split into legs, with each leg's release rules: what the coordinator
/// runs and the margin check checks (one construction for both).
#[derive(Clone, Debug)]
pub(crate) struct Plans {
    /// Every robot's legs, robot 0's first, each robot's in order.
    pub(crate) legs: Vec<Timeline>,
    /// The robot of each leg.
    pub(crate) robot_of: Vec<usize>,
    /// The first reference sample of each leg (in its robot's reference).
    pub(crate) ref0: Vec<usize>,
    /// Per robot, its legs `first_leg[i]..first_leg[i + 1]`.
    pub(crate) first_leg: Vec<usize>,
    /// Per leg, its release rules `rules[rule_start[l]..rule_start[l + 1]]`.
    pub(crate) rule_start: Vec<usize>,
    /// The release rules of every leg, in leg order.
    pub(crate) rules: Vec<Rule>,
}

impl Plans {
    /// Splits `robots` at `holds` (one list per robot, or none at all) after checking them
    /// ([`check_holds`]).
    ///
    /// # Errors
    /// [`Error::BadHold`], or [`Error::LengthMismatch`] for a number of hold lists that is
    /// neither 0 nor `N`.
    pub(crate) fn new(robots: &[Timeline], holds: &[Vec<Hold>]) -> Result<Plans> {
        let n = robots.len();
        if !holds.is_empty() && holds.len() != n {
            return Err(Error::LengthMismatch {
                what: "holds",
                expected: n,
                found: holds.len(),
            });
        }
        let none: &[Hold] = &[];
        let holds_of = |i: usize| holds.get(i).map_or(none, Vec::as_slice);
        let mut plans = Plans {
            legs: Vec::new(),
            robot_of: Vec::new(),
            ref0: Vec::new(),
            first_leg: Vec::with_capacity(n + 1),
            rule_start: Vec::new(),
            rules: Vec::new(),
        };
        for (i, tl) in robots.iter().enumerate() {
            check_holds(i, holds_of(i), tl, n, |r| robots[r].n_ref())?;
            plans.first_leg.push(plans.legs.len());
            let mut from = 0;
            for leg in legs(tl, holds_of(i))? {
                let n_ref = leg.n_ref();
                plans.legs.push(leg);
                plans.robot_of.push(i);
                plans.ref0.push(from);
                from += n_ref;
            }
        }
        plans.first_leg.push(plans.legs.len());
        for (l, &i) in plans.robot_of.clone().iter().enumerate() {
            plans.rule_start.push(plans.rules.len());
            let ref0 = plans.ref0[l];
            // Leg 0 takes the rules of a start hold, a later leg those of the hold it starts at.
            let Some(h) = holds_of(i).iter().find(|h| h.ref_idx == ref0) else {
                continue;
            };
            for a in &h.after {
                let legs_of_a = plans.first_leg[a.robot]..plans.first_leg[a.robot + 1];
                let leg = legs_of_a
                    .clone()
                    .rev()
                    .find(|&la| plans.ref0[la] < a.ref_idx)
                    .expect("ref_idx ≥ 1 lies in a leg of the robot awaited");
                if plans.legs[leg].start_s() >= plans.legs[l].start_s() {
                    return Err(Error::BadHold {
                        robot: i,
                        ref_idx: ref0,
                        why: "waits for a leg of another robot that starts no earlier on schedule (legs start in order of their starts: it would wait forever)",
                    });
                }
                let local = a.ref_idx - plans.ref0[leg];
                plans.rules.push(Rule {
                    robot: a.robot,
                    leg,
                    threshold_s: plans.legs[leg].sample_clock_s()[local],
                });
            }
        }
        plans.rule_start.push(plans.rules.len());
        Ok(plans)
    }

    /// Whether any robot has more than one leg or any leg a release rule.
    pub(crate) fn has_holds(&self) -> bool {
        self.legs.len() > self.robot_of.last().map_or(0, |&r| r + 1) || !self.rules.is_empty()
    }

    /// The release rules of leg `l`.
    pub(crate) fn rules_of(&self, l: usize) -> &[Rule] {
        &self.rules[self.rule_start[l]..self.rule_start[l + 1]]
    }
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
        assert!(check(&[Hold::at(0), Hold::at(2)]).is_ok());
        let start_dwell = Hold {
            dwell_s: 1.0,
            ..Hold::at(0)
        };
        assert!(check(&[start_dwell]).is_err());
        for (holds, at) in [
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
