//! Task ratios of a continuous cell of different tasks (issue 45): a cyclic plan whose
//! period holds `r_k` tasks of robot `k`, the bound on the period of every such plan, and
//! the best small ratios by that bound (docs/decisions.md, "The continuous cell of different
//! tasks: task ratios and the mixed operator-limited bound").
//!
//! Robot `k` does its own task: `L_k` (s) of low-confidence time per task at the operator's
//! mean rate ([`TaskShape::lc_total_s`]) and at least `D_k` (s) per task
//! ([`TaskShape::fastest_s`]). With ratios `r`, a period `P` (real s) satisfies
//! `P ≥ max(Σ_k r_k·L_k + c·δ, max_k r_k·D_k)` ([`mix_period_lower_bound_s`]; `c` the robots
//! with low-confidence time when at least two have some, else 0), so the cell completes at
//! most `3600·Σ_k r_k / P` tasks per hour. Two bounds that hold for every ratio follow: the
//! *mixed operator-limited bound* `3600 / (Σ_k r_k·L_k / Σ_k r_k)` (the operator supervises
//! one robot at a time, `Σ r_k L_k / Σ r_k` is the mean operator-seconds per task over the
//! mix) and the *robot-limited bound* `Σ_k 3600 / D_k` (robot `k` finishes a task at most
//! every `D_k`).

use super::TaskShape;
use crate::Problem;
use crate::error::{Error, Result};

/// Most tasks of one robot per period [`best_mix`] searches.
pub const MAX_MIX_RATIO: usize = 8;

/// One robot's task as the ratio bound sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MixTask {
    /// `D_k` (real s): the task's fastest admissible duration (high-confidence samples at
    /// `ψ̇min`, low-confidence ones at the operator's mean rate).
    pub fastest_s: f64,
    /// `L_k` (real s): its low-confidence time per task at the operator's mean rate.
    pub lc_s: f64,
}

impl MixTask {
    /// The task of `problem` ([`TaskShape::fastest_s`], [`TaskShape::lc_total_s`]).
    #[must_use]
    pub fn of(problem: &Problem) -> MixTask {
        let shape = TaskShape::new(problem);
        MixTask {
            fastest_s: shape.fastest_s(),
            lc_s: shape.lc_total_s(),
        }
    }
}

/// The best ratios of a mix and their bounds ([`best_mix`]).
#[derive(Clone, Debug, PartialEq)]
pub struct MixBound {
    /// `r_k`: tasks of robot `k` per period (each in `1..=max_ratio`).
    pub ratios: Vec<usize>,
    /// The least period (real s) any plan with these ratios can have
    /// ([`mix_period_lower_bound_s`]).
    pub period_lower_bound_s: f64,
    /// `3600·Σ r_k / period_lower_bound_s`: tasks per hour no plan with these ratios exceeds.
    pub tasks_per_hour_bound: f64,
    /// The mixed operator-limited bound of these ratios (tasks per hour, `∞` when no task
    /// needs the operator): `3600·Σ r_k / Σ r_k·L_k`.
    pub operator_limited_per_hour: f64,
    /// The robot-limited bound (tasks per hour): `Σ_k 3600 / D_k`.
    pub robot_limited_per_hour: f64,
}

/// Checks the tasks: 1 to `MAX_ROBOTS` of them, each `D_k` finite > 0 and `L_k` finite in
/// `[0, D_k]`.
fn check_tasks(tasks: &[MixTask]) -> Result<()> {
    if tasks.is_empty() || tasks.len() > tandem_realtime::MAX_ROBOTS {
        return Err(Error::BadParam {
            name: "tasks",
            why: "must be one per robot, 1 to MAX_ROBOTS of them",
        });
    }
    for t in tasks {
        if !(t.fastest_s.is_finite() && t.fastest_s > 0.0) {
            return Err(Error::BadParam {
                name: "fastest_s",
                why: "must be finite and > 0 (a task's fastest duration in seconds)",
            });
        }
        if !(t.lc_s.is_finite() && t.lc_s >= 0.0 && t.lc_s <= t.fastest_s) {
            return Err(Error::BadParam {
                name: "lc_s",
                why: "must be finite, >= 0 and at most the task's fastest duration",
            });
        }
    }
    Ok(())
}

