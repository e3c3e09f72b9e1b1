//! Topics of different rates onto one grid: the grid over the span every topic covers, and
//! per column linear interpolation, slerp for a quaternion, or sample-and-hold for a flag.

use crate::read::Series;
use crate::{Error, GAP_FACTOR, Result};

/// A grid time within this many nanoseconds of a message's time takes that message's value
/// as it is (no interpolation): 1 µs. Message times are whole nanoseconds, so a grid laid on
/// the messages' own period (a run tandem wrote, an execution at the model's period) would
/// otherwise mix in a 1e-7 share of the neighbouring message from rounding alone.
pub const SNAP_NS: i64 = 1_000;

/// How one group of columns is resampled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Interp {
    /// Linear interpolation between the two messages around the grid time.
    Linear,
    /// The last message at or before the grid time (a flag holds until it changes).
    Hold,
    /// Four columns `x, y, z, w` of a unit quaternion: spherical linear interpolation on the
    /// shorter arc, in the earlier message's hemisphere.
    Slerp,
}

/// The grid: `n` times `t0 + round(j · period_ns)` (ns), `j = 0..n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Grid {
    /// First grid time (ns, bag time).
    pub(crate) t0_ns: i64,
    /// Grid period (ns).
    pub(crate) period_ns: f64,
    /// Number of grid times.
    pub(crate) n: usize,
}

impl Grid {
    /// Grid time `j` (ns).
    pub(crate) fn time(&self, j: usize) -> i64 {
        self.t0_ns + (j as f64 * self.period_ns).round() as i64
    }
}

/// The grid of period `period_ns` over the span all `series` cover (from the latest first
/// message to the earliest last one). `names[k]` names series `k` in errors.
///
/// # Errors
/// [`Error::Coverage`] when a topic starts later or ends earlier than the first-starting or
/// last-ending topic by more than [`GAP_FACTOR`] × its own median period;
/// [`Error::Layout`] when the span holds fewer than 2 grid times.
pub(crate) fn grid(series: &[&Series], names: &[&str], file: &str, period_ns: f64) -> Result<Grid> {
    let first = |s: &Series| s.times_ns[0];
    let last = |s: &Series| s.times_ns[s.times_ns.len() - 1];
    let (k_first, _) = series
        .iter()
        .enumerate()
        .min_by_key(|(_, s)| first(s))
        .expect("at least one series");
    let (k_last, _) = series
        .iter()
        .enumerate()
        .max_by_key(|(_, s)| last(s))
        .expect("at least one series");
    let (earliest, latest_end) = (first(series[k_first]), last(series[k_last]));
    for (k, s) in series.iter().enumerate() {
        let limit = GAP_FACTOR * s.median_ns as f64;
        let late = first(s) - earliest;
        let early = latest_end - last(s);
        for (by, starts_late, other) in [(late, true, k_first), (early, false, k_last)] {
            if by as f64 > limit {
                return Err(Error::Coverage {
                    file: file.into(),
                    topic: names[k].into(),
                    starts_late,
                    by_s: by as f64 / 1e9,
                    other: names[other].into(),
                    median_s: s.median_ns as f64 / 1e9,
                });
            }
        }
    }
    let t0_ns = series.iter().map(|s| first(s)).max().expect("non-empty");
    let t_end = series.iter().map(|s| last(s)).min().expect("non-empty");
    let span = (t_end - t0_ns) as f64;
    let n = if span < 0.0 {
        0
    } else {
        ((span + SNAP_NS as f64) / period_ns).floor() as usize + 1
    };
    let mut g = Grid {
        t0_ns,
        period_ns,
        n,
    };
    // The last grid time must not pass the span by more than the snap.
    while g.n > 0 && g.time(g.n - 1) > t_end + SNAP_NS {
        g.n -= 1;
    }
    if g.n < 2 {
        return Err(Error::Layout {
            file: file.into(),
            why: format!(
                "the selected topics overlap for {:.6} s only: fewer than 2 samples at a period \
                 of {} s",
                span.max(0.0) / 1e9,
                period_ns / 1e9
            ),
        });
    }
    Ok(g)
}

/// Resamples one series (`width` columns, resampled group by group as `plan` says: each
/// entry covers 1 column, 4 for [`Interp::Slerp`]) onto `grid`, writing its columns at
/// `offset` of every row of `out` (`grid.n` rows of `row_width`).
pub(crate) fn resample_into(
    s: &Series,
    width: usize,
    plan: &[Interp],
    grid: &Grid,
    out: &mut [f64],
    row_width: usize,
    offset: usize,
) {
    let times = &s.times_ns;
    let v = &s.values;
    let mut k = 0usize;
    for j in 0..grid.n {
        let t = grid.time(j);
        while k + 1 < times.len() && times[k + 1] <= t {
            k += 1;
        }
        let row = &mut out[j * row_width + offset..j * row_width + offset + width];
        let a = &v[k * width..(k + 1) * width];
        // Snap to a message at (or within SNAP_NS of) the grid time.
        if (t - times[k]).abs() <= SNAP_NS || k + 1 == times.len() {
            row.copy_from_slice(a);
            continue;
        }
        let b = &v[(k + 1) * width..(k + 2) * width];
        if times[k + 1] - t <= SNAP_NS {
            row.copy_from_slice(b);
            continue;
        }
        let f = (t - times[k]) as f64 / (times[k + 1] - times[k]) as f64;
        let mut c = 0;
        for interp in plan {
            match interp {
                Interp::Linear => {
                    row[c] = a[c] + f * (b[c] - a[c]);
                    c += 1;
                }
                Interp::Hold => {
                    row[c] = a[c];
                    c += 1;
                }
                Interp::Slerp => {
                    let q = slerp(&a[c..c + 4], &b[c..c + 4], f);
                    row[c..c + 4].copy_from_slice(&q);
                    c += 4;
                }
            }
        }
    }
}

