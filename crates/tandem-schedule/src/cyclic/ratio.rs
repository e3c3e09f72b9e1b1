//! The maximum cycle ratio of an event graph: the least period `P` of a 1-periodic schedule.
//!
//! An [`Arc`] `u → v` of weight `w` (s) carrying `h` tokens is the constraint
//! `t[v] ≥ t[u] + w − P·h` on the event times `t` (s) of one period: the occurrence of `v` in
//! period `p + h` is at least `w` after the occurrence of `u` in period `p`. A period `P` is
//! feasible when such times exist, i.e. when no cycle has positive weight under the weights
//! `w − P·h`. For a cycle `C` with `h(C) = Σh` and `w(C) = Σw` that is `P ≥ w(C)/h(C)` when
//! `h(C) > 0`, `w(C) ≤ 0` when `h(C) = 0`, and `P ≤ w(C)/h(C)` when `h(C) < 0` (a maximum
//! time lag across a period boundary). So the feasible periods are an interval whose least
//! point is the maximum cycle ratio `max_{h(C) > 0} w(C)/h(C)`, if that point is feasible.
//!
//! **Method (parametric, exact in finitely many steps).** [`max_cycle_ratio`] starts from a
//! `λ₀` below every cycle ratio and repeats: find a cycle of positive weight under
//! `w − λ·h` (Bellman–Ford longest paths with the predecessor graph checked for a cycle after
//! every pass); if there is none, `λ` is feasible and the Bellman–Ford distances are the
//! event times that prove it; if the cycle has `h(C) > 0`, set `λ` to its ratio `w(C)/h(C)`,
//! which is strictly larger than `λ`; if `h(C) ≤ 0`, no period is feasible. Every `λ` after
//! the first is the ratio of a cycle, so it is a lower bound on every feasible period, and a
//! cycle with `h(C) ≤ 0` that is positive at `λ` is positive at every `P ≥ λ`: the
//! infeasibility is proven. The ratios strictly increase and the cycles found are simple
//! (there are finitely many), so the loop ends, and it ends at a `λ` that is both a cycle
//! ratio (a lower bound) and feasible: the least period. This is Dinkelbach's (Newton's) method
//! for fractional programs with a cycle oracle (Dasdan 2004 compares it with Howard's policy
//! iteration, which is faster on large graphs; the graphs here have tens of events). Unlike
//! Howard's method it needs no special case for arcs with negative tokens. Equalities are
//! decided with a relative tolerance of `1e-12` of the sum of `|w − λ·h|` (rounding of the
//! sums), so "exact" means exact up to that rounding.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// One arc of an event graph: the constraint `t[to] ≥ t[from] + weight_s − P·tokens` on the
/// event times `t` (s) of one period of length `P` (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Arc {
    /// The earlier event (node index).
    pub from: usize,
    /// The later event (node index).
    pub to: usize,
    /// The least time lag (s, schedule clock) from `from` to `to`; negative for a maximum lag
    /// written as a backward arc (`t[from] ≥ t[to] − max` is the arc `to → from`, weight
    /// `−max`). Finite.
    pub weight_s: f64,
    /// Periods between the two occurrences: 0 (same period), 1 (`to` in the next period), or
    /// `−1` for a backward maximum-lag arc across a period boundary.
    pub tokens: i32,
}

/// The result of [`max_cycle_ratio`]: the least feasible period, the cycle that fixes it and
/// event times that satisfy every arc at that period.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CycleRatio {
    /// The least feasible period `P` (s): `w(C)/h(C)` of [`CycleRatio::critical`].
    pub period_s: f64,
    /// A critical cycle: arc indices in the order they are traversed (the `to` of each is the
    /// `from` of the next); its ratio is `period_s`, so it is tight (weight 0 under
    /// `w − P·h`).
    pub critical: Vec<usize>,
    /// Event times (s, one period's frame), one per node, least is 0: `t[to] ≥ t[from] + w −
    /// P·h` for every arc up to the rounding tolerance (the potential that proves `P`
    /// feasible). They are the least such times that are ≥ 0 (longest paths from a virtual
    /// source).
    pub times_s: Vec<f64>,
    /// Bellman–Ford runs (cycle-ratio updates plus the final feasibility proof).
    pub iterations: usize,
}

/// Relative tolerance of a positive cycle (module docs).
const REL_TOL: f64 = 1e-12;

