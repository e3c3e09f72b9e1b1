//! A cyclic plan at run time: the continuous coordinator of `tandem-realtime` on the plan's
//! operator order (issue 21, item 3; `tandem_realtime::continuous`).
//!
//! The coordinator runs every robot on the problem's fastest warp ([`Problem::fastest_warp`]:
//! `ψ̇min` on high-confidence samples, `ψ̇̄` on low-confidence ones, the operator's rate
//! there), lets it wait at the usable holds ([`Problem::usable_holds`]) and passes the
//! operator's token in the plan's order. It is sound by construction (two robots are never
//! low-confidence in one tick, for any operator and any number of tasks; the argument is in
//! `tandem_realtime::continuous`), provided the order is *runnable*: [`is_runnable`].

use tandem_realtime::continuous::{self, ContinuousCoordinator, Group};
use tandem_realtime::{MAX_ROBOTS, Timeline};

use super::graph::Stretch;
use super::plan::CyclicPlan;
use crate::{Error, Problem, Result};

/// Whether the continuous coordinator can run the operator's cyclic `order` on `problem`:
/// no other robot's stretch comes between two stretches `k − 1` and `k` of one robot that
/// have no usable hold between them (the robot cannot wait there, so the operator must take
/// them one after the other). The coordinator's own check
/// (`tandem_realtime::continuous::is_runnable` on the task's groups, for the robots
/// `0..=max robot` that `order` names), so a malformed order — one that does not list every
/// stretch of those robots once, each robot's in task order around the cycle, or that names
/// more than `MAX_ROBOTS` robots — is not runnable either: the coordinator could not run it
/// ([`crate::cyclic_plan_for_order`] says what is wrong with it).
#[must_use]
pub fn is_runnable(problem: &Problem, order: &[Stretch]) -> bool {
    let n_robots = order
        .iter()
        .map(|s| s.robot.saturating_add(1))
        .max()
        .unwrap_or(0);
    runnable(problem, order, n_robots)
}

/// The groups of `problem`'s task as the continuous coordinator cuts them: its stretches
/// between two usable holds ([`Problem::usable_holds`]; `continuous::groups`).
pub(crate) fn groups_of(problem: &Problem) -> Result<Vec<Group>> {
    Ok(continuous::groups(problem.conf(), &problem.usable_holds())?)
}

/// [`is_runnable`] for `n_robots` robots.
fn runnable(problem: &Problem, order: &[Stretch], n_robots: usize) -> bool {
    if n_robots > MAX_ROBOTS {
        return false;
    }
    let Ok(groups) = groups_of(problem) else {
        return false;
    };
    let order: Vec<(usize, usize)> = order.iter().map(|&s| s.into()).collect();
    continuous::is_runnable(&order, &groups, n_robots)
}

impl CyclicPlan {
    /// Whether this plan's order of its `n_robots` robots can run on `problem`
    /// ([`is_runnable`]; `false` for a problem with another number of stretches).
    #[must_use]
    pub fn is_runnable(&self, problem: &Problem) -> bool {
        runnable(problem, &self.order, self.n_robots)
    }

