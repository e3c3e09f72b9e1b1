//! The cyclic plan of one operator order: the event graph's least period laid out per robot.

use serde::{Deserialize, Serialize};

use super::graph::{EventGraph, Stretch, TaskShape, event_graph, graph_of_shape};
use super::ratio::max_cycle_ratio;
use crate::problem::check_robot_count;
use crate::{Problem, Result};

/// A repeated (1-periodic) plan of `N` robots repeating one task with one operator (module
/// docs of [`crate::cyclic`]): every period of `period_s` seconds each robot does one task and
/// the operator supervises the `N·m` low-confidence stretches once each, in `order`.
///
/// Times are schedule-clock seconds. The period assumes that the operator follows `ψ̇̄` on
/// low-confidence stretches and that the robots run at their planned rates. At run time
/// [`CyclicPlan::coordinator`] runs it soundly under any drift by the token rule (robots wait
/// at gates instead of relying on margins), for a runnable order; the period is then not
/// guaranteed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CyclicPlan {
    /// Number of robots `N` (`1..=MAX_ROBOTS`).
    pub n_robots: usize,
    /// The operator's cyclic order of low-confidence stretches within one period (empty for a
    /// task without low confidence).
    pub order: Vec<Stretch>,
    /// The least period `P` (s) of this order: `N` tasks per period.
    pub period_s: f64,
    /// Duration (s) of each low-confidence stretch at `ψ̇̄`, by stretch index.
    pub lc_s: Vec<f64>,
    /// Per robot, the task that starts in period 0 (it repeats every `period_s`).
    pub robots: Vec<RobotCycle>,
    /// Throughput (tasks per hour): `3600·N/P`.
    pub tasks_per_hour: f64,
    /// The operator's busy share: `N·L/P` in `[0, 1]`, `L` the task's total low-confidence
    /// duration at `ψ̇̄`.
    pub operator_share: f64,
    /// A lower bound (s) on the period of every 1-periodic plan of `N` robots, whatever the
    /// order: [`period_lower_bound_s`]; for a plan searched with the hand-overs counted
    /// ([`crate::CyclicParams::handover_tick_s`]) among runnable orders, the bound of every
    /// such plan, [`handover_bound_s`] (at least the former); with a switch time
    /// ([`crate::CyclicParams::switch_s`] `> 0`) also at least
    /// [`period_lower_bound_with_switch_s`] and the chain bound (each interval before a stretch
    /// a switch or the robot's own gap, whichever is shorter; docs/decisions.md, "The
    /// continuous cell's chain bound with the switch time (issue 41)"), and with a load cap its
    /// bound.
    pub lower_bound_s: f64,
    /// `period_s / lower_bound_s − 1` (0 when the plan is at the bound, up to rounding).
    pub gap: f64,
    /// Whether `order` is the best of all orders (the search enumerated every order, or every
    /// order up to the first whose period meets `lower_bound_s`, which no order beats), so
    /// `period_s` is the least period of every 1-periodic plan; `false` for a given order or
    /// a heuristic search.
    pub order_exhaustive: bool,
    /// Orders whose period was computed to choose this one (1 for a given order; the search
    /// stops at an order whose period meets `lower_bound_s`).
    pub orders_evaluated: usize,
}

/// One robot's task within a [`CyclicPlan`] (schedule clock, s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotCycle {
    /// When it leaves its task start (reference sample 0) for the task of period 0: its phase,
    /// in `[0, P)`.
    pub start_s: f64,
    /// When it enters each low-confidence stretch of that task (≥ `start_s`, possibly past
    /// `P` when the task straddles the period's end; the phase is this modulo `P`).
    pub lc_start_s: Vec<f64>,
    /// Its high-confidence gaps as planned (see `TaskShape::gaps`: head, between stretches,
    /// tail), with the waits at hold points.
    pub gaps: Vec<GapPlan>,
    /// The wait (s) at the task start before `start_s`: the period minus the task as planned
    /// (tail at its fastest), so that its next task starts `P` later.
    pub start_wait_s: f64,
}

/// One high-confidence gap of a robot's task as planned.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GapPlan {
    /// Its planned duration (s), between `Σψ̇min·Δt_s` and `Σψ̇max·Δt_s`, or more with a hold.
    pub duration_s: f64,
    /// The part of it spent waiting at `hold` (s): what exceeds `Σψ̇max·Δt_s` (the robot
    /// slows to `ψ̇max` first); 0 without a hold.
    pub wait_s: f64,
    /// The hold point where it waits (reference sample), if the gap has one.
    pub hold: Option<usize>,
}

