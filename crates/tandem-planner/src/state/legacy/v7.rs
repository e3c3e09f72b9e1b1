//! State format 7: the parameters without hold points, the schedule without holds.

use serde::Deserialize;
use tandem_lfd::TaskModel;

use super::v8_to_v10::FitParamsV8;
use crate::state::v11;

/// The schedule of state formats 5 to 7: without holds.
#[derive(Deserialize)]
pub(super) struct ScheduleV7 {
    pub(super) grad_exec: Vec<Vec<f64>>,
    pub(super) offsets_s: Vec<f64>,
    pub(super) tick_s: f64,
}

/// The outcome as state formats 5 to 7 wrote it: the schedule without holds.
#[derive(Deserialize)]
pub(super) struct OutcomeV7 {
    pub(super) schedule: ScheduleV7,
    pub(super) t_total_s: f64,
    pub(super) source: v11::Source,
    pub(super) stats: v11::SamplerStats,
    pub(super) lower_bound_s: f64,
    pub(super) bound_is_optimum: bool,
    pub(super) gap: f64,
}

impl From<OutcomeV7> for v11::Outcome {
    /// Every robot without holds (none could be declared then).
    fn from(v7: OutcomeV7) -> Self {
        v11::Outcome {
            schedule: v11::Schedule {
                grad_exec: v7.schedule.grad_exec,
                offsets_s: v7.schedule.offsets_s,
                tick_s: v7.schedule.tick_s,
                holds: Vec::new(),
            },
            t_total_s: v7.t_total_s,
            source: v7.source,
            stats: v7.stats,
            lower_bound_s: v7.lower_bound_s,
            bound_is_optimum: v7.bound_is_optimum,
            gap: v7.gap,
        }
    }
}

/// `PlannerParams` as state format 7 wrote them: without hold points.
#[derive(Deserialize)]
struct PlannerParamsV7 {
    fit: FitParamsV8,
    confidence: v11::ConfidenceParams,
    sampler: v11::SamplerParams,
}

/// The payload of state format 7.
#[derive(Deserialize)]
pub(super) struct V7 {
    params: PlannerParamsV7,
    model: TaskModel,
    observations: v11::Observations,
    confidence: v11::Confidence,
    outcome: OutcomeV7,
    rounds_recorded: usize,
    rounds: Vec<u64>,
}

impl From<V7> for v11::Payload {
    /// The saved planner with no hold points (none could be declared then).
    fn from(v7: V7) -> Self {
        v11::Payload {
            params: v11::PlannerParams {
                fit: v7.params.fit.into(),
                confidence: v7.params.confidence,
                sampler: v7.params.sampler,
                holds: v11::HoldSpec {
                    at_s: Vec::new(),
                    rules: Vec::new(),
                },
            },
            model: v7.model,
            observations: v7.observations,
            confidence: v7.confidence,
            outcome: v7.outcome.into(),
            rounds_recorded: v7.rounds_recorded,
            rounds: v7.rounds,
            reference: None,
            records: Vec::new(),
        }
    }
}
