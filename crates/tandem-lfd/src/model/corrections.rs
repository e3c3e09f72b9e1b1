//! Admissible corrections (§II-B2) and the command (Eq. 7).
//!
//! Per reference sample, the eigen-decomposition of the range-scaled scatter matrix
//! `D·S·D`, `D = diag(1/r)` (the principal components of the weighted augmented residuals);
//! `K = min(n − 1, k_max, d)` components, each stored as a ±3σ displacement
//! `c_k = 3·s_k/√n · v_k ⊙ r`, signs kept continuous in time. A name with the suffix `_t`
//! is a value interpolated at one fractional reference time `t`.
//!
//! Each sample is decomposed when first needed and cached until the next fit, load or
//! update. Two sign frames: the *task* frame ([`TaskModel::corrections_at`],
//! [`TaskModel::command_into`]) continues every sign from the first reference sample, which
//! needs every sample; the *local* frame ([`TaskModel::local_corrections_at`],
//! [`TaskModel::local_command_into`]) fixes the signs from the two samples around `t`. The
//! relative sign of two neighbours is the same in both (the sign of the dot product of
//! their eigenvectors; where it is 0 or not finite the local frame takes the task frame's),
//! so a component of one frame is the other's or its negation, exactly.

use std::sync::OnceLock;

use nalgebra::{DMatrix, SMatrix, SymmetricEigen};
use rayon::prelude::*;

use super::layout::Item;
use super::stats::{packed_idx, packed_len};
use super::{TaskModel, bracket};
use crate::quat;
use crate::{Error, Result};

/// The `K` leading eigenpairs of one reference sample's scaled scatter `D·S·D`, as the
/// decomposition returns them (each eigenvector's sign arbitrary).
#[derive(Clone, Debug)]
struct Eigenpairs {
    /// `3·s_k/√n` per component, largest eigenvalue first.
    sig: Box<[f64]>,
    /// `K × d` unit eigenvectors, one row per component, in the order of `sig`.
    vecs: Box<[f64]>,
}

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

/// The correction directions of one version of the statistics, computed on demand: each
/// reference sample's eigenpairs when a command or correction first needs that sample, the
/// sign-continuous table of every sample when first asked for. A fit, load or update starts
/// a new, empty cache.
#[derive(Clone, Debug)]
pub(super) struct CorrectionCache {
    /// One entry per reference sample.
    samples: Box<[OnceLock<Eigenpairs>]>,
    table: OnceLock<CorrectionTable>,
}

impl CorrectionCache {
    /// An empty cache for `n_ref` reference samples.
    pub(super) fn new(n_ref: usize) -> Self {
        Self {
            samples: (0..n_ref).map(|_| OnceLock::new()).collect(),
            table: OnceLock::new(),
        }
    }
}

/// Eigenvalues and column-major eigenvectors of the symmetric `$d × $d` matrix `$a(i, j)` in
/// fixed-size storage on the stack: the same arithmetic as the dynamic form, without its heap.
macro_rules! eigen_fixed {
    ($d:literal, $a:expr) => {{
        let eig = SymmetricEigen::new(SMatrix::<f64, $d, $d>::from_fn($a));
        (
            eig.eigenvalues.as_slice().to_vec(),
            eig.eigenvectors.as_slice().to_vec(),
        )
    }};
}

/// Eigenvalues and column-major eigenvectors of the symmetric `d × d` matrix `a(i, j)`:
/// fixed-size storage for `d ≤ 12`, heap storage beyond.
fn eigen(d: usize, a: impl Fn(usize, usize) -> f64) -> (Vec<f64>, Vec<f64>) {
    match d {
        1 => eigen_fixed!(1, a),
        2 => eigen_fixed!(2, a),
        3 => eigen_fixed!(3, a),
        4 => eigen_fixed!(4, a),
        5 => eigen_fixed!(5, a),
        6 => eigen_fixed!(6, a),
        7 => eigen_fixed!(7, a),
        8 => eigen_fixed!(8, a),
        9 => eigen_fixed!(9, a),
        10 => eigen_fixed!(10, a),
        11 => eigen_fixed!(11, a),
        12 => eigen_fixed!(12, a),
        _ => eigen_dynamic(d, a),
    }
}

/// [`eigen`] with heap storage (any `d`).
fn eigen_dynamic(d: usize, a: impl Fn(usize, usize) -> f64) -> (Vec<f64>, Vec<f64>) {
    let eig = SymmetricEigen::new(DMatrix::from_fn(d, d, a));
    (
        eig.eigenvalues.as_slice().to_vec(),
        eig.eigenvectors.as_slice().to_vec(),
    )
}

