//! A continuous cell: `N` robots repeating the same task with one operator, as a repeated
//! (1-periodic) plan, and its exact period (issue 21; docs/decisions.md, "A continuous cell:
//! the cyclic plan and its exact period").
//!
//! **The model.** The task is cut by [`Problem::runs`] into high- and low-confidence runs;
//! the `m` low-confidence runs are the task's *stretches*. In the plan every robot follows
//! `ψ̇̄` on low-confidence samples (the operator supervises them; Eq. 20 constraint 4), so
//! stretch `k` lasts exactly `L_k = Σ ψ̇̄·Δt_s`; on high-confidence samples it runs at any
//! rate in `[ψ̇min, ψ̇max]`, and at a usable hold point ([`Problem::usable_holds`]) and at the
//! task start (always a hold) it may wait any time. So the gap between two consecutive
//! stretches of one robot lasts `[Σψ̇min·Δt_s, Σψ̇max·Δt_s]` without a hold and
//! `[Σψ̇min·Δt_s, ∞)` with one; from its last stretch to the first of its next task it
//! passes the task start, so that gap has no upper bound. In one period of `P` seconds each
//! robot does one task and the operator supervises all `N·m` stretches once, one at a time,
//! in a cyclic `order` ([`Stretch`]s; each robot's in task order, starting anywhere: a task
//! may straddle the period's end).
//!
//! **The event graph** ([`event_graph`]): per robot a node for leaving its task start and
//! one per stretch start; arcs ([`Arc`]: `t[to] ≥ t[from] + w − P·h`) for the head
//! (minimum, and a backward maximum when the head has no hold), each gap (`L_k + min`, and
//! the backward `−(L_k + max)` without a hold), the last stretch and the tail to the next
//! task's start (one token), and the operator: the end of each stretch in `order` before
//! the start of the next (weight `L`), the wrap to the first one token later. A stretch that
//! comes before its robot's stretch 0 in the period belongs to the task started one period
//! earlier ([`EventGraph::wrapped`]); the robot's arcs carry the difference in periods as
//! tokens, so a backward arc across the period boundary carries `−1`. The least period is
//! the maximum cycle ratio of the graph ([`max_cycle_ratio`], exact: module docs of
//! `ratio`), and its event times are the plan ([`CyclicPlan`], [`cyclic_plan_for_order`]).
//! [`cyclic_plan`] searches the order.
//!
//! **What the period assumes.** The operator follows `ψ̇̄` on every low-confidence stretch
//! and the robots run at their planned rates; the period is the plan's, not a run-time
//! guarantee. At run time [`CyclicPlan::coordinator`] runs the plan with the token rule of
//! `tandem_realtime::continuous` (a robot waits at the gate of its next group of stretches
//! until the previous group in the order has been left), which is sound across cycle
//! boundaries by construction, for any operator and any number of tasks; it needs a
//! *runnable* order ([`is_runnable`]), which [`cyclic_plan`] searches by default
//! ([`CyclicParams::runnable_only`]). The rule costs the operator, at every hand-over to
//! another robot's group, the travel from the group's gate to its first stretch and about a
//! tick; with [`CyclicParams::handover_tick_s`] (the cell's control tick) the operator arc
//! into such a stretch carries that cost ([`TaskShape::entry_s`] plus one tick), so the period
//! is what the cell does under the planned operator and the search optimizes it.
//!
//! **The certificate.** [`period_lower_bound_s`] `= max(N·(L + I), D_min)` holds for every
//! order: the operator's load `N·L`, its forced idle time `N·I` in gaps without hold too
//! short for any stretch, and a robot's fastest task `D_min`; the plan reports its gap to it.
//! A plan searched among runnable orders with the hand-overs counted reports its gap to
//! [`handover_bound_s`] instead, the bound of every such plan (each group's span and entry,
//! and a tick per robot change).
//!
//! ```
//! use tandem_schedule::{Problem, cyclic_plan, CyclicParams};
//!
//! // 1 s of high confidence (ψ̇min 0.5: 0.5 s at the fastest), 1 s of low confidence, 1 s of
//! // high confidence, at 10 ms.
//! let conf: Vec<bool> = (0..300).map(|n| !(100..200).contains(&n)).collect();
//! let problem = Problem::new(conf, vec![1.0; 300], vec![0.5; 300], vec![2.0; 300], 0.01)?;
//! // One robot: its own fastest task, 0.5 + 1 + 0.5 s.
//! let one = cyclic_plan(&problem, 1, &CyclicParams::default())?;
//! assert!((one.period_s - 2.0).abs() < 1e-9);
//! // Three robots: the operator is the bottleneck, 3 × 1 s per period, 3600 tasks/h.
//! let three = cyclic_plan(&problem, 3, &CyclicParams::default())?;
//! assert!((three.period_s - 3.0).abs() < 1e-9 && three.gap.abs() < 1e-9);
//! assert!((three.tasks_per_hour - 3600.0).abs() < 1e-6);
//! assert!((three.operator_share - 1.0).abs() < 1e-9);
//! # Ok::<(), tandem_schedule::Error>(())
//! ```

mod checked;
mod fleet;
mod graph;
mod mix;
mod mixed;
mod plan;
mod ratio;
mod run;
mod search;

pub use checked::CheckedCyclicPlan;
pub use fleet::{
    FleetCellChoice, SectoredPlan, fleet_cell_choice, nominal_tasks_per_hour,
    pooled_period_lower_bound_s, sectored_coordinator, sectored_plan,
};
pub use graph::{Event, EventGraph, Gap, Stretch, TaskShape, event_graph};
pub use mix::{MAX_MIX_RATIO, MixBound, MixTask, best_mix, mix_period_lower_bound_s};
pub use mixed::{
    MixedCyclicPlan, MixedParams, MixedRobotCycle, mixed_cyclic_plan, mixed_period_lower_bound_s,
    mixed_plan_for_order, mixed_plan_of_shapes, repeated_shape,
};
pub use plan::{
    CyclicPlan, GapPlan, RobotCycle, cyclic_plan_for_order, handover_bound_s, period_lower_bound_s,
    period_lower_bound_with_switch_s,
};
pub use ratio::{Arc, CycleRatio, max_cycle_ratio};
pub use run::is_runnable;
pub use search::{CyclicParams, cyclic_plan, order_count};

#[cfg(doc)]
use crate::Problem;
