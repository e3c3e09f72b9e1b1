//! `cargo xtask capacity`: how many robots can one operator run on this task?
//!
//! Runs the study of §III (`tandem::sim::study`) once per robot count `N = 1..=max_robots`
//! with reduced sizes (defaults: 3 trials, 240 executions per trial rounded down to a
//! multiple of `N`, 2000 sampler candidates per re-schedule, the configuration file's seed;
//! see [`CapacityArgs`]), in rounds (the paper's cell, `run_study`), in a continuous cell
//! (`run_cell_study`: each robot starts its next task as soon as it is safe), or both
//! (`--cell rounds|continuous|both`, default both), and reports at the end of learning, per
//! `N`:
//!
//! - the steady throughput: tasks completed per hour of cell time over the last
//!   [`END_SHARE`] of each trial (rounds: its last rounds; continuous: its last tasks,
//!   `tandem::sim::study::Steady`), mean over trials — what one operator gets;
//! - rounds also: `T_total` of the final schedule (mean ± std over trials, s) and its planned
//!   throughput `N·3600 / T_total`; continuous also: the last plan's period as tasks per hour
//!   and its certificate's bound `3600·N / P_lower`;
//! - the operator busy share (share of the control ticks in which some robot was
//!   low-confidence) and the supervised seconds per task over the same window;
//! - the robots' waiting share over the same window: robot time not moving along the task
//!   (rounds: start offsets, holds and the wait for the round's last robot; continuous: the
//!   gates, where a robot waits for the operator's token);
//! - overlapping low-confidence ticks over every trial (must be 0).
//!
//! The operator-limited bound is `3600 / E[low-confidence seconds per task]`: one operator
//! supervising one robot at a time can support at most that many tasks per hour, however many
//! robots run. `E[·]` pools the end-of-learning supervised seconds per task of every row.
//!
//! Writes `capacity.json`, `capacity.svg` and `capacity.png` under the output folder
//! (default `results/capacity/`) and prints the tables (docs/study.md quotes them).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, anyhow, bail};
use plotters::prelude::*;
use serde::{Deserialize, Serialize};
use tandem::realtime::MAX_ROBOTS;

/// The default `--max-robots`: 8, the figure of docs/study.md (it was `MAX_ROBOTS` until that
/// became 16 in issue 44; the default run is unchanged).
const DEFAULT_MAX_ROBOTS: usize = 8;
use tandem::sim::study::{
    Cell, CellStudyResult, Steady, StudyConfig, StudyInputs, StudyResult, mean_std, run_cell_study,
    run_study, throughput_per_h,
};
use tandem::sim::workcell::PlanGap;
use tandem_plot::{FONT_FAMILY, GROUND_TRUTH, MEAN, OPERATOR};

use crate::study::{TrialBar, read_config};
use crate::workspace_root;

/// Share of a trial's rounds (or tasks, in a continuous cell), at its end, over which the
/// throughput, busy share, waiting and supervised time per task are measured ("the end of
/// learning"); the continuous study's `Steady` window is the same share.
pub(crate) const END_SHARE: f64 = 0.1;

/// `--cell` of `cargo xtask capacity`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CellChoice {
    /// Rounds of N executions (the paper).
    Rounds,
    /// A continuous cell.
    Continuous,
    /// Both, on one figure.
    Both,
}

/// Flags of `cargo xtask capacity`.
#[derive(clap::Args, Debug)]
pub(crate) struct CapacityArgs {
    /// Largest robot count (runs N = 1..=this; at most `MAX_ROBOTS` = 16). Default 8: the
    /// figure of docs/study.md (one operator saturates at about three robots).
    #[arg(long, default_value_t = DEFAULT_MAX_ROBOTS)]
    max_robots: usize,
    /// Trials per robot count.
    #[arg(long, default_value_t = 3)]
    trials: usize,
    /// Executions (tasks) per trial, rounded down to a multiple of N for each N.
    #[arg(long, default_value_t = 240)]
    executions: usize,
    /// Sampler candidates per re-schedule (rounds).
    #[arg(long, default_value_t = 2000)]
    samples: usize,
    /// Which cell to run: rounds, a continuous cell, or both on one figure.
    #[arg(long, value_enum, default_value = "both")]
    cell: CellChoice,
    /// Master seed (default: the configuration file's).
    #[arg(long)]
    seed: Option<u64>,
    /// Study configuration (default: fixtures/study.toml).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Output folder. Default: results/capacity/ in the workspace.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Smallest robot count (runs N = this..=max-robots).
    #[arg(long, default_value_t = 1)]
    min_robots: usize,
    /// The operator's switch time δ (s, ≥ 0) the schedules are planned with (issue 41), or
    /// several, comma-separated (`0,1,2,5,7`): a sweep, every robot count at every δ, drawn
    /// against δ in `capacity_switch.svg`/`.png`. Default: the configuration's
    /// (`[operator] switch_s`, 0).
    #[arg(
        long = "switch-s",
        value_name = "S,…",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    switch_s: Vec<f64>,
    /// Operators M of a fleet (issue 44), comma-separated (`2,4`): after the one-operator
    /// continuous rows (which need `--min-robots 1`), a pooled continuous cell of `M` tokens
    /// for every `N` of `--fleet-robots` above `M`, against the best sectors and the ceiling
    /// `min(r·N, o·M)` measured in the same run (`fleet.json`, `fleet.svg`, `fleet.png`;
    /// `crate::fleet`).
    #[arg(long, value_name = "M,…", value_delimiter = ',')]
    operators: Vec<usize>,
    /// With --operators: the robot counts N of the fleet (default: --max-robots).
    #[arg(
        long,
        value_name = "N,…",
        value_delimiter = ',',
        requires = "operators"
    )]
    fleet_robots: Vec<usize>,
    /// Measure the steady state over the last this many tasks of each trial (rounded up to
    /// whole rounds or periods of `N` tasks) instead of the last 10 %: the tasks before them
    /// are a warm-up in which the cell learns its task but is not measured (docs/decisions.md,
    /// "Capacity of a cell that knows its task (issue 41)"). Default: the last 10 %.
    #[arg(long, value_name = "TASKS")]
    steady_tasks: Option<usize>,
    /// Run nothing: read `capacity.json` from each of these output folders of earlier runs
    /// (comma-separated; e.g. one run per switch time, side by side) and write their rows
    /// together under `--out`: the tables, `capacity.json` and the figure. The runs of one
    /// cell must agree on trials, samples, seed and measured window; the rounds runs and the
    /// continuous runs may differ from each other (`capacity.json` then records the
    /// continuous cell's as `continuous_sizes`).
    #[arg(long, value_name = "DIR,…", value_delimiter = ',')]
    merge: Vec<PathBuf>,
}

/// The run sizes a `capacity.json` records, which merged runs must share cell by cell.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Sizes {
    trials: usize,
    samples: usize,
    seed: u64,
    steady_tasks: Option<usize>,
}

impl Sizes {
    /// The fields in which `self` differs from `other`, each as `name value` (the name as its
    /// command-line flag, e.g. `trials 2`).
    fn differing(&self, other: &Sizes) -> Vec<String> {
        let tasks = |t: Option<usize>| t.map_or_else(|| "none".to_string(), |k| k.to_string());
        [
            (self.trials != other.trials).then(|| format!("trials {}", self.trials)),
            (self.samples != other.samples).then(|| format!("samples {}", self.samples)),
            (self.seed != other.seed).then(|| format!("seed {}", self.seed)),
            (self.steady_tasks != other.steady_tasks)
                .then(|| format!("steady-tasks {}", tasks(self.steady_tasks))),
        ]
        .into_iter()
        .flatten()
        .collect()
    }
}

/// The sizes of each cell's rows (`None`: no rows of that cell). A run of `cargo xtask
/// capacity` gives both cells the same sizes; `--merge` may join rounds and continuous runs of
/// different sizes (e.g. the continuous cell at more trials), never two runs of one cell that
/// differ.
#[derive(Clone, Copy, Debug, PartialEq)]
struct CellSizes {
    rounds: Option<Sizes>,
    continuous: Option<Sizes>,
}

impl CellSizes {
    /// The sizes `capacity.json` records at its top level: the rounds rows', else the
    /// continuous cell's.
    fn main(&self) -> Option<Sizes> {
        self.rounds.or(self.continuous)
    }

