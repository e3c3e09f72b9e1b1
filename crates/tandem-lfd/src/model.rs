//! The aligned task model (paper §II-B1/B2): mean behaviour, augmented mean (Eq. 5),
//! variance (Eq. 6), gradient bounds (Eq. 14), admissible corrections and commands (Eq. 7),
//! incremental updates with executions (Eq. 21).
//!
//! # Coordinates
//!
//! Statistics live in the *tangent layout* of dimension `d = m − 3·(quaternion blocks) + 1`:
//! the channels in column order, where each quaternion block is replaced (at the position
//! of its first channel) by the 3 components of its rotation vector relative to a per
//! reference-sample anchor orientation, followed by the warp gradient `ψ̇` ("rate", demo
//! samples per reference sample). See [`TaskModel::tangent_names`].
//!
//! # Quaternion statistics
//!
//! The anchor `q_a(n)` at reference sample `n` is the reference demonstration's (demo 0's)
//! orientation at its aligned time `ψ_0(n)`, fixed at fit time.
//! Each orientation `q` enters the statistics as `r = log(q_a⁻¹ ⊗ q)` (the shortest rotation
//! vector, so `q` and `−q` give the same `r`). The mean orientation is `q_a ⊗ exp(r̄)`, with
//! `r̄` the mean rotation vector; residuals are `r − r̄`. Because the anchor never changes,
//! these are ordinary vector statistics: an [`TaskModel::update`] equals a refit on the same
//! aligned data exactly (up to rounding). For the small orientation spreads of one task
//! instant, `q_a ⊗ exp(r̄)` agrees with the Karcher mean to second order in the spread.

use std::borrow::Cow;
use std::sync::OnceLock;

use nalgebra::{DMatrix, SymmetricEigen};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::demo::{ChannelSchema, DT_TOLERANCE, Demonstration};
use crate::quat::{self, Quat};
use crate::{Error, Result};

/// Parameters of [`TaskModel::fit`] and [`TaskModel::fit_aligned`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitParams {
    /// GDTW parameters for aligning every demonstration to demo 0 (Eq. 2–3).
    /// When `warp.weights` is `None` (default), the weights are derived from the ranges:
    /// `1/r_j²` per scalar channel and `4/r_q²` per quaternion component (a small rotation
    /// `δr` moves a unit quaternion by `|δr|/2`), so the alignment uses the same `W` as
    /// the statistics. Default: `WarpParams::default()`.
    pub warp: tandem_warp::WarpParams,
    /// Per tangent-coordinate ranges `r_j` (length `d`, warp gradient last; physical units:
    /// channel units, radians for rotation vectors, demo samples per reference sample for
    /// the rate); `W⁺ = diag(1/r_j²)` (Eq. 6). `None` (default): each scalar channel's
    /// range over all demonstrations' samples; for a quaternion block, the largest
    /// component range of the rotation vectors relative to demo 0's first orientation;
    /// for the rate, the range of all demonstrations' warp gradients.
    pub ranges: Option<Vec<f64>>,
    /// Ranges below this are replaced by 1 (constant channels). Default: 1e-9.
    pub min_range: f64,
    /// Maximum number of correction components `k_max`; `K = min(n − 1, k_max, d)`.
    /// Must be ≥ 1. Default: 3.
    pub k_max: usize,
    /// Channel kinds and quaternion blocks. Default: [`ChannelSchema::default`].
    pub schema: ChannelSchema,
}

impl Default for FitParams {
    fn default() -> Self {
        Self {
            warp: tandem_warp::WarpParams::default(),
            ranges: None,
            min_range: 1e-9,
            k_max: 3,
            schema: ChannelSchema::default(),
        }
    }
}

impl FitParams {
    /// Checks every field (the warp parameters are checked by `tandem-warp`).
    pub fn validate(&self) -> Result<()> {
        if self.k_max == 0 {
            return Err(Error::BadParam {
                name: "k_max",
                why: "must be ≥ 1".into(),
            });
        }
        if !(self.min_range.is_finite() && self.min_range >= 0.0) {
            return Err(Error::BadParam {
                name: "min_range",
                why: format!("must be finite ≥ 0, got {}", self.min_range),
            });
        }
        let bad_range = self
            .ranges
            .iter()
            .flatten()
            .find(|v| !(v.is_finite() && **v > 0.0));
        if let Some(v) = bad_range {
            return Err(Error::BadParam {
                name: "ranges",
                why: format!("every range must be finite > 0, got {v}"),
            });
        }
        self.schema.validate()
    }
}

/// One item of the tangent layout.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
enum Item {
    /// A scalar channel (its column).
    Scalar(usize),
    /// A quaternion block (columns of x, y, z, w; index among the model's blocks).
    Quat([usize; 4], usize),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Layout {
    items: Vec<Item>,
    names: Vec<String>,
    n_quat: usize,
}

impl Layout {
    fn new(channels: &[String], schema: &ChannelSchema) -> Result<Self> {
        let find = |n: &str| channels.iter().position(|c| c == n);
        let mut in_block = vec![None; channels.len()];
        let mut blocks = Vec::new();
        for block in &schema.quaternions {
            let cols: Vec<Option<usize>> = block.channels.iter().map(|c| find(c)).collect();
            let present = cols.iter().filter(|c| c.is_some()).count();
            if present == 0 {
                continue;
            }
            if present < 4 {
                return Err(Error::BadData {
                    what: format!("quaternion block `{}`", block.name),
                    why: format!(
                        "only {present} of its channels {:?} are present",
                        block.channels
                    ),
                });
            }
            let cols = [0, 1, 2, 3].map(|k| cols[k].expect("all four present"));
            for &c in &cols {
                in_block[c] = Some(blocks.len());
            }
            blocks.push((block.name.clone(), cols));
        }
        let mut items = Vec::new();
        let mut names = Vec::new();
        let mut emitted = vec![false; blocks.len()];
        for (j, name) in channels.iter().enumerate() {
            match in_block[j] {
                None => {
                    items.push(Item::Scalar(j));
                    names.push(name.clone());
                }
                Some(b) if !emitted[b] => {
                    emitted[b] = true;
                    items.push(Item::Quat(blocks[b].1, b));
                    for axis in ["rx", "ry", "rz"] {
                        names.push(format!("{}.{axis}", blocks[b].0));
                    }
                }
                Some(_) => {}
            }
        }
        names.push("rate".into());
        Ok(Self {
            items,
            names,
            n_quat: blocks.len(),
        })
    }

