//! The operator order: enumerated while the orders are few, else seeded local search.

use tandem_realtime::continuous::{Group, first_split_group};

use super::graph::{Stretch, TaskShape};
use super::plan::{CyclicPlan, period_of, plan_bound_of, plan_for_order};
use super::run::groups_of;
use crate::problem::check_robot_count;
use crate::{Error, Problem, Result};

/// Parameters of the order search of [`cyclic_plan`].
#[derive(Clone, Debug, PartialEq)]
pub struct CyclicParams {
    /// Enumerate every order (up to rotation) when there are at most this many; otherwise
    /// search locally. Must be ≥ 1. Default 100 000: every order for two robots with up to 8
    /// low-confidence stretches (51 480 orders) and three robots with up to 3 (5 040).
    pub max_enumerated: u64,
    /// Passes of the adjacent-swap local search per seed (each pass takes the best improving
    /// swap of two neighbouring stretches of different robots, or stops). Default 200.
    pub max_swap_passes: usize,
    /// Consider only orders the continuous coordinator can run ([`crate::cyclic::is_runnable`]:
    /// no other robot's stretch between two stretches of one robot with no usable hold
    /// between them), so that [`CyclicPlan::coordinator`] accepts the plan. The enumeration
    /// skips the others; the local search moves whole groups (the stretches between two holds)
    /// instead of single stretches. `false`: every order, as a plan only. Default `true`.
    pub runnable_only: bool,
    /// The control tick (real s) of the cell that will run the plan
    /// ([`CyclicPlan::coordinator`]), to plan the token rule's hand-overs: when given, the
    /// operator arc into a stretch that opens a group of another robot also carries the
    /// stretch's [`crate::cyclic::TaskShape::entry_s`] (the token's robot leaves its gate
    /// only once the previous group has been left, then travels to the stretch at `ψ̇min`)
    /// plus one tick (the leave is detected at a tick's end, and the arrival at the stretch
    /// and the leave each fall on the tick grid: half a tick each on average, a tick each
    /// when the clocks fall on the grid). So the period is what a token-rule cell with the
    /// planned operator does, and the search optimizes it (docs/decisions.md, "A plan is
    /// what the continuous cell does"). `None`: the operator's order alone (the model of
    /// the module docs), which a cell reaches only with gates next to the stretches.
    /// Must be finite and > 0. Default `None`.
    pub handover_tick_s: Option<f64>,
    /// The operator's switch time `δ` (real s, ≥ 0; issue 41): the operator arc from a
    /// stretch to the next of *another* robot carries at least `δ` after the stretch's end
    /// (the larger of `δ` and the hand-over when that is counted; consecutive stretches of one
    /// robot need none), so the period and the search account for it, and the plan's bound is
    /// [`crate::cyclic::period_lower_bound_with_switch_s`] when larger (docs/decisions.md,
    /// "The switch time in the scheduler's bounds (issue 41)"). Default 0: the plan without it, the same
    /// float operations.
    pub switch_s: f64,
    /// The load cap `u_max` (issue 41): the operator's busy share per period, its supervised
    /// stretches plus `switch_s` per change of robot (`(N·L + c·δ)/P`), must not exceed it, so
    /// the period of an order is `max(λ*, (N·L + c·δ)/u_max)` (an order whose event graph
    /// admits no such period is skipped) and the plan's bound is at least
    /// `(N·L + N·δ)/u_max` (docs/decisions.md, "The switch time in the scheduler's bounds
    /// (issue 41)"). Over the cycle, not a rolling window: the plan repeats, so every window of
    /// whole periods has this share. In `(0, 1]`; default 1: no cap, the same float operations.
    pub max_busy_share: f64,
}

impl Default for CyclicParams {
    fn default() -> Self {
        CyclicParams {
            max_enumerated: 100_000,
            max_swap_passes: 200,
            runnable_only: true,
            handover_tick_s: None,
            switch_s: 0.0,
            max_busy_share: 1.0,
        }
    }
}

