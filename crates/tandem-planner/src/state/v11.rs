//! The payload of state format 11, the current one: plain wire types, apart from the library
//! types they store, with explicit conversions both ways.
//!
//! Every type here is a frozen copy of a library type's fields *as format 11 writes them*
//! (postcard is positional: the order of the fields is the format). The library types may
//! change (a field renamed, a parameter added, a variant appended); these may not, except by
//! a new format version (a `v12.rs`, this file moving to `state::legacy`).
//!
//! Each conversion from a library type destructures it field by field without `..`, and each
//! conversion to one names every field, so a field added to a library type fails to compile
//! here and must be decided on, never silently dropped (module docs of [`super`], "Adding a
//! library parameter").
//!
//! One library type is stored in its own serde form: the fitted [`tandem_lfd::TaskModel`],
//! whose private data (`ModelData`: statistics, not parameters) only `tandem-lfd` can build;
//! it holds no parameter, so no new parameter changes it. The hold rules are stored as their
//! text (`gripper>0.5`, the form the user writes), as their serde form always was.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use tandem_confidence as conf;
use tandem_lfd as lfd;
use tandem_realtime as rt;
use tandem_schedule as sched;
use tandem_warp as warp;

use super::Extras;
use crate::planner::ExecutionRecord;
use crate::{Error, Result};

/// The whole payload of a format 11 state file: the serialized part of a
/// [`crate::Planner`] (its scheduling problem is rebuilt on load).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Payload {
    /// The planner's parameters.
    pub params: PlannerParams,
    /// The fitted task model, in `tandem-lfd`'s own serde form (module docs).
    pub model: lfd::TaskModel,
    /// The correction observations (Eq. 9).
    pub observations: Observations,
    /// The latched confidence (Eq. 10–12).
    pub confidence: Confidence,
    /// The current schedule and its certificate.
    pub outcome: Outcome,
    /// Rounds of executions recorded so far.
    pub rounds_recorded: usize,
    /// Fingerprints of the rounds recorded since format 6 (a repeat is refused).
    pub rounds: Vec<u64>,
    /// The reference demonstration (in the model's channel order); `None` for a planner
    /// made from a model or loaded from a file older than format 11.
    pub reference: Option<Demonstration>,
    /// Every round recorded since format 11, its executions as taken in.
    pub records: Vec<Vec<Record>>,
}

/// [`crate::PlannerParams`] as format 11 writes them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlannerParams {
    /// The fit's parameters.
    pub fit: FitParams,
    /// The confidence's parameters.
    pub confidence: ConfidenceParams,
    /// The sampler's parameters.
    pub sampler: SamplerParams,
    /// The declared hold points.
    pub holds: HoldSpec,
}

/// The name under which [`lfd::FitParams::rate_term`] is stored ([`Extras`], its spelling
/// `relative:opening=13,window=0` as a string) when it differs
/// from the form of the stored model (absent: that form, so every file written before the
/// parameter existed loads with the form its model was fitted with: absolute before the
/// relative term, relative without a duration window before the duration term).
pub const FIT_RATE_TERM: &str = "fit.rate_term";

/// The name under which [`sched::SamplerParams::switch_s`] (the operator's switch time, s) is
/// stored ([`Extras`], an `f64`) when it is not 0 (absent: 0, the planner of every file written
/// before the parameter existed).
pub const SAMPLER_SWITCH_S: &str = "sampler.switch_s";

/// The name under which [`sched::SamplerParams::max_busy_share`] (the operator's load cap) is
/// stored ([`Extras`], an `f64`) when it is not 1 (absent: 1, no cap).
pub const SAMPLER_MAX_BUSY_SHARE: &str = "sampler.max_busy_share";

/// The name under which [`sched::SamplerParams::operators`] (the cell's number of operators
/// `M`, issue 44) is stored ([`Extras`], a `u64`) when it is not 1 (absent: 1, one operator).
pub const SAMPLER_OPERATORS: &str = "sampler.operators";

/// [`lfd::FitParams`] as format 11 writes them.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitParams {
    pub warp: WarpParams,
    pub ranges: Option<Vec<f64>>,
    pub min_range: f64,
    pub k_max: usize,
    pub schema: ChannelSchema,
    pub reference: Reference,
}

/// [`warp::WarpParams`] as formats 10 and 11 write them (the fields' meaning: there).
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WarpParams {
    pub n_nodes: Option<usize>,
    pub n_candidates: usize,
    pub lambda_inst: f64,
    pub lambda_cum: f64,
    pub slope_min: f64,
    pub slope_max: f64,
    pub refinements: usize,
    pub refine_radius: f64,
    pub max_jump: Option<usize>,
    pub coarse_nodes: usize,
    pub coarse_candidates: usize,
    pub weights: Option<Vec<f64>>,
    pub smooth_width: usize,
    pub fill_length: f64,
}

/// [`lfd::ChannelSchema`] as format 11 writes it.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChannelSchema {
    pub kinds: BTreeMap<String, ChannelKind>,
    pub quaternions: Vec<QuaternionBlock>,
}