    /// Tangent dimension `d` including the rate.
    fn dim(&self) -> usize {
        self.names.len()
    }
}

/// Per reference sample correction directions, `K × d` each, sign-continuous.
#[derive(Clone, Debug)]
struct CorrectionTable {
    k: usize,
    /// `n_ref × K × d`: `c_k(n)` in physical tangent units.
    comps: Vec<f64>,
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

/// An execution recorded by the system (Eq. 21): its samples and, per sample, the
/// fractional reference time (reference samples) it executed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Execution {
    /// The executed samples (same channels as the model, any order; same `Δt_s` within 1 %).
    pub demonstration: Demonstration,
    /// Reference time of each sample, reference samples, monotone non-decreasing, inside
    /// `[0, T_ref − 1]`, one per sample.
    pub ref_time_log: Vec<f64>,
}

/// Sufficient statistics and derived arrays of the aligned task model.
///
/// All per-time arrays are indexed by reference sample `n ∈ 0..n_ref()` (period
/// [`TaskModel::dt_s`]). Serialized form: the sufficient statistics only; derived arrays are
/// recomputed on load and the corrections lazily on first use.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "ModelData", into = "ModelData")]
pub struct TaskModel {
    data: ModelData,
    mean: Vec<f64>,
    grad_mean: Vec<f64>,
    sigma2_d: Vec<f64>,
    corrections: OnceLock<CorrectionTable>,
}

/// The persisted part of a [`TaskModel`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelData {
    channel_names: Vec<String>,
    layout: Layout,
    dt_s: f64,
    n_ref: usize,
    k_max: usize,
    ranges: Vec<f64>,
    /// `n_ref × n_quat` anchor quaternions `[x, y, z, w]`.
    anchors: Vec<Quat>,
    count: usize,
    /// `n_ref × d` means in the tangent layout.
    stat_mean: Vec<f64>,
    /// `n_ref × d(d+1)/2` packed upper-triangular scatter matrices `Σ_i e_i e_iᵀ`.
    scatter: Vec<f64>,
    grad_min: Vec<f64>,
    grad_max: Vec<f64>,
}

impl TryFrom<ModelData> for TaskModel {
    type Error = Error;
    fn try_from(data: ModelData) -> Result<Self> {
        let d = data.layout.dim();
        let n = data.n_ref;
        let ok = n >= 2
            && data.count >= 2
            && data.k_max >= 1
            && data.dt_s.is_finite()
            && data.dt_s > 0.0
            && data.ranges.len() == d
            && data.anchors.len() == n * data.layout.n_quat
            && data.stat_mean.len() == n * d
            && data.scatter.len() == n * packed_len(d)
            && data.grad_min.len() == n
            && data.grad_max.len() == n
            && data.layout.names.len() == d
            && data.layout.items.iter().all(|it| match it {
                Item::Scalar(j) => *j < data.channel_names.len(),
                Item::Quat(cols, b) => {
                    cols.iter().all(|c| *c < data.channel_names.len()) && *b < data.layout.n_quat
                }
            })
            && data.ranges.iter().all(|r| r.is_finite() && *r > 0.0)
            && data
                .stat_mean
                .iter()
                .chain(&data.scatter)
                .all(|v| v.is_finite())
            && data.anchors.iter().flatten().all(|v| v.is_finite());
        if !ok {
            return Err(Error::BadData {
                what: "task model".into(),
                why: "inconsistent shapes or non-finite values in persisted model".into(),
            });
        }
        Ok(Self::from_data(data))
    }
}

impl From<TaskModel> for ModelData {
    fn from(m: TaskModel) -> Self {
        m.data
    }
}

fn packed_len(d: usize) -> usize {
    d * (d + 1) / 2
}

/// Index of `(i, j)`, `i ≤ j`, in a packed upper triangle of a `d × d` matrix.
fn packed_idx(d: usize, i: usize, j: usize) -> usize {
    i * d - i * i.saturating_sub(1) / 2 + (j - i)
}

/// Checks the demonstration set; returns it with every channel order equal to demo 0's
/// (borrowed when it already is).
fn check_demos(demos: &[Demonstration]) -> Result<Cow<'_, [Demonstration]>> {
    if demos.len() < 2 {
        return Err(Error::TooFewDemonstrations { found: demos.len() });
    }
    let names = demos[0].channel_names();
    let dt = demos[0].dt_s();
    let mut reordered = false;
    for d in demos {
        check_dt(d, dt)?;
        reordered |= matches!(d.conform_to(names)?, Cow::Owned(_));
    }
    if !reordered {
        return Ok(Cow::Borrowed(demos));
    }
    demos
        .iter()
        .map(|d| Ok(d.conform_to(names)?.into_owned()))
        .collect::<Result<Vec<_>>>()
        .map(Cow::Owned)
}

fn check_dt(d: &Demonstration, dt_ref: f64) -> Result<()> {
    if (d.dt_s() - dt_ref).abs() > DT_TOLERANCE * dt_ref {
        return Err(Error::SamplePeriodMismatch {
            file: d.source().into(),
            expected_s: dt_ref,
            found_s: d.dt_s(),
        });
    }
    Ok(())
}

fn check_quaternion_norms(layout: &Layout, demo: &Demonstration) -> Result<()> {
    for item in &layout.items {
        if let Item::Quat(cols, _) = item {
            for t in 0..demo.n_samples() {
                let s = demo.sample(t);
                let q = cols.map(|c| s[c]);
                if quat::norm(&q) < 1e-6 {
                    return Err(Error::BadData {
                        what: demo.source().into(),
                        why: format!(
                            "sample {t}: quaternion `{}` has norm {} (≈ 0)",
                            demo.channel_names()[cols[0]],
                            quat::norm(&q)
                        ),
                    });
                }
            }
        }
    }
    Ok(())
}

/// Quaternion of block `cols` at fractional demo time `q_t` (nlerp between neighbours).
fn quat_at(demo: &Demonstration, cols: &[usize; 4], q_t: f64) -> Quat {
    let (lo, hi, alpha) = bracket(q_t, demo.n_samples());
    let a = quat::normalize(&cols.map(|c| demo.sample(lo)[c]));
    if alpha == 0.0 {
        return a;
    }
    let b = quat::normalize(&cols.map(|c| demo.sample(hi)[c]));
    quat::nlerp(&a, &b, alpha)
}

/// `(lo, hi, alpha)` with `t = lo + alpha`, clamped to `[0, n − 1]`.
fn bracket(t: f64, n: usize) -> (usize, usize, f64) {
    let t = t.clamp(0.0, (n - 1) as f64);
    let lo = (t.floor() as usize).min(n - 1);
    let hi = (lo + 1).min(n - 1);
    (lo, hi, t - lo as f64)
}

/// Execution samples per reference sample over the first step `[a, b]` of `steps` (pairs
/// of consecutive reference-time log entries) that moves; 1 if none does.
fn pace<'a>(mut steps: impl Iterator<Item = &'a [f64]>) -> f64 {
    steps
        .find(|w| w[1] > w[0])
        .map_or(1.0, |w| 1.0 / (w[1] - w[0]))
}

/// Reference samples per parallel work item in per-sample loops (results do not depend
/// on the split).
const PAR_MIN_LEN: usize = 512;

