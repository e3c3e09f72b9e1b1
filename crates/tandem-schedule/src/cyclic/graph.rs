//! The event graph of a 1-periodic plan for a fixed operator order (module docs of
//! [`crate::cyclic`]).

use serde::{Deserialize, Serialize};

use super::ratio::Arc;
use crate::problem::check_robot_count;
use crate::{Error, Problem, Result};

/// One low-confidence stretch of one robot's task: the operator's unit of work.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stretch {
    /// The robot (0-based).
    pub robot: usize,
    /// Which low-confidence run of the task (0-based, in reference order; the `lc`-th run of
    /// [`Problem::runs`] with `high_conf == false`).
    pub lc: usize,
}

/// The stretch as `tandem_realtime::continuous` names it: `(robot, lc)`.
impl From<Stretch> for (usize, usize) {
    fn from(s: Stretch) -> (usize, usize) {
        (s.robot, s.lc)
    }
}

/// What a node of an [`EventGraph`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Event {
    /// The robot leaves its task start (reference sample 0, a hold) for its next task.
    TaskStart {
        /// The robot (0-based).
        robot: usize,
    },
    /// The robot enters a low-confidence stretch; it leaves it `lc_s[lc]` later.
    LcStart(Stretch),
}

/// The task cut into its runs, in schedule-clock seconds (every duration a sum of
/// `ψ̇·Δt_s` over the run's samples, as the clock sums them).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TaskShape {
    /// Duration (s) of each low-confidence run at `ψ̇̄` (Eq. 20 constraint 4), in order.
    pub lc_s: Vec<f64>,
    /// The `m + 1` high-confidence gaps (`m` = number of low-confidence runs): gap 0 is the
    /// head (before the first run), gap `k` lies between runs `k − 1` and `k`, gap `m` is the
    /// tail. Without low-confidence runs there is one gap, the whole task.
    pub gaps: Vec<Gap>,
    /// Per stretch `k`, when it opens a group of the token rule (`k = 0`, or a usable hold in
    /// gap `k`: `tandem_realtime::continuous::groups`), the fastest travel (s, `Σψ̇min·Δt_s`
    /// over the samples from its gate to its first sample) from its gate — the latest usable
    /// hold before it, or the task start — to its start; 0 for a stretch inside a group. At a
    /// hand-over the token's robot leaves its gate only once the previous group has been
    /// left, so the operator waits this long ([`crate::CyclicParams::handover_tick_s`]).
    pub entry_s: Vec<f64>,
}

/// One high-confidence gap of the task (see [`TaskShape::gaps`]); empty gaps have zero
/// durations.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gap {
    /// First reference sample of the gap.
    pub ref_start: usize,
    /// One past its last reference sample.
    pub ref_end: usize,
    /// Its fastest traversal (s): `Σ ψ̇min·Δt_s`.
    pub min_s: f64,
    /// Its slowest traversal without waiting (s): `Σ ψ̇max·Δt_s`.
    pub max_s: f64,
    /// The latest usable hold point inside the gap ([`Problem::usable_holds`]), where a robot
    /// may wait any time: with one, the gap has no upper bound.
    pub hold: Option<usize>,
}

impl TaskShape {
    /// The runs of `problem` as a task shape.
    #[must_use]
    pub fn new(problem: &Problem) -> TaskShape {
        let dt = problem.dt_s();
        let usable = problem.usable_holds();
        let sum =
            |g: &[f64], from: usize, to: usize| tandem_realtime::clock_end_s(&g[from..to], 0.0, dt);
        let gap = |from: usize, to: usize| Gap {
            ref_start: from,
            ref_end: to,
            min_s: sum(problem.grad_min(), from, to),
            max_s: sum(problem.grad_max(), from, to),
            hold: usable.iter().copied().rfind(|&h| from < h && h < to),
        };
        let mut lc_s = Vec::new();
        let mut gaps = Vec::new();
        let mut entry_s = Vec::new();
        let mut from = 0;
        for run in problem.runs().iter().filter(|r| !r.high_conf) {
            let g = gap(from, run.start);
            // The gate of a group's first stretch: its gap's hold, or the task start for the
            // first stretch; a stretch after a gap without a hold continues a group.
            entry_s.push(match (gaps.is_empty(), g.hold) {
                (_, Some(h)) => sum(problem.grad_min(), h, run.start),
                (true, None) => g.min_s,
                (false, None) => 0.0,
            });
            gaps.push(g);
            lc_s.push(sum(problem.grad_mean(), run.start, run.end));
            from = run.end;
        }
        gaps.push(gap(from, problem.n_ref()));
        TaskShape {
            lc_s,
            gaps,
            entry_s,
        }
    }

    /// Whether stretch `k` opens a group of the token rule: the first stretch, or one after a
    /// gap with a usable hold (the robot may wait before it).
    #[must_use]
    pub fn opens_group(&self, k: usize) -> bool {
        k == 0 || self.gaps.get(k).is_some_and(|g| g.hold.is_some())
    }

