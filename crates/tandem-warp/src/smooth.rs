//! Smoothing of the signals before they are compared ([`WarpParams::smooth_width`]).
//!
//! [`WarpParams::smooth_width`]: crate::WarpParams::smooth_width

/// Largest accepted [`WarpParams::smooth_width`](crate::WarpParams::smooth_width) (samples).
pub const MAX_SMOOTH_WIDTH: usize = 10_001;

/// Standard deviation (samples) of the smoothing kernel of
/// [`WarpParams::smooth_width`](crate::WarpParams::smooth_width) `= w` (odd): three running
/// means of `w` samples, each of variance `(w² − 1)/12`, so `√((w² − 1)/4)`.
///
/// ```
/// assert!((tandem_warp::smooth_sigma(7) - 12f64.sqrt()).abs() < 1e-12); // ≈ 3.46 samples
/// assert_eq!(tandem_warp::smooth_sigma(1), 0.0); // width 1: no smoothing
/// ```
#[must_use]
pub fn smooth_sigma(w: usize) -> f64 {
    let w = w as f64;
    (0.25 * (w * w - 1.0)).sqrt()
}

/// `‖k‖₂`, the root of the sum of squares of the smoothing kernel of width `w` (three running
/// means of `w` samples, see [`smooth`]; 1 for `w = 1`): white noise of standard deviation `σ`
/// has standard deviation `‖k‖₂ σ` after the smoothing (away from the signal's ends).
pub(crate) fn kernel_l2(w: usize) -> f64 {
    let mut k = vec![1.0];
    for _ in 0..3 {
        let mut next = vec![0.0; k.len() + w - 1];
        for (i, v) in k.iter().enumerate() {
            for n in &mut next[i..i + w] {
                *n += v / w as f64;
            }
        }
        k = next;
    }
    k.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// The sample-major `data` (`nc` channels) with every channel passed three times through a
/// centred running mean of odd width `w` samples, samples beyond either end repeating the end
/// value: a kernel close to a Gaussian of standard deviation [`smooth_sigma`]`(w)`, symmetric,
/// so a feature keeps its position. `w = 1` returns the data unchanged. O(samples · channels)
/// whatever `w`.
pub(crate) fn smooth(data: &[f64], nc: usize, w: usize) -> Vec<f64> {
    debug_assert!(w % 2 == 1 && nc > 0);
    let n = data.len() / nc;
    if w <= 1 || n == 0 {
        return data.to_vec();
    }
    let mut a = data.to_vec();
    let mut b = vec![0.0; data.len()];
    for _ in 0..3 {
        running_mean(&a, &mut b, nc, w);
        std::mem::swap(&mut a, &mut b);
    }
    a
}

/// One pass of [`smooth`]: `dst` is `src` (sample-major, `nc` channels) under a centred
/// running mean of odd width `w`, indices clamped to the signal. All channels slide together,
/// so memory is read in order; the window sums are summed afresh at the start of every block
/// of 4096 samples so that rounding cannot build up.
fn running_mean(src: &[f64], dst: &mut [f64], nc: usize, w: usize) {
    const BLOCK: usize = 4096;
    let n = src.len() / nc;
    let h = (w / 2) as isize;
    let last = n as isize - 1;
    let row = |i: isize| {
        let i = i.clamp(0, last) as usize * nc;
        &src[i..i + nc]
    };
    let inv = 1.0 / w as f64;
    let mut sum = vec![0.0; nc];
    for t in 0..n {
        if t % BLOCK == 0 {
            sum.fill(0.0);
            for k in -h..=h {
                for (s, x) in sum.iter_mut().zip(row(t as isize + k)) {
                    *s += x;
                }
            }
        } else {
            let t = t as isize;
            for ((s, add), sub) in sum.iter_mut().zip(row(t + h)).zip(row(t - h - 1)) {
                *s += add - sub;
            }
        }
        for (d, s) in dst[t * nc..(t + 1) * nc].iter_mut().zip(&sum) {
            *d = s * inv;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_impulse_response_of_width_3_is_the_binomial_like_kernel() {
        // Three running means of 3 samples: (1, 1, 1)/3 convolved three times is
        // (1, 3, 6, 7, 6, 3, 1)/27.
        let mut x = vec![0.0; 21];
        x[10] = 27.0;
        let y = smooth(&x, 1, 3);
        let want = [1.0, 3.0, 6.0, 7.0, 6.0, 3.0, 1.0];
        for (t, v) in y.iter().enumerate() {
            let w = if (7..=13).contains(&t) {
                want[t - 7]
            } else {
                0.0
            };
            assert!((v - w).abs() < 1e-12, "sample {t}: {v} vs {w}");
        }
        assert!((smooth_sigma(3) - 2f64.sqrt()).abs() < 1e-12);
        // its variance: Σ k² (1, 3, 6, 7, 6, 3, 1)/27 over k = −3..3 = 54/27 = 2
        let var: f64 = want
            .iter()
            .zip(-3i32..=3)
            .map(|(w, k)| w * f64::from(k * k) / 27.0)
            .sum();
        assert!((var - 2.0).abs() < 1e-12);
    }

    #[test]
    fn ramps_and_constants_are_kept_and_steps_stay_centred() {
        let n = 200;
        let w = 7;
        let reach = 3 * (w / 2);
        // Two channels: a ramp and a constant.
        let x: Vec<f64> = (0..n).flat_map(|t| [0.5 * t as f64 - 3.0, 2.5]).collect();
        let y = smooth(&x, 2, w);
        for t in reach..n - reach {
            assert!((y[2 * t] - x[2 * t]).abs() < 1e-9, "ramp at {t}");
        }
        assert!(y.chunks(2).all(|s| (s[1] - 2.5).abs() < 1e-12));
        // A step between samples 99 and 100: the kernel is symmetric, so the smoothed step is
        // antisymmetric about 99.5.
        let step: Vec<f64> = (0..n).map(|t| f64::from(u8::from(t >= 100))).collect();
        let s = smooth(&step, 1, w);
        for k in 0..=reach {
            assert!((s[99 - k] + s[100 + k] - 1.0).abs() < 1e-12, "offset {k}");
        }
        assert!(s[99 - reach].abs() < 1e-12 && (s[100 + reach] - 1.0).abs() < 1e-12);
        assert!(s[99 - reach + 1] > 0.0 && s[100 + reach - 1] < 1.0);
        // Width 1 is the identity.
        assert_eq!(smooth(&x, 2, 1), x);
    }

    #[test]
    fn the_kernel_norm_is_that_of_the_impulse_response() {
        // width 3: (1, 3, 6, 7, 6, 3, 1)/27, Σ k² = 141/729
        assert!((kernel_l2(3) - (141.0f64 / 729.0).sqrt()).abs() < 1e-15);
        assert_eq!(kernel_l2(1), 1.0);
        // the same as the impulse response of `smooth` away from the ends
        let mut x = vec![0.0; 101];
        x[50] = 1.0;
        let y = smooth(&x, 1, 7);
        let direct = y.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((kernel_l2(7) - direct).abs() < 1e-12);
    }

    #[test]
    fn long_signals_do_not_drift() {
        // The running sum is refreshed, so a long constant stays exact to rounding.
        let x = vec![0.1; 50_000];
        let y = smooth(&x, 1, 9);
        assert!(y.iter().all(|v| (v - 0.1).abs() < 1e-14));
    }
}
