//! The tick's own cost with the node's queues attached against without, in the same run
//! (issue 43: at most 1.1×): `bare` ticks a three-robot rounds controller of the test task;
//! `loop_only` is the node's loop without the links, what a user's own live loop on `CellLoop`
//! runs: the clock read, the three robots heard (`CellLoop::heard`) and `CellLoop::advance`;
//! `with_queues` is the node's tick thread on the same controller without the network
//! (`link::TickEnd::tick`, which `Ticker::run` of node.rs runs): the clock read, the
//! pending-message counter (nothing queued), the robots' progress counters (each robot reported
//! since the last tick), the loop's tick (`CellLoop::advance`'s: liveness, the round's log, the
//! controller's tick), the command's words written from the loop into the ring (no `Command`
//! built) and the state slot's `want` flag, answered with a snapshot every 10th
//! tick (the 100 Hz state topics at a 1 kHz tick; `with_queues_state_every_tick`: every tick,
//! the 10 ms tick's case). The queues' cost is `with_queues` − `loop_only`.
//! The DDS side's ends (three progress reports, the command popped, the snapshot taken) run
//! in the same loop here and are counted. `advance_only` is `CellLoop::advance` alone (a fixed
//! instant, no links): the loop's own share of the difference. `tick_thread_only` is
//! `with_queues` with the DDS side's ends run between timed batches of 64 ticks (in the node they
//! run on the DDS thread): the tick thread's own share. `node_threads` is the node's pair of
//! threads: the tick thread's work as in `with_queues` plus the wake of the DDS side
//! (`Thread::unpark`), which runs on a thread of its own that parks when idle, drains the ring
//! and hears the three robots after each wake, as the node's DDS thread does; the time is the
//! tick thread's. Run with `cargo bench -p tandem-ros2 --bench tick`.
#![expect(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

use std::hint::black_box;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use tandem_console::{Console, ConsoleConfig, Geometry};
use tandem_planner::{Cell, Planner};
use tandem_realtime::{Controller, Operator};
use tandem_ros2::link::{Links, TickEnd};
use tandem_ros2::{CellLoop, ConsoleFeed, Inbound, LoopParams, Request};

#[path = "../tests/support/mod.rs"]
mod support;

/// The node's tick thread's side of the links and the DDS side's ends, in one loop.
struct NodeTick {
    l: CellLoop,
    links: Links,
    end: TickEnd,
    ask_every: u64,
    i: u64,
}

fn start(l: &mut CellLoop) {
    l.handle(
        Inbound::Request {
            token: 0,
            what: Request::Start,
        },
        Instant::now(),
        &mut |_| {},
    );
}

impl NodeTick {
    fn new(planner: &Planner, ask_every: u64) -> NodeTick {
        let ctl = planner.controller(Cell::Rounds).expect("a plan");
        let mut l = CellLoop::new(ctl, planner.model(), LoopParams::default()).expect("valid");
        start(&mut l);
        NodeTick {
            l,
            links: Links::new(3, 4096),
            end: TickEnd::new(3),
            ask_every,
            i: 0,
        }
    }

    /// One tick of the tick thread (`console` after the step when given) and the DDS side's
    /// work for it.
    fn tick(&mut self, console: Option<&mut ConsoleFeed>) -> Option<f64> {
        // The DDS side: three progress reports; the state topics' request at their rate.
        for k in 0..3 {
            self.links.heard.hear(k);
        }
        self.i += 1;
        if self.i.is_multiple_of(self.ask_every) {
            self.links.state.ask();
        }
        let now = self.tick_thread(console);
        // The DDS side takes the command and the snapshot.
        black_box(now);
        let c = self.links.commands.pop().map(|(c, at)| (c.ref_time[0], at));
        let s = if self.i.is_multiple_of(self.ask_every) {
            self.links.state.take().map(|s| s.ref_time[1])
        } else {
            None
        };
        c.map(|(r, _)| r).or(s)
    }

