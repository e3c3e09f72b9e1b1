//! The previous schedule re-timed for a new problem: the incumbent of a re-schedule when the
//! previous schedule itself no longer passes (docs/decisions.md, "Learning never makes the
//! plan worse").
//!
//! After a round the model update (Eq. 21) moves the mean gradient `ψ̇̄` and the bounds
//! `[ψ̇min, ψ̇max]`, so the previous schedule breaks Eq. 20 constraint 4 on every
//! low-confidence (LC) sample whose mean moved, even though confidence only grew. Setting those
//! samples to the new mean (the plain repair, `choose::repair`) shifts every later event of the
//! robot by the change of the LC durations, which breaks the clearances the margin check
//! needed (tight pairs overlap or lose their margin) and drops the planned dwells. Re-timing
//! keeps what made the previous schedule valid instead:
//!
//! 1. **Its order and clearances.** Every robot's LC runs of the new problem (each inside an
//!    LC run of the old one: confidence only grows) are laid out in the old global times; for
//!    every two consecutive ones of different robots, the later must start at least as long
//!    after the earlier ends as it did before (plus `extra_clear_s`).
//! 2. **No event earlier than before.** Each LC run starts no earlier than it did, each robot
//!    no earlier than its old start offset.
//! 3. **The new chain.** LC runs last their new durations `L_k = Σ ψ̇̄·Δt_s` (constraint 4) and
//!    the high-confidence (HC) gaps between them stay inside their new ranges
//!    `[Σ ψ̇min·Δt_s, Σ ψ̇max·Δt_s]` (constraint 1) — without upper bound where the robot
//!    keeps a hold of the old schedule (it may dwell there).
//!
//! These are difference constraints; their earliest solution (longest paths, the same
//! Bellman–Ford as the exact search's `stn.rs`) is the least in every event at once, so an
//! event moves later than before only where a lengthened LC run pushes it. When nothing
//! lengthened (confidence grew, the means stayed), the earliest solution is the old times
//! exactly. Each robot then ends at its old end if its tail allows, so `T_total` does not
//! grow unless a chain of tight LC runs lengthened. The HC gradients are the old ones clamped
//! into the new bounds and blended towards `ψ̇min` (shorter) or `ψ̇max` (longer) to last what
//! the times say, keeping their shape (the completion's tilt); in a gap with a kept hold, time
//! beyond the old gradients is a planned dwell there. Holds the new problem no longer allows
//! are dropped; release rules are kept as they were.
//!
//! The result is a candidate only: the scheduler validates it (every constraint of Eq. 20,
//! the margin check included) before it can be the incumbent.

use tandem_realtime::Hold;

use crate::exact::stn::{Edge, longest_paths, relax_tolerance};
use crate::problem::Problem;
use crate::schedule::Schedule;

/// `previous` re-timed for `problem` at control tick `tick_s` (s) (see the module docs), every
/// clearance between two consecutive LC runs of different robots raised by `extra_clear_s`
/// (s, ≥ 0). `None` for a schedule of the wrong shape, non-finite values, or when the
/// constraints have no solution (robot 1, which cannot start later, would have to).
pub(crate) fn retime(
    problem: &Problem,
    previous: &Schedule,
    tick_s: f64,
    extra_clear_s: f64,
) -> Option<Schedule> {
    retime_with_pairs(problem, previous, tick_s, extra_clear_s, &[], false)
}

/// A clearance of one pair of low-confidence (LC) runs of different robots for
/// [`retime_with_pairs`]: robot `cur.0`'s LC run `cur.1` starts at least `extra_s` (s, ≥ 0)
/// later after the end of robot `prev.0`'s LC run `prev.1` than it did in the previous
/// schedule (and never before that end). Runs are counted among the problem's LC runs in
/// reference order, robots from 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PairClearance {
    /// `(robot, LC run)` of the earlier run.
    pub(crate) prev: (usize, usize),
    /// `(robot, LC run)` of the later run.
    pub(crate) cur: (usize, usize),
    /// The clearance added (s, ≥ 0).
    pub(crate) extra_s: f64,
}

