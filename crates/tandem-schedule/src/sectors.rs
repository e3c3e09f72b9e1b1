//! Rounds with `M > 1` operators (issue 44): the sectored schedule — a fixed partition of the
//! `N` robots into `M` sectors, each sector a one-operator round planned by the one-operator
//! scheduler ([`sample_schedule_n`]) and run side by side with the others
//! (`tandem_realtime::Coordinator::sectored`) — and the lower bound on the `T_total` of every
//! round of `N` robots under `M` operators. docs/decisions.md, "M operators in rounds: sectors
//! end to end (issue 44)".

use serde::{Deserialize, Serialize};

use crate::choose::{Outcome, sample_schedule_n};
use crate::problem::{Problem, check_robot_count};
use crate::sampler::SamplerParams;
use crate::{Result, Schedule};

/// The lower bound (s) on the `T_total` (Eq. 13) of every round of `n_robots` robots on
/// `problem` in which at most `operators` = `M` robots are low-confidence at any instant:
/// `max(a_0 + N·Σ_k L_k / M + a_m, D_min)`, with `L_k = Σ ψ̇̄·Δt_s` the fixed duration of LC
/// run `k` (Eq. 20 constraint 4), `a_0` the fastest head (the HC samples before the first LC
/// sample at `ψ̇min`), `a_m` the fastest tail and `D_min` one robot's fastest execution. With
/// `M = 1` it is [`crate::operator_bound_s`]'s formula.
///
/// **Why.** Each robot traverses every LC run once: the round has LC intervals of total length
/// `N·Σ L_k`. At every instant at most `M` of them are open, so their union covers at least
/// `N·Σ L_k / M` seconds of global time (the integral of the number open is `N·Σ L_k`, and the
/// number is at most `M` on the union). Every interval lies in `[a_0, T_total − a_m]`: its
/// robot starts at `τ_i ≥ 0` and spends at least `a_0` before its first LC sample, and after any
/// LC interval still traverses at least the tail, ending by `T_total`. So `T_total − a_m − a_0 ≥
/// N·Σ L_k / M`. And a robot needs its fastest execution. A switch time only removes schedules,
/// so the bound holds for every `δ ≥ 0` too (it does not add the switches).
///
/// # Errors
/// [`crate::Error::Realtime`] (`RobotCount`, `OperatorCount`) for `n_robots` or `operators`
/// outside `1..=MAX_ROBOTS`.
pub fn fleet_operator_bound_s(problem: &Problem, n_robots: usize, operators: usize) -> Result<f64> {
    check_robot_count(n_robots)?;
    let m = tandem_realtime::OperatorCount::new(operators)?.get();
    let dt = problem.dt_s();
    let (gmean, gmin) = (problem.grad_mean(), problem.grad_min());
    let sum = |v: &[f64], a: usize, b: usize| v[a..b].iter().sum::<f64>() * dt;
    let runs = problem.runs();
    let lc: f64 = runs
        .iter()
        .filter(|r| !r.high_conf)
        .map(|r| sum(gmean, r.start, r.end))
        .sum();
    let fastest: f64 = runs
        .iter()
        .map(|r| {
            if r.high_conf {
                sum(gmin, r.start, r.end)
            } else {
                sum(gmean, r.start, r.end)
            }
        })
        .sum();
    let first_lc = runs.iter().position(|r| !r.high_conf);
    let last_lc = runs.iter().rposition(|r| !r.high_conf);
    let (Some(first), Some(last)) = (first_lc, last_lc) else {
        return Ok(fastest);
    };
    let head = sum(gmin, 0, runs[first].start);
    let tail = sum(gmin, runs[last].end, problem.n_ref());
    Ok((head + n_robots as f64 * lc / m as f64 + tail).max(fastest))
}

/// The sizes of `M` sectors of `N` robots as even as can be: `N mod M` sectors of `⌈N/M⌉`
/// robots, then sectors of `⌊N/M⌋` (with `N < M`, `N` sectors of one robot and `M − N` empty
/// ones, dropped). Every partition into at most `M` parts has a part of at least `⌈N/M⌉`
/// robots, so when a larger one-operator round never ends sooner (the sampler's `T_total` is
/// non-decreasing in the robots, as every measured row is) these sizes give the least round.
#[must_use]
pub fn even_sector_sizes(n_robots: usize, operators: usize) -> Vec<usize> {
    let m = operators.max(1);
    (0..m)
        .map(|o| n_robots / m + usize::from(o < n_robots % m))
        .filter(|&k| k > 0)
        .collect()
}

