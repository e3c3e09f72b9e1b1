//! `cargo xtask study --cell-file FILE`: the simulated study with a cell of different tasks
//! on different robots (issue 45). The cell file (docs/formats.md, "Cell file") names each
//! task's demonstrations, robots, hold rules and ground truth. A cell of one task with the
//! sanding labels as its truth is today's study on that task's demonstrations and robots
//! (study.json identical); a cell of two or more tasks runs
//! `tandem::sim::study::run_mixed_study` in rounds and writes `study.json` with, per
//! iteration, `T_total` against the mixed lower bound and each task's high confidence
//! against its truth; with `--cell continuous` it runs
//! `tandem::sim::study::run_mixed_cell_study` (the mixed cyclic plan run and re-planned as
//! the tasks learn) and writes each trial's plans, completions and steady throughput
//! against the plan and the mixed operator-limited bound.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, bail};
use serde::Serialize;
use tandem::sim::study::{
    CellFile, CellTruth, MixedCellStudyResult, MixedStudyResult, StudyConfig, mean_std,
};

use crate::study::{TrialBar, git_revision};

/// Reads a cell file; returns it with its folder (the base of its relative paths).
pub(crate) fn read_cell_file(path: &Path) -> anyhow::Result<(CellFile, PathBuf)> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("reading cell file {}", path.display()))?;
    let file: CellFile = toml::from_str(&text).with_context(|| {
        format!(
            "parsing cell file {} (docs/formats.md, \"Cell file\")",
            path.display()
        )
    })?;
    if file.task.is_empty() {
        bail!(
            "cell file {}: no [[task]]: give at least one",
            path.display()
        );
    }
    let dir = path
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    Ok((file, dir))
}

/// Whether the cell file is one task with the sanding labels as its truth: today's study.
pub(crate) fn is_single_labels(file: &CellFile) -> bool {
    file.task.len() == 1 && file.task[0].truth == CellTruth::Labels
}

/// One iteration across trials: means and standard deviations.
#[derive(Serialize)]
struct MixedSummary {
    iteration: usize,
    t_total_mean_s: f64,
    t_total_std_s: f64,
    lower_bound_mean_s: f64,
    /// Mean of `T_total / lower bound − 1` across trials.
    gap_mean: f64,
    /// Per task: mean high confidence (%).
    high_conf_pct_mean: Vec<f64>,
    /// Per task: mean falsely trusted samples.
    falsely_trusted_mean: Vec<f64>,
}

/// What `study.json` holds for a mixed cell.
#[derive(Serialize)]
struct MixedStudyFile<'a> {
    git_revision: String,
    /// "rounds, mixed tasks".
    cell: &'static str,
    /// Per task (the cell's order): the share of its reference where its truth never needs
    /// the operator (%), the most its confidence can truthfully trust.
    truth_never_needed_pct: Vec<f64>,
    summary: Vec<MixedSummary>,
    config: &'a StudyConfig,
    result: &'a MixedStudyResult,
}

fn summarize(result: &MixedStudyResult) -> Vec<MixedSummary> {
    let n_iter = result.trials[0].iterations.len();
    let n_tasks = result.tasks.len();
    (0..n_iter)
        .map(|k| {
            let its: Vec<_> = result.trials.iter().map(|t| &t.iterations[k]).collect();
            let (t_mean, t_std) = mean_std(its.iter().map(|i| i.t_total_s));
            let (lb, _) = mean_std(its.iter().map(|i| i.lower_bound_s));
            let (gap, _) = mean_std(its.iter().map(|i| i.t_total_s / i.lower_bound_s - 1.0));
            MixedSummary {
                iteration: k,
                t_total_mean_s: t_mean,
                t_total_std_s: t_std,
                lower_bound_mean_s: lb,
                gap_mean: gap,
                high_conf_pct_mean: (0..n_tasks)
                    .map(|t| mean_std(its.iter().map(|i| i.tasks[t].high_conf_pct)).0)
                    .collect(),
                falsely_trusted_mean: (0..n_tasks)
                    .map(|t| {
                        mean_std(
                            its.iter()
                                .map(|i| i.tasks[t].falsely_trusted_samples as f64),
                        )
                        .0
                    })
                    .collect(),
            }
        })
        .collect()
}

