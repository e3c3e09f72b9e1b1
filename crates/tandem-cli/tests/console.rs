//! `tandem console STATE --simulate`: the page's URL is the first line of standard output and
//! serves frames of the state's cell; bad input exits 2 naming the flag and the fix.

mod common;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use common::{SMALL_N_REF, scratch, small_demo, small_state, tandem, write};

/// Kills the console when the test ends, however it ends.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn get(host_port: &str, path: &str) -> (u16, String) {
    let mut s = TcpStream::connect(host_port).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    let status = out[9..12].parse().unwrap();
    (
        status,
        out.split_once("\r\n\r\n").map_or("", |x| x.1).to_string(),
    )
}

#[test]
fn the_url_comes_first_and_the_page_shows_the_states_cell() {
    let dir = scratch("console");
    let state = small_state(&dir);
    for (cell, robots) in [("rounds", None), ("continuous", Some("3"))] {
        let mut args = vec![
            "console",
            state.to_str().unwrap(),
            "--simulate",
            "--cell",
            cell,
        ];
        if let Some(n) = robots {
            args.extend(["--robots", n]);
        }
        let child = Command::new(env!("CARGO_BIN_EXE_tandem"))
            .args(&args)
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let mut run = Running(child);
        let mut first = String::new();
        BufReader::new(run.0.stdout.take().unwrap())
            .read_line(&mut first)
            .unwrap();
        let url = first.trim();
        let host_port = url
            .strip_prefix("http://127.0.0.1:")
            .map(|p| format!("127.0.0.1:{}", p.trim_end_matches('/')))
            .unwrap_or_else(|| panic!("the first line is the page's local URL: {url:?}"));
        assert_eq!(get(&host_port, "/").0, 200);
        let t0 = Instant::now();
        let frame: serde_json::Value = loop {
            let (status, body) = get(&host_port, "/frame");
            if status == 200 {
                let f: serde_json::Value = serde_json::from_str(&body).unwrap();
                if f["tick"].as_u64().unwrap() > 0 {
                    break f;
                }
            }
            assert!(
                t0.elapsed() < Duration::from_secs(20),
                "no frame: {status} {body}"
            );
            std::thread::sleep(Duration::from_millis(50));
        };
        assert_eq!(frame["cell"], cell);
        let n = robots.map_or(2, |n| n.parse().unwrap());
        assert_eq!(frame["robots"].as_array().unwrap().len(), n);
        let lc = frame["robots"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["state"] == "lc")
            .count();
        assert!(lc <= 1, "{frame}");
    }
}

