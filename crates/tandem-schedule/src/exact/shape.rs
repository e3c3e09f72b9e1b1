//! Speed shaping inside HC runs: how a run's duration (fixed by the event times) is spread over
//! its samples so that the worst-case margin check (Alg. 2) finds little lead to absorb (see
//! "Margin-aware completion" in the module docs of [`super`]).

use super::build::fill_uniform;
use super::chain::Chain;
use super::stn::Times;
use crate::problem::Problem;
use crate::schedule::Schedule;

/// The schedule with event times `times` and shaped HC speeds (LC samples at the mean, Eq. 20
/// constraint 4), at control tick `tick_s` (s).
///
/// Each HC run (gap `g` of robot `r`) lasts exactly as `times` say, up to rounding, with the
/// tilted speed factor `u_i = u₀ + θ·(1 − 2i/(N − 1))` (`θ = tilt ∈ [0, 1]`, sample `i` of the
/// run's `N`, clamped into `[0, 1]` between `ψ̇min` and `ψ̇max`; slow first, fast last for
/// `θ > 0`, one factor for the whole run at `θ = 0`) and `u₀` set by the run's duration. If no
/// level reaches the duration, the run gets one speed factor for all its samples
/// (`fill_uniform`). (No fixed-speed edges next to the robot's own LC runs: they cost the
/// responding robot its room to slow down, docs/decisions.md, "The margin-aware completion".)
pub(crate) fn shaped_schedule(
    problem: &Problem,
    chain: &Chain,
    times: &Times,
    tilt: f64,
    tick_s: f64,
) -> Schedule {
    let warps = [0, 1].map(|r| {
        let gaps = times.gaps_s(chain, r);
        let mut warp = problem.grad_mean().to_vec();
        for (g, &(a, b)) in chain.gap_ref.iter().enumerate() {
            if b > a {
                let body = Body {
                    problem,
                    start: a,
                    end: b,
                    tilt,
                };
                body.fill_run(&mut warp[a..b], gaps[g]);
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

/// [`shaped_schedule`] with hold points (`chain` built by `Chain::with_holds`): each HC run
/// that holds a usable hold `h` (`chain.gap_hold`) travels from `h` to the next LC run in one
/// control tick `tick_s` more than its fastest speeds need (at one speed factor; all of the
/// run's slowest if shorter), so that a release rule on `h` costs that travel after the awaited
/// run ends (`Clearance::rules` counts the same), and spreads the rest of its duration over
/// the samples before `h` (shaped at the tilt); what their slowest speeds cannot fill is a
/// planned dwell at `h`. Returns the schedule with its dwells as holds (no release rules yet).
///
/// **Why a tick more than the fastest travel.** A robot leaves its hold at a tick start, up to
/// a tick after the awaited robot has passed. Planned at its fastest it could not make that
/// up, and since the pace of Alg. 1 is the clock every running robot can reach, its lag holds
/// the other robot back too, whose next release is then late in turn: along the switches of
/// a round the ticks add up (+1.1–1.5 % over the plan on random problems with holds,
/// `tandem-sim`'s `plan_is_what_the_cell_does`). With a tick of room it runs its fastest and
/// reaches the LC run on time.
pub(crate) fn held_schedule(
    problem: &Problem,
    chain: &Chain,
    times: &Times,
    tilt: f64,
    tick_s: f64,
) -> Schedule {
    let mut schedule = shaped_schedule(problem, chain, times, tilt, tick_s);
    let dt = problem.dt_s();
    let (gmin, gmax) = (problem.grad_min(), problem.grad_max());
    let sum = |v: &[f64], a: usize, b: usize| v[a..b].iter().sum::<f64>() * dt;
    let mut holds: Vec<Vec<tandem_realtime::Hold>> = vec![Vec::new(); 2];
    for (r, robot_holds) in holds.iter_mut().enumerate() {
        let gaps = times.gaps_s(chain, r);
        let warp = &mut schedule.grad_exec[r];
        for (g, &(a, b)) in chain.gap_ref.iter().enumerate() {
            let Some(h) = chain.gap_hold[g] else {
                continue;
            };
            let (pre_min, pre_max) = (sum(gmin, a, h), sum(gmax, a, h));
            let travel_s = (sum(gmin, h, b) + tick_s).min(sum(gmax, h, b));
            // A run too short for the travel with its room and the fastest samples before the
            // hold (it cannot be shorter than both at their fastest) travels with less room.
            let travel_s = travel_s.min(gaps[g] - pre_min).max(sum(gmin, h, b));
            let pre_s = (gaps[g] - travel_s).clamp(pre_min, pre_max);
            fill_uniform(problem, &mut warp[h..b], h, travel_s);
            Body {
                problem,
                start: a,
                end: h,
                tilt,
            }
            .fill_run(&mut warp[a..h], pre_s);
            let filled_s = tandem_realtime::clock_end_s(&warp[a..b], 0.0, dt);
            let dwell_s = gaps[g] - filled_s;
            if dwell_s > 0.0 {
                robot_holds.push(tandem_realtime::Hold {
                    dwell_s,
                    ..tandem_realtime::Hold::at(h)
                });
            }
        }
    }
    if holds.iter().any(|h| !h.is_empty()) {
        schedule.holds = holds;
    }
    schedule
}

/// An HC run: reference samples `start..end` with a tilted speed factor.
struct Body<'a> {
    problem: &'a Problem,
    start: usize,
    end: usize,
    tilt: f64,
}

impl Body<'_> {
    /// Writes into `out` (the run's samples) gradients lasting `dur_s` (s); see
    /// [`shaped_schedule`].
    fn fill_run(&self, out: &mut [f64], dur_s: f64) {
        let p = self.problem;
        let dt = p.dt_s();
        let (gmin, gmax) = (p.grad_min(), p.grad_max());
        let a = self.start;
        if !self.fill(out, dur_s) {
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
            let s = shaped_schedule(&p, &chain, &times, tilt, 0.01);
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
                let u = |n: usize| (g[n] - 0.5) / (p.grad_max()[n] - 0.5);
                if tilt == 0.0 {
                    // One speed factor for the whole run: 0.3 s over 40 samples of 10 ms is
                    // a mean gradient of 0.75, so Σ (0.5 + u·(hi − 0.5)) = 30, u = 10 / Σ (hi − 0.5).
                    let span: f64 = p.grad_max()[10..50].iter().map(|h| h - 0.5).sum();
                    for n in 10..50 {
                        assert!((u(n) - 10.0 / span).abs() < 1e-9, "{n}: {}", u(n));
                    }
                } else {
                    // With a tilt the run goes slow first, fast last.
                    assert!(u(16) > u(44), "tilt {tilt}: {} ≤ {}", u(16), u(44));
                }
            }
        }
    }

    #[test]
    fn a_held_run_travels_from_its_hold_with_a_tick_of_room_and_dwells_the_rest() {
        // [HC ×4, LC ×4, HC ×2], gradients 1 in [0.5, 2], 0.1 s, a hold at sample 3, a tick of
        // 0.05 s: the head of robot 2 lasts 1.5 s. Sample 3 (after the hold) in its fastest
        // 0.05 s plus a tick, 0.1 s (gradient 1); samples 0..3 at most 3 · 0.2 = 0.6 s; the
        // rest, 1.5 − 0.7 = 0.8 s, is the dwell at 3. Robot 1's head of 0.2 s is too short for
        // the room: 0.15 + 0.05 s, every sample fastest, no dwell.
        let conf: Vec<bool> = (0..10).map(|n| !(4..8).contains(&n)).collect();
        let p = Problem::new(conf, vec![1.0; 10], vec![0.5; 10], vec![2.0; 10], 0.1)
            .unwrap()
            .with_holds(vec![3])
            .unwrap();
        let chain = Chain::with_holds(&p, 10.0);
        assert_eq!(chain.gap_hold, vec![Some(3), None]);
        let times = stn::Times {
            tau_s: 0.0,
            lc_start_s: [vec![0.2], vec![1.5]],
            end_s: [0.7, 2.0],
        };
        for tilt in [0.0, 0.5] {
            let s = held_schedule(&p, &chain, &times, tilt, 0.05);
            let close = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9);
            assert!(
                close(&s.grad_exec[1][..4], &[2.0, 2.0, 2.0, 1.0]),
                "{:?}",
                s.grad_exec[1]
            );
            assert!(
                close(&s.grad_exec[0][..4], &[0.5; 4]),
                "{:?}",
                s.grad_exec[0]
            );
            assert!(s.holds[0].is_empty());
            assert_eq!(s.holds[1].len(), 1);
            assert_eq!(s.holds[1][0].ref_idx, 3);
            assert!(
                (s.holds[1][0].dwell_s - 0.8).abs() < 1e-9,
                "{:?}",
                s.holds[1]
            );
            assert!((s.t_total_s(0.1) - 2.0).abs() < 1e-9);
        }
    }
}
