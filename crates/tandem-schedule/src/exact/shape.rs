//! Speed shaping inside HC runs, so that the worst-case margin check (Alg. 2) finds little lead
//! to absorb (see "Margin-aware completion" in the module docs of [`super`]).

use super::build::fill_uniform;
use super::chain::Chain;
use super::stn::Times;
use crate::problem::Problem;
use crate::schedule::Schedule;

/// Knobs of the shaping; times in s of global (schedule-clock) time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Shaping {
    /// How far around the other robot's LC stretches it counts as LC (the margin check widens
    /// LC regions by one maximal step `M`).
    pub(crate) window_s: f64,
    /// Length of the stretch before the end of the other robot's LC stretch in which this robot
    /// runs at `ψ̇min` (where the margin check decides the pair).
    pub(crate) zone_s: f64,
    /// Length of the stretch after the robot's own LC run in which it keeps the slow rate of its
    /// last LC sample (it is the dragging robot there).
    pub(crate) edge_s: f64,
    /// Largest fast rate `F = ψ̇_E/ψ̇min` a sample may get unless the run's duration needs more
    /// (the margin check's maximal step grows with the largest `F` of any sample).
    pub(crate) f_cap: f64,
}

/// Time class of an HC sample, by the global time at which the robot enters it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Class {
    /// Right after the robot's own LC run: it is the dragging robot there.
    Post,
    /// The other robot is LC nearby and its LC stretch ends soon: the pair is decided there.
    Zone,
    /// The other robot is LC nearby.
    Band,
    /// The other robot is HC.
    Free,
}

/// Where the other robot is LC, as time intervals (s) of global time: `(band_from, zone_from,
/// end, band_to)` per LC stretch (band `[start − w, end + w]`, zone `[end − zone, end]`).
fn other_stretches(times: &Times, chain: &Chain, other: usize, k: &Shaping) -> Vec<[f64; 4]> {
    times.lc_start_s[other]
        .iter()
        .zip(&chain.lc_s)
        .map(|(&s, &l)| {
            let e = s + l;
            [
                s - k.window_s,
                (e - k.zone_s).max(s - k.window_s),
                e,
                e + k.window_s,
            ]
        })
        .collect()
}

/// The schedule with event times `times` and shaped HC speeds (LC samples at the mean).
///
/// With `keep = Some((t_s, base))`, HC runs entered at or after global time `t_s` keep
/// `base`'s gradients instead (for a margin check that only looks at what comes before).
pub(crate) fn shaped_schedule(
    problem: &Problem,
    chain: &Chain,
    times: &Times,
    knobs: &Shaping,
    keep: Option<(f64, &Schedule)>,
    tick_s: f64,
) -> Schedule {
    let warps = [0, 1].map(|r| {
        let stretches = other_stretches(times, chain, 1 - r, knobs);
        let gaps = times.gaps_s(chain, r);
        let mut warp = problem.grad_mean().to_vec();
        for (g, &(a, b)) in chain.gap_ref.iter().enumerate() {
            if b == a {
                continue;
            }
            let t0 = if g == 0 {
                if r == 0 { 0.0 } else { times.tau_s }
            } else {
                times.lc_start_s[r][g - 1] + chain.lc_s[g - 1]
            };
            if let Some((t_keep, base)) = keep
                && t0 >= t_keep
            {
                warp[a..b].copy_from_slice(&base.grad_exec[r][a..b]);
                continue;
            }
            let post_slow = (g > 0).then(|| problem.grad_mean()[a - 1] / problem.grad_max()[a - 1]);
            let run = Run {
                problem,
                stretches: &stretches,
                start: a,
                t0,
                post_slow,
                knobs,
            };
            fill_uniform(problem, &mut warp[a..b], a, gaps[g]);
            run.fill(&mut warp[a..b], gaps[g]);
        }
        warp
    });
    Schedule {
        grad_exec: warps,
        offset_s: times.tau_s,
        tick_s,
    }
}

/// One HC run of one robot to be shaped.
struct Run<'a> {
    problem: &'a Problem,
    stretches: &'a [[f64; 4]],
    /// First reference sample.
    start: usize,
    /// Global time (s) at which the robot enters the run.
    t0: f64,
    /// `S = ψ̇̄/ψ̇max` of the robot's last LC sample when the run follows one of its LC runs.
    post_slow: Option<f64>,
    knobs: &'a Shaping,
}

