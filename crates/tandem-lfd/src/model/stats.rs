//! Per reference-sample sufficient statistics: tangent observations of aligned
//! demonstrations, batch mean and scatter (Eq. 5–6), the Welford step of an update
//! (Eq. 21), gradient bounds (Eq. 14), and the arrays derived from them.
//!
//! Storage: the tangent means are `n_ref × d` and the scatter matrices
//! `n_ref × d(d+1)/2` (packed upper triangles, row-major). A name with the suffix `_n` is
//! the slice of such an array at one reference sample `n`.

use rayon::prelude::*;

use super::layout::{Item, Layout, quat_at};
use super::{PAR_MIN_LEN, TaskModel, bracket};
use crate::demo::Demonstration;
use crate::quat::{self, Quat};

/// Length of a packed upper triangle of a `d × d` matrix.
pub(super) fn packed_len(d: usize) -> usize {
    d * (d + 1) / 2
}

/// Index of `(i, j)`, `i ≤ j`, in a packed upper triangle of a `d × d` matrix.
pub(super) fn packed_idx(d: usize, i: usize, j: usize) -> usize {
    i * d - i * i.saturating_sub(1) / 2 + (j - i)
}

/// Tangent-layout observation `x_i⁺(ψ_i(n))` of an aligned demonstration at reference
/// sample `n` into `out` (`d` values; rate = forward-difference warp gradient, the last
/// entry repeating the previous one). `anchors_n` are the anchor orientations at `n`, one
/// per quaternion block; `warp` is the demonstration's warp (demo samples per reference
/// sample, `n_ref` values).
pub(super) fn observe_at(
    layout: &Layout,
    anchors_n: &[Quat],
    demo: &Demonstration,
    warp: &[f64],
    n: usize,
    out: &mut [f64],
) {
    let demo_t = warp[n];
    let (lo, hi, alpha) = bracket(demo_t, demo.n_samples());
    let (a, b) = (demo.sample(lo), demo.sample(hi));
    let mut coord = 0;
    for item in &layout.items {
        match item {
            Item::Scalar(j) => {
                out[coord] = a[*j] + alpha * (b[*j] - a[*j]);
                coord += 1;
            }
            Item::Quat(cols, blk) => {
                let q = quat_at(demo, cols, demo_t);
                out[coord..coord + 3].copy_from_slice(&quat::log_relative(&anchors_n[*blk], &q));
                coord += 3;
            }
        }
    }
    out[coord] = if n + 1 < warp.len() {
        warp[n + 1] - warp[n]
    } else {
        warp[n] - warp[n - 1]
    };
}

/// Tangent-layout observations of one aligned demonstration, `n_ref × d`.
pub(super) fn observe(
    layout: &Layout,
    anchors: &[Quat],
    demo: &Demonstration,
    warp: &[f64],
) -> Vec<f64> {
    let (d, n_quat) = (layout.dim(), layout.n_quat);
    let mut out = vec![0.0; warp.len() * d];
    out.par_chunks_mut(d)
        .enumerate()
        .with_min_len(PAR_MIN_LEN)
        .for_each(|(n, x)| {
            let anchors_n = &anchors[n * n_quat..(n + 1) * n_quat];
            observe_at(layout, anchors_n, demo, warp, n, x);
        });
    out
}

/// The default range of the rate coordinate (demo samples per reference sample): the largest
/// speed-up the alignment admits, `s_max − 1` (normalized time, [`tandem_warp::WarpParams`];
/// 3 at its default), at the demonstrations' mean pace (the mean warp gradient over every
/// observation of `obs`, one `n_ref × d` array per demonstration, rate last). With
/// [`rate_terms`]' weighting the rate's term of `σ²_D` is then the squared coefficient of
/// variation of the demonstrations' speeds over `(s_max − 1)²`, whichever demonstration is
/// the reference (docs/decisions.md, "Fit defaults on the task zoo: the rate term").
pub(super) fn default_rate_range(
    obs: &[Vec<f64>],
    d: usize,
    warp: &tandem_warp::WarpParams,
) -> f64 {
    let mut paces: Vec<f64> = obs
        .iter()
        .flat_map(|o| o.iter().skip(d - 1).step_by(d).copied())
        .collect();
    // Summed in ascending order: the same bits for any order of the demonstrations.
    paces.sort_by(f64::total_cmp);
    let mean_pace = paces.iter().sum::<f64>() / paces.len() as f64;
    (warp.slope_max - 1.0) * mean_pace
}

