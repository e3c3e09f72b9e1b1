//! Command-line arguments (clap derive).

use std::path::PathBuf;

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand, ValueEnum};
use tandem::lfd::{HoldRule, RateTerm, Reference};
use tandem::planner::Cell;
use tandem::sim::workcell::OperatorParams;

/// Coordinated multi-robot shared autonomy from your own demonstrations: one operator, 1 to 16
/// robots (2 by default, --robots N at fit) (Hagenow et al., RA-L 2023).
///
/// Typical session:
///
///   tandem fit demo_1.csv demo_2.csv demo_3.csv -o cell.tandem   # learn the task, first schedule
///   tandem schedule cell.tandem                 # show it (text Gantt; --json for robots)
///   tandem need cell.tandem --region 21.3-27.6=0.5 -o need.csv   # where workpieces need help
///   tandem simulate cell.tandem --need need.csv --rounds 5   # what-if, nothing saved
///   tandem record cell.tandem --execution a.csv --log a.reflog.csv --corrections a.corr.csv \
///                             --execution b.csv --log b.reflog.csv --corrections b.corr.csv
///   tandem inspect cell.tandem                  # model and confidence summary
///   tandem plot cell.tandem -o plots/           # SVG and PNG figures
///
/// Every user error prints `error: ...` naming the file and the problem and exits with
/// code 2; a failing command writes nothing and leaves the state file as it was.
/// File formats: docs/formats.md; walk-through: docs/guide.md ("Your own task, end to end"
/// for a task of your own, from CSV files to the robot loop in Python; its "Glossary" explains
/// every term tandem prints: certificate, latched, margin-aware, fallback, …).
#[derive(Debug, Parser)]
#[command(name = "tandem", version, verbatim_doc_comment)]
pub(crate) struct Cli {
    /// The command.
    #[command(subcommand)]
    pub(crate) command: Command,
    /// Print the full lists that are otherwise summarized: every hold-point stretch, one
    /// note per file (periods, jitter, bag grids), every stretch and the whole operator's
    /// order of a continuous plan.
    #[arg(short, long, global = true)]
    pub(crate) verbose: bool,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub(crate) enum Command {
    /// Learn the task model and the first schedule from demonstrations; write a state file.
    ///
    /// Aligns every demonstration to the reference (GDTW), computes the mean behaviour, its
    /// variability σ²_D(t), the demonstrated speed bounds and the admissible corrections,
    /// sets the confidence from the demonstrations alone (the prior) and samples a first
    /// schedule. The model's time axis is the reference's sample index. The reference is
    /// the medoid, the demonstration on whose time axis the demonstrations agree best (the
    /// model does not depend on the order of the files), or with --reference first the
    /// first file.
    ///
    /// Demonstrations are CSV (header of channel names, optional time column `t` in seconds),
    /// JSON ({"channels", "dt_s", "samples"}, extension `.json`), or ROS 2 bags (rosbag2
    /// MCAP, extension `.mcap`: every topic of a supported type resampled onto one grid,
    /// --rate, --topics; `tandem inspect BAG` lists the channels). They may be mixed if the
    /// channel names agree.
    ///
    /// Example:
    ///
    ///   tandem fit fixtures/sanding/demo_?.csv -o cell.tandem
    ///   tandem fit a.csv b.csv c.csv --ranges force=20,x=0.5 --params params.toml --samples 2000 -o cell.tandem
    ///   tandem fit fixtures/sanding/demo_?.csv --reference first -o cell.tandem
    ///   tandem fit fixtures/sanding/demo_?.csv --robots 3 -o cell3.tandem
    ///   tandem fit fixtures/examples/ros2/demo_?.mcap -o cell.tandem
    #[command(verbatim_doc_comment)]
    Fit(FitArgs),
    /// Re-optimize the schedule of a state file and show it (text Gantt, or JSON).
    ///
    /// Runs the anytime sampler warm-started with the saved schedule, so the result is never
    /// longer than the saved one. Without --seed it draws candidates from a seed stream that
    /// fit/record did not use (deterministic: the same state gives the same result). The
    /// state file is changed only with --save (atomically).
    /// The JSON (--json) has the offset τ, per-robot execution gradients, every
    /// low-confidence interval in global time and T_total: give it to the robots.
    ///
    /// With --cell continuous it shows instead the plan of a continuous cell (no rounds:
    /// each robot starts its next task as soon as the plan allows): the period, tasks per
    /// hour, the operator's busy share, a lower bound on the period and the gap to it, the
    /// operator's order of low-confidence stretches and a text Gantt of two periods. It
    /// assumes the operator follows the demonstrated mean speed; at run time
    /// `CyclicPlan::coordinator` (Python: `planner.continuous_coordinator()`) runs it, and
    /// `record` still learns from rounds. Many stretches and a long operator's order are
    /// summarized; --verbose prints them all.
    ///
    /// Example:
    ///
    ///   tandem schedule cell.tandem
    ///   tandem schedule cell.tandem --samples 20000 --seed 3 --save
    ///   tandem schedule cell.tandem --json > schedule.json
    ///   tandem schedule cell.tandem --cell continuous
    #[command(verbatim_doc_comment)]
    Schedule(ScheduleArgs),
    /// Add an executed round (one execution of each robot) (Eq. 21),
    /// update the confidence, re-schedule, save.
    ///
    /// Give exactly one execution per robot of the state file (robot 1 first; two unless
    /// fitted with --robots), each with its execution CSV, its reference-time log and its
    /// correction flags. Everything is checked before the state
    /// file is replaced (atomically); on any error it is left byte for byte as it was.
    ///
    /// Example:
    ///
    ///   tandem record cell.tandem \
    ///     --execution run1_robot1.csv --log run1_robot1.reflog.csv --corrections run1_robot1.corr.csv \
    ///     --execution run1_robot2.csv --log run1_robot2.reflog.csv --corrections run1_robot2.corr.csv
    ///   tandem record cell.tandem --resample --execution a.csv --log a.reflog.csv \
    ///     --corrections a.corr.csv …                          # irregular `t` (own clock)
    ///   tandem record cell.tandem round1.mcap                 # a ROS 2 bag of the round
    ///   tandem record cell.tandem run.mcap --round 3          # round 3 of simulate --bag
    #[command(verbatim_doc_comment)]
    Record(RecordArgs),
    /// Summarize the model, the confidence and the schedule of a state file.
    ///
    /// Example:
    ///
    ///   tandem inspect cell.tandem
    ///   tandem inspect cell.tandem --json
    ///   tandem inspect demo.mcap                # a bag's topics and channel names
    #[command(verbatim_doc_comment)]
    Inspect(InspectArgs),
    /// Draw the model, the confidence and the schedule as SVG and PNG files.
    ///
    /// Writes model.{svg,png} (mean ± one standard deviation per channel and the speed
    /// bounds over reference time), confidence.{svg,png} (σ²_D(t), the high-confidence
    /// map and the correction observations) and schedule.{svg,png} (every robot in global
    /// time; blue = robot 1 low-confidence, red = robot 2 low-confidence, …; the bottom row
    /// is whom the operator supervises). The folder is
    /// created if missing; existing files of these names are replaced.
    ///
    /// Example:
    ///
    ///   tandem plot cell.tandem -o plots/
    #[command(verbatim_doc_comment)]
    Plot(PlotArgs),
    /// What-if: run rounds (one execution of each robot) with a simulated operator on your
    /// model; nothing is saved.
    ///
    /// NEED.csv gives, per reference sample, the probability that a correction is needed
    /// (column `need`, optional integer column `region`: samples of one region share one
    /// draw per workpiece; without it, every run of consecutive equal non-zero values is a
    /// region). For each round, each robot's workpiece draws its needed regions, the
    /// robots run the current schedule through the real-time coordinator, the operator
    /// corrects the supervised (low-confidence) robot where needed (missing 1 %, and
    /// correcting 1 % of unneeded samples by default), and the round is recorded in memory
    /// exactly as `tandem record` would. Prints T_total and the share of high-confidence
    /// samples per round. With --write DIR, each execution is written in the formats
    /// `tandem record` reads (round_K_robot_I.csv, .reflog.csv, .corr.csv).
    ///
    /// Example:
    ///
    ///   tandem simulate cell.tandem --need need.csv --rounds 10
    ///   tandem simulate cell.tandem --need need.csv --rounds 2 --write sim/ --seed 7
    ///   tandem simulate cell.tandem --need need.csv --rounds 20 --bag run.mcap
    #[command(verbatim_doc_comment)]
    Simulate(SimulateArgs),
    /// Write a need file for `tandem simulate --need` from reference-time intervals.
    ///
    /// A region START-END=LEVEL says that a workpiece needs the operator from START to END
    /// (reference seconds, as `tandem inspect` prints them; START inclusive, END exclusive)
    /// with probability LEVEL in [0, 1]: one draw per region and workpiece, so a defect
    /// covers its whole region or none of it. Samples outside every region never need the
    /// operator. Instead of regions: a label file with one row per reference sample
    /// (--from-labels FILE --column NAME: each run of equal values is a region, the value its
    /// level, or --level P wherever the value is not 0), or every current low-confidence
    /// region of the state at one level (--low-confidence LEVEL).
    /// The output is a new file; an existing one is replaced only with --force.
    ///
    /// Example:
    ///
    ///   tandem need cell.tandem --region 21.3-27.6=0.5 --region 40-52=0.25 -o need.csv
    ///   tandem need cell.tandem --from-labels demo_0.labels.csv --column defect --level 0.5 -o need.csv
    ///   tandem need cell.tandem --low-confidence 0.5 -o need.csv
    #[command(verbatim_doc_comment)]
    Need(NeedArgs),
    /// Print the default parameter file (TOML) for `tandem fit --params`.
    ///
    /// Example:
    ///
    ///   tandem params > params.toml
    #[command(verbatim_doc_comment)]
    Params,
    /// The operator's console: a local web page showing which robot needs the operator now
    /// and next, with controls (acknowledge, hold, clear fault, pause).
    ///
    /// With --simulate, a simulated cell runs in real time from the state file: the
    /// planner's plan for --cell (rounds one after the other, or a continuous cell) with
    /// the study's simulated operator, ticked every control period divided by --speed. The
    /// page's URL is the first line of standard output; the server listens on 127.0.0.1
    /// (this machine) unless --host says otherwise; --port 0 picks a free port. Without
    /// --need, every low-confidence sample needs the operator. Runs until interrupted; the
    /// state file is not modified. The page's DOM and the frame format: docs/formats.md.
    ///
    /// --record FILE writes every tick of the simulated cell into a console recording
    /// (JSON Lines, docs/formats.md); with --until (`ticks:N`, `rounds:N`, `tasks:N`) the
    /// cell runs as fast as it can, without a server, until then. --replay FILE|DIR plays a
    /// recording on the same page at --speed (no state file needed); a damaged or truncated
    /// recording plays up to its damage and the page and the log say so. --check with
    /// --replay prints, as JSON, what the page showed on every tick against the coordinator
    /// (frames with two robots `lc`, frames whose `lc` robot is not the coordinator's, the
    /// pre-alert's notice before each low-confidence stretch) and exits.
    ///
    /// STATE --replay RUN.mcap replays a run bag (`tandem simulate --bag`): every tick of its
    /// rounds rebuilt from the bag's logs (reference times, supervised flags, schedule clocks)
    /// against the rounds plan of the state file the run was simulated from. A bag records
    /// no pre-alert: the page shows no countdown, and --check counts none.
    ///
    /// Example:
    ///
    ///   tandem console cell.tandem --simulate
    ///   tandem console cell.tandem --simulate --cell continuous --speed 2 --port 8080
    ///   tandem console cell.tandem --simulate --robots 3 --need need.csv
    ///   tandem console cell.tandem --simulate --record run.jsonl --until rounds:10
    ///   tandem console --replay run.jsonl --speed 4
    ///   tandem console --replay run.jsonl --check
    ///   tandem console cell.tandem --replay run.mcap --check
    #[command(verbatim_doc_comment)]
    Console(ConsoleArgs),
    /// Run the state file's coordinator live as a ROS 2 node (built with `--features ros2`).
    ///
    /// The coordinator ticks on its own thread at the schedule's tick; per robot K it
    /// publishes /tandem/robotK/command (reference time and speed scale, every tick),
    /// setpoint and needs_operator, and reads /tandem/robotK/progress; the operator's
    /// sensor_msgs/Joy on /tandem/operator sets the supervised robot's timing. Services
    /// (std_srvs/Trigger): /tandem/start_round, stop_round, clear_fault, record_round (into
    /// the state file, with the checks and lock of `tandem record`). A robot that stops
    /// reporting for --stall seconds holds the cell until clear_fault. docs/guide.md, "tandem
    /// in a ROS 2 graph".
    ///
    /// Example:
    ///
    ///   tandem node cell.tandem --domain 7
    ///   tandem node cell.tandem --cell continuous --robots 3 --seconds 600
    #[cfg(feature = "ros2")]
    #[command(verbatim_doc_comment)]
    Node(crate::node::NodeArgs),
}

/// `tandem console`.
#[derive(Debug, Args)]
pub(crate) struct ConsoleArgs {
    /// The state file (read only); with --replay only for a run bag (its plan).
    pub(crate) state: Option<PathBuf>,
    /// Run a simulated cell from the state file.
    #[arg(long)]
    pub(crate) simulate: bool,
    /// Replay a console recording (a file, or a directory holding console.jsonl), or with
    /// STATE a run bag (RUN.mcap, or a folder holding one).
    #[arg(long, value_name = "FILE|DIR|RUN.mcap", conflicts_with = "simulate")]
    pub(crate) replay: Option<PathBuf>,
    /// With --replay: print what the page showed against the coordinator (JSON) and exit.
    #[arg(long, requires = "replay")]
    pub(crate) check: bool,
    /// With --simulate: write every tick into this new console recording.
    #[arg(long, value_name = "FILE", requires = "simulate")]
    pub(crate) record: Option<PathBuf>,
    /// With --record: run as fast as possible without a server until `ticks:N`,
    /// `rounds:N` (rounds cells) or `tasks:N` (continuous cells: tasks of all robots).
    #[arg(long, value_name = "WHAT:N", requires = "record")]
    pub(crate) until: Option<String>,
    /// Robots of the simulated cell. Default: the state's. Another count is planned from the
    /// state's model, only for a state with no recorded round.
    #[arg(long, value_name = "N")]
    pub(crate) robots: Option<usize>,
    /// How the robots repeat the task.
    #[arg(long, value_name = "MODE", value_parser = cell_parser(), default_value = "rounds")]
    pub(crate) cell: Cell,
    /// Real-time factor of the simulation, in (0, 1000].
    #[arg(long, value_name = "X", default_value_t = 1.0)]
    pub(crate) speed: f64,
    /// Probability of a needed correction per reference sample (CSV, as `tandem simulate`'s),
    /// drawn once per robot.
    #[arg(long, value_name = "CSV")]
    pub(crate) need: Option<PathBuf>,
    /// Seed of the simulated operator and the need draws.
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub(crate) seed: u64,
    /// Port to listen on (0: any free port).
    #[arg(long, value_name = "P", default_value_t = 0)]
    pub(crate) port: u16,
    /// Address to listen on.
    #[arg(long, value_name = "IP", default_value_t = crate::console::localhost())]
    pub(crate) host: std::net::IpAddr,
    /// Lead of the pre-alert (s): the countdown turns amber this long before a handover.
    /// Default: 7 s, or the operator's switch time of the state's parameters
    /// (`[sampler] switch_s`) where it is longer.
    #[arg(long, value_name = "S")]
    pub(crate) lead: Option<f64>,
    /// Channel whose increase the simulated operator's corrections aim at. Default: the
    /// model's process quantity, as `tandem simulate`'s --channel
    #[arg(long, value_name = "NAME", requires = "simulate")]
    pub(crate) channel: Option<String>,
}

/// Overrides of the anytime sampler's settings.
#[derive(Debug, Args)]
pub(crate) struct SamplerArgs {
    /// Number of sampled candidate schedules (the paper uses 5000). Default: from the
    /// parameters (5000).
    #[arg(long, value_name = "N")]
    pub(crate) samples: Option<usize>,
    /// Master seed of the sampler. Default: from the parameters (0).
    #[arg(long, value_name = "S")]
    pub(crate) seed: Option<u64>,
    /// The operator's switch time δ in seconds (finite, ≥ 0; issue 41): at least this long
    /// between the end of one robot's low-confidence stretch and the start of another
    /// robot's, in the worst case (rounds and the continuous cell). Stored in the state file.
    /// Default: from the parameters (0: no switch time).
    #[arg(
        long = "switch-s",
        value_name = "SECONDS",
        allow_negative_numbers = true
    )]
    pub(crate) switch_s: Option<f64>,
    /// The operator's load cap u_max, a share of the time in (0, 1]: the operator's busy
    /// share (supervised time plus the switch time per change of robot) may not exceed it.
    /// Stored in the state file. Default: from the parameters (1: no cap).
    #[arg(long = "max-busy", value_name = "SHARE", allow_negative_numbers = true)]
    pub(crate) max_busy: Option<f64>,
    /// The cell's number of operators M (1 to 16; issue 44): a continuous cell runs M tokens,
    /// rounds run M sectors (the robots split evenly, each sector a one-operator round); at
    /// most M robots low-confidence at once, each with its own operator. Stored in the state
    /// file. Default: from the parameters (1).
    #[arg(long, value_name = "M")]
    pub(crate) operators: Option<usize>,
}

