//! Rounds with `M > 1` operators (issue 44): a sound check that at most `M` robots are
//! low-confidence in any tick, for every admissible input of every operator, and the assignment
//! of every low-confidence stretch to one operator that proves it ([`assign_operators`]).
//!
//! The one-operator check (the rest of [`crate::margins`]) keeps the robots' *relative* timing;
//! this one bounds each robot's schedule clock *per tick*, whatever the others do, and needs no
//! argument about who sets the pace. With one operator the coordinator does not use it
//! (`M = 1` is today's check, bit for bit).
//!
//! # Per-robot envelopes
//! Notation as in [`crate::margins`]: `h` the tick, robot `i`'s schedule clock `s_i(n)` at the
//! start of tick `n` (all robots at `min_j τ_j` at `n = 0`), its start `τ_i`, its end `e_i`,
//! `M_i = h·max(1, max F_i)` its largest step. Facts of the rounds coordinator (`rounds`,
//! `strategy`) used, valid up to the first tick with more than `M` low-confidence robots (no
//! fault holds a robot before it; no holds: a coordinator with `M > 1` refuses them):
//! 1. a running robot's step is in `[min(1, S_i(n))·h, max(1, F_i(n))·h]` with the rates of its
//!    sample at the tick start (the operator's rate, Eq. 18's response, Alg. 1, or `h` alone),
//!    capped at `e_i`;
//! 2. a waiting robot's new clock is `max(s, min(cap, x))` with `cap ≤ τ_i` and `x` the least
//!    new clock of the running robots, or `s + h` when none runs; a robot with `τ_k ≥ τ_i`
//!    never runs while `i` waits.
//!
//! The **upper envelope** `U_i(n) ≥ s_i(n)`: if `U_i(n) ≥ τ_i`, `U_i(n+1) = min(e_i, U_i(n) +
//! h·max(1, max F_i))`, the maximum over the samples meeting `[U_i(n) − M_i, U_i(n)]` (a robot
//! at or above `U − M_i` reads one of them; one below stays below `U` after a step of at most
//! `M_i`; a waiting robot stays below `τ_i ≤ U`). If `U_i(n) < τ_i` the robot waits and
//! `U_i(n+1) = min(τ_i, max(U_i(n), X))` with `X` the least `U_k(n+1)` over the robots *surely
//! running* in tick `n` (`L_k(n) ≥ τ_k`, `U_k(n) < e_k`), or, with none, `max(U_i(n) + h,
//! max_k U_k(n+1))` over the robots that may run.
//!
//! The **lower envelope** `L_i(n) ≤ s_i(n)`: if `L_i(n) ≥ τ_i` the robot has started and
//! `L_i(n+1) = min(e_i, L_i(n) + h·min(1, min S_i))` over the samples meeting `[L_i(n), L_i(n) +
//! M_i]` (a robot above `L + M_i` stays above after any step ≥ 0). Otherwise `L_i(n+1) =
//! max(L_i(n), min(τ_i, min_k L_k(n+1)))` over the robots `k` with `τ_k < τ_i` (and `L_i = τ_i`
//! from the start for the first robots): a waiting robot is at least at the least clock of the
//! robots started before it (by induction over the ticks: while one runs it follows the least
//! of them; when all have finished, at their ends, it moves on by `h`), and a started one is
//! at or past `τ_i`. Also `L_i(n+1) ≥ min(τ_i, L_i(n) + h, min_k L_k(n+1))` over only the
//! robots `k` with `τ_k < τ_i` not surely finished (`L_k(n) < e_k`; `+∞` when there are none):
//! the robots running in tick `n` are among them, so the least new clock `x` they set is at
//! least that minimum; with none running the robot moves on by `h`; and the cap is `τ_i` or the
//! start `τ_j < τ_i` of a waiting robot `j`, which is among them with `L_j(n+1) ≤ τ_j`. Without
//! this second bound a robot that finished long ago (its clock stays at `e_k`) held the lower
//! envelope of every later robot back: a third wave of robots had windows from its upper
//! envelope's start to far past its real end, and a round of four waves of four robots was
//! refused with four operators (`four_waves_of_four_robots_need_four_operators`).
//!
//! # Windows, and why they are conservative
//! Robot `i` reports low confidence in tick `n` only if a low-confidence sample of one of its
//! runs `[a, b)` (clock, [`Timeline::lc_intervals`]) meets `[s_i(n) − tol, s_i(n+1) + tol]`, so
//! only if `U_i(n+1) + tol ≥ a` and `L_i(n) − tol < b`. The *window* of the run is every tick
//! satisfying that with `2·tol` in place of `tol`: contiguous, since both envelopes are
//! non-decreasing. It contains every tick in which the run can be traversed under *any*
//! admissible inputs of any operators, because the envelopes bound every trajectory. A robot's
//! windows that share or touch a tick are merged, so a contiguous low-confidence stretch of
//! ticks lies in one merged window.
//!
//! # Assignment (interval colouring)
//! The merged windows are intervals of ticks. They are given operators greedily in order of
//! their first tick: an operator is free for a window when its last window ended before it
//! (another robot's: more than `k` ticks before, the switch time); the robot's previous operator
//! is preferred, else the lowest index. With `k = 0` greedy start-order colouring of intervals
//! uses exactly the largest number of windows sharing a tick (when window `w` starts, every busy
//! operator holds a window containing `w`'s first tick, so a new colour is needed only when
//! `w` and those windows form a clique): the check accepts exactly when at most `M` robots'
//! windows ever share a tick. With `k > 0` a successful assignment is still a proof.
//!
//! **Ordered robots.** The envelopes bound each robot alone and forget that in a round robot
//! `b` with `e_a ≤ τ_b` starts only after robot `a` has finished: while `a` runs, the least new
//! clock `x` of the running robots is at most `e_a ≤ τ_b`, and while `a` waits the cap is at
//! most `τ_a < τ_b`, so `b` reaches `τ_b` at the earliest in the tick in which `a` finishes and
//! runs (and reports low confidence) only from the next one. Their stretches never share a
//! tick, however wide their windows (waves of robots, each after the last: the uncertainty of
//! the clocks grows from wave to wave and the windows of consecutive waves overlap). With
//! `k = 0` an operator is therefore also free for a window of `b` while it holds windows of
//! such robots `a` (before or after it); with `k > 0` the windows must be `k` ticks apart as
//! above. The greedy colouring checks every window an operator holds; with ordered robots it
//! may need more operators than the most robots that can be low-confidence at once, but every
//! assignment it returns is a proof.
//!
//! **The guarantee.** Two robots low-confidence in one tick lie in two windows containing that
//! tick, of robots not ordered, which have different operators; an operator's windows are
//! disjoint or of ordered robots. So in every tick
//! each operator has at most one low-confidence robot, at most `M` robots are low-confidence,
//! no stretch changes operator (its window has one), and an operator's stretches of two robots
//! have at least `k` ticks between them. The coordinator finds a robot's operator from the run
//! it is in (never from the tick count), so the assignment holds however the run unfolds.

