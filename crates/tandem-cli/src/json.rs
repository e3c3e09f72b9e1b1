//! The documented JSON outputs of the command line (docs/formats.md) as types of their own,
//! apart from the library types they show: a library field renamed or added changes no
//! output (each conversion names every field of the library type, so a field added fails to
//! compile here until it is decided on), and `tests/json_outputs.rs` pins every output's
//! keys against a committed golden shape.
//!
//! `schedule --json` is [`ScheduleDoc`], `inspect --json` [`InspectDoc`], `schedule --cell
//! continuous --json` `tandem::planner::json::CyclicPlanJson` (the planner's, shared with
//! Python's `CyclicPlan.to_json()`) and `inspect BAG --json` [`BagDoc`]. What the state
//! documents used to take from a library type's serde form is here too: the schedule
//! ([`ScheduleOut`]), the declared hold points ([`HoldSpecOut`]), the confidence parameters
//! ([`ConfidenceParamsOut`]), the operator's error rates ([`ErrorRatesOut`]) and the
//! low-confidence regions ([`LowRegionOut`]). The cyclic plan is printed directly (keys in
//! the documented order); the other documents through a
//! `serde_json::Value` (keys in alphabetical order).

use serde::Serialize;
use tandem::confidence::{ConfidenceParams, ErrorRates};
use tandem::lfd::HoldSpec;
use tandem::planner::{ChannelShare, LowCause, LowRegion};
use tandem::realtime::{After, Hold};
use tandem::schedule::Schedule;

/// The document of `tandem schedule --json` and `schedule` of `tandem inspect --json`
/// (docs/formats.md, "Schedule JSON"): times in seconds of global time, robots 1-based.
#[derive(Serialize)]
pub(crate) struct ScheduleDoc {
    /// Eq. 13: `max_i(τ_i + |ψ_Ei|)` (s).
    pub(crate) t_total_s: f64,
    /// The certificate: no schedule of Eq. 20 is shorter (s).
    pub(crate) lower_bound_s: f64,
    /// Whether the bound is the proven margin-free optimum.
    pub(crate) bound_is_optimum: bool,
    /// `(t_total_s − lower_bound_s) / lower_bound_s`.
    pub(crate) gap: f64,
    /// The fastest serial schedule's `T_total` (s).
    pub(crate) serial_t_total_s: f64,
    /// `N`.
    pub(crate) n_robots: usize,
    /// `τ` of robot 2 (s); `null` for one robot.
    pub(crate) offset_s: Option<f64>,
    /// `τ_2 … τ_N` (s).
    pub(crate) offsets_s: Vec<f64>,
    /// `|ψ_E1| … |ψ_EN|` (s).
    pub(crate) durations_s: Vec<f64>,
    /// The reference sample period `Δt_s` (s).
    pub(crate) dt_s: f64,
    /// The control tick the schedule was checked with (s).
    pub(crate) tick_s: f64,
    /// Reference samples.
    pub(crate) n_ref: usize,
    /// Where the schedule came from, as text.
    pub(crate) source: String,
    /// Every low-confidence stretch, sorted by start.
    pub(crate) lc_intervals: Vec<LcIntervalOut>,
    /// The schedule itself.
    pub(crate) schedule: ScheduleOut,
    /// Its holds with global times; only when it has any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) holds: Option<Vec<ScheduleHoldOut>>,
    /// The planned waiting per robot (s); only when it has holds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) dwells_s: Option<Vec<f64>>,
    /// `schedule` only: whether `--save` wrote it into the state file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) saved: Option<bool>,
    /// `schedule` only: `T_total` of the state file's schedule before this run (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) previous_t_total_s: Option<f64>,
}

/// One of [`ScheduleDoc::lc_intervals`]: reference samples `ref_start ≤ n < ref_end` of robot
/// `robot` (1-based), from `start_s` to `end_s` (global time, s).
#[derive(Serialize)]
pub(crate) struct LcIntervalOut {
    pub(crate) robot: usize,
    pub(crate) ref_start: usize,
    pub(crate) ref_end: usize,
    pub(crate) start_s: f64,
    pub(crate) end_s: f64,
}

