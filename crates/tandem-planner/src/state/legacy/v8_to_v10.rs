//! State formats 8 to 10: today's payload without the reference demonstration and the stored
//! executions (format 11), with the fit's warp parameters of its format.

use serde::Deserialize;
use tandem_lfd::TaskModel;

use crate::state::v11;

/// `tandem_warp::WarpParams` as state formats 4 to 8 wrote them: without `smooth_width` and
/// `fill_length`.
#[derive(Deserialize)]
pub(super) struct WarpParamsV8 {
    n_nodes: Option<usize>,
    n_candidates: usize,
    lambda_inst: f64,
    lambda_cum: f64,
    slope_min: f64,
    slope_max: f64,
    refinements: usize,
    refine_radius: f64,
    max_jump: Option<usize>,
    coarse_nodes: usize,
    coarse_candidates: usize,
    weights: Option<Vec<f64>>,
}

/// `tandem_warp::WarpParams` as state format 9 wrote them: format 8's fields, then
/// `smooth_width` (nesting [`WarpParamsV8`] reads the same bytes), without `fill_length`.
#[derive(Deserialize)]
pub(super) struct WarpParamsV9 {
    v8: WarpParamsV8,
    smooth_width: usize,
}

impl From<WarpParamsV9> for v11::WarpParams {
    /// The saved parameters with `fill_length = 0`: flat stretches were not filled (the
    /// alignment the file's model was fitted with).
    fn from(v9: WarpParamsV9) -> Self {
        let w = v9.v8;
        v11::WarpParams {
            n_nodes: w.n_nodes,
            n_candidates: w.n_candidates,
            lambda_inst: w.lambda_inst,
            lambda_cum: w.lambda_cum,
            slope_min: w.slope_min,
            slope_max: w.slope_max,
            refinements: w.refinements,
            refine_radius: w.refine_radius,
            max_jump: w.max_jump,
            coarse_nodes: w.coarse_nodes,
            coarse_candidates: w.coarse_candidates,
            weights: w.weights,
            smooth_width: v9.smooth_width,
            fill_length: 0.0,
        }
    }
}

impl From<WarpParamsV8> for v11::WarpParams {
    /// The saved parameters with `smooth_width = 1` and `fill_length = 0`: the signals were
    /// aligned unsmoothed and unfilled (the alignment the file's model was fitted with).
    fn from(v8: WarpParamsV8) -> Self {
        WarpParamsV9 {
            v8,
            smooth_width: 1,
        }
        .into()
    }
}

/// `FitParams` as state formats 4 to 10 wrote them, with the warp parameters `W` of that
/// format ([`WarpParamsV8`], [`WarpParamsV9`], [`v11::WarpParams`]).
#[derive(Deserialize)]
pub(super) struct FitParamsOld<W> {
    warp: W,
    ranges: Option<Vec<f64>>,
    min_range: f64,
    k_max: usize,
    schema: v11::ChannelSchema,
    reference: v11::Reference,
}

/// `FitParams` as state formats 4 to 8 wrote them.
pub(super) type FitParamsV8 = FitParamsOld<WarpParamsV8>;

impl<W: Into<v11::WarpParams>> From<FitParamsOld<W>> for v11::FitParams {
    fn from(old: FitParamsOld<W>) -> Self {
        v11::FitParams {
            warp: old.warp.into(),
            ranges: old.ranges,
            min_range: old.min_range,
            k_max: old.k_max,
            schema: old.schema,
            reference: old.reference,
        }
    }
}

/// `PlannerParams` as state formats 8 to 10 wrote them: the fit's parameters `F` of that
/// format.
#[derive(Deserialize)]
pub(super) struct PlannerParamsOld<F> {
    fit: F,
    confidence: v11::ConfidenceParams,
    sampler: v11::SamplerParams,
    holds: v11::HoldSpec,
}

/// The payload of state formats 8 to 10: [`PlannerParamsOld`], without the reference
/// demonstration and the recorded executions (format 11).
#[derive(Deserialize)]
pub(super) struct PayloadOld<F> {
    params: PlannerParamsOld<F>,
    model: TaskModel,
    observations: v11::Observations,
    confidence: v11::Confidence,
    outcome: v11::Outcome,
    rounds_recorded: usize,
    rounds: Vec<u64>,
}

/// The payload of state format 8 (the fit's warp without `smooth_width` and `fill_length`).
pub(super) type V8 = PayloadOld<FitParamsV8>;

/// The payload of state format 9 (the fit's warp without `fill_length`).
pub(super) type V9 = PayloadOld<FitParamsOld<WarpParamsV9>>;

/// The payload of state format 10: today's parameters, without the reference demonstration
/// and the recorded executions.
pub(super) type V10 = PayloadOld<v11::FitParams>;

impl<F: Into<v11::FitParams>> From<PayloadOld<F>> for v11::Payload {
    /// Without a reference demonstration and stored executions: its rounds cannot be
    /// replayed.
    fn from(old: PayloadOld<F>) -> Self {
        v11::Payload {
            params: v11::PlannerParams {
                fit: old.params.fit.into(),
                confidence: old.params.confidence,
                sampler: old.params.sampler,
                holds: old.params.holds,
            },
            model: old.model,
            observations: old.observations,
            confidence: old.confidence,
            outcome: old.outcome,
            rounds_recorded: old.rounds_recorded,
            rounds: old.rounds,
            reference: None,
            records: Vec::new(),
        }
    }
}
