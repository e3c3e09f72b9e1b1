//! The console's server against a live loop, over plain HTTP (no browser): the control
//! messages' round trip, one controlling client, malformed and out-of-order messages refused
//! with a clear error, and the coordinator unaffected by any of them.

mod support;

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use tandem_console::{Console, ConsoleConfig, Driver, Frame, Geometry};
use tandem_realtime::{Controller, Operator};

/// One HTTP/1.1 request; returns the status and the body.
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
    let body = out.split_once("\r\n\r\n").map_or("", |x| x.1).to_string();
    (status, body)
}

/// The newest frame, or `None` before the loop's first (503).
fn frame(addr: SocketAddr) -> Option<Frame> {
    let (status, body) = http(addr, "GET", "/frame", "");
    if status == 503 {
        return None;
    }
    assert_eq!(status, 200, "{body}");
    Some(serde_json::from_str(&body).unwrap())
}

fn wait_for(addr: SocketAddr, what: &str, mut ok: impl FnMut(&Frame) -> bool) -> Frame {
    let t0 = Instant::now();
    loop {
        let f = frame(addr);
        if let Some(f) = f.as_ref().filter(|f| ok(f)) {
            return f.clone();
        }
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "timed out waiting for {what}: {f:?}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn controls_round_trip_and_bad_messages_leave_the_coordinator_alone() {
    let ctl = support::rounds(3);
    let (console, mut handle) =
        Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).unwrap();
    let addr = console.addr();
    assert_eq!(console.url(), format!("http://{addr}/"));
    assert!(addr.ip().is_loopback());
    let stop = Arc::new(AtomicBool::new(false));
    // The user's loop: a controller and its twin, ticked alike whenever the console lets the
    // loop tick; at the end they must agree (nothing the console got changed the controller).
    let loop_stop = stop.clone();
    let worker = std::thread::spawn(move || {
        let mut ctl = ctl;
        let mut twin = ctl.clone();
        let mut ticks = 0u64;
        while !loop_stop.load(Ordering::Relaxed) {
            if Driver::apply(&mut handle, &mut ctl) {
                if ctl.is_finished() {
                    ctl.reset();
                    twin.reset();
                }
                let t = ctl.tick(Operator::Slowest).unwrap();
                twin.tick(Operator::Slowest).unwrap();
                ticks += 1;
                handle.publish(&t, &ctl);
            } else {
                handle.publish(&tandem_console::tick_now(&ctl), &ctl);
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        (ctl, twin, ticks)
    });
    let page = http(addr, "GET", "/", "");
    assert_eq!(page.0, 200);
    assert!(page.1.contains("data-attention"), "the page is served");
    wait_for(addr, "a first frame", |f| f.tick > 0);

    // Malformed, unknown op, unknown field, missing robot: 400 with the reason.
    for (body, want) in [
        ("{not json", "malformed control message"),
        (
            r#"{"client":"a","id":1,"op":"explode"}"#,
            "unknown variant `explode`",
        ),
        (
            r#"{"client":"a","id":1,"op":"pause","extra":1}"#,
            "unknown field `extra`",
        ),
        (
            r#"{"client":"","id":1,"op":"claim"}"#,
            "`client` must be 1 to 64 characters",
        ),
    ] {
        let (status, text) = http(addr, "POST", "/control", body);
        assert_eq!(status, 400, "{body} → {text}");
        assert!(text.contains(want), "{body} → {text}");
    }
    // No controller yet: a control is refused.
    let (status, text) = http(
        addr,
        "POST",
        "/control",
        r#"{"client":"a","id":1,"op":"pause"}"#,
    );
    assert_eq!(
        (status, text.contains("claim control first")),
        (403, true),
        "{text}"
    );
    // The first to claim controls; a second client is read-only.
    let (status, _) = http(
        addr,
        "POST",
        "/control",
        r#"{"client":"a","id":2,"op":"claim"}"#,
    );
    assert_eq!(status, 200);
    let (status, text) = http(
        addr,
        "POST",
        "/control",
        r#"{"client":"b","id":1,"op":"claim"}"#,
    );
    assert_eq!(status, 409);
    assert!(
        text.contains("read-only: client a controls the cell"),
        "{text}"
    );
    let (status, text) = http(
        addr,
        "POST",
        "/control",
        r#"{"client":"b","id":2,"op":"pause"}"#,
    );
    assert_eq!((status, text.contains("read-only")), (403, true), "{text}");
    // Out of order: an id not above the client's last.
    let (status, text) = http(
        addr,
        "POST",
        "/control",
        r#"{"client":"a","id":2,"op":"pause"}"#,
    );
    assert_eq!(status, 409);
    assert!(
        text.contains("out-of-order message: id 2 after id 2"),
        "{text}"
    );
    // A hold needs a robot of the cell; a rounds plan without hold points refuses it.
    let (status, text) = http(
        addr,
        "POST",
        "/control",
        r#"{"client":"a","id":3,"op":"hold","robot":4}"#,
    );
    assert_eq!((status, text.contains("1..=3")), (400, true), "{text}");
    let (status, _) = http(
        addr,
        "POST",
        "/control",
        r#"{"client":"a","id":4,"op":"hold","robot":2}"#,
    );
    assert_eq!(status, 202);
    let f = wait_for(addr, "the hold's answer", |f| {
        f.acks.iter().any(|a| a.id == 4)
    });
    let ack = f.acks.iter().find(|a| a.id == 4).unwrap();
    assert!(!ack.ok && ack.message.contains("no hold points"), "{ack:?}");

    // Pause: confirmed in the frame stream with its id, and the cell stops ticking.
    let (status, text) = http(
        addr,
        "POST",
        "/control",
        r#"{"client":"a","id":5,"op":"pause"}"#,
    );
    assert_eq!(status, 202, "{text}");
    let f = wait_for(addr, "the pause's confirmation", |f| {
        f.paused && f.acks.iter().any(|a| a.id == 5 && a.ok && a.client == "a")
    });
    std::thread::sleep(Duration::from_millis(200));
    let later = wait_for(addr, "a newer frame", |g| g.seq > f.seq);
    assert_eq!(later.tick, f.tick, "a paused cell does not tick");
    // Clear fault without a fault: refused by the loop, in words.
    http(
        addr,
        "POST",
        "/control",
        r#"{"client":"a","id":6,"op":"clear_fault"}"#,
    );
    let f = wait_for(addr, "the clear's answer", |f| {
        f.acks.iter().any(|a| a.id == 6)
    });
    assert!(
        f.acks
            .iter()
            .any(|a| a.id == 6 && !a.ok && a.message == "no fault is latched")
    );
    // Resume: ticking again.
    http(
        addr,
        "POST",
        "/control",
        r#"{"client":"a","id":7,"op":"resume"}"#,
    );
    let f = wait_for(addr, "resumed", |g| !g.paused && g.tick > f.tick);
    assert!(f.acks.iter().any(|a| a.id == 7 && a.ok));
    // Hand control over: a releases, b claims.
    assert_eq!(
        http(
            addr,
            "POST",
            "/control",
            r#"{"client":"a","id":8,"op":"release"}"#
        )
        .0,
        200
    );
    assert_eq!(
        http(
            addr,
            "POST",
            "/control",
            r#"{"client":"b","id":3,"op":"claim"}"#
        )
        .0,
        200
    );
    assert_eq!(
        wait_for(addr, "b controls", |f| f.controller.as_deref() == Some("b"))
            .controller
            .as_deref(),
        Some("b")
    );

    stop.store(true, Ordering::Relaxed);
    let (ctl, twin, ticks) = worker.join().unwrap();
    assert!(ticks > 0);
    assert_eq!(ctl.ticks(), twin.ticks());
    assert_eq!(ctl.ref_time_now(), twin.ref_time_now());
    assert_eq!(ctl.clock_s(), twin.clock_s());
    assert!(ctl.fault().is_none());
    console.stop();
}

#[test]
fn a_taken_port_is_a_clear_error_and_bad_settings_are_refused() {
    let ctl = support::rounds(2);
    let (console, _h) = Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).unwrap();
    let taken = ConsoleConfig {
        port: console.addr().port(),
        ..ConsoleConfig::default()
    };
    let err = Console::start(&taken, Geometry::new(&ctl))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("cannot listen on 127.0.0.1:") && err.contains("--port 0"),
        "{err}"
    );
    let bad = ConsoleConfig {
        max_hz: 0.0,
        ..ConsoleConfig::default()
    };
    let err = Console::start(&bad, Geometry::new(&ctl))
        .unwrap_err()
        .to_string();
    assert!(err.contains("max_hz"), "{err}");
}