/// A lower bound (s) on the period of every 1-periodic plan of `n_robots` robots on `problem`,
/// whatever the operator order: `max(N·(L + I), D_min)` ([`TaskShape::lc_total_s`],
/// [`TaskShape::idle_s`], [`TaskShape::fastest_s`]). Divided by `k` it also bounds the period
/// per task and robot of a plan with `k` tasks per robot per period.
///
/// **Why.**
/// 1. In one period the operator supervises every robot's every low-confidence stretch once,
///    each for its fixed duration at `ψ̇̄`, one at a time: `N·L` seconds.
/// 2. Let `G = (g₁, g₂)` be a gap of robot `r` between two of its stretches, without a hold
///    and lasting at most `Σψ̇max·Δt_s < L_min` (the shortest stretch). No stretch of another
///    robot meets `G`: one that crossed `g₁` or `g₂` would overlap `r`'s stretch ending at
///    `g₁` or starting at `g₂`, and one inside `G` would be shorter than `L_min`. So the
///    operator is idle during `G`, for at least its fastest duration. Two such gaps of
///    different robots are disjoint: if `g₁ ≤ h₁ < g₂` for another's gap `(h₁, h₂)`, that
///    robot's stretch ending at `h₁` meets `G` (or, when `h₁ = g₁`, overlaps `r`'s stretch
///    ending at the same instant). So the operator is idle at least `N·I` per period, and
///    busy `N·L`: `P ≥ N·(L + I)`. (The head and the tail are not counted: a robot may wait
///    at its task start instead.)
/// 3. Each robot does one task per period and starts its next only after the last one's
///    end; a task takes at least `D_min` (every high-confidence sample at `ψ̇min`,
///    low-confidence ones at `ψ̇̄`): `P ≥ D_min` (the robot's cycle of the event graph).
///
/// None of these uses the order, so they bound every order, and they count per task, so
/// they bound plans with more tasks per robot per period as well.
///
/// # Errors
/// [`crate::Error::Realtime`] (`RobotCount`) for `n_robots` outside `1..=MAX_ROBOTS`.
pub fn period_lower_bound_s(problem: &Problem, n_robots: usize) -> Result<f64> {
    check_robot_count(n_robots)?;
    Ok(bound_of(&TaskShape::new(problem), n_robots))
}

pub(crate) fn bound_of(shape: &TaskShape, n_robots: usize) -> f64 {
    (n_robots as f64 * (shape.lc_total_s() + shape.idle_s())).max(shape.fastest_s())
}

/// [`period_lower_bound_s`] with the operator's switch time `switch_s` (real s, ≥ 0): for
/// `N ≥ 2` robots and `m ≥ 1` stretches, `max(N·(L + I + δ), D_min)`; otherwise
/// [`period_lower_bound_s`].
///
/// **Why.** One period of the operator is its `N·m` stretches and the intervals between
/// consecutive ones (cyclically). Each robot's stretches form at least one block of the cyclic
/// order, so with `N ≥ 2` robots the robot changes at least `N` times around the cycle, and each
/// change's interval lasts at least `δ`. The forced idle gaps of `I` (item 2 of
/// [`period_lower_bound_s`]) lie between two consecutive stretches of one robot (no other
/// robot's stretch meets them), so they are other intervals than the changes: the three sums
/// add, `P ≥ N·L + N·I + N·δ`. `P ≥ D_min` as before.
///
/// # Errors
/// [`crate::Error::BadParam`] for `n_robots` outside `1..=MAX_ROBOTS` or a `switch_s` not
/// finite and ≥ 0.
pub fn period_lower_bound_with_switch_s(
    problem: &Problem,
    n_robots: usize,
    switch_s: f64,
) -> Result<f64> {
    check_robot_count(n_robots)?;
    if !(switch_s.is_finite() && switch_s >= 0.0) {
        return Err(crate::Error::BadParam {
            name: "switch_s",
            why: "must be finite and >= 0 (the operator's switch time in seconds; 0 for none)",
        });
    }
    Ok(switch_bound_of(
        &TaskShape::new(problem),
        n_robots,
        switch_s,
    ))
}

