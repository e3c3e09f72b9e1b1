//! The control loop without the network: rounds run and record, a silent robot stalls the
//! cell, refusals, the operator's mapping.

mod support;

use std::time::{Duration, Instant};

use tandem_planner::{Cell, Planner};
use tandem_realtime::{Controller, Operator};
use tandem_ros2::core::{Refusal, operator_input};
use tandem_ros2::{CellLoop, Inbound, LoopParams, NodeFault, Reply, Request, RoundLog};

/// A loop on `planner`'s controller for `cell`.
fn cell_loop(planner: &Planner, cell: Cell) -> CellLoop {
    let ctl = planner.controller(cell).unwrap();
    CellLoop::new(ctl, planner.model(), LoopParams::default()).unwrap()
}

/// Sends `what` and returns the reply.
fn ask(l: &mut CellLoop, what: Request, now: Instant) -> Reply {
    let mut got = None;
    l.handle(Inbound::Request { token: 7, what }, now, &mut |r| {
        got = Some(r)
    });
    got.expect("every request is answered")
}

fn refused(r: &Reply) -> Option<Refusal> {
    match r {
        Reply::Done {
            token: 7, result, ..
        } => result.err(),
        Reply::Done { .. } => panic!("wrong token"),
        Reply::Round { .. } => None,
    }
}

/// Runs a started round to its end with every robot reporting every tick (virtual time);
/// returns the ticks and the ticks with two robots low-confidence.
fn run_round(l: &mut CellLoop, t0: Instant, tick: Duration) -> (u64, u64) {
    let n = l.controller().n_robots();
    let (mut ticks, mut overlaps) = (0, 0);
    let mut now = t0;
    loop {
        now += tick;
        for k in 0..n {
            l.handle(
                Inbound::Progress {
                    robot: k,
                    ref_time: 0.0,
                },
                now,
                &mut |_| {},
            );
        }
        let s = l.step(now).unwrap();
        ticks += 1;
        overlaps += u64::from(s.overlap);
        assert!(s.fault.is_none(), "{:?}", s.fault);
        assert!(s.needs_operator.count() <= 1);
        if s.finished {
            assert!(!s.active);
            return (ticks, overlaps);
        }
        assert!(ticks < 100_000, "the round never ended");
    }
}

#[test]
fn a_round_runs_and_its_record_lands_in_the_planner() {
    for n in [2, 3] {
        let mut planner = support::planner(n);
        let mut l = cell_loop(&planner, Cell::Rounds);
        let tick = Duration::from_secs_f64(l.controller().tick_s());
        let t0 = Instant::now();
        assert_eq!(
            refused(&ask(&mut l, Request::TakeRound, t0)),
            Some(Refusal::NoFinishedRound)
        );
        assert_eq!(
            refused(&ask(&mut l, Request::Stop, t0)),
            Some(Refusal::NotRunning)
        );
        assert_eq!(refused(&ask(&mut l, Request::Start, t0)), None);
        assert_eq!(
            refused(&ask(&mut l, Request::Start, t0)),
            Some(Refusal::Running)
        );
        let (ticks, overlaps) = run_round(&mut l, t0, tick);
        assert_eq!(overlaps, 0, "N = {n}");
        // The round took the planned length give or take the tick grid: every robot ended.
        let planned = (0..n)
            .map(|i| l.controller().as_rounds().unwrap().planned_end_s(i))
            .fold(0.0, f64::max);
        let took = ticks as f64 * tick.as_secs_f64();
        assert!(
            took >= planned - 1e-9 && took <= planned + 3.0 * tick.as_secs_f64(),
            "{took} vs {planned}"
        );
        let Reply::Round { log, .. } = ask(&mut l, Request::TakeRound, t0) else {
            panic!("a finished round is handed over");
        };
        assert_eq!(log.robots.len(), n);
        for r in &log.robots {
            // One entry per running tick: from 0 up the whole task, never back.
            assert!(r.ref_time.windows(2).all(|w| w[1] >= w[0]));
            assert_eq!(r.ref_time[0], 0.0);
            assert!(
                r.supervised.iter().any(|&s| s),
                "the low-confidence stretch is watched"
            );
            assert!(r.corrected.iter().all(|&c| !c), "nobody corrected");
        }
        // Taken once.
        assert_eq!(
            refused(&ask(&mut l, Request::TakeRound, t0)),
            Some(Refusal::NoFinishedRound)
        );
        let records = log.records(planner.model()).unwrap();
        planner.record_round(&records).unwrap();
        assert_eq!(planner.rounds_recorded(), 1);
        // The same round again is a duplicate: the planner's own check.
        assert!(planner.record_round(&records).is_err());
    }
}

