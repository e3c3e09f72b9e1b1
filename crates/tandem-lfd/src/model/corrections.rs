//! Admissible corrections (§II-B2) and the command (Eq. 7).
//!
//! Per reference sample, the eigen-decomposition of the range-scaled scatter matrix
//! `D·S·D`, `D = diag(1/r)` (the principal components of the weighted augmented residuals);
//! `K = min(n − 1, k_max, d)` components, each stored as a ±3σ displacement
//! `c_k = 3·s_k/√n · v_k ⊙ r`, signs kept continuous in time. A name with the suffix `_t`
//! is a value interpolated at one fractional reference time `t`.

use nalgebra::{DMatrix, SymmetricEigen};
use rayon::prelude::*;

use super::layout::Item;
use super::stats::{packed_idx, packed_len};
use super::{TaskModel, bracket};
use crate::quat;
use crate::{Error, Result};

/// Per reference sample correction directions, `K × d` each, sign-continuous.
#[derive(Clone, Debug)]
pub(super) struct CorrectionTable {
    /// Number of components `K`.
    k: usize,
    /// `n_ref × K × d`: `c_k(n)` in physical tangent units.
    components: Vec<f64>,
}

/// The admissible corrections at one (fractional) reference time.
#[derive(Clone, Debug, PartialEq)]
pub struct Corrections {
    /// The admissible scale `a ∈ [0, 1]`: the largest factor for which
    /// `μ̂⁺ + a·Σ_k u_k c_k` keeps its rate inside `[ψ̇min, ψ̇max]` for every `u ∈ [−1, 1]^K`.
    pub scale: f64,
    /// The unscaled components `c_k`, one `d`-vector per component in the tangent layout
    /// ([`TaskModel::tangent_names`]): `3·s_k/√n · v_k ⊙ r`, a ±3σ displacement in
    /// physical units (rotation vectors in radians, rate in demo samples per reference
    /// sample).
    pub components: Vec<Vec<f64>>,
}

impl TaskModel {
    /// Number of correction components `K = min(n − 1, k_max, d)`.
    pub fn n_components(&self) -> usize {
        (self.data.count - 1)
            .min(self.data.k_max)
            .min(self.data.layout.dim())
    }

    /// Computes the correction directions now if they are not cached (they are otherwise
    /// computed on the first call that needs them, after a fit, load or update).
    pub fn prepare_corrections(&self) {
        self.table();
    }

    fn table(&self) -> &CorrectionTable {
        self.corrections.get_or_init(|| self.compute_corrections())
    }

    fn compute_corrections(&self) -> CorrectionTable {
        let data = &self.data;
        let d = data.layout.dim();
        let pl = packed_len(d);
        let k_n = self.n_components();
        let count = data.count as f64;
        // Per sample eigen-decomposition of the scaled scatter D·S·D, D = diag(1/r).
        let per_sample: Vec<(Vec<f64>, Vec<f64>)> = (0..data.n_ref)
            .into_par_iter()
            .map(|n| {
                let scatter_n = &data.scatter[n * pl..(n + 1) * pl];
                let mut scaled = DMatrix::<f64>::zeros(d, d);
                for i in 0..d {
                    for j in i..d {
                        let v = scatter_n[packed_idx(d, i, j)] / (data.ranges[i] * data.ranges[j]);
                        scaled[(i, j)] = v;
                        scaled[(j, i)] = v;
                    }
                }
                let eig = SymmetricEigen::new(scaled);
                let mut order: Vec<usize> = (0..d).collect();
                order.sort_by(|&x, &y| eig.eigenvalues[y].total_cmp(&eig.eigenvalues[x]));
                let mut sig = Vec::with_capacity(k_n);
                let mut vecs = Vec::with_capacity(k_n * d);
                for &o in order.iter().take(k_n) {
                    sig.push(3.0 * (eig.eigenvalues[o].max(0.0) / count).sqrt());
                    vecs.extend(eig.eigenvectors.column(o).iter().copied());
                }
                (sig, vecs)
            })
            .collect();
        // Sign continuity (sequential), then scale to physical units.
        let mut components = vec![0.0; data.n_ref * k_n * d];
        let mut prev: Vec<f64> = vec![0.0; k_n * d];
        for (n, (sig, vecs)) in per_sample.iter().enumerate() {
            let rate_fixed = data.grad_max[n] <= data.grad_min[n];
            for k in 0..k_n {
                let v = &vecs[k * d..(k + 1) * d];
                let flip = if n == 0 {
                    // Convention: the largest-magnitude entry is positive.
                    let big = v
                        .iter()
                        .copied()
                        .fold(0.0f64, |acc, x| if x.abs() > acc.abs() { x } else { acc });
                    big < 0.0
                } else {
                    v.iter()
                        .zip(&prev[k * d..(k + 1) * d])
                        .map(|(a, b)| a * b)
                        .sum::<f64>()
                        < 0.0
                };
                let s = if flip { -1.0 } else { 1.0 };
                let out = &mut components[(n * k_n + k) * d..(n * k_n + k + 1) * d];
                for j in 0..d {
                    prev[k * d + j] = s * v[j];
                    out[j] = s * sig[k] * v[j] * data.ranges[j];
                }
                if rate_fixed {
                    out[d - 1] = 0.0;
                }
            }
        }
        CorrectionTable { k: k_n, components }
    }

