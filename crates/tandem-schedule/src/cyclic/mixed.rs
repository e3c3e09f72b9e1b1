//! The cyclic plan of a continuous cell of different tasks (issue 45): robot `k` does its own
//! task, `r_k` times per period, and the operator supervises every robot's stretches once
//! per period in one cyclic order (docs/decisions.md, "The continuous cell of different
//! tasks: the mixed cyclic plan and its bound (issue 45)").
//!
//! **The model.** Robot `k`'s `r_k` tasks of one period are one *repeated task*
//! ([`repeated_shape`]): its task shape ([`TaskShape`]) `r_k` times, the tail of one copy and
//! the head of the next merged into one gap whose hold is the task start (always a hold:
//! the robot may wait there any time, so the merged gap has no upper bound). Each robot has
//! its own shape, so the event graph of [`crate::cyclic`] (module docs there) is built per
//! robot: robot `k`'s nodes are its task start and its `r_k·m_k` stretch starts, its arcs
//! its own head, gaps and tail, and the operator's arcs join the stretches of all robots in
//! the cyclic `order` (each robot's in task order around the cycle, starting anywhere). With
//! the cell's control tick ([`MixedParams::handover_tick_s`]) an operator arc into a group of
//! another robot carries the token rule's hand-over (the stretch's entry plus a tick), with a
//! switch time `δ` at least `δ`: the arcs of [`crate::CyclicParams`], each robot's from its
//! own shape. The least period of an order is the maximum cycle ratio of its graph
//! ([`crate::cyclic::max_cycle_ratio`], exact).
//!
//! **The search** ([`mixed_cyclic_plan`]). Ratios `r ∈ {1..R}^N` are taken in decreasing
//! order of the throughput their bound allows ([`mixed_period_lower_bound_s`]); for each, an
//! order of whole groups (runnable: a robot never waits for the operator between two
//! stretches without a usable hold between them) is built twice — greedily (the group whose
//! start could come first next) and spread (each robot's groups at the fraction of its task
//! where they start, so a short robot's groups fall between a long robot's) — and each is
//! improved by an insertion search (every group moved to the position of the least period
//! its robot's order allows, passes repeated while the period falls). The search stops when the best plan found completes at least as
//! many tasks per hour as the next ratios' bound allows (no plan with them does better), or
//! after [`MixedParams::max_ratio_candidates`] ratios.
//!
//! **The bound** ([`mixed_period_lower_bound_s`]) holds for every plan with ratios `r`,
//! whatever the order: `max(Σ_k r_k·L_k + c·δ, max_k r_k·D_k)`
//! ([`crate::cyclic::mix_period_lower_bound_s`], its proof there), and with the hand-overs
//! counted, `Σ_k r_k·Σ_g (S_g + E_g) + c·h`: the argument of
//! [`crate::cyclic::handover_bound_s`] with each robot's groups its own (around one period
//! the operator passes every group of every robot's `r_k` tasks once: its span `S_g` at the
//! fastest, then before the next group `h` either a change of robot, which costs at least
//! `E_h` plus `max(tick, δ − E_h)`, or the robot's own gap, which holds `E_h`), `c` the robots
//! with stretches when at least two have some (each robot's groups form at least one block
//! of the cyclic order), `h` the least cost of a change over the groups it can enter.

use serde::{Deserialize, Serialize};

use super::graph::{Gap, Stretch, TaskShape, push_robot_chain};
use super::mix::{MAX_MIX_RATIO, MixTask, mix_period_lower_bound_s};
use super::plan::groups_per_task_s;
use super::ratio::{Arc, max_cycle_ratio};
use crate::problem::check_robot_count;
use crate::{Error, Problem, Result};

/// The most ratio vectors [`mixed_cyclic_plan`] enumerates (`R^N` is cut to this by lowering
/// `R`).
const MAX_RATIO_VECTORS: usize = 65_536;

/// Parameters of [`mixed_cyclic_plan`].
#[derive(Clone, Debug, PartialEq)]
pub struct MixedParams {
    /// `R`: the most tasks of one robot per period (`1..=MAX_MIX_RATIO`; lowered so that
    /// `R^N ≤ 65 536`). Default 6 (docs/decisions.md, "The mixed cyclic plan near its best
    /// bound: the insertion search and ratios up to 6 (issue 45)").
    pub max_ratio: usize,
    /// The most ratio vectors whose order is searched (the ones whose bound allows the most
    /// tasks per hour first). Must be ≥ 1. Default 12.
    pub max_ratio_candidates: usize,
    /// The most periods computed per ratio vector by the order search (the insertion search
    /// from two starting orders, [`mixed_cyclic_plan`]). Default 600.
    pub max_evaluations: usize,
    /// The control tick (real s) of the cell that runs the plan: counts the token rule's
    /// hand-overs as [`crate::CyclicParams::handover_tick_s`] does. `None`: the operator's
    /// order alone. Finite and > 0. Default `None`.
    pub handover_tick_s: Option<f64>,
    /// The operator's switch time `δ` (real s, ≥ 0), as [`crate::CyclicParams::switch_s`].
    /// Default 0.
    pub switch_s: f64,
    /// Search only orders the token rule can run (each group of stretches between two usable
    /// holds contiguous, as [`crate::CyclicParams::runnable_only`]); `false`: single
    /// stretches are ordered, a plan only (a robot may have to keep pace between stretches
    /// without a hold). Default `true`.
    pub runnable_only: bool,
}

impl Default for MixedParams {
    fn default() -> Self {
        MixedParams {
            max_ratio: 6,
            max_ratio_candidates: 12,
            max_evaluations: 600,
            handover_tick_s: None,
            switch_s: 0.0,
            runnable_only: true,
        }
    }
}

impl MixedParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field: `max_ratio` outside `1..=MAX_MIX_RATIO`,
    /// `max_ratio_candidates` or `max_evaluations` 0, a `handover_tick_s` not finite and > 0,
    /// a `switch_s` not finite and ≥ 0.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &'static str, why: &'static str| Err(Error::BadParam { name, why });
        if !(1..=MAX_MIX_RATIO).contains(&self.max_ratio) {
            return bad(
                "max_ratio",
                "must be 1 to MAX_MIX_RATIO (tasks of one robot per period)",
            );
        }
        if self.max_ratio_candidates == 0 {
            return bad("max_ratio_candidates", "must be ≥ 1");
        }
        if self.max_evaluations == 0 {
            return bad("max_evaluations", "must be ≥ 1");
        }
        if self
            .handover_tick_s
            .is_some_and(|t| !(t.is_finite() && t > 0.0))
        {
            return bad("handover_tick_s", "must be finite and > 0");
        }
        if !(self.switch_s.is_finite() && self.switch_s >= 0.0) {
            return bad(
                "switch_s",
                "must be finite and >= 0 (the operator's switch time in seconds; 0 for none)",
            );
        }
        Ok(())
    }
}

