//! The one cursor type and the one operator step of every controller (rounds and the
//! continuous cell): how a robot's monotone cursors index its plan, and the schedule-clock step
//! the operator's input gives a low-confidence robot (§II-B5).

use crate::Operator;
use crate::timeline::Timeline;

/// Per-robot monotone cursors into its plan (each O(1) amortized: a schedule clock never
/// decreases on one plan; a controller resets them when the robot changes plan — a leg, a
/// task).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Cursors {
    /// Sample containing the schedule clock (mode and rates are read here).
    pub(crate) at: usize,
    /// Sample containing `clock − tol` (first sample a tick may traverse).
    pub(crate) lo: usize,
    /// Sample containing `clock + tol` (last sample a tick may traverse).
    pub(crate) hi: usize,
}

impl Cursors {
    /// All three cursors at sample `k`.
    pub(crate) fn at(k: usize) -> Cursors {
        Cursors {
            at: k,
            lo: k,
            hi: k,
        }
    }
}

/// Schedule-clock step (s) of a low-confidence robot at sample `n` of its plan `plan` in one
/// control tick of `tick_s` real seconds, commanded by the operator's input `op`: the gradient
/// `g` it gives (`ψ̇_E` without a correction, `ψ̇min` rushing, `ψ̇max` dragging, or a commanded
/// gradient clamped to `[ψ̇min, ψ̇max]`) gives the step `(ψ̇_E/g)·tick_s`. `op` is checked
/// ([`Operator::validate`]) by the caller.
pub(crate) fn operator_step(plan: &Timeline, n: usize, op: Operator, tick_s: f64) -> f64 {
    let (lo, hi, e) = (plan.grad_min()[n], plan.grad_max()[n], plan.grad_exec()[n]);
    let g = match op {
        Operator::Scheduled => e,
        Operator::Gradient(x) => x.clamp(lo, hi),
        Operator::Fastest => lo,
        Operator::Slowest => hi,
    };
    e / g * tick_s
}
