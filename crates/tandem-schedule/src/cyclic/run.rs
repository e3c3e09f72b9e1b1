//! A cyclic plan at run time: the continuous coordinator of `tandem-realtime` on the plan's
//! operator order (issue 21, item 3; `tandem_realtime::continuous`).
//!
//! The coordinator runs every robot on the problem's fastest warp ([`Problem::fastest_warp`]:
//! `ψ̇min` on high-confidence samples, `ψ̇̄` on low-confidence ones, the operator's rate
//! there), lets it wait at the usable holds ([`Problem::usable_holds`]) and passes the
//! operator's token in the plan's order. It is sound by construction (two robots are never
//! low-confidence in one tick, for any operator and any number of tasks; the argument is in
//! `tandem_realtime::continuous`), provided the order is *runnable*: [`is_runnable`].

use tandem_realtime::Timeline;
use tandem_realtime::continuous::ContinuousCoordinator;

use super::graph::{Stretch, TaskShape};
use super::plan::CyclicPlan;
use crate::{Error, Problem, Result};

/// Whether the continuous coordinator can run the operator's cyclic `order` on `problem`: no
/// other robot's stretch comes between two stretches `k − 1` and `k` of one robot that have no
/// usable hold between them (the robot cannot wait there, so the operator must take them one
/// after the other). Checks only this condition; a malformed order is rejected by
/// [`crate::cyclic_plan_for_order`] and [`CyclicPlan::coordinator`].
#[must_use]
pub fn is_runnable(problem: &Problem, order: &[Stretch]) -> bool {
    runnable(&TaskShape::new(problem), order)
}

/// [`is_runnable`] on the task's shape: the first position that breaks the condition, if any.
pub(crate) fn first_unrunnable(shape: &TaskShape, order: &[Stretch]) -> Option<usize> {
    let len = order.len();
    (0..len).find(|&q| {
        let s = order[q];
        s.lc >= 1
            && s.lc < shape.n_lc()
            && shape.gaps[s.lc].hold.is_none()
            && order[(q + len - 1) % len]
                != Stretch {
                    robot: s.robot,
                    lc: s.lc - 1,
                }
    })
}

pub(crate) fn runnable(shape: &TaskShape, order: &[Stretch]) -> bool {
    first_unrunnable(shape, order).is_none()
}

impl CyclicPlan {
    /// Whether this plan's order can run on `problem` ([`is_runnable`]).
    #[must_use]
    pub fn is_runnable(&self, problem: &Problem) -> bool {
        is_runnable(problem, &self.order)
    }

    /// The continuous coordinator of this plan on `problem` (the problem it was planned for)
    /// at a control tick of `tick_s` real seconds: `n_robots` robots on the fastest warp,
    /// waiting at the usable holds, the operator's token passed in `order`
    /// (the token rule of `tandem_realtime::continuous`). Every robot starts at sample 0 of
    /// its first task.
    ///
    /// Under the planned operator (`Operator::Scheduled`) its steady throughput is the plan's
    /// `tasks_per_hour` less the hand-over cost (a robot leaves its gate only once the
    /// previous group has been left, so the operator waits for the travel from the gate to the
    /// stretch, plus the tick quantization); under drift only soundness is guaranteed.
    ///
    /// # Errors
    /// [`Error::NotRunnable`] for an order [`is_runnable`] rejects; [`Error::BadParam`] when
    /// the plan's stretches do not match the problem's; [`Error::Realtime`] for a bad
    /// `tick_s` or a malformed order.
    pub fn coordinator(&self, problem: &Problem, tick_s: f64) -> Result<ContinuousCoordinator> {
        let shape = TaskShape::new(problem);
        if shape.n_lc() != self.lc_s.len() {
            return Err(Error::BadParam {
                name: "problem",
                why: "has not the plan's number of low-confidence stretches",
            });
        }
        if let Some(position) = first_unrunnable(&shape, &self.order) {
            let s = self.order[position];
            return Err(Error::NotRunnable {
                position,
                robot: s.robot,
                lc: s.lc,
            });
        }
        let task = Timeline::new(
            problem.conf(),
            &problem.fastest_warp(),
            problem.grad_min(),
            problem.grad_max(),
            0.0,
            problem.dt_s(),
        )?;
        let order: Vec<(usize, usize)> = self.order.iter().map(|s| (s.robot, s.lc)).collect();
        Ok(ContinuousCoordinator::new(
            task,
            &problem.usable_holds(),
            &order,
            self.n_robots,
            tick_s,
        )?)
    }
}