/// `tandem fit`.
#[derive(Debug, Args)]
pub(crate) struct FitArgs {
    /// Demonstration files (CSV, .json, or ROS 2 bags .mcap). At least two.
    #[arg(required_unless_present = "task", value_name = "DEMO")]
    pub(crate) demos: Vec<PathBuf>,
    /// A cell of different tasks on different robots (issue 45) instead of DEMO files: one
    /// task per --task, its name (letters, digits, `_`, `-`) and its demonstration files,
    /// e.g. `--task sanding=s0.csv,s1.csv --task deburring=d0.csv,d1.csv`; each task's
    /// robots by --robots NAME=K,… (1 each by default). The parameters (--params and the
    /// flags) apply to every task; the state holds every task's model, confidence and
    /// rounds (docs/guide.md, "Different tasks on different robots").
    #[arg(
        long,
        value_name = "NAME=FILE,…",
        conflicts_with_all = ["demos", "keep_rounds", "force", "ranges"]
    )]
    pub(crate) task: Vec<String>,
    /// Which demonstration is the reference, whose samples are the model's time axis:
    /// `medoid` (the one whose model has the least median σ²_D; n alignment passes instead
    /// of one; the model is the same for any order of the files) or `first` (the first
    /// file). Default: from the parameters (`[fit] reference`, `first`).
    #[arg(long, value_name = "CHOICE", value_enum)]
    pub(crate) reference: Option<ReferenceArg>,
    /// Per-coordinate ranges r_j of the weights W = diag(1/r_j²), as NAME=VALUE pairs
    /// (channel names, `<block>.rx|ry|rz` for quaternions, `rate` for the speed). Unnamed
    /// coordinates keep their automatic range (spread over all demonstrations).
    #[arg(long, value_name = "NAME=VALUE,…", value_delimiter = ',')]
    pub(crate) ranges: Vec<String>,
    /// How the demonstrations' speeds enter σ²_D: `relative` (speed differences relative to
    /// the local pace, opened over 13 samples, with the duration term over the default
    /// window), `absolute` (the paper's variance of the warp gradients), or
    /// `relative:opening=N,window=M` (odd widths in reference samples; window 0: no
    /// duration term). Default: from the parameters (`[fit] rate_term`, `relative`).
    #[arg(long, value_name = "FORM", value_parser = parse_rate_term)]
    pub(crate) rate_term: Option<RateTerm>,
    /// Parameter file (TOML, sections `[fit]`, `[confidence]`, `[sampler]`; `tandem params`
    /// prints the defaults).
    #[arg(long, value_name = "FILE")]
    pub(crate) params: Option<PathBuf>,
    /// Sample period (s) of demonstrations without a time column `t`. Default: 0.01. A file
    /// with its own time (`t`, JSON `dt_s`) uses it; a --dt that disagrees is an error.
    #[arg(long, value_name = "SECONDS")]
    pub(crate) dt: Option<f64>,
    /// Resample CSV demonstrations with an irregular `t` column (dropped samples, a drifting
    /// logger) onto an even grid: period --dt, or each file's logger period (the span over
    /// its steps, each counted in median steps), every file onto the period most of them
    /// share when the loggers' periods differ by at most 10 % (drifting clocks); channels are
    /// interpolated linearly, quaternions (`qx, qy, qz, qw`) by slerp, 0/1 channels held (the
    /// one resampling policy, as for executions and bags); a gap over 3 periods is refused.
    /// Without it,
    /// a `t` column must stay within 25 % of a period of its even grid.
    #[arg(long)]
    pub(crate) resample: bool,
    /// ROS 2 bags: rate (Hz) of the grid every topic is resampled onto. Default: each bag's
    /// slowest selected topic's median message rate.
    #[arg(long, value_name = "HZ")]
    pub(crate) rate: Option<f64>,
    /// ROS 2 bags: the topics to read (full names). Default: every topic of a supported type
    /// (PoseStamped, WrenchStamped, TwistStamped, JointState, Float64, Bool).
    #[arg(long, value_name = "/A,/B", value_delimiter = ',')]
    pub(crate) topics: Vec<String>,
    /// Robots run by the one operator, 1 to 16 (the paper: 2): every schedule has N warps and
    /// `tandem record` takes N executions per round. Stored in the state file. Default: 2,
    /// or with --keep-rounds the state's. With --task: each task's robots, NAME=K,… (robots
    /// numbered task by task in the order of the --task flags; a task not named has 1).
    #[arg(long, value_name = "N | NAME=K,…", value_parser = parse_robots)]
    pub(crate) robots: Option<RobotsArg>,
    /// Hold points at these reference times (s, the reference demonstration's clock), each at
    /// its nearest reference sample: places where a robot may wait as long as needed (the
    /// tool lifted, a part held); a hold on a low-confidence sample is inactive until the
    /// sample is trusted. Replaces the parameter file's `[holds] at_s`.
    #[arg(
        long,
        value_name = "SECONDS,…",
        value_delimiter = ',',
        allow_negative_numbers = true
    )]
    pub(crate) hold_at: Vec<f64>,
    /// Hold points wherever the mean of a channel satisfies a comparison, e.g.
    /// `--hold-where "tool<0.5"` or `gripper>=0.5` (`<`, `<=`, `>`, `>=`; quote it in a
    /// shell); a rule that holds nowhere is refused. Repeatable; replaces the
    /// parameter file's `[holds] rules`.
    #[arg(long, value_name = "RULE")]
    pub(crate) hold_where: Vec<HoldRule>,
    /// No hold points, also none from the parameter file: the schedule of before hold
    /// points existed, bit for bit.
    #[arg(long, conflicts_with_all = ["hold_at", "hold_where"])]
    pub(crate) no_holds: bool,
    /// Sampler overrides.
    #[command(flatten)]
    pub(crate) sampler: SamplerArgs,
    /// The state file to write (atomically). An existing state file that holds recorded
    /// rounds (the operator's corrections) is replaced only with --keep-rounds or --force.
    #[arg(short, long, value_name = "STATE")]
    pub(crate) output: PathBuf,
    /// Keep the rounds recorded in the state file -o: fit the new demonstrations, then replay
    /// every recorded round onto the new model in its order (executions, reference-time logs
    /// carried onto the new reference, supervised and corrected flags), as if recorded
    /// after a fresh fit. Rounds recorded by a tandem older than state format 11 cannot be
    /// replayed (their executions were not kept): refused, use --force.
    #[arg(long, conflicts_with = "force")]
    pub(crate) keep_rounds: bool,
    /// Replace the state file -o even if it holds recorded rounds, discarding them (says how
    /// many).
    #[arg(long)]
    pub(crate) force: bool,
}