/// Tangent-layout observation `x_i⁺(ψ_i(n))` of an aligned demonstration at reference
/// sample `n` into `out` (`d` values; rate = forward-difference warp gradient, the last
/// entry repeating the previous one).
fn observe_at(
    layout: &Layout,
    anchors: &[Quat],
    demo: &Demonstration,
    warp: &[f64],
    n: usize,
    out: &mut [f64],
) {
    let nq = layout.n_quat;
    let q_t = warp[n];
    let (lo, hi, alpha) = bracket(q_t, demo.n_samples());
    let (a, b) = (demo.sample(lo), demo.sample(hi));
    let mut k = 0;
    for item in &layout.items {
        match item {
            Item::Scalar(j) => {
                out[k] = a[*j] + alpha * (b[*j] - a[*j]);
                k += 1;
            }
            Item::Quat(cols, blk) => {
                let q = quat_at(demo, cols, q_t);
                out[k..k + 3].copy_from_slice(&quat::log_relative(&anchors[n * nq + blk], &q));
                k += 3;
            }
        }
    }
    out[k] = if n + 1 < warp.len() {
        warp[n + 1] - warp[n]
    } else {
        warp[n] - warp[n - 1]
    };
}

/// Derived values at one reference sample from its statistics: the physical mean into
/// `out` (`m` values, quaternions `anchor ⊗ exp(r̄)`), and returns (mean rate, `σ²_D`) with
/// `σ²_D = Σ_j scatter_jj / r_j² / denom` (Eq. 6, `denom = n − 1`).
fn derive_at(
    layout: &Layout,
    anchors: &[Quat],
    inv_w: &[f64],
    denom: f64,
    mu: &[f64],
    sc: &[f64],
    out: &mut [f64],
) -> (f64, f64) {
    let d = mu.len();
    let mut k = 0;
    for item in &layout.items {
        match item {
            Item::Scalar(j) => {
                out[*j] = mu[k];
                k += 1;
            }
            Item::Quat(cols, blk) => {
                let r = [mu[k], mu[k + 1], mu[k + 2]];
                let q = quat::exp_relative(&anchors[*blk], &r);
                for (c, v) in cols.iter().zip(q) {
                    out[*c] = v;
                }
                k += 3;
            }
        }
    }
    let s2 = (0..d)
        .map(|i| sc[packed_idx(d, i, i)] * inv_w[i])
        .sum::<f64>()
        / denom;
    (mu[d - 1], s2)
}

/// Tangent-layout observations of one aligned demonstration, `n_ref × d`.
fn observe(layout: &Layout, anchors: &[Quat], demo: &Demonstration, warp: &[f64]) -> Vec<f64> {
    let d = layout.dim();
    let mut out = vec![0.0; warp.len() * d];
    out.par_chunks_mut(d)
        .enumerate()
        .with_min_len(PAR_MIN_LEN)
        .for_each(|(n, x)| observe_at(layout, anchors, demo, warp, n, x));
    out
}

/// Default ranges of the non-rate tangent coordinates (see [`FitParams::ranges`]).
fn channel_ranges(layout: &Layout, demos: &[Demonstration], min_range: f64) -> Vec<f64> {
    let mut ranges = Vec::with_capacity(layout.dim());
    let guard = |r: f64| {
        if r < min_range || !r.is_finite() {
            1.0
        } else {
            r
        }
    };
    for item in &layout.items {
        match item {
            Item::Scalar(j) => {
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for d in demos {
                    for t in 0..d.n_samples() {
                        let v = d.sample(t)[*j];
                        lo = lo.min(v);
                        hi = hi.max(v);
                    }
                }
                ranges.push(guard(hi - lo));
            }
            Item::Quat(cols, _) => {
                let anchor = quat::normalize(&cols.map(|c| demos[0].sample(0)[c]));
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for d in demos {
                    for t in 0..d.n_samples() {
                        let q = quat::normalize(&cols.map(|c| d.sample(t)[c]));
                        let r = quat::log_relative(&anchor, &q);
                        for k in 0..3 {
                            lo[k] = lo[k].min(r[k]);
                            hi[k] = hi[k].max(r[k]);
                        }
                    }
                }
                let r = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
                ranges.extend([guard(r); 3]);
            }
        }
    }
    ranges
}

/// Alignment weights per channel derived from the tangent ranges.
fn warp_weights(layout: &Layout, ranges: &[f64], m: usize) -> Vec<f64> {
    let mut w = vec![0.0; m];
    let mut k = 0;
    for item in &layout.items {
        match item {
            Item::Scalar(j) => {
                w[*j] = 1.0 / (ranges[k] * ranges[k]);
                k += 1;
            }
            Item::Quat(cols, _) => {
                let r = ranges[k..k + 3].iter().copied().fold(0.0, f64::max);
                for &c in cols {
                    w[c] = 4.0 / (r * r);
                }
                k += 3;
            }
        }
    }
    w
}

/// A copy of the samples with every quaternion block sign-continuous in time and in the
/// hemisphere of `reference` (demo 0's first orientation), for alignment.
fn sign_aligned(layout: &Layout, demo: &Demonstration, reference: &[Quat]) -> Vec<f64> {
    let m = demo.n_channels();
    let mut data = demo.samples().to_vec();
    for item in &layout.items {
        if let Item::Quat(cols, blk) = item {
            let mut prev = reference[*blk];
            for row in data.chunks_exact_mut(m) {
                let q = cols.map(|c| row[c]);
                if quat::dot(&q, &prev) < 0.0 {
                    for &c in cols {
                        row[c] = -row[c];
                    }
                }
                prev = cols.map(|c| row[c]);
            }
        }
    }
    data
}

impl TaskModel {
    /// Fits the model: aligns every demonstration to demo 0 with GDTW
    /// (`tandem_warp::align_many`, in parallel), then computes the statistics as
    /// [`TaskModel::fit_aligned`] does. Demo 0 is the reference: `n_ref() = T_0`.
    ///
    /// Errors: fewer than 2 demonstrations, different channel sets or sample periods,
    /// a partial or zero quaternion, bad parameters, alignment failure.
    pub fn fit(demos: &[Demonstration], params: &FitParams) -> Result<Self> {
        params.validate()?;
        let demos = check_demos(demos)?;
        let layout = Layout::new(demos[0].channel_names(), &params.schema)?;
        for d in demos.iter() {
            check_quaternion_norms(&layout, d)?;
        }
        let d = layout.dim();
        let ranges = match &params.ranges {
            Some(r) => {
                check_ranges_len(r, d)?;
                r[..d - 1].to_vec()
            }
            None => channel_ranges(&layout, &demos, params.min_range),
        };
        let m = demos[0].n_channels();
        let mut warp_params = params.warp.clone();
        if warp_params.weights.is_none() {
            warp_params.weights = Some(warp_weights(&layout, &ranges, m));
        }
        let reference: Vec<Quat> = layout
            .items
            .iter()
            .filter_map(|it| match it {
                Item::Quat(cols, _) => Some(quat::normalize(&cols.map(|c| demos[0].sample(0)[c]))),
                Item::Scalar(_) => None,
            })
            .collect();
        let signals: Vec<Vec<f64>> = demos
            .par_iter()
            .map(|dm| sign_aligned(&layout, dm, &reference))
            .collect();
        let refs = signals
            .iter()
            .map(|s| tandem_warp::SignalRef::new(s, m))
            .collect::<std::result::Result<Vec<_>, _>>()?;
        let warps = tandem_warp::align_many(refs[0], &refs[1..], &warp_params)?;
        let mut values: Vec<Vec<f64>> = Vec::with_capacity(demos.len());
        values.push((0..demos[0].n_samples()).map(|n| n as f64).collect());
        values.extend(warps.iter().map(|w| w.values().to_vec()));
        Self::fit_checked(&demos, &values, params, layout, Some(ranges))
    }

