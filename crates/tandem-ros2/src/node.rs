//! The live node: a tick thread running a [`CellLoop`] at the schedule's tick and a DDS thread
//! (ros2-client on RustDDS) publishing and subscribing, joined by the wait-free links of
//! [`crate::link`] (every tick's command in a ring, the state snapshot when asked, progress as
//! counters) and a bounded queue of the rare messages, only ever used with
//! `try_send`/`try_recv` by the tick thread (std's bounded channel: a lock-free array queue).
//! The DDS thread sleeps by the deadline each tick announces with its command
//! ([`WriterSchedule`]); the tick thread wakes it only for a reply or a half-full ring.
//!
//! The topics and services (`K` = 1…N, robot 1 first):
//!
//! | name | type | direction | rate |
//! |---|---|---|---|
//! | `/tandem/robotK/progress` | `std_msgs/Float64` | in | the robot's (reference samples reached) |
//! | `/tandem/robotK/command` | `std_msgs/Float64MultiArray` | out | every tick: `[ref_time, speed_scale, tick, stamp_s]` |
//! | `/tandem/robotK/setpoint` | `std_msgs/Float64MultiArray` | out | 100 Hz: the model's channels (Eq. 7, `u = 0`), those of the pose left out |
//! | `/tandem/robotK/setpoint_pose` | `geometry_msgs/PoseStamped` | out | 100 Hz, when the model's channels name a pose ([`PoseChannels`]) |
//! | `/tandem/robotK/needs_operator` | `std_msgs/Bool` | out | 100 Hz and on change |
//! | `/tandem/next_handover` | `std_msgs/Float64MultiArray` | out | 100 Hz: `[robot, earliest_s, latest_s]` or empty |
//! | `/tandem/fault` | `std_msgs/String` | out | 100 Hz and on change (empty: none) |
//! | `/tandem/operator` | `sensor_msgs/Joy` | in | axis 0 timing, button 0 correcting |
//! | `/tandem/{start_round,stop_round,clear_fault,record_round}` | `std_srvs/Trigger` | service | |

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TryRecvError, sync_channel};
use std::sync::{Arc, OnceLock};
use std::thread::JoinHandle;
use std::time::{Duration, Instant, SystemTime};

use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, Node as RosNode, NodeName, NodeOptions,
    Publisher, QosProfile, RmwRequestId, Server, ServiceMapping, ServiceTypeName, Subscription,
};
use tandem_console::{Console, ConsoleConfig, Geometry};
use tandem_lfd::TaskModel;
use tandem_planner::state::{DEFAULT_LOCK_TIMEOUT, StateLock};
use tandem_planner::{Cell, Planner};
use tandem_realtime::Controller;

use crate::console::ConsoleFeed;
use crate::core::{CellLoop, Command, Inbound, LoopParams, Reply, Request, RoundLog};
use crate::error::{Error, Result, dds};
use crate::link::{Links, TickEnd, WriterSchedule};
use crate::msg::{
    self, BOOL, Bool, FLOAT64, FLOAT64_MULTI_ARRAY, Float64, Float64MultiArray, JOY, Joy,
    POSE_STAMPED, PoseStamped, STRING, TRIGGER, Text, TriggerRequest, TriggerResponse, TypeName,
};
use crate::pose::{PoseChannels, PoseMap};

/// The node's parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct NodeParams {
    /// The DDS domain (ROS_DOMAIN_ID), 0…232. Default: 0.
    pub domain: u16,
    /// Rounds or a continuous cell. Default: rounds.
    pub cell: Cell,
    /// The robot count the caller expects; `None` takes the state file's. Default: `None`.
    pub robots: Option<usize>,
    /// The rate of the state topics (Hz; the commands go out every tick). Default: 100.
    pub state_hz: f64,
    /// Capacity of each queue between the threads (messages). Default: 4096.
    pub queue: usize,
    /// The control loop's timeouts.
    pub loop_params: LoopParams,
    /// Which channels form the setpoint's pose. Default: [`PoseChannels::Auto`].
    pub pose_channels: PoseChannels,
    /// The pose's `header.frame_id`. Default: `world`.
    pub frame_id: String,
    /// The nice value (−20…19, lower runs first) the tick thread and the DDS thread (and the
    /// DDS library's threads, which it starts) ask for at their start, so that on a loaded
    /// machine the OS runs them before ordinary work; 0 leaves them at the process's. Only a
    /// process allowed to (root, `CAP_SYS_NICE`, or an `RLIMIT_NICE` that admits it) gets a
    /// negative one; otherwise they run at the process's priority and [`NodeStats`] says so
    /// ([`Priority::Refused`]). Never required. Default: −10 (docs/decisions.md, "The node's
    /// tick thread wakes its writer, both at a raised priority (issue 43)").
    pub nice: i32,
    /// A measurement aid: when set, the DDS thread notes, for every command it publishes, when
    /// its tick started, when it took it from the ring and when each robot's `publish` returned,
    /// and writes them to this file when the node stops (one line per tick: `tick start_s
    /// pop_ns pub1_ns … pubN_ns`, the start as wall-clock s since the Unix epoch, the others ns
    /// after it), so a subscriber's receive times split the latency into its stages
    /// (docs/decisions.md, "The node's tick: a few stores, and where the stream's tail is
    /// (issue 43)"). Costs a branch per command when `None`. Default: `None`.
    pub stage_trace: Option<PathBuf>,
}