/// The statistics of a set of aligned demonstrations, every array per reference sample.
pub(super) struct BatchStats {
    /// `n_ref × d` tangent means.
    pub(super) tangent_mean: Vec<f64>,
    /// `n_ref × d(d+1)/2` packed scatter matrices `Σ_i e_i e_iᵀ`.
    pub(super) scatter: Vec<f64>,
    /// `ψ̇min(n)` (Eq. 14).
    pub(super) grad_min: Vec<f64>,
    /// `ψ̇max(n)` (Eq. 14).
    pub(super) grad_max: Vec<f64>,
}

/// Two-pass batch statistics (Eq. 5, 6, 14) of the tangent observations `obs` (one
/// `n_ref × d` array per demonstration).
pub(super) fn batch_statistics(obs: &[Vec<f64>], n_ref: usize, d: usize) -> BatchStats {
    let n_demos = obs.len();
    let pl = packed_len(d);
    let mut tangent_mean = vec![0.0; n_ref * d];
    let mut scatter = vec![0.0; n_ref * pl];
    let mut grad_min = vec![f64::INFINITY; n_ref];
    let mut grad_max = vec![f64::NEG_INFINITY; n_ref];
    tangent_mean
        .par_chunks_mut(d)
        .zip(scatter.par_chunks_mut(pl))
        .zip(grad_min.par_iter_mut().zip(grad_max.par_iter_mut()))
        .enumerate()
        .for_each(|(n, ((mean_n, scatter_n), (gmin, gmax)))| {
            for o in obs {
                let x = &o[n * d..(n + 1) * d];
                for (mu, v) in mean_n.iter_mut().zip(x) {
                    *mu += v;
                }
                *gmin = gmin.min(x[d - 1]);
                *gmax = gmax.max(x[d - 1]);
            }
            for mu in mean_n.iter_mut() {
                *mu /= n_demos as f64;
            }
            let mut e = vec![0.0; d];
            for o in obs {
                for (coord, ec) in e.iter_mut().enumerate() {
                    *ec = o[n * d + coord] - mean_n[coord];
                }
                let mut p = 0;
                for (i, &ei) in e.iter().enumerate() {
                    for ej in &e[i..] {
                        scatter_n[p] += ei * ej;
                        p += 1;
                    }
                }
            }
        });
    BatchStats {
        tangent_mean,
        scatter,
        grad_min,
        grad_max,
    }
}

/// The Welford step of one new observation `x` at one reference sample (Eq. 21): updates
/// the tangent mean and the packed scatter from `count` to `count + 1` observations.
/// `delta` is scratch of length `d`.
pub(super) fn welford_add(
    x: &[f64],
    count: usize,
    mean_n: &mut [f64],
    scatter_n: &mut [f64],
    delta: &mut [f64],
) {
    let new_count = count as f64 + 1.0;
    let (inv_count, factor) = (1.0 / new_count, count as f64 / new_count);
    for coord in 0..x.len() {
        delta[coord] = x[coord] - mean_n[coord];
        mean_n[coord] += delta[coord] * inv_count;
    }
    let mut p = 0;
    for (i, &di) in delta.iter().enumerate() {
        let di = di * factor;
        for dj in &delta[i..] {
            scatter_n[p] += di * dj;
            p += 1;
        }
    }
}