    /// Number of low-confidence runs `m`.
    #[must_use]
    pub fn n_lc(&self) -> usize {
        self.lc_s.len()
    }

    /// `L` (s): the task's total low-confidence duration at `ψ̇̄`.
    #[must_use]
    pub fn lc_total_s(&self) -> f64 {
        self.lc_s.iter().sum()
    }

    /// `I` (s): the operator's forced idle time per task — the sum of the fastest durations
    /// of the gaps between two stretches that have no hold and are shorter, even at their
    /// slowest (`Σψ̇max·Δt_s`), than the shortest stretch: no stretch of another robot fits
    /// in such a gap, so the operator supervises nothing during it
    /// ([`crate::cyclic::period_lower_bound_s`]).
    #[must_use]
    pub fn idle_s(&self) -> f64 {
        let shortest = self.lc_s.iter().copied().fold(f64::INFINITY, f64::min);
        let m = self.n_lc();
        (1..m)
            .map(|k| self.gaps[k])
            .filter(|g| g.hold.is_none() && g.max_s < shortest)
            .map(|g| g.min_s)
            .sum()
    }

    /// `D_min` (s): the fastest task (every high-confidence sample at `ψ̇min`, low-confidence
    /// ones at `ψ̇̄`), summed as the robot's cycle in the event graph sums it.
    #[must_use]
    pub fn fastest_s(&self) -> f64 {
        let m = self.n_lc();
        if m == 0 {
            return self.gaps[0].min_s;
        }
        // Arc weights of the robot's cycle: head, then lc_k + gap_{k+1}, the last with the
        // tail (and the head is its own arc).
        let mut d = self.gaps[0].min_s;
        for k in 0..m - 1 {
            d += self.lc_s[k] + self.gaps[k + 1].min_s;
        }
        d + (self.lc_s[m - 1] + self.gaps[m].min_s)
    }
}

/// The event graph of a 1-periodic plan of `n_robots` robots with one operator order: nodes
/// ([`EventGraph::events`]), arcs for [`super::max_cycle_ratio`], and the bookkeeping that
/// turns its event times into a plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EventGraph {
    /// What each node is: per robot `r`, node `r·(m + 1)` is its task start and node
    /// `r·(m + 1) + 1 + k` the start of its stretch `k`.
    pub events: Vec<Event>,
    /// The arcs (module docs of [`crate::cyclic`]).
    pub arcs: Vec<Arc>,
    /// The task cut into runs.
    pub shape: TaskShape,
    /// Per robot, per stretch: 1 when, in the operator's period, the stretch comes before the
    /// robot's stretch 0 (the task started in period `p` runs it in period `p + 1`), else 0.
    pub wrapped: Vec<Vec<u8>>,
}

impl EventGraph {
    /// Node of robot `robot`'s task start.
    #[must_use]
    pub fn task_start_node(&self, robot: usize) -> usize {
        robot * (self.shape.n_lc() + 1)
    }

    /// Node of the start of stretch `s`.
    #[must_use]
    pub fn stretch_node(&self, s: Stretch) -> usize {
        s.robot * (self.shape.n_lc() + 1) + 1 + s.lc
    }
}

