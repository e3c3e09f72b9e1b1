//! Speed shaping inside HC runs: how a run's duration (fixed by the event times) is spread over
//! its samples so that the worst-case margin check (Alg. 2) finds little lead to absorb (see
//! "Margin-aware completion" in the module docs of [`super`]).

use super::build::fill_uniform;
use super::chain::Chain;
use super::stn::Times;
use crate::problem::Problem;
use crate::schedule::Schedule;

/// How the HC runs are shaped; times in s of schedule clock.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Shaping {
    /// Length of the edges next to the robot's own LC runs: the margin check reads a robot's
    /// mode and rates over a window of one maximal step `M` around its clock and its clock can
    /// overshoot by one more step, so `2·M` (plus the check's tolerance).
    pub(crate) edge_s: f64,
    /// Tilt `θ` of the body's speed factor, in `[0, 1]`: sample `i` of `N` gets
    /// `u_i = u₀ + θ·(1 − 2i/(N − 1))` clamped into `[0, 1]` (slow first, fast last for `θ > 0`;
    /// one factor for the whole body at `θ = 0`), with `u₀` set by the run's duration.
    pub(crate) tilt: f64,
}

/// The schedule with event times `times` and shaped HC speeds (LC samples at the mean, Eq. 20
/// constraint 4), at control tick `tick_s` (s).
///
/// Each HC run (gap `g` of robot `r`) lasts exactly as `times` say, up to rounding:
/// - its last samples, over `edge_s` of clock before the robot's own next LC run, run at
///   `ψ̇min` (`F = 1`): the check counts the robot as LC up to a step before its run and lets it
///   rush at its largest `F` in the window, which is then no more than the LC run's own;
/// - its first samples, over `edge_s` after the robot's own LC run, run no faster than that run
///   left it (`S = ψ̇_E/ψ̇max` at least the smallest `S` of the run's last `edge_s`): the check
///   lets the leaving robot drag at the smallest `S` in its window, which then stays the LC
///   run's own;
/// - the body in between gets the tilted speed factor of [`Shaping::tilt`] between `ψ̇min` and
///   `ψ̇max`.
///
/// If the edges leave no way to reach the duration, the run gets one speed factor for all its
/// samples (`fill_uniform`).
pub(crate) fn shaped_schedule(
    problem: &Problem,
    chain: &Chain,
    times: &Times,
    shaping: &Shaping,
    tick_s: f64,
) -> Schedule {
    let warps = [0, 1].map(|r| {
        let gaps = times.gaps_s(chain, r);
        let mut warp = problem.grad_mean().to_vec();
        for (g, &(a, b)) in chain.gap_ref.iter().enumerate() {
            if b > a {
                let run = Run {
                    problem,
                    chain,
                    gap: g,
                    start: a,
                    end: b,
                    shaping,
                };
                run.fill(&mut warp[a..b], gaps[g]);
            }
        }
        warp
    });
    Schedule {
        grad_exec: Vec::from(warps),
        offsets_s: vec![times.tau_s],
        tick_s,
        holds: Vec::new(),
    }
}

/// One HC run (gap `gap` of the chain, reference samples `start..end`).
struct Run<'a> {
    problem: &'a Problem,
    chain: &'a Chain,
    gap: usize,
    start: usize,
    end: usize,
    shaping: &'a Shaping,
}

