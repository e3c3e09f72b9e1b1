//! Console recordings and their replay (`tandem console --replay FILE|DIR`): a recorded run is
//! a JSON Lines file (docs/formats.md, "Console recordings") of a header — the plan's
//! [`Geometry`], the robot count, the control period — and one line per control tick with
//! each robot's snapshot as the loop published it (the [`RawFrame`]'s state, schedule clock,
//! reference time, tasks) and the coordinator's own supervised robot
//! (`Controller::low_conf_now`). [`Recorder`] writes it (`tandem console --simulate --record
//! FILE`, or [`crate::record_sim`] as fast as the machine runs); [`read_recording`] reads it
//! back, keeping every tick before a damaged or truncated line and saying what is wrong;
//! [`replay`] plays it into a console at a chosen speed through the same handle, server and
//! page as a live cell; [`check_recording`] measures, on every tick's frame, what the page
//! shows against what the coordinator decided (the must-show).

use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use serde::{Deserialize, Serialize};
use tandem_realtime::{Controller, MAX_ROBOTS, PreAlert, Tick};

use crate::error::{Error, Result};
use crate::frame::{Geometry, RawFrame, RawRobot, RobotState, build_frame};
use crate::handle::{ConsoleHandle, Op};
use crate::server::Console;

/// The `format` of a recording's header.
pub const RECORDING_FORMAT: &str = "tandem-console-recording";
/// The recording format's version this build writes and reads.
pub const RECORDING_VERSION: u32 = 1;
/// The file a recording directory holds (`--replay DIR` reads `DIR/console.jsonl`).
pub const RECORDING_FILE: &str = "console.jsonl";

/// A recording's first line.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    format: String,
    version: u32,
    cell: String,
    n_robots: usize,
    tick_s: f64,
    geometry: Geometry,
    /// The schedule and its certificate, in words (the page's health).
    #[serde(default)]
    schedule: Option<String>,
}

/// One robot of a recorded tick.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordedRobot {
    /// Its state on the page.
    pub state: RobotState,
    /// Its schedule clock (s) in its current task.
    pub clock_s: f64,
    /// Its reference time (reference samples) in its current task.
    pub ref_time: f64,
    /// Tasks it completed.
    pub tasks: u64,
}

/// One recorded control tick.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordedTick {
    /// Cell time (s) since the recording's first tick.
    pub t_s: f64,
    /// The controller's tick count (restarts with each round).
    pub tick: u64,
    /// Rounds completed before this tick.
    pub rounds_done: u64,
    /// Whether a fault was latched.
    pub fault: bool,
    /// Every robot, robot 1 first.
    pub robots: Vec<RecordedRobot>,
    /// The robot (1-based) the coordinator supervised (`Controller::low_conf_now`), if any.
    pub coordinator_lc: Option<usize>,
    /// The coordinator's pre-alert (`Tick::next`), if any.
    #[serde(default)]
    pub next: Option<RecordedPreAlert>,
}

/// The coordinator's pre-alert of a recorded tick (`tandem_realtime::PreAlert`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordedPreAlert {
    /// The robot (1-based) whose next low-confidence stretch can start soonest.
    pub robot: usize,
    /// Lower bound (s) on the time until it starts, from the tick.
    pub earliest_s: f64,
    /// Upper bound (s); `None` when unbounded.
    pub latest_s: Option<f64>,
}

impl RecordedTick {
    pub(crate) fn raw(&self, tick_s: f64) -> RawFrame {
        let mut raw = RawFrame {
            n: self.robots.len().min(MAX_ROBOTS),
            tick: self.tick,
            tick_s,
            rounds_done: self.rounds_done,
            fault: self.fault,
            // The countdown the loop's page showed: the coordinator's pre-alert of the tick.
            next: self.next.map(|p| PreAlert {
                robot: p.robot.saturating_sub(1),
                earliest_s: p.earliest_s,
                latest_s: p.latest_s.unwrap_or(f64::INFINITY),
            }),
            ..RawFrame::default()
        };
        for (r, t) in raw.robots.iter_mut().zip(&self.robots) {
            *r = RawRobot {
                state: t.state,
                clock_s: t.clock_s,
                ref_time: t.ref_time,
                tasks: t.tasks,
                // Recordings do not carry the operator's input: the page shows none.
                corrections: 0,
            };
        }
        raw
    }
}

