//! The drag lead of two robots: per pair of LC runs, the least room the margin check lets
//! a switch keep, for [`super::drag_charged_bound`] (docs/decisions.md, "Two robots: a bound
//! that charges the drag lead (issue 38)").
//!
//! Notation (both robots traverse the same reference): sample `n` lasts `d_n = ψ̇_E[n]·Δt`
//! schedule-clock seconds as planned, between `ψ̇min[n]·Δt` (fastest) and `ψ̇max[n]·Δt`
//! (slowest, Eq. 20 constraint 1); an LC sample is planned at `ψ̇̄[n]` (constraint 4). The
//! check's slow rate `S = ψ̇_E/ψ̇max` (Eq. 17) makes a robot that goes as slowly as the
//! demonstrations allow cross sample `n` in `ψ̇max[n]·Δt` seconds of real time whatever its
//! plan: the *slow time* of a stretch of reference is fixed by the problem, its planned
//! (schedule-clock) duration is not. Positions `u` on the reference are continuous (`u ∈
//! [0, T_ref]`, sample `⌊u⌋` partly crossed).

use std::collections::BTreeMap;

use super::chain::Chain;
use crate::problem::Problem;

/// Largest number of entry points `a` tried per LC run (a stride over its samples when it has
/// more): the room is the largest over the points tried, so fewer points only lower it.
const MAX_ENTRY_POINTS: usize = 96;

/// Cumulative durations along the reference (s): fastest (`ψ̇min`), slowest (`ψ̇max`, the
/// slow time) and mean (`ψ̇̄`), each `T_ref + 1` long with `cum[0] = 0`.
struct Cum {
    fast: Vec<f64>,
    slow: Vec<f64>,
    mean: Vec<f64>,
}

/// `cum` at the continuous position `u` (linear within a sample).
fn at(cum: &[f64], u: f64) -> f64 {
    let n = cum.len() - 1;
    let u = u.clamp(0.0, n as f64);
    let i = (u.floor() as usize).min(n.saturating_sub(1));
    let frac = u - i as f64;
    if n == 0 {
        return cum[0];
    }
    cum[i] + frac * (cum[i + 1] - cum[i])
}

/// The position `u` with `at(cum, u) = v` (`cum` strictly increasing: every duration is > 0),
/// clamped to `[0, T_ref]`.
fn inverse(cum: &[f64], v: f64) -> f64 {
    let n = cum.len() - 1;
    if v <= cum[0] {
        return 0.0;
    }
    if v >= cum[n] {
        return n as f64;
    }
    let i = cum.partition_point(|&c| c <= v) - 1;
    let w = cum[i + 1] - cum[i];
    i as f64 + ((v - cum[i]) / w).clamp(0.0, 1.0)
}

impl Cum {
    fn new(problem: &Problem) -> Cum {
        let dt = problem.dt_s();
        let prefix = |g: &[f64]| {
            let mut c = Vec::with_capacity(g.len() + 1);
            c.push(0.0);
            let mut s = 0.0;
            for &x in g {
                s += x * dt;
                c.push(s);
            }
            c
        };
        Cum {
            fast: prefix(problem.grad_min()),
            slow: prefix(problem.grad_max()),
            mean: prefix(problem.grad_mean()),
        }
    }
}

/// What the room of one switch is computed from (all s, schedule clock unless said).
pub(crate) struct DragParams {
    /// `M_lo`: the least the check's maximal step can be (the LC samples' `ψ̇̄/ψ̇min` alone,
    /// less the gradient tolerance).
    pub(crate) step_lo_s: f64,
    /// `M_hi`: the most it can be (every sample at its largest fast rate, `ψ̇max/ψ̇min` on HC
    /// samples, plus the tolerance), plus the check's clock tolerance `ε`.
    pub(crate) step_hi_s: f64,
    /// The control tick `h` (real s).
    pub(crate) tick_s: f64,
    /// Relative tolerance of planned gradients (`tol::GRADIENT_REL`).
    pub(crate) rel: f64,
}

