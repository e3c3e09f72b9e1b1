//! `cargo xtask study`: the simulated study of §III (Fig. 5).
//!
//! Reads the configuration (`fixtures/study.toml`, overridable by flags), runs the study
//! loop of `tandem::sim::study` on the fixture demonstrations with a progress bar on stderr,
//! and writes under the output folder (default `results/`):
//! `study.json` (compact; git revision, configuration, every trial and iteration, the
//! per-iteration summary), `study.csv` (one row per trial and iteration), `fig5.svg` and `fig5.png`.
//! Finally it prints the time spent in each phase. With `--bag DIR` it writes the chosen rounds
//! (`--bag-trials`, `--bag-rounds`; default the first and the last round of trial 0) as ROS 2
//! bags, `DIR/trial_<T>_round_<K>.mcap` (`tandem::bag::RunWriter`), as they run.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use anyhow::{Context, bail};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use tandem::sim::study::{
    Cell, CellStudyResult, CellSummary, IterationSummary, PhaseTimes, StudyConfig, StudyInputs,
    StudyResult,
};

use crate::fig5::{ExampleSchedule, Fig5Data, draw_fig5};
use crate::workspace_root;

/// Flags of `cargo xtask study`; unset flags take the configuration file's values.
#[derive(clap::Args, Debug)]
pub(crate) struct StudyArgs {
    /// Study configuration (TOML with the fields of `tandem::sim::study::StudyConfig`).
    /// Default: fixtures/study.toml in the workspace.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Number of trials.
    #[arg(long)]
    trials: Option<usize>,
    /// Executions per trial (a multiple of the robot count: they run in rounds of one
    /// execution per robot).
    #[arg(long)]
    executions: Option<usize>,
    /// Robots N run by the one operator (1 to 16; default: the configuration's, 2). The
    /// configured executions are rounded down to a multiple of N unless --executions is given.
    #[arg(long)]
    robots: Option<usize>,
    /// Sampler iterations per re-schedule.
    #[arg(long)]
    samples: Option<usize>,
    /// Master seed.
    #[arg(long)]
    seed: Option<u64>,
    /// The simulated operator's miss rate (probability per needed control sample).
    #[arg(long)]
    miss_rate: Option<f64>,
    /// The simulated operator's false-correction rate (share of the supervised time that
    /// needs no correction).
    #[arg(long)]
    false_correction_rate: Option<f64>,
    /// Mean length (s) of an unneeded correction episode; 0 draws every control tick alone.
    #[arg(long)]
    false_correction_s: Option<f64>,
    /// The switch time δ (s, ≥ 0) the schedules are planned with (`[operator] switch_s`;
    /// issue 41): at least δ between one robot's low-confidence stretch and another's.
    #[arg(long, value_name = "S")]
    switch_s: Option<f64>,
    /// The operator's load cap u_max in (0, 1] the schedules are planned with (`[operator]
    /// max_busy_share`).
    #[arg(long, value_name = "U")]
    max_busy: Option<f64>,
    /// The simulated operator's own switch time δ_true (s, ≥ 0; `[operator] switch_true_s`):
    /// corrections needed in its first δ_true after another robot's stretch ended are missed
    /// and counted.
    #[arg(long, value_name = "S")]
    switch_true_s: Option<f64>,
    /// The cell's number of operators M (1 to 16; `[operator] operators`; issue 44): M tokens
    /// (continuous) or M sectors (rounds) and M simulated operators, one per operator index,
    /// each with the rates above.
    #[arg(long, value_name = "M")]
    operators: Option<usize>,
    /// Which continuous cell M > 1 operators run (`[operator] fleet_cell`; issue 44): `auto`
    /// (the pooled cell unless the even sectors measure strictly faster with the planned
    /// operator), `pooled` or `sectored` (forced: the two cells on the same run).
    #[arg(long, value_name = "CELL", value_parser = clap::builder::PossibleValuesParser::new(["auto", "pooled", "sectored"]))]
    fleet_cell: Option<String>,
    /// Decide confidence with the paper's model (Eq. 8–12: zero error rates, nothing
    /// estimated, every control sample one observation) instead of the configured one.
    #[arg(long)]
    paper_confidence: bool,
    /// Output folder (created if missing). Default: results/ in the workspace.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Folder with demo_{i}.csv and each one's demo_{i}.labels.csv (the truth is the labels of
    /// the fit's reference). Default: fixtures/sanding/.
    #[arg(long)]
    fixtures: Option<PathBuf>,
    /// Worker threads (default: all cores). Results do not depend on it.
    #[arg(long)]
    threads: Option<usize>,
    /// How the robots run: `rounds` (the paper: all start together, the next round when the
    /// last finishes) or `continuous` (each robot starts its next task as soon as it is safe;
    /// writes the steady throughput in study.json's summary). Default: the configuration's
    /// (rounds).
    #[arg(long, value_name = "CELL", value_parser = cell_parser())]
    cell: Option<Cell>,
    /// Ignore the configuration's hold points (`[planner.holds]`): the study as before hold
    /// points existed.
    #[arg(long)]
    no_holds: bool,
    /// A continuous cell of different tasks (`--cell-file` of two or more tasks) runs the
    /// token rule alone, without nested groups (`[operator] nested_groups = false`): the
    /// comparison for issue 45.
    #[arg(long)]
    no_nested_groups: bool,
    /// Write chosen rounds as ROS 2 bags (MCAP, for Foxglove) into this folder, one file per
    /// round: `trial_<T>_round_<K>.mcap` (replaced if present).
    #[arg(long, value_name = "DIR")]
    bag: Option<PathBuf>,
    /// With --bag: the trials to write (0-based). Default: 0.
    #[arg(long, value_name = "T,…", value_delimiter = ',', requires = "bag")]
    bag_trials: Vec<usize>,
    /// With --bag: the rounds to write (1-based). Default: the first and the last.
    #[arg(long, value_name = "K,…", value_delimiter = ',', requires = "bag")]
    bag_rounds: Vec<usize>,
    /// Save each trial's planner after its last round as a state file in this folder
    /// (created if missing): `trial_<T>.tandem`, for `tandem console`, `tandem simulate`,
    /// `tandem inspect`. Refuses to start when one of those files exists already.
    #[arg(long, value_name = "DIR")]
    save_state: Option<PathBuf>,
    /// A cell of different tasks on different robots (issue 45; docs/formats.md, "Cell
    /// file"): each task's demonstrations, robots, hold rules and ground truth. One task with
    /// the sanding labels as its truth runs today's study on its demonstrations and robots;
    /// two or more tasks run the mixed cell in rounds (study.json: `T_total` against the mixed
    /// bound, each task's confidence against its truth).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["robots", "fixtures", "bag", "save_state"])]
    cell_file: Option<PathBuf>,
}

