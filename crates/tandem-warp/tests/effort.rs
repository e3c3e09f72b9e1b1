//! Property test: more search effort never makes the alignment materially worse (the
//! "effort never coarsens the search" decision in docs/decisions.md).
//!
//! With the former solver, raising `coarse_nodes` from 48 to 200 multiplied the final objective by
//! up to 23 and tripled the error against the true warp on the ground-truth benchmark
//! (`bench/peers/warp_truth.py`): the first pass could no longer follow moderate slopes. Here one
//! effort parameter at a time (more coarse nodes, more coarse candidates, more refinement
//! candidates, more refinements, a larger refinement radius) is raised on random task-like
//! signals with a known warp (minimum-jerk reaches between dwells, a binary channel, local
//! slow-downs, noise), and neither the final objective nor the distance to the true warp may
//! rise by more than a tolerance.
//!
//! Why a tolerance, and why in units of the noise: the search is a chain of local passes, and a
//! chain that searches more can end in another local optimum; an exact "never rises" would need
//! the more expensive search to re-run the cheaper one. The optima it ends in differ mostly by
//! sub-sample choices of where to interpolate the noise (linear interpolation halves the noise's
//! variance half-way between two query samples), worth a fraction of the loss the noise itself
//! contributes ([`NOISE_LOSS`]). Over 11 000 random cases the largest rises seen were about one
//! `NOISE_LOSS` and 1.3 query samples; the former solver fails this test within 500 cases
//! (docs/decisions.md, "tandem-warp: effort never hurts").

use proptest::prelude::*;
use tandem_warp::{SignalRef, Warp, WarpParams, align};

/// Largest rise, in query samples, of the mean distance to the true warp allowed when one
/// effort parameter is raised.
const ERROR_TOLERANCE: f64 = 2.0;

/// Noise amplitude of every sample: uniform in `±NOISE`.
const NOISE: f64 = 0.01;

/// The loss the noise alone contributes to the objective: `Σ_c E[(n₂ − n₁)²] = 3 · 2 NOISE² / 3`
/// (three channels, uniform noise on both signals, normalized time of length 1).
const NOISE_LOSS: f64 = 2.0 * NOISE * NOISE;

/// Largest rise of the final objective allowed when one effort parameter is raised, in units of
/// [`NOISE_LOSS`].
const OBJECTIVE_TOLERANCE: f64 = 2.0;

/// A reference and a query of one task, with their channel count.
#[derive(Clone, Debug)]
struct Pair {
    reference: Vec<f64>,
    query: Vec<f64>,
    n_channels: usize,
    truth: Vec<f64>,
    /// Whether each reference sample lies in a dwell.
    in_dwell: Vec<bool>,
}

/// One task of task time `u ∈ [0, 1]`: `reaches` minimum-jerk moves between waypoints (2
/// position channels), separated by dwells of equal length, and a binary channel that toggles
/// in the middle of the dwells flagged in `toggles`.
#[derive(Clone, Debug)]
struct Task {
    waypoints: Vec<[f64; 2]>,
    toggles: Vec<bool>,
    dwell: f64,
}

impl Task {
    /// Duration of one reach in task time (dwell, reach, dwell, …, reach, dwell).
    fn reach(&self) -> f64 {
        let k = self.waypoints.len() - 1;
        (1.0 - self.dwell * (k + 1) as f64) / k as f64
    }

    /// Whether task time `u` lies in a dwell (all channels flat: the warp is not identifiable).
    fn in_dwell(&self, u: f64) -> bool {
        let period = self.dwell + self.reach();
        u - (u / period).floor() * period < self.dwell
    }

    fn eval(&self, u: f64) -> [f64; 3] {
        let k = self.waypoints.len() - 1;
        let reach = self.reach();
        let mut pos = self.waypoints[0];
        let mut grip = 0.0;
        for i in 0..k {
            let start = self.dwell * (i + 1) as f64 + reach * i as f64;
            let tau = ((u - start) / reach).clamp(0.0, 1.0);
            let s = tau * tau * tau * (10.0 - 15.0 * tau + 6.0 * tau * tau);
            if u >= start {
                let (a, b) = (self.waypoints[i], self.waypoints[i + 1]);
                pos = [a[0] + (b[0] - a[0]) * s, a[1] + (b[1] - a[1]) * s];
            }
            if self.toggles[i] && u >= start - 0.5 * self.dwell {
                grip = 1.0 - grip;
            }
        }
        [pos[0], pos[1], grip]
    }
}

/// Task time at own normalized time `s` of one demonstration: a smooth speed change `a` plus a
/// local slow-down of depth `depth` (0.5 = half speed) around `centre`.
fn task_time(s: f64, a: f64, centre: f64, depth: f64) -> f64 {
    use std::f64::consts::PI;
    // ∫ speed, speed = 1 + a cos(2π s) − depth · bump(s − centre), normalized to end at 1
    let width = 0.05;
    let bump = |x: f64| {
        let y = ((x - centre) / width).clamp(-0.5, 0.5);
        width * (y + 0.5 + (2.0 * PI * y).sin() / (2.0 * PI))
    };
    let raw = |x: f64| x + a * (2.0 * PI * x).sin() / (2.0 * PI) - depth * bump(x);
    raw(s) / raw(1.0)
}

