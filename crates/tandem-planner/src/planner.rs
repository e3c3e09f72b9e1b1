//! The iterative loop of the paper's Fig. 2 (§II-C, Eq. 21): model, observations,
//! confidence and schedule, updated after every pair of executions.

use std::path::Path;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use tandem_confidence::{Confidence, ConfidenceParams, Observations};
use tandem_lfd::{Demonstration, Execution, FitParams, TaskModel};
use tandem_realtime::Coordinator;
use tandem_schedule::{
    Outcome, Problem, SamplerParams, SamplerStats, Schedule, Source, sample_schedule_n,
};

use crate::{Error, Result, derive_seed, state};

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
}

/// What [`Planner::record_pair`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordReport {
    /// Reference samples that became high-confidence (latched) in this update.
    pub newly_high: usize,
    /// Where the new schedule came from (sampled, previous, repaired previous, serial).
    pub source: Source,
    /// The new schedule's `T_total` (Eq. 13), s.
    pub t_total_s: f64,
    /// Wall time of the model update (Eq. 21).
    pub model_update: Duration,
    /// Wall time of recording the observations and updating the confidence (Eq. 9–12).
    pub confidence: Duration,
    /// Wall time of re-scheduling (§II-C).
    pub scheduling: Duration,
}

/// The loop of Fig. 2: the task model learned from demonstrations and executions, the
/// correction observations, the latched confidence and the current schedule.
///
/// After each pair of executions, [`Planner::record_pair`] adds both executions to the
/// model with their known reference-time logs (Eq. 21, no re-alignment), adds their
/// supervised samples to the observations, updates the confidence (Eq. 9–12, with the
/// latch: a high-confidence sample stays high) and re-schedules, warm-started by the
/// previous schedule.
///
/// # The previous schedule as fallback
///
/// The paper says the previous schedule "will always remain valid" because confidence
/// only grows. That is not quite so here: the model update moves the mean gradient
/// `ψ̇̄_D` and widens `[ψ̇min, ψ̇max]`, and Eq. 20 requires low-confidence samples to run at
/// the *new* mean. So the previous schedule is offered to the sampler
/// ([`tandem_schedule::sample_schedule`]) as it is, and the sampler re-validates it against
/// the new problem; if it fails, the sampler re-projects it (low-confidence samples at the
/// new mean, high-confidence gradients clamped into the new bounds, `τ` clamped into
/// `[0, |ψ_E1|]`) and validates that again (all constraints of Eq. 20 including the margin
/// check) before using it as incumbent. If neither passes, the fastest serial schedule
/// is the incumbent. [`RecordReport::source`] says which one won.
#[derive(Clone, Debug)]
pub struct Planner {
    params: PlannerParams,
    model: TaskModel,
    observations: Observations,
    confidence: Confidence,
    problem: Problem,
    outcome: Outcome,
    pairs_recorded: usize,
}

/// The serialized part of a [`Planner`] (the problem is rebuilt on load).
#[derive(Serialize, Deserialize)]
struct PlannerState {
    params: PlannerParams,
    model: TaskModel,
    observations: Observations,
    confidence: Confidence,
    outcome: Outcome,
    pairs_recorded: usize,
}

/// [`PlannerState`] as state format version 4 wrote it: the same but for the two-robot
/// schedule ([`ScheduleV4`]).
#[derive(Deserialize)]
struct PlannerStateV4 {
    params: PlannerParams,
    model: TaskModel,
    observations: Observations,
    confidence: Confidence,
    outcome: OutcomeV4,
    pairs_recorded: usize,
}

/// [`Outcome`] as state format version 4 wrote it (field for field, the schedule
/// [`ScheduleV4`]).
#[derive(Deserialize)]
struct OutcomeV4 {
    schedule: ScheduleV4,
    t_total_s: f64,
    source: Source,
    stats: SamplerStats,
    lower_bound_s: f64,
    bound_is_optimum: bool,
    gap: f64,
}