/// [`lfd::ChannelKind`] as format 11 writes it (the variant's index is the format).
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ChannelKind {
    Position,
    Force,
    Binary,
    Rate,
    Scalar,
}

/// [`lfd::QuaternionBlock`] as format 11 writes it.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QuaternionBlock {
    pub name: String,
    pub channels: [String; 4],
}

/// [`lfd::Reference`] as format 11 writes it (the variant's index is the format).
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Reference {
    First,
    Medoid,
}

/// [`conf::ConfidenceParams`] as formats 7 to 11 write them.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConfidenceParams {
    pub gamma_p: f64,
    pub sigma2_max: f64,
    pub epsilon: f64,
    pub mu_c: f64,
    pub gamma_c: f64,
    pub false_correction_rate: f64,
    pub miss_rate: f64,
    pub estimate_error_rates: bool,
    pub one_vote_per_execution: bool,
}

/// [`sched::SamplerParams`] as formats 4 to 11 write them.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SamplerParams {
    pub samples: usize,
    pub seed: u64,
    pub tick_s: Option<f64>,
    pub pieces: usize,
    pub p_fastest: f64,
    pub widen_max: f64,
    pub max_margin_checks: Option<usize>,
    pub exact: ExactParams,
}

/// [`sched::ExactParams`] as formats 4 to 11 write them.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExactParams {
    pub max_pieces: usize,
    pub max_margin_checks: usize,
}

/// [`lfd::HoldSpec`] as formats 8 to 11 write it: the rules as their text.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct HoldSpec {
    pub at_s: Vec<f64>,
    pub rules: Vec<String>,
}

/// [`conf::Observations`] as formats 7 to 11 write them.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Observations {
    pub corrections: Vec<f64>,
    pub supervised: Vec<f64>,
    pub miss: MissEvidence,
}

/// [`conf::MissEvidence`] as formats 7 to 11 write it.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MissEvidence {
    pub gap_samples: f64,
    pub stretch_samples: f64,
}

/// [`conf::Confidence`] as formats 7 to 11 write it: its parameters and the latched flags.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Confidence {
    pub params: ConfidenceParams,
    pub high: Vec<bool>,
}

/// [`sched::Outcome`] as formats 8 to 11 write it: every field of the schedule and its holds
/// always written (the schedule's own serde form leaves out empty holds, zero dwells and
/// empty release lists, which postcard cannot read back); not the previous schedule's fate
/// nor the split of the gap (a loaded outcome has neither).
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    pub schedule: Schedule,
    pub t_total_s: f64,
    pub source: Source,
    pub stats: SamplerStats,
    pub lower_bound_s: f64,
    pub bound_is_optimum: bool,
    pub gap: f64,
}

/// [`sched::Schedule`] as formats 8 to 11 write it.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Schedule {
    pub grad_exec: Vec<Vec<f64>>,
    pub offsets_s: Vec<f64>,
    pub tick_s: f64,
    pub holds: Vec<Vec<Hold>>,
}

/// [`rt::Hold`] as formats 8 to 11 write it.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hold {
    pub ref_idx: usize,
    pub dwell_s: f64,
    pub after: Vec<After>,
}

/// [`rt::After`] as formats 8 to 11 write it.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct After {
    pub robot: usize,
    pub ref_idx: usize,
}

/// [`sched::Source`] as formats 8 to 11 write it (the variant's index is the format).
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Source {
    Sampled { candidate: u64 },
    Completed,
    Previous,
    RepairedPrevious,
    Serial,
    Held,
    Staggered,
}

/// [`sched::SamplerStats`] as formats 4 to 11 write them.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SamplerStats {
    pub candidates: usize,
    pub cheap_feasible: usize,
    pub margin_checks: usize,
    pub completion_margin_checks: usize,
    pub search: SearchStats,
}

/// [`sched::SearchStats`] as formats 4 to 11 write them.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct SearchStats {
    pub lc_runs: usize,
    pub states: usize,
    pub pieces: usize,
}

/// [`lfd::Demonstration`] as format 11 writes it: channel names, the period (always
/// written, `Some`) and the samples row by row; not its source label.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Demonstration {
    pub channels: Vec<String>,
    pub dt_s: Option<f64>,
    pub samples: Vec<Vec<f64>>,
}

/// [`ExecutionRecord`] as format 11 writes it.
#[expect(
    missing_docs,
    reason = "a field for field copy of the library type named above, whose fields are documented"
)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record {
    pub demonstration: Demonstration,
    pub ref_time_log: Vec<f64>,
    pub supervised: Vec<bool>,
    pub corrected: Vec<bool>,
}

// ---- library → wire (every field named, no `..`: a new field does not compile) ----

