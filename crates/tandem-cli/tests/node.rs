//! `tandem node` (feature `ros2`) as a process: a probe (`tandem_ros2::Probe`) plays the two
//! robots over DDS on loopback, drives a round through `start_round` and `record_round`, the
//! state file holds one more round, and the node stops cleanly when its standard input closes
//! (`--stdin-stop`). Bad input exits 2 with the problem named. CI runs it inside `unshare --net`
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
    assert!(
        lines.iter().any(|l| l.starts_with("stopped: ")),
        "{lines:?}"
    );
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
    let _ = std::fs::remove_dir_all(&dir);
}
