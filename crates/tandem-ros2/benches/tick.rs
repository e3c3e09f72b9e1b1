//! The tick's own cost with the node's queues attached against without, in the same run
//! (issue 43: at most 1.1×), on a three-robot rounds controller of the test task:
//! - `bare`: the controller's tick alone; `bare_clocked`: the same plus one clock read.
//! - `loop_only`: the node's loop without the links, what a user's own live loop on `CellLoop`
//!   runs: the clock read, the three robots heard (`CellLoop::heard`) and `CellLoop::advance`.
//!   `loop_paced`: the same plus the clock read a live loop paces its sleep by.
//! - `tick_thread_only`: **the "with the queues attached"**, the node's tick thread's
//!   own work per tick as `Ticker::run` of node.rs does it but the sleep: the clock read,
//!   `link::TickEnd::tick` (the pending-message counter, the robots' progress counters, the
//!   loop's tick, the command's words into the ring with the next tick's deadline, the state
//!   slot asked every 10th tick), the pacing clock read and `TickEnd::account` (no wake of the
//!   DDS side: the node's tick thread wakes it only when `TickEnd::tick` asks, never here). The DDS side's ends run between timed batches, but for its three
//!   progress counts a tick (a load and a store each), so the robots are heard every tick as
//!   in `loop_only`. The pair is `tick_thread_only` against `loop_paced` (both with
//!   the pacing read), and against `loop_only` (the node's pacing read counted against it).
//! - `with_queues`: `TickEnd::tick` and the DDS side's ends (three progress reports, the
//!   command popped, the snapshot taken) in one loop, without the wake, the pacing read and
//!   the counters: an upper bound of the queues' cost on one core, not the tick thread's
//!   (the DDS side's ends run on another thread in the node).
//!   `with_queues_state_every_tick`: the snapshot every tick (the 10 ms tick's case);
//!   `with_queues_and_console`: plus the console's feed.
//! - `advance_only`: `CellLoop::advance` alone (a fixed instant, no links); `links_only`: the
//!   links' both ends on a fixed command.
//! - `node_threads`: the node's pair of threads: the tick thread's work as `Ticker::run` does
//!   it (`tick_thread_only`'s, each tick announcing a deadline 0.5 ms after its start, the DDS
//!   side woken only when `TickEnd::tick` asks), against a DDS side on a thread of its own
//!   that sleeps by `WriterSchedule::NODE` on the announced deadlines and, at each wake, drains
//!   the ring, takes an asked snapshot and hears the three robots, as the node's DDS thread
//!   does. The ticks run back to back, so each wake drains a few hundred ticks' records (the
//!   node's, at its tick, one); the time is the tick thread's; the wakes it made are printed
//!   (0 expected). `node_threads_woken_each_tick`: the node before it, for the comparison in
//!   one run: the tick thread wakes the DDS side (`Thread::unpark`) after every tick, which
//!   parks 200 µs when idle (a wake of a parked thread is a futex system call).
//!   `node_threads_spinning`: the same with a DDS side that spins instead of parking: the tick
//!   thread against a consumer on the other core at every tick's lines, no futex wake.
//!
//! Run with `cargo bench -p tandem-ros2 --bench tick`.
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
use tandem_ros2::link::{Links, TickEnd, WriterSchedule};
use tandem_ros2::{CellLoop, Command, ConsoleFeed, Inbound, LoopParams, Request};

#[path = "../tests/support/mod.rs"]
mod support;

/// The node's tick thread's side of the links and the DDS side's ends, in one loop.
struct NodeTick {
    l: CellLoop,
    links: Links,
    end: TickEnd,
    ask_every: u64,
    i: u64,
    /// The DDS side's command buffer (`CommandRing::pop_into`).
    popped: Command,
    /// The next tick's deadline, kept as `Ticker::run` keeps it (`next += period`).
    next: Instant,
}

