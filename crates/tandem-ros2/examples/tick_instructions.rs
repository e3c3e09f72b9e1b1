//! Runs N ticks of each variant of the node's tick in a function of its own, so that
//! `valgrind --tool=callgrind` counts the instructions of each (inclusive cost of `run_*`
//! divided by N): repeatable on a loaded machine, where criterion's times are not (issue 43,
//! "the tick's cost with the node's queues attached against without").
//!
//! ```text
//! cargo build --release -p tandem-ros2 --example tick_instructions
//! valgrind --tool=callgrind --callgrind-out-file=/tmp/tick.cg \
//!     target/release/examples/tick_instructions 20000
//! callgrind_annotate --inclusive=yes /tmp/tick.cg | grep run_
//! ```
//!
//! The variants, on a three-robot rounds controller of the test task (a round restarted when it
//! finishes, every variant alike):
//! - `run_bare`: the controller's tick alone (`Controller::tick`, the scheduled operator);
//! - `run_bare_clocked`: the same plus one clock read (any live loop reads the clock);
//! - `run_loop`: the node's loop without the links: the clock read, the three robots heard
//!   (`CellLoop::heard`) and `CellLoop::advance` — what a user's own live loop on `CellLoop`
//!   runs;
//! - `run_loop_paced`: the same plus the clock read a live loop paces its sleep by (the
//!   tick thread's second clock read, below);
//! - `run_tick_thread`: the node's tick thread as `Ticker::run` runs it (`link::TickEnd::tick`:
//!   the pending-message counter, the progress counters, the loop's tick (`advance` without
//!   building its `Command`), the command's words into the ring, the state slot asked every 10th
//!   tick, with the next tick's deadline), plus its per-tick bookkeeping (`TickEnd::account`);
//!   the writer is woken only when `TickEnd::tick` asks (never here: the DDS side drains each
//!   tick);
//! - `run_dds_side`: the DDS thread's ends for those ticks (three progress counters, the ring
//!   drained into one reused command, the slot asked and taken), for reference: in the node
//!   they run on another thread.
//!
//! Under valgrind the clock read is a system call (no vDSO), whose kernel side is not counted.

use std::hint::black_box;
use std::time::Instant;

use tandem_planner::{AnyController, Cell};
use tandem_realtime::{Controller, Operator};
use tandem_ros2::link::{Links, TickEnd};
use tandem_ros2::{CellLoop, Command, Inbound, LoopParams, Request};

/// The tick period `run_tick_thread` announces (its ticks run back to back).
const PERIOD: std::time::Duration = std::time::Duration::from_micros(500);

#[path = "../tests/support/mod.rs"]
mod support;

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

fn cell_loop(ctl: AnyController, planner: &tandem_planner::Planner) -> CellLoop {
    // A stall bound no run reaches (valgrind runs ~50× slower than native).
    let params = LoopParams {
        stall_s: 3600.0,
        ..LoopParams::default()
    };
    let mut l = CellLoop::new(ctl, planner.model(), params).expect("valid");
    start(&mut l);
    l
}

#[inline(never)]
fn run_bare(ctl: &mut AnyController, ticks: u64) {
    for _ in 0..ticks {
        if ctl.is_finished() {
            ctl.reset();
        }
        black_box(ctl.tick(Operator::Scheduled).expect("a valid operator"));
    }
}

#[inline(never)]
fn run_bare_clocked(ctl: &mut AnyController, ticks: u64) {
    for _ in 0..ticks {
        black_box(Instant::now());
        if ctl.is_finished() {
            ctl.reset();
        }
        black_box(ctl.tick(Operator::Scheduled).expect("a valid operator"));
    }
}

#[inline(never)]
fn run_loop(l: &mut CellLoop, ticks: u64) {
    for _ in 0..ticks {
        let now = Instant::now();
        for k in 0..3 {
            l.heard(k, now);
        }
        let c = l.advance(now).expect("a valid operator");
        if c.finished {
            start(l);
        }
        black_box(c.tick);
    }
}

#[inline(never)]
fn run_loop_paced(l: &mut CellLoop, ticks: u64) {
    for _ in 0..ticks {
        let now = Instant::now();
        for k in 0..3 {
            l.heard(k, now);
        }
        let c = l.advance(now).expect("a valid operator");
        if c.finished {
            start(l);
        }
        black_box((c.tick, Instant::now()));
    }
}

#[inline(never)]
fn run_tick_thread(
    l: &mut CellLoop,
    end: &mut TickEnd,
    links: &Links,
    writer: &std::thread::Thread,
    next: &mut Instant,
    i: u64,
) {
    let now = Instant::now();
    *next += PERIOD;
    let wake = end
        .tick(l, links, now, *next, |_| unreachable!("nothing is queued"))
        .expect("a valid operator");
    if wake {
        writer.unpark();
    }
    end.account(links, Instant::now());
    if l.is_finished() {
        start(l);
    }
    black_box(i);
}

#[inline(never)]
fn run_dds_side(links: &Links, popped: &mut Command, i: u64) {
    for k in 0..3 {
        links.heard.hear(k);
    }
    if i.is_multiple_of(10) {
        links.state.ask();
    }
    while let Some(at) = links.commands.pop_into(popped) {
        black_box((at, popped.tick));
    }
    if i.is_multiple_of(10) {
        black_box(links.state.take());
    }
}

fn main() {
    let ticks: u64 = std::env::args()
        .nth(1)
        .map_or(20_000, |a| a.parse().expect("ticks: a whole number"));
    let planner = support::planner(3);
    let ctl = || planner.controller(Cell::Rounds).expect("a plan");
    let mut bare = ctl();
    run_bare(&mut bare, ticks);
    let mut clocked = ctl();
    run_bare_clocked(&mut clocked, ticks);
    let mut l = cell_loop(ctl(), &planner);
    run_loop(&mut l, ticks);
    let mut l = cell_loop(ctl(), &planner);
    run_loop_paced(&mut l, ticks);
    let mut l = cell_loop(ctl(), &planner);
    let links = Links::new(3, 4096);
    let mut end = TickEnd::new(3);
    let writer = std::thread::current();
    let mut popped = Command::idle(3);
    let mut next = Instant::now();
    for i in 1..=ticks {
        run_dds_side(&links, &mut popped, i);
        run_tick_thread(&mut l, &mut end, &links, &writer, &mut next, i);
    }
    use std::io::Write as _;
    let _ = writeln!(std::io::stdout(), "{ticks} ticks of each variant");
}