impl From<&warp::WarpParams> for WarpParams {
    fn from(p: &warp::WarpParams) -> Self {
        let warp::WarpParams {
            n_nodes,
            n_candidates,
            lambda_inst,
            lambda_cum,
            slope_min,
            slope_max,
            refinements,
            refine_radius,
            max_jump,
            coarse_nodes,
            coarse_candidates,
            weights,
            smooth_width,
            fill_length,
        } = p;
        WarpParams {
            n_nodes: *n_nodes,
            n_candidates: *n_candidates,
            lambda_inst: *lambda_inst,
            lambda_cum: *lambda_cum,
            slope_min: *slope_min,
            slope_max: *slope_max,
            refinements: *refinements,
            refine_radius: *refine_radius,
            max_jump: *max_jump,
            coarse_nodes: *coarse_nodes,
            coarse_candidates: *coarse_candidates,
            weights: weights.clone(),
            smooth_width: *smooth_width,
            fill_length: *fill_length,
        }
    }
}

impl From<WarpParams> for warp::WarpParams {
    fn from(w: WarpParams) -> Self {
        warp::WarpParams {
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
            smooth_width: w.smooth_width,
            fill_length: w.fill_length,
        }
    }
}

impl From<lfd::ChannelKind> for ChannelKind {
    fn from(k: lfd::ChannelKind) -> Self {
        match k {
            lfd::ChannelKind::Position => ChannelKind::Position,
            lfd::ChannelKind::Force => ChannelKind::Force,
            lfd::ChannelKind::Binary => ChannelKind::Binary,
            lfd::ChannelKind::Rate => ChannelKind::Rate,
            lfd::ChannelKind::Scalar => ChannelKind::Scalar,
        }
    }
}

impl From<ChannelKind> for lfd::ChannelKind {
    fn from(k: ChannelKind) -> Self {
        match k {
            ChannelKind::Position => lfd::ChannelKind::Position,
            ChannelKind::Force => lfd::ChannelKind::Force,
            ChannelKind::Binary => lfd::ChannelKind::Binary,
            ChannelKind::Rate => lfd::ChannelKind::Rate,
            ChannelKind::Scalar => lfd::ChannelKind::Scalar,
        }
    }
}

impl From<&lfd::ChannelSchema> for ChannelSchema {
    fn from(s: &lfd::ChannelSchema) -> Self {
        let lfd::ChannelSchema { kinds, quaternions } = s;
        ChannelSchema {
            kinds: kinds.iter().map(|(n, &k)| (n.clone(), k.into())).collect(),
            quaternions: quaternions
                .iter()
                .map(|q| {
                    let lfd::QuaternionBlock { name, channels } = q;
                    QuaternionBlock {
                        name: name.clone(),
                        channels: channels.clone(),
                    }
                })
                .collect(),
        }
    }
}

impl From<ChannelSchema> for lfd::ChannelSchema {
    fn from(s: ChannelSchema) -> Self {
        lfd::ChannelSchema {
            kinds: s.kinds.into_iter().map(|(n, k)| (n, k.into())).collect(),
            quaternions: s
                .quaternions
                .into_iter()
                .map(|q| lfd::QuaternionBlock {
                    name: q.name,
                    channels: q.channels,
                })
                .collect(),
        }
    }
}

impl From<lfd::Reference> for Reference {
    fn from(r: lfd::Reference) -> Self {
        match r {
            lfd::Reference::First => Reference::First,
            lfd::Reference::Medoid => Reference::Medoid,
        }
    }
}

impl From<Reference> for lfd::Reference {
    fn from(r: Reference) -> Self {
        match r {
            Reference::First => lfd::Reference::First,
            Reference::Medoid => lfd::Reference::Medoid,
        }
    }
}

impl From<&lfd::FitParams> for FitParams {
    fn from(p: &lfd::FitParams) -> Self {
        let lfd::FitParams {
            warp,
            ranges,
            min_range,
            k_max,
            schema,
            reference,
            // Stored by name (`FIT_RATE_TERM`).
            rate_term: _,
        } = p;
        FitParams {
            warp: warp.into(),
            ranges: ranges.clone(),
            min_range: *min_range,
            k_max: *k_max,
            schema: schema.into(),
            reference: (*reference).into(),
        }
    }
}

impl From<FitParams> for lfd::FitParams {
    fn from(f: FitParams) -> Self {
        lfd::FitParams {
            warp: f.warp.into(),
            ranges: f.ranges,
            min_range: f.min_range,
            k_max: f.k_max,
            schema: f.schema.into(),
            reference: f.reference.into(),
            // Stored by name (`FIT_RATE_TERM`): `Payload::into_state` reads it, absent the
            // form the stored model was fitted with.
            rate_term: lfd::RateTerm::DEFAULT,
        }
    }
}