/// Derived values at one reference sample from its statistics: the physical mean into
/// `out` (`m` values, quaternions `anchor ⊗ exp(r̄)`), and returns (mean rate, the channels'
/// part of `σ²_D`) with that part `Σ_{j < d−1} scatter_jj / r_j² / denom` (Eq. 6,
/// `denom = n − 1`; `inv_w[j] = 1/r_j²`): every coordinate but the rate, whose term
/// [`rate_terms`] adds.
pub(super) fn derive_at(
    layout: &Layout,
    anchors_n: &[Quat],
    inv_w: &[f64],
    denom: f64,
    mean_n: &[f64],
    scatter_n: &[f64],
    out: &mut [f64],
) -> (f64, f64) {
    let d = mean_n.len();
    let mut coord = 0;
    for item in &layout.items {
        match item {
            Item::Scalar(j) => {
                out[*j] = mean_n[coord];
                coord += 1;
            }
            Item::Quat(cols, blk) => {
                let r = [mean_n[coord], mean_n[coord + 1], mean_n[coord + 2]];
                let q = quat::exp_relative(&anchors_n[*blk], &r);
                for (c, v) in cols.iter().zip(q) {
                    out[*c] = v;
                }
                coord += 3;
            }
        }
    }
    let s2 = (0..d - 1)
        .map(|i| scatter_n[packed_idx(d, i, i)] * inv_w[i])
        .sum::<f64>()
        / denom;
    (mean_n[d - 1], s2)
}

/// The mean pace `ψ̄̇₀` (mean warp gradient over the reference) and the local pace
/// `ψ̄̇(n)` of the statistics (`tangent_mean`, `n_ref × d`, rate last).
fn paces(tangent_mean: &[f64], d: usize) -> (Vec<f64>, f64) {
    let pace: Vec<f64> = tangent_mean
        .iter()
        .skip(d - 1)
        .step_by(d)
        .copied()
        .collect();
    let mean_pace = pace.iter().sum::<f64>() / pace.len() as f64;
    (pace, mean_pace)
}

/// The rate's term of `σ²_D` per reference sample, [`RateTerm::Relative`](super::RateTerm):
/// the variance of the warp gradients relative to the local mean pace,
/// `var_n(ψ̇) / (r_rate · ψ̄̇(n) / ψ̄̇₀)²` with `ψ̄̇₀` the mean of `ψ̄̇` over the reference (so
/// the rate range `r_rate` counts at the task's mean pace, and a speed difference of 10 %
/// weighs the same wherever the reference itself was fast or slow), then opened (a running
/// minimum, then a running maximum, over `opening` samples): a rise of the term narrower
/// than the alignment can place a change of speed is removed, a wider one kept as it is.
///
/// `scatter`, `tangent_mean`: the model's statistics (`n_ref` rows); `denom = n − 1`.
pub(super) fn rate_terms(
    scatter: &[f64],
    tangent_mean: &[f64],
    d: usize,
    rate_range: f64,
    denom: f64,
    opening: usize,
) -> Vec<f64> {
    let pl = packed_len(d);
    let (pace, mean_pace) = paces(tangent_mean, d);
    let raw: Vec<f64> = pace
        .iter()
        .enumerate()
        .map(|(n, &p)| {
            let var = scatter[n * pl + packed_idx(d, d - 1, d - 1)] / denom;
            // A pace of 0 (or a mean pace of 0, no demonstrated motion) falls back to the
            // range as given.
            let local = if p > 0.0 && mean_pace > 0.0 {
                rate_range * p / mean_pace
            } else {
                rate_range
            };
            var / (local * local)
        })
        .collect();
    let eroded = running(&raw, opening / 2, f64::min);
    running(&eroded, opening / 2, f64::max)
}

/// The reference samples `[a, b]` of the duration window of width `window` around `n`
/// (clipped to the reference's `n_ref` samples).
fn window_at(n: usize, window: usize, n_ref: usize) -> (usize, usize) {
    let h = window / 2;
    (n.saturating_sub(h), (n + h).min(n_ref - 1))
}

/// Per reference sample the time (demo samples) a warp spent on the duration window of
/// width `window` around it: `ψ(b) − ψ(a)` ([`window_at`]).
pub(super) fn window_durations(warp: &[f64], window: usize) -> Vec<f64> {
    (0..warp.len())
        .map(|n| {
            let (a, b) = window_at(n, window, warp.len());
            warp[b] - warp[a]
        })
        .collect()
}

