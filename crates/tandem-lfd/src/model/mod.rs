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
//! The anchor `q_a(n)` at reference sample `n` is the reference demonstration's orientation
//! at its aligned time `ψ_0(n)`, fixed at fit time.
//! Each orientation `q` enters the statistics as `r = log(q_a⁻¹ ⊗ q)` (the shortest rotation
//! vector, so `q` and `−q` give the same `r`). The mean orientation is `q_a ⊗ exp(r̄)`, with
//! `r̄` the mean rotation vector; residuals are `r − r̄`. Because the anchor never changes,
//! these are ordinary vector statistics: an [`TaskModel::update`] equals a refit on the same
//! aligned data exactly (up to rounding). For the small orientation spreads of one task
//! instant, `q_a ⊗ exp(r̄)` agrees with the Karcher mean to second order in the spread.
//!
//! # Files
//!
//! `params.rs`: [`FitParams`]. `layout.rs`: the tangent layout and what reads a
//! demonstration through it. `fit.rs`: checks, alignment, statistics from warps.
//! `stats.rs`: per sample sufficient statistics and derived arrays. `execution.rs`:
//! [`Execution`] and the update (Eq. 21). `corrections.rs`: [`Corrections`] and the
//! command (Eq. 7).
//!
//! # Names
//!
//! A per reference-sample array keeps its plain name for the whole array (`anchors`,
//! `tangent_mean`, `scatter`: `n_ref` rows); the slice of it at one reference sample `n`
//! carries the suffix `_n` (`anchors_n`, `mean_n`, `scatter_n`); a value interpolated at a
//! fractional reference time carries `_t` (`comps_t`). A warp (`warp`, `warps[i]`) is the
//! demo time (demo samples, fractional) at every reference sample. `d` is the tangent
//! dimension, `m` the channel count, `coord` an index into the tangent layout.

use serde::{Deserialize, Serialize};

use crate::demo::{DT_TOLERANCE, Demonstration};
use crate::quat::Quat;
use crate::{Error, Result};

mod corrections;
mod execution;
mod fit;
mod holds;
mod layout;
mod params;
mod stats;

pub use corrections::Corrections;
pub use execution::{EXECUTION_DURATION_RATIO, Execution, Resampled};
pub use holds::{Comparison, HoldRule, HoldSpec};
pub use params::{FitParams, RateTerm, Reference};

use corrections::CorrectionCache;
use layout::Layout;
use stats::packed_len;

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
    corrections: CorrectionCache,
}

/// The persisted part of a [`TaskModel`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelData {
    channel_names: Vec<String>,
    layout: Layout,
    dt_s: f64,
    n_ref: usize,
    /// Index of the reference among the demonstrations given to the fit.
    reference_idx: usize,
    k_max: usize,
    ranges: Vec<f64>,
    /// `n_ref × n_quat` anchor quaternions `[x, y, z, w]`.
    anchors: Vec<Quat>,
    count: usize,
    /// `n_ref × d` means in the tangent layout.
    tangent_mean: Vec<f64>,
    /// `n_ref × d(d+1)/2` packed upper-triangular scatter matrices `Σ_i e_i e_iᵀ`.
    scatter: Vec<f64>,
    grad_min: Vec<f64>,
    grad_max: Vec<f64>,
    /// How the rate enters `σ²_D`. Not a field of the wire format: it is written after the
    /// `d` ranges of `ranges` (see [`ModelData::split_rate_term`]).
    #[serde(skip)]
    rate_term: RateTerm,
    /// With a duration window ([`RateTerm::Relative`]`::window > 0`): per reference sample
    /// the mean time the demonstrations and executions spent on the window around it (demo
    /// samples), `n_ref` values; empty otherwise. Written after the rate term's widths.
    #[serde(skip)]
    duration_mean: Vec<f64>,
    /// The scatter (sum of squared deviations) of those durations, `n_ref` values; empty
    /// without a duration window.
    #[serde(skip)]
    duration_scatter: Vec<f64>,
}

