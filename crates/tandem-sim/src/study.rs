//! The simulated study of §III (Fig. 5): configuration, per-iteration records, summaries.
//!
//! A trial starts from the demonstrations, schedules, runs a pair of executions in the
//! simulated workcell, records them (Eq. 21), re-schedules, and so on for
//! `executions / 2` pairs. Iteration `k` is the schedule made after `k` recorded pairs
//! (iteration 0: demonstrations only) together with the outcome of running the next pair
//! under it (none for the last iteration).

use std::fmt::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use tandem_lfd::{Demonstration, TaskModel};
use tandem_planner::{Planner, PlannerParams, derive_seed};
use tandem_schedule::{GlobalTimeline, Source};

use tandem_confidence::ErrorRates;

use crate::task::{self, Label, TaskParams, Workpiece};
use crate::truth::{OperatorTally, falsely_trusted};
use crate::workcell::{self, OperatorParams};
use crate::{Error, Result};

/// Study configuration (`fixtures/study.toml`, §III).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StudyConfig {
    /// Independent trials (paper: 5). Default: 5.
    pub trials: usize,
    /// Executions per trial, run in rounds of [`StudyConfig::robots`] (one execution per
    /// robot), so a positive multiple of `robots` (paper: 300, in pairs). Default: 300.
    pub executions: usize,
    /// Robots `N` run by the one operator, `1 ≤ N ≤` [`tandem_realtime::MAX_ROBOTS`]
    /// (paper: 2). Default: 2.
    pub robots: usize,
    /// Sampler iterations per re-schedule (paper: 5000). Default: 5000.
    pub samples: usize,
    /// Master seed; trial `k` is seeded from `(seed, k)` only. Default: 2023.
    pub seed: u64,
    /// Probability that the simulated operator misses a needed correction (§III: 1 %).
    /// Default: 0.01.
    pub miss_rate: f64,
    /// Probability that the operator corrects a sample that needs none (§III: 1 %).
    /// Default: 0.01.
    pub false_correction_rate: f64,
    /// Mean duration (s) of one unneeded correction episode (see
    /// [`OperatorParams::false_correction_s`]). Default: 0.5 s.
    pub false_correction_s: f64,
    /// Iterations whose schedules Fig. 5 draws as examples (trial 0). Default: 0, 25, 50, 100, 150.
    pub example_iterations: Vec<usize>,
    /// Model, confidence and sampler parameters. The sampler's `samples` and `seed` are
    /// replaced by [`StudyConfig::samples`] and the trial's seed. Default: `PlannerParams::default()`.
    pub planner: PlannerParams,
    /// Task parameters for drawing each execution's workpiece (only `n_sections` matters);
    /// must match the demonstrations'. Default: `TaskParams::default()` (the fixtures').
    pub task: TaskParams,
}

impl Default for StudyConfig {
    fn default() -> Self {
        Self {
            trials: 5,
            executions: 300,
            robots: 2,
            samples: 5000,
            seed: 2023,
            miss_rate: 0.01,
            false_correction_rate: 0.01,
            false_correction_s: 0.5,
            example_iterations: vec![0, 25, 50, 100, 150],
            planner: PlannerParams::default(),
            task: TaskParams::default(),
        }
    }
}

impl StudyConfig {
    /// Number of rounds per trial (`executions / robots`; pairs for two robots).
    pub fn n_rounds(&self) -> usize {
        self.executions / self.robots.max(1)
    }

    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the first invalid field.
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &'static str, why: &'static str| Err(Error::BadParam { name, why });
        if self.trials == 0 {
            return bad("trials", "must be at least 1");
        }
        if !(1..=tandem_realtime::MAX_ROBOTS).contains(&self.robots) {
            return bad(
                "robots",
                "must be between 1 and 8 (tandem_realtime::MAX_ROBOTS)",
            );
        }
        if self.executions == 0 || self.executions % self.robots != 0 {
            return bad(
                "executions",
                if self.robots == 2 {
                    "must be a positive even number (executions run in pairs)"
                } else {
                    "must be a positive multiple of `robots` (executions run in rounds of one \
                     execution per robot)"
                },
            );
        }
        if self.samples == 0 {
            return bad("samples", "must be at least 1");
        }
        for (name, p) in [
            ("miss_rate", self.miss_rate),
            ("false_correction_rate", self.false_correction_rate),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return bad(name, "must be a probability in [0, 1]");
            }
        }
        if self.false_correction_rate >= 1.0 {
            return bad("false_correction_rate", "must be below 1");
        }
        if !(self.false_correction_s.is_finite() && self.false_correction_s >= 0.0) {
            return bad("false_correction_s", "must be finite and ≥ 0");
        }
        self.planner.validate()?;
        self.task.validate()?;
        Ok(())
    }

    /// The operator of the workcell.
    pub fn operator(&self) -> OperatorParams {
        OperatorParams {
            miss_rate: self.miss_rate,
            false_correction_rate: self.false_correction_rate,
            false_correction_s: self.false_correction_s,
            ..OperatorParams::default()
        }
    }
}

