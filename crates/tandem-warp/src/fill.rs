//! Flat stretches ([`WarpParams::fill_length`]): where neither signal moves beyond its noise,
//! no channel identifies the warp, and GDTW's slope penalty draws a straight line between the
//! stretch's edges: a speed ratio that is constant inside and jumps at both edges. The fill
//! replaces the warp there by its smoothest continuation: the speed ratio carries on from the
//! warp around the stretch and changes gradually inside it.
//!
//! [`WarpParams::fill_length`]: crate::WarpParams::fill_length

use crate::objective::Prepared;
use crate::smooth::kernel_l2;

/// Half-width, in samples, of the window in which a sample's neighbourhood must stay within
/// its noise to count as flat (the window spans `2 · FLAT_HALF_WINDOW + 1` samples of the
/// smoothed signal).
pub const FLAT_HALF_WINDOW: usize = 10;

/// A channel is flat around a sample when its smoothed values in the window vary by at most
/// this many standard deviations of its smoothed white noise (the noise estimated as for
/// [`NOISE_PENALTY`](crate::NOISE_PENALTY), times the smoothing kernel's `‖k‖₂`), or by at most
/// [`FLAT_RANGE_FRACTION`] of its range, whichever is larger.
pub const FLAT_NOISE_MULTIPLE: f64 = 4.0;

/// Least variation, as a fraction of a channel's range over its whole signal, that counts as
/// motion (what makes noise-free signals flat where they move imperceptibly).
pub const FLAT_RANGE_FRACTION: f64 = 0.01;

/// Per sample, whether every channel of weight > 0 of one signal is flat around it (see
/// [`FLAT_NOISE_MULTIPLE`]): `smoothed` and `raw` are the sample-major signal after and before
/// the smoothing, `sd` its channels' noise standard deviations, `kl2` the smoothing kernel's
/// `‖k‖₂`.
///
/// Every window's maximum and minimum come from running maxima and minima over blocks of the
/// window's length, counted from each block's start and from its end (van Herk, Gil and
/// Werman: a window spans the end of one block and the start of the next), on the signal
/// padded with its end values (which a window clipped at an end contains anyway): O(samples ·
/// channels) whatever the window, all channels side by side.
fn flat_samples(
    smoothed: &[f64],
    raw: &[f64],
    nc: usize,
    w: &[f64],
    sd: &[f64],
    kl2: f64,
) -> Vec<bool> {
    let n = smoothed.len() / nc;
    let half = FLAT_HALF_WINDOW;
    let k = 2 * half + 1;
    // thresholds: channels of weight 0 never count as moving
    let mut lo = vec![f64::INFINITY; nc];
    let mut hi = vec![f64::NEG_INFINITY; nc];
    for row in raw.chunks_exact(nc) {
        for ((l, h), &v) in lo.iter_mut().zip(hi.iter_mut()).zip(row) {
            *l = l.min(v);
            *h = h.max(v);
        }
    }
    let thr: Vec<f64> = (0..nc)
        .map(|c| {
            if w[c] > 0.0 {
                (FLAT_NOISE_MULTIPLE * kl2 * sd[c]).max(FLAT_RANGE_FRACTION * (hi[c] - lo[c]))
            } else {
                f64::INFINITY
            }
        })
        .collect();
    let mut flat = vec![true; n];
    let len = n + 2 * half;
    let mut padded = vec![0.0; len];
    let (mut fwd_max, mut fwd_min) = (vec![0.0; len], vec![0.0; len]);
    let (mut back_max, mut back_min) = (vec![0.0; len], vec![0.0; len]);
    for c in (0..nc).filter(|&c| hi[c] - lo[c] > thr[c]) {
        // padded[j] = smoothed[clamp(j − half, 0, n − 1)] of channel c
        for (j, p) in padded.iter_mut().enumerate() {
            *p = smoothed[j.saturating_sub(half).min(n - 1) * nc + c];
        }
        for start in (0..len).step_by(k) {
            let end = (start + k).min(len);
            let (mut mx, mut mn) = (padded[start], padded[start]);
            for j in start..end {
                mx = mx.max(padded[j]);
                mn = mn.min(padded[j]);
                fwd_max[j] = mx;
                fwd_min[j] = mn;
            }
            let (mut mx, mut mn) = (padded[end - 1], padded[end - 1]);
            for j in (start..end).rev() {
                mx = mx.max(padded[j]);
                mn = mn.min(padded[j]);
                back_max[j] = mx;
                back_min[j] = mn;
            }
        }
        // sample i's window is padded[i..i + k]
        for (i, f) in flat.iter_mut().enumerate() {
            let e = i + k - 1;
            if back_max[i].max(fwd_max[e]) - back_min[i].min(fwd_min[e]) > thr[c] {
                *f = false;
            }
        }
    }
    flat
}