/// Mean `|ψ[n] − ψ_true[n]|` over the reference samples outside dwells, in query samples.
fn mean_error(w: &Warp, pair: &Pair) -> f64 {
    let errors: Vec<f64> = w
        .values()
        .iter()
        .zip(&pair.truth)
        .zip(&pair.in_dwell)
        .filter(|(_, dwell)| !**dwell)
        .map(|((a, b), _)| (a - b).abs())
        .collect();
    errors.iter().sum::<f64>() / errors.len() as f64
}

fn signals() -> impl Strategy<Value = Pair> {
    (
        (3usize..=5, 200usize..=500, 0.7f64..1.4, 0.03f64..0.1),
        prop::collection::vec((0.3f64..0.6, 0.0f64..6.3, any::<bool>()), 6),
        (-0.3f64..0.3, 0.1f64..0.9, 0.0f64..0.6),
        (-0.3f64..0.3, 0.1f64..0.9, 0.0f64..0.6),
        prop::collection::vec(-1.0f64..1.0, 3 * 700),
    )
        .prop_map(|((k, n_ref, ratio, dwell), points, r_map, q_map, noise)| {
            // each reach moves 0.3–0.6 in a random direction
            let mut waypoints = vec![[0.0, 0.0]];
            for p in points.iter().take(k) {
                let last = waypoints[waypoints.len() - 1];
                waypoints.push([last[0] + p.0 * p.1.cos(), last[1] + p.0 * p.1.sin()]);
            }
            let task = Task {
                waypoints,
                toggles: points.iter().take(k).map(|p| p.2).collect(),
                dwell,
            };
            let n_query = ((n_ref as f64) * ratio).round() as usize;
            let mut noise = noise.into_iter().cycle();
            let mut make = |n: usize, (a, centre, depth): (f64, f64, f64)| {
                let mut out = Vec::with_capacity(3 * n);
                for i in 0..n {
                    let u = task_time(i as f64 / (n - 1) as f64, a, centre, depth);
                    for v in task.eval(u) {
                        out.push(v + NOISE * noise.next().unwrap_or(0.0));
                    }
                }
                out
            };
            let u_ref =
                |n: usize| task_time(n as f64 / (n_ref - 1) as f64, r_map.0, r_map.1, r_map.2);
            let in_dwell = (0..n_ref).map(|n| task.in_dwell(u_ref(n))).collect();
            let truth = (0..n_ref)
                .map(|n| {
                    let u = u_ref(n);
                    let (mut lo, mut hi) = (0.0, 1.0);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        if task_time(mid, q_map.0, q_map.1, q_map.2) < u {
                            lo = mid
                        } else {
                            hi = mid
                        }
                    }
                    0.5 * (lo + hi) * (n_query - 1) as f64
                })
                .collect();
            Pair {
                reference: make(n_ref, r_map),
                query: make(n_query, q_map),
                n_channels: 3,
                truth,
                in_dwell,
            }
        })
}

/// A modest search effort and one way of raising it.
fn efforts() -> impl Strategy<Value = (WarpParams, WarpParams)> {
    (
        16usize..64,
        33usize..129,
        9usize..21,
        2usize..5,
        1.5f64..4.0,
        prop::option::of(2usize..6),
        0usize..5,
        1usize..40,
    )
        .prop_map(
            |(coarse, coarse_m, m, refinements, radius, max_jump, knob, more)| {
                let less = WarpParams {
                    coarse_nodes: coarse,
                    coarse_candidates: coarse_m,
                    n_candidates: m,
                    refinements,
                    refine_radius: radius,
                    max_jump,
                    ..WarpParams::default()
                };
                let mut plus = less.clone();
                match knob {
                    0 => plus.coarse_nodes += more,
                    1 => plus.coarse_candidates += 2 * more,
                    2 => plus.n_candidates += more,
                    3 => plus.refinements += 1 + more % 3,
                    _ => plus.refine_radius += 0.1 * more as f64,
                }
                (less, plus)
            },
        )
}

proptest! {
    // a fixed seed: CI runs the same 48 cases every time (PROPTEST_CASES=N runs more)
    #![proptest_config(ProptestConfig {
        rng_seed: proptest::test_runner::RngSeed::Fixed(14),
        ..ProptestConfig::with_cases(48)
    })]
    #[test]
    fn more_effort_never_makes_the_alignment_worse(pair in signals(), (less, more) in efforts()) {
        let nc = pair.n_channels;
        let r = SignalRef::new(&pair.reference, nc).unwrap();
        let q = SignalRef::new(&pair.query, nc).unwrap();
        let w_less = align(r, q, &less).unwrap();
        let w_more = align(r, q, &more).unwrap();
        let (e_less, e_more) = (mean_error(&w_less, &pair), mean_error(&w_more, &pair));
        prop_assert!(
            e_more <= e_less + ERROR_TOLERANCE,
            "more effort moved the warp away from the truth: mean error {} -> {} query samples",
            e_less, e_more
        );
        let (j_less, j_more) = (w_less.objective(), w_more.objective());
        prop_assert!(
            j_more <= j_less + OBJECTIVE_TOLERANCE * NOISE_LOSS,
            "more effort raised the objective from {} to {} ({:+.2} times the noise's own loss)",
            j_less, j_more, (j_more - j_less) / NOISE_LOSS
        );
    }
}
