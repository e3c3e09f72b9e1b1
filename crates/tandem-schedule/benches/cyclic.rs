//! Benchmark: the cyclic plan (issue 21) on a synthetic problem shaped like the sanding task
//! — 6000 reference samples at 10 ms, three low-confidence passes of 12.8 s at `ψ̇̄ = 1` and
//! 21.6 s of high confidence (29.0 s at `ψ̇̄ = 1.343`, 21.6 s at `ψ̇min = 1`) in a head, two
//! transitions and a tail, a hold point in the middle of each transition — for `N = 2, 4, 8`:
//! the period of one fixed order (round robin by stretch) and the full order search. Results:
//! `docs/decisions.md` ("A continuous cell: the cyclic plan and its exact period").
#![allow(clippy::print_stdout, reason = "a bench reports the plans it timed")]
#![allow(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use tandem_schedule::{
    CyclicParams, Problem, Stretch, cyclic_plan, cyclic_plan_for_order, max_cycle_ratio,
};

/// Head 600, pass 1280, transition 480, pass 1280, transition 480, pass 1280, tail 600
/// samples; holds at the middle of both transitions (or none).
fn sanding_like(holds: bool) -> Problem {
    let runs = [
        (600, true),
        (1280, false),
        (480, true),
        (1280, false),
        (480, true),
        (1280, false),
        (600, true),
    ];
    let conf: Vec<bool> = runs
        .iter()
        .flat_map(|&(l, c)| std::iter::repeat_n(c, l))
        .collect();
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
    for n in [2usize, 4, 8] {
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
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