/// Runs the study of a cell of two or more tasks (or one task with a need file) in rounds;
/// writes `study.json` into `out` and prints the summary. `config.robots` is set to the
/// cell's robots and, unless `executions_given`, its executions rounded down to whole rounds.
pub(crate) fn run_mixed(
    mut config: StudyConfig,
    file: &CellFile,
    dir: &Path,
    executions_given: bool,
    out: &Path,
    root: &Path,
) -> anyhow::Result<()> {
    let wall = Instant::now();
    let n = file.n_robots();
    config.robots = n;
    if !executions_given {
        config.executions = (config.executions / n.max(1)) * n;
    }
    config
        .validate()
        .context("study configuration with the cell file's robots")?;
    let t = Instant::now();
    let tasks = file
        .tasks(dir, &config)
        .context("fitting the cell's tasks")?;
    let fit_s = t.elapsed().as_secs_f64();
    let bar = TrialBar::new(&config, "rounds")?;
    let result = tandem::sim::study::run_mixed_study(&config, &tasks, &|p| bar.step(p))?;
    bar.finish();
    let summary = summarize(&result);
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let study = MixedStudyFile {
        git_revision: git_revision(root),
        cell: "rounds, mixed tasks",
        truth_never_needed_pct: tasks
            .iter()
            .map(|t| 100.0 * t.truth.never_needed_share())
            .collect(),
        summary,
        config: &config,
        result: &result,
    };
    let path = out.join("study.json");
    std::fs::write(&path, serde_json::to_string(&study)? + "\n")
        .with_context(|| format!("writing {}", path.display()))?;
    let names: Vec<String> = file
        .task
        .iter()
        .map(|t| format!("{} {}", t.robots, t.name))
        .collect();
    println!(
        "mixed cell {}: {} trials × {} rounds, seed {}",
        names.join(" + "),
        config.trials,
        config.n_rounds(),
        config.seed
    );
    let (first, last) = (&study.summary[0], &study.summary[study.summary.len() - 1]);
    println!(
        "T_total: {:.2} ± {:.2} s (bound {:.2} s) at iteration 0 → {:.2} ± {:.2} s (bound \
         {:.2} s, gap {:.1} %) at iteration {}",
        first.t_total_mean_s,
        first.t_total_std_s,
        first.lower_bound_mean_s,
        last.t_total_mean_s,
        last.t_total_std_s,
        last.lower_bound_mean_s,
        100.0 * last.gap_mean,
        last.iteration
    );
    for (t, task) in file.task.iter().enumerate() {
        println!(
            "  task {}: high confidence {:.1} % → {:.1} % (truth never needs the operator on \
             {:.1} %), falsely trusted {:.1} samples at the end",
            task.name,
            first.high_conf_pct_mean[t],
            last.high_conf_pct_mean[t],
            study.truth_never_needed_pct[t],
            last.falsely_trusted_mean[t]
        );
    }
    // The cell run continuously on each trial's last problems: the mixed cyclic plan
    // (`tandem::planner::CellPlanner::continuous_plan`) against the bound of its ratios, the
    // mixed operator-limited bound (3600 over the mean operator-seconds per task of the
    // mix) and the best any ratios r ∈ {1..4}^N allow (docs/decisions.md).
    for trial in &result.trials {
        let c = &trial.continuous_plan;
        println!(
            "  trial {}, last plan, continuous: ratios {:?} (tasks per robot per period), \
             period {:.2} s (bound {:.2} s, gap {:.1} %), {:.1} tasks/h = {:.1} % of the mixed \
             operator-limited bound {:.1} tasks/h of these ratios, {:.1} % of the best bound \
             {:.1} tasks/h (operator busy {:.1} %; {} ratio vectors, {} orders evaluated)",
            trial.trial,
            c.ratios,
            c.period_s,
            c.lower_bound_s,
            100.0 * c.gap,
            c.tasks_per_hour,
            100.0 * c.tasks_per_hour / c.operator_limited_per_hour,
            c.operator_limited_per_hour,
            100.0 * c.tasks_per_hour / c.best_bound_per_hour,
            c.best_bound_per_hour,
            100.0 * c.operator_share,
            c.ratios_evaluated,
            c.orders_evaluated
        );
    }
    let (overlaps, faults) = result.overlaps_and_faults();
    println!("overlapping low-confidence ticks: {overlaps}, faults: {faults}");
    println!(
        "wrote {} (fit {:.1} s, wall {:.1} s)",
        path.display(),
        fit_s,
        wall.elapsed().as_secs_f64()
    );
    if overlaps > 0 || faults > 0 {
        bail!("two robots were low-confidence in the same tick: the cell is unsafe");
    }
    Ok(())
}

/// What `study.json` holds for a continuous mixed cell.
#[derive(Serialize)]
struct MixedCellStudyFile<'a> {
    git_revision: String,
    /// "continuous, mixed tasks".
    cell: &'static str,
    /// Per task (the cell's order): the share of its reference where its truth never needs
    /// the operator (%).
    truth_never_needed_pct: Vec<f64>,
    config: &'a StudyConfig,
    result: &'a MixedCellStudyResult,
}