/// A sectored round: robots `0..N` in contiguous sectors, sector `o` run by operator `o` as a
/// one-operator round of its own schedule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SectoredRounds {
    /// Robots per sector (sector `o` is robots `Σ_{p<o} sizes[p] .. + sizes[o]`).
    pub sizes: Vec<usize>,
    /// Each sector's one-operator schedule (its robot `j` is the sector's `j`-th robot; its
    /// holds' release rules name robots of the sector by that index), planned on the problem
    /// with its hold points.
    pub schedules: Vec<Schedule>,
    /// The round's `T_total` (s): the latest sector's.
    pub t_total_s: f64,
    /// [`fleet_operator_bound_s`] of `N` robots and `M` operators: no round of `M`
    /// operators ends sooner.
    pub lower_bound_s: f64,
}

impl SectoredRounds {
    /// Robot `i`'s sector (its operator), one entry per robot.
    #[must_use]
    pub fn sector_of(&self) -> Vec<usize> {
        self.sizes
            .iter()
            .enumerate()
            .flat_map(|(o, &k)| std::iter::repeat_n(o, k))
            .collect()
    }

    /// Every robot's plan (robot `i` at index `i`; global schedule clock from 0, each
    /// sector's own), as the sectors' schedules give them on `problem` (the plans without
    /// their dwells: [`SectoredRounds::holds`] splits them at run time).
    ///
    /// # Errors
    /// As [`Schedule::timelines`].
    pub fn timelines(&self, problem: &Problem) -> Result<Vec<tandem_realtime::Timeline>> {
        let mut out = Vec::new();
        for s in &self.schedules {
            out.extend(s.timelines(problem)?);
        }
        Ok(out)
    }

    /// Every robot's hold points with their planned dwells and release rules (robot `i` at
    /// index `i`, the rules naming robots of the round: a sector's robot `j` is robot
    /// `Σ_{p<o} sizes[p] + j`); empty when no sector's schedule has a hold, as
    /// `tandem_realtime::Coordinator::sectored` takes them.
    #[must_use]
    pub fn holds(&self) -> Vec<Vec<tandem_realtime::Hold>> {
        if !self.schedules.iter().any(Schedule::has_holds) {
            return Vec::new();
        }
        let mut out = Vec::new();
        let mut first = 0;
        for (s, &k) in self.schedules.iter().zip(&self.sizes) {
            for robot in 0..k {
                let mut list = s.holds_of(robot).to_vec();
                for h in &mut list {
                    for a in &mut h.after {
                        a.robot += first;
                    }
                }
                out.push(list);
            }
            first += k;
        }
        out
    }
}