/// Frames per second of cell time a recording keeps at least (the page's rate).
pub const RECORDING_HZ: f64 = 30.0;

/// Writes a recording: one line per page frame — every tick at which a robot's state, the
/// fault or the round changes, and otherwise one tick per `1/RECORDING_HZ` s of cell time
/// ([`RECORDING_HZ`]: the page's own rate) — flushed every 256 lines and at
/// [`Recorder::flush`] (a run cut short leaves a file that reads back up to its last whole
/// line).
#[derive(Debug)]
pub struct Recorder {
    path: PathBuf,
    out: BufWriter<File>,
    lines: u64,
    tick_s: f64,
    /// Ticks recorded or skipped so far.
    seen: u64,
    /// Cell time of the last line written, and its states.
    last: Option<(f64, bool, u64, Vec<usize>)>,
}

impl Recorder {
    /// Creates `path` (refusing an existing file) and writes the header of the cell of
    /// `geometry` ticked every `tick_s` s, running the schedule described by `schedule` (its
    /// source and certificate in words, shown in the page's health), if known.
    ///
    /// # Errors
    /// [`Error::Recording`] when the file exists or cannot be written.
    pub fn create(
        path: impl AsRef<Path>,
        geometry: &Geometry,
        tick_s: f64,
        schedule: Option<&str>,
    ) -> Result<Recorder> {
        let path = path.as_ref().to_path_buf();
        let err = |why: String| Error::Recording {
            path: path.display().to_string(),
            why,
        };
        let file = File::options()
            .write(true)
            .create_new(true)
            .open(&path)
            .map_err(|e| {
                if e.kind() == std::io::ErrorKind::AlreadyExists {
                    err("exists; a recording never overwrites a file: choose another name".into())
                } else {
                    err(format!("cannot create the recording: {e}"))
                }
            })?;
        let header = Header {
            format: RECORDING_FORMAT.to_string(),
            version: RECORDING_VERSION,
            cell: if geometry.is_rounds() {
                "rounds"
            } else {
                "continuous"
            }
            .to_string(),
            n_robots: geometry.n_robots(),
            tick_s,
            geometry: geometry.clone(),
            schedule: schedule.map(str::to_string),
        };
        let mut rec = Recorder {
            out: BufWriter::new(file),
            path,
            lines: 0,
            tick_s,
            seen: 0,
            last: None,
        };
        let line = serde_json::to_string(&header).map_err(|e| rec.err(e.to_string()))?;
        rec.line(&line)?;
        Ok(rec)
    }

    fn err(&self, why: String) -> Error {
        Error::Recording {
            path: self.path.display().to_string(),
            why,
        }
    }

    fn line(&mut self, line: &str) -> Result<()> {
        writeln!(self.out, "{line}").map_err(|e| self.err(format!("cannot write: {e}")))?;
        self.lines += 1;
        if self.lines % 256 == 0 {
            self.flush()?;
        }
        Ok(())
    }