/// The least period (s) at which the operator's busy share of `order` is at most
/// `max_busy_share`: `(N·L + c·δ)/u_max`, `c` the changes of robot around the cyclic order
/// (each costs the switch time `δ` of the operator's attention).
fn capped_period_s(
    graph: &EventGraph,
    n_robots: usize,
    order: &[Stretch],
    switch_s: f64,
    max_busy_share: f64,
) -> f64 {
    let len = order.len();
    let changes = (0..len)
        .filter(|&q| order[q].robot != order[(q + 1) % len].robot)
        .count();
    (n_robots as f64 * graph.shape.lc_total_s() + changes as f64 * switch_s) / max_busy_share
}

/// The load cap's bound (s): every plan whose busy share, switches included, is at most
/// `max_busy_share` has `P ≥ (N·L + c·δ)/u_max` with `c ≥ N` changes of robot for `N ≥ 2`
/// (the argument of [`period_lower_bound_with_switch_s`]), `c ≥ 0` for one robot.
fn cap_bound_of(shape: &TaskShape, n_robots: usize, switch_s: f64, max_busy_share: f64) -> f64 {
    let changes = if n_robots >= 2 && shape.n_lc() > 0 {
        n_robots as f64
    } else {
        0.0
    };
    (n_robots as f64 * shape.lc_total_s() + changes * switch_s) / max_busy_share
}

/// [`period_lower_bound_with_switch_s`] of a task shape.
pub(crate) fn switch_bound_of(shape: &TaskShape, n_robots: usize, switch_s: f64) -> f64 {
    if switch_s > 0.0 && n_robots >= 2 && shape.n_lc() > 0 {
        (n_robots as f64 * (shape.lc_total_s() + shape.idle_s() + switch_s)).max(shape.fastest_s())
    } else {
        bound_of(shape, n_robots)
    }
}

/// A lower bound (s) on the period of every 1-periodic plan of `n_robots` robots on
/// `problem` whose order is runnable ([`crate::cyclic::is_runnable`]) and whose hand-overs
/// are counted at the control tick `tick_s` ([`crate::CyclicParams::handover_tick_s`]):
/// for `N ≥ 2`, `max(N·(Σ_g (S_g + E_g) + tick_s), D_min)` over the task's groups `g` (its
/// stretches between two usable holds), `S_g` the group's span at its fastest (its
/// stretches at `ψ̇̄` and the gaps between them at `ψ̇min`), `E_g` the travel from its gate
/// to its first stretch ([`TaskShape::entry_s`]); for one robot, [`period_lower_bound_s`].
/// It is at least [`period_lower_bound_s`] (the spans hold every stretch and every gap that
/// `I` counts).
///
/// **Why.** In a runnable order each group's stretches are consecutive, so from the start of
/// a group's first stretch to the end of its last the operator supervises that group only,
/// for at least `S_g` (the robot's own arcs). From there to the start of the next entry of
/// the order, a group `h`: if `h` is another robot's, the hand-over arc gives `E_h + tick_s`;
/// if it is the same robot's (its next group, or group 0 of its next task through the task
/// start), the robot's own arc gives at least the gap before `h` at its fastest, which holds
/// the travel from `h`'s gate: `≥ E_h`. Summed around one period, which holds every group of
/// every robot once, `P ≥ N·Σ_g (S_g + E_g) + c·tick_s`, where `c ≥ N` is the number of
/// robot changes in the order (each robot's entries form at least one block when `N ≥ 2`).
/// And `P ≥ D_min` as before.
///
/// # Errors
/// [`crate::Error::Realtime`] (`RobotCount`) for `n_robots` outside `1..=MAX_ROBOTS`.
pub fn handover_bound_s(problem: &Problem, n_robots: usize, tick_s: f64) -> Result<f64> {
    check_robot_count(n_robots)?;
    Ok(handover_bound_of(
        &TaskShape::new(problem),
        n_robots,
        tick_s,
    ))
}

pub(crate) fn handover_bound_of(shape: &TaskShape, n_robots: usize, tick_s: f64) -> f64 {
    let old = bound_of(shape, n_robots);
    let m = shape.n_lc();
    if n_robots < 2 || m == 0 {
        return old;
    }
    (n_robots as f64 * (groups_per_task_s(shape) + tick_s)).max(old)
}