impl ModelData {
    /// Reads the rate term out of the entries after the `d` ranges (how a model is stored
    /// without a change of the state format: docs/decisions.md, "Fit defaults on the task
    /// zoo", "An old state file keeps its model", and "Timing-only variable sections: the
    /// duration term"):
    ///
    /// - none: [`RateTerm::Absolute`], a model saved before the relative term;
    /// - one, the opening's width: [`RateTerm::Relative`] without a duration window (every
    ///   model saved before the duration term, with an opening of 13);
    /// - `2 + 2·n_ref`: the opening's width, the window's width, then the window durations'
    ///   means and scatters.
    ///
    /// A build from before the duration term refuses the last kind as inconsistent (its
    /// ranges are too long) rather than misreading it.
    fn split_rate_term(&mut self) -> Result<()> {
        let d = self.layout.dim();
        let bad = |why: String| Error::BadData {
            what: "task model".into(),
            why,
        };
        let width = |v: f64, what: &str| -> Result<usize> {
            if v.is_finite() && v >= 0.0 && v.fract() == 0.0 && v <= 1e9 {
                Ok(v as usize)
            } else {
                Err(bad(format!(
                    "the rate term's {what} {v} is not a number of samples"
                )))
            }
        };
        self.rate_term = RateTerm::Absolute;
        self.duration_mean.clear();
        self.duration_scatter.clear();
        if self.ranges.len() <= d {
            return Ok(());
        }
        let tail = self.ranges.split_off(d);
        let n = self.n_ref;
        if tail.len() == 1 {
            self.rate_term = RateTerm::Relative {
                opening: width(tail[0], "opening")?,
                window: 0,
            };
        } else if tail.len() == 2 + 2 * n {
            let window = width(tail[1], "window")?;
            if window == 0 {
                return Err(bad("a duration window of 0 samples with durations".into()));
            }
            self.rate_term = RateTerm::Relative {
                opening: width(tail[0], "opening")?,
                window,
            };
            self.duration_mean = tail[2..2 + n].to_vec();
            self.duration_scatter = tail[2 + n..].to_vec();
        } else {
            return Err(bad(format!(
                "{} entries after the {d} ranges, which are no rate term",
                tail.len()
            )));
        }
        self.rate_term.validate().map_err(|e| bad(e.to_string()))
    }
}

impl TryFrom<ModelData> for TaskModel {
    type Error = Error;
    fn try_from(mut data: ModelData) -> Result<Self> {
        let d = data.layout.dim();
        data.split_rate_term()?;
        let n = data.n_ref;
        let ok = n >= 2
            && data.count >= 2
            && data.k_max >= 1
            && data.dt_s.is_finite()
            && data.dt_s > 0.0
            && data.ranges.len() == d
            && data.anchors.len() == n * data.layout.n_quat
            && data.tangent_mean.len() == n * d
            && data.scatter.len() == n * packed_len(d)
            && data.grad_min.len() == n
            && data.grad_max.len() == n
            && data.layout.fits(data.channel_names.len())
            && data.ranges.iter().all(|r| r.is_finite() && *r > 0.0)
            && data
                .tangent_mean
                .iter()
                .chain(&data.scatter)
                .chain(&data.duration_mean)
                .chain(&data.duration_scatter)
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
    fn from(model: TaskModel) -> Self {
        let mut data = model.data;
        if let RateTerm::Relative { opening, window } = data.rate_term {
            data.ranges.push(opening as f64);
            if window > 0 {
                data.ranges.push(window as f64);
                data.ranges.extend(&data.duration_mean);
                data.ranges.extend(&data.duration_scatter);
            }
        }
        data
    }
}

/// `(lo, hi, alpha)` with `t = lo + alpha`, clamped to `[0, n − 1]`.
fn bracket(t: f64, n: usize) -> (usize, usize, f64) {
    let t = t.clamp(0.0, (n - 1) as f64);
    let lo = (t.floor() as usize).min(n - 1);
    let hi = (lo + 1).min(n - 1);
    (lo, hi, t - lo as f64)
}

/// Reference samples per parallel work item in per-sample loops (results do not depend
/// on the split).
const PAR_MIN_LEN: usize = 512;

/// Rejects a demonstration whose sample period differs from `dt_ref` by more than 1 %;
/// `whose` names where `dt_ref` came from in the error (`the model`).
fn check_dt(demo: &Demonstration, dt_ref: f64, whose: &dyn Fn() -> String) -> Result<()> {
    if (demo.dt_s() - dt_ref).abs() > DT_TOLERANCE * dt_ref {
        let (line, column) = demo.header_at(None);
        return Err(Error::SamplePeriodMismatch {
            file: demo.source().into(),
            line,
            column,
            expected_s: dt_ref,
            expected_from: whose(),
            found_s: demo.dt_s(),
        });
    }
    Ok(())
}

impl TaskModel {
    fn from_data(data: ModelData) -> Self {
        let corrections = CorrectionCache::new(data.n_ref);
        let mut model = Self {
            data,
            mean: Vec::new(),
            grad_mean: Vec::new(),
            sigma2_d: Vec::new(),
            corrections,
        };
        model.refresh_derived();
        model
    }