impl Default for NodeParams {
    fn default() -> Self {
        NodeParams {
            domain: 0,
            cell: Cell::Rounds,
            robots: None,
            state_hz: 100.0,
            queue: 4096,
            loop_params: LoopParams::default(),
            pose_channels: PoseChannels::Auto,
            frame_id: "world".into(),
            nice: -10,
            stage_trace: None,
        }
    }
}

impl NodeParams {
    /// Checks every field.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field.
    pub fn validate(&self) -> Result<()> {
        self.loop_params.validate()?;
        if self.domain > 232 {
            return Err(Error::BadParam {
                name: "domain",
                why: format!("is {}; a DDS domain is 0…232", self.domain),
            });
        }
        if !(self.state_hz.is_finite() && self.state_hz > 0.0) {
            return Err(Error::BadParam {
                name: "state_hz",
                why: "must be finite and > 0 (Hz)".into(),
            });
        }
        if self.queue == 0 {
            return Err(Error::BadParam {
                name: "queue",
                why: "must be ≥ 1 (messages)".into(),
            });
        }
        if !(-20..=19).contains(&self.nice) {
            return Err(Error::BadParam {
                name: "nice",
                why: format!(
                    "is {}; a nice value is −20…19 (lower runs first; 0 leaves the priority)",
                    self.nice
                ),
            });
        }
        Ok(())
    }
}

/// A node thread's scheduling priority: what it asked for ([`NodeParams::nice`]) and what the
/// OS gave it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Priority {
    /// Nothing asked (nice 0), or the thread has not started yet: the process's priority.
    #[default]
    Unchanged,
    /// The thread runs at this nice value.
    Applied(i32),
    /// The OS refused `nice` (not root, no `CAP_SYS_NICE`, an `RLIMIT_NICE` below it): the
    /// thread runs at the process's priority. `errno` is the OS's error number.
    Refused {
        /// The nice value asked for.
        nice: i32,
        /// The OS's error number (`EACCES` or `EPERM`).
        errno: i32,
    },
    /// Not Linux: a thread's own nice value is Linux's (the thread runs at the process's).
    Unsupported,
}

impl std::fmt::Display for Priority {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Priority::Unchanged => write!(f, "the process's priority"),
            Priority::Applied(n) => write!(f, "nice {n}"),
            Priority::Refused { nice, errno } => write!(
                f,
                "the process's priority (nice {nice} refused, errno {errno}: run as root or \
                 with CAP_SYS_NICE to raise it)"
            ),
            Priority::Unsupported => write!(f, "the process's priority (not Linux)"),
        }
    }
}

/// Sets the calling thread's nice value to `nice` (Linux: each thread has its own, and the
/// threads it starts afterwards inherit it); 0 does nothing. Never fails: what applied is the
/// answer. The node's tick and DDS threads call it at their start ([`NodeParams::nice`]); a
/// test's subscriber may call it too.
#[must_use]
pub fn set_thread_nice(nice: i32) -> Priority {
    if nice == 0 {
        return Priority::Unchanged;
    }
    #[cfg(target_os = "linux")]
    {
        match rustix::process::setpriority_process(Some(rustix::thread::gettid()), nice) {
            Ok(()) => Priority::Applied(nice),
            Err(e) => Priority::Refused {
                nice,
                errno: e.raw_os_error(),
            },
        }
    }
    #[cfg(not(target_os = "linux"))]
    {
        Priority::Unsupported
    }
}

/// Counters of a running node (shared with its threads).
#[derive(Debug, Default)]
struct Counters {
    tick_priority: OnceLock<Priority>,
    dds_priority: OnceLock<Priority>,
    overruns: AtomicU64,
    inbound_dropped: AtomicU64,
    commands: AtomicU64,
    publish_failed: AtomicU64,
    wakes: AtomicU64,
    late_wakes: AtomicU64,
}

/// What a node did so far.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodeStats {
    /// Ticks of its loop.
    pub ticks: u64,
    /// The longest time between two tick starts (s): the tick thread's worst period.
    pub max_period_s: f64,
    /// The longest time one tick's work took (s), the queues' included.
    pub max_tick_s: f64,
    /// Ticks that started more than one period late.
    pub overruns: u64,
    /// Ticks whose command the tick thread could not hand over: the command ring was full (the
    /// DDS thread `queue` ticks behind), so that tick's `command` was never published. (Named
    /// `state_dropped` before the ring: the state topics' snapshot is never dropped, a request
    /// the tick thread cannot answer at once is answered at the next tick.)
    pub commands_dropped: u64,
    /// Messages from the network the DDS thread could not queue (the tick thread behind).
    pub inbound_dropped: u64,
    /// Commands published.
    pub commands: u64,
    /// Publications DDS refused (a full reliable window: never waited for).
    pub publish_failed: u64,
    /// The tick thread's priority ([`NodeParams::nice`]).
    pub tick_priority: Priority,
    /// The DDS thread's priority, which the DDS library's threads inherit.
    pub dds_priority: Priority,
    /// Times the tick thread woke the DDS thread (a reply to a request or a round to record,
    /// a ring half full, the stop): none for the ticks themselves, by whose announced
    /// deadlines the DDS thread sleeps ([`WriterSchedule`]).
    pub wakes: u64,
    /// Times the DDS thread woke for a tick's command ([`WriterSchedule::is_late`]) before the
    /// tick thread had pushed it, and slept again for [`WriterSchedule`]'s `retry` (doubled
    /// when again too early): each adds at most that sleep to a command's latency.
    pub late_wakes: u64,
}

