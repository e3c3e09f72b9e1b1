//! Benchmarks of the margin checks (two robots: single pass, per pair, printed; N robots: the
//! lead bound against the per-tick worst-pace simulation it replaced) and of the
//! coordinator: a whole run, and one `Coordinator::tick` for 2, 4 and 8 robots (run with
//! `cargo bench -p tandem-realtime --bench margins -- coordinator_tick`).

use criterion::{BenchmarkId, Criterion, black_box, criterion_main};
use tandem_realtime::continuous::ContinuousCoordinator;
use tandem_realtime::holds::{release_rules, usable_holds};
use tandem_realtime::margins::baseline;
use tandem_realtime::{
    Controller, Coordinator, MarginParams, Operator, Tick, Timeline, check_margins, margin_slacks,
    sufficient_margins, sufficient_margins_per_pair,
};

/// A deterministic problem of `n_ref` samples with 16 evenly spaced LC regions (a sixth of each
/// period), both robots on the mean gradient; robot 2 starts half a period after robot 1, so
/// the executions overlap throughout and every pair of both roles is simulated.
fn robots(n_ref: usize) -> [Timeline; 2] {
    let period = n_ref / 16;
    let conf: Vec<bool> = (0..n_ref).map(|n| n % period >= period / 6).collect();
    let mean: Vec<f64> = (0..n_ref)
        .map(|n| 1.0 + 0.3 * ((n as f64) * 0.05).sin())
        .collect();
    let lo: Vec<f64> = mean.iter().map(|m| 0.6 * m).collect();
    let hi: Vec<f64> = mean.iter().map(|m| 1.8 * m).collect();
    let dt_s = 0.01;
    let r0 = Timeline::new(&conf, &mean, &lo, &hi, 0.0, dt_s).expect("valid");
    let tau = r0.sample_clock_s()[period / 2];
    let r1 = Timeline::new(&conf, &mean, &lo, &hi, tau, dt_s).expect("valid");
    [r0, r1]
}

/// `n_robots` robots on the plan of [`robots`]: robot `i` starts `i` periods / `n_robots` after
/// robot 0 (wrapping), so the robots' regions interleave.
fn robots_n(n_ref: usize, n_robots: usize) -> Vec<Timeline> {
    let [r0, _] = robots(n_ref);
    let period = n_ref / 16;
    (0..n_robots)
        .map(|i| {
            let start = r0.sample_clock_s()[(i * period / n_robots) % n_ref];
            Timeline::new(
                r0.conf(),
                r0.grad_exec(),
                r0.grad_min(),
                r0.grad_max(),
                start,
                0.01,
            )
            .expect("valid")
        })
        .collect()
}

/// `n_robots` robots on the plan of [`robots`], robot `i` starting half an execution after robot
/// `i − 1`, every other one half a period later: two executions overlap at any time, their
/// low-confidence regions alternate.
fn robots_staggered(n_ref: usize, n_robots: usize) -> Vec<Timeline> {
    let [r0, _] = robots(n_ref);
    let period_s = r0.sample_clock_s()[n_ref / 16];
    let half = 0.5 * r0.end_s() + 0.5 * period_s;
    (0..n_robots)
        .map(|i| {
            Timeline::new(
                r0.conf(),
                r0.grad_exec(),
                r0.grad_min(),
                r0.grad_max(),
                half * i as f64,
                0.01,
            )
            .expect("valid")
        })
        .collect()
}

/// One `Coordinator::tick` per iteration of a run of `robots` (rewound with `reset` at the end,
/// which allocates nothing), operator inputs cycling through rush, drag, a gradient and no
/// correction.
fn bench_tick(c: &mut Criterion, id: &str, robots: Vec<Timeline>, tick_s: f64) {
    let co = Coordinator::new_unchecked(robots, tick_s).expect("valid tick");
    bench_controller(c, id, co);
}