/// What happened when a pair of executions ran under one schedule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairStats {
    /// Control ticks in which both robots traversed a low-confidence sample (must be 0).
    pub overlap_ticks: usize,
    /// Share of the pair's duration (ticks) in which no robot was low-confidence, in [0, 1].
    pub operator_idle_share: f64,
    /// Actual duration of the pair (s, global time), from the start until both finished.
    pub duration_s: f64,
    /// Ticks in which a robot was low-confidence (supervised), both robots together.
    pub supervised_ticks: usize,
    /// Supervised ticks in which the operator corrected, both robots together.
    pub corrected_ticks: usize,
    /// Operator busy share, in [0, 1]: the share of the round's control ticks (from the
    /// first robot's start until the last robot finished) in which at least one robot
    /// traversed a low-confidence sample, so that the operator was needed
    /// (`1 − operator_idle_share`; docs/study.md).
    pub operator_busy_share: f64,
}

/// One iteration of a trial: a schedule and what running it gave.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IterationRecord {
    /// Pairs recorded before this schedule was made (0 = demonstrations only).
    pub iteration: usize,
    /// Planned `T_total` (Eq. 13, s).
    pub t_total_s: f64,
    /// Planned offset `τ` of robot 2 (s, global time; 0 for a single robot).
    pub offset_s: f64,
    /// Share of reference samples that are high-confidence (Eq. 12), in percent.
    pub high_conf_pct: f64,
    /// Where the schedule came from.
    pub source: ScheduleSource,
    /// Planned low-confidence intervals `[start_s, end_s)` of each robot, robot 1 first
    /// (global time, s).
    pub lc_intervals_s: Vec<Vec<[f64; 2]>>,
    /// The outcome of running the next pair under this schedule (`None` for the last one).
    pub pair: Option<PairStats>,
    /// The schedule's certificate ([`tandem_schedule::Outcome::lower_bound_s`]): a lower
    /// bound (s, global time) on the `T_total` of every schedule of Eq. 20 for this
    /// iteration's problem, the margin-free optimum `T*₀` when
    /// [`IterationRecord::bound_is_optimum`].
    pub lower_bound_s: f64,
    /// Whether [`IterationRecord::lower_bound_s`] is the proven margin-free optimum `T*₀`.
    pub bound_is_optimum: bool,
    /// `(T_total − lower_bound_s) / lower_bound_s` (dimensionless, ≥ 0).
    pub gap: f64,
    /// Planned throughput: tasks per hour per operator, `N·3600 / T_total` (`N` robots each
    /// finish one task per `T_total` seconds of the schedule).
    pub throughput_per_h: f64,
    /// Planned start offsets `τ_2, …, τ_N` of robots 2..N (s, global time; `N − 1` values,
    /// `[offset_s]` for two robots).
    pub offsets_s: Vec<f64>,
    /// Reference samples that truly need help ([`crate::truth::needs_help`]) but are
    /// high-confidence in this iteration's confidence: sanded unsupervised.
    #[serde(default)]
    pub falsely_trusted_samples: usize,
    /// Low-confidence runs of each robot's schedule, robot 1 first (the lengths of
    /// [`IterationRecord::lc_intervals_s`]).
    #[serde(default)]
    pub lc_runs: Vec<usize>,
    /// The operator's error rates this iteration's confidence was decided with (estimated
    /// from the rounds recorded so far, or the configured ones; per control sample).
    #[serde(default)]
    pub error_rates: ErrorRates,
    /// The simulated operator's actual rates over the rounds recorded so far
    /// ([`OperatorTally::rates`]); `None` before any round.
    #[serde(default)]
    pub simulated_rates: Option<ErrorRates>,
}

/// Where a study iteration's schedule came from: the kind of [`tandem_schedule::Source`]
/// without the candidate index, under the name the study's JSON and CSV give it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ScheduleSource {
    /// A candidate of the anytime sampler (`Source::Sampled`): `sampled`.
    Sampled,
    /// The margin-aware completion of the exact margin-free optimum (`Source::Completed`):
    /// `completed`.
    Completed,
    /// The previous schedule, unchanged (`Source::Previous`): `previous`.
    Previous,
    /// The previous schedule re-projected onto the new problem (`Source::RepairedPrevious`):
    /// `repaired`.
    Repaired,
    /// The fastest serial schedule (`Source::Serial`): `serial`.
    Serial,
}

impl ScheduleSource {
    /// The name in the study's JSON and CSV.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sampled => "sampled",
            Self::Completed => "completed",
            Self::Previous => "previous",
            Self::Repaired => "repaired",
            Self::Serial => "serial",
        }
    }
}

impl From<Source> for ScheduleSource {
    fn from(source: Source) -> Self {
        match source {
            Source::Sampled { .. } => Self::Sampled,
            Source::Completed => Self::Completed,
            Source::Previous => Self::Previous,
            Source::RepairedPrevious => Self::Repaired,
            Source::Serial => Self::Serial,
        }
    }
}

