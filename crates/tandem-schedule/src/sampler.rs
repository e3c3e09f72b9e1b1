//! The anytime sampler of §II-C: sample offsets and high-confidence gradients, keep the
//! feasible candidate with the least `T_total`.
//!
//! # Sampling distribution
//!
//! Candidate `k` draws, from its own ChaCha8 stream `(seed, k)`:
//! 1. for each robot, one *speed factor* `u ∈ [0, 1]` per piece of every maximal
//!    high-confidence run (see [`Distribution`]); the piece's gradients are
//!    `ψ̇_E[n] = ψ̇min[n] + u·(ψ̇max[n] − ψ̇min[n])`, and `u = 0` (fastest) with probability
//!    [`SamplerParams::p_fastest`], else `u` is uniform;
//! 2. `v` uniform in `[0, 1)`, giving `τ` at fraction `v` of the offsets in `[0, |ψ_E1|]`
//!    (Eq. 20 constraint 2) that keep the two robots' low-confidence intervals apart
//!    ([`OffsetSampling::UniformFeasible`]; or of all of them, [`OffsetSampling::Uniform`]).
//!
//! Low-confidence samples follow the mean gradient (constraint 4).
//!
//! Why per run rather than per sample (the literal reading of the paper): with independent
//! per-sample gradients the duration of a run of `m` samples is a sum of `m` independent
//! terms, so it concentrates at its mean (relative spread `∝ 1/√m`) and the sampler never
//! proposes a fast or a slow run. Yet where the low-confidence intervals fall in global time
//! — which decides overlap and `T_total` — depends only on the run durations. One factor per
//! piece spreads each run's duration evenly over its whole admissible range, and lets a
//! candidate's low-confidence intervals and `T_total` be computed in `O(#pieces)` from
//! per-piece sums of `ψ̇min`, `ψ̇max` and `ψ̇̄`, without building the warp. The numbers that
//! decided it (`cargo run --release -p tandem-schedule --example sampling_distributions`,
//! synthetic fixture-like problem of 5700 samples, serial `T_total` 93.47 s, 5000 samples,
//! best `T_total` as mean ± std over 20 seeds (4 for per-sample), 2 cores):
//!
//! | distribution                              | best `T_total` (s) | time per sample |
//! |-------------------------------------------|--------------------|-----------------|
//! | per sample, `τ` uniform                   | 93.47 (= serial)   | 191 µs          |
//! | per sample, `τ` uniform-feasible          | 93.47 (= serial)   | 232 µs          |
//! | per run, `τ` uniform                      | 79.35 ± 3.40       | 1.1 µs          |
//! | per run, `p_fastest` 0.25, `τ` uniform    | 78.71 ± 2.78       | 1.0 µs          |
//! | per run, `τ` uniform-feasible             | 77.19 ± 2.67       | 2.3 µs          |
//! | per run, `p_fastest` 0.25, feasible `τ`   | 76.92 ± 2.44       | 1.6 µs          |
//! | **per run, `p_fastest` 0.5, feasible `τ`**| **76.93 ± 2.07**   | **1.0 µs**      |
//! | 2 pieces per run, 0.25, feasible `τ`      | 78.37 ± 4.68       | 1.9 µs          |
//! | 4 pieces per run, 0.25, feasible `τ`      | 76.82 ± 3.93       | 2.8 µs          |
//!
//! Per-sample candidates never beat the serial schedule (their hundreds of cheap-feasible
//! candidates all fail the margin check) and cost ~200× more; more pieces per run did not
//! help on average and widened the spread. The default is one factor per run, exact zero
//! (fastest) with probability 0.5, and `τ` uniform over the non-overlapping offsets.
//!
//! # Evaluation order
//!
//! 1. The incumbent: the previous schedule if it is still valid (else its repair: gradients
//!    clamped into the new bounds, the new mean on low-confidence samples, `τ` clamped), or
//!    the fastest serial schedule if that is faster or there is no valid previous one.
//! 2. Cheap checks on all candidates in parallel: `T_total` below the incumbent's and no
//!    overlap of the two robots' low-confidence intervals (constraint 3).
//! 3. The survivors sorted by `(T_total, k)`; the full constraints (the margin check of
//!    Alg. 2 last) run in that order, a few candidates at a time in parallel, until the first
//!    passes. The winner is therefore the least `(T_total, k)` among the fully feasible
//!    candidates, whatever the number of threads.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::problem::Problem;
use crate::schedule::{Schedule, execution_s};
use crate::validate::{MarginCheck, margins_ok, validate_cheap, validate_with_tick};
use crate::{Error, Result};