use crate::error::{Error, Result};
use crate::robots::{OperatorCount, check_count};
use crate::timeline::Timeline;
use crate::tol::clock_tolerance_s;

/// Ticks of the envelope simulation before the check gives up (a plan of more than 10⁷ ticks).
const MAX_TICKS: u64 = 10_000_000;

/// One merged window: robot `robot`'s low-confidence runs `runs` (indices into
/// [`Timeline::lc_intervals`]) can be traversed only in ticks `first..=last` (tick indices from
/// the start of the round), under any admissible operator inputs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OperatorWindow {
    /// The robot (index `0..N`).
    pub robot: usize,
    /// The first of its low-confidence runs in the window.
    pub first_run: usize,
    /// One past the last of its runs in the window.
    pub end_run: usize,
    /// The first tick in which one of the runs can be traversed.
    pub first: u64,
    /// The last such tick.
    pub last: u64,
    /// The operator (index `0..M`) the window is assigned to (0 before [`assign_operators`]).
    pub operator: u8,
}

/// The operator of every low-confidence run of every robot, for a round of `M` operators
/// ([`assign_operators`]).
#[derive(Clone, Debug, PartialEq)]
pub struct OperatorPlan {
    m: usize,
    windows: Vec<OperatorWindow>,
    /// Per robot, per low-confidence run: its operator.
    op_of_run: Vec<Vec<u8>>,
    /// Per robot, per reference sample `n`: the number of its low-confidence runs that end at
    /// or before `n` (so the first run at or after sample `n` has this index).
    runs_before: Vec<Vec<u32>>,
}

impl OperatorPlan {
    /// `M`, the number of operators.
    #[must_use]
    pub fn operators(&self) -> usize {
        self.m
    }