/// The tick period the benches' ticks announce (their ticks run back to back).
const PERIOD: Duration = Duration::from_micros(500);

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
            popped: Command::idle(3),
            next: Instant::now(),
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
        let c = self
            .links
            .commands
            .pop_into(&mut self.popped)
            .map(|at| (self.popped.ref_time[0], at));
        let s = if self.i.is_multiple_of(self.ask_every) {
            self.links.state.take().map(|s| s.ref_time[1])
        } else {
            None
        };
        c.map(|(r, _)| r).or(s)
    }

    /// The tick thread's part of one tick (as `Ticker::run`, without the counters; the ring
    /// drained often enough that it never asks for the writer's wake); returns the tick's
    /// instant.
    fn tick_thread(&mut self, console: Option<&mut ConsoleFeed>) -> Instant {
        let now = Instant::now();
        self.next += PERIOD;
        let wake = self
            .end
            .tick(&mut self.l, &self.links, now, self.next, |_| {
                unreachable!("nothing is queued in this benchmark")
            })
            .expect("a valid operator");
        assert!(!wake, "a drained ring asks for no wake");
        if let Some(feed) = console {
            feed.publish(&self.l);
        }
        if self.l.is_finished() {
            start(&mut self.l);
        }
        now
    }
}

/// How the benches' DDS side waits between its passes.
#[derive(Clone, Copy, PartialEq)]
enum Side {
    /// As the node's DDS thread: sleeps by `WriterSchedule::NODE` on the announced deadlines;
    /// the tick thread wakes it only when `TickEnd::tick` asks.
    Scheduled,
    /// As the node's before: parks 200 µs when idle, woken by the tick thread after each tick.
    WokenEachTick,
    /// Never parks (spins between passes), woken after each tick as `WokenEachTick`: the wake
    /// is always of an awake thread.
    Spinning,
}

/// The node's pair of threads: this (the tick thread's side) and a DDS side on its own thread
/// that, at each pass, drains the ring, takes an asked snapshot and hears the three robots.
struct Threads {
    node: NodeTick,
    links: Arc<Links>,
    writer: std::thread::JoinHandle<u64>,
    stop: Arc<AtomicBool>,
    side: Side,
    /// Wakes of the DDS side by the tick thread.
    wakes: u64,
    ticks: u64,
}

