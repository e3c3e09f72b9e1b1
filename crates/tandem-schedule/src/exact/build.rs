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
    let mut holds: Vec<Vec<Hold>> = vec![Vec::new(); 2];
    let warps = [0, 1].map(|r| {
        let gaps = times.gaps_s(chain, r);
        let mut warp = problem.grad_mean().to_vec();
        for (g, &(a, b)) in chain.gap_ref.iter().enumerate() {
            fill_uniform(problem, &mut warp[a..b], a, gaps[g]);
            // A gap longer than its slowest speeds allow (only a gap with a hold may be, in a
            // chain built with holds): the rest is a planned dwell at its hold.
            if let Some(h) = chain.gap_hold[g] {
                let filled_s = tandem_realtime::clock_end_s(&warp[a..b], 0.0, problem.dt_s());
                let dwell_s = gaps[g] - filled_s;
                if dwell_s > 0.0 {
                    holds[r].push(Hold {
                        dwell_s,
                        ..Hold::at(h)
                    });
                }
            }
        }
        warp
    });
    if holds.iter().all(Vec::is_empty) {
        holds.clear();
    }
    Schedule {
        grad_exec: Vec::from(warps),
        offsets_s: vec![times.tau_s],
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