/// How a candidate's high-confidence gradients are sampled (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Distribution {
    /// One independent factor per high-confidence reference sample (the literal reading of
    /// §II-C). Kept as a measured baseline.
    PerSample,
    /// Each maximal high-confidence run is cut into `pieces` pieces of (nearly) equal sample
    /// count, with one speed factor per piece. `pieces ≥ 1`.
    PerRun {
        /// Pieces per high-confidence run.
        pieces: usize,
    },
}

impl Default for Distribution {
    fn default() -> Self {
        Distribution::PerRun { pieces: 1 }
    }
}

/// How a candidate's offset `τ` is drawn, given its two warps.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum OffsetSampling {
    /// Uniform in `[0, |ψ_E1|]`; candidates whose low-confidence intervals overlap are
    /// rejected (the literal reading of §II-C).
    Uniform,
    /// Uniform over the offsets in `[0, |ψ_E1|]` at which the two robots' low-confidence
    /// intervals do not overlap (computed exactly from the intervals). This is the
    /// distribution of `Uniform` conditioned on passing constraint 3 — the same proposals,
    /// without the rejected ones.
    #[default]
    UniformFeasible,
}

/// Parameters of [`sample_schedule`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SamplerParams {
    /// Number of sampled candidates (§II-C: the paper uses 5000). ≥ 1. Default: 5000.
    pub samples: usize,
    /// Seed; candidate `k` uses ChaCha8 stream `k` of this seed. Default: 0.
    pub seed: u64,
    /// Control tick (s) of the margin check (Alg. 2). `None` = the reference period `Δt_s`.
    /// Must be finite and > 0. Default: `None`.
    pub tick_s: Option<f64>,
    /// Sampling distribution of the high-confidence gradients. Default: one factor per
    /// high-confidence run (`PerRun { pieces: 1 }`).
    pub distribution: Distribution,
    /// Probability that a factor is exactly 0 (the run at `ψ̇min`, fastest), in `[0, 1]`.
    /// Default: 0.5.
    pub p_fastest: f64,
    /// How `τ` is drawn. Default: [`OffsetSampling::UniformFeasible`].
    pub offset: OffsetSampling,
    /// Margin-check implementation. Default: [`MarginCheck::SinglePass`].
    pub margin_check: MarginCheck,
    /// `false` (default): margins only in `(T_total, k)` order until the first candidate
    /// passes. `true`: check every cheap-feasible candidate (the straightforward baseline; the
    /// same result, slower).
    pub exhaustive_margins: bool,
}

impl Default for SamplerParams {
    fn default() -> Self {
        SamplerParams {
            samples: 5000,
            seed: 0,
            tick_s: None,
            distribution: Distribution::default(),
            p_fastest: 0.5,
            offset: OffsetSampling::UniformFeasible,
            margin_check: MarginCheck::SinglePass,
            exhaustive_margins: false,
        }
    }
}

impl SamplerParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field.
    pub fn validate(&self) -> Result<()> {
        if self.samples == 0 {
            return Err(Error::BadParam {
                name: "samples",
                why: "must be ≥ 1",
            });
        }
        if let Some(t) = self.tick_s
            && !(t.is_finite() && t > 0.0)
        {
            return Err(Error::BadParam {
                name: "tick_s",
                why: "must be finite and > 0",
            });
        }
        if let Distribution::PerRun { pieces: 0 } = self.distribution {
            return Err(Error::BadParam {
                name: "distribution.pieces",
                why: "must be ≥ 1",
            });
        }
        if !(0.0..=1.0).contains(&self.p_fastest) {
            return Err(Error::BadParam {
                name: "p_fastest",
                why: "must be in [0, 1]",
            });
        }
        Ok(())
    }
}

/// Where the returned schedule came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Source {
    /// Sampled candidate number `candidate` (ChaCha8 stream of the seed).
    Sampled {
        /// Candidate index `k`.
        candidate: u64,
    },
    /// The previous schedule, unchanged (still valid, nothing better found).
    Previous,
    /// The previous schedule repaired for the new problem (gradients clamped into the new
    /// bounds, new mean on low-confidence samples, `τ` clamped to `[0, |ψ_E1|]`).
    RepairedPrevious,
    /// The fastest serial schedule ([`Problem::serial_schedule`]).
    Serial,
}