impl std::fmt::Display for ScheduleSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One trial: its seed and every iteration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrialResult {
    /// Trial index `k`.
    pub trial: usize,
    /// Seed of the trial, derived from `(seed, k)` by [`trial_seed`].
    pub seed: u64,
    /// Iterations `0..=n_pairs`.
    pub iterations: Vec<IterationRecord>,
}

/// The whole study: everything the JSON output holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyResult {
    /// The configuration it ran with.
    pub config: StudyConfig,
    /// Reference samples of the task (`T_ref`).
    pub n_ref: usize,
    /// Reference sample period `Δt_s` (s).
    pub dt_s: f64,
    /// Ground truth (§III): percent of reference samples outside the sanding of passes 1–3.
    pub ground_truth_pct: f64,
    /// The trials, in trial order.
    pub trials: Vec<TrialResult>,
}

/// Per-iteration statistics across trials.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct IterationSummary {
    /// Iteration index (pairs recorded).
    pub iteration: usize,
    /// Mean planned `T_total` across trials (s).
    pub t_total_mean_s: f64,
    /// Sample standard deviation of `T_total` across trials (s); 0 for a single trial.
    pub t_total_std_s: f64,
    /// Mean percent of high-confidence reference samples across trials.
    pub high_conf_pct_mean: f64,
    /// Sample standard deviation of that percent across trials (percentage points).
    pub high_conf_pct_std: f64,
    /// Overlap ticks summed across trials (must be 0).
    pub overlap_ticks: usize,
    /// Mean certificate lower bound `T*₀` across trials (s; [`IterationRecord::lower_bound_s`]).
    pub lower_bound_mean_s: f64,
    /// Share of trials, in [0, 1], whose lower bound is the proven margin-free optimum.
    pub bound_proven_share: f64,
    /// Mean relative gap of `T_total` to the lower bound across trials (dimensionless).
    pub gap_mean: f64,
    /// Mean planned throughput across trials (tasks per hour per operator,
    /// [`IterationRecord::throughput_per_h`]).
    pub throughput_mean_per_h: f64,
    /// Mean operator busy share across trials of the round run under this iteration's
    /// schedule ([`PairStats::operator_busy_share`], in [0, 1]); `None` for the last
    /// iteration, after which no round runs.
    pub operator_busy_share_mean: Option<f64>,
}

/// Seed of trial `trial` from the master `seed` ([`derive_seed`]), so trials are
/// independent of each other and of the order in which threads run them.
pub fn trial_seed(seed: u64, trial: usize) -> u64 {
    derive_seed(seed, trial as u64)
}

impl StudyResult {
    /// Mean and standard deviation of each iteration across trials (Fig. 5 top and bottom).
    pub fn summary(&self) -> Vec<IterationSummary> {
        let n_iter = self
            .trials
            .iter()
            .map(|t| t.iterations.len())
            .min()
            .unwrap_or(0);
        (0..n_iter)
            .map(|k| {
                let recs: Vec<&IterationRecord> =
                    self.trials.iter().map(|t| &t.iterations[k]).collect();
                let (mean, std) = mean_std(recs.iter().map(|r| r.t_total_s));
                let (hc, hc_std) = mean_std(recs.iter().map(|r| r.high_conf_pct));
                IterationSummary {
                    iteration: recs[0].iteration,
                    t_total_mean_s: mean,
                    t_total_std_s: std,
                    high_conf_pct_mean: hc,
                    high_conf_pct_std: hc_std,
                    overlap_ticks: recs
                        .iter()
                        .filter_map(|r| r.pair.as_ref())
                        .map(|p| p.overlap_ticks)
                        .sum(),
                    lower_bound_mean_s: mean_std(recs.iter().map(|r| r.lower_bound_s)).0,
                    bound_proven_share: recs.iter().filter(|r| r.bound_is_optimum).count() as f64
                        / recs.len() as f64,
                    gap_mean: mean_std(recs.iter().map(|r| r.gap)).0,
                    throughput_mean_per_h: mean_std(recs.iter().map(|r| r.throughput_per_h)).0,
                    operator_busy_share_mean: {
                        let busy: Vec<f64> = recs
                            .iter()
                            .filter_map(|r| r.pair.as_ref())
                            .map(|p| p.operator_busy_share)
                            .collect();
                        (!busy.is_empty()).then(|| mean_std(busy.into_iter()).0)
                    },
                }
            })
            .collect()
    }

    /// Total overlap ticks over every pair of every trial (must be 0).
    pub fn total_overlap_ticks(&self) -> usize {
        self.trials
            .iter()
            .flat_map(|t| &t.iterations)
            .filter_map(|r| r.pair.as_ref())
            .map(|p| p.overlap_ticks)
            .sum()
    }