    /// Fits the model from known warps: `warps_values[i][n]` is demo `i`'s time (demo
    /// samples, fractional) at reference sample `n` (demo 0 is the reference, so
    /// `warps_values[0]` is normally the identity `0, 1, …, T_0 − 1`).
    ///
    /// Per reference sample it computes the mean `μ̂(n)`, the mean warp gradient and the
    /// augmented mean `μ̂⁺` (Eq. 5), the weighted variance `σ²_D(n)` (Eq. 6) and the gradient
    /// bounds (Eq. 14); the correction directions are computed on first use.
    ///
    /// Errors: as [`TaskModel::fit`], plus a warp of the wrong length, non-finite,
    /// decreasing, or outside `[0, T_i − 1]`.
    pub fn fit_aligned(
        demos: &[Demonstration],
        warps_values: &[Vec<f64>],
        params: &FitParams,
    ) -> Result<Self> {
        params.validate()?;
        let demos = check_demos(demos)?;
        let layout = Layout::new(demos[0].channel_names(), &params.schema)?;
        for d in demos.iter() {
            check_quaternion_norms(&layout, d)?;
        }
        Self::fit_checked(&demos, warps_values, params, layout, None)
    }

    fn fit_checked(
        demos: &[Demonstration],
        warps_values: &[Vec<f64>],
        params: &FitParams,
        layout: Layout,
        channel_ranges_known: Option<Vec<f64>>,
    ) -> Result<Self> {
        let n_ref = demos[0].n_samples();
        if warps_values.len() != demos.len() {
            return Err(Error::BadData {
                what: "warps".into(),
                why: format!(
                    "{} warps for {} demonstrations",
                    warps_values.len(),
                    demos.len()
                ),
            });
        }
        for (i, (w, dm)) in warps_values.iter().zip(demos).enumerate() {
            check_warp(i, w, n_ref, dm.n_samples())?;
        }
        let d = layout.dim();
        let nq = layout.n_quat;
        // Anchors: demo 0's orientation at its aligned time.
        let mut anchors = Vec::with_capacity(n_ref * nq);
        for &q_t in &warps_values[0] {
            for item in &layout.items {
                if let Item::Quat(cols, _) = item {
                    anchors.push(quat_at(&demos[0], cols, q_t));
                }
            }
        }
        let obs: Vec<Vec<f64>> = demos
            .par_iter()
            .zip(warps_values.par_iter())
            .map(|(dm, w)| observe(&layout, &anchors, dm, w))
            .collect();
        let ranges = match &params.ranges {
            Some(r) => {
                check_ranges_len(r, d)?;
                r.clone()
            }
            None => {
                let mut r = channel_ranges_known
                    .unwrap_or_else(|| channel_ranges(&layout, demos, params.min_range));
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for o in &obs {
                    for g in o.iter().skip(d - 1).step_by(d) {
                        lo = lo.min(*g);
                        hi = hi.max(*g);
                    }
                }
                let rr = hi - lo;
                r.push(if rr < params.min_range { 1.0 } else { rr });
                r
            }
        };
        // Batch two-pass statistics (Eq. 5, 6, 14).
        let n_d = obs.len();
        let pl = packed_len(d);
        let mut stat_mean = vec![0.0; n_ref * d];
        let mut scatter = vec![0.0; n_ref * pl];
        let mut grad_min = vec![f64::INFINITY; n_ref];
        let mut grad_max = vec![f64::NEG_INFINITY; n_ref];
        stat_mean
            .par_chunks_mut(d)
            .zip(scatter.par_chunks_mut(pl))
            .zip(grad_min.par_iter_mut().zip(grad_max.par_iter_mut()))
            .enumerate()
            .for_each(|(n, ((mu, sc), (gmin, gmax)))| {
                for o in &obs {
                    let x = &o[n * d..(n + 1) * d];
                    for (m, v) in mu.iter_mut().zip(x) {
                        *m += v;
                    }
                    *gmin = gmin.min(x[d - 1]);
                    *gmax = gmax.max(x[d - 1]);
                }
                for m in mu.iter_mut() {
                    *m /= n_d as f64;
                }
                let mut e = vec![0.0; d];
                for o in &obs {
                    for (k, ek) in e.iter_mut().enumerate() {
                        *ek = o[n * d + k] - mu[k];
                    }
                    let mut p = 0;
                    for (i, &ei) in e.iter().enumerate() {
                        for ej in &e[i..] {
                            sc[p] += ei * ej;
                            p += 1;
                        }
                    }
                }
            });
        let data = ModelData {
            channel_names: demos[0].channel_names().to_vec(),
            layout,
            dt_s: demos[0].dt_s(),
            n_ref,
            k_max: params.k_max,
            ranges,
            anchors,
            count: n_d,
            stat_mean,
            scatter,
            grad_min,
            grad_max,
        };
        Ok(Self::from_data(data))
    }

    fn from_data(data: ModelData) -> Self {
        let mut model = Self {
            data,
            mean: Vec::new(),
            grad_mean: Vec::new(),
            sigma2_d: Vec::new(),
            corrections: OnceLock::new(),
        };
        model.refresh_derived();
        model
    }