    /// Records the snapshot of `ctl` after `tick` (`rounds`: a rounds cell; `rounds_done`:
    /// rounds completed before it).
    ///
    /// # Errors
    /// [`Error::Recording`] when the file cannot be written.
    pub fn record<C: Controller + ?Sized>(
        &mut self,
        tick: &Tick,
        ctl: &C,
        rounds: bool,
        rounds_done: u64,
    ) -> Result<()> {
        let raw = RawFrame::from_controller(tick, ctl, rounds);
        let t_s = self.seen as f64 * self.tick_s;
        self.seen += 1;
        let mut states: Vec<usize> = raw.robots[..raw.n]
            .iter()
            .map(|r| r.state as usize)
            .collect();
        states.push(tick.next.map_or(0, |p| p.robot + 1));
        if let Some((last_s, fault, round, last_states)) = &self.last {
            let changed = *fault != raw.fault || *round != rounds_done || *last_states != states;
            if !changed && t_s - last_s < 1.0 / RECORDING_HZ - 1e-9 {
                return Ok(());
            }
        }
        self.last = Some((t_s, raw.fault, rounds_done, states));
        let low = ctl.low_conf_now();
        let t = RecordedTick {
            t_s,
            tick: raw.tick,
            rounds_done,
            fault: raw.fault,
            robots: raw.robots[..raw.n]
                .iter()
                .map(|r| RecordedRobot {
                    state: r.state,
                    clock_s: r.clock_s,
                    ref_time: r.ref_time,
                    tasks: r.tasks,
                })
                .collect(),
            coordinator_lc: (0..raw.n).find(|&i| low[i]).map(|i| i + 1),
            next: tick.next.map(|p| RecordedPreAlert {
                robot: p.robot + 1,
                earliest_s: p.earliest_s,
                latest_s: p.latest_s.is_finite().then_some(p.latest_s),
            }),
        };
        let line = serde_json::to_string(&t).map_err(|e| self.err(e.to_string()))?;
        self.line(&line)
    }

    /// Writes what is buffered to the file.
    ///
    /// # Errors
    /// [`Error::Recording`] when the file cannot be written.
    pub fn flush(&mut self) -> Result<()> {
        self.out
            .flush()
            .map_err(|e| self.err(format!("cannot write: {e}")))
    }
}

/// A recording read back ([`read_recording`]).
#[derive(Clone, Debug)]
pub struct Recording {
    /// The file read.
    pub path: PathBuf,
    /// The plan.
    pub geometry: Geometry,
    /// Control period (s).
    pub tick_s: f64,
    /// The schedule and its certificate, in words, if the recording says.
    pub schedule: Option<String>,
    /// Every tick read, in order.
    pub ticks: Vec<RecordedTick>,
    /// What stopped the reading before the end of the file (a damaged or truncated line), if
    /// anything: the ticks before it are kept.
    pub problem: Option<String>,
}

/// The first bytes of an MCAP file (a ROS 2 bag, tandem-bag's run bags).
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";

/// Whether `path` is an MCAP bag, or a folder holding one and no console recording
/// (`tandem console STATE --replay RUN.mcap` replays it with the state file).
#[must_use]
pub fn looks_like_bag(path: &Path) -> bool {
    if path.is_dir() {
        !path.join(RECORDING_FILE).exists() && dir_holds_a_bag(path)
    } else {
        is_bag(path)
    }
}

/// Whether `path` is an MCAP bag: its extension, or its first bytes.
fn is_bag(path: &Path) -> bool {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
    {
        return true;
    }
    let mut head = [0u8; 8];
    File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
        .is_ok_and(|()| head == MCAP_MAGIC)
}

/// Whether directory `dir` holds an MCAP bag (a rosbag2 folder, a run's outputs).
fn dir_holds_a_bag(dir: &Path) -> bool {
    std::fs::read_dir(dir).is_ok_and(|entries| {
        entries.flatten().any(|e| {
            e.path()
                .extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("mcap"))
        })
    })
}

/// The refusal of a bag as a replay (docs/decisions.md, "The console's replay: what a recorded
/// run is, …"): what it lacks and what to record instead.
fn not_a_bag(path: &Path) -> Error {
    Error::Recording {
        path: path.display().to_string(),
        why: "an MCAP bag is not a console recording: a run bag holds each round's logs and \
              schedule, not the plan's speed bounds the page needs; pass the state file the \
              run was simulated from before it (`tandem console STATE --replay RUN.mcap`), or \
              record the run for the console with `tandem console STATE --simulate --record \
              FILE [--until …]` (or `tandem_console::Recorder` in your own loop) and replay \
              that file with `--replay FILE`"
            .into(),
    }
}