/// [`retime`] with, beside the uniform `extra_clear_s` between consecutive runs, one more
/// difference constraint per entry of `pairs` ([`PairClearance`]; entries naming a robot or
/// run the schedule does not have are ignored): the clearances of the margin check's failing
/// pairs, each only where it fails (docs/decisions.md, "Per-pair clearances for N ≥ 3").
///
/// With `dwell_anywhere`, an HC gap in which the robot keeps no hold of `previous` but the
/// problem has a usable hold point is unbounded too: time beyond its gradients becomes a
/// planned dwell at the gap's last usable hold, which the result then lists (holds added this
/// way that get no dwell are left out). Without it only `previous`'s holds may dwell (as
/// [`retime`]): a schedule that lists only the holds it dwells at (the margin-free optimum's)
/// would otherwise have every gap without a dwell rigid at its `ψ̇max`, and a clearance that
/// reaches robot 1 (whose start is the origin) through such gaps has no solution.
pub(crate) fn retime_with_pairs(
    problem: &Problem,
    previous: &Schedule,
    tick_s: f64,
    extra_clear_s: f64,
    pairs: &[PairClearance],
    dwell_anywhere: bool,
) -> Option<Schedule> {
    retime_pairs(
        problem,
        previous,
        tick_s,
        extra_clear_s,
        pairs,
        dwell_anywhere,
        false,
    )
}

/// [`retime_with_pairs`] with every pair of `pairs` at the clearance `extra_s` itself (s, ≥ 0:
/// the later run starts at least that long after the earlier ends) instead of its old
/// clearance plus `extra_s`; a pair of consecutive runs that `pairs` names no longer keeps its
/// old clearance, so room one switch of `previous` had to spare can go to another that lacks
/// it (docs/decisions.md, "Two robots with holds: clearances traded between switches (issue
/// 38)"). Pairs not named keep their old clearances, events no earlier than in `previous`.
pub(crate) fn retime_with_set_pairs(
    problem: &Problem,
    previous: &Schedule,
    tick_s: f64,
    pairs: &[PairClearance],
    dwell_anywhere: bool,
) -> Option<Schedule> {
    retime_pairs(problem, previous, tick_s, 0.0, pairs, dwell_anywhere, true)
}