/// Two-pass mean and scatter (sum of squared deviations) per reference sample of the
/// window durations of `warps` ([`window_durations`]).
pub(super) fn duration_statistics(warps: &[Vec<f64>], window: usize) -> (Vec<f64>, Vec<f64>) {
    let durations: Vec<Vec<f64>> = warps
        .par_iter()
        .map(|w| window_durations(w, window))
        .collect();
    let n_ref = warps[0].len();
    let count = durations.len() as f64;
    (0..n_ref)
        .into_par_iter()
        .map(|n| {
            let mean = durations.iter().map(|d| d[n]).sum::<f64>() / count;
            let scatter = durations.iter().map(|d| (d[n] - mean).powi(2)).sum::<f64>();
            (mean, scatter)
        })
        .unzip()
}

/// The duration term of `σ²_D` per reference sample ([`RateTerm::Relative`](super::RateTerm)
/// with a window): the variance over the demonstrations and executions of the time each
/// spent on the window around the sample, relative to its mean as the rate term weighs a
/// pace, `var_n(D) / (r_rate · D̄(n) / ψ̄̇₀)²` (a window of `k` steps spent at the mean pace
/// everywhere has `D̄ = k·ψ̄̇₀`, and the term is then the rate term of the window's mean
/// speed). Where a variable stretch was absorbed by the alignment as one steep step of
/// some warps, the per-sample rate term sees a rise narrower than its opening and drops it;
/// the window durations see the whole difference wherever in the window it was placed.
pub(super) fn duration_terms(
    duration_mean: &[f64],
    duration_scatter: &[f64],
    tangent_mean: &[f64],
    d: usize,
    rate_range: f64,
    denom: f64,
    window: usize,
) -> Vec<f64> {
    let (_, mean_pace) = paces(tangent_mean, d);
    let n_ref = duration_mean.len();
    (0..n_ref)
        .map(|n| {
            let var = duration_scatter[n] / denom;
            let (a, b) = window_at(n, window, n_ref);
            let local = if duration_mean[n] > 0.0 && mean_pace > 0.0 {
                rate_range * duration_mean[n] / mean_pace
            } else {
                rate_range * (b - a).max(1) as f64
            };
            var / (local * local)
        })
        .collect()
}

/// `out[n] = fold(v[n − h..=n + h])` (clipped at the ends) for an associative, commutative
/// `fold` such as `f64::min`.
fn running(v: &[f64], h: usize, fold: fn(f64, f64) -> f64) -> Vec<f64> {
    (0..v.len())
        .map(|n| {
            v[n.saturating_sub(h)..(n + h + 1).min(v.len())]
                .iter()
                .copied()
                .reduce(fold)
                .expect("a window holds its centre")
        })
        .collect()
}

impl TaskModel {
    /// `1/r_j²` per tangent coordinate (the diagonal of `W⁺`, Eq. 6).
    pub(super) fn inverse_weights(&self) -> Vec<f64> {
        self.data.ranges.iter().map(|r| 1.0 / (r * r)).collect()
    }

    /// Recomputes the physical mean, mean gradient and `σ²_D` from the statistics.
    pub(super) fn refresh_derived(&mut self) {
        let inv_w = self.inverse_weights();
        let data = &self.data;
        let (n_ref, d, m) = (data.n_ref, data.layout.dim(), data.channel_names.len());
        let n_quat = data.layout.n_quat;
        let pl = packed_len(d);
        let mut mean = std::mem::take(&mut self.mean);
        let mut grad_mean = std::mem::take(&mut self.grad_mean);
        let mut sigma2 = std::mem::take(&mut self.sigma2_d);
        mean.resize(n_ref * m, 0.0);
        grad_mean.resize(n_ref, 0.0);
        sigma2.resize(n_ref, 0.0);
        let denom = (data.count - 1) as f64;
        mean.par_chunks_mut(m)
            .zip(grad_mean.par_iter_mut().zip(sigma2.par_iter_mut()))
            .enumerate()
            .with_min_len(PAR_MIN_LEN)
            .for_each(|(n, (out, (g, s2)))| {
                let mean_n = &data.tangent_mean[n * d..(n + 1) * d];
                let scatter_n = &data.scatter[n * pl..(n + 1) * pl];
                let anchors_n = &data.anchors[n * n_quat..(n + 1) * n_quat];
                (*g, *s2) = derive_at(
                    &data.layout,
                    anchors_n,
                    &inv_w,
                    denom,
                    mean_n,
                    scatter_n,
                    out,
                );
            });
        self.mean = mean;
        self.grad_mean = grad_mean;
        self.sigma2_d = sigma2;
        self.add_rate_terms();
    }

