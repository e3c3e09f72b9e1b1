//! The known pitfalls of GDTW implementations, as tests.
//!
//! An independent implementation of Deriso & Boyd's GDTW (the Julia port in
//! `DynamicAxisWarping.jl`) had to fix three of them after its first release:
//! 1. the instantaneous-slope penalty must measure the slope against 1 (`(φ' − 1)²`, the paper's
//!    Eq. 3), not against 0;
//! 2. the loss and regularizer sums need their Riemann-sum prefactor (the time step), or the
//!    objective grows with the number of samples and the balance between loss and regularizers
//!    (and so the warp) depends on the sampling rate;
//! 3. the feasible band computed from the slope bounds must not exclude valid paths by rounding,
//!    or changing the number of grid points by one can change the answer by orders of magnitude.
//!
//! Each test states the property in the crate's terms and is sensitive to the pitfall: it
//! derives the number by hand, or shows that the quantity it holds fixed does move when the
//! parameter the pitfall would leak does.
//!
//! The pitfalls are of the objective and its discretization, so every test here aligns the
//! signals as given and returns the objective's minimizer ([`PLAIN`]): the default smoothing
//! ([`WarpParams::smooth_width`]) is over a number of *samples*, like the default node spacing,
//! so it changes the signals themselves with the sampling rate, which these tests hold fixed;
//! and the fill of flat stretches ([`WarpParams::fill_length`]) replaces the minimizer where no
//! channel identifies it.

use tandem_warp::{SignalRef, Warp, WarpParams, align, objective_of};

/// The defaults without smoothing and without the fill of flat stretches (checked against
/// [`WarpParams::default`] below).
const PLAIN: WarpParams = WarpParams {
    n_nodes: None,
    n_candidates: 15,
    lambda_inst: 0.005,
    lambda_cum: 0.001,
    slope_min: 0.25,
    slope_max: 4.0,
    refinements: 4,
    refine_radius: 2.5,
    max_jump: Some(3),
    coarse_nodes: 48,
    coarse_candidates: 97,
    weights: None,
    smooth_width: 1,
    fill_length: 0.0,
};

/// A smooth 2-channel signal of task time `u ∈ [0, 1]`.
fn shape(u: f64) -> [f64; 2] {
    use std::f64::consts::PI;
    [
        (2.0 * PI * 2.0 * u).sin() + 0.3 * (2.0 * PI * 5.0 * u).cos(),
        (2.0 * PI * 3.0 * u + 0.4).cos() * (0.5 + u),
    ]
}

/// The true warp in normalized time: slopes in about [0.55, 1.45].
fn phi(t: f64) -> f64 {
    use std::f64::consts::PI;
    t + 0.07 * (2.0 * PI * t).sin()
}