/// Solves `A x = b` for a symmetric positive definite pentadiagonal `A` (diagonal `d0`, first
/// and second superdiagonals `d1[i] = A[i][i+1]`, `d2[i] = A[i][i+2]`) by `L D Lᵀ`, in place in
/// `b`. Returns `false` (and leaves `b` undefined) if a pivot is not positive and finite.
fn solve_pentadiagonal(d0: &[f64], d1: &[f64], d2: &[f64], b: &mut [f64]) -> bool {
    let m = d0.len();
    let (mut d, mut l1, mut l2) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
    for i in 0..m {
        let mut di = d0[i];
        if i >= 1 {
            di -= l1[i - 1] * l1[i - 1] * d[i - 1];
        }
        if i >= 2 {
            di -= l2[i - 2] * l2[i - 2] * d[i - 2];
        }
        if !(di.is_finite() && di > 0.0) {
            return false;
        }
        d[i] = di;
        if i + 1 < m {
            let mut a = d1[i];
            if i >= 1 {
                a -= l2[i - 1] * l1[i - 1] * d[i - 1];
            }
            l1[i] = a / di;
        }
        if i + 2 < m {
            l2[i] = d2[i] / di;
        }
    }
    for i in 0..m {
        if i >= 1 {
            b[i] -= l1[i - 1] * b[i - 1];
        }
        if i >= 2 {
            b[i] -= l2[i - 2] * b[i - 2];
        }
    }
    for (bi, di) in b.iter_mut().zip(&d) {
        *bi /= di;
    }
    for i in (0..m).rev() {
        if i + 1 < m {
            b[i] -= l1[i] * b[i + 1];
        }
        if i + 2 < m {
            b[i] -= l2[i] * b[i + 2];
        }
    }
    true
}