    /// Recomputes the physical mean, mean gradient and `σ²_D` from the statistics.
    fn refresh_derived(&mut self) {
        let data = &self.data;
        let (n_ref, d, m) = (data.n_ref, data.layout.dim(), data.channel_names.len());
        let nq = data.layout.n_quat;
        let pl = packed_len(d);
        let mut mean = std::mem::take(&mut self.mean);
        let mut grad_mean = std::mem::take(&mut self.grad_mean);
        let mut sigma2 = std::mem::take(&mut self.sigma2_d);
        mean.resize(n_ref * m, 0.0);
        grad_mean.resize(n_ref, 0.0);
        sigma2.resize(n_ref, 0.0);
        let inv_w: Vec<f64> = data.ranges.iter().map(|r| 1.0 / (r * r)).collect();
        let denom = (data.count - 1) as f64;
        mean.par_chunks_mut(m)
            .zip(grad_mean.par_iter_mut().zip(sigma2.par_iter_mut()))
            .enumerate()
            .with_min_len(PAR_MIN_LEN)
            .for_each(|(n, (out, (g, s2)))| {
                let mu = &data.stat_mean[n * d..(n + 1) * d];
                let sc = &data.scatter[n * pl..(n + 1) * pl];
                let anchors = &data.anchors[n * nq..(n + 1) * nq];
                (*g, *s2) = derive_at(&data.layout, anchors, &inv_w, denom, mu, sc, out);
            });
        self.mean = mean;
        self.grad_mean = grad_mean;
        self.sigma2_d = sigma2;
    }

    /// Adds one execution recorded by the system (Eq. 21) without re-alignment: its warp
    /// is the inverse of its reference-time log, its gradient per reference sample follows.
    /// Updates the per-reference-sample count, mean and scatter (Welford) and the gradient
    /// bounds in `O(n_ref · d²)`; the ranges, anchors and `k_max` stay as fitted; the
    /// correction directions are recomputed on next use.
    ///
    /// Errors (the model is unchanged): different channel set or sample period, log length
    /// ≠ sample count, non-finite, decreasing or outside `[0, n_ref − 1]` log, zero quaternion.
    pub fn update(&mut self, execution: &Execution) -> Result<()> {
        let values = self.execution_warp(execution)?;
        let demo = execution
            .demonstration
            .conform_to(&self.data.channel_names)?;
        let d = self.data.layout.dim();
        let pl = packed_len(d);
        let data = &mut self.data;
        let (layout, anchors) = (&data.layout, &data.anchors);
        let count = data.count as f64 + 1.0;
        let (inv_count, factor) = (1.0 / count, data.count as f64 / count);
        let (m, nq) = (data.channel_names.len(), layout.n_quat);
        let inv_w: Vec<f64> = data.ranges.iter().map(|r| 1.0 / (r * r)).collect();
        let denom = data.count as f64; // (count + 1) − 1
        data.stat_mean
            .par_chunks_mut(d)
            .zip(data.scatter.par_chunks_mut(pl))
            .zip(
                data.grad_min
                    .par_iter_mut()
                    .zip(data.grad_max.par_iter_mut()),
            )
            .zip(
                self.mean.par_chunks_mut(m).zip(
                    self.grad_mean
                        .par_iter_mut()
                        .zip(self.sigma2_d.par_iter_mut()),
                ),
            )
            .enumerate()
            .with_min_len(PAR_MIN_LEN)
            .for_each_init(
                || (vec![0.0; d], vec![0.0; d]),
                |(x, delta), (n, (((mu, sc), (gmin, gmax)), (out, (g, s2))))| {
                    observe_at(layout, anchors, &demo, &values, n, x);
                    for k in 0..d {
                        delta[k] = x[k] - mu[k];
                        mu[k] += delta[k] * inv_count;
                    }
                    let mut p = 0;
                    for (i, &di) in delta.iter().enumerate() {
                        let di = di * factor;
                        for dj in &delta[i..] {
                            sc[p] += di * dj;
                            p += 1;
                        }
                    }
                    *gmin = gmin.min(x[d - 1]);
                    *gmax = gmax.max(x[d - 1]);
                    let anchors = &anchors[n * nq..(n + 1) * nq];
                    (*g, *s2) = derive_at(layout, anchors, &inv_w, denom, mu, sc, out);
                },
            );
        data.count += 1;
        self.corrections = OnceLock::new();
        Ok(())
    }

    /// The warp (reference → execution samples) of an execution: the inverse of its
    /// reference-time log, `ψ_E(n) = min{q : log(q) ≥ n}` with linear interpolation of the
    /// log between samples. Reference samples before the log's first entry or after its
    /// last are extrapolated at the execution's first or last pace (execution samples per
    /// reference sample, from the nearest pair of distinct log entries; 1 if there is
    /// none), so the warp gradient stays that of the execution at both ends — an execution
    /// ends once its last step passes `T_ref − 1`, so its log may stop a step short of it.
    /// The warp may thus leave `[0, T_E − 1]` by less than a step at either end.
    /// Validates the execution.
    pub fn execution_warp(&self, execution: &Execution) -> Result<Vec<f64>> {
        let demo = &execution.demonstration;
        let log = &execution.ref_time_log;
        demo.conform_to(&self.data.channel_names)?;
        check_dt(demo, self.data.dt_s)?;
        check_quaternion_norms(&self.data.layout, demo)?;
        let bad = |why: String| Error::BadLog {
            file: demo.source().into(),
            why,
        };
        if log.len() != demo.n_samples() {
            return Err(bad(format!(
                "{} entries for {} samples",
                log.len(),
                demo.n_samples()
            )));
        }
        let last_ref = (self.data.n_ref - 1) as f64;
        for (k, &v) in log.iter().enumerate() {
            if !v.is_finite() || !(0.0..=last_ref).contains(&v) {
                return Err(bad(format!("entry {k} = {v} is outside [0, {last_ref}]")));
            }
            if k > 0 && v < log[k - 1] {
                return Err(bad(format!(
                    "entry {k} = {v} decreases from {}",
                    log[k - 1]
                )));
            }
        }
        let t_e = log.len();
        // Execution samples per reference sample over the first and last distinct steps.
        let first_pace = pace(log.windows(2));
        let last_pace = pace(log.windows(2).rev());
        let mut values = Vec::with_capacity(self.data.n_ref);
        let mut k = 0;
        for n in 0..self.data.n_ref {
            let nf = n as f64;
            let q = if nf <= log[0] {
                -(log[0] - nf) * first_pace
            } else if nf > log[t_e - 1] {
                (t_e - 1) as f64 + (nf - log[t_e - 1]) * last_pace
            } else {
                while log[k + 1] < nf {
                    k += 1;
                }
                k as f64 + (nf - log[k]) / (log[k + 1] - log[k])
            };
            values.push(q);
        }
        Ok(values)
    }

    /// Number of reference samples `T_ref` (the length of every per-time array).
    pub fn n_ref(&self) -> usize {
        self.data.n_ref
    }

    /// Reference sample period `Δt_s`, seconds.
    pub fn dt_s(&self) -> f64 {
        self.data.dt_s
    }

    /// Channel names `m`, in the order of [`TaskModel::mean`]'s rows.
    pub fn channel_names(&self) -> &[String] {
        &self.data.channel_names
    }

    /// Names of the `d` tangent coordinates (statistics, ranges, corrections): scalar
    /// channels by name, quaternion blocks as `<block>.rx/.ry/.rz`, then `rate`.
    pub fn tangent_names(&self) -> &[String] {
        &self.data.layout.names
    }