impl CyclicParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::BadParam`] for `max_enumerated == 0`, a `handover_tick_s` not finite and
    /// > 0, a `switch_s` not finite and ≥ 0, or a `max_busy_share` outside `(0, 1]`.
    pub fn validate(&self) -> Result<()> {
        if self.max_enumerated == 0 {
            return Err(Error::BadParam {
                name: "max_enumerated",
                why: "must be ≥ 1",
            });
        }
        if self
            .handover_tick_s
            .is_some_and(|t| !(t.is_finite() && t > 0.0))
        {
            return Err(Error::BadParam {
                name: "handover_tick_s",
                why: "must be finite and > 0",
            });
        }
        if !(self.switch_s.is_finite() && self.switch_s >= 0.0) {
            return Err(Error::BadParam {
                name: "switch_s",
                why: "must be finite and >= 0 (the operator's switch time in seconds; 0 for none)",
            });
        }
        if !(self.max_busy_share > 0.0 && self.max_busy_share <= 1.0) {
            return Err(Error::BadParam {
                name: "max_busy_share",
                why: "must be in (0, 1] (the operator's largest busy share; 1 for no cap)",
            });
        }
        Ok(())
    }
}

/// Number of operator orders up to rotation for `n` robots with `m` stretches each: robot
/// 0's stretch 0 first, the other `N·m − 1` positions a multiset permutation, and each other
/// robot's stretches starting at any of its `m` stretches: `(Nm − 1)!/((m − 1)!·m!^(N−1)) ·
/// m^(N−1)`; saturating.
#[must_use]
pub fn order_count(n_robots: usize, m: usize) -> u64 {
    if m == 0 || n_robots == 0 {
        return 1;
    }
    // Multinomial as a product of binomials: place robot 0's m − 1, then each other robot's m.
    let mut count: u128 = 1;
    let mut free = (n_robots * m - 1) as u128;
    let mut take = |k: u128, count: &mut u128| {
        let mut c: u128 = 1;
        for i in 0..k {
            c = c * (free - i) / (i + 1);
            if c > u128::from(u64::MAX) {
                return false;
            }
        }
        free -= k;
        *count = count.saturating_mul(c);
        true
    };
    if !take((m - 1) as u128, &mut count) {
        return u64::MAX;
    }
    for _ in 1..n_robots {
        if !take(m as u128, &mut count) {
            return u64::MAX;
        }
        count = count.saturating_mul(m as u128);
    }
    u64::try_from(count).unwrap_or(u64::MAX)
}

/// The cyclic plan of `n_robots` robots repeating `problem`'s task: the operator order with
/// the least period, found by
///
/// - **enumeration** when [`order_count`] is at most `params.max_enumerated`: every order up
///   to rotation (robot 0's stretch 0 first; the first order in lexicographic order of robot
///   labels and rotations wins ties), so the plan's period is the least of every 1-periodic
///   plan ([`CyclicPlan::order_exhaustive`]) — of every runnable one with
///   [`CyclicParams::runnable_only`], which skips the others. Two robots are enumerated up to
///   8 stretches per task at the default.
/// - **local search** beyond: three seeds — round robin by stretch (every robot's stretch 0,
///   then every robot's stretch 1, …), the staggered round robin (robot `r` begins at
///   stretch `r mod m`) and the serial order (robot by robot, always feasible) — each
///   improved by best-improving swaps of two neighbouring stretches of different robots
///   (the wrap included) until no swap shortens the period or `max_swap_passes`; the best
///   wins, the earlier seed on ties. Deterministic. With `runnable_only` the units are the
///   task's groups (the stretches between two usable holds) instead of single stretches:
///   seeds and swaps are the same on groups, so every order visited is runnable (with a hold
///   in every gap, groups are stretches and nothing changes).
///
/// Both stop as soon as the best order's period meets the plan's lower bound
/// ([`CyclicPlan::lower_bound_s`]): no order can then be better by the search's rule, so
/// the plan is the one the whole search returns, bit for bit, with fewer orders evaluated
/// (docs/decisions.md, "Issue 44's fleet at steady confidence …").
///
/// A task without low-confidence stretches has the empty order and the period `D_min`; one
/// robot has its own task's order and period `D_min`.
///
/// # Errors
/// [`Error::Realtime`] (`RobotCount`) for `n_robots` outside `1..=MAX_ROBOTS`;
/// [`Error::BadParam`] for bad `params`.
pub fn cyclic_plan(
    problem: &Problem,
    n_robots: usize,
    params: &CyclicParams,
) -> Result<CyclicPlan> {
    search(problem, n_robots, params, true)
}