    /// The merged windows with their operators, in order of their first tick.
    #[must_use]
    pub fn windows(&self) -> &[OperatorWindow] {
        &self.windows
    }

    /// The operator of the first low-confidence run of `robot` at or after reference sample
    /// `n` (its run at `n` when `n` is low-confidence); 0 if none follows. O(1).
    #[must_use]
    pub fn operator_from(&self, robot: usize, n: usize) -> u8 {
        let r = self.runs_before[robot].get(n).copied().unwrap_or(u32::MAX) as usize;
        self.op_of_run[robot].get(r).copied().unwrap_or(0)
    }

    /// The largest number of robots whose windows share one tick: the operators the plan
    /// needs at least (at most `M` when it exists).
    #[must_use]
    pub fn max_concurrent(&self) -> usize {
        max_concurrent(&self.windows)
    }
}

/// The largest number of windows sharing one tick.
#[must_use]
pub fn max_concurrent(windows: &[OperatorWindow]) -> usize {
    let mut ev: Vec<(u64, i32)> = windows
        .iter()
        .flat_map(|w| [(w.first, 1), (w.last + 1, -1)])
        .collect();
    // Ends before starts at the same tick: `last + 1` is outside the window.
    ev.sort_unstable_by_key(|&(t, d)| (t, d));
    let (mut cur, mut best) = (0_i32, 0_i32);
    for (_, d) in ev {
        cur += d;
        best = best.max(cur);
    }
    best as usize
}