/// Spherical linear interpolation from unit quaternion `a` (at `f = 0`) to `b` (at `f = 1`)
/// along the shorter arc; the result is normalized and in `a`'s hemisphere.
pub(crate) fn slerp(a: &[f64], b: &[f64], f: f64) -> [f64; 4] {
    let norm = |q: [f64; 4]| {
        let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        q.map(|x| x / n)
    };
    let a = norm([a[0], a[1], a[2], a[3]]);
    let mut b = norm([b[0], b[1], b[2], b[3]]);
    let mut dot: f64 = (0..4).map(|i| a[i] * b[i]).sum();
    if dot < 0.0 {
        b = b.map(|x| -x);
        dot = -dot;
    }
    if dot > 1.0 - 1e-12 {
        return norm([0, 1, 2, 3].map(|i| a[i] + f * (b[i] - a[i])));
    }
    let theta = dot.min(1.0).acos();
    let s = theta.sin();
    let (wa, wb) = (((1.0 - f) * theta).sin() / s, (f * theta).sin() / s);
    norm([0, 1, 2, 3].map(|i| wa * a[i] + wb * b[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn series(times: &[i64], values: &[f64]) -> Series {
        Series {
            times_ns: times.to_vec(),
            log_time: true,
            values: values.to_vec(),
            median_ns: times[1] - times[0],
            period_ns: (times[1] - times[0]) as f64,
        }
    }

    #[test]
    fn linear_hold_and_snap() {
        // Messages at 0, 10, 20 ms; grid every 5 ms.
        let s = series(
            &[0, 10_000_000, 20_000_000],
            &[0.0, 1.0, 10.0, 20.0, 4.0, 0.0],
        );
        let g = grid(&[&s], &["a"], "f", 5e6).unwrap();
        assert_eq!(g.n, 5);
        let mut out = vec![0.0; 10];
        resample_into(&s, 2, &[Interp::Linear, Interp::Hold], &g, &mut out, 2, 0);
        assert_eq!(out, [0.0, 1.0, 5.0, 1.0, 10.0, 20.0, 7.0, 20.0, 4.0, 0.0]);
    }

    #[test]
    fn a_grid_within_a_microsecond_of_the_messages_takes_their_values() {
        let s = series(&[0, 10_000_001, 20_000_000], &[0.1, 0.2, 0.3]);
        let g = grid(&[&s], &["a"], "f", 1e7).unwrap();
        let mut out = vec![0.0; 3];
        resample_into(&s, 1, &[Interp::Linear], &g, &mut out, 1, 0);
        assert_eq!(out, [0.1, 0.2, 0.3]);
    }

    #[test]
    fn slerp_halfway_is_the_half_angle_and_takes_the_short_arc() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        // Identity to 90° about z: halfway is 45° about z.
        let q = slerp(&[0.0, 0.0, 0.0, 1.0], &[0.0, 0.0, h, h], 0.5);
        let (s, c) = (
            std::f64::consts::FRAC_PI_8.sin(),
            std::f64::consts::FRAC_PI_8.cos(),
        );
        assert!(
            (q[2] - s).abs() < 1e-12 && (q[3] - c).abs() < 1e-12,
            "{q:?}"
        );
        // The same rotation given as −q: still the short way, in a's hemisphere.
        let q2 = slerp(&[0.0, 0.0, 0.0, 1.0], &[0.0, 0.0, -h, -h], 0.5);
        assert!(
            (q2[2] - s).abs() < 1e-12 && (q2[3] - c).abs() < 1e-12,
            "{q2:?}"
        );
    }

    #[test]
    fn late_topics_and_short_overlaps_are_errors() {
        const MS: i64 = 1_000_000;
        let a = series(&[0, 10 * MS, 20 * MS, 30 * MS, 40 * MS], &[0.0; 5]);
        let b = series(&[35 * MS, 45 * MS, 55 * MS], &[0.0; 3]);
        let e = grid(&[&a, &b], &["/a", "/b"], "f", 1e7).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("topic `/b` starts") && text.contains("after topic `/a`"),
            "{e}"
        );
        // Ending 9 ms early is within 3 periods of 10 ms.
        let c = series(&[0, 10 * MS, 20 * MS, 31 * MS], &[0.0; 4]);
        assert!(grid(&[&a, &c], &["/a", "/c"], "f", 1e7).is_ok());
        let e = grid(&[&a], &["/a"], "f", 5e7).unwrap_err();
        assert!(e.to_string().contains("fewer than 2 samples"), "{e}");
    }
}