fn phi_inv(tau: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if phi(mid) < tau { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// `shape` sampled at `n` samples of the reference's time (`shape(u)`) or the query's
/// (`shape(φ⁻¹(s))`, so that `query(φ(t)) = reference(t)`).
fn sampled(n: usize, query: bool) -> Vec<f64> {
    (0..n)
        .flat_map(|i| {
            let s = i as f64 / (n - 1) as f64;
            shape(if query { phi_inv(s) } else { s })
        })
        .collect()
}

fn align2(r: &[f64], q: &[f64], p: &WarpParams) -> Warp {
    align(
        SignalRef::new(r, 2).unwrap(),
        SignalRef::new(q, 2).unwrap(),
        p,
    )
    .unwrap()
}

/// The warp in normalized time `φ(t) = ψ(t (T_ref − 1)) / (T_query − 1)` at `t`.
fn normalized(w: &Warp, n_query: usize, t: f64) -> f64 {
    w.eval(t * (w.n_ref() - 1) as f64) / (n_query - 1) as f64
}

/// Largest `|φ_a(t) − φ_b(t)|` over 1001 times, in normalized time.
fn distance(a: (&Warp, usize), b: (&Warp, usize)) -> f64 {
    (0..=1000)
        .map(|i| {
            let t = f64::from(i) / 1000.0;
            (normalized(a.0, a.1, t) - normalized(b.0, b.1, t)).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_slope_penalty_is_measured_against_slope_one() {
    // Loss-free signals (constant), so only the regularizers count. The identity costs nothing:
    // measured against 0 it would cost λ_inst.
    let flat = vec![0.5; 2 * 5];
    let s = SignalRef::new(&flat, 2).unwrap();
    let identity = [0.0, 1.0, 2.0, 3.0, 4.0];
    let p = |li: f64, lc: f64| WarpParams {
        lambda_inst: li,
        lambda_cum: lc,
        ..PLAIN
    };
    assert_eq!(objective_of(s, s, &identity, &p(1.0, 1.0)).unwrap(), 0.0);
    // slope 2 on [0, ½], then 0: ∫(φ' − 1)² = ½·1 + ½·1 = 1 and
    // ∫(φ − t)² = ∫₀^½ t² dt + ∫_½^1 (1 − t)² dt = 1/24 + 1/24 = 1/12
    let kink = [0.0, 2.0, 4.0, 4.0, 4.0];
    let inst = objective_of(s, s, &kink, &p(1.0, 0.0)).unwrap();
    let cum = objective_of(s, s, &kink, &p(0.0, 1.0)).unwrap();
    assert!((inst - 1.0).abs() < 1e-12, "∫(φ' − 1)² = {inst}");
    assert!((cum - 1.0 / 12.0).abs() < 1e-12, "∫(φ − t)² = {cum}");
    // align() reports the same convention: on flat signals the optimum is the identity, at
    // objective 0, whatever λ_inst and the lengths
    for (n_ref, n_query) in [(5, 5), (40, 61), (61, 40)] {
        let (r, q) = (vec![0.5; 2 * n_ref], vec![0.5; 2 * n_query]);
        let w = align2(&r, &q, &p(0.3, 0.0));
        assert!(w.objective().abs() < 1e-12, "objective {}", w.objective());
        for (n, v) in w.values().iter().enumerate() {
            let t = n as f64 / (n_ref - 1) as f64;
            assert!((v - t * (n_query - 1) as f64).abs() < 1e-9, "ψ[{n}] = {v}");
        }
    }
}

#[test]
fn the_objective_is_an_integral_not_a_sum() {
    // The same continuous pair sampled at 300, 600 and 1200 reference samples (and the query
    // at 1.3 times that): the objective of the true warp is an integral and must not grow with
    // the sample count (without the time step's prefactor it would double at every step).
    let params = WarpParams {
        lambda_inst: 0.05,
        lambda_cum: 0.01,
        ..PLAIN
    };
    let mut objectives = Vec::new();
    for n_ref in [300, 600, 1200] {
        let n_query = n_ref * 13 / 10;
        let (r, q) = (sampled(n_ref, false), sampled(n_query, true));
        let truth: Vec<f64> = (0..n_ref)
            .map(|n| phi(n as f64 / (n_ref - 1) as f64) * (n_query - 1) as f64)
            .collect();
        let (rs, qs) = (
            SignalRef::new(&r, 2).unwrap(),
            SignalRef::new(&q, 2).unwrap(),
        );
        objectives.push(objective_of(rs, qs, &truth, &params).unwrap());
    }
    // the true warp's loss is only interpolation error; the regularizers are the same integrals
    let exact_inst = {
        // ∫(φ' − 1)² = ∫ (0.14π cos 2πt)² dt = (0.14π)²/2
        let a = 0.14 * std::f64::consts::PI;
        0.05 * a * a / 2.0
    };
    for j in &objectives {
        assert!((j / objectives[2] - 1.0).abs() < 0.01, "{objectives:?}");
        assert!(*j >= exact_inst, "{j} < λ_inst ∫(φ' − 1)² = {exact_inst}");
    }
}

#[test]
fn the_warp_does_not_depend_on_the_sampling_rate() {
    // Aligning the same continuous pair sampled at 400 or 800 reference samples gives the same
    // warp in normalized time, within the discretization error; and the test is sensitive: a
    // strong regularizer keeps the warp well away from the truth (by 0.07 of the duration), so
    // scaling the loss (as a missing prefactor would) moves the warp by much more.
    let base = WarpParams {
        lambda_inst: 20.0,
        lambda_cum: 0.05,
        ..PLAIN
    };
    let run = |n_ref: usize, p: &WarpParams| {
        let n_query = n_ref * 5 / 4;
        let w = align2(&sampled(n_ref, false), &sampled(n_query, true), p);
        (w, n_query)
    };
    let (a, b) = (run(400, &base), run(800, &base));
    let tol = 1.6 / 400.0; // 1.6 reference samples of the coarser grid
    let moved = distance((&a.0, a.1), (&b.0, b.1));
    assert!(
        moved < tol,
        "φ moves by {moved} between 400 and 800 samples"
    );
    // relative objective change: the two discretizations of one integral
    let rel = (a.0.objective() / b.0.objective() - 1.0).abs();
    assert!(
        rel < 0.02,
        "objectives {} vs {}",
        a.0.objective(),
        b.0.objective()
    );
    // doubling the loss weight (what a loss summed without its step does when the sample count
    // doubles) gives a visibly different warp
    let doubled = WarpParams {
        weights: Some(vec![2.0, 2.0]),
        ..base
    };
    let c = run(400, &doubled);
    let shift = distance((&a.0, a.1), (&c.0, c.1));
    assert!(shift > 3.0 * tol, "the loss weight moves φ only by {shift}");
}

/// The upper edge of the feasible band: slope `s_max` from `(0, 0)`, then `s_min` into `(1, 1)`.
fn corner(t: f64, s_min: f64, s_max: f64) -> f64 {
    (s_max * t).min(1.0 - s_min * (1.0 - t))
}

#[test]
fn a_warp_on_the_edge_of_the_slope_band_stays_feasible() {
    // The true warp runs along the upper edge of the feasible band: slope s_max = 2 until
    // t = 1/3, then s_min = 1/2. Rounding in the band's bounds or in the slope checks would
    // exclude it at some grid sizes and the result would jump; across reference lengths and
    // node counts that differ by one, the warp must stay within a sample of the truth.
    let (s_min, s_max) = (0.5, 2.0);
    let shape_at = |u: f64| [(9.0 * u).sin(), (5.0 * u).cos() + u];
    for n_ref in [299, 300, 301] {
        for n_query in [240, 241] {
            let r: Vec<f64> = (0..n_ref)
                .flat_map(|n| {
                    let t = n as f64 / (n_ref - 1) as f64;
                    shape_at(corner(t, s_min, s_max))
                })
                .collect();
            let q: Vec<f64> = (0..n_query)
                .flat_map(|m| shape_at(m as f64 / (n_query - 1) as f64))
                .collect();
            for n_nodes in [None, Some(100), Some(101), Some(n_ref)] {
                let p = WarpParams {
                    slope_min: s_min,
                    slope_max: s_max,
                    lambda_inst: 0.0,
                    lambda_cum: 0.0,
                    n_nodes,
                    ..PLAIN
                };
                let w = align2(&r, &q, &p);
                let worst = w
                    .values()
                    .iter()
                    .enumerate()
                    .map(|(n, v)| {
                        let t = n as f64 / (n_ref - 1) as f64;
                        (v - corner(t, s_min, s_max) * (n_query - 1) as f64).abs()
                    })
                    .fold(0.0, f64::max);
                assert!(
                    worst < 1.0,
                    "{n_ref} -> {n_query}, nodes {n_nodes:?}: {worst} query samples off the edge"
                );
            }
        }
    }
}

#[test]
fn one_grid_point_more_changes_the_answer_only_by_the_discretization_error() {
    // Node counts, candidate counts and signal lengths that differ by one give warps within a
    // fraction of a sample of each other and objectives within a few per cent.
    let (n_ref, n_query) = (500, 620);
    let (r, q) = (sampled(n_ref, false), sampled(n_query, true));
    let base = WarpParams {
        lambda_inst: 0.05,
        lambda_cum: 0.01,
        ..PLAIN
    };
    let variants: Vec<WarpParams> = vec![
        WarpParams {
            n_nodes: Some(125),
            ..base.clone()
        },
        WarpParams {
            n_nodes: Some(126),
            ..base.clone()
        },
        WarpParams {
            n_nodes: Some(127),
            ..base.clone()
        },
        WarpParams {
            coarse_nodes: 49,
            ..base.clone()
        },
        WarpParams {
            coarse_candidates: 98,
            ..base.clone()
        },
        WarpParams {
            n_candidates: 16,
            ..base.clone()
        },
    ];
    let reference = align2(&r, &q, &base);
    for p in &variants {
        let w = align2(&r, &q, p);
        let moved = distance((&reference, n_query), (&w, n_query)) * (n_query - 1) as f64;
        let rel = (w.objective() / reference.objective() - 1.0).abs();
        assert!(
            moved < 1.0 && rel < 0.02,
            "{p:?}: moved {moved} samples, objective {rel:+e}"
        );
    }
    // and the signal lengths: one reference or query sample more
    for (nr, nq) in [
        (n_ref + 1, n_query),
        (n_ref, n_query + 1),
        (n_ref - 1, n_query - 1),
    ] {
        let w = align2(&sampled(nr, false), &sampled(nq, true), &base);
        let moved = distance((&reference, n_query), (&w, nq)) * (n_query - 1) as f64;
        let rel = (w.objective() / reference.objective() - 1.0).abs();
        assert!(
            moved < 1.0 && rel < 0.02,
            "{nr} -> {nq}: moved {moved} samples, {rel:+e}"
        );
    }
}

#[test]
fn plain_is_the_defaults_without_smoothing_and_fill() {
    assert_eq!(
        PLAIN,
        WarpParams {
            smooth_width: 1,
            fill_length: 0.0,
            ..WarpParams::default()
        }
    );
}
