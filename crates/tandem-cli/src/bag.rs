//! ROS 2 bags on the command line: demonstrations and executions from rosbag2 MCAP files
//! (`fit`, `record`), a bag's topics (`inspect`), and simulated runs written as MCAP
//! (`simulate --bag`). The one place that dispatches on the extension `.mcap`.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use tandem::bag::{
    BagOptions, ExecutionOptions, Existing, Recording, Role, RunWriter, bag_file, count_rounds,
    extend_schema, inspect, is_bag, read_bag, read_executions,
};
use tandem::lfd::{ChannelSchema, Demonstration};
use tandem::sim::workcell::RoundRun;
use tandem::{ExecutionRecord, Planner};

use crate::cmd::{grouped_notes, out};
use crate::input;

/// `--topics /a,/b` as the reader's selection (`None` when not given).
fn topics(list: &[String]) -> Option<Vec<String>> {
    (!list.is_empty()).then(|| list.iter().map(|t| t.trim().to_owned()).collect())
}

/// The demonstrations of `tandem fit`: a bag (`.mcap`) resampled at `rate_hz` (default: its
/// slowest topic's median rate), a CSV or JSON file as before (`dt_s` for files without a
/// time column). The bags' pose orientations are added to `schema` as quaternion blocks.
pub(crate) fn read_demos(
    paths: &[PathBuf],
    dt_s: Option<f64>,
    rate_hz: Option<f64>,
    topic_list: &[String],
    schema: &mut ChannelSchema,
    resample: bool,
) -> Result<Vec<Demonstration>> {
    if let Some(r) = rate_hz
        && !(r.is_finite() && r > 0.0)
    {
        bail!("--rate {r}: the grid rate must be finite and > 0 Hz");
    }
    let any_bag = paths.iter().any(|p| is_bag(p));
    let any_bag = any_bag || paths.iter().any(|p| p.is_dir());
    if !any_bag && (rate_hz.is_some() || !topic_list.is_empty()) {
        bail!("--rate and --topics apply to ROS 2 bags (.mcap); no demonstration is one");
    }
    let options = BagOptions {
        topics: topics(topic_list),
        rate_hz,
        namespace: None,
    };
    let mut recordings: Vec<Recording> = Vec::new();
    let mut demos = Vec::with_capacity(paths.len());
    // `--resample` without `--dt`: the CSV logs go onto one grid when their loggers' clocks
    // merely drift apart (`input::read_demos_resampled`).
    let logs: Vec<&Path> = paths
        .iter()
        .filter(|p| !(is_bag(p) || p.is_dir()))
        .map(PathBuf::as_path)
        .collect();
    let mut resampled = if resample && dt_s.is_none() {
        input::read_demos_resampled(&logs)?.into_iter()
    } else {
        Vec::new().into_iter()
    };
    for p in paths {
        // A folder is a rosbag2 recording: its one .mcap file is read (or the folder is
        // refused with what it holds and the fix).
        if is_bag(p) || p.is_dir() {
            let rec = read_bag(bag_file(p)?, &options)?;
            demos.push(rec.demonstration()?);
            recordings.push(rec);
        } else if let Some(demo) = resampled.next() {
            demos.push(demo);
        } else {
            demos.push(if resample {
                input::read_demo_resampled(p, dt_s)?
            } else {
                input::read_demo(p, dt_s)?
            });
        }
    }
    // Which topic set each bag's grid, once for every bag it applies to.
    let grids: Vec<(String, String)> = recordings
        .iter()
        .filter_map(|r| Some((r.source.clone(), r.grid_reason()?)))
        .collect();
    grouped_notes(&grids);
    extend_schema(schema, &recordings);
    schema
        .validate()
        .context("the bags' orientations as quaternion blocks")?;
    Ok(demos)
}

/// The executions of one round for `tandem record` from bags: one bag holding every robot
/// (topics under `/robot_<i>`), or one bag per robot (robot 1 first). `round` picks a round
/// of a bag of several (a run `tandem simulate --bag` wrote).
pub(crate) fn read_round(
    planner: &Planner,
    bags: &[PathBuf],
    round: Option<usize>,
    topic_list: &[String],
) -> Result<Vec<ExecutionRecord>> {
    let n = planner.n_robots();
    let model = planner.model();
    let mut files = Vec::with_capacity(bags.len());
    for b in bags {
        if !is_bag(b) && !b.is_dir() {
            bail!(
                "{}: not a bag (.mcap); give CSV executions with --execution/--log/--corrections",
                b.display()
            );
        }
        files.push(bag_file(b)?);
    }
    let bags = &files[..];
    let per_bag: Vec<(PathBuf, Vec<usize>)> = match bags.len() {
        1 => vec![(bags[0].clone(), (1..=n).collect())],
        k if k == n => bags
            .iter()
            .enumerate()
            .map(|(i, b)| (b.clone(), vec![i + 1]))
            .collect(),
        k => bail!(
            "{k} bags given; the state has {n} robots: give one bag holding every robot \
             (/robot_1 … /robot_{n}) or one bag per robot (robot 1 first)"
        ),
    };
    let mut records = Vec::with_capacity(n);
    for (bag, robots) in per_bag {
        let options = ExecutionOptions {
            dt_s: model.dt_s(),
            robots: robots.clone(),
            round,
            topics: topics(topic_list),
        };
        let got = read_executions(&bag, &options)?;
        for (record, robot) in got.into_iter().zip(robots) {
            check_coverage(planner, robot, &record, &bag)?;
            records.push(record);
        }
    }
    Ok(records)
}

