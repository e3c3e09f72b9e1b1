//! The anytime sampler of §II-C: sample offsets and high-confidence gradients, keep the
//! feasible candidate with the least `T_total`.
//!
//! # Sampling distribution
//!
//! Candidate `k` draws, from its own ChaCha8 stream `(seed, k)`:
//! 1. for robot 1 (and, unless robot 2 is fitted, robot 2), one *speed factor* `u ∈ [0, 1]`
//!    per piece of every maximal high-confidence run ([`SamplerParams::pieces`] per run;
//!    the baseline [`SamplerBaselines::per_sample`]: one per sample); the piece's
//!    gradients are `ψ̇_E[n] = ψ̇min[n] + u·(ψ̇max[n] − ψ̇min[n])`, and `u = 0` (fastest) with
//!    probability [`SamplerParams::p_fastest`], else `u` is uniform;
//! 2. the offset `τ`: by default only a widening `w ≤` [`SamplerParams::widen_max`] is
//!    drawn, and `τ` and robot 2's factors are *fitted* to robot 1's warp: an exact sweep
//!    over robot 2's pieces (see `Sampler::fit_second`) finds the earliest finish of robot 2
//!    whose low-confidence intervals keep `w·length + 2 ticks` clear of robot 1's. The
//!    baselines ([`SamplerBaselines::drawn_offset`]) draw `v` uniform in `[0, 1)` and put `τ`
//!    at fraction `v` of the offsets in `[0, |ψ_E1|]` (Eq. 20 constraint 2) that keep the two
//!    robots' low-confidence intervals apart ([`DrawnOffset::UniformFeasible`]) or of all of
//!    them ([`DrawnOffset::Uniform`]).
//!
//! The piece sums (and the per-run sums of the warm start) are the search's heuristic: they
//! order the candidates and cut those that cannot beat the incumbent. Every `T_total` the
//! sampler returns or compares for its final choice is read from the one clock
//! ([`Schedule::t_total_s`], `tandem_realtime::clock_s`) of the materialized schedule.
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
//! per-piece sums of `ψ̇min`, `ψ̇max` and `ψ̇̄`, without building the warp.
//!
//! Why fit robot 2: for two robots to alternate, each of robot 2's low-confidence passes
//! must land in a gap of robot 1's, which takes every one of robot 2's run durations and
//! `τ` to be right at once; independent draws almost never are. Given robot 1, the sweep
//! finds the best robot 2 exactly (up to the widening), so each candidate is a good one.
//! The widening `w` (uniform in `[0, widen_max]`) trades `T_total` for room that the
//! worst-case margin check (Alg. 2) needs; the candidates are checked in `T_total` order,
//! so the least widening that passes wins.
//!
//! The numbers that decided it (`cargo run --release -p tandem-schedule --example
//! sampling_distributions`: `fixtures/sanding/problem.csv` with passes 1–3 sanding low
//! confidence, `T_ref` 9873, serial `T_total` 145.75 s, 5000 samples, best `T_total` as
//! mean ± std over 20 seeds (4 for per sample), default margin budget, 2 cores; measured at
//! commit `6b0ffb6`, before the fixtures' warp defaults changed — the same command on the
//! current fixtures, with the same ranking, is in docs/decisions.md, "The sampler's
//! distributions"):
//!
//! | distribution                               | best `T_total` (s) | time per sample |
//! |--------------------------------------------|--------------------|-----------------|
//! | per sample, `τ` uniform                    | 145.75 (= serial)  | 123 µs          |
//! | per sample, `τ` uniform-feasible           | 145.75 (= serial)  | 124 µs          |
//! | per run, `τ` uniform                       | 116.71 ± 8.20      | 6.7 µs          |
//! | per run, `p_fastest` 0.25, `τ` uniform     | 114.72 ± 4.44      | 3.8 µs          |
//! | per run, `τ` uniform-feasible              | 108.82 ± 6.67      | 6.2 µs          |
//! | per run, `p_fastest` 0.25, feasible `τ`    | 109.76 ± 7.55      | 5.0 µs          |
//! | per run, `p_fastest` 0.5, feasible `τ`     | 111.96 ± 4.16      | 3.6 µs          |
//! | 2 pieces per run, 0.25, feasible `τ`       | 105.88 ± 5.99      | 6.4 µs          |
//! | 4 pieces per run, 0.25, feasible `τ`       | 109.96 ± 10.51     | 10.0 µs         |
//! | per run, 0.5, robot 2 fitted, `w` = 0      | 124.21 ± 0.00      | 23.7 µs         |
//! | **per run, 0.5, robot 2 fitted, `w` ≤ 0.1**| **94.38 ± 1.22**   | **4.8 µs**      |
//! | per run, 0.5, robot 2 fitted, `w` ≤ 0.3    | 95.73 ± 4.59       | 4.3 µs          |
//!
//! Per-sample candidates never beat the serial schedule. Fitting robot 2 with no widening
//! packs the regions so tightly that almost every candidate fails the margin check; a
//! little widening (the default `widen_max` 0.1) gives the best and steadiest result, 16 %
//! below the best sampled-offset setting. The default is one factor per run, exact zero
//! (fastest) with probability 0.5, robot 2 fitted with `w ≤ 0.1`.
//!
//! # Warm start
//!
//! With robot 2 fitted (the default) and a previous schedule, 8 more candidates
//! (`k = samples..samples + 8`) keep robot 1's warp of the (repaired) previous schedule and
//! fit robot 2 with widenings `w ∈ widen_max·{0, ¼, ½, ¾, 1, 1½, 2, 3}`: after a model
//! update moves the mean gradients, the previous schedule itself may no longer pass, but
//! its robot 1 usually still admits a good robot 2.
//!
//! # Evaluation order
//!
//! 1. The incumbent, chosen by the scheduler ([`crate::sample_schedule`], which owns the
//!    choice): the previous schedule if it is still valid (else its repair: gradients
//!    clamped into the new bounds, the new mean on low-confidence samples, `τ` clamped), or
//!    the fastest serial schedule if that is faster or there is no valid previous one. The
//!    sampler only sees its `T_total`, the bound its candidates must beat; the scheduler
//!    keeps the incumbent unless the sampler's winner or the margin-aware completion beside
//!    it is shorter.
//! 2. Cheap checks on all candidates in parallel: `T_total` below the incumbent's and no
//!    overlap of the two robots' low-confidence intervals (constraint 3).
//! 3. The survivors sorted by `(T_total, k)`; the full constraints (the margin check of
//!    Alg. 2 last) run in that order, a few candidates at a time in parallel, until the first
//!    passes. The winner is therefore the least `(T_total, k)` among the fully feasible
//!    candidates checked, whatever the number of threads. At most
//!    [`SamplerParams::max_margin_checks`] are checked (default 64: the best 32, then 32
//!    ranks spread geometrically down to the last): in the study, once the confidence is
//!    fragmented, thousands of candidates can beat the incumbent on paper and fail the
//!    margin check, at ~0.4 ms each (measured at commit `6b0ffb6`).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::choose::repair;
use crate::exact::SearchStats;
use crate::problem::Problem;
use tandem_realtime::{LcInterval, tol};