    /// The continuous cell's sizes when they differ from [`CellSizes::main`] (recorded as
    /// `continuous_sizes`).
    fn continuous_apart(&self) -> Option<Sizes> {
        self.continuous
            .filter(|c| self.rounds.is_some_and(|r| r != *c))
    }
}

/// `capacity.json` as read back (`--merge`).
#[derive(Deserialize)]
struct CapacityFileIn {
    trials: usize,
    samples: usize,
    seed: u64,
    #[serde(default)]
    steady_tasks: Option<usize>,
    /// The continuous rows' sizes when a merge joined them to rounds of other sizes.
    #[serde(default)]
    continuous_sizes: Option<Sizes>,
    rows: Vec<CapacityRow>,
    continuous: Vec<CellRow>,
}

/// Folds `these`, the sizes of `path`'s rows of `cell`, into `seen`, the sizes of that cell's
/// rows read so far, or fails when they differ.
fn same_sizes(
    seen: &mut Option<(Sizes, PathBuf)>,
    these: Sizes,
    cell: &str,
    path: &Path,
) -> anyhow::Result<()> {
    match seen {
        Some((first, from)) if *first != these => bail!(
            "--merge: the {cell} rows of {} were run with {}, those of {} with {}; merge only \
             runs of one cell with the same sizes (re-run one of them with the other's {})",
            path.display(),
            these.differing(first).join(", "),
            from.display(),
            first.differing(&these).join(", "),
            these
                .differing(first)
                .iter()
                .map(|d| format!("--{}", d.split(' ').next().unwrap_or_default()))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        Some(_) => Ok(()),
        None => {
            *seen = Some((these, path.to_path_buf()));
            Ok(())
        }
    }
}

/// The rows of the `capacity.json` in each of `dirs` (`--merge`), in order, and each cell's
/// sizes: the rounds rows of every folder must share theirs, and so must the continuous rows,
/// but the two cells may differ.
fn read_runs(dirs: &[PathBuf]) -> anyhow::Result<(CellSizes, Vec<CapacityRow>, Vec<CellRow>)> {
    let (mut rows, mut cells) = (Vec::new(), Vec::new());
    let (mut rounds, mut continuous) = (None, None);
    for dir in dirs {
        let path = dir.join("capacity.json");
        let text = std::fs::read_to_string(&path).with_context(|| {
            format!(
                "--merge: reading {} (a folder `cargo xtask capacity --out` wrote)",
                path.display()
            )
        })?;
        let file: CapacityFileIn = serde_json::from_str(&text)
            .with_context(|| format!("--merge: {} is not a capacity.json", path.display()))?;
        let these = Sizes {
            trials: file.trials,
            samples: file.samples,
            seed: file.seed,
            steady_tasks: file.steady_tasks,
        };
        if !file.rows.is_empty() {
            same_sizes(&mut rounds, these, "rounds", &path)?;
        }
        if !file.continuous.is_empty() {
            let sizes = file.continuous_sizes.unwrap_or(these);
            same_sizes(&mut continuous, sizes, "continuous", &path)?;
        }
        rows.extend(file.rows);
        cells.extend(file.continuous);
    }
    if dirs.is_empty() {
        bail!("--merge: no folders given");
    }
    let sizes = CellSizes {
        rounds: rounds.map(|(s, _)| s),
        continuous: continuous.map(|(s, _)| s),
    };
    if sizes.main().is_none() {
        bail!("--merge: the folders hold no rows (give folders of runs that finished)");
    }
    Ok((sizes, rows, cells))
}

/// One robot count's result in rounds, at the end of learning.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct CapacityRow {
    /// Robots `N`.
    pub robots: usize,
    /// The switch time `δ` (s) the schedules were planned with (`[operator] switch_s`).
    pub switch_s: f64,
    /// Executions per trial actually run (a multiple of `N`).
    pub executions: usize,
    /// Rounds per trial.
    pub rounds: usize,
    /// Mean `T_total` of the final schedules (s).
    pub t_total_mean_s: f64,
    /// Sample standard deviation of that `T_total` across trials (s).
    pub t_total_std_s: f64,
    /// Mean planned throughput of the final schedules, `N·3600 / T_total` (tasks per hour per
    /// operator).
    pub throughput_per_h: f64,
    /// Mean bound of the final schedules' certificates, `N·3600 / T*` (tasks per hour; `T*`
    /// the lower bound `IterationRecord::lower_bound_s`, with the switch time when the
    /// scheduler counts it).
    pub bound_per_h: f64,
    /// Mean measured throughput over the last rounds: their tasks per hour of their actual
    /// durations (tasks per hour per operator).
    pub steady_throughput_per_h: f64,
    /// Mean operator busy share over the last rounds (in [0, 1]).
    pub operator_busy_share: f64,
    /// Mean share of the robots' time spent waiting over the last rounds (in [0, 1]).
    pub robot_wait_share: f64,
    /// Mean supervised (low-confidence) seconds per task over the last rounds (s).
    pub lc_s_per_task: f64,
    /// Overlapping low-confidence ticks over every round of every trial (must be 0).
    pub overlap_ticks: usize,
    /// Mean percent of high-confidence reference samples at the end.
    pub high_conf_pct: f64,
    /// Wall time of this robot count's study (s).
    pub wall_s: f64,
}

/// One robot count's result in a continuous cell, at the end of learning.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct CellRow {
    /// Robots `N`.
    pub robots: usize,
    /// The switch time `δ` (s) the plans were made with (`[operator] switch_s`).
    pub switch_s: f64,
    /// Tasks per trial (a multiple of `N`).
    pub tasks: usize,
    /// Mean steady throughput over the last tasks (tasks per hour per operator).
    pub steady_throughput_per_h: f64,
    /// Its sample standard deviation across trials.
    pub steady_throughput_std_per_h: f64,
    /// Mean operator busy share over the last tasks (in [0, 1]).
    pub operator_busy_share: f64,
    /// Mean share of the robots' time spent waiting at gates over the last tasks (in [0, 1]).
    pub robot_wait_share: f64,
    /// Mean supervised (low-confidence) seconds per task over the last tasks (s).
    pub lc_s_per_task: f64,
    /// Mean planned throughput of the last plans, `3600·N / P` (tasks per hour per operator).
    pub plan_per_h: f64,
    /// Mean bound of the last plans' certificates, `3600·N / P_lower` (tasks per hour).
    pub bound_per_h: f64,
    /// Mean low-confidence stretches of the last plans' task.
    pub lc_stretches: f64,
    /// Overlapping low-confidence ticks over every trial (must be 0).
    pub overlap_ticks: u64,
    /// Faults of the coordinator's monitor over every trial (must be 0).
    pub faults: u64,
    /// Mean percent of high-confidence reference samples at the end.
    pub high_conf_pct: f64,
    /// Wall time of this robot count's study (s).
    pub wall_s: f64,
    /// Tasks per trial in the measured window (whole periods).
    #[serde(default)]
    pub steady_tasks: usize,
    /// The measured window's tasks against the plan in force, per task (s), averaged over
    /// trials (`CellCompletion::plan_gap`): realized minus planned and its causes.
    #[serde(default)]
    pub plan_gap_per_task: PlanGap,
}

/// What `capacity.json` holds.
#[derive(Serialize)]
struct CapacityFile<'a> {
    trials: usize,
    samples: usize,
    seed: u64,
    end_share: f64,
    /// `--steady-tasks`: the measured window in tasks per trial (`None`: `end_share`).
    steady_tasks: Option<usize>,
    /// The continuous rows' sizes when they differ from the rounds rows' above (`--merge` of
    /// runs of the two cells at different sizes); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    continuous_sizes: Option<Sizes>,
    /// `3600 / E[low-confidence seconds per task]` (tasks per hour per operator).
    operator_limited_per_h: f64,
    /// Rounds, per `N` (empty with `--cell continuous`).
    rows: &'a [CapacityRow],
    /// The continuous cell, per `N` (empty with `--cell rounds`).
    continuous: &'a [CellRow],
}

