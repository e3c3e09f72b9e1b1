//! The whole loop measured on every family (issue 38, Deliver 2 and 4; `cargo xtask zoo`).
//!
//! Per family and seed the task is generated and fitted once with the defaults, as a user's
//! first try would (`PlannerParams::default()`, plus the family's hold rules declared as
//! `tandem fit --hold-where` declares them): [`prepare`]. The truth is mapped onto the
//! model's reference samples (the reference demonstration's true progress per sample →
//! [`crate::ZooTask::need_at`] → a `tandem_sim::needs::NeedProfile`, one draw per need span
//! and workpiece). Then, for every robot count `N` and cell, the study's own loop runs
//! ([`run_rounds`]: `tandem_sim::study::run_trial_on`, schedule → round with the simulated
//! operator who follows the truth → `record_round` → re-schedule; [`run_continuous`]:
//! `run_cell_trial_on`, the continuous cell re-planned every `N` tasks), for
//! [`EvalParams::rounds`] rounds. Every run is a pure function of the family, the seed, `N`
//! and the cell: runs go in parallel (rayon) and come back sorted, so the report is the same
//! on any number of threads.
//!
//! What is measured ([`RunReport`], [`FitReport`]), and summarized per family as the mean
//! over seeds ([`FamilyRow`]): the final `T_total` against the margin-free bound and against
//! serial; high confidence against the truth and the samples falsely trusted (where the
//! demonstrations vary, and apart where they all agree); rounds until the robots first
//! overlap; the largest round-to-round increase of `T_total`; realized against planned time
//! and throughput; backward steps of reference time and overlapping ticks (from the per-tick
//! records; must be 0); the reference-choice spread; the alignment's error against the
//! family's known warps ([`WarpError`]; [`export_alignments`] writes the same data for a peer
//! aligner). [`Thresholds`] is the one place the acceptance limits live ([`check`]).

mod prepare;
mod run;
mod summary;
mod warps;

use std::path::Path;
use std::sync::Mutex;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use tandem_lfd::TaskModel;
use tandem_planner::PlannerParams;
use tandem_sim::study::Cell;

pub use prepare::{
    FitReport, Prepared, ReferenceSpread, SANDING, correction_channel, falsely_trusted_split,
    prepare, prepare_sanding,
};
pub use run::{Fate, FateCount, FateIncreases, RunReport, run_continuous, run_rounds};
pub use summary::{Breach, FamilyRow, FitRow, Thresholds, check, family_rows, fit_rows};
pub use warps::{ExportMeta, WarpError, export_alignment, fitted_warps, warp_error, warp_errors};

use crate::{Error, Family, Result};

/// Default number of learning rounds per run: see [`EvalParams::rounds`].
pub const DEFAULT_ROUNDS: usize = 30;

/// What to evaluate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EvalParams {
    /// Seeds of every family.
    pub seeds: Vec<u64>,
    /// Robot counts `N` (each in `1..=8`).
    pub robots: Vec<usize>,
    /// Cells: rounds, continuous, or both.
    pub cells: Vec<Cell>,
    /// Learning rounds per run (continuous: re-plans, each after `N` tasks). Default: 30 —
    /// long enough for every variable section to be supervised, corrected and learnt (the
    /// confidence of a need span of probability `p` rises only with rounds that needed it;
    /// with `p ≥ 0.2` thirty rounds give six or more such rounds per robot), short enough
    /// that the zoo runs on every family in minutes; the sanding study's 150 rounds would
    /// take five times longer for a tail in which nothing changes.
    pub rounds: usize,
    /// Measure the reference-choice spread (one more fit per demonstration, and the medoid).
    pub reference_spread: bool,
    /// The planner's parameters before the family's holds are added: the defaults.
    pub planner: PlannerParams,
}

impl Default for EvalParams {
    fn default() -> Self {
        Self {
            seeds: crate::HELD_OUT_SEEDS.collect(),
            robots: vec![2, 3, 4],
            cells: vec![Cell::Rounds, Cell::Continuous],
            rounds: DEFAULT_ROUNDS,
            reference_spread: true,
            planner: PlannerParams::default(),
        }
    }
}