/// One of [`ScheduleDoc::holds`]: robot `robot` (1-based) stops at reference sample
/// `ref_idx` (reference time `ref_s`), from `start_s` to `end_s` (global time, s; `dwell_s`
/// the difference), and leaves once every `after` rule holds (robots 1-based; always
/// written).
#[derive(Serialize)]
pub(crate) struct ScheduleHoldOut {
    pub(crate) robot: usize,
    pub(crate) ref_idx: usize,
    pub(crate) ref_s: f64,
    pub(crate) start_s: f64,
    pub(crate) end_s: f64,
    pub(crate) dwell_s: f64,
    pub(crate) after: Vec<AfterOut>,
}

/// `schedule` of [`ScheduleDoc`]: the warps, start
/// offsets and tick of the schedule, and its holds only when it has any (so a schedule
/// without holds prints as before hold points).
#[derive(Serialize)]
pub(crate) struct ScheduleOut {
    /// Per robot, execution samples per reference sample (`N` lists of `n_ref` values).
    grad_exec: Vec<Vec<f64>>,
    /// Start offsets `τ_2 … τ_N` (s).
    offsets_s: Vec<f64>,
    /// The control tick of its margin check (s).
    tick_s: f64,
    /// Per robot, its holds (robots 0-based); left out when no robot has one.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    holds: Vec<Vec<HoldOut>>,
}

/// One hold of [`ScheduleOut::holds`].
#[derive(Serialize)]
pub(crate) struct HoldOut {
    /// The reference sample at whose start the robot stops.
    ref_idx: usize,
    /// Planned dwell (s); left out when 0.
    #[serde(skip_serializing_if = "is_zero")]
    dwell_s: f64,
    /// Release rules; left out when empty.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    after: Vec<AfterOut>,
}

