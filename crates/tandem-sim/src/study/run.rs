//! Running a study: trials of schedule, round, record (§III, Fig. 5), in parallel, with the
//! time spent in each phase.

use std::time::{Duration, Instant};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use tandem_lfd::TaskModel;
use tandem_planner::{ExecutionRecord, Planner, derive_seed};

use super::config::StudyConfig;
use super::inputs::StudyInputs;
use super::record::{IterationRecord, RoundStats, StudyResult, TrialResult, throughput_per_h};
use super::trial::{TrialKind, TrialState, run_trial_loop};
use crate::task::{self, Label};
use crate::truth::{OperatorTally, SandingTruth, TaskTruth, falsely_trusted_where};
use crate::workcell::{self, OperatorParams};
use crate::{Error, Result};

/// Seed of trial `trial` from the master `seed` ([`derive_seed`]), so trials are
/// independent of each other and of the order in which threads run them.
pub fn trial_seed(seed: u64, trial: usize) -> u64 {
    derive_seed(seed, trial as u64)
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

/// Progress of a running study, reported after every recorded round.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Progress {
    /// Trial index.
    pub trial: usize,
    /// Rounds of this trial recorded so far.
    pub rounds_done: usize,
}

/// The record of the planner's current schedule (no round run yet); `can_need` per reference
/// sample ([`TaskTruth::can_need`]).
fn iteration_record(
    planner: &Planner,
    can_need: &[bool],
    tally: &OperatorTally,
) -> Result<IterationRecord> {
    let schedule = planner.schedule();
    let outcome = planner.outcome();
    let n_robots = planner.n_robots();
    // M > 1 operators (issue 44): the round runs the planner's sectored round, so the record
    // is that round's: its `T_total`, bound and gap, and its robots' starts and intervals
    // (each sector's schedule as its robots run it, after the planned dwells at its holds,
    // robot `i` at index `i`), not the stored one-operator schedule's.
    let sectored = if planner.params().sampler.operators > 1 {
        Some(planner.sectored_rounds()?.0)
    } else {
        None
    };
    let (lc, offsets_s, t_total_s, lower_bound_s, gap) = match &sectored {
        Some(s) => {
            let mut lc = Vec::with_capacity(n_robots);
            // Every robot's start in the round's global time (each sector's robots from 0);
            // the record keeps robots 2..N's, `τ_2, …, τ_N`.
            let mut starts_s = Vec::with_capacity(n_robots);
            for sector in &s.schedules {
                lc.extend(sector.lc_intervals(planner.problem())?);
                starts_s.extend(sector.starts_s());
            }
            let offsets_s: Vec<f64> = starts_s.into_iter().skip(1).collect();
            let gap = (s.t_total_s - s.lower_bound_s) / s.lower_bound_s;
            (lc, offsets_s, s.t_total_s, s.lower_bound_s, gap)
        }
        // As the robots run it: after a hold, a robot's intervals come after its planned
        // dwell.
        None => (
            schedule.lc_intervals(planner.problem())?,
            schedule.offsets_s.clone(),
            outcome.t_total_s,
            outcome.lower_bound_s,
            outcome.gap,
        ),
    };
    let lc_intervals_s = lc
        .iter()
        .map(|v| v.iter().map(|i| [i.start_s, i.end_s]).collect())
        .collect();
    Ok(IterationRecord {
        iteration: planner.rounds_recorded(),
        t_total_s,
        offset_s: offsets_s.first().copied().unwrap_or(0.0),
        high_conf_pct: 100.0 * planner.confidence().high_share(),
        source: outcome.source.into(),
        lc_intervals_s,
        round: None,
        lower_bound_s,
        bound_is_optimum: outcome.bound_is_optimum && sectored.is_none(),
        gap,
        gap_search: outcome
            .gap_split()
            .filter(|_| sectored.is_none())
            .map(|g| g.search),
        throughput_per_h: throughput_per_h(n_robots, t_total_s),
        offsets_s,
        falsely_trusted_samples: falsely_trusted_where(planner.confidence().conf(), can_need),
        lc_runs: lc.iter().map(Vec::len).collect(),
        error_rates: planner.error_rates()?,
        simulated_rates: (planner.rounds_recorded() > 0).then(|| tally.rates()),
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
    let truth = SandingTruth::new(reference_labels.to_vec(), config.task.clone());
    let run = run_trial_on(config, model, &truth, trial, progress, observe)?;
    Ok((run.result, run.times))
}

/// A trial as it ended ([`run_trial_on`]): its record, the time spent in each phase, and the
/// planner after the last round (its model, confidence and schedule).
#[derive(Debug)]
pub struct TrialRun {
    /// The trial's record.
    pub result: TrialResult,
    /// Wall time per phase.
    pub times: PhaseTimes,
    /// The planner after the last recorded round.
    pub planner: Planner,
}

/// The simulated operator of a study on `truth`'s task: the configuration's rates, corrections
/// that raise [`TaskTruth::correction_channel`].
pub(super) fn truth_operator(config: &StudyConfig, truth: &dyn TaskTruth) -> OperatorParams {
    OperatorParams {
        force_channel: truth.correction_channel().to_string(),
        ..config.operator()
    }
}

/// The start of every trial, of rounds ([`run_trial_on`]) and of the continuous cell
/// ([`run_cell_trial_on`](super::run_cell_trial_on)): checks the configuration and the truth,
/// and returns the trial's seed ([`trial_seed`]), its planner on `model` (the sampler seeded
/// with that seed, `config.samples` samples, `config.robots` robots) and the simulation's
/// random stream (ChaCha8 from the seed, stream 1).
pub(super) fn start_trial(
    config: &StudyConfig,
    model: &TaskModel,
    truth: &dyn TaskTruth,
    trial: usize,
) -> Result<(u64, Planner, ChaCha8Rng)> {
    config.validate()?;
    check_truth(model, truth)?;
    let seed = trial_seed(config.seed, trial);
    let mut params = config.planner_params();
    params.sampler.samples = config.samples;
    params.sampler.seed = seed;
    let planner = Planner::from_model_with_robots(model.clone(), params, config.robots)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(1);
    Ok((seed, planner, rng))
}

/// Checks that `truth` is given on `model`'s reference samples.
pub(super) fn check_truth(model: &TaskModel, truth: &dyn TaskTruth) -> Result<()> {
    if truth.n_ref() != model.n_ref() {
        return Err(Error::Mismatch {
            what: "ground truth (one value per reference sample)",
            expected: model.n_ref(),
            found: truth.n_ref(),
        });
    }
    Ok(())
}

/// [`run_trial_observed`] on any task: every robot's workpiece of every round is drawn from
/// `truth` ([`TaskTruth::draw`], robot 1 first), the simulated operator corrects
/// [`TaskTruth::correction_channel`], and falsely trusted samples are counted against
/// [`TaskTruth::can_need`]. On the sanding task ([`SandingTruth`]) it is the study's trial,
/// bit for bit. Returns the planner after the last round beside the record.
///
/// # Errors
/// As [`run_trial`], and [`Error::Mismatch`] for a truth on another number of reference
/// samples than the model's.
pub fn run_trial_on(
    config: &StudyConfig,
    model: &TaskModel,
    truth: &dyn TaskTruth,
    trial: usize,
    progress: &(dyn Fn(Progress) + Sync),
    observe: &(dyn Fn(RoundView<'_>) + Sync),
) -> Result<TrialRun> {
    run_trial_loop(config, model, truth, trial, progress, |state| {
        let can_need = state.truth.can_need();
        let tally = OperatorTally::default();
        let first = iteration_record(&state.planner, can_need, &tally)?;
        let mut iterations = Vec::with_capacity(config.n_rounds() + 1);
        iterations.push(first);
        Ok(Rounds {
            can_need,
            observe,
            n_rounds: config.n_rounds(),
            tally,
            iterations,
        })
    })
}

/// Rounds in the one trial loop ([`run_trial_loop`]): a batch is one round of the planner's
/// schedule, every robot's workpiece drawn from the truth (robot 1 first); the next plan is
/// the schedule the planner made while recording it.
struct Rounds<'a> {
    /// Where the truth can need the operator (falsely trusted samples are counted on it).
    can_need: &'a [bool],
    /// Sees every round after it ran, before it is recorded.
    observe: &'a (dyn Fn(RoundView<'_>) + Sync),
    /// Rounds per trial.
    n_rounds: usize,
    /// What the simulated operator did so far.
    tally: OperatorTally,
    /// The records so far; the last one is the current schedule's, its round not run yet.
    iterations: Vec<IterationRecord>,
}

impl TrialKind for Rounds<'_> {
    type Run = TrialRun;

    fn next_batch(
        &mut self,
        state: &mut TrialState<'_>,
        round: usize,
    ) -> Result<Option<Vec<ExecutionRecord>>> {
        if round > self.n_rounds {
            return Ok(None);
        }
        let planner = &state.planner;
        let needed = (0..planner.n_robots())
            .map(|_| state.truth.draw(&mut state.rng))
            .collect::<Result<Vec<_>>>()?;
        let t = Instant::now();
        let run = workcell::run_round_with(
            planner,
            |robot, ref_idx| needed[robot][ref_idx],
            &state.operator,
            &mut state.rng,
        )
        .map_err(|e| state.in_round(round, e))?;
        let records = run.records(planner.model())?;
        state.times.simulation += t.elapsed();
        self.tally.add(&run);
        (self.observe)(RoundView {
            trial: state.trial,
            round,
            planner,
            run: &run,
        });
        let record = self
            .iterations
            .last_mut()
            .expect("the loop's start pushed the first schedule's record");
        record.round = Some(round_stats(&run, &needed));
        Ok(Some(records))
    }

    fn replan(&mut self, state: &mut TrialState<'_>) -> Result<()> {
        let record = iteration_record(&state.planner, self.can_need, &self.tally)?;
        self.iterations.push(record);
        Ok(())
    }

    fn finish(self, state: TrialState<'_>) -> Result<TrialRun> {
        Ok(TrialRun {
            result: TrialResult {
                trial: state.trial,
                seed: state.seed,
                iterations: self.iterations,
            },
            times: state.times,
            planner: state.planner,
        })
    }
}