/// The end-of-learning row of one study in rounds.
pub(crate) fn row(
    result: &StudyResult,
    wall_s: f64,
    steady_tasks: Option<usize>,
) -> anyhow::Result<CapacityRow> {
    let config = &result.config;
    let n = config.robots;
    let finals: Vec<_> = result
        .trials
        .iter()
        .map(|t| {
            t.iterations
                .last()
                .ok_or_else(|| anyhow!("a trial without iterations"))
        })
        .collect::<anyhow::Result<_>>()?;
    let (t_mean, t_std) = mean_std(finals.iter().map(|r| r.t_total_s));
    let rounds = config.n_rounds();
    let last = steady_tasks
        .map_or((END_SHARE * rounds as f64).ceil() as usize, |t| {
            t.div_ceil(n)
        })
        .clamp(1, rounds);
    fn end_rounds(
        t: &tandem::sim::study::TrialResult,
        skip: usize,
    ) -> impl Iterator<Item = &tandem::sim::study::RoundStats> {
        t.iterations
            .iter()
            .filter_map(|r| r.round.as_ref())
            .skip(skip)
    }
    let end_rounds = |t| end_rounds(t, rounds - last);
    let all_end: Vec<_> = result.trials.iter().flat_map(end_rounds).collect();
    // Per trial, its last rounds' tasks per hour of their actual durations.
    let steady = result.trials.iter().map(|t| {
        let pairs: Vec<_> = end_rounds(t).collect();
        let s: f64 = pairs.iter().map(|p| p.duration_s).sum();
        throughput_per_h(n * pairs.len(), s)
    });
    let tick_s = result.dt_s;
    Ok(CapacityRow {
        robots: n,
        switch_s: config.operator.switch_s,
        executions: config.executions,
        rounds,
        t_total_mean_s: t_mean,
        t_total_std_s: t_std,
        throughput_per_h: mean_std(finals.iter().map(|r| r.throughput_per_h)).0,
        bound_per_h: mean_std(finals.iter().map(|r| throughput_per_h(n, r.lower_bound_s))).0,
        steady_throughput_per_h: mean_std(steady).0,
        operator_busy_share: mean_std(all_end.iter().map(|p| p.operator_busy_share)).0,
        robot_wait_share: mean_std(all_end.iter().map(|p| p.robot_wait_share)).0,
        lc_s_per_task: mean_std(
            all_end
                .iter()
                .map(|p| p.supervised_ticks as f64 * tick_s / n as f64),
        )
        .0,
        overlap_ticks: result.total_overlap_ticks(),
        high_conf_pct: mean_std(finals.iter().map(|r| r.high_conf_pct)).0,
        wall_s,
    })
}

/// The end-of-learning row of one continuous study.
pub(crate) fn cell_row(
    result: &CellStudyResult,
    wall_s: f64,
    steady_tasks: Option<usize>,
) -> anyhow::Result<CellRow> {
    let n = result.config.robots;
    let summary = result.summary();
    // Each trial's measured window: the study's own (the last 10 %) or the last
    // `steady_tasks` (whole periods).
    let steady: Vec<Steady> = result
        .trials
        .iter()
        .map(|t| match steady_tasks {
            None => Some(t.steady),
            Some(k) => Steady::of_last(&t.completions, n, result.dt_s, k),
        })
        .collect::<Option<_>>()
        .ok_or_else(|| anyhow!("a continuous trial without completed tasks"))?;
    let (throughput, throughput_std) = mean_std(steady.iter().map(|s| s.throughput_per_h));
    let per_task: Vec<PlanGap> = steady
        .iter()
        .map(|s| s.plan_gap.scaled(1.0 / s.tasks.max(1) as f64))
        .collect();
    let last: Vec<_> = result
        .trials
        .iter()
        .map(|t| {
            t.iterations
                .last()
                .ok_or_else(|| anyhow!("a continuous trial without plans"))
        })
        .collect::<anyhow::Result<_>>()?;
    Ok(CellRow {
        robots: n,
        switch_s: result.config.operator.switch_s,
        tasks: result.config.executions,
        steady_throughput_per_h: throughput,
        steady_throughput_std_per_h: throughput_std,
        operator_busy_share: mean_std(steady.iter().map(|s| s.operator_busy_share)).0,
        robot_wait_share: mean_std(steady.iter().map(|s| s.robot_wait_share)).0,
        // Busy seconds of the window over its tasks: each busy tick supervises one robot.
        lc_s_per_task: mean_std(
            steady
                .iter()
                .map(|s| s.operator_busy_share * s.duration_s / s.tasks as f64),
        )
        .0,
        plan_per_h: summary.last_plan_tasks_per_hour,
        bound_per_h: summary.last_plan_bound_tasks_per_hour,
        lc_stretches: summary.last_plan_lc_stretches,
        overlap_ticks: summary.overlap_ticks,
        faults: summary.faults,
        high_conf_pct: mean_std(last.iter().map(|i| i.high_conf_pct)).0,
        wall_s,
        steady_tasks: steady.first().map_or(0, |s| s.tasks),
        plan_gap_per_task: PlanGap::mean(&per_task).unwrap_or_default(),
    })
}

/// `3600 / E[low-confidence seconds per task]` pooled over the rows of both cells (tasks per
/// hour): the throughput of one operator busy all the time, each task taking its
/// low-confidence seconds.
pub(crate) fn operator_limited_per_h(rows: &[CapacityRow], cells: &[CellRow]) -> f64 {
    let lc = rows
        .iter()
        .map(|r| r.lc_s_per_task)
        .chain(cells.iter().map(|r| r.lc_s_per_task));
    throughput_per_h(1, mean_std(lc).0)
}

/// The rounds table as Markdown (docs/study.md).
pub(crate) fn table(rows: &[CapacityRow]) -> String {
    let mut out = String::from(
        "| N | executions (rounds) | `T_total` (s) | planned (tasks/h) | measured (tasks/h) | \
         operator busy | robots waiting | LC s per task | high confidence (%) | overlaps |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out += &format!(
            "| {} | {} ({}) | {:.1} ± {:.1} | {:.1} | {:.1} | {:.0} % | {:.0} % | {:.1} | {:.1} | {} |\n",
            r.robots,
            r.executions,
            r.rounds,
            r.t_total_mean_s,
            r.t_total_std_s,
            r.throughput_per_h,
            r.steady_throughput_per_h,
            100.0 * r.operator_busy_share,
            100.0 * r.robot_wait_share,
            r.lc_s_per_task,
            r.high_conf_pct,
            r.overlap_ticks
        );
    }
    out
}

/// The continuous cell's table as Markdown (docs/study.md).
pub(crate) fn cell_table(rows: &[CellRow]) -> String {
    let mut out = String::from(
        "| N | tasks | measured (tasks/h) | last plan (tasks/h) | plan bound (tasks/h) | \
         operator busy | robots waiting | LC s per task | LC stretches | high confidence (%) \
         | overlaps |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out += &format!(
            "| {} | {} | {:.1} ± {:.1} | {:.1} | {:.1} | {:.0} % | {:.0} % | {:.1} | {:.1} | {:.1} | {} |\n",
            r.robots,
            r.tasks,
            r.steady_throughput_per_h,
            r.steady_throughput_std_per_h,
            r.plan_per_h,
            r.bound_per_h,
            100.0 * r.operator_busy_share,
            100.0 * r.robot_wait_share,
            r.lc_s_per_task,
            r.lc_stretches,
            r.high_conf_pct,
            r.overlap_ticks
        );
    }
    out
}