use crate::schedule::Schedule;
use crate::validate::{MarginCheck, validate_full};
use crate::{Error, ExactParams, Result};

/// Parameters of [`crate::sample_schedule`] (the sampler and, in [`SamplerParams::exact`], the
/// exact search and completion it runs beside): what a user tunes. They are stored in the
/// planner's state file and printed by `tandem params`; the benchmark-only alternatives
/// measured in the module docs are [`SamplerBaselines`], which are never stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SamplerParams {
    /// Number of sampled candidates (§II-C: the paper uses 5000). ≥ 1. Default: 5000.
    pub samples: usize,
    /// Seed; candidate `k` uses ChaCha8 stream `k` of this seed. Default: 0.
    pub seed: u64,
    /// Control tick (real s) of the margin check (Alg. 2), stored in the returned schedule
    /// ([`Schedule::tick_s`]) as the only period the coordinator may run it at. `None` = the
    /// reference period `Δt_s`. Must be finite and > 0. Default: `None`.
    pub tick_s: Option<f64>,
    /// Pieces per maximal high-confidence run, each with one speed factor (the run is cut
    /// into `pieces` stretches of nearly equal sample count; see the module docs). ≥ 1.
    /// Default: 1.
    pub pieces: usize,
    /// Probability that a factor is exactly 0 (the run at `ψ̇min`, fastest), in `[0, 1]`.
    /// Default: 0.5.
    pub p_fastest: f64,
    /// Largest relative widening `w` of robot 1's low-confidence intervals when robot 2 is
    /// fitted to robot 1: each interval `[a, b)` is widened to `[a − δ, b + δ)` with
    /// `δ = w·(b − a) + 2·tick_s`, `w` drawn uniformly in `[0, widen_max]` per candidate
    /// (room for the operator's drag and rush, which the margin check then verifies). Finite
    /// and ≥ 0. Default: 0.1.
    pub widen_max: f64,
    /// At most this many cheap-feasible candidates go through the full constraints: the
    /// best half of them in `(T_total, k)` order, the rest at geometrically spaced ranks
    /// down to the last; the first to pass wins, and if none does the incumbent stays. `None` = no
    /// limit. Once the confidence is fragmented into many short low-confidence runs, most
    /// candidates that beat a good incumbent fail the margin check, and checking them all
    /// costs up to ~0.5 s per re-schedule for nothing (see the module docs). ≥ 1.
    /// Default: `Some(64)`.
    pub max_margin_checks: Option<usize>,
    /// The exact margin-free search (the lower bound `T*₀` every returned schedule is
    /// certified against) and the margin-aware completion run beside the sampler as its
    /// second opinion. Default: `ExactParams::default()`.
    pub exact: ExactParams,
}

impl Default for SamplerParams {
    fn default() -> Self {
        SamplerParams {
            samples: 5000,
            seed: 0,
            tick_s: None,
            pieces: 1,
            p_fastest: 0.5,
            widen_max: 0.1,
            max_margin_checks: Some(64),
            exact: ExactParams::default(),
        }
    }
}