/// What a round did ([`RoundStats`]); `needed[robot][n]`: whether robot `robot`'s
/// workpiece needed the operator at reference sample `n`.
fn round_stats(run: &workcell::RoundRun, needed: &[Vec<bool>]) -> RoundStats {
    let count = |pick: fn(&workcell::RobotRun) -> &Vec<bool>| {
        run.robots
            .iter()
            .map(|r| pick(r).iter().filter(|b| **b).count())
            .sum()
    };
    RoundStats {
        overlap_ticks: run.overlap_ticks,
        operator_idle_share: run.operator_idle_share(),
        duration_s: run.duration_s(),
        supervised_ticks: count(|r| &r.supervised),
        corrected_ticks: count(|r| &r.corrected),
        operator_busy_share: run.operator_busy_share(),
        faults: run.faults,
        robot_wait_share: run.robot_wait_share(),
        hold_ticks: run.robots.iter().map(|r| r.hold_ticks).sum(),
        plan_gap: run.plan_gap,
        needed_unsupervised: run.needed_unsupervised(|robot, n| needed[robot][n]),
        switch_missed: run.robots.iter().map(|r| r.switch_missed).sum(),
        rest_s: run.rest_ticks as f64 * run.tick_s,
    }
}

/// Runs the study (§III): fits the model once, then runs the trials ([`run_trials`]).
///
/// # Errors
/// Invalid configuration or inputs, or any stage's error (the first trial's in order). The
/// truth is the labels of whichever demonstration the fit chose as the reference
/// ([`StudyInputs::reference_labels`]).
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
    run_study_finished(config, inputs, progress, observe, &|_, _| {})
}