#[test]
fn a_silent_robot_stalls_the_whole_cell_until_cleared() {
    let planner = support::planner(2);
    let mut l = cell_loop(&planner, Cell::Rounds);
    let tick = Duration::from_secs_f64(l.controller().tick_s());
    let t0 = Instant::now();
    ask(&mut l, Request::Start, t0);
    let report = |l: &mut CellLoop, k: usize, now: Instant| {
        l.handle(
            Inbound::Progress {
                robot: k,
                ref_time: 0.0,
            },
            now,
            &mut |_| {},
        );
    };
    let mut now = t0;
    // Five ticks with both reporting.
    for _ in 0..5 {
        now += tick;
        report(&mut l, 0, now);
        report(&mut l, 1, now);
        assert!(l.step(now).unwrap().fault.is_none());
    }
    // Robot 2 falls silent: the fault latches after stall_s (0.25 s), not before.
    let silent_from = now;
    let mut stalled_at = None;
    let mut frozen = None;
    for _ in 0..100 {
        now += tick;
        report(&mut l, 0, now);
        let s = l.step(now).unwrap();
        if let Some(NodeFault::Stalled { robot, silent_s }) = s.fault {
            assert_eq!(robot, 1);
            assert!(
                silent_s > 0.25 && silent_s <= 0.25 + 1.5 * tick.as_secs_f64(),
                "{silent_s}"
            );
            stalled_at.get_or_insert(now);
            // Held: no robot's reference time moves while stalled.
            match frozen {
                None => frozen = Some(s.ref_time),
                Some(f) => assert_eq!(s.ref_time, f),
            }
            assert!(s.speed.iter().all(|&v| v == 0.0));
        }
    }
    let at = stalled_at.expect("a silent robot is a fault");
    let silent = (at - silent_from).as_secs_f64();
    assert!(
        silent > 0.25 && silent < 0.25 + 2.0 * tick.as_secs_f64(),
        "{silent}"
    );
    // Cleared while still silent: a fresh grace, then the fault again.
    assert_eq!(refused(&ask(&mut l, Request::ClearFault, now)), None);
    now += tick;
    report(&mut l, 0, now);
    assert!(l.step(now).unwrap().fault.is_none());
    for _ in 0..40 {
        now += tick;
        report(&mut l, 0, now);
        l.step(now).unwrap();
    }
    assert!(matches!(
        l.fault(),
        Some(NodeFault::Stalled { robot: 1, .. })
    ));
    // Reporting again and cleared: the round runs to its end.
    report(&mut l, 1, now);
    ask(&mut l, Request::ClearFault, now);
    let (_, overlaps) = run_round(&mut l, now, tick);
    assert_eq!(overlaps, 0);
    assert_eq!(
        refused(&ask(&mut l, Request::ClearFault, now)),
        Some(Refusal::NoFault)
    );
}

#[test]
fn stop_aborts_the_round_and_a_continuous_cell_records_none() {
    let planner = support::planner(2);
    let mut l = cell_loop(&planner, Cell::Rounds);
    let tick = Duration::from_secs_f64(l.controller().tick_s());
    let mut now = Instant::now();
    ask(&mut l, Request::Start, now);
    for _ in 0..20 {
        now += tick;
        l.handle(
            Inbound::Progress {
                robot: 0,
                ref_time: 0.0,
            },
            now,
            &mut |_| {},
        );
        l.handle(
            Inbound::Progress {
                robot: 1,
                ref_time: 0.0,
            },
            now,
            &mut |_| {},
        );
        l.step(now).unwrap();
    }
    assert!(l.controller().ref_time_now()[0] > 0.0);
    assert_eq!(refused(&ask(&mut l, Request::Stop, now)), None);
    assert_eq!(l.controller().ref_time_now()[0], 0.0);
    assert_eq!(
        refused(&ask(&mut l, Request::TakeRound, now)),
        Some(Refusal::NoFinishedRound)
    );

    let mut c = cell_loop(&planner, Cell::Continuous);
    assert_eq!(
        refused(&ask(&mut c, Request::TakeRound, now)),
        Some(Refusal::Continuous)
    );
}