/// One robot's tasks within a [`MixedCyclicPlan`] (schedule clock, s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MixedRobotCycle {
    /// `r_k`: its tasks per period.
    pub ratio: usize,
    /// `m_k`: low-confidence stretches per task.
    pub stretches_per_task: usize,
    /// When it leaves its task start for the first of its `r_k` tasks of period 0, in
    /// `[0, P)`.
    pub start_s: f64,
    /// When it enters each of its `r_k·m_k` stretches of period 0 (task by task; ≥ `start_s`,
    /// possibly past `P`).
    pub lc_start_s: Vec<f64>,
    /// The duration (s) of each of those stretches at `ψ̇̄`.
    pub lc_s: Vec<f64>,
}

/// A repeated plan of a cell of different tasks (the docs of the module `cyclic::mixed`):
/// every `period_s` robot `k` completes `ratios[k]` tasks and the operator supervises every
/// stretch once, in
/// `order` (a [`Stretch`]'s `lc` counts the robot's stretches over its `r_k` tasks:
/// `lc = copy·m_k + k`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MixedCyclicPlan {
    /// `r_k` per robot.
    pub ratios: Vec<usize>,
    /// The operator's cyclic order.
    pub order: Vec<Stretch>,
    /// The least period `P` (s) of this order and these ratios.
    pub period_s: f64,
    /// Per robot, its tasks of period 0.
    pub robots: Vec<MixedRobotCycle>,
    /// `3600·Σ_k r_k / P`.
    pub tasks_per_hour: f64,
    /// The operator's busy share `Σ_k r_k·L_k / P`.
    pub operator_share: f64,
    /// [`mixed_period_lower_bound_s`] of these ratios: no plan with them has a shorter period.
    pub lower_bound_s: f64,
    /// `period_s / lower_bound_s − 1`.
    pub gap: f64,
    /// The mixed operator-limited bound of these ratios (tasks/h, `∞` without low
    /// confidence): `3600 / (Σ_k r_k·L_k / Σ_k r_k)`, 3600 over the mean operator-seconds per
    /// task of the mix.
    pub operator_limited_per_hour: f64,
    /// The most tasks per hour any plan with ratios in `{1..R}^N` can complete (the best
    /// `3600·Σ r_k / bound` over them): the plan's throughput is at most this.
    pub best_bound_per_hour: f64,
    /// `R` as searched (after lowering so that `R^N ≤ 65 536`).
    pub max_ratio: usize,
    /// Ratio vectors whose order was searched.
    pub ratios_evaluated: usize,
    /// Periods computed over all of them.
    pub orders_evaluated: usize,
}

/// Robot `k`'s `r` tasks of one period as one task shape (the docs of the module
/// `cyclic::mixed`): the shape `r` times, the tail of each copy and the head of the next one
/// merged into one gap (its
/// durations their sums) whose hold is the head's hold or else the task start
/// (reference sample `c·n_ref` of copy `c`); a stretch's entry is its copy's. `r = 1` is the
/// shape itself.
///
/// # Errors
/// [`Error::BadParam`] for `r = 0`.
pub fn repeated_shape(shape: &TaskShape, r: usize) -> Result<TaskShape> {
    if r == 0 {
        return Err(Error::BadParam {
            name: "ratios",
            why: "must be one per robot, each at least 1",
        });
    }
    if r == 1 {
        return Ok(shape.clone());
    }
    let m = shape.n_lc();
    let n_ref = shape.gaps[m].ref_end;
    let shift = |g: Gap, off: usize| Gap {
        ref_start: g.ref_start + off,
        ref_end: g.ref_end + off,
        hold: g.hold.map(|h| h + off),
        ..g
    };
    if m == 0 {
        let g = shape.gaps[0];
        return Ok(TaskShape {
            lc_s: Vec::new(),
            gaps: vec![Gap {
                ref_start: 0,
                ref_end: r * n_ref,
                min_s: r as f64 * g.min_s,
                max_s: r as f64 * g.max_s,
                hold: Some(0),
            }],
            entry_s: Vec::new(),
        });
    }
    let mut lc_s = Vec::with_capacity(r * m);
    let mut gaps = Vec::with_capacity(r * m + 1);
    let mut entry_s = Vec::with_capacity(r * m);
    for c in 0..r {
        let off = c * n_ref;
        for k in 0..m {
            let g = if k == 0 && c > 0 {
                let (tail, head) = (shape.gaps[m], shape.gaps[0]);
                Gap {
                    ref_start: tail.ref_start + off - n_ref,
                    ref_end: head.ref_end + off,
                    min_s: tail.min_s + head.min_s,
                    max_s: tail.max_s + head.max_s,
                    hold: Some(head.hold.map_or(off, |h| h + off)),
                }
            } else {
                shift(shape.gaps[k], off)
            };
            gaps.push(g);
            lc_s.push(shape.lc_s[k]);
            entry_s.push(shape.entry_s[k]);
        }
    }
    gaps.push(shift(shape.gaps[m], (r - 1) * n_ref));
    Ok(TaskShape {
        lc_s,
        gaps,
        entry_s,
    })
}

/// The lower bound (s) on the period of every plan in which robot `k` (task shape
/// `shapes[k]`) completes `ratios[k]` tasks per period, whatever the order (the docs of the
/// module `cyclic::mixed`): [`crate::cyclic::mix_period_lower_bound_s`], and with
/// `handover_tick_s` the bound of every runnable order with the hand-overs counted.
///
/// # Errors
/// [`Error::BadParam`] for shapes outside `1..=MAX_ROBOTS`, ratios not one per robot or 0, a
/// bad tick or switch time; [`Error::Realtime`] (`RobotCount`) as the robot count check.
pub fn mixed_period_lower_bound_s(
    shapes: &[TaskShape],
    ratios: &[usize],
    handover_tick_s: Option<f64>,
    switch_s: f64,
) -> Result<f64> {
    check_robot_count(shapes.len())?;
    if ratios.len() != shapes.len() {
        return Err(Error::BadParam {
            name: "ratios",
            why: "must be one per robot, each at least 1",
        });
    }
    MixedParams {
        handover_tick_s,
        switch_s,
        ..MixedParams::default()
    }
    .validate()?;
    let tasks = mix_tasks(shapes);
    let supers = ratios
        .iter()
        .zip(shapes)
        .map(|(&r, s)| repeated_shape(s, r))
        .collect::<Result<Vec<_>>>()?;
    bound_for(&tasks, &supers, ratios, handover_tick_s, switch_s)
}