/// Reads the recording at `path`: a file, or a directory holding [`RECORDING_FILE`]. A bag
/// (an `.mcap` file, a file that starts as one, a directory of one without the recording) is
/// refused with what to record instead. The ticks
/// up to the first damaged line are kept and the damage is described in
/// [`Recording::problem`] (a run cut short, a file truncated in a copy).
///
/// # Errors
/// [`Error::Recording`] when the file cannot be opened or its header is not a recording's
/// (naming the line and what was expected).
pub fn read_recording(path: impl AsRef<Path>) -> Result<Recording> {
    let mut path = path.as_ref().to_path_buf();
    if path.is_dir() {
        let inner = path.join(RECORDING_FILE);
        if !inner.exists() && dir_holds_a_bag(&path) {
            return Err(not_a_bag(&path));
        }
        path = inner;
    }
    if is_bag(&path) {
        return Err(not_a_bag(&path));
    }
    let shown = path.display().to_string();
    let err = |line: usize, why: String| Error::Recording {
        path: if line > 0 {
            format!("{shown}:{line}")
        } else {
            shown.clone()
        },
        why,
    };
    let file = File::open(&path).map_err(|e| {
        err(
            0,
            format!(
                "cannot open the recording: {e} (a recording is written by `tandem console \
                 --simulate --record FILE`; a directory must hold {RECORDING_FILE})"
            ),
        )
    })?;
    let mut lines = BufReader::new(file).split(b'\n');
    let first = match lines.next() {
        None => return Err(err(1, "empty file: not a console recording".into())),
        Some(Err(e)) => return Err(err(1, format!("cannot read: {e}"))),
        Some(Ok(l)) => l,
    };
    let header: Header = serde_json::from_slice(&first).map_err(|e| {
        err(
            1,
            format!("not a console recording's header ({e}); expected {{\"format\": \"{RECORDING_FORMAT}\", …}}"),
        )
    })?;
    if header.format != RECORDING_FORMAT {
        return Err(err(
            1,
            format!("format `{}` is not `{RECORDING_FORMAT}`", header.format),
        ));
    }
    if header.version != RECORDING_VERSION {
        return Err(err(
            1,
            format!(
                "recording version {} (this tandem reads version {RECORDING_VERSION}): \
                 record it again with this tandem",
                header.version
            ),
        ));
    }
    let n = header.n_robots;
    if !(1..=MAX_ROBOTS).contains(&n) || n != header.geometry.n_robots() {
        return Err(err(
            1,
            format!(
                "n_robots {n} must be in 1..={MAX_ROBOTS} and match the plan's {} robots",
                header.geometry.n_robots()
            ),
        ));
    }
    if !(header.tick_s > 0.0 && header.tick_s.is_finite()) {
        return Err(err(
            1,
            format!("tick_s {} must be finite and > 0", header.tick_s),
        ));
    }
    if header.cell
        != if header.geometry.is_rounds() {
            "rounds"
        } else {
            "continuous"
        }
    {
        return Err(err(
            1,
            format!("cell `{}` does not match the plan", header.cell),
        ));
    }
    let mut ticks = Vec::new();
    let mut problem = None;
    let mut last_t_s = 0.0f64;
    for (k, line) in lines.enumerate() {
        let no = k + 2;
        let line = match line {
            Ok(l) => l,
            Err(e) => {
                problem = Some(format!("line {no}: cannot read: {e}"));
                break;
            }
        };
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let t: RecordedTick = match serde_json::from_slice(&line) {
            Ok(t) => t,
            Err(e) => {
                let what = if e.is_eof() { "truncated" } else { "damaged" };
                problem = Some(format!("line {no} is {what} ({e})"));
                break;
            }
        };
        let finite = t.t_s.is_finite()
            && t.t_s >= last_t_s
            && t.robots
                .iter()
                .all(|r| r.clock_s.is_finite() && r.ref_time.is_finite() && r.ref_time >= 0.0);
        if t.robots.len() != n || !finite || t.coordinator_lc.is_some_and(|k| k == 0 || k > n) {
            problem = Some(format!(
                "line {no} is damaged: {n} robots with finite clocks and reference times, a \
                 supervised robot in 1..={n} and a cell time t_s not before the line before \
                 expected"
            ));
            break;
        }
        last_t_s = t.t_s;
        ticks.push(t);
    }
    Ok(Recording {
        path,
        geometry: header.geometry,
        tick_s: header.tick_s,
        schedule: header.schedule,
        ticks,
        problem,
    })
}