/// `tandem fit --robots`: a robot count, or with `--task` each task's robots.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum RobotsArg {
    /// `N`: the robots of the one task.
    Count(usize),
    /// `NAME=K,…`: the robots of each task of a cell.
    PerTask(Vec<(String, usize)>),
}

/// Parses `--robots`: `N`, or `NAME=K,…` with each `K` a whole number ≥ 1.
fn parse_robots(s: &str) -> Result<RobotsArg, String> {
    if let Ok(n) = s.trim().parse::<usize>() {
        return Ok(RobotsArg::Count(n));
    }
    let mut per = Vec::new();
    for part in s.split(',') {
        let Some((name, k)) = part.split_once('=') else {
            return Err(format!(
                "`{part}`: give a robot count N, or NAME=K for each task of --task (e.g. \
                 sanding=2,deburring=1)"
            ));
        };
        let k = k
            .trim()
            .parse::<usize>()
            .ok()
            .filter(|&k| k >= 1)
            .ok_or_else(|| format!("`{part}`: K must be a whole number of robots ≥ 1"))?;
        per.push((name.trim().to_string(), k));
    }
    Ok(RobotsArg::PerTask(per))
}

/// `tandem fit --rate-term`: `tandem::lfd::RateTerm` by its parameter-file spelling; the error
/// names the choices (clap adds the flag).
fn parse_rate_term(s: &str) -> Result<RateTerm, String> {
    s.parse::<RateTerm>().map_err(|e| match e {
        tandem::lfd::Error::BadParam { why, .. } => why,
        other => other.to_string(),
    })
}