fn mix_tasks(shapes: &[TaskShape]) -> Vec<MixTask> {
    shapes
        .iter()
        .map(|s| MixTask {
            fastest_s: s.fastest_s(),
            lc_s: s.lc_total_s(),
        })
        .collect()
}

fn bound_for(
    tasks: &[MixTask],
    supers: &[TaskShape],
    ratios: &[usize],
    handover_tick_s: Option<f64>,
    switch_s: f64,
) -> Result<f64> {
    let base = mix_period_lower_bound_s(tasks, ratios, switch_s)?;
    let Some(tick_s) = handover_tick_s else {
        return Ok(base);
    };
    let with_lc: Vec<&TaskShape> = supers.iter().filter(|s| s.n_lc() > 0).collect();
    if with_lc.len() < 2 {
        return Ok(base);
    }
    // The least cost of a change of robot beyond the entered group's entry.
    let per_change = with_lc
        .iter()
        .flat_map(|s| {
            (0..s.n_lc())
                .filter(|&k| s.opens_group(k))
                .map(|k| tick_s.max(switch_s - s.entry_s[k]))
        })
        .fold(f64::INFINITY, f64::min);
    let groups: f64 = with_lc.iter().map(|s| groups_per_task_s(s)).sum();
    Ok(base.max(groups + with_lc.len() as f64 * per_change))
}

/// Per robot, the groups of its repeated shape: `(first, last)` stretch indices (single
/// stretches unless `runnable_only`).
fn groups_of_shape(shape: &TaskShape, runnable_only: bool) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for k in 0..shape.n_lc() {
        match out.last_mut() {
            Some(g) if runnable_only && !shape.opens_group(k) => g.1 = k,
            _ => out.push((k, k)),
        }
    }
    out
}

/// Checks an order over robots with `m[r]` stretches each: every stretch once, each robot's
/// in task order around the cycle.
fn check_mixed_order(order: &[Stretch], m: &[usize]) -> Result<()> {
    let bad = |why: &'static str| Error::BadParam { name: "order", why };
    let base: Vec<usize> = m
        .iter()
        .scan(0, |acc, &x| {
            let b = *acc;
            *acc += x;
            Some(b)
        })
        .collect();
    let total: usize = m.iter().sum();
    if order.len() != total {
        return Err(bad(
            "must list every robot's every low-confidence stretch once",
        ));
    }
    let mut seen = vec![false; total];
    for s in order {
        if s.robot >= m.len() || s.lc >= m[s.robot] {
            return Err(bad("names a robot or a stretch that does not exist"));
        }
        let i = base[s.robot] + s.lc;
        if seen[i] {
            return Err(bad("names a stretch twice"));
        }
        seen[i] = true;
    }
    for (r, &mr) in m.iter().enumerate() {
        if mr == 0 {
            continue;
        }
        let first = order
            .iter()
            .position(|s| s.robot == r && s.lc == 0)
            .expect("every stretch is listed (checked above)");
        let mut next = 0;
        for q in 0..order.len() {
            let s = order[(first + q) % order.len()];
            if s.robot == r {
                if s.lc != next {
                    return Err(bad(
                        "must keep each robot's stretches in task order around the cycle",
                    ));
                }
                next += 1;
            }
        }
    }
    Ok(())
}

/// The event graph of robots with their own (repeated) shapes and one operator order.
struct MixedGraph {
    n_nodes: usize,
    arcs: Vec<Arc>,
    /// Node of each robot's task start; its stretch `k` is `base[r] + 1 + k`.
    base: Vec<usize>,
    wrapped: Vec<Vec<u8>>,
}

fn mixed_graph(
    supers: &[TaskShape],
    order: &[Stretch],
    handover_tick_s: Option<f64>,
    switch_s: f64,
) -> Result<MixedGraph> {
    let m: Vec<usize> = supers.iter().map(TaskShape::n_lc).collect();
    check_mixed_order(order, &m)?;
    let mut base = Vec::with_capacity(supers.len());
    let mut n_nodes = 0;
    for &mr in &m {
        base.push(n_nodes);
        n_nodes += mr + 1;
    }
    let mut pos: Vec<Vec<usize>> = m.iter().map(|&mr| vec![0; mr]).collect();
    for (q, s) in order.iter().enumerate() {
        pos[s.robot][s.lc] = q;
    }
    let mut arcs = Vec::new();
    let mut push = |from: usize, to: usize, weight_s: f64, tokens: i32| {
        arcs.push(Arc {
            from,
            to,
            weight_s,
            tokens,
        });
    };
    let mut wrapped: Vec<Vec<u8>> = m.iter().map(|&mr| vec![0; mr]).collect();
    for (r, shape) in supers.iter().enumerate() {
        let a = base[r];
        let mr = m[r];
        if mr == 0 {
            push(a, a, shape.gaps[0].min_s, 1);
            continue;
        }
        for k in 0..mr {
            wrapped[r][k] = u8::from(pos[r][k] < pos[r][0]);
        }
        push_robot_chain(shape, a, &wrapped[r], &mut push);
    }
    let len = order.len();
    for q in 0..len {
        let (from, to) = (order[q], order[(q + 1) % len]);
        let to_shape = &supers[to.robot];
        let change = to.robot != from.robot;
        let handover = match handover_tick_s {
            Some(tick_s) if change && to_shape.opens_group(to.lc) => {
                to_shape.entry_s[to.lc] + tick_s
            }
            _ => 0.0,
        };
        let handover = if switch_s > 0.0 && change {
            handover.max(switch_s)
        } else {
            handover
        };
        push(
            base[from.robot] + 1 + from.lc,
            base[to.robot] + 1 + to.lc,
            supers[from.robot].lc_s[from.lc] + handover,
            i32::from(q + 1 == len),
        );
    }
    Ok(MixedGraph {
        n_nodes,
        arcs,
        base,
        wrapped,
    })
}

/// The stretches of an order of groups.
fn expand(blocks: &[(usize, usize, usize)]) -> Vec<Stretch> {
    blocks
        .iter()
        .flat_map(|&(robot, first, last)| (first..=last).map(move |lc| Stretch { robot, lc }))
        .collect()
}

/// The period of an order of groups, `None` if no period admits it.
fn period_of_blocks(
    supers: &[TaskShape],
    blocks: &[(usize, usize, usize)],
    params: &MixedParams,
) -> Result<Option<f64>> {
    let g = mixed_graph(
        supers,
        &expand(blocks),
        params.handover_tick_s,
        params.switch_s,
    )?;
    match max_cycle_ratio(g.n_nodes, &g.arcs) {
        Ok(r) => Ok(Some(r.period_s)),
        Err(Error::InfeasibleCycle { .. }) => Ok(None),
        Err(e) => Err(e),
    }
}