    /// One CSV row per trial and iteration. Columns: `trial, iteration, t_total_s, offset_s,
    /// high_conf_pct, source, overlap_ticks, operator_idle_share, duration_s, supervised_ticks,
    /// corrected_ticks, operator_busy_share, lower_bound_s, bound_is_optimum, gap,
    /// throughput_per_h`, then one `lc_intervals_robot<i>_s` column per robot; round columns
    /// (`overlap_ticks` to `operator_busy_share`) are empty for the last iteration;
    /// intervals are `start-end` pairs (s) joined by `;`.
    pub fn to_csv(&self) -> String {
        let n_robots = self
            .trials
            .iter()
            .flat_map(|t| &t.iterations)
            .map(|r| r.lc_intervals_s.len())
            .max()
            .unwrap_or(0);
        let mut out = String::from(
            "trial,iteration,t_total_s,offset_s,high_conf_pct,source,overlap_ticks,\
             operator_idle_share,duration_s,supervised_ticks,corrected_ticks,\
             operator_busy_share,lower_bound_s,bound_is_optimum,gap,throughput_per_h",
        );
        for i in 1..=n_robots {
            let _ = write!(out, ",lc_intervals_robot{i}_s");
        }
        out.push('\n');
        for t in &self.trials {
            for r in &t.iterations {
                let pair = match &r.pair {
                    Some(p) => format!(
                        "{},{},{},{},{},{}",
                        p.overlap_ticks,
                        p.operator_idle_share,
                        p.duration_s,
                        p.supervised_ticks,
                        p.corrected_ticks,
                        p.operator_busy_share,
                    ),
                    None => ",,,,,".to_string(),
                };
                // Writing to a String cannot fail.
                let _ = write!(
                    out,
                    "{},{},{},{},{},{},{},{},{},{},{}",
                    t.trial,
                    r.iteration,
                    r.t_total_s,
                    r.offset_s,
                    r.high_conf_pct,
                    r.source,
                    pair,
                    r.lower_bound_s,
                    r.bound_is_optimum,
                    r.gap,
                    r.throughput_per_h,
                );
                for i in 0..n_robots {
                    let intervals = r.lc_intervals_s.get(i).map_or_else(String::new, |v| {
                        v.iter()
                            .map(|[a, b]| format!("{a:.3}-{b:.3}"))
                            .collect::<Vec<_>>()
                            .join(";")
                    });
                    let _ = write!(out, ",{intervals}");
                }
                out.push('\n');
            }
        }
        out
    }
}

/// Wall time spent in each phase of a study, summed over trials (trials run in parallel,
/// so the sum can exceed the elapsed time).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseTimes {
    /// Aligning the demonstrations and fitting the model (once per study, §II-B1).
    pub alignment: Duration,
    /// Adding executions to the model (Eq. 21).
    pub model_update: Duration,
    /// Recording observations and updating the confidence (Eq. 9–12).
    pub confidence: Duration,
    /// Sampling schedules (§II-C), the first one included.
    pub scheduling: Duration,
    /// Running the workcell (coordinator, operator, commands).
    pub simulation: Duration,
}

impl PhaseTimes {
    fn add(&mut self, other: &PhaseTimes) {
        self.alignment += other.alignment;
        self.model_update += other.model_update;
        self.confidence += other.confidence;
        self.scheduling += other.scheduling;
        self.simulation += other.simulation;
    }
}

/// Progress of a running study, reported after every recorded pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Trial index.
    pub trial: usize,
    /// Pairs of this trial recorded so far.
    pub pairs_done: usize,
}

/// What a study learns from: demonstrations (demo 0 is the reference) and the ground-truth
/// labels of the reference demonstration, one per sample.
#[derive(Clone, Debug, PartialEq)]
pub struct StudyInputs {
    /// The demonstrations, demo 0 first.
    pub demos: Vec<Demonstration>,
    /// Labels of demo 0's samples (pass, section, painted, phase).
    pub reference_labels: Vec<Label>,
}

impl StudyInputs {
    /// Reads `demo_0.csv`, `demo_1.csv`, … (until the first missing index) and
    /// `demo_0.labels.csv` from `dir` (the layout of `fixtures/sanding/`).
    ///
    /// # Errors
    /// [`Error::BadInput`] naming the file for a missing or unreadable labels file, fewer
    /// than two demonstrations, or labels that do not match demo 0's samples; the model
    /// crate's error (naming file and line) for a bad demonstration.
    pub fn from_dir(dir: &Path) -> Result<Self> {
        let mut demos = Vec::new();
        loop {
            let path = dir.join(format!("demo_{}.csv", demos.len()));
            if !path.exists() {
                break;
            }
            demos.push(Demonstration::from_csv_path(&path, None)?);
        }
        if demos.len() < 2 {
            return Err(Error::BadInput {
                path: dir.to_path_buf(),
                why: format!(
                    "found {} demonstrations demo_0.csv, demo_1.csv, …; need at least 2",
                    demos.len()
                ),
            });
        }
        let path = dir.join("demo_0.labels.csv");
        let inputs = Self {
            demos,
            reference_labels: read_labels(&path)?,
        };
        inputs
            .check()
            .map_err(|why| Error::BadInput { path, why })?;
        Ok(inputs)
    }