/// The merged windows of every robot's low-confidence runs at tick `tick_s` (module docs),
/// sorted by first tick, then robot; operators all 0.
///
/// # Errors
/// [`Error::RobotCount`] unless `1 ≤ N ≤ MAX_ROBOTS`; [`Error::BadParam`] for a `tick_s` not
/// finite and > 0, or a plan whose envelopes take more than 10⁷ ticks.
pub fn operator_windows(robots: &[Timeline], tick_s: f64) -> Result<Vec<OperatorWindow>> {
    check_count(robots.len())?;
    crate::contract::check_tick(tick_s)?;
    let n = robots.len();
    let h = tick_s;
    let tol = clock_tolerance_s(robots, tick_s);
    let pad = 2.0 * tol;
    let start: Vec<f64> = robots.iter().map(Timeline::start_s).collect();
    let end: Vec<f64> = robots.iter().map(Timeline::end_s).collect();
    let step: Vec<f64> = robots.iter().map(|r| h * r.max_rate_fast()).collect();
    let t0 = start.iter().copied().fold(f64::INFINITY, f64::min);
    let mut up = vec![t0; n];
    let mut lo = vec![t0; n];
    // Per robot, the next run whose window has not opened / not closed, and the windows.
    let mut next_open = vec![0_usize; n];
    let mut next_close = vec![0_usize; n];
    let mut first_tick: Vec<Vec<u64>> = robots
        .iter()
        .map(|r| vec![0; r.lc_intervals().len()])
        .collect();
    let mut last_tick = first_tick.clone();
    let mut new_up = vec![0.0; n];
    let mut new_lo = vec![0.0; n];
    let mut tick: u64 = 0;
    while (0..n).any(|i| next_close[i] < robots[i].lc_intervals().len()) {
        if tick >= MAX_TICKS {
            return Err(Error::BadParam {
                name: "tick_s",
                why: "is too short for this plan: the operators' check needs more than 10^7 \
                      ticks; use a longer tick",
            });
        }
        // Upper envelope: robots that may run first, then waiting ones.
        for i in 0..n {
            if up[i] >= start[i] {
                let r = &robots[i];
                let (a, b) = (r.sample_at(up[i] - step[i]), r.sample_at(up[i]));
                let f = (a..=b).map(|k| r.rate_fast(k)).fold(1.0, f64::max);
                new_up[i] = (up[i] + h * f).min(end[i]);
            }
        }
        let surely = |k: usize| lo[k] >= start[k] && up[k] < end[k];
        let sure_min = (0..n)
            .filter(|&k| surely(k))
            .map(|k| new_up[k])
            .fold(f64::INFINITY, f64::min);
        let may_max = (0..n)
            .filter(|&k| up[k] >= start[k] && lo[k] < end[k])
            .map(|k| new_up[k])
            .fold(f64::NEG_INFINITY, f64::max);
        for i in 0..n {
            if up[i] < start[i] {
                let x = if sure_min.is_finite() {
                    up[i].max(sure_min)
                } else {
                    (up[i] + h).max(may_max)
                };
                new_up[i] = x.min(start[i]);
            }
        }
        // Lower envelope: started robots, then waiting ones in order of start.
        for i in 0..n {
            if lo[i] >= start[i] {
                let r = &robots[i];
                let (a, b) = (r.sample_at(lo[i]), r.sample_at(lo[i] + step[i]));
                let s = (a..=b).map(|k| r.rate_slow(k)).fold(1.0, f64::min);
                new_lo[i] = (lo[i] + h * s).min(end[i]);
            }
        }
        let mut order: Vec<usize> = (0..n).filter(|&i| lo[i] < start[i]).collect();
        order.sort_by(|&a, &b| start[a].total_cmp(&start[b]).then(a.cmp(&b)));
        for &i in &order {
            let least = (0..n)
                .filter(|&k| start[k] < start[i])
                .map(|k| new_lo[k])
                .fold(f64::INFINITY, f64::min);
            // Every robot that can run while `i` waits starts before it, so `least` is finite.
            new_lo[i] = lo[i].max(least.min(start[i]));
            // The same over the robots before it not surely finished (a finished robot does
            // not run; none running, `i` moves on by `h`): `+∞` when all surely finished.
            let unfinished = (0..n)
                .filter(|&k| start[k] < start[i] && lo[k] < end[k])
                .map(|k| new_lo[k])
                .fold(f64::INFINITY, f64::min);
            new_lo[i] = new_lo[i].max(unfinished.min(lo[i] + h).min(start[i]));
        }
        // Windows: tick `tick` is in run `[a, b)`'s window iff U(tick+1) + pad ≥ a and
        // L(tick) − pad < b.
        for i in 0..n {
            let runs = robots[i].lc_intervals();
            while next_open[i] < runs.len() && new_up[i] + pad >= runs[next_open[i]].start_s {
                first_tick[i][next_open[i]] = tick;
                next_open[i] += 1;
            }
            while next_close[i] < next_open[i] && lo[i] - pad >= runs[next_close[i]].end_s {
                // The window closed at the previous tick.
                last_tick[i][next_close[i]] =
                    tick.saturating_sub(1).max(first_tick[i][next_close[i]]);
                next_close[i] += 1;
            }
            // A run that is past in the lower envelope and the upper one alike (the robot
            // finished): close it at this tick.
            if lo[i] >= end[i] {
                while next_close[i] < next_open[i] {
                    last_tick[i][next_close[i]] = tick;
                    next_close[i] += 1;
                }
            }
        }
        up.copy_from_slice(&new_up);
        lo.copy_from_slice(&new_lo);
        tick += 1;
    }
    let mut windows = Vec::new();
    for i in 0..n {
        let runs = robots[i].lc_intervals().len();
        let mut r = 0;
        while r < runs {
            let (first, mut last, first_run) = (first_tick[i][r], last_tick[i][r], r);
            r += 1;
            while r < runs && first_tick[i][r] <= last + 1 {
                last = last.max(last_tick[i][r]);
                r += 1;
            }
            windows.push(OperatorWindow {
                robot: i,
                first_run,
                end_run: r,
                first,
                last,
                operator: 0,
            });
        }
    }
    windows.sort_by_key(|w| (w.first, w.robot));
    Ok(windows)
}