/// Runs `cargo xtask capacity`.
pub(crate) fn run(args: &CapacityArgs) -> anyhow::Result<()> {
    tandem::realtime::RobotCount::new(args.max_robots).map_err(|e| anyhow!("--max-robots: {e}"))?;
    let root = workspace_root();
    let (base, path) = read_config(args.config.as_deref())?;
    let inputs = StudyInputs::from_dir(&root.join("fixtures/sanding"))
        .context("reading the sanding fixtures")?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| root.join("results/capacity"));
    let seed = args.seed.unwrap_or(base.seed);
    if !args.merge.is_empty() {
        let (sizes, rows, cells) = read_runs(&args.merge)?;
        let mut deltas: Vec<f64> = rows
            .iter()
            .map(|r| r.switch_s)
            .chain(cells.iter().map(|r| r.switch_s))
            .collect();
        deltas.sort_by(f64::total_cmp);
        deltas.dedup();
        return report(&sizes, &rows, &cells, &deltas, &out, Instant::now());
    }
    let (do_rounds, do_cell) = match args.cell {
        CellChoice::Rounds => (true, false),
        CellChoice::Continuous => (false, true),
        CellChoice::Both => (true, true),
    };
    println!(
        "capacity ({}): N = {}..={} robots, {} trials × up to {} executions (rounded down to a \
         multiple of N), {} samples per schedule, seed {seed}; end of learning = the {}",
        match args.cell {
            CellChoice::Rounds => "rounds",
            CellChoice::Continuous => "continuous cell",
            CellChoice::Both => "rounds and continuous cell",
        },
        args.min_robots,
        args.max_robots,
        args.trials,
        args.executions,
        args.samples,
        args.steady_tasks.map_or_else(
            || format!("last {:.0} % of rounds or tasks", 100.0 * END_SHARE),
            |k| format!("last {k} tasks (whole rounds or periods; the rest a warm-up)")
        )
    );
    let wall = Instant::now();
    let (mut rows, mut cells) = (Vec::new(), Vec::new());
    let deltas = if args.switch_s.is_empty() {
        vec![base.operator.switch_s]
    } else {
        args.switch_s.clone()
    };
    if let Some(d) = deltas.iter().find(|d| !(d.is_finite() && **d >= 0.0)) {
        bail!("--switch-s {d}: a switch time is a finite number of seconds ≥ 0 (0: none)");
    }
    if !(1..=args.max_robots).contains(&args.min_robots) {
        bail!(
            "--min-robots {}: must be between 1 and --max-robots ({})",
            args.min_robots,
            args.max_robots
        );
    }
    if !args.operators.is_empty() {
        if !do_cell || args.min_robots != 1 || deltas.len() > 1 {
            bail!(
                "--operators runs the continuous cell after its one-operator rows N = 1, 2, …: \
                 give --cell continuous or both, --min-robots 1 and at most one --switch-s"
            );
        }
        if let Some(m) = args
            .operators
            .iter()
            .find(|&&m| !(1..=MAX_ROBOTS).contains(&m))
        {
            bail!("--operators {m}: a cell has 1 to {MAX_ROBOTS} operators");
        }
    }
    let runs = deltas
        .iter()
        .flat_map(|&d| (args.min_robots..=args.max_robots).map(move |n| (d, n)));
    for (delta, n) in runs {
        let mut config = StudyConfig {
            trials: args.trials,
            executions: args.executions / n * n,
            robots: n,
            samples: args.samples,
            seed,
            ..base.clone()
        };
        config.operator.switch_s = delta;
        let n_text = if deltas.len() > 1 || delta != 0.0 {
            format!("{n} at δ = {delta} s")
        } else {
            n.to_string()
        };
        config
            .validate()
            .with_context(|| format!("{} with N = {n_text}", path.display()))?;
        if do_rounds {
            let config = StudyConfig {
                cell: Cell::Rounds,
                ..config.clone()
            };
            let t = Instant::now();
            let bar = TrialBar::new(&config, &format!("rounds of N = {n}"))?;
            let (result, _) = run_study(&config, &inputs, &|p| bar.step(p))
                .with_context(|| format!("the study with N = {n} robots in rounds"))?;
            bar.clear();
            let r = row(&result, t.elapsed().as_secs_f64(), args.steady_tasks)?;
            println!(
                "N = {n_text}, rounds: T_total {:.1} ± {:.1} s, {:.1} tasks/h planned, {:.1} \
                 measured, operator busy {:.0} %, robots waiting {:.0} %, {} overlapping \
                 ticks ({:.1} s)",
                r.t_total_mean_s,
                r.t_total_std_s,
                r.throughput_per_h,
                r.steady_throughput_per_h,
                100.0 * r.operator_busy_share,
                100.0 * r.robot_wait_share,
                r.overlap_ticks,
                r.wall_s
            );
            rows.push(r);
        }
        if do_cell {
            let config = StudyConfig {
                cell: Cell::Continuous,
                ..config
            };
            let t = Instant::now();
            let bar = TrialBar::new(&config, &format!("re-plans of N = {n} (continuous)"))?;
            let (result, _) = run_cell_study(&config, &inputs, &|p| bar.step(p))
                .with_context(|| format!("the continuous study with N = {n} robots"))?;
            bar.clear();
            let r = cell_row(&result, t.elapsed().as_secs_f64(), args.steady_tasks)?;
            println!(
                "N = {n_text}, continuous: {:.1} ± {:.1} tasks/h measured, last plan {:.1} (bound \
                 {:.1}), operator busy {:.0} %, robots waiting {:.0} %, {} overlapping ticks, \
                 {} faults ({:.1} s)",
                r.steady_throughput_per_h,
                r.steady_throughput_std_per_h,
                r.plan_per_h,
                r.bound_per_h,
                100.0 * r.operator_busy_share,
                100.0 * r.robot_wait_share,
                r.overlap_ticks,
                r.faults,
                r.wall_s
            );
            println!(
                "  its {} measured tasks against the plan in force, per task: {}",
                r.steady_tasks,
                r.plan_gap_per_task.describe()
            );
            cells.push(r);
        }
    }
    let sizes = Sizes {
        trials: args.trials,
        samples: args.samples,
        seed,
        steady_tasks: args.steady_tasks,
    };
    let sizes = CellSizes {
        rounds: do_rounds.then_some(sizes),
        continuous: do_cell.then_some(sizes),
    };
    report(&sizes, &rows, &cells, &deltas, &out, wall)?;
    let fleet_over = if args.operators.is_empty() {
        0
    } else {
        let robots = if args.fleet_robots.is_empty() {
            vec![args.max_robots]
        } else {
            args.fleet_robots.clone()
        };
        let mut base = base.clone();
        base.trials = args.trials;
        base.samples = args.samples;
        base.executions = args.executions;
        base.seed = seed;
        base.operator.switch_s = deltas[0];
        crate::fleet::run(
            &base,
            &inputs,
            &cells,
            &robots,
            &args.operators,
            args.steady_tasks,
            &out,
        )?
    };
    if fleet_over > 0 {
        bail!("{fleet_over} ticks of the fleet had more than M robots low-confidence, or faults");
    }
    Ok(())
}