/// Replaces the warp `values` (query samples at every reference sample) inside its flat
/// stretches by the smoothest continuation of the warp around them; returns whether anything
/// changed. A reference sample is in a flat stretch when the reference is flat around it and
/// the query is flat around the query sample the warp maps it to ([`FLAT_NOISE_MULTIPLE`]).
///
/// With `φ = ψ / (T_query − 1)` in normalized time, the continuation minimizes
///
/// `Σ_{n not flat} ω_n g_n (φ_n − φ̂_n)² + λ_inst ∫ (φ' − 1)² dt + λ_inst ℓ² ∫ φ''² dt`
///
/// with `φ(0) = 0`, `φ(1) = 1`: `φ̂` the warp found, `ω_n` the trapezoid weights,
/// `g_n = (T_query − 1)² ‖x₂'(ψ̂_n)‖²_W` the loss's Gauss–Newton curvature at it (`x₂'` the
/// smoothed query's central difference), `λ_inst` the alignment's ([`Prepared::lambda_inst`])
/// and `ℓ = fill_length`. Where the signals move, the loss holds the warp where it was found;
/// inside a flat stretch the last two terms alone shape it, so its slope at the edges carries
/// on for about `ℓ` and straightens beyond. Each stretch is then shifted linearly to meet the
/// found warp at the samples next to it, and kept only if every slope stays within `s`
/// (normalized time); the samples outside flat stretches never change.
pub(crate) fn fill_flats(
    prep: &Prepared<'_>,
    values: &mut [f64],
    fill_length: f64,
    smooth_width: usize,
    s: (f64, f64),
) -> bool {
    let (nr, nq, nc) = (prep.nr, prep.nq, prep.nc);
    let lambda = prep.lambda_inst;
    // both validated finite and >= 0
    if fill_length <= 0.0 || nr < 3 || nq < 2 || lambda <= 0.0 {
        return false;
    }
    let kl2 = kernel_l2(smooth_width);
    let flat_r = flat_samples(&prep.r, prep.r_raw, nc, &prep.w, &prep.sd_r, kl2);
    if !flat_r[1..nr - 1].contains(&true) {
        return false;
    }
    let flat_q = flat_samples(&prep.q, prep.q_raw, nc, &prep.w, &prep.sd_q, kl2);
    let mut flat: Vec<bool> = values
        .iter()
        .zip(&flat_r)
        .map(|(&v, &fr)| fr && flat_q[(v.round().max(0.0) as usize).min(nq - 1)])
        .collect();
    flat[0] = false;
    flat[nr - 1] = false;
    if !flat.contains(&true) {
        return false;
    }

    // normal equations of the quadratic above over all nr samples (bands of a symmetric
    // pentadiagonal matrix), then the two pinned ends eliminated
    let (qs, h) = (prep.qscale, prep.h);
    // the smoothed query's central difference at sample t, from its forward differences
    // (one-sided at both ends)
    let dq = &prep.dq;
    let slope_at = |t: usize, c: usize| match (t.checked_sub(1), t + 1 < nq) {
        (Some(a), true) => 0.5 * (dq[a * nc + c] + dq[t * nc + c]),
        (Some(a), false) => dq[a * nc + c],
        (None, _) => dq[c],
    };
    let mut d0 = vec![0.0; nr];
    let mut d1 = vec![0.0; nr];
    let mut d2 = vec![0.0; nr];
    let mut rhs = vec![0.0; nr];
    for n in (0..nr).filter(|&n| !flat[n]) {
        let tau = values[n].clamp(0.0, qs);
        let t0 = (tau as usize).min(nq - 2);
        let f = tau - t0 as f64;
        let g: f64 = (0..nc)
            .map(|c| {
                let d = (1.0 - f) * slope_at(t0, c) + f * slope_at(t0 + 1, c);
                prep.w[c] * d * d
            })
            .sum();
        let a = prep.trap_weight(n) * g * qs * qs;
        d0[n] += a;
        rhs[n] += a * values[n] / qs;
    }
    // λ/h Σ (φ_{k+1} − φ_k − h)²: with both ends pinned, the target slope only adds a constant
    let ci = lambda / h;
    for k in 0..nr - 1 {
        d0[k] += ci;
        d0[k + 1] += ci;
        d1[k] -= ci;
    }
    // μ/h³ Σ (φ_{k−1} − 2 φ_k + φ_{k+1})², μ = λ ℓ²
    let ck = lambda * fill_length * fill_length / (h * h * h);
    for k in 1..nr - 1 {
        d0[k - 1] += ck;
        d0[k] += 4.0 * ck;
        d0[k + 1] += ck;
        d1[k - 1] -= 2.0 * ck;
        d1[k] -= 2.0 * ck;
        d2[k - 1] += ck;
    }
    // unknowns φ_1 … φ_{nr−2}; φ_0 = 0 adds nothing, φ_{nr−1} = 1 moves to the right side
    let m = nr - 2;
    rhs[nr - 2] -= d1[nr - 2];
    if nr >= 4 {
        rhs[nr - 3] -= d2[nr - 3];
    }
    let mut phi = rhs[1..nr - 1].to_vec();
    let d1r: Vec<f64> = (0..m)
        .map(|u| if u + 1 < m { d1[u + 1] } else { 0.0 })
        .collect();
    let d2r: Vec<f64> = (0..m)
        .map(|u| if u + 2 < m { d2[u + 1] } else { 0.0 })
        .collect();
    if !solve_pentadiagonal(&d0[1..nr - 1], &d1r, &d2r, &mut phi) {
        return false;
    }
    let fill = |n: usize| {
        if n == 0 {
            0.0
        } else if n == nr - 1 {
            qs
        } else {
            phi[n - 1] * qs
        }
    };

    // every flat stretch a..=b, shifted to meet the warp at a − 1 and b + 1
    let (lo, hi) = (s.0 * qs * h, s.1 * qs * h); // query samples per reference sample
    let tol = 1e-9 * qs * h;
    let mut changed = false;
    let mut n = 1;
    while n < nr - 1 {
        if !flat[n] {
            n += 1;
            continue;
        }
        let a = n;
        while flat[n + 1] {
            n += 1;
        }
        let (left, right) = (a - 1, n + 1);
        let (ea, eb) = (values[left] - fill(left), values[right] - fill(right));
        let span = (right - left) as f64;
        let seg: Vec<f64> = (left..=right)
            .map(|k| {
                let t = (k - left) as f64 / span;
                fill(k) + ea + (eb - ea) * t
            })
            .collect();
        let ok = seg.iter().all(|v| v.is_finite())
            && seg
                .windows(2)
                .all(|p| p[1] - p[0] >= lo - tol && p[1] - p[0] <= hi + tol);
        if ok {
            values[a..=n].copy_from_slice(&seg[1..seg.len() - 1]);
            changed = true;
        }
        n += 1;
    }
    // rounding must never make the warp decrease
    for k in 1..nr {
        if values[k] < values[k - 1] {
            values[k] = values[k - 1];
        }
    }
    changed
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pentadiagonal_solver_solves() {
        // a diagonally dominant symmetric pentadiagonal system with a known solution
        let m = 9;
        let d0: Vec<f64> = (0..m).map(|i| 6.0 + i as f64 * 0.1).collect();
        let d1: Vec<f64> = (0..m).map(|i| -1.0 - 0.05 * i as f64).collect();
        let d2: Vec<f64> = (0..m).map(|i| 0.5 + 0.01 * i as f64).collect();
        let x: Vec<f64> = (0..m).map(|i| (i as f64 * 0.7).sin()).collect();
        let mut b = vec![0.0; m];
        for i in 0..m {
            b[i] += d0[i] * x[i];
            if i + 1 < m {
                b[i] += d1[i] * x[i + 1];
                b[i + 1] += d1[i] * x[i];
            }
            if i + 2 < m {
                b[i] += d2[i] * x[i + 2];
                b[i + 2] += d2[i] * x[i];
            }
        }
        assert!(solve_pentadiagonal(&d0, &d1, &d2, &mut b));
        for (got, want) in b.iter().zip(&x) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
        // not positive definite: refused
        let mut b = vec![1.0; 3];
        assert!(!solve_pentadiagonal(
            &[1.0, 1.0, 1.0],
            &[2.0, 2.0, 0.0],
            &[0.0; 3],
            &mut b
        ));
    }

    #[test]
    fn flat_means_within_the_noise_or_a_hundredth_of_the_range() {
        // one channel: flat, a ramp of 1/128 per sample over samples 100..228, flat; noise-free
        // (every value exact in binary)
        let x: Vec<f64> = (0..340)
            .map(|t| (t.clamp(100, 228) - 100) as f64 / 128.0)
            .collect();
        let flat = flat_samples(&x, &x, 1, &[1.0], &[0.0], 1.0);
        // a sample is flat when its window of ±10 samples moves by at most 0.01 of the range,
        // i.e. by one step of the ramp: far from the ramp and at its very ends, not on it
        assert!(flat[..=91].iter().all(|&f| f));
        assert!(flat[92..=236].iter().all(|&f| !f));
        assert!(flat[237..].iter().all(|&f| f));
        // noise: a window may move by FLAT_NOISE_MULTIPLE noise deviations (here 4 × 0.01)
        let flat = flat_samples(&x, &x, 1, &[1.0], &[0.01], 1.0);
        assert!(flat[..=95].iter().all(|&f| f) && !flat[96]);
        // a channel of weight 0 never makes a sample non-flat
        let two: Vec<f64> = x.iter().flat_map(|&v| [0.0, v]).collect();
        assert!(
            flat_samples(&two, &two, 2, &[1.0, 0.0], &[0.0; 2], 1.0)
                .iter()
                .all(|&f| f)
        );
    }
}