/// The least period (real s) of every cyclic plan in which robot `k` (doing `tasks[k]`)
/// completes `ratios[k]` tasks per period, with the operator's switch time `switch_s`
/// (real s): `max(Σ_k r_k·L_k + c·δ, max_k r_k·D_k)`, `c` the robots with `L_k > 0` when
/// there are at least two of them, else 0.
///
/// **Why.** (1) The operator supervises one robot at a time, so its stretches in one
/// period take `Σ_k r_k·L_k` at least (each at the operator's mean rate, which the
/// margin check plans for; a correction only slows a stretch). Each robot's stretches form
/// at least one block of the cyclic order; with `c ≥ 2` robots that have any, the robot
/// changes at least `c` times around the cycle, each change at least `δ` apart. (2) Robot
/// `k` starts its next task only after the last one's end, and a task takes at least `D_k`:
/// its `r_k` tasks take `r_k·D_k` of the period. Neither uses the order of the stretches.
///
/// # Errors
/// [`Error::BadParam`] for tasks outside `1..=MAX_ROBOTS`, a bad `D_k` or `L_k`, ratios
/// that are not one per task or are 0, or a `switch_s` that is not finite and ≥ 0.
pub fn mix_period_lower_bound_s(tasks: &[MixTask], ratios: &[usize], switch_s: f64) -> Result<f64> {
    check_tasks(tasks)?;
    if ratios.len() != tasks.len() || ratios.contains(&0) {
        return Err(Error::BadParam {
            name: "ratios",
            why: "must be one per robot, each at least 1",
        });
    }
    check_switch(switch_s)?;
    Ok(bound(tasks, ratios, switch_s))
}

fn check_switch(switch_s: f64) -> Result<()> {
    if switch_s.is_finite() && switch_s >= 0.0 {
        Ok(())
    } else {
        Err(Error::BadParam {
            name: "switch_s",
            why: "must be finite and >= 0 (the operator's switch time in seconds; 0 for none)",
        })
    }
}

fn bound(tasks: &[MixTask], ratios: &[usize], switch_s: f64) -> f64 {
    let with_lc = tasks.iter().filter(|t| t.lc_s > 0.0).count();
    let changes = if with_lc >= 2 { with_lc as f64 } else { 0.0 };
    let operator: f64 = tasks
        .iter()
        .zip(ratios)
        .map(|(t, &r)| r as f64 * t.lc_s)
        .sum::<f64>()
        + changes * switch_s;
    let robots = tasks
        .iter()
        .zip(ratios)
        .map(|(t, &r)| r as f64 * t.fastest_s)
        .fold(0.0, f64::max);
    operator.max(robots)
}

