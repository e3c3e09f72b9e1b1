//! The simulated study of §III (Fig. 5): configuration, per-iteration records, summaries.
//!
//! A trial starts from the demonstrations, schedules, runs a round (one execution of each of
//! the `N` robots, a pair in the paper) in the simulated workcell, records it (Eq. 21),
//! re-schedules, and so on for `executions / N` rounds. Iteration `k` is the schedule made
//! after `k` recorded rounds (iteration 0: demonstrations only) together with the outcome of
//! running the next round under it ([`RoundStats`]; none for the last iteration).

mod cell;
mod cell_file;
mod config;
mod inputs;
mod mixed;
mod mixed_cell;
mod record;
mod run;
mod trial;

pub use cell::{
    CellCompletion, CellIteration, CellStudyResult, CellSummary, CellTrialResult, CellTrialRun,
    Steady, run_cell_study, run_cell_study_finished, run_cell_trial, run_cell_trial_on,
    run_cell_trials, run_cell_trials_finished, task_gap,
};
pub use cell_file::{CellFile, CellFileTask, CellTruth};
pub use config::{Cell, StudyConfig, StudyOperator};
pub use inputs::{StudyInputs, read_labels, reference_labels};
pub use mixed::{
    MixedIteration, MixedRoundStats, MixedStudyResult, MixedTask, MixedTaskState, MixedTrialResult,
    run_mixed_study, run_mixed_trial,
};
pub use mixed_cell::{
    MixedCellCompletion, MixedCellIteration, MixedCellStudyResult, MixedCellTrialResult,
    MixedSteady, run_mixed_cell_study, run_mixed_cell_trial,
};
pub use record::{
    IterationRecord, IterationSummary, RoundStats, ScheduleSource, StudyResult, TrialResult,
    mean_std, throughput_per_h,
};
// The two-robot name of one release ago, deprecated at the crate's public edge only.
#[expect(deprecated, reason = "re-exported for one release at the public edge")]
pub use record::PairStats;
pub use run::{
    PhaseTimes, Progress, RoundView, TrialRun, run_study, run_study_finished, run_study_observed,
    run_trial, run_trial_observed, run_trial_on, run_trials, run_trials_finished,
    run_trials_observed, trial_seed,
};
