//! Benchmark: the cyclic plan (issue 21) on a synthetic problem shaped like the sanding task
//! — 6000 reference samples at 10 ms, three low-confidence passes of 12.8 s at `ψ̇̄ = 1` and
//! 21.6 s of high confidence (29.0 s at `ψ̇̄ = 1.343`, 21.6 s at `ψ̇min = 1`) in a head, two
//! transitions and a tail, a hold point in the middle of each transition — for
//! `N = 2, 3, 4, 8`: the period of one fixed order (round robin by stretch) and the full order
//! search; and what the continuous study does at each re-plan (`replan/N`): the order search
//! (`cyclic_plan`), the new plan's coordinator at the problem's tick
//! (`CyclicPlan::coordinator`, `tick_s = Δt_s` = 10 ms) and the hand-over of the running cell
//! to it (`ContinuousCoordinator::take_over`); and the hand-over alone (`take_over/N`). The
//! running cell is the coordinator of the previous plan, of the same problem with one more
//! low-confidence sample (the head's last, sample 599, which the refinement turned high), run
//! under `Operator::Scheduled` for 10 000 ticks (100 s: the robots are mid-task) and then on to
//! the first tick at which the new plan can take over (outside the timing).
//! Results: `docs/decisions.md` ("A continuous cell: the cyclic plan and its exact period").
#![allow(clippy::print_stdout, reason = "a bench reports the plans it timed")]
#![allow(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

use criterion::measurement::WallTime;
use criterion::{
    BatchSize, BenchmarkGroup, BenchmarkId, Criterion, criterion_group, criterion_main,
};
use tandem_realtime::Operator;
use tandem_schedule::{
    CyclicParams, Problem, Stretch, cyclic_plan, cyclic_plan_for_order, max_cycle_ratio,
};

/// Head 600, pass 1280, transition 480, pass 1280, transition 480, pass 1280, tail 600
/// samples; holds at the middle of both transitions (or none).
fn sanding_like(holds: bool) -> Problem {
    sanding_like_flipped(holds, None)
}

/// [`sanding_like`] with the confidence of reference sample `flip` inverted (and its rates
/// those of its new confidence).
fn sanding_like_flipped(holds: bool, flip: Option<usize>) -> Problem {
    let runs = [
        (600, true),
        (1280, false),
        (480, true),
        (1280, false),
        (480, true),
        (1280, false),
        (600, true),
    ];
    let mut conf: Vec<bool> = runs
        .iter()
        .flat_map(|&(l, c)| std::iter::repeat_n(c, l))
        .collect();
    if let Some(k) = flip {
        conf[k] = !conf[k];
    }
    let pick =
        |hc: f64, lc: f64| -> Vec<f64> { conf.iter().map(|&c| if c { hc } else { lc }).collect() };
    let (mean, min, max) = (pick(1.343, 1.0), pick(1.0, 1.0), pick(2.0, 1.0));
    Problem::new(conf.clone(), mean, min, max, 0.01)
        .expect("valid by construction")
        .with_holds(if holds {
            vec![600 + 1280 + 240, 600 + 2 * 1280 + 480 + 240]
        } else {
            Vec::new()
        })
        .expect("increasing holds inside the task")
}

fn round_robin(n_robots: usize, m: usize) -> Vec<Stretch> {
    (0..m)
        .flat_map(|lc| (0..n_robots).map(move |robot| Stretch { robot, lc }))
        .collect()
}