/// The ratios `r ∈ {1..max_ratio}^N` whose plans may complete the most tasks per hour by
/// [`mix_period_lower_bound_s`] (`3600·Σ r_k / P(r)`), ties broken by the fewest tasks per
/// period and then the first in lexicographic order (so that `(1, 1)` and `(2, 2)` give
/// `(1, 1)`), with the bounds of [`MixBound`]. Exhaustive: `max_ratio^N ≤ 8⁸` candidates.
///
/// # Errors
/// As [`mix_period_lower_bound_s`], and [`Error::BadParam`] for `max_ratio` outside
/// `1..=MAX_MIX_RATIO`.
pub fn best_mix(tasks: &[MixTask], max_ratio: usize, switch_s: f64) -> Result<MixBound> {
    check_tasks(tasks)?;
    check_switch(switch_s)?;
    if !(1..=MAX_MIX_RATIO).contains(&max_ratio) {
        return Err(Error::BadParam {
            name: "max_ratio",
            why: "must be 1 to MAX_MIX_RATIO (tasks of one robot per period)",
        });
    }
    let n = tasks.len();
    let mut r = vec![1usize; n];
    let mut best: Option<(f64, usize, Vec<usize>)> = None;
    loop {
        let total: usize = r.iter().sum();
        let rate = 3600.0 * total as f64 / bound(tasks, &r, switch_s);
        let better = match &best {
            None => true,
            // Strictly better by more than rounding, or as good with fewer tasks per period.
            Some((b, t, _)) => {
                rate > b * (1.0 + 1e-12) || (rate >= b * (1.0 - 1e-12) && total < *t)
            }
        };
        if better {
            best = Some((rate, total, r.clone()));
        }
        // The next ratio vector in lexicographic order (last index fastest).
        let mut k = n;
        loop {
            if k == 0 {
                let (rate, total, ratios) = best.expect("at least one candidate");
                let lc: f64 = tasks
                    .iter()
                    .zip(&ratios)
                    .map(|(t, &q)| q as f64 * t.lc_s)
                    .sum();
                return Ok(MixBound {
                    period_lower_bound_s: bound(tasks, &ratios, switch_s),
                    tasks_per_hour_bound: rate,
                    operator_limited_per_hour: if lc > 0.0 {
                        3600.0 * total as f64 / lc
                    } else {
                        f64::INFINITY
                    },
                    robot_limited_per_hour: tasks.iter().map(|t| 3600.0 / t.fastest_s).sum(),
                    ratios,
                });
            }
            k -= 1;
            if r[k] < max_ratio {
                r[k] += 1;
                r[k + 1..].fill(1);
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn task(fastest_s: f64, lc_s: f64) -> MixTask {
        MixTask { fastest_s, lc_s }
    }

    #[test]
    fn the_bound_is_the_operator_or_the_slowest_robot() {
        // A 100 s task with 30 s of the operator and a 25 s task with 10 s of it, r = (1, 3):
        // operator 30 + 3·10 = 60 s, robots max(100, 75) = 100 s.
        let t = [task(100.0, 30.0), task(25.0, 10.0)];
        assert_eq!(mix_period_lower_bound_s(&t, &[1, 3], 0.0).unwrap(), 100.0);
        // r = (1, 4): robots max(100, 100) = 100, operator 70: 5 tasks per 100 s.
        assert_eq!(mix_period_lower_bound_s(&t, &[1, 4], 0.0).unwrap(), 100.0);
        // r = (2, 8): operator 60 + 80 = 140, robots max(200, 200) = 200 s.
        assert_eq!(mix_period_lower_bound_s(&t, &[2, 8], 0.0).unwrap(), 200.0);
        // A switch time of 1 s: two robots with stretches change twice per period.
        assert_eq!(mix_period_lower_bound_s(&t, &[3, 1], 1.0).unwrap(), 300.0);
        let busy = [task(10.0, 8.0), task(10.0, 8.0)];
        assert_eq!(mix_period_lower_bound_s(&busy, &[1, 1], 0.5).unwrap(), 17.0);
    }

    #[test]
    fn the_best_ratios_fill_the_short_robot_until_the_operator_binds() {
        // Robot 1: 100 s, 30 s of the operator; robot 2: 25 s, 10 s. Per r2 with r1 = 1:
        // P = max(30 + 10·r2, 100, 25·r2). r2 = 4: P = 100, 5 tasks → 180/h; r2 = 5:
        // P = max(80, 125) = 125, 6 tasks → 172.8/h. With r1 = 2: r2 = 8 → P = 200, 10 tasks
        // → 180/h (a tie, more tasks): (1, 4).
        let t = [task(100.0, 30.0), task(25.0, 10.0)];
        let b = best_mix(&t, 8, 0.0).unwrap();
        assert_eq!(b.ratios, [1, 4]);
        assert_eq!(b.period_lower_bound_s, 100.0);
        assert!((b.tasks_per_hour_bound - 180.0).abs() < 1e-9);
        // Operator-limited: 3600·5 / 70 = 257.14/h; robot-limited 36 + 144 = 180/h.
        assert!((b.operator_limited_per_hour - 3600.0 * 5.0 / 70.0).abs() < 1e-9);
        assert!((b.robot_limited_per_hour - 180.0).abs() < 1e-9);
        // Within r ≤ 2 the best is (1, 2): P = max(50, 100) = 100, 3 tasks → 108/h.
        let b = best_mix(&t, 2, 0.0).unwrap();
        assert_eq!(b.ratios, [1, 2]);
        assert!((b.tasks_per_hour_bound - 108.0).abs() < 1e-9);
    }

    #[test]
    fn equal_tasks_keep_one_each_and_the_operator_bound_is_the_papers() {
        // Two equal tasks: every r = (k, k) ties with (1, 1); N·L = 80 > D = 50: the bound
        // is the operator's, 2 tasks per 80 s = 90/h = 3600 / 40.
        let t = [task(50.0, 40.0), task(50.0, 40.0)];
        let b = best_mix(&t, 4, 0.0).unwrap();
        assert_eq!(b.ratios, [1, 1]);
        assert!((b.tasks_per_hour_bound - 90.0).abs() < 1e-9);
        assert!((b.operator_limited_per_hour - 90.0).abs() < 1e-9);
    }

    #[test]
    fn every_ratio_is_under_both_bounds() {
        let t = [task(120.0, 50.0), task(30.0, 12.0), task(45.0, 0.0)];
        let b = best_mix(&t, 4, 0.2).unwrap();
        for r1 in 1..=4 {
            for r2 in 1..=4 {
                for r3 in 1..=4 {
                    let r = [r1, r2, r3];
                    let p = mix_period_lower_bound_s(&t, &r, 0.2).unwrap();
                    let rate = 3600.0 * (r1 + r2 + r3) as f64 / p;
                    assert!(rate <= b.tasks_per_hour_bound * (1.0 + 1e-12), "{r:?}");
                    assert!(rate <= b.robot_limited_per_hour * (1.0 + 1e-12), "{r:?}");
                    let lc = r1 as f64 * 50.0 + r2 as f64 * 12.0;
                    assert!(rate <= 3600.0 * (r1 + r2 + r3) as f64 / lc + 1e-9, "{r:?}");
                }
            }
        }
    }

    #[test]
    fn bad_inputs_are_named() {
        let t = [task(10.0, 2.0)];
        let msg = |e: Error| e.to_string();
        assert!(msg(best_mix(&[], 2, 0.0).unwrap_err()).contains("tasks"));
        assert!(msg(best_mix(&t, 0, 0.0).unwrap_err()).contains("max_ratio"));
        assert!(msg(best_mix(&t, 2, -1.0).unwrap_err()).contains("switch_s"));
        assert!(msg(best_mix(&[task(0.0, 0.0)], 2, 0.0).unwrap_err()).contains("fastest_s"));
        assert!(msg(best_mix(&[task(1.0, 2.0)], 2, 0.0).unwrap_err()).contains("lc_s"));
        assert!(msg(mix_period_lower_bound_s(&t, &[0], 0.0).unwrap_err()).contains("ratios"));
        assert!(msg(mix_period_lower_bound_s(&t, &[1, 1], 0.0).unwrap_err()).contains("ratios"));
    }
}