fn unix_ms() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64() * 1e3)
}

/// Plays `rec` into the console `console` through `handle` (from [`Console::start`] with
/// the recording's geometry), one recorded tick every `tick_s / speed` real seconds, until
/// `stop` is set: the page shows the recorded cell as it ran. Pause and resume work; the
/// controls that would change the cell (hold, clear fault) are refused with the reason. A
/// damaged or truncated recording plays up to its damage, and the page and the log say so;
/// the page says when the replay has ended.
///
/// # Errors
/// [`Error::BadParam`] for a `speed` outside (0, 1000].
pub fn replay(
    rec: &Recording,
    speed: f64,
    console: &Console,
    mut handle: ConsoleHandle,
    stop: &AtomicBool,
) -> Result<()> {
    if !(speed > 0.0 && speed <= 1000.0) {
        return Err(Error::BadParam {
            name: "speed",
            why: "must be in (0, 1000]",
        });
    }
    let damage = rec.problem.as_ref().map(|p| {
        if rec.ticks.is_empty() {
            format!("cannot replay {}: {p}", rec.path.display())
        } else {
            format!(
                "recording {} is damaged: {p}; replaying the {} frames before it",
                rec.path.display(),
                rec.ticks.len()
            )
        }
    });
    if let Some(d) = &damage {
        eprintln!("console: {d}");
    }
    console.set_notice(damage.clone());
    let period_s = rec.tick_s / speed;
    let mut paused = false;
    let mut base = Instant::now();
    let mut base_t_s = rec.ticks.first().map_or(0.0, |t| t.t_s);
    let mut next = 0usize;
    let mut ended = false;
    let publish = |handle: &mut ConsoleHandle, k: usize, paused: bool| {
        if let Some(t) = rec.ticks.get(k) {
            let mut raw = t.raw(rec.tick_s);
            raw.paused = paused;
            // The health line's `published`: recorded frames handed over so far.
            raw.published = k as u64 + 1;
            raw.published_unix_ms = unix_ms();
            handle.publish_raw(&raw);
        }
    };
    if rec.ticks.is_empty() {
        // Nothing to show but the notice: an empty snapshot keeps the frames coming.
        handle.publish_raw(&RawFrame {
            tick_s: rec.tick_s,
            published_unix_ms: unix_ms(),
            ..RawFrame::default()
        });
    }
    while !stop.load(Ordering::Relaxed) {
        while let Some(msg) = handle.poll_control() {
            let (ok, text) = match msg.op {
                Op::Pause => {
                    paused = true;
                    (true, "replay paused".to_string())
                }
                Op::Resume => {
                    if paused {
                        paused = false;
                        base = Instant::now();
                        base_t_s = next
                            .checked_sub(1)
                            .and_then(|k| rec.ticks.get(k))
                            .map_or(0.0, |t| t.t_s);
                        // The frame shown, no longer paused, now: the next recorded tick may
                        // be far off, or none be left (a replay resumed after its end).
                        publish(&mut handle, next.saturating_sub(1), false);
                    }
                    (true, "replay resumed".to_string())
                }
                Op::Acknowledge => (true, "handover acknowledged (replay)".to_string()),
                Op::Claim | Op::Release => (true, "answered by the server".to_string()),
                op => (
                    false,
                    format!(
                        "a replay shows a recorded cell and cannot change it: `{}` does not apply",
                        op.name()
                    ),
                ),
            };
            handle.confirm(&msg, ok, text);
        }
        if paused {
            publish(&mut handle, next.saturating_sub(1), true);
        } else if next < rec.ticks.len() {
            // Cell time due now: the base's cell time plus the real time since, times speed.
            let due_s = base_t_s + base.elapsed().as_secs_f64() * speed;
            let mut published = None;
            while next < rec.ticks.len() && rec.ticks[next].t_s <= due_s {
                published = Some(next);
                next += 1;
            }
            // Only the newest is published: the page would drop the others anyway.
            if let Some(k) = published {
                publish(&mut handle, k, false);
            }
        } else if !ended && !rec.ticks.is_empty() {
            ended = true;
            let last = rec.ticks.last().map_or(0.0, |t| t.t_s);
            let text = format!(
                "replay ended: {} frames, {:.1} s of cell time{}",
                rec.ticks.len(),
                last,
                damage.as_ref().map_or(String::new(), |d| format!("; {d}"))
            );
            eprintln!("console: {text}");
            console.set_notice(Some(text));
        }
        std::thread::sleep(Duration::from_secs_f64(period_s.clamp(0.001, 0.02)));
    }
    Ok(())
}