/// Assigns every low-confidence run of `robots` to one of `operators` operators so that no
/// admissible inputs make an operator supervise two robots in one tick, or two robots' stretches
/// fewer than `switch_ticks` ticks apart (module docs). `Ok(None)` when the greedy colouring of
/// the windows needs more than `M` operators (with `switch_ticks = 0`: exactly when more than
/// `M` robots' windows share a tick).
///
/// # Errors
/// Those of [`operator_windows`].
pub fn assign_operators(
    robots: &[Timeline],
    tick_s: f64,
    operators: OperatorCount,
    switch_ticks: u64,
) -> Result<Option<OperatorPlan>> {
    let mut windows = operator_windows(robots, tick_s)?;
    let m = operators.get();
    // Robot `b` starts only after robot `a` has finished when `e_a ≤ τ_b` (module docs,
    // "Ordered robots"): their stretches never share a tick.
    let ordered = |a: usize, b: usize| {
        let (ra, rb) = (&robots[a], &robots[b]);
        ra.end_s() <= rb.start_s() || rb.end_s() <= ra.start_s()
    };
    // Per operator: the windows (indices) assigned to it so far.
    let mut held: Vec<Vec<usize>> = vec![Vec::new(); m];
    let mut last_op: Vec<Option<usize>> = vec![None; robots.len()];
    for wi in 0..windows.len() {
        let w = windows[wi];
        let free = |o: usize| {
            held[o].iter().all(|&vi| {
                let v: &OperatorWindow = &windows[vi];
                if v.robot == w.robot {
                    v.last < w.first
                } else {
                    v.last.saturating_add(switch_ticks) < w.first
                        || (switch_ticks == 0 && ordered(v.robot, w.robot))
                }
            })
        };
        let pick = last_op[w.robot]
            .filter(|&o| free(o))
            .or_else(|| (0..m).find(|&o| free(o)));
        let Some(o) = pick else {
            return Ok(None);
        };
        windows[wi].operator = o as u8;
        held[o].push(wi);
        last_op[w.robot] = Some(o);
    }
    let mut op_of_run: Vec<Vec<u8>> = robots
        .iter()
        .map(|r| vec![0; r.lc_intervals().len()])
        .collect();
    for w in &windows {
        op_of_run[w.robot][w.first_run..w.end_run].fill(w.operator);
    }
    let runs_before = robots.iter().map(runs_before).collect();
    Ok(Some(OperatorPlan {
        m,
        windows,
        op_of_run,
        runs_before,
    }))
}