/// A running node; [`Node::stop`] ends it.
#[derive(Debug)]
pub struct Node {
    /// Ends the tick thread (it then publishes its last command: [`CellLoop::halt`]).
    stop: Arc<AtomicBool>,
    /// Ends the DDS thread, set once the tick thread has ended (so its last command goes out).
    io_stop: Arc<AtomicBool>,
    counters: Arc<Counters>,
    tick: Option<JoinHandle<Result<()>>>,
    io: Option<JoinHandle<Result<()>>>,
    n_robots: usize,
    tick_s: f64,
    console: Option<Console>,
    links: Arc<Links>,
    pose: Option<PoseMap>,
    channels: Vec<String>,
}

impl Node {
    /// Loads the planner in `state`, builds its controller for `params.cell` and starts the
    /// node's two threads; returns once its DDS entities exist (nothing runs until a
    /// `start_round` request).
    ///
    /// # Errors
    /// Bad `params`; the planner's errors loading the state or planning the cell;
    /// [`Error::RobotCount`]; [`Error::Dds`] when an entity cannot be created.
    pub fn start(state: &Path, params: &NodeParams) -> Result<Node> {
        Node::start_inner(state, params, None)
    }

    /// [`Node::start`] with an operator console on `console`'s address fed by the tick thread
    /// ([`ConsoleFeed`]): the page at [`Node::console_url`] shows the live node.
    ///
    /// # Errors
    /// Those of [`Node::start`]; [`Error::Console`] for bad `console` settings or an address
    /// that is taken.
    pub fn start_with_console(
        state: &Path,
        params: &NodeParams,
        console: &ConsoleConfig,
    ) -> Result<Node> {
        Node::start_inner(state, params, Some(console))
    }

    fn start_inner(
        state: &Path,
        params: &NodeParams,
        console: Option<&ConsoleConfig>,
    ) -> Result<Node> {
        params.validate()?;
        let planner = Planner::load(state)?;
        let n = planner.n_robots();
        if let Some(given) = params.robots
            && given != n
        {
            return Err(Error::RobotCount { state: n, given });
        }
        let ctl = planner.controller(params.cell)?;
        let tick_s = ctl.tick_s();
        let (console, feed) = match console {
            Some(config) => {
                let (console, handle) = Console::start(config, Geometry::new(&ctl))?;
                (Some(console), Some(ConsoleFeed::new(handle)))
            }
            None => (None, None),
        };
        let model = planner.model().clone();
        let pose = params.pose_channels.resolve(model.channel_names())?;
        let cell_loop = CellLoop::new(ctl, &model, params.loop_params.clone())?;
        let stop = Arc::new(AtomicBool::new(false));
        let io_stop = Arc::new(AtomicBool::new(false));
        let counters = Arc::new(Counters::default());
        let (in_tx, in_rx) = sync_channel::<Inbound>(params.queue);
        let links = Arc::new(Links::new(n, params.queue));
        let (reply_tx, reply_rx) = sync_channel::<Reply>(64);
        let (ready_tx, ready_rx) = sync_channel::<Result<()>>(1);
        let io = Io {
            state: state.to_path_buf(),
            cell: params.cell,
            domain: params.domain,
            n,
            state_period: Duration::from_secs_f64(1.0 / params.state_hz),
            pose,
            frame_id: params.frame_id.clone(),
            model,
            in_tx: in_tx.clone(),
            links: links.clone(),
            reply_rx,
            stop: io_stop.clone(),
            counters: counters.clone(),
            nice: params.nice,
            stage_trace: params.stage_trace.clone(),
        };
        let io = std::thread::Builder::new()
            .name("tandem-dds".into())
            .spawn(move || io.run(&ready_tx))
            .map_err(|e| Error::Thread {
                name: "tandem-dds",
                why: e.to_string(),
            })?;
        match ready_rx.recv() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return Err(e),
            Err(_) => {
                return Err(join(io, "tandem-dds").err().unwrap_or(Error::Thread {
                    name: "tandem-dds",
                    why: "ended before its entities existed".into(),
                }));
            }
        }
        let links_keep = links.clone();
        let (started_tx, started_rx) = sync_channel::<()>(1);
        let ticker = Ticker {
            writer: io.thread().clone(),
            nice: params.nice,
            started: started_tx,
            cell_loop,
            tick_s,
            in_rx,
            links,
            reply_tx,
            stop: stop.clone(),
            counters: counters.clone(),
            console: feed,
        };
        let tick = std::thread::Builder::new()
            .name("tandem-tick".into())
            .spawn(move || ticker.run())
            .map_err(|e| Error::Thread {
                name: "tandem-tick",
                why: e.to_string(),
            })?;
        // The tick thread has set its priority (so `stats` reports it from here on); an error
        // is a thread that ended at once, which `stop` reports.
        let _ = started_rx.recv();
        Ok(Node {
            stop,
            io_stop,
            counters,
            tick: Some(tick),
            io: Some(io),
            n_robots: n,
            tick_s,
            console,
            links: links_keep,
            pose,
            channels: planner.model().channel_names().to_vec(),
        })
    }

    /// The console's page (`http://127.0.0.1:PORT/`) when started with one.
    #[must_use]
    pub fn console_url(&self) -> Option<&str> {
        self.console.as_ref().map(Console::url)
    }

    /// The model's channels that form the setpoint's pose (`setpoint_pose`), by name:
    /// position `x, y, z`, then the orientation's `x, y, z, w` when the pose has one; empty
    /// when the node publishes no pose.
    #[must_use]
    pub fn pose_channels(&self) -> Vec<&str> {
        self.pose.map_or_else(Vec::new, |m| {
            m.position
                .iter()
                .chain(m.orientation.iter().flatten())
                .map(|&k| self.channels[k].as_str())
                .collect()
        })
    }

    /// Robots it runs.
    #[must_use]
    pub fn n_robots(&self) -> usize {
        self.n_robots
    }

    /// Its control tick (s).
    #[must_use]
    pub fn tick_s(&self) -> f64 {
        self.tick_s
    }

    /// Its counters now.
    #[must_use]
    pub fn stats(&self) -> NodeStats {
        let c = &self.counters;
        let l = &self.links;
        let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
        NodeStats {
            ticks: get(&l.ticks),
            max_period_s: get(&l.max_period_ns) as f64 * 1e-9,
            max_tick_s: get(&l.max_tick_ns) as f64 * 1e-9,
            overruns: get(&c.overruns),
            commands_dropped: l.commands.dropped(),
            inbound_dropped: get(&c.inbound_dropped),
            commands: get(&c.commands),
            publish_failed: get(&c.publish_failed),
            tick_priority: c.tick_priority.get().copied().unwrap_or_default(),
            dds_priority: c.dds_priority.get().copied().unwrap_or_default(),
            wakes: get(&c.wakes),
            late_wakes: get(&c.late_wakes),
        }
    }

    /// Whether both threads still run.
    #[must_use]
    pub fn is_running(&self) -> bool {
        [&self.tick, &self.io]
            .iter()
            .all(|h| h.as_ref().is_some_and(|h| !h.is_finished()))
    }

    /// Stops the node cleanly and returns the counters: the tick thread ends its loop and
    /// hands over a last command ([`CellLoop::halt`]: a running round aborted where it stands,
    /// every robot's speed scale 0, nobody needing the operator); then the DDS thread publishes
    /// what is left in the ring, waits for a `record_round` in progress to finish (its save is
    /// atomic and under the state file's lock either way) and ends.
    ///
    /// # Errors
    /// The first error a thread ended with.
    pub fn stop(mut self) -> Result<NodeStats> {
        self.stop.store(true, Ordering::Relaxed);
        let tick = self.tick.take().map(|h| join(h, "tandem-tick"));
        self.io_stop.store(true, Ordering::Relaxed);
        let io = self.io.take().map(|h| join(h, "tandem-dds"));
        if let Some(c) = self.console.take() {
            c.stop();
        }
        tick.transpose()?;
        io.transpose()?;
        Ok(self.stats())
    }
}

