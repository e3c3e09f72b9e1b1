//! The one study trial loop (issue 40), for rounds and for the continuous cell: run the
//! cell's controller until it has a batch of `N` executions, record them into the planner
//! (Eq. 21, Eq. 9–12), re-plan, and repeat until the trial's budget is spent (argmin's
//! executor is the model: one loop drives every solver, each solver says what a step is).
//!
//! What differs between the two kinds of cell is what happens at a batch boundary, the
//! [`TrialKind`]: rounds ([`super::run`]) run one round of the planner's schedule per batch
//! (one execution of each robot) and take the next schedule at the next round; the
//! continuous cell ([`super::cell`]) ticks a running cell until `N` more tasks have
//! completed, whichever robots did them, and hands the new plan over to the running
//! controller. The loop itself — the trial's start ([`start_trial`]), the record of each
//! batch with its phase times, the progress report, the order of the random draws — is
//! here once.

use std::time::Instant;

use rand_chacha::ChaCha8Rng;
use tandem_lfd::TaskModel;
use tandem_planner::{ExecutionRecord, Planner};

use super::config::StudyConfig;
use super::run::{PhaseTimes, Progress, start_trial, truth_operator};
use crate::truth::TaskTruth;
use crate::workcell::OperatorParams;
use crate::{Error, Result};

/// A trial in progress: what the loop owns and lends to its [`TrialKind`] at each step.
pub(super) struct TrialState<'a> {
    /// The study's configuration.
    pub(super) config: &'a StudyConfig,
    /// Where the task needs the operator; every workpiece is drawn from it.
    pub(super) truth: &'a dyn TaskTruth,
    /// The trial index.
    pub(super) trial: usize,
    /// The trial's seed ([`super::trial_seed`]).
    pub(super) seed: u64,
    /// The planner, recorded into after every batch.
    pub(super) planner: Planner,
    /// The simulation's random stream (workpieces, the operator).
    pub(super) rng: ChaCha8Rng,
    /// The simulated operator ([`truth_operator`]).
    pub(super) operator: OperatorParams,
    /// Wall time per phase so far.
    pub(super) times: PhaseTimes,
}

impl TrialState<'_> {
    /// `e` as the error of round (batch) `round` (1-based) of this trial.
    pub(super) fn in_round(&self, round: usize, e: Error) -> Error {
        Error::InTrial {
            trial: self.trial,
            round,
            source: Box::new(e),
        }
    }
}

/// What a kind of cell does in the trial loop ([`run_trial_loop`]) at a batch boundary.
pub(super) trait TrialKind {
    /// What the trial gives back when it ends.
    type Run;

    /// Runs the cell until it has the next batch of `N` executions — batch `round`
    /// (1-based) — and returns their records in the order the planner records them;
    /// `None` once the trial's budget is spent.
    ///
    /// # Errors
    /// Any stage's error while running or recording the executions.
    fn next_batch(
        &mut self,
        state: &mut TrialState<'_>,
        round: usize,
    ) -> Result<Option<Vec<ExecutionRecord>>>;

    /// After a batch is recorded into the planner: the cell's next plan (rounds: the record
    /// of the planner's new schedule; the continuous cell: a new plan, handed over to the
    /// running controller).
    ///
    /// # Errors
    /// Any stage's error while planning.
    fn replan(&mut self, state: &mut TrialState<'_>) -> Result<()>;

    /// The trial's result once [`next_batch`](Self::next_batch) said the budget is spent.
    ///
    /// # Errors
    /// Any stage's error while summing up.
    fn finish(self, state: TrialState<'_>) -> Result<Self::Run>;
}

/// The one study trial loop: the trial's start ([`start_trial`], then `start` makes the
/// kind of cell on it; both timed as scheduling), then batch, record, re-plan until
/// [`TrialKind::next_batch`] says the budget is spent, reporting `progress` after every
/// re-plan. A recording error names the trial and the round ([`Error::InTrial`]).
///
/// # Errors
/// Those of [`start_trial`], of the kind's steps, and of [`Planner::record_round`].
pub(super) fn run_trial_loop<'a, K: TrialKind>(
    config: &'a StudyConfig,
    model: &TaskModel,
    truth: &'a dyn TaskTruth,
    trial: usize,
    progress: &(dyn Fn(Progress) + Sync),
    start: impl FnOnce(&mut TrialState<'a>) -> Result<K>,
) -> Result<K::Run> {
    let t = Instant::now();
    let (seed, planner, rng) = start_trial(config, model, truth, trial)?;
    let mut state = TrialState {
        config,
        truth,
        trial,
        seed,
        planner,
        rng,
        operator: truth_operator(config, truth),
        times: PhaseTimes::default(),
    };
    let mut kind = start(&mut state)?;
    state.times.scheduling += t.elapsed();
    let mut rounds_done = 0;
    while let Some(batch) = kind.next_batch(&mut state, rounds_done + 1)? {
        let report = match state.planner.record_round(&batch) {
            Ok(report) => report,
            Err(e) => return Err(state.in_round(rounds_done + 1, e.into())),
        };
        rounds_done += 1;
        state.times.model_update += report.model_update;
        state.times.confidence += report.confidence;
        state.times.scheduling += report.scheduling;
        kind.replan(&mut state)?;
        progress(Progress { trial, rounds_done });
    }
    kind.finish(state)
}
