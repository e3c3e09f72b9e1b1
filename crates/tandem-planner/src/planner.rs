//! The iterative loop of the paper's Fig. 2 (§II-C, Eq. 21): model, observations,
//! confidence and schedule, updated after every pair of executions.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use tandem_confidence::{
    Confidence, ConfidenceParams, ErrorRates, Observations, estimate_error_rates,
};
use tandem_lfd::{Demonstration, Execution, FitParams, HoldSpec, Regridded, TaskModel};
use tandem_realtime::Coordinator;
use tandem_schedule::{
    CheckedSchedule, Outcome, PreviousFate, Problem, SamplerParams, Schedule, Source,
    sample_schedule_n,
};

use crate::state::{PlannerState, Stamp, StateLock};
use crate::{Error, Result, derive_seed, state};

/// Correction flags of the samples of a log put on a new grid. Supervision is a state: read
/// at the original sample nearest to each new one (`nearest`), as a logger at the new period
/// would have. A correction is an event: kept if any original sample of the new sample's
/// period had one (`bin_of`, original → new), and then the sample counts as supervised.
fn merge_flags(
    supervised: &[bool],
    corrected: &[bool],
    nearest: &[usize],
    bin_of: &[usize],
) -> (Vec<bool>, Vec<bool>) {
    let mut sup: Vec<bool> = nearest.iter().map(|&k| supervised[k]).collect();
    let mut cor = vec![false; nearest.len()];
    for (k, &j) in bin_of.iter().enumerate() {
        cor[j] |= corrected[k];
    }
    for (s, c) in sup.iter_mut().zip(&cor) {
        *s |= *c;
    }
    (sup, cor)
}

/// The rule of every execution record, whoever made it (CSV files, bags, Python arrays): the
/// operator corrects only what they supervise, so `corrected[k]` implies `supervised[k]`.
/// A correction on an unsupervised sample would be dropped from the observations (Eq. 9
/// counts supervised samples only) and lost without a word. `source` names the execution,
/// `unit` what an index counts (`"sample"`, or `"row"` of a file's rows).
fn check_corrections_supervised(
    source: &str,
    unit: &str,
    supervised: &[bool],
    corrected: &[bool],
) -> Result<()> {
    match (0..supervised.len().min(corrected.len())).find(|&k| corrected[k] && !supervised[k]) {
        Some(k) => Err(Error::BadExecution {
            what: "corrected",
            why: format!(
                "{source}: {unit} {k}: `corrected` is 1 but `supervised` is 0 (only a supervised, \
                 low-confidence sample can be corrected)"
            ),
        }),
        None => Ok(()),
    }
}

/// Parameters of a [`Planner`]: one block per stage of Fig. 2.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlannerParams {
    /// Alignment and model (§II-B1/2). Default: `FitParams::default()`.
    pub fit: FitParams,
    /// Confidence prior and threshold (Eq. 10–12). Default: `ConfidenceParams::default()`.
    pub confidence: ConfidenceParams,
    /// Anytime sampler (§II-C). Its `seed` is the master seed: the schedule made after
    /// `k` recorded pairs uses `derive_seed(seed, k)`. Default: `SamplerParams::default()`.
    pub sampler: SamplerParams,
    /// Hold points (reference samples where a robot may dwell, its clock stopped): reference
    /// times and channel rules, resolved on the model whenever the problem is (re)built
    /// (`crate::holds`); [`Planner::set_holds`] refuses a hold where the recorded corrections
    /// show the operator is needed ([`Error::HoldInLowConfidence`]). Default:
    /// none (the task start is always a hold and is never listed), and a planner without
    /// holds schedules exactly as before hold points existed.
    pub holds: HoldSpec,
}

impl PlannerParams {
    /// Checks every block.
    ///
    /// # Errors
    /// The lower crate's error for the first invalid block.
    pub fn validate(&self) -> Result<()> {
        self.fit.validate()?;
        self.confidence.validate()?;
        self.sampler.validate()?;
        self.holds.validate()?;
        Ok(())
    }
}

/// One execution as the system recorded it: samples with their reference-time log
/// (Eq. 21) and, per sample, whether the robot was supervised (low confidence) and
/// whether the operator corrected it.
#[derive(Clone, Debug, PartialEq)]
pub struct ExecutionRecord {
    /// The executed samples and the reference time (reference samples) of each.
    pub execution: Execution,
    /// `supervised[k]`: sample `k` ran low-confidence, with the operator watching.
    pub supervised: Vec<bool>,
    /// `corrected[k]`: the operator corrected sample `k` (only read where `supervised[k]`).
    pub corrected: Vec<bool>,
}

impl ExecutionRecord {
    /// Reference times and correction flags of the supervised samples only (the
    /// observations of Eq. 9: unsupervised samples carry no information).
    ///
    /// # Errors
    /// [`Error::BadExecution`] when the flag vectors do not have one entry per sample.
    pub fn observations(&self) -> Result<(Vec<f64>, Vec<bool>)> {
        let n = self.execution.ref_time_log.len();
        for (what, len) in [
            ("supervised", self.supervised.len()),
            ("corrected", self.corrected.len()),
        ] {
            if len != n {
                return Err(Error::BadExecution {
                    what,
                    why: format!("{len} flags for {n} logged samples"),
                });
            }
        }
        let mut times = Vec::new();
        let mut corrected = Vec::new();
        for k in 0..n {
            if self.supervised[k] {
                times.push(self.execution.ref_time_log[k]);
                corrected.push(self.corrected[k]);
            }
        }
        Ok((times, corrected))
    }

    /// [`observations`](Self::observations) with, for each supervised sample, the reference
    /// time at which its control tick ended (the next logged sample's; the sample's own for
    /// the last): `(times, swept_to, corrected)`, for
    /// [`Observations::record_votes_swept`](tandem_confidence::Observations::record_votes_swept).
    ///
    /// # Errors
    /// As [`observations`](Self::observations).
    pub fn observation_spans(&self) -> Result<(Vec<f64>, Vec<f64>, Vec<bool>)> {
        let (times, corrected) = self.observations()?;
        let log = &self.execution.ref_time_log;
        let ends = (0..log.len())
            .filter(|&k| self.supervised[k])
            .map(|k| log.get(k + 1).copied().unwrap_or(log[k]).max(log[k]))
            .collect();
        Ok((times, ends, corrected))
    }

    /// An execution logged with its own times (`tandem record --resample`: jitter, dropped
    /// samples), put on the even grid of [`Demonstration::regrid_csv_str`] with the series
    /// logged beside it, one entry per row of the file: the reference-time log interpolated
    /// linearly like the channels ([`Regridded::interpolate`]); the flags as
    /// [`Planner::check_execution`] merges them (a grid sample supervised if the row nearest
    /// to it in time was, corrected, and then supervised, if any row of its period was, so
    /// no correction is lost). The record is then taken in like any other (resampled to the
    /// model's period if its grid is finer).
    ///
    /// # Errors
    /// [`Error::BadExecution`] when the log or a flag vector does not have one entry per row,
    /// or a row is corrected but not supervised (as [`Planner::check_execution`]).
    pub fn from_regridded(
        grid: Regridded,
        ref_time_log: &[f64],
        supervised: &[bool],
        corrected: &[bool],
    ) -> Result<Self> {
        let rows = grid.n_rows();
        let source = grid.demonstration.source().to_owned();
        for (what, len) in [
            ("ref_time_log", ref_time_log.len()),
            ("supervised", supervised.len()),
            ("corrected", corrected.len()),
        ] {
            if len != rows {
                return Err(Error::BadExecution {
                    what,
                    why: format!("{len} entries for the {rows} rows of {source} (one per row)"),
                });
            }
        }
        check_corrections_supervised(&source, "row", supervised, corrected)?;
        let log = grid.interpolate("ref_time_log", ref_time_log)?;
        let (supervised, corrected) =
            merge_flags(supervised, corrected, &grid.nearest, &grid.bin_of);
        Ok(Self {
            execution: Execution {
                demonstration: grid.demonstration,
                ref_time_log: log,
            },
            supervised,
            corrected,
        })
    }

    /// FNV-1a (64 bit) of the samples (in their channel order), the log and the flags: what
    /// makes two records the same execution. Stable across builds and platforms.
    fn fingerprint(&self) -> u64 {
        let mut h = Fnv::new();
        let demo = &self.execution.demonstration;
        h.word(demo.n_samples() as u64);
        h.word(demo.n_channels() as u64);
        for v in demo.samples().iter().chain(&self.execution.ref_time_log) {
            h.word(v.to_bits());
        }
        for flags in [&self.supervised, &self.corrected] {
            h.word(flags.len() as u64);
            for &f in flags {
                h.byte(u8::from(f));
            }
        }
        h.finish()
    }
}