#[test]
fn the_operator_axis_maps_to_the_coordinator_input() {
    let db = LoopParams::default().deadband;
    assert_eq!(operator_input(0.0, db), Operator::Scheduled);
    assert_eq!(operator_input(0.04, db), Operator::Scheduled);
    assert_eq!(operator_input(f64::NAN, db), Operator::Scheduled);
    assert_eq!(operator_input(1.0, db), Operator::Fastest);
    assert_eq!(operator_input(0.96, db), Operator::Fastest);
    assert_eq!(operator_input(-1.0, db), Operator::Slowest);
    // Half throw forward: 2^(−½) execution samples per reference sample.
    for (axis, want) in [
        (0.5, std::f64::consts::FRAC_1_SQRT_2),
        (-0.5, std::f64::consts::SQRT_2),
    ] {
        let Operator::Gradient(g) = operator_input(axis, db) else {
            panic!("a gradient");
        };
        assert!((g - want).abs() < 1e-15, "{g} vs {want}");
    }
}

#[test]
fn an_empty_log_is_an_error_not_a_panic() {
    let planner = support::planner(2);
    let log = RoundLog {
        tick_s: 0.01,
        robots: vec![Default::default(); 2],
    };
    let mut p = planner;
    let err = log.records(p.model()).and_then(|r| Ok(p.record_round(&r)?));
    assert!(err.is_err());
}

/// Robot speeds in the ticks each robot was supervised, and the round's log, for a round run
/// with the operator's axis `axis` (button held) on every tick, or no input at all.
fn supervised_speeds(axis: Option<f64>) -> (Vec<f64>, RoundLog) {
    let planner = support::planner(2);
    let mut l = cell_loop(&planner, Cell::Rounds);
    let tick = Duration::from_secs_f64(l.controller().tick_s());
    let mut now = Instant::now();
    ask(&mut l, Request::Start, now);
    let mut speeds = Vec::new();
    let mut needs = l.controller().low_conf_now();
    for _ in 0..10_000 {
        now += tick;
        for k in 0..2 {
            l.handle(
                Inbound::Progress {
                    robot: k,
                    ref_time: 0.0,
                },
                now,
                &mut |_| {},
            );
        }
        if let Some(axis) = axis {
            l.handle(
                Inbound::Operator {
                    axis,
                    correcting: true,
                },
                now,
                &mut |_| {},
            );
        }
        let s = l.step(now).unwrap();
        for k in 0..2 {
            if needs[k] {
                speeds.push(s.speed[k]);
            }
        }
        needs = s.needs_operator;
        if s.finished {
            let Reply::Round { log, .. } = ask(&mut l, Request::TakeRound, now) else {
                panic!("a finished round is handed over");
            };
            return (speeds, log);
        }
    }
    panic!("the round never ended");
}

#[test]
fn the_operators_input_sets_the_supervised_robots_speed_and_is_recorded() {
    // The test task's low-confidence stretch allows 1 to 2 execution samples per reference
    // sample: speed scale 1 (fastest) to ½ (slowest) at a tick of one sample period.
    let (scheduled, log) = supervised_speeds(None);
    assert!(!scheduled.is_empty());
    assert!(log.robots.iter().all(|r| r.corrected.iter().all(|&c| !c)));
    // The share of supervised ticks at speed `v` (a tick that leaves the stretch runs part
    // of it at the scheduled rate).
    let share = |speeds: &[f64], v: f64| {
        speeds.iter().filter(|&&x| (x - v).abs() < 1e-9).count() as f64 / speeds.len() as f64
    };
    let (slowest, log) = supervised_speeds(Some(-1.0));
    assert!(share(&slowest, 0.5) >= 0.9, "{slowest:?}");
    assert!(
        share(&scheduled, 0.5) < 0.5,
        "the schedule alone is not already the slowest: {scheduled:?}"
    );
    // Corrected exactly where supervised.
    for r in &log.robots {
        assert_eq!(r.corrected, r.supervised);
    }
    let (fastest, _) = supervised_speeds(Some(1.0));
    assert!(
        fastest.iter().all(|&v| (v - 1.0).abs() < 1e-9),
        "{fastest:?}"
    );
}