impl Threads {
    fn new(planner: &Planner, side: Side) -> Threads {
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
            let mut popped = Command::idle(3);
            let (schedule, mut late) = (WriterSchedule::NODE, 0);
            while !st.load(Ordering::Relaxed) {
                let mut busy = false;
                while let Some(at) = l.commands.pop_into(&mut popped) {
                    black_box((at, popped.tick));
                    taken += 1;
                    busy = true;
                    late = 0;
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
                    continue;
                }
                match side {
                    Side::Scheduled => {
                        // As `Io::run` of node.rs.
                        let now = Instant::now();
                        let next = l.commands.next_deadline();
                        let sleep = schedule.sleep(now, next, late);
                        if schedule.is_late(now, next) {
                            late += 1;
                        }
                        std::thread::park_timeout(sleep);
                    }
                    Side::WokenEachTick => std::thread::park_timeout(Duration::from_micros(200)),
                    Side::Spinning => std::hint::spin_loop(),
                }
            }
            taken
        });
        Threads {
            node,
            links,
            writer,
            stop,
            side,
            wakes: 0,
            ticks: 0,
        }
    }

    /// One tick of the tick thread against the shared links, and the wake when one is due.
    fn tick(&mut self) -> u64 {
        let n = &mut self.node;
        let l = &*self.links;
        let now = Instant::now();
        n.next += PERIOD;
        let behind = n
            .end
            .tick(&mut n.l, l, now, n.next, |_| {
                unreachable!("nothing is queued in this benchmark")
            })
            .expect("a valid operator");
        if behind || self.side != Side::Scheduled {
            self.writer.thread().unpark();
            self.wakes += 1;
        }
        self.ticks += 1;
        n.end.account(l, Instant::now());
        let finished = n.l.is_finished();
        if finished {
            start(&mut n.l);
        }
        u64::from(finished)
    }

    /// Ends the DDS side; prints the ticks, the wakes the tick thread made and the records the
    /// DDS side took.
    fn finish(self, name: &str) -> u64 {
        self.stop.store(true, Ordering::Relaxed);
        self.writer.thread().unpark();
        let taken = self.writer.join().expect("the writer thread");
        eprintln!(
            "{name}: {} ticks, {} wakes of the DDS side by the tick thread, {taken} records taken",
            self.ticks, self.wakes
        );
        taken
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
    // `loop_only` and the clock read that paces a live loop's sleep (`Ticker::run` reads the
    // clock after its tick for the sleep and `TickEnd::account`): the baseline of
    // `tick_thread_only`, which has that read too.
    let mut node = NodeTick::new(&planner, 10);
    group.bench_function("loop_paced", |b| {
        b.iter(|| {
            let now = Instant::now();
            for k in 0..3 {
                node.l.heard(k, now);
            }
            let c = node.l.advance(now).expect("a valid operator");
            if c.finished {
                start(&mut node.l);
            }
            black_box((c.tick, Instant::now()))
        });
    });
    let mut node = NodeTick::new(&planner, 10);
    group.bench_function("with_queues", |b| {
        b.iter(|| black_box(node.tick(None)));
    });
    // The tick thread's own work, as `Ticker::run` does it each tick but the sleep: the clock
    // read, `TickEnd::tick` (the ring drained often enough that it never asks for the DDS
    // side's wake), the pacing clock read and `TickEnd::account`. The DDS side's ends that
    // the tick thread never runs (the ring drained, the snapshot taken) run between timed
    // batches of 64 ticks (the ring holds 4,096); the one DDS-side write left inside the timing
    // is the three robots' progress counts, one report per robot per tick as `loop_only` hears
    // them (`Heard::hear`: a load and a store each), so that the tick stores the three robots'
    // instants every tick as `loop_only` does. Its like-for-like baseline is `loop_paced`.
    let mut node = NodeTick::new(&planner, 10);
    group.bench_function("tick_thread_only", |b| {
        b.iter_custom(|iters| {
            let mut spent = Duration::ZERO;
            let mut left = iters;
            while left > 0 {
                let batch = left.min(64);
                let t0 = Instant::now();
                for _ in 0..batch {
                    for k in 0..3 {
                        node.links.heard.hear(k);
                    }
                    node.i += 1;
                    if node.i.is_multiple_of(node.ask_every) {
                        node.links.state.ask();
                    }
                    black_box(node.tick_thread(None));
                    node.end.account(&node.links, Instant::now());
                }
                spent += t0.elapsed();
                while let Some(c) = node.links.commands.pop_into(&mut node.popped) {
                    black_box((c, node.popped.tick));
                }
                black_box(node.links.state.take());
                left -= batch;
            }
            spent
        });
    });
    // The node's two threads, the DDS side sleeping by the announced deadlines.
    let mut threads = Threads::new(&planner, Side::Scheduled);
    group.bench_function("node_threads", |b| {
        b.iter(|| black_box(threads.tick()));
    });
    black_box(threads.finish("node_threads"));
    // The node before: the DDS side woken after every tick, parking when idle.
    let mut threads = Threads::new(&planner, Side::WokenEachTick);
    group.bench_function("node_threads_woken_each_tick", |b| {
        b.iter(|| black_box(threads.tick()));
    });
    black_box(threads.finish("node_threads_woken_each_tick"));
    // The same with a DDS side that spins instead of parking (it takes a core while it runs):
    // the tick thread's work against a consumer on another core, the wake always of an awake
    // thread.
    let mut threads = Threads::new(&planner, Side::Spinning);
    group.bench_function("node_threads_spinning", |b| {
        b.iter(|| black_box(threads.tick()));
    });
    black_box(threads.finish("node_threads_spinning"));
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