/// Per reference sample `n`: the number of low-confidence runs of `r` that end at or before
/// `n` (a run of samples `n0..n1` ends at `n1`).
fn runs_before(r: &Timeline) -> Vec<u32> {
    let conf = r.conf();
    let mut out = Vec::with_capacity(conf.len());
    let mut ended = 0_u32;
    for (k, &hc) in conf.iter().enumerate() {
        if hc && k > 0 && !conf[k - 1] {
            ended += 1;
        }
        out.push(ended);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `hc` high-confidence samples, `lc` low, `hc2` high, of 1 s, bounds `[lo, hi]` gradients.
    fn task(hc: usize, lc: usize, hc2: usize, start: f64, lo: f64, hi: f64) -> Timeline {
        let conf: Vec<bool> = (0..hc + lc + hc2).map(|k| k < hc || k >= hc + lc).collect();
        let g = vec![1.0; conf.len()];
        Timeline::new(
            &conf,
            &g,
            &vec![lo; g.len()],
            &vec![hi; g.len()],
            start,
            1.0,
        )
        .unwrap()
    }

    #[test]
    fn one_robot_on_schedule_has_its_window_by_hand() {
        // Bounds [1, 1]: the robot runs on schedule, one sample per tick. LC samples 2..4 are
        // the clock [2, 4): traversed in ticks 2 and 3; the tolerance pad reaches ticks 1 and 4
        // (a tick ending at 2 touches the run's start within `tol`).
        let w = operator_windows(&[task(2, 2, 3, 0.0, 1.0, 1.0)], 1.0).unwrap();
        assert_eq!(w.len(), 1);
        assert_eq!((w[0].first, w[0].last), (1, 4));
    }

    #[test]
    fn three_identical_robots_need_three_operators_and_staggered_ones_fewer() {
        let same = [0.0; 3].map(|s| task(2, 2, 6, s, 1.0, 1.0));
        let m = |k| OperatorCount::new(k).unwrap();
        assert!(assign_operators(&same, 1.0, m(2), 0).unwrap().is_none());
        let p = assign_operators(&same, 1.0, m(3), 0).unwrap().unwrap();
        assert_eq!(p.max_concurrent(), 3);
        let ops: Vec<u8> = p.windows().iter().map(|w| w.operator).collect();
        assert_eq!(ops, [0, 1, 2]);
        // Robot 2 five ticks later: its window [6, 9] is clear of [1, 4]; two operators, and
        // robot 2 takes the operator robot 0 had.
        let st = [0.0, 0.0, 5.0].map(|s| task(2, 2, 6, s, 1.0, 1.0));
        let p = assign_operators(&st, 1.0, m(2), 0).unwrap().unwrap();
        assert_eq!(p.max_concurrent(), 2);
        assert_eq!(p.windows()[2].robot, 2);
        assert_eq!(p.windows()[2].operator, 0);
        // With a switch time of 2 ticks the gap [5] of 1 tick is too short.
        assert!(assign_operators(&st, 1.0, m(2), 2).unwrap().is_none());
        assert_eq!(p.operator_from(2, 0), 0);
        assert_eq!(p.operator_from(1, 3), 1);
    }

    /// Four waves of four robots of [HC, HC, LC, LC, HC × 6] (one sample a second, started
    /// together within a wave, the waves 30 s apart), ticked at 1 s. Rigid (bounds [1, 1]): the
    /// clock is the tick count, so wave `w`'s windows are `[30w + 1, 30w + 4]` as for one robot
    /// (`one_robot_on_schedule_has_its_window_by_hand`), four robots share each: four operators
    /// suffice, three do not. Before the lower envelope left out the robots surely finished,
    /// wave 2's envelope stayed at the first wave's end (10 s) while wave 1 ran, its windows
    /// ran into wave 3's and the round was refused with four operators. With bounds [0.5, 2]
    /// the windows of consecutive waves overlap, but the waves are ordered (module docs,
    /// "Ordered robots"): four operators again, without a switch time.
    #[test]
    fn four_waves_of_four_robots_need_four_operators() {
        let m = |k| OperatorCount::new(k).unwrap();
        let waves = |lo: f64, hi: f64| -> Vec<Timeline> {
            (0..16)
                .map(|i| task(2, 2, 6, 30.0 * (i / 4) as f64, lo, hi))
                .collect()
        };
        let rigid = waves(1.0, 1.0);
        let w = operator_windows(&rigid, 1.0).unwrap();
        assert_eq!(w.len(), 16);
        for x in &w {
            let wave = (x.robot / 4) as u64;
            assert_eq!((x.first, x.last), (30 * wave + 1, 30 * wave + 4), "{x:?}");
        }
        assert!(assign_operators(&rigid, 1.0, m(3), 0).unwrap().is_none());
        let p = assign_operators(&rigid, 1.0, m(4), 0).unwrap().unwrap();
        assert_eq!(p.max_concurrent(), 4);
        // [0.5, 2]: wave `w` may end 5 to 20 ticks after its start, so the clocks' uncertainty
        // grows by 15 ticks a wave and the windows of consecutive waves overlap from wave 2 on
        // (8 windows share a tick); the waves are ordered (each ends 20 s of clock before the
        // next starts), so each operator holds one robot of every wave.
        let wide = waves(0.5, 2.0);
        let w = operator_windows(&wide, 1.0).unwrap();
        let of = |r: usize| w.iter().find(|x| x.robot == r).map(|x| (x.first, x.last));
        assert!(of(8).unwrap().1 >= of(12).unwrap().0, "{w:?}");
        let p = assign_operators(&wide, 1.0, m(4), 0).unwrap().unwrap();
        assert_eq!(p.max_concurrent(), 8);
        for wave in 0..4 {
            let mut ops: Vec<u8> = (0..4).map(|j| p.operator_from(4 * wave + j, 0)).collect();
            ops.sort_unstable();
            assert_eq!(ops, [0, 1, 2, 3]);
        }
        assert!(assign_operators(&wide, 1.0, m(3), 0).unwrap().is_none());
        // With a switch time the order gives no gap of `k` ticks: the windows must be apart,
        // and these are not (the limit: such a round is refused, `Error::Unsafe`).
        assert!(assign_operators(&wide, 1.0, m(4), 1).unwrap().is_none());
        assert!(assign_operators(&rigid, 1.0, m(4), 1).unwrap().is_some());
        let err = crate::Coordinator::new_unchecked(wide, 1.0)
            .unwrap()
            .with_switch_s(1.0)
            .unwrap()
            .with_operators(m(4))
            .unwrap_err();
        assert!(
            matches!(err, Error::Unsafe { tick_s } if tick_s == 1.0),
            "{err}"
        );
        assert!(
            err.to_string()
                .contains("the margin check rejects these plans"),
            "{err}"
        );
    }

    #[test]
    fn the_windows_widen_with_the_admissible_rates() {
        // Bounds [0.5, 2]: F = 2, S = 0.5. The run [4, 6) starts at the earliest when the
        // fastest robot reaches 4 − pad: ticks of 2 s of clock from 0, so the tick 1 (ending
        // at 4); it ends at the latest when the slowest robot, 0.5 s a tick, leaves 6: it is
        // at 6 after 12 ticks, so tick 11 is the last in which it can touch the run.
        let w = operator_windows(&[task(4, 2, 4, 0.0, 0.5, 2.0)], 1.0).unwrap();
        assert_eq!((w[0].first, w[0].last), (1, 12));
    }
}