    /// The continuous coordinator of this plan on `problem` (the problem it was planned for)
    /// at a control tick of `tick_s` real seconds: `n_robots` robots on the fastest warp,
    /// waiting at the usable holds, the operator's token passed in `order`
    /// (the token rule of `tandem_realtime::continuous`). Every robot starts at sample 0 of
    /// its first task.
    ///
    /// Under the planned operator (`Operator::Scheduled`) its steady throughput is the plan's
    /// `tasks_per_hour` when the plan counted the hand-overs at this tick
    /// ([`crate::CyclicParams::handover_tick_s`]; at least 97 % of it on random problems,
    /// `tests/cyclic_run.rs`), and the plan's less the hand-over cost otherwise (a robot
    /// leaves its gate only once the previous group has been left, so the operator waits for
    /// the travel from the gate to the stretch, plus the tick quantization); under drift only
    /// soundness is guaranteed.
    ///
    /// # Errors
    /// [`Error::NotRunnable`] for an order that splits a group, the first such position (the
    /// rule of [`is_runnable`], `continuous::first_split_group`); [`Error::BadParam`] when
    /// the plan's stretches do not match the problem's; [`Error::Realtime`] for a bad
    /// `tick_s` or a malformed order.
    pub fn coordinator(&self, problem: &Problem, tick_s: f64) -> Result<ContinuousCoordinator> {
        let groups = groups_of(problem)?;
        if groups.last().map_or(0, |g| g.end_lc) != self.lc_s.len() {
            return Err(Error::BadParam {
                name: "problem",
                why: "has not the plan's number of low-confidence stretches",
            });
        }
        if let Some(position) = continuous::first_split_group(&self.order, &groups) {
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

#[cfg(test)]
mod tests {
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    use super::*;
    use crate::cyclic::graph::{TaskShape, check_order};

    /// The schedule crate's own rule before it was merged into the realtime one, kept as the
    /// reference: the first position whose stretch `lc ≥ 1` has no usable hold in the gap
    /// before it and does not follow its robot's stretch `lc − 1`.
    fn reference_first_unrunnable(shape: &TaskShape, order: &[Stretch]) -> Option<usize> {
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

    /// The local search's units as they were cut from the task's shape.
    fn reference_units(shape: &TaskShape) -> Vec<(usize, usize)> {
        let mut out: Vec<(usize, usize)> = Vec::new();
        for k in 0..shape.n_lc() {
            if k == 0 || shape.gaps[k].hold.is_some() {
                out.push((k, k + 1));
            } else if let Some(last) = out.last_mut() {
                last.1 = k + 1;
            }
        }
        out
    }

    /// A random task: 0–5 stretches of 1–4 samples between gaps of 1–5, each sample a hold
    /// with probability `hold_p` (usable or not).
    fn random_problem(rng: &mut ChaCha8Rng, hold_p: f64) -> Problem {
        let m = rng.random_range(0..=5);
        let mut conf = Vec::new();
        for k in 0..=m {
            conf.extend(std::iter::repeat_n(true, rng.random_range(1..=5)));
            if k < m {
                conf.extend(std::iter::repeat_n(false, rng.random_range(1..=4)));
            }
        }
        let n = conf.len();
        let holds: Vec<usize> = (0..n).filter(|_| rng.random_bool(hold_p)).collect();
        crate::problem::unit_gradients(conf, (0.5, 2.0), 0.1)
            .with_holds(holds)
            .unwrap()
    }

    /// A random well-formed order of `n` robots' `m` stretches (each robot's in task order
    /// from a random first stretch, interleaved at random), sometimes broken: two entries
    /// swapped, one dropped or one renamed to another robot or stretch.
    fn random_order(rng: &mut ChaCha8Rng, n: usize, m: usize) -> Vec<Stretch> {
        let first: Vec<usize> = (0..n).map(|_| rng.random_range(0..m.max(1))).collect();
        let mut taken = vec![0; n];
        let mut out = Vec::new();
        while taken.iter().any(|&k| k < m) {
            let robot = loop {
                let r = rng.random_range(0..n);
                if taken[r] < m {
                    break r;
                }
            };
            out.push(Stretch {
                robot,
                lc: (first[robot] + taken[robot]) % m,
            });
            taken[robot] += 1;
        }
        if !out.is_empty() && rng.random_bool(0.3) {
            let q = rng.random_range(0..out.len());
            match rng.random_range(0..3) {
                0 => {
                    let q2 = rng.random_range(0..out.len());
                    out.swap(q, q2);
                }
                1 => {
                    out.remove(q);
                }
                _ => {
                    out[q] = Stretch {
                        robot: rng.random_range(0..n + 1),
                        lc: rng.random_range(0..m + 1),
                    };
                }
            }
        }
        out
    }

    /// The realtime rule (`continuous::first_split_group` on the coordinator's groups), which
    /// the order search uses, finds the same first position as the schedule's former rule on
    /// the task's shape, for any order; the public `is_runnable` is that rule and a
    /// well-formed order; the search's units are the groups.
    #[test]
    fn the_realtime_rule_is_the_former_schedule_rule() {
        let mut rng = ChaCha8Rng::seed_from_u64(21);
        let (mut runnable_seen, mut split_seen, mut malformed_seen) = (0, 0, 0);
        for case in 0..4000 {
            let problem = random_problem(&mut rng, [0.0, 0.2, 0.5][case % 3]);
            let shape = TaskShape::new(&problem);
            let groups = groups_of(&problem).unwrap();
            let m = shape.n_lc();
            assert_eq!(groups.last().map_or(0, |g| g.end_lc), m);
            let gs: Vec<(usize, usize)> = groups.iter().map(|g| (g.first_lc, g.end_lc)).collect();
            assert_eq!(gs, reference_units(&shape), "case {case}");
            // The search's shortcut: a hold in every gap between stretches, one per group.
            let every_gap_held = (1..m).all(|k| shape.gaps[k].hold.is_some());
            assert_eq!(every_gap_held, groups.len() == m, "case {case}");
            let n = rng.random_range(1..=4);
            let order = random_order(&mut rng, n, m);
            let reference = reference_first_unrunnable(&shape, &order);
            assert_eq!(
                continuous::first_split_group(&order, &groups),
                reference,
                "case {case}: {order:?}"
            );
            let named = order.iter().map(|s| s.robot + 1).max().unwrap_or(0);
            let well_formed = check_order(&order, named, m).is_ok();
            assert_eq!(
                is_runnable(&problem, &order),
                well_formed && reference.is_none(),
                "case {case}: {order:?}"
            );
            match (well_formed, reference) {
                (false, _) => malformed_seen += 1,
                (true, None) => runnable_seen += 1,
                (true, Some(_)) => split_seen += 1,
            }
        }
        // Each kind of order is well represented.
        assert!(runnable_seen > 500 && split_seen > 500 && malformed_seen > 500);
    }
}