/// What the page showed against the coordinator over every tick of a recording
/// ([`check_recording`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ReplayCheck {
    /// Frames checked (one per recorded tick).
    pub frames: usize,
    /// Frames with two or more robots `lc` on the page.
    pub two_lc: usize,
    /// Frames whose `lc` robot (or none) is not the coordinator's supervised robot.
    pub lc_differs: usize,
    /// Low-confidence stretches that started during the recording (a robot became `lc`).
    pub stretches: usize,
    /// Of them, those the schedule gave at least `lead_s` of notice: the stretch is certain to
    /// be the next one from the start of the stretch before it (any robot's; until that one
    /// starts, it is the next), the round's start or the recording's start, whichever is
    /// latest, and that moment is at least `lead_s` before it. In rounds it must also follow
    /// the stretch that the plan's order of the round puts before it (`out_of_order`
    /// otherwise): a stretch that the run's pace moved ahead of another was not fixed by the
    /// schedule when the stretch before it started, so no worst-case pre-alert could name it
    /// then. Docs: docs/formats.md, "Console recordings".
    pub allowed: usize,
    /// Rounds: stretches whose stretch before (or the round's start, for the first) is not
    /// the one before them in the plan's order of the round (by schedule clock): never
    /// allowed. 0 for a continuous cell (its coordinator keeps the token order).
    #[serde(default)]
    pub out_of_order: usize,
    /// Of the allowed, those the page pre-alerted (the countdown naming the robot with
    /// `prealert` on, without a break until the stretch began) at least `lead_s` ahead.
    pub alerted: usize,
    /// Of the allowed, those pre-alerted at least `lead_s − 1/RECORDING_HZ` ahead (one
    /// frame of the page short).
    pub alerted_within_frame: usize,
    /// The shortest pre-alert (s) over the allowed stretches.
    pub min_notice_s: Option<f64>,
    /// As `alerted`, for the coordinator's own pre-alert (`Tick::next`: on while its
    /// `earliest_s ≤ lead_s`, naming the robot).
    pub contract_alerted: usize,
    /// As `alerted_within_frame`, for the coordinator's pre-alert.
    pub contract_alerted_within_frame: usize,
    /// As `min_notice_s`, for the coordinator's pre-alert.
    pub contract_min_notice_s: Option<f64>,
    /// The pre-alert's lead (s) checked.
    pub lead_s: f64,
}

