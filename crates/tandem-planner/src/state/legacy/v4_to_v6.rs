//! State formats 4 to 6: the paper's confidence model (no operator error rates, no evidence
//! of misses); 4 and 5 without round fingerprints; 4 with a two-robot schedule.

use serde::Deserialize;
use tandem_lfd::TaskModel;

use super::v7::{OutcomeV7, ScheduleV7};
use super::v8_to_v10::FitParamsV8;
use crate::state::v11;

/// `ConfidenceParams` as state formats 4 to 6 wrote them: the paper's model, without the
/// operator's error rates.
#[derive(Deserialize)]
struct ConfidenceParamsV6 {
    gamma_p: f64,
    sigma2_max: f64,
    epsilon: f64,
    mu_c: f64,
    gamma_c: f64,
}

impl From<ConfidenceParamsV6> for v11::ConfidenceParams {
    /// The saved parameters with both error rates 0 and not estimated
    /// (`ConfidenceParams::paper()`): the model the file's confidence was decided with.
    fn from(v6: ConfidenceParamsV6) -> Self {
        v11::ConfidenceParams {
            gamma_p: v6.gamma_p,
            sigma2_max: v6.sigma2_max,
            epsilon: v6.epsilon,
            mu_c: v6.mu_c,
            gamma_c: v6.gamma_c,
            ..v11::ConfidenceParams::from(&tandem_confidence::ConfidenceParams::paper())
        }
    }
}

/// `PlannerParams` as state formats 4 to 6 wrote them.
#[derive(Deserialize)]
struct PlannerParamsV6 {
    fit: FitParamsV8,
    confidence: ConfidenceParamsV6,
    sampler: v11::SamplerParams,
}

/// `Confidence` as state formats 4 to 6 wrote it.
#[derive(Deserialize)]
struct ConfidenceV6 {
    params: ConfidenceParamsV6,
    high: Vec<bool>,
}

/// `Observations` as state formats 4 to 6 wrote them (no evidence of misses).
#[derive(Deserialize)]
struct ObservationsV6 {
    corrections: Vec<f64>,
    supervised: Vec<f64>,
}

/// The payload of state format 6.
#[derive(Deserialize)]
pub(super) struct V6 {
    params: PlannerParamsV6,
    model: TaskModel,
    observations: ObservationsV6,
    confidence: ConfidenceV6,
    outcome: OutcomeV7,
    rounds_recorded: usize,
    rounds: Vec<u64>,
}

impl From<V6> for v11::Payload {
    /// In the paper's confidence model, with no evidence of misses and no hold points.
    fn from(v6: V6) -> Self {
        v11::Payload {
            params: v11::PlannerParams {
                fit: v6.params.fit.into(),
                confidence: v6.params.confidence.into(),
                sampler: v6.params.sampler,
                holds: v11::HoldSpec {
                    at_s: Vec::new(),
                    rules: Vec::new(),
                },
            },
            model: v6.model,
            observations: v11::Observations {
                corrections: v6.observations.corrections,
                supervised: v6.observations.supervised,
                miss: v11::MissEvidence::default(),
            },
            confidence: v11::Confidence {
                params: v6.confidence.params.into(),
                high: v6.confidence.high,
            },
            outcome: v6.outcome.into(),
            rounds_recorded: v6.rounds_recorded,
            rounds: v6.rounds,
            reference: None,
            records: Vec::new(),
        }
    }
}

/// The payload of state format 5: format 6 without the round fingerprints.
#[derive(Deserialize)]
pub(super) struct V5 {
    params: PlannerParamsV6,
    model: TaskModel,
    observations: ObservationsV6,
    confidence: ConfidenceV6,
    outcome: OutcomeV7,
    rounds_recorded: usize,
}

impl From<V5> for V6 {
    /// No fingerprints: the rounds recorded then cannot be told from new ones.
    fn from(v5: V5) -> Self {
        V6 {
            params: v5.params,
            model: v5.model,
            observations: v5.observations,
            confidence: v5.confidence,
            outcome: v5.outcome,
            rounds_recorded: v5.rounds_recorded,
            rounds: Vec::new(),
        }
    }
}

impl From<V5> for v11::Payload {
    fn from(v5: V5) -> Self {
        V6::from(v5).into()
    }
}

/// The two-robot schedule of state format 4: two warps and robot 2's offset.
#[derive(Deserialize)]
struct ScheduleV4 {
    grad_exec: [Vec<f64>; 2],
    offset_s: f64,
    tick_s: f64,
}

/// The outcome as state format 4 wrote it (the schedule [`ScheduleV4`]).
#[derive(Deserialize)]
struct OutcomeV4 {
    schedule: ScheduleV4,
    t_total_s: f64,
    source: v11::Source,
    stats: v11::SamplerStats,
    lower_bound_s: f64,
    bound_is_optimum: bool,
    gap: f64,
}

/// The payload of state format 4: format 5 but for the two-robot schedule.
#[derive(Deserialize)]
pub(super) struct V4 {
    params: PlannerParamsV6,
    model: TaskModel,
    observations: ObservationsV6,
    confidence: ConfidenceV6,
    outcome: OutcomeV4,
    rounds_recorded: usize,
}

impl From<V4> for V5 {
    /// The two-robot schedule as an `N`-robot one: `offsets_s = [offset_s]`.
    fn from(v4: V4) -> Self {
        let OutcomeV4 {
            schedule,
            t_total_s,
            source,
            stats,
            lower_bound_s,
            bound_is_optimum,
            gap,
        } = v4.outcome;
        V5 {
            params: v4.params,
            model: v4.model,
            observations: v4.observations,
            confidence: v4.confidence,
            outcome: OutcomeV7 {
                schedule: ScheduleV7 {
                    grad_exec: Vec::from(schedule.grad_exec),
                    offsets_s: vec![schedule.offset_s],
                    tick_s: schedule.tick_s,
                },
                t_total_s,
                source,
                stats,
                lower_bound_s,
                bound_is_optimum,
                gap,
            },
            rounds_recorded: v4.rounds_recorded,
        }
    }
}

impl From<V4> for v11::Payload {
    fn from(v4: V4) -> Self {
        V5::from(v4).into()
    }
}