/// `Φ_k(R)`: the least planned time (s) from the position `y` the robot entering LC run `k`
/// (`c`) can have had when the drag began to the start of run `k`, given that `c` crossed
/// slow time at least `R` (real s) from `y` to its position `x` at the exit, and kept at least
/// `M` of planned time from `x` to its run: `min over x of fast(Y_R(x), x) + max(M_lo,
/// fast(x, g₁))` with `Y_R(x)` the position `R` of slow time before `x` (`y ≤ Y_R(x)`), `x`
/// in gap `k` `[g₀, g₁]` with `Y_R(x) ≥ g₀`; `+∞` when no `x` has that much slow time after
/// `g₀`. The function is piecewise linear in `x` with breaks where `x` or `Y_R(x)` crosses a
/// sample boundary and where `fast(x, g₁) = M_lo`, so its least value is at one of those.
fn least_before(cum: &Cum, gap: (usize, usize), r_s: f64, dp: &DragParams) -> f64 {
    let (g0, g1) = (gap.0 as f64, gap.1 as f64);
    let k_fast = 1.0 - dp.rel;
    let fast = |u: f64| k_fast * at(&cum.fast, u);
    let tail = |x: f64| dp.step_lo_s.max(fast(g1) - fast(x));
    if r_s <= 0.0 {
        // No slow time to cross: `x` may be anywhere, `y = x`.
        return dp.step_lo_s.max(0.0);
    }
    let slow_g0 = at(&cum.slow, g0);
    if slow_g0 + r_s > at(&cum.slow, g1) {
        return f64::INFINITY;
    }
    let x_lo = inverse(&cum.slow, slow_g0 + r_s).max(g0);
    let f = |x: f64| {
        let y = inverse(&cum.slow, at(&cum.slow, x) - r_s);
        fast(x) - fast(y) + tail(x)
    };
    let mut best = f(x_lo).min(f(g1));
    // `x` at sample boundaries.
    for n in (x_lo.ceil() as usize)..=gap.1 {
        best = best.min(f(n as f64));
    }
    // `Y_R(x)` at sample boundaries.
    for b in gap.0..=gap.1 {
        let x = inverse(&cum.slow, cum.slow[b] + r_s);
        if x > g1 {
            break;
        }
        if x >= x_lo {
            best = best.min(f(x));
        }
    }
    // The kink of `max(M_lo, fast(x, g₁))`.
    let x_star = inverse(&cum.fast, (fast(g1) - dp.step_lo_s) / k_fast);
    if (x_lo..=g1).contains(&x_star) {
        best = best.min(f(x_star));
    }
    best
}

/// The least real time (s) the dragging robot `p` spends in LC run `[s, e)`, cumulative from
/// `s` (`e − s + 1` entries): the check moves `p` by `S^w·h` per tick, `S^w` the least slow
/// rate of its window (fix 2), which holds every point within `M + ε` of its clock; a step is
/// at most `h` (`S ≤ 1`), so every LC sample of the run within `r = M_lo − h` (planned clock,
/// at most `(1 + rel)·ψ̇̄·Δt` per sample) of every point of sample `n` is in the window while
/// `p` crosses `n`, and `p` spends at least `ψ̇_E[n]·Δt/S̃(n)` real seconds there, `S̃(n)` the
/// least `ψ̇̄/ψ̇max` of those samples (`n` itself among them: at least its slow time).
fn drag_time(problem: &Problem, cum: &Cum, run: (usize, usize), dp: &DragParams) -> Vec<f64> {
    let (s, e) = run;
    let (gmean, gmax) = (problem.grad_mean(), problem.grad_max());
    let reach = (dp.step_lo_s - dp.tick_s * (1.0 + dp.rel)).max(0.0) / (1.0 + dp.rel);
    let rate = |n: usize| gmean[n] / gmax[n];
    let mut out = Vec::with_capacity(e - s + 1);
    out.push(0.0);
    let mut sum = 0.0;
    for n in s..e {
        let mut least = rate(n);
        let mut b = n + 1;
        while b < e && cum.mean[b] - cum.mean[n] <= reach {
            least = least.min(rate(b));
            b += 1;
        }
        let mut a = n;
        while a > s && cum.mean[n + 1] - cum.mean[a] <= reach {
            least = least.min(rate(a - 1));
            a -= 1;
        }
        sum += (1.0 - 3.0 * dp.rel) * (cum.mean[n + 1] - cum.mean[n]) / least;
        out.push(sum);
    }
    out
}