/// The page's countdown is the coordinator's pre-alert (`Tick::next`) of the tick the frame
/// shows, exactly: robot, earliest start (the countdown), latest start; the pre-alert's lead is
/// the switch time where that exceeds the configured 7 s.
#[test]
fn the_countdown_is_the_coordinators_pre_alert() {
    use std::collections::HashMap;
    use std::sync::Mutex;
    use tandem_planner::AnyController;

    let AnyController::Rounds(c) = support::rounds(3) else {
        unreachable!("support::rounds is a rounds cell")
    };
    let ctl = AnyController::Rounds(c.with_switch_s(8.0).unwrap());
    let geometry = Geometry::new(&ctl);
    assert_eq!(geometry.switch_s(), 8.0);
    let (console, mut handle) = Console::start(&ConsoleConfig::default(), geometry).unwrap();
    let addr = console.addr();
    type Seen = HashMap<u64, Option<tandem_realtime::PreAlert>>;
    let truth: Arc<Mutex<Seen>> = Arc::default();
    let stop = Arc::new(AtomicBool::new(false));
    let (loop_truth, loop_stop) = (truth.clone(), stop.clone());
    let worker = std::thread::spawn(move || {
        let mut ctl = ctl;
        while !loop_stop.load(Ordering::Relaxed) && !ctl.is_finished() {
            let t = ctl.tick(Operator::Scheduled).unwrap();
            loop_truth.lock().unwrap().insert(ctl.ticks(), t.next);
            handle.publish(&t, &ctl);
            std::thread::sleep(Duration::from_millis(10));
        }
        handle.published()
    });
    let (mut looks, mut with_next, mut alerted, mut unbounded) = (0, 0, 0, 0);
    let t0 = Instant::now();
    while t0.elapsed() < Duration::from_millis(2500) {
        let Some(f) = frame(addr) else { continue };
        looks += 1;
        assert_eq!(f.lead_s, 8.0, "the switch time exceeds the default 7 s");
        let want = *truth
            .lock()
            .unwrap()
            .get(&f.tick)
            .expect("a published tick");
        match (want, &f.next) {
            (None, None) => {}
            (Some(p), Some(n)) => {
                with_next += 1;
                assert_eq!(n.robot, p.robot + 1, "tick {}", f.tick);
                assert_eq!(n.in_s, p.earliest_s, "tick {}", f.tick);
                assert_eq!(n.latest_s, p.latest_s.is_finite().then_some(p.latest_s));
                assert_eq!(f.prealert, p.earliest_s <= 8.0);
                alerted += usize::from(f.prealert);
                unbounded += usize::from(n.latest_s.is_none());
                assert!(n.duration_s > 0.0, "{n:?}");
            }
            (w, n) => panic!("tick {}: coordinator {w:?}, page {n:?}", f.tick),
        }
        assert!(f.health.published >= f.tick, "{:?}", f.health);
        std::thread::sleep(Duration::from_millis(15));
    }
    stop.store(true, Ordering::Relaxed);
    let published = worker.join().unwrap();
    console.stop();
    assert!(
        looks >= 20 && with_next >= 10 && alerted >= 1,
        "{looks} looks, {with_next} with a pre-alert, {alerted} alerted, {unbounded} unbounded"
    );
    assert!(published > 0);
}