impl SamplerParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field.
    pub fn validate(&self) -> Result<()> {
        self.exact.validate()?;
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
        if self.pieces == 0 {
            return Err(Error::BadParam {
                name: "pieces",
                why: "must be ≥ 1",
            });
        }
        if self.max_margin_checks == Some(0) {
            return Err(Error::BadParam {
                name: "max_margin_checks",
                why: "must be ≥ 1 (or none for no limit)",
            });
        }
        if !(self.widen_max.is_finite() && self.widen_max >= 0.0) {
            return Err(Error::BadParam {
                name: "widen_max",
                why: "must be finite and ≥ 0",
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

/// Benchmark-only alternatives to the sampler's design, measured in the module docs' table
/// (`sampling_distributions` example) and in the `reschedule_5000` bench.
///
/// They are not part of [`SamplerParams`] and have no serde form: an experiment never
/// changes the user's state file or what `tandem params` prints. The default is the
/// sampler's own design with its second opinion (what [`crate::sample_schedule`] runs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SamplerBaselines {
    /// The sampler alone: no margin-aware completion beside it (the bound `T*₀` is still
    /// computed for the certificate). For measuring the sampler itself.
    pub sampler_only: bool,
    /// The margin-aware completion alone: no candidate is sampled (the fallbacks stay). For
    /// measuring the completion itself (the `certify` bench and example).
    pub completion_only: bool,
    /// One independent factor per high-confidence reference sample instead of per piece of
    /// a run (the literal reading of §II-C; [`SamplerParams::pieces`] is then ignored).
    pub per_sample: bool,
    /// Draw `τ` (and sample robot 2's factors like robot 1's) instead of fitting robot 2 to
    /// robot 1 (`None`, the default; [`SamplerParams::widen_max`] is then ignored).
    pub drawn_offset: Option<DrawnOffset>,
    /// Margin-check implementation. Default: [`MarginCheck::SinglePass`].
    pub margin_check: MarginCheck,
    /// `false` (default): margins only in `(T_total, k)` order until the first candidate
    /// passes. `true`: check every cheap-feasible candidate within the margin budget (the
    /// straightforward baseline; the same result, slower).
    pub exhaustive_margins: bool,
}

impl SamplerBaselines {
    /// The sampler alone, as designed ([`SamplerBaselines::sampler_only`]).
    pub const SAMPLER_ONLY: SamplerBaselines = SamplerBaselines {
        sampler_only: true,
        completion_only: false,
        per_sample: false,
        drawn_offset: None,
        margin_check: MarginCheck::SinglePass,
        exhaustive_margins: false,
    };

    /// The margin-aware completion alone ([`SamplerBaselines::completion_only`]).
    pub const COMPLETION_ONLY: SamplerBaselines = SamplerBaselines {
        sampler_only: false,
        completion_only: true,
        ..SamplerBaselines::SAMPLER_ONLY
    };
}

/// How a [`SamplerBaselines::drawn_offset`] candidate draws its offset `τ` from `v` uniform in
/// `[0, 1)`, given its two warps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawnOffset {
    /// Uniform in `[0, |ψ_E1|]`; candidates whose low-confidence intervals overlap are
    /// rejected (the literal reading of §II-C).
    Uniform,
    /// Uniform over the offsets in `[0, |ψ_E1|]` at which the two robots' low-confidence
    /// intervals do not overlap (computed exactly from the intervals): the distribution of
    /// `Uniform` conditioned on passing constraint 3.
    UniformFeasible,
}

/// How a candidate's high-confidence gradients are drawn (from params and baselines).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Distribution {
    /// One factor per high-confidence reference sample.
    PerSample,
    /// `pieces` factors per maximal high-confidence run.
    PerRun { pieces: usize },
}

/// How a candidate's offset (and robot 2) is chosen (from params and baselines).
#[derive(Clone, Copy, Debug, PartialEq)]
enum OffsetSampling {
    /// A drawn offset (a baseline).
    Drawn(DrawnOffset),
    /// Robot 2 fitted to robot 1 with widenings up to `widen_max`.
    Fitted { widen_max: f64 },
}

/// Counts of one scheduler run (identical for a seed whatever the thread count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SamplerStats {
    /// Candidates sampled.
    pub candidates: usize,
    /// Candidates that beat the incumbent's `T_total` with no low-confidence overlap.
    pub cheap_feasible: usize,
    /// Candidates whose full constraints (incl. margins) were decided in `(T_total, k)` order
    /// (the parallel loop may check up to a few more, whose results are discarded).
    pub margin_checks: usize,
    /// Margin checks (Alg. 2) the margin-aware completion ran ([`crate::ExactParams`]).
    pub completion_margin_checks: usize,
    /// Work counts of the exact search behind the bound.
    pub search: SearchStats,
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
    /// Number of robots `N` (2 unless the caller says otherwise; the drawn-offset baselines
    /// are for two robots only).
    n_robots: usize,
    /// How `τ` and robot 2 are chosen.
    offset: OffsetSampling,
    /// Margin-check implementation.
    margin_check: MarginCheck,
    pieces: Vec<Piece>,
    /// `suffix_min_s[p]`: shortest duration (s) of pieces `p..` (`0` past the last).
    suffix_min_s: Vec<f64>,
    tick_s: f64,
    /// Warm start (fitted robot 2 only): robot 1's warp of the (repaired)
    /// previous schedule, with its low-confidence intervals and duration (s). Candidates
    /// `k ≥ samples` keep it and fit robot 2 with the widening `WARM_WIDEN[k − samples]`.
    warm: Option<Warm>,
}