/// The 64-bit FNV-1a hash (Fowler, Noll, Vo): small, stable, enough to tell accidental
/// repeats of a round from new rounds.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
    fn byte(&mut self, b: u8) {
        self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
    }
    fn word(&mut self, w: u64) {
        for b in w.to_le_bytes() {
            self.byte(b);
        }
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

/// The fingerprint of a round: of its executions' fingerprints in sorted order, so that the
/// same executions given in another robot order are the same round.
fn round_fingerprint(records: &[ExecutionRecord]) -> u64 {
    let mut each: Vec<u64> = records.iter().map(ExecutionRecord::fingerprint).collect();
    each.sort_unstable();
    let mut h = Fnv::new();
    for f in each {
        h.word(f);
    }
    h.finish()
}

/// Where a planner was loaded from (or last saved to), and that file's content then: a save
/// into the same file refuses to overwrite content some other process wrote since.
#[derive(Debug, Default)]
pub(crate) struct Origin(Mutex<Option<(PathBuf, Stamp)>>);

impl Origin {
    pub(crate) fn get(&self) -> Option<(PathBuf, Stamp)> {
        self.0.lock().map_or(None, |o| o.clone())
    }
    pub(crate) fn set(&self, path: PathBuf, stamp: Stamp) {
        if let Ok(mut o) = self.0.lock() {
            *o = Some((path, stamp));
        }
    }

    /// The one guarded save of a state file (a planner's or a cell's), under `lock`: refuses a
    /// target that is not a state file, one another process saved into since it was loaded
    /// from here ([`Error::Changed`]), and one this state did not come from that holds rounds
    /// (`rounds_at` counts them; [`Error::WouldDiscardRounds`] unless `discard`); then writes
    /// `encode()`'s bytes atomically and remembers them as this state's origin. Returns the
    /// rounds discarded (`None`: an unreadable file replaced with `discard`).
    pub(crate) fn save_guarded(
        &self,
        lock: &StateLock,
        discard: bool,
        rounds_at: impl FnOnce(&Path) -> Result<usize>,
        encode: impl FnOnce() -> Result<Vec<u8>>,
    ) -> Result<Option<usize>> {
        let path = lock.state_path();
        state::check_target(path)?;
        let here = state::resolved(path);
        let origin = self.get();
        if let Some((from, stamp)) = &origin
            && *from == here
            && let Some(now) = state::stamp_at(path)?
            && now != *stamp
        {
            return Err(Error::Changed {
                path: path.to_path_buf(),
            });
        }
        // A file this state did not come from: its rounds would be lost.
        let mut discarded = Some(0);
        if origin.is_none_or(|(from, _)| from != here) {
            match rounds_at(path) {
                Ok(0) => {}
                Ok(rounds) if !discard => {
                    return Err(Error::WouldDiscardRounds {
                        path: path.to_path_buf(),
                        rounds,
                    });
                }
                Ok(rounds) => discarded = Some(rounds),
                Err(_) if discard => discarded = None,
                Err(e) => return Err(e),
            }
        }
        let bytes = encode()?;
        state::write_atomic(path, &bytes)?;
        if let Some(stamp) = state::stamp_of(&bytes) {
            self.set(here, stamp);
        }
        Ok(discarded)
    }
}

impl Clone for Origin {
    fn clone(&self) -> Self {
        Self(Mutex::new(self.get()))
    }
}

/// What [`Planner::record_round`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordReport {
    /// Reference samples that became high-confidence in this update (newly latched, or a
    /// latched run whose prior's trust no longer yields: [`tandem_confidence::RoundUpdate`]).
    pub newly_high: usize,
    /// High-confidence samples that turned low-confidence again ([`Confidence::update_round`]):
    /// latched samples this round's corrections reopened (rounds recorded out of order bring
    /// corrections of samples latched since they ran; in order, a supervised sample's split
    /// and sweep reach a latched sample at the edge of a supervised stretch), and latched
    /// samples resting on their prior whose trust now yields to a need on both sides.
    pub reopened: usize,
    /// Where the new schedule came from (sampled, previous, repaired previous, serial).
    pub source: Source,
    /// The new schedule's `T_total` (Eq. 13), s.
    pub t_total_s: f64,
    /// The `T_total` (Eq. 13, s) of the schedule the round ran (the previous one).
    pub previous_t_total_s: f64,
    /// What became of the previous schedule on the updated problem: still valid, re-timed
    /// for the updated model, or invalid and why ([`PreviousFate::describe`] says it in one
    /// sentence). While it is `Valid` or `Repaired`, [`RecordReport::t_total_s`] is at most
    /// that schedule's `T_total`.
    pub previous: PreviousFate,
    /// Wall time of the model update (Eq. 21).
    pub model_update: Duration,
    /// Wall time of recording the observations and updating the confidence (Eq. 9–12).
    pub confidence: Duration,
    /// Wall time of re-scheduling (§II-C).
    pub scheduling: Duration,
    /// One sentence per execution that was not taken in as given: resampled from its own
    /// sample period to the model's ([`Planner::check_execution`]). Front ends show them.
    pub notices: Vec<String>,
}

/// What [`Planner::refit`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct RefitReport {
    /// Rounds replayed into the new planner (all the old one recorded).
    pub rounds: usize,
    /// Whether the new reference differs from the old one (or the old one is unknown: a
    /// planner made from a model), so that each recorded execution was aligned to the new
    /// reference for its reference-time log instead of keeping the recorded one.
    pub reference_changed: bool,
    /// The old planner's share of high-confidence reference samples (`Confidence::high_share`).
    pub high_share_before: f64,
}

/// Whether two demonstrations are the same signal: channels, period and samples (the source
/// label aside).
fn same_signal(a: &Demonstration, b: &Demonstration) -> bool {
    a.channel_names() == b.channel_names() && a.dt_s() == b.dt_s() && a.samples() == b.samples()
}

/// The reference-time log of an execution of `n_samples` samples from its warp (`warp[n]`:
/// the execution's sample, fractional, at reference sample `n`; monotone, pinned at both
/// ends): for each sample `k` the reference time whose warp value it is (linear between
/// reference samples; the first sample of a flat stretch), in `[0, warp.len() − 1]`;
/// monotone.
fn log_from_warp(warp: &[f64], n_samples: usize) -> Vec<f64> {
    let last = warp.len() - 1;
    (0..n_samples)
        .map(|k| {
            let v = k as f64;
            // First n with warp[n] ≥ v.
            let hi = warp.partition_point(|&w| w < v);
            if hi == 0 {
                return 0.0;
            }
            if hi > last {
                return last as f64;
            }
            let (a, b) = (warp[hi - 1], warp[hi]);
            let frac = if b > a { (v - a) / (b - a) } else { 1.0 };
            ((hi - 1) as f64 + frac).clamp(0.0, last as f64)
        })
        .collect()
}

/// The loop of Fig. 2: the task model learned from demonstrations and executions, the
/// correction observations, the latched confidence and the current schedule.
///
/// After each round of executions, [`Planner::record_round`] adds every execution to the
/// model with their known reference-time logs (Eq. 21, no re-alignment), adds their
/// supervised samples to the observations, updates the confidence (Eq. 9–12, with the
/// latch: a high-confidence sample stays high unless the round's corrections of it make its
/// totals fail) and re-schedules, warm-started by the previous schedule.
///
/// # The previous schedule as fallback
///
/// The paper says the previous schedule "will always remain valid" because confidence
/// only grows. That is not quite so here: the model update moves the mean gradient
/// `ψ̇̄_D` and widens `[ψ̇min, ψ̇max]`, and Eq. 20 requires low-confidence samples to run at
/// the *new* mean. So the previous schedule is offered to the sampler
/// ([`tandem_schedule::sample_schedule`]) as it is, and the sampler re-validates it against
/// the new problem; if it fails, the sampler re-times it for the new problem (its order of
/// low-confidence runs, its clearances and its holds kept, low-confidence samples at the new
/// mean, no event earlier than before) and validates that again (all constraints of Eq. 20
/// including the margin check) before using it as incumbent, so the new `T_total` is at most
/// the re-timed one. If nothing passes, the fastest serial schedule is the incumbent.
/// [`RecordReport::source`] says which one won and [`RecordReport::previous`] what became of
/// the previous schedule (docs/decisions.md, "Learning never makes the plan worse").
#[derive(Clone, Debug)]
pub struct Planner {
    params: PlannerParams,
    model: TaskModel,
    observations: Observations,
    confidence: Confidence,
    problem: Problem,
    outcome: Outcome,
    pairs_recorded: usize,
    /// Fingerprints of the rounds recorded since the state format had them (version 6).
    rounds: Vec<u64>,
    /// The reference demonstration the model's time axis is (its samples in the model's
    /// channel order), kept since state format 11 so that a refit can carry the recorded
    /// reference times onto another reference; `None` for a planner made from a model.
    reference: Option<Demonstration>,
    /// Every round recorded since state format 11, in order: the executions as
    /// [`Planner::check_execution`] took them in (at the model's period), for
    /// [`Planner::refit`].
    records: Vec<Vec<ExecutionRecord>>,
    origin: Origin,
    /// Set by [`Planner::load`] when it replaced a stored schedule that failed the check.
    load_notice: Option<String>,
}

/// The scheduling problem for the current model and confidence (Eq. 12, 14).
///
/// `ψ̇̄` is clamped into `[ψ̇min, ψ̇max]` sample by sample: the mean of the same values that
/// define the bounds lies between them, but its floating-point update (Welford) can
/// overshoot by a rounding error.
///
/// The hold points are `holds` resolved on `model` ([`HoldSpec::resolve`]); without a
/// declaration the problem is the one built before hold points existed.
fn problem_for(model: &TaskModel, confidence: &Confidence, holds: &HoldSpec) -> Result<Problem> {
    let (gmin, gmax) = (model.grad_min(), model.grad_max());
    let gmean = model
        .grad_mean()
        .iter()
        .zip(gmin.iter().zip(gmax))
        .map(|(&g, (&lo, &hi))| if lo <= hi { g.clamp(lo, hi) } else { g })
        .collect();
    let problem = Problem::new(
        confidence.conf().to_vec(),
        gmean,
        gmin.to_vec(),
        gmax.to_vec(),
        model.dt_s(),
    )?;
    if holds.is_empty() {
        return Ok(problem);
    }
    Ok(problem.with_holds(crate::holds::resolve(holds, model)?)?)
}

/// [`tandem_realtime::RobotCount::new`], the one check of a robot count: `1 ≤ n_robots ≤
/// MAX_ROBOTS`.
///
/// # Errors
/// [`Error::Realtime`] with `tandem_realtime::Error::RobotCount` otherwise.
fn check_robot_count(n_robots: usize) -> Result<()> {
    tandem_realtime::RobotCount::new(n_robots)?;
    Ok(())
}

impl Planner {
    /// Learns the task from demonstrations (the reference is the one `params.fit.reference`
    /// chooses) and makes the first schedule: aligns and fits the model (§II-B1/2), sets the
    /// confidence from the prior alone (Eq. 10–12) and samples a schedule (§II-C) with seed
    /// `derive_seed(seed, 0)`.
    ///
    /// # Errors
    /// Invalid parameters, or the lower crates' errors for the demonstrations.
    pub fn new(demos: &[Demonstration], params: PlannerParams) -> Result<Self> {
        Self::with_robots(demos, params, 2)
    }

    /// As [`Planner::new`] for `n_robots` robots (`1 ≤ N ≤` [`tandem_realtime::MAX_ROBOTS`])
    /// doing the same task under one operator: every schedule has `N` warps and `N − 1`
    /// offsets, and [`Planner::record_round`] takes `N` executions. [`Planner::new`] is the
    /// paper's `N = 2`. The state file stores `N` (as the schedule's robot count).
    ///
    /// # Errors
    /// [`Error::Realtime`] (`RobotCount`) for `n_robots` outside `1..=MAX_ROBOTS`, and as
    /// [`Planner::new`].
    pub fn with_robots(
        demos: &[Demonstration],
        params: PlannerParams,
        n_robots: usize,
    ) -> Result<Self> {
        check_robot_count(n_robots)?;
        params.validate()?;
        let model = TaskModel::fit(demos, &params.fit)?;
        let reference = demos[model.reference_idx()]
            .conform_to(model.channel_names())?
            .into_owned();
        let mut planner = Self::from_model_with_robots(model, params, n_robots)?;
        planner.reference = Some(reference);
        Ok(planner)
    }

    /// As [`Planner::new`] from an already fitted model (e.g. to run several trials from
    /// one alignment). `params.fit` is kept for the record only.
    ///
    /// # Errors
    /// Invalid parameters, a degenerate prior or an infeasible problem.
    pub fn from_model(model: TaskModel, params: PlannerParams) -> Result<Self> {
        Self::from_model_with_robots(model, params, 2)
    }

    /// As [`Planner::from_model`] for `n_robots` robots (see [`Planner::with_robots`]).
    ///
    /// # Errors
    /// [`Error::Realtime`] (`RobotCount`), and as [`Planner::from_model`].
    pub fn from_model_with_robots(
        model: TaskModel,
        params: PlannerParams,
        n_robots: usize,
    ) -> Result<Self> {
        check_robot_count(n_robots)?;
        params.validate()?;
        crate::holds::check_declared(&params.holds, &model)?;
        let confidence = Confidence::from_prior(model.sigma2_d(), params.confidence.clone())?;
        let observations = Observations::new(model.n_ref())?;
        let problem = problem_for(&model, &confidence, &params.holds)?;
        let outcome =
            sample_schedule_n(&problem, n_robots, &Self::sampler_params(&params, 0), None)?;
        Ok(Self {
            params,
            model,
            observations,
            confidence,
            problem,
            outcome,
            pairs_recorded: 0,
            rounds: Vec::new(),
            reference: None,
            records: Vec::new(),
            origin: Origin::default(),
            load_notice: None,
        })
    }