/// Counts of one sampler run (identical for a seed whatever the thread count).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SamplerStats {
    /// Candidates sampled.
    pub candidates: usize,
    /// Candidates that beat the incumbent's `T_total` with no low-confidence overlap.
    pub cheap_feasible: usize,
    /// Candidates whose full constraints (incl. margins) were decided in `(T_total, k)` order
    /// (the parallel loop may check up to a few more, whose results are discarded).
    pub margin_checks: usize,
}

/// The sampler's result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// The schedule; it passes [`crate::validate_with_tick`] at the sampler's tick.
    pub schedule: Schedule,
    /// Its `T_total` (Eq. 13), s.
    pub t_total_s: f64,
    /// Where it came from.
    pub source: Source,
    /// Counts.
    pub stats: SamplerStats,
}

/// One piece of the reference with a fixed duration (low confidence) or a speed factor.
#[derive(Clone, Copy, Debug)]
struct Piece {
    start: usize,
    end: usize,
    high_conf: bool,
    /// Duration (s) at `u = 0` (or the mean duration for low confidence).
    min_s: f64,
    /// Extra duration (s) at `u = 1`: `Σ (ψ̇max − ψ̇min)·Δt_s`.
    span_s: f64,
}

fn pieces(problem: &Problem, distribution: Distribution) -> Vec<Piece> {
    let dt = problem.dt_s();
    let (gmin, gmax, gmean) = (problem.grad_min(), problem.grad_max(), problem.grad_mean());
    let mut out = Vec::new();
    let mut push = |start: usize, end: usize, high_conf: bool| {
        let (min_s, span_s) = if high_conf {
            let lo: f64 = gmin[start..end].iter().sum();
            let hi: f64 = gmax[start..end].iter().sum();
            (lo * dt, (hi - lo) * dt)
        } else {
            (gmean[start..end].iter().sum::<f64>() * dt, 0.0)
        };
        out.push(Piece {
            start,
            end,
            high_conf,
            min_s,
            span_s,
        });
    };
    for run in problem.runs() {
        if !run.high_conf {
            push(run.start, run.end, false);
            continue;
        }
        let m = run.end - run.start;
        let n_pieces = match distribution {
            Distribution::PerSample => m,
            Distribution::PerRun { pieces } => pieces.min(m),
        };
        for j in 0..n_pieces {
            let a = run.start + m * j / n_pieces;
            let b = run.start + m * (j + 1) / n_pieces;
            push(a, b, true);
        }
    }
    out
}

/// Everything a worker needs to evaluate candidates.
struct Sampler<'a> {
    problem: &'a Problem,
    params: &'a SamplerParams,
    pieces: Vec<Piece>,
    tick_s: f64,
}

/// Per-worker scratch: factors and low-confidence intervals relative to each robot's start.
#[derive(Default)]
struct Scratch {
    factors: [Vec<f64>; 2],
    lc: [Vec<(f64, f64)>; 2],
    forbidden: Vec<(f64, f64)>,
}

/// A candidate's draws, with its factors left in the scratch.
struct Draw {
    /// `[|ψ_E1|, |ψ_E2|]` from the piece sums (s).
    dur: [f64; 2],
    /// `τ` (s); `None` when no admissible offset avoids a low-confidence overlap.
    offset_s: Option<f64>,
}

