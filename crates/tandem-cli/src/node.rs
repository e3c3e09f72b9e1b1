//! `tandem node` (feature `ros2`): a state file's coordinator live in a ROS 2 graph
//! (crate `tandem-ros2`; docs/guide.md, "tandem in a ROS 2 graph").

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::Args;
use tandem::planner::Cell;
use tandem_ros2::{Node, NodeParams};

use crate::cli::cell_parser;
use crate::cmd::out;

/// `tandem node`.
#[derive(Debug, Args)]
pub(crate) struct NodeArgs {
    /// The state file: its schedule runs; `record_round` records into it (under its lock).
    pub(crate) state: PathBuf,
    /// Robots the cell has (checked against the state file's). Default: the state's.
    #[arg(long, value_name = "N")]
    pub(crate) robots: Option<usize>,
    /// How the robots repeat the task.
    #[arg(long, value_name = "MODE", value_parser = cell_parser(), default_value = "rounds")]
    pub(crate) cell: Cell,
    /// The DDS domain (ROS_DOMAIN_ID), 0…232.
    #[arg(long, value_name = "D", default_value_t = 0)]
    pub(crate) domain: u16,
    /// A robot silent this long (s) while the cell runs is a fault: the cell holds.
    #[arg(long, value_name = "S", default_value_t = 0.25)]
    pub(crate) stall: f64,
    /// Serve the operator console (a local web page) showing the live node; its URL is the
    /// first line printed.
    #[arg(long)]
    pub(crate) console: bool,
    /// The console's port on 127.0.0.1 (0: a free one). Needs --console.
    #[arg(long, value_name = "P", requires = "console")]
    pub(crate) port: Option<u16>,
    /// The model's channels that form the setpoint's pose, published as
    /// `geometry_msgs/PoseStamped` on /tandem/robotK/setpoint_pose: 3 names (x,y,z) or 7
    /// (x,y,z,qx,qy,qz,qw); `auto` takes the channels named x,y,z (and qx,qy,qz,qw) when the
    /// model has them; `none` publishes no pose. The other channels stay in `setpoint`.
    #[arg(long, value_name = "NAMES", default_value = "auto")]
    pub(crate) pose_channels: String,
    /// The pose's frame (`header.frame_id`).
    #[arg(long, value_name = "FRAME", default_value = "world")]
    pub(crate) frame_id: String,
    /// The nice value (−20…19, lower runs first) the node's tick and DDS threads ask for, so a
    /// loaded machine runs them first; 0 leaves them at the process's. A process not allowed to
    /// raise its priority (not root, no CAP_SYS_NICE) runs them at its own: the start says
    /// which applied.
    #[arg(long, value_name = "N", default_value_t = -10, allow_negative_numbers = true)]
    pub(crate) nice: i32,
    /// Stop cleanly (the threads joined, the counters printed) when standard input closes: a
    /// supervisor's or a script's way to end the node. Off by default (a node started with
    /// its input at /dev/null would stop at once).
    #[arg(long)]
    pub(crate) stdin_stop: bool,
    /// Stop after this long (s). Default: run until interrupted (SIGINT or SIGTERM end the
    /// node cleanly: a running round aborted where it stands, a record in progress finished,
    /// exit 0; a second signal exits at once with 130).
    #[arg(long, value_name = "S")]
    pub(crate) seconds: Option<f64>,
}

