//! A cyclic plan this build has checked on its problem at the cell's control tick: the form
//! the continuous coordinator is built from (issue 40; the continuous counterpart of
//! [`crate::CheckedSchedule`]).

use tandem_realtime::continuous::ContinuousCoordinator;

use super::graph::TaskShape;
use super::plan::CyclicPlan;
use super::search::{CyclicParams, cyclic_plan};
use crate::{Error, Problem, Result};

/// Relative tolerance of the stretch durations a plan must share with its problem
/// ([`CyclicPlan::check`]): both are sums of the same `ψ̇̄·Δt_s`, so only a plan of another
/// problem differs by more.
const LC_REL_TOL: f64 = 1e-9;

/// [`Error::BadParam`] naming `tick_s` unless it is finite and > 0.
fn check_tick(tick_s: f64) -> Result<()> {
    if tick_s.is_finite() && tick_s > 0.0 {
        Ok(())
    } else {
        Err(Error::BadParam {
            name: "tick_s",
            why: "must be finite and > 0",
        })
    }
}

/// A [`CyclicPlan`] that passed [`CyclicPlan::check`] on one problem at one control tick:
/// its stretches are the problem's, its operator order is runnable by the token rule
/// ([`crate::cyclic::is_runnable`]), and the continuous coordinator of the plan at
/// [`CheckedCyclicPlan::tick_s`] was built. It carries that tick, as a
/// [`crate::CheckedSchedule`] carries its schedule's: the cell runs at the tick the plan
/// counted its hand-overs at ([`CyclicParams::handover_tick_s`], when planned by
/// [`CheckedCyclicPlan::search`]).
///
/// Its fields are private: the only ways to make one are [`CyclicPlan::check`] and
/// [`CheckedCyclicPlan::search`], so holding one means the check ran in this build, and
/// [`CheckedCyclicPlan::coordinator`] runs exactly what was checked (infallibly).
///
/// ```
/// use tandem_schedule::{CheckedCyclicPlan, CyclicParams, Problem};
///
/// // 1 s of high confidence, 1 s of low confidence, 1 s of high confidence, at 10 ms.
/// let conf: Vec<bool> = (0..300).map(|n| !(100..200).contains(&n)).collect();
/// let problem = Problem::new(conf, vec![1.0; 300], vec![0.5; 300], vec![2.0; 300], 0.01)?;
/// let checked = CheckedCyclicPlan::search(&problem, 3, &CyclicParams::default(), 0.01)?;
/// assert_eq!(checked.tick_s(), 0.01);
/// let cell = checked.coordinator();
/// assert_eq!((cell.n_robots(), cell.tick_s()), (3, 0.01));
/// // A plan checked on another problem (here: another stretch) is refused.
/// let other: Vec<bool> = (0..300).map(|n| !(100..150).contains(&n)).collect();
/// let other = Problem::new(other, vec![1.0; 300], vec![0.5; 300], vec![2.0; 300], 0.01)?;
/// assert!(checked.plan().clone().check(&other, 0.01).is_err());
/// # Ok::<(), tandem_schedule::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct CheckedCyclicPlan {
    plan: CyclicPlan,
    tick_s: f64,
    /// The coordinator built by the check, never ticked: cloned by
    /// [`CheckedCyclicPlan::coordinator`] (its tables are shared, the clone is O(N)); boxed,
    /// as its per-robot arrays are large beside the plan.
    coordinator: Box<ContinuousCoordinator>,
}

impl CyclicPlan {
    /// Checks this plan on `problem` (the problem it was planned for) for a cell ticking
    /// every `tick_s` real seconds, and keeps the tick with it.
    ///
    /// # Errors
    /// [`Error::BadParam`] for a `tick_s` not finite and > 0, or when the plan's stretches
    /// (their number or their durations at `ψ̇̄`) are not the problem's; otherwise as
    /// [`CyclicPlan::coordinator`] ([`Error::NotRunnable`] for an order the token rule
    /// cannot run).
    pub fn check(self, problem: &Problem, tick_s: f64) -> Result<CheckedCyclicPlan> {
        check_tick(tick_s)?;
        let shape = TaskShape::new(problem);
        let same_stretches = shape.lc_s.len() == self.lc_s.len()
            && shape
                .lc_s
                .iter()
                .zip(&self.lc_s)
                .all(|(a, b)| (a - b).abs() <= LC_REL_TOL * a.abs().max(b.abs()));
        if !same_stretches {
            return Err(Error::BadParam {
                name: "problem",
                why: "has not the plan's low-confidence stretches (the plan was made on \
                      another problem: plan the cell again on this one)",
            });
        }
        let coordinator = self.coordinator(problem, tick_s)?;
        Ok(CheckedCyclicPlan {
            plan: self,
            tick_s,
            coordinator: Box::new(coordinator),
        })
    }
}