/// Per pair `(j, k)` of LC runs (robot `p` leaves run `j`, the other robot `c` enters run `k`
/// next on the operator), the least room `T_c − T_p` (s) every two-robot schedule without
/// usable holds that the margin check accepts at tick `dp.tick_s` keeps, when `c` is not robot
/// 2 entering its first run after a robot-1 run that ended by robot 2's start (the search's
/// `after_start` exception). Not below 0; the caller takes the larger of this and the step
/// charge `M`. The proof is in [`super::drag_charged_bound`].
pub(crate) fn drag_room(
    problem: &Problem,
    chain: &Chain,
    dp: &DragParams,
) -> BTreeMap<(usize, usize), f64> {
    let cum = Cum::new(problem);
    let m = chain.n_lc();
    let k_mean = 1.0 + dp.rel;
    let k_fast = 1.0 - dp.rel;
    let lag_s = dp.tick_s * k_mean;
    let mut out = BTreeMap::new();
    for j in 0..m {
        let (s_j, e_j) = chain.lc_ref[j];
        let n_j = e_j - s_j;
        let stride = n_j.div_ceil(MAX_ENTRY_POINTS).max(1);
        let mut entries: Vec<usize> = (s_j..e_j).step_by(stride).collect();
        entries.push(e_j);
        // Per entry point `q`: the slow time of `p` from `q` to its exit, and the planned time
        // (at most `(1 + rel)·Σψ̇̄Δt`) it has left.
        let p_real = drag_time(problem, &cum, (s_j, e_j), dp);
        let slow_left = |q: usize| p_real[e_j - s_j] - p_real[q - s_j];
        let mean_left = |q: usize| k_mean * (cum.mean[e_j] - cum.mean[q]);
        for k in 0..m {
            let gap = chain.gap_ref[k];
            let gap_fast = k_fast * (cum.fast[gap.1] - cum.fast[gap.0]);
            // `c` still near its previous run when the drag began: it left that run's window
            // at most `2·M_hi` (clock) before the drag's first tick.
            let clamp = if k == 0 {
                f64::INFINITY
            } else {
                gap_fast - 2.0 * dp.step_hi_s
            };
            // `C_gen`: `c`'s exit position `x` is one for every entry point, so per cell
            // `[x_i, x_{i+1}]` of gap `k` the largest bound over the entry points, each at its
            // least on the cell, and the least over the cells.
            let general = if gap.0 == gap.1 {
                // No HC sample before run `k`: `c`'s window always holds an LC sample.
                0.0
            } else {
                let fast = |u: f64| k_fast * at(&cum.fast, u);
                let g1_fast = fast(gap.1 as f64);
                let slow_g0 = cum.slow[gap.0];
                (gap.0..gap.1)
                    .map(|i| {
                        let (x0, x1) = (i as f64, (i + 1) as f64);
                        let tail = dp.step_lo_s.max(g1_fast - fast(x1));
                        entries
                            .iter()
                            .map(|&q| {
                                let r_s = slow_left(q);
                                // `Y_R(x) ≤ Y_R(x_{i+1})`, `x ≥ x_i`.
                                let back = cum.slow[i + 1] - r_s;
                                let drag = if back < slow_g0 && r_s > 0.0 {
                                    f64::INFINITY
                                } else {
                                    let y1 = inverse(&cum.slow, back);
                                    (fast(x0) - fast(y1)).max(0.0) + tail
                                };
                                drag.min(clamp) - mean_left(q) - lag_s
                            })
                            .fold(f64::NEG_INFINITY, f64::max)
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            let room = if k == 0 {
                // Robot 2 may start inside run `j` (at `τ`, then the drag begins there with
                // the lead 0): the least, over cells `[q_i, q_{i+1}]` of `τ`, of the larger of
                // the drag bound and its fastest head, each at its least on the cell.
                let started = entries
                    .windows(2)
                    .map(|w| {
                        let drag = least_before(&cum, gap, slow_left(w[1]), dp);
                        drag.max(gap_fast) - mean_left(w[0]) - lag_s
                    })
                    .fold(f64::INFINITY, f64::min);
                general.min(started)
            } else {
                general
            };
            out.insert((j, k), room.max(0.0));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `at` and `inverse` by hand on durations 1, 2, 1.
    #[test]
    fn positions_by_hand() {
        let cum = [0.0, 1.0, 3.0, 4.0];
        assert_eq!(at(&cum, 1.5), 2.0);
        assert_eq!(inverse(&cum, 2.0), 1.5);
        assert_eq!(inverse(&cum, 5.0), 3.0);
        assert_eq!(inverse(&cum, -1.0), 0.0);
        assert_eq!(at(&cum, 3.0), 4.0);
    }
}
