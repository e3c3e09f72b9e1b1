//! The node feeds the operator console (issue 43, "the console and the node share one
//! source"): the console's `/frame` shows the loop's own tick, its low-confidence robot is the
//! node's `needs_operator`, a controller replaced after a recorded round brings its plan to the
//! page, the page says when the node is idle and how long the operator rests after a round
//! (the load cap), and a node started with a console serves the live round.
//! Loopback only.

mod support;

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::time::{Duration, Instant};

use tandem_console::{Console, ConsoleConfig, Frame, Geometry, RobotState};
use tandem_planner::Cell;
use tandem_realtime::Controller;
use tandem_ros2::{
    CellLoop, ConsoleFeed, FINISHED_NOTICE, IDLE_NOTICE, Inbound, LoopParams, Node, NodeParams,
    Probe, Request, rest_notice,
};

/// One HTTP/1.1 request; returns the status and the body.
fn http(addr: SocketAddr, method: &str, path: &str) -> (u16, String) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\nContent-Length: 0\r\n\r\n"
    )
    .unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    let status = out[9..12].parse().unwrap();
    let body = out.split_once("\r\n\r\n").map_or("", |x| x.1).to_string();
    (status, body)
}

/// The newest frame, or `None` before the loop's first (503).
fn frame(addr: SocketAddr) -> Option<Frame> {
    let (status, body) = http(addr, "GET", "/frame");
    if status == 503 {
        return None;
    }
    assert_eq!(status, 200, "{body}");
    Some(serde_json::from_str(&body).unwrap())
}

fn lc_robots(f: &Frame) -> Vec<usize> {
    f.robots
        .iter()
        .enumerate()
        .filter(|(_, r)| r.state == RobotState::Lc)
        .map(|(i, _)| i)
        .collect()
}

#[test]
fn the_consoles_lc_robot_is_the_nodes_needs_operator_at_every_change() {
    let planner = support::planner(2);
    let ctl = planner.controller(Cell::Rounds).unwrap();
    let (console, handle) = Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).unwrap();
    let addr = console.addr();
    let mut feed = ConsoleFeed::new(handle);
    let mut cell = CellLoop::new(ctl, planner.model(), LoopParams::default()).unwrap();
    let t0 = Instant::now();
    let tick = Duration::from_secs_f64(cell.controller().tick_s());
    let mut replies = Vec::new();
    cell.handle(
        Inbound::Request {
            token: 1,
            what: Request::Start,
        },
        t0,
        &mut |r| replies.push(r),
    );
    assert_eq!(replies.len(), 1);
    let mut before: Option<Vec<usize>> = None;
    let (mut checked, mut with_lc, mut without_lc) = (0, 0, 0);
    for i in 1..=10_000_u32 {
        let now = t0 + tick * i;
        for robot in 0..2 {
            let ref_time = cell.last_tick().ref_time[robot];
            cell.handle(Inbound::Progress { robot, ref_time }, now, &mut |_| {});
        }
        let snap = cell.step(now).unwrap();
        let needs: Vec<usize> = (0..2).filter(|&k| snap.needs_operator[k]).collect();
        // At every change of the robot that needs the operator (and the round's end): the
        // loop holds still and publishes until the page's frame is this tick's.
        if before.as_ref() != Some(&needs) || snap.finished {
            let want = cell.controller().ticks();
            let end = Instant::now() + Duration::from_secs(10);
            let f = loop {
                feed.publish(&cell);
                if let Some(f) = frame(addr).filter(|f| f.tick == want) {
                    break f;
                }
                assert!(Instant::now() < end, "no frame of tick {want}");
                std::thread::sleep(Duration::from_millis(5));
            };
            assert_eq!(lc_robots(&f), needs, "tick {want}: {f:?}");
            assert!(needs.len() <= 1, "two robots need the operator: {needs:?}");
            checked += 1;
            if needs.is_empty() {
                without_lc += 1;
            } else {
                with_lc += 1;
            }
            before = Some(needs);
        } else {
            feed.publish(&cell);
        }
        if snap.finished {
            // The round's end is counted on the page.
            let f = loop {
                feed.publish(&cell);
                if let Some(f) = frame(addr).filter(|f| f.rounds_done == 1) {
                    break f;
                }
                std::thread::sleep(Duration::from_millis(5));
            };
            assert_eq!(f.rounds_done, 1);
            break;
        }
    }
    eprintln!("{checked} changes checked: {with_lc} with a robot lc, {without_lc} without");
    // Both robots' low-confidence runs (reference samples 10..20) begin and end: at least
    // two frames with a robot lc and three without.
    assert!(with_lc >= 2 && without_lc >= 3, "{with_lc} / {without_lc}");
    assert!(feed.published() > 0);
    console.stop();
}