/// `Σ_g (S_g + E_g)` (s): every stretch, every gap inside a group, every group's entry.
pub(crate) fn groups_per_task_s(shape: &TaskShape) -> f64 {
    (0..shape.n_lc())
        .map(|k| {
            let before = if shape.opens_group(k) {
                shape.entry_s[k]
            } else {
                shape.gaps[k].min_s
            };
            shape.lc_s[k] + before
        })
        .sum()
}

/// [`handover_bound_of`] with the operator's switch time `switch_s > 0`, for plans whose
/// operator arcs into another robot's group carry `max(E_h + tick, δ)`
/// ([`crate::CyclicParams::switch_s`]): `max(N·(Σ_g (S_g + E_g) + min_h max(tick, δ − E_h)),
/// N·(L + I + δ), D_min)`. The argument of [`handover_bound_s`] with each of the `c ≥ N`
/// changes of robot costing `max(E_h + tick, δ) = E_h + max(tick, δ − E_h)` instead of
/// `E_h + tick`, `h` the group it enters (in a runnable order a change enters a group at its
/// first stretch).
fn handover_switch_bound_of(shape: &TaskShape, n_robots: usize, tick_s: f64, switch_s: f64) -> f64 {
    let old = switch_bound_of(shape, n_robots, switch_s);
    let m = shape.n_lc();
    if n_robots < 2 || m == 0 {
        return old;
    }
    let per_change = (0..m)
        .filter(|&k| shape.opens_group(k))
        .map(|k| tick_s.max(switch_s - shape.entry_s[k]))
        .fold(f64::INFINITY, f64::min);
    let per_change = if per_change.is_finite() {
        per_change
    } else {
        tick_s
    };
    (n_robots as f64 * (groups_per_task_s(shape) + per_change)).max(old)
}

/// The chain bound (s) with the operator's switch time `switch_s > 0`: for `N ≥ 2` robots and
/// `m ≥ 1` stretches, `max(N·(L + Σ_k min(C_k, G_k) + max(0, min_k (C_k − G_k))), D_min)`, where
/// for the interval before stretch `k` of a robot `G_k` is the robot's own least time from
/// its previous stretch (gap `k` at its fastest; for `k = 0` the tail and the head of the next
/// task) and `C_k` the least time after another robot's stretch: the switch time `δ`, or
/// `max(δ, E_k + tick)` when the hand-overs are counted at `handover_tick_s` and `k` opens a
/// group ([`crate::CyclicParams::switch_s`]); `∞` where no other robot's stretch can come
/// before it (a gap without a usable hold too short, even at its slowest, for the shortest
/// stretch; with `runnable`, any `k` inside a group).
///
/// **Why** (docs/decisions.md, "The continuous cell's chain bound with the switch time (issue
/// 41)"). Around one period the operator supervises the `N·m` stretches once each, in the
/// cyclic order, with an interval before each: `P = N·L + Σ intervals`. The stretch before
/// robot `r`'s stretch `k` in the order is either `r`'s own previous stretch (each robot's
/// stretches come in task order around the cycle), and then the robot's arcs make the
/// interval at least `G_k`; or another robot's, and then the operator arc makes it at least
/// `C_k`. So each interval is at least `min(C_k, G_k)`, and with `N ≥ 2` robots each robot's
/// stretches are entered from another robot at least once per period, which costs
/// `C_k − G_k` more at one `k` when every `C_k` exceeds its `G_k`. The intervals are
/// disjoint, one per stretch, so the per-robot sums add. At `δ = 0` without hand-overs it is
/// `N·(L + I)` ([`period_lower_bound_s`]); it is at least [`period_lower_bound_with_switch_s`]
/// (every `min(C_k, G_k)` is at least `G_k` on a forced idle gap and at least 0 elsewhere, and
/// the extra term, with the `min` terms that take `C_k`, gives at least one `δ` per robot) and,
/// with the hand-overs, than [`handover_bound_s`]'s argument with the switch time
/// (`G_k ≥ E_k` for a group's first stretch, `G_k = ` the in-group gap otherwise).
pub(crate) fn chain_switch_bound_of(
    shape: &TaskShape,
    n_robots: usize,
    switch_s: f64,
    handover_tick_s: Option<f64>,
    runnable: bool,
) -> f64 {
    let m = shape.n_lc();
    if n_robots < 2 || m == 0 {
        return bound_of(shape, n_robots);
    }
    let shortest = shape.lc_s.iter().copied().fold(f64::INFINITY, f64::min);
    let (mut sum, mut extra) = (0.0, f64::INFINITY);
    for k in 0..m {
        let own = if k == 0 {
            shape.gaps[m].min_s + shape.gaps[0].min_s
        } else {
            shape.gaps[k].min_s
        };
        let gap = shape.gaps[k];
        let closed = k >= 1 && gap.hold.is_none() && (runnable || gap.max_s < shortest);
        let other = if closed {
            f64::INFINITY
        } else {
            match handover_tick_s {
                Some(tick_s) if shape.opens_group(k) => switch_s.max(shape.entry_s[k] + tick_s),
                _ => switch_s,
            }
        };
        sum += own.min(other);
        extra = extra.min((other - own).max(0.0));
    }
    (n_robots as f64 * (shape.lc_total_s() + sum + extra)).max(shape.fastest_s())
}