/// `tandem fit --reference`: `tandem::lfd::Reference` by its parameter-file names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum ReferenceArg {
    /// The first demonstration file.
    First,
    /// The demonstration whose model has the least median σ²_D.
    Medoid,
}

impl From<ReferenceArg> for Reference {
    fn from(r: ReferenceArg) -> Self {
        match r {
            ReferenceArg::First => Reference::First,
            ReferenceArg::Medoid => Reference::Medoid,
        }
    }
}

/// `tandem schedule`.
#[derive(Debug, Args)]
pub(crate) struct ScheduleArgs {
    /// The state file.
    pub(crate) state: PathBuf,
    /// Sampler overrides.
    #[command(flatten)]
    pub(crate) sampler: SamplerArgs,
    /// Print JSON instead of the text Gantt.
    #[arg(long)]
    pub(crate) json: bool,
    /// Save the re-optimized schedule into the state file (atomically).
    #[arg(long)]
    pub(crate) save: bool,
    /// How the cell runs: `rounds` (every robot starts together, the next round when the last
    /// one is done; the schedule `record` and the coordinator run) or `continuous` (each
    /// robot repeats the task on its own, one period per task: the cyclic plan, shown, never
    /// saved).
    #[arg(long, value_name = "MODE", value_parser = cell_parser(), default_value = "rounds")]
    pub(crate) cell: Cell,
}

