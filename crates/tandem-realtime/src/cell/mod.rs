//! A continuous cell at run time (issue 21): `N` robots each repeat the same task for ever,
//! one operator supervises their low-confidence stretches in a fixed cyclic order, and no
//! robot waits for a round to end.
//!
//! **The task and its groups.** Every robot runs the same task plan (a [`Timeline`](crate::Timeline) started at
//! schedule clock 0, typically the fastest warp: `ψ̇min` on high-confidence samples, `ψ̇̄` on
//! low-confidence ones). Its maximal low-confidence runs are the *stretches* `0..m`, in
//! reference order. Consecutive stretches with no usable hold between them (a hold at sample
//! `h` with `ref_end(k) < h < ref_start(k + 1)`, samples `h − 1` and `h` high-confidence) form
//! one [`Group`]: a robot cannot stop between them. Before each group lies its *gate*: the
//! last usable hold before the group's first stretch, or the task start (sample 0, always a
//! hold). So a robot between two groups, or waiting at a gate, is on high-confidence samples
//! only.
//!
//! **The token rule.** The operator's cyclic order of stretches `(robot, lc)` becomes a cyclic
//! sequence of [`Token`]s `(robot, group)` ([`token_sequence`]). At run time:
//! - a robot whose next group is not the current token's waits at that group's gate (clock
//!   stopped, high-confidence);
//! - the token's robot may pass its gate, but not the gate of its following group;
//! - when the token's robot has *left* its group (its schedule clock at least `tol` past the
//!   end of the group's last low-confidence sample, `tol` = the clock tolerance of
//!   [`crate::tol`], or at the task's end), the token moves to the next entry, at the end of
//!   the tick;
//! - a robot that finishes task `k` is at sample 0 of task `k + 1` (the start hold) at the end
//!   of that tick and goes on as far as its gate.
//!
//! In the first pass through the sequence the entries of a robot that precede its group 0 are
//! skipped: in the cyclic plan they belong to the task it started one period earlier, which
//! at run time does not exist.
//!
//! **Why it is sound, for any number of tasks and any operator.** Call a robot *inside* from
//! the tick start at which it holds the token for its next group until the tick end at which
//! it leaves that group. The token has one holder, and it moves only at a tick end, once its
//! holder has left; so at most one robot is inside during any tick. A robot that is not
//! inside is, during the whole tick, between the point `tol` past the end of its previous
//! group's last low-confidence sample and its next gate (the clock is capped there), or
//! waiting at the start; the samples it can traverse, even widened by `tol` on both sides,
//! are high-confidence (the gate's sample and the one before it are high-confidence, and no
//! low-confidence sample lies between a group and the next gate). So every low-confidence tick
//! (any low-confidence sample in the traversed interval `[s_old − tol, s_new + tol]`, the
//! rounds coordinator's conservative definition) is a tick of the one robot inside: two robots
//! are never low-confidence in one tick. Nothing here depends on the operator's rates, on the
//! number of tasks, or on where a task ends — the drift of the clocks never matters, because
//! the robots never rely on a margin: they wait.
//!
//! **M operators (issue 44).** With [`ContinuousCoordinator::with_operators`] the cell has `M`
//! tokens, one per operator. The cyclic sequence orders the robots waiting for an operator:
//! at the end of every tick (and at the start), the robots that wait at the gate of their next
//! group and hold no operator are taken in the order of their next entries `(robot, group)` in
//! the sequence, and each is *granted* a free operator — one that holds no entry and whose
//! switch time is over for that robot (below); the robot's last operator if it qualifies, else
//! the lowest index — until one cannot be granted (a robot is overtaken only by robots whose
//! entries come first). A robot still on its way to its gate holds back neither an operator
//! nor the robots behind it (the one-operator rule run with `M` tokens did: its next entry's
//! robot, often still inside its previous group, stopped every grant while operators idled).
//! A robot granted an operator may pass its gate, but not the gate
//! of its following group; once it has *left* the group (as above) the operator is released,
//! at the end of that tick. A robot's rate on low confidence is its operator's input
//! ([`ContinuousCoordinator::tick_many`], one input per operator). With `M = 1` the cell runs
//! the one-operator token rule above (the token granted when it moves, whether or not its
//! robot is at the gate yet, released when it moves on): the same ticks, bit for bit.
//!
//! *Soundness with M operators, for any inputs and any number of tasks.* Call a robot inside
//! from the tick start at which it holds an operator until the tick end at which it leaves its
//! group. Each inside robot holds one operator and each operator at most one entry, so at most
//! `M` robots are inside during any tick; a robot that is not inside traverses high-confidence
//! samples only (the argument above, word for word). So at most `M` robots are low-confidence
//! in any tick, and each of them is inside, with the operator it was granted before it passed
//! its gate and keeps until it has left the group: a stretch is never handed over mid-way
//! ([`Tick::operator`](crate::Tick::operator) names it). *Switch time, per operator*: when
//! operator `o`'s robot leaves at the end of tick `a`, `o` may be granted to *another* robot
//! for its group `G` only from tick `a + 1 + k − min(k, e_G)` on, `e_G` the whole ticks a robot
//! surely travels from `G`'s gate before it is low-confidence in `G` (it travels while the
//! operator switches), so between two robots' stretches of one operator at least `k` ticks
//! pass in which `o` supervises no one. *Liveness*: a robot that is not inside reaches its
//! next gate (or its task's end, then the start of the next) in finitely many ticks on
//! high-confidence samples; an inside robot leaves its group in finitely many ticks (rate at
//! least `S`), releasing its operator, whose switch time ends `k` ticks later. A robot waiting
//! at its gate with next entry `K` is overtaken only by grants of entries before `K`, and each
//! entry is granted once: finitely many. So it is granted in finitely
//! many ticks: no deadlock, every robot keeps completing tasks (docs/decisions.md, "M
//! operators: the invariant and the continuous cell (issue 44)" and "The pooled cell grants
//! the robots at their gates (issue 44)").
//! The pre-alert is computed for one operator only (`None` with `M > 1`).
//!
//! **Runnable orders.** The rule needs each group to be contiguous in the order: between two
//! stretches of one robot with no usable hold between them no other robot's stretch may come
//! (the robot cannot wait there for it). [`is_runnable`] checks it; [`token_sequence`] rejects
//! other orders. Each robot's stretches must also come in task order around the cycle.
//!
//! **A cell of different tasks (issue 45).** [`ContinuousCoordinator::mixed`] gives robot `k`
//! its own task plan (its timeline, holds and so its groups, gates, leave points and
//! pre-alert tables) and `r_k` tasks per pass: the operator's order lists robot `k`'s
//! stretches of its `r_k` tasks, and its tokens are its own groups, `r_k` times per pass
//! ([`mixed_token_sequence`]). Every step of the rule and of its argument above reads one
//! robot's own timeline only (where it waits, what it traverses, when it has left its
//! group), so it holds unchanged: at most `M` robots inside, the rest on high-confidence
//! samples of their own tasks. A one-task cell is [`ContinuousCoordinator::new`]'s, tick for
//! tick.
//!
//! **Liveness.** Each robot's tokens come in its task order (group 0, 1, …, then group 0 of its
//! next task), which is the order in which it reaches its gates; so the token's robot always
//! reaches the token's gate (it runs on high-confidence samples at least at `S·tick_s > 0`
//! per tick) and leaves the group (the operator's rate is at least `S` too). No deadlock.
//! Across hand-overs to new plans ([`ContinuousCoordinator::take_over`]) the token goes to the
//! robot whose turn it was, or to the robot served least recently once one has waited a
//! whole pass, so however often the plan changes, between two of a robot's passages through
//! a group another robot passes at most `(2N − 1)·G` groups (`G` per task):
//! docs/decisions.md, "Hand-over liveness".
//!
//! **The period.** Under the planned operator (`Operator::Scheduled`) the cell settles into
//! the cyclic plan's rhythm minus what the rule costs: a robot starts moving from its gate only
//! once the token is its, so each hand-over costs the operator the travel from the gate to the
//! stretch (one sample when the gate is next to the stretch) plus the tick quantization
//! (about a tick). `tandem-schedule`'s cyclic plan counts both when it is given the cell's
//! tick (`CyclicParams::handover_tick_s`), so its period is then the cell's.
//! Under drift the period is not guaranteed; only soundness is.
//!
//! ```
//! use tandem_realtime::cell::ContinuousCoordinator;
//! use tandem_realtime::{Operator, Timeline};
//!
//! // [HC, LC, HC] at Δt_s = 1 s, ψ̇ = 1 everywhere: a task of 3 s with one 1 s stretch.
//! let task = Timeline::new(&[true, false, true], &[1.0; 3], &[0.5; 3], &[2.0; 3], 0.0, 1.0)?;
//! // Two robots, the operator's order: robot 0's stretch, then robot 1's. Gates at the start.
//! let mut cell = ContinuousCoordinator::new(task, &[], &[(0, 0), (1, 0)], 2, 1.0)?;
//! let t = cell.tick(Operator::Scheduled)?; // robot 0 moves to 1 s, robot 1 waits at 0
//! assert_eq!((t.ref_time[0], t.ref_time[1]), (1.0, 0.0));
//! assert!(t.waiting[1] && !t.running[1]);
//! for _ in 0..1000 {
//!     assert!(!cell.tick(Operator::Fastest)?.overlap());
//! }
//! assert!(cell.tasks_completed().iter().all(|&k| k > 100));
//! # Ok::<(), tandem_realtime::Error>(())
//! ```

mod coordinator;
mod groups;
#[cfg(test)]
mod liveness;
mod nest;
pub(crate) mod pace;

#[allow(deprecated)]
pub use coordinator::{CellRun, CellTick};
pub use coordinator::{ContinuousCoordinator, SectorOrder, run_cell};
pub use groups::{
    Group, Token, first_split_group, groups, is_runnable, mixed_token_sequence, token_sequence,
};