    fn check_ref_time(&self, ref_time: f64) -> Result<()> {
        let last = (self.data.n_ref - 1) as f64;
        if !(ref_time.is_finite() && (0.0..=last).contains(&ref_time)) {
            return Err(Error::BadParam {
                name: "ref_time",
                why: format!("{ref_time} is outside [0, {last}] reference samples"),
            });
        }
        Ok(())
    }

    /// The admissible scale `a` at `(lo, hi, alpha)` for the interpolated components
    /// `comps_t` (`K × d`), from the interpolated mean rate and bounds.
    fn scale_at(&self, lo: usize, hi: usize, alpha: f64, comps_t: &[f64]) -> f64 {
        let lerp = |v: &[f64]| v[lo] + alpha * (v[hi] - v[lo]);
        let (g, gmin, gmax) = (
            lerp(&self.grad_mean),
            lerp(&self.data.grad_min),
            lerp(&self.data.grad_max),
        );
        let d = self.data.layout.dim();
        let reach: f64 = comps_t.chunks_exact(d).map(|c| c[d - 1].abs()).sum();
        if reach <= 0.0 {
            return 1.0;
        }
        ((gmax - g) / reach).min((g - gmin) / reach).clamp(0.0, 1.0)
    }

    /// Interpolated components at `(lo, hi, alpha)` into `comps_t` (`K × d`).
    fn comps_at(&self, lo: usize, hi: usize, alpha: f64, comps_t: &mut [f64]) {
        let table = self.table();
        let kd = table.k * self.data.layout.dim();
        let a = &table.components[lo * kd..(lo + 1) * kd];
        let b = &table.components[hi * kd..(hi + 1) * kd];
        for ((o, x), y) in comps_t.iter_mut().zip(a).zip(b) {
            *o = x + alpha * (y - x);
        }
    }

    /// The admissible corrections at fractional reference time `ref_time` (reference
    /// samples): components interpolated linearly between neighbouring samples, and the
    /// admissible scale computed from the interpolated mean rate and bounds.
    ///
    /// # Errors
    /// [`Error::BadParam`] if `ref_time` is outside `[0, n_ref − 1]`.
    pub fn corrections_at(&self, ref_time: f64) -> Result<Corrections> {
        self.check_ref_time(ref_time)?;
        let (lo, hi, alpha) = bracket(ref_time, self.data.n_ref);
        let d = self.data.layout.dim();
        let k = self.n_components();
        let mut comps_t = vec![0.0; k * d];
        self.comps_at(lo, hi, alpha, &mut comps_t);
        Ok(Corrections {
            scale: self.scale_at(lo, hi, alpha, &comps_t),
            components: comps_t.chunks_exact(d).map(<[f64]>::to_vec).collect(),
        })
    }