impl Drop for Node {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        self.io_stop.store(true, Ordering::Relaxed);
    }
}

fn join(h: JoinHandle<Result<()>>, name: &'static str) -> Result<()> {
    h.join().map_err(|_| Error::Thread {
        name,
        why: "panicked".into(),
    })?
}

/// The tick thread.
struct Ticker {
    /// The DDS thread, woken only for a reply, a half-full ring and the stop: it sleeps by the
    /// deadline each command announces ([`WriterSchedule`]).
    writer: std::thread::Thread,
    nice: i32,
    /// Told once the thread's priority is set.
    started: SyncSender<()>,
    cell_loop: CellLoop,
    tick_s: f64,
    in_rx: Receiver<Inbound>,
    links: Arc<Links>,
    reply_tx: SyncSender<Reply>,
    stop: Arc<AtomicBool>,
    counters: Arc<Counters>,
    console: Option<ConsoleFeed>,
}

impl Ticker {
    fn run(mut self) -> Result<()> {
        let _ = self.counters.tick_priority.set(set_thread_nice(self.nice));
        let _ = self.started.try_send(());
        let period = Duration::from_secs_f64(self.tick_s);
        let mut next = Instant::now();
        let c = self.counters.clone();
        let links = self.links.clone();
        let mut end = TickEnd::new(self.cell_loop.controller().n_robots());
        while !self.stop.load(Ordering::Relaxed) {
            let now = Instant::now();
            // The rare messages (operator, requests, records), only when some were queued; at
            // most one queue's worth per tick: a flood cannot lengthen the tick unboundedly.
            let (in_rx, reply_tx) = (&self.in_rx, &self.reply_tx);
            let mut replied = false;
            let drain = |l: &mut CellLoop| {
                for _ in 0..4096 {
                    match in_rx.try_recv() {
                        Ok(m) => l.handle(m, now, &mut |r| {
                            // 64 slots for at most a handful of pending requests.
                            let _ = reply_tx.try_send(r);
                            replied = true;
                        }),
                        Err(TryRecvError::Empty | TryRecvError::Disconnected) => break,
                    }
                }
            };
            // Every tick's command, announcing the next tick's deadline, by which the DDS
            // thread sleeps; the state topics' snapshot when asked, or at once when the fault
            // or the round's state changed (so their topics follow within the tick).
            next += period;
            let behind = end.tick(&mut self.cell_loop, &links, now, next, drain)?;
            // No wake per tick (a futex wake when the DDS thread sleeps, ≈ 0.5 µs: the
            // benchmark `node_threads` before "The node's DDS thread sleeps by the tick's
            // announced deadline, no wake per tick (issue 43)"): only a reply, which a
            // service caller waits for, and a ring half full wake it. Before the console's
            // feed: the command goes out first.
            if behind || replied {
                self.writer.unpark();
                c.wakes.fetch_add(1, Ordering::Relaxed);
            }
            if let Some(feed) = &mut self.console {
                feed.publish(&self.cell_loop);
            }
            // One clock read for both the tick's work and the sleep.
            let after = Instant::now();
            end.account(&links, after);
            if next > after {
                std::thread::sleep(next - after);
            } else if after - next > period {
                // More than a period late: keep the grid from here, count the overrun.
                c.overruns.fetch_add(1, Ordering::Relaxed);
                next = after;
            }
        }
        // The last command: the round aborted where it stands (`CellLoop::halt`). A full ring
        // (the DDS thread `queue` ticks behind) drops it, counted as any other.
        let last = self.cell_loop.halt();
        self.links.commands.push(&last, Instant::now());
        self.writer.unpark();
        c.wakes.fetch_add(1, Ordering::Relaxed);
        if let Some(feed) = &mut self.console {
            feed.publish(&self.cell_loop);
        }
        Ok(())
    }
}