/// The cyclic plan of `n_robots` robots on `problem` with the operator's cyclic order `order`
/// (each robot's stretches in task order around the cycle, starting anywhere): the least
/// period of its event graph ([`event_graph`], [`max_cycle_ratio`]) and each robot's times.
///
/// # Errors
/// [`crate::Error::BadParam`] for `n_robots` or a malformed order;
/// [`crate::Error::InfeasibleCycle`] when no period admits the order (it would need a robot
/// to wait inside a gap without a hold point).
pub fn cyclic_plan_for_order(
    problem: &Problem,
    n_robots: usize,
    order: &[Stretch],
) -> Result<CyclicPlan> {
    plan_for_order(problem, n_robots, order, None, false, 0.0, 1.0)
}

/// [`cyclic_plan_for_order`], counting the token rule's hand-overs at the control tick
/// `handover_tick_s` when given ([`crate::CyclicParams::handover_tick_s`]); with
/// `runnable_only` (the order was searched among runnable orders) and a tick, the plan's
/// bound is [`handover_bound_s`].
pub(crate) fn plan_for_order(
    problem: &Problem,
    n_robots: usize,
    order: &[Stretch],
    handover_tick_s: Option<f64>,
    runnable_only: bool,
    switch_s: f64,
    max_busy_share: f64,
) -> Result<CyclicPlan> {
    let graph = match (handover_tick_s, switch_s > 0.0) {
        (None, false) => event_graph(problem, n_robots, order)?,
        _ => graph_of_shape(
            TaskShape::new(problem),
            n_robots,
            order,
            handover_tick_s,
            switch_s,
        )?,
    };
    let mut ratio = max_cycle_ratio(graph.events.len(), &graph.arcs)?;
    if max_busy_share < 1.0 {
        let capped = capped_period_s(&graph, n_robots, order, switch_s, max_busy_share);
        if capped > ratio.period_s {
            ratio.times_s = super::ratio::times_at(graph.events.len(), &graph.arcs, capped).ok_or(
                crate::Error::BadParam {
                    name: "max_busy_share",
                    why: "no period of this order keeps the operator's busy share under the cap \
                          (a robot would wait too long inside a gap without a hold point)",
                },
            )?;
            ratio.period_s = capped;
        }
    }
    let lower_bound_s = plan_bound_of(
        &graph.shape,
        n_robots,
        handover_tick_s,
        runnable_only,
        switch_s,
        max_busy_share,
    );
    Ok(layout(
        &graph,
        n_robots,
        order,
        ratio.period_s,
        &ratio.times_s,
        lower_bound_s,
    ))
}