/// `--cell`'s parser: the planner's `Cell` by its name (`rounds`, `continuous`), each value
/// with its help (`Cell::help`).
pub(crate) fn cell_parser() -> impl TypedValueParser<Value = Cell> {
    PossibleValuesParser::new(Cell::ALL.map(|c| PossibleValue::new(c.name()).help(c.help())))
        .try_map(|name| name.parse::<Cell>())
}

/// Writes the rounds `--bag` chose as they run (from worker threads); remembers the files
/// written and the first error.
struct BagSink {
    dir: PathBuf,
    trials: Vec<usize>,
    rounds: Vec<usize>,
    written: std::sync::Mutex<Vec<PathBuf>>,
    error: std::sync::Mutex<Option<String>>,
}

impl BagSink {
    fn new(args: &StudyArgs, config: &StudyConfig) -> anyhow::Result<Option<Self>> {
        let Some(dir) = &args.bag else {
            return Ok(None);
        };
        let n = config.n_rounds();
        let trials = if args.bag_trials.is_empty() {
            vec![0]
        } else {
            args.bag_trials.clone()
        };
        let rounds = if args.bag_rounds.is_empty() {
            vec![1, n]
        } else {
            args.bag_rounds.clone()
        };
        if let Some(t) = trials.iter().find(|&&t| t >= config.trials) {
            bail!(
                "--bag-trials {t}: the study runs trials 0 to {}",
                config.trials - 1
            );
        }
        if let Some(k) = rounds.iter().find(|&&k| k == 0 || k > n) {
            bail!("--bag-rounds {k}: a trial runs rounds 1 to {n}");
        }
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Some(Self {
            dir: dir.clone(),
            trials,
            rounds,
            written: std::sync::Mutex::new(Vec::new()),
            error: std::sync::Mutex::new(None),
        }))
    }

    fn observe(&self, view: tandem::sim::study::RoundView<'_>) {
        if !(self.trials.contains(&view.trial) && self.rounds.contains(&view.round)) {
            return;
        }
        let path = self
            .dir
            .join(format!("trial_{}_round_{}.mcap", view.trial, view.round));
        let result = (|| -> anyhow::Result<()> {
            let mut w = tandem::bag::RunWriter::create(
                &path,
                view.planner,
                tandem::bag::Existing::Replace,
            )?;
            w.write_round(view.planner, view.run)?;
            w.finish()?;
            Ok(())
        })();
        match result {
            Ok(()) => self.written.lock().expect("no panic holds it").push(path),
            Err(e) => {
                let mut first = self.error.lock().expect("no panic holds it");
                first.get_or_insert(format!("{}: {e:#}", path.display()));
            }
        }
    }
}