/// Runs the continuous study of a cell of two or more tasks (or one task with a need file):
/// `config.executions` tasks per trial (the cell's, every robot's together); writes
/// `study.json` into `out` and prints, per trial, the steady throughput against the last
/// plan and the mixed operator-limited bound, and each task's learnt confidence against its
/// truth.
pub(crate) fn run_mixed_continuous(
    mut config: StudyConfig,
    file: &CellFile,
    dir: &Path,
    out: &Path,
    root: &Path,
) -> anyhow::Result<()> {
    let wall = Instant::now();
    config.robots = file.n_robots();
    config
        .validate()
        .context("study configuration with the cell file's robots")?;
    let t = Instant::now();
    let tasks = file
        .tasks(dir, &config)
        .context("fitting the cell's tasks")?;
    let fit_s = t.elapsed().as_secs_f64();
    let bar = TrialBar::new(&config, "rounds")?;
    let result = tandem::sim::study::run_mixed_cell_study(&config, &tasks, &|p| bar.step(p))?;
    bar.finish();
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let study = MixedCellStudyFile {
        git_revision: git_revision(root),
        cell: "continuous, mixed tasks",
        truth_never_needed_pct: tasks
            .iter()
            .map(|t| 100.0 * t.truth.never_needed_share())
            .collect(),
        config: &config,
        result: &result,
    };
    let path = out.join("study.json");
    std::fs::write(&path, serde_json::to_string(&study)? + "\n")
        .with_context(|| format!("writing {}", path.display()))?;
    let names: Vec<String> = file
        .task
        .iter()
        .map(|t| format!("{} {}", t.robots, t.name))
        .collect();
    println!(
        "mixed continuous cell {}: {} trials × {} tasks, seed {}",
        names.join(" + "),
        config.trials,
        config.executions,
        config.seed
    );
    for trial in &result.trials {
        let (first, last) = (
            &trial.iterations[0],
            &trial.iterations[trial.iterations.len() - 1],
        );
        let s = &trial.steady;
        println!(
            "  trial {}: {} plans ({} hand-overs), last ratios {:?}, period {:.2} s (bound \
             {:.2} s), groups per task {:?}; plan {:.1} tasks/h, mixed operator-limited bound \
             {:.1} tasks/h (plan {:.1} % of it); steady (last {} tasks, {:.0} s, per robot \
             {:?}): {:.1} tasks/h = {:.1} % of the plan, {:.1} % of the operator-limited \
             bound, {:.1} % of the best bound {:.1} tasks/h of any plan the token rule can run \
             (ratios ≤ {}; robot- and operator-limited; no such plan exceeds {:.1} % of its \
             operator-limited bound), operator busy {:.1} %; unrecorded at the end {:?}; \
             groups nested {}",
            trial.trial,
            trial.iterations.len(),
            trial.stats.hand_overs,
            last.ratios,
            last.period_s,
            last.lower_bound_s,
            last.groups,
            last.tasks_per_hour,
            last.operator_limited_per_hour,
            100.0 * last.tasks_per_hour / last.operator_limited_per_hour,
            s.tasks,
            s.duration_s,
            s.tasks_per_robot,
            s.throughput_per_h,
            100.0 * s.throughput_per_h / last.tasks_per_hour,
            100.0 * s.throughput_per_h / last.operator_limited_per_hour,
            100.0 * s.throughput_per_h / last.best_bound_per_hour,
            last.best_bound_per_hour,
            last.max_ratio,
            100.0 * last.best_operator_limited_share,
            100.0 * s.operator_busy_share,
            trial.unrecorded,
            trial.nested_groups
        );
        println!(
            "    first plan: ratios {:?}, {:.1} tasks/h against the bound {:.1} tasks/h",
            first.ratios, first.tasks_per_hour, first.operator_limited_per_hour
        );
        for (k, task) in file.task.iter().enumerate() {
            println!(
                "    task {}: high confidence {:.1} % → {:.1} % (truth never needs the \
                 operator on {:.1} %), falsely trusted {} samples at the end, {} rounds recorded \
                 in {} record steps",
                task.name,
                first.tasks[k].high_conf_pct,
                last.tasks[k].high_conf_pct,
                study.truth_never_needed_pct[k],
                last.tasks[k].falsely_trusted_samples,
                last.task_rounds[k],
                last.records
            );
        }
    }
    let (overlaps, faults) = result.overlaps_and_faults();
    println!("overlapping low-confidence ticks: {overlaps}, faults: {faults}");
    println!(
        "wrote {} (fit {:.1} s, wall {:.1} s)",
        path.display(),
        fit_s,
        wall.elapsed().as_secs_f64()
    );
    if overlaps > 0 || faults > 0 {
        bail!("two robots were low-confidence in the same tick: the cell is unsafe");
    }
    Ok(())
}