/// [`run_study_observed`] handing every trial's planner after its last recorded round to
/// `finished` (the trial, 0-based, and the planner: its model, confidence and the schedule
/// the next round would run), from worker threads as the trials end, in no particular order
/// (`cargo xtask study --save-state` saves them, so the study's last round can be replayed).
/// The result is the same as without.
///
/// # Errors
/// As [`run_study`].
pub fn run_study_finished(
    config: &StudyConfig,
    inputs: &StudyInputs,
    progress: &(dyn Fn(Progress) + Sync),
    observe: &(dyn Fn(RoundView<'_>) + Sync),
    finished: &(dyn Fn(usize, &Planner) + Sync),
) -> Result<(StudyResult, PhaseTimes)> {
    let (model, alignment) = fit_study_model(config, inputs)?;
    let labels = inputs.reference_labels(&model)?;
    let (result, mut times) =
        run_trials_finished(config, &model, &labels, progress, observe, finished)?;
    times.alignment = alignment;
    Ok((result, times))
}

/// The study's model: the configuration and inputs checked, the demonstrations fitted
/// (§II-B1), the correction directions prepared; and the time it took.
///
/// # Errors
/// As [`run_study`].
pub(super) fn fit_study_model(
    config: &StudyConfig,
    inputs: &StudyInputs,
) -> Result<(TaskModel, Duration)> {
    config.validate()?;
    inputs.check().map_err(|why| Error::BadInput {
        path: "<study inputs>".into(),
        why,
    })?;
    let t = Instant::now();
    let model = TaskModel::fit(&inputs.demos, &config.planner.fit)?;
    model.prepare_corrections();
    Ok((model, t.elapsed()))
}

/// Runs every trial of a study from a fitted model, in parallel (rayon). Each trial
/// depends only on `(config.seed, trial)`, so the result is the same for any number of
/// threads. `progress` is called after every recorded round, from worker threads.
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
    run_trials_finished(
        config,
        model,
        reference_labels,
        progress,
        observe,
        &|_, _| {},
    )
}

/// [`run_trials_observed`] handing every trial's planner after its last round to `finished`
/// ([`run_study_finished`]).
///
/// # Errors
/// As [`run_trials`].
pub fn run_trials_finished(
    config: &StudyConfig,
    model: &TaskModel,
    reference_labels: &[Label],
    progress: &(dyn Fn(Progress) + Sync),
    observe: &(dyn Fn(RoundView<'_>) + Sync),
    finished: &(dyn Fn(usize, &Planner) + Sync),
) -> Result<(StudyResult, PhaseTimes)> {
    let truth = SandingTruth::new(reference_labels.to_vec(), config.task.clone());
    let (trials, times) = par_trials(config, model, reference_labels, |k| {
        let run = run_trial_on(config, model, &truth, k, progress, observe)?;
        finished(k, &run.planner);
        Ok((run.result, run.times))
    })?;
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

/// Runs `trial(k)` for every trial `k` of `config` in parallel (rayon), after checking the
/// configuration and that `labels` are one per reference sample of `model`: the trials in
/// trial order and their phase times summed. Each trial depends only on `(config.seed, k)`,
/// so the result is the same for any number of threads.
///
/// # Errors
/// Invalid configuration, mismatched labels, or the first failing trial's error in trial
/// order.
pub(super) fn par_trials<T: Send>(
    config: &StudyConfig,
    model: &TaskModel,
    labels: &[Label],
    trial: impl Fn(usize) -> Result<(T, PhaseTimes)> + Sync,
) -> Result<(Vec<T>, PhaseTimes)> {
    config.validate()?;
    if labels.len() != model.n_ref() {
        return Err(Error::BadInput {
            path: "<reference labels>".into(),
            why: format!(
                "{} labels for {} reference samples",
                labels.len(),
                model.n_ref()
            ),
        });
    }
    let outcomes: Vec<Result<(T, PhaseTimes)>> =
        (0..config.trials).into_par_iter().map(&trial).collect();
    let mut times = PhaseTimes::default();
    let mut trials = Vec::with_capacity(config.trials);
    for outcome in outcomes {
        let (t, phase) = outcome?;
        times.add(&phase);
        trials.push(t);
    }
    Ok((trials, times))
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