/// Saves each trial's planner after its last round (`--save-state`), from worker threads as
/// the trials end; remembers the files written and the first error.
struct StateSink {
    dir: PathBuf,
    written: std::sync::Mutex<Vec<PathBuf>>,
    error: std::sync::Mutex<Option<String>>,
}

impl StateSink {
    /// The sink of `--save-state DIR`, or `None` without the flag. Creates `DIR` and refuses,
    /// before the study runs, a `DIR` that holds one of the files the study would write: the
    /// study never replaces a state file it did not create.
    fn new(args: &StudyArgs, config: &StudyConfig) -> anyhow::Result<Option<Self>> {
        let Some(dir) = &args.save_state else {
            return Ok(None);
        };
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        for trial in 0..config.trials {
            let path = Self::path(dir, trial);
            if path.exists() {
                bail!(
                    "--save-state {}: {} exists already (from an earlier study?); the study \
                     does not replace state files it did not create: remove it or pass \
                     another folder",
                    dir.display(),
                    path.display()
                );
            }
        }
        Ok(Some(Self {
            dir: dir.clone(),
            written: std::sync::Mutex::new(Vec::new()),
            error: std::sync::Mutex::new(None),
        }))
    }

    /// The state file of trial `trial` (0-based) in `dir`.
    fn path(dir: &Path, trial: usize) -> PathBuf {
        dir.join(format!("trial_{trial}.tandem"))
    }

    /// Saves trial `trial`'s planner through the planner's normal save (atomic, locked, a
    /// versioned state file); a file that appeared there meanwhile is left alone.
    fn save(&self, trial: usize, planner: &tandem::planner::Planner) {
        let path = Self::path(&self.dir, trial);
        let result = if path.exists() {
            Err(anyhow::anyhow!(
                "exists already (created while the study ran); not replaced"
            ))
        } else {
            planner.save(&path).map_err(anyhow::Error::from)
        };
        match result {
            Ok(()) => self.written.lock().expect("no panic holds it").push(path),
            Err(e) => {
                let mut first = self.error.lock().expect("no panic holds it");
                first.get_or_insert(format!("{}: {e:#}", path.display()));
            }
        }
    }

    /// The files written, in trial order, or the first error.
    fn finish(self) -> anyhow::Result<Vec<PathBuf>> {
        if let Some(e) = self.error.into_inner().expect("no panic holds it") {
            bail!("saving a trial's state: {e}");
        }
        let mut written = self.written.into_inner().expect("no panic holds it");
        written.sort_by_key(|p| {
            p.file_stem()
                .and_then(|s| s.to_str())
                .and_then(|s| s.strip_prefix("trial_"))
                .and_then(|k| k.parse::<usize>().ok())
        });
        Ok(written)
    }
}

/// Saves a trial's planner into `sink` when there is one (the study's `finished` callback).
fn save_into(sink: &Option<StateSink>) -> impl Fn(usize, &tandem::planner::Planner) + Sync + '_ {
    move |trial, planner| {
        if let Some(s) = sink {
            s.save(trial, planner);
        }
    }
}

/// Prints the state files `--save-state` wrote (or fails with its first error).
fn report_saved(sink: Option<StateSink>) -> anyhow::Result<()> {
    if let Some(s) = sink {
        for p in s.finish()? {
            println!("wrote {}", p.display());
        }
    }
    Ok(())
}