/// Publishes the cell as it is (no tick, no correction) until the page's frame is of the
/// controller's current tick; returns it.
fn settle<C: Controller>(
    addr: SocketAddr,
    handle: &mut tandem_console::ConsoleHandle,
    ctl: &C,
) -> Frame {
    let t0 = Instant::now();
    loop {
        handle.publish_corrected(&tandem_console::tick_now(ctl), ctl, false);
        if let Some(f) = frame(addr).filter(|f| f.tick == ctl.ticks()) {
            return f;
        }
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "no frame of tick {}",
            ctl.ticks()
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn the_strip_counts_the_operators_corrections_in_the_current_execution() {
    // support::rounds(3): robot i low-confidence from 4 + 4i s for 20 ticks, task 10 s.
    let mut ctl = support::rounds(3);
    let (console, mut handle) =
        Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).unwrap();
    let addr = console.addr();
    let counts =
        |f: &Frame| -> Vec<Option<u64>> { f.robots.iter().map(|r| r.strip.corrections).collect() };
    let (mut last_lc, mut k_in) = (None, 0usize);
    let mut checked = 0;
    while ctl.ticks() < 110 {
        let lc = ctl.low_conf_now().first();
        k_in = if lc == last_lc { k_in + 1 } else { 0 };
        last_lc = lc;
        // Before any stretch (no robot supervised): input that moves nobody, not counted.
        // Robot 1: corrected on its stretch's ticks 0-2 and 6-7 (two corrections); robot 2:
        // ticks 0-4 (one); robot 3 none.
        let corrected = match lc {
            None => ctl.ticks() < 5,
            Some(0) => [0, 1, 2, 6, 7].contains(&k_in),
            Some(1) => k_in < 5,
            Some(_) => false,
        };
        let op = if corrected {
            Operator::Gradient(1.0)
        } else {
            Operator::Scheduled
        };
        let t = ctl.tick(op).unwrap();
        handle.publish_corrected(&t, &ctl, corrected);
        if lc == Some(0) && k_in == 10 {
            let f = settle(addr, &mut handle, &ctl);
            assert_eq!(f.robots[0].state.name(), "lc", "{f:?}");
            assert_eq!(counts(&f), [Some(2), Some(0), Some(0)], "tick {}", f.tick);
            checked += 1;
        }
    }
    // 11 s: robot 1 finished its task at 10 s (a new execution: none yet), robot 2's stretch
    // (8-10 s) is behind it with its one correction, robot 3's is ahead.
    let f = settle(addr, &mut handle, &ctl);
    assert_eq!(f.robots[0].tasks, 1, "{f:?}");
    assert_eq!(counts(&f), [Some(0), Some(1), Some(0)], "tick {}", f.tick);
    assert_eq!(checked, 1);
    console.stop();

    // A loop that does not report its operator's input: the strip shows no count.
    let mut ctl = support::rounds(2);
    let (console, mut handle) =
        Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).unwrap();
    let t0 = Instant::now();
    let f = loop {
        let t = ctl.tick(Operator::Scheduled).unwrap();
        handle.publish(&t, &ctl);
        if let Some(f) = frame(console.addr()) {
            break f;
        }
        assert!(t0.elapsed() < Duration::from_secs(10), "no frame");
        std::thread::sleep(Duration::from_millis(10));
    };
    assert_eq!(counts(&f), [None, None]);
    console.stop();
}