/// The liveness check is one comparison against the earliest instant a robot can be stalled
/// at; it must decide exactly as a check of every robot each tick: not stalled at a silence of
/// exactly `stall_s`, stalled one nanosecond later, and a progress dated earlier than the last
/// one (a caller's clock) brings the bound forward.
#[test]
fn the_stall_bound_decides_to_the_nanosecond() {
    let planner = support::planner(2);
    let stall = Duration::from_millis(250);
    let start = |l: &mut CellLoop, t: Instant| {
        assert_eq!(refused(&ask(l, Request::Start, t)), None);
    };
    let t0 = Instant::now();
    // Robot 1 reports at t0 + 0.1 s, robot 2 not since the start (t0).
    let mut l = cell_loop(&planner, Cell::Rounds);
    start(&mut l, t0);
    l.heard(0, t0 + Duration::from_millis(100));
    assert!(
        l.step(t0 + Duration::from_millis(100))
            .unwrap()
            .fault
            .is_none()
    );
    assert!(
        l.step(t0 + stall).unwrap().fault.is_none(),
        "silent exactly stall_s"
    );
    let late = t0 + stall + Duration::from_nanos(1);
    match l.step(late).unwrap().fault {
        Some(NodeFault::Stalled { robot, silent_s }) => {
            assert_eq!(robot, 1);
            assert_eq!(silent_s, 0.250_000_001);
        }
        other => panic!("robot 2 silent for 0.25 s + 1 ns is stalled, got {other:?}"),
    }
    // A bound computed at t0 + 0.2 s (both heard then: due at t0 + 0.45 s), then robot 2's
    // progress dated t0 + 0.1 s: due at t0 + 0.35 s, so stalled at t0 + 0.4 s.
    let mut l = cell_loop(&planner, Cell::Rounds);
    start(&mut l, t0);
    let t2 = t0 + Duration::from_millis(200);
    l.heard(0, t2);
    l.heard(1, t2);
    assert!(l.step(t2).unwrap().fault.is_none());
    l.heard(1, t0 + Duration::from_millis(100));
    l.heard(0, t0 + Duration::from_millis(400));
    match l.step(t0 + Duration::from_millis(400)).unwrap().fault {
        Some(NodeFault::Stalled { robot, silent_s }) => {
            assert_eq!(robot, 1);
            assert!((silent_s - 0.3).abs() < 1e-12, "{silent_s}");
        }
        other => panic!("robot 2 silent for 0.3 s is stalled, got {other:?}"),
    }
}

/// The messages of tick `i` of [`the_tick_thread_sends_what_advance_returns`]'s sequence.
fn scripted(i: u64, finished_at: Option<u64>) -> Vec<Inbound> {
    let mut m = Vec::new();
    let request = |what| Inbound::Request { token: 7, what };
    match i {
        0 => m.push(request(Request::Start)),
        // The operator slows the supervised robot, then a gradient, then lets go.
        20..=30 => m.push(Inbound::Operator {
            axis: -1.0,
            correcting: true,
        }),
        100 => m.push(Inbound::Operator {
            axis: 0.5,
            correcting: false,
        }),
        // Robot 2 is silent from tick 40 (below): stalled after 0.25 s; cleared at tick 75.
        75 => m.push(request(Request::ClearFault)),
        _ => {}
    }
    if let Some(f) = finished_at {
        if i == f + 5 {
            m.push(request(Request::TakeRound));
        } else if i == f + 6 {
            m.push(request(Request::Start));
        } else if i == f + 36 {
            m.push(request(Request::Stop));
        }
    }
    m
}