/// Prints the tables of `rows` and `cells` (run with `sizes`, at the switch times `deltas`)
/// and writes `capacity.json` and the figure under `out` (the switch-time figure for several
/// `δ`, else the figure against `N`); fails if any run had overlapping low-confidence ticks.
fn report(
    sizes: &CellSizes,
    rows: &[CapacityRow],
    cells: &[CellRow],
    deltas: &[f64],
    out: &Path,
    wall: Instant,
) -> anyhow::Result<()> {
    let (rows, cells) = (rows.to_vec(), cells.to_vec());
    let bound = operator_limited_per_h(&rows, &cells);
    if !rows.is_empty() {
        println!("\nrounds:");
        print!("{}", table(&rows));
    }
    if !cells.is_empty() {
        println!("\ncontinuous cell:");
        print!("{}", cell_table(&cells));
    }
    println!(
        "operator-limited bound: {bound:.1} tasks per hour (3600 / {:.1} s low-confidence \
         per task)",
        3600.0 / bound
    );
    let sweep = deltas.len() > 1 || deltas.iter().any(|&d| d != 0.0);
    if sweep {
        println!("\nthroughput against its proven bound, per switch time δ:");
        print!("{}", switch_table(&rows, &cells));
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let main = sizes
        .main()
        .ok_or_else(|| anyhow!("no rows to report (neither cell ran)"))?;
    let file = CapacityFile {
        trials: main.trials,
        samples: main.samples,
        seed: main.seed,
        end_share: END_SHARE,
        steady_tasks: main.steady_tasks,
        continuous_sizes: sizes.continuous_apart(),
        operator_limited_per_h: bound,
        rows: &rows,
        continuous: &cells,
    };
    let json_path = out.join("capacity.json");
    std::fs::write(&json_path, serde_json::to_string_pretty(&file)? + "\n")
        .with_context(|| format!("writing {}", json_path.display()))?;
    if deltas.len() > 1 {
        let name = |s: Option<Sizes>| {
            s.and_then(|s| s.steady_tasks)
                .map_or_else(|| "last 10 %".to_string(), |k| format!("last {k} tasks"))
        };
        let window = match (sizes.rounds, sizes.continuous) {
            (Some(r), Some(c)) if r.steady_tasks != c.steady_tasks => {
                format!("rounds {}, continuous {}", name(Some(r)), name(Some(c)))
            }
            _ => name(sizes.main()),
        };
        draw_switch(
            &rows,
            &cells,
            &window,
            &out.join("capacity_switch.svg"),
            &out.join("capacity_switch.png"),
        )?;
        println!(
            "wrote capacity.json, capacity_switch.svg, capacity_switch.png in {} ({:.1} s wall)",
            out.display(),
            wall.elapsed().as_secs_f64()
        );
    } else {
        draw_capacity(
            &rows,
            &cells,
            bound,
            &out.join("capacity.svg"),
            &out.join("capacity.png"),
        )?;
        println!(
            "wrote capacity.json, capacity.svg, capacity.png in {} ({:.1} s wall)",
            out.display(),
            wall.elapsed().as_secs_f64()
        );
    }
    let overlaps = rows.iter().map(|r| r.overlap_ticks as u64).sum::<u64>()
        + cells
            .iter()
            .map(|r| r.overlap_ticks + r.faults)
            .sum::<u64>();
    if overlaps > 0 {
        bail!("{overlaps} ticks had two or more robots low-confidence: a schedule is unsafe");
    }
    Ok(())
}

/// Image size (pixels; SVG user units): two panels side by side.
const SIZE_PX: (u32, u32) = (1500, 640);

/// Colour of the continuous cell's series (rounds use [`MEAN`]).
const CONTINUOUS: RGBColor = OPERATOR;

/// One series of the figure: its points `(N, value)`.
type Series = Vec<(f64, f64)>;

/// Draws, against `N`, the measured throughput of rounds and of the continuous cell with the
/// operator-limited bound (dashed) and the continuous plans' bounds (dotted) on the left, and
/// the operator's busy share and the robots' waiting share of both cells on the right, as SVG
/// and PNG.
///
/// # Errors
/// No rows at all, or a failure to render or write a file.
pub(crate) fn draw_capacity(
    rows: &[CapacityRow],
    cells: &[CellRow],
    bound_per_h: f64,
    svg: &Path,
    png: &Path,
) -> anyhow::Result<()> {
    if rows.is_empty() && cells.is_empty() {
        bail!("capacity figure: no robot counts to draw");
    }
    tandem_plot::register_font()?;
    let mut svg_text = String::new();
    {
        let root = SVGBackend::with_string(&mut svg_text, SIZE_PX).into_drawing_area();
        draw_on(&root, rows, cells, bound_per_h)?;
        root.present()
            .map_err(|e| anyhow!("finishing the capacity SVG: {e}"))?;
    }
    {
        let root = BitMapBackend::new(png, SIZE_PX).into_drawing_area();
        draw_on(&root, rows, cells, bound_per_h)?;
        root.present()
            .map_err(|e| anyhow!("writing {}: {e}", png.display()))?;
    }
    std::fs::write(svg, svg_text).with_context(|| format!("writing {}", svg.display()))?;
    Ok(())
}

fn draw_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    rows: &[CapacityRow],
    cells: &[CellRow],
    bound_per_h: f64,
) -> anyhow::Result<()> {
    let err = |what: &'static str| {
        move |e: DrawingAreaErrorKind<DB::ErrorType>| {
            anyhow!("drawing the capacity figure ({what}): {e}")
        }
    };
    root.fill(&WHITE).map_err(err("background"))?;
    let (left, right) = root.split_horizontally(SIZE_PX.0 / 2 + 40);
    let n_max = rows
        .iter()
        .map(|r| r.robots)
        .chain(cells.iter().map(|r| r.robots))
        .max()
        .unwrap_or(1) as f64;
    let x_range = 0.5..n_max + 0.5;
    let n_labels = n_max as usize;

    // Left: throughput.
    let rounds_tp: Series = rows
        .iter()
        .map(|r| (r.robots as f64, r.steady_throughput_per_h))
        .collect();
    let cell_tp: Series = cells
        .iter()
        .map(|r| (r.robots as f64, r.steady_throughput_per_h))
        .collect();
    let cell_bound: Series = cells
        .iter()
        .map(|r| (r.robots as f64, r.bound_per_h))
        .collect();
    let top = rounds_tp
        .iter()
        .chain(&cell_tp)
        .chain(&cell_bound)
        .map(|p| p.1)
        .fold(bound_per_h, f64::max);
    let y_max = crate::fig5::nice_ceiling(top * 1.45);
    let mut chart = ChartBuilder::on(&left)
        .margin(20)
        .caption("throughput", (FONT_FAMILY, 24))
        .x_label_area_size(60)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.clone(), 0.0..y_max)
        .map_err(err("throughput axes"))?;
    mesh_style!(
        chart
            .configure_mesh()
            .x_labels(n_labels)
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .x_desc("robots N run by one operator")
            .y_desc("throughput (tasks per hour per operator)")
    )
    .draw()
    .map_err(err("throughput mesh"))?;
    for (series, colour, label) in [
        (&rounds_tp, MEAN, "rounds (measured, last 10 %)"),
        (
            &cell_tp,
            CONTINUOUS,
            "continuous cell (measured, last 10 %)",
        ),
    ] {
        if series.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(series.clone(), colour.stroke_width(3)))
            .map_err(err("throughput"))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
            });
        chart
            .draw_series(series.iter().map(|&p| Circle::new(p, 5, colour.filled())))
            .map_err(err("throughput points"))?;
    }
    if !cell_bound.is_empty() {
        chart
            .draw_series(DashedLineSeries::new(
                cell_bound.clone(),
                3,
                5,
                CONTINUOUS.stroke_width(2),
            ))
            .map_err(err("plan bound"))?
            .label("continuous plan's bound 3600·N / P_lower")
            .legend(dashed_mark!(CONTINUOUS));
    }
    chart
        .draw_series(DashedLineSeries::new(
            [(0.5, bound_per_h), (n_max + 0.5, bound_per_h)],
            8,
            6,
            GROUND_TRUTH.stroke_width(3),
        ))
        .map_err(err("bound"))?
        .label("operator-limited bound 3600 / E[LC s per task]")
        .legend(dashed_mark!(GROUND_TRUTH));
    draw_legend!(
        chart,
        SeriesLabelPosition::UpperLeft,
        17,
        err("throughput legend")
    )?;

    // Right: the operator's busy share and the robots' waiting share.
    let pct = |v: f64| 100.0 * v;
    let mut chart = ChartBuilder::on(&right)
        .margin(20)
        .caption("operator and robots", (FONT_FAMILY, 24))
        .x_label_area_size(60)
        .y_label_area_size(70)
        .build_cartesian_2d(x_range, 0.0..140.0)
        .map_err(err("share axes"))?;
    mesh_style!(
        chart
            .configure_mesh()
            .x_labels(n_labels)
            .y_labels(8)
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&crate::legend::percent_label)
            .x_desc("robots N run by one operator")
            .y_desc("share of time (%)")
    )
    .draw()
    .map_err(err("share mesh"))?;
    let shares: [(Series, RGBColor, bool, &str); 4] = [
        (
            rows.iter()
                .map(|r| (r.robots as f64, pct(r.operator_busy_share)))
                .collect(),
            MEAN,
            true,
            "operator busy, rounds",
        ),
        (
            cells
                .iter()
                .map(|r| (r.robots as f64, pct(r.operator_busy_share)))
                .collect(),
            CONTINUOUS,
            true,
            "operator busy, continuous",
        ),
        (
            rows.iter()
                .map(|r| (r.robots as f64, pct(r.robot_wait_share)))
                .collect(),
            MEAN,
            false,
            "robots waiting, rounds",
        ),
        (
            cells
                .iter()
                .map(|r| (r.robots as f64, pct(r.robot_wait_share)))
                .collect(),
            CONTINUOUS,
            false,
            "robots waiting, continuous",
        ),
    ];
    for (series, colour, busy, label) in shares {
        if series.is_empty() {
            continue;
        }
        if busy {
            chart
                .draw_series(LineSeries::new(series.clone(), colour.stroke_width(3)))
                .map_err(err("busy share"))?
                .label(label)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
                });
            chart
                .draw_series(series.iter().map(|&p| Circle::new(p, 5, colour.filled())))
                .map_err(err("busy share points"))?;
        } else {
            chart
                .draw_series(DashedLineSeries::new(
                    series.clone(),
                    8,
                    6,
                    colour.stroke_width(3),
                ))
                .map_err(err("waiting share"))?
                .label(label)
                .legend(dashed_mark!(colour));
            chart
                .draw_series(
                    series
                        .iter()
                        .map(|&p| TriangleMarker::new(p, 7, colour.filled())),
                )
                .map_err(err("waiting share points"))?;
        }
    }
    draw_legend!(
        chart,
        SeriesLabelPosition::UpperLeft,
        17,
        err("share legend")
    )?;
    Ok(())
}