/// Sign convention of the first reference sample: an eigenvector is negated when its
/// largest-magnitude entry (the first of equal magnitudes) is negative.
fn first_sample_flip(v: &[f64]) -> bool {
    let big = v
        .iter()
        .copied()
        .fold(0.0f64, |acc, x| if x.abs() > acc.abs() { x } else { acc });
    big < 0.0
}

/// `Σ_j a_j·b_j`, summed in index order.
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>()
}

impl TaskModel {
    /// Number of correction components `K = min(n − 1, k_max, d)`.
    pub fn n_components(&self) -> usize {
        (self.data.count - 1)
            .min(self.data.k_max)
            .min(self.data.layout.dim())
    }

    /// Computes the correction directions now if they are not cached (they are otherwise
    /// computed on the first call that needs them, after a fit, load or update): the
    /// decomposition of every reference sample and the sign-continuous table.
    pub fn prepare_corrections(&self) {
        self.table();
    }

    fn table(&self) -> &CorrectionTable {
        self.corrections
            .table
            .get_or_init(|| self.compute_corrections())
    }

    /// The eigenpairs of reference sample `n`, decomposed on first use.
    fn eigenpairs(&self, n: usize) -> &Eigenpairs {
        self.corrections.samples[n].get_or_init(|| self.decompose(n))
    }

    /// Eigen-decomposition of the scaled scatter `D·S·D`, `D = diag(1/r)`, at reference
    /// sample `n`: its `K` leading eigenpairs.
    fn decompose(&self, n: usize) -> Eigenpairs {
        let data = &self.data;
        let d = data.layout.dim();
        let pl = packed_len(d);
        let k_n = self.n_components();
        let count = data.count as f64;
        let scatter_n = &data.scatter[n * pl..(n + 1) * pl];
        let (values, vectors) = eigen(d, |i, j| {
            let (i, j) = (i.min(j), i.max(j));
            scatter_n[packed_idx(d, i, j)] / (data.ranges[i] * data.ranges[j])
        });
        let mut order: Vec<usize> = (0..d).collect();
        order.sort_by(|&x, &y| values[y].total_cmp(&values[x]));
        let mut sig = Vec::with_capacity(k_n);
        let mut vecs = Vec::with_capacity(k_n * d);
        for &o in order.iter().take(k_n) {
            sig.push(3.0 * (values[o].max(0.0) / count).sqrt());
            vecs.extend_from_slice(&vectors[o * d..(o + 1) * d]);
        }
        Eigenpairs {
            sig: sig.into(),
            vecs: vecs.into(),
        }
    }

    /// Component `k` of sample `n` with sign `s` (±1) into `out` (`d` values): the ±3σ
    /// displacement `s·3·s_k/√n · v_k ⊙ r`, rate entry 0 where the rate is fixed
    /// (`ψ̇max ≤ ψ̇min`).
    fn component_into(&self, pairs: &Eigenpairs, n: usize, k: usize, s: f64, out: &mut [f64]) {
        let data = &self.data;
        let d = data.layout.dim();
        let v = &pairs.vecs[k * d..(k + 1) * d];
        for j in 0..d {
            out[j] = s * pairs.sig[k] * v[j] * data.ranges[j];
        }
        if data.grad_max[n] <= data.grad_min[n] {
            out[d - 1] = 0.0;
        }
    }

    fn compute_corrections(&self) -> CorrectionTable {
        let data = &self.data;
        let d = data.layout.dim();
        let k_n = self.n_components();
        // Per sample eigen-decomposition of the scaled scatter D·S·D, D = diag(1/r), for the
        // samples not decomposed yet.
        (0..data.n_ref).into_par_iter().for_each(|n| {
            self.eigenpairs(n);
        });
        // Sign continuity (sequential), then scale to physical units.
        let mut components = vec![0.0; data.n_ref * k_n * d];
        let mut prev: Vec<f64> = vec![0.0; k_n * d];
        for n in 0..data.n_ref {
            let pairs = self.eigenpairs(n);
            for k in 0..k_n {
                let v = &pairs.vecs[k * d..(k + 1) * d];
                let flip = if n == 0 {
                    first_sample_flip(v)
                } else {
                    dot(v, &prev[k * d..(k + 1) * d]) < 0.0
                };
                let s = if flip { -1.0 } else { 1.0 };
                for j in 0..d {
                    prev[k * d + j] = s * v[j];
                }
                let out = &mut components[(n * k_n + k) * d..(n * k_n + k + 1) * d];
                self.component_into(pairs, n, k, s, out);
            }
        }
        CorrectionTable { k: k_n, components }
    }