/// What `study.json` holds.
#[derive(Serialize)]
struct StudyFile<'a> {
    /// `git describe --always --dirty` of the workspace, or "unknown".
    git_revision: String,
    /// Mean and standard deviation per iteration across trials (Fig. 5).
    summary: Vec<IterationSummary>,
    /// Everything else: configuration, trials, iterations.
    result: &'a StudyResult,
}

/// What `study.json` holds for a continuous cell.
#[derive(Serialize)]
struct CellStudyFile<'a> {
    /// `git describe --always --dirty` of the workspace, or "unknown".
    git_revision: String,
    /// "continuous".
    cell: &'static str,
    /// Across trials: the steady throughput (last 10 % of tasks), busy and waiting shares,
    /// the last plan's figures, overlaps and faults.
    summary: CellSummary,
    /// Everything else: configuration, trials, plans, completions.
    result: &'a CellStudyResult,
}

/// The continuous study (`--cell continuous`): runs it with a progress bar, writes
/// `study.json` and prints the summary.
fn run_continuous(
    config: &StudyConfig,
    inputs: &StudyInputs,
    out: &Path,
    root: &Path,
    wall: Instant,
    states: Option<StateSink>,
) -> anyhow::Result<()> {
    let bar = TrialBar::new(config, "re-plans (every N tasks)")?;
    let (result, times) = tandem::sim::study::run_cell_study_finished(
        config,
        inputs,
        &|p| bar.step(p),
        &save_into(&states),
    )?;
    bar.finish();
    report_saved(states)?;
    let summary = result.summary();
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let file = CellStudyFile {
        git_revision: git_revision(root),
        cell: Cell::Continuous.name(),
        summary: summary.clone(),
        result: &result,
    };
    let path = out.join("study.json");
    std::fs::write(&path, serde_json::to_string(&file)? + "\n")
        .with_context(|| format!("writing {}", path.display()))?;
    crate::cellfig::draw_cell_study(&result, &out.join("cell.svg"), &out.join("cell.png"))?;
    println!(
        "continuous cell: {} trials × {} tasks, {} robots, re-planned every {} tasks, seed {}",
        config.trials, config.executions, config.robots, config.robots, config.seed
    );
    for t in &result.trials {
        let last = t.iterations.last().expect("the first plan at least");
        let picks: Vec<_> = t
            .iterations
            .iter()
            .filter_map(|i| i.fleet.as_ref())
            .collect();
        if let Some(p) = picks.last() {
            // M > 1 (issue 44): which cell ran, and the measured rates it was picked by.
            let sectored = picks
                .iter()
                .filter(|p| p.cell == tandem::planner::FleetCell::Sectored)
                .count();
            let rate = |r: Option<f64>| r.map_or("-".to_string(), |r| format!("{r:.1}"));
            println!(
                "  trial {}: {} of {} plans ran sectored ({}), {} pooled; last plan measured \
                 with the planned operator: pooled {} tasks/h, sectored {} (planned {})",
                t.trial,
                sectored,
                picks.len(),
                p.sectors
                    .iter()
                    .map(usize::to_string)
                    .collect::<Vec<_>>()
                    .join(" + "),
                picks.len() - sectored,
                rate(p.pooled_tasks_per_hour),
                rate(p.sectored_tasks_per_hour),
                rate(p.sectored_planned_tasks_per_hour),
            );
        }
        println!(
            "  trial {}: steady {:.1} tasks/h, operator busy {:.1} %, robots waiting {:.1} %; \
             last plan {:.1} tasks/h (bound {:.1}, {} stretches), {} hand-overs",
            t.trial,
            t.steady.throughput_per_h,
            100.0 * t.steady.operator_busy_share,
            100.0 * t.steady.robot_wait_share,
            last.tasks_per_hour,
            3600.0 * config.robots as f64 / last.lower_bound_s,
            last.lc_stretches,
            t.stats.hand_overs
        );
    }
    println!(
        "steady throughput (last 10 % of tasks): {:.1} ± {:.1} tasks/h per operator, operator \
         busy {:.1} %, robots waiting at gates {:.1} % of their time",
        summary.steady_throughput_per_h,
        summary.steady_throughput_std_per_h,
        100.0 * summary.steady_operator_busy_share,
        100.0 * summary.steady_robot_wait_share
    );
    println!(
        "last plan: {:.1} tasks/h planned, bound {:.1} tasks/h",
        summary.last_plan_tasks_per_hour, summary.last_plan_bound_tasks_per_hour
    );
    let gap = &summary.steady_plan_gap_per_task;
    println!(
        "steady tasks against the plan's period (per task): {}; planned / realized throughput \
         {:.3}; needed but unsupervised: {:.2} samples per task",
        gap.describe(),
        if gap.realized_s > 0.0 {
            gap.planned_s / gap.realized_s
        } else {
            f64::NAN
        },
        summary.steady_needed_unsupervised_per_task
    );
    if !config.operator.is_default() {
        let (missed, tasks) = result.switch_missed_total();
        let op = &config.operator;
        println!(
            "operator: {} operator(s), planned switch time δ {} s, load cap {}; own switch \
             time δ_true {} s: {} needed corrections missed while switching ({:.2} per task)",
            op.operators,
            op.switch_s,
            op.max_busy_share,
            op.switch_true_s,
            missed,
            missed as f64 / tasks.max(1) as f64,
        );
    }
    println!(
        "overlapping low-confidence ticks: {}, faults: {}",
        summary.overlap_ticks, summary.faults
    );
    println!(
        "wrote {}, cell.svg, cell.png in {}",
        path.file_name()
            .map_or("study.json".into(), |f| f.to_string_lossy()),
        out.display()
    );
    print_times(&times, wall.elapsed());
    if summary.overlap_ticks > 0 || summary.faults > 0 {
        bail!("two robots were low-confidence in the same tick: the cell is unsafe");
    }
    Ok(())
}