/// The least period `P` (s) such that event times satisfy every arc of `arcs` on `n_nodes`
/// events (module docs): the maximum cycle ratio over cycles with tokens, its critical cycle
/// and the event times that prove it feasible.
///
/// # Errors
/// - [`Error::BadArc`] for an arc with a node `≥ n_nodes` or a non-finite weight;
/// - [`Error::NoTokenCycle`] when no cycle carries a positive number of tokens (and none is
///   infeasible): the period is not bounded below;
/// - [`Error::InfeasibleCycle`] with a cycle that no period satisfies: `Σh = 0` and `Σw > 0`
///   (e.g. contradictory exact durations), or `Σh < 0` with a ratio below that of a cycle with
///   tokens (maximum lags that the least period already breaks);
/// - [`Error::BadArc`] naming arc 0 if the longest paths do not settle within `2n + 2`
///   passes without a cycle in the predecessor graph, which only rounding of weights many
///   orders of magnitude apart can cause.
pub fn max_cycle_ratio(n_nodes: usize, arcs: &[Arc]) -> Result<CycleRatio> {
    for (i, a) in arcs.iter().enumerate() {
        if a.from >= n_nodes || a.to >= n_nodes {
            return Err(Error::BadArc {
                arc: i,
                why: "names a node that does not exist",
            });
        }
        if !a.weight_s.is_finite() {
            return Err(Error::BadArc {
                arc: i,
                why: "has a weight that is not finite",
            });
        }
    }
    // Below the ratio of every simple cycle with tokens: |w(C)| ≤ Σ|w| and h(C) ≥ 1.
    let mut lambda = -(arcs.iter().map(|a| a.weight_s.abs()).sum::<f64>() + 1.0);
    let mut critical: Vec<usize> = Vec::new();
    let mut scratch = Scratch::new(n_nodes);
    let mut iterations = 0;
    loop {
        iterations += 1;
        match positive_cycle(n_nodes, arcs, lambda, &mut scratch)? {
            None => {
                if critical.is_empty() {
                    return Err(Error::NoTokenCycle);
                }
                let min = scratch.dist.iter().copied().fold(f64::INFINITY, f64::min);
                let times_s = scratch.dist.iter().map(|d| d - min).collect();
                return Ok(CycleRatio {
                    period_s: lambda,
                    critical,
                    times_s,
                    iterations,
                });
            }
            Some(cycle) => {
                let w: f64 = cycle.iter().map(|&i| arcs[i].weight_s).sum();
                let h: i64 = cycle.iter().map(|&i| i64::from(arcs[i].tokens)).sum();
                if h <= 0 {
                    return Err(Error::InfeasibleCycle {
                        arcs: cycle,
                        weight_s: w,
                        tokens: h,
                    });
                }
                let ratio = w / h as f64;
                if ratio <= lambda {
                    // Positive only by rounding: treat λ as feasible on the next run with
                    // this cycle as the critical one (cannot loop: λ does not change, so the
                    // same tolerance applies and the cycle is found again only if rounding
                    // keeps it above; guard by giving up on further increase).
                    return finish(n_nodes, arcs, lambda, cycle, iterations, &mut scratch);
                }
                lambda = ratio;
                critical = cycle;
            }
        }
    }
}