/// One tick of `co` per iteration (reset when finished), the operators of [`bench_tick`].
fn bench_controller(c: &mut Criterion, id: &str, mut co: impl Controller) {
    let ops = [
        Operator::Fastest,
        Operator::Fastest,
        Operator::Slowest,
        Operator::Gradient(1.1),
        Operator::Scheduled,
    ];
    let mut k = 0usize;
    c.bench_function(id, |b| {
        b.iter(|| {
            if co.is_finished() {
                co.reset();
            }
            k = k.wrapping_add(1);
            let t = co.tick(black_box(ops[k % ops.len()]));
            // The interleaved plans may overlap: release a held robot, as an operator would.
            if matches!(t, Ok(Tick { fault: Some(_), .. })) {
                co.clear_fault();
            }
            black_box(t)
        })
    });
}

fn bench(c: &mut Criterion) {
    let tick_s = 0.01;
    let mut g = c.benchmark_group("margins");
    for n_ref in [1000usize, 6000] {
        let r = robots(n_ref);
        assert!(sufficient_margins(&r, tick_s).expect("valid tick"));
        g.bench_with_input(BenchmarkId::new("single_pass", n_ref), &r, |b, r| {
            b.iter(|| sufficient_margins(black_box(r), tick_s))
        });
        g.bench_with_input(BenchmarkId::new("per_pair", n_ref), &r, |b, r| {
            b.iter(|| sufficient_margins_per_pair(black_box(r), tick_s))
        });
        // The printed check rejects this schedule at its first pair (robot 2 starts in an LC
        // sample after robot 1's first region ended: the printed loop steps before testing).
        assert!(!baseline::printed(&r, tick_s).expect("valid tick"));
        g.bench_with_input(BenchmarkId::new("printed", n_ref), &r, |b, r| {
            b.iter(|| baseline::printed(black_box(r), tick_s))
        });
    }
    g.finish();
    // N robots: the lead bound (`sufficient_margins` for N ≥ 3) against the per-tick worst-pace
    // simulation it replaced (`baseline::greedy_pace`, the N-robot check before), on schedules
    // both accept (each robot half an execution after the one before: every pair is decided
    // by integrating or simulating to its end) and on the interleaved ones of `robots_n`.
    let mut g = c.benchmark_group("margins_n");
    for n_robots in [3usize, 4, 8] {
        let staggered = robots_staggered(6000, n_robots);
        assert!(sufficient_margins(&staggered, tick_s).expect("valid tick"));
        assert!(baseline::greedy_pace(&staggered, tick_s).expect("valid tick"));
        g.bench_with_input(
            BenchmarkId::new("lead_bound_staggered", n_robots),
            &staggered,
            |b, r| b.iter(|| sufficient_margins(black_box(r), tick_s)),
        );
        g.bench_with_input(
            BenchmarkId::new("greedy_pace_staggered", n_robots),
            &staggered,
            |b, r| b.iter(|| baseline::greedy_pace(black_box(r), tick_s)),
        );
        let interleaved = robots_n(6000, n_robots);
        g.bench_with_input(
            BenchmarkId::new("lead_bound_interleaved", n_robots),
            &interleaved,
            |b, r| b.iter(|| sufficient_margins(black_box(r), tick_s)),
        );
        g.bench_with_input(
            BenchmarkId::new("greedy_pace_interleaved", n_robots),
            &interleaved,
            |b, r| b.iter(|| baseline::greedy_pace(black_box(r), tick_s)),
        );
    }
    g.finish();
    // The operator's switch time (issue 41): the check and every pair's slack without and with
    // δ = 0.5 s and 2 s, same run, two robots (the simulation) and four staggered (the lead
    // bound). The slacks do the same work whatever the verdict; the check stops at the first
    // rejection.
    let mut g = c.benchmark_group("margins_switch");
    let cases: [(&str, Vec<Timeline>); 2] = [
        ("2", robots(6000).to_vec()),
        ("4_staggered", robots_staggered(6000, 4)),
    ];
    for (label, r) in &cases {
        for switch_s in [0.0, 0.5, 2.0] {
            let params = MarginParams::new(tick_s).with_switch_s(switch_s);
            let id = format!("{label}/delta_{switch_s}");
            g.bench_with_input(BenchmarkId::new("check", &id), r, |b, r| {
                b.iter(|| check_margins(black_box(r), &[], &params))
            });
            g.bench_with_input(BenchmarkId::new("slacks", &id), r, |b, r| {
                b.iter(|| margin_slacks(black_box(r), &[], &params))
            });
        }
    }
    g.finish();
    let r = robots(6000);
    c.bench_function("coordinator_run/6000", |b| {
        b.iter(|| {
            let mut co = Coordinator::new_unchecked(r.clone(), tick_s).expect("valid tick");
            let mut k = 0u32;
            while !co.is_finished() {
                let g = if k % 7 < 3 {
                    Operator::Fastest
                } else {
                    Operator::Slowest
                };
                black_box(co.tick(g).expect("admissible operator"));
                k += 1;
            }
            k
        })
    });
    // One tick: the same run, one tick per iteration (the two-robot figure of
    // docs/decisions.md).
    bench_tick(c, "coordinator_tick/6000", r.to_vec(), tick_s);
    for n_robots in [2, 4, 8] {
        let id = format!("coordinator_tick_robots/{n_robots}");
        bench_tick(c, &id, robots_n(6000, n_robots), tick_s);
    }
    // The switch time at run time (issue 41): one tick without and with δ = 2 s, same run —
    // rounds of four robots with holds at every usable sample and their release rules (where
    // δ delays releases), and a continuous cell of four robots on robot 1's plan with those
    // holds (where δ delays the token). Both compute the pre-alert in every tick.
    let r4 = robots_n(6000, 4);
    let usable: Vec<Vec<usize>> = r4
        .iter()
        .map(|tl| usable_holds(tl.conf(), &(1..tl.n_ref()).step_by(50).collect::<Vec<_>>()))
        .collect();
    let holds = release_rules(&r4, &[], &usable);
    let task = r4[0].clone();
    let groups =
        tandem_realtime::continuous::groups(task.conf(), &usable[0]).expect("usable holds");
    let order: Vec<(usize, usize)> = groups
        .iter()
        .flat_map(|g| {
            (0..4).flat_map(move |robot| (g.first_lc..g.end_lc).map(move |lc| (robot, lc)))
        })
        .collect();
    // The pre-alert alone (computed in every tick above): one call on a coordinator in the
    // middle of its run, so that a tick's cost without it is the difference.
    for (label, robots) in [("2", r.to_vec()), ("4", r4.clone())] {
        let mut co = Coordinator::new_unchecked(robots, tick_s).expect("valid tick");
        for _ in 0..5000 {
            let t = co.tick(Operator::Scheduled).expect("admissible operator");
            if t.fault.is_some() {
                co.clear_fault();
            }
        }
        c.bench_function(&format!("pre_alert/{label}"), |b| {
            b.iter(|| black_box(black_box(&co).pre_alert()))
        });
    }
    for switch_s in [0.0, 2.0] {
        let co = Coordinator::with_holds_unchecked(r4.clone(), &holds, tick_s)
            .expect("valid holds")
            .with_switch_s(switch_s)
            .expect("valid switch time");
        bench_controller(
            c,
            &format!("coordinator_tick_switch/holds_4/delta_{switch_s}"),
            co,
        );
        let cell = ContinuousCoordinator::new(task.clone(), &usable[0], &order, 4, tick_s)
            .expect("a runnable order")
            .with_switch_s(switch_s)
            .expect("valid switch time");
        bench_controller(
            c,
            &format!("coordinator_tick_switch/cell_4/delta_{switch_s}"),
            cell,
        );
    }
}

/// Runs every benchmark of this file (configured from the command line).
pub fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
}

criterion_main!(benches);