    /// Number of reference samples `T_ref` (the length of every per-time array).
    pub fn n_ref(&self) -> usize {
        self.data.n_ref
    }

    /// Index of the reference demonstration (whose samples are the time axis) among the
    /// demonstrations given to [`TaskModel::fit`] (see [`FitParams::reference`]); 0 after
    /// [`TaskModel::fit_aligned`].
    pub fn reference_idx(&self) -> usize {
        self.data.reference_idx
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

    /// The rate's part of [`TaskModel::sigma2_d`] per reference sample (dimensionless, as
    /// [`TaskModel::rate_term`] says; the rest is the channels' part): it scales as
    /// `1/r_rate²` with the rate's range, so a range `r` instead of the model's gives
    /// `σ²_D − part + part · (r_model / r)²`.
    #[must_use]
    pub fn sigma2_d_rate(&self) -> Vec<f64> {
        self.rate_part()
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

    /// How the demonstrations' speeds enter [`TaskModel::sigma2_d`]: the form the model was
    /// fitted with ([`FitParams::rate_term`]; [`RateTerm::Absolute`] for a model saved
    /// before the relative term, [`RateTerm::Relative`] without a duration window for one
    /// saved before the duration term).
    pub fn rate_term(&self) -> RateTerm {
        self.data.rate_term
    }

    /// Ranges `r_j` of the tangent coordinates; `W⁺ = diag(1/r_j²)`.
    pub fn ranges(&self) -> &[f64] {
        &self.data.ranges
    }

    /// Per channel (model channel order, [`TaskModel::channel_names`]) the weight `W_jj` with
    /// which the fit aligned every demonstration to the reference (Eq. 3), and
    /// [`TaskModel::align_demonstration`] aligns one, when `FitParams::warp.weights` does not
    /// give them: `1/r_j²` for a scalar channel, `4/r²` for each channel of a quaternion block
    /// (`r` the largest of the block's rotation ranges). Read-only; for peers that must align
    /// the same data with the same weights (the task zoo's alignment comparison).
    #[must_use]
    pub fn warp_weights(&self) -> Vec<f64> {
        let d = self.data.layout.dim();
        self.data
            .layout
            .warp_weights(&self.data.ranges[..d - 1], self.data.channel_names.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quat;

    pub(super) fn demo(names: &[&str], samples: Vec<f64>) -> Demonstration {
        Demonstration::new(names.iter().map(|s| s.to_string()).collect(), samples, 0.01).unwrap()
    }

    pub(super) fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * (1.0 + b.abs())
    }

    /// Demo 1 is demo 0 played at varying speed; warp values given.
    pub(super) fn three_demos() -> (Vec<Demonstration>, Vec<Vec<f64>>) {
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

    /// The model of [`three_demos`] with the default parameters.
    pub(super) fn three_demo_model() -> TaskModel {
        let (demos, warps) = three_demos();
        TaskModel::fit_aligned(&demos, &warps, &FitParams::default()).unwrap()
    }

    #[test]
    fn a_model_saved_without_the_rate_terms_marker_keeps_the_absolute_term() {
        let (demos, warps) = three_demos();
        let params = FitParams {
            rate_term: RateTerm::RELATIVE_WITHOUT_WINDOW,
            ..FitParams::default()
        };
        let model = TaskModel::fit_aligned(&demos, &warps, &params).unwrap();
        let data = ModelData::from(model.clone());
        // The relative term without a duration window is persisted as one entry after the
        // d = 2 ranges: the opening's width. Loaded back, the same model.
        assert_eq!(data.ranges.len(), 3);
        assert_eq!(data.ranges[2], 13.0);
        let again = TaskModel::try_from(data.clone()).unwrap();
        assert_eq!(again.sigma2_d(), model.sigma2_d());
        assert_eq!(again.ranges(), model.ranges());
        // Without it (a model saved before the relative term), the absolute term with the
        // stored rate range 25/6: n = 0, gradients 1, 1.5, 1, var 1/12 → (1/12)·36/625 =
        // 3/625; n = 1, gradients 1, 2.5, 1, var 3/4 → 27/625, plus the force's 1/192.
        let mut legacy = data;
        legacy.ranges.pop();
        let old = TaskModel::try_from(legacy).unwrap();
        assert!(close(old.sigma2_d()[0], 3.0 / 625.0));
        assert!(close(old.sigma2_d()[1], 1.0 / 192.0 + 27.0 / 625.0));
        // It stays absolute when saved again, and after an update (Eq. 21).
        assert_eq!(ModelData::from(old.clone()).ranges.len(), 2);
        let mut updated = old.clone();
        updated
            .update(&crate::Execution {
                demonstration: demo(&["force"], vec![0.0, 10.0, 20.0]),
                ref_time_log: vec![0.0, 1.0, 2.0],
            })
            .unwrap();
        assert_eq!(ModelData::from(updated).ranges.len(), 2);
        // An opening that is no width is refused, naming it.
        let mut other = ModelData::from(model);
        other.ranges[2] = 8.0;
        let err = TaskModel::try_from(other).unwrap_err().to_string();
        assert!(err.contains("opening must be an odd number"), "{err}");
    }

    #[test]
    fn the_duration_term_by_hand_and_through_the_serde_form() {
        let (demos, warps) = three_demos();
        let params = FitParams {
            rate_term: RateTerm::Relative {
                opening: 13,
                window: 3,
            },
            ..FitParams::default()
        };
        let model = TaskModel::fit_aligned(&demos, &warps, &params).unwrap();
        // Windows of 3 samples: n = 0 spans [0, 1], durations 1, 1.5, 1 (mean 7/6, variance
        // 1/12); n = 1 spans [0, 2]: 2, 4, 2 (mean 8/3, variance 4/3); n = 2 spans [1, 2]:
        // 1, 2.5, 1 (mean 3/2, variance 3/4). The term is var / (r_rate · D̄ / ψ̄̇₀)² with
        // r_rate/ψ̄̇₀ = 3: 1/147, 1/48, 1/27; the opened rate term is 1/147 everywhere
        // (`hand_derived_statistics`), so the rate's part is the larger of the two.
        let part = model.sigma2_d_rate();
        assert!(close(part[0], 1.0 / 147.0));
        assert!(close(part[1], 1.0 / 48.0));
        assert!(close(part[2], 1.0 / 27.0));
        assert!(close(model.sigma2_d()[1], 1.0 / 192.0 + 1.0 / 48.0));
        // Persisted after the ranges: the widths, then 3 means and 3 scatters.
        let data = ModelData::from(model.clone());
        assert_eq!(data.ranges.len(), 2 + 2 + 2 * 3);
        assert_eq!(&data.ranges[2..4], &[13.0, 3.0]);
        assert!(close(data.ranges[5], 8.0 / 3.0) && close(data.ranges[8], 8.0 / 3.0));
        let again = TaskModel::try_from(data.clone()).unwrap();
        assert_eq!(again.rate_term(), model.rate_term());
        assert_eq!(again.sigma2_d(), model.sigma2_d());
        // A tail of another length is refused, naming what it holds.
        let mut cut = data;
        cut.ranges.pop();
        let err = TaskModel::try_from(cut).unwrap_err().to_string();
        assert!(err.contains("which are no rate term"), "{err}");
    }

    /// The model of two 2-sample demonstrations holding the constant orientations `a` and
    /// `b` (channels `qx, qy, qz, qw`), identity warps.
    fn constant_orientations_model(a: quat::Quat, b: quat::Quat) -> TaskModel {
        let quat_demo = |q: quat::Quat| demo(&["qx", "qy", "qz", "qw"], [q, q].concat());
        let id = vec![0.0, 1.0];
        TaskModel::fit_aligned(
            &[quat_demo(a), quat_demo(b)],
            &[id.clone(), id],
            &FitParams::default(),
        )
        .unwrap()
    }

    #[test]
    fn warp_weights_are_the_inverse_squared_ranges() {
        // force spans 0..20 over the demonstrations: W = 1/20².
        assert_eq!(three_demo_model().warp_weights(), [1.0 / 400.0]);
    }

    #[test]
    fn quaternion_mean_of_q_and_minus_q_is_q() {
        let q = quat::exp(&[0.1, -0.2, 0.3]);
        let model = constant_orientations_model(q, q.map(|v| -v));
        assert_eq!(model.tangent_names(), ["q.rx", "q.ry", "q.rz", "rate"]);
        for n in 0..2 {
            let got = &model.mean()[n * 4..(n + 1) * 4];
            for k in 0..4 {
                assert!((got[k] - q[k]).abs() < 1e-12, "{got:?} vs {q:?}");
            }
            assert!(model.sigma2_d()[n].abs() < 1e-20);
        }
    }

    #[test]
    fn quaternion_mean_of_opposite_turns_is_between() {
        // ±0.2 rad about z: the mean is the identity; residuals ±0.2 rad about z.
        let a = quat::exp(&[0.0, 0.0, 0.2]);
        let b = quat::exp(&[0.0, 0.0, -0.2]);
        let model = constant_orientations_model(a, b);
        let mean = &model.mean()[0..4];
        assert!(
            mean.iter()
                .zip(quat::IDENTITY)
                .all(|(x, y)| (x - y).abs() < 1e-12)
        );
        // Range: rotation vectors relative to demo 0's first orientation span 0.4 rad.
        assert!(close(model.ranges()[2], 0.4));
        // σ²_D = 2·0.2² / 0.4² / 1 = 0.5.
        assert!(close(model.sigma2_d()[0], 0.5));
        // The command at u = 1 turns the mean by +3σ = 3·0.2 rad about ±z.
        let cmd = model.command(&[1.0], 0.0).unwrap();
        let r = quat::log(&[cmd[0], cmd[1], cmd[2], cmd[3]]);
        assert!(close(r[2].abs(), 0.6) && r[0].abs() < 1e-12);
    }

    #[test]
    fn serde_round_trip_keeps_statistics() {
        let model = three_demo_model();
        let json = serde_json::to_string(&model).unwrap();
        let back: TaskModel = serde_json::from_str(&json).unwrap();
        assert_eq!(back.sigma2_d(), model.sigma2_d());
        assert_eq!(back.mean(), model.mean());
        assert_eq!(
            back.command(&[0.5, -0.5], 1.3).unwrap(),
            model.command(&[0.5, -0.5], 1.3).unwrap()
        );
        let broken = json.replace("\"n_ref\":3", "\"n_ref\":4");
        assert!(serde_json::from_str::<TaskModel>(&broken).is_err());
    }
}