/// The greedy order of groups: repeatedly the group whose first stretch could start first
/// (its robot's own chain at the fastest, the operator free after the previous group and the
/// hand-over), ties to the robot with the least share of its groups placed, then the lowest.
fn greedy_blocks(
    supers: &[TaskShape],
    groups: &[Vec<(usize, usize)>],
    params: &MixedParams,
) -> Vec<(usize, usize, usize)> {
    let n = supers.len();
    let mut next = vec![0usize; n];
    let mut ready: Vec<f64> = supers.iter().map(|s| s.gaps[0].min_s).collect();
    let (mut free, mut last): (f64, Option<usize>) = (0.0, None);
    let total: usize = groups.iter().map(Vec::len).sum();
    let mut out = Vec::with_capacity(total);
    for _ in 0..total {
        let change = |r: usize, first: usize| -> f64 {
            if last == Some(r) || last.is_none() {
                return 0.0;
            }
            let h = params
                .handover_tick_s
                .map_or(0.0, |t| supers[r].entry_s[first] + t);
            if params.switch_s > 0.0 {
                h.max(params.switch_s)
            } else {
                h
            }
        };
        let mut best: Option<(f64, f64, usize)> = None;
        for r in 0..n {
            if next[r] >= groups[r].len() {
                continue;
            }
            let (first, _) = groups[r][next[r]];
            let start = ready[r].max(free + change(r, first));
            let share = next[r] as f64 / groups[r].len() as f64;
            let better = match best {
                None => true,
                Some((s, sh, _)) => start < s || (start == s && share < sh),
            };
            if better {
                best = Some((start, share, r));
            }
        }
        let (start, _, r) = best.expect("a group is left");
        let (first, last_k) = groups[r][next[r]];
        let shape = &supers[r];
        let span: f64 = (first..=last_k).map(|k| shape.lc_s[k]).sum::<f64>()
            + (first + 1..=last_k)
                .map(|k| shape.gaps[k].min_s)
                .sum::<f64>();
        let end = start + span;
        free = end;
        last = Some(r);
        let m = shape.n_lc();
        ready[r] = if last_k + 1 < m {
            end + shape.gaps[last_k + 1].min_s
        } else {
            end + shape.gaps[m].min_s + shape.gaps[0].min_s
        };
        next[r] += 1;
        out.push((r, first, last_k));
    }
    out
}

/// One block of the operator's order: `(robot, first group, last group)` of that robot's
/// repeated shape, the groups `first..=last` served back to back.
type Block = (usize, usize, usize);

/// The best plan so far over the ratio vectors: `(tasks per hour, tasks per period Σ r_k,
/// the ratios r_k, the order's blocks, the period P in s)`.
type BestRatio = (f64, usize, Vec<usize>, Vec<Block>, f64);

/// The spread order of groups: every robot's groups placed by the fraction of its repeated
/// task at which each starts (its own chain at the fastest: the start of the group's first
/// stretch over the repeated task's fastest duration), merged in that order (ties: the lower
/// robot first). A short robot's groups then fall between the long robot's evenly over the
/// period, where the greedy order puts them all at the head while the short robot is ready.
fn spread_blocks(supers: &[TaskShape], groups: &[Vec<(usize, usize)>]) -> Vec<Block> {
    let mut keyed: Vec<(f64, usize, Block)> = Vec::new();
    for (r, (shape, gs)) in supers.iter().zip(groups).enumerate() {
        let total = shape.fastest_s();
        // The start of stretch k on the robot's own chain at the fastest.
        let mut t = shape.gaps[0].min_s;
        let mut starts = Vec::with_capacity(shape.n_lc());
        for k in 0..shape.n_lc() {
            if k > 0 {
                t += shape.lc_s[k - 1] + shape.gaps[k].min_s;
            }
            starts.push(t);
        }
        for &(first, last) in gs {
            let key = if total > 0.0 {
                starts[first] / total
            } else {
                0.0
            };
            keyed.push((key, r, (r, first, last)));
        }
    }
    keyed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    keyed.into_iter().map(|(_, _, b)| b).collect()
}

/// `a` strictly shorter than `b` (`None`: no period admits the order).
fn shorter(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (Some(a), Some(b)) => a < b * (1.0 - 1e-12),
        (Some(_), None) => true,
        _ => false,
    }
}

/// Local search on an order of groups by *insertion*: each block in turn is moved to every
/// position its robot's order allows (past the neighbouring blocks of other robots, up to the
/// robot's previous and next block, cyclically; one step is the neighbouring swap), and kept
/// at the position of the least period; passes repeat while the period falls, at most
/// `budget` periods computed. Returns the period and the periods computed.
fn insertion_search(
    supers: &[TaskShape],
    blocks: &mut [Block],
    mut best: Option<f64>,
    params: &MixedParams,
    budget: usize,
) -> Result<(Option<f64>, usize)> {
    let len = blocks.len();
    let mut evals = 0;
    if len < 2 {
        return Ok((best, evals));
    }
    let mut improved = true;
    while improved && evals < budget {
        improved = false;
        for q0 in 0..len {
            // Moves of the block at q0 forward (dir 1) and backward (dir len − 1), one step
            // at a time; the block's best position is kept.
            for dir in [1, len - 1] {
                let mut q = q0;
                let mut at_best = q0;
                let mut moved = 0;
                while moved + 1 < len && evals < budget {
                    let q2 = (q + dir) % len;
                    if blocks[q2].0 == blocks[q].0 {
                        break;
                    }
                    blocks.swap(q, q2);
                    q = q2;
                    moved += 1;
                    evals += 1;
                    let p = period_of_blocks(supers, blocks, params)?;
                    if shorter(p, best) {
                        best = p;
                        at_best = q;
                        improved = true;
                    }
                }
                // Back from q to at_best (the swaps undone in reverse).
                let back = (dir * (len - 1)) % len;
                while q != at_best {
                    let q2 = (q + back) % len;
                    blocks.swap(q, q2);
                    q = q2;
                }
                if at_best != q0 {
                    break;
                }
            }
        }
    }
    Ok((best, evals))
}