/// Builds the page's frame of every tick of `rec` (as [`replay`] serves it, with the pre-alert
/// lead `lead_s`) and counts: frames with two `lc` robots, frames whose `lc` robot is not the
/// coordinator's, and the pre-alert's notice before each low-confidence stretch.
#[must_use]
pub fn check_recording(rec: &Recording, lead_s: f64) -> ReplayCheck {
    let mut g = rec.geometry.clone();
    g.lead_s = lead_s;
    let mut c = ReplayCheck {
        lead_s,
        ..ReplayCheck::default()
    };
    let eps = 1e-6;
    let mut prev_attention: Option<usize> = None;
    // Time of the latest event from which the next stretch could be known as next.
    let mut known_from_s = 0.0f64;
    // Start of the current uninterrupted pre-alert (robot, since): the page's, the contract's.
    let mut alert: Option<(usize, f64)> = None;
    let mut contract: Option<(usize, f64)> = None;
    let mut last_round = 0u64;
    // Rounds: the plan's order of a round, and the run of the last stretch this round.
    let plan = g.plan_order();
    let mut last_run: Option<(usize, usize)> = None;
    for (k, t) in rec.ticks.iter().enumerate() {
        let t_s = t.t_s;
        let raw = t.raw(rec.tick_s);
        let f = build_frame(&g, &raw);
        c.frames += 1;
        let lc: Vec<usize> = f
            .robots
            .iter()
            .filter(|r| r.state == RobotState::Lc)
            .map(|r| r.robot)
            .collect();
        if lc.len() >= 2 {
            c.two_lc += 1;
        }
        if lc.first().copied() != t.coordinator_lc {
            c.lc_differs += 1;
        }
        if t.rounds_done != last_round {
            last_round = t.rounds_done;
            known_from_s = t_s;
            alert = None;
            contract = None;
            last_run = None;
        }
        let attention = f.attention.as_ref().map(|a| a.robot);
        if let Some(r) = attention {
            // The stretch's run, and whether the plan puts the last stretch right before it.
            let i = r.saturating_sub(1);
            let run = t
                .robots
                .get(i)
                .and_then(|x| g.run_at(i, x.ref_time))
                .map(|m| (i, m));
            let in_order = plan.as_ref().is_none_or(|p| {
                run.and_then(|x| p.iter().position(|&e| e == x))
                    .is_some_and(|q| q.checked_sub(1).map(|q| p[q]) == last_run)
            });
            if prev_attention != Some(r) && k > 0 {
                c.stretches += 1;
                if !in_order {
                    c.out_of_order += 1;
                }
                let allowed_s = t_s - known_from_s;
                if in_order && allowed_s >= lead_s - eps {
                    c.allowed += 1;
                    let notice = alert.filter(|a| a.0 == r).map_or(0.0, |a| t_s - a.1);
                    if notice >= lead_s - eps {
                        c.alerted += 1;
                    }
                    if notice >= lead_s - 1.0 / RECORDING_HZ - eps {
                        c.alerted_within_frame += 1;
                    }
                    c.min_notice_s = Some(c.min_notice_s.map_or(notice, |m| m.min(notice)));
                    let notice = contract.filter(|a| a.0 == r).map_or(0.0, |a| t_s - a.1);
                    if notice >= lead_s - eps {
                        c.contract_alerted += 1;
                    }
                    if notice >= lead_s - 1.0 / RECORDING_HZ - eps {
                        c.contract_alerted_within_frame += 1;
                    }
                    c.contract_min_notice_s =
                        Some(c.contract_min_notice_s.map_or(notice, |m| m.min(notice)));
                }
                known_from_s = t_s;
            }
            if prev_attention != Some(r) {
                last_run = run;
            }
        }
        prev_attention = attention;
        // The pre-alerts after this tick.
        let on = |now: Option<usize>, was: Option<(usize, f64)>| match (now, was) {
            (Some(r), Some((w, since))) if r == w => Some((r, since)),
            (Some(r), _) => Some((r, t_s)),
            (None, _) => None,
        };
        alert = on(
            f.next.as_ref().filter(|_| f.prealert).map(|n| n.robot),
            alert,
        );
        contract = on(
            t.next
                .filter(|p| crate::frame::prealert_on(p.earliest_s, lead_s, rec.tick_s))
                .map(|p| p.robot),
            contract,
        );
    }
    c
}