/// The progress bar of a study's trials: one step per round (or re-plan) of every trial,
/// with the trials done as its message.
pub(crate) struct TrialBar {
    bar: ProgressBar,
    trials: usize,
    steps_per_trial: usize,
    trials_done: AtomicUsize,
}

impl TrialBar {
    /// A bar of `config.trials × config.n_rounds()` steps named `unit`.
    pub(crate) fn new(config: &StudyConfig, unit: &str) -> anyhow::Result<TrialBar> {
        let steps_per_trial = config.n_rounds();
        let bar = ProgressBar::new((config.trials * steps_per_trial) as u64);
        bar.set_style(
            ProgressStyle::with_template(&format!(
                "{{elapsed_precise}} [{{bar:40}}] {{pos}}/{{len}} {unit}, {{msg}} (eta {{eta}})"
            ))
            .context("progress bar template")?
            .progress_chars("=> "),
        );
        bar.set_message(format!("0/{} trials done", config.trials));
        Ok(TrialBar {
            bar,
            trials: config.trials,
            steps_per_trial,
            trials_done: AtomicUsize::new(0),
        })
    }

    /// One step of a trial (the study's progress callback; called from worker threads).
    pub(crate) fn step(&self, p: tandem::sim::study::Progress) {
        self.bar.inc(1);
        if p.rounds_done == self.steps_per_trial {
            let done = self.trials_done.fetch_add(1, Ordering::Relaxed) + 1;
            self.bar
                .set_message(format!("{done}/{} trials done", self.trials));
        }
    }

    /// Leaves the bar at its end.
    pub(crate) fn finish(&self) {
        self.bar.finish();
    }

    /// Removes the bar (a caller that prints its own line per study).
    pub(crate) fn clear(&self) {
        self.bar.finish_and_clear();
    }
}

/// `git describe --always --dirty` of the workspace at `root`, or "unknown".
pub(crate) fn git_revision(root: &Path) -> String {
    std::process::Command::new("git")
        .args(["describe", "--always", "--dirty"])
        .current_dir(root)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map(|s| s.trim().to_string())
        .unwrap_or_else(|| "unknown".into())
}

/// The study configuration at `path`, or `fixtures/study.toml` of the workspace; returns it
/// with the path read (for messages).
pub(crate) fn read_config(path: Option<&Path>) -> anyhow::Result<(StudyConfig, PathBuf)> {
    let path = path.map_or_else(
        || workspace_root().join("fixtures/study.toml"),
        Path::to_path_buf,
    );
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("reading study configuration {}", path.display()))?;
    let config = toml::from_str(&text).with_context(|| format!("parsing {}", path.display()))?;
    Ok((config, path))
}