/// The two-robot [`Schedule`] of state format version 4: two warps and robot 2's offset.
#[derive(Deserialize)]
struct ScheduleV4 {
    grad_exec: [Vec<f64>; 2],
    offset_s: f64,
    tick_s: f64,
}

impl From<PlannerStateV4> for PlannerState {
    fn from(v4: PlannerStateV4) -> Self {
        let OutcomeV4 {
            schedule,
            t_total_s,
            source,
            stats,
            lower_bound_s,
            bound_is_optimum,
            gap,
        } = v4.outcome;
        PlannerState {
            params: v4.params,
            model: v4.model,
            observations: v4.observations,
            confidence: v4.confidence,
            outcome: Outcome {
                schedule: Schedule {
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
            pairs_recorded: v4.pairs_recorded,
        }
    }
}

/// The scheduling problem for the current model and confidence (Eq. 12, 14).
///
/// `ψ̇̄` is clamped into `[ψ̇min, ψ̇max]` sample by sample: the mean of the same values that
/// define the bounds lies between them, but its floating-point update (Welford) can
/// overshoot by a rounding error.
fn problem_for(model: &TaskModel, confidence: &Confidence) -> Result<Problem> {
    let (gmin, gmax) = (model.grad_min(), model.grad_max());
    let gmean = model
        .grad_mean()
        .iter()
        .zip(gmin.iter().zip(gmax))
        .map(|(&g, (&lo, &hi))| if lo <= hi { g.clamp(lo, hi) } else { g })
        .collect();
    Ok(Problem::new(
        confidence.conf().to_vec(),
        gmean,
        gmin.to_vec(),
        gmax.to_vec(),
        model.dt_s(),
    )?)
}

/// [`Error::RobotCount`] unless `1 ≤ n_robots ≤ MAX_ROBOTS`.
fn check_robot_count(n_robots: usize) -> Result<()> {
    let max = tandem_realtime::MAX_ROBOTS;
    if (1..=max).contains(&n_robots) {
        Ok(())
    } else {
        Err(Error::RobotCount { n_robots, max })
    }
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
    /// [`Error::RobotCount`] for `n_robots` outside `1..=MAX_ROBOTS`, and as [`Planner::new`].
    pub fn with_robots(
        demos: &[Demonstration],
        params: PlannerParams,
        n_robots: usize,
    ) -> Result<Self> {
        check_robot_count(n_robots)?;
        params.validate()?;
        let model = TaskModel::fit(demos, &params.fit)?;
        Self::from_model_with_robots(model, params, n_robots)
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
    /// [`Error::RobotCount`], and as [`Planner::from_model`].
    pub fn from_model_with_robots(
        model: TaskModel,
        params: PlannerParams,
        n_robots: usize,
    ) -> Result<Self> {
        check_robot_count(n_robots)?;
        params.validate()?;
        let confidence = Confidence::from_prior(model.sigma2_d(), params.confidence.clone())?;
        let observations = Observations::new(model.n_ref())?;
        let problem = problem_for(&model, &confidence)?;
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
        })
    }

    fn sampler_params(params: &PlannerParams, pairs_recorded: usize) -> SamplerParams {
        SamplerParams {
            seed: derive_seed(params.sampler.seed, pairs_recorded as u64),
            ..params.sampler.clone()
        }
    }

    /// Records a round of executions, one per robot of the schedule (robot 1 first), and
    /// re-schedules (see the type docs).
    ///
    /// Everything is checked before the planner changes: on error it is as before.
    ///
    /// # Errors
    /// [`Error::BadExecution`] for a number of records other than the schedule's robot count
    /// or flag vectors of the wrong length; the lower crates' errors for a bad execution
    /// (channels, period, log) or observation.
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
        let t0 = Instant::now();
        let mut model = self.model.clone();
        for e in executions {
            model.update(&e.execution)?;
        }
        let t1 = Instant::now();
        let mut observations = self.observations.clone();
        for e in executions {
            let (times, corrected) = e.observations()?;
            observations.record(&times, &corrected)?;
        }
        let mut confidence = self.confidence.clone();
        let newly_high = confidence.update(model.sigma2_d(), &observations)?;
        let problem = problem_for(&model, &confidence)?;
        let t2 = Instant::now();
        let pairs_recorded = self.pairs_recorded + 1;
        let outcome = sample_schedule_n(
            &problem,
            n_robots,
            &Self::sampler_params(&self.params, pairs_recorded),
            Some(&self.outcome.schedule),
        )?;
        let t3 = Instant::now();
        let report = RecordReport {
            newly_high,
            source: outcome.source,
            t_total_s: outcome.t_total_s,
            model_update: t1 - t0,
            confidence: t2 - t1,
            scheduling: t3 - t2,
        };
        self.model = model;
        self.observations = observations;
        self.confidence = confidence;
        self.problem = problem;
        self.outcome = outcome;
        self.pairs_recorded = pairs_recorded;
        Ok(report)
    }