/// `--cell`'s parser: the planner's [`Cell`] by its name, each value with its help
/// ([`Cell::help`]).
pub(crate) fn cell_parser() -> impl TypedValueParser<Value = Cell> {
    PossibleValuesParser::new(Cell::ALL.map(|c| PossibleValue::new(c.name()).help(c.help())))
        .try_map(|name| name.parse::<Cell>())
}

/// `tandem record`.
#[derive(Debug, Args)]
pub(crate) struct RecordArgs {
    /// The state file (updated atomically).
    pub(crate) state: PathBuf,
    /// ROS 2 bags (.mcap) of the round instead of CSV files: one bag holding every robot
    /// (topics under /robot_1 … /robot_N), or one bag per robot, robot 1 first; each robot's
    /// channel topics, a Float64 topic `ref_sample` and Bool topics `supervised`, `corrected`.
    #[arg(value_name = "BAG", conflicts_with_all = ["execution", "log", "corrections"])]
    pub(crate) bags: Vec<PathBuf>,
    /// With bags: the round to read from a bag of several (a run of `tandem simulate --bag`).
    #[arg(long, value_name = "K", requires = "bags")]
    pub(crate) round: Option<usize>,
    /// With bags: the topics to read (full names). Default: every topic of a supported type.
    #[arg(long, value_name = "/A,/B", value_delimiter = ',', requires = "bags")]
    pub(crate) topics: Vec<String>,
    /// Execution CSV of robot 1, then robot 2, … (channel columns, optional `t`).
    #[arg(
        long,
        value_name = "CSV",
        num_args = 1,
        required_unless_present = "bags"
    )]
    pub(crate) execution: Vec<PathBuf>,
    /// Reference-time log of each execution (column `ref_sample`), same order.
    #[arg(
        long,
        value_name = "CSV",
        num_args = 1,
        required_unless_present = "bags"
    )]
    pub(crate) log: Vec<PathBuf>,
    /// Correction flags of each execution (columns `supervised,corrected`), same order.
    #[arg(
        long,
        value_name = "CSV",
        num_args = 1,
        required_unless_present = "bags"
    )]
    pub(crate) corrections: Vec<PathBuf>,
    /// Resample execution CSVs with an irregular `t` column (jitter beyond a quarter
    /// period, dropped samples) onto the even grid of their logger's period, as `fit
    /// --resample` does; the log and the flags (one row per execution row) follow: log
    /// interpolated, a sample supervised where the nearest row was, corrected where any row
    /// of its period was. A grid finer than the model's is then resampled to it as usual.
    #[arg(long, conflicts_with = "bags")]
    pub(crate) resample: bool,
}