impl From<&conf::ConfidenceParams> for ConfidenceParams {
    fn from(p: &conf::ConfidenceParams) -> Self {
        let conf::ConfidenceParams {
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
        ConfidenceParams {
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

impl From<ConfidenceParams> for conf::ConfidenceParams {
    fn from(p: ConfidenceParams) -> Self {
        conf::ConfidenceParams {
            gamma_p: p.gamma_p,
            sigma2_max: p.sigma2_max,
            epsilon: p.epsilon,
            mu_c: p.mu_c,
            gamma_c: p.gamma_c,
            false_correction_rate: p.false_correction_rate,
            miss_rate: p.miss_rate,
            estimate_error_rates: p.estimate_error_rates,
            one_vote_per_execution: p.one_vote_per_execution,
        }
    }
}

impl From<&sched::SamplerParams> for SamplerParams {
    fn from(p: &sched::SamplerParams) -> Self {
        let sched::SamplerParams {
            samples,
            seed,
            tick_s,
            pieces,
            p_fastest,
            widen_max,
            max_margin_checks,
            exact,
            // Added after format 11: stored by name ([`SAMPLER_SWITCH_S`]).
            switch_s: _,
            // Added after format 11: stored by name ([`SAMPLER_MAX_BUSY_SHARE`]).
            max_busy_share: _,
            // Added after format 11: stored by name ([`SAMPLER_OPERATORS`]).
            operators: _,
        } = p;
        let sched::ExactParams {
            max_pieces,
            max_margin_checks: exact_margin_checks,
        } = *exact;
        SamplerParams {
            samples: *samples,
            seed: *seed,
            tick_s: *tick_s,
            pieces: *pieces,
            p_fastest: *p_fastest,
            widen_max: *widen_max,
            max_margin_checks: *max_margin_checks,
            exact: ExactParams {
                max_pieces,
                max_margin_checks: exact_margin_checks,
            },
        }
    }
}

impl From<SamplerParams> for sched::SamplerParams {
    fn from(p: SamplerParams) -> Self {
        sched::SamplerParams {
            samples: p.samples,
            seed: p.seed,
            tick_s: p.tick_s,
            pieces: p.pieces,
            p_fastest: p.p_fastest,
            widen_max: p.widen_max,
            max_margin_checks: p.max_margin_checks,
            exact: sched::ExactParams {
                max_pieces: p.exact.max_pieces,
                max_margin_checks: p.exact.max_margin_checks,
            },
            // Stored by name after the payload; set by `Payload::into_state`.
            ..sched::SamplerParams::default()
        }
    }
}

impl From<&lfd::HoldSpec> for HoldSpec {
    fn from(h: &lfd::HoldSpec) -> Self {
        let lfd::HoldSpec { at_s, rules } = h;
        HoldSpec {
            at_s: at_s.clone(),
            rules: rules.iter().map(ToString::to_string).collect(),
        }
    }
}

impl TryFrom<HoldSpec> for lfd::HoldSpec {
    type Error = Error;
    fn try_from(h: HoldSpec) -> Result<Self> {
        Ok(lfd::HoldSpec {
            at_s: h.at_s,
            rules: h
                .rules
                .iter()
                .map(|r| r.parse())
                .collect::<std::result::Result<_, lfd::Error>>()?,
        })
    }
}

impl From<&crate::PlannerParams> for PlannerParams {
    fn from(p: &crate::PlannerParams) -> Self {
        let crate::PlannerParams {
            fit,
            confidence,
            sampler,
            holds,
        } = p;
        PlannerParams {
            fit: fit.into(),
            confidence: confidence.into(),
            sampler: sampler.into(),
            holds: holds.into(),
        }
    }
}

impl TryFrom<PlannerParams> for crate::PlannerParams {
    type Error = Error;
    fn try_from(p: PlannerParams) -> Result<Self> {
        Ok(crate::PlannerParams {
            fit: p.fit.into(),
            confidence: p.confidence.into(),
            sampler: p.sampler.into(),
            holds: p.holds.try_into()?,
        })
    }
}

impl From<&conf::Observations> for Observations {
    fn from(o: &conf::Observations) -> Self {
        let conf::MissEvidence {
            gap_samples,
            stretch_samples,
        } = o.miss_evidence();
        Observations {
            corrections: o.corrections().to_vec(),
            supervised: o.supervised().to_vec(),
            miss: MissEvidence {
                gap_samples,
                stretch_samples,
            },
        }
    }
}

impl TryFrom<Observations> for conf::Observations {
    type Error = Error;
    fn try_from(o: Observations) -> Result<Self> {
        Ok(
            conf::Observations::from_counts(o.corrections, o.supervised)?.with_miss_evidence(
                conf::MissEvidence {
                    gap_samples: o.miss.gap_samples,
                    stretch_samples: o.miss.stretch_samples,
                },
            )?,
        )
    }
}

impl From<&conf::Confidence> for Confidence {
    fn from(c: &conf::Confidence) -> Self {
        Confidence {
            params: c.params().into(),
            // The latch; `conf` is evaluated from it and the totals on load.
            high: c.latched().to_vec(),
        }
    }
}

impl TryFrom<Confidence> for conf::Confidence {
    type Error = Error;
    fn try_from(c: Confidence) -> Result<Self> {
        Ok(conf::Confidence::from_parts(c.params.into(), c.high)?)
    }
}

impl From<sched::Source> for Source {
    fn from(s: sched::Source) -> Self {
        match s {
            sched::Source::Sampled { candidate } => Source::Sampled { candidate },
            sched::Source::Completed => Source::Completed,
            sched::Source::Previous => Source::Previous,
            sched::Source::RepairedPrevious => Source::RepairedPrevious,
            sched::Source::Serial => Source::Serial,
            sched::Source::Held => Source::Held,
            sched::Source::Staggered => Source::Staggered,
        }
    }
}

impl From<Source> for sched::Source {
    fn from(s: Source) -> Self {
        match s {
            Source::Sampled { candidate } => sched::Source::Sampled { candidate },
            Source::Completed => sched::Source::Completed,
            Source::Previous => sched::Source::Previous,
            Source::RepairedPrevious => sched::Source::RepairedPrevious,
            Source::Serial => sched::Source::Serial,
            Source::Held => sched::Source::Held,
            Source::Staggered => sched::Source::Staggered,
        }
    }
}

impl From<sched::SamplerStats> for SamplerStats {
    fn from(s: sched::SamplerStats) -> Self {
        let sched::SamplerStats {
            candidates,
            cheap_feasible,
            margin_checks,
            completion_margin_checks,
            search,
        } = s;
        let sched::SearchStats {
            lc_runs,
            states,
            pieces,
        } = search;
        SamplerStats {
            candidates,
            cheap_feasible,
            margin_checks,
            completion_margin_checks,
            search: SearchStats {
                lc_runs,
                states,
                pieces,
            },
        }
    }
}

impl From<SamplerStats> for sched::SamplerStats {
    fn from(s: SamplerStats) -> Self {
        sched::SamplerStats {
            candidates: s.candidates,
            cheap_feasible: s.cheap_feasible,
            margin_checks: s.margin_checks,
            completion_margin_checks: s.completion_margin_checks,
            search: sched::SearchStats {
                lc_runs: s.search.lc_runs,
                states: s.search.states,
                pieces: s.search.pieces,
            },
        }
    }
}

impl From<&sched::Schedule> for Schedule {
    fn from(s: &sched::Schedule) -> Self {
        let sched::Schedule {
            grad_exec,
            offsets_s,
            tick_s,
            holds,
        } = s;
        Schedule {
            grad_exec: grad_exec.clone(),
            offsets_s: offsets_s.clone(),
            tick_s: *tick_s,
            holds: holds
                .iter()
                .map(|hs| {
                    hs.iter()
                        .map(|h| {
                            let rt::Hold {
                                ref_idx,
                                dwell_s,
                                after,
                            } = h;
                            Hold {
                                ref_idx: *ref_idx,
                                dwell_s: *dwell_s,
                                after: after
                                    .iter()
                                    .map(|&rt::After { robot, ref_idx }| After { robot, ref_idx })
                                    .collect(),
                            }
                        })
                        .collect()
                })
                .collect(),
        }
    }
}

impl From<Schedule> for sched::Schedule {
    fn from(s: Schedule) -> Self {
        sched::Schedule {
            grad_exec: s.grad_exec,
            offsets_s: s.offsets_s,
            tick_s: s.tick_s,
            holds: s
                .holds
                .into_iter()
                .map(|hs| {
                    hs.into_iter()
                        .map(|h| rt::Hold {
                            ref_idx: h.ref_idx,
                            dwell_s: h.dwell_s,
                            after: h
                                .after
                                .into_iter()
                                .map(|a| rt::After {
                                    robot: a.robot,
                                    ref_idx: a.ref_idx,
                                })
                                .collect(),
                        })
                        .collect()
                })
                .collect(),
        }
    }
}

impl From<&sched::Outcome> for Outcome {
    /// Not stored: the previous schedule's fate and the split of the gap
    /// (`margin_free_s`), which describe the run that made the outcome.
    fn from(o: &sched::Outcome) -> Self {
        let sched::Outcome {
            schedule,
            t_total_s,
            source,
            stats,
            lower_bound_s,
            bound_is_optimum,
            gap,
            margin_free_s: _,
            previous: _,
        } = o;
        Outcome {
            schedule: schedule.into(),
            t_total_s: *t_total_s,
            source: (*source).into(),
            stats: (*stats).into(),
            lower_bound_s: *lower_bound_s,
            bound_is_optimum: *bound_is_optimum,
            gap: *gap,
        }
    }
}

impl From<Outcome> for sched::Outcome {
    /// A loaded outcome has no previous schedule and no split of its gap.
    fn from(o: Outcome) -> Self {
        sched::Outcome {
            schedule: o.schedule.into(),
            t_total_s: o.t_total_s,
            source: o.source.into(),
            stats: o.stats.into(),
            lower_bound_s: o.lower_bound_s,
            bound_is_optimum: o.bound_is_optimum,
            gap: o.gap,
            margin_free_s: None,
            previous: sched::PreviousFate::NotGiven,
        }
    }
}

impl From<&lfd::Demonstration> for Demonstration {
    fn from(d: &lfd::Demonstration) -> Self {
        Demonstration {
            channels: d.channel_names().to_vec(),
            dt_s: Some(d.dt_s()),
            samples: d
                .samples()
                .chunks_exact(d.n_channels())
                .map(<[f64]>::to_vec)
                .collect(),
        }
    }
}

impl TryFrom<Demonstration> for lfd::Demonstration {
    type Error = Error;
    /// The demonstration, checked as any other ([`lfd::Demonstration::new`]); its source
    /// label is `<memory>`.
    fn try_from(d: Demonstration) -> Result<Self> {
        let m = d.channels.len();
        if let Some(r) = d.samples.iter().position(|row| row.len() != m) {
            return Err(Error::Inconsistent {
                what: "demonstration",
                why: format!("sample {r} does not have {m} values"),
            });
        }
        let Some(dt_s) = d.dt_s else {
            return Err(Error::Inconsistent {
                what: "demonstration",
                why: "no sample period".into(),
            });
        };
        Ok(lfd::Demonstration::new(
            d.channels,
            d.samples.into_iter().flatten().collect(),
            dt_s,
        )?)
    }
}

impl From<&ExecutionRecord> for Record {
    fn from(r: &ExecutionRecord) -> Self {
        let ExecutionRecord {
            execution,
            supervised,
            corrected,
        } = r;
        Record {
            demonstration: (&execution.demonstration).into(),
            ref_time_log: execution.ref_time_log.clone(),
            supervised: supervised.clone(),
            corrected: corrected.clone(),
        }
    }
}

impl TryFrom<Record> for ExecutionRecord {
    type Error = Error;
    fn try_from(r: Record) -> Result<Self> {
        Ok(ExecutionRecord {
            execution: lfd::Execution {
                demonstration: r.demonstration.try_into()?,
                ref_time_log: r.ref_time_log,
            },
            supervised: r.supervised,
            corrected: r.corrected,
        })
    }
}

impl Payload {
    /// The payload of `state` and the parameters it stores by name after the payload
    /// ([`Extras`]; none in format 11 as released: each parameter added later goes there,
    /// see the module docs of [`super`]).
    ///
    /// # Errors
    /// [`Error::Encode`] when a parameter stored by name cannot be encoded.
    pub(crate) fn from_state(state: &super::PlannerState) -> Result<(Self, Extras)> {
        let super::PlannerState {
            params,
            model,
            observations,
            confidence,
            outcome,
            rounds_recorded,
            rounds,
            reference,
            records,
        } = state;
        let mut extras = Extras::default();
        // Absent: the form of the stored model, which every planner of a build without the
        // parameter was fitted with.
        extras.put(
            FIT_RATE_TERM,
            &params.fit.rate_term.to_string(),
            &model.rate_term().to_string(),
        )?;
        extras.put(SAMPLER_SWITCH_S, &params.sampler.switch_s, &0.0)?;
        extras.put(SAMPLER_MAX_BUSY_SHARE, &params.sampler.max_busy_share, &1.0)?;
        extras.put(SAMPLER_OPERATORS, &(params.sampler.operators as u64), &1)?;
        let payload = Payload {
            params: params.into(),
            model: model.clone(),
            observations: observations.into(),
            confidence: confidence.into(),
            outcome: outcome.into(),
            rounds_recorded: *rounds_recorded,
            rounds: rounds.clone(),
            reference: reference.as_ref().map(Demonstration::from),
            records: records
                .iter()
                .map(|round| round.iter().map(Record::from).collect())
                .collect(),
        };
        Ok((payload, extras))
    }

    /// The planner state this payload and the parameters stored by name after it describe.
    ///
    /// # Errors
    /// A part the library refuses (counts, flags, a demonstration, a hold rule), or
    /// [`Error::Inconsistent`] for a parameter stored by name that this build does not know
    /// (the file was written by a newer build).
    pub(crate) fn into_state(self, mut extras: Extras) -> Result<super::PlannerState> {
        let mut params: crate::PlannerParams = self.params.try_into()?;
        let rate_term: String = extras.take(FIT_RATE_TERM, self.model.rate_term().to_string())?;
        params.fit.rate_term = rate_term.parse().map_err(|e| Error::Inconsistent {
            what: "parameters stored by name",
            why: format!("`{FIT_RATE_TERM}` = `{rate_term}`: {e}"),
        })?;
        params.sampler.switch_s = extras.take(SAMPLER_SWITCH_S, 0.0)?;
        params.sampler.max_busy_share = extras.take(SAMPLER_MAX_BUSY_SHARE, 1.0)?;
        let operators: u64 = extras.take(SAMPLER_OPERATORS, 1)?;
        params.sampler.operators = usize::try_from(operators).unwrap_or(usize::MAX);
        params.sampler.validate()?;
        extras.finish()?;
        Ok(super::PlannerState {
            params,
            model: self.model,
            observations: self.observations.try_into()?,
            confidence: self.confidence.try_into()?,
            outcome: self.outcome.into(),
            rounds_recorded: self.rounds_recorded,
            rounds: self.rounds,
            reference: self.reference.map(TryInto::try_into).transpose()?,
            records: self
                .records
                .into_iter()
                .map(|round| round.into_iter().map(TryInto::try_into).collect())
                .collect::<Result<_>>()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use std::path::{Path, PathBuf};

    use super::*;
    use crate::state::{HEADER_LEN, decode_any, encode_payload};

    /// The golden state file (`fixtures/state/example.tandem`, format 11).
    fn golden() -> (PathBuf, Vec<u8>) {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/state/example.tandem");
        let bytes = std::fs::read(&path).unwrap();
        (path, bytes)
    }

    #[test]
    fn parameters_off_their_defaults_convert_to_the_wire_and_back_unchanged() {
        let mut p = crate::PlannerParams::default();
        p.fit.warp.weights = Some(vec![1.0, 0.5]);
        p.fit.warp.n_nodes = Some(40);
        p.fit.warp.smooth_width = 5;
        p.fit.warp.fill_length = 0.25;
        p.fit.ranges = Some(vec![0.1, 0.2]);
        p.fit.reference = lfd::Reference::Medoid;
        p.fit.schema.quaternions.push(lfd::QuaternionBlock {
            name: "q".into(),
            channels: ["qx".into(), "qy".into(), "qz".into(), "qw".into()],
        });
        p.fit
            .schema
            .kinds
            .insert("rate".into(), lfd::ChannelKind::Rate);
        p.confidence.miss_rate = 0.1;
        p.confidence.estimate_error_rates = true;
        p.sampler.tick_s = Some(0.02);
        p.sampler.exact.max_pieces = 3;
        p.holds = lfd::HoldSpec {
            at_s: vec![1.5],
            rules: vec!["tool<0.5".parse().unwrap(), "force >= 2".parse().unwrap()],
        };
        let wire = PlannerParams::from(&p);
        assert_eq!(wire.holds.rules, ["tool<0.5", "force>=2"]);
        assert_eq!(crate::PlannerParams::try_from(wire).unwrap(), p);
    }

    #[test]
    fn a_hold_rule_that_does_not_parse_is_a_clear_error() {
        let mut wire = PlannerParams::from(&crate::PlannerParams::default());
        wire.holds.rules = vec!["tool = 1".into()];
        let err = crate::PlannerParams::try_from(wire)
            .unwrap_err()
            .to_string();
        assert!(err.contains("tool = 1"), "{err}");
    }

    #[test]
    fn the_golden_payload_converts_to_library_types_and_back_to_the_same_bytes() {
        let (path, bytes) = golden();
        let (payload, extras) = decode_any(&bytes, &path).unwrap();
        assert!(extras.is_empty());
        let state = payload.into_state(extras).unwrap();
        let (again, extras) = Payload::from_state(&state).unwrap();
        assert_eq!(encode_payload(&again, &extras).unwrap(), bytes);
    }

    #[test]
    fn the_rate_term_is_stored_by_name_only_off_its_models_form() {
        let (path, bytes) = golden();
        let (payload, extras) = decode_any(&bytes, &path).unwrap();
        let mut state = payload.into_state(extras).unwrap();
        // Absent from the file: the form its model was fitted with.
        assert_eq!(state.params.fit.rate_term, state.model.rate_term());
        // Another form is written after the payload, by name, and read back.
        let other = lfd::RateTerm::Relative {
            opening: 5,
            window: 49,
        };
        state.params.fit.rate_term = other;
        let (payload, extras) = Payload::from_state(&state).unwrap();
        assert_eq!(extras.names().collect::<Vec<_>>(), [FIT_RATE_TERM]);
        let file = encode_payload(&payload, &extras).unwrap();
        assert_eq!(&file[HEADER_LEN..bytes.len()], &bytes[HEADER_LEN..]);
        let (payload, extras) = decode_any(&file, &path).unwrap();
        assert_eq!(
            payload.into_state(extras).unwrap().params.fit.rate_term,
            other
        );
        // A stored value this build cannot read is refused, naming the parameter and the
        // choices.
        let mut bad = Extras::default();
        bad.put(
            FIT_RATE_TERM,
            &"relative:window=4".to_owned(),
            &String::new(),
        )
        .unwrap();
        let (payload, _) = decode_any(&bytes, &path).unwrap();
        let err = payload.into_state(bad).unwrap_err().to_string();
        assert!(
            err.contains(FIT_RATE_TERM) && err.contains("odd number of samples ≥ 3, got 4"),
            "{err}"
        );
    }

    #[test]
    fn the_operators_switch_time_and_load_cap_are_stored_by_name_only_off_their_defaults() {
        let (path, bytes) = golden();
        let (payload, extras) = decode_any(&bytes, &path).unwrap();
        let mut state = payload.into_state(extras).unwrap();
        // Absent from the file: no switch time, no cap.
        assert_eq!(state.params.sampler.switch_s, 0.0);
        assert_eq!(state.params.sampler.max_busy_share, 1.0);
        state.params.sampler.switch_s = 2.5;
        state.params.sampler.max_busy_share = 0.7;
        let (payload, extras) = Payload::from_state(&state).unwrap();
        assert_eq!(
            extras.names().collect::<Vec<_>>(),
            [SAMPLER_SWITCH_S, SAMPLER_MAX_BUSY_SHARE]
        );
        let file = encode_payload(&payload, &extras).unwrap();
        // The payload's bytes are those of the golden file; only the list after it is new.
        assert_eq!(&file[HEADER_LEN..bytes.len()], &bytes[HEADER_LEN..]);
        let (payload, extras) = decode_any(&file, &path).unwrap();
        let back = payload.into_state(extras).unwrap().params.sampler;
        assert_eq!((back.switch_s, back.max_busy_share), (2.5, 0.7));
        // A stored value the library refuses is a clear error naming it.
        let mut bad = Extras::default();
        bad.put(SAMPLER_MAX_BUSY_SHARE, &1.5_f64, &1.0).unwrap();
        let (payload, _) = decode_any(&bytes, &path).unwrap();
        let err = payload.into_state(bad).unwrap_err().to_string();
        assert!(err.contains("max_busy_share"), "{err}");
    }

    #[test]
    fn the_operator_count_is_stored_by_name_only_off_its_default() {
        let (path, bytes) = golden();
        let (payload, extras) = decode_any(&bytes, &path).unwrap();
        let mut state = payload.into_state(extras).unwrap();
        // Absent from the file: one operator, and one operator writes nothing.
        assert_eq!(state.params.sampler.operators, 1);
        let (_, extras) = Payload::from_state(&state).unwrap();
        assert_eq!(extras.names().count(), 0);
        state.params.sampler.operators = 3;
        let (payload, extras) = Payload::from_state(&state).unwrap();
        assert_eq!(extras.names().collect::<Vec<_>>(), [SAMPLER_OPERATORS]);
        let file = encode_payload(&payload, &extras).unwrap();
        // The payload's bytes are those of the golden file; only the list after it is new.
        assert_eq!(&file[HEADER_LEN..bytes.len()], &bytes[HEADER_LEN..]);
        let (payload, extras) = decode_any(&file, &path).unwrap();
        assert_eq!(
            payload.into_state(extras).unwrap().params.sampler.operators,
            3
        );
        // A stored count the library refuses (0, or more than the robot limit) is a clear
        // error naming it.
        for m in [0_u64, 17, u64::MAX] {
            let mut bad = Extras::default();
            bad.put(SAMPLER_OPERATORS, &m, &1).unwrap();
            let (payload, _) = decode_any(&bytes, &path).unwrap();
            let err = payload.into_state(bad).unwrap_err().to_string();
            assert!(err.contains("operators"), "{m}: {err}");
        }
    }

    /// What a build whose warp parameters gained a parameter with a default would write and
    /// read (the change the module docs of [`crate::state`] describe): `rate_form`, absent =
    /// `Linear` (the behaviour before it), stored by name as `fit.warp.rate_form`.
    mod next_build {
        use super::*;

        #[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
        pub(super) enum RateForm {
            #[default]
            Linear,
            Log,
        }

        pub(super) const NAME: &str = "fit.warp.rate_form";

        /// The payload of `state` whose warp parameters also have `rate_form`.
        pub(super) fn save(state: &crate::state::PlannerState, rate_form: RateForm) -> Vec<u8> {
            let (payload, mut extras) = Payload::from_state(state).unwrap();
            extras.put(NAME, &rate_form, &RateForm::Linear).unwrap();
            encode_payload(&payload, &extras).unwrap()
        }

        /// The state and `rate_form` of a file image.
        pub(super) fn load(bytes: &[u8]) -> (crate::state::PlannerState, RateForm) {
            let (payload, mut extras) = decode_any(bytes, Path::new("next.tandem")).unwrap();
            let form = extras.take(NAME, RateForm::Linear).unwrap();
            (payload.into_state(extras).unwrap(), form)
        }
    }

    #[test]
    fn a_new_parameter_at_its_default_does_not_change_the_format() {
        use next_build::RateForm;
        let (path, bytes) = golden();
        let state = crate::state::decode_state(&bytes, &path).unwrap();
        // At its default: the golden file's bytes, version 11, and it reads back as it.
        let same = next_build::save(&state, RateForm::Linear);
        assert_eq!(same, bytes);
        assert_eq!(next_build::load(&same).1, RateForm::Linear);
        // Every older golden file reads with the default too.
        for v in 4..=10 {
            let old = std::fs::read(
                Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join(format!("tests/fixtures/example_v{v}.tandem")),
            )
            .unwrap();
            assert_eq!(next_build::load(&old).1, RateForm::Linear, "version {v}");
        }
        // Off its default: the same payload, then the list of parameters by name; still
        // version 11, and it reads back.
        let other = next_build::save(&state, RateForm::Log);
        assert_eq!(other[8..12], bytes[8..12]);
        assert!(other[HEADER_LEN..].starts_with(&bytes[HEADER_LEN..]));
        // One entry: 1 (count), 18 (name length) and the name, 1 (value length) and 1 (variant
        // `Log`).
        assert_eq!(
            &other[bytes.len()..],
            [&[1u8, 18][..], next_build::NAME.as_bytes(), &[1, 1]].concat()
        );
        let (loaded, form) = next_build::load(&other);
        assert_eq!(form, RateForm::Log);
        assert_eq!(loaded.params, state.params);
        // This build, which does not know the parameter, refuses the file, naming it.
        let err = crate::state::decode_state(&other, Path::new("next.tandem"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("next.tandem")
                && err.contains(next_build::NAME)
                && err.contains("newer build"),
            "{err}"
        );
    }
}