    /// The tick thread's part of one tick (as `Ticker::run`, without the writer's wake and the
    /// counters); returns the tick's instant.
    fn tick_thread(&mut self, console: Option<&mut ConsoleFeed>) -> Instant {
        let now = Instant::now();
        self.end
            .tick(&mut self.l, &self.links, now, |_| {
                unreachable!("nothing is queued in this benchmark")
            })
            .expect("a valid operator");
        if let Some(feed) = console {
            feed.publish(&self.l);
        }
        if self.l.is_finished() {
            start(&mut self.l);
        }
        now
    }
}

/// The node's pair of threads: this (the tick thread's side) and a DDS side on its own thread
/// that parks when idle and, after each wake, drains the ring, takes an asked snapshot and hears
/// the three robots.
struct Threads {
    node: NodeTick,
    links: Arc<Links>,
    writer: std::thread::JoinHandle<u64>,
    stop: Arc<AtomicBool>,
}

impl Threads {
    fn new(planner: &Planner) -> Threads {
        let mut node = NodeTick::new(planner, 10);
        // The DDS side's thread may be starved for longer than the default 0.25 s on a loaded
        // machine: a latched stall would hold the loop and time a tick that does not tick.
        let params = LoopParams {
            stall_s: 3600.0,
            ..LoopParams::default()
        };
        let ctl = planner.controller(Cell::Rounds).expect("a plan");
        node.l = CellLoop::new(ctl, planner.model(), params).expect("valid");
        start(&mut node.l);
        let links = Arc::new(Links::new(3, 4096));
        let stop = Arc::new(AtomicBool::new(false));
        let (l, st) = (links.clone(), stop.clone());
        let writer = std::thread::spawn(move || {
            let mut taken = 0_u64;
            let mut asked = Instant::now();
            while !st.load(Ordering::Relaxed) {
                let mut busy = false;
                while let Some((c, _)) = l.commands.pop() {
                    black_box(c);
                    taken += 1;
                    busy = true;
                }
                if asked.elapsed() >= Duration::from_millis(1) {
                    l.state.ask();
                    asked = Instant::now();
                }
                if l.state.take().is_some() {
                    busy = true;
                }
                if busy {
                    for k in 0..3 {
                        l.heard.hear(k);
                    }
                } else {
                    std::thread::park_timeout(Duration::from_micros(200));
                }
            }
            taken
        });
        Threads {
            node,
            links,
            writer,
            stop,
        }
    }

    /// One tick of the tick thread against the shared links, and the wake.
    fn tick(&mut self) -> u64 {
        let n = &mut self.node;
        let l = &*self.links;
        let now = Instant::now();
        n.end
            .tick(&mut n.l, l, now, |_| {
                unreachable!("nothing is queued in this benchmark")
            })
            .expect("a valid operator");
        self.writer.thread().unpark();
        n.end.account(l, Instant::now());
        let finished = n.l.is_finished();
        if finished {
            start(&mut n.l);
        }
        u64::from(finished)
    }