/// Robot 1 of the warm start: warp (gradients per reference sample), low-confidence
/// intervals relative to its start (s), duration (s).
struct Warm {
    warp: Vec<f64>,
    lc: Vec<LcInterval>,
    dur_s: f64,
}

/// Relative widenings `w / widen_max` of the warm-start candidates.
const WARM_WIDEN: [f64; 8] = [0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0];

/// Low-confidence intervals (relative to the start) and duration (s) of one robot's warp, from
/// per-run sums: the sampler's search heuristic, like the piece sums (the schedule it returns
/// is timed by the one clock, `tandem_realtime::clock_s`).
fn lc_of_warp(problem: &Problem, warp: &[f64]) -> (Vec<LcInterval>, f64) {
    let dt = problem.dt_s();
    let mut lc = Vec::new();
    let mut t = 0.0;
    for run in problem.runs() {
        let d = warp[run.start..run.end].iter().sum::<f64>() * dt;
        if !run.high_conf {
            lc.push(LcInterval {
                ref_start: run.start,
                ref_end: run.end,
                start_s: t,
                end_s: t + d,
            });
        }
        t += d;
    }
    (lc, t)
}

/// Per-worker scratch: per robot its factors and low-confidence intervals (robot 1 from its
/// start at 0; fitted robots in global time; a drawn-offset baseline's robot 2 relative to its
/// start), the fitted robots' offsets `τ_i` and every robot's duration (s).
#[derive(Default)]
struct Scratch {
    factors: Vec<Vec<f64>>,
    lc: Vec<Vec<LcInterval>>,
    offsets_s: Vec<f64>,
    durs_s: Vec<f64>,
    forbidden: Vec<(f64, f64)>,
    /// Fitted robot 2: feasible start sets of all pieces, flattened, and where each begins.
    sets: Vec<(f64, f64)>,
    set_starts: Vec<usize>,
}

impl Scratch {
    /// Room for `n_robots` robots' factors and intervals.
    fn for_robots(n_robots: usize) -> Scratch {
        Scratch {
            factors: vec![Vec::new(); n_robots],
            lc: vec![Vec::new(); n_robots],
            ..Scratch::default()
        }
    }
}

impl<'a> Sampler<'a> {
    /// The pieces, their suffix sums and, for fitted robot 2 with a previous
    /// schedule, the warm start (robot 1 of its repair).
    fn new(
        problem: &'a Problem,
        n_robots: usize,
        params: &'a SamplerParams,
        baselines: &SamplerBaselines,
        tick_s: f64,
        previous: Option<&Schedule>,
    ) -> Self {
        let distribution = if baselines.per_sample {
            Distribution::PerSample
        } else {
            Distribution::PerRun {
                pieces: params.pieces,
            }
        };
        let offset = match baselines.drawn_offset {
            Some(drawn) => OffsetSampling::Drawn(drawn),
            None => OffsetSampling::Fitted {
                widen_max: params.widen_max,
            },
        };
        let pieces = pieces(problem, distribution);
        let mut suffix_min_s = vec![0.0; pieces.len() + 1];
        for (p, piece) in pieces.iter().enumerate().rev() {
            suffix_min_s[p] = suffix_min_s[p + 1] + piece.min_s;
        }
        let warm = match (
            offset,
            previous
                .and_then(|prev| repair(problem, prev, tick_s))
                .and_then(|fixed| fixed.grad_exec.into_iter().next()),
        ) {
            (OffsetSampling::Fitted { .. }, Some(warp)) => {
                let (lc, dur_s) = lc_of_warp(problem, &warp);
                Some(Warm { warp, lc, dur_s })
            }
            _ => None,
        };
        Sampler {
            problem,
            params,
            n_robots,
            offset,
            margin_check: baselines.margin_check,
            pieces,
            suffix_min_s,
            tick_s,
            warm,
        }
    }
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

    /// Draws one robot's factors into `factors` and its low-confidence intervals (relative to
    /// its start, from the piece sums) into `lc`; returns its duration `|ψ_E|` (s).
    fn draw_robot(
        &self,
        rng: &mut ChaCha8Rng,
        factors: &mut Vec<f64>,
        lc: &mut Vec<LcInterval>,
    ) -> f64 {
        factors.clear();
        self.walk(0.0, lc, || {
            let u = self.factor(rng);
            factors.push(u);
            u
        })
    }

    /// One robot's pass over the pieces from `start_s` (s): each high-confidence piece takes
    /// the factor `next_factor()` (its duration `min_s + u·span_s`), each low-confidence piece
    /// its mean duration, pushed into `lc` (cleared first) as an interval; returns the end
    /// (s), from the piece sums.
    fn walk(
        &self,
        start_s: f64,
        lc: &mut Vec<LcInterval>,
        mut next_factor: impl FnMut() -> f64,
    ) -> f64 {
        lc.clear();
        let mut t = start_s;
        for p in &self.pieces {
            if p.high_conf {
                t += p.min_s + next_factor() * p.span_s;
            } else {
                lc.push(LcInterval {
                    ref_start: p.start,
                    ref_end: p.end,
                    start_s: t,
                    end_s: t + p.min_s,
                });
                t += p.min_s;
            }
        }
        t
    }