    /// Number of demonstrations and executions in the statistics `n`.
    pub fn count(&self) -> usize {
        self.data.count
    }

    /// Mean behaviour `μ̂(n)`, sample-major `n_ref × m` in channel units (reference time);
    /// quaternions unit-norm.
    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    /// Weighted demonstration variance `σ²_D(n)` (Eq. 6), dimensionless, per reference sample.
    pub fn sigma2_d(&self) -> &[f64] {
        &self.sigma2_d
    }

    /// Mean warp gradient `ψ̄̇_D(n)` (Eq. 5), demo samples per reference sample.
    pub fn grad_mean(&self) -> &[f64] {
        &self.grad_mean
    }

    /// Minimum warp gradient `ψ̇min(n)` (Eq. 14), demo samples per reference sample.
    pub fn grad_min(&self) -> &[f64] {
        &self.data.grad_min
    }

    /// Maximum warp gradient `ψ̇max(n)` (Eq. 14), demo samples per reference sample.
    pub fn grad_max(&self) -> &[f64] {
        &self.data.grad_max
    }

    /// Ranges `r_j` of the tangent coordinates; `W⁺ = diag(1/r_j²)`.
    pub fn ranges(&self) -> &[f64] {
        &self.data.ranges
    }

    /// Mean tangent statistics at reference sample `n` (`d` values; rotation vectors
    /// relative to the anchor; rate last). Panics if `n ≥ n_ref()`.
    pub fn tangent_mean(&self, n: usize) -> &[f64] {
        let d = self.data.layout.dim();
        &self.data.stat_mean[n * d..(n + 1) * d]
    }

    /// Sample covariance (`scatter / (n − 1)`) of the tangent coordinates at reference
    /// sample `n`, row-major `d × d`. Panics if `n ≥ n_ref()`.
    pub fn covariance(&self, n: usize) -> Vec<f64> {
        let d = self.data.layout.dim();
        let sc = &self.data.scatter[n * packed_len(d)..(n + 1) * packed_len(d)];
        let denom = (self.data.count - 1) as f64;
        let mut c = vec![0.0; d * d];
        for i in 0..d {
            for j in i..d {
                let v = sc[packed_idx(d, i, j)] / denom;
                c[i * d + j] = v;
                c[j * d + i] = v;
            }
        }
        c
    }

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
                let sc = &data.scatter[n * pl..(n + 1) * pl];
                let mut a = DMatrix::<f64>::zeros(d, d);
                for i in 0..d {
                    for j in i..d {
                        let v = sc[packed_idx(d, i, j)] / (data.ranges[i] * data.ranges[j]);
                        a[(i, j)] = v;
                        a[(j, i)] = v;
                    }
                }
                let eig = SymmetricEigen::new(a);
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
        let mut comps = vec![0.0; data.n_ref * k_n * d];
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
                let out = &mut comps[(n * k_n + k) * d..(n * k_n + k + 1) * d];
                for j in 0..d {
                    prev[k * d + j] = s * v[j];
                    out[j] = s * sig[k] * v[j] * data.ranges[j];
                }
                if rate_fixed {
                    out[d - 1] = 0.0;
                }
            }
        }
        CorrectionTable { k: k_n, comps }
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

    /// Interpolated (mean rate, min, max, components) at a fractional reference time.
    fn scale_at(&self, lo: usize, hi: usize, alpha: f64, comps: &[f64]) -> f64 {
        let lerp = |v: &[f64]| v[lo] + alpha * (v[hi] - v[lo]);
        let (g, gmin, gmax) = (
            lerp(&self.grad_mean),
            lerp(&self.data.grad_min),
            lerp(&self.data.grad_max),
        );
        let d = self.data.layout.dim();
        let reach: f64 = comps.chunks_exact(d).map(|c| c[d - 1].abs()).sum();
        if reach <= 0.0 {
            return 1.0;
        }
        ((gmax - g) / reach).min((g - gmin) / reach).clamp(0.0, 1.0)
    }

    /// Interpolated components at `(lo, hi, alpha)` into `out` (`K × d`).
    fn comps_at(&self, lo: usize, hi: usize, alpha: f64, out: &mut [f64]) {
        let table = self.table();
        let kd = table.k * self.data.layout.dim();
        let a = &table.comps[lo * kd..(lo + 1) * kd];
        let b = &table.comps[hi * kd..(hi + 1) * kd];
        for ((o, x), y) in out.iter_mut().zip(a).zip(b) {
            *o = x + alpha * (y - x);
        }
    }

    /// The admissible corrections at fractional reference time `ref_time` (reference
    /// samples): components interpolated linearly between neighbouring samples, and the
    /// admissible scale computed from the interpolated mean rate and bounds.
    pub fn corrections_at(&self, ref_time: f64) -> Result<Corrections> {
        self.check_ref_time(ref_time)?;
        let (lo, hi, alpha) = bracket(ref_time, self.data.n_ref);
        let d = self.data.layout.dim();
        let k = self.n_components();
        let mut flat = vec![0.0; k * d];
        self.comps_at(lo, hi, alpha, &mut flat);
        Ok(Corrections {
            scale: self.scale_at(lo, hi, alpha, &flat),
            components: flat.chunks_exact(d).map(<[f64]>::to_vec).collect(),
        })
    }

    /// The command `x_f⁺(u, t) = μ̂⁺(t) + δx⁺(u, t)` (Eq. 7) at fractional reference time
    /// `ref_time` for operator input `u ∈ [−1, 1]^K`: `m` channel values in channel order
    /// (quaternions as `mean ⊗ exp(δ)`, unit-norm) followed by the rate (demo samples per
    /// reference sample), which stays inside `[ψ̇min(t), ψ̇max(t)]`.
    pub fn command(&self, u: &[f64], ref_time: f64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; self.data.channel_names.len() + 1];
        self.command_into(u, ref_time, &mut out)?;
        Ok(out)
    }

    /// [`TaskModel::command`] into a caller buffer of length `m + 1`. Does not allocate
    /// once the corrections are prepared (at most `k_max · d ≤ 64` values; larger use the heap).
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
        let comps: &mut [f64] = if k * d <= 64 {
            &mut stack[..k * d]
        } else {
            heap.resize(k * d, 0.0);
            &mut heap
        };
        self.comps_at(lo, hi, alpha, comps);
        let a = self.scale_at(lo, hi, alpha, comps);
        let delta =
            |j: usize| -> f64 { a * (0..k).map(|kk| u[kk] * comps[kk * d + j]).sum::<f64>() };
        let lerp =
            |v: &[f64], w: usize, j: usize| v[lo * w + j] + alpha * (v[hi * w + j] - v[lo * w + j]);
        let mut t = 0;
        for item in &self.data.layout.items {
            match item {
                Item::Scalar(j) => {
                    out[*j] = lerp(&self.mean, m, *j) + delta(t);
                    t += 1;
                }
                Item::Quat(cols, _) => {
                    let qa = cols.map(|c| self.mean[lo * m + c]);
                    let qb = cols.map(|c| self.mean[hi * m + c]);
                    let q = quat::nlerp(&qa, &qb, alpha);
                    let r = [delta(t), delta(t + 1), delta(t + 2)];
                    let qc = quat::exp_relative(&q, &r);
                    for (c, v) in cols.iter().zip(qc) {
                        out[*c] = v;
                    }
                    t += 3;
                }
            }
        }
        let gmin = lerp(&self.data.grad_min, 1, 0);
        let gmax = lerp(&self.data.grad_max, 1, 0);
        out[m] = (lerp(&self.grad_mean, 1, 0) + delta(d - 1)).clamp(gmin, gmax);
        Ok(())
    }
}