    fn sampler_params(params: &PlannerParams, pairs_recorded: usize) -> SamplerParams {
        SamplerParams {
            seed: derive_seed(params.sampler.seed, pairs_recorded as u64),
            ..params.sampler.clone()
        }
    }

    /// One execution as [`Planner::record_round`] takes it in, checked: its flags have one
    /// entry per sample; an execution logged at a finer period than the model's (a control
    /// loop faster than the demonstrations) is resampled to the model's period
    /// ([`TaskModel::resample_execution`]: samples and log interpolated; a sample is supervised
    /// if the original sample nearest to it in time was, and corrected (and supervised) if any
    /// original sample of its period was corrected, so no correction is lost); then the
    /// model's checks of an execution (channels,
    /// log, coverage of the whole task, a duration the demonstrated speeds allow). Returns the
    /// record at the model's period and, when it was resampled, a sentence saying so.
    ///
    /// # Errors
    /// [`Error::BadExecution`] for flag vectors of the wrong length and for a sample
    /// corrected but not supervised (the operator corrects only what they supervise: such a
    /// correction would be dropped without a word; every front end gets this check here); the
    /// model crate's errors (`CoarseExecution`, `TruncatedExecution`, `ExecutionDuration`,
    /// channels, log).
    pub fn check_execution(
        &self,
        record: &ExecutionRecord,
    ) -> Result<(ExecutionRecord, Option<String>)> {
        let demo = &record.execution.demonstration;
        let n = demo.n_samples();
        for (what, len) in [
            ("supervised", record.supervised.len()),
            ("corrected", record.corrected.len()),
        ] {
            if len != n {
                return Err(Error::BadExecution {
                    what,
                    why: format!("{len} flags for the {n} samples of {}", demo.source()),
                });
            }
        }
        check_corrections_supervised(
            demo.source(),
            "sample",
            &record.supervised,
            &record.corrected,
        )?;
        let resampled = self.model.resample_execution(&record.execution)?;
        let n_new = resampled.execution.demonstration.n_samples();
        let (supervised, corrected, note) = if resampled.bin_of.len() == n_new {
            (record.supervised.clone(), record.corrected.clone(), None)
        } else {
            let (sup, cor) = merge_flags(
                &record.supervised,
                &record.corrected,
                &resampled.nearest,
                &resampled.bin_of,
            );
            let note = format!(
                "{}: logged {} s apart, resampled to the model's {} s ({n} → {n_new} samples)",
                demo.source(),
                (demo.dt_s() * 1e9).round() / 1e9,
                (self.model.dt_s() * 1e9).round() / 1e9
            );
            (sup, cor, Some(note))
        };
        self.model.execution_warp(&resampled.execution)?;
        Ok((
            ExecutionRecord {
                execution: resampled.execution,
                supervised,
                corrected,
            },
            note,
        ))
    }

    /// Records a round of executions, one per robot of the schedule (robot 1 first), and
    /// re-schedules (see the type docs) at the control tick of the current schedule (the one
    /// the round ran at, [`Schedule::tick_s`]), with seed `derive_seed(seed, k)` after `k`
    /// recorded rounds.
    ///
    /// Each execution is taken in through [`Planner::check_execution`] (resampled to the
    /// model's period if it was logged finer; refused if it does not cover the task or lasts
    /// longer or shorter than any admissible speed allows). A round with the same executions,
    /// logs and flags as one recorded before (in any robot order) is refused.
    /// Everything is checked before the planner changes: on error it is as before.
    ///
    /// # Errors
    /// [`Error::BadExecution`] for a number of records other than the schedule's robot count
    /// or flag vectors of the wrong length; [`Error::DuplicateRound`]; the lower crates'
    /// errors for a bad execution (channels, period, log, coverage, duration) or observation.
    pub fn record_round(&mut self, executions: &[ExecutionRecord]) -> Result<RecordReport> {
        let n_robots = self.n_robots();
        if executions.len() != n_robots {
            return Err(Error::BadExecution {
                what: "executions",
                why: format!(
                    "{} execution records for a round of {n_robots} robots (one per robot)",
                    executions.len()
                ),
            });
        }
        let mut records = Vec::with_capacity(n_robots);
        let mut notices = Vec::new();
        for e in executions {
            let (record, note) = self.check_execution(e)?;
            records.push(record);
            notices.extend(note);
        }
        let fingerprint = round_fingerprint(&records);
        if let Some(k) = self.rounds.iter().position(|&f| f == fingerprint) {
            return Err(Error::DuplicateRound {
                round: self.pairs_recorded - self.rounds.len() + k + 1,
            });
        }
        let t0 = Instant::now();
        let mut model = self.model.clone();
        for e in &records {
            model.update(&e.execution)?;
        }
        let t1 = Instant::now();
        let mut observations = self.observations.clone();
        for e in &records {
            if self.params.confidence.one_vote_per_execution {
                let (times, swept_to, corrected) = e.observation_spans()?;
                observations.record_votes_swept(&times, &swept_to, &corrected)?;
            } else {
                let (times, corrected) = e.observations()?;
                observations.record(&times, &corrected)?;
            }
        }
        let mut confidence = self.confidence.clone();
        // The totals' decision; the latch yields only to this round's corrections (rounds
        // recorded out of order: docs/decisions.md, "The same rounds in any order").
        let latching =
            confidence.update_round(model.sigma2_d(), &self.observations, &observations)?;
        let problem = problem_for(&model, &confidence, &self.params.holds)?;
        let t2 = Instant::now();
        let pairs_recorded = self.pairs_recorded + 1;
        let sampler = SamplerParams {
            tick_s: Some(self.schedule().tick_s),
            ..Self::sampler_params(&self.params, pairs_recorded)
        };
        let outcome =
            sample_schedule_n(&problem, n_robots, &sampler, Some(&self.outcome.schedule))?;
        let t3 = Instant::now();
        let report = RecordReport {
            newly_high: latching.newly_high,
            reopened: latching.reopened,
            source: outcome.source,
            t_total_s: outcome.t_total_s,
            previous_t_total_s: self.outcome.t_total_s,
            previous: outcome.previous.clone(),
            model_update: t1 - t0,
            confidence: t2 - t1,
            scheduling: t3 - t2,
            notices,
        };
        self.model = model;
        self.observations = observations;
        self.confidence = confidence;
        self.problem = problem;
        self.outcome = outcome;
        self.pairs_recorded = pairs_recorded;
        self.rounds.push(fingerprint);
        self.records.push(records);
        Ok(report)
    }

    /// Fits the task again from `demos` with `params` (as [`Planner::with_robots`], for this
    /// planner's robot count) and replays every round this planner recorded, in their
    /// original order, so that the operator's corrections are kept: the returned planner is
    /// the one a fresh fit would be after recording the same rounds.
    ///
    /// Each recorded execution keeps its samples and its supervised/corrected flags (per
    /// execution sample); only its reference-time log changes frame. When the new model's
    /// reference is the old one (the same samples), the logs are kept as recorded (the
    /// coordinator's exact clock); otherwise each execution is aligned to the new reference
    /// as the fit aligns every demonstration ([`TaskModel::align_demonstration`]) and its log
    /// is the inverse of that warp. Every round then goes through
    /// [`Planner::record_round`] (the checks of [`Planner::check_execution`], the model update
    /// of Eq. 21, the observations, the latched confidence and a schedule with the seed of
    /// that round), so the confidence, model and schedule are those of a fresh fit with the
    /// same rounds recorded. The round fingerprints are the recorded ones (a round given
    /// again is still refused). The new planner saves into the file this one was loaded from
    /// (the check that no other process saved into it meanwhile applies) and nowhere else
    /// that holds rounds ([`Planner::save_locked`]). This planner is not changed.
    ///
    /// # Errors
    /// As [`Planner::with_robots`]; [`Error::CannotReplay`] when rounds were recorded by a
    /// build older than state format 11 (their executions were not kept), or when a recorded
    /// execution does not align to the new reference or fails the new model's checks (other
    /// channels, period, coverage, duration).
    pub fn refit(
        &self,
        demos: &[Demonstration],
        params: PlannerParams,
    ) -> Result<(Planner, RefitReport)> {
        let rounds = self.pairs_recorded;
        if self.records.len() < rounds {
            return Err(Error::CannotReplay {
                why: format!(
                    "{} of its {rounds} rounds were recorded by a tandem older than state \
                     format 11, which did not keep the executions, so they cannot be replayed",
                    rounds - self.records.len()
                ),
            });
        }
        let mut planner = Self::with_robots(demos, params, self.n_robots())?;
        let new_reference = planner
            .reference
            .clone()
            .expect("with_robots keeps the reference");
        // The recorded logs hold on the new model when its reference is the old one.
        let same_reference = self
            .reference
            .as_ref()
            .is_some_and(|old| same_signal(old, &new_reference));
        for (k, round) in self.records.iter().enumerate() {
            let mut carried = Vec::with_capacity(round.len());
            for (robot, r) in round.iter().enumerate() {
                let mut r = r.clone();
                if !same_reference {
                    let demo = &r.execution.demonstration;
                    let warp = planner
                        .model
                        .align_demonstration(&new_reference, demo, &planner.params.fit)
                        .map_err(|e| Error::CannotReplay {
                            why: format!(
                                "round {}, robot {}: the execution does not align to the new \
                                 reference ({e})",
                                k + 1,
                                robot + 1
                            ),
                        })?;
                    r.execution.ref_time_log = log_from_warp(&warp, demo.n_samples());
                }
                carried.push(r);
            }
            planner
                .record_round(&carried)
                .map_err(|e| Error::CannotReplay {
                    why: format!("round {} does not replay on the new model: {e}", k + 1),
                })?;
        }
        planner.rounds.clone_from(&self.rounds);
        planner.origin = self.origin.clone();
        let report = RefitReport {
            rounds,
            reference_changed: !same_reference,
            high_share_before: self.confidence.high_share(),
        };
        Ok((planner, report))
    }