/// The frame of `addr` once it shows tick `tick` and satisfies `ok`, publishing meanwhile.
fn frame_at(
    addr: SocketAddr,
    tick: u64,
    mut publish: impl FnMut(),
    ok: impl Fn(&Frame) -> bool,
) -> Frame {
    let end = Instant::now() + Duration::from_secs(10);
    loop {
        publish();
        if let Some(f) = frame(addr).filter(|f| f.tick == tick && ok(f)) {
            return f;
        }
        assert!(Instant::now() < end, "no frame of tick {tick} as wanted");
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_replaced_controller_brings_its_plan_to_the_page_and_the_page_says_idle() {
    let planner = support::planner(2);
    let ctl = planner.controller(Cell::Rounds).unwrap();
    let geometry_a = Geometry::new(&ctl);
    let (console, handle) = Console::start(&ConsoleConfig::default(), geometry_a.clone()).unwrap();
    let addr = console.addr();
    let mut feed = ConsoleFeed::new(handle);
    let mut cell = CellLoop::new(ctl, planner.model(), LoopParams::default()).unwrap();
    // Before any round: the page says the node is idle.
    let idle = frame_at(addr, 0, || feed.publish(&cell), |f| f.notice.is_some());
    assert_eq!(idle.notice.as_deref(), Some(IDLE_NOTICE));
    // The next round's controller, as `record_round` hands it over: here another plan (the
    // task at a 20 ms tick, so every stretch twice as far), swapped in at the next start.
    let other = support::planner_with(support::model_at(0.02), 2)
        .controller(Cell::Rounds)
        .unwrap();
    let geometry_b = Geometry::new(&other);
    let t0 = Instant::now();
    cell.handle(
        Inbound::Replace(Box::new(other), Box::new(geometry_b.clone())),
        t0,
        &mut |_| {},
    );
    assert_eq!(
        cell.plan_generation(),
        0,
        "swapped in at the next start only"
    );
    cell.handle(
        Inbound::Request {
            token: 1,
            what: Request::Start,
        },
        t0,
        &mut |_| {},
    );
    assert_eq!(cell.plan_generation(), 1);
    let tick = Duration::from_secs_f64(cell.controller().tick_s());
    let mut now = t0;
    let mut step = |cell: &mut CellLoop| {
        now += tick;
        for robot in 0..2 {
            cell.heard(robot, now);
        }
        cell.step(now).unwrap()
    };
    for _ in 0..5 {
        step(&mut cell);
    }
    let t = cell.controller().ticks();
    let got = frame_at(addr, t, || feed.publish(&cell), |f| f.notice.is_none());
    // What a console started on each plan shows for the same tick of the same controller.
    let shown_on = |g: &Geometry| {
        let (c, mut h) = Console::start(&ConsoleConfig::default(), g.clone()).unwrap();
        let f = frame_at(
            c.addr(),
            t,
            || h.publish(cell.last_tick(), cell.controller()),
            |_| true,
        );
        c.stop();
        f
    };
    let (on_a, on_b) = (shown_on(&geometry_a), shown_on(&geometry_b));
    assert_ne!(
        on_a.stretches, on_b.stretches,
        "the two plans must differ for this test"
    );
    assert!(!got.stretches.is_empty());
    assert_eq!(got.stretches, on_b.stretches, "the page kept the old plan");
    assert_eq!((got.lead_s, got.horizon_s), (on_b.lead_s, on_b.horizon_s));
    // The round's end: the page says a round waits to be recorded.
    let end = Instant::now() + Duration::from_secs(30);
    while !step(&mut cell).finished {
        assert!(Instant::now() < end, "the round did not finish");
    }
    let t = cell.controller().ticks();
    let done = frame_at(addr, t, || feed.publish(&cell), |f| f.notice.is_some());
    assert_eq!(done.notice.as_deref(), Some(FINISHED_NOTICE));
    console.stop();
}

#[test]
fn the_page_says_how_long_the_operator_rests_after_a_round() {
    let mut planner = support::planner(2);
    planner.set_operator(0.0, 0.1).unwrap();
    let ctl = planner.controller(Cell::Rounds).unwrap();
    let (console, handle) = Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).unwrap();
    let addr = console.addr();
    let mut feed = ConsoleFeed::new(handle);
    let mut cell = CellLoop::new(ctl, planner.model(), LoopParams::default()).unwrap();
    let tick = Duration::from_secs_f64(cell.controller().tick_s());
    let mut now = Instant::now();
    let start = Inbound::Request {
        token: 1,
        what: Request::Start,
    };
    cell.handle(start, now, &mut |_| {});
    let mut step = |cell: &mut CellLoop| {
        now += tick;
        for robot in 0..2 {
            cell.heard(robot, now);
        }
        cell.step(now).unwrap()
    };
    while !step(&mut cell).finished {}
    let t = cell.controller().ticks();
    let rest = cell.rest_left_ticks();
    assert!(rest > 0, "the cap of 0.1 binds on this round");
    // Whole seconds, rounded up: never less than is left.
    let left_s = (cell.rest_left_s()).ceil() as u64;
    assert!(left_s >= 1);
    let resting = frame_at(addr, t, || feed.publish(&cell), |f| f.notice.is_some());
    assert_eq!(
        resting.notice.as_deref(),
        Some(rest_notice(left_s, true).as_str())
    );
    assert!(rest_notice(left_s, true).starts_with(&format!("rest: {left_s} s")));
    // The rest passes in idle ticks (the controller does not tick: the frame's tick stays);
    // then the page says the round waits, as without a cap.
    for _ in 0..rest {
        step(&mut cell);
    }
    assert_eq!(cell.rest_left_ticks(), 0);
    let done = frame_at(
        addr,
        t,
        || feed.publish(&cell),
        |f| f.notice.as_deref() == Some(FINISHED_NOTICE),
    );
    assert_eq!(done.notice.as_deref(), Some(FINISHED_NOTICE));
    console.stop();
}

#[test]
fn a_node_with_a_console_serves_its_live_round() {
    let state = support::state_file("console", 2);
    let params = NodeParams {
        domain: 70,
        robots: Some(2),
        ..NodeParams::default()
    };
    let node = Node::start_with_console(&state, &params, &ConsoleConfig::default()).unwrap();
    let url = node.console_url().expect("a console").to_string();
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");
    let addr: SocketAddr = url
        .trim_start_matches("http://")
        .trim_end_matches('/')
        .parse()
        .unwrap();
    // Before a round: the page shows the node's two robots, none low-confidence.
    let end = Instant::now() + Duration::from_secs(10);
    let idle = loop {
        if let Some(f) = frame(addr) {
            break f;
        }
        assert!(Instant::now() < end, "no frame from the node");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(idle.robots.len(), 2);
    assert_eq!(idle.notice.as_deref(), Some(IDLE_NOTICE), "{idle:?}");
    // A round driven over DDS: the page follows the node's controller tick by tick and counts
    // the round once it ends.
    let probe = Probe::new(70, 2).unwrap();
    let echo = || {
        for k in 0..2 {
            if let Some(c) = probe.commands(k).last() {
                probe.report(k, c.ref_time).unwrap();
            }
        }
    };
    // Discovery on loopback first: both robots' commands reach the probe.
    let end = Instant::now() + Duration::from_secs(30);
    let mut seen = [false; 2];
    while !seen.iter().all(|&s| s) {
        for (k, s) in seen.iter_mut().enumerate() {
            *s |= !probe.commands(k).is_empty();
        }
        assert!(Instant::now() < end, "no discovery on loopback");
        std::thread::sleep(Duration::from_millis(5));
    }
    let r = probe
        .call("start_round", Duration::from_secs(10), echo)
        .unwrap();
    assert!(r.success, "{}", r.message);
    let end = Instant::now() + Duration::from_secs(60);
    let mut ticks = Vec::new();
    let mut lc_seen = false;
    loop {
        echo();
        if let Some(f) = frame(addr) {
            ticks.push(f.tick);
            lc_seen |= !lc_robots(&f).is_empty();
            assert!(lc_robots(&f).len() <= 1, "{f:?}");
            if f.rounds_done == 1 {
                break;
            }
        }
        assert!(
            Instant::now() < end,
            "the page never showed the round's end"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
    assert!(ticks.windows(2).all(|w| w[0] <= w[1]), "{ticks:?}");
    assert!(ticks.last() > ticks.first(), "{ticks:?}");
    assert!(lc_seen, "no frame showed a robot low-confidence");
    // The finished round waits: the page says so.
    let end = Instant::now() + Duration::from_secs(10);
    while frame(addr).and_then(|f| f.notice).as_deref() != Some(FINISHED_NOTICE) {
        assert!(Instant::now() < end, "the page never said the round waits");
        std::thread::sleep(Duration::from_millis(20));
    }
    node.stop().unwrap();
    support::remove(&state);
}
