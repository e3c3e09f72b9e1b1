//! The staggered candidate for `N ≥ 2` robots: every robot on its fastest warp, started at
//! the least offsets that the full check accepts (for two robots beside the margin-aware
//! completion: docs/decisions.md, "Two robots on their fastest warps at the least offset the
//! check accepts (issue 38)").
//!
//! The sampler widens each earlier robot's low-confidence intervals by `δ = w·length +
//! 2·tick_s` with `w ≤ 0.1` (docs/decisions.md, "The sampler's distributions"); a task whose
//! worst case needs more room than that (a short low-confidence insert whose operator may drag
//! it to `1/0.7` of its length) gets no overlapping candidate from it, and without the
//! two-robot completion nothing else tried to. This candidate asks the check itself
//! ([`crate::validate`]) how much room is needed, in two ways, the better passing one winning:
//! 1. **Equal spacing** `τ_i = i·s`: the least `s` on a grid of `|ψ_E|/128` whose LC
//!    intervals are disjoint and that passes, bisected down to a tick (a joint placement).
//! 2. **Greedy**, robot by robot: robot `i`'s start aligns one of its low-confidence runs to
//!    the end of an earlier robot's run, plus a clearance `c` that grows from 0, then from one
//!    tick by factors of `2^(1/4)`, until the robots `0..=i` pass (then it is bisected down);
//!    alignments in increasing start order, the first start that passes winning.
//!
//! The check is not monotone within a tick (robot 2's samples fall on the ticks in another
//! phase: a start may pass while one a millisecond later fails), so both bisections end by
//! walking the tick grid down from their start to its first failing point (at most
//! `GRID_PROBES` checks; docs/decisions.md, "The staggered start walks the tick grid down
//! (issue 38)").
//!
//! (docs/decisions.md, "N robots in the margin-free search".)

use crate::{Problem, Schedule, validate_with_switch};

/// Full checks (`validate` of the robots placed so far) one staggered schedule may use in all,
/// the equal spacing first, then the greedy placement's robots in turn; past it a robot starts
/// where the latest robot before it ends (docs/decisions.md, "N robots in the margin-free
/// search": 14–36 checks on the fixture, 127 of a budget of 160 on the peg task before the
/// spacing went first).
pub(crate) const MAX_STAGGER_CHECKS: usize = 96;

/// Beyond this many low-confidence runs only a robot's first run is aligned to earlier runs
/// (the alignments grow as `runs²` per robot).
const MAX_ALIGNED_RUNS: usize = 16;

/// Alignments tried per robot, the least starts first (fragmented confidence has thousands).
const MAX_BASES: usize = 64;

/// Steps of the clearance ladder: from one tick by factors of `2^(1/4)` (so that a window of
/// passing clearances wider than 19 % of its start is not stepped over, as a window between
/// "too close behind one robot" and "too close ahead of another" can be), up to `2¹⁶` ticks.
const LADDER_STEPS: usize = 64;

