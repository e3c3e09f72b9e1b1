//! Parameters of the GDTW optimization.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// `κ`, the noise-proportional part of the slope penalty: an alignment uses
/// `λ_inst + κ ν̂` in place of [`WarpParams::lambda_inst`] ([`crate::effective_lambda_inst`]),
/// where `ν̂` is the loss's estimated noise floor (the `W`-weighted white-noise variance of
/// both signals, from their second differences). Noisier signals so get a stronger slope
/// penalty, clean ones keep `λ_inst`; `ν̂` is in the loss's units, like `λ_inst`, so `κ` is
/// dimensionless. Chosen with the defaults on the families benchmark (docs/decisions.md,
/// "tandem-warp defaults").
pub const NOISE_PENALTY: f64 = 2.0;

/// Default spacing of time nodes, in reference samples, when [`WarpParams::n_nodes`] is `None`.
pub const DEFAULT_NODE_SPACING: usize = 4;

/// GDTW parameters (Deriso & Boyd; paper §II-B1, Eq. 3).
///
/// Time is normalized on both sides: reference time `t ∈ [0, 1]` (reference sample `n` is at
/// `t = n / (T_ref − 1)`), query time `φ(t) ∈ [0, 1]` (query sample `q` is at `q / (T_query − 1)`).
/// The warp `φ` is piecewise linear between time nodes placed on reference samples; the
/// optimizer minimizes
///
/// `∫₀¹ (x₂(φ(t)) − x₁(t))ᵀ W (x₂(φ(t)) − x₁(t)) dt + λ_inst ∫₀¹ (φ'(t) − 1)² dt + λ_cum ∫₀¹ (φ(t) − t)² dt`
///
/// subject to `φ(0) = 0`, `φ(1) = 1` and `slope_min ≤ φ' ≤ slope_max`, where `x₁` is the
/// reference, `x₂` the query (linearly interpolated at fractional times) and `W = diag(weights)`.
/// See [`crate::objective_of`] for the exact discretization.
///
/// Solver: a first dynamic-programming pass over the whole feasible band with
/// [`coarse_nodes`](Self::coarse_nodes) nodes and at least
/// [`coarse_candidates`](Self::coarse_candidates) candidates each, then
/// [`refinements`](Self::refinements) passes that double the node count up to all
/// [`n_nodes`](Self::n_nodes) nodes, each on a finer candidate grid centred on the previous
/// solution (see [`refine_radius`](Self::refine_radius)), then two polish passes on all `N`
/// nodes ([`POLISH_STEPS`](crate::POLISH_STEPS)). Every pass keeps the best warp so far (by the
/// exact objective). Candidate spacings are tied to the node spacing
/// ([`COARSE_SLOPE_STEP`](crate::COARSE_SLOPE_STEP),
/// [`REFINE_SPACING_RATIO`](crate::REFINE_SPACING_RATIO)), so more nodes, more candidates, more
/// refinements or a larger radius widen or refine the search and never coarsen it.
///
/// **Defaults** were chosen on the families benchmark `bench/peers/warp_families.py` (eight
/// families of synthetic demonstrations with known warps: clean and noisy sensors, ripple and
/// vibration, long dwells, abrupt speed changes, very different lengths, channels of very
/// different scales; docs/decisions.md, "tandem-warp defaults"), by the worst family's ratio
/// to the authors' `gdtw` at its most accurate setting: `λ_inst = 0.005` plus
/// [`NOISE_PENALTY`] times the estimated noise floor, `λ_cum = 0.001`; and the smoothing
/// [`smooth_width`](Self::smooth_width) = 7 by the worst family's change against no smoothing
/// (docs/decisions.md, "tandem-warp: smoothing before alignment"); the fill of flat stretches
/// [`fill_length`](Self::fill_length) = 0.1 by the worst family's ratio to `gdtw` again
/// (docs/decisions.md, "tandem-warp: flat stretches").
/// The alignment is done on the caller's scale: the benchmark, like `tandem-lfd`, divides
/// every channel by its range (`W = diag(1/r²)` on raw data).
/// The defaults align two ~10 000-sample, 9-channel fixture demonstrations in about 14 ms on
/// one core (bench `align_fixture` on the 2-core build machine: 14.1 and 13.7 ms, against 16.6
/// and 15.9 ms for the build before the fill and the bounded transitions in the same session;
/// docs/decisions.md, "tandem-warp: flat stretches").
/// To solve "the same problem" as the authors'
/// `gdtw` package, use `n_nodes = Some(T_ref)` (one node per reference sample),
/// `n_candidates = 301`, `smooth_width = 1` and `fill_length = 0`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WarpParams {
    /// Number `N` of time nodes of the final passes, placed on reference samples as evenly as
    /// possible (the first and last reference samples are always nodes). The loss is integrated
    /// over every reference sample between nodes, so `N` sets only the warp's flexibility.
    /// `None` (default) = one node every [`DEFAULT_NODE_SPACING`] reference samples.
    /// Must be ≥ 2; values above `T_ref` are clamped to `T_ref` (one node per reference sample).
    pub n_nodes: Option<usize>,
    /// Least number `M` of candidate values of `φ` per node in the refinement passes; more
    /// candidates widen the searched range at the same spacing (see
    /// [`refine_radius`](Self::refine_radius)). Must be in `3..=65535`. Default: 15.
    pub n_candidates: usize,
    /// `λ_inst`, weight of `∫ (φ'(t) − 1)² dt` (normalized time), in the loss's units; the
    /// alignment adds [`NOISE_PENALTY`] times the loss's estimated noise floor
    /// ([`crate::effective_lambda_inst`]). Must be finite and ≥ 0. Default: 0.005, chosen on
    /// the families benchmark by the worst family's ratio to `gdtw` (docs/decisions.md,
    /// "tandem-warp defaults"); the former 0.02, chosen on one family, was 1.18 times `gdtw`'s
    /// mean error on the clean family. `tandem-lfd` fits with 0.02, because the model also reads
    /// the warps' gradients. Its effect depends on the loss scale: the benchmark's channels
    /// span 1 (range-scaled, as `tandem-lfd` weights them).
    pub lambda_inst: f64,
    /// `λ_cum`, weight of `∫ (φ(t) − t)² dt` (normalized time). Must be finite and ≥ 0.
    /// Default: 0.001, a tie-breaker only (ground-truth benchmark: pulling the warp towards the
    /// identity never helped; `λ_cum = 0.1` gave 2.78 query samples against 2.77).
    pub lambda_cum: f64,
    /// `s_min`, lower bound on `φ'` in normalized time. Must be in `(0, 1]`. Default: 0.25.
    pub slope_min: f64,
    /// `s_max`, upper bound on `φ'` in normalized time. Must be finite and ≥ 1. Default: 4.
    pub slope_max: f64,
    /// Number of grid-refinement passes after the first pass. Pass `k < refinements` uses
    /// `min(N, coarse_nodes · 2^k)` nodes (and the coarse loss quadrature while below `N`); the
    /// last pass uses all `N` nodes. The polish passes follow in any case. Must be ≤ 64.
    /// Default: 4.
    pub refinements: usize,
    /// Least half-width of a refinement pass's candidate range at a node, in units of the
    /// previous pass's resolution there: its candidate spacing, but at least the query span of a
    /// slope change of [`COARSE_SLOPE_STEP`](crate::COARSE_SLOPE_STEP) over its node spacing
    /// (what its nodes and quadrature cannot resolve). The candidates are
    /// [`REFINE_SPACING_RATIO`](crate::REFINE_SPACING_RATIO) resolutions apart, centred on the
    /// previous solution and truncated to the feasible band; there are
    /// `max(n_candidates, 2 ⌈refine_radius / REFINE_SPACING_RATIO⌉ + 1)` of them, so a larger
    /// radius or more candidates widen the range and never coarsen it. Must be finite and
    /// ≥ 0.5. Default: 2.5 (with 15 candidates: the former grid, ±7 spacings of 5/14).
    pub refine_radius: f64,
    /// In refinement passes, a transition from candidate `j` to candidate `k` of the next node
    /// is searched only if `|k − j| ≤ max_jump` (both grids are centred on the previous
    /// solution and have the fixed relative spacing
    /// [`REFINE_SPACING_RATIO`](crate::REFINE_SPACING_RATIO), so this bounds how fast the
    /// solution may depart from it whatever the candidate count); slope bounds are always
    /// enforced. The polish passes search every feasible transition. `None` = search every
    /// feasible transition. Default: `Some(3)`.
    pub max_jump: Option<usize>,
    /// Number of nodes of the first pass, which searches the whole feasible band; clamped to
    /// `N`. While a pass has fewer than `N` nodes it evaluates the loss at
    /// [`COARSE_POINTS_PER_SEGMENT`](crate::COARSE_POINTS_PER_SEGMENT) reference samples per
    /// segment instead of all of them. Must be ≥ 2. Default: 48.
    pub coarse_nodes: usize,
    /// Least number of candidates per node in the first pass, spread evenly over the feasible
    /// band `[max(s_min t, 1 − s_max (1 − t)), min(s_max t, 1 − s_min (1 − t))]`. More are used
    /// where needed to keep neighbouring candidates within a slope change of
    /// [`COARSE_SLOPE_STEP`](crate::COARSE_SLOPE_STEP) over the first pass's node spacing (at most
    /// 65535). Must be in `3..=65535`. Default: 97.
    pub coarse_candidates: usize,
    /// Diagonal of `W`: one weight ≥ 0 (finite) per channel. `None` (default) = all 1.
    pub weights: Option<Vec<f64>>,
    /// Width `w` (samples, odd) of the smoothing of both signals before they are compared:
    /// every channel passes three times through a centred running mean of `w` samples (of the
    /// reference and of the query alike; ends repeat their value), a kernel close to a Gaussian
    /// of standard deviation [`smooth_sigma`](crate::smooth_sigma)`(w) = √((w² − 1)/4)`
    /// samples that keeps every feature where it is. The loss, the noise floor of
    /// [`NOISE_PENALTY`] and [`crate::objective_of`] all see the smoothed signals. `1` = no
    /// smoothing. Must be odd and at most [`MAX_SMOOTH_WIDTH`](crate::MAX_SMOOTH_WIDTH).
    /// Default: 7 (σ ≈ 3.5 samples), chosen on the families benchmark (docs/decisions.md,
    /// "tandem-warp: smoothing before alignment"): sensor noise, ripple and vibration are
    /// finer than the warp can follow at its default node spacing, and fitting them moves it.
    /// `tandem-lfd` fits with 1 (its model was measured without).
    pub smooth_width: usize,
    /// `ℓ`, in normalized reference time (a fraction of the reference's length), of the fill
    /// of flat stretches: where neither signal moves beyond its noise (see
    /// [`FLAT_NOISE_MULTIPLE`](crate::FLAT_NOISE_MULTIPLE)), no channel identifies the warp
    /// and the slope penalty alone would draw a straight line between the stretch's edges;
    /// there the warp is replaced by the minimizer of the slope penalty plus `λ_inst ℓ² ∫ φ''²`
    /// held by the loss's Gauss–Newton curvature wherever the signals move, so the speed ratio
    /// at a flat stretch's edges carries on for about `ℓ` into it instead of jumping. Only
    /// samples inside flat stretches change, and only within the slope bounds;
    /// [`crate::Warp::objective`] is that of the returned warp. `0` = no fill: the minimizer of
    /// [`crate::objective_of`] alone. Must be finite and ≥ 0. Default: 0.1, chosen on the
    /// families benchmark (docs/decisions.md, "tandem-warp: flat stretches"). `tandem-lfd` fits
    /// with 0 (its model was measured without).
    pub fill_length: f64,
}

