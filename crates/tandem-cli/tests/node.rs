//! `tandem node` (feature `ros2`) as a process: a probe (`tandem_ros2::Probe`) plays the two
//! robots over DDS on loopback, drives a round through `start_round` and `record_round`, the
//! state file holds one more round, and the node stops cleanly when its standard input closes
//! (`--stdin-stop`) or on SIGINT mid-round (the round aborted where it stands, the state file
//! untouched, exit 0). Bad input exits 2 with the problem named. CI runs it inside `unshare --net`
//! with the other ROS 2 tests (.ci/run: `cargo test -p tandem-cli --features ros2 --test node`).
#![cfg(feature = "ros2")]

mod common;

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{scratch, small_state, tandem};
use tandem::planner::Planner;
use tandem_ros2::Probe;

/// Kills the node when the test ends, however it ends.
struct Running(Option<Child>);

impl Drop for Running {
    fn drop(&mut self) {
        if let Some(c) = &mut self.0 {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// Every robot reports the reference time of its last command.
fn echo(probe: &Probe, n: usize) {
    for k in 0..n {
        if let Some(c) = probe.commands(k).last() {
            probe.report(k, c.ref_time).unwrap();
        }
    }
}

#[test]
fn a_node_process_runs_a_round_records_it_and_stops_when_stdin_closes() {
    let dir = scratch("node-round");
    let state = small_state(&dir);
    let before = Planner::load(&state).unwrap().rounds_recorded();
    let child = Command::new(env!("CARGO_BIN_EXE_tandem"))
        .args(["node", state.to_str().unwrap()])
        .args(["--robots", "2", "--domain", "93", "--stdin-stop"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut node = Running(Some(child));
    let probe = Probe::new(93, 2).unwrap();
    // Discovery: both robots' commands arrive.
    let end = Instant::now() + Duration::from_secs(60);
    let mut seen = [false; 2];
    while !seen.iter().all(|&s| s) {
        assert!(Instant::now() < end, "no commands from the node in 60 s");
        for (k, s) in seen.iter_mut().enumerate() {
            *s |= !probe.commands(k).is_empty();
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let r = probe
        .call("start_round", Duration::from_secs(20), || echo(&probe, 2))
        .unwrap();
    assert!(r.success, "{}", r.message);
    let end = Instant::now() + Duration::from_secs(120);
    let mut faults = Vec::new();
    let recorded = loop {
        assert!(Instant::now() < end, "the round was not recorded in 120 s");
        let until = Instant::now() + Duration::from_millis(200);
        while Instant::now() < until {
            echo(&probe, 2);
            if let Some(f) = probe.fault().filter(|f| !f.is_empty()) {
                faults.push(f);
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        let r = probe
            .call("record_round", Duration::from_secs(30), || echo(&probe, 2))
            .unwrap();
        if r.success {
            break r.message;
        }
        assert!(r.message.contains("no finished round"), "{}", r.message);
    };
    assert!(faults.is_empty(), "faults during the round: {faults:?}");
    assert!(recorded.starts_with("recorded round"), "{recorded}");
    assert_eq!(Planner::load(&state).unwrap().rounds_recorded(), before + 1);
    // Closing standard input stops the node cleanly: exit 0, the counters printed.
    let mut child = node.0.take().unwrap();
    drop(child.stdin.take());
    let end = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        assert!(
            Instant::now() < end,
            "the node did not stop within 30 s of stdin closing"
        );
        std::thread::sleep(Duration::from_millis(20));
    };
    let lines: Vec<String> = BufReader::new(child.stdout.take().unwrap())
        .lines()
        .map(Result::unwrap)
        .collect();
    assert!(status.success(), "exit {status:?}; stdout {lines:?}");
    assert!(lines[0].starts_with("tandem node: 2 robots"), "{lines:?}");
    // The threads' priority, raised or (a process not allowed to) refused, is said at the start.
    let priority = &lines[1];
    assert!(
        priority.starts_with("priority: tick thread at ")
            && priority.matches("nice -10").count() == 2,
        "{lines:?}"
    );
    assert!(
        lines.iter().any(|l| l.starts_with("stopped: ")),
        "{lines:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sigint_mid_round_stops_the_node_cleanly_holding_the_robots() {
    let dir = scratch("node-sigint");
    let state = small_state(&dir);
    let bytes_before = std::fs::read(&state).unwrap();
    let child = Command::new(env!("CARGO_BIN_EXE_tandem"))
        .args(["node", state.to_str().unwrap()])
        .args(["--robots", "2", "--domain", "97"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut node = Running(Some(child));
    let probe = Probe::new(97, 2).unwrap();
    // Every command and the last `needs_operator` of each robot (the probe hands each once).
    let mut hist: [Vec<tandem_ros2::probe::Command>; 2] = [Vec::new(), Vec::new()];
    let mut needs = [None; 2];
    let mut pull = |hist: &mut [Vec<tandem_ros2::probe::Command>; 2]| {
        for k in 0..2 {
            hist[k].extend(probe.commands(k));
            if let Some(b) = probe.needs(k) {
                needs[k] = Some(b);
            }
        }
    };
    let end = Instant::now() + Duration::from_secs(60);
    while hist.iter().any(Vec::is_empty) {
        assert!(Instant::now() < end, "no commands from the node in 60 s");
        pull(&mut hist);
        std::thread::sleep(Duration::from_millis(5));
    }
    let echo_hist = |hist: &[Vec<tandem_ros2::probe::Command>; 2]| {
        for (k, h) in hist.iter().enumerate() {
            if let Some(c) = h.last() {
                probe.report(k, c.ref_time).unwrap();
            }
        }
    };
    let r = probe
        .call("start_round", Duration::from_secs(20), || {
            for k in 0..2 {
                if let Some(c) = probe.commands(k).last() {
                    probe.report(k, c.ref_time).unwrap();
                }
            }
        })
        .unwrap();
    assert!(r.success, "{}", r.message);
    // Mid-round: some robot has moved off its start.
    let end = Instant::now() + Duration::from_secs(30);
    while !hist
        .iter()
        .any(|h| h.last().is_some_and(|c| c.speed > 0.0 && c.ref_time > 0.0))
    {
        assert!(
            Instant::now() < end,
            "no robot moved in 30 s after start_round"
        );
        pull(&mut hist);
        echo_hist(&hist);
        std::thread::sleep(Duration::from_millis(1));
    }
    let pid = node.0.as_ref().unwrap().id().to_string();
    let kill = Command::new("kill").args(["-INT", &pid]).status().unwrap();
    assert!(kill.success());
    let mut child = node.0.take().unwrap();
    let end = Instant::now() + Duration::from_secs(30);
    let status = loop {
        // The robots keep reporting: the node must stop on the signal, not on a stall.
        pull(&mut hist);
        echo_hist(&hist);
        if let Some(st) = child.try_wait().unwrap() {
            break st;
        }
        assert!(
            Instant::now() < end,
            "the node did not stop within 30 s of SIGINT"
        );
        std::thread::sleep(Duration::from_millis(1));
    };
    let lines: Vec<String> = BufReader::new(child.stdout.take().unwrap())
        .lines()
        .map(Result::unwrap)
        .collect();
    assert!(status.success(), "exit {status:?}; stdout {lines:?}");
    assert!(
        lines.iter().any(|l| l.starts_with("stopped on SIGINT: ")),
        "{lines:?}"
    );
    pull(&mut hist);
    // The last command of each robot holds it where it is: speed scale 0, the reference time
    // of the command before it (not sent back to its start), the tick after it; nobody needs
    // the operator.
    for (k, h) in hist.iter().enumerate() {
        let (last, before) = (h[h.len() - 1], h[h.len() - 2]);
        assert_eq!(last.speed, 0.0, "robot {}: {last:?}", k + 1);
        assert_eq!(last.tick, before.tick + 1, "robot {}: no tick lost", k + 1);
        assert_eq!(
            last.ref_time,
            before.ref_time,
            "robot {}: held in place",
            k + 1
        );
        assert_eq!(needs[k], Some(false), "robot {}", k + 1);
    }
    assert!(
        hist.iter().any(|h| h[h.len() - 1].ref_time > 0.0),
        "the round had moved a robot off its start before the signal"
    );
    // An unfinished round is never recorded: the state file is byte for byte as it was.
    assert_eq!(std::fs::read(&state).unwrap(), bytes_before);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_input_exits_2_naming_the_problem() {
    let dir = scratch("node-bad");
    let missing = dir.join("missing.tandem");
    let out = tandem(["node", missing.to_str().unwrap(), "--domain", "94"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains("missing.tandem"), "{err}");

    let state = small_state(&dir);
    let out = tandem(["node", state.to_str().unwrap(), "--domain", "300"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("domain") && err.contains("0…232"), "{err}");

    let out = tandem([
        "node",
        state.to_str().unwrap(),
        "--domain",
        "95",
        "--robots",
        "3",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--robots 3") && err.contains("plans 2 robots"),
        "{err}"
    );

    let out = tandem([
        "node",
        state.to_str().unwrap(),
        "--domain",
        "96",
        "--pose-channels",
        "x,y,nope",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    // The small task's channels are x and force: `y` is the first name it lacks.
    assert!(err.contains("`y`") && err.contains("x,force"), "{err}");

    let out = tandem([
        "node",
        state.to_str().unwrap(),
        "--domain",
        "97",
        "--nice",
        "-25",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("nice") && err.contains("is -25") && err.contains("−20…19"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