impl Run<'_> {
    /// Writes into `out` gradients lasting `dur_s` (s); see [`shaped_schedule`].
    fn fill(&self, out: &mut [f64], dur_s: f64) {
        let p = self.problem;
        let dt = p.dt_s();
        let (gmin, gmax) = (p.grad_min(), p.grad_max());
        let (a, b) = (self.start, self.end);
        let edge = self.shaping.edge_s;
        // Trailing edge at ψ̇min before the robot's own next LC run.
        let mut pre = b;
        if self.gap < self.chain.n_lc() {
            let mut clock = 0.0;
            while pre > a && clock < edge {
                pre -= 1;
                clock += gmin[pre] * dt;
            }
        }
        // Leading edge no faster than the robot's own LC run left it.
        let mut post = a;
        if self.gap > 0 {
            let slow = self.exit_slow_rate();
            let mut clock = 0.0;
            while post < pre && clock < edge {
                let g = (slow * gmax[post]).clamp(gmin[post], gmax[post]);
                out[post - a] = g;
                clock += g * dt;
                post += 1;
            }
        }
        out[pre - a..].copy_from_slice(&gmin[pre..b]);
        let fixed_s: f64 = out[..post - a].iter().chain(&out[pre - a..]).sum::<f64>() * dt;
        let body = Body {
            problem: p,
            start: post,
            end: pre,
            tilt: self.shaping.tilt,
        };
        if !body.fill(&mut out[post - a..pre - a], dur_s - fixed_s) {
            fill_uniform(p, out, a, dur_s);
        }
        // Rounding goes to the last samples, within their bounds.
        let mut rest = (dur_s - out.iter().sum::<f64>() * dt) / dt;
        for (i, g) in out.iter_mut().enumerate().rev() {
            if rest == 0.0 {
                break;
            }
            let n = a + i;
            let new = (*g + rest).clamp(gmin[n], gmax[n]);
            rest -= new - *g;
            *g = new;
        }
    }

    /// The smallest `S = ψ̇̄/ψ̇max` over the last `edge_s` of clock of the LC run before this gap.
    fn exit_slow_rate(&self) -> f64 {
        let p = self.problem;
        let (lc_a, lc_b) = self.chain.lc_ref[self.gap - 1];
        let (gmean, gmax) = (p.grad_mean(), p.grad_max());
        let mut clock = 0.0;
        let mut slow = f64::INFINITY;
        let mut n = lc_b;
        while n > lc_a && clock < self.shaping.edge_s {
            n -= 1;
            clock += gmean[n] * p.dt_s();
            slow = slow.min(gmean[n] / gmax[n]);
        }
        slow
    }
}

/// The body of an HC run: reference samples `start..end` with a tilted speed factor.
struct Body<'a> {
    problem: &'a Problem,
    start: usize,
    end: usize,
    tilt: f64,
}