impl Sampler<'_> {
    fn rng(&self, k: u64) -> ChaCha8Rng {
        let mut rng = ChaCha8Rng::seed_from_u64(self.params.seed);
        rng.set_stream(k);
        rng
    }

    fn factor(&self, rng: &mut ChaCha8Rng) -> f64 {
        if rng.random_bool(self.params.p_fastest) {
            0.0
        } else {
            rng.random::<f64>()
        }
    }

    /// Draws candidate `k`: factors (into `scratch.factors`), durations and offset.
    fn draw(&self, scratch: &mut Scratch, k: u64) -> Draw {
        let mut rng = self.rng(k);
        let mut dur = [0.0; 2];
        for ((factors, lc), dur) in scratch
            .factors
            .iter_mut()
            .zip(scratch.lc.iter_mut())
            .zip(dur.iter_mut())
        {
            factors.clear();
            lc.clear();
            let mut t = 0.0;
            for p in &self.pieces {
                if p.high_conf {
                    let u = self.factor(&mut rng);
                    factors.push(u);
                    t += p.min_s + u * p.span_s;
                } else {
                    lc.push((t, t + p.min_s));
                    t += p.min_s;
                }
            }
            *dur = t;
        }
        let v = rng.random::<f64>();
        let offset_s = match self.params.offset {
            OffsetSampling::Uniform => {
                let offset_s = v * dur[0];
                (!overlaps(&scratch.lc, offset_s)).then_some(offset_s)
            }
            OffsetSampling::UniformFeasible => feasible_offset(scratch, dur[0], v),
        };
        Draw { dur, offset_s }
    }

    /// Cheap evaluation of candidate `k`: `Some(T_total)` if it beats `bound_s` and has no
    /// low-confidence overlap.
    fn cheap(&self, scratch: &mut Scratch, k: u64, bound_s: f64) -> Option<f64> {
        let d = self.draw(scratch, k);
        let t_total = d.dur[0].max(d.offset_s? + d.dur[1]);
        (t_total < bound_s).then_some(t_total)
    }

    /// The full schedule of candidate `k` (same draws as [`Sampler::cheap`]).
    fn materialize(&self, k: u64) -> Option<Schedule> {
        let mut scratch = Scratch::default();
        let d = self.draw(&mut scratch, k);
        let (gmin, gmax, gmean) = (
            self.problem.grad_min(),
            self.problem.grad_max(),
            self.problem.grad_mean(),
        );
        let n_ref = self.problem.n_ref();
        let mut warps = [Vec::with_capacity(n_ref), Vec::with_capacity(n_ref)];
        for (warp, factors) in warps.iter_mut().zip(&scratch.factors) {
            let mut factors = factors.iter();
            for p in &self.pieces {
                if p.high_conf {
                    let u = *factors.next().expect("one factor was drawn per HC piece");
                    warp.extend((p.start..p.end).map(|n| gmin[n] + u * (gmax[n] - gmin[n])));
                } else {
                    warp.extend_from_slice(&gmean[p.start..p.end]);
                }
            }
        }
        Some(Schedule {
            grad_exec: warps,
            offset_s: d.offset_s?,
        })
    }

    /// Full constraints of candidate `k`: the schedule and its `T_total` if feasible.
    fn full(&self, k: u64) -> Option<(Schedule, f64)> {
        let s = self.materialize(k)?;
        let ok = validate_cheap(self.problem, &s).is_ok()
            && matches!(
                margins_ok(self.problem, &s, self.tick_s, self.params.margin_check),
                Ok(true)
            );
        ok.then(|| {
            let t = s.t_total_s(self.problem.dt_s());
            (s, t)
        })
    }
}

/// Whether robot 2's low-confidence intervals shifted by `offset_s` overlap robot 1's
/// (positive-length intersection; both lists in time order).
fn overlaps(lc: &[Vec<(f64, f64)>; 2], offset_s: f64) -> bool {
    let (a, b) = (&lc[0], &lc[1]);
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let (b0, b1) = (b[j].0 + offset_s, b[j].1 + offset_s);
        if a[i].0.max(b0) < a[i].1.min(b1) {
            return true;
        }
        if a[i].1 <= b1 {
            i += 1;
        } else {
            j += 1;
        }
    }
    false
}

/// The point at fraction `v ∈ [0, 1)` of the measure of the admissible offsets:
/// `[0, max_s = |ψ_E1|]` without every open interval `(a_i − d_j, b_i − c_j)` that would make robot 1's interval
/// `[a_i, b_i)` and robot 2's `[c_j, d_j)` overlap. `None` if that set has measure zero.
fn feasible_offset(scratch: &mut Scratch, max_s: f64, v: f64) -> Option<f64> {
    let forbidden = &mut scratch.forbidden;
    forbidden.clear();
    for &(a, b) in &scratch.lc[0] {
        for &(c, d) in &scratch.lc[1] {
            let (lo, hi) = ((a - d).max(0.0), (b - c).min(max_s));
            if lo < hi {
                forbidden.push((lo, hi));
            }
        }
    }
    forbidden.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    // Merge in place, then walk the gaps.
    let mut merged = 0;
    for i in 0..forbidden.len() {
        let cur = forbidden[i];
        if merged > 0 && cur.0 <= forbidden[merged - 1].1 {
            forbidden[merged - 1].1 = forbidden[merged - 1].1.max(cur.1);
        } else {
            forbidden[merged] = cur;
            merged += 1;
        }
    }
    forbidden.truncate(merged);
    let blocked: f64 = forbidden.iter().map(|(lo, hi)| hi - lo).sum();
    let free = max_s - blocked;
    if free <= 1e-12 * max_s.max(1.0) {
        return None;
    }
    let mut target = v * free;
    let mut lo = 0.0;
    for &(f0, f1) in forbidden.iter() {
        let gap = f0 - lo;
        if target < gap {
            return Some(lo + target);
        }
        target -= gap;
        lo = f1;
    }
    Some((lo + target).min(max_s))
}