impl CheckedCyclicPlan {
    /// The cyclic plan of `n_robots` robots on `problem` ([`cyclic_plan`] with `params`),
    /// its hand-overs counted at the cell's tick `tick_s` (s; `params.handover_tick_s` is
    /// replaced by it, so the period is what the cell does at that tick under the planned
    /// operator), checked at that tick ([`CyclicPlan::check`]).
    ///
    /// # Errors
    /// As [`cyclic_plan`] (bad `params`, `n_robots` outside `1..=MAX_ROBOTS`, a `tick_s` not
    /// finite and > 0) and [`CyclicPlan::check`] (an order the token rule cannot run, when
    /// `params.runnable_only` is off).
    pub fn search(
        problem: &Problem,
        n_robots: usize,
        params: &CyclicParams,
        tick_s: f64,
    ) -> Result<CheckedCyclicPlan> {
        check_tick(tick_s)?;
        let params = CyclicParams {
            handover_tick_s: Some(tick_s),
            ..params.clone()
        };
        cyclic_plan(problem, n_robots, &params)?.check(problem, tick_s)
    }

    /// The plan that was checked.
    #[must_use]
    pub fn plan(&self) -> &CyclicPlan {
        &self.plan
    }

    /// The plan, by value (unchecked again once it leaves).
    #[must_use]
    pub fn into_plan(self) -> CyclicPlan {
        self.plan
    }

    /// The cell's control tick (real s per coordinator tick) the plan was checked at.
    #[must_use]
    pub fn tick_s(&self) -> f64 {
        self.tick_s
    }

    /// Robots `N` of the plan.
    #[must_use]
    pub fn n_robots(&self) -> usize {
        self.plan.n_robots
    }

    /// The continuous coordinator of the checked plan ([`CyclicPlan::coordinator`]) at
    /// [`CheckedCyclicPlan::tick_s`]: every robot at sample 0 of its first task. The check is
    /// not run again.
    #[must_use]
    pub fn coordinator(&self) -> ContinuousCoordinator {
        (*self.coordinator).clone()
    }
}

#[cfg(test)]
mod tests {
    use tandem_realtime::Operator;

    use super::*;
    use crate::cyclic::graph::Stretch;

    /// Two stretches of 1 s (samples 100..200 and 300..400 at 10 ms) with no hold between
    /// them: robot 1's two stretches form one group, so an order that puts robot 2 between
    /// them is not runnable.
    fn two_stretches() -> Problem {
        let conf: Vec<bool> = (0..500)
            .map(|n| !((100..200).contains(&n) || (300..400).contains(&n)))
            .collect();
        Problem::new(conf, vec![1.0; 500], vec![0.5; 500], vec![2.0; 500], 0.01).unwrap()
    }

    #[test]
    fn the_checked_plan_is_the_plan_at_its_tick() {
        let problem = two_stretches();
        let params = CyclicParams::default();
        let checked = CheckedCyclicPlan::search(&problem, 2, &params, 0.02).unwrap();
        // The same plan as the search with the hand-overs counted at that tick.
        let with_tick = CyclicParams {
            handover_tick_s: Some(0.02),
            ..params
        };
        let plan = cyclic_plan(&problem, 2, &with_tick).unwrap();
        assert_eq!(checked.plan(), &plan);
        assert_eq!((checked.tick_s(), checked.n_robots()), (0.02, 2));
        // Its coordinator is the plan's at the tick, fresh every time.
        let mut a = checked.coordinator();
        let b = plan.coordinator(&problem, 0.02).unwrap();
        assert_eq!((a.tick_s(), a.n_robots()), (b.tick_s(), b.n_robots()));
        for _ in 0..100 {
            a.tick(Operator::Scheduled).unwrap();
        }
        assert_eq!(a.ticks(), 100);
        assert_eq!(checked.coordinator().ticks(), 0);
        assert_eq!(checked.into_plan(), plan);
    }

    #[test]
    fn a_bad_tick_another_problem_or_an_unrunnable_order_is_refused() {
        let problem = two_stretches();
        let plan = cyclic_plan(&problem, 2, &CyclicParams::default()).unwrap();
        for tick in [0.0, -0.01, f64::NAN, f64::INFINITY] {
            let err = plan.clone().check(&problem, tick).unwrap_err();
            assert!(
                matches!(err, Error::BadParam { name: "tick_s", .. }),
                "{tick}: {err}"
            );
            let err =
                CheckedCyclicPlan::search(&problem, 2, &CyclicParams::default(), tick).unwrap_err();
            assert!(
                matches!(err, Error::BadParam { name: "tick_s", .. }),
                "{tick}: {err}"
            );
        }
        // Same number of stretches, the second 0.5 s instead of 1 s.
        let conf: Vec<bool> = (0..500)
            .map(|n| !((100..200).contains(&n) || (300..350).contains(&n)))
            .collect();
        let shorter =
            Problem::new(conf, vec![1.0; 500], vec![0.5; 500], vec![2.0; 500], 0.01).unwrap();
        let err = plan.clone().check(&shorter, 0.01).unwrap_err();
        assert!(
            matches!(
                err,
                Error::BadParam {
                    name: "problem",
                    ..
                }
            ),
            "{err}"
        );
        // Robot 2's first stretch between robot 1's two, with no hold between them.
        let split = [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(robot, lc)| Stretch { robot, lc });
        let unrunnable = crate::cyclic_plan_for_order(&problem, 2, &split).unwrap();
        let err = unrunnable.check(&problem, 0.01).unwrap_err();
        assert!(matches!(err, Error::NotRunnable { .. }), "{err}");
        // The planned one passes.
        assert!(plan.check(&problem, 0.01).is_ok());
    }
}
