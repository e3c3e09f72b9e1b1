//! Minimal unit-quaternion algebra for orientation statistics.
//!
//! Quaternions are `[x, y, z, w]` (the channel order of the fixtures: `qx, qy, qz, qw`).
//! Rotation vectors are angle × axis in radians.
//! `q` and `−q` are the same rotation; [`log`] always returns the shortest rotation
//! vector (angle ≤ π), so statistics never see the sign of a quaternion.

/// A quaternion `[x, y, z, w]`.
pub(crate) type Quat = [f64; 4];

/// The identity rotation.
pub(crate) const IDENTITY: Quat = [0.0, 0.0, 0.0, 1.0];

/// Hamilton product `a ⊗ b`.
pub(crate) fn mul(a: &Quat, b: &Quat) -> Quat {
    let [ax, ay, az, aw] = *a;
    let [bx, by, bz, bw] = *b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// Conjugate (the inverse of a unit quaternion).
pub(crate) fn conj(q: &Quat) -> Quat {
    [-q[0], -q[1], -q[2], q[3]]
}

/// Euclidean norm.
pub(crate) fn norm(q: &Quat) -> f64 {
    (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt()
}

/// `q / |q|`; the identity for a zero quaternion (callers validate norms first).
pub(crate) fn normalize(q: &Quat) -> Quat {
    let n = norm(q);
    if n > 0.0 {
        [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
    } else {
        IDENTITY
    }
}

/// Dot product of the 4-vectors.
pub(crate) fn dot(a: &Quat, b: &Quat) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]
}

/// Logarithm map of a unit quaternion: the shortest rotation vector (radians, |r| ≤ π).
pub(crate) fn log(q: &Quat) -> [f64; 3] {
    // Choose the hemisphere w ≥ 0 so that q and −q give the same vector.
    let s = if q[3] < 0.0 { -1.0 } else { 1.0 };
    let (x, y, z, w) = (s * q[0], s * q[1], s * q[2], s * q[3]);
    let vn = (x * x + y * y + z * z).sqrt();
    // angle = 2 atan2(|v|, w); factor = angle / |v| (→ 2/w as |v| → 0).
    let factor = if vn < 1e-12 {
        2.0 / w.max(f64::MIN_POSITIVE)
    } else {
        2.0 * vn.atan2(w) / vn
    };
    [factor * x, factor * y, factor * z]
}

/// Exponential map: the unit quaternion of rotation vector `r` (radians).
pub(crate) fn exp(r: &[f64; 3]) -> Quat {
    let theta = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
    let half = 0.5 * theta;
    // sin(θ/2)/θ, with its series near 0.
    let k = if theta < 1e-8 {
        0.5 - theta * theta / 48.0
    } else {
        half.sin() / theta
    };
    [k * r[0], k * r[1], k * r[2], half.cos()]
}

/// Normalized linear interpolation between `a` and `b` at fraction `alpha ∈ [0, 1]`,
/// on the shorter arc (b is flipped into a's hemisphere first).
pub(crate) fn nlerp(a: &Quat, b: &Quat, alpha: f64) -> Quat {
    let s = if dot(a, b) < 0.0 { -1.0 } else { 1.0 };
    let q = [
        (1.0 - alpha) * a[0] + alpha * s * b[0],
        (1.0 - alpha) * a[1] + alpha * s * b[1],
        (1.0 - alpha) * a[2] + alpha * s * b[2],
        (1.0 - alpha) * a[3] + alpha * s * b[3],
    ];
    normalize(&q)
}

/// Spherical linear interpolation from unit quaternion `a` (at `f = 0`) to `b` (at `f = 1`)
/// along the shorter arc: both normalized first, `b` flipped into `a`'s hemisphere; the
/// result is normalized (normalized linear interpolation when the two are within 1e-12 of
/// each other, where the slerp's weights lose precision). The resampling policy's
/// quaternion rule ([`crate::resample`]).
pub(crate) fn slerp(a: &Quat, b: &Quat, f: f64) -> Quat {
    let a = normalize(a);
    let mut b = normalize(b);
    let mut d = dot(&a, &b);
    if d < 0.0 {
        b = b.map(|x| -x);
        d = -d;
    }
    if d > 1.0 - 1e-12 {
        return normalize(&[0, 1, 2, 3].map(|i| a[i] + f * (b[i] - a[i])));
    }
    let theta = d.min(1.0).acos();
    let s = theta.sin();
    let (wa, wb) = (((1.0 - f) * theta).sin() / s, (f * theta).sin() / s);
    normalize(&[0, 1, 2, 3].map(|i| wa * a[i] + wb * b[i]))
}

/// Rotation vector of `q` relative to `anchor`: `log(anchor⁻¹ ⊗ q)` (body frame).
pub(crate) fn log_relative(anchor: &Quat, q: &Quat) -> [f64; 3] {
    log(&mul(&conj(anchor), q))
}

/// `anchor ⊗ exp(r)`, normalized.
pub(crate) fn exp_relative(anchor: &Quat, r: &[f64; 3]) -> Quat {
    normalize(&mul(anchor, &exp(r)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn exp_log_round_trip() {
        for r in [
            [0.1, -0.2, 0.3],
            [0.0, 0.0, 0.0],
            [1e-10, 0.0, -1e-10],
            [2.0, 1.0, -0.5],
        ] {
            let q = exp(&r);
            assert!((norm(&q) - 1.0).abs() < 1e-14);
            assert!(close(&log(&q), &r, 1e-12), "{r:?}");
        }
    }

    #[test]
    fn log_ignores_sign() {
        let q = exp(&[0.3, 0.1, -0.4]);
        let mq = [-q[0], -q[1], -q[2], -q[3]];
        assert!(close(&log(&q), &log(&mq), 1e-14));
    }

    #[test]
    fn quarter_turn_about_z() {
        // 90° about z: (0, 0, sin 45°, cos 45°); log = (0, 0, π/2).
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let r = log(&[0.0, 0.0, h, h]);
        assert!(close(&r, &[0.0, 0.0, std::f64::consts::FRAC_PI_2], 1e-14));
        // Two quarter turns about z make a half turn: (0, 0, 1, 0).
        let q = mul(&[0.0, 0.0, h, h], &[0.0, 0.0, h, h]);
        assert!(close(&q, &[0.0, 0.0, 1.0, 0.0], 1e-15));
    }

    #[test]
    fn relative_round_trip() {
        let a = exp(&[0.5, -0.3, 0.2]);
        let q = exp(&[0.4, -0.1, 0.25]);
        let r = log_relative(&a, &q);
        assert!(close(&exp_relative(&a, &r), &q, 1e-14));
    }

    #[test]
    fn slerp_keeps_a_constant_angular_rate_on_the_short_arc() {
        // 0.2 → 1.6 rad about z: a quarter of the way is 0.55 rad (nlerp gives less).
        let a = exp(&[0.0, 0.0, 0.2]);
        let b = exp(&[0.0, 0.0, 1.6]);
        let q = slerp(&a, &b, 0.25);
        assert!(close(&log(&q), &[0.0, 0.0, 0.55], 1e-12), "{:?}", log(&q));
        let mb = [-b[0], -b[1], -b[2], -b[3]];
        assert!(close(&log(&slerp(&a, &mb, 0.25)), &[0.0, 0.0, 0.55], 1e-12));
        assert!((norm(&slerp(&a, &a, 0.3)) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn nlerp_takes_short_arc() {
        let a = exp(&[0.0, 0.0, 0.2]);
        let b = exp(&[0.0, 0.0, 0.4]);
        let mb = [-b[0], -b[1], -b[2], -b[3]];
        let m = nlerp(&a, &mb, 0.5);
        assert!(close(&log(&m), &[0.0, 0.0, 0.3], 1e-12));
    }
}