fn repair(problem: &Problem, previous: &Schedule) -> Option<Schedule> {
    let n_ref = problem.n_ref();
    if previous.grad_exec.iter().any(|g| g.len() != n_ref) {
        return None;
    }
    let warps = previous.grad_exec.each_ref().map(|g| {
        (0..n_ref)
            .map(|n| {
                if problem.conf()[n] {
                    let x = if g[n].is_finite() {
                        g[n]
                    } else {
                        problem.grad_mean()[n]
                    };
                    x.clamp(problem.grad_min()[n], problem.grad_max()[n])
                } else {
                    problem.grad_mean()[n]
                }
            })
            .collect::<Vec<f64>>()
    });
    let max_s = execution_s(&warps[0], problem.dt_s());
    let offset_s = if previous.offset_s.is_finite() {
        previous.offset_s.clamp(0.0, max_s)
    } else {
        max_s
    };
    Some(Schedule {
        grad_exec: warps,
        offset_s,
    })
}

/// The anytime sampler of §II-C (see the module docs for the distribution and the order of
/// evaluation): the least-`T_total` schedule among `params.samples` sampled candidates, the
/// previous schedule (kept on ties) and the fastest serial schedule that satisfies every
/// constraint of Eq. 20 at the control tick `params.tick_s`.
///
/// Runs on the current rayon thread pool; the result for a seed is the same whatever the
/// number of threads.
///
/// # Errors
/// [`Error::BadParam`] for invalid parameters; [`Error::NoFeasibleSchedule`] if not even the
/// serial schedule passes (which would mean the margin check rejects a schedule with no
/// concurrent execution at all).
pub fn sample_schedule(
    problem: &Problem,
    params: &SamplerParams,
    previous: Option<&Schedule>,
) -> Result<Outcome> {
    params.validate()?;
    let tick_s = params.tick_s.unwrap_or(problem.dt_s());
    let dt_s = problem.dt_s();

    // 1. Incumbent.
    let mut incumbent: Option<(Schedule, f64, Source)> = None;
    if let Some(prev) = previous {
        if validate_with_tick(problem, prev, tick_s).is_ok() {
            incumbent = Some((prev.clone(), prev.t_total_s(dt_s), Source::Previous));
        } else if let Some(fixed) = repair(problem, prev)
            && validate_with_tick(problem, &fixed, tick_s).is_ok()
        {
            let t = fixed.t_total_s(dt_s);
            incumbent = Some((fixed, t, Source::RepairedPrevious));
        }
    }
    let serial = problem.serial_schedule();
    let serial_t = serial.t_total_s(dt_s);
    let serial_violation = if incumbent.as_ref().is_none_or(|inc| serial_t < inc.1) {
        match validate_with_tick(problem, &serial, tick_s) {
            Ok(()) => {
                incumbent = Some((serial, serial_t, Source::Serial));
                None
            }
            Err(v) => Some(v),
        }
    } else {
        None
    };
    let bound_s = incumbent.as_ref().map_or(f64::INFINITY, |inc| inc.1);

    // 2. Cheap checks, in parallel; collect keeps candidate order.
    let pieces = pieces(problem, params.distribution);
    let sampler = Sampler {
        problem,
        params,
        pieces,
        tick_s,
    };
    let n = params.samples as u64;
    let mut feasible: Vec<(f64, u64)> = (0..n)
        .into_par_iter()
        .map_init(Scratch::default, |scratch, k| {
            sampler.cheap(scratch, k, bound_s).map(|t| (t, k))
        })
        .flatten_iter()
        .collect();
    feasible.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let cheap_feasible = feasible.len();

    // 3. Full constraints in (T_total, k) order.
    let mut winner: Option<(Schedule, f64, u64)> = None;
    let mut margin_checks = 0;
    if params.exhaustive_margins {
        let results: Vec<Option<(Schedule, f64)>> =
            feasible.par_iter().map(|&(_, k)| sampler.full(k)).collect();
        margin_checks = results.len();
        winner = results
            .into_iter()
            .zip(&feasible)
            .find_map(|(r, &(_, k))| r.map(|(s, t)| (s, t, k)));
    } else {
        let chunk = 2 * rayon::current_num_threads().max(1);
        for group in feasible.chunks(chunk) {
            let results: Vec<Option<(Schedule, f64)>> =
                group.par_iter().map(|&(_, k)| sampler.full(k)).collect();
            if let Some(pos) = results.iter().position(Option::is_some) {
                margin_checks += pos + 1;
                let (s, t) = results
                    .into_iter()
                    .nth(pos)
                    .flatten()
                    .expect("position() found Some at pos");
                winner = Some((s, t, group[pos].1));
                break;
            }
            margin_checks += group.len();
        }
    }

    let stats = SamplerStats {
        candidates: params.samples,
        cheap_feasible,
        margin_checks,
    };
    let chosen = match (winner, incumbent) {
        (Some((_, t, _)), Some(inc)) if t >= inc.1 => inc,
        (Some((s, t, k)), _) => (s, t, Source::Sampled { candidate: k }),
        (None, Some(inc)) => inc,
        (None, None) => {
            return Err(Error::NoFeasibleSchedule {
                serial: serial_violation.expect("the serial schedule was checked: no incumbent"),
            });
        }
    };
    Ok(Outcome {
        schedule: chosen.0,
        t_total_s: chosen.1,
        source: chosen.2,
        stats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(lc0: &[(f64, f64)], lc1: &[(f64, f64)]) -> Scratch {
        Scratch {
            lc: [lc0.to_vec(), lc1.to_vec()],
            ..Scratch::default()
        }
    }

    #[test]
    fn feasible_offset_by_hand() {
        // Robot 1 LC [1, 2), robot 2 LC [0, 1) after its start: τ ∈ (0, 2) overlaps, so the
        // admissible offsets in [0, 3] are {0} ∪ [2, 3], of measure 1.
        let mut s = scratch(&[(1.0, 2.0)], &[(0.0, 1.0)]);
        assert_eq!(feasible_offset(&mut s, 3.0, 0.0), Some(2.0));
        assert_eq!(feasible_offset(&mut s, 3.0, 0.5), Some(2.5));
        // Two forbidden stretches: robot 2 LC [0, 1) and [2, 3) against robot 1 LC [4, 5):
        // τ ∈ (3, 5) and (1, 3) → free [0, 1] ∪ [5, 6] within [0, 6].
        let mut s = scratch(&[(4.0, 5.0)], &[(0.0, 1.0), (2.0, 3.0)]);
        assert_eq!(feasible_offset(&mut s, 6.0, 0.25), Some(0.5));
        assert_eq!(feasible_offset(&mut s, 6.0, 0.75), Some(5.5));
        // Everything forbidden: one LC run covering each whole execution.
        let mut s = scratch(&[(0.0, 3.0)], &[(0.0, 3.0)]);
        assert_eq!(feasible_offset(&mut s, 3.0, 0.5), None);
    }

    #[test]
    fn overlap_test_by_hand() {
        let lc = [vec![(1.0, 2.0)], vec![(0.0, 1.0)]];
        assert!(overlaps(&lc, 0.5));
        assert!(!overlaps(&lc, 2.0)); // touching
        assert!(!overlaps(&lc, 0.0)); // touching
    }

    #[test]
    fn pieces_split_runs_evenly() {
        let p = Problem::new(
            vec![true; 5].into_iter().chain([false; 2]).collect(),
            vec![1.0; 7],
            vec![0.5; 7],
            vec![2.0; 7],
            0.1,
        )
        .unwrap();
        let ps = pieces(&p, Distribution::PerRun { pieces: 2 });
        let spans: Vec<(usize, usize, bool)> =
            ps.iter().map(|q| (q.start, q.end, q.high_conf)).collect();
        assert_eq!(spans, vec![(0, 2, true), (2, 5, true), (5, 7, false)]);
        // Durations: HC piece of 2 samples = 2·0.5·0.1 s at u = 0, + 2·1.5·0.1 s at u = 1.
        assert!((ps[0].min_s - 0.1).abs() < 1e-12 && (ps[0].span_s - 0.3).abs() < 1e-12);
        assert!((ps[2].min_s - 0.2).abs() < 1e-12 && ps[2].span_s == 0.0);
        assert_eq!(pieces(&p, Distribution::PerSample).len(), 6);
    }
}