#[test]
fn a_recorded_run_replays_and_checks() {
    let dir = scratch("console-record");
    let state = small_state(&dir);
    let rec = dir.join("run.jsonl");
    let out = tandem([
        "console",
        state.to_str().unwrap(),
        "--simulate",
        "--cell",
        "continuous",
        "--robots",
        "3",
        "--record",
        rec.to_str().unwrap(),
        "--until",
        "tasks:30",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = tandem(["console", "--replay", rec.to_str().unwrap(), "--check"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let check: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(check["frames"].as_u64().unwrap() > 100, "{check}");
    assert_eq!(check["two_lc"], 0, "{check}");
    assert_eq!(check["lc_differs"], 0, "{check}");
    assert!(check["stretches"].as_u64().unwrap() >= 30, "{check}");
}

/// A task without a `force` channel (a welder's `current`): `simulate` and the console's
/// simulated operator correct along the model's process quantity and say so; a named channel
/// the model lacks is refused before anything is written (no half-made recording is left).
#[test]
fn console_simulates_a_task_without_a_force_channel() {
    let dir = scratch("console-current");
    let demos: Vec<_> = (0..3)
        .map(|i| {
            let text = small_demo([SMALL_N_REF, 66, 56][i], [0.0, 6.0, 12.0][i]).replacen(
                "t,x,force",
                "t,x,current",
                1,
            );
            write(&dir, &format!("weld_{i}.csv"), &text)
        })
        .collect();
    let state = dir.join("weld.tandem");
    let mut args = vec!["fit".to_string()];
    args.extend(demos.iter().map(|p| p.to_str().unwrap().to_string()));
    args.extend(["--samples", "200", "-o", state.to_str().unwrap()].map(String::from));
    let out = tandem(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rec = dir.join("run.jsonl");
    let record = |channel: Option<&str>| {
        let mut args = vec![
            "console",
            state.to_str().unwrap(),
            "--simulate",
            "--record",
            rec.to_str().unwrap(),
            "--until",
            "rounds:2",
        ];
        if let Some(c) = channel {
            args.extend(["--channel", c]);
        }
        tandem(args)
    };
    let bad = record(Some("force"));
    assert_eq!(bad.status.code(), Some(2));
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("--channel force") && err.contains("current"),
        "{err}"
    );
    assert!(!rec.exists(), "a refused run left {}", rec.display());
    let out = record(None);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("channel `current`"), "{err}");
    let out = tandem(["console", "--replay", rec.to_str().unwrap(), "--check"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let check: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(check["frames"].as_u64().unwrap() > 10, "{check}");
    assert_eq!(check["two_lc"], 0, "{check}");
    assert_eq!(check["lc_differs"], 0, "{check}");
}

/// `tandem console STATE --replay RUN.mcap`: the bag of `tandem simulate --bag` replayed
/// against its state file's plan, one frame per tick of its rounds; the page's `lc` robot is
/// the one the run logged as supervised (the frames are rebuilt from the bag's flags, so the
/// count of stretches is the count of the bag's supervised runs, read here through
/// `read_executions`, the reader `tandem record` uses). Without the state file, and for a
/// truncated bag, a clear refusal.
#[test]
fn a_run_bag_replays_with_its_state_file() {
    let dir = scratch("console-bag");
    let state = small_state(&dir);
    let s = state.to_str().unwrap();
    let bag = dir.join("run.mcap");
    let b = bag.to_str().unwrap();
    let need = write(
        &dir,
        "need.csv",
        &format!("need\n{}", "1\n".repeat(SMALL_N_REF)),
    );
    let n = need.to_str().unwrap();
    let out = tandem([
        "simulate", s, "--need", n, "--rounds", "2", "--seed", "3", "--bag", b,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = tandem(["console", s, "--replay", b, "--check"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("records no pre-alert"), "{err}");
    let check: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Every tick of both rounds, and the supervised runs of the bag, robot by robot.
    let rounds = tandem::bag::read_run(&bag, 2).unwrap();
    let ticks: usize = rounds.iter().map(|r| r.ticks).sum();
    assert_eq!(check["frames"].as_u64(), Some(ticks as u64), "{check}");
    assert_eq!(check["two_lc"], 0, "{check}");
    assert_eq!(check["lc_differs"], 0, "{check}");
    let mut runs = 0;
    for round in 1..=2 {
        let opts = tandem::bag::ExecutionOptions {
            dt_s: rounds[0].dt_s,
            robots: vec![1, 2],
            round: Some(round),
            topics: None,
        };
        for e in tandem::bag::read_executions(&bag, &opts).unwrap() {
            runs += e
                .supervised
                .iter()
                .enumerate()
                .filter(|&(k, &on)| on && (k == 0 || !e.supervised[k - 1]))
                .count();
        }
    }
    assert!(runs > 0);
    // The check counts the stretches that start during the replay, not one under way at its
    // first frame.
    let under_way = rounds[0]
        .robots
        .iter()
        .any(|r| r.start_tick == 0 && r.supervised.first() == Some(&true));
    assert_eq!(
        check["stretches"].as_u64(),
        Some((runs - usize::from(under_way)) as u64),
        "{check}"
    );
    assert_eq!(check["alerted"], 0, "{check}");

    // Without the state file: refused, naming the fix.
    let out = tandem(["console", "--replay", b, "--check"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("tandem console STATE --replay RUN.mcap"),
        "{err}"
    );
    // A truncated bag: an error naming it.
    let bytes = std::fs::read(&bag).unwrap();
    let cut = dir.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let out = tandem(["console", s, "--replay", cut.to_str().unwrap(), "--check"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cut.mcap") && err.contains("cannot replay this run bag"),
        "{err}"
    );
    // A console recording with a state file: the state is refused as meaningless.
    let rec = dir.join("run.jsonl");
    std::fs::write(&rec, "{}\n").unwrap();
    let out = tandem(["console", s, "--replay", rec.to_str().unwrap(), "--check"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("only for a run bag"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_console_input_exits_2_with_the_reason() {
    let dir = scratch("console-bad");
    let state = small_state(&dir);
    let s = state.to_str().unwrap();
    let rec = dir.join("run.jsonl");
    let r = rec.to_str().unwrap();
    let cases: [(&[&str], &str); 12] = [
        (&["console", s, "--simulate", "--lead=-1"], "--lead -1"),
        (&["console", s], "needs a source: STATE --simulate"),
        (
            &[
                "console",
                s,
                "--simulate",
                "--record",
                r,
                "--until",
                "laps:3",
            ],
            "--until laps:3: expected ticks:N, rounds:N or tasks:N",
        ),
        (
            &[
                "console",
                s,
                "--simulate",
                "--record",
                r,
                "--until",
                "tasks:3",
            ],
            "--until tasks:3: counts tasks, and a rounds cell counts rounds",
        ),
        (
            &["console", "--replay", "missing.jsonl", "--check"],
            "cannot open the recording",
        ),
        (
            &["console", "--replay", s, "--check"],
            "not a console recording",
        ),
        (
            &["console", "--replay", "run.mcap", "--check"],
            "an MCAP bag is not a console recording",
        ),
        (
            &["console", s, "--simulate", "--replay", r],
            "cannot be used with",
        ),
        (&["console", "--replay", r, "--speed", "0"], "--speed 0"),
        (&["console", s, "--simulate", "--speed", "0"], "--speed 0"),
        (
            &["console", s, "--simulate", "--robots", "17"],
            "--robots 17",
        ),
        (
            &["console", "missing.tandem", "--simulate"],
            "missing.tandem",
        ),
    ];
    for (args, want) in cases {
        let out = tandem(args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(want), "{args:?}: {err}");
    }
    // A recording never overwrites a file.
    let out = tandem([
        "console",
        s,
        "--simulate",
        "--record",
        s,
        "--until",
        "ticks:5",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--record") && err.contains("never overwrites"),
        "{err}"
    );
    // A state holding recorded rounds keeps its robot count.
    let golden = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/state/example.tandem"
    );
    let out = tandem(["console", golden, "--simulate", "--robots", "3"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("recorded round") && err.contains("tandem fit --robots 3"),
        "{err}"
    );
}