/// How long the DDS thread keeps its entities after the tick thread's last command, so that
/// reliable delivery can repair a lost sample (a few heartbeat periods on loopback).
const LINGER: Duration = Duration::from_millis(300);

/// The DDS thread's inputs.
struct Io {
    state: PathBuf,
    cell: Cell,
    domain: u16,
    n: usize,
    state_period: Duration,
    pose: Option<PoseMap>,
    frame_id: String,
    model: TaskModel,
    in_tx: SyncSender<Inbound>,
    links: Arc<Links>,
    reply_rx: Receiver<Reply>,
    stop: Arc<AtomicBool>,
    counters: Arc<Counters>,
    nice: i32,
    stage_trace: Option<PathBuf>,
}

/// The wall-clock time (s since the Unix epoch) of `at`, by the pair `clock` of one monotonic
/// instant and the wall-clock time read together: a command's stamp is its tick's start.
fn wall_s(at: Instant, clock: (Instant, SystemTime)) -> f64 {
    let (i0, w0) = clock;
    let wall = match at.checked_duration_since(i0) {
        Some(d) => w0 + d,
        None => w0 - i0.duration_since(at),
    };
    wall.duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// Writes the DDS thread's stage trace ([`NodeParams::stage_trace`]): one line per command.
fn write_trace(path: &Path, rows: &[(u64, f64, Vec<u64>)]) -> Result<()> {
    use std::fmt::Write as _;
    let mut text = String::with_capacity(rows.len() * 48);
    for (tick, start, stages) in rows {
        let _ = write!(text, "{tick} {start:.9}");
        for s in stages {
            let _ = write!(text, " {s}");
        }
        text.push('\n');
    }
    std::fs::write(path, text).map_err(|e| Error::Trace {
        path: path.to_path_buf(),
        why: e.to_string(),
    })
}

/// The QoS of every topic: reliable, volatile, keep last 16 — ROS 2's default profile, the one
/// the client library's interop matrix passes with every RMW; reliable publication never
/// waits for a full window (`WhenFull::Fail`: the sample is counted as failed).
pub fn qos() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::Fail)
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 16 })
}

/// The name of robot `k`'s (0-based) topic `base`: `/tandem/robot{k+1}/{base}`.
///
/// # Errors
/// [`Error::Dds`] (never for these names).
pub fn robot_topic(k: usize, base: &str) -> Result<Name> {
    Name::new(&format!("/tandem/robot{}", k + 1), base).map_err(|e| dds(format!("name {base}"), e))
}

/// The name of the cell's topic or service `base`: `/tandem/{base}`.
///
/// # Errors
/// [`Error::Dds`] (never for these names).
pub fn cell_topic(base: &str) -> Result<Name> {
    Name::new("/tandem", base).map_err(|e| dds(format!("name {base}"), e))
}

/// A ROS 2 context on `domain` and a node named `name` in it.
///
/// # Errors
/// [`Error::Dds`].
pub fn ros_node(domain: u16, name: &str) -> Result<RosNode> {
    let ctx = Context::with_options(ContextOptions::new().domain_id(domain))
        .map_err(|e| dds(format!("join DDS domain {domain}"), e))?;
    ctx.new_node(
        NodeName::new("/", name).map_err(|e| dds("name the node", e))?,
        NodeOptions::new().enable_rosout(false),
    )
    .map_err(|e| dds("create the node", e))
}

/// A publisher of `ty` on `name`.
///
/// # Errors
/// [`Error::Dds`].
pub fn publisher<M: serde::Serialize>(
    node: &mut RosNode,
    name: &Name,
    ty: TypeName,
) -> Result<Publisher<M>> {
    let topic = node
        .create_topic(name, MessageTypeName::new(ty.0, ty.1), &qos())
        .map_err(|e| dds(format!("create topic {name:?}"), e))?;
    node.create_publisher(&topic, None)
        .map_err(|e| dds(format!("publish on {name:?}"), e))
}

/// A subscription of `ty` on `name`.
///
/// # Errors
/// [`Error::Dds`].
pub fn subscription<M: 'static + serde::de::DeserializeOwned>(
    node: &mut RosNode,
    name: &Name,
    ty: TypeName,
) -> Result<Subscription<M>> {
    let topic = node
        .create_topic(name, MessageTypeName::new(ty.0, ty.1), &qos())
        .map_err(|e| dds(format!("create topic {name:?}"), e))?;
    node.create_subscription(&topic, None)
        .map_err(|e| dds(format!("subscribe to {name:?}"), e))
}

/// The service mapping of every service: ROS 2's "enhanced" request/reply (Fast DDS's).
pub const SERVICE_MAPPING: ServiceMapping = ServiceMapping::Enhanced;

/// The node's four services, in [`SERVICES`] order.
pub const SERVICES: [(&str, Request); 4] = [
    ("start_round", Request::Start),
    ("stop_round", Request::Stop),
    ("clear_fault", Request::ClearFault),
    ("record_round", Request::TakeRound),
];

