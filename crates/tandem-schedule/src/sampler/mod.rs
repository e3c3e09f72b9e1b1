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
//!
//! # Files
//!
//! `params.rs`: [`SamplerParams`], the benchmark-only [`SamplerBaselines`], [`DrawnOffset`]
//! and the counts [`SamplerStats`]. `pieces.rs`: the pieces of the reference and their
//! duration sums (the search heuristic). `candidate.rs`: drawing candidate `k` from its
//! stream, its cheap check and its materialized, fully checked schedule. `fit.rs`: the exact
//! sweep that fits robots 2..N to the earlier robots. `offsets.rs`: interval geometry of the
//! drawn-offset baselines (overlap, admissible offsets). This file: the types the files share
//! and [`run`], the evaluation order.

mod candidate;
mod fit;
mod offsets;
mod params;
mod pieces;

use rayon::prelude::*;
use tandem_realtime::LcInterval;

use params::OffsetSampling;
pub use params::{DrawnOffset, SamplerBaselines, SamplerParams, SamplerStats};
use pieces::Piece;

use crate::problem::Problem;
use crate::schedule::Schedule;
use crate::validate::MarginCheck;

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
    /// Whether the problem has usable hold points: a candidate the margins reject is tried
    /// again with release rules (`Problem::with_release_rules`).
    has_holds: bool,
    pieces: Vec<Piece>,
    /// `suffix_min_s[p]`: shortest duration (s) of pieces `p..` (`0` past the last).
    suffix_min_s: Vec<f64>,
    tick_s: f64,
    /// Warm start (fitted robot 2 only): robot 1's warp of the (repaired)
    /// previous schedule, with its low-confidence intervals and duration (s). Candidates
    /// `k ≥ samples` keep it and fit robot 2 with the widening `WARM_WIDEN[k − samples]`.
    warm: Option<Warm>,
    /// The room (s) a fitted robot keeps from an earlier robot's LC run for the operator's
    /// switch time `δ`, by candidate parity: even `k` `δ·max(1, max ψ̇̄/ψ̇min of an LC
    /// sample)` (the margin check charges each of a simulated switch's ticks a step of at
    /// least that rate), odd `k` `δ` (a robot started after the other left its run, whose
    /// switch the check counts in the steps of the samples around it); 0 without a switch
    /// time.
    switch_room_s: [f64; 2],
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
pub(super) mod tests {
    use super::*;

    /// Intervals `[a, b)` (s) as low-confidence intervals (their reference samples unused).
    pub(super) fn ivs(v: &[(f64, f64)]) -> Vec<LcInterval> {
        v.iter()
            .map(|&(start_s, end_s)| LcInterval {
                ref_start: 0,
                ref_end: 1,
                start_s,
                end_s,
            })
            .collect()
    }

    pub(super) fn scratch(lc0: &[(f64, f64)], lc1: &[(f64, f64)]) -> Scratch {
        Scratch {
            factors: vec![Vec::new(); 2],
            lc: vec![ivs(lc0), ivs(lc1)],
            ..Scratch::default()
        }
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
}