/// The best order found for one ratio vector: from the greedy order and from the spread
/// order ([`spread_blocks`]), each improved by the insertion search
/// ([`insertion_search`]), at most `max_evaluations` periods computed in all (half each).
fn search_order(
    supers: &[TaskShape],
    params: &MixedParams,
) -> Result<Option<(Vec<Block>, f64, usize)>> {
    let groups: Vec<Vec<(usize, usize)>> = supers
        .iter()
        .map(|s| groups_of_shape(s, params.runnable_only))
        .collect();
    let starts = [
        greedy_blocks(supers, &groups, params),
        spread_blocks(supers, &groups),
    ];
    let mut evals = 0;
    let mut out: Option<(Vec<Block>, f64)> = None;
    for (i, mut blocks) in starts.into_iter().enumerate() {
        if i > 0 && evals >= params.max_evaluations {
            break;
        }
        let p0 = period_of_blocks(supers, &blocks, params)?;
        evals += 1;
        let budget = if i == 0 {
            params.max_evaluations / 2
        } else {
            params.max_evaluations.saturating_sub(evals)
        };
        let (p, e) = insertion_search(supers, &mut blocks, p0, params, budget)?;
        evals += e;
        if let Some(p) = p
            && out.as_ref().is_none_or(|o| shorter(Some(p), Some(o.1)))
        {
            out = Some((blocks, p));
        }
    }
    Ok(out.map(|(b, p)| (b, p, evals)))
}

/// The cyclic plan of a continuous cell whose robot `k` does the task of `problems[k]`
/// (the docs of the module `cyclic::mixed`): the best ratios and order found, their least
/// period, and the bound.
///
/// # Errors
/// [`Error::Realtime`] (`RobotCount`) for a robot count outside `1..=MAX_ROBOTS`;
/// [`Error::BadParam`] for bad `params`; [`Error::InfeasibleCycle`] when no searched order
/// admits a period (a robot would wait inside a gap without a hold point).
pub fn mixed_cyclic_plan(problems: &[&Problem], params: &MixedParams) -> Result<MixedCyclicPlan> {
    check_robot_count(problems.len())?;
    params.validate()?;
    let shapes: Vec<TaskShape> = problems.iter().map(|p| TaskShape::new(p)).collect();
    mixed_plan_of_shapes(&shapes, params)
}

/// [`mixed_cyclic_plan`] of task shapes already cut from their problems.
///
/// # Errors
/// As [`mixed_cyclic_plan`].
pub fn mixed_plan_of_shapes(shapes: &[TaskShape], params: &MixedParams) -> Result<MixedCyclicPlan> {
    check_robot_count(shapes.len())?;
    params.validate()?;
    let n = shapes.len();
    let tasks = mix_tasks(shapes);
    // R lowered so that R^N ≤ 65 536.
    let mut max_ratio = params.max_ratio;
    while max_ratio > 1 && (max_ratio as f64).powi(n as i32) > MAX_RATIO_VECTORS as f64 {
        max_ratio -= 1;
    }
    // Every ratio vector with its bound's throughput.
    let mut candidates: Vec<(f64, usize, Vec<usize>)> = Vec::new();
    let mut r = vec![1usize; n];
    loop {
        let supers = r
            .iter()
            .zip(shapes)
            .map(|(&q, s)| repeated_shape(s, q))
            .collect::<Result<Vec<_>>>()?;
        let p = bound_for(
            &tasks,
            &supers,
            &r,
            params.handover_tick_s.filter(|_| params.runnable_only),
            params.switch_s,
        )?;
        let total: usize = r.iter().sum();
        candidates.push((3600.0 * total as f64 / p, total, r.clone()));
        let Some(k) = (0..n).rev().find(|&k| r[k] < max_ratio) else {
            break;
        };
        r[k] += 1;
        r[k + 1..].fill(1);
    }
    candidates.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    let best_bound_per_hour = candidates[0].0;
    let mut best: Option<BestRatio> = None;
    let (mut ratios_evaluated, mut orders_evaluated) = (0, 0);
    for (bound_rate, _, ratios) in &candidates {
        if ratios_evaluated >= params.max_ratio_candidates {
            break;
        }
        if best
            .as_ref()
            .is_some_and(|b| b.0 >= bound_rate * (1.0 - 1e-12))
        {
            break;
        }
        ratios_evaluated += 1;
        let supers = ratios
            .iter()
            .zip(shapes)
            .map(|(&q, s)| repeated_shape(s, q))
            .collect::<Result<Vec<_>>>()?;
        let Some((blocks, period_s, evals)) = search_order(&supers, params)? else {
            continue;
        };
        orders_evaluated += evals;
        let total: usize = ratios.iter().sum();
        let rate = 3600.0 * total as f64 / period_s;
        let better = best.as_ref().is_none_or(|b| {
            rate > b.0 * (1.0 + 1e-12) || (rate >= b.0 * (1.0 - 1e-12) && total < b.1)
        });
        if better {
            best = Some((rate, total, ratios.clone(), blocks, period_s));
        }
    }
    let Some((_, _, ratios, blocks, _)) = best else {
        return Err(Error::BadParam {
            name: "order",
            why: "no searched order admits a period (a robot would wait inside a gap without a \
                  hold point): raise max_ratio_candidates",
        });
    };
    let mut plan = mixed_plan_for_order(shapes, &ratios, &expand(&blocks), params)?;
    plan.best_bound_per_hour = best_bound_per_hour;
    plan.max_ratio = max_ratio;
    plan.ratios_evaluated = ratios_evaluated;
    plan.orders_evaluated = orders_evaluated;
    Ok(plan)
}