fn bench(c: &mut Criterion) {
    let params = CyclicParams::default();
    let without = sanding_like(false);
    for n in 1..=8 {
        let best = cyclic_plan(&without, n, &params).expect("valid problem");
        println!(
            "without holds, N = {n}: P = {:.3} s ({} orders, exhaustive {}), bound {:.3} s, gap {:.4}, {:.2} tasks/h, operator busy {:.3}",
            best.period_s,
            best.orders_evaluated,
            best.order_exhaustive,
            best.lower_bound_s,
            best.gap,
            best.tasks_per_hour,
            best.operator_share
        );
    }
    let problem = sanding_like(true);
    for n in 1..=8 {
        let rr = cyclic_plan_for_order(&problem, n, &round_robin(n, 3)).expect("feasible");
        let best = cyclic_plan(&problem, n, &params).expect("valid problem");
        println!(
            "N = {n}: round robin P = {:.3} s; search P = {:.3} s ({} orders, exhaustive {}), bound {:.3} s, gap {:.2e}, {:.2} tasks/h, operator busy {:.3}",
            rr.period_s,
            best.period_s,
            best.orders_evaluated,
            best.order_exhaustive,
            best.lower_bound_s,
            best.gap,
            best.tasks_per_hour,
            best.operator_share
        );
    }
    let mut group = c.benchmark_group("cyclic");
    for n in [2usize, 3, 4, 8] {
        let order = round_robin(n, 3);
        let graph = tandem_schedule::cyclic::event_graph(&problem, n, &order).expect("valid order");
        group.bench_with_input(BenchmarkId::new("max_cycle_ratio", n), &graph, |b, g| {
            b.iter(|| max_cycle_ratio(g.events.len(), &g.arcs).expect("feasible"));
        });
        group.bench_with_input(BenchmarkId::new("plan_for_order", n), &order, |b, o| {
            b.iter(|| cyclic_plan_for_order(&problem, n, o).expect("feasible"));
        });
        group.bench_with_input(BenchmarkId::new("order_search", n), &n, |b, &n| {
            b.iter(|| cyclic_plan(&problem, n, &params).expect("valid problem"));
        });
    }
    replan(&mut group, &problem, &params);
    group.finish();
}

/// Ticks the previous plan's cell runs before the re-plan (100 s at 10 ms: mid-task).
const RUN_TICKS: u64 = 10_000;

/// The continuous study's re-plan: search, coordinator, hand-over (module docs).
fn replan(group: &mut BenchmarkGroup<'_, WallTime>, problem: &Problem, params: &CyclicParams) {
    let tick_s = problem.dt_s();
    // The previous plan's problem: the head's last sample still low-confidence (the pass
    // began one sample earlier); the new problem's low-confidence samples are among its own.
    let previous = sanding_like_flipped(true, Some(599));
    for n in [2usize, 3, 4, 8] {
        let old_plan = cyclic_plan(&previous, n, params).expect("valid problem");
        let mut old = old_plan
            .coordinator(&previous, tick_s)
            .expect("a runnable plan");
        for _ in 0..RUN_TICKS {
            old.tick(Operator::Scheduled).expect("a valid operator");
        }
        let new = cyclic_plan(problem, n, params)
            .expect("valid problem")
            .coordinator(problem, tick_s)
            .expect("a runnable plan");
        // On to the first hand-over point of the new plan (at the latest the token's move).
        let mut waited = 0_u64;
        while new.clone().take_over(&old).is_err() {
            old.tick(Operator::Scheduled).expect("a valid operator");
            waited += 1;
            assert!(waited < 1_000_000, "no hand-over point");
        }
        println!(
            "replan N = {n}: hand-over after {RUN_TICKS} + {waited} ticks, tasks {:?}, clocks {:.2?} s",
            old.tasks_completed(),
            old.clock_s()
        );
        group.bench_with_input(BenchmarkId::new("replan", n), &n, |b, &n| {
            b.iter(|| {
                let mut next = cyclic_plan(problem, n, params)
                    .expect("valid problem")
                    .coordinator(problem, tick_s)
                    .expect("a runnable plan");
                next.take_over(&old).expect("a hand-over point");
                next
            });
        });
        group.bench_with_input(BenchmarkId::new("take_over", n), &new, |b, new| {
            b.iter_batched(
                || new.clone(),
                |mut next| {
                    next.take_over(&old).expect("a hand-over point");
                    next
                },
                BatchSize::SmallInput,
            );
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