/// A release rule of [`HoldOut`]: robot `robot` (0-based) has passed reference sample
/// `ref_idx`.
#[derive(Serialize)]
pub(crate) struct AfterOut {
    pub(crate) robot: usize,
    pub(crate) ref_idx: usize,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl From<&Hold> for HoldOut {
    fn from(h: &Hold) -> Self {
        let Hold {
            ref_idx,
            dwell_s,
            after,
        } = h;
        HoldOut {
            ref_idx: *ref_idx,
            dwell_s: *dwell_s,
            after: after
                .iter()
                .map(|&After { robot, ref_idx }| AfterOut { robot, ref_idx })
                .collect(),
        }
    }
}

impl From<&Schedule> for ScheduleOut {
    fn from(s: &Schedule) -> Self {
        let Schedule {
            grad_exec,
            offsets_s,
            tick_s,
            holds,
        } = s;
        ScheduleOut {
            grad_exec: grad_exec.clone(),
            offsets_s: offsets_s.clone(),
            tick_s: *tick_s,
            holds: holds
                .iter()
                .map(|hs| hs.iter().map(HoldOut::from).collect())
                .collect(),
        }
    }
}

/// `holds.declared` of `tandem inspect --json`: the declared hold points (reference times,
/// s) and rules (as written: `gripper>0.5`).
#[derive(Serialize)]
pub(crate) struct HoldSpecOut {
    at_s: Vec<f64>,
    rules: Vec<String>,
}

impl From<&HoldSpec> for HoldSpecOut {
    fn from(h: &HoldSpec) -> Self {
        let HoldSpec { at_s, rules } = h;
        HoldSpecOut {
            at_s: at_s.clone(),
            rules: rules.iter().map(ToString::to_string).collect(),
        }
    }
}

/// `confidence.params` of `tandem inspect --json` (meaning: `ConfidenceParams`, Eq. 10–12).
#[derive(Serialize)]
pub(crate) struct ConfidenceParamsOut {
    gamma_p: f64,
    sigma2_max: f64,
    epsilon: f64,
    mu_c: f64,
    gamma_c: f64,
    false_correction_rate: f64,
    miss_rate: f64,
    estimate_error_rates: bool,
    one_vote_per_execution: bool,
}

impl From<&ConfidenceParams> for ConfidenceParamsOut {
    fn from(p: &ConfidenceParams) -> Self {
        let ConfidenceParams {
            gamma_p,
            sigma2_max,
            epsilon,
            mu_c,
            gamma_c,
            false_correction_rate,
            miss_rate,
            estimate_error_rates,
            one_vote_per_execution,
        } = *p;
        ConfidenceParamsOut {
            gamma_p,
            sigma2_max,
            epsilon,
            mu_c,
            gamma_c,
            false_correction_rate,
            miss_rate,
            estimate_error_rates,
            one_vote_per_execution,
        }
    }
}

/// `confidence.error_rates` of `tandem inspect --json`: the operator's rates the confidence
/// decides with, per control sample.
#[derive(Serialize)]
pub(crate) struct ErrorRatesOut {
    false_correction_rate: f64,
    miss_rate: f64,
}

impl From<ErrorRates> for ErrorRatesOut {
    fn from(r: ErrorRates) -> Self {
        let ErrorRates {
            false_correction_rate,
            miss_rate,
        } = r;
        ErrorRatesOut {
            false_correction_rate,
            miss_rate,
        }
    }
}

/// One of `confidence.low_regions` of `tandem inspect --json` (meaning: docs/formats.md).
#[derive(Serialize)]
pub(crate) struct LowRegionOut {
    ref_start: usize,
    ref_end: usize,
    start_s: f64,
    end_s: f64,
    /// `"variance"` or `"corrections"`.
    cause: &'static str,
    sigma2_d_max: f64,
    sigma2_d_prior_threshold: Option<f64>,
    channels: Vec<ChannelShareOut>,
    supervised: f64,
    corrections: f64,
    expected_false_corrections: f64,
    clean_executions_needed: Option<usize>,
}

/// One of [`LowRegionOut::channels`].
#[derive(Serialize)]
pub(crate) struct ChannelShareOut {
    name: String,
    sigma2: f64,
    share: f64,
    range: f64,
    range_for_prior: Option<f64>,
}

impl From<&LowRegion> for LowRegionOut {
    fn from(r: &LowRegion) -> Self {
        let LowRegion {
            ref_start,
            ref_end,
            start_s,
            end_s,
            cause,
            sigma2_d_max,
            sigma2_d_prior_threshold,
            channels,
            supervised,
            corrections,
            expected_false_corrections,
            clean_executions_needed,
        } = r;
        LowRegionOut {
            ref_start: *ref_start,
            ref_end: *ref_end,
            start_s: *start_s,
            end_s: *end_s,
            cause: match cause {
                LowCause::Variance => "variance",
                LowCause::Corrections => "corrections",
            },
            sigma2_d_max: *sigma2_d_max,
            sigma2_d_prior_threshold: *sigma2_d_prior_threshold,
            channels: channels
                .iter()
                .map(|c| {
                    let ChannelShare {
                        name,
                        sigma2,
                        share,
                        range,
                        range_for_prior,
                    } = c;
                    ChannelShareOut {
                        name: name.clone(),
                        sigma2: *sigma2,
                        share: *share,
                        range: *range,
                        range_for_prior: *range_for_prior,
                    }
                })
                .collect(),
            supervised: *supervised,
            corrections: *corrections,
            expected_false_corrections: *expected_false_corrections,
            clean_executions_needed: *clean_executions_needed,
        }
    }
}

/// `value` as a JSON value (keys in alphabetical order, as every document is printed).
///
/// # Errors
/// serde_json's (none for these types: every key is a string).
pub(crate) fn value<T: Serialize>(value: &T) -> serde_json::Result<serde_json::Value> {
    serde_json::to_value(value)
}

/// The document of `tandem inspect STATE --json` (docs/formats.md, "Schedule JSON": the
/// paragraphs on `inspect`).
#[derive(Serialize)]
pub(crate) struct InspectDoc {
    /// The state file, as given.
    pub(crate) state: String,
    /// Rounds recorded (one execution of each robot).
    pub(crate) rounds_recorded: usize,
    /// Deprecated duplicate of `rounds_recorded` (the two-robot name), kept one release.
    pub(crate) pairs_recorded: usize,
    /// The task model.
    pub(crate) model: ModelOut,
    /// The confidence and the observations.
    pub(crate) confidence: ConfidenceOut,
    /// The schedule, as `tandem schedule --json` prints it (without `saved` and
    /// `previous_t_total_s`).
    pub(crate) schedule: ScheduleDoc,
    /// The hold points.
    pub(crate) holds: HoldsOut,
}

/// `model` of [`InspectDoc`].
#[derive(Serialize)]
pub(crate) struct ModelOut {
    pub(crate) channels: Vec<String>,
    pub(crate) reference: ReferenceOut,
    pub(crate) n_ref: usize,
    pub(crate) dt_s: f64,
    pub(crate) reference_duration_s: f64,
    /// Demonstrations and executions in the statistics.
    pub(crate) count: usize,
    pub(crate) correction_components: usize,
    /// The range `r_j` of every tangent coordinate, by name.
    pub(crate) ranges: std::collections::BTreeMap<String, f64>,
    pub(crate) sigma2_d: QuantilesOut,
    pub(crate) mean_duration_s: f64,
    pub(crate) fastest_duration_s: f64,
    pub(crate) slowest_duration_s: f64,
}

/// `model.reference` of [`InspectDoc`]: how the reference was chosen (`first`, `medoid`) and
/// which demonstration of the fit it is (0-based).
#[derive(Serialize)]
pub(crate) struct ReferenceOut {
    pub(crate) choice: String,
    pub(crate) demo_idx: usize,
}

/// Quantiles of a per-sample value (`model.sigma2_d`).
#[derive(Serialize)]
pub(crate) struct QuantilesOut {
    pub(crate) min: f64,
    pub(crate) median: f64,
    pub(crate) p90: f64,
    pub(crate) max: f64,
}

/// `confidence` of [`InspectDoc`].
#[derive(Serialize)]
pub(crate) struct ConfidenceOut {
    pub(crate) params: ConfidenceParamsOut,
    pub(crate) high_share: f64,
    pub(crate) n_high: usize,
    pub(crate) low_regions: Vec<LowRegionOut>,
    pub(crate) error_rates: ErrorRatesOut,
    pub(crate) sigma2_d_prior_threshold: Option<f64>,
    pub(crate) total_supervised: f64,
    pub(crate) total_corrections: f64,
}

/// `holds` of [`InspectDoc`]: the declaration, the resolved samples, how many of them are
/// high-confidence (a robot may dwell there now), and their stretches.
#[derive(Serialize)]
pub(crate) struct HoldsOut {
    pub(crate) declared: HoldSpecOut,
    pub(crate) samples: Vec<usize>,
    pub(crate) active_samples: usize,
    pub(crate) stretches: Vec<HoldStretchOut>,
}

/// One of [`HoldsOut::stretches`]: consecutive hold samples `ref_start..=ref_last` (reference
/// time `start_s..=last_s`) of the same activity.
#[derive(Serialize)]
pub(crate) struct HoldStretchOut {
    pub(crate) ref_start: usize,
    pub(crate) ref_last: usize,
    pub(crate) start_s: f64,
    pub(crate) last_s: f64,
    pub(crate) active: bool,
}

/// The document of `tandem inspect BAG --json`: the bag, its rounds and its topics.
#[derive(Serialize)]
pub(crate) struct BagDoc {
    /// The bag, as given.
    pub(crate) bag: String,
    /// Rounds recorded in it (`/tandem/round` markers).
    pub(crate) rounds: usize,
    /// Every topic.
    pub(crate) topics: Vec<BagTopicOut>,
}

/// One of [`BagDoc::topics`] (docs/formats.md, "ROS 2 bags").
#[derive(Serialize)]
pub(crate) struct BagTopicOut {
    /// Topic name.
    pub(crate) topic: String,
    /// Its schema (message type) name, if any.
    pub(crate) r#type: Option<String>,
    /// Whether tandem reads its message type.
    pub(crate) supported: bool,
    /// Number of messages.
    pub(crate) messages: usize,
    /// The channels it gives.
    pub(crate) channels: Vec<String>,
    /// Median period between messages (s).
    pub(crate) median_period_s: Option<f64>,
    /// The period it is read at (s).
    pub(crate) period_s: Option<f64>,
    /// First and last message time (s).
    pub(crate) start_s: Option<f64>,
    pub(crate) end_s: Option<f64>,
    /// `"log time"` or `"header stamp"`: which time is used.
    pub(crate) time: &'static str,
    /// Its role (`channel`, …).
    pub(crate) role: &'static str,
}