/// The plan of given ratios and a given order (a [`Stretch`]'s `lc` counts over the robot's
/// `r_k` tasks) on task shapes: its least period, event times and bound.
///
/// # Errors
/// As [`mixed_period_lower_bound_s`]; [`Error::BadParam`] for an order that does not list
/// every stretch once with each robot's in task order around the cycle;
/// [`Error::InfeasibleCycle`] when no period admits the order.
pub fn mixed_plan_for_order(
    shapes: &[TaskShape],
    ratios: &[usize],
    order: &[Stretch],
    params: &MixedParams,
) -> Result<MixedCyclicPlan> {
    let lower_bound_s = mixed_period_lower_bound_s(
        shapes,
        ratios,
        params.handover_tick_s.filter(|_| params.runnable_only),
        params.switch_s,
    )?;
    params.validate()?;
    let supers = ratios
        .iter()
        .zip(shapes)
        .map(|(&q, s)| repeated_shape(s, q))
        .collect::<Result<Vec<_>>>()?;
    let g = mixed_graph(&supers, order, params.handover_tick_s, params.switch_s)?;
    // The hand-over bound holds for runnable orders only: a stretch inside a group follows
    // its robot's previous one.
    let len = order.len();
    if params.runnable_only
        && (0..len).any(|q| {
            let s = order[q];
            !supers[s.robot].opens_group(s.lc)
                && order[(q + len - 1) % len]
                    != Stretch {
                        robot: s.robot,
                        lc: s.lc - 1,
                    }
        })
    {
        return Err(Error::BadParam {
            name: "order",
            why: "is not runnable (another robot's stretch inside a group of stretches without \
                  a usable hold between them): reorder, or set runnable_only to false",
        });
    }
    let ratio = max_cycle_ratio(g.n_nodes, &g.arcs)?;
    let period_s = ratio.period_s;
    let robots: Vec<MixedRobotCycle> = supers
        .iter()
        .enumerate()
        .map(|(r, shape)| {
            let a = ratio.times_s[g.base[r]];
            let shift = (a / period_s).floor() * period_s;
            MixedRobotCycle {
                ratio: ratios[r],
                stretches_per_task: shapes[r].n_lc(),
                start_s: a - shift,
                lc_start_s: (0..shape.n_lc())
                    .map(|k| {
                        ratio.times_s[g.base[r] + 1 + k] + f64::from(g.wrapped[r][k]) * period_s
                            - shift
                    })
                    .collect(),
                lc_s: shape.lc_s.clone(),
            }
        })
        .collect();
    let total: usize = ratios.iter().sum();
    let lc: f64 = supers.iter().map(TaskShape::lc_total_s).sum();
    Ok(MixedCyclicPlan {
        ratios: ratios.to_vec(),
        order: order.to_vec(),
        period_s,
        robots,
        tasks_per_hour: 3600.0 * total as f64 / period_s,
        operator_share: lc / period_s,
        lower_bound_s,
        gap: period_s / lower_bound_s - 1.0,
        operator_limited_per_hour: if lc > 0.0 {
            3600.0 * total as f64 / lc
        } else {
            f64::INFINITY
        },
        best_bound_per_hour: f64::NAN,
        max_ratio: params.max_ratio,
        ratios_evaluated: 0,
        orders_evaluated: 1,
    })
}