/// The configuration file with the flags applied. With `--robots N` and no `--executions`,
/// the configured executions are rounded down to a multiple of `N` (a remainder cannot form
/// a round), and a note says so.
fn config(args: &StudyArgs) -> anyhow::Result<StudyConfig> {
    let (mut config, path) = read_config(args.config.as_deref())?;
    if let Some(v) = args.trials {
        config.trials = v;
    }
    if let Some(v) = args.robots {
        config.robots = v;
    }
    if let Some(v) = args.executions {
        config.executions = v;
    } else if let Some(n) = args.robots.filter(|&n| n > 0) {
        let whole = config.executions / n * n;
        if whole != config.executions && whole > 0 {
            println!(
                "note: {} executions do not fill rounds of {n} robots; running {whole} \
                 ({} rounds), the remainder of {} is dropped",
                config.executions,
                whole / n,
                config.executions - whole
            );
            config.executions = whole;
        }
    }
    if let Some(v) = args.samples {
        config.samples = v;
    }
    if let Some(v) = args.seed {
        config.seed = v;
    }
    if let Some(v) = args.miss_rate {
        config.miss_rate = v;
    }
    if let Some(v) = args.false_correction_rate {
        config.false_correction_rate = v;
    }
    if let Some(v) = args.false_correction_s {
        config.false_correction_s = v;
    }
    if let Some(v) = args.switch_s {
        config.operator.switch_s = v;
    }
    if let Some(v) = args.max_busy {
        config.operator.max_busy_share = v;
    }
    if let Some(v) = args.switch_true_s {
        config.operator.switch_true_s = v;
    }
    if let Some(m) = args.operators {
        config.operator.operators = m;
    }
    if let Some(f) = &args.fleet_cell {
        config.operator.fleet_cell = f.parse()?;
    }
    if args.no_holds {
        config.planner.holds = Default::default();
    }
    if args.no_nested_groups {
        config.operator.nested_groups = false;
    }
    if let Some(c) = args.cell {
        config.cell = c;
    }
    if args.paper_confidence {
        let c = &mut config.planner.confidence;
        *c = tandem::confidence::ConfidenceParams {
            gamma_p: c.gamma_p,
            sigma2_max: c.sigma2_max,
            epsilon: c.epsilon,
            mu_c: c.mu_c,
            gamma_c: c.gamma_c,
            ..tandem::confidence::ConfidenceParams::paper()
        };
    }
    config
        .validate()
        .with_context(|| format!("study configuration {} with flags", path.display()))?;
    Ok(config)
}

/// Fig. 5 from the study: the summary, example schedules of trial 0, the ground truth.
fn fig5_data(result: &StudyResult, summary: &[IterationSummary]) -> Fig5Data {
    let trial0 = &result.trials[0];
    let examples = result
        .config
        .example_iterations
        .iter()
        .filter_map(|&k| trial0.iterations.iter().find(|r| r.iteration == k))
        .map(|r| {
            let pairs = |v: &[[f64; 2]]| v.iter().map(|[a, b]| (*a, b.min(r.t_total_s))).collect();
            ExampleSchedule {
                iteration: r.iteration,
                t_total_s: r.t_total_s,
                lc: r.lc_intervals_s.iter().map(|v| pairs(v)).collect(),
            }
        })
        .collect();
    Fig5Data {
        iterations: summary.iter().map(|s| s.iteration).collect(),
        t_total_mean_s: summary.iter().map(|s| s.t_total_mean_s).collect(),
        t_total_std_s: summary.iter().map(|s| s.t_total_std_s).collect(),
        lower_bound_mean_s: summary.iter().map(|s| s.lower_bound_mean_s).collect(),
        high_conf_pct_mean: summary.iter().map(|s| s.high_conf_pct_mean).collect(),
        high_conf_pct_std: summary.iter().map(|s| s.high_conf_pct_std).collect(),
        ground_truth_pct: result.ground_truth_pct,
        n_robots: result.config.robots,
        examples,
    }
}

/// The ground truth per trial at the last iteration: low-confidence runs per robot,
/// falsely trusted samples (at the end and summed over iterations), the operator's rates
/// as estimated and as simulated.
fn print_ground_truth(result: &StudyResult) {
    let pct = |r: f64| 100.0 * r;
    for t in &result.trials {
        let Some(last) = t.iterations.last() else {
            continue;
        };
        let summed: usize = t.iterations.iter().map(|r| r.falsely_trusted_samples).sum();
        let sim = last.simulated_rates.unwrap_or_default();
        println!(
            "trial {}: low-confidence runs per robot {:?}, T_total {:.2} s (bound {:.2} s), \
             falsely trusted {} at the end, {summed} summed over iterations; \
             f {:.3} % estimated / {:.3} % simulated, m {:.3} % / {:.3} %",
            t.trial,
            last.lc_runs,
            last.t_total_s,
            last.lower_bound_s,
            last.falsely_trusted_samples,
            pct(last.error_rates.false_correction_rate),
            pct(sim.false_correction_rate),
            pct(last.error_rates.miss_rate),
            pct(sim.miss_rate),
        );
    }
}