/// Checks an operator order: every stretch `(robot < n_robots, lc < m)` exactly once, and each
/// robot's stretches in task order around the cycle (starting anywhere).
pub(crate) fn check_order(order: &[Stretch], n_robots: usize, m: usize) -> Result<()> {
    let bad = |why: &'static str| Error::BadParam { name: "order", why };
    if order.len() != n_robots * m {
        return Err(bad(
            "must list every robot's every low-confidence stretch once",
        ));
    }
    let mut seen = vec![false; n_robots * m];
    for s in order {
        if s.robot >= n_robots || s.lc >= m {
            return Err(bad("names a robot or a stretch that does not exist"));
        }
        let i = s.robot * m + s.lc;
        if seen[i] {
            return Err(bad("names a stretch twice"));
        }
        seen[i] = true;
    }
    if m == 0 {
        return Ok(());
    }
    // Cyclic task order: reading from the robot's stretch 0, its stretches come 0, 1, …, m − 1.
    for r in 0..n_robots {
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

/// The event graph of `n_robots` robots repeating `problem`'s task with the operator's cyclic
/// order `order` (module docs of [`crate::cyclic`]).
///
/// # Errors
/// [`Error::Realtime`] (`RobotCount`) for `n_robots` outside `1..=MAX_ROBOTS`;
/// [`Error::BadParam`] for an order that does not
/// list every stretch once with each robot's stretches in task order around the cycle.
pub fn event_graph(problem: &Problem, n_robots: usize, order: &[Stretch]) -> Result<EventGraph> {
    graph_of_shape(TaskShape::new(problem), n_robots, order, None, 0.0)
}

/// [`event_graph`] of a task shape already cut from its problem; with `handover_tick_s`
/// (the control tick of the token-rule cell, s) every operator arc into a stretch that opens
/// a group of another robot also carries the hand-over: the stretch's
/// [`TaskShape::entry_s`] plus one tick ([`crate::CyclicParams::handover_tick_s`]). With the
/// operator's switch time `switch_s > 0` every operator arc between stretches of different
/// robots carries at least `switch_s` ([`crate::CyclicParams::switch_s`]).
pub(crate) fn graph_of_shape(
    shape: TaskShape,
    n_robots: usize,
    order: &[Stretch],
    handover_tick_s: Option<f64>,
    switch_s: f64,
) -> Result<EventGraph> {
    check_robot_count(n_robots)?;
    let m = shape.n_lc();
    check_order(order, n_robots, m)?;
    let per = m + 1;
    let mut events = Vec::with_capacity(n_robots * per);
    for robot in 0..n_robots {
        events.push(Event::TaskStart { robot });
        for lc in 0..m {
            events.push(Event::LcStart(Stretch { robot, lc }));
        }
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
    // Position of every stretch in the operator's period.
    let mut pos = vec![0usize; n_robots * m];
    for (q, s) in order.iter().enumerate() {
        pos[s.robot * m + s.lc] = q;
    }
    let mut wrapped = vec![vec![0u8; m]; n_robots];
    for r in 0..n_robots {
        let a = r * per;
        if m == 0 {
            // The whole task, back to the start: one task per period.
            push(a, a, shape.gaps[0].min_s, 1);
            continue;
        }
        for k in 0..m {
            wrapped[r][k] = u8::from(pos[r * m + k] < pos[r * m]);
        }
        push_robot_chain(&shape, a, &wrapped[r], &mut push);
    }
    // The operator: each stretch after the one before it has ended; the wrap is next period.
    let len = order.len();
    for q in 0..len {
        let (from, to) = (order[q], order[(q + 1) % len]);
        let node = |s: Stretch| s.robot * per + 1 + s.lc;
        // The token rule: `to`'s robot leaves its gate once `from`'s group has been left
        // (detected at a tick's end), then travels to the stretch.
        let handover = match handover_tick_s {
            Some(tick_s) if to.robot != from.robot && shape.opens_group(to.lc) => {
                shape.entry_s[to.lc] + tick_s
            }
            _ => 0.0,
        };
        // The operator's switch time: the next stretch of another robot starts at least δ
        // after this one ended (the larger of δ and the hand-over, both counted from the end).
        let handover = if switch_s > 0.0 && to.robot != from.robot {
            handover.max(switch_s)
        } else {
            handover
        };
        push(
            node(from),
            node(to),
            shape.lc_s[from.lc] + handover,
            i32::from(q + 1 == len),
        );
    }
    Ok(EventGraph {
        events,
        arcs,
        shape,
        wrapped,
    })
}

/// The arcs of one robot's own chain in the event graph: its task start (event `a`) → its
/// stretch 0 (event `a + 1`) → … → its last stretch (event `a + m`) → its next task's start,
/// each after the stretch before it and the gap between (at least the gap's fastest
/// duration, s), and back from each stretch to the one before it by the gap's slowest
/// duration where the gap has no hold (a robot cannot wait there). `wrapped[k]` is 1 when
/// stretch `k` falls in the period after stretch 0's in the operator's order (the arc's
/// tokens); the arc into the next task's start carries the period's one token. Used by the
/// one-task graph and the mixed cell's (one repeated shape per robot).
pub(crate) fn push_robot_chain(
    shape: &TaskShape,
    a: usize,
    wrapped: &[u8],
    push: &mut impl FnMut(usize, usize, f64, i32),
) {
    let m = wrapped.len();
    let w = |k: usize| i32::from(wrapped[k]);
    let s = |k: usize| a + 1 + k;
    // Head: leave the start, reach stretch 0.
    let head = shape.gaps[0];
    push(a, s(0), head.min_s, 0);
    if head.hold.is_none() {
        push(s(0), a, -head.max_s, 0);
    }
    // Stretch k, then gap k + 1, then stretch k + 1.
    for k in 0..m - 1 {
        let gap = shape.gaps[k + 1];
        let h = w(k + 1) - w(k);
        push(s(k), s(k + 1), shape.lc_s[k] + gap.min_s, h);
        if gap.hold.is_none() {
            push(s(k + 1), s(k), -(shape.lc_s[k] + gap.max_s), -h);
        }
    }
    // The last stretch, the tail, the task start (a hold: no maximum) of the next task.
    push(
        s(m - 1),
        a,
        shape.lc_s[m - 1] + shape.gaps[m].min_s,
        1 - w(m - 1),
    );
}