    /// From demonstrations made by the task generator ([`crate::task`]), demo 0 the
    /// reference: channels [`task::CHANNELS`], each demo's own `Δt_s`.
    ///
    /// # Errors
    /// The model crate's error if a demonstration is invalid, [`Error::BadInput`] for
    /// fewer than two.
    pub fn from_task_demos(demos: &[task::TaskDemo]) -> Result<Self> {
        let names: Vec<String> = task::CHANNELS.iter().map(|c| (*c).to_string()).collect();
        let converted = demos
            .iter()
            .map(|d| {
                let flat: Vec<f64> = d.samples.iter().flatten().copied().collect();
                Demonstration::new(names.clone(), flat, d.dt_s)
            })
            .collect::<std::result::Result<Vec<_>, _>>()?;
        let inputs = Self {
            demos: converted,
            reference_labels: demos.first().map(|d| d.labels.clone()).unwrap_or_default(),
        };
        inputs.check().map_err(|why| Error::BadInput {
            path: "<generated demonstrations>".into(),
            why,
        })?;
        Ok(inputs)
    }

    fn check(&self) -> std::result::Result<(), String> {
        if self.demos.len() < 2 {
            return Err(format!(
                "{} demonstrations, need at least 2",
                self.demos.len()
            ));
        }
        let n = self.demos[0].n_samples();
        if self.reference_labels.len() != n {
            return Err(format!(
                "{} labels for the {n} samples of the reference demonstration",
                self.reference_labels.len()
            ));
        }
        Ok(())
    }
}

/// Reads a labels file of the fixtures (`demo_<i>.labels.csv`: columns `pass, section,
/// painted, phase`, one row per sample of demo `i`).
///
/// # Errors
/// [`Error::BadInput`] naming the file (and the row) when it cannot be read or parsed.
pub fn read_labels(path: &Path) -> Result<Vec<Label>> {
    let bad = |why: String| Error::BadInput {
        path: path.to_path_buf(),
        why,
    };
    let mut reader = csv::Reader::from_path(path).map_err(|e| bad(e.to_string()))?;
    reader
        .deserialize::<Label>()
        .enumerate()
        .map(|(k, r)| r.map_err(|e| bad(format!("row {}: {e}", k + 1))))
        .collect()
}

/// The record of the planner's current schedule (no pair run yet), with the ground truth
/// of `labels` and the operator's actual rates `tally` over the rounds recorded.
fn iteration_record(
    planner: &Planner,
    labels: &[Label],
    tally: &OperatorTally,
) -> Result<IterationRecord> {
    let schedule = planner.schedule();
    let timeline = GlobalTimeline::new(planner.problem(), schedule)?;
    let lc_intervals_s = timeline
        .lc_intervals()
        .iter()
        .map(|v| v.iter().map(|i| [i.start_s, i.end_s]).collect())
        .collect();
    let outcome = planner.outcome();
    let n_robots = planner.n_robots();
    Ok(IterationRecord {
        iteration: planner.pairs_recorded(),
        t_total_s: outcome.t_total_s,
        offset_s: schedule.offsets_s.first().copied().unwrap_or(0.0),
        high_conf_pct: 100.0 * planner.confidence().high_share(),
        source: outcome.source.into(),
        lc_intervals_s,
        pair: None,
        lower_bound_s: outcome.lower_bound_s,
        bound_is_optimum: outcome.bound_is_optimum,
        gap: outcome.gap,
        throughput_per_h: throughput_per_h(n_robots, outcome.t_total_s),
        offsets_s: schedule.offsets_s.clone(),
        falsely_trusted_samples: falsely_trusted(planner.confidence().conf(), labels),
        lc_runs: timeline.lc_intervals().iter().map(|v| v.len()).collect(),
        error_rates: planner.error_rates()?,
        simulated_rates: (planner.pairs_recorded() > 0).then(|| tally.rates()),
    })
}

/// Runs trial `trial` of a study from a fitted model (see the module docs). Its seed is
/// [`trial_seed`]`(config.seed, trial)`: schedules use `derive_seed(trial seed, k)`,
/// workpieces and the operator a ChaCha8 stream of the trial seed.
///
/// # Errors
/// Invalid configuration, or any stage's error.
pub fn run_trial(
    config: &StudyConfig,
    model: &TaskModel,
    reference_labels: &[Label],
    trial: usize,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<(TrialResult, PhaseTimes)> {
    run_trial_observed(config, model, reference_labels, trial, progress, &|_| {})
}

/// One simulated round of a study as it ran: what [`run_study_observed`]'s observer sees.
#[derive(Clone, Copy, Debug)]
pub struct RoundView<'a> {
    /// The trial (0-based).
    pub trial: usize,
    /// The round within the trial (1-based; round `k` ran the schedule of iteration `k − 1`).
    pub round: usize,
    /// The planner the round ran under (its schedule), before the round is recorded.
    pub planner: &'a Planner,
    /// The round.
    pub run: &'a workcell::RoundRun,
}