/// The lower bound (s) on the period of every order of a plan searched with these parameters
/// ([`plan_for_order`]'s `lower_bound_s`): [`handover_bound_s`] for runnable orders with the
/// hand-overs counted, else [`period_lower_bound_s`]; raised by the switch time's bounds and
/// the load cap's when they are set.
pub(crate) fn plan_bound_of(
    shape: &TaskShape,
    n_robots: usize,
    handover_tick_s: Option<f64>,
    runnable_only: bool,
    switch_s: f64,
    max_busy_share: f64,
) -> f64 {
    let lower_bound_s = match handover_tick_s {
        Some(tick_s) if runnable_only && switch_s > 0.0 => {
            handover_switch_bound_of(shape, n_robots, tick_s, switch_s)
        }
        Some(tick_s) if runnable_only => handover_bound_of(shape, n_robots, tick_s),
        _ => bound_of(shape, n_robots),
    };
    let lower_bound_s = if switch_s > 0.0 {
        lower_bound_s
            .max(switch_bound_of(shape, n_robots, switch_s))
            .max(chain_switch_bound_of(
                shape,
                n_robots,
                switch_s,
                handover_tick_s,
                handover_tick_s.is_some() && runnable_only,
            ))
    } else {
        lower_bound_s
    };
    if max_busy_share < 1.0 {
        lower_bound_s.max(cap_bound_of(shape, n_robots, switch_s, max_busy_share))
    } else {
        lower_bound_s
    }
}

/// The period of one order, or `None` if no period admits it (for the search).
pub(crate) fn period_of(
    shape: &TaskShape,
    n_robots: usize,
    order: &[Stretch],
    handover_tick_s: Option<f64>,
    switch_s: f64,
    max_busy_share: f64,
) -> Result<Option<f64>> {
    let graph = graph_of_shape(shape.clone(), n_robots, order, handover_tick_s, switch_s)?;
    match max_cycle_ratio(graph.events.len(), &graph.arcs) {
        Ok(r) if max_busy_share < 1.0 => {
            let capped = capped_period_s(&graph, n_robots, order, switch_s, max_busy_share);
            if capped <= r.period_s {
                Ok(Some(r.period_s))
            } else if super::ratio::times_at(graph.events.len(), &graph.arcs, capped).is_some() {
                Ok(Some(capped))
            } else {
                Ok(None)
            }
        }
        Ok(r) => Ok(Some(r.period_s)),
        Err(crate::Error::InfeasibleCycle { .. }) => Ok(None),
        Err(e) => Err(e),
    }
}

fn layout(
    graph: &EventGraph,
    n_robots: usize,
    order: &[Stretch],
    period_s: f64,
    times_s: &[f64],
    lower_bound_s: f64,
) -> CyclicPlan {
    let shape = &graph.shape;
    let m = shape.n_lc();
    let robots = (0..n_robots)
        .map(|r| {
            let a = times_s[graph.task_start_node(r)];
            let shift = (a / period_s).floor() * period_s;
            let start_s = a - shift;
            let lc_start_s: Vec<f64> = (0..m)
                .map(|lc| {
                    times_s[graph.stretch_node(Stretch { robot: r, lc })]
                        + f64::from(graph.wrapped[r][lc]) * period_s
                        - shift
                })
                .collect();
            let gap_plan = |k: usize, duration_s: f64| {
                let g = shape.gaps[k];
                GapPlan {
                    duration_s,
                    wait_s: if g.hold.is_some() {
                        (duration_s - g.max_s).max(0.0)
                    } else {
                        0.0
                    },
                    hold: g.hold,
                }
            };
            let mut gaps = Vec::with_capacity(m + 1);
            let (start_wait_s, tail_end);
            if m == 0 {
                gaps.push(gap_plan(0, shape.gaps[0].min_s));
                tail_end = start_s + shape.gaps[0].min_s;
            } else {
                gaps.push(gap_plan(0, lc_start_s[0] - start_s));
                for k in 1..m {
                    gaps.push(gap_plan(
                        k,
                        lc_start_s[k] - (lc_start_s[k - 1] + shape.lc_s[k - 1]),
                    ));
                }
                gaps.push(gap_plan(m, shape.gaps[m].min_s));
                tail_end = lc_start_s[m - 1] + shape.lc_s[m - 1] + shape.gaps[m].min_s;
            }
            start_wait_s = (start_s + period_s - tail_end).max(0.0);
            RobotCycle {
                start_s,
                lc_start_s,
                gaps,
                start_wait_s,
            }
        })
        .collect();
    let n = n_robots as f64;
    CyclicPlan {
        n_robots,
        order: order.to_vec(),
        period_s,
        lc_s: shape.lc_s.clone(),
        robots,
        tasks_per_hour: 3600.0 * n / period_s,
        operator_share: n * shape.lc_total_s() / period_s,
        lower_bound_s,
        gap: period_s / lower_bound_s - 1.0,
        order_exhaustive: false,
        orders_evaluated: 1,
    }
}
