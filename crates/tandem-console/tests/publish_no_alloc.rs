//! The control loop's side of the console never allocates (issue 42): a whole run of
//! `Driver::apply`, `tick` and `ConsoleHandle::publish` (and `publish_corrected`) against a running server, which asks for
//! snapshots at its frame rate meanwhile (so the write path runs), measured with the
//! `allocation-counter` crate's per-thread counting allocator (the server's own thread, which
//! does allocate, is not counted).

mod support;

use std::hint::black_box;
use std::time::{Duration, Instant};

use allocation_counter::measure;
use tandem_console::{Console, ConsoleConfig, Driver, Geometry};
use tandem_realtime::{Controller, Operator};

#[test]
fn the_loops_side_allocates_nothing() {
    // Non-vacuity: the counting allocator is the one in use.
    let boxed = measure(|| {
        black_box(Box::new(7_u64));
    });
    assert_eq!(boxed.count_total, 1, "the counting allocator is not active");

    for mut ctl in [support::rounds(3), support::continuous(3)] {
        let (console, mut handle) =
            Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).unwrap();
        let mut ticks = 0u64;
        let counts = measure(|| {
            let t0 = Instant::now();
            // 0.4 s at one tick a millisecond: the server asks about 12 times.
            while t0.elapsed() < Duration::from_millis(400) {
                if Driver::apply(&mut handle, &mut ctl) {
                    if ctl.is_finished() {
                        ctl.reset();
                    }
                    // Every third tick a correction, counted on the supervised robot.
                    let corrected = ticks % 3 == 0;
                    let op = if corrected {
                        Operator::Slowest
                    } else {
                        Operator::Scheduled
                    };
                    let t = ctl.tick(op).expect("a valid operator");
                    if ticks % 2 == 0 {
                        handle.publish_corrected(&t, &ctl, corrected);
                    } else {
                        handle.publish(&t, &ctl);
                    }
                    ticks += 1;
                }
                std::thread::sleep(Duration::from_millis(1));
            }
        });
        assert_eq!(counts.count_total, 0, "{counts:?} over {ticks} ticks");
        assert_eq!(handle.published(), ticks);
        assert!(ticks >= 50, "{ticks} ticks in 0.4 s");
        // The server took snapshots meanwhile: the write path ran.
        let f = wait_frame(console.addr());
        assert!(f > 0, "the server saw tick {f}");
        console.stop();
    }
}

/// The tick of the console's newest frame (polled for up to 5 s).
fn wait_frame(addr: std::net::SocketAddr) -> u64 {
    use std::io::{Read, Write};
    let t0 = Instant::now();
    loop {
        let mut s = std::net::TcpStream::connect(addr).unwrap();
        write!(
            s,
            "GET /frame HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
        )
        .unwrap();
        let mut out = String::new();
        s.read_to_string(&mut out).unwrap();
        if out.starts_with("HTTP/1.1 200") {
            let body = out.split_once("\r\n\r\n").map_or("", |x| x.1);
            let v: serde_json::Value = serde_json::from_str(body).unwrap();
            return v["tick"].as_u64().unwrap();
        }
        assert!(t0.elapsed() < Duration::from_secs(5), "no frame: {out}");
        std::thread::sleep(Duration::from_millis(20));
    }
}