/// Runs the node until SIGINT/SIGTERM, `--seconds` or (with `--stdin-stop`) the end of standard
/// input, printing its counters every 10 s; then stops it cleanly ([`Node::stop`]).
pub(crate) fn node(a: &NodeArgs) -> Result<()> {
    // Before any thread starts, so that every thread of the node inherits the blocked mask and
    // the signals reach only the thread that waits for them.
    let signalled = Arc::new(AtomicU8::new(0));
    stop_on_signals(&signalled)?;
    let params = NodeParams {
        domain: a.domain,
        cell: a.cell,
        robots: a.robots,
        loop_params: tandem_ros2::LoopParams {
            stall_s: a.stall,
            ..Default::default()
        },
        pose_channels: match a.pose_channels.as_str() {
            "auto" => tandem_ros2::PoseChannels::Auto,
            "none" => tandem_ros2::PoseChannels::Off,
            names => tandem_ros2::PoseChannels::Named(
                names.split(',').map(|n| n.trim().to_owned()).collect(),
            ),
        },
        frame_id: a.frame_id.clone(),
        nice: a.nice,
        ..NodeParams::default()
    };
    if let Some(s) = a.seconds {
        anyhow::ensure!(
            s.is_finite() && s > 0.0,
            "--seconds {s}: give a duration > 0 (s), or leave it out to run until interrupted"
        );
    }
    let node = if a.console {
        let config = tandem_console::ConsoleConfig {
            port: a.port.unwrap_or(0),
            schedule: Some(format!(
                "the state file's {} cell, run by a ROS 2 node",
                a.cell
            )),
            ..tandem_console::ConsoleConfig::default()
        };
        Node::start_with_console(&a.state, &params, &config)
    } else {
        Node::start(&a.state, &params)
    }
    .with_context(|| format!("cannot start the node on {}", a.state.display()))?;
    if let Some(url) = node.console_url() {
        out(url);
    }
    out(&format!(
        "tandem node: {} robots, tick {:.4} s, DDS domain {}; topics /tandem/robot1..{}/{{progress,command,setpoint,needs_operator}}, /tandem/{{next_handover,fault,operator}}; services /tandem/{{start_round,stop_round,clear_fault,record_round}}",
        node.n_robots(),
        node.tick_s(),
        a.domain,
        node.n_robots()
    ));
    let s = node.stats();
    out(&format!(
        "priority: tick thread at {}, DDS thread at {}",
        s.tick_priority, s.dds_priority
    ));
    let pose = node.pose_channels();
    if pose.is_empty() {
        out("setpoint: every channel in /tandem/robotK/setpoint (no pose: --pose-channels)");
    } else {
        out(&format!(
            "setpoint_pose: geometry_msgs/PoseStamped in frame `{}` from channels {} (--pose-channels {}); the others in /tandem/robotK/setpoint",
            a.frame_id,
            pose.join(","),
            a.pose_channels
        ));
    }
    let closed = Arc::new(AtomicBool::new(false));
    if a.stdin_stop {
        let closed = closed.clone();
        // Reads standard input to its end; the thread is left behind when the node stops first.
        std::thread::spawn(move || {
            let _ = std::io::copy(&mut std::io::stdin().lock(), &mut std::io::sink());
            closed.store(true, Ordering::Relaxed);
        });
    }
    let start = Instant::now();
    let mut report = start;
    while node.is_running()
        && !closed.load(Ordering::Relaxed)
        && signalled.load(Ordering::Relaxed) == 0
    {
        if a.seconds
            .is_some_and(|s| start.elapsed().as_secs_f64() >= s)
        {
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
        if report.elapsed() >= Duration::from_secs(10) {
            report = Instant::now();
            let s = node.stats();
            eprintln!(
                "node: {} ticks, worst period {:.2} ms, {} commands, {} dropped",
                s.ticks,
                s.max_period_s * 1e3,
                s.commands,
                s.commands_dropped + s.inbound_dropped + s.publish_failed
            );
        }
    }
    let why = match signalled.load(Ordering::Relaxed) {
        0 => "",
        SIGTERM_CODE => " on SIGTERM",
        _ => " on SIGINT",
    };
    let s = node.stop()?;
    out(&format!(
        "stopped{why}: {} ticks, worst period {:.2} ms, {} overruns, {} commands, {} commands and {} messages dropped, {} publications refused",
        s.ticks,
        s.max_period_s * 1e3,
        s.overruns,
        s.commands,
        s.commands_dropped,
        s.inbound_dropped,
        s.publish_failed
    ));
    Ok(())
}

/// What `signalled` holds after SIGTERM (SIGINT: 2; none: 0).
const SIGTERM_CODE: u8 = 15;

/// Blocks SIGINT and SIGTERM in this thread (and so in every thread started after it) and
/// starts a thread that waits for them (`sigwait`, nix's safe `SigSet::wait`: no signal
/// handler, no unsafe code): the first sets `signalled` (2 or 15), which the main loop polls
/// every 50 ms to stop the node cleanly; a second one exits at once with 130, for a stop that
/// hangs.
#[cfg(unix)]
fn stop_on_signals(signalled: &Arc<AtomicU8>) -> Result<()> {
    use nix::sys::signal::{SigSet, Signal};
    let mut set = SigSet::empty();
    set.add(Signal::SIGINT);
    set.add(Signal::SIGTERM);
    set.thread_block()
        .context("cannot block SIGINT and SIGTERM for a clean stop")?;
    let signalled = signalled.clone();
    std::thread::Builder::new()
        .name("tandem-signals".into())
        .spawn(move || {
            while let Ok(sig) = set.wait() {
                if signalled.load(Ordering::Relaxed) != 0 {
                    eprintln!("tandem node: {sig} again: exiting without a clean stop");
                    std::process::exit(130);
                }
                let code = if sig == Signal::SIGTERM {
                    SIGTERM_CODE
                } else {
                    2
                };
                eprintln!("tandem node: {sig}: stopping (again to exit at once)");
                signalled.store(code, Ordering::Relaxed);
            }
        })
        .context("cannot start the thread that waits for SIGINT and SIGTERM")?;
    Ok(())
}

/// No signals to wait for on this platform: the node stops on `--seconds` or `--stdin-stop`.
#[cfg(not(unix))]
fn stop_on_signals(_signalled: &Arc<AtomicU8>) -> Result<()> {
    Ok(())
}