impl Run<'_> {
    /// Walks the run at speed level `lam` (see [`level`]), writing the gradients into `out`;
    /// returns the run's duration (s). Each sample's class follows the walk's own times.
    fn walk(&self, lam: f64, out: &mut [f64]) -> f64 {
        self.walk_with(out, |_, lo, hi, class| {
            level(
                lam,
                lo,
                hi,
                class,
                self.post_slow.unwrap_or(1.0),
                self.knobs.f_cap,
            )
        })
    }

    /// Walks the run with gradient `gradient(i, lo, hi, class)` per sample, writing the
    /// gradients into `out`; returns the run's duration (s).
    fn walk_with(
        &self,
        out: &mut [f64],
        mut gradient: impl FnMut(usize, f64, f64, Class) -> f64,
    ) -> f64 {
        let p = self.problem;
        let (gmin, gmax) = (p.grad_min(), p.grad_max());
        let dt = p.dt_s();
        let k = self.knobs;
        let st = self.stretches;
        let mut j = st.partition_point(|s| s[3] < self.t0);
        let mut t = self.t0;
        for (i, g) in out.iter_mut().enumerate() {
            while j < st.len() && st[j][3] < t {
                j += 1;
            }
            let class = match self.post_slow {
                Some(_) if t - self.t0 < k.edge_s => Class::Post,
                _ => match st.get(j) {
                    Some(s) if t >= s[1] && t <= s[2] => Class::Zone,
                    Some(s) if t >= s[0] => Class::Band,
                    _ => Class::Free,
                },
            };
            let n = self.start + i;
            *g = gradient(i, gmin[n], gmax[n], class);
            t += *g * dt;
        }
        t - self.t0
    }

    /// The speed level that gives `dur_s` (s) with every sample kept in the class it has at the
    /// times of the gradients in `g` (the duration is then piecewise linear in the level).
    fn guess(&self, g: &[f64], dur_s: f64) -> f64 {
        let dt = self.problem.dt_s();
        let mut at = g.to_vec();
        let mut class = Vec::with_capacity(g.len());
        self.walk_with(&mut at, |i, lo, hi, c| {
            class.push((lo, hi, c));
            g[i]
        });
        let (post, cap) = (self.post_slow.unwrap_or(1.0), self.knobs.f_cap);
        let total = |lam: f64| {
            class
                .iter()
                .map(|&(lo, hi, c)| level(lam, lo, hi, c, post, cap))
                .sum::<f64>()
                * dt
        };
        let knots = [-1.0, 0.0, 1.0, 2.0];
        let totals = knots.map(total);
        if dur_s <= totals[0] {
            return -1.0;
        }
        for s in 0..3 {
            if dur_s <= totals[s + 1] {
                let (t0, t1) = (totals[s], totals[s + 1]);
                return knots[s]
                    + if t1 > t0 {
                        (dur_s - t0) / (t1 - t0)
                    } else {
                        0.0
                    };
            }
        }
        2.0
    }

    /// Writes the shaped gradients lasting `dur_s` (s) into `out` (which holds the uniform
    /// speeds of that duration): the speed level is found by a safeguarded regula falsi on the
    /// walk's duration (monotone in the level, but it may jump by up to a sample where a sample
    /// changes class), and the two bracketing walks are blended sample by sample to the exact
    /// duration. If no level reaches it (only rounding: the times respect every run's range),
    /// the uniform speeds stay.
    fn fill(&self, out: &mut [f64], dur_s: f64) {
        let dt = self.problem.dt_s();
        let guess = self.guess(out, dur_s);
        let mut lower = out.to_vec();
        let mut upper = out.to_vec();
        let mut scratch = out.to_vec();
        // Bracket outward from the guess.
        let (mut a, mut b) = (
            (guess - GUESS_STEP).max(-1.0),
            (guess + GUESS_STEP).min(2.0),
        );
        let mut fa = self.walk(a, &mut lower) - dur_s;
        while fa > 0.0 && a > -1.0 {
            a = (a - 4.0 * (b - a)).max(-1.0);
            fa = self.walk(a, &mut lower) - dur_s;
        }
        let mut fb = self.walk(b, &mut upper) - dur_s;
        while fb < 0.0 && b < 2.0 {
            b = (b + 4.0 * (b - a)).min(2.0);
            fb = self.walk(b, &mut upper) - dur_s;
        }
        if !(fa <= 0.0 && fb >= 0.0) {
            return;
        }
        let mut side = 0;
        for iter in 0..60 {
            if fa == 0.0 || fb == 0.0 || b - a < 1e-12 {
                break;
            }
            let secant = (a * fb - b * fa) / (fb - fa);
            let c = if iter % 3 != 2 && secant > a && secant < b {
                secant
            } else {
                0.5 * (a + b)
            };
            let fc = self.walk(c, &mut scratch) - dur_s;
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
            if fc.abs() < 1e-7 || b - a < 1e-3 {
                break;
            }
        }
        let total = |g: &[f64]| g.iter().sum::<f64>() * dt;
        let (ta, tb) = (total(&lower), total(&upper));
        let mu = if tb > ta {
            ((dur_s - ta) / (tb - ta)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        for ((g, lo), up) in out.iter_mut().zip(&lower).zip(&upper) {
            *g = lo + mu * (up - lo);
        }
        // Rounding goes to the last samples, within their bounds.
        let (gmin, gmax) = (self.problem.grad_min(), self.problem.grad_max());
        let mut rest = (dur_s - total(out)) / dt;
        for (i, g) in out.iter_mut().enumerate().rev() {
            if rest == 0.0 {
                break;
            }
            let n = self.start + i;
            let new = (*g + rest).clamp(gmin[n], gmax[n]);
            rest -= new - *g;
            *g = new;
        }
    }
}

/// Half-width of the first bracket around the guessed speed level.
const GUESS_STEP: f64 = 0.01;

/// The gradient of a sample with bounds `[lo, hi]` in class `class` at speed level
/// `lam ∈ [−1, 2]` (larger is slower). Presets: `Post` at `hi·post_slow` (the robot's last LC
/// sample's slow rate), `Zone` at `lo`, `Free` at `lo`, `Band` free to move: on `[−1, 0]` the
/// presets go from `lo` to their value (`Band` stays at `lo`); on `[0, 1]` `Band` goes from `lo`
/// to `min(hi, f_cap·lo)`; on `[1, 2]` everyone goes to `hi`.
fn level(lam: f64, lo: f64, hi: f64, class: Class, post_slow: f64, f_cap: f64) -> f64 {
    let cap = hi.min(lo * f_cap).max(lo);
    let preset = match class {
        Class::Post => (hi * post_slow).clamp(lo, cap),
        Class::Zone | Class::Free | Class::Band => lo,
    };
    let lam = lam.clamp(-1.0, 2.0);
    if lam < 0.0 {
        lo + (lam + 1.0) * (preset - lo)
    } else if lam < 1.0 {
        if class == Class::Band {
            lo + lam * (cap - lo)
        } else {
            preset
        }
    } else {
        let base = if class == Class::Band { cap } else { preset };
        base + (lam - 1.0) * (hi - base)
    }
}