    /// The command `x_f⁺(u, t) = μ̂⁺(t) + δx⁺(u, t)` (Eq. 7) at fractional reference time
    /// `ref_time` for operator input `u ∈ [−1, 1]^K`: `m` channel values in channel order
    /// (quaternions as `mean ⊗ exp(δ)`, unit-norm) followed by the rate (demo samples per
    /// reference sample), which stays inside `[ψ̇min(t), ψ̇max(t)]`.
    ///
    /// # Errors
    /// As [`TaskModel::command_into`].
    pub fn command(&self, u: &[f64], ref_time: f64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; self.data.channel_names.len() + 1];
        self.command_into(u, ref_time, &mut out)?;
        Ok(out)
    }

    /// [`TaskModel::command`] into a caller buffer of length `m + 1`. Does not allocate
    /// once the corrections are prepared (at most `k_max · d ≤ 64` values; larger use the heap).
    ///
    /// # Errors
    /// [`Error::BadParam`] for `ref_time` outside `[0, n_ref − 1]`, `u` of the wrong length
    /// or outside `[−1, 1]`, or `out` of the wrong length.
    pub fn command_into(&self, u: &[f64], ref_time: f64, out: &mut [f64]) -> Result<()> {
        self.check_ref_time(ref_time)?;
        let k = self.n_components();
        let d = self.data.layout.dim();
        let m = self.data.channel_names.len();
        if u.len() != k {
            return Err(Error::BadParam {
                name: "u",
                why: format!("has {} entries, the model has {k} components", u.len()),
            });
        }
        if let Some(v) = u
            .iter()
            .find(|v| !(v.is_finite() && (-1.0..=1.0).contains(*v)))
        {
            return Err(Error::BadParam {
                name: "u",
                why: format!("entry {v} is outside [-1, 1]"),
            });
        }
        if out.len() != m + 1 {
            return Err(Error::BadParam {
                name: "out",
                why: format!("has length {}, expected m + 1 = {}", out.len(), m + 1),
            });
        }
        let (lo, hi, alpha) = bracket(ref_time, self.data.n_ref);
        let mut stack = [0.0; 64];
        let mut heap = Vec::new();
        let comps_t: &mut [f64] = if k * d <= 64 {
            &mut stack[..k * d]
        } else {
            heap.resize(k * d, 0.0);
            &mut heap
        };
        self.comps_at(lo, hi, alpha, comps_t);
        let scale = self.scale_at(lo, hi, alpha, comps_t);
        let delta = |coord: usize| -> f64 {
            scale
                * (0..k)
                    .map(|kk| u[kk] * comps_t[kk * d + coord])
                    .sum::<f64>()
        };
        let lerp =
            |v: &[f64], w: usize, j: usize| v[lo * w + j] + alpha * (v[hi * w + j] - v[lo * w + j]);
        let mut coord = 0;
        for item in &self.data.layout.items {
            match item {
                Item::Scalar(j) => {
                    out[*j] = lerp(&self.mean, m, *j) + delta(coord);
                    coord += 1;
                }
                Item::Quat(cols, _) => {
                    let qa = cols.map(|c| self.mean[lo * m + c]);
                    let qb = cols.map(|c| self.mean[hi * m + c]);
                    let q = quat::nlerp(&qa, &qb, alpha);
                    let r = [delta(coord), delta(coord + 1), delta(coord + 2)];
                    let qc = quat::exp_relative(&q, &r);
                    for (c, v) in cols.iter().zip(qc) {
                        out[*c] = v;
                    }
                    coord += 3;
                }
            }
        }
        let gmin = lerp(&self.data.grad_min, 1, 0);
        let gmax = lerp(&self.data.grad_max, 1, 0);
        out[m] = (lerp(&self.grad_mean, 1, 0) + delta(d - 1)).clamp(gmin, gmax);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{close, demo, three_demo_model};
    use super::*;
    use crate::FitParams;

    #[test]
    fn hand_derived_correction_and_scale() {
        // Two demos, same force, gradients 1 and 2 (demo 1 twice as slow).
        let d0 = demo(&["force"], vec![0.0, 10.0, 20.0]);
        let d1 = demo(&["force"], vec![0.0, 5.0, 10.0, 15.0, 20.0]);
        let warps = vec![vec![0.0, 1.0, 2.0], vec![0.0, 2.0, 4.0]];
        let model = TaskModel::fit_aligned(&[d0, d1], &warps, &FitParams::default()).unwrap();
        assert_eq!(model.n_components(), 1);
        // Scaled scatter diag(0, 0.5) → s = √0.5, v = (0, 1); c = 3·√0.5/√2·(0, 1)⊙(20, 1).
        let c = model.corrections_at(1.0).unwrap();
        assert!(close(c.components[0][0], 0.0));
        assert!(close(c.components[0][1], 1.5));
        // Mean rate 1.5 in [1, 2], reach 1.5 → a = 0.5 / 1.5.
        assert!(close(c.scale, 1.0 / 3.0));
        let up = model.command(&[1.0], 1.0).unwrap();
        let down = model.command(&[-1.0], 1.0).unwrap();
        assert!(close(up[0], 10.0) && close(up[1], 2.0));
        assert!(close(down[0], 10.0) && close(down[1], 1.0));
        // Fractional reference time interpolates the mean.
        assert!(close(model.command(&[0.0], 0.25).unwrap()[0], 2.5));
    }

    #[test]
    fn identical_demos_give_zero_variance_and_no_correction() {
        let d = demo(
            &["x", "force"],
            vec![0.0, 1.0, 0.5, 3.0, 1.0, 2.0, 1.5, 0.0],
        );
        let id: Vec<f64> = (0..4).map(f64::from).collect();
        let model = TaskModel::fit_aligned(
            &[d.clone(), d.clone(), d],
            &[id.clone(), id.clone(), id],
            &FitParams::default(),
        )
        .unwrap();
        assert!(model.sigma2_d().iter().all(|&s| s == 0.0));
        for t in [0.0, 0.7, 2.0, 3.0] {
            let c = model.corrections_at(t).unwrap();
            assert!(c.components.iter().flatten().all(|&v| v == 0.0));
            let mean = model.command(&[0.0, 0.0], t).unwrap();
            assert_eq!(model.command(&[1.0, -1.0], t).unwrap(), mean);
        }
    }

    #[test]
    fn bad_commands_are_errors() {
        let model = three_demo_model();
        assert!(model.command(&[2.0, 0.0], 1.0).is_err());
        assert!(model.command(&[0.0], 1.0).is_err());
        assert!(model.command(&[0.0, 0.0], 2.5).is_err());
        assert!(model.command(&[0.0, f64::NAN], 1.0).is_err());
    }
}