/// [`retime_with_pairs`] (`set` false) and [`retime_with_set_pairs`] (`set` true).
fn retime_pairs(
    problem: &Problem,
    previous: &Schedule,
    tick_s: f64,
    extra_clear_s: f64,
    pairs: &[PairClearance],
    dwell_anywhere: bool,
    set: bool,
) -> Option<Schedule> {
    let n_ref = problem.n_ref();
    let n_robots = previous.n_robots();
    if previous.check_shape().is_err()
        || previous
            .grad_exec
            .iter()
            .any(|g| g.len() != n_ref || g.iter().any(|x| !x.is_finite()))
        || previous.offsets_s.iter().any(|o| !o.is_finite())
        || previous
            .holds
            .iter()
            .flatten()
            .any(|h| !h.dwell_s.is_finite())
    {
        return None;
    }
    let dt = problem.dt_s();
    let (gmean, gmin, gmax) = (problem.grad_mean(), problem.grad_min(), problem.grad_max());
    // The new chain: LC runs and the HC gaps around them (gap g before LC run g; gap m the
    // tail; empty ranges where a run is missing).
    let mut lc: Vec<(usize, usize)> = Vec::new();
    let mut gaps: Vec<(usize, usize)> = Vec::new();
    let mut pending: Option<(usize, usize)> = None;
    for run in problem.runs() {
        if run.high_conf {
            pending = Some((run.start, run.end));
        } else {
            gaps.push(pending.take().unwrap_or((run.start, run.start)));
            lc.push((run.start, run.end));
        }
    }
    gaps.push(pending.unwrap_or((n_ref, n_ref)));
    let m = lc.len();
    let sum = |v: &[f64], (a, b): (usize, usize)| v[a..b].iter().sum::<f64>() * dt;
    let lc_s: Vec<f64> = lc.iter().map(|&r| sum(gmean, r)).collect();
    let gap_lo: Vec<f64> = gaps.iter().map(|&r| sum(gmin, r)).collect();
    let gap_hi: Vec<f64> = gaps.iter().map(|&r| sum(gmax, r)).collect();
    let gap_of = |n: usize| gaps.iter().position(|&(a, b)| a < n && n < b);

    // The holds each robot keeps: the task start, and every hold still usable on the new
    // problem (on a hold point, samples n − 1 and n high-confidence).
    let usable = problem.usable_holds();
    let kept: Vec<Vec<Hold>> = (0..n_robots)
        .map(|i| {
            previous
                .holds_of(i)
                .iter()
                .filter(|h| h.ref_idx == 0 || usable.binary_search(&h.ref_idx).is_ok())
                .cloned()
                .collect()
        })
        .collect();
    // Holds added where the robot keeps none in a gap but the problem has a usable one (the
    // gap's last), with `dwell_anywhere`.
    let mut added: Vec<Vec<usize>> = vec![Vec::new(); n_robots];
    let mut kept = kept;
    if dwell_anywhere {
        for (i, hs) in kept.iter_mut().enumerate() {
            for &(a, b) in &gaps {
                if hs.iter().any(|h| a < h.ref_idx && h.ref_idx < b) {
                    continue;
                }
                let last = usable.partition_point(|&n| n < b);
                if last > 0 && usable[last - 1] > a {
                    added[i].push(usable[last - 1]);
                    hs.push(Hold::at(usable[last - 1]));
                }
            }
            hs.sort_by_key(|h| h.ref_idx);
        }
    }
    let gap_held = |i: usize, g: usize| {
        kept[i]
            .iter()
            .any(|h| h.ref_idx > 0 && gap_of(h.ref_idx) == Some(g))
    };

    // Old departure time of every sample boundary, per robot (after a dwell at a hold there).
    let old_at: Vec<Vec<f64>> = (0..n_robots)
        .map(|i| {
            let holds = previous.holds_of(i);
            let mut c = previous.start_s(i);
            let mut h = 0;
            let mut at = Vec::with_capacity(n_ref + 1);
            for (n, &g) in previous.grad_exec[i].iter().enumerate() {
                while h < holds.len() && holds[h].ref_idx < n {
                    h += 1;
                }
                if h < holds.len() && holds[h].ref_idx == n {
                    c += holds[h].dwell_s;
                }
                at.push(c);
                c += g * dt;
            }
            at.push(c);
            at
        })
        .collect();

    // Variables: 0 the origin (robot 1's start), 1..N the starts of robots 2..N, then the
    // start of LC run k of robot i.
    const ORIGIN: usize = 0;
    let start_var = |i: usize| if i == 0 { ORIGIN } else { i };
    let lc_var = |i: usize, k: usize| n_robots + i * m + k;
    let n_vars = n_robots + n_robots * m;
    let mut edges: Vec<Edge> = Vec::with_capacity(4 * n_vars + 4);
    let mut push = |from: usize, to: usize, w: f64| edges.push(Edge { from, to, w });
    for (i, at) in old_at.iter().enumerate() {
        if i > 0 {
            push(ORIGIN, start_var(i), previous.start_s(i).max(0.0));
        }
        let mut prev = (start_var(i), 0.0);
        for (k, &(p, _)) in lc.iter().enumerate() {
            push(prev.0, lc_var(i, k), prev.1 + gap_lo[k]);
            if !gap_held(i, k) {
                push(lc_var(i, k), prev.0, -(prev.1 + gap_hi[k]));
            }
            push(ORIGIN, lc_var(i, k), at[p]);
            prev = (lc_var(i, k), lc_s[k]);
        }
    }
    // The old order of LC runs and the clearances between robots.
    let mut order: Vec<(f64, usize, usize)> = (0..n_robots)
        .flat_map(|i| (0..m).map(move |k| (i, k)))
        .map(|(i, k)| (old_at[i][lc[k].0], i, k))
        .collect();
    order.sort_by(|a, b| a.0.total_cmp(&b.0).then((a.1, a.2).cmp(&(b.1, b.2))));
    let named = |i: usize, k: usize, j: usize, l: usize| {
        pairs.iter().any(|pc| pc.prev == (i, k) && pc.cur == (j, l))
    };
    for w in order.windows(2) {
        let ((_, i, k), (start_s, j, l)) = (w[0], w[1]);
        if i != j {
            // A named pair's clearance is its own (below); the order stays.
            let clear_s = if set && named(i, k, j, l) {
                0.0
            } else {
                (start_s - old_at[i][lc[k].1]).max(0.0) + extra_clear_s
            };
            push(lc_var(i, k), lc_var(j, l), lc_s[k] + clear_s);
        }
    }
    for pc in pairs {
        let ((i, k), (j, l)) = (pc.prev, pc.cur);
        if i == j || i >= n_robots || j >= n_robots || k >= m || l >= m {
            continue;
        }
        let clear_s = if set {
            pc.extra_s.max(0.0)
        } else {
            (old_at[j][lc[l].0] - old_at[i][lc[k].1]).max(0.0) + pc.extra_s.max(0.0)
        };
        push(lc_var(i, k), lc_var(j, l), lc_s[k] + clear_s);
    }
    let x = match longest_paths(&edges, n_vars, 0.0) {
        Some(x) => x,
        None => longest_paths(&edges, n_vars, relax_tolerance(&edges, n_vars))?,
    };
    if x.iter().any(|v| !v.is_finite()) {
        return None;
    }

    // From the times to gradients and dwells.
    let mut warps = Vec::with_capacity(n_robots);
    let mut holds_out: Vec<Vec<Hold>> = kept.clone();
    for i in 0..n_robots {
        let old = &previous.grad_exec[i];
        let mut warp = gmean.to_vec();
        let mut free_s = x[start_var(i)];
        for g in 0..=m {
            let dur_s = if g < m {
                x[lc_var(i, g)] - free_s
            } else {
                let old_end = old_at[i][n_ref];
                let hi = if gap_held(i, g) {
                    f64::INFINITY
                } else {
                    gap_hi[g]
                };
                old_end.min(free_s + hi).max(free_s + gap_lo[g]) - free_s
            };
            let (a, b) = gaps[g];
            let dwell_s = fill(problem, old, &mut warp, (a, b), dur_s, gap_held(i, g));
            if dwell_s > 0.0 {
                spread_dwell(&mut holds_out[i], previous.holds_of(i), (a, b), dwell_s);
            } else {
                for h in holds_out[i]
                    .iter_mut()
                    .filter(|h| a < h.ref_idx && h.ref_idx < b)
                {
                    h.dwell_s = 0.0;
                }
            }
            if g < m {
                free_s = x[lc_var(i, g)] + lc_s[g];
            }
        }
        warps.push(warp);
    }
    for (hs, added) in holds_out.iter_mut().zip(&added) {
        hs.retain(|h| h.dwell_s > 0.0 || added.binary_search(&h.ref_idx).is_err());
    }
    if holds_out.iter().all(Vec::is_empty) {
        holds_out.clear();
    }
    let mut out = Schedule {
        grad_exec: warps,
        offsets_s: (1..n_robots).map(|i| x[start_var(i)]).collect(),
        tick_s,
        holds: holds_out,
    };
    // Constraint 2: no robot starts after every robot before it has ended. A robot pushed
    // past that (the serial schedule, whose robot 2 starts at robot 1's end, after robot 1's
    // runs lengthened) starts at the latest end instead, read from the same clock the check
    // reads, so "starts when the other ended" stays exact.
    for i in 1..n_robots {
        let latest_s = (0..i)
            .map(|j| out.end_s(j, dt))
            .fold(f64::NEG_INFINITY, f64::max);
        if out.offsets_s[i - 1] > latest_s {
            out.offsets_s[i - 1] = latest_s;
        }
    }
    Some(out)
}