impl Default for WarpParams {
    fn default() -> Self {
        Self {
            n_nodes: None,
            n_candidates: 15,
            lambda_inst: 0.005,
            lambda_cum: 0.001,
            slope_min: 0.25,
            slope_max: 4.0,
            refinements: 4,
            refine_radius: 2.5,
            max_jump: Some(3),
            coarse_nodes: 48,
            coarse_candidates: 97,
            weights: None,
            smooth_width: 7,
            fill_length: 0.1,
        }
    }
}

fn bad(name: &'static str, why: impl Into<String>) -> Error {
    Error::BadParam {
        name,
        why: why.into(),
    }
}

impl WarpParams {
    /// Checks every field against its documented range (channel count is checked by
    /// [`crate::align`], which knows the signals).
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field, or [`Error::InfeasibleSlopes`] if
    /// `slope_min > 1` or `slope_max < 1` (no monotone warp joins `(0, 0)` and `(1, 1)`).
    pub fn validate(&self) -> Result<()> {
        if let Some(n) = self.n_nodes {
            if n < 2 {
                return Err(bad("n_nodes", format!("must be >= 2 (got {n})")));
            }
        }
        if !(3..=crate::solver::MAX_CANDIDATES).contains(&self.n_candidates) {
            return Err(bad(
                "n_candidates",
                format!("must be in 3..=65535 (got {})", self.n_candidates),
            ));
        }
        for (name, v) in [
            ("lambda_inst", self.lambda_inst),
            ("lambda_cum", self.lambda_cum),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(bad(name, format!("must be finite and >= 0 (got {v})")));
            }
        }
        if !(self.slope_min.is_finite() && self.slope_min > 0.0) {
            return Err(bad(
                "slope_min",
                format!("must be finite and > 0 (got {})", self.slope_min),
            ));
        }
        if !self.slope_max.is_finite() {
            return Err(bad(
                "slope_max",
                format!("must be finite (got {})", self.slope_max),
            ));
        }
        if self.slope_min > 1.0 || self.slope_max < 1.0 {
            return Err(Error::InfeasibleSlopes {
                slope_min: self.slope_min,
                slope_max: self.slope_max,
            });
        }
        if self.refinements > 64 {
            return Err(bad(
                "refinements",
                format!("must be <= 64 (got {})", self.refinements),
            ));
        }
        if !(self.refine_radius.is_finite() && self.refine_radius >= 0.5) {
            return Err(bad(
                "refine_radius",
                format!("must be finite and >= 0.5 (got {})", self.refine_radius),
            ));
        }
        if !(3..=crate::solver::MAX_CANDIDATES).contains(&self.coarse_candidates) {
            return Err(bad(
                "coarse_candidates",
                format!("must be in 3..=65535 (got {})", self.coarse_candidates),
            ));
        }
        if self.coarse_nodes < 2 {
            return Err(bad(
                "coarse_nodes",
                format!("must be >= 2 (got {})", self.coarse_nodes),
            ));
        }
        if self.smooth_width % 2 == 0 || self.smooth_width > crate::MAX_SMOOTH_WIDTH {
            return Err(bad(
                "smooth_width",
                format!(
                    "must be odd and at most {} (1 = no smoothing; got {})",
                    crate::MAX_SMOOTH_WIDTH,
                    self.smooth_width
                ),
            ));
        }
        if !(self.fill_length.is_finite() && self.fill_length >= 0.0) {
            return Err(bad(
                "fill_length",
                format!(
                    "must be finite and >= 0 (0 = no fill; got {})",
                    self.fill_length
                ),
            ));
        }
        if let Some(w) = &self.weights {
            if let Some((i, v)) = w
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v >= 0.0 && **v <= crate::MAX_ABS_VALUE))
            {
                return Err(bad(
                    "weights",
                    format!("weight {i} must be in [0, 1e100] (got {v})"),
                ));
            }
        }
        Ok(())
    }

    /// Validates and also checks `weights` against a channel count.
    pub(crate) fn validate_for(&self, n_channels: usize) -> Result<()> {
        self.validate()?;
        if let Some(w) = &self.weights {
            if w.len() != n_channels {
                return Err(bad(
                    "weights",
                    format!(
                        "has {} entries but the signals have {n_channels} channels",
                        w.len()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The diagonal of `W` for `n_channels` channels (all ones when `weights` is `None`).
    pub(crate) fn weight_vec(&self, n_channels: usize) -> Vec<f64> {
        self.weights
            .clone()
            .unwrap_or_else(|| vec![1.0; n_channels])
    }

    /// Number of nodes `N` actually used for a reference of `n_ref` samples.
    #[must_use]
    pub fn nodes_for(&self, n_ref: usize) -> usize {
        let n = self
            .n_nodes
            .unwrap_or_else(|| (n_ref - 1).div_ceil(DEFAULT_NODE_SPACING) + 1);
        n.clamp(2, n_ref.max(2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_documented() {
        let p = WarpParams::default();
        p.validate().unwrap();
        assert_eq!(p.n_candidates, 15);
        assert_eq!((p.lambda_inst, p.lambda_cum), (0.005, 0.001));
        assert_eq!(p.smooth_width, 7);
        assert_eq!(p.fill_length, 0.1);
        assert_eq!(p.nodes_for(9), 3);
        assert_eq!(p.nodes_for(10), 4);
        assert_eq!(p.nodes_for(2), 2);
    }

    #[test]
    fn rejects_bad_values() {
        let cases: Vec<(WarpParams, &str)> = vec![
            (
                WarpParams {
                    n_nodes: Some(1),
                    ..Default::default()
                },
                "n_nodes",
            ),
            (
                WarpParams {
                    smooth_width: 0,
                    ..Default::default()
                },
                "smooth_width",
            ),
            (
                WarpParams {
                    smooth_width: 8,
                    ..Default::default()
                },
                "smooth_width",
            ),
            (
                WarpParams {
                    smooth_width: crate::MAX_SMOOTH_WIDTH + 2,
                    ..Default::default()
                },
                "smooth_width",
            ),
            (
                WarpParams {
                    fill_length: -0.1,
                    ..Default::default()
                },
                "fill_length",
            ),
            (
                WarpParams {
                    fill_length: f64::NAN,
                    ..Default::default()
                },
                "fill_length",
            ),
            (
                WarpParams {
                    n_candidates: 2,
                    ..Default::default()
                },
                "n_candidates",
            ),
            (
                WarpParams {
                    lambda_inst: -1.0,
                    ..Default::default()
                },
                "lambda_inst",
            ),
            (
                WarpParams {
                    lambda_cum: f64::NAN,
                    ..Default::default()
                },
                "lambda_cum",
            ),
            (
                WarpParams {
                    slope_min: 0.0,
                    ..Default::default()
                },
                "slope_min",
            ),
            (
                WarpParams {
                    slope_max: f64::INFINITY,
                    ..Default::default()
                },
                "slope_max",
            ),
            (
                WarpParams {
                    refine_radius: 0.1,
                    ..Default::default()
                },
                "refine_radius",
            ),
            (
                WarpParams {
                    coarse_candidates: 1,
                    ..Default::default()
                },
                "coarse_candidates",
            ),
            (
                WarpParams {
                    coarse_nodes: 1,
                    ..Default::default()
                },
                "coarse_nodes",
            ),
            (
                WarpParams {
                    weights: Some(vec![1.0, -0.5]),
                    ..Default::default()
                },
                "weights",
            ),
        ];
        for (p, field) in cases {
            match p.validate() {
                Err(Error::BadParam { name, .. }) => assert_eq!(name, field),
                other => panic!("{field}: expected BadParam, got {other:?}"),
            }
        }
        for (lo, hi) in [(1.5, 3.0), (0.2, 0.9)] {
            let p = WarpParams {
                slope_min: lo,
                slope_max: hi,
                ..Default::default()
            };
            assert!(matches!(p.validate(), Err(Error::InfeasibleSlopes { .. })));
        }
    }

    #[test]
    fn serde_uses_defaults_and_rejects_unknown() {
        let p: WarpParams = serde_json::from_str(r#"{"lambda_inst": 0.5}"#).unwrap();
        assert_eq!(
            p,
            WarpParams {
                lambda_inst: 0.5,
                ..Default::default()
            }
        );
        assert!(serde_json::from_str::<WarpParams>(r#"{"lambda": 0.5}"#).is_err());
    }
}
