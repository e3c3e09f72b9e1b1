//! Integration tests of the public API: recovery of known warps, identity, objective
//! consistency, input validation and parallel determinism.

use tandem_warp::{Error, SignalRef, Warp, WarpParams, align, align_many, objective_of};

/// SplitMix64: a tiny seeded generator so the tests need no RNG crate.
struct Rng(u64);
impl Rng {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Approximately standard normal (Irwin–Hall with 12 uniforms).
    fn normal(&mut self) -> f64 {
        (0..12).map(|_| self.next_f64()).sum::<f64>() - 6.0
    }
}

/// A smooth 3-channel signal of normalized time `u ∈ [0, 1]`.
fn shape(u: f64) -> [f64; 3] {
    use std::f64::consts::PI;
    [
        (2.0 * PI * 3.0 * u).sin() + 0.5 * (2.0 * PI * 7.0 * u).cos(),
        (2.0 * PI * 2.0 * u + 0.3).cos() * (1.0 + u),
        4.0 * (u - 0.5).powi(2) + 0.4 * (2.0 * PI * 5.0 * u).sin(),
    ]
}

/// True warp in normalized time: smooth, monotone, slopes in [0.58, 1.42].
fn phi(t: f64) -> f64 {
    use std::f64::consts::PI;
    t + 0.06 * (2.0 * PI * t).sin() + 0.02 * (4.0 * PI * t).sin()
}

