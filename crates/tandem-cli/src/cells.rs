//! A cell of different tasks on different robots (issue 45): `fit --task NAME=FILES…
//! --robots NAME=K,…`, and `record` and `inspect` of a state file that holds such a cell
//! (format 12, `tandem::planner::CellPlanner`). A state of one task goes through the
//! single-task commands unchanged.

use std::io::Read;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use tandem::lfd::Demonstration;
use tandem::planner::state::{CELL_FORMAT_VERSION, MAGIC};
use tandem::planner::{CellPlanner, TaskSpec};
use tandem::{ExecutionRecord, PlannerParams};

use crate::cli::{FitArgs, InspectArgs, RecordArgs, RobotsArg, ScheduleArgs};
use crate::cmd::{out, period_notes, read_execution, secs};
use crate::{bag, state_io};

/// Whether `path` is a state file of a cell of two or more tasks (its header says format
/// [`CELL_FORMAT_VERSION`]); `false` for anything else, which the single-task commands read
/// (or refuse) as before.
pub(crate) fn is_cell(path: &Path) -> bool {
    let mut head = [0u8; 12];
    std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok()
        && head[..8] == MAGIC
        && u32::from_le_bytes([head[8], head[9], head[10], head[11]]) == CELL_FORMAT_VERSION
}

/// Parses one `--task NAME=FILE,…`.
fn parse_task(arg: &str) -> Result<(String, Vec<PathBuf>)> {
    let Some((name, files)) = arg.split_once('=') else {
        bail!(
            "--task {arg}: give NAME=FILE,… (the task's name, then its demonstration files, \
             e.g. --task sanding=demo_0.csv,demo_1.csv)"
        );
    };
    let files: Vec<PathBuf> = files
        .split(',')
        .filter(|f| !f.trim().is_empty())
        .map(|f| PathBuf::from(f.trim()))
        .collect();
    if files.len() < 2 {
        bail!(
            "--task {arg}: {} demonstration file(s); the variability of a task needs at least 2 \
             (give every demonstration file after `{name}=`, separated by commas)",
            files.len()
        );
    }
    Ok((name.trim().to_string(), files))
}