/// The node's tick thread (`TickEnd::tick`: the progress counters, the loop's tick, the
/// command into the ring, the snapshot into the slot) sends exactly the commands that
/// `CellLoop::advance` returns for the same sequence of ticks and messages — a round with an
/// operator's corrections, a stall and its clearance, the round's end, its hand-over, a second
/// round stopped — and a snapshot equal to `CellLoop::snapshot` whenever the fault, the
/// round's end or the running state changed or the DDS side asked (every 10th tick).
#[test]
fn the_tick_thread_sends_what_advance_returns() {
    use tandem_ros2::link::{Links, TickEnd};
    let planner = support::planner(3);
    let mut a = cell_loop(&planner, Cell::Rounds);
    let mut b = cell_loop(&planner, Cell::Rounds);
    let tick = Duration::from_secs_f64(a.controller().tick_s());
    let links = Links::new(3, 64);
    let mut end = TickEnd::new(3);
    let t0 = Instant::now();
    let (mut finished_at, mut last_flags) = (None, None);
    let (mut faults, mut corrected, mut needs, mut snaps) = (0, 0, 0, 0);
    let (mut log_a, mut log_b) = (None, None);
    for i in 0..2_000_u64 {
        let now = t0 + tick * (i as u32);
        for k in 0..3 {
            if !((40..75).contains(&i) && k == 1) {
                a.heard(k, now);
                links.heard.hear(k);
            }
        }
        for m in scripted(i, finished_at) {
            a.handle(m, now, &mut |r| {
                if let Reply::Round { log, .. } = r {
                    log_a = Some(log);
                }
            });
        }
        let msgs = scripted(i, finished_at);
        if !msgs.is_empty() {
            links.pending.sent();
        }
        if i % 10 == 0 {
            links.state.ask();
        }
        let want = a.advance(now).unwrap();
        let wake = end
            .tick(&mut b, &links, now, now + tick, |l| {
                for m in msgs {
                    l.handle(m, now, &mut |r| {
                        if let Reply::Round { log, .. } = r {
                            log_b = Some(log);
                        }
                    });
                }
            })
            .unwrap();
        assert!(!wake, "tick {i}: a drained ring asks for no wake");
        let (got, at) = links.commands.pop().expect("one command per tick");
        assert_eq!(got, want, "tick {i}");
        assert_eq!(at, now);
        assert_eq!(links.commands.next_deadline(), Some(now + tick));
        assert!(links.commands.pop().is_none());
        let flags = (want.active, want.finished, want.fault);
        let snap = links.state.take();
        if last_flags != Some(flags) || i % 10 == 0 {
            assert_eq!(snap, Some(a.snapshot()), "tick {i}: a snapshot is due");
            snaps += 1;
        } else {
            assert_eq!(snap, None, "tick {i}: no snapshot is due");
        }
        last_flags = Some(flags);
        faults += u64::from(want.fault);
        needs += u64::from(want.needs_operator.count() > 0);
        corrected += u64::from(want.speed.iter().any(|&v| (v - 0.5).abs() < 1e-9));
        if want.finished && finished_at.is_none() {
            finished_at = Some(i);
        }
        if finished_at.is_some_and(|f| i > f + 40) {
            break;
        }
    }
    let f = finished_at.expect("the round finished");
    assert!(
        faults > 0 && corrected > 0 && needs > 0,
        "{faults} {corrected} {needs}"
    );
    assert!(snaps > f / 10, "{snaps} snapshots in {f} ticks");
    assert!(
        log_a.is_some() && log_a == log_b,
        "the round's log handed over alike"
    );
}

/// The tick thread's counters from the instants it is given: ticks counted, the longest time
/// between two tick starts and the longest tick's work, in ns; nothing before the first tick.
#[test]
fn the_tick_threads_counters_take_the_longest_period_and_work() {
    use std::sync::atomic::Ordering;
    use tandem_ros2::link::{Links, TickEnd};
    let planner = support::planner(2);
    let mut l = cell_loop(&planner, Cell::Rounds);
    let links = Links::new(2, 16);
    let mut end = TickEnd::new(2);
    let t0 = Instant::now();
    end.account(&links, t0);
    assert_eq!(links.ticks.load(Ordering::Relaxed), 0);
    let us = |u: u64| Duration::from_micros(u);
    // Starts at 0, 1 ms, 4 ms, 5 ms; work 200, 700, 100, 300 µs.
    for (start, work) in [(0, 200), (1_000, 700), (4_000, 100), (5_000, 300)] {
        let now = t0 + us(start);
        end.tick(&mut l, &links, now, now + us(1_000), |_| {})
            .unwrap();
        end.account(&links, now + us(work));
        while links.commands.pop().is_some() {}
    }
    assert_eq!(links.ticks.load(Ordering::Relaxed), 4);
    assert_eq!(links.max_period_ns.load(Ordering::Relaxed), 3_000_000);
    assert_eq!(links.max_tick_ns.load(Ordering::Relaxed), 700_000);
}