fn check_ranges_len(r: &[f64], d: usize) -> Result<()> {
    if r.len() != d {
        return Err(Error::BadParam {
            name: "ranges",
            why: format!("has {} entries, the tangent layout has {d}", r.len()),
        });
    }
    Ok(())
}

fn check_warp(i: usize, w: &[f64], n_ref: usize, t_i: usize) -> Result<()> {
    let bad = |why: String| Error::BadWarp { demo_idx: i, why };
    if w.len() != n_ref {
        return Err(bad(format!(
            "{} values for {n_ref} reference samples",
            w.len()
        )));
    }
    let last = (t_i - 1) as f64;
    let tol = 1e-9 * last.max(1.0);
    for (n, &v) in w.iter().enumerate() {
        if !v.is_finite() || v < -tol || v > last + tol {
            return Err(bad(format!(
                "value {v} at reference sample {n} is outside [0, {last}]"
            )));
        }
        if n > 0 && v < w[n - 1] {
            return Err(bad(format!("decreases at reference sample {n}")));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn demo(names: &[&str], samples: Vec<f64>) -> Demonstration {
        Demonstration::new(names.iter().map(|s| s.to_string()).collect(), samples, 0.01).unwrap()
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * (1.0 + b.abs())
    }

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

    /// Demo 1 is demo 0 played at varying speed; warp values given.
    fn three_demos() -> (Vec<Demonstration>, Vec<Vec<f64>>) {
        let d0 = demo(&["force"], vec![0.0, 10.0, 20.0]);
        let d1 = demo(&["force"], vec![0.0, 5.0, 10.0, 15.0, 20.0]);
        (
            vec![d0.clone(), d1, d0],
            vec![
                vec![0.0, 1.0, 2.0],
                vec![0.0, 1.5, 4.0],
                vec![0.0, 1.0, 2.0],
            ],
        )
    }

    #[test]
    fn hand_derived_statistics() {
        let (demos, warps) = three_demos();
        let m = TaskModel::fit_aligned(&demos, &warps, &FitParams::default()).unwrap();
        assert_eq!(m.n_ref(), 3);
        assert_eq!(m.tangent_names(), ["force", "rate"]);
        // Force range 20 N; gradients {1, 1.5, 2.5} → rate range 1.5.
        assert_eq!(m.ranges(), [20.0, 1.5]);
        // n = 1: forces 10, 7.5, 10 (demo 1 at its time 1.5); gradients 1, 2.5, 1.
        assert!(close(m.mean()[1], 55.0 / 6.0));
        assert!(close(m.grad_mean()[1], 1.5));
        assert_eq!((m.grad_min()[1], m.grad_max()[1]), (1.0, 2.5));
        // σ²_D = [ (25+100+25)/36 / 20² + 1.5 / 1.5² ] / 2 = (1/96 + 2/3) / 2 = 65/192.
        assert!(close(m.sigma2_d()[1], 65.0 / 192.0));
        // n = 0: forces all 0, gradients 1, 1.5, 1 → rate residuals −1/6, 1/3, −1/6.
        assert!(close(m.grad_mean()[0], 7.0 / 6.0));
        assert!(close(m.sigma2_d()[0], (1.0 / 6.0) / 2.25 / 2.0));
        // n = 2: last gradient repeats the previous: 1, 2.5, 1.
        assert_eq!(m.grad_max()[2], 2.5);
        assert_eq!(m.n_components(), 2);
    }

    #[test]
    fn hand_derived_correction_and_scale() {
        // Two demos, same force, gradients 1 and 2 (demo 1 twice as slow).
        let d0 = demo(&["force"], vec![0.0, 10.0, 20.0]);
        let d1 = demo(&["force"], vec![0.0, 5.0, 10.0, 15.0, 20.0]);
        let warps = vec![vec![0.0, 1.0, 2.0], vec![0.0, 2.0, 4.0]];
        let m = TaskModel::fit_aligned(&[d0, d1], &warps, &FitParams::default()).unwrap();
        assert_eq!(m.n_components(), 1);
        // Scaled scatter diag(0, 0.5) → s = √0.5, v = (0, 1); c = 3·√0.5/√2·(0, 1)⊙(20, 1).
        let c = m.corrections_at(1.0).unwrap();
        assert!(close(c.components[0][0], 0.0));
        assert!(close(c.components[0][1], 1.5));
        // Mean rate 1.5 in [1, 2], reach 1.5 → a = 0.5 / 1.5.
        assert!(close(c.scale, 1.0 / 3.0));
        let up = m.command(&[1.0], 1.0).unwrap();
        let down = m.command(&[-1.0], 1.0).unwrap();
        assert!(close(up[0], 10.0) && close(up[1], 2.0));
        assert!(close(down[0], 10.0) && close(down[1], 1.0));
        // Fractional reference time interpolates the mean.
        assert!(close(m.command(&[0.0], 0.25).unwrap()[0], 2.5));
    }

    #[test]
    fn identical_demos_give_zero_variance_and_no_correction() {
        let d = demo(
            &["x", "force"],
            vec![0.0, 1.0, 0.5, 3.0, 1.0, 2.0, 1.5, 0.0],
        );
        let id: Vec<f64> = (0..4).map(f64::from).collect();
        let m = TaskModel::fit_aligned(
            &[d.clone(), d.clone(), d],
            &[id.clone(), id.clone(), id],
            &FitParams::default(),
        )
        .unwrap();
        assert!(m.sigma2_d().iter().all(|&s| s == 0.0));
        for t in [0.0, 0.7, 2.0, 3.0] {
            let c = m.corrections_at(t).unwrap();
            assert!(c.components.iter().flatten().all(|&v| v == 0.0));
            let mean = m.command(&[0.0, 0.0], t).unwrap();
            assert_eq!(m.command(&[1.0, -1.0], t).unwrap(), mean);
        }
    }

    fn quat_demo(qs: &[[f64; 4]]) -> Demonstration {
        demo(
            &["qx", "qy", "qz", "qw"],
            qs.iter().flatten().copied().collect(),
        )
    }

    #[test]
    fn quaternion_mean_of_q_and_minus_q_is_q() {
        let q = quat::exp(&[0.1, -0.2, 0.3]);
        let mq = q.map(|v| -v);
        let id = vec![0.0, 1.0];
        let m = TaskModel::fit_aligned(
            &[quat_demo(&[q, q]), quat_demo(&[mq, mq])],
            &[id.clone(), id],
            &FitParams::default(),
        )
        .unwrap();
        assert_eq!(m.tangent_names(), ["q.rx", "q.ry", "q.rz", "rate"]);
        for n in 0..2 {
            let got = &m.mean()[n * 4..(n + 1) * 4];
            for k in 0..4 {
                assert!((got[k] - q[k]).abs() < 1e-12, "{got:?} vs {q:?}");
            }
            assert!(m.sigma2_d()[n].abs() < 1e-20);
        }
    }

    #[test]
    fn quaternion_mean_of_opposite_turns_is_between() {
        // ±0.2 rad about z: the mean is the identity; residuals ±0.2 rad about z.
        let a = quat::exp(&[0.0, 0.0, 0.2]);
        let b = quat::exp(&[0.0, 0.0, -0.2]);
        let id = vec![0.0, 1.0];
        let m = TaskModel::fit_aligned(
            &[quat_demo(&[a, a]), quat_demo(&[b, b])],
            &[id.clone(), id],
            &FitParams::default(),
        )
        .unwrap();
        let mean = &m.mean()[0..4];
        assert!(
            mean.iter()
                .zip(quat::IDENTITY)
                .all(|(x, y)| (x - y).abs() < 1e-12)
        );
        // Range: rotation vectors relative to demo 0's first orientation span 0.4 rad.
        assert!(close(m.ranges()[2], 0.4));
        // σ²_D = 2·0.2² / 0.4² / 1 = 0.5.
        assert!(close(m.sigma2_d()[0], 0.5));
        // The command at u = 1 turns the mean by +3σ = 3·0.2 rad about ±z.
        let cmd = m.command(&[1.0], 0.0).unwrap();
        let r = quat::log(&[cmd[0], cmd[1], cmd[2], cmd[3]]);
        assert!(close(r[2].abs(), 0.6) && r[0].abs() < 1e-12);
    }

    #[test]
    fn execution_warp_inverts_the_log() {
        let (demos, warps) = three_demos();
        let m = TaskModel::fit_aligned(&demos, &warps, &FitParams::default()).unwrap();
        // 5 samples at half speed: ref times 0, 0.5, …, 2 → warp 0, 2, 4.
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0, 5.0, 10.0, 15.0, 20.0]),
            ref_time_log: vec![0.0, 0.5, 1.0, 1.5, 2.0],
        };
        assert_eq!(m.execution_warp(&exec).unwrap(), [0.0, 2.0, 4.0]);
        // A pause (flat log) maps to its first sample; a late start is extrapolated at the
        // first pace (2 samples per reference sample): 0.5 reference samples early → −1.
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0; 5]),
            ref_time_log: vec![0.5, 1.0, 1.0, 1.0, 2.0],
        };
        assert_eq!(m.execution_warp(&exec).unwrap(), [-1.0, 1.0, 4.0]);
        // A log that stops short of the last reference sample (its last step went past it)
        // is extrapolated from its last sample (4) at the last moving pace (2 samples per
        // reference sample): 4 + 0.5·2 = 5, so the gradient there is 3, not 0.
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0; 5]),
            ref_time_log: vec![0.0, 0.5, 1.0, 1.5, 1.5],
        };
        assert_eq!(m.execution_warp(&exec).unwrap(), [0.0, 2.0, 5.0]);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let (demos, warps) = three_demos();
        let p = FitParams::default();
        assert!(matches!(
            TaskModel::fit_aligned(&demos[..1], &warps[..1], &p),
            Err(Error::TooFewDemonstrations { found: 1 })
        ));
        let mut w = warps.clone();
        w[1] = vec![0.0, 3.0, 2.0];
        assert!(matches!(
            TaskModel::fit_aligned(&demos, &w, &p),
            Err(Error::BadWarp { demo_idx: 1, .. })
        ));
        w[1] = vec![0.0, 1.0, 4.5];
        assert!(matches!(
            TaskModel::fit_aligned(&demos, &w, &p),
            Err(Error::BadWarp { demo_idx: 1, .. })
        ));
        let bad = FitParams {
            k_max: 0,
            ..FitParams::default()
        };
        assert!(matches!(
            TaskModel::fit_aligned(&demos, &warps, &bad),
            Err(Error::BadParam { name: "k_max", .. })
        ));
        let m = TaskModel::fit_aligned(&demos, &warps, &p).unwrap();
        assert!(m.command(&[2.0, 0.0], 1.0).is_err());
        assert!(m.command(&[0.0], 1.0).is_err());
        assert!(m.command(&[0.0, 0.0], 2.5).is_err());
        assert!(m.command(&[0.0, f64::NAN], 1.0).is_err());
        let mut m2 = m.clone();
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0; 3]),
            ref_time_log: vec![0.0, 2.0, 1.0],
        };
        assert!(matches!(m2.update(&exec), Err(Error::BadLog { .. })));
        let exec = Execution {
            demonstration: demo(&["force"], vec![0.0; 3]),
            ref_time_log: vec![0.0, 2.0],
        };
        assert!(matches!(m2.update(&exec), Err(Error::BadLog { .. })));
        let exec = Execution {
            demonstration: demo(&["torque"], vec![0.0; 3]),
            ref_time_log: vec![0.0, 1.0, 2.0],
        };
        assert!(matches!(
            m2.update(&exec),
            Err(Error::ChannelMismatch { .. })
        ));
        assert_eq!(m2.count(), 3);
        // A partial quaternion block is rejected.
        let q = demo(&["qx", "qy", "qz"], vec![0.0; 6]);
        let id = vec![0.0, 1.0];
        assert!(TaskModel::fit_aligned(&[q.clone(), q], &[id.clone(), id], &p).is_err());
    }

    #[test]
    fn serde_round_trip_keeps_statistics() {
        let (demos, warps) = three_demos();
        let m = TaskModel::fit_aligned(&demos, &warps, &FitParams::default()).unwrap();
        let json = serde_json::to_string(&m).unwrap();
        let back: TaskModel = serde_json::from_str(&json).unwrap();
        assert_eq!(back.sigma2_d(), m.sigma2_d());
        assert_eq!(back.mean(), m.mean());
        assert_eq!(
            back.command(&[0.5, -0.5], 1.3).unwrap(),
            m.command(&[0.5, -0.5], 1.3).unwrap()
        );
        let broken = json.replace("\"n_ref\":3", "\"n_ref\":4");
        assert!(serde_json::from_str::<TaskModel>(&broken).is_err());
    }
}