/// The final answer at `lambda` when a cycle is positive only by rounding: the distances of a
/// Bellman–Ford run with the cycle's excess tolerated.
fn finish(
    n_nodes: usize,
    arcs: &[Arc],
    lambda: f64,
    critical: Vec<usize>,
    iterations: usize,
    scratch: &mut Scratch,
) -> Result<CycleRatio> {
    // Bounded passes: the distances of the last pass are a potential up to the rounding.
    scratch.reset();
    let tol = tolerance(arcs, lambda) * 4.0;
    for _ in 0..=n_nodes {
        let mut changed = false;
        for a in arcs {
            let c = scratch.dist[a.from] + a.weight_s - lambda * f64::from(a.tokens);
            if c > scratch.dist[a.to] + tol {
                scratch.dist[a.to] = c;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    let min = scratch.dist.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(CycleRatio {
        period_s: lambda,
        critical,
        times_s: scratch.dist.iter().map(|d| d - min).collect(),
        iterations: iterations + 1,
    })
}

/// Event times (s, the least 0) of a 1-periodic schedule at the given period `period_s` (s):
/// Bellman–Ford longest paths under the weights `w − P·h`, with the rounding tolerance of
/// [`max_cycle_ratio`]; `None` when a cycle is positive at that period (it is not feasible,
/// e.g. above a maximum time lag across the period boundary).
pub(crate) fn times_at(n_nodes: usize, arcs: &[Arc], period_s: f64) -> Option<Vec<f64>> {
    let mut dist = vec![0.0_f64; n_nodes];
    let tol = tolerance(arcs, period_s) * 4.0;
    for _ in 0..=n_nodes {
        let mut changed = false;
        for a in arcs {
            let c = dist[a.from] + a.weight_s - period_s * f64::from(a.tokens);
            if c > dist[a.to] + tol {
                dist[a.to] = c;
                changed = true;
            }
        }
        if !changed {
            let min = dist.iter().copied().fold(f64::INFINITY, f64::min);
            return Some(dist.iter().map(|d| d - min).collect());
        }
    }
    None
}

fn tolerance(arcs: &[Arc], lambda: f64) -> f64 {
    let scale: f64 = arcs
        .iter()
        .map(|a| (a.weight_s - lambda * f64::from(a.tokens)).abs())
        .sum();
    REL_TOL * scale.max(1e-300)
}

/// Buffers of one Bellman–Ford run.
struct Scratch {
    dist: Vec<f64>,
    pred: Vec<usize>,
    mark: Vec<usize>,
}

const NONE: usize = usize::MAX;

impl Scratch {
    fn new(n: usize) -> Scratch {
        Scratch {
            dist: vec![0.0; n],
            pred: vec![NONE; n],
            mark: vec![NONE; n],
        }
    }
    fn reset(&mut self) {
        self.dist.fill(0.0);
        self.pred.fill(NONE);
    }
}

/// A cycle of positive weight under `w − λ·h` (arc indices in traversal order), or `None`
/// with `scratch.dist` a potential: longest paths from a virtual source joined to every node
/// by an arc of weight 0.
fn positive_cycle(
    n_nodes: usize,
    arcs: &[Arc],
    lambda: f64,
    scratch: &mut Scratch,
) -> Result<Option<Vec<usize>>> {
    scratch.reset();
    let tol = tolerance(arcs, lambda);
    // Without a positive cycle the distances settle within n passes; with one the
    // predecessor graph has a cycle by then (each pass is checked). The cap only guards
    // against rounding.
    for _ in 0..(2 * n_nodes + 2) {
        let mut changed = false;
        for (i, a) in arcs.iter().enumerate() {
            let c = scratch.dist[a.from] + a.weight_s - lambda * f64::from(a.tokens);
            if c > scratch.dist[a.to] + tol {
                scratch.dist[a.to] = c;
                scratch.pred[a.to] = i;
                changed = true;
            }
        }
        if !changed {
            return Ok(None);
        }
        if let Some(cycle) = pred_cycle(arcs, scratch) {
            return Ok(Some(cycle));
        }
    }
    Err(Error::BadArc {
        arc: 0,
        why: "weights too large for the longest-path search to settle (rounding)",
    })
}

/// A cycle of the predecessor graph (each node's last relaxing arc), arcs in traversal order.
fn pred_cycle(arcs: &[Arc], scratch: &mut Scratch) -> Option<Vec<usize>> {
    let n = scratch.pred.len();
    scratch.mark.fill(NONE);
    for start in 0..n {
        if scratch.mark[start] != NONE {
            continue;
        }
        // Walk back along predecessors, marking with this walk's id.
        let mut v = start;
        while scratch.mark[v] == NONE {
            scratch.mark[v] = start;
            match scratch.pred[v] {
                NONE => break,
                i => v = arcs[i].from,
            }
        }
        if scratch.mark[v] == start && scratch.pred[v] != NONE {
            // v is on a cycle found by this walk: collect it.
            let mut cycle = Vec::new();
            let mut u = v;
            loop {
                let i = scratch.pred[u];
                cycle.push(i);
                u = arcs[i].from;
                if u == v {
                    break;
                }
            }
            cycle.reverse();
            return Some(cycle);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(from: usize, to: usize, weight_s: f64, tokens: i32) -> Arc {
        Arc {
            from,
            to,
            weight_s,
            tokens,
        }
    }

    #[test]
    fn a_self_loop_is_its_weight() {
        let r = max_cycle_ratio(1, &[arc(0, 0, 3.5, 1)]).unwrap();
        assert_eq!(r.period_s, 3.5);
        assert_eq!(r.critical, vec![0]);
        assert_eq!(r.times_s, vec![0.0]);
    }

    #[test]
    fn pred_walk_that_ends_at_a_root_is_not_a_cycle() {
        // The walk from node 1 stops at node 0 (no predecessor): no cycle.
        let arcs = [arc(0, 1, 1.0, 0)];
        let mut s = Scratch::new(2);
        s.pred[1] = 0;
        assert!(pred_cycle(&arcs, &mut s).is_none());
    }
}
