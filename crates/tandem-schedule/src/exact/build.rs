//! From event times to execution warps.

use super::chain::Chain;
use super::stn::Times;
use crate::problem::Problem;
use crate::schedule::Schedule;
use tandem_realtime::Hold;

/// The schedule with event times `times`: the mean gradient on LC samples (Eq. 20 constraint
/// 4) and, on each HC run, one speed factor `u ∈ [0, 1]` for all its samples,
/// `ψ̇_E[n] = ψ̇min[n] + u·(ψ̇max[n] − ψ̇min[n])`, chosen so that the run lasts as long as the
/// times say.
/// The schedule carries the control tick `tick_s` (s) it is meant to be checked and run at.
pub(crate) fn uniform_schedule(
    problem: &Problem,
    chain: &Chain,
    times: &Times,
    tick_s: f64,
) -> Schedule {
    let gaps = [0, 1].map(|r| times.gaps_s(chain, r));
    gap_schedule(problem, chain, &gaps, vec![times.tau_s], tick_s)
}

/// The schedule of `N = gaps_s.len()` robots whose HC gap `g` of robot `r` lasts `gaps_s[r][g]`
/// (s), robots 2..N starting at `offsets_s`: the mean gradient on LC samples and one speed
/// factor per HC run as [`uniform_schedule`]; a gap longer than its slowest speeds allow (only
/// a gap with a hold may be) gets the rest as a planned dwell at its hold.
pub(crate) fn gap_schedule(
    problem: &Problem,
    chain: &Chain,
    gaps_s: &[Vec<f64>],
    offsets_s: Vec<f64>,
    tick_s: f64,
) -> Schedule {
    let mut holds: Vec<Vec<Hold>> = vec![Vec::new(); gaps_s.len()];
    let warps: Vec<Vec<f64>> = gaps_s
        .iter()
        .zip(&mut holds)
        .map(|(gaps, holds)| {
            let mut warp = problem.grad_mean().to_vec();
            for (g, &(a, b)) in chain.gap_ref.iter().enumerate() {
                fill_uniform(problem, &mut warp[a..b], a, gaps[g]);
                if let Some(h) = chain.gap_hold[g] {
                    let filled_s = tandem_realtime::clock_end_s(&warp[a..b], 0.0, problem.dt_s());
                    let dwell_s = gaps[g] - filled_s;
                    if dwell_s > 0.0 {
                        holds.push(Hold {
                            dwell_s,
                            ..Hold::at(h)
                        });
                    }
                }
            }
            warp
        })
        .collect();
    if holds.iter().all(Vec::is_empty) {
        holds.clear();
    }
    Schedule {
        grad_exec: warps,
        offsets_s,
        tick_s,
        holds,
    }
}

/// Writes into `out` (the HC run starting at reference sample `start`) the one-factor speeds
/// that make it last `dur_s` seconds (clamped into the run's range).
pub(crate) fn fill_uniform(problem: &Problem, out: &mut [f64], start: usize, dur_s: f64) {
    let dt = problem.dt_s();
    let end = start + out.len();
    let lo: f64 = problem.grad_min()[start..end].iter().sum();
    let hi: f64 = problem.grad_max()[start..end].iter().sum();
    let u = if hi > lo {
        ((dur_s / dt - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    for (k, g) in out.iter_mut().enumerate() {
        let n = start + k;
        let (a, b) = (problem.grad_min()[n], problem.grad_max()[n]);
        *g = a + u * (b - a);
    }
}

/// `schedule` with each robot's waits before its low-confidence runs moved from slowed
/// high-confidence samples into planned dwells at holds, its low-confidence intervals on the
/// same schedule clock (up to rounding): every high-confidence run followed by a
/// low-confidence run and holding a usable hold (`Problem::usable_holds`; the latest, `h`)
/// runs its samples before `h` at `ψ̇min`, travels from `h` to the run as
/// `shape::held_schedule` does (its fastest plus one control tick `tick_s`, at most its
/// slowest; less room when the run is too short), and dwells at `h` for the rest of the run's
/// planned duration (its samples' clock plus the dwells it had). The dwells carry no release
/// rules (`Problem::with_release_rules` derives them). `None` when nothing changes.
///
/// **Why** (docs/decisions.md, "Three robots at δ ≥ 1 s: waits as dwells (issue 41)"): the
/// margin check's worst-case operator may run any high-confidence sample at `ψ̇min`, covering
/// `ψ̇_E/ψ̇min` ticks of schedule clock per tick, so a robot whose approach to its stretch
/// was planned slowed can arrive that much earlier: with a switch time the room a pair needs
/// grows with that rate (the lead bound's `M_c + (k − 1)·M_c'`). A dwell's clock passes one
/// tick per tick whatever the operator, and the hold can wait for the robot before it by a
/// release rule.
pub(crate) fn dwelled(problem: &Problem, schedule: &Schedule, tick_s: f64) -> Option<Schedule> {
    let usable = problem.usable_holds();
    if usable.is_empty() {
        return None;
    }
    let dt = problem.dt_s();
    let (gmin, gmax) = (problem.grad_min(), problem.grad_max());
    let sum = |v: &[f64], a: usize, b: usize| v[a..b].iter().sum::<f64>() * dt;
    let n_ref = problem.n_ref();
    let n = schedule.n_robots();
    let mut out = schedule.clone();
    if out.holds.is_empty() {
        out.holds = vec![Vec::new(); n];
    }
    let mut changed = false;
    for r in 0..n {
        for run in problem.runs() {
            let (a, b) = (run.start, run.end);
            if !run.high_conf || b >= n_ref {
                continue;
            }
            let Some(h) = usable.iter().rev().copied().find(|&h| a < h && h < b) else {
                continue;
            };
            let warp = &mut out.grad_exec[r];
            let holds = &mut out.holds[r];
            let dwells_s: f64 = holds
                .iter()
                .filter(|x| a < x.ref_idx && x.ref_idx < b)
                .map(|x| x.dwell_s)
                .sum();
            let duration_s = tandem_realtime::clock_end_s(&warp[a..b], 0.0, dt) + dwells_s;
            let pre_min = sum(gmin, a, h);
            let travel_min = sum(gmin, h, b);
            let travel_s = (travel_min + tick_s)
                .min(sum(gmax, h, b))
                .min(duration_s - pre_min)
                .max(travel_min);
            let mut new = warp[a..b].to_vec();
            new[..h - a].copy_from_slice(&gmin[a..h]);
            fill_uniform(problem, &mut new[h - a..], h, travel_s);
            let dwell_s = duration_s - tandem_realtime::clock_end_s(&new, 0.0, dt);
            // Less than rounding: the run is at its fastest already.
            if !(dwell_s.is_finite() && dwell_s > 1e-9) {
                continue;
            }
            let same = new == warp[a..b]
                && holds
                    .iter()
                    .filter(|x| a < x.ref_idx && x.ref_idx < b)
                    .map(|x| (x.ref_idx, x.dwell_s))
                    .eq([(h, dwell_s)]);
            if same {
                continue;
            }
            warp[a..b].copy_from_slice(&new);
            holds.retain(|x| !(a < x.ref_idx && x.ref_idx < b));
            holds.push(Hold {
                dwell_s,
                ..Hold::at(h)
            });
            holds.sort_by_key(|x| x.ref_idx);
            changed = true;
        }
    }
    changed.then_some(out)
}
