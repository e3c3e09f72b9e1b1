//! The tick's own cost with the node's queues attached against without, in the same run
//! (issue 43: at most 1.1×): `bare` ticks a three-robot rounds controller of the test task;
//! `with_queues` is the node's tick thread on the same controller without the network — the
//! robots' progress taken from a bounded queue (`try_recv`), `CellLoop::step` (liveness, the
//! round's log, the tick) and the snapshot handed to the DDS side's queue (`try_send`); the
//! DDS side's two ends (three progress messages in, the snapshot out) run in the same loop
//! here and are counted. Run with `cargo bench -p tandem-ros2 --bench tick`.
#![expect(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

use std::hint::black_box;
use std::sync::mpsc::sync_channel;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use tandem_console::{Console, ConsoleConfig, Geometry};
use tandem_planner::Cell;
use tandem_realtime::{Controller, Operator};
use tandem_ros2::{CellLoop, ConsoleFeed, Inbound, LoopParams, Request, Snapshot};

#[path = "../tests/support/mod.rs"]
mod support;

fn bench(c: &mut Criterion) {
    let planner = support::planner(3);
    let mut group = c.benchmark_group("tick");
    let mut bare = planner.controller(Cell::Rounds).expect("a plan");
    group.bench_function("bare", |b| {
        b.iter(|| {
            if bare.is_finished() {
                bare.reset();
            }
            black_box(bare.tick(Operator::Scheduled).expect("a valid operator"))
        });
    });
    let ctl = planner.controller(Cell::Rounds).expect("a plan");
    let mut l = CellLoop::new(ctl, planner.model(), LoopParams::default()).expect("valid");
    let (in_tx, in_rx) = sync_channel::<Inbound>(4096);
    let (state_tx, state_rx) = sync_channel::<Snapshot>(4096);
    let start = |l: &mut CellLoop| {
        l.handle(
            Inbound::Request {
                token: 0,
                what: Request::Start,
            },
            Instant::now(),
            &mut |_| {},
        );
    };
    start(&mut l);
    group.bench_function("with_queues", |b| {
        b.iter(|| {
            for k in 0..3 {
                let _ = in_tx.try_send(Inbound::Progress {
                    robot: k,
                    ref_time: 0.0,
                });
            }
            let now = Instant::now();
            while let Ok(m) = in_rx.try_recv() {
                l.handle(m, now, &mut |_| {});
            }
            let s = l.step(now).expect("a valid operator");
            let _ = state_tx.try_send(s);
            if s.finished {
                start(&mut l);
            }
            black_box(state_rx.try_recv().ok())
        });
    });
    // The same with the node's console attached (`tandem node --console`): the feed after each
    // step, a server running (no page open: the server asks for a snapshot at its rate anyway).
    let ctl = planner.controller(Cell::Rounds).expect("a plan");
    let (console, handle) =
        Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).expect("a free port");
    let mut feed = ConsoleFeed::new(handle);
    let mut l = CellLoop::new(ctl, planner.model(), LoopParams::default()).expect("valid");
    start(&mut l);
    group.bench_function("with_queues_and_console", |b| {
        b.iter(|| {
            for k in 0..3 {
                let _ = in_tx.try_send(Inbound::Progress {
                    robot: k,
                    ref_time: 0.0,
                });
            }
            let now = Instant::now();
            while let Ok(m) = in_rx.try_recv() {
                l.handle(m, now, &mut |_| {});
            }
            let s = l.step(now).expect("a valid operator");
            feed.publish(&l, &s);
            let _ = state_tx.try_send(s);
            if s.finished {
                start(&mut l);
            }
            black_box(state_rx.try_recv().ok())
        });
    });
    group.finish();
    console.stop();
}

criterion_group!(benches, bench);
criterion_main!(benches);
