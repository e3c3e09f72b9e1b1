//! The fill of flat stretches (`WarpParams::fill_length`) on a task with one long dwell: it
//! changes the warp only inside the dwell, keeps it a valid warp within the slope bounds,
//! reports the objective of what it returns, and follows a smoothly varying speed ratio
//! through the dwell better than the straight line of the slope penalty.

use tandem_warp::{SignalRef, Warp, WarpParams, align, objective_of};

/// Reference samples; the query has `N_QUERY`.
const N_REF: usize = 1000;
const N_QUERY: usize = 800;
/// The dwell, in task time: every channel is constant from `DWELL.0` to `DWELL.1`.
const DWELL: (f64, f64) = (0.3, 0.7);

/// Two channels of task time `u ∈ [0, 1]`: moving before and after the dwell, constant inside.
fn task(u: f64) -> [f64; 2] {
    use std::f64::consts::PI;
    // task time with the dwell cut out, so both channels are continuous at its edges
    let v = if u < DWELL.0 {
        u
    } else if u < DWELL.1 {
        DWELL.0
    } else {
        u - (DWELL.1 - DWELL.0)
    };
    [(4.0 * PI * v).sin(), (3.0 * PI * v).cos() * (0.5 + v)]
}

/// The true warp in normalized time: the query runs through the task at a smoothly varying
/// speed (slope `1 + 0.12 π cos 2πt`, in about [0.62, 1.38]), so inside the dwell the true warp
/// bends away from the straight line between its edges by up to ~5 query samples.
fn phi(t: f64) -> f64 {
    t + 0.06 * (2.0 * std::f64::consts::PI * t).sin()
}

fn phi_inv(tau: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if phi(mid) < tau {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Reference and query (sample-major, 2 channels) with white noise of `noise` (0 = none), and
/// the true warp in query samples at every reference sample.
fn pair(noise: f64, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    // a small deterministic generator of Gaussian noise (Box–Muller on a 64-bit LCG)
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut uniform = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let mut gauss = move || {
        let (a, b) = (uniform(), uniform());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    };
    let mut reference = Vec::new();
    for n in 0..N_REF {
        let t = n as f64 / (N_REF - 1) as f64;
        reference.extend(task(t).map(|x| x + noise * gauss()));
    }
    let mut query = Vec::new();
    for s in 0..N_QUERY {
        let tau = s as f64 / (N_QUERY - 1) as f64;
        query.extend(task(phi_inv(tau)).map(|x| x + noise * gauss()));
    }
    let truth = (0..N_REF)
        .map(|n| phi(n as f64 / (N_REF - 1) as f64) * (N_QUERY - 1) as f64)
        .collect();
    (reference, query, truth)
}

fn run(r: &[f64], q: &[f64], fill_length: f64) -> Warp {
    let params = WarpParams {
        fill_length,
        ..WarpParams::default()
    };
    align(
        SignalRef::new(r, 2).unwrap(),
        SignalRef::new(q, 2).unwrap(),
        &params,
    )
    .unwrap()
}

/// Mean absolute error (query samples) over the reference samples `range`.
fn error(w: &Warp, truth: &[f64], range: std::ops::Range<usize>) -> f64 {
    let n = range.len() as f64;
    range.map(|i| (w.values()[i] - truth[i]).abs()).sum::<f64>() / n
}

/// Reference samples inside the dwell.
fn dwell() -> std::ops::Range<usize> {
    let at = |u: f64| (u * (N_REF - 1) as f64).round() as usize;
    at(DWELL.0)..at(DWELL.1) + 1
}

/// Aligns one pair with and without the fill, checks what must hold whatever the noise, and
/// returns the mean errors inside the dwell (query samples): filled, then plain.
fn filled_and_plain(noise: f64, seed: u64) -> (f64, f64) {
    let (r, q, truth) = pair(noise, seed);
    let plain = run(&r, &q, 0.0);
    let filled = run(&r, &q, WarpParams::default().fill_length);
    let inside = dwell();
    // only samples inside the dwell move
    for (i, (a, b)) in plain.values().iter().zip(filled.values()).enumerate() {
        assert!(
            a == b || inside.contains(&i),
            "noise {noise}, seed {seed}: sample {i} outside the dwell moved from {a} to {b}"
        );
    }
    assert!(
        plain.values() != filled.values(),
        "noise {noise}, seed {seed}: nothing filled"
    );
    // a valid warp within the slope bounds, with its own objective
    let p = WarpParams::default();
    let g = (N_QUERY - 1) as f64 / (N_REF - 1) as f64;
    for w in filled.values().windows(2) {
        let slope = (w[1] - w[0]) / g;
        assert!(slope >= p.slope_min - 1e-9 && slope <= p.slope_max + 1e-9);
    }
    let direct = objective_of(
        SignalRef::new(&r, 2).unwrap(),
        SignalRef::new(&q, 2).unwrap(),
        filled.values(),
        &p,
    )
    .unwrap();
    assert!((filled.objective() - direct).abs() <= 1e-12 * direct.max(1e-12));
    (
        error(&filled, &truth, inside.clone()),
        error(&plain, &truth, inside),
    )
}

#[test]
fn the_fill_changes_only_the_dwell_and_follows_the_speed_ratio_through_it() {
    // Noise-free and at 1 % of the channels' amplitude: the dwell is one flat stretch, and the
    // fill halves the error there (measured 2.09 against 3.84 query samples noise-free, 2.17
    // to 2.45 against 3.96 to 4.44 with noise).
    for (noise, seed) in [(0.0, 1), (0.01, 2), (0.01, 3), (0.01, 5), (0.01, 6)] {
        let (filled, plain) = filled_and_plain(noise, seed);
        assert!(
            filled < 0.7 * plain,
            "noise {noise}, seed {seed}: inside the dwell {filled} against {plain} query samples"
        );
    }
    // At 3 %, noise makes the dwell's edges and the plain warp inside it wander, and the fill
    // gains less and not on every seed (measured 20.97 against 25.83 query samples summed over
    // these six seeds; on seed 7 2.31 against 2.28).
    let (mut filled, mut plain) = (0.0, 0.0);
    for seed in [4, 7, 8, 9, 10, 11] {
        let (f, p) = filled_and_plain(0.03, seed);
        filled += f;
        plain += p;
    }
    assert!(
        filled < 0.9 * plain,
        "noise 0.03: inside the dwell {filled} against {plain} query samples (summed)"
    );
}

#[test]
fn signals_that_always_move_are_not_filled() {
    // the same task without its dwell: nothing is flat, so the fill changes nothing
    let n = 600;
    let r: Vec<f64> = (0..n)
        .flat_map(|i| {
            let t = i as f64 / (n - 1) as f64;
            [(7.0 * t).sin(), (5.0 * t).cos() + t]
        })
        .collect();
    let q: Vec<f64> = (0..n + 100)
        .flat_map(|i| {
            let t = phi_inv(i as f64 / (n + 99) as f64);
            [(7.0 * t).sin(), (5.0 * t).cos() + t]
        })
        .collect();
    assert_eq!(run(&r, &q, 0.0), run(&r, &q, 0.1));
}