/// `tandem inspect`.
#[derive(Debug, Args)]
pub(crate) struct InspectArgs {
    /// The state file, or a ROS 2 bag (.mcap): its topics, types, rates and channel names.
    pub(crate) state: PathBuf,
    /// Print JSON.
    #[arg(long)]
    pub(crate) json: bool,
}

/// `tandem plot`.
#[derive(Debug, Args)]
pub(crate) struct PlotArgs {
    /// The state file.
    pub(crate) state: PathBuf,
    /// Output folder.
    #[arg(short, long, value_name = "DIR")]
    pub(crate) output: PathBuf,
}

/// `tandem need`.
#[derive(Debug, Args)]
pub(crate) struct NeedArgs {
    /// The state file (read only): its reference's length and sample period.
    pub(crate) state: PathBuf,
    /// A region START-END=LEVEL in reference seconds (repeatable; regions must not overlap).
    #[arg(long, value_name = "START-END=LEVEL", conflicts_with_all = ["from_labels", "low_confidence"])]
    pub(crate) region: Vec<String>,
    /// A CSV file with one row per reference sample (e.g. the reference demonstration's labels).
    #[arg(
        long,
        value_name = "CSV",
        requires = "column",
        conflicts_with = "low_confidence"
    )]
    pub(crate) from_labels: Option<PathBuf>,
    /// With --from-labels: the column to read.
    #[arg(long, value_name = "NAME", requires = "from_labels")]
    pub(crate) column: Option<String>,
    /// With --from-labels: the level of every sample whose value is not 0 (default: the
    /// values are the levels, each in [0, 1]).
    #[arg(long, value_name = "P", requires = "from_labels")]
    pub(crate) level: Option<f64>,
    /// Every current low-confidence region of the state, at this level.
    #[arg(long, value_name = "LEVEL")]
    pub(crate) low_confidence: Option<f64>,
    /// The need file to write (a new file unless --force).
    #[arg(short, long, value_name = "CSV")]
    pub(crate) output: PathBuf,
    /// Replace an existing output file.
    #[arg(long)]
    pub(crate) force: bool,
}