fn print_times(times: &PhaseTimes, wall: std::time::Duration) {
    println!("phase times (summed over trials; trials run in parallel):");
    for (name, d) in [
        ("alignment (fit, once)", times.alignment),
        ("model update (Eq. 21)", times.model_update),
        ("confidence (Eq. 9-12)", times.confidence),
        ("scheduling (sampler)", times.scheduling),
        ("simulation (workcell)", times.simulation),
    ] {
        println!("  {name:<24} {:>9.2} s", d.as_secs_f64());
    }
    println!("  {:<24} {:>9.2} s", "wall time", wall.as_secs_f64());
}

/// Runs `cargo xtask study`.
pub(crate) fn run(args: &StudyArgs) -> anyhow::Result<()> {
    let wall = Instant::now();
    let root = workspace_root();
    let mut config = config(args)?;
    if let Some(n) = args.threads {
        if n == 0 {
            bail!("--threads must be at least 1");
        }
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("setting up the worker threads")?;
    }
    let mut fixtures = args
        .fixtures
        .clone()
        .unwrap_or_else(|| root.join("fixtures/sanding"));
    if let Some(path) = &args.cell_file {
        let (file, dir) = crate::study_cell::read_cell_file(path)?;
        if !crate::study_cell::is_single_labels(&file) {
            let out = args.out.clone().unwrap_or_else(|| root.join("results"));
            let mut file = file;
            if args.no_holds {
                for t in &mut file.task {
                    t.holds.clear();
                }
            }
            if config.cell == Cell::Continuous {
                return crate::study_cell::run_mixed_continuous(config, &file, &dir, &out, &root);
            }
            return crate::study_cell::run_mixed(
                config,
                &file,
                &dir,
                args.executions.is_some(),
                &out,
                &root,
            );
        }
        // One task with the sanding labels: today's study on its demonstrations, robots and
        // hold rules.
        let task = &file.task[0];
        config.robots = task.robots;
        if args.executions.is_none() && task.robots > 0 {
            config.executions = config.executions / task.robots * task.robots;
        }
        if !args.no_holds {
            config.planner.holds.rules = task
                .holds
                .iter()
                .map(|r| r.parse())
                .collect::<Result<_, _>>()
                .with_context(|| format!("task `{}`: its hold rules", task.name))?;
        }
        config
            .validate()
            .context("study configuration with the cell file's task")?;
        fixtures = dir.join(&task.demos);
    }
    let inputs = StudyInputs::from_dir(&fixtures)
        .with_context(|| format!("reading demonstrations from {}", fixtures.display()))?;
    let out = args.out.clone().unwrap_or_else(|| root.join("results"));
    if config.cell == Cell::Continuous {
        if args.bag.is_some() {
            bail!("--bag writes rounds; a continuous cell has none (use --cell rounds)");
        }
        let states = StateSink::new(args, &config)?;
        return run_continuous(&config, &inputs, &out, &root, wall, states);
    }

    let sink = BagSink::new(args, &config)?;
    let states = StateSink::new(args, &config)?;
    let bar = TrialBar::new(&config, "rounds")?;
    let observe = |view: tandem::sim::study::RoundView<'_>| {
        if let Some(s) = &sink {
            s.observe(view);
        }
    };
    let (result, times) = tandem::sim::study::run_study_finished(
        &config,
        &inputs,
        &|p| bar.step(p),
        &observe,
        &save_into(&states),
    )?;
    bar.finish();
    report_saved(states)?;
    if let Some(s) = sink {
        if let Some(e) = s.error.into_inner().expect("no panic holds it") {
            bail!("writing a bag: {e}");
        }
        let mut written = s.written.into_inner().expect("no panic holds it");
        written.sort();
        for p in written {
            println!("wrote {}", p.display());
        }
    }

    let summary = result.summary();
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let file = StudyFile {
        git_revision: git_revision(&root),
        summary: summary.clone(),
        result: &result,
    };
    let json = serde_json::to_string(&file)? + "\n";
    let write = |name: &str, bytes: &[u8]| -> anyhow::Result<PathBuf> {
        let path = out.join(name);
        std::fs::write(&path, bytes).with_context(|| format!("writing {}", path.display()))?;
        Ok(path)
    };
    write("study.json", json.as_bytes())?;
    write("study.csv", result.to_csv().as_bytes())?;
    draw_fig5(
        &fig5_data(&result, &summary),
        &out.join("fig5.svg"),
        &out.join("fig5.png"),
    )?;

    let (first, last) = (&summary[0], &summary[summary.len() - 1]);
    println!(
        "{} trials × {} executions ({} rounds of {} robots), {} samples per schedule, seed {}",
        config.trials,
        config.executions,
        config.n_rounds(),
        config.robots,
        config.samples,
        config.seed
    );
    println!(
        "T_total: {:.2} ± {:.2} s at iteration 0 → {:.2} ± {:.2} s at iteration {}",
        first.t_total_mean_s,
        first.t_total_std_s,
        last.t_total_mean_s,
        last.t_total_std_s,
        last.iteration
    );
    println!(
        "high confidence: {:.1} % → {:.1} % (ground truth {:.1} %)",
        first.high_conf_pct_mean, last.high_conf_pct_mean, result.ground_truth_pct
    );
    // Where the gap goes (issue 38): what the margin-free search left open, and what the
    // margins cost above the best margin-free schedule known (`Outcome::gap_split`).
    let split = last.gap_search_mean.map_or(String::new(), |search| {
        format!(
            " (search {:.1} % + margins {:.1} %)",
            100.0 * search,
            100.0 * (last.gap_mean - search)
        )
    });
    println!(
        "certificate at iteration {}: lower bound {:.2} s (the proven margin-free optimum in {:.0} % of trials), \
         mean gap {:.1} %{split}",
        last.iteration,
        last.lower_bound_mean_s,
        100.0 * last.bound_proven_share,
        100.0 * last.gap_mean
    );
    let last_round = summary.iter().rev().find_map(|s| {
        s.operator_busy_share_mean
            .map(|b| (s.iteration, s.throughput_mean_per_h, b))
    });
    if let Some((k, throughput, busy)) = last_round {
        let m = config.operator.operators;
        if m > 1 {
            // The sectored round (issue 44): the cell's tasks per hour, shared by M operators;
            // the busy share counts the ticks in which any of them is busy.
            println!(
                "round at iteration {k}: {throughput:.1} tasks per hour of the cell of {m} \
                 operators in sectors (planned), some operator busy {:.1} % of the round",
                100.0 * busy
            );
        } else {
            println!(
                "round at iteration {k}: {throughput:.1} tasks per hour per operator (planned), \
                 operator busy {:.1} % of the round",
                100.0 * busy
            );
        }
    }
    let (gap, unsupervised) = result.plan_gap_total(0);
    let rounds = config.trials * config.n_rounds();
    println!(
        "realized against planned T_total, {rounds} rounds: {}; needed but unsupervised: {} \
         samples ({:.1} per round)",
        gap.describe(),
        unsupervised,
        unsupervised as f64 / rounds.max(1) as f64
    );
    if !config.operator.is_default() {
        let (missed, rounds) = result.switch_missed_total();
        let op = &config.operator;
        println!(
            "operator: planned switch time δ {} s, load cap {}; own switch time δ_true {} s: {} \
             needed corrections missed while switching ({:.2} per round); realized T_total \
             {:.2} s per round on average (planned {:.2} s)",
            op.switch_s,
            op.max_busy_share,
            op.switch_true_s,
            missed,
            missed as f64 / rounds.max(1) as f64,
            gap.realized_s / rounds.max(1) as f64,
            gap.planned_s / rounds.max(1) as f64,
        );
    }
    print_ground_truth(&result);
    println!(
        "overlapping low-confidence ticks: {}",
        result.total_overlap_ticks()
    );
    println!(
        "wrote study.json, study.csv, fig5.svg, fig5.png in {}",
        out.display()
    );
    print_times(&times, wall.elapsed());
    if result.total_overlap_ticks() > 0 {
        bail!("both robots were low-confidence in the same tick: the schedule is unsafe");
    }
    Ok(())
}
