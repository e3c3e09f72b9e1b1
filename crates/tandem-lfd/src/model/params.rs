//! [`FitParams`]: the parameters of a fit, and [`Reference`]: which demonstration's time
//! axis the model lives on.

use serde::{Deserialize, Serialize};

use crate::demo::ChannelSchema;
use crate::{Error, Result};

/// Which demonstration is the *reference*: the model's time axis is its sample index
/// (`n_ref = T_ref`), every other demonstration is aligned to it (GDTW, Eq. 2–3), and every
/// per-time array (mean, `σ²_D`, gradient bounds, confidence, schedule) is read on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reference {
    /// The first demonstration given (the model then depends on which file the user names
    /// first, by 5.8 pp of high confidence on the task zoo's selection seeds,
    /// docs/decisions.md, "Fit defaults on the task zoo").
    First,
    /// The medoid (default): every demonstration is tried as the reference (all the others
    /// aligned to it with the weights it would have as the reference, and the statistics
    /// fitted), and the one whose model has the least median `σ²_D` (Eq. 6) over its
    /// reference samples wins: the time axis on which the demonstrations agree best at a
    /// typical instant. Costs `n_demos` alignment passes instead of one. Ties go to the
    /// demonstration first in a fixed order of their content, and the others enter the
    /// statistics in that order, so the fitted model is bit-identical for any order in which
    /// the demonstrations are given (docs/decisions.md, "Fit defaults on the task zoo"; the
    /// default since "The medoid reference by default: labels follow the reference").
    #[default]
    Medoid,
}

impl std::fmt::Display for Reference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Reference::First => "first",
            Reference::Medoid => "medoid",
        })
    }
}

/// Parameters of [`TaskModel::fit`](crate::TaskModel::fit) and
/// [`TaskModel::fit_aligned`](crate::TaskModel::fit_aligned).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitParams {
    /// GDTW parameters for aligning every demonstration to the reference (Eq. 2–3).
    /// When `warp.weights` is `None` (default), the weights are derived from the ranges:
    /// `1/r_j²` per scalar channel and `4/r_q²` per quaternion component (a small rotation
    /// `δr` moves a unit quaternion by `|δr|/2`), so the alignment uses the same `W` as
    /// the statistics. Default: `WarpParams::default()` with `lambda_inst = 0.02` (four times
    /// the alignment crate's default): the model reads the warps' gradients too (the rate
    /// channel of `σ²_D`, the speed bounds), and a weaker slope penalty makes them follow
    /// every speed wobble, so that on the fixtures the variance contrast between the sanding
    /// passes and pass 4 falls from 3.13 to 2.84 (docs/decisions.md, "tandem-warp defaults");
    /// `smooth_width = 1` (no smoothing before alignment, the crate's default smooths over
    /// 7 samples) and `fill_length = 0` (flat stretches keep the straight line of the slope
    /// penalty, the crate's default fills them): the model's gradients and statistics were
    /// measured without either.
    pub warp: tandem_warp::WarpParams,
    /// Per tangent-coordinate ranges `r_j` (length `d`, warp gradient last; physical units:
    /// channel units, radians for rotation vectors, demo samples per reference sample for
    /// the rate); `W⁺ = diag(1/r_j²)` (Eq. 6). `None` (default): each scalar channel's
    /// range over all demonstrations' samples; for a quaternion block, the largest
    /// component range of the rotation vectors relative to the reference's first
    /// orientation; for the rate, the largest speed-up the alignment admits at the
    /// demonstrations' mean pace, `(warp.slope_max − 1) · ψ̄̇₀` (`ψ̄̇₀` the mean warp gradient).
    /// The rate's term of `σ²_D` divides its range by the local mean pace over `ψ̄̇₀`, so it
    /// weighs relative speed differences, and is opened over 13 reference samples (a rise
    /// narrower than the alignment can place a change of speed is removed; docs/decisions.md,
    /// "Fit defaults on the task zoo").
    pub ranges: Option<Vec<f64>>,
    /// Ranges below this are replaced by 1 (constant channels). Default: 1e-9.
    pub min_range: f64,
    /// Maximum number of correction components `k_max`; `K = min(n − 1, k_max, d)`.
    /// Must be ≥ 1. Default: 3.
    pub k_max: usize,
    /// Channel kinds and quaternion blocks. Default: [`ChannelSchema::default`].
    pub schema: ChannelSchema,
    /// Which demonstration is the reference (its samples are the model's time axis).
    /// Default: [`Reference::Medoid`] (the model does not depend on the order of the files;
    /// docs/decisions.md, "The medoid reference by default: labels follow the reference").
    /// [`TaskModel::fit_aligned`](crate::TaskModel::fit_aligned)
    /// takes warps onto demo 0, whose samples are then the time axis whatever this says.
    pub reference: Reference,
}

impl Default for FitParams {
    fn default() -> Self {
        Self {
            warp: tandem_warp::WarpParams {
                lambda_inst: 0.02,
                smooth_width: 1,
                fill_length: 0.0,
                ..tandem_warp::WarpParams::default()
            },
            ranges: None,
            min_range: 1e-9,
            k_max: 3,
            schema: ChannelSchema::default(),
            reference: Reference::Medoid,
        }
    }
}

impl FitParams {
    /// Checks every field (the warp parameters are checked by `tandem-warp`).
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field, or the schema's error.
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

    /// Checks that explicit [`FitParams::ranges`] has one entry per tangent coordinate
    /// (`d`, rate included).
    pub(super) fn check_ranges_len(&self, d: usize) -> Result<()> {
        match &self.ranges {
            Some(r) if r.len() != d => Err(Error::BadParam {
                name: "ranges",
                why: format!("has {} entries, the tangent layout has {d}", r.len()),
            }),
            _ => Ok(()),
        }
    }
}