    /// [`Planner::record_round`] for the paper's two robots.
    ///
    /// # Errors
    /// As [`Planner::record_round`].
    pub fn record_pair(&mut self, executions: &[ExecutionRecord; 2]) -> Result<RecordReport> {
        self.record_round(executions)
    }

    /// Re-runs the anytime sampler (§II-C) on the current problem with `sampler`, warm-started
    /// by the current schedule, and replaces the stored outcome by the result. Model,
    /// observations, confidence, parameters and [`Planner::pairs_recorded`] are unchanged
    /// (`sampler` is used for this call only and not stored in [`Planner::params`]).
    ///
    /// The current schedule is the sampler's incumbent, re-checked at `sampler.tick_s`, so
    /// `T_total` (Eq. 13, s) never increases as long as the current schedule is valid at
    /// that tick: always so when it is the tick the current schedule was made with
    /// ([`Schedule::tick_s`]). Otherwise the sampler repairs it or falls back to the fastest
    /// serial schedule, as in [`Planner::record_pair`]. The new schedule carries
    /// `sampler.tick_s`: run it at that tick.
    ///
    /// On error the planner is as before.
    ///
    /// # Errors
    /// The schedule crate's error for invalid `sampler` parameters or an infeasible problem.
    pub fn reschedule(&mut self, sampler: &SamplerParams) -> Result<&Outcome> {
        let outcome = sample_schedule_n(
            &self.problem,
            self.n_robots(),
            sampler,
            Some(&self.outcome.schedule),
        )?;
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
    /// runs the two robots until the next [`Planner::record_pair`].
    ///
    /// # Errors
    /// The schedule crate's error if the schedule does not lay out on the problem (not for a
    /// planner made by [`Planner::new`], [`Planner::from_model`] or [`Planner::load`]).
    pub fn coordinator(&self) -> Result<Coordinator> {
        Ok(self.schedule().coordinator(&self.problem)?)
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

    /// The latched confidence (`conf()[n]`: reference sample `n` is high-confidence).
    pub fn confidence(&self) -> &Confidence {
        &self.confidence
    }

    /// The parameters.
    pub fn params(&self) -> &PlannerParams {
        &self.params
    }

    /// Pairs of executions recorded so far.
    pub fn pairs_recorded(&self) -> usize {
        self.pairs_recorded
    }

    /// Saves the planner to `path` as a versioned state file, atomically: on error or a
    /// crash the previous file at `path` is intact (see [`crate::state`]).
    ///
    /// # Errors
    /// [`Error::Io`] naming the file or directory, [`Error::Encode`].
    pub fn save(&self, path: impl AsRef<Path>) -> Result<()> {
        state::save(path.as_ref(), &self.to_state())
    }

    /// Loads a planner saved by [`Planner::save`], of the current state format or an older one
    /// this build still reads (version 4: a two-robot schedule with one offset, converted to
    /// `offsets_s = [offset_s]`; saving writes the current version).
    ///
    /// # Errors
    /// As [`crate::state::load`] (missing, foreign, truncated, corrupt or other-version
    /// file, each naming `path`), or [`Error::Corrupt`] when the parts do not fit together.
    pub fn load(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let bytes = state::read(path)?;
        let (version, payload) = state::checked_payload(&bytes, path)?;
        let st: PlannerState = if version == 4 {
            state::decode_payload::<PlannerStateV4>(payload, path)?.into()
        } else {
            state::decode_payload(payload, path)?
        };
        Self::from_state(st).map_err(|e| Error::Corrupt {
            path: path.to_path_buf(),
            why: e.to_string(),
        })
    }

    fn to_state(&self) -> PlannerState {
        PlannerState {
            params: self.params.clone(),
            model: self.model.clone(),
            observations: self.observations.clone(),
            confidence: self.confidence.clone(),
            outcome: self.outcome.clone(),
            pairs_recorded: self.pairs_recorded,
        }
    }

    fn from_state(st: PlannerState) -> Result<Self> {
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
        let problem = problem_for(&st.model, &st.confidence)?;
        Ok(Self {
            params: st.params,
            model: st.model,
            observations: st.observations,
            confidence: st.confidence,
            problem,
            outcome: st.outcome,
            pairs_recorded: st.pairs_recorded,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::{CrashPoint, encode, temp_path, write_atomic_with};

    /// A small planner: three 1-channel demonstrations, aligned by the identity warp, whose
    /// force differs only on reference samples 10..20 (low confidence there).
    fn small_planner(seed: u64) -> Planner {
        let n = 40;
        let names = vec!["force".to_string()];
        let demo = |bump: f64| {
            let x = (0..n)
                .map(|i| if (10..20).contains(&i) { bump } else { 1.0 })
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
        Planner::from_model(model, params).unwrap()
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
                matches!(err, Error::RobotCount { n_robots, max: 8 } if n_robots == n),
                "{err}"
            );
            assert!(err.to_string().contains("1 to 8 robots"), "{err}");
        }
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
        assert_eq!(q.pairs_recorded(), 0);
    }

    #[test]
    fn a_crash_while_saving_keeps_the_previous_state() {
        let dir = std::env::temp_dir().join(format!("tandem-planner-crash-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("cell.tandem");
        let old = small_planner(1);
        old.save(&path).unwrap();
        let newer = small_planner(2);
        let bytes = encode(&newer.to_state()).unwrap();
        for crash in [CrashPoint::MidWrite, CrashPoint::BeforeRename] {
            write_atomic_with(&path, &bytes, crash).unwrap();
            assert!(temp_path(&path).unwrap().exists());
            let loaded = Planner::load(&path).unwrap();
            assert_eq!(loaded.schedule(), old.schedule(), "{crash:?}");
            assert_eq!(loaded.params(), old.params(), "{crash:?}");
        }
        newer.save(&path).unwrap();
        assert_eq!(Planner::load(&path).unwrap().params(), newer.params());
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
        let (conf, pairs) = (p.confidence().conf().to_vec(), p.pairs_recorded());
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
        assert_eq!(p.pairs_recorded(), pairs);
        // Bad sampler parameters leave the planner as it was.
        let before = p.outcome().clone();
        let bad = SamplerParams {
            p_fastest: 1.5,
            ..SamplerParams::default()
        };
        assert!(p.reschedule(&bad).is_err());
        assert_eq!(p.outcome(), &before);
    }

    #[test]
    fn reschedule_seeds_depend_on_the_pair_count_only() {
        let params = PlannerParams::default();
        let s0 = Planner::sampler_params(&params, 0).seed;
        let s1 = Planner::sampler_params(&params, 1).seed;
        assert_ne!(s0, s1);
        assert_eq!(s1, Planner::sampler_params(&params, 1).seed);
    }
}