/// [`cyclic_plan`], stopping at the bound or not (`stop_at_bound = false`: the whole search,
/// for the test that both give the same plan).
fn search(
    problem: &Problem,
    n_robots: usize,
    params: &CyclicParams,
    stop_at_bound: bool,
) -> Result<CyclicPlan> {
    params.validate()?;
    check_robot_count(n_robots)?;
    let shape = TaskShape::new(problem);
    let m = shape.n_lc();
    // The coordinator's groups, which a runnable order keeps contiguous; not needed (every
    // order is runnable, every group one stretch) when a usable hold lies between every two
    // stretches, which spares cutting the task a second time.
    let groups = if params.runnable_only && (1..m).any(|k| shape.gaps[k].hold.is_none()) {
        Some(groups_of(problem)?)
    } else {
        None
    };
    let count = order_count(n_robots, m);
    let bound_s = if stop_at_bound {
        search_bound(&shape, n_robots, params)
    } else {
        f64::NEG_INFINITY
    };
    let (order, evaluated, exhaustive) = if count <= params.max_enumerated {
        let (order, evaluated) =
            enumerate(&shape, n_robots, m, groups.as_deref(), params, bound_s)?;
        (order, evaluated, true)
    } else {
        let (order, evaluated) =
            local_search(&shape, n_robots, params, groups.as_deref(), bound_s)?;
        (order, evaluated, false)
    };
    let mut plan = plan_for_order(
        problem,
        n_robots,
        &order,
        params.handover_tick_s,
        params.runnable_only,
        params.switch_s,
        params.max_busy_share,
    )?;
    plan.order_exhaustive = exhaustive;
    plan.orders_evaluated = evaluated;
    Ok(plan)
}

/// The serial order: robot by robot, each robot's stretches in task order.
fn serial(n_robots: usize, m: usize) -> Vec<Stretch> {
    (0..n_robots)
        .flat_map(|robot| (0..m).map(move |lc| Stretch { robot, lc }))
        .collect()
}

fn better(p: Option<f64>, best: Option<f64>) -> bool {
    match (p, best) {
        (Some(p), Some(b)) => p < b * (1.0 - 1e-12),
        (Some(_), None) => true,
        _ => false,
    }
}

/// Whether a period `p` of the search is at the plan's lower bound `bound_s` (the
/// `lower_bound_s` its plan gets, [`plan_bound_of`]; `−∞`: never), so that no order can be
/// [`better`]:
/// that would take a period below `p·(1 − 10⁻¹²)` ≤ `bound_s·(1 − 4.9·10⁻¹³)`, a cycle ratio
/// more than `4.9·10⁻¹³` (relative) below a proven bound on every order's period, far beyond
/// the rounding of the ratio's sums (≈ 10⁻¹⁵). So the search stops there with the order it
/// would have returned anyway: the same plan, bit for bit, sooner.
fn at_bound(p: Option<f64>, bound_s: f64) -> bool {
    p.is_some_and(|p| p <= bound_s * (1.0 + 5e-13))
}

/// The lower bound the plan of `params` gets ([`plan_bound_of`]), for [`at_bound`].
fn search_bound(shape: &TaskShape, n_robots: usize, params: &CyclicParams) -> f64 {
    plan_bound_of(
        shape,
        n_robots,
        params.handover_tick_s,
        params.runnable_only,
        params.switch_s,
        params.max_busy_share,
    )
}