/// Per robot: its publishers and subscription.
struct RobotIo {
    command: Publisher<Float64MultiArray>,
    setpoint: Publisher<Float64MultiArray>,
    setpoint_pose: Option<Publisher<PoseStamped>>,
    needs: Publisher<Bool>,
    progress: Subscription<Float64>,
}

/// What a record worker reports.
struct Recorded {
    token: u64,
    result: std::result::Result<(String, Box<TaskModel>), String>,
}

impl Io {
    fn run(self, ready: &SyncSender<Result<()>>) -> Result<()> {
        // Before the DDS library starts its threads, so that they inherit it.
        let _ = self.counters.dds_priority.set(set_thread_nice(self.nice));
        let entities = self.entities();
        let (mut node, robots, handover, fault, operator, servers) = match entities {
            Ok(e) => {
                let _ = ready.send(Ok(()));
                e
            }
            Err(e) => {
                let _ = ready.send(Err(e));
                return Ok(());
            }
        };
        let _ = &mut node;
        let mut model = self.model.clone();
        // The setpoint's array: the channels not in the pose.
        let others: Vec<usize> = (0..model.channel_names().len())
            .filter(|&k| !self.pose.is_some_and(|p| p.contains(k)))
            .collect();
        let labels = others
            .iter()
            .map(|&k| model.channel_names()[k].as_str())
            .collect::<Vec<_>>()
            .join(",");
        let u0 = vec![0.0; model.n_components()];
        let mut cmd = vec![0.0; model.channel_names().len() + 1];
        let mut pending: HashMap<u64, (usize, RmwRequestId)> = HashMap::new();
        let mut token = 0_u64;
        let (rec_tx, rec_rx) = sync_channel::<Recorded>(8);
        let mut last_needs = vec![None; self.n];
        let mut last_fault: Option<String> = None;
        // The command each pop overwrites (`CommandRing::pop_into`: nothing zeroed per pop).
        let mut command = Command::idle(self.n);
        let mut next_state = Instant::now();
        let clock = (Instant::now(), SystemTime::now());
        let c = &self.counters;
        let fail = |ok: bool| {
            if !ok {
                c.publish_failed.fetch_add(1, Ordering::Relaxed);
            }
        };
        // Records running on their threads: the loop ends only when none is left.
        let mut recording = 0_usize;
        // Per command: the tick, its start (wall s), then the pop and each publish's return
        // (ns after the start).
        let mut trace: Option<Vec<(u64, f64, Vec<u64>)>> = self
            .stage_trace
            .as_ref()
            .map(|_| Vec::with_capacity(1 << 16));
        let mut stopped_at: Option<Instant> = None;
        // Passes in a row that woke for a command not pushed yet.
        let mut late = 0_u32;
        let schedule = WriterSchedule::NODE;
        loop {
            // Set once the tick thread has ended: this pass publishes its last commands.
            let stopping = self.stop.load(Ordering::Relaxed);
            if stopping && stopped_at.is_none() {
                stopped_at = Some(Instant::now());
            }
            let mut busy = false;
            // 1. The tick thread's commands, every tick's; `needs_operator` on change.
            let links = &*self.links;
            while let Some(at) = links.commands.pop_into(&mut command) {
                busy = true;
                late = 0;
                // The tick's start: the latency a subscriber measures is the coordinator's.
                let stamp = wall_s(at, clock);
                let since = |t: Instant| t.saturating_duration_since(at).as_nanos() as u64;
                let mut stages = trace.as_ref().map(|_| vec![since(Instant::now())]);
                for (k, r) in robots.iter().enumerate() {
                    let data = vec![
                        command.ref_time[k],
                        command.speed[k],
                        command.tick as f64,
                        stamp,
                    ];
                    let m = Float64MultiArray::labelled("ref_time,speed_scale,tick,stamp_s", data);
                    fail(r.command.publish(m).is_ok());
                    if let Some(s) = &mut stages {
                        s.push(since(Instant::now()));
                    }
                    c.commands.fetch_add(1, Ordering::Relaxed);
                }
                if let (Some(t), Some(s)) = (&mut trace, stages) {
                    t.push((command.tick, stamp, s));
                }
                for (k, r) in robots.iter().enumerate() {
                    let needs = command.needs_operator[k];
                    if last_needs[k] != Some(needs) {
                        fail(r.needs.publish(Bool { data: needs }).is_ok());
                        last_needs[k] = Some(needs);
                    }
                }
                if command.fault != last_fault.is_some() {
                    // The fault's text is the snapshot's: ask for it now.
                    links.state.ask();
                }
            }
            // 2. The state topics at their rate: ask for a snapshot, publish it when it comes.
            let now = Instant::now();
            if now >= next_state {
                links.state.ask();
                next_state = (next_state + self.state_period).max(now);
            }
            if let Some(snap) = links.state.take() {
                busy = true;
                for (k, r) in robots.iter().enumerate() {
                    let needs = snap.needs_operator[k];
                    fail(r.needs.publish(Bool { data: needs }).is_ok());
                    last_needs[k] = Some(needs);
                    let t = snap.ref_time[k].clamp(0.0, (model.n_ref() - 1) as f64);
                    if model.command_into(&u0, t, &mut cmd).is_ok() {
                        let values = others.iter().map(|&k| cmd[k]).collect();
                        let sp = Float64MultiArray::labelled(&labels, values);
                        fail(r.setpoint.publish(sp).is_ok());
                        if let (Some(p), Some(map)) = (&r.setpoint_pose, self.pose) {
                            fail(
                                p.publish(map.pose(&cmd, &self.frame_id, msg::now()))
                                    .is_ok(),
                            );
                        }
                    }
                }
                let text = snap.fault.map(|f| f.to_string());
                fail(
                    fault
                        .publish(Text {
                            data: text.clone().unwrap_or_default(),
                        })
                        .is_ok(),
                );
                last_fault = text;
                let data = snap.next.map_or_else(Vec::new, |p| {
                    vec![(p.robot + 1) as f64, p.earliest_s, p.latest_s]
                });
                let m = Float64MultiArray::labelled("robot,earliest_s,latest_s", data);
                fail(handover.publish(m).is_ok());
            }
            // The network's messages to the tick thread: progress as a count per robot.
            for (k, r) in robots.iter().enumerate() {
                while let Ok(Some((m, _))) = r.progress.take() {
                    busy = true;
                    if m.data.is_finite() {
                        links.heard.hear(k);
                    }
                }
            }
            while let Ok(Some((joy, _))) = operator.take() {
                busy = true;
                let axis = joy.axes.first().map_or(0.0, |&a| f64::from(a));
                let correcting = joy.buttons.first().is_some_and(|&b| b != 0);
                self.forward(Inbound::Operator { axis, correcting });
            }
            // 3. Service requests.
            for (i, server) in servers.iter().enumerate() {
                while let Ok(Some((id, _))) = server.receive_request() {
                    busy = true;
                    token += 1;
                    let what = SERVICES[i].1;
                    match self.in_tx.try_send(Inbound::Request { token, what }) {
                        Ok(()) => {
                            self.links.pending.sent();
                            pending.insert(token, (i, id));
                        }
                        Err(_) => {
                            let r = respond(false, "the node is busy; ask again".into());
                            fail(server.send_response(id, r).is_ok());
                        }
                    }
                }
            }
            // 4. The tick thread's replies.
            while let Ok(reply) = self.reply_rx.try_recv() {
                busy = true;
                match reply {
                    Reply::Done {
                        token,
                        what,
                        result,
                    } => {
                        if let Some((i, id)) = pending.remove(&token) {
                            let r = match result {
                                Ok(()) => respond(true, done_text(what)),
                                Err(e) => respond(false, e.to_string()),
                            };
                            fail(servers[i].send_response(id, r).is_ok());
                        }
                    }
                    Reply::Round { token, log } => {
                        if self.spawn_record(token, log, rec_tx.clone()) {
                            recording += 1;
                        }
                    }
                }
            }
            // 5. Finished recordings.
            while let Ok(done) = rec_rx.try_recv() {
                busy = true;
                recording = recording.saturating_sub(1);
                let r = match done.result {
                    Ok((text, new_model)) => {
                        model = *new_model;
                        respond(true, text)
                    }
                    Err(text) => respond(false, text),
                };
                if let Some((i, id)) = pending.remove(&done.token) {
                    fail(servers[i].send_response(id, r).is_ok());
                }
            }
            // The DDS entities live on for `LINGER` after the last publication: the library's
            // publisher cannot wait for acknowledgments, and a reliable sample lost on the wire
            // is repaired only while its writer exists.
            if stopped_at.is_some_and(|t| t.elapsed() >= LINGER) && recording == 0 {
                break;
            }
            // Idle: sleep by the deadline the last command announced (`WriterSchedule`):
            // before it for the network's messages, just past it for its tick's command, at
            // least every millisecond; a wake from the tick thread (a reply, a half-full ring,
            // the stop) or a record's thread ends the sleep early (an unpark before the park
            // makes the park return at once).
            if !busy {
                let now = Instant::now();
                let next = links.commands.next_deadline();
                let sleep = schedule.sleep(now, next, late);
                if schedule.is_late(now, next) {
                    late = late.saturating_add(1);
                    c.late_wakes.fetch_add(1, Ordering::Relaxed);
                }
                std::thread::park_timeout(sleep);
            }
        }
        if let (Some(path), Some(rows)) = (&self.stage_trace, trace) {
            write_trace(path, &rows)?;
        }
        Ok(())
    }