    fn finish(self) -> u64 {
        self.stop.store(true, Ordering::Relaxed);
        self.writer.thread().unpark();
        self.writer.join().expect("the writer thread")
    }
}

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
    // A bare tick paced by a clock, as any live loop is (the node's tick thread reads the clock
    // once a tick for its period and uses that reading for liveness too): the baseline that
    // isolates what the node adds.
    let mut paced = planner.controller(Cell::Rounds).expect("a plan");
    group.bench_function("bare_clocked", |b| {
        b.iter(|| {
            black_box(Instant::now());
            if paced.is_finished() {
                paced.reset();
            }
            black_box(paced.tick(Operator::Scheduled).expect("a valid operator"))
        });
    });
    // The links alone, both ends, on a fixed command (no tick, no clock): three progress
    // counters heard and compared, the ring's push and pop, the slot asked every 10th tick,
    // written and taken.
    let mut node = NodeTick::new(&planner, 10);
    let now_fixed = Instant::now();
    let fixed = node.l.advance(now_fixed).expect("a valid operator");
    let snap = node.l.snapshot();
    let mut seen = [0; tandem_realtime::MAX_ROBOTS];
    group.bench_function("links_only", |b| {
        b.iter(|| {
            let links = &node.links;
            for k in 0..3 {
                links.heard.hear(k);
            }
            node.i += 1;
            if node.i.is_multiple_of(10) {
                links.state.ask();
            }
            let heard = links.heard.changed(3, &mut seen);
            links.commands.push(black_box(&fixed), now_fixed);
            if links.state.wanted() {
                links.state.put(snap);
            }
            let c = links.commands.pop().map(|(c, _)| c.ref_time[0]);
            let s = if node.i.is_multiple_of(10) {
                links.state.take().map(|s| s.ref_time[1])
            } else {
                None
            };
            black_box((heard, c, s))
        });
    });
    // The loop's own work without the links or the clock (`CellLoop::advance` at a fixed
    // instant, the robots heard): what the node's tick adds to a bare one before any queue.
    let mut node = NodeTick::new(&planner, 10);
    let now = Instant::now();
    group.bench_function("advance_only", |b| {
        b.iter(|| {
            for k in 0..3 {
                node.l.heard(k, now);
            }
            let c = node.l.advance(now).expect("a valid operator");
            if c.finished {
                start(&mut node.l);
            }
            black_box(c.tick)
        });
    });
    // The node's loop without the links, as a user's own live loop runs it: the clock read,
    // the robots heard, `advance`. `with_queues` − this is what the queues cost.
    let mut node = NodeTick::new(&planner, 10);
    group.bench_function("loop_only", |b| {
        b.iter(|| {
            let now = Instant::now();
            for k in 0..3 {
                node.l.heard(k, now);
            }
            let c = node.l.advance(now).expect("a valid operator");
            if c.finished {
                start(&mut node.l);
            }
            black_box(c.tick)
        });
    });
    let mut node = NodeTick::new(&planner, 10);
    group.bench_function("with_queues", |b| {
        b.iter(|| black_box(node.tick(None)));
    });
    // The tick thread's share alone: the DDS side's ends between timed batches of 64 ticks (the
    // ring holds 4,096); the robots are heard once a batch (the tick's store of their instants,
    // three words, runs once a batch instead of every tick).
    let mut node = NodeTick::new(&planner, 10);
    group.bench_function("tick_thread_only", |b| {
        b.iter_custom(|iters| {
            let mut spent = Duration::ZERO;
            let mut left = iters;
            while left > 0 {
                let batch = left.min(64);
                for k in 0..3 {
                    node.links.heard.hear(k);
                }
                let t0 = Instant::now();
                for _ in 0..batch {
                    node.i += 1;
                    if node.i.is_multiple_of(node.ask_every) {
                        node.links.state.ask();
                    }
                    black_box(node.tick_thread(None));
                }
                spent += t0.elapsed();
                while let Some(c) = node.links.commands.pop() {
                    black_box(c);
                }
                black_box(node.links.state.take());
                left -= batch;
            }
            spent
        });
    });
    // The node's two threads, the DDS side woken each tick.
    let mut threads = Threads::new(&planner);
    group.bench_function("node_threads", |b| {
        b.iter(|| black_box(threads.tick()));
    });
    black_box(threads.finish());
    let mut node = NodeTick::new(&planner, 1);
    group.bench_function("with_queues_state_every_tick", |b| {
        b.iter(|| black_box(node.tick(None)));
    });
    // The same with the node's console attached (`tandem node --console`): the feed after each
    // step, a server running (no page open: the server asks for a snapshot at its rate anyway).
    let ctl = planner.controller(Cell::Rounds).expect("a plan");
    let (console, handle) =
        Console::start(&ConsoleConfig::default(), Geometry::new(&ctl)).expect("a free port");
    let mut feed = ConsoleFeed::new(handle);
    let mut node = NodeTick::new(&planner, 10);
    group.bench_function("with_queues_and_console", |b| {
        b.iter(|| black_box(node.tick(Some(&mut feed))));
    });
    group.finish();
    console.stop();
}

criterion_group!(benches, bench);
criterion_main!(benches);