    /// [`Planner::record_round`] for the paper's two robots; deprecated: a round is one
    /// execution of each of the `N` robots, and `record_round` takes any `N`.
    ///
    /// # Errors
    /// As [`Planner::record_round`].
    #[deprecated(
        since = "0.1.0",
        note = "use `Planner::record_round` (a round of N robots)"
    )]
    pub fn record_pair(&mut self, executions: &[ExecutionRecord; 2]) -> Result<RecordReport> {
        self.record_round(executions)
    }

    /// Re-runs the anytime sampler (§II-C) on the current problem with `sampler`, warm-started
    /// by the current schedule, and replaces the stored outcome by the result. Model,
    /// observations, confidence, parameters and [`Planner::rounds_recorded`] are unchanged
    /// (`sampler` is used for this call only and not stored in [`Planner::params`]).
    ///
    /// `sampler.tick_s = None` keeps the current schedule's control tick
    /// ([`Schedule::tick_s`]); `Some(t)` re-schedules for tick `t`, which later
    /// [`Planner::record_round`]s keep. The current schedule is the sampler's incumbent,
    /// re-checked at that tick, so `T_total` (Eq. 13, s) never increases as long as the
    /// current schedule is valid at it: always so at the current schedule's own tick.
    /// Otherwise the sampler repairs it or falls back to the fastest serial schedule, as in
    /// [`Planner::record_round`]. The new schedule carries the tick: run it at that tick.
    ///
    /// On error the planner is as before.
    ///
    /// # Errors
    /// The schedule crate's error for invalid `sampler` parameters or an infeasible problem.
    pub fn reschedule(&mut self, sampler: &SamplerParams) -> Result<&Outcome> {
        let sampler = SamplerParams {
            tick_s: sampler.tick_s.or(Some(self.schedule().tick_s)),
            ..sampler.clone()
        };
        let outcome = sample_schedule_n(
            &self.problem,
            self.n_robots(),
            &sampler,
            Some(&self.outcome.schedule),
        )?;
        self.outcome = outcome;
        Ok(&self.outcome)
    }

    /// Declares the hold points `holds` on this planner in place of its own
    /// ([`PlannerParams::holds`]) and re-schedules (warm-started by the current schedule, at
    /// its tick, with the seed of a plain re-schedule, [`crate::reschedule_seed`], so the same
    /// call gives the same schedule). Model, observations, confidence and
    /// [`Planner::rounds_recorded`] are unchanged. On error the planner is as before.
    ///
    /// # Errors
    /// As the declaration check of [`Planner::new`] (a malformed hold, a time outside the task,
    /// an unknown channel, a rule that holds nowhere), and [`Error::HoldInLowConfidence`] for a
    /// hold inside a low-confidence stretch that the recorded corrections show needs the
    /// operator (see `crate::holds`).
    pub fn set_holds(&mut self, holds: HoldSpec) -> Result<&Outcome> {
        crate::holds::check_declared(&holds, &self.model)?;
        crate::holds::check_evidence(&holds, &self.model, &self.explain_low_confidence()?)?;
        let problem = problem_for(&self.model, &self.confidence, &holds)?;
        let sampler = SamplerParams {
            tick_s: Some(self.schedule().tick_s),
            seed: crate::reschedule_seed(self.params.sampler.seed, self.pairs_recorded),
            ..self.params.sampler.clone()
        };
        let outcome = sample_schedule_n(
            &problem,
            self.n_robots(),
            &sampler,
            Some(&self.outcome.schedule),
        )?;
        self.params.holds = holds;
        self.problem = problem;
        self.outcome = outcome;
        Ok(&self.outcome)
    }

    /// Robots `N` the planner schedules (the current schedule's robot count; 2 unless made by
    /// [`Planner::with_robots`]).
    pub fn n_robots(&self) -> usize {
        self.outcome.schedule.n_robots()
    }

    /// The current schedule.
    pub fn schedule(&self) -> &Schedule {
        &self.outcome.schedule
    }

    /// The real-time coordinator (Eq. 17–18, Alg. 1) of the current schedule on the current
    /// problem, at the control tick the schedule was checked with ([`Schedule::tick_s`]): what
    /// runs the robots until the next [`Planner::record_round`].
    ///
    /// The schedule is checked on the problem first ([`Schedule::check`]: every constraint of
    /// Eq. 20 with this build's margin check), so that a coordinator never runs a schedule
    /// this build has not accepted.
    ///
    /// # Errors
    /// The schedule crate's [`tandem_schedule::Error::Invalid`] if the schedule fails the
    /// check (never for a planner made by [`Planner::new`], [`Planner::from_model`] or
    /// [`Planner::load`], which re-schedules a stored schedule that fails it).
    ///
    /// It runs with the operator's switch time of the planner's parameters
    /// (`params().sampler.switch_s`, [`Coordinator::with_switch_s`]): a robot leaves a hold
    /// with release rules no sooner than that after the robots it waits for left their
    /// stretches.
    ///
    /// With `params().sampler.operators = M > 1` (issue 44) it is the sectored round of
    /// [`Planner::sectored_rounds`] ([`Coordinator::sectored`]): `M` one-operator rounds side
    /// by side, one per operator.
    ///
    /// With a load cap `params().sampler.max_busy_share = u < 1` (issue 41) it counts each
    /// operator's busy ticks ([`Coordinator::with_max_busy_share`]) and, once the round has
    /// ended, [`Coordinator::rest_ticks`] is the rest before the next round that keeps every
    /// operator's share of the round and its rest at most `u`: whoever starts the next round
    /// (the simulated workcell, `tandem simulate`, a user's loop) waits it.
    pub fn coordinator(&self) -> Result<Coordinator> {
        let sp = &self.params().sampler;
        let c = if sp.operators > 1 {
            self.sectored_rounds()?.1
        } else {
            self.checked_schedule()?
                .coordinator()?
                .with_switch_s(sp.switch_s)?
        };
        Ok(c.with_max_busy_share(sp.max_busy_share)?)
    }

    /// The round of `M = params().sampler.operators` operators (issue 44; docs/decisions.md,
    /// "M operators in rounds: sectors end to end"), and its coordinator
    /// ([`Coordinator::sectored`]): of two candidates the one with the least `T_total` —
    /// the even sectors ([`tandem_schedule::sectored_rounds`], each sector's one-operator
    /// schedule sampled with this planner's parameters and the seed of the current schedule,
    /// on the problem with its hold points, each sector waiting at its holds by its own
    /// release rules), and the current `N`-robot schedule run by operator 0 alone (with its
    /// holds; the other operators idle), which wins only where one operator's round is
    /// shorter than the sectors'. Either keeps at most one robot
    /// low-confidence per operator in every tick. The returned [`tandem_schedule::SectoredRounds`]
    /// is the chosen one (one sector of `N` for the second candidate); its `lower_bound_s`
    /// bounds every round of `M` operators. A snapshot: the planner and its state file keep
    /// the one-operator schedule.
    ///
    /// # Errors
    /// As [`Planner::checked_schedule`] and [`tandem_schedule::sectored_rounds`]; the realtime
    /// crate's for the coordinator (never `Unsafe` for the sampler's schedules).
    pub fn sectored_rounds(&self) -> Result<(tandem_schedule::SectoredRounds, Coordinator)> {
        let sp = &self.params().sampler;
        let m = tandem_realtime::OperatorCount::new(sp.operators)?;
        let tick_s = self.schedule().tick_s;
        let sampler = SamplerParams {
            tick_s: Some(tick_s),
            ..Self::sampler_params(&self.params, self.pairs_recorded)
        };
        let margins = tandem_realtime::MarginParams {
            tick_s,
            switch_s: sp.switch_s,
        };
        let n = self.n_robots();
        let mut sectors = tandem_schedule::sectored_rounds(self.problem(), n, m.get(), &sampler)?;
        let mut robots = sectors.timelines(self.problem())?;
        if self.outcome.t_total_s < sectors.t_total_s {
            let one = self.checked_schedule()?;
            robots = one.timelines().to_vec();
            sectors = tandem_schedule::SectoredRounds {
                sizes: vec![n],
                schedules: vec![one.into_schedule()],
                t_total_s: self.outcome.t_total_s,
                lower_bound_s: sectors.lower_bound_s,
            };
        }
        let holds = sectors.holds();
        let coord = Coordinator::sectored(robots, &holds, &sectors.sector_of(), m, &margins)?;
        Ok((sectors, coord))
    }

    /// The current schedule checked on the current problem ([`Schedule::check`]): what
    /// [`Planner::coordinator`] runs.
    ///
    /// # Errors
    /// As [`Planner::coordinator`].
    pub fn checked_schedule(&self) -> Result<CheckedSchedule> {
        let sp = &self.params.sampler;
        Ok(self
            .schedule()
            .check_with_operator(&self.problem, sp.switch_s, sp.max_busy_share)?)
    }

    /// Why [`Planner::load`] replaced the stored schedule, if it did: the stored one failed
    /// this build's check on the stored problem (e.g. a file written by a build whose margin
    /// check accepted more, or edited by hand), and a fresh one was made. The replacement is
    /// in memory until the planner is saved.
    pub fn load_notice(&self) -> Option<&str> {
        self.load_notice.as_deref()
    }

    /// The sampler's result for the current schedule (`T_total`, source, counts).
    pub fn outcome(&self) -> &Outcome {
        &self.outcome
    }

    /// The current scheduling problem (confidence and gradient bounds per reference sample).
    pub fn problem(&self) -> &Problem {
        &self.problem
    }

    /// The task model.
    pub fn model(&self) -> &TaskModel {
        &self.model
    }

    /// The correction observations so far.
    pub fn observations(&self) -> &Observations {
        &self.observations
    }

    /// The operator's error rates the confidence decides with: estimated from the
    /// observations when `params().confidence.estimate_error_rates`, else the configured
    /// ones (`tandem_confidence::estimate_error_rates`; probabilities per control sample).
    ///
    /// # Errors
    /// The confidence crate's error for invalid parameters (a loaded planner has valid ones).
    pub fn error_rates(&self) -> Result<ErrorRates> {
        Ok(estimate_error_rates(
            &self.observations,
            &self.params.confidence,
        )?)
    }

    /// The latched confidence (`conf()[n]`: reference sample `n` is high-confidence).
    pub fn confidence(&self) -> &Confidence {
        &self.confidence
    }

    /// The parameters.
    pub fn params(&self) -> &PlannerParams {
        &self.params
    }

    /// Sets the operator's switch time `δ = switch_s` (real s, finite and ≥ 0) and load cap
    /// `u_max = max_busy_share` (in `(0, 1]`) of [`PlannerParams::sampler`] (issue 41): the
    /// parameters every later schedule of this planner honours ([`Planner::record_round`],
    /// [`Planner::plan`]) and the state file stores. The current schedule is not changed:
    /// call [`Planner::reschedule`] with them to re-plan now. On error the planner is as
    /// before.
    ///
    /// # Errors
    /// [`Error::Schedule`] (`BadParam` naming `switch_s` or `max_busy_share`) for a value
    /// outside its range.
    pub fn set_operator(&mut self, switch_s: f64, max_busy_share: f64) -> Result<()> {
        let sampler = SamplerParams {
            switch_s,
            max_busy_share,
            ..self.params.sampler.clone()
        };
        sampler.validate()?;
        self.params.sampler = sampler;
        Ok(())
    }

    /// Sets the cell's number of operators `M` ([`SamplerParams::operators`], issue 44): a
    /// continuous cell of this planner runs `M` tokens ([`Planner::controller`]); the
    /// schedules are unchanged. Stored in the state file. On error the planner is as before.
    ///
    /// # Errors
    /// [`Error::Schedule`] (`BadParam` naming `operators`) unless `1 ≤ M ≤` the robot limit.
    pub fn set_operators(&mut self, operators: usize) -> Result<()> {
        let sampler = SamplerParams {
            operators,
            ..self.params.sampler.clone()
        };
        sampler.validate()?;
        self.params.sampler = sampler;
        Ok(())
    }

    /// Rounds recorded so far (a round is one execution of each of the `N` robots).
    pub fn rounds_recorded(&self) -> usize {
        self.pairs_recorded
    }

    /// [`Planner::rounds_recorded`] under its two-robot name; deprecated.
    #[deprecated(
        since = "0.1.0",
        note = "use `Planner::rounds_recorded` (rounds of N robots)"
    )]
    pub fn pairs_recorded(&self) -> usize {
        self.rounds_recorded()
    }

    /// Saves the planner to `path` as a versioned state file, atomically and under the
    /// file's lock ([`StateLock`], waiting up to [`state::DEFAULT_LOCK_TIMEOUT`]): on error or
    /// a crash the previous file at `path` is intact (see [`crate::state`]). For a whole
    /// read–modify–write (load, record, save) hold the lock throughout and use
    /// [`Planner::save_locked`].
    ///
    /// # Errors
    /// As [`Planner::save_locked`], and [`Error::Locked`] when another writer holds the lock
    /// for longer than the timeout.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        let lock = StateLock::acquire(path.as_ref(), state::DEFAULT_LOCK_TIMEOUT)?;
        self.save_locked(&lock)
    }

    /// Saves the planner to the state file `lock` protects ([`StateLock::state_path`]),
    /// atomically. Refuses to replace a file that is not a state file
    /// ([`state::check_target`]), and, when this planner was loaded from (or last saved to)
    /// that file, a file whose content changed since (another process saved into it: saving
    /// would lose its round).
    ///
    /// # Errors
    /// [`Error::WouldOverwrite`], [`Error::Changed`], [`Error::Io`] naming the file or
    /// directory, [`Error::Encode`].
    pub fn save_locked(&self, lock: &StateLock) -> Result<()> {
        self.save_checked(lock, false).map(|_| ())
    }

    /// [`Planner::save_locked`] that replaces a state file holding rounds this planner does
    /// not hold, discarding them on purpose (`tandem fit --force`, Python
    /// `save(path, force=True)`). Returns how many rounds the replaced file held (0 when there
    /// was none, or when this planner was loaded from that file and holds them all); the
    /// count is `None` when the file there is a state file this build cannot read.
    ///
    /// # Errors
    /// As [`Planner::save_locked`] but [`Error::WouldDiscardRounds`].
    pub fn save_locked_discarding(&self, lock: &StateLock) -> Result<Option<usize>> {
        self.save_checked(lock, true)
    }

    /// The save of [`Planner::save_locked`]; `discard`: replace a file holding rounds this
    /// planner does not hold. Returns the rounds discarded.
    fn save_checked(&self, lock: &StateLock, discard: bool) -> Result<Option<usize>> {
        self.origin.save_guarded(
            lock,
            discard,
            |path| Self::rounds_at(path),
            || state::encode_state(&self.to_state()),
        )
    }

    /// Loads a planner saved by [`Planner::save`], of the current state format or an older one
    /// this build still reads (version 4: a two-robot schedule with one offset, converted to
    /// `offsets_s = [offset_s]`; versions 4 and 5 have no round fingerprints, so the rounds
    /// they hold are not checked for repeats; versions 4 to 6 load with the paper's
    /// confidence model, `ConfidenceParams::paper()` with their own `γ_p`, `σ²_MAX`, `ε`,
    /// `μ_c`, `γ_c`, the model they were decided with; versions 4 to 7 load without hold points;
    /// versions 4 to 8 unsmoothed and 4 to 9 without the fill of flat stretches;
    /// saving writes the current version). Reading
    /// takes no lock (saves are atomic renames); the planner remembers the file's content, so
    /// that saving into it again refuses to overwrite what another process saved meanwhile.
    ///
    /// # Errors
    /// As [`crate::state::load`] (missing, foreign, truncated, corrupt or other-version
    /// file, each naming `path`), or [`Error::Corrupt`] when the parts do not fit together.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = state::read(path)?;
        let st = state::decode_state(&bytes, path)?;
        let planner = Self::from_loaded(st, path)?;
        if let Some(stamp) = state::stamp_of(&bytes) {
            planner.origin.set(state::resolved(path), stamp);
        }
        Ok(planner)
    }

    /// The planner of a state read from `path` (for error messages), its schedule re-checked
    /// ([`Planner::load`] without the file's origin).
    ///
    /// # Errors
    /// As [`Planner::load`].
    pub(crate) fn from_loaded(st: PlannerState, path: &Path) -> Result<Self> {
        let mut planner = Self::from_state(st).map_err(|e| Error::Corrupt {
            path: path.to_path_buf(),
            why: e.to_string(),
        })?;
        planner.recheck_schedule()?;
        Ok(planner)
    }

    /// The rounds recorded in the state file at `path` ([`Planner::rounds_recorded`] of the
    /// planner saved there); 0 when there is no file or an empty one. What a save of another
    /// planner over that file would discard.
    ///
    /// # Errors
    /// As [`Planner::load`] for a file that is there but cannot be read as a state file.
    pub fn rounds_at(path: impl AsRef<Path>) -> Result<usize> {
        let path = path.as_ref();
        let bytes = match std::fs::read(path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(0),
            Err(source) => {
                return Err(Error::Io {
                    path: path.to_path_buf(),
                    op: "read state file",
                    source,
                });
            }
        };
        if bytes.is_empty() {
            return Ok(0);
        }
        Ok(state::decode_any(&bytes, path)?.0.rounds_recorded)
    }

    /// Re-checks the stored schedule on the stored problem with this build's check
    /// ([`Planner::checked_schedule`]: [`tandem_schedule::validate`] with constraint 2 relaxed by the stored
    /// operator parameters); one that fails is never run: it is replaced by a fresh schedule (the
    /// sampler from scratch, at the stored tick when that is a valid tick, with the seed the
    /// next schedule would have had) and [`Planner::load_notice`] says why.
    fn recheck_schedule(&mut self) -> Result<()> {
        // Constraint 2 as the operator's parameters relax it (the idle gaps of a schedule
        // planned with a switch time or a load cap), everything else as `validate`.
        let violation = match self.checked_schedule() {
            Ok(_) => return Ok(()),
            Err(Error::Schedule(tandem_schedule::Error::Invalid(v))) => v,
            Err(e) => return Err(e),
        };
        let tick_s = self.schedule().tick_s;
        let sampler = SamplerParams {
            tick_s: (tick_s.is_finite() && tick_s > 0.0).then_some(tick_s),
            ..Self::sampler_params(&self.params, self.pairs_recorded)
        };
        let outcome = sample_schedule_n(&self.problem, self.n_robots(), &sampler, None)?;
        self.load_notice = Some(format!(
            "the stored schedule fails this build's check ({violation}); it was replaced by a \
             new schedule of {:.2} s (T_total), saved with the next command that writes the \
             state",
            outcome.t_total_s
        ));
        self.outcome = outcome;
        Ok(())
    }

    pub(crate) fn to_state(&self) -> PlannerState {
        PlannerState {
            params: self.params.clone(),
            model: self.model.clone(),
            observations: self.observations.clone(),
            confidence: self.confidence.clone(),
            outcome: self.outcome.clone(),
            rounds_recorded: self.pairs_recorded,
            rounds: self.rounds.clone(),
            reference: self.reference.clone(),
            records: self.records.clone(),
        }
    }

    fn from_state(mut st: PlannerState) -> Result<Self> {
        st.params.validate()?;
        let n_ref = st.model.n_ref();
        let schedule = &st.outcome.schedule;
        schedule.check_shape().map_err(|v| Error::Inconsistent {
            what: "schedule",
            why: v.to_string(),
        })?;
        // `check_shape` bounds the robot count by MAX_ROBOTS, the names' count.
        const WARPS: [&str; tandem_realtime::MAX_ROBOTS] = [
            "schedule robot 1",
            "schedule robot 2",
            "schedule robot 3",
            "schedule robot 4",
            "schedule robot 5",
            "schedule robot 6",
            "schedule robot 7",
            "schedule robot 8",
            "schedule robot 9",
            "schedule robot 10",
            "schedule robot 11",
            "schedule robot 12",
            "schedule robot 13",
            "schedule robot 14",
            "schedule robot 15",
            "schedule robot 16",
        ];
        let warps = WARPS
            .iter()
            .zip(&schedule.grad_exec)
            .map(|(&w, g)| (w, g.len()));
        for (what, n) in [
            ("observations", st.observations.n_ref()),
            ("confidence", st.confidence.n_ref()),
        ]
        .into_iter()
        .chain(warps)
        {
            if n != n_ref {
                return Err(Error::Inconsistent {
                    what,
                    why: format!("{n} reference samples, the model has {n_ref}"),
                });
            }
        }
        if st.rounds.len() > st.rounds_recorded {
            return Err(Error::Inconsistent {
                what: "rounds",
                why: format!(
                    "{} round fingerprints for {} recorded rounds",
                    st.rounds.len(),
                    st.rounds_recorded
                ),
            });
        }
        if st.records.len() > st.rounds_recorded {
            return Err(Error::Inconsistent {
                what: "records",
                why: format!(
                    "{} stored rounds for {} recorded rounds",
                    st.records.len(),
                    st.rounds_recorded
                ),
            });
        }
        if let Some(r) = &st.reference
            && r.n_samples() != n_ref
        {
            return Err(Error::Inconsistent {
                what: "reference",
                why: format!("{} samples, the model has {n_ref}", r.n_samples()),
            });
        }
        // The file holds the latch; `conf` is the latch less the prior's trust that yields to
        // a need on both sides, a function of the model's σ²_D and the observations' totals
        // (`tandem_confidence::Confidence`), so it is evaluated again here, as `record_round`
        // left it.
        st.confidence
            .refresh(st.model.sigma2_d(), &st.observations)?;
        let problem = problem_for(&st.model, &st.confidence, &st.params.holds)?;
        Ok(Self {
            params: st.params,
            model: st.model,
            observations: st.observations,
            confidence: st.confidence,
            problem,
            outcome: st.outcome,
            pairs_recorded: st.rounds_recorded,
            rounds: st.rounds,
            reference: st.reference,
            records: st.records,
            origin: Origin::default(),
            load_notice: None,
        })
    }
}