impl MixedCyclicPlan {
    /// The continuous coordinator of this plan (issue 45,
    /// `tandem_realtime::continuous::ContinuousCoordinator::mixed`): robot `k` runs the
    /// fastest warp of its task `tasks[robot_task[k]]` (the problem the plan was made on:
    /// `ψ̇min` on high-confidence samples, `ψ̇̄` on low-confidence ones), waits at that task's
    /// usable holds, and does `ratios[k]` tasks per pass of the plan's operator `order`, at a
    /// control tick of `tick_s` real seconds. The token rule makes it sound for any operator
    /// and any number of tasks (the argument of `tandem_realtime::continuous` reads each
    /// robot's own timeline); under the planned operator its steady period is the plan's
    /// when the plan counted the hand-overs at this tick ([`MixedParams::handover_tick_s`]).
    ///
    /// # Errors
    /// [`Error::BadParam`] when `robot_task` has not one entry per robot of the plan or names
    /// no task, or a robot's task has not the plan's number of stretches;
    /// [`Error::Realtime`] for a bad `tick_s`, a malformed or not runnable order.
    pub fn coordinator(
        &self,
        tasks: &[&Problem],
        robot_task: &[usize],
        tick_s: f64,
    ) -> Result<tandem_realtime::continuous::ContinuousCoordinator> {
        if robot_task.len() != self.robots.len() || robot_task.iter().any(|&t| t >= tasks.len()) {
            return Err(Error::BadParam {
                name: "robot_task",
                why: "must name one of the tasks for each robot of the plan",
            });
        }
        for (k, &t) in robot_task.iter().enumerate() {
            if TaskShape::new(tasks[t]).n_lc() != self.robots[k].stretches_per_task {
                return Err(Error::BadParam {
                    name: "tasks",
                    why: "a robot's task has not the plan's number of low-confidence stretches \
                          (the plan was made on other problems: plan the cell again)",
                });
            }
        }
        let timelines = tasks
            .iter()
            .map(|p| {
                Ok((
                    tandem_realtime::Timeline::new(
                        p.conf(),
                        &p.fastest_warp(),
                        p.grad_min(),
                        p.grad_max(),
                        0.0,
                        p.dt_s(),
                    )?,
                    p.usable_holds(),
                ))
            })
            .collect::<Result<Vec<_>>>()?;
        let order: Vec<(usize, usize)> = self.order.iter().map(|s| (s.robot, s.lc)).collect();
        Ok(tandem_realtime::continuous::ContinuousCoordinator::mixed(
            &timelines,
            robot_task,
            &self.ratios,
            &order,
            tick_s,
        )?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `hc` high-confidence, `lc` low-confidence, `hc` high-confidence samples at 10 ms,
    /// `ψ̇̄ = 1`, `ψ̇min = 0.5`: `D = 0.005·2·hc + 0.01·lc` s, `L = 0.01·lc` s.
    fn task(hc: usize, lc: usize) -> Problem {
        let conf: Vec<bool> = (0..2 * hc + lc)
            .map(|n| !(hc..hc + lc).contains(&n))
            .collect();
        let n = conf.len();
        Problem::new(conf, vec![1.0; n], vec![0.5; n], vec![2.0; n], 0.01).unwrap()
    }

    #[test]
    fn the_repeated_shape_merges_tail_and_head_at_a_hold() {
        let s = TaskShape::new(&task(50, 25));
        let r = repeated_shape(&s, 3).unwrap();
        assert_eq!(r.n_lc(), 3);
        assert!((r.fastest_s() - 3.0 * s.fastest_s()).abs() < 1e-12);
        assert!((r.lc_total_s() - 0.75).abs() < 1e-12);
        // Copies 1 and 2 open their own group at the task start (a hold), 0.25 s from it.
        assert!(r.opens_group(1) && r.opens_group(2));
        assert_eq!(r.gaps[1].hold, Some(125));
        assert!((r.gaps[1].min_s - 0.5).abs() < 1e-12 && (r.entry_s[2] - 0.25).abs() < 1e-12);
        assert_eq!(r.gaps[3].ref_end, 375);
        assert_eq!(repeated_shape(&s, 1).unwrap(), s);
        assert!(repeated_shape(&s, 0).is_err());
    }

    #[test]
    fn one_task_per_robot_is_the_one_task_plan() {
        // Two robots of one task: the mixed graph is the one-task graph, the same period.
        let p = task(100, 100);
        let mixed = mixed_cyclic_plan(
            &[&p, &p],
            &MixedParams {
                max_ratio: 1,
                ..MixedParams::default()
            },
        )
        .unwrap();
        let one = super::super::cyclic_plan(&p, 2, &crate::CyclicParams::default()).unwrap();
        assert!((mixed.period_s - one.period_s).abs() < 1e-9);
        assert_eq!(mixed.ratios, [1, 1]);
    }

    #[test]
    fn the_best_ratios_by_hand() {
        // A: 0.5 + 1 + 0.5 s (D = 2, L = 1); B: 0.25 + 0.25 + 0.25 s (D = 0.75, L = 0.25),
        // one stretch per task, so every order of r = (1, q) is A then B's q stretches:
        // P(1, q) = max(2, 1 + 0.75·(q − 1) + 0.25, 0.75·q) (A's stretch, B's chain
        // between its stretches, B's stretch back to A): (1, 1) 2 s → 3600/h; (1, 2) 2 s →
        // 5400/h; (1, 3) 2.75 s → 5236/h; (1, 4) 3.5 s → 5143/h. The bounds allow (1, 3)
        // 6400/h (2.25 s), (1, 4) 6000/h, (1, 2) and (2, 4) 5400/h: after (1, 2) reaches
        // 5400/h no other can beat it.
        let (a, b) = (task(100, 100), task(50, 25));
        let r4 = MixedParams {
            max_ratio: 4,
            ..MixedParams::default()
        };
        let plan = mixed_cyclic_plan(&[&a, &b], &r4).unwrap();
        assert_eq!(plan.ratios, [1, 2]);
        assert!((plan.period_s - 2.0).abs() < 1e-9, "{}", plan.period_s);
        assert!((plan.tasks_per_hour - 5400.0).abs() < 1e-6);
        assert!((plan.lower_bound_s - 2.0).abs() < 1e-9 && plan.gap.abs() < 1e-9);
        assert!((plan.best_bound_per_hour - 6400.0).abs() < 1e-6);
        assert!((plan.operator_limited_per_hour - 3600.0 * 3.0 / 1.5).abs() < 1e-6);
        assert_eq!(plan.ratios_evaluated, 3);
        let shapes = [TaskShape::new(&a), TaskShape::new(&b)];
        let order = |q: usize| -> Vec<Stretch> {
            std::iter::once(Stretch { robot: 0, lc: 0 })
                .chain((0..q).map(|lc| Stretch { robot: 1, lc }))
                .collect()
        };
        let p = MixedParams::default();
        for (q, want) in [(1, 2.0), (2, 2.0), (3, 2.75), (4, 3.5)] {
            let plan = mixed_plan_for_order(&shapes, &[1, q], &order(q), &p).unwrap();
            assert!(
                (plan.period_s - want).abs() < 1e-9,
                "q {q}: {}",
                plan.period_s
            );
        }
    }

    /// The plan's stretches, laid out over two periods, never meet, each robot's follow its
    /// own chain, and the period is at least its bound.
    fn assert_sound(plan: &MixedCyclicPlan, shapes: &[TaskShape]) {
        let p = plan.period_s;
        let mut iv: Vec<(f64, f64)> = Vec::new();
        for rc in &plan.robots {
            for (s, l) in rc.lc_start_s.iter().zip(&rc.lc_s) {
                for k in -1..=2 {
                    iv.push((s + f64::from(k) * p, s + l + f64::from(k) * p));
                }
            }
        }
        iv.sort_by(|a, b| a.0.total_cmp(&b.0));
        for w in iv.windows(2) {
            assert!(w[1].0 >= w[0].1 - 1e-9, "{w:?}");
        }
        for (rc, shape) in plan.robots.iter().zip(shapes) {
            let sup = repeated_shape(shape, rc.ratio).unwrap();
            for k in 1..sup.n_lc() {
                let lag = rc.lc_start_s[k] - rc.lc_start_s[k - 1];
                assert!(lag >= sup.lc_s[k - 1] + sup.gaps[k].min_s - 1e-9);
            }
            assert!(rc.ratio as f64 * shape.fastest_s() <= p + 1e-9);
        }
        assert!(plan.period_s >= plan.lower_bound_s - 1e-9);
        assert!(plan.tasks_per_hour <= plan.best_bound_per_hour * (1.0 + 1e-9));
    }

    #[test]
    fn plans_with_many_stretches_are_sound() {
        // Two tasks with three stretches each (holds: none; every gap a group boundary only
        // at the task start), a third without the operator.
        let mk = |runs: &[(usize, usize)], n: usize| {
            let conf: Vec<bool> = (0..n)
                .map(|i| !runs.iter().any(|&(a, b)| (a..b).contains(&i)))
                .collect();
            Problem::new(conf, vec![1.0; n], vec![0.5; n], vec![2.0; n], 0.01).unwrap()
        };
        let a = mk(&[(20, 60), (100, 130), (200, 210)], 260);
        let b = mk(&[(10, 20), (40, 45), (60, 80)], 100);
        let c = mk(&[], 80);
        let small = MixedParams {
            max_ratio: 3,
            max_ratio_candidates: 4,
            max_evaluations: 100,
            ..MixedParams::default()
        };
        for params in [
            small.clone(),
            MixedParams {
                handover_tick_s: Some(0.01),
                switch_s: 0.05,
                ..small.clone()
            },
            MixedParams {
                runnable_only: false,
                ..small
            },
        ] {
            let plan = mixed_cyclic_plan(&[&a, &b, &a, &c], &params).unwrap();
            let shapes: Vec<TaskShape> =
                [&a, &b, &a, &c].iter().map(|p| TaskShape::new(p)).collect();
            assert_sound(&plan, &shapes);
            assert_eq!(plan.robots[3].stretches_per_task, 0);
        }
        // Each of a's and b's tasks is one group (no hold between its stretches): an order
        // that puts b's stretch inside a's group is refused unless runnable_only is false.
        let shapes = [TaskShape::new(&a), TaskShape::new(&b)];
        let st = |robot: usize, lc: usize| Stretch { robot, lc };
        let order = [st(0, 0), st(1, 0), st(0, 1), st(0, 2), st(1, 1), st(1, 2)];
        let e = mixed_plan_for_order(&shapes, &[1, 1], &order, &MixedParams::default());
        assert!(e.unwrap_err().to_string().contains("runnable"));
        let loose = MixedParams {
            runnable_only: false,
            ..MixedParams::default()
        };
        // As a plan it is infeasible: b's stretch 1 must start within 0.1 + 0.4 s of its
        // stretch 0 (gap of 20 samples at ψ̇max 2), but a's 0.3 s stretch, its 0.35 s gap
        // and 0.1 s stretch come between them.
        assert!(matches!(
            mixed_plan_for_order(&shapes, &[1, 1], &order, &loose),
            Err(Error::InfeasibleCycle { .. })
        ));
    }

    #[test]
    fn bad_inputs_are_named() {
        let a = task(10, 10);
        let msg = |e: Error| e.to_string();
        let p = |f: fn(&mut MixedParams)| {
            let mut p = MixedParams::default();
            f(&mut p);
            msg(mixed_cyclic_plan(&[&a], &p).unwrap_err())
        };
        assert!(p(|p| p.max_ratio = 0).contains("max_ratio"));
        assert!(p(|p| p.max_ratio = 9).contains("max_ratio"));
        assert!(p(|p| p.max_evaluations = 0).contains("max_evaluations"));
        assert!(p(|p| p.handover_tick_s = Some(0.0)).contains("handover_tick_s"));
        assert!(p(|p| p.switch_s = f64::NAN).contains("switch_s"));
        let s = [TaskShape::new(&a)];
        assert!(
            msg(mixed_period_lower_bound_s(&s, &[1, 1], None, 0.0).unwrap_err()).contains("ratios")
        );
        let bad = [Stretch { robot: 0, lc: 1 }];
        assert!(
            msg(mixed_plan_for_order(&s, &[1], &bad, &MixedParams::default()).unwrap_err())
                .contains("order")
        );
    }

    #[test]
    fn the_plan_runs_at_its_period_under_the_planned_operator() {
        // A (D = 2 s, L = 1 s) beside B (D = 0.75 s, L = 0.25 s), the plan counting the
        // token rule's hand-overs at a 10 ms tick: ratios (1, 4) (robot 1's four stretches,
        // each entered 0.25 s after its gate, cost the hand-overs robot 0's one does not).
        // Its coordinator at that tick under the planned operator: no overlap, robot 1
        // completing 4 tasks per task of robot 0, and over tasks 10..40 of robot 0 the
        // realized period within 1 % of the plan's.
        let (a, b) = (task(100, 100), task(50, 25));
        let params = MixedParams {
            handover_tick_s: Some(0.01),
            max_ratio: 4,
            ..MixedParams::default()
        };
        let plan = mixed_cyclic_plan(&[&a, &b], &params).unwrap();
        assert_eq!(plan.ratios, [1, 4]);
        let mut c = plan.coordinator(&[&a, &b], &[0, 1], 0.01).unwrap();
        assert!(plan.coordinator(&[&a], &[0, 1], 0.01).is_err());
        assert!(plan.coordinator(&[&a, &a], &[0, 1], 0.01).is_ok());
        let mut at_10 = None;
        for tick in 1..=20_000u64 {
            let t = c.tick(tandem_realtime::Operator::Scheduled).unwrap();
            assert!(!t.overlap());
            if at_10.is_none() && c.tasks_completed()[0] == 10 {
                at_10 = Some((tick, c.tasks_completed()[1]));
            }
            if c.tasks_completed()[0] == 40 {
                let (t10, b10) = at_10.unwrap();
                let period = (tick - t10) as f64 * 0.01 / 30.0;
                assert!(
                    (period - plan.period_s).abs() <= 0.01 * plan.period_s,
                    "{period} against {}",
                    plan.period_s
                );
                let b = c.tasks_completed()[1] - b10;
                assert!((119..=121).contains(&b), "{b}");
                return;
            }
        }
        panic!("robot 0 did not complete 40 tasks");
    }

    /// A long task of five low-confidence runs with a hold in every gap between them, at
    /// 10 ms, `ψ̇̄ = 1`, `ψ̇min = 0.5`: head 0.5 s, runs of 1 s, gaps of 1 s, tail 0.5 s
    /// (`D = 10` s, `L = 5` s); beside it a short task 0.25 + 0.5 + 0.25 s (`D = 1` s,
    /// `L = 0.5` s) without holds.
    fn long_and_short() -> (Problem, Problem) {
        let (mut conf, mut holds) = (vec![true; 100], Vec::new());
        for j in 0..5 {
            conf.extend([false; 100]);
            if j < 4 {
                holds.push(conf.len() + 100);
                conf.extend([true; 200]);
            }
        }
        conf.extend([true; 100]);
        let n = conf.len();
        let a = Problem::new(conf, vec![1.0; n], vec![0.5; n], vec![2.0; n], 0.01)
            .unwrap()
            .with_holds(holds)
            .unwrap();
        (a, task(50, 50))
    }

    #[test]
    fn the_short_robots_groups_go_into_the_long_robots_gaps() {
        // Ratios ≤ 4: every r = (1, q) has the bound max(5 + 0.5·q, 10, q) = 10 s, so (1, 4)
        // allows the most, 5 tasks per 10 s = 1800/h. It is reached: the long robot runs at
        // its fastest, runs at [0.5, 1.5], [2.5, 3.5], … [8.5, 9.5] s, and the short robot's
        // four stretches fill its four gaps, [1.5, 2], [3.5, 4], [5.5, 6], [7.5, 8] s (2 s
        // apart ≥ its 1 s chain; it waits at its task start, a hold). So the plan is
        // optimal. The greedy order with neighbouring swaps stopped at 10.5 s (1714/h): the
        // greedy order starts the short robot first and the swaps could not move its
        // stretches by more than one group.
        let (a, b) = long_and_short();
        let params = MixedParams {
            max_ratio: 4,
            ..MixedParams::default()
        };
        let plan = mixed_cyclic_plan(&[&a, &b], &params).unwrap();
        assert_eq!(plan.ratios, [1, 4]);
        assert!(
            (plan.lower_bound_s - 10.0).abs() < 1e-9,
            "{}",
            plan.lower_bound_s
        );
        assert!((plan.period_s - 10.0).abs() < 1e-9, "{}", plan.period_s);
        assert!((plan.tasks_per_hour - 1800.0).abs() < 1e-6);
        assert_sound(&plan, &[TaskShape::new(&a), TaskShape::new(&b)]);
        // The operator alternates: one short stretch between two long ones, four times.
        let robots: Vec<usize> = plan.order.iter().map(|s| s.robot).collect();
        let switches = (0..robots.len())
            .filter(|&q| robots[q] != robots[(q + 1) % robots.len()])
            .count();
        assert_eq!(switches, 8, "{robots:?}");
        // Ratios up to 6: the short robot fits one stretch into each gap and one into the
        // long robot's tail and head (1 s): (1, 5) at 10 s, 2160/h, on its bound; (1, 6)
        // has the bound 10 s too (2520/h) but no sixth slot: the plan is at least (1, 5)'s.
        let plan = mixed_cyclic_plan(&[&a, &b], &MixedParams::default()).unwrap();
        assert!(plan.tasks_per_hour >= 2160.0 - 1e-6, "{plan:?}");
        assert!(plan.ratios[1] >= 5);
        assert_sound(&plan, &[TaskShape::new(&a), TaskShape::new(&b)]);
    }
}