/// Every order up to rotation ([`cyclic_plan`]); with `groups` (runnable orders only) those
/// that keep every group contiguous (`continuous::first_split_group`, the coordinator's rule).
fn enumerate(
    shape: &TaskShape,
    n_robots: usize,
    m: usize,
    groups: Option<&[Group]>,
    params: &CyclicParams,
    bound_s: f64,
) -> Result<(Vec<Stretch>, usize)> {
    if m == 0 {
        return Ok((Vec::new(), 1));
    }
    let len = n_robots * m;
    let mut labels = vec![0usize; len];
    let mut left = vec![m; n_robots];
    left[0] = m - 1;
    let mut rot = vec![0usize; n_robots];
    let mut best: (Option<f64>, Vec<Stretch>) = (None, serial(n_robots, m));
    let mut evaluated = 0;
    let mut order = Vec::with_capacity(len);
    // Depth-first over the labels of positions 1..len, then over the rotations.
    // `visit` returns whether to go on (false once the best order is at the bound).
    fn labels_at(
        q: usize,
        labels: &mut [usize],
        left: &mut [usize],
        visit: &mut dyn FnMut(&[usize]) -> Result<bool>,
    ) -> Result<bool> {
        if q == labels.len() {
            return visit(labels);
        }
        for r in 0..left.len() {
            if left[r] > 0 {
                left[r] -= 1;
                labels[q] = r;
                let go_on = labels_at(q + 1, labels, left, visit)?;
                left[r] += 1;
                if !go_on {
                    return Ok(false);
                }
            }
        }
        Ok(true)
    }
    let mut visit = |labels: &[usize]| -> Result<bool> {
        // Every rotation of robots 1..N (robot 0 starts at its stretch 0).
        rot.fill(0);
        loop {
            order.clear();
            let mut seen = vec![0usize; n_robots];
            for &r in labels {
                order.push(Stretch {
                    robot: r,
                    lc: (rot[r] + seen[r]) % m,
                });
                seen[r] += 1;
            }
            if groups.is_none_or(|g| first_split_group(&order, g).is_none()) {
                evaluated += 1;
                let p = period_of(
                    shape,
                    n_robots,
                    &order,
                    params.handover_tick_s,
                    params.switch_s,
                    params.max_busy_share,
                )?;
                if better(p, best.0) {
                    best = (p, order.clone());
                    if at_bound(p, bound_s) {
                        return Ok(false);
                    }
                }
            }
            // Next rotation (odometer over robots 1..N).
            let mut r = 1;
            while r < n_robots {
                rot[r] += 1;
                if rot[r] < m {
                    break;
                }
                rot[r] = 0;
                r += 1;
            }
            if r == n_robots {
                return Ok(true);
            }
        }
    };
    labels[0] = 0;
    labels_at(1, &mut labels, &mut left, &mut visit)?;
    Ok((best.1, evaluated))
}

/// The units of the local search: `(first, end)` stretch ranges — single stretches of the
/// `m`, or the coordinator's `groups` (runnable orders only: a new group at stretch 0 and
/// after every gap with a usable hold).
fn units(m: usize, groups: Option<&[Group]>) -> Vec<(usize, usize)> {
    match groups {
        Some(groups) => groups.iter().map(|g| (g.first_lc, g.end_lc)).collect(),
        None => (0..m).map(|k| (k, k + 1)).collect(),
    }
}