/// [`run_trial`] calling `observe` with every round after it ran and before it is recorded
/// (to write chosen rounds out, e.g. as bags); the result is the same as without.
///
/// # Errors
/// As [`run_trial`].
pub fn run_trial_observed(
    config: &StudyConfig,
    model: &TaskModel,
    reference_labels: &[Label],
    trial: usize,
    progress: &(dyn Fn(Progress) + Sync),
    observe: &(dyn Fn(RoundView<'_>) + Sync),
) -> Result<(TrialResult, PhaseTimes)> {
    config.validate()?;
    let seed = trial_seed(config.seed, trial);
    let mut params = config.planner.clone();
    params.sampler.samples = config.samples;
    params.sampler.seed = seed;
    let mut times = PhaseTimes::default();
    let t = Instant::now();
    let mut planner = Planner::from_model_with_robots(model.clone(), params, config.robots)?;
    times.scheduling += t.elapsed();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(1);
    let operator = config.operator();
    let n_pairs = config.n_rounds();
    let n_robots = planner.n_robots();
    let mut iterations = Vec::with_capacity(n_pairs + 1);
    let mut tally = OperatorTally::default();
    for pair in 0..n_pairs {
        let mut record = iteration_record(&planner, reference_labels, &tally)?;
        let workpieces = (0..n_robots)
            .map(|_| Workpiece::random(&config.task, &mut rng))
            .collect::<Result<Vec<_>>>()?;
        let t = Instant::now();
        let run =
            workcell::run_round(&planner, reference_labels, &workpieces, &operator, &mut rng)?;
        let records = run.records(planner.model())?;
        times.simulation += t.elapsed();
        tally.add(&run);
        let count = |f: fn(&bool) -> bool, pick: fn(&workcell::RobotRun) -> &Vec<bool>| {
            run.robots
                .iter()
                .map(|r| pick(r).iter().filter(|b| f(b)).count())
                .sum()
        };
        observe(RoundView {
            trial,
            round: pair + 1,
            planner: &planner,
            run: &run,
        });
        record.pair = Some(PairStats {
            overlap_ticks: run.overlap_ticks,
            operator_idle_share: run.operator_idle_share(),
            duration_s: run.duration_s(),
            supervised_ticks: count(|b| *b, |r| &r.supervised),
            corrected_ticks: count(|b| *b, |r| &r.corrected),
            operator_busy_share: run.operator_busy_share(),
        });
        iterations.push(record);
        let report = planner.record_round(&records)?;
        times.model_update += report.model_update;
        times.confidence += report.confidence;
        times.scheduling += report.scheduling;
        progress(Progress {
            trial,
            pairs_done: pair + 1,
        });
    }
    iterations.push(iteration_record(&planner, reference_labels, &tally)?);
    Ok((
        TrialResult {
            trial,
            seed,
            iterations,
        },
        times,
    ))
}

/// Runs the study (§III): fits the model once, then runs the trials ([`run_trials`]).
///
/// # Errors
/// Invalid configuration or inputs, a fit whose reference is not demo 0 (the labels are
/// demo 0's; call [`run_trials`] with the reference's labels), or any stage's error (the
/// first trial's in order).
pub fn run_study(
    config: &StudyConfig,
    inputs: &StudyInputs,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<(StudyResult, PhaseTimes)> {
    run_study_observed(config, inputs, progress, &|_| {})
}

/// [`run_study`] calling `observe` with every round of every trial after it ran and before it
/// is recorded ([`RoundView`]; from worker threads, in no particular order across trials);
/// the result is the same as without.
///
/// # Errors
/// As [`run_study`].
pub fn run_study_observed(
    config: &StudyConfig,
    inputs: &StudyInputs,
    progress: &(dyn Fn(Progress) + Sync),
    observe: &(dyn Fn(RoundView<'_>) + Sync),
) -> Result<(StudyResult, PhaseTimes)> {
    config.validate()?;
    inputs.check().map_err(|why| Error::BadInput {
        path: "<study inputs>".into(),
        why,
    })?;
    let t = Instant::now();
    let model = TaskModel::fit(&inputs.demos, &config.planner.fit)?;
    if model.reference_idx() != 0 {
        // The labels are demo 0's; another reference needs its own labels (`run_trials`).
        return Err(Error::BadInput {
            path: "<study inputs>".into(),
            why: format!(
                "the fit chose demo {} as the reference (fit.reference = {}), but the \
                 ground-truth labels are demo 0's",
                model.reference_idx(),
                config.planner.fit.reference
            ),
        });
    }
    model.prepare_corrections();
    let alignment = t.elapsed();
    let (result, mut times) =
        run_trials_observed(config, &model, &inputs.reference_labels, progress, observe)?;
    times.alignment = alignment;
    Ok((result, times))
}

/// Runs every trial of a study from a fitted model, in parallel (rayon). Each trial
/// depends only on `(config.seed, trial)`, so the result is the same for any number of
/// threads. `progress` is called after every recorded pair, from worker threads.
///
/// # Errors
/// Invalid configuration, labels that do not match the model's reference, or any stage's
/// error (the first trial's in trial order).
pub fn run_trials(
    config: &StudyConfig,
    model: &TaskModel,
    reference_labels: &[Label],
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<(StudyResult, PhaseTimes)> {
    run_trials_observed(config, model, reference_labels, progress, &|_| {})
}

/// [`run_trials`] with an observer of every round ([`run_trial_observed`]).
///
/// # Errors
/// As [`run_trials`].
pub fn run_trials_observed(
    config: &StudyConfig,
    model: &TaskModel,
    reference_labels: &[Label],
    progress: &(dyn Fn(Progress) + Sync),
    observe: &(dyn Fn(RoundView<'_>) + Sync),
) -> Result<(StudyResult, PhaseTimes)> {
    config.validate()?;
    if reference_labels.len() != model.n_ref() {
        return Err(Error::BadInput {
            path: "<reference labels>".into(),
            why: format!(
                "{} labels for {} reference samples",
                reference_labels.len(),
                model.n_ref()
            ),
        });
    }
    let outcomes: Vec<Result<(TrialResult, PhaseTimes)>> = (0..config.trials)
        .into_par_iter()
        .map(|k| run_trial_observed(config, model, reference_labels, k, progress, observe))
        .collect();
    let mut times = PhaseTimes::default();
    let mut trials = Vec::with_capacity(config.trials);
    for outcome in outcomes {
        let (trial, t) = outcome?;
        times.add(&t);
        trials.push(trial);
    }
    Ok((
        StudyResult {
            config: config.clone(),
            n_ref: model.n_ref(),
            dt_s: model.dt_s(),
            ground_truth_pct: 100.0 * task::ground_truth_share(reference_labels),
            trials,
        },
        times,
    ))
}

/// Tasks per hour per operator when `n_robots` robots each finish one task every
/// `t_total_s` seconds: `N·3600 / T_total`.
#[must_use]
pub fn throughput_per_h(n_robots: usize, t_total_s: f64) -> f64 {
    n_robots as f64 * 3600.0 / t_total_s
}

/// Mean and sample standard deviation (n − 1 denominator; 0 for one value, NaN for none).
pub fn mean_std(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let v: Vec<f64> = values.collect();
    if v.is_empty() {
        return (f64::NAN, f64::NAN);
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (mean, 0.0);
    }
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, var.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(iteration: usize, t_total_s: f64, pair: bool) -> IterationRecord {
        IterationRecord {
            iteration,
            t_total_s,
            offset_s: 1.0,
            high_conf_pct: 10.0 * iteration as f64,
            source: ScheduleSource::Sampled,
            lc_intervals_s: vec![vec![[0.0, 1.5]], vec![[2.0, 2.25], [3.0, 4.0]]],
            pair: pair.then_some(PairStats {
                overlap_ticks: 0,
                operator_idle_share: 0.5,
                duration_s: t_total_s,
                supervised_ticks: 10,
                corrected_ticks: 4,
                operator_busy_share: 0.5,
            }),
            lower_bound_s: t_total_s - 1.0,
            bound_is_optimum: iteration == 0,
            gap: 1.0 / (t_total_s - 1.0),
            throughput_per_h: throughput_per_h(2, t_total_s),
            offsets_s: vec![1.0],
            falsely_trusted_samples: 0,
            lc_runs: vec![1, 2],
            error_rates: ErrorRates::default(),
            simulated_rates: None,
        }
    }

    fn result() -> StudyResult {
        let trial = |k: usize, a: f64, b: f64| TrialResult {
            trial: k,
            seed: trial_seed(1, k),
            iterations: vec![record(0, a, true), record(1, b, false)],
        };
        StudyResult {
            config: StudyConfig::default(),
            n_ref: 100,
            dt_s: 0.01,
            ground_truth_pct: 50.0,
            trials: vec![trial(0, 10.0, 8.0), trial(1, 12.0, 8.0)],
        }
    }

    #[test]
    fn defaults_are_the_papers_study() {
        let c = StudyConfig::default();
        assert_eq!((c.trials, c.executions, c.samples), (5, 300, 5000));
        assert_eq!((c.robots, c.n_rounds()), (2, 150));
        assert_eq!((c.miss_rate, c.false_correction_rate), (0.01, 0.01));
        c.validate().unwrap();
    }

    #[test]
    fn bad_configs_name_the_field() {
        let cases: [(StudyConfig, &str); 7] = [
            (
                StudyConfig {
                    robots: 0,
                    ..Default::default()
                },
                "robots",
            ),
            (
                StudyConfig {
                    robots: 9,
                    ..Default::default()
                },
                "robots",
            ),
            (
                StudyConfig {
                    robots: 7,
                    ..Default::default()
                },
                "executions",
            ),
            (
                StudyConfig {
                    trials: 0,
                    ..Default::default()
                },
                "trials",
            ),
            (
                StudyConfig {
                    executions: 7,
                    ..Default::default()
                },
                "executions",
            ),
            (
                StudyConfig {
                    samples: 0,
                    ..Default::default()
                },
                "samples",
            ),
            (
                StudyConfig {
                    miss_rate: f64::NAN,
                    ..Default::default()
                },
                "miss_rate",
            ),
        ];
        // Rounds of N robots: 300 executions are 100 rounds of 3.
        let three = StudyConfig {
            robots: 3,
            ..Default::default()
        };
        three.validate().unwrap();
        assert_eq!(three.n_rounds(), 100);
        for (c, name) in cases {
            let err = c.validate().unwrap_err();
            assert!(
                matches!(err, Error::BadParam { name: n, .. } if n == name),
                "{err}"
            );
        }
    }

    #[test]
    fn config_reads_from_toml_with_defaults_and_rejects_unknown_keys() {
        let c: StudyConfig = toml::from_str("trials = 2\nseed = 7\n").unwrap();
        assert_eq!((c.trials, c.seed, c.executions), (2, 7, 300));
        assert!(toml::from_str::<StudyConfig>("trails = 2\n").is_err());
        let nested: StudyConfig = toml::from_str(
            "[planner.sampler]\np_fastest = 0.5\n[planner.confidence]\ngamma_c = 0.9\n",
        )
        .unwrap();
        assert_eq!(nested.planner.sampler.p_fastest, 0.5);
        assert_eq!(nested.planner.confidence.gamma_c, 0.9);
        assert!(toml::from_str::<StudyConfig>("[planner.sampler]\nbogus = 1\n").is_err());
        // The committed configuration is the paper's study.
        let committed = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../fixtures/study.toml"
        ))
        .unwrap();
        let c: StudyConfig = toml::from_str(&committed).unwrap();
        assert_eq!(c, StudyConfig::default());
    }

    #[test]
    fn schedule_sources_keep_their_names_in_json_csv_and_display() {
        let cases = [
            (
                Source::Sampled { candidate: 41 },
                ScheduleSource::Sampled,
                "sampled",
            ),
            (Source::Previous, ScheduleSource::Previous, "previous"),
            (
                Source::RepairedPrevious,
                ScheduleSource::Repaired,
                "repaired",
            ),
            (Source::Serial, ScheduleSource::Serial, "serial"),
        ];
        for (source, kind, name) in cases {
            assert_eq!(ScheduleSource::from(source), kind);
            assert_eq!(kind.to_string(), name);
            let json = serde_json::to_string(&kind).unwrap();
            assert_eq!(json, format!("\"{name}\""));
            assert_eq!(serde_json::from_str::<ScheduleSource>(&json).unwrap(), kind);
        }
    }

    #[test]
    fn trial_seeds_differ_and_are_stable() {
        let seeds: Vec<u64> = (0..5).map(|k| trial_seed(2023, k)).collect();
        for i in 0..5 {
            for j in 0..i {
                assert_ne!(seeds[i], seeds[j]);
            }
        }
        assert_eq!(trial_seed(2023, 3), seeds[3]);
        assert_ne!(trial_seed(2024, 0), seeds[0]);
    }

    #[test]
    fn summary_is_mean_and_sample_std_across_trials() {
        let s = result().summary();
        assert_eq!(s.len(), 2);
        // Trials give 10 and 12: mean 11, sample std sqrt(2).
        assert_eq!(s[0].t_total_mean_s, 11.0);
        assert!((s[0].t_total_std_s - 2f64.sqrt()).abs() < 1e-12);
        assert_eq!((s[1].t_total_mean_s, s[1].t_total_std_s), (8.0, 0.0));
        assert_eq!(s[1].high_conf_pct_mean, 10.0);
        // The certificate: bounds 9 and 11 (mean 10), both proven at iteration 0, neither
        // at 1; gaps 1/9 and 1/11.
        assert_eq!(s[0].lower_bound_mean_s, 10.0);
        assert_eq!(
            (s[0].bound_proven_share, s[1].bound_proven_share),
            (1.0, 0.0)
        );
        assert!((s[0].gap_mean - (1.0 / 9.0 + 1.0 / 11.0) / 2.0).abs() < 1e-15);
        // Two robots at 8 s: 900 tasks per hour; 10 s and 12 s: (720 + 600) / 2.
        assert_eq!(s[1].throughput_mean_per_h, 900.0);
        assert_eq!(s[0].throughput_mean_per_h, 660.0);
        // A round ran at iteration 0 only.
        assert_eq!(s[0].operator_busy_share_mean, Some(0.5));
        assert_eq!(s[1].operator_busy_share_mean, None);
    }

    #[test]
    fn throughput_is_tasks_per_hour_per_operator() {
        assert_eq!(throughput_per_h(2, 120.0), 60.0);
        assert_eq!(throughput_per_h(1, 3600.0), 1.0);
        assert_eq!(throughput_per_h(8, 90.0), 320.0);
    }

    #[test]
    fn csv_has_one_row_per_trial_and_iteration() {
        let csv = result().to_csv();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 1 + 4);
        let n_cols = lines[0].split(',').count();
        assert_eq!(n_cols, 18);
        assert!(lines[0].ends_with(",lc_intervals_robot1_s,lc_intervals_robot2_s"));
        for l in &lines[1..] {
            assert_eq!(l.split(',').count(), n_cols, "{l}");
        }
        assert_eq!(
            lines[1],
            "0,0,10,1,0,sampled,0,0.5,10,10,4,0.5,9,true,0.1111111111111111,720,\
             0.000-1.500,2.000-2.250;3.000-4.000"
        );
        assert!(lines[2].starts_with("0,1,8,1,10,sampled,,,,,,,7,false,"));
    }
}
