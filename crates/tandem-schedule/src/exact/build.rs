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