/// The staggered schedule of the `N ≥ 2` robots of `serial` (the fastest serial schedule,
/// [`Problem::serial_schedule_n`], at its tick) on `problem`, if it passes [`crate::validate`]
/// and some robot overlaps the one before it (else it is the serial schedule, which the
/// scheduler has already), with its `T_total` (s) and the checks used. `None` also for a
/// problem without low-confidence samples (every robot at 0 is then the optimum, which the
/// sampler finds). With the operator's switch time `switch_s` (s, ≥ 0; 0: none, the same
/// float operations) every check is [`validate_with_switch`] and the greedy clearance starts
/// at `δ` instead of 0 (a robot's run aligned to the end of another's needs at least `δ`).
pub(crate) fn staggered(
    problem: &Problem,
    serial: &Schedule,
    switch_s: f64,
) -> Option<(Schedule, f64, usize)> {
    let dt_s = problem.dt_s();
    let (n_robots, tick_s) = (serial.n_robots(), serial.tick_s);
    let warp = serial.grad_exec[0].clone();
    let one = Schedule {
        grad_exec: vec![warp.clone()],
        offsets_s: Vec::new(),
        tick_s,
        holds: Vec::new(),
    };
    let base: Vec<(f64, f64)> = one.lc_intervals(problem).ok()?[0]
        .iter()
        .map(|iv| (iv.start_s, iv.end_s))
        .collect();
    if base.is_empty() {
        return None;
    }
    let aligned = if base.len() <= MAX_ALIGNED_RUNS {
        base.len()
    } else {
        1
    };
    let duration_s = one.t_total_s(dt_s);
    let mut offsets_s: Vec<f64> = Vec::with_capacity(n_robots - 1);
    // Earlier robots' LC intervals (s, global), sorted by start, and their latest end.
    let mut placed = Placed::new(base.clone());
    let mut latest_end_s = duration_s;
    let mut checks = 0;
    let mut overlapped = false;
    // One schedule of every robot on the fastest warp, checked with its first
    // `offsets.len() + 1` robots: the warps are cloned once, not per check.
    let mut checked = Schedule {
        grad_exec: vec![warp.clone(); n_robots],
        offsets_s: Vec::with_capacity(n_robots - 1),
        tick_s,
        holds: Vec::new(),
    };
    let mut spare: Vec<Vec<f64>> = Vec::with_capacity(n_robots);
    let mut passes = |offsets: &[f64], checks: &mut usize| {
        *checks += 1;
        let k = offsets.len() + 1;
        while checked.grad_exec.len() > k {
            spare.extend(checked.grad_exec.pop());
        }
        while checked.grad_exec.len() < k {
            checked.grad_exec.extend(spare.pop());
        }
        checked.offsets_s.clear();
        checked.offsets_s.extend_from_slice(offsets);
        validate_with_switch(problem, &checked, switch_s).is_ok()
    };
    // Equal spacing `τ_i = i·s`, the least `s` on a grid of `duration/SPACING_STEPS` that
    // passes, bisected down to a tick: a joint placement, for when the greedy one leaves a
    // later robot no room (the check sees every robot at once, so an earlier robot's least
    // start can fail once a later robot runs).
    let mut spaced = None;
    let mut lo = 0.0;
    for j in 0..SPACING_STEPS {
        if checks >= MAX_STAGGER_CHECKS {
            break;
        }
        let step = duration_s * j as f64 / SPACING_STEPS as f64;
        let offsets: Vec<f64> = (1..n_robots).map(|i| i as f64 * step).collect();
        if !spaced_disjoint(&base, &offsets) {
            lo = step;
            continue;
        }
        if passes(&offsets, &mut checks) {
            let mut hi = step;
            while hi - lo > tick_s && checks < MAX_STAGGER_CHECKS {
                let mid = 0.5 * (lo + hi);
                let offsets: Vec<f64> = (1..n_robots).map(|i| i as f64 * mid).collect();
                if spaced_disjoint(&base, &offsets) && passes(&offsets, &mut checks) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            // The check is not monotone within a tick (the robots' samples fall on the ticks
            // in another phase), so a failing `lo` may lie above a passing point: walk the
            // tick grid down from `hi` to its first failing point.
            for _ in 0..GRID_PROBES {
                let below = grid_below(hi, tick_s);
                if below <= 0.0 || checks >= MAX_STAGGER_CHECKS {
                    break;
                }
                let offsets: Vec<f64> = (1..n_robots).map(|i| i as f64 * below).collect();
                if !(spaced_disjoint(&base, &offsets) && passes(&offsets, &mut checks)) {
                    break;
                }
                hi = below;
            }
            spaced = Some((1..n_robots).map(|i| i as f64 * hi).collect::<Vec<f64>>());
            break;
        }
        lo = step;
    }
    for _robot in 1..n_robots {
        let mut bases: Vec<f64> = placed
            .intervals
            .iter()
            .flat_map(|&(_, end)| base[..aligned].iter().map(move |&(s, _)| end - s))
            .filter(|&o| (0.0..latest_end_s).contains(&o))
            .collect();
        bases.push(0.0);
        bases.sort_by(f64::total_cmp);
        bases.dedup_by(|a, b| (*a - *b).abs() <= 1e-9);
        bases.truncate(MAX_BASES);
        let mut best: Option<f64> = None;
        let mut trial = offsets_s.clone();
        trial.push(0.0);
        let mut ok = |o: f64, checks: &mut usize| -> bool {
            if o > latest_end_s || !placed.disjoint(&base, o) {
                return false;
            }
            *trial.last_mut().expect("pushed") = o;
            passes(&trial, checks)
        };
        'bases: for &o in &bases {
            if best.is_some_and(|b| o >= b) || checks >= MAX_STAGGER_CHECKS {
                break;
            }
            // The first clearance that passes: 0, then the ladder from one tick.
            let mut lo: Option<f64> = None;
            let mut c = switch_s;
            let mut hi = None;
            for j in 0..=LADDER_STEPS {
                if best.is_some_and(|b| o + c >= b) || checks >= MAX_STAGGER_CHECKS {
                    continue 'bases;
                }
                if ok(o + c, &mut checks) {
                    hi = Some(c);
                    break;
                }
                lo = Some(c);
                c = if switch_s > 0.0 {
                    switch_s + tick_s * f64::powf(2.0, j as f64 / 4.0)
                } else {
                    tick_s * f64::powf(2.0, j as f64 / 4.0)
                };
            }
            let Some(mut hi) = hi else { continue };
            // Bisect between the last failing clearance and the passing one, to a tick or an
            // eighth of the clearance.
            if let Some(mut lo) = lo {
                while hi - lo > tick_s.max(hi / 8.0) && checks < MAX_STAGGER_CHECKS {
                    let mid = 0.5 * (lo + hi);
                    if ok(o + mid, &mut checks) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
            }
            // As for the spacing: the tick grid below the bisected start, to its first
            // failing point.
            let mut start = o + hi;
            for _ in 0..GRID_PROBES {
                let below = grid_below(start, tick_s);
                if below < o || checks >= MAX_STAGGER_CHECKS || !ok(below, &mut checks) {
                    break;
                }
                start = below;
            }
            best = Some(start);
        }
        let start_s = match best {
            Some(o) => {
                overlapped = true;
                o
            }
            // As the serial schedule: after the latest end on the coordinator's clock.
            None => offsets_s.iter().fold(latest_end_s, |a, &o| {
                a.max(tandem_realtime::clock_end_s(&warp, o, dt_s))
            }),
        };
        offsets_s.push(start_s);
        latest_end_s = latest_end_s.max(start_s + duration_s);
        placed.add(&base, start_s);
    }
    let greedy = overlapped
        .then(|| {
            checks += 1;
            passes(&offsets_s, &mut checks).then_some(offsets_s)
        })
        .flatten();
    let schedule_of = |offsets_s: Vec<f64>| Schedule {
        grad_exec: vec![warp.clone(); n_robots],
        offsets_s,
        tick_s,
        holds: Vec::new(),
    };
    [greedy, spaced]
        .into_iter()
        .flatten()
        .map(|o| {
            let s = schedule_of(o);
            let t = s.t_total_s(dt_s);
            (s, t)
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(s, t)| (s, t, checks))
}

/// Tick-grid points below a bisected start that are tried, downwards, until one fails.
const GRID_PROBES: usize = 4;

/// The largest multiple of `tick_s` (s) strictly below `t_s` (by more than a nanosecond).
fn grid_below(t_s: f64, tick_s: f64) -> f64 {
    let k = ((t_s - 1e-9) / tick_s).floor();
    k * tick_s
}

/// Grid steps of the equal spacing over one execution.
const SPACING_STEPS: usize = 128;

/// Whether robots on one warp (LC intervals `base`, s from the start) started at 0 and at
/// `offsets_s` have pairwise disjoint LC intervals.
fn spaced_disjoint(base: &[(f64, f64)], offsets_s: &[f64]) -> bool {
    let mut all: Vec<(f64, f64)> = std::iter::once(0.0)
        .chain(offsets_s.iter().copied())
        .flat_map(|o| base.iter().map(move |&(s, e)| (s + o, e + o)))
        .collect();
    all.sort_by(|a, b| a.0.total_cmp(&b.0));
    all.windows(2).all(|w| w[0].1 <= w[1].0)
}

/// LC intervals (s, global) sorted by start, with the running maximum of their ends.
struct Placed {
    intervals: Vec<(f64, f64)>,
    max_end: Vec<f64>,
}

impl Placed {
    fn new(mut intervals: Vec<(f64, f64)>) -> Placed {
        intervals.sort_by(|a, b| a.0.total_cmp(&b.0));
        let max_end = intervals
            .iter()
            .scan(f64::NEG_INFINITY, |m, iv| {
                *m = m.max(iv.1);
                Some(*m)
            })
            .collect();
        Placed { intervals, max_end }
    }

    /// Adds one robot's intervals `mine` (s, from its start) started at `start_s`.
    fn add(&mut self, mine: &[(f64, f64)], start_s: f64) {
        let mut all = std::mem::take(&mut self.intervals);
        all.extend(mine.iter().map(|&(s, e)| (s + start_s, e + start_s)));
        *self = Placed::new(all);
    }

    /// Whether `mine` (s, from the robot's start) shifted by `offset_s` overlaps none of the
    /// intervals; intervals are half-open, so touching ones are disjoint. `O(log P)` per
    /// interval: of the intervals starting before one ends, the latest end decides.
    fn disjoint(&self, mine: &[(f64, f64)], offset_s: f64) -> bool {
        mine.iter().all(|&(s, e)| {
            let (s, e) = (s + offset_s, e + offset_s);
            let upto = self.intervals.partition_point(|p| p.0 < e);
            upto == 0 || self.max_end[upto - 1] <= s
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disjoint_by_hand() {
        // A long interval [0, 4) holds a short one [1, 2): the latest end decides.
        let placed = Placed::new(vec![(1.0, 2.0), (0.0, 4.0), (5.0, 6.0)]);
        assert!(placed.disjoint(&[(0.0, 1.0)], 4.0));
        assert!(placed.disjoint(&[(0.0, 0.5)], 6.0));
        assert!(!placed.disjoint(&[(0.0, 0.1)], 3.0));
        assert!(!placed.disjoint(&[(0.0, 0.1)], 5.5));
        assert!(!placed.disjoint(&[(0.0, 10.0)], -1.0));
        assert!(!placed.disjoint(&[(0.0, 1.0), (2.0, 2.5)], -1.0));
        let mut more = Placed::new(vec![(0.0, 1.0)]);
        more.add(&[(0.0, 1.0)], 2.0);
        assert!(more.disjoint(&[(0.0, 1.0)], 1.0));
        assert!(!more.disjoint(&[(0.0, 1.0)], 1.5));
    }
}