    /// Draws candidate `k`: factors (into `scratch.factors`), durations (into
    /// `scratch.durs_s`) and offsets (into `scratch.offsets_s`); returns its `T_total` (s,
    /// from the piece sums), or `None` when no admissible offset avoids a low-confidence
    /// overlap. With fitted robots, candidates whose robots cannot all finish before
    /// `bound_s` get `None` (the same draws otherwise, whatever `bound_s`).
    fn draw(&self, scratch: &mut Scratch, k: u64, bound_s: f64) -> Option<f64> {
        let mut rng = self.rng(k);
        scratch.offsets_s.clear();
        scratch.durs_s.clear();
        if let OffsetSampling::Fitted { widen_max } = self.offset {
            let (dur0, w) = match (&self.warm, k.checked_sub(self.params.samples as u64)) {
                (Some(warm), Some(j)) => {
                    scratch.factors[0].clear();
                    scratch.lc[0].clear();
                    scratch.lc[0].extend_from_slice(&warm.lc);
                    (warm.dur_s, widen_max * WARM_WIDEN[j as usize])
                }
                _ => {
                    let (f0, lc0) = (&mut scratch.factors[0], &mut scratch.lc[0]);
                    let dur0 = self.draw_robot(&mut rng, f0, lc0);
                    (dur0, rng.random::<f64>() * widen_max)
                }
            };
            // Robots 2..N in turn, each fitted against every earlier robot (the latest end
            // so far bounds its offset, Eq. 20 constraint 2); `T_total` is the latest end.
            scratch.durs_s.push(dur0);
            let mut t_total = dur0;
            for robot in 1..self.n_robots {
                let (offset_s, dur) = self.fit_next(scratch, robot, t_total, w, bound_s)?;
                scratch.offsets_s.push(offset_s);
                scratch.durs_s.push(dur);
                t_total = t_total.max(offset_s + dur);
                if robot + 1 < self.n_robots {
                    self.lc_of_factors(scratch, robot, offset_s);
                }
            }
            return Some(t_total);
        }
        let (f0, f1) = scratch.factors.split_at_mut(1);
        let (lc0, lc1) = scratch.lc.split_at_mut(1);
        let dur = [
            self.draw_robot(&mut rng, &mut f0[0], &mut lc0[0]),
            self.draw_robot(&mut rng, &mut f1[0], &mut lc1[0]),
        ];
        let v = rng.random::<f64>();
        let offset_s = match self.offset {
            OffsetSampling::Drawn(DrawnOffset::Uniform) => {
                let offset_s = v * dur[0];
                (!overlaps(&scratch.lc[0], &scratch.lc[1], offset_s)).then_some(offset_s)
            }
            OffsetSampling::Drawn(DrawnOffset::UniformFeasible) => {
                feasible_offset(scratch, dur[0], v)
            }
            OffsetSampling::Fitted { .. } => unreachable!("fitted candidates returned above"),
        }?;
        scratch.durs_s.extend(dur);
        scratch.offsets_s.push(offset_s);
        Some(dur[0].max(offset_s + dur[1]))
    }

    /// Writes robot `robot`'s low-confidence intervals in global time (it starts at
    /// `offset_s`) into `scratch.lc[robot]`, from its factors and the piece sums.
    fn lc_of_factors(&self, scratch: &mut Scratch, robot: usize, offset_s: f64) {
        let mut factors = scratch.factors[robot].iter();
        self.walk(offset_s, &mut scratch.lc[robot], || {
            factors.next().copied().unwrap_or(0.0)
        });
    }