impl EvalParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::Eval`] naming the parameter.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &str, why: &str| {
            Err(Error::Eval {
                what: what.into(),
                why: why.into(),
            })
        };
        if self.seeds.is_empty() {
            return bad("seeds", "give at least one seed");
        }
        if self.robots.is_empty() || self.robots.iter().any(|n| !(1..=8).contains(n)) {
            return bad("robots", "give robot counts between 1 and 8");
        }
        if self.cells.is_empty() {
            return bad("cells", "give rounds, continuous or both");
        }
        if self.rounds == 0 {
            return bad("rounds", "run at least one round");
        }
        self.planner.validate()?;
        Ok(())
    }
}

/// What the whole evaluation gives.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ZooReport {
    /// The parameters.
    pub params: EvalParams,
    /// The families evaluated, in [`crate::families`] order.
    pub families: Vec<String>,
    /// Per family and seed, what the fit shows (family order, then seed order).
    pub fits: Vec<FitReport>,
    /// Per family, seed, `N` and cell, what the loop did (sorted in that order).
    pub runs: Vec<RunReport>,
}

/// A step of progress of [`evaluate`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// A task was generated and fitted (one per family and seed).
    Fitted,
    /// A round was recorded (continuous: a re-plan).
    Round,
}

/// How many [`Step`]s [`evaluate`] reports for `n_families` families and `n_extra` extra
/// tasks.
#[must_use]
pub fn steps(params: &EvalParams, n_families: usize, n_extra: usize) -> u64 {
    let tasks = (n_families * params.seeds.len()) as u64;
    let runs = tasks + n_extra as u64;
    tasks + runs * (params.robots.len() * params.cells.len() * params.rounds) as u64
}

/// Evaluates `families` (module docs): fits every family and seed, then runs every `N` and
/// cell, in parallel; `progress` is called with every [`Step`] from worker threads. `extra`
/// tasks prepared elsewhere (the sanding fixture, [`prepare_sanding`]) run after the
/// families' (their fits are not reported as steps).
///
/// # Errors
/// Invalid parameters; the first failing fit or run's error, in report order.
pub fn evaluate(
    families: &[&Family],
    extra: Vec<Prepared>,
    params: &EvalParams,
    progress: &(dyn Fn(Step) + Sync),
) -> Result<ZooReport> {
    params.validate()?;
    let tasks: Vec<(&Family, u64)> = families
        .iter()
        .flat_map(|f| params.seeds.iter().map(move |&s| (*f, s)))
        .collect();
    let mut prepared: Vec<Prepared> = tasks
        .par_iter()
        .map(|(family, seed)| {
            let p = prepare(family, *seed, &params.planner, params.reference_spread);
            progress(Step::Fitted);
            p
        })
        .collect::<Vec<Result<Prepared>>>()
        .into_iter()
        .collect::<Result<_>>()?;
    let mut names: Vec<String> = families.iter().map(|f| f.name.to_string()).collect();
    for p in extra {
        if !names.iter().any(|n| n == p.family) {
            names.push(p.family.to_string());
        }
        prepared.push(p);
    }
    let jobs: Vec<(usize, usize, Cell)> = (0..prepared.len())
        .flat_map(|t| {
            params
                .robots
                .iter()
                .flat_map(move |&n| params.cells.iter().map(move |&c| (t, n, c)))
        })
        .collect();
    // Longest first, so that the last jobs to start are short ones.
    let mut order: Vec<usize> = (0..jobs.len()).collect();
    order.sort_by_key(|&j| std::cmp::Reverse(prepared[jobs[j].0].model.n_ref() * jobs[j].1));
    let done = Mutex::new(Vec::with_capacity(jobs.len()));
    order.par_iter().for_each(|&j| {
        let (t, n, cell) = jobs[j];
        let tick = || progress(Step::Round);
        let report = match cell {
            Cell::Rounds => run_rounds(&prepared[t], n, params.rounds, &tick),
            Cell::Continuous => run_continuous(&prepared[t], n, params.rounds, &tick),
        };
        done.lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .push((j, report));
    });
    let mut done = done
        .into_inner()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    done.sort_by_key(|(j, _)| *j);
    let runs = done.into_iter().map(|(_, r)| r).collect::<Result<_>>()?;
    Ok(ZooReport {
        params: params.clone(),
        families: names,
        fits: prepared.into_iter().map(|p| p.report).collect(),
        runs,
    })
}

/// Generates and fits (as [`prepare`] does: the defaults of `planner.fit`) every family of
/// `families` at every seed, and writes what a peer aligner needs to align the same
/// demonstrations with the same weights into `dir/<family>/<seed>/` ([`export_alignment`]),
/// in parallel. Returns every task's [`ExportMeta`] in family, then seed order.
///
/// # Errors
/// The generator's, the fit's or the alignment's errors; [`Error::Io`] naming a file that
/// could not be written.
pub fn export_alignments(
    families: &[&Family],
    seeds: &[u64],
    planner: &PlannerParams,
    dir: &Path,
) -> Result<Vec<ExportMeta>> {
    let tasks: Vec<(&Family, u64)> = families
        .iter()
        .flat_map(|f| seeds.iter().map(move |&s| (*f, s)))
        .collect();
    tasks
        .par_iter()
        .map(|(family, seed)| {
            let task = (family.generate)(*seed)?;
            let demos = task.demos()?;
            let model = TaskModel::fit(&demos, &planner.fit)?;
            export_alignment(
                &task,
                &demos,
                &model,
                &planner.fit,
                &dir.join(family.name).join(seed.to_string()),
            )
        })
        .collect()
}
