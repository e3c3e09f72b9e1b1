//! The run-time tick and the margin checks for a given robot count, as a plain binary whose
//! instruction count callgrind measures exactly (criterion's wall times are noisy on a shared
//! machine): docs/decisions.md, "Up to 16 robots: what limits N (issue 44)".
//!
//! ```text
//! cargo build --release -p tandem-realtime --example tick_cost
//! valgrind --tool=callgrind --callgrind-out-file=/dev/null target/release/examples/tick_cost rounds 8 20000
//! ```
//!
//! - `rounds N TICKS`: `TICKS` ticks of a rounds `Coordinator` of `N` robots on the interleaved
//!   plans of `benches/margins.rs` (reset when finished; inputs cycling through rush, rush,
//!   drag, a gradient and no correction). The cost of one tick is the difference of two
//!   counts over the difference of their `TICKS`.
//! - `cell N TICKS`: the same for a continuous cell of `N` robots (holds every 50 samples, each
//!   group served by the robots in turn).
//! - `rounds|cell N TICKS M`: the same with `M` operators (`with_operators`, `tick_many`;
//!   operator `o` gives the input `o` places further along the cycle). Rounds with `M > 1`
//!   runs the operators' check first (it must accept the interleaved plans).
//! - `lead N`: `sufficient_margins` (the lead bound) on `N` staggered robots (every pair decided
//!   to its end); `lead-interleaved N` on the interleaved ones; `operators N`: the operators'
//!   check (`assign_operators`, `M = ⌈N/4⌉`, no switch time) on the staggered ones; `setup N`
//!   only builds the robots (the count to subtract).
//!
//! Prints what it ran (and the wall time, for orientation only).

#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

use std::time::Instant;

use tandem_realtime::continuous::{ContinuousCoordinator, groups};
use tandem_realtime::holds::usable_holds;
use tandem_realtime::margins::operators::assign_operators;
use tandem_realtime::{
    Controller, Coordinator, Operator, OperatorCount, Timeline, sufficient_margins,
};

/// Control tick (s).
const TICK_S: f64 = 0.005;
/// Reference samples of the plan.
const N_REF: usize = 6000;

/// The two-robot plan of `benches/margins.rs`: 16 evenly spaced low-confidence regions (a
/// sixth of each period), gradients around 1 with bounds [0.6, 1.8] times the mean.
fn base() -> Timeline {
    let period = N_REF / 16;
    let conf: Vec<bool> = (0..N_REF).map(|n| n % period >= period / 6).collect();
    let mean: Vec<f64> = (0..N_REF)
        .map(|n| 1.0 + 0.3 * ((n as f64) * 0.05).sin())
        .collect();
    let lo: Vec<f64> = mean.iter().map(|m| 0.6 * m).collect();
    let hi: Vec<f64> = mean.iter().map(|m| 1.8 * m).collect();
    Timeline::new(&conf, &mean, &lo, &hi, 0.0, 0.01).expect("valid")
}

fn at(r0: &Timeline, start_s: f64) -> Timeline {
    Timeline::new(
        r0.conf(),
        r0.grad_exec(),
        r0.grad_min(),
        r0.grad_max(),
        start_s,
        0.01,
    )
    .expect("valid")
}

/// Robot `i` starts `i/N` of a period after robot 0: the regions interleave.
fn interleaved(n: usize) -> Vec<Timeline> {
    let r0 = base();
    let period = N_REF / 16;
    (0..n)
        .map(|i| at(&r0, r0.sample_clock_s()[(i * period / n) % N_REF]))
        .collect()
}

/// Robot `i` starts half an execution (plus half a period on odd robots) after robot `i − 1`.
fn staggered(n: usize) -> Vec<Timeline> {
    let r0 = base();
    let period_s = r0.sample_clock_s()[N_REF / 16];
    let half = 0.5 * r0.end_s() + 0.5 * period_s;
    (0..n).map(|i| at(&r0, half * i as f64)).collect()
}

fn run_ticks(mut co: impl Controller, ticks: u64) -> u64 {
    let ops = [
        Operator::Fastest,
        Operator::Fastest,
        Operator::Slowest,
        Operator::Gradient(1.1),
        Operator::Scheduled,
    ];
    let m = co.operators();
    let mut inputs = [Operator::Scheduled; tandem_realtime::MAX_ROBOTS];
    let mut low = 0;
    for k in 0..ticks {
        if co.is_finished() {
            co.reset();
        }
        // Operator `o` gives the input `o` places further along the cycle.
        for (o, input) in inputs.iter_mut().enumerate().take(m) {
            *input = ops[(k as usize + o) % ops.len()];
        }
        let t = co
            .tick_many(std::hint::black_box(&inputs[..m]))
            .expect("admissible");
        low += t.low_conf.count() as u64;
        if t.fault.is_some() {
            co.clear_fault();
        }
    }
    low
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let usage = "usage: tick_cost rounds|cell N TICKS [M] | tick_cost setup|lead|lead-interleaved|operators N";
    let mode = args.get(1).expect(usage).as_str();
    let n: usize = args.get(2).and_then(|a| a.parse().ok()).expect(usage);
    let t0 = Instant::now();
    match mode {
        "rounds" | "cell" => {
            let ticks: u64 = args.get(3).and_then(|a| a.parse().ok()).expect(usage);
            let m = args.get(4).map_or(1, |a| a.parse().expect(usage));
            let m = OperatorCount::new(m).expect("1 to MAX_ROBOTS operators");
            let low = if mode == "rounds" {
                let co = Coordinator::new_unchecked(interleaved(n), TICK_S).expect("valid");
                let co = if m.get() > 1 {
                    co.with_operators(m)
                        .expect("the operators' check accepts the plan")
                } else {
                    co
                };
                run_ticks(co, ticks)
            } else {
                let task = base();
                let points: Vec<usize> = (1..N_REF).step_by(50).collect();
                let usable = usable_holds(task.conf(), &points);
                let gs = groups(task.conf(), &usable).expect("usable holds");
                let order: Vec<(usize, usize)> = gs
                    .iter()
                    .flat_map(|g| {
                        (0..n).flat_map(move |robot| {
                            (g.first_lc..g.end_lc).map(move |lc| (robot, lc))
                        })
                    })
                    .collect();
                let cell = ContinuousCoordinator::new(task, &usable, &order, n, TICK_S)
                    .expect("a runnable order")
                    .with_operators(m);
                run_ticks(cell, ticks)
            };
            println!(
                "{mode} N = {n}, M = {}: {ticks} ticks, {low} robot-ticks low-confidence, {:.3} s",
                m.get(),
                t0.elapsed().as_secs_f64()
            );
        }
        "setup" | "lead" | "lead-interleaved" | "operators" => {
            let (s, i) = (staggered(n), interleaved(n));
            let m = OperatorCount::new(n.div_ceil(4)).expect("a count");
            let verdict = match mode {
                "lead" => sufficient_margins(&s, TICK_S).expect("valid tick"),
                "lead-interleaved" => sufficient_margins(&i, TICK_S).expect("valid tick"),
                "operators" => assign_operators(&s, TICK_S, m, 0)
                    .expect("valid tick")
                    .is_some(),
                _ => true,
            };
            println!(
                "{mode} N = {n} (operators M = {}): {verdict}, {:.3} s",
                m.get(),
                t0.elapsed().as_secs_f64()
            );
        }
        _ => panic!("{usage}"),
    }
}