fn phi_inv(tau: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if phi(mid) < tau { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// Reference of `n_ref` samples and a query of `n_query` samples with `query(φ(t)) = reference(t)`,
/// plus noise of standard deviation `noise` on both; returns also the true warp in query samples.
fn warped_pair(
    n_ref: usize,
    n_query: usize,
    noise: f64,
    seed: u64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut rng = Rng(seed);
    let mut r = Vec::new();
    for n in 0..n_ref {
        for v in shape(n as f64 / (n_ref - 1) as f64) {
            r.push(v + noise * rng.normal());
        }
    }
    let mut q = Vec::new();
    for m in 0..n_query {
        for v in shape(phi_inv(m as f64 / (n_query - 1) as f64)) {
            q.push(v + noise * rng.normal());
        }
    }
    let truth = (0..n_ref)
        .map(|n| phi(n as f64 / (n_ref - 1) as f64) * (n_query - 1) as f64)
        .collect();
    (r, q, truth)
}

fn mae(w: &Warp, truth: &[f64]) -> f64 {
    w.values()
        .iter()
        .zip(truth)
        .map(|(a, b)| (a - b).abs())
        .sum::<f64>()
        / truth.len() as f64
}

/// Independent re-implementation of the documented objective (see `objective_of`).
/// `x` (sample-major, `nc` channels) after [`WarpParams::smooth_width`]'s smoothing, computed
/// the slow way: three passes, each sample the plain mean of the `w` samples centred on it
/// (indices clamped to the signal).
fn smoothed_directly(x: &[f64], nc: usize, w: usize) -> Vec<f64> {
    let n = x.len() / nc;
    let h = (w / 2) as isize;
    let mut cur = x.to_vec();
    for _ in 0..3 {
        let prev = cur.clone();
        for t in 0..n {
            for c in 0..nc {
                let sum: f64 = (-h..=h)
                    .map(|k| prev[(t as isize + k).clamp(0, n as isize - 1) as usize * nc + c])
                    .sum();
                cur[t * nc + c] = sum / w as f64;
            }
        }
    }
    cur
}

/// The documented objective of `psi` at the `λ_inst` in `p` (the caller passes the one in
/// effect), on the signals smoothed as `p.smooth_width` says.
fn direct_objective(r: &[f64], q: &[f64], nc: usize, psi: &[f64], p: &WarpParams) -> f64 {
    let (r, q) = (
        &smoothed_directly(r, nc, p.smooth_width)[..],
        &smoothed_directly(q, nc, p.smooth_width)[..],
    );
    let (nr, nq) = (r.len() / nc, q.len() / nc);
    let h = 1.0 / (nr - 1) as f64;
    let w = p.weights.clone().unwrap_or(vec![1.0; nc]);
    let mut total = 0.0;
    for n in 0..nr {
        let s = (psi[n].floor() as usize).min(nq - 2);
        let f = psi[n] - s as f64;
        let mut l = 0.0;
        for c in 0..nc {
            let x2 = (1.0 - f) * q[s * nc + c] + f * q[(s + 1) * nc + c];
            l += w[c] * (x2 - r[n * nc + c]).powi(2);
        }
        total += if n == 0 || n == nr - 1 { 0.5 * h } else { h } * l;
    }
    for n in 0..nr - 1 {
        let (a, b) = (psi[n] / (nq - 1) as f64, psi[n + 1] / (nq - 1) as f64);
        let (ta, tb) = (n as f64 * h, (n + 1) as f64 * h);
        total += p.lambda_inst * h * ((b - a) / h - 1.0).powi(2);
        // exact ∫ (φ − t)² over the piece by 3-point Simpson (exact for quadratics)
        let (da, db) = (a - ta, b - tb);
        let dm = 0.5 * (da + db);
        total += p.lambda_cum * h * (da * da + 4.0 * dm * dm + db * db) / 6.0;
    }
    total
}

/// Aligns two 3-channel signals of [`warped_pair`] (which are valid by construction).
fn align3(r: &[f64], q: &[f64], params: &WarpParams) -> Warp {
    align(
        SignalRef::new(r, 3).unwrap(),
        SignalRef::new(q, 3).unwrap(),
        params,
    )
    .unwrap()
}

#[test]
fn recovers_a_known_smooth_warp_from_noisy_signals() {
    for (n_ref, n_query, seed) in [(800, 1000, 1), (900, 700, 2)] {
        let (r, q, truth) = warped_pair(n_ref, n_query, 0.05, seed);
        let params = WarpParams {
            lambda_inst: 0.01,
            lambda_cum: 0.01,
            ..Default::default()
        };
        let w = align3(&r, &q, &params);
        let err = mae(&w, &truth);
        eprintln!("known warp {n_ref} -> {n_query}: MAE {err:.3} query samples");
        assert!(
            err <= 0.01 * n_query as f64,
            "MAE {err} samples > 1% of {n_query}"
        );
        // and it is far better than the linear warp
        let lin: Vec<f64> = (0..n_ref)
            .map(|n| n as f64 * (n_query - 1) as f64 / (n_ref - 1) as f64)
            .collect();
        let lin_err = lin
            .iter()
            .zip(&truth)
            .map(|(a, b)| (a - b).abs())
            .sum::<f64>()
            / n_ref as f64;
        assert!(err < 0.2 * lin_err, "MAE {err} vs linear {lin_err}");
    }
}

#[test]
fn defaults_are_as_accurate_as_the_same_problem_setting() {
    // "Same problem" as gdtw: one node per reference sample and M = 301 candidates.
    let (r, q, truth) = warped_pair(600, 700, 0.05, 3);
    let (rs, qs) = (
        SignalRef::new(&r, 3).unwrap(),
        SignalRef::new(&q, 3).unwrap(),
    );
    let base = WarpParams {
        lambda_inst: 0.01,
        lambda_cum: 0.01,
        ..Default::default()
    };
    let same = WarpParams {
        n_nodes: Some(600),
        n_candidates: 301,
        refinements: 6,
        refine_radius: 22.5,
        max_jump: Some(16),
        ..base.clone()
    };
    let e_default = mae(&align(rs, qs, &base).unwrap(), &truth);
    let e_same = mae(&align(rs, qs, &same).unwrap(), &truth);
    eprintln!("known warp: MAE default {e_default:.3}, same-problem {e_same:.3} query samples");
    assert!(
        e_default <= 1.1 * e_same + 0.1,
        "default MAE {e_default} vs same-problem {e_same}"
    );
}

#[test]
fn identical_signals_give_the_identity_warp() {
    let (r, _, _) = warped_pair(500, 10, 0.0, 4);
    let s = SignalRef::new(&r, 3).unwrap();
    let w = align(s, s, &WarpParams::default()).unwrap();
    for (n, v) in w.values().iter().enumerate() {
        assert!((v - n as f64).abs() < 1e-6, "ψ[{n}] = {v}");
    }
    assert!(w.objective().abs() < 1e-12);
    // same shape at another length: the identity in normalized time
    let short: Vec<f64> = (0..300).flat_map(|n| shape(n as f64 / 299.0)).collect();
    let long: Vec<f64> = (0..451).flat_map(|n| shape(n as f64 / 450.0)).collect();
    let at = |smooth_width: usize| {
        align(
            SignalRef::new(&short, 3).unwrap(),
            SignalRef::new(&long, 3).unwrap(),
            &WarpParams {
                smooth_width,
                ..WarpParams::default()
            },
        )
        .unwrap()
    };
    let worst = |w: &Warp| {
        w.values()
            .iter()
            .enumerate()
            .map(|(n, v)| (v - n as f64 * 450.0 / 299.0).abs())
            .fold(0.0, f64::max)
    };
    let unsmoothed = worst(&at(1));
    assert!(unsmoothed < 0.5, "{unsmoothed}");
    // Smoothing over the same number of samples is a wider smoothing in task time for the
    // shorter signal, so the two smoothed shapes no longer match exactly. The kernel is
    // symmetric and keeps every feature's position, so what moves the warp is only that
    // mismatch of shape: less than half the kernel's standard deviation (1.14 query samples
    // measured at the default 7, σ ≈ 3.46).
    let smoothed = worst(&at(7));
    assert!(smoothed < 0.5 * tandem_warp::smooth_sigma(7), "{smoothed}");
}

#[test]
fn reported_objective_equals_direct_evaluation() {
    let (r, q, _) = warped_pair(400, 520, 0.1, 5);
    for params in [
        WarpParams::default(),
        WarpParams {
            weights: Some(vec![2.0, 0.0, 0.5]),
            lambda_cum: 3.0,
            ..Default::default()
        },
        WarpParams {
            n_nodes: Some(400),
            refinements: 1,
            max_jump: None,
            ..Default::default()
        },
    ] {
        let (rs, qs) = (
            SignalRef::new(&r, 3).unwrap(),
            SignalRef::new(&q, 3).unwrap(),
        );
        let w = align(rs, qs, &params).unwrap();
        // the documented objective at the slope penalty in effect (noise-dependent)
        let in_effect = WarpParams {
            lambda_inst: tandem_warp::effective_lambda_inst(rs, qs, &params).unwrap(),
            ..params.clone()
        };
        let direct = direct_objective(&r, &q, 3, w.values(), &in_effect);
        assert!(
            (w.objective() - direct).abs() <= 1e-9 * direct,
            "{} vs {direct}",
            w.objective()
        );
        let via_api = objective_of(rs, qs, w.values(), &params).unwrap();
        assert!((via_api - direct).abs() <= 1e-9 * direct);
        // the optimum beats the linear warp
        let lin: Vec<f64> = (0..400).map(|n| n as f64 * 519.0 / 399.0).collect();
        assert!(w.objective() < direct_objective(&r, &q, 3, &lin, &in_effect));
    }
}

#[test]
fn bad_inputs_are_errors() {
    let good: Vec<f64> = (0..20).map(|i| i as f64).collect();
    let g2 = SignalRef::new(&good, 2).unwrap();
    let p = WarpParams::default();
    // NaN in either signal, located
    let mut nan = good.clone();
    nan[7] = f64::NAN;
    let e = align(g2, SignalRef::new(&nan, 2).unwrap(), &p).unwrap_err();
    assert_eq!(
        e,
        Error::NonFinite {
            signal: "query".into(),
            sample: 3,
            channel: 1
        }
    );
    let e = align(SignalRef::new(&nan, 2).unwrap(), g2, &p).unwrap_err();
    assert!(matches!(
        e,
        Error::NonFinite {
            sample: 3,
            channel: 1,
            ..
        }
    ));
    let mut inf = good.clone();
    inf[0] = f64::INFINITY;
    assert!(align(g2, SignalRef::new(&inf, 2).unwrap(), &p).is_err());
    // finite but so large that squared differences would overflow: an error, not a panic
    let mut huge = good.clone();
    huge[5] = 1e200;
    let e = align(g2, SignalRef::new(&huge, 2).unwrap(), &p).unwrap_err();
    assert_eq!(
        e,
        Error::TooLarge {
            signal: "query".into(),
            sample: 2,
            channel: 1,
            value: 1e200
        }
    );
    let mut heavy = p.clone();
    heavy.weights = Some(vec![1.0, 1e200]);
    assert!(matches!(
        align(g2, g2, &heavy).unwrap_err(),
        Error::BadParam { .. }
    ));
    // channel mismatch
    let e = align(g2, SignalRef::new(&good, 1).unwrap(), &p).unwrap_err();
    assert_eq!(
        e,
        Error::ChannelMismatch {
            reference: 2,
            query: 1
        }
    );
    // empty / too short / ragged
    assert!(matches!(
        SignalRef::new(&[], 2),
        Err(Error::TooShort { n_samples: 0 })
    ));
    assert!(matches!(
        SignalRef::new(&good[..3], 2),
        Err(Error::RaggedData { .. })
    ));
    // slope bounds that cannot join the endpoints
    for (lo, hi) in [(0.5, 0.9), (1.2, 3.0)] {
        let p = WarpParams {
            slope_min: lo,
            slope_max: hi,
            ..Default::default()
        };
        assert!(matches!(
            align(g2, g2, &p),
            Err(Error::InfeasibleSlopes { .. })
        ));
    }
    // weights of the wrong length or sign
    let p = WarpParams {
        weights: Some(vec![1.0]),
        ..Default::default()
    };
    assert!(matches!(
        align(g2, g2, &p),
        Err(Error::BadParam {
            name: "weights",
            ..
        })
    ));
    let p = WarpParams {
        weights: Some(vec![1.0, f64::NAN]),
        ..Default::default()
    };
    assert!(matches!(
        align(g2, g2, &p),
        Err(Error::BadParam {
            name: "weights",
            ..
        })
    ));
    // objective_of rejects malformed warps
    let w = [0.0, 1.0, 0.5, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 9.0];
    assert!(matches!(
        objective_of(g2, g2, &w, &WarpParams::default()),
        Err(Error::BadWarp { .. })
    ));
    assert!(objective_of(g2, g2, &w[..5], &WarpParams::default()).is_err());
    // align_many names the failing query
    let e = align_many(
        g2,
        &[g2, SignalRef::new(&nan, 2).unwrap()],
        &WarpParams::default(),
    )
    .unwrap_err();
    assert!(matches!(e, Error::NonFinite { ref signal, .. } if signal == "query #1"));
}

#[test]
fn extreme_slope_bounds_are_handled() {
    // gdtw's defaults: practically unconstrained slopes
    let (r, q, truth) = warped_pair(300, 360, 0.02, 7);
    let p = WarpParams {
        slope_min: 1e-8,
        slope_max: 1e8,
        lambda_inst: 0.01,
        lambda_cum: 0.01,
        ..Default::default()
    };
    let w = align3(&r, &q, &p);
    assert!(w.values().windows(2).all(|x| x[1] >= x[0]));
    assert_eq!(w.values()[299], 359.0);
    assert!(mae(&w, &truth) <= 3.6, "MAE {}", mae(&w, &truth));
}

#[test]
fn tight_but_feasible_slopes_force_the_identity() {
    let (r, q, _) = warped_pair(120, 150, 0.0, 6);
    let p = WarpParams {
        slope_min: 1.0,
        slope_max: 1.0,
        ..Default::default()
    };
    let w = align3(&r, &q, &p);
    for (n, v) in w.values().iter().enumerate() {
        assert!((v - n as f64 * 149.0 / 119.0).abs() < 1e-6);
    }
}

#[test]
fn align_many_matches_align_in_order_and_across_thread_counts() {
    let pairs: Vec<_> = (0..4)
        .map(|i| warped_pair(300, 250 + 40 * i, 0.05, 10 + i as u64))
        .collect();
    let r = &pairs[0].0;
    let rs = SignalRef::new(r, 3).unwrap();
    let qs: Vec<SignalRef<'_>> = pairs
        .iter()
        .map(|p| SignalRef::new(&p.1, 3).unwrap())
        .collect();
    let p = WarpParams::default();
    let single: Vec<Warp> = qs.iter().map(|&q| align(rs, q, &p).unwrap()).collect();
    for threads in [1, 3] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let many = pool.install(|| align_many(rs, &qs, &p)).unwrap();
        assert_eq!(many, single, "{threads} threads");
    }
}

#[test]
fn the_slope_penalty_grows_with_the_estimated_noise() {
    use tandem_warp::{NOISE_PENALTY, effective_lambda_inst};
    // Smooth signals with white noise of standard deviation 0.05 (channel 0) and 0.02 (channel
    // 1) on both: the loss's noise floor is Σ_c W_c (σ²_c + σ²_c) = 2 (0.05² + 0.02²) = 0.0058.
    let n = 20_000;
    let mut rng = Rng(99);
    let mut noisy = |scale: f64| -> Vec<f64> {
        (0..n)
            .flat_map(|i| {
                let u = i as f64 / (n - 1) as f64;
                [
                    (6.0 * u).sin() + 0.05 * scale * rng.normal(),
                    u * u + 0.02 * scale * rng.normal(),
                ]
            })
            .collect()
    };
    let (r, q, clean) = (noisy(1.0), noisy(1.0), noisy(0.0));
    let (rs, qs, cs) = (
        SignalRef::new(&r, 2).unwrap(),
        SignalRef::new(&q, 2).unwrap(),
        SignalRef::new(&clean, 2).unwrap(),
    );
    let p = WarpParams {
        lambda_inst: 0.01,
        ..Default::default()
    };
    let floor = (effective_lambda_inst(rs, qs, &p).unwrap() - 0.01) / NOISE_PENALTY;
    assert!((floor / 0.0058 - 1.0).abs() < 0.05, "noise floor {floor}");
    // noise-free smooth signals keep λ_inst (their second differences are below 1e-7, so the
    // floor is below 1e-13)
    let lam = effective_lambda_inst(cs, cs, &p).unwrap();
    assert!((lam - 0.01).abs() < 1e-12, "{lam}");
    // the floor is W-weighted
    let weighted = WarpParams {
        weights: Some(vec![4.0, 0.0]),
        ..p.clone()
    };
    let floor_w = (effective_lambda_inst(rs, qs, &weighted).unwrap() - 0.01) / NOISE_PENALTY;
    assert!(
        (floor_w / (4.0 * 2.0 * 0.0025) - 1.0).abs() < 0.05,
        "{floor_w}"
    );
    // align and objective_of use the effective value: the objective equals the documented one
    // at λ_inst = effective_lambda_inst
    let short: Vec<f64> = r[..2 * 400].to_vec();
    let shorter: Vec<f64> = q[..2 * 350].to_vec();
    let (a, b) = (
        SignalRef::new(&short, 2).unwrap(),
        SignalRef::new(&shorter, 2).unwrap(),
    );
    let w = align(a, b, &p).unwrap();
    let fixed = WarpParams {
        lambda_inst: effective_lambda_inst(a, b, &p).unwrap(),
        ..p.clone()
    };
    assert!(
        fixed.lambda_inst > 0.01 + NOISE_PENALTY * 0.004,
        "{}",
        fixed.lambda_inst
    );
    assert_eq!(objective_of(a, b, w.values(), &p).unwrap(), w.objective());
    let direct = direct_objective(&short, &shorter, 2, w.values(), &fixed);
    assert!((direct - w.objective()).abs() <= 1e-9 * direct);
}