/// `tandem fit --task NAME=FILE,… [--robots NAME=K,…] -o STATE`.
pub(crate) fn fit_cell(a: &FitArgs, params: PlannerParams) -> Result<()> {
    let tasks = a
        .task
        .iter()
        .map(|t| parse_task(t))
        .collect::<Result<Vec<_>>>()?;
    let per_task = match &a.robots {
        None => Vec::new(),
        Some(RobotsArg::PerTask(p)) => p.clone(),
        Some(RobotsArg::Count(n)) => bail!(
            "--robots {n}: with --task give each task's robots as NAME=K,… (e.g. --robots {}=2)",
            tasks[0].0
        ),
    };
    for (name, _) in &per_task {
        if !tasks.iter().any(|(t, _)| t == name) {
            bail!(
                "--robots {name}=…: no task `{name}` (the tasks: {}); name a task of --task",
                tasks
                    .iter()
                    .map(|(t, _)| t.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    state_io::check_file_target(&a.output)?;
    let held = CellPlanner::rounds_at(&a.output).with_context(|| {
        format!(
            "{}: cannot tell whether it holds recorded rounds; write to another file",
            a.output.display()
        )
    })?;
    if held > 0 {
        bail!(
            "{}: holds {held} recorded round(s) (the operator's corrections), which a new fit \
             would discard; nothing was written. Write the new cell to another file (-o)",
            a.output.display()
        );
    }
    let mut specs = Vec::with_capacity(tasks.len());
    for (name, files) in &tasks {
        let mut task_params = params.clone();
        let demos: Vec<Demonstration> = bag::read_demos(
            files,
            a.dt,
            a.rate,
            &a.topics,
            &mut task_params.fit.schema,
            a.resample,
        )
        .with_context(|| format!("task `{name}`"))?;
        period_notes(&demos.iter().collect::<Vec<_>>(), "");
        let robots = per_task
            .iter()
            .rev()
            .find(|(t, _)| t == name)
            .map_or(1, |&(_, k)| k);
        specs.push(TaskSpec {
            name: name.clone(),
            demos,
            params: task_params,
            robots,
        });
    }
    let cell = CellPlanner::fit(&specs).context("cannot fit the cell")?;
    cell.save(&a.output)?;
    out(&format!(
        "fitted a cell of {} task(s), {} robots",
        cell.tasks().len(),
        cell.n_robots()
    ));
    summary(&cell);
    if !cell.is_mixed() {
        out(&format!(
            "one task: saved as its planner's state file (format 11; the name `{}` is not \
             stored, it reads back as `task`)",
            cell.tasks()[0].name()
        ));
    }
    out(&format!("saved {}", a.output.display()));
    Ok(())
}

/// The robots (1-based) of task `t`, as text (`robots 1, 2` or `robot 3`).
fn robots_text(cell: &CellPlanner, t: usize) -> String {
    let robots: Vec<String> = cell
        .robot_task()
        .iter()
        .enumerate()
        .filter(|&(_, &x)| x == t)
        .map(|(i, _)| (i + 1).to_string())
        .collect();
    format!(
        "robot{} {}",
        if robots.len() == 1 { "" } else { "s" },
        robots.join(", ")
    )
}

/// Per task its robots, reference, channels, confidence and rounds; then the cell's
/// schedule.
fn summary(cell: &CellPlanner) {
    for (t, task) in cell.tasks().iter().enumerate() {
        let p = task.planner();
        let m = p.model();
        let c = p.confidence();
        out(&format!(
            "task {}: {}; reference {} samples × {} s = {:.2} s; channels: {}",
            task.name(),
            robots_text(cell, t),
            m.n_ref(),
            secs(m.dt_s()),
            m.n_ref() as f64 * m.dt_s(),
            m.channel_names().join(", ")
        ));
        out(&format!(
            "task {}: high confidence {:.1} % of reference samples ({} of {}), {} \
             low-confidence regions; {} round(s) recorded",
            task.name(),
            100.0 * c.high_share(),
            c.n_high(),
            c.n_ref(),
            c.low_regions().len(),
            p.rounds_recorded()
        ));
    }
    match cell.schedule() {
        Some(s) => {
            out(&format!(
                "schedule (rounds, every robot its own task): T_total {:.2} s, lower bound \
                 {:.2} s (gap {:.2} s), tick {} s",
                s.t_total_s,
                s.lower_bound_s,
                s.gap_s(),
                secs(s.tick_s)
            ));
            let starts: Vec<String> = (0..cell.n_robots())
                .map(|i| {
                    format!(
                        "robot {} ({}) at {:.2} s",
                        i + 1,
                        cell.tasks()[cell.robot_task()[i]].name(),
                        s.start_s(i)
                    )
                })
                .collect();
            out(&format!("schedule: {}", starts.join(", ")));
        }
        None => out(&format!(
            "schedule (rounds): T_total {:.2} s",
            cell.t_total_s()
        )),
    }
}

/// `tandem inspect` of a cell of two or more tasks: per task its robots, model, confidence
/// and rounds, then the cell's schedule; `--json`: [`cell_doc`].
pub(crate) fn inspect_cell(a: &InspectArgs) -> Result<()> {
    let cell = CellPlanner::load(&a.state).context("cannot load the state")?;
    if a.json {
        out(&serde_json::to_string_pretty(&cell_doc(&cell, &a.state)?)?);
        return Ok(());
    }
    out(&format!(
        "{}: a cell of {} tasks, {} robots, {} round(s) recorded",
        a.state.display(),
        cell.tasks().len(),
        cell.n_robots(),
        cell.rounds_recorded()
    ));
    summary(&cell);
    Ok(())
}

/// Robot `i`'s label in a cell's chart and lists: `robot 1 (sanding)` (1-based, its task).
fn robot_label(cell: &CellPlanner, i: usize) -> String {
    format!(
        "robot {} ({})",
        i + 1,
        cell.tasks()[cell.robot_task()[i]].name()
    )
}

/// The JSON document of a cell (`tandem inspect --json` and `tandem schedule --json` of a
/// cell of several tasks; docs/formats.md, "A cell of tasks as JSON"): per task its name,
/// robots (1-based), reference samples and period (s), channels, high-confidence share and
/// count, low-confidence regions and rounds; per robot its task; the schedule (global s):
/// `T_total`, its lower bound and gap, the tick, every robot's start and planned end, and
/// every low-confidence interval (robot 1-based, its task, reference samples of that task).
fn cell_doc(cell: &CellPlanner, state: &Path) -> Result<serde_json::Value> {
    let tasks: Vec<serde_json::Value> = cell
        .tasks()
        .iter()
        .enumerate()
        .map(|(t, task)| {
            let p = task.planner();
            let c = p.confidence();
            serde_json::json!({
                "name": task.name(),
                "robots": cell
                    .robot_task()
                    .iter()
                    .enumerate()
                    .filter(|&(_, &x)| x == t)
                    .map(|(i, _)| i + 1)
                    .collect::<Vec<_>>(),
                "n_ref": p.model().n_ref(),
                "dt_s": p.model().dt_s(),
                "channels": p.model().channel_names(),
                "high_share": c.high_share(),
                "n_high": c.n_high(),
                "low_regions": c.low_regions().len(),
                "rounds_recorded": p.rounds_recorded(),
            })
        })
        .collect();
    let timelines = cell.timelines().context("the cell's schedule")?;
    let robots: Vec<serde_json::Value> = timelines
        .iter()
        .enumerate()
        .map(|(i, tl)| {
            serde_json::json!({
                "robot": i + 1,
                "task": cell.tasks()[cell.robot_task()[i]].name(),
                "start_s": tl.start_s(),
                "end_s": tl.end_s(),
            })
        })
        .collect();
    let lc: Vec<serde_json::Value> = crate::gantt::cell_intervals(timelines)
        .into_iter()
        .map(|(i, iv)| {
            serde_json::json!({
                "robot": i + 1,
                "task": cell.tasks()[cell.robot_task()[i]].name(),
                "start_s": iv.start_s,
                "end_s": iv.end_s,
                "ref_start": iv.ref_start,
                "ref_end": iv.ref_end,
            })
        })
        .collect();
    let schedule = match cell.schedule() {
        Some(s) => serde_json::json!({
            "t_total_s": s.t_total_s,
            "lower_bound_s": s.lower_bound_s,
            "gap_s": s.gap_s(),
            "tick_s": s.tick_s,
            "margin_checks": s.margin_checks,
            "robots": robots,
            "lc_intervals": lc,
        }),
        None => serde_json::json!({
            "t_total_s": cell.t_total_s(),
            "robots": robots,
            "lc_intervals": lc,
        }),
    };
    Ok(serde_json::json!({
        "state": state.display().to_string(),
        "n_robots": cell.n_robots(),
        "rounds_recorded": cell.rounds_recorded(),
        "tasks": tasks,
        "robot_tasks": (0..cell.n_robots())
            .map(|i| cell.tasks()[cell.robot_task()[i]].name())
            .collect::<Vec<_>>(),
        "schedule": schedule,
    }))
}

/// `tandem schedule` of a cell of two or more tasks: its rounds schedule as a chart naming
/// each robot's task (or [`cell_doc`] with `--json`). A cell is re-scheduled when a round is
/// recorded; this shows the schedule it holds, so the sampler's flags and `--save` have
/// nothing to act on and are refused rather than ignored.
pub(crate) fn schedule_cell(a: &ScheduleArgs) -> Result<()> {
    if a.cell == tandem::planner::Cell::Continuous {
        bail!(
            "{}: a cell of several tasks has no continuous plan on the command line yet; \
             `cargo xtask study --cell-file FILE --cell continuous` runs one, or leave out \
             --cell continuous for its rounds schedule",
            a.state.display()
        );
    }
    let s = &a.sampler;
    if a.save
        || s.samples.is_some()
        || s.seed.is_some()
        || s.switch_s.is_some()
        || s.max_busy.is_some()
        || s.operators.is_some()
    {
        bail!(
            "{}: a cell of several tasks is re-scheduled when a round is recorded (`tandem \
             record`), with the parameters each task was fitted with; `tandem schedule` shows \
             the schedule it holds. Leave out --save, --samples, --seed, --switch-s, \
             --max-busy and --operators",
            a.state.display()
        );
    }
    let cell = CellPlanner::load(&a.state).context("cannot load the state")?;
    if a.json {
        out(&serde_json::to_string_pretty(&cell_doc(&cell, &a.state)?)?);
        return Ok(());
    }
    let timelines = cell.timelines().context("the cell's schedule")?;
    match cell.schedule() {
        Some(s) => out(&format!(
            "T_total {:.2} s — lower bound {:.2} s (gap {:.2} s): the longest robot's fastest \
             task, or every robot's low-confidence time in turn; tick {} s",
            s.t_total_s,
            s.lower_bound_s,
            s.gap_s(),
            secs(s.tick_s)
        )),
        None => out(&format!("T_total {:.2} s", cell.t_total_s())),
    }
    let runs: Vec<String> = timelines
        .iter()
        .enumerate()
        .map(|(i, tl)| {
            format!(
                "{} starts at {:.2} s, runs {:.2} s",
                robot_label(&cell, i),
                tl.start_s(),
                tl.end_s() - tl.start_s()
            )
        })
        .collect();
    out(&runs.join("; "));
    let labels: Vec<String> = (0..cell.n_robots())
        .map(|i| robot_label(&cell, i))
        .collect();
    out(crate::gantt::cell_chart(timelines, &labels)?.trim_end());
    Ok(())
}

/// `tandem record` into a cell of two or more tasks: robot `i`'s execution is of its own
/// task and is recorded into that task's model and confidence.
pub(crate) fn record_cell(a: &RecordArgs) -> Result<()> {
    if !a.bags.is_empty() {
        bail!(
            "{}: a cell of several tasks records from CSV files only for now (--execution, \
             --log, --corrections per robot); bags are not read for cells yet",
            a.state.display()
        );
    }
    let lock = state_io::lock(&a.state)?;
    let mut cell = CellPlanner::load(&a.state).context("cannot load the state")?;
    let n = cell.n_robots();
    for (flag, v) in [
        ("--execution", &a.execution),
        ("--log", &a.log),
        ("--corrections", &a.corrections),
    ] {
        if v.len() != n {
            bail!(
                "{flag} given {} time(s); {} has {n} robots, so a round needs exactly {n} \
                 (robot 1 first, each of its own task: {})",
                v.len(),
                a.state.display(),
                (0..n)
                    .map(|i| format!(
                        "robot {} {}",
                        i + 1,
                        cell.tasks()[cell.robot_task()[i]].name()
                    ))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
    }
    let before_high: Vec<f64> = cell
        .tasks()
        .iter()
        .map(|t| t.planner().confidence().high_share())
        .collect();
    let round = (0..n)
        .map(|i| {
            let task = &cell.tasks()[cell.robot_task()[i]];
            read_execution(
                task.planner(),
                i + 1,
                &a.execution[i],
                &a.log[i],
                &a.corrections[i],
                a.resample,
            )
            .with_context(|| format!("task `{}`", task.name()))
        })
        .collect::<Result<Vec<ExecutionRecord>>>()?;
    let demos: Vec<&Demonstration> = round.iter().map(|r| &r.execution.demonstration).collect();
    period_notes(
        &demos,
        " (the assumed period is the control tick of the schedule it ran)",
    );
    let report = cell
        .record_round(&round)
        .context("cannot record the round")?;
    cell.save_locked(&lock)?;
    drop(lock);
    out(&format!(
        "recorded round {} into {}",
        cell.rounds_recorded(),
        a.state.display()
    ));
    for ((task, r), before) in cell.tasks().iter().zip(&report.tasks).zip(&before_high) {
        for n in &r.notices {
            crate::cmd::note(n);
        }
        out(&format!(
            "task {}: {} reference samples became high-confidence; {:.1} % → {:.1} %",
            task.name(),
            r.newly_high,
            100.0 * before,
            100.0 * task.planner().confidence().high_share()
        ));
    }
    out(&format!(
        "T_total: {:.2} s → {:.2} s",
        report.previous_t_total_s, report.t_total_s
    ));
    summary(&cell);
    Ok(())
}