/// The sectored round of `n_robots` robots and `operators` = `M` operators on `problem`: the
/// [`even_sector_sizes`], each size's one-operator schedule by [`sample_schedule_n`] with
/// `params` (one run per distinct size: the robots are alike), on `problem` with its hold
/// points (each sector waits at its holds by its own release rules, with its own wait clock:
/// `tandem_realtime::Coordinator::sectored`). Each schedule is valid for one operator at
/// `params`' tick and switch time, so each sector has at most one robot low-confidence in any
/// tick: at most `M` in all.
///
/// # Errors
/// Those of [`sample_schedule_n`] and [`fleet_operator_bound_s`].
pub fn sectored_rounds(
    problem: &Problem,
    n_robots: usize,
    operators: usize,
    params: &SamplerParams,
) -> Result<SectoredRounds> {
    let lower_bound_s = fleet_operator_bound_s(problem, n_robots, operators)?;
    let sizes = even_sector_sizes(n_robots, operators);
    let mut by_size: Vec<(usize, Outcome)> = Vec::new();
    for &k in &sizes {
        if !by_size.iter().any(|(j, _)| *j == k) {
            by_size.push((k, sample_schedule_n(problem, k, params, None)?));
        }
    }
    let schedules: Vec<Schedule> = sizes
        .iter()
        .map(|k| {
            let (_, o) = by_size.iter().find(|(j, _)| j == k).expect("planned above");
            o.schedule.clone()
        })
        .collect();
    let t_total_s = sizes
        .iter()
        .map(|k| {
            by_size
                .iter()
                .find(|(j, _)| j == k)
                .expect("planned")
                .1
                .t_total_s
        })
        .fold(0.0, f64::max);
    Ok(SectoredRounds {
        sizes,
        schedules,
        t_total_s,
        lower_bound_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1 s of high confidence (0.5 s at the fastest), 1 s of low confidence, 1 s of high
    /// confidence (0.5 s at the fastest), at 10 ms.
    fn one_stretch() -> Problem {
        let conf: Vec<bool> = (0..300).map(|n| !(100..200).contains(&n)).collect();
        Problem::new(conf, vec![1.0; 300], vec![0.5; 300], vec![2.0; 300], 0.01).unwrap()
    }

    #[test]
    fn the_fleet_bound_by_hand() {
        let p = one_stretch();
        let b = |n, m| fleet_operator_bound_s(&p, n, m).unwrap();
        // a_0 = a_m = 0.5 s, L = 1 s, D_min = 2 s.
        assert!((b(1, 1) - 2.0).abs() < 1e-9);
        assert!((b(4, 1) - 5.0).abs() < 1e-9);
        assert!((b(4, 2) - 3.0).abs() < 1e-9);
        assert!((b(3, 2) - 2.5).abs() < 1e-9);
        // D_min binds once the operators outnumber the robots' stretches.
        assert!((b(4, 4) - 2.0).abs() < 1e-9);
        // M = 1 is the one-operator bound.
        assert!((b(4, 1) - crate::operator_bound_s(&p, 4).unwrap()).abs() < 1e-9);
        assert!(fleet_operator_bound_s(&p, 4, 0).is_err());
    }

    #[test]
    fn even_sizes() {
        assert_eq!(even_sector_sizes(4, 2), vec![2, 2]);
        assert_eq!(even_sector_sizes(8, 3), vec![3, 3, 2]);
        assert_eq!(even_sector_sizes(3, 2), vec![2, 1]);
        assert_eq!(even_sector_sizes(2, 4), vec![1, 1]);
        assert_eq!(even_sector_sizes(5, 1), vec![5]);
    }

    #[test]
    fn sectored_rounds_are_the_sectors_schedules_and_above_the_bound() {
        let p = one_stretch();
        let params = SamplerParams {
            samples: 64,
            tick_s: Some(0.01),
            ..SamplerParams::default()
        };
        let s = sectored_rounds(&p, 4, 2, &params).unwrap();
        assert_eq!(s.sizes, vec![2, 2]);
        assert_eq!(s.sector_of(), vec![0, 0, 1, 1]);
        let two = sample_schedule_n(&p, 2, &params, None).unwrap();
        assert_eq!(s.schedules, vec![two.schedule.clone(), two.schedule]);
        assert_eq!(s.t_total_s, two.t_total_s);
        // Two robots, one stretch each of 1 s: the pair's round is at least 3 s, the bound of
        // 4 robots under 2 operators.
        assert!(s.t_total_s >= s.lower_bound_s - 1e-9, "{s:?}");
        assert!((s.lower_bound_s - 3.0).abs() < 1e-9);
        assert_eq!(s.timelines(&p).unwrap().len(), 4);
        assert!(s.holds().is_empty());
    }

    /// [HC ×4, LC ×4, HC ×2], gradients 1 in [0.25, 2], `Δt = 0.1` s, with a hold point at
    /// sample 3 or none (`tests/holds.rs`: two robots' best round waits at the hold, 1.025 s).
    fn short_stretch(hold: bool) -> Problem {
        let conf: Vec<bool> = (0..10).map(|n| !(4..8).contains(&n)).collect();
        let p = Problem::new(conf, vec![1.0; 10], vec![0.25; 10], vec![2.0; 10], 0.1).unwrap();
        if hold {
            p.with_holds(vec![3]).unwrap()
        } else {
            p
        }
    }

    /// With hold points each sector is the one-operator scheduler's schedule on the problem
    /// with its holds, and the round's holds are the sectors' renumbered: sector 1's rules
    /// name robots 2 and 3.
    #[test]
    fn sectors_are_planned_with_the_hold_points() {
        let p = short_stretch(true);
        let params = SamplerParams {
            samples: 200,
            seed: 3,
            tick_s: Some(0.05),
            ..SamplerParams::default()
        };
        let s = sectored_rounds(&p, 4, 2, &params).unwrap();
        let two = sample_schedule_n(&p, 2, &params, None).unwrap();
        assert!(two.schedule.has_holds(), "{:?}", two.schedule);
        assert_eq!(
            s.schedules,
            vec![two.schedule.clone(), two.schedule.clone()]
        );
        assert_eq!(s.t_total_s, two.t_total_s);
        assert!((s.t_total_s - 1.025).abs() < 1e-9, "{}", s.t_total_s);
        let holds = s.holds();
        assert_eq!(holds.len(), 4);
        for j in 0..2 {
            assert_eq!(holds[j], two.schedule.holds_of(j));
            let shifted: Vec<Vec<usize>> = holds[2 + j]
                .iter()
                .map(|h| h.after.iter().map(|a| a.robot).collect())
                .collect();
            let own: Vec<Vec<usize>> = two
                .schedule
                .holds_of(j)
                .iter()
                .map(|h| h.after.iter().map(|a| a.robot + 2).collect())
                .collect();
            assert_eq!(shifted, own);
        }
        // The round's plans run in sectors with these holds.
        let c = tandem_realtime::Coordinator::sectored(
            s.timelines(&p).unwrap(),
            &holds,
            &s.sector_of(),
            tandem_realtime::OperatorCount::new(2).unwrap(),
            &tandem_realtime::MarginParams::new(0.05),
        )
        .unwrap();
        assert!(c.has_holds());
        // Without the holds the pair's round is longer: the holds are what the sectors gain.
        let free = sectored_rounds(&short_stretch(false), 4, 2, &params).unwrap();
        assert!(
            free.t_total_s > s.t_total_s,
            "{} {}",
            free.t_total_s,
            s.t_total_s
        );
    }
}