    #[allow(clippy::type_complexity)]
    fn entities(
        &self,
    ) -> Result<(
        RosNode,
        Vec<RobotIo>,
        Publisher<Float64MultiArray>,
        Publisher<Text>,
        Subscription<Joy>,
        Vec<Server<TriggerRequest, TriggerResponse>>,
    )> {
        let mut node = ros_node(self.domain, "tandem")?;
        let robots = (0..self.n)
            .map(|k| {
                Ok(RobotIo {
                    command: publisher(
                        &mut node,
                        &robot_topic(k, "command")?,
                        FLOAT64_MULTI_ARRAY,
                    )?,
                    setpoint: publisher(
                        &mut node,
                        &robot_topic(k, "setpoint")?,
                        FLOAT64_MULTI_ARRAY,
                    )?,
                    setpoint_pose: match self.pose {
                        Some(_) => Some(publisher(
                            &mut node,
                            &robot_topic(k, "setpoint_pose")?,
                            POSE_STAMPED,
                        )?),
                        None => None,
                    },
                    needs: publisher(&mut node, &robot_topic(k, "needs_operator")?, BOOL)?,
                    progress: subscription(&mut node, &robot_topic(k, "progress")?, FLOAT64)?,
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let handover = publisher(
            &mut node,
            &cell_topic("next_handover")?,
            FLOAT64_MULTI_ARRAY,
        )?;
        let fault = publisher(&mut node, &cell_topic("fault")?, STRING)?;
        let operator = subscription(&mut node, &cell_topic("operator")?, JOY)?;
        let servers = SERVICES
            .iter()
            .map(|(name, _)| {
                node.create_server::<TriggerRequest, TriggerResponse>(
                    SERVICE_MAPPING,
                    &cell_topic(name)?,
                    &ServiceTypeName::new(TRIGGER.0, TRIGGER.1),
                    qos(),
                    qos(),
                )
                .map_err(|e| dds(format!("serve {name}"), e))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok((node, robots, handover, fault, operator, servers))
    }

    fn forward(&self, m: Inbound) {
        if self.in_tx.try_send(m).is_err() {
            self.counters
                .inbound_dropped
                .fetch_add(1, Ordering::Relaxed);
        } else {
            self.links.pending.sent();
        }
    }

    /// Records `log` into the state file on a thread of its own (the lock may be waited for,
    /// the planner re-schedules): the same lock, load, checks and save as `tandem record`.
    /// `true` when its thread runs (it reports on `done`).
    fn spawn_record(&self, token: u64, log: RoundLog, done: SyncSender<Recorded>) -> bool {
        let state = self.state.clone();
        let cell = self.cell;
        let in_tx = self.in_tx.clone();
        let links = self.links.clone();
        // This (the DDS) thread, woken when the record is done: it sleeps by the ticks.
        let dds = std::thread::current();
        let spawned = std::thread::Builder::new()
            .name("tandem-record".into())
            .spawn(move || {
                let result = match record(&state, cell, &log) {
                    Ok((text, ctl, model)) => {
                        // Blocking send is fine here: this thread is not the tick's.
                        let plan = Box::new(Geometry::new(&ctl));
                        if in_tx.send(Inbound::Replace(ctl, plan)).is_ok() {
                            links.pending.sent();
                        }
                        Ok((text, model))
                    }
                    Err(e) => {
                        if in_tx.send(Inbound::Restore(log)).is_ok() {
                            links.pending.sent();
                        }
                        Err(format!("cannot record the round: {e}"))
                    }
                };
                let _ = done.send(Recorded { token, result });
                dds.unpark();
            });
        if spawned.is_err() {
            self.counters.publish_failed.fetch_add(1, Ordering::Relaxed);
        }
        spawned.is_ok()
    }
}

/// The record: lock, load, [`Planner::record_round`], save under the lock, the new controller.
#[allow(clippy::type_complexity)]
fn record(
    state: &Path,
    cell: Cell,
    log: &RoundLog,
) -> Result<(String, Box<tandem_planner::AnyController>, Box<TaskModel>)> {
    let lock = StateLock::acquire(state, DEFAULT_LOCK_TIMEOUT)?;
    let mut planner = Planner::load(state)?;
    let records = log.records(planner.model())?;
    let report = planner.record_round(&records)?;
    planner.save_locked(&lock)?;
    drop(lock);
    let ctl = planner.controller(cell)?;
    let mut text = format!(
        "recorded round {} into {}",
        planner.rounds_recorded(),
        state.display()
    );
    for n in &report.notices {
        text.push_str("; ");
        text.push_str(n);
    }
    Ok((text, Box::new(ctl), Box::new(planner.model().clone())))
}

fn respond(success: bool, message: String) -> TriggerResponse {
    TriggerResponse { success, message }
}

fn done_text(what: Request) -> String {
    match what {
        Request::Start => "started",
        Request::Stop => "stopped; every robot back at its start",
        Request::ClearFault => "fault cleared",
        Request::TakeRound => "recorded",
    }
    .into()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_command_is_stamped_with_its_ticks_wall_clock_time() {
        let i0 = Instant::now();
        let w0 = SystemTime::UNIX_EPOCH + Duration::from_secs(1_000);
        let at = i0 + Duration::from_millis(1_500);
        assert!((wall_s(at, (i0, w0)) - 1_001.5).abs() < 1e-9);
        // A tick before the pair was read (the ring's first records).
        let before = i0.checked_sub(Duration::from_millis(250)).unwrap_or(i0);
        let back = i0.duration_since(before).as_secs_f64();
        assert!((wall_s(before, (i0, w0)) - (1_000.0 - back)).abs() < 1e-9);
    }

    #[test]
    fn nice_is_checked_and_a_thread_gets_the_priority_it_may() {
        for nice in [-21, 20] {
            let p = NodeParams {
                nice,
                ..NodeParams::default()
            };
            let e = p.validate().unwrap_err().to_string();
            assert!(e.contains("nice") && e.contains("−20…19"), "{e}");
        }
        assert_eq!(set_thread_nice(0), Priority::Unchanged);
        // Lowering a thread's priority is always allowed; only that thread changes.
        let (got, now) = std::thread::spawn(|| {
            let got = set_thread_nice(7);
            #[cfg(target_os = "linux")]
            let now = rustix::process::getpriority_process(Some(rustix::thread::gettid())).ok();
            #[cfg(not(target_os = "linux"))]
            let now = None;
            (got, now)
        })
        .join()
        .unwrap();
        if cfg!(target_os = "linux") {
            assert_eq!(got, Priority::Applied(7));
            assert_eq!(now, Some(7));
            #[cfg(target_os = "linux")]
            assert_ne!(
                rustix::process::getpriority_process(Some(rustix::thread::gettid())).ok(),
                Some(7),
                "this thread keeps its own"
            );
        } else {
            assert_eq!(got, Priority::Unsupported);
        }
    }
}