/// `tandem simulate`. The operator's defaults are the study's
/// (`tandem::sim::workcell::OperatorParams::default()`).
#[derive(Debug, Args)]
pub(crate) struct SimulateArgs {
    /// The state file (read only).
    pub(crate) state: PathBuf,
    /// Probability of a needed correction per reference sample (CSV, see docs/formats.md).
    #[arg(long, value_name = "CSV")]
    pub(crate) need: PathBuf,
    /// Number of rounds to run (a round is one execution of each robot of the state file).
    #[arg(long, value_name = "N", required_unless_present = "pairs")]
    pub(crate) rounds: Option<usize>,
    /// Deprecated alias of `--rounds` (kept one release; prints a deprecation line on stderr).
    #[arg(long, value_name = "N", hide = true, conflicts_with = "rounds")]
    pub(crate) pairs: Option<usize>,
    /// Write every execution into this folder in `tandem record`'s formats.
    #[arg(long, value_name = "DIR")]
    pub(crate) write: Option<PathBuf>,
    /// Write the run as one ROS 2 bag (MCAP, a new file) for Foxglove: per robot the commanded
    /// pose and channels, low-confidence and corrected flags, reference time, schedule clock
    /// and waits; the schedule of every round.
    #[arg(long, value_name = "FILE.mcap")]
    pub(crate) bag: Option<PathBuf>,
    /// Seed of the simulated workpieces and operator.
    #[arg(long, value_name = "S", default_value_t = 0)]
    pub(crate) seed: u64,
    /// Probability that the operator misses a needed correction, in [0, 1].
    #[arg(long, value_name = "P", default_value_t = OperatorParams::default().miss_rate)]
    pub(crate) miss_rate: f64,
    /// Share of the supervised samples needing no correction that the operator corrects
    /// anyway, in [0, 1).
    #[arg(long, value_name = "P", default_value_t = OperatorParams::default().false_correction_rate)]
    pub(crate) false_rate: f64,
    /// Mean duration (s) of one unneeded correction episode (0: every control tick drawn
    /// on its own).
    #[arg(long, value_name = "S", default_value_t = OperatorParams::default().false_correction_s)]
    pub(crate) false_episode: f64,
    /// Channel whose increase a correction aims at. Default: the model's process quantity
    /// (the first of force, fz, torque, tz, flow, pressure, depth, width it has, else its
    /// first scalar channel that is not a position)
    #[arg(long, value_name = "NAME")]
    pub(crate) channel: Option<String>,
}