    /// Fitted robot `robot` (≥ 1; robot 2 for two robots): its earliest finish given the
    /// low-confidence intervals of robots `0..robot` in `scratch.lc` (global time; robot 1
    /// starts at 0), each widened by `δ = w·length + 2·tick_s`, over `τ ∈ [0, latest_end_s]`
    /// (the latest end of the earlier robots, s; `|ψ_E1|` for robot 2) and the robot's
    /// per-piece durations. Writes its factors into `scratch.factors[robot]`; returns
    /// `(τ, |ψ_E|)`, or `None` when it cannot finish before `bound_s` clear of the earlier
    /// robots.
    ///
    /// The sweep keeps, for each piece, the set of its feasible start times as sorted
    /// disjoint intervals: a high-confidence piece of durations `[d_min, d_max]` maps `[x, y]`
    /// to `[x + d_min, y + d_max]`; a low-confidence piece of duration `L` keeps the starts
    /// `s` with `[s, s + L]` inside a gap between forbidden intervals, shifted by `L`. Starts
    /// from which even the fastest rest of robot 2 would end at or after `bound_s` are cut.
    /// The earliest end is then traced back, each high-confidence piece taking its shortest
    /// duration that still meets the start set before it (the fastest speeds: the most room
    /// for the coordinator to slow that robot down while the other is dragged).
    fn fit_next(
        &self,
        scratch: &mut Scratch,
        robot: usize,
        latest_end_s: f64,
        w: f64,
        bound_s: f64,
    ) -> Option<(f64, f64)> {
        let dur0 = latest_end_s;
        let margin = 2.0 * self.tick_s;
        let forbidden = &mut scratch.forbidden;
        forbidden.clear();
        forbidden.extend(scratch.lc[..robot].iter().flatten().map(|iv| {
            let d = w * (iv.end_s - iv.start_s) + margin;
            (iv.start_s - d, iv.end_s + d)
        }));
        sort_and_merge(forbidden);
        let forbidden = &scratch.forbidden;
        // Gap g lies between forbidden[g − 1] and forbidden[g] (unbounded at both ends).
        // Starts of a piece of length `len` inside gap g, `w·len` clear of both ends.
        let gap = |g: usize, len: f64| -> (f64, f64) {
            let pad = w * len;
            let lo = if g == 0 {
                f64::NEG_INFINITY
            } else {
                forbidden[g - 1].1 + pad
            };
            let hi = forbidden.get(g).map_or(f64::INFINITY, |f| f.0 - len - pad);
            (lo, hi)
        };

        let sets = &mut scratch.sets;
        let starts = &mut scratch.set_starts;
        sets.clear();
        starts.clear();
        let n_pieces = self.pieces.len();
        let hi0 = dur0.min(bound_s - self.suffix_min_s[0]);
        if hi0 < 0.0 {
            return None;
        }
        starts.push(0);
        sets.push((0.0, hi0));
        for (p, piece) in self.pieces.iter().enumerate() {
            let (from, to) = (starts[p], sets.len());
            let cap = bound_s - self.suffix_min_s[p + 1];
            starts.push(to);
            let push = |sets: &mut Vec<(f64, f64)>, lo: f64, hi: f64| {
                let hi = hi.min(cap);
                if lo > hi {
                    return;
                }
                let fresh = sets.len() == to;
                match sets.last_mut() {
                    Some(last) if !fresh && lo <= last.1 => last.1 = last.1.max(hi),
                    _ => sets.push((lo, hi)),
                }
            };
            if piece.high_conf {
                let (d_min, d_max) = (piece.min_s, piece.min_s + piece.span_s);
                for i in from..to {
                    let (x, y) = sets[i];
                    push(sets, x + d_min, y + d_max);
                }
            } else {
                let len = piece.min_s;
                let x_min = sets[from].0;
                let mut g = forbidden.partition_point(|f| f.0 - len - w * len < x_min);
                let mut i = from;
                while i < to && g <= forbidden.len() {
                    let (x, y) = sets[i];
                    let (glo, ghi) = gap(g, len);
                    let (lo, hi) = (x.max(glo), y.min(ghi));
                    if lo <= hi {
                        push(sets, lo + len, hi + len);
                    }
                    if y < ghi {
                        i += 1;
                    } else {
                        g += 1;
                    }
                }
            }
            if sets.len() == starts[p + 1] {
                return None;
            }
        }

        // Trace the earliest end back.
        let factors = &mut scratch.factors[robot];
        factors.clear();
        let mut e = sets[starts[n_pieces]].0;
        if e >= bound_s {
            return None;
        }
        for (p, piece) in self.pieces.iter().enumerate().rev() {
            if !piece.high_conf {
                e -= piece.min_s;
                continue;
            }
            let set = &sets[starts[p]..starts[p + 1]];
            let (d_min, d_max) = (piece.min_s, piece.min_s + piece.span_s);
            let latest = e - d_min;
            let idx = set.partition_point(|iv| iv.0 <= latest).max(1) - 1;
            let s = set[idx].1.min(latest).max(e - d_max);
            let u = if piece.span_s > 0.0 {
                ((e - s - d_min) / piece.span_s).clamp(0.0, 1.0)
            } else {
                0.0
            };
            factors.push(u);
            e = s;
        }
        factors.reverse();
        let tau = e.clamp(0.0, dur0);
        let mut dur1 = 0.0;
        let mut f = factors.iter();
        for p in &self.pieces {
            dur1 += if p.high_conf {
                p.min_s + f.next().copied().unwrap_or(0.0) * p.span_s
            } else {
                p.min_s
            };
        }
        Some((tau, dur1))
    }

    /// Cheap evaluation of candidate `k`: `Some(T_total)` if it beats `bound_s` and has no
    /// low-confidence overlap.
    fn cheap(&self, scratch: &mut Scratch, k: u64, bound_s: f64) -> Option<f64> {
        let t_total = self.draw(scratch, k, bound_s)?;
        (t_total < bound_s).then_some(t_total)
    }

    /// The full schedule of candidate `k` (same draws as [`Sampler::cheap`]).
    fn materialize(&self, k: u64) -> Option<Schedule> {
        let mut scratch = Scratch::for_robots(self.n_robots);
        self.draw(&mut scratch, k, f64::INFINITY)?;
        let (gmin, gmax, gmean) = (
            self.problem.grad_min(),
            self.problem.grad_max(),
            self.problem.grad_mean(),
        );
        let n_ref = self.problem.n_ref();
        let mut warps = vec![Vec::with_capacity(n_ref); self.n_robots];
        for (robot, (warp, factors)) in warps.iter_mut().zip(&scratch.factors).enumerate() {
            if robot == 0
                && k >= self.params.samples as u64
                && let Some(warm) = &self.warm
            {
                warp.extend_from_slice(&warm.warp);
                continue;
            }
            let mut factors = factors.iter();
            for p in &self.pieces {
                if p.high_conf {
                    let u = *factors.next().expect("one factor was drawn per HC piece");
                    // `ψ̇min + u·(ψ̇max − ψ̇min)` can round one ulp above `ψ̇max` at `u = 1`:
                    // capped, so every stored gradient meets constraint 1 exactly.
                    warp.extend(
                        (p.start..p.end).map(|n| (gmin[n] + u * (gmax[n] - gmin[n])).min(gmax[n])),
                    );
                } else {
                    warp.extend_from_slice(&gmean[p.start..p.end]);
                }
            }
        }
        Some(Schedule {
            grad_exec: warps,
            offsets_s: scratch.offsets_s,
            tick_s: self.tick_s,
        })
    }

