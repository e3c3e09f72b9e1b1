//! Console recordings: written by a loop, read back, replayed through the server as the page
//! sees them, and checked frame by frame against the coordinator (issue 42's must-show on
//! the hand-made cells; the figures on a fitted state are in docs/decisions.md). A damaged or
//! truncated recording replays up to its damage with a clear notice, never a panic.

mod support;

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use tandem_console::{
    Console, ConsoleConfig, Frame, Geometry, RECORDING_HZ, Recorder, check_recording,
    read_recording, replay, tick_now,
};
use tandem_planner::AnyController;
use tandem_realtime::{Controller, Operator};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tandem-console-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Records `ctl` driven by the scheduled operator (a rounds cell restarts `rounds` times; a
/// continuous cell runs until its robots completed `tasks` tasks together).
fn record(ctl: &mut AnyController, path: &std::path::Path, rounds: u64, tasks: u64) -> u64 {
    let is_rounds = matches!(ctl, AnyController::Rounds(_));
    let mut rec =
        Recorder::create(path, &Geometry::new(ctl), ctl.tick_s(), Some("hand-made")).unwrap();
    rec.record(&tick_now(ctl), ctl, is_rounds, 0).unwrap();
    let (mut done, mut ticks) = (0u64, 0u64);
    loop {
        if is_rounds && ctl.is_finished() {
            done += 1;
            if done == rounds {
                break;
            }
            ctl.reset();
        }
        if !is_rounds && ctl.tasks_now().iter().sum::<u64>() >= tasks {
            break;
        }
        let t = ctl.tick(Operator::Scheduled).unwrap();
        rec.record(&t, ctl, is_rounds, done).unwrap();
        ticks += 1;
    }
    rec.flush().unwrap();
    ticks
}

/// Three robots on a 30 s task (300 samples of 0.1 s), low-confidence on samples 100..120,
/// starting 0, 10 and 20 s: stretches at 10, 20 and 30 s of each round.
fn spaced() -> AnyController {
    let conf: Vec<bool> = (0..300).map(|k| !(100..120).contains(&k)).collect();
    let (g, lo, hi) = (vec![1.0; 300], vec![0.5; 300], vec![2.0; 300]);
    let robots: Vec<_> = (0..3)
        .map(|i| tandem_realtime::Timeline::new(&conf, &g, &lo, &hi, 10.0 * i as f64, 0.1).unwrap())
        .collect();
    AnyController::Rounds(tandem_realtime::Coordinator::new(robots, 0.1).unwrap())
}

#[test]
fn every_frame_of_a_replay_shows_the_coordinators_robot() {
    let dir = scratch("check");
    // Rounds: three robots whose stretches are 4 s apart, five rounds; the continuous cell of
    // three robots, 300 tasks.
    for (name, mut ctl, rounds, tasks) in [
        ("rounds", support::rounds(3), 5, 0),
        ("spaced", spaced(), 3, 0),
        ("continuous", support::continuous(3), 0, 300),
    ] {
        let path = dir.join(format!("{name}.jsonl"));
        let ticks = record(&mut ctl, &path, rounds, tasks);
        let rec = read_recording(&path).unwrap();
        assert!(rec.problem.is_none(), "{:?}", rec.problem);
        // Every state change is a line, and at least one line per 1/30 s of cell time.
        let span_s = rec.ticks.last().unwrap().t_s;
        assert!(
            (span_s - ticks as f64 * 0.1).abs() < 1e-6,
            "{span_s} s, {ticks} ticks"
        );
        assert!(rec.ticks.len() as f64 >= span_s * RECORDING_HZ.min(10.0));
        let c = check_recording(&rec, 7.0);
        eprintln!("{name}: {ticks} ticks → {c:?}");
        assert_eq!(c.frames, rec.ticks.len());
        assert_eq!(c.two_lc, 0, "{name}: frames with two robots lc");
        assert_eq!(
            c.lc_differs, 0,
            "{name}: frames where the page's lc robot differs"
        );
        if name == "spaced" {
            // Robot 1's stretch at 10 s of each round is known as next from the round's
            // start: 10 s of notice allowed. The robots run their high-confidence samples at
            // the fastest admissible pace (ψ̇min = ½), so robot 2's stretch follows robot 1's
            // start by 6.1 s and robot 3's robot 2's by 5.9 s: less than 7 s allowed.
            assert_eq!((c.stretches, c.allowed), (9, 3), "{c:?}");
            // Every allowed stretch was pre-alerted 7 s ahead, by the page and the contract.
            assert_eq!((c.alerted, c.contract_alerted), (3, 3), "{c:?}");
            assert!(c.min_notice_s.unwrap() >= 7.0 - 1e-9, "{c:?}");
        } else if name == "rounds" {
            // Per round: robots 1, 2, 3 at 3.9, 7.9, 11.9 s (4 s apart): each is known as
            // next from the start of the one before (4 s) or, robot 1, from the round's start
            // (3.9 s): no stretch leaves 7 s of notice.
            assert_eq!(c.stretches, 15);
            assert_eq!(c.allowed, 0);
        } else {
            assert_eq!(c.stretches, 300);
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_damaged_recording_reads_up_to_its_damage_and_says_where() {
    let dir = scratch("damage");
    let path = dir.join("run.jsonl");
    let mut ctl = support::rounds(2);
    record(&mut ctl, &path, 1, 0);
    let text = std::fs::read_to_string(&path).unwrap();
    let lines = text.lines().count();
    // A recording never overwrites a file.
    let err = Recorder::create(&path, &Geometry::new(&ctl), 0.1, None)
        .unwrap_err()
        .to_string();
    assert!(err.contains("never overwrites"), "{err}");

    // Truncated in the middle of a line (a copy cut short).
    let cut = dir.join("cut.jsonl");
    std::fs::write(&cut, &text[..text.len() - 40]).unwrap();
    let rec = read_recording(&cut).unwrap();
    let p = rec.problem.as_deref().unwrap();
    assert!(p.contains(&format!("line {lines} is truncated")), "{p}");
    assert_eq!(
        rec.ticks.len(),
        lines - 2,
        "every whole line before it is kept"
    );

    // A damaged line in the middle: ticks before it kept.
    let bad = dir.join("bad.jsonl");
    let mut v: Vec<&str> = text.lines().collect();
    v[5] = r#"{"t_s": "soon"}"#;
    std::fs::write(&bad, v.join("\n")).unwrap();
    let rec = read_recording(&bad).unwrap();
    assert!(
        rec.problem
            .as_deref()
            .unwrap()
            .contains("line 6 is damaged")
    );
    assert_eq!(rec.ticks.len(), 4);
    // A line with another robot count, or time going back.
    let mut v: Vec<String> = text.lines().map(str::to_string).collect();
    v[3] = v[3].replace("\"t_s\":0.2", "\"t_s\":-1.0");
    std::fs::write(&bad, v.join("\n")).unwrap();
    let p = read_recording(&bad).unwrap().problem.unwrap();
    assert!(p.contains("line 4 is damaged") && p.contains("t_s"), "{p}");

    // Not a recording at all, an empty file, a missing one, a directory without one: errors
    // naming the file and what is expected.
    let junk = dir.join("junk.jsonl");
    std::fs::write(&junk, "hello\n").unwrap();
    let e = read_recording(&junk).unwrap_err().to_string();
    assert!(
        e.contains("junk.jsonl:1") && e.contains("not a console recording"),
        "{e}"
    );
    std::fs::write(&junk, "").unwrap();
    let e = read_recording(&junk).unwrap_err().to_string();
    assert!(e.contains("empty file"), "{e}");
    let e = read_recording(dir.join("none.jsonl"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("cannot open the recording"), "{e}");
    let empty_dir = dir.join("empty");
    std::fs::create_dir_all(&empty_dir).unwrap();
    let e = read_recording(&empty_dir).unwrap_err().to_string();
    assert!(e.contains("console.jsonl"), "{e}");
    // A directory holding console.jsonl reads it.
    std::fs::copy(&path, empty_dir.join("console.jsonl")).unwrap();
    assert_eq!(read_recording(&empty_dir).unwrap().ticks.len(), lines - 1);
    // A bag (MCAP: by extension, by its first bytes, a folder of one) is refused with what
    // to record instead.
    let bag_dir = dir.join("bag");
    std::fs::create_dir_all(&bag_dir).unwrap();
    std::fs::write(bag_dir.join("run_0.mcap"), b"\x89MCAP0\r\n\0\0").unwrap();
    let magic = dir.join("run.bin");
    std::fs::write(&magic, b"\x89MCAP0\r\n\0\0").unwrap();
    for p in [bag_dir.join("run_0.mcap"), magic, bag_dir.clone()] {
        let e = read_recording(&p).unwrap_err().to_string();
        assert!(
            e.contains("an MCAP bag is not a console recording") && e.contains("--record FILE"),
            "{}: {e}",
            p.display()
        );
    }
    let v2 = text.replacen("\"version\":1", "\"version\":2", 1);
    std::fs::write(&junk, v2).unwrap();
    let e = read_recording(&junk).unwrap_err().to_string();
    assert!(
        e.contains("version 2") && e.contains("record it again"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

fn http(addr: SocketAddr, method: &str, path: &str, body: &str) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\nContent-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
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

fn wait_for(addr: SocketAddr, what: &str, mut ok: impl FnMut(&Frame) -> bool) -> Frame {
    let t0 = Instant::now();
    loop {
        let (status, body) = http(addr, "GET", "/frame", "");
        if status == 200 {
            let f: Frame = serde_json::from_str(&body).unwrap();
            if ok(&f) {
                return f;
            }
        }
        assert!(
            t0.elapsed() < Duration::from_secs(20),
            "timed out waiting for {what}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn a_truncated_replay_plays_to_its_damage_then_says_so_on_the_page() {
    let dir = scratch("serve");
    let path = dir.join("run.jsonl");
    let mut ctl = support::rounds(3);
    record(&mut ctl, &path, 1, 0);
    let text = std::fs::read_to_string(&path).unwrap();
    let cut = dir.join("cut.jsonl");
    std::fs::write(&cut, &text[..text.len() - 30]).unwrap();
    let rec = read_recording(&cut).unwrap();
    let (console, handle) =
        Console::start(&ConsoleConfig::default(), rec.geometry.clone()).unwrap();
    let addr = console.addr();
    let stop = Arc::new(AtomicBool::new(false));
    let console = Arc::new(console);
    let worker = {
        let (stop, console, rec) = (stop.clone(), console.clone(), rec.clone());
        std::thread::spawn(move || replay(&rec, 50.0, &console, handle, &stop))
    };
    // The damage is on the page from the first frame, while the valid ticks play.
    let f = wait_for(addr, "a frame with the notice", |f| f.notice.is_some());
    let notice = f.notice.unwrap();
    assert!(
        notice.contains("is truncated") && notice.contains("replaying the"),
        "{notice}"
    );
    // A replay refuses controls that would change the recorded cell, with the reason.
    assert_eq!(
        http(
            addr,
            "POST",
            "/control",
            r#"{"client":"a","id":1,"op":"claim"}"#
        )
        .0,
        200
    );
    assert_eq!(
        http(
            addr,
            "POST",
            "/control",
            r#"{"client":"a","id":2,"op":"clear_fault"}"#
        )
        .0,
        202
    );
    let f = wait_for(addr, "the refusal", |f| f.acks.iter().any(|a| a.id == 2));
    let ack = f.acks.iter().find(|a| a.id == 2).unwrap();
    assert!(
        !ack.ok && ack.message.contains("cannot change it"),
        "{ack:?}"
    );
    // The end of the replay is announced, with the damage; the last frame is the last tick.
    let f = wait_for(addr, "the end", |f| {
        f.notice
            .as_deref()
            .is_some_and(|n| n.starts_with("replay ended"))
    });
    assert_eq!(f.tick, rec.ticks.last().unwrap().tick);
    assert!(f.notice.unwrap().contains("truncated"));
    // The operator strip counted the replayed stretches: three robots, one stretch each.
    assert_eq!(f.operator.switches, 2, "{:?}", f.operator);
    assert!(f.operator.busy_share > 0.0 && f.operator.longest_busy_s > 0.0);
    // Paused and resumed after its end, with no tick left to play: the page is told it
    // resumed (the frame's flag), not left showing a pause.
    for (id, op, paused) in [(3, "pause", true), (4, "resume", false)] {
        let body = format!(r#"{{"client":"a","id":{id},"op":"{op}"}}"#);
        assert_eq!(http(addr, "POST", "/control", &body).0, 202, "{op}");
        let f = wait_for(addr, op, |f| {
            f.paused == paused && f.acks.iter().any(|a| a.id == id && a.ok)
        });
        assert_eq!(f.tick, rec.ticks.last().unwrap().tick, "{op}");
    }
    stop.store(true, Ordering::Relaxed);
    worker.join().unwrap().unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The check's "allowed" by hand (issue 42): a stretch is allowed `lead_s` of notice when it
/// is certain to be next at least `lead_s` before it starts — from the start of the stretch
/// before it (or the round's start) — and, in rounds, follows the stretch the plan's order
/// puts before it. Two robots, 30 samples of 1 s, low confidence on samples 10–11, robot 2
/// starting 10 s after robot 1: the plan's order of a round is robot 1's stretch (schedule
/// clock 10 s), then robot 2's (20 s). Hand-written frames: round 1 runs robot 2's stretch
/// at 10 s and robot 1's at 25 s (both out of the plan's order: not allowed, although 10 s
/// and 15 s followed what came before); round 2 (from 30 s) robot 1's at 40 s (10 s after
/// the round's start: allowed) and robot 2's at 45 s (5 s after robot 1's start: not).
/// Without the order rule 3 of the 4 would count as allowed.
#[test]
fn allowed_counts_notice_from_when_the_plan_fixes_the_stretch() {
    let dir = scratch("allowed");
    let path = dir.join("hand.jsonl");
    let conf: Vec<bool> = (0..30).map(|n| !(10..12).contains(&n)).collect();
    let (g, lo, hi) = (vec![1.0; 30], vec![0.5; 30], vec![2.0; 30]);
    let robots: Vec<_> = (0..2)
        .map(|i| tandem_realtime::Timeline::new(&conf, &g, &lo, &hi, 10.0 * i as f64, 1.0).unwrap())
        .collect();
    let ctl = AnyController::Rounds(tandem_realtime::Coordinator::new(robots, 0.1).unwrap());
    let rec = Recorder::create(&path, &Geometry::new(&ctl), 0.1, Some("hand-made")).unwrap();
    drop(rec);
    let header = std::fs::read_to_string(&path).unwrap();
    let header = header.lines().next().unwrap();
    // (cell time, round, robot 1's state and reference time, robot 2's).
    let frames: [(f64, u64, &str, f64, &str, f64); 12] = [
        (0.0, 0, "hc", 0.0, "wait", 0.0),
        (10.0, 0, "hc", 10.0, "lc", 10.0),
        (12.0, 0, "hc", 12.0, "hc", 12.0),
        (25.0, 0, "lc", 10.0, "hc", 20.0),
        (27.0, 0, "hc", 12.0, "hc", 22.0),
        (29.0, 0, "done", 30.0, "done", 30.0),
        (30.0, 1, "hc", 0.0, "wait", 0.0),
        (40.0, 1, "lc", 10.2, "wait", 0.0),
        (42.0, 1, "hc", 12.0, "hc", 2.0),
        (45.0, 1, "hc", 15.0, "lc", 10.1),
        (47.0, 1, "hc", 17.0, "hc", 12.0),
        (59.0, 1, "done", 30.0, "done", 30.0),
    ];
    let mut text = format!("{header}\n");
    for (k, (t_s, round, s1, r1, s2, r2)) in frames.iter().enumerate() {
        let lc = match (*s1, *s2) {
            ("lc", _) => "1",
            (_, "lc") => "2",
            _ => "null",
        };
        text.push_str(&format!(
            "{{\"t_s\":{t_s},\"tick\":{k},\"rounds_done\":{round},\"fault\":false,\"robots\":[\
             {{\"state\":\"{s1}\",\"clock_s\":0.0,\"ref_time\":{r1},\"tasks\":0}},\
             {{\"state\":\"{s2}\",\"clock_s\":0.0,\"ref_time\":{r2},\"tasks\":0}}],\
             \"coordinator_lc\":{lc},\"next\":null}}\n"
        ));
    }
    std::fs::write(&path, text).unwrap();
    let rec = read_recording(&path).unwrap();
    assert!(rec.problem.is_none(), "{:?}", rec.problem);
    let c = check_recording(&rec, 7.0);
    assert_eq!((c.frames, c.two_lc, c.lc_differs), (12, 0, 0), "{c:?}");
    assert_eq!((c.stretches, c.out_of_order, c.allowed), (4, 2, 1), "{c:?}");
    // No pre-alert was recorded: the allowed one was not alerted.
    assert_eq!(
        (c.alerted, c.contract_alerted, c.min_notice_s),
        (0, 0, Some(0.0))
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
