//! The pieces of the reference (one per low-confidence run, [`SamplerParams::pieces`] per
//! high-confidence run) and their duration sums: the sampler's search heuristic.
//!
//! [`SamplerParams::pieces`]: super::SamplerParams::pieces

use tandem_realtime::LcInterval;

use super::params::Distribution;
use crate::problem::Problem;

/// One piece of the reference with a fixed duration (low confidence) or a speed factor.
#[derive(Clone, Copy, Debug)]
pub(super) struct Piece {
    pub(super) start: usize,
    pub(super) end: usize,
    pub(super) high_conf: bool,
    /// Duration (s) at `u = 0` (or the mean duration for low confidence).
    pub(super) min_s: f64,
    /// Extra duration (s) at `u = 1`: `Σ (ψ̇max − ψ̇min)·Δt_s`.
    pub(super) span_s: f64,
}

/// The pieces of `problem`'s reference for `distribution`, in reference order.
pub(super) fn pieces(problem: &Problem, distribution: Distribution) -> Vec<Piece> {
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

/// Low-confidence intervals (relative to the start) and duration (s) of one robot's warp, from
/// per-run sums: the sampler's search heuristic, like the piece sums (the schedule it returns
/// is timed by the one clock, `tandem_realtime::clock_s`).
pub(super) fn lc_of_warp(problem: &Problem, warp: &[f64]) -> (Vec<LcInterval>, f64) {
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

#[cfg(test)]
mod tests {
    use super::*;

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