    /// Full constraints of candidate `k`: the schedule and its `T_total` if feasible.
    fn full(&self, k: u64) -> Option<(Schedule, f64)> {
        let s = self.materialize(k)?;
        let ok = validate_full(self.problem, &s, self.margin_check).is_ok();
        ok.then(|| {
            let t = s.t_total_s(self.problem.dt_s());
            (s, t)
        })
    }
}

/// Whether robot 2's low-confidence intervals `b` shifted by `offset_s` overlap robot 1's `a`
/// (positive-length intersection; both lists in time order).
fn overlaps(a: &[LcInterval], b: &[LcInterval], offset_s: f64) -> bool {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let bj = b[j].shifted(offset_s);
        if a[i].overlap_s(&bj) > 0.0 {
            return true;
        }
        if a[i].end_s <= bj.end_s {
            i += 1;
        } else {
            j += 1;
        }
    }
    false
}

/// Sorts intervals `(lo, hi)` by start and merges, in place, those that overlap or touch.
fn sort_and_merge(intervals: &mut Vec<(f64, f64)>) {
    intervals.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let mut merged = 0;
    for i in 0..intervals.len() {
        let cur = intervals[i];
        if merged > 0 && cur.0 <= intervals[merged - 1].1 {
            intervals[merged - 1].1 = intervals[merged - 1].1.max(cur.1);
        } else {
            intervals[merged] = cur;
            merged += 1;
        }
    }
    intervals.truncate(merged);
}