    /// The rate's part of `σ²_D` per reference sample, as the model's
    /// [`RateTerm`](super::RateTerm) says: `var_n(ψ̇)/r_rate²` (absolute), or the relative
    /// term ([`rate_terms`]), with a duration window the larger of it and the duration term
    /// ([`duration_terms`]).
    pub(super) fn rate_part(&self) -> Vec<f64> {
        let data = &self.data;
        let d = data.layout.dim();
        let pl = packed_len(d);
        let rate_range = data.ranges[d - 1];
        let denom = (data.count - 1) as f64;
        match data.rate_term {
            super::RateTerm::Absolute => {
                // The models saved before the relative term: `var_n(ψ̇) / r_rate²` per sample.
                let inv = 1.0 / (rate_range * rate_range * denom);
                (0..data.n_ref)
                    .map(|n| data.scatter[n * pl + packed_idx(d, d - 1, d - 1)] * inv)
                    .collect()
            }
            super::RateTerm::Relative { opening, window } => {
                let mut terms = rate_terms(
                    &data.scatter,
                    &data.tangent_mean,
                    d,
                    rate_range,
                    denom,
                    opening,
                );
                if window > 0 {
                    let durations = duration_terms(
                        &data.duration_mean,
                        &data.duration_scatter,
                        &data.tangent_mean,
                        d,
                        rate_range,
                        denom,
                        window,
                    );
                    for (t, u) in terms.iter_mut().zip(durations) {
                        *t = t.max(u);
                    }
                }
                terms
            }
        }
    }

    /// Adds the rate's part ([`TaskModel::rate_part`]) to `σ²_D`, whose channels' part
    /// [`derive_at`] wrote.
    pub(super) fn add_rate_terms(&mut self) {
        let part = self.rate_part();
        for (s2, t) in self.sigma2_d.iter_mut().zip(part) {
            *s2 += t;
        }
    }

    /// Mean tangent statistics at reference sample `n` (`d` values; rotation vectors
    /// relative to the anchor; rate last). Panics if `n ≥ n_ref()`.
    pub fn tangent_mean(&self, n: usize) -> &[f64] {
        let d = self.data.layout.dim();
        &self.data.tangent_mean[n * d..(n + 1) * d]
    }

    /// Sample covariance (`scatter / (n − 1)`) of the tangent coordinates at reference
    /// sample `n`, row-major `d × d`. Panics if `n ≥ n_ref()`.
    pub fn covariance(&self, n: usize) -> Vec<f64> {
        let d = self.data.layout.dim();
        let scatter_n = &self.data.scatter[n * packed_len(d)..(n + 1) * packed_len(d)];
        let denom = (self.data.count - 1) as f64;
        let mut c = vec![0.0; d * d];
        for i in 0..d {
            for j in i..d {
                let v = scatter_n[packed_idx(d, i, j)] / denom;
                c[i * d + j] = v;
                c[j * d + i] = v;
            }
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packed_index_matches_row_major_upper() {
        let d = 4;
        let mut p = 0;
        for i in 0..d {
            for j in i..d {
                assert_eq!(packed_idx(d, i, j), p);
                p += 1;
            }
        }
        assert_eq!(p, packed_len(d));
    }
}