    /// The components at `(lo, hi, alpha)` into `comps_t` (`K × d`) in the frame local to
    /// `lo` and `hi` (see [`TaskModel::local_corrections_at`]): component `k` of `lo` takes
    /// the first sample's sign convention, that of `hi` the sign continuing it, so each
    /// interpolated component is the table's or its negation. Decomposes only `lo` and `hi`;
    /// where the continuation is undecided (an eigenvector orthogonal to its neighbour's, or
    /// not finite) the table's own signs decide, as they do in the table.
    fn local_comps_at(&self, lo: usize, hi: usize, alpha: f64, comps_t: &mut [f64]) {
        let d = self.data.layout.dim();
        let (a, b) = (self.eigenpairs(lo), self.eigenpairs(hi));
        let mut x = [0.0; 16];
        let mut y = [0.0; 16];
        let mut heap = (Vec::new(), Vec::new());
        let (x, y): (&mut [f64], &mut [f64]) = if d <= 16 {
            (&mut x[..d], &mut y[..d])
        } else {
            heap.0.resize(d, 0.0);
            heap.1.resize(d, 0.0);
            (&mut heap.0, &mut heap.1)
        };
        for k in 0..self.n_components() {
            let (va, vb) = (&a.vecs[k * d..(k + 1) * d], &b.vecs[k * d..(k + 1) * d]);
            let s_lo = if first_sample_flip(va) { -1.0 } else { 1.0 };
            let s_hi = if lo == hi {
                s_lo
            } else {
                let along = dot(vb, va);
                if along > 0.0 {
                    s_lo
                } else if along < 0.0 {
                    -s_lo
                } else {
                    self.comps_at(lo, hi, alpha, comps_t);
                    return;
                }
            };
            self.component_into(a, lo, k, s_lo, x);
            self.component_into(b, hi, k, s_hi, y);
            for ((o, x), y) in comps_t[k * d..(k + 1) * d].iter_mut().zip(&*x).zip(&*y) {
                *o = x + alpha * (y - x);
            }
        }
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
    /// admissible scale computed from the interpolated mean rate and bounds. Each
    /// component's sign is continuous in time over the whole task (the first reference
    /// sample fixes it), so an input `u` held constant moves the command continuously; the
    /// first call after a fit, load or update decomposes every reference sample.
    ///
    /// # Errors
    /// [`Error::BadParam`] if `ref_time` is outside `[0, n_ref − 1]`.
    pub fn corrections_at(&self, ref_time: f64) -> Result<Corrections> {
        self.corrections_in(Frame::Task, ref_time)
    }

    /// The admissible corrections at `ref_time` as [`TaskModel::corrections_at`] gives them,
    /// except that each component may be negated as a whole: its sign is fixed by the two
    /// reference samples around `ref_time` alone (the one before takes the convention of the
    /// first sample, the one after continues it), not by the whole task. Only those two
    /// samples are decomposed (and cached), so right after an update this costs two `d × d`
    /// eigendecompositions instead of `n_ref`.
    ///
    /// Meant for a caller that chooses its input from the components it is given, as the
    /// simulated operator does (a sign that raises the force): with
    /// [`TaskModel::local_command_into`] (the same frame) the command equals the one
    /// [`TaskModel::corrections_at`] and [`TaskModel::command_into`] give for the input
    /// chosen the same way, bit for bit. The scale is the same as there.
    ///
    /// # Errors
    /// [`Error::BadParam`] if `ref_time` is outside `[0, n_ref − 1]`.
    pub fn local_corrections_at(&self, ref_time: f64) -> Result<Corrections> {
        self.corrections_in(Frame::Local, ref_time)
    }

    fn corrections_in(&self, frame: Frame, ref_time: f64) -> Result<Corrections> {
        self.check_ref_time(ref_time)?;
        let (lo, hi, alpha) = bracket(ref_time, self.data.n_ref);
        let d = self.data.layout.dim();
        let k = self.n_components();
        let mut comps_t = vec![0.0; k * d];
        match frame {
            Frame::Task => self.comps_at(lo, hi, alpha, &mut comps_t),
            Frame::Local => self.local_comps_at(lo, hi, alpha, &mut comps_t),
        }
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

    /// [`TaskModel::command`] into a caller buffer of length `m + 1`, `u` along the
    /// components of [`TaskModel::corrections_at`]. Does not allocate once the corrections
    /// are prepared (at most `k_max · d ≤ 64` values; larger use the heap). `u = 0` gives the
    /// mean and needs no correction directions.
    ///
    /// # Errors
    /// [`Error::BadParam`] for `ref_time` outside `[0, n_ref − 1]`, `u` of the wrong length
    /// or outside `[−1, 1]`, or `out` of the wrong length.
    pub fn command_into(&self, u: &[f64], ref_time: f64, out: &mut [f64]) -> Result<()> {
        self.command_in(Frame::Task, u, ref_time, out)
    }

    /// [`TaskModel::command_into`] with `u` along the components of
    /// [`TaskModel::local_corrections_at`] at the same `ref_time` (the frame of the two
    /// reference samples around it; decomposes only those two).
    ///
    /// # Errors
    /// As [`TaskModel::command_into`].
    pub fn local_command_into(&self, u: &[f64], ref_time: f64, out: &mut [f64]) -> Result<()> {
        self.command_in(Frame::Local, u, ref_time, out)
    }

    fn command_in(&self, frame: Frame, u: &[f64], ref_time: f64, out: &mut [f64]) -> Result<()> {
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
        // No input, no displacement: every δ is 0 whatever the directions and the scale.
        let scale = if u.iter().all(|&v| v == 0.0) {
            0.0
        } else {
            match frame {
                Frame::Task => self.comps_at(lo, hi, alpha, comps_t),
                Frame::Local => self.local_comps_at(lo, hi, alpha, comps_t),
            }
            self.scale_at(lo, hi, alpha, comps_t)
        };
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

/// Which signs the correction components take (see [`TaskModel::local_corrections_at`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Frame {
    /// Continuous over the whole task, fixed by the first reference sample.
    Task,
    /// Fixed by the two reference samples around the time asked for.
    Local,
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

    /// A symmetric positive semi-definite `d × d` matrix `B·Bᵀ` of deterministic
    /// pseudo-random entries (varied magnitudes, as scaled scatters have).
    fn gram(d: usize, seed: u64) -> Vec<f64> {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let b: Vec<f64> = (0..d * d)
            .map(|i| next() * (1.0 + (i % 7) as f64))
            .collect();
        let mut a = vec![0.0; d * d];
        for i in 0..d {
            for j in 0..d {
                a[i * d + j] = (0..d).map(|k| b[i * d + k] * b[j * d + k]).sum();
            }
        }
        a
    }

    #[test]
    fn fixed_size_decomposition_is_the_dynamic_one_bit_for_bit() {
        for d in 1..=13 {
            for seed in 0..40 {
                let a = gram(d, seed);
                let at = |i: usize, j: usize| a[i * d + j];
                let (fixed, dynamic) = (eigen(d, at), eigen_dynamic(d, at));
                assert_eq!(fixed.0.len(), d);
                assert_eq!(fixed.1.len(), d * d);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(
                    bits(&fixed.0),
                    bits(&dynamic.0),
                    "eigenvalues d {d} seed {seed}"
                );
                assert_eq!(
                    bits(&fixed.1),
                    bits(&dynamic.1),
                    "eigenvectors d {d} seed {seed}"
                );
            }
        }
    }

    #[test]
    fn local_frame_follows_the_task_frame_across_orthogonal_neighbours() {
        // Two demos over channels (x, y), identity warps (rate fixed): sample 0 varies in x
        // only, sample 1 in y only, so the one component's eigenvectors at 0 and 1 are
        // orthogonal and the sign continuing sample 0 is undecided; the local frame takes the
        // task's signs there, so the interpolated component is the task's (or its negation),
        // not a mix of one sample's sign with the other's flipped.
        let d0 = demo(&["x", "y"], vec![0.0, 0.0, 5.0, 1.0]);
        let d1 = demo(&["x", "y"], vec![2.0, 0.0, 5.0, 3.0]);
        let id = vec![0.0, 1.0];
        let model =
            TaskModel::fit_aligned(&[d0, d1], &[id.clone(), id], &FitParams::default()).unwrap();
        assert_eq!(model.n_components(), 1);
        let local = model.local_corrections_at(0.25).unwrap();
        let task = model.corrections_at(0.25).unwrap();
        let c = &task.components[0];
        assert!(c[0].abs() > 0.0 && c[1].abs() > 0.0, "{c:?}");
        let l = &local.components[0];
        assert!(
            l == c || l.iter().zip(c).all(|(a, b)| *a == -b),
            "{l:?} vs {c:?}"
        );
        assert_eq!(local.scale, task.scale);
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