/// The point at fraction `v ∈ [0, 1)` of the measure of the admissible offsets:
/// `[0, max_s = |ψ_E1|]` without every open interval `(a_i − d_j, b_i − c_j)` that would make robot 1's interval
/// `[a_i, b_i)` and robot 2's `[c_j, d_j)` overlap. `None` if that set has measure zero.
fn feasible_offset(scratch: &mut Scratch, max_s: f64, v: f64) -> Option<f64> {
    let forbidden = &mut scratch.forbidden;
    forbidden.clear();
    for &LcInterval {
        start_s: a,
        end_s: b,
        ..
    } in &scratch.lc[0]
    {
        for &LcInterval {
            start_s: c,
            end_s: d,
            ..
        } in &scratch.lc[1]
        {
            let (lo, hi) = ((a - d).max(0.0), (b - c).min(max_s));
            if lo < hi {
                forbidden.push((lo, hi));
            }
        }
    }
    // Merge, then walk the gaps.
    sort_and_merge(forbidden);
    let blocked: f64 = forbidden.iter().map(|(lo, hi)| hi - lo).sum();
    let free = max_s - blocked;
    if free <= tol::MEASURE_ZERO_REL * max_s.max(1.0) {
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

/// Which ranks (in `(T_total, k)` order) of `len` cheap-feasible candidates get the full
/// check when at most `cap` may: all if `len ≤ cap`; else the best `cap / 2`, then
/// `cap − cap / 2` ranks spread geometrically over the rest up to the last, so a run of
/// failing aggressive candidates at the top cannot hide the good, more cautious ones
/// further down. Ascending, distinct.
fn margin_ranks(len: usize, cap: usize) -> Vec<usize> {
    if len <= cap {
        return (0..len).collect();
    }
    let head = cap / 2;
    let tail = cap - head;
    let mut ranks: Vec<usize> = (0..head).collect();
    let span = (len - head) as f64;
    for j in 1..=tail {
        let r = head - 1 + span.powf(j as f64 / tail as f64).round() as usize;
        let r = r.min(len - 1);
        if ranks.last().is_none_or(|&last| r > last) {
            ranks.push(r);
        }
    }
    ranks
}

/// The sampler's winner (§II-C): the least `(T_total, k)` among the `params.samples` sampled
/// candidates (plus the warm-start ones, robot 1 of `previous` repaired) that beat `bound_s`
/// (s, the incumbent's `T_total`) and pass every constraint of Eq. 20 at `tick_s`, with at
/// most `params.max_margin_checks` full checks (see the module docs); and its counts.
///
/// Runs on the current rayon thread pool; the result for a seed is the same whatever the
/// number of threads.
pub(crate) fn run(
    problem: &Problem,
    n_robots: usize,
    params: &SamplerParams,
    baselines: &SamplerBaselines,
    tick_s: f64,
    previous: Option<&Schedule>,
    bound_s: f64,
) -> (Option<Winner>, SamplerStats) {
    let sampler = Sampler::new(problem, n_robots, params, baselines, tick_s, previous);
    let n_warm = if sampler.warm.is_some() {
        WARM_WIDEN.len()
    } else {
        0
    };
    let n = (params.samples + n_warm) as u64;
    let mut feasible: Vec<(f64, u64)> = (0..n)
        .into_par_iter()
        .map_init(
            || Scratch::for_robots(n_robots),
            |scratch, k| sampler.cheap(scratch, k, bound_s).map(|t| (t, k)),
        )
        .flatten_iter()
        .collect();
    feasible.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let cheap_feasible = feasible.len();
    // Full constraints in (T_total, k) order.
    if let Some(max) = params.max_margin_checks {
        feasible = margin_ranks(feasible.len(), max)
            .into_iter()
            .map(|r| feasible[r])
            .collect();
    }
    let mut winner: Option<Winner> = None;
    let mut margin_checks = 0;
    if baselines.exhaustive_margins {
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
        ..SamplerStats::default()
    };
    (winner, stats)
}

/// A sampled schedule that passed every constraint: schedule, `T_total` (s), candidate `k`.
pub(crate) type Winner = (Schedule, f64, u64);

#[cfg(test)]
mod tests {
    use super::*;

    /// Intervals `[a, b)` (s) as low-confidence intervals (their reference samples unused).
    fn ivs(v: &[(f64, f64)]) -> Vec<LcInterval> {
        v.iter()
            .map(|&(start_s, end_s)| LcInterval {
                ref_start: 0,
                ref_end: 1,
                start_s,
                end_s,
            })
            .collect()
    }

    fn scratch(lc0: &[(f64, f64)], lc1: &[(f64, f64)]) -> Scratch {
        Scratch {
            factors: vec![Vec::new(); 2],
            lc: vec![ivs(lc0), ivs(lc1)],
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

    /// [LC ×10, HC ×20, LC ×10] at 0.1 s per sample, gradients 1 in [0.5, 2]: pieces LC
    /// 1 s, HC 1–4 s, LC 1 s.
    fn three_runs() -> Problem {
        let conf: Vec<bool> = (0..40).map(|n| (10..30).contains(&n)).collect();
        Problem::new(conf, vec![1.0; 40], vec![0.5; 40], vec![2.0; 40], 0.1).unwrap()
    }

    #[test]
    fn fitted_robot_2_by_hand() {
        let p = three_runs();
        let params = SamplerParams::default();
        let sampler = Sampler::new(&p, 2, &params, &SamplerBaselines::default(), 0.1, None);
        // Robot 1 runs its HC piece at the slowest (4 s): LC [0, 1) and [5, 6), 6 s long.
        let mut s = scratch(&[(0.0, 1.0), (5.0, 6.0)], &[]);
        // w = 0: forbidden [−0.2, 1.2] and [4.8, 6.2] (two ticks of 0.1 s). Robot 2's first
        // LC starts in [1.2, 3.8] and ends in [2.2, 4.8]; its HC piece (1–4 s) reaches
        // [3.2, 8.8]; its last LC must start in [3.2, 3.8] or from 6.2: earliest end 4.2,
        // traced back with the HC piece at its shortest (u = 0) and τ = 1.2.
        let (tau, dur) = sampler
            .fit_next(&mut s, 1, 6.0, 0.0, f64::INFINITY)
            .unwrap();
        assert!(
            (tau - 1.2).abs() < 1e-9 && (dur - 3.0).abs() < 1e-9,
            "{tau} {dur}"
        );
        assert_eq!(s.factors[1], [0.0]);
        // w = 0.1: robot 1's regions grow by 0.1·1 + 0.2 s and robot 2's LC keeps 0.1 s
        // clear: starts [1.4, 3.6] → earliest end 4.4 with τ = 1.4.
        let (tau, dur) = sampler
            .fit_next(&mut s, 1, 6.0, 0.1, f64::INFINITY)
            .unwrap();
        assert!(
            (tau - 1.4).abs() < 1e-9 && (dur - 3.0).abs() < 1e-9,
            "{tau} {dur}"
        );
        // An incumbent of 4 s cuts every start: robot 2 needs 3 s and cannot start before 1.2.
        assert_eq!(sampler.fit_next(&mut s, 1, 6.0, 0.0, 4.0), None);
        // Robot 1 at its fastest (LC [0, 1) and [2, 3)): no gap holds a 1 s region before
        // τ's upper end |ψ_E1| = 3 s, so robot 2 cannot be fitted.
        let mut s = scratch(&[(0.0, 1.0), (2.0, 3.0)], &[]);
        assert_eq!(sampler.fit_next(&mut s, 1, 3.0, 0.0, f64::INFINITY), None);
    }

    #[test]
    fn margin_ranks_keep_the_best_then_spread_geometrically() {
        assert_eq!(margin_ranks(10, 64), (0..10).collect::<Vec<_>>());
        // Head 0..4, then 3 + 996^(j/4) rounded: 9, 35, 180, 999.
        assert_eq!(margin_ranks(1000, 8), [0, 1, 2, 3, 9, 35, 180, 999]);
        let r = margin_ranks(5000, 64);
        assert!(r.len() <= 64 && r.windows(2).all(|w| w[0] < w[1]));
        assert_eq!((r[31], r[32], *r.last().unwrap()), (31, 32, 4999));
    }

    #[test]
    fn overlap_test_by_hand() {
        let (a, b) = (ivs(&[(1.0, 2.0)]), ivs(&[(0.0, 1.0)]));
        assert!(overlaps(&a, &b, 0.5));
        assert!(!overlaps(&a, &b, 2.0)); // touching
        assert!(!overlaps(&a, &b, 0.0)); // touching
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