/// Throughput against its proven bound per switch time `δ` as Markdown: per cell, robot count
/// and `δ`, the measured throughput (last 10 %), the bound of the final plan's certificate
/// (rounds: `N·3600 / T*`; continuous: `3600·N / P_lower`, with the switch time in it), the
/// measured throughput as a share of that bound, and the operator's busy share.
pub(crate) fn switch_table(rows: &[CapacityRow], cells: &[CellRow]) -> String {
    let mut out = String::from(
        "| cell | N | δ (s) | measured (tasks/h) | planned (tasks/h) | proven bound (tasks/h) | \
         measured / bound | operator busy |\n|---|---|---|---|---|---|---|---|\n",
    );
    let line = |cell: &str, n: usize, d: f64, m: f64, p: f64, b: f64, busy: f64| {
        format!(
            "| {cell} | {n} | {d} | {m:.1} | {p:.1} | {b:.1} | {:.1} % | {:.0} % |\n",
            100.0 * m / b,
            100.0 * busy
        )
    };
    for r in rows {
        out += &line(
            "rounds",
            r.robots,
            r.switch_s,
            r.steady_throughput_per_h,
            r.throughput_per_h,
            r.bound_per_h,
            r.operator_busy_share,
        );
    }
    for r in cells {
        out += &line(
            "continuous",
            r.robots,
            r.switch_s,
            r.steady_throughput_per_h,
            r.plan_per_h,
            r.bound_per_h,
            r.operator_busy_share,
        );
    }
    out
}

/// Colours of the robot counts in the switch-time figure, cycled.
const N_COLOURS: [RGBColor; 4] = [MEAN, OPERATOR, GROUND_TRUTH, RGBColor(120, 120, 120)];

/// Draws, against the switch time `δ`, the measured throughput (solid, points) and the proven
/// bound (dashed) of every cell and robot count on the left, and the operator's busy share on
/// the right, as SVG and PNG (`cargo xtask capacity --switch-s 0,1,2,…`). Rounds are drawn
/// with circles, the continuous cell with triangles, each cell and robot count in a colour of
/// its own (cycled).
///
/// # Errors
/// No rows at all, or a failure to render or write a file.
pub(crate) fn draw_switch(
    rows: &[CapacityRow],
    cells: &[CellRow],
    window: &str,
    svg: &Path,
    png: &Path,
) -> anyhow::Result<()> {
    if rows.is_empty() && cells.is_empty() {
        bail!("switch-time figure: no rows to draw");
    }
    tandem_plot::register_font()?;
    let mut svg_text = String::new();
    {
        let root = SVGBackend::with_string(&mut svg_text, SIZE_PX).into_drawing_area();
        draw_switch_on(&root, rows, cells, window)?;
        root.present()
            .map_err(|e| anyhow!("finishing the switch-time SVG: {e}"))?;
    }
    {
        let root = BitMapBackend::new(png, SIZE_PX).into_drawing_area();
        draw_switch_on(&root, rows, cells, window)?;
        root.present()
            .map_err(|e| anyhow!("writing {}: {e}", png.display()))?;
    }
    std::fs::write(svg, svg_text).with_context(|| format!("writing {}", svg.display()))?;
    Ok(())
}

/// One line of the switch-time figure: its label, colour, whether continuous, and its
/// points `(δ, measured, bound, busy share)` in order of `δ`.
type SwitchLine = (String, RGBColor, bool, Vec<(f64, f64, f64, f64)>);

/// The lines of the switch-time figure, one per cell and robot count.
fn switch_lines(rows: &[CapacityRow], cells: &[CellRow]) -> Vec<SwitchLine> {
    let mut lines: Vec<SwitchLine> = Vec::new();
    let mut robots: Vec<usize> = rows
        .iter()
        .map(|r| r.robots)
        .chain(cells.iter().map(|r| r.robots))
        .collect();
    robots.sort_unstable();
    robots.dedup();
    for (k, &n) in robots.iter().enumerate() {
        // Rounds and the continuous cell of one robot count in two colours.
        let colour = N_COLOURS[(2 * k) % N_COLOURS.len()];
        let cell_colour = N_COLOURS[(2 * k + 1) % N_COLOURS.len()];
        let mut pts: Vec<(f64, f64, f64, f64)> = rows
            .iter()
            .filter(|r| r.robots == n)
            .map(|r| {
                (
                    r.switch_s,
                    r.steady_throughput_per_h,
                    r.bound_per_h,
                    r.operator_busy_share,
                )
            })
            .collect();
        if !pts.is_empty() {
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            lines.push((format!("rounds, N = {n}"), colour, false, pts));
        }
        let mut pts: Vec<(f64, f64, f64, f64)> = cells
            .iter()
            .filter(|r| r.robots == n)
            .map(|r| {
                (
                    r.switch_s,
                    r.steady_throughput_per_h,
                    r.bound_per_h,
                    r.operator_busy_share,
                )
            })
            .collect();
        if !pts.is_empty() {
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            lines.push((format!("continuous, N = {n}"), cell_colour, true, pts));
        }
    }
    lines
}