/// Writes the gradients of the HC gap `a..b` into `warp` so that it lasts `dur_s` (s): the
/// old gradients `old` clamped into the problem's bounds, blended towards `ψ̇min` (to last
/// less) or `ψ̇max` (to last more) by one factor; with `held`, time beyond the clamped old
/// gradients is left as a dwell instead. Returns that dwell (s, ≥ 0).
fn fill(
    problem: &Problem,
    old: &[f64],
    warp: &mut [f64],
    (a, b): (usize, usize),
    dur_s: f64,
    held: bool,
) -> f64 {
    let dt = problem.dt_s();
    let (gmin, gmax) = (problem.grad_min(), problem.grad_max());
    for n in a..b {
        warp[n] = old[n].clamp(gmin[n], gmax[n]);
    }
    let g_s: f64 = warp[a..b].iter().sum::<f64>() * dt;
    if held && dur_s >= g_s {
        return dur_s - g_s;
    }
    let lo_s: f64 = gmin[a..b].iter().sum::<f64>() * dt;
    let hi_s: f64 = gmax[a..b].iter().sum::<f64>() * dt;
    if dur_s < g_s && g_s > lo_s {
        let lambda = ((g_s - dur_s) / (g_s - lo_s)).clamp(0.0, 1.0);
        for n in a..b {
            warp[n] = (warp[n] - lambda * (warp[n] - gmin[n])).clamp(gmin[n], gmax[n]);
        }
    } else if dur_s > g_s && hi_s > g_s {
        let lambda = ((dur_s - g_s) / (hi_s - g_s)).clamp(0.0, 1.0);
        for n in a..b {
            warp[n] = (warp[n] + lambda * (gmax[n] - warp[n])).clamp(gmin[n], gmax[n]);
        }
    }
    0.0
}