impl Body<'_> {
    /// Writes the gradients at level `u0` into `out`; returns their duration (s),
    /// non-decreasing in `u0`.
    fn walk(&self, u0: f64, out: &mut [f64]) -> f64 {
        let p = self.problem;
        let (gmin, gmax) = (p.grad_min(), p.grad_max());
        let last = (self.end - self.start).saturating_sub(1).max(1) as f64;
        let mut sum = 0.0;
        for (i, g) in out.iter_mut().enumerate() {
            let n = self.start + i;
            let u = (u0 + self.tilt * (1.0 - 2.0 * i as f64 / last)).clamp(0.0, 1.0);
            *g = gmin[n] + u * (gmax[n] - gmin[n]);
            sum += *g;
        }
        sum * p.dt_s()
    }

    /// Fills `out` with the level whose duration is `need_s` (s), blending the two bracketing
    /// walks sample by sample to the exact duration; `false` (and `out` undefined) if no level
    /// reaches it.
    fn fill(&self, out: &mut [f64], need_s: f64) -> bool {
        if out.is_empty() {
            return need_s.abs() <= 1e-12;
        }
        let (mut a, mut b) = (-1.0 - self.tilt, 2.0 + self.tilt);
        let mut lower = out.to_vec();
        let mut upper = out.to_vec();
        let fa = self.walk(a, &mut lower);
        let fb = self.walk(b, &mut upper);
        if !(fa <= need_s && need_s <= fb) {
            return false;
        }
        let (mut fa, mut fb) = (fa - need_s, fb - need_s);
        let mut scratch = out.to_vec();
        let mut side = 0;
        // Illinois regula falsi on the (piecewise linear, non-decreasing) duration.
        for _ in 0..48 {
            if fa == 0.0 || fb == 0.0 || b - a < 1e-9 {
                break;
            }
            let c = (a * fb - b * fa) / (fb - fa);
            let c = if c > a && c < b { c } else { 0.5 * (a + b) };
            let fc = self.walk(c, &mut scratch) - need_s;
            if fc < 0.0 {
                (a, fa) = (c, fc);
                std::mem::swap(&mut lower, &mut scratch);
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            } else {
                (b, fb) = (c, fc);
                std::mem::swap(&mut upper, &mut scratch);
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            }
            if fc.abs() < 1e-9 {
                break;
            }
        }
        let dt = self.problem.dt_s();
        let total = |g: &[f64]| g.iter().sum::<f64>() * dt;
        let (ta, tb) = (total(&lower), total(&upper));
        let mu = if tb > ta {
            ((need_s - ta) / (tb - ta)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        for ((g, lo), up) in out.iter_mut().zip(&lower).zip(&upper) {
            *g = lo + mu * (up - lo);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::search::Clearance;
    use crate::exact::stn;

    /// [LC ×10, HC ×40, LC ×10], mean 1 in [0.5, 2] with a wobble in the HC bounds, 10 ms.
    fn lhl() -> Problem {
        let n = 60;
        let conf: Vec<bool> = (0..n).map(|i| (10..50).contains(&i)).collect();
        let hi: Vec<f64> = (0..n).map(|i| 2.0 + 0.5 * ((i % 7) as f64 / 7.0)).collect();
        Problem::new(conf, vec![1.0; n], vec![0.5; n], hi, 0.01).unwrap()
    }

    #[test]
    fn shaped_runs_last_as_the_times_say_within_bounds() {
        let p = lhl();
        let chain = Chain::new(&p);
        // 1 2 1 2 with 0.1 s between the robots: each HC run lasts 0.3 s (of [0.2, ~0.9] s),
        // waiting for the other robot's LC run and the clearances.
        let times = stn::earliest(&chain, &[0, 1, 0, 1], &Clearance::uniform(0.1, None)).unwrap();
        for tilt in [0.0, 0.5, 1.0] {
            let shaping = Shaping { edge_s: 0.02, tilt };
            let s = shaped_schedule(&p, &chain, &times, &shaping, 0.01);
            for r in 0..2 {
                let g = &s.grad_exec[r];
                // LC samples at the mean (Eq. 20 constraint 4), HC within the bounds.
                assert!(g[..10].iter().chain(&g[50..]).all(|&x| x == 1.0));
                let bounds = p.grad_min().iter().zip(p.grad_max());
                for (n, (&x, (&lo, &hi))) in g.iter().zip(bounds).enumerate().take(50).skip(10) {
                    assert!(x >= lo && x <= hi, "{tilt} {r} {n}");
                }
                let dur: f64 = g[10..50].iter().sum::<f64>() * 0.01;
                let want = times.gaps_s(&chain, r)[1];
                assert!(
                    (dur - want).abs() < 1e-12,
                    "tilt {tilt}, robot {r}: {dur} vs {want}"
                );
                assert!((times.gaps_s(&chain, r)[1] - 0.3).abs() < 1e-12);
                // The edge before the robot's own next LC run is at ψ̇min (0.02 s = 4 samples);
                // rounding goes to the last sample.
                assert!(g[46..49].iter().all(|&x| x == 0.5), "{:?}", &g[40..50]);
                // The first 0.02 s after its LC run are no faster than the run left it: the
                // smallest S = ψ̇̄/ψ̇max over the run's last 0.02 s (samples 8 and 9), so
                // ψ̇_E ≥ S·ψ̇max.
                let (gmax, gmean) = (p.grad_max(), p.grad_mean());
                let exit = (gmean[8] / gmax[8]).min(gmean[9] / gmax[9]);
                assert!(g[10] >= exit * gmax[10] - 1e-12 && g[11] >= exit * gmax[11] - 1e-12);
                // With a tilt the body runs slow first, fast last.
                if tilt > 0.0 {
                    let u = |n: usize| (g[n] - 0.5) / (p.grad_max()[n] - 0.5);
                    assert!(u(16) > u(44), "tilt {tilt}: {} ≤ {}", u(16), u(44));
                }
            }
        }
    }
}