/// The unit tests' planner (this module's and the cell's): `n` samples of one channel
/// `force`, from three demonstrations aligned by the identity warp that differ only on `lc`
/// (low confidence exactly there), for `robots` robots, 50 samples per schedule from `seed`.
#[cfg(test)]
pub(crate) fn test_planner(
    n: usize,
    lc: std::ops::Range<usize>,
    robots: usize,
    seed: u64,
) -> Planner {
    let names = vec!["force".to_string()];
    let demo = |bump: f64| {
        let x = (0..n)
            .map(|i| if lc.contains(&i) { bump } else { 1.0 })
            .collect();
        Demonstration::new(names.clone(), x, 0.01).unwrap()
    };
    let demos = [demo(1.0), demo(5.0), demo(9.0)];
    let identity: Vec<f64> = (0..n).map(|i| i as f64).collect();
    let model = TaskModel::fit_aligned(
        &demos,
        &[identity.clone(), identity.clone(), identity],
        &FitParams::default(),
    )
    .unwrap();
    let params = PlannerParams {
        sampler: SamplerParams {
            samples: 50,
            seed,
            ..SamplerParams::default()
        },
        ..PlannerParams::default()
    };
    Planner::from_model_with_robots(model, params, robots).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::{CrashPoint, write_atomic_with};
    use tandem_schedule::validate;

    /// An empty folder `<temp>/<name>-<pid>` for one test's files.
    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// A small planner: three 1-channel demonstrations, aligned by the identity warp, whose
    /// force differs only on reference samples 10..20 (low confidence there), two robots.
    fn small_planner(seed: u64) -> Planner {
        test_planner(40, 10..20, 2, seed)
    }

    #[test]
    fn small_planner_has_the_expected_low_confidence_stretch() {
        let p = small_planner(1);
        let conf = p.confidence().conf();
        assert!(conf[..10].iter().all(|c| *c) && conf[20..].iter().all(|c| *c));
        assert!(conf[10..20].iter().all(|c| !*c));
    }

    #[test]
    fn robot_counts_outside_one_to_max_and_rounds_of_another_size_are_refused() {
        let p = small_planner(1);
        assert_eq!(p.n_robots(), 2);
        for n in [0, tandem_realtime::MAX_ROBOTS + 1] {
            let err = Planner::from_model_with_robots(p.model().clone(), p.params().clone(), n)
                .unwrap_err();
            assert!(
                matches!(
                    err,
                    Error::Realtime(tandem_realtime::Error::RobotCount { n: count, max: 16 })
                        if count == n
                ),
                "{err}"
            );
            assert!(err.to_string().contains("1 to 16 robots"), "{err}");
        }
        // The largest count is accepted: 16 robots, 16 warps, and the planner's round
        // checks take 16 executions.
        let big = Planner::from_model_with_robots(
            p.model().clone(),
            p.params().clone(),
            tandem_realtime::MAX_ROBOTS,
        )
        .unwrap();
        assert_eq!(big.n_robots(), 16);
        let dir = scratch("tandem-planner-sixteen");
        let path = dir.join("cell.tandem");
        big.save(&path).unwrap();
        let loaded = Planner::load(&path).unwrap();
        assert_eq!((loaded.n_robots(), loaded.schedule()), (16, big.schedule()));
        std::fs::remove_dir_all(&dir).unwrap();
        let mut q = p.clone();
        let err = q.record_round(&[]).unwrap_err();
        assert!(
            matches!(
                err,
                Error::BadExecution {
                    what: "executions",
                    ..
                }
            ),
            "{err}"
        );
        assert!(
            err.to_string()
                .contains("0 execution records for a round of 2 robots")
        );
        assert_eq!(q.rounds_recorded(), 0);
    }

    #[test]
    fn a_crash_while_saving_keeps_the_previous_state() {
        let dir = scratch("tandem-planner-crash");
        let path = dir.join("cell.tandem");
        let old = small_planner(1);
        old.save(&path).unwrap();
        let newer = small_planner(2);
        let bytes = crate::state::encode_state(&newer.to_state()).unwrap();
        for crash in [CrashPoint::MidWrite, CrashPoint::BeforeRename] {
            let tmp = write_atomic_with(&path, &bytes, crash).unwrap();
            assert!(tmp.exists());
            let loaded = Planner::load(&path).unwrap();
            assert_eq!(loaded.schedule(), old.schedule(), "{crash:?}");
            assert_eq!(loaded.params(), old.params(), "{crash:?}");
        }
        newer.save(&path).unwrap();
        assert_eq!(Planner::load(&path).unwrap().params(), newer.params());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_stored_schedule_that_fails_the_check_is_replaced_on_load_never_run() {
        let dir = scratch("tandem-planner-recheck");
        let path = dir.join("cell.tandem");
        let p = small_planner(1);
        p.save(&path).unwrap();
        let fresh = Planner::load(&path).unwrap();
        assert_eq!(fresh.load_notice(), None);
        assert_eq!(fresh.schedule(), p.schedule());
        // Edit the stored schedule: robot 2 starts so that its low-confidence stretch begins
        // 1 ms after robot 1's ends on schedule. Constraints 1–4 hold; the margin check
        // rejects it (robot 1 may be dragged into robot 2's stretch).
        let mut st = p.to_state();
        let s = &mut st.outcome.schedule;
        let clock = |g: &[f64], n: usize| g[..n].iter().sum::<f64>() * 0.01;
        let lc_end_1 = clock(&s.grad_exec[0], 20);
        let lc_start_2 = clock(&s.grad_exec[1], 10);
        s.offsets_s[0] = lc_end_1 - lc_start_2 + 1e-3;
        let edited = s.clone();
        assert!(matches!(
            validate(p.problem(), &edited),
            Err(tandem_schedule::Violation::InsufficientMargins { .. })
        ));
        crate::state::write_atomic(&path, &crate::state::encode_state(&st).unwrap()).unwrap();
        let loaded = Planner::load(&path).unwrap();
        let notice = loaded.load_notice().expect("a notice");
        assert!(
            notice.contains("fails this build's check") && notice.contains("margin"),
            "{notice}"
        );
        // Replaced, valid, at the stored tick; the coordinator runs the new one.
        assert_ne!(loaded.schedule(), &edited);
        assert!(validate(loaded.problem(), loaded.schedule()).is_ok());
        assert_eq!(loaded.schedule().tick_s, edited.tick_s);
        let c = loaded.coordinator().unwrap();
        assert_eq!(c.robots()[1].start_s(), loaded.schedule().offsets_s[0]);
        // The file is untouched until a command saves.
        assert_eq!(
            Planner::from_state(
                crate::state::decode_state(&std::fs::read(&path).unwrap(), &path).unwrap()
            )
            .unwrap()
            .schedule(),
            &edited
        );
        // And a planner holding a failing schedule (built in memory) gives no coordinator.
        let mut bad = p.clone();
        bad.outcome.schedule = edited;
        assert!(matches!(
            bad.coordinator(),
            Err(Error::Schedule(tandem_schedule::Error::Invalid(_)))
        ));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn inconsistent_parts_are_rejected_on_load() {
        let p = small_planner(1);
        let mut st = p.to_state();
        st.observations = Observations::new(7).unwrap();
        let err = Planner::from_state(st).unwrap_err();
        assert!(
            matches!(
                err,
                Error::Inconsistent {
                    what: "observations",
                    ..
                }
            ),
            "{err}"
        );
    }

    #[test]
    fn reschedule_never_increases_t_total_and_stays_valid() {
        let mut p = small_planner(3);
        let (conf, pairs) = (p.confidence().conf().to_vec(), p.rounds_recorded());
        let mut t_prev = p.outcome().t_total_s;
        for seed in 10..14 {
            let sp = SamplerParams {
                samples: 20,
                seed,
                ..p.params().sampler.clone()
            };
            let t = p.reschedule(&sp).unwrap().t_total_s;
            assert!(t <= t_prev, "seed {seed}: {t} > {t_prev}");
            assert_eq!(t, p.schedule().t_total_s(p.problem().dt_s()));
            tandem_schedule::validate(p.problem(), p.schedule()).unwrap();
            t_prev = t;
        }
        // Only the outcome changes.
        assert_eq!(p.confidence().conf(), &conf[..]);
        assert_eq!(p.rounds_recorded(), pairs);
        // Bad sampler parameters leave the planner as it was.
        let before = p.outcome().clone();
        let bad = SamplerParams {
            p_fastest: 1.5,
            ..SamplerParams::default()
        };
        assert!(p.reschedule(&bad).is_err());
        assert_eq!(p.outcome(), &before);
    }

    /// A round of two replays of the small planner's first demonstration (identity log,
    /// supervised on its low-confidence stretch 10..20, never corrected) whose force is offset by `a` and `b`,
    /// logged `per_sample` times per reference sample at `dt_s`.
    fn round(p: &Planner, a: f64, b: f64, per_sample: usize, dt_s: f64) -> [ExecutionRecord; 2] {
        let n_ref = p.model().n_ref();
        let n = (n_ref - 1) * per_sample + 1;
        let record = |offset: f64| {
            let log: Vec<f64> = (0..n).map(|k| k as f64 / per_sample as f64).collect();
            let force = log
                .iter()
                .map(|&r| {
                    let bump = if (10.0..20.0).contains(&r) { 5.0 } else { 1.0 };
                    bump + offset
                })
                .collect();
            let supervised: Vec<bool> = log.iter().map(|r| (10.0..20.0).contains(r)).collect();
            ExecutionRecord {
                execution: Execution {
                    demonstration: Demonstration::new(vec!["force".into()], force, dt_s).unwrap(),
                    ref_time_log: log,
                },
                corrected: vec![false; n],
                supervised,
            }
        };
        [record(a), record(b)]
    }

    #[test]
    fn holds_are_refused_where_the_operator_corrected_and_kept_inactive_where_untested() {
        let mut p = small_planner(2);
        let spec = |t: f64| HoldSpec {
            at_s: vec![t],
            rules: Vec::new(),
        };
        // Before any round the stretch 0.10–0.20 s is low-confidence for lack of executions
        // only: a hold there is kept, inactive.
        p.set_holds(spec(0.15)).unwrap();
        assert_eq!(p.problem().holds(), &[15]);
        assert_eq!(p.problem().active_holds().count(), 0);
        // Two rounds in which the operator corrects the whole stretch.
        for k in 0..2 {
            let mut r = round(&p, 0.01 * k as f64, 0.02 + 0.01 * k as f64, 1, 0.01);
            for e in &mut r {
                e.corrected = e.supervised.clone();
            }
            p.record_round(&r).unwrap();
        }
        let regions = p.explain_low_confidence().unwrap();
        assert!(
            regions
                .iter()
                .any(|r| r.cause == crate::LowCause::Corrections)
        );
        // The hold declared before stays (never refused after a round), inactive.
        assert_eq!(p.problem().holds(), &[15]);
        assert_eq!(p.problem().active_holds().count(), 0);
        // Declared now, it is refused naming the stretch; the planner is unchanged.
        let before = p.outcome().clone();
        let err = p.set_holds(spec(0.12)).unwrap_err();
        let Error::HoldInLowConfidence {
            at_s,
            start_s,
            end_s,
            ..
        } = err
        else {
            panic!("{err}");
        };
        assert!((at_s - 0.12).abs() < 1e-9 && start_s <= 0.12 && end_s > 0.12);
        let msg = p.set_holds(spec(0.12)).unwrap_err().to_string();
        assert!(
            msg.contains("the hold at 0.12 s") && msg.contains("corrected"),
            "{msg}"
        );
        assert_eq!(p.outcome(), &before);
        assert_eq!(p.params().holds, spec(0.15));
        // Outside the stretch, high-confidence: accepted and active.
        p.set_holds(spec(0.3)).unwrap();
        assert_eq!(p.problem().holds(), &[30]);
        assert_eq!(p.problem().active_holds().collect::<Vec<_>>(), vec![30]);
        // No holds again: the problem without them.
        p.set_holds(HoldSpec::default()).unwrap();
        assert!(p.problem().holds().is_empty());
    }

    #[test]
    fn the_tick_a_user_chose_survives_record_round() {
        let mut p = small_planner(4);
        assert_eq!(p.schedule().tick_s, 0.01);
        let sp = SamplerParams {
            tick_s: Some(0.005),
            ..p.params().sampler.clone()
        };
        p.reschedule(&sp).unwrap();
        assert_eq!(p.schedule().tick_s, 0.005);
        p.record_round(&round(&p, 0.0, 0.1, 1, 0.01)).unwrap();
        assert_eq!(
            p.schedule().tick_s,
            0.005,
            "record_round kept the chosen tick"
        );
        // Without a tick of its own, a re-schedule keeps the current one as well.
        let plain = SamplerParams {
            tick_s: None,
            ..p.params().sampler.clone()
        };
        p.reschedule(&plain).unwrap();
        assert_eq!(p.schedule().tick_s, 0.005);
        assert_eq!(p.coordinator().unwrap().tick_s(), 0.005);
    }

    #[test]
    fn a_round_reports_what_became_of_the_previous_schedule() {
        // Replays at the demonstrated speed: the mean gradient stays 1, confidence only grows,
        // so the schedule the round ran stays valid and bounds the new one.
        let mut p = small_planner(5);
        for k in 0..4 {
            let before = p.outcome().t_total_s;
            let dt = p.model().dt_s();
            let r = round(&p, 0.01 * k as f64, 0.02 + 0.01 * k as f64, 1, dt);
            let report = p.record_round(&r).unwrap();
            assert_eq!(report.previous_t_total_s, before);
            match &report.previous {
                PreviousFate::Valid { t_total_s } => {
                    assert_eq!(*t_total_s, before);
                    assert!(report.t_total_s <= before, "round {k}");
                }
                PreviousFate::Repaired { t_total_s, .. } => {
                    assert!(report.t_total_s <= *t_total_s, "round {k}");
                }
                other => panic!("round {k}: {other:?}"),
            }
            assert!(report.previous.describe().is_some());
            assert_eq!(report.previous, p.outcome().previous);
        }
        // A reloaded outcome knows nothing of a previous schedule.
        let dir = scratch("previous-fate");
        let path = dir.join("s.tandem");
        p.save(&path).unwrap();
        let loaded = Planner::load(&path).unwrap();
        assert_eq!(loaded.outcome().previous, PreviousFate::NotGiven);
        assert_eq!(loaded.outcome().margin_free_s, None);
        assert_eq!(loaded.outcome().t_total_s, p.outcome().t_total_s);
    }

    #[test]
    fn the_same_round_recorded_twice_is_refused() {
        let mut p = small_planner(5);
        let first = round(&p, 0.0, 0.1, 1, 0.01);
        p.record_round(&first).unwrap();
        let before = (p.rounds_recorded(), p.model().count(), p.outcome().clone());
        let swapped = [first[1].clone(), first[0].clone()];
        for again in [first.clone(), swapped] {
            let err = p.record_round(&again).unwrap_err();
            assert!(matches!(err, Error::DuplicateRound { round: 1 }), "{err}");
            assert!(
                err.to_string().contains("already recorded as round 1"),
                "{err}"
            );
            assert_eq!(
                (p.rounds_recorded(), p.model().count(), p.outcome().clone()),
                before
            );
        }
        // Another round records; the fingerprints survive a save and a load.
        p.record_round(&round(&p, 0.2, 0.3, 1, 0.01)).unwrap();
        let dir = scratch("tandem-planner-dup");
        let path = dir.join("cell.tandem");
        p.save(&path).unwrap();
        let mut q = Planner::load(&path).unwrap();
        assert!(matches!(
            q.record_round(&first),
            Err(Error::DuplicateRound { round: 1 })
        ));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_execution_logged_at_1_khz_is_resampled_to_the_model_period() {
        let base = small_planner(6);
        let mut at_100hz = base.clone();
        let mut at_1khz = base.clone();
        let r100 = at_100hz
            .record_round(&round(&base, 0.0, 0.5, 1, 0.01))
            .unwrap();
        assert!(r100.notices.is_empty());
        let r1k = at_1khz
            .record_round(&round(&base, 0.0, 0.5, 10, 0.001))
            .unwrap();
        assert_eq!(r1k.notices.len(), 2);
        assert!(
            r1k.notices[0].contains(
                "logged 0.001 s apart, resampled to the model's 0.01 s (391 → 40 samples)"
            ),
            "{}",
            r1k.notices[0]
        );
        // The same model and observations as the same executions logged at 100 Hz: the mean
        // execution does not grow tenfold.
        let (a, b) = (at_100hz.model(), at_1khz.model());
        for (x, y) in a.grad_mean().iter().zip(b.grad_mean()) {
            assert!((x - y).abs() < 1e-9, "{x} vs {y}");
        }
        for (x, y) in a.mean().iter().zip(b.mean()) {
            assert!((x - y).abs() < 1e-9, "{x} vs {y}");
        }
        let (oa, ob) = (at_100hz.observations(), at_1khz.observations());
        assert!((oa.total_supervised() - ob.total_supervised()).abs() < 1e-9);
        // Given as 10 ms samples, the 1 kHz log lasts ten times too long: refused, naming
        // the fix, and the planner is unchanged.
        let mut wrong = base.clone();
        let err = wrong
            .record_round(&round(&base, 0.0, 0.5, 10, 0.01))
            .unwrap_err();
        assert!(err.to_string().contains("give its sample period"), "{err}");
        assert_eq!(wrong.rounds_recorded(), 0);
    }

    #[test]
    fn an_execution_logged_with_jitter_and_a_dropped_row_is_regridded_then_recorded() {
        // 250 Hz rows (t = 0.004·k ± 0.8 ms, row 50 dropped) over the 0.39 s task at the
        // demonstrated speed: reference time = 100·t (clamped to the last sample, 39).
        let base = small_planner(8);
        let mut text = String::from("t,force\n");
        let (mut log, mut sup, mut cor) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..=98usize {
            if k == 50 {
                continue;
            }
            // A fixed pseudo-random jitter in ±0.8 ms (splitmix64's finalizer of k).
            let mut h = (k as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
            h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            h ^= h >> 31;
            let jitter = if k == 0 || k == 98 {
                0.0
            } else {
                0.0016 * ((h % 1001) as f64 / 1000.0 - 0.5)
            };
            let t = 0.004 * k as f64 + jitter;
            let r = (100.0 * t).min(39.0);
            let force = if (10.0..20.0).contains(&r) { 5.0 } else { 1.0 };
            text.push_str(&format!("{t},{force}\n"));
            log.push(r);
            sup.push((10.0..20.0).contains(&r));
            // One correction, on a single 250 Hz row mid-region.
            cor.push(k == 37);
        }
        // Without resampling the dropped row is refused with the fix.
        let e = Demonstration::from_csv_str(&text, "j.csv", None).unwrap_err();
        assert!(e.to_string().contains("resample"), "{e}");
        let grid = Demonstration::regrid_csv_str(&text, "j.csv", None).unwrap();
        assert_eq!(grid.demonstration.dt_s(), 0.004, "the logger's 250 Hz");
        assert_eq!(grid.demonstration.n_samples(), 99);
        let short = ExecutionRecord::from_regridded(grid.clone(), &log[1..], &sup, &cor);
        assert!(
            matches!(
                short,
                Err(Error::BadExecution {
                    what: "ref_time_log",
                    ..
                })
            ),
            "{short:?}"
        );
        let record = ExecutionRecord::from_regridded(grid, &log, &sup, &cor).unwrap();
        assert_eq!(record.corrected.iter().filter(|&&c| c).count(), 1);
        assert!(
            record
                .supervised
                .iter()
                .zip(&record.corrected)
                .all(|(s, c)| *s || !*c)
        );
        let log = &record.execution.ref_time_log;
        assert!(log.windows(2).all(|w| w[1] >= w[0]) && log[log.len() - 1] == 39.0);
        // Taken in like any finer log: resampled to the model's 10 ms, the correction kept.
        let (at_model, note) = base.check_execution(&record).unwrap();
        assert_eq!(at_model.execution.demonstration.n_samples(), 41);
        assert!(
            note.unwrap()
                .contains("logged 0.004 s apart, resampled to the model's 0.01 s (99 → 41")
        );
        assert_eq!(at_model.corrected.iter().filter(|&&c| c).count(), 1);
        let mut p = base.clone();
        p.record_round(&[record.clone(), record]).unwrap();
        assert_eq!(p.rounds_recorded(), 1);
        assert!(p.observations().total_corrections() > 0.0);
    }

    #[test]
    fn a_save_refuses_to_overwrite_what_another_process_saved_since_the_load() {
        let dir = scratch("tandem-planner-cas");
        let path = dir.join("cell.tandem");
        small_planner(7).save(&path).unwrap();
        let mut mine = Planner::load(&path).unwrap();
        let mut theirs = Planner::load(&path).unwrap();
        theirs
            .record_round(&round(&theirs, 0.0, 0.1, 1, 0.01))
            .unwrap();
        theirs.save(&path).unwrap();
        let after_theirs = std::fs::read(&path).unwrap();
        mine.record_round(&round(&mine, 0.4, 0.5, 1, 0.01)).unwrap();
        let err = mine.save(&path).unwrap_err();
        assert!(matches!(err, Error::Changed { .. }), "{err}");
        assert!(err.to_string().contains("load it again"), "{err}");
        assert_eq!(
            std::fs::read(&path).unwrap(),
            after_theirs,
            "their round is kept"
        );
        // Saved elsewhere it goes through; a planner that saved keeps saving into its file.
        mine.save(dir.join("mine.tandem")).unwrap();
        theirs
            .record_round(&round(&theirs, 0.6, 0.7, 1, 0.01))
            .unwrap();
        theirs.save(&path).unwrap();
        assert_eq!(Planner::load(&path).unwrap().rounds_recorded(), 2);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn two_concurrent_writers_lose_no_round() {
        let dir = scratch("tandem-planner-two");
        let path = dir.join("cell.tandem");
        let start = small_planner(8);
        start.save(&path).unwrap();
        const ROUNDS: usize = 50;
        let writer = |w: usize| {
            let path = path.clone();
            std::thread::spawn(move || {
                for k in 0..ROUNDS {
                    let lock = StateLock::acquire(&path, state::DEFAULT_LOCK_TIMEOUT).unwrap();
                    let mut p = Planner::load(&path).unwrap();
                    let offset = (w * ROUNDS + k) as f64 * 1e-3;
                    p.record_round(&round(&p, offset, offset + 0.5, 1, 0.01))
                        .unwrap();
                    p.save_locked(&lock).unwrap();
                }
            })
        };
        let (a, b) = (writer(0), writer(1));
        a.join().unwrap();
        b.join().unwrap();
        let p = Planner::load(&path).unwrap();
        assert_eq!(p.rounds_recorded(), 2 * ROUNDS);
        assert_eq!(p.model().count(), 3 + 4 * ROUNDS);
        // Every round is in the file: its fingerprint, computed from the same inputs.
        let mut want: Vec<u64> = (0..2 * ROUNDS)
            .map(|i| {
                let offset = i as f64 * 1e-3;
                let r = round(&start, offset, offset + 0.5, 1, 0.01);
                let checked: Vec<ExecutionRecord> = r
                    .iter()
                    .map(|e| start.check_execution(e).unwrap().0)
                    .collect();
                round_fingerprint(&checked)
            })
            .collect();
        let mut got = p.rounds.clone();
        want.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, want);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_correction_of_an_unsupervised_sample_is_refused_naming_it() {
        let mut p = small_planner(8);
        let mut r = round(&p, 0.0, 0.1, 1, 0.01);
        // Sample 25 ran unsupervised (high-confidence) and is flagged corrected.
        r[1].corrected[25] = true;
        let before = (p.rounds_recorded(), p.observations().clone());
        let err = p.record_round(&r).unwrap_err();
        assert!(
            matches!(
                err,
                Error::BadExecution {
                    what: "corrected",
                    ..
                }
            ),
            "{err:?}"
        );
        let msg = err.to_string();
        assert!(
            msg.contains("sample 25: `corrected` is 1 but `supervised` is 0")
                && msg.contains("only a supervised, low-confidence sample can be corrected"),
            "{msg}"
        );
        assert_eq!((p.rounds_recorded(), p.observations().clone()), before);
        // The same on the rows of a log put on a grid (before the flags are merged, which
        // would otherwise make the row supervised).
        let text = "t,force\n0.0,1\n0.01,1\n0.02,1\n";
        let grid = Demonstration::regrid_csv_str(text, "exec.csv", None).unwrap();
        let err = ExecutionRecord::from_regridded(
            grid,
            &[0.0, 1.0, 2.0],
            &[true, false, true],
            &[false, true, false],
        )
        .unwrap_err();
        assert!(
            err.to_string()
                .contains("exec.csv: row 1: `corrected` is 1 but `supervised` is 0"),
            "{err}"
        );
    }

    #[test]
    fn reschedule_seeds_depend_on_the_pair_count_only() {
        let params = PlannerParams::default();
        let s0 = Planner::sampler_params(&params, 0).seed;
        let s1 = Planner::sampler_params(&params, 1).seed;
        assert_ne!(s0, s1);
        assert_eq!(s1, Planner::sampler_params(&params, 1).seed);
    }

    /// The `operators` parameter end to end in the planner (issue 44): a continuous cell gets
    /// `M` tokens and takes `M` inputs; one operator is the coordinator of before; rounds with
    /// more than one run the sectored round; an out-of-range count is refused and leaves the
    /// planner as it was.
    #[test]
    fn the_operator_count_makes_the_continuous_cell_and_the_sectored_round() {
        use tandem_realtime::{Controller, Operator};
        let mut p = test_planner(40, 10..20, 3, 1);
        let one = p.controller(crate::Cell::Continuous).unwrap();
        let crate::AnyController::Continuous(one) = one else {
            panic!("a continuous cell")
        };
        assert_eq!(one.operators(), 1);
        p.set_operators(2).unwrap();
        assert_eq!(p.params().sampler.operators, 2);
        let crate::AnyController::Continuous(mut two) =
            p.controller(crate::Cell::Continuous).unwrap()
        else {
            panic!("a continuous cell")
        };
        assert_eq!(Controller::operators(&two), 2);
        assert!(two.tick(Operator::Scheduled).is_err());
        two.tick_many(&[Operator::Scheduled; 2]).unwrap();
        // Rounds with two operators: the sectored round (issue 44), run to its end with two
        // inputs, never two robots of one sector low-confidence, each under its sector's
        // operator, no fault.
        let (sectors, _) = p.sectored_rounds().unwrap();
        assert!(sectors.t_total_s >= sectors.lower_bound_s * (1.0 - 1e-9));
        let crate::AnyController::Rounds(mut r) = p.controller(crate::Cell::Rounds).unwrap() else {
            panic!("rounds")
        };
        assert_eq!(Controller::operators(&r), 2);
        assert!(Controller::tick(&mut r, Operator::Scheduled).is_err());
        let sector_of = sectors.sector_of();
        assert_eq!(sector_of.len(), 3);
        let mut lc_ticks = 0;
        for _ in 0..100_000 {
            if Controller::is_finished(&r) {
                break;
            }
            let t = Controller::tick_many(&mut r, &[Operator::Fastest, Operator::Slowest]).unwrap();
            assert!(t.fault.is_none());
            for (i, &o) in sector_of.iter().enumerate() {
                if t.low_conf[i] {
                    lc_ticks += 1;
                    assert_eq!(t.operator[i], Some(o as u8));
                }
            }
        }
        assert!(Controller::is_finished(&r) && lc_ticks > 0);
        for bad in [0, tandem_realtime::MAX_ROBOTS + 1] {
            let err = p.set_operators(bad).unwrap_err().to_string();
            assert!(err.contains("operators"), "{err}");
            assert_eq!(p.params().sampler.operators, 2);
        }
    }

    /// The continuous cell of `M > 1` operators is picked by measurement (issue 44):
    /// `FleetCell::Auto` runs the even sectors exactly when they measure strictly faster than
    /// the pooled cell with the planned operator (both rates reported), `Pooled` and
    /// `Sectored` force the cell; a sectored coordinator's robots run under their contiguous
    /// sector's operator only; one operator has no pick; the sectors' ceiling never exceeds
    /// the pooled one's.
    #[test]
    fn the_continuous_cell_of_m_operators_is_picked_by_measurement() {
        use crate::FleetCell;
        use tandem_realtime::{Controller, Operator};
        let p1 = test_planner(40, 10..20, 4, 1);
        let crate::Plan::Continuous(plan) = p1.plan(crate::Cell::Continuous).unwrap() else {
            panic!("a continuous plan")
        };
        assert!(
            p1.fleet_coordinator(&plan, FleetCell::Auto)
                .unwrap()
                .1
                .is_none()
        );
        for (n, m) in [(4, 2), (3, 2), (4, 4)] {
            let mut p = test_planner(40, 10..20, n, 1);
            p.set_operators(m).unwrap();
            let choice = p.fleet_cell().unwrap();
            assert!(
                choice.sectored_bound_tasks_per_hour
                    <= choice.pooled_bound_tasks_per_hour * (1.0 + 1e-9)
            );
            let crate::Plan::Continuous(plan) = p.plan(crate::Cell::Continuous).unwrap() else {
                panic!("a continuous plan")
            };
            let (pooled, pick) = p.fleet_coordinator(&plan, FleetCell::Pooled).unwrap();
            let pick = pick.unwrap();
            assert!(pooled.sector_of().is_none() && pick.cell == FleetCell::Pooled);
            assert_eq!(pick.pooled_tasks_per_hour, None);
            let want: Vec<u8> = pick
                .sectors
                .iter()
                .enumerate()
                .flat_map(|(o, &k)| std::iter::repeat_n(o as u8, k))
                .collect();
            let (forced, _) = p.fleet_coordinator(&plan, FleetCell::Sectored).unwrap();
            assert_eq!(&forced.sector_of().unwrap()[..], &want[..], "({n}, {m})");
            let (mut c, pick) = p.fleet_coordinator(&plan, FleetCell::Auto).unwrap();
            let pick = pick.unwrap();
            let (pr, sr) = (
                pick.pooled_tasks_per_hour.unwrap(),
                pick.sectored_tasks_per_hour.unwrap(),
            );
            assert!(pr > 0.0 && sr > 0.0, "({n}, {m}): {pick:?}");
            assert_eq!(
                pick.cell == FleetCell::Sectored,
                sr > pr,
                "({n}, {m}): {pick:?}"
            );
            assert_eq!(c.sector_of().is_some(), sr > pr, "({n}, {m})");
            // The controller runs the same pick.
            let crate::AnyController::Continuous(k) =
                p.controller(crate::Cell::Continuous).unwrap()
            else {
                panic!("a continuous cell")
            };
            assert_eq!(k.sector_of(), c.sector_of());
            assert_eq!(Controller::operators(&c), m);
            let sector_of = forced.sector_of().unwrap();
            c = forced;
            let inputs: Vec<Operator> = (0..m)
                .map(|o| [Operator::Fastest, Operator::Slowest][o % 2])
                .collect();
            let mut lc_ticks = 0;
            for _ in 0..20_000 {
                let t = c.tick_many(&inputs).unwrap();
                assert!(t.fault.is_none() && !t.over(m));
                for (i, &o) in sector_of.iter().enumerate() {
                    if t.low_conf[i] {
                        lc_ticks += 1;
                        assert_eq!(t.operator[i], Some(o));
                    }
                }
            }
            assert!(lc_ticks > 0 && c.tasks_completed().iter().all(|&k| k > 0));
        }
    }

    /// The sectored round (issue 44) of (N, M) = (4, 2) and (3, 2) on a small problem: even
    /// sectors ([2, 2], [2, 1]), each sector's schedule of its own size passes the one-operator
    /// check (Eq. 20 with Alg. 2's margin check) on the planner's problem, the round's
    /// `T_total` is the slower sector's own `T_total` (Eq. 13 of its schedule), the sectored
    /// coordinator's robots are those schedules' (its latest robot ends at `T_total`), and the
    /// round lies between the fleet bound and one operator's N-robot round.
    #[test]
    fn sectored_rounds_take_the_slower_sectors_t_total() {
        use tandem_realtime::Timeline;
        for (n, sizes) in [(4, vec![2, 2]), (3, vec![2, 1])] {
            let mut p = test_planner(60, 20..30, n, 1);
            p.set_operators(2).unwrap();
            let (s, coord) = p.sectored_rounds().unwrap();
            assert_eq!(s.sizes, sizes, "N = {n}");
            let free = p.problem();
            let own: Vec<f64> = s
                .schedules
                .iter()
                .zip(&sizes)
                .map(|(sch, &k)| {
                    assert_eq!(sch.n_robots(), k);
                    let sp = &p.params().sampler;
                    sch.check_with_operator(free, sp.switch_s, sp.max_busy_share)
                        .unwrap();
                    sch.t_total_s(free.dt_s())
                })
                .collect();
            let slower = own.iter().copied().fold(0.0, f64::max);
            assert!(
                (s.t_total_s - slower).abs() < 1e-9,
                "{} {own:?}",
                s.t_total_s
            );
            if n == 3 {
                // The sector of two robots is the slower one: a second robot's stretch waits.
                assert!(own[0] > own[1], "{own:?}");
            }
            assert_eq!(coord.operators(), 2);
            assert_eq!(coord.n_robots(), n);
            let end = coord
                .robots()
                .iter()
                .map(Timeline::end_s)
                .fold(0.0, f64::max);
            assert!((end - s.t_total_s).abs() < 1e-9, "{end} {}", s.t_total_s);
            let bound = tandem_schedule::fleet_operator_bound_s(p.problem(), n, 2).unwrap();
            assert_eq!(s.lower_bound_s, bound);
            assert!(bound <= s.t_total_s + 1e-9);
            assert!(
                s.t_total_s < p.outcome().t_total_s,
                "sectors beat one operator here"
            );
        }
    }
}