fn draw_switch_on<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    rows: &[CapacityRow],
    cells: &[CellRow],
    window: &str,
) -> anyhow::Result<()> {
    let err = |what: &'static str| {
        move |e: DrawingAreaErrorKind<DB::ErrorType>| {
            anyhow!("drawing the switch-time figure ({what}): {e}")
        }
    };
    root.fill(&WHITE).map_err(err("background"))?;
    let (left, right) = root.split_horizontally(SIZE_PX.0 / 2 + 40);
    let lines = switch_lines(rows, cells);
    let d_max = lines
        .iter()
        .flat_map(|l| l.3.iter().map(|p| p.0))
        .fold(0.0, f64::max)
        .max(1.0);
    let x_range = -0.05 * d_max..1.05 * d_max;
    let top = lines
        .iter()
        .flat_map(|l| l.3.iter().map(|p| p.1.max(p.2)))
        .fold(1.0, f64::max);
    let y_max = crate::fig5::nice_ceiling(top * 1.45);
    let mut chart = ChartBuilder::on(&left)
        .margin(20)
        .caption("throughput against the switch time", (FONT_FAMILY, 24))
        .x_label_area_size(60)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.clone(), 0.0..y_max)
        .map_err(err("throughput axes"))?;
    mesh_style!(
        chart
            .configure_mesh()
            .x_label_formatter(&|v| format!("{v:.1}"))
            .y_label_formatter(&|v| format!("{v:.0}"))
            .x_desc("the operator's switch time δ (s) the plans are made with")
            .y_desc("throughput (tasks per hour per operator)")
    )
    .draw()
    .map_err(err("throughput mesh"))?;
    for (label, colour, continuous, pts) in &lines {
        let colour = *colour;
        let measured: Series = pts.iter().map(|p| (p.0, p.1)).collect();
        let bound: Series = pts.iter().map(|p| (p.0, p.2)).collect();
        chart
            .draw_series(LineSeries::new(measured.clone(), colour.stroke_width(3)))
            .map_err(err("throughput"))?
            .label(format!("{label} (measured, {window})"))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
            });
        if *continuous {
            chart
                .draw_series(
                    measured
                        .iter()
                        .map(|&p| TriangleMarker::new(p, 7, colour.filled())),
                )
                .map_err(err("throughput points"))?;
        } else {
            chart
                .draw_series(measured.iter().map(|&p| Circle::new(p, 5, colour.filled())))
                .map_err(err("throughput points"))?;
        }
        chart
            .draw_series(DashedLineSeries::new(bound, 3, 5, colour.stroke_width(2)))
            .map_err(err("bound"))?
            .label(format!("{label}: proven bound"))
            .legend(dashed_mark!(colour));
    }
    draw_legend!(
        chart,
        SeriesLabelPosition::UpperRight,
        15,
        err("throughput legend")
    )?;

    let mut chart = ChartBuilder::on(&right)
        .margin(20)
        .caption("operator busy", (FONT_FAMILY, 24))
        .x_label_area_size(60)
        .y_label_area_size(70)
        .build_cartesian_2d(x_range, 0.0..140.0)
        .map_err(err("share axes"))?;
    mesh_style!(
        chart
            .configure_mesh()
            .y_labels(8)
            .x_label_formatter(&|v| format!("{v:.1}"))
            .y_label_formatter(&crate::legend::percent_label)
            .x_desc("the operator's switch time δ (s) the plans are made with")
            .y_desc("operator busy, share of time (%)")
    )
    .draw()
    .map_err(err("share mesh"))?;
    for (label, colour, continuous, pts) in &lines {
        let colour = *colour;
        let busy: Series = pts.iter().map(|p| (p.0, 100.0 * p.3)).collect();
        if *continuous {
            chart
                .draw_series(DashedLineSeries::new(
                    busy.clone(),
                    8,
                    6,
                    colour.stroke_width(3),
                ))
                .map_err(err("busy share"))?
                .label(label.clone())
                .legend(dashed_mark!(colour));
            chart
                .draw_series(
                    busy.iter()
                        .map(|&p| TriangleMarker::new(p, 7, colour.filled())),
                )
                .map_err(err("busy share points"))?;
        } else {
            chart
                .draw_series(LineSeries::new(busy.clone(), colour.stroke_width(3)))
                .map_err(err("busy share"))?
                .label(label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(3))
                });
            chart
                .draw_series(busy.iter().map(|&p| Circle::new(p, 5, colour.filled())))
                .map_err(err("busy share points"))?;
        }
    }
    draw_legend!(
        chart,
        SeriesLabelPosition::UpperLeft,
        17,
        err("share legend")
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn r(robots: usize, t: f64, busy: f64, lc: f64) -> CapacityRow {
        CapacityRow {
            robots,
            switch_s: 0.0,
            executions: 12 / robots * robots,
            rounds: 12 / robots,
            t_total_mean_s: t,
            t_total_std_s: 0.0,
            throughput_per_h: robots as f64 * 3600.0 / t,
            bound_per_h: robots as f64 * 3600.0 / (t - 10.0),
            steady_throughput_per_h: robots as f64 * 3600.0 / (t + 10.0),
            operator_busy_share: busy,
            robot_wait_share: 0.25,
            lc_s_per_task: lc,
            overlap_ticks: 0,
            high_conf_pct: 60.0,
            wall_s: 1.0,
        }
    }

    fn c(robots: usize, lc: f64) -> CellRow {
        CellRow {
            robots,
            switch_s: 0.0,
            tasks: 240,
            steady_throughput_per_h: 80.0,
            steady_throughput_std_per_h: 1.0,
            operator_busy_share: 0.95,
            robot_wait_share: 0.2,
            lc_s_per_task: lc,
            plan_per_h: 85.0,
            bound_per_h: 90.0,
            lc_stretches: 3.0,
            overlap_ticks: 0,
            faults: 0,
            high_conf_pct: 60.0,
            wall_s: 1.0,
            steady_tasks: 24,
            plan_gap_per_task: PlanGap::default(),
        }
    }

    #[test]
    fn the_operator_limited_bound_is_3600_over_the_mean_lc_time_per_task() {
        // 30 s and 50 s of supervision per task: 40 s on average, 90 tasks per hour.
        let rows = [r(1, 100.0, 0.3, 30.0), r(2, 120.0, 0.6, 50.0)];
        assert_eq!(operator_limited_per_h(&rows, &[]), 90.0);
        // A continuous row's 60 s pools with them: (30 + 50 + 60) / 3 s per task.
        let cells = [c(2, 60.0)];
        assert!((operator_limited_per_h(&rows, &cells) - 3600.0 * 3.0 / 140.0).abs() < 1e-9);
        let t = table(&rows);
        // 3600 / 110 = 32.7 and 2·3600 / 130 = 55.4 tasks per hour measured.
        assert!(
            t.contains(
                "| 1 | 12 (12) | 100.0 ± 0.0 | 36.0 | 32.7 | 30 % | 25 % | 30.0 | 60.0 | 0 |"
            ),
            "{t}"
        );
        assert!(
            t.contains(
                "| 2 | 12 (6) | 120.0 ± 0.0 | 60.0 | 55.4 | 60 % | 25 % | 50.0 | 60.0 | 0 |"
            ),
            "{t}"
        );
        let t = cell_table(&cells);
        assert!(
            t.contains(
                "| 2 | 240 | 80.0 ± 1.0 | 85.0 | 90.0 | 95 % | 20 % | 60.0 | 3.0 | 60.0 | 0 |"
            ),
            "{t}"
        );
    }

    #[test]
    fn the_row_takes_the_final_schedule_and_the_last_tenth_of_the_rounds() {
        use tandem::sim::study::{
            IterationRecord, RoundStats, ScheduleSource, StudyConfig, StudyResult, TrialResult,
        };
        // Three robots, 30 executions: 10 rounds, the last 10 % is round 9 alone. Round k
        // keeps the operator busy k/10 of the time and supervises 300·k ticks (10 ms) over the
        // three robots: k s per task.
        let record = |k: usize, t_total_s: f64| IterationRecord {
            iteration: k,
            t_total_s,
            offset_s: 1.0,
            high_conf_pct: 60.0,
            source: ScheduleSource::Sampled,
            lc_intervals_s: vec![vec![]; 3],
            round: (k < 10).then(|| RoundStats {
                overlap_ticks: 0,
                operator_idle_share: 1.0 - k as f64 / 10.0,
                duration_s: t_total_s,
                supervised_ticks: 300 * k,
                corrected_ticks: 0,
                operator_busy_share: k as f64 / 10.0,
                faults: 0,
                robot_wait_share: k as f64 / 20.0,
                hold_ticks: 0,
                plan_gap: tandem::sim::workcell::PlanGap::default(),
                needed_unsupervised: 0,
                switch_missed: 0,
                rest_s: 0.0,
            }),
            lower_bound_s: t_total_s,
            bound_is_optimum: false,
            gap: 0.0,
            gap_search: None,
            throughput_per_h: 3.0 * 3600.0 / t_total_s,
            offsets_s: vec![1.0, 2.0],
            falsely_trusted_samples: 0,
            lc_runs: vec![0; 3],
            error_rates: Default::default(),
            simulated_rates: None,
        };
        let trial = |k: usize, last_s: f64| TrialResult {
            trial: k,
            seed: k as u64,
            iterations: (0..=10)
                .map(|i| record(i, if i == 10 { last_s } else { 500.0 }))
                .collect(),
        };
        let result = StudyResult {
            config: StudyConfig {
                executions: 30,
                robots: 3,
                ..StudyConfig::default()
            },
            n_ref: 100,
            dt_s: 0.01,
            ground_truth_pct: 66.0,
            trials: vec![trial(0, 100.0), trial(1, 200.0)],
        };
        let row = row(&result, 1.0, None).unwrap();
        assert_eq!((row.robots, row.executions, row.rounds), (3, 30, 10));
        assert_eq!(row.t_total_mean_s, 150.0);
        assert!((row.t_total_std_s - 50.0 * 2f64.sqrt()).abs() < 1e-12);
        // 3·3600/100 = 108 and 3·3600/200 = 54 tasks per hour: mean 81.
        assert_eq!(row.throughput_per_h, 81.0);
        assert!((row.operator_busy_share - 0.9).abs() < 1e-15);
        assert!((row.lc_s_per_task - 9.0).abs() < 1e-12);
        assert!((row.robot_wait_share - 0.45).abs() < 1e-15);
        // The last round of each trial (round 9) took 500 s for three tasks: 21.6 per hour.
        assert!((row.steady_throughput_per_h - 21.6).abs() < 1e-12);
        assert_eq!(row.overlap_ticks, 0);
    }

    #[test]
    fn the_switch_sweep_tables_and_draws_each_cell_against_its_bound() {
        let rows: Vec<CapacityRow> = [0.0, 2.0]
            .iter()
            .map(|&d| CapacityRow {
                switch_s: d,
                ..r(3, 100.0 + 10.0 * d, 0.9, 30.0)
            })
            .collect();
        let cells: Vec<CellRow> = [0.0, 2.0]
            .iter()
            .map(|&d| CellRow {
                switch_s: d,
                steady_throughput_per_h: 90.0 - 5.0 * d,
                bound_per_h: 100.0 - 5.0 * d,
                ..c(3, 30.0)
            })
            .collect();
        let t = switch_table(&rows, &cells);
        // Rounds at δ = 2: T_total 120 s, measured 3·3600/130 = 83.1, planned 3·3600/120 =
        // 90.0, bound 3·3600/110 = 98.2 tasks/h: 84.6 % of it.
        assert!(
            t.contains("| rounds | 3 | 2 | 83.1 | 90.0 | 98.2 | 84.6 % | 90 % |"),
            "{t}"
        );
        // Continuous at δ = 2: 80 of 90 tasks/h, 88.9 %.
        assert!(
            t.contains("| continuous | 3 | 2 | 80.0 | 85.0 | 90.0 | 88.9 % | 95 % |"),
            "{t}"
        );
        let dir = crate::fig5::tests::scratch_dir("capacity-switch");
        let (svg, png) = (dir.join("s.svg"), dir.join("s.png"));
        draw_switch(&rows, &cells, "last 10 %", &svg, &png).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for label in [
            "the operator&apos;s switch time δ (s) the plans are made with",
            "continuous, N = 3: proven bound",
            "rounds, N = 3 (measured, last 10 %)",
            "operator busy, share of time (%)",
        ] {
            assert!(
                text.contains(label) || text.contains(&label.replace("&apos;", "'")),
                "{label}"
            );
        }
        assert!(draw_switch(&[], &[], "last 10 %", &svg, &png).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Writes a `capacity.json` of `rows` and `cells` run with `sizes` (both cells) into a
    /// new folder `dir/name`, as `report` does.
    fn run_dir(
        dir: &Path,
        name: &str,
        sizes: Sizes,
        rows: &[CapacityRow],
        cells: &[CellRow],
    ) -> PathBuf {
        let out = dir.join(name);
        let sizes = CellSizes {
            rounds: (!rows.is_empty()).then_some(sizes),
            continuous: (!cells.is_empty()).then_some(sizes),
        };
        report(&sizes, rows, cells, &[0.0], &out, Instant::now()).unwrap();
        out
    }

    #[test]
    fn merge_checks_the_sizes_of_each_cell_apart() {
        let dir = crate::fig5::tests::scratch_dir("capacity-merge");
        let rounds = Sizes {
            trials: 1,
            samples: 1000,
            seed: 2023,
            steady_tasks: None,
        };
        let continuous = Sizes {
            trials: 2,
            samples: 200,
            ..rounds
        };
        let at = |d: f64| CapacityRow {
            switch_s: d,
            ..r(3, 150.0, 0.6, 30.0)
        };
        let cell_at = |d: f64| CellRow {
            switch_s: d,
            ..c(3, 30.0)
        };
        let r0 = run_dir(&dir, "r0", rounds, &[at(0.0)], &[]);
        let r1 = run_dir(&dir, "r1", rounds, &[at(1.0)], &[]);
        let c0 = run_dir(&dir, "c0", continuous, &[], &[cell_at(0.0)]);
        // Rounds and continuous runs of different sizes merge, each cell keeping its own.
        let (sizes, rows, cells) = read_runs(&[r0.clone(), c0.clone(), r1.clone()]).unwrap();
        assert_eq!(sizes.rounds, Some(rounds));
        assert_eq!(sizes.continuous, Some(continuous));
        assert_eq!((rows.len(), cells.len()), (2, 1));
        // The merged file records the continuous cell's sizes apart and reads back the same.
        let merged = dir.join("merged");
        report(&sizes, &rows, &cells, &[0.0, 1.0], &merged, Instant::now()).unwrap();
        let text = std::fs::read_to_string(merged.join("capacity.json")).unwrap();
        assert!(text.contains("\"continuous_sizes\""), "{text}");
        let (again, rows2, cells2) = read_runs(std::slice::from_ref(&merged)).unwrap();
        assert_eq!(again, sizes);
        assert_eq!((rows2, cells2), (rows, cells));
        // A run with both cells at one size has no separate continuous sizes.
        let both = run_dir(&dir, "both", rounds, &[at(2.0)], &[cell_at(2.0)]);
        let text = std::fs::read_to_string(both.join("capacity.json")).unwrap();
        assert!(!text.contains("continuous_sizes"), "{text}");
        // Two runs of one cell at different sizes are refused, naming the cell and both folders.
        let err = read_runs(&[r0.clone(), both.clone(), c0.clone()])
            .unwrap_err()
            .to_string();
        assert!(err.contains("the continuous rows of"), "{err}");
        assert!(err.contains("c0") && err.contains("both"), "{err}");
        // The field that differs, with both values and the flag to re-run with.
        assert!(
            err.contains("trials 2") && err.contains("trials 1") && err.contains("--trials"),
            "{err}"
        );
        assert!(
            err.contains("samples 200") && err.contains("samples 1000"),
            "{err}"
        );
        assert!(!err.contains("seed"), "{err}");
        let r2 = run_dir(
            &dir,
            "r2",
            Sizes {
                trials: 2,
                ..rounds
            },
            &[at(2.0)],
            &[],
        );
        let err = read_runs(&[r0, merged, r2]).unwrap_err().to_string();
        assert!(
            err.contains("the rounds rows of") && err.contains("r2"),
            "{err}"
        );
        assert!(
            err.contains("trials 2") && !err.contains("samples"),
            "{err}"
        );
        assert!(read_runs(&[]).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A measurement, not a check (docs/decisions.md, "Three robots at δ ≥ 1 s: per-pair
    /// clearances on the dwelled schedule (issue 41)"): the state file `TANDEM_STATE` (e.g. a
    /// `trial_0.tandem` of `cargo xtask study --robots 3 --switch-s 1 --save-state DIR`)
    /// re-scheduled at each switch time of `TANDEM_SWITCH_S` (comma-separated, s) with 200
    /// samples, printing `T_total`, the source and the `δ`-bound. Run with
    /// `TANDEM_STATE=… TANDEM_SWITCH_S=1,2,5 cargo test -p xtask --bin xtask --
    /// --ignored --nocapture reschedule_a_saved_state`.
    #[test]
    #[ignore = "a measurement on a saved state (TANDEM_STATE), minutes"]
    fn reschedule_a_saved_state() {
        let path = std::env::var("TANDEM_STATE").expect("TANDEM_STATE: a saved .tandem file");
        let switches = std::env::var("TANDEM_SWITCH_S").unwrap_or_else(|_| "1".into());
        for sw in switches.split(',') {
            let sw: f64 = sw
                .trim()
                .parse()
                .expect("TANDEM_SWITCH_S: numbers, comma-separated");
            let mut planner = tandem::Planner::load(&path).unwrap();
            let serial_s = planner.outcome().t_total_s;
            let sampler = tandem::schedule::SamplerParams {
                samples: 200,
                switch_s: sw,
                ..planner.params().sampler.clone()
            };
            let start = Instant::now();
            let out = planner.reschedule(&sampler).unwrap();
            eprintln!(
                "δ = {sw} s: T_total {:.2} s ({}), δ-bound {:.2} s, saved {serial_s:.2} s, \
                 {} margin checks, {:.0} s",
                out.t_total_s,
                out.source.name(),
                out.lower_bound_s,
                out.stats.completion_margin_checks,
                start.elapsed().as_secs_f64()
            );
        }
    }

    #[test]
    fn the_figure_renders_with_its_labels() {
        let dir = crate::fig5::tests::scratch_dir("capacity");
        let rows: Vec<CapacityRow> = (1..=4)
            .map(|n| r(n, 90.0 + 20.0 * n as f64, 0.2 * n as f64, 30.0))
            .collect();
        let cells: Vec<CellRow> = (1..=4).map(|n| c(n, 30.0)).collect();
        let (svg, png) = (dir.join("c.svg"), dir.join("c.png"));
        draw_capacity(&rows, &cells, 120.0, &svg, &png).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for label in [
            "robots N run by one operator",
            "throughput (tasks per hour per operator)",
            "share of time (%)",
            "operator-limited bound",
            "continuous cell (measured, last 10 %)",
            "robots waiting, rounds",
            "operator busy, continuous",
        ] {
            assert!(text.contains(label), "{label}");
        }
        assert_eq!(
            crate::fig5::tests::png_size(&std::fs::read(&png).unwrap()),
            SIZE_PX
        );
        // One cell alone draws too.
        draw_capacity(&[], &cells, 120.0, &svg, &png).unwrap();
        assert!(draw_capacity(&[], &[], 1.0, &svg, &png).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