/// The library's check of an execution as it enters ([`Planner::check_execution`]: period,
/// coverage of the whole task, duration), with the bag and the robot named.
fn check_coverage(
    planner: &Planner,
    robot: usize,
    record: &ExecutionRecord,
    bag: &Path,
) -> Result<()> {
    planner
        .check_execution(record)
        .with_context(|| format!("{}: robot {robot}", bag.display()))?;
    Ok(())
}

/// `tandem inspect BAG`: every topic, its type, messages, rate and the channels it gives.
pub(crate) fn inspect_bag(path: &Path, as_json: bool) -> Result<()> {
    let file = bag_file(path)?;
    let path = file.as_path();
    let topics = inspect(path)?;
    let rounds = count_rounds(path)?;
    if as_json {
        let doc = crate::json::BagDoc {
            bag: path.display().to_string(),
            rounds,
            topics: topics
                .iter()
                .map(|t| crate::json::BagTopicOut {
                    topic: t.topic.clone(),
                    r#type: t.schema.clone(),
                    supported: t.msg_type.is_some(),
                    messages: t.messages,
                    channels: t.channels.clone(),
                    median_period_s: t.median_period_s,
                    period_s: t.period_s,
                    start_s: t.span_s.map(|s| s.0),
                    end_s: t.span_s.map(|s| s.1),
                    time: if t.log_time {
                        "log time"
                    } else {
                        "header stamp"
                    },
                    role: t.role.name(),
                })
                .collect(),
        };
        out(&serde_json::to_string_pretty(&crate::json::value(&doc)?)?);
        return Ok(());
    }
    out(&format!("bag {}: {} topics", path.display(), topics.len()));
    if rounds > 0 {
        out(&format!(
            "a run written by tandem: {rounds} round(s) (tandem record --round K reads one)"
        ));
    }
    for t in &topics {
        let ty = t.schema.as_deref().unwrap_or("no schema");
        let Some(period) = t.period_s else {
            out(&format!(
                "  {}  {ty}  {} messages  (not read: {})",
                t.topic,
                t.messages,
                if t.msg_type.is_some() || t.role == Role::View {
                    "viewing only"
                } else {
                    "unsupported type"
                }
            ));
            continue;
        };
        let (a, b) = t.span_s.unwrap_or((0.0, 0.0));
        out(&format!(
            "  {}  {ty}  {} messages  {} Hz  {:.3}–{:.3} s ({})  role {}",
            t.topic,
            t.messages,
            rate_text(period),
            a,
            b,
            if t.log_time {
                "log time"
            } else {
                "header stamps"
            },
            t.role.name()
        ));
        out(&format!("    channels: {}", t.channels.join(", ")));
    }
    Ok(())
}

/// A topic's rate from its period: `100.00` for whole rates (the period snapped to one), two
/// decimals otherwise.
fn rate_text(period_s: f64) -> String {
    format!("{:.2}", 1.0 / period_s)
}

/// `tandem simulate --bag`: the run's rounds written as they are simulated, the file put in
/// place at the end.
pub(crate) struct RunBag {
    writer: RunWriter,
    path: PathBuf,
}

impl RunBag {
    /// Starts the bag for `planner`'s robots and channels; refuses an existing file.
    pub(crate) fn create(path: &Path, planner: &Planner) -> Result<Self> {
        crate::state_io::check_writable(path)?;
        let writer = RunWriter::create(path, planner, Existing::Refuse)?;
        Ok(Self {
            writer,
            path: path.to_path_buf(),
        })
    }

    /// Writes one round run under `planner`'s current schedule (before it is recorded).
    pub(crate) fn write_round(&mut self, planner: &Planner, run: &RoundRun) -> Result<()> {
        self.writer.write_round(planner, run).with_context(|| {
            format!(
                "writing round {} into {}",
                self.writer.rounds() + 1,
                self.path.display()
            )
        })
    }

    /// Finishes the file and says so.
    pub(crate) fn finish(self) -> Result<()> {
        let rounds = self.writer.rounds();
        self.writer.finish()?;
        out(&format!(
            "wrote {} ({rounds} round(s); open it in Foxglove, or `tandem record STATE {} --round K`)",
            self.path.display(),
            self.path.display()
        ));
        Ok(())
    }
}