/// Sets the dwells of the holds of `holds` inside the gap `a..b` to `dwell_s` (s) in all: in
/// proportion to their old dwells in `old` when those add up to more than 0, else all on the
/// latest of them.
fn spread_dwell(holds: &mut [Hold], old: &[Hold], (a, b): (usize, usize), dwell_s: f64) {
    let inside = |h: &Hold| a < h.ref_idx && h.ref_idx < b;
    let old_dwell = |n: usize| {
        old.iter()
            .find(|h| h.ref_idx == n)
            .map_or(0.0, |h| h.dwell_s)
    };
    let total: f64 = holds
        .iter()
        .filter(|h| inside(h))
        .map(|h| old_dwell(h.ref_idx))
        .sum();
    let last = holds.iter().rposition(inside);
    for (q, h) in holds.iter_mut().enumerate() {
        if !inside(h) {
            continue;
        }
        h.dwell_s = if total > 0.0 {
            dwell_s * old_dwell(h.ref_idx) / total
        } else if Some(q) == last {
            dwell_s
        } else {
            0.0
        };
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::choose::repair;
    use crate::{SamplerParams, sample_schedule_n, validate};

    // `pegs`: the peg-in-hole problem the integration tests with hold points share.
    include!("../tests/common/pegs.rs");

    /// `p` after a model update that slowed its low-confidence samples by `factor` (the mean
    /// gradient times `factor`, the bounds widened to keep it inside), same confidence and holds.
    pub(crate) fn slowed(p: &Problem, factor: f64) -> Problem {
        let mean: Vec<f64> = (0..p.n_ref())
            .map(|n| p.grad_mean()[n] * if p.conf()[n] { 1.0 } else { factor })
            .collect();
        let lo = (0..p.n_ref())
            .map(|n| p.grad_min()[n].min(mean[n]))
            .collect();
        let hi = (0..p.n_ref())
            .map(|n| p.grad_max()[n].max(mean[n]))
            .collect();
        Problem::new(p.conf().to_vec(), mean, lo, hi, p.dt_s())
            .unwrap()
            .with_holds(p.holds().to_vec())
            .unwrap()
    }

    fn schedule(p: &Problem, n: usize, seed: u64) -> crate::Outcome {
        let params = SamplerParams {
            samples: 400,
            seed,
            tick_s: Some(0.05),
            ..SamplerParams::default()
        };
        sample_schedule_n(p, n, &params, None).unwrap()
    }

    /// The lengthening (s) of the low-confidence runs of one robot from `p` to `q`.
    fn lc_growth_s(p: &Problem, q: &Problem) -> f64 {
        (0..p.n_ref())
            .filter(|&n| !q.conf()[n])
            .map(|n| (q.grad_mean()[n] - p.grad_mean()[n]) * p.dt_s())
            .sum()
    }

    #[test]
    fn nothing_moves_when_nothing_changed() {
        for holds in [false, true] {
            let p = pegs(holds);
            for n in [2, 3] {
                let out = schedule(&p, n, 1);
                let again = retime(&p, &out.schedule, 0.05, 0.0).unwrap();
                assert_eq!(again.offsets_s, out.schedule.offsets_s);
                // The same times up to the rounding of re-summing the dwells.
                let t = again.t_total_s(p.dt_s());
                assert!((t - out.t_total_s).abs() <= 1e-12 * t, "{holds} {n}: {t}");
                validate(&p, &again).unwrap();
            }
        }
    }

    #[test]
    fn a_held_schedule_survives_a_slower_mean_where_the_plain_repair_fails() {
        // Cause 1 (docs/decisions.md, "Learning never makes the plan worse"): the exact optimum
        // with holds plans dwells that put one robot's insert right after the other's; the
        // model update slows the inserts by 3 %. The plain repair dropped the holds (and so the
        // release rules the schedule relied on); with its holds kept, the inserts, now longer,
        // overlap by what they grew. Re-timed, the order and the clearances hold.
        let p = pegs(true);
        // The held candidate itself (the scheduler's `Source::Held`): the margin-free optimum
        // with release rules, whose planned waits may let a sampled schedule win the race.
        let optimum = crate::solve_exact(&p, &crate::ExactParams::default())
            .unwrap()
            .schedule
            .expect("two robots: the search finishes");
        let held = p
            .with_release_rules(&Schedule {
                tick_s: 0.05,
                ..optimum
            })
            .unwrap();
        validate(&p, &held).unwrap();
        let out = crate::Outcome {
            t_total_s: held.t_total_s(p.dt_s()),
            ..schedule(&p, 2, 2)
        };
        let out = crate::Outcome {
            schedule: held,
            ..out
        };
        let q = slowed(&p, 1.03);
        let plain = repair(&q, &out.schedule, 0.05).unwrap();
        assert!(!plain.has_holds());
        assert!(validate(&q, &plain).is_err());
        // With its holds kept, whether the plain repair overlaps depends on the slack that the
        // release rules' planned waits leave (docs/decisions.md, "A plan is what the cell
        // does"); the re-timed schedule must be valid either way.
        let re = retime(&q, &out.schedule, 0.05, 0.0).unwrap();
        validate(&q, &re).unwrap();
        // Longer by at most what each insert grew, once per robot.
        let grown = lc_growth_s(&p, &q);
        let t = re.t_total_s(q.dt_s());
        assert!(
            t <= out.t_total_s + 2.0 * grown + 1e-9,
            "{t} vs {} + 2·{grown}",
            out.t_total_s
        );
    }

    #[test]
    fn a_schedule_at_its_margins_survives_a_slower_mean_where_the_plain_repair_fails() {
        // Cause 2: without holds, the margin-aware schedule keeps the least clearance the
        // margin check accepts between the robots' inserts; the plain repair lengthens the
        // inserts in place and eats it.
        let p = pegs(false);
        for (n, seed) in [(2, 3), (3, 3)] {
            let out = schedule(&p, n, seed);
            assert!(out.t_total_s < p.serial_schedule_n(n, 0.05).unwrap().t_total_s(p.dt_s()));
            let q = slowed(&p, 1.03);
            let plain = repair(&q, &out.schedule, 0.05).unwrap();
            assert!(validate(&q, &plain).is_err(), "{n} robots");
            // The scheduler's ladder of extra clearances (0, M, 4M): the first that passes.
            let step_s = crate::choose::max_step_s(&q, 0.05);
            let (extra, re) = [0.0, step_s, 4.0 * step_s]
                .into_iter()
                .filter_map(|x| Some((x, retime(&q, &out.schedule, 0.05, x)?)))
                .find(|(_, s)| validate(&q, s).is_ok())
                .expect("a re-timing passes");
            // At most every robot's growth pushed along the whole chain (counted twice over),
            // plus the extra clearance at every switch of robots.
            let grown = lc_growth_s(&p, &q);
            let switches = (2 * n - 1) as f64;
            let t = re.t_total_s(q.dt_s());
            assert!(
                t <= out.t_total_s + 2.0 * n as f64 * grown + switches * extra + 1e-9,
                "{n} robots: {t} vs {} (+{grown} per robot, extra {extra})",
                out.t_total_s
            );
        }
    }

    #[test]
    fn a_faster_mean_never_lengthens_the_schedule() {
        for holds in [false, true] {
            let p = pegs(holds);
            let out = schedule(&p, 2, 4);
            let q = slowed(&p, 0.97);
            let re = retime(&q, &out.schedule, 0.05, 0.0).unwrap();
            validate(&q, &re).unwrap();
            assert!(re.t_total_s(q.dt_s()) <= out.t_total_s + 1e-9);
        }
    }
}