fn local_search(
    shape: &TaskShape,
    n_robots: usize,
    params: &CyclicParams,
    groups: Option<&[Group]>,
    bound_s: f64,
) -> Result<(Vec<Stretch>, usize)> {
    let units = units(shape.n_lc(), groups);
    let u = units.len();
    // Orders of units `(robot, unit)`, flattened to stretches for the period.
    let flat = |order: &[(usize, usize)]| -> Vec<Stretch> {
        order
            .iter()
            .flat_map(|&(robot, k)| (units[k].0..units[k].1).map(move |lc| Stretch { robot, lc }))
            .collect()
    };
    let round_robin: Vec<(usize, usize)> = (0..u)
        .flat_map(|k| (0..n_robots).map(move |robot| (robot, k)))
        .collect();
    let staggered: Vec<(usize, usize)> = (0..u)
        .flat_map(|j| (0..n_robots).map(move |robot| (robot, (j + robot) % u)))
        .collect();
    let serial_units: Vec<(usize, usize)> = (0..n_robots)
        .flat_map(|robot| (0..u).map(move |k| (robot, k)))
        .collect();
    let mut evaluated = 0;
    let mut best: (Option<f64>, Vec<Stretch>) = (None, flat(&serial_units));
    for seed in [round_robin, staggered, serial_units] {
        let mut cur = seed;
        let mut p = period_of(
            shape,
            n_robots,
            &flat(&cur),
            params.handover_tick_s,
            params.switch_s,
            params.max_busy_share,
        )?;
        evaluated += 1;
        let len = cur.len();
        for _ in 0..params.max_swap_passes {
            if at_bound(p, bound_s) {
                break;
            }
            let mut step: Option<(usize, Option<f64>)> = None;
            for q in 0..len {
                let q2 = (q + 1) % len;
                if cur[q].0 == cur[q2].0 {
                    continue;
                }
                cur.swap(q, q2);
                let pq = period_of(
                    shape,
                    n_robots,
                    &flat(&cur),
                    params.handover_tick_s,
                    params.switch_s,
                    params.max_busy_share,
                )?;
                evaluated += 1;
                cur.swap(q, q2);
                if better(pq, step.map_or(p, |s| s.1)) {
                    step = Some((q, pq));
                }
            }
            match step {
                Some((q, pq)) => {
                    cur.swap(q, (q + 1) % len);
                    p = pq;
                }
                None => break,
            }
        }
        if better(p, best.0) {
            best = (p, flat(&cur));
        }
        if at_bound(best.0, bound_s) {
            break;
        }
    }
    Ok((best.1, evaluated))
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand::rngs::StdRng;

    use super::*;
    use crate::testkit::{hold_points, random_problem};

    /// Stopping at the bound returns the whole search's plan bit for bit (order, period,
    /// bound), with at most as many orders evaluated; over random problems with and without
    /// holds, 2 to 8 robots (enumerated and local search), with and without the hand-overs,
    /// the switch time and the load cap; and it does stop on some (a saturated operator).
    #[test]
    fn stopping_at_the_bound_gives_the_whole_searchs_plan() {
        let mut rng = StdRng::seed_from_u64(44);
        let (mut cases, mut stopped) = (0, 0);
        for case in 0..48 {
            let p = random_problem(&mut rng, 60..=240, 0.1).unwrap();
            let p = if case % 2 == 0 {
                let holds = hold_points(p.conf());
                p.with_holds(holds).unwrap()
            } else {
                p
            };
            let n = 2 + case % 7;
            let params = CyclicParams {
                handover_tick_s: (case % 3 != 0).then_some(0.1),
                switch_s: if case % 4 == 1 { 0.7 } else { 0.0 },
                max_busy_share: if case % 5 == 2 { 0.8 } else { 1.0 },
                max_swap_passes: 20,
                ..CyclicParams::default()
            };
            let (Ok(fast), Ok(whole)) =
                (search(&p, n, &params, true), search(&p, n, &params, false))
            else {
                // An order the cap admits for no period: both must fail alike.
                assert_eq!(
                    search(&p, n, &params, true).is_ok(),
                    search(&p, n, &params, false).is_ok()
                );
                continue;
            };
            cases += 1;
            assert_eq!(fast.order, whole.order, "case {case}");
            assert_eq!(
                fast.period_s.to_bits(),
                whole.period_s.to_bits(),
                "case {case}"
            );
            assert_eq!(fast.lower_bound_s.to_bits(), whole.lower_bound_s.to_bits());
            assert_eq!(fast.order_exhaustive, whole.order_exhaustive);
            assert!(fast.orders_evaluated <= whole.orders_evaluated);
            // The plan's bound is the one the search stops at.
            let bound = search_bound(&TaskShape::new(&p), n, &params);
            assert_eq!(
                bound.to_bits(),
                whole.lower_bound_s.to_bits(),
                "case {case}"
            );
            stopped += usize::from(fast.orders_evaluated < whole.orders_evaluated);
        }
        assert!(cases >= 40, "{cases} cases planned");
        assert!(
            stopped >= 5,
            "the search stopped early in {stopped} of {cases} cases"
        );
    }
}
