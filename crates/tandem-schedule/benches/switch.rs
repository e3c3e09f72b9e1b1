//! Benchmark: the operator's switch time `δ` (issue 41) in the scheduler, on the fixture problem
//! (`fixtures/sanding/problem.csv`, passes 1–3 sanding low-confidence, tick = `Δt_s`), with
//! against without `δ`, same run: the certificate's bound (`margin_free_bound`: for two robots
//! the exact search, for four the branch and bound over machine orders) and the validation of
//! the scheduler's two-robot schedule (`validate_with_switch`: constraints 1–4, the scheduled
//! switch gaps and the margin check with the switch time). It prints the bounds for
//! `δ ∈ {0, 0.5, 2, 7}` s and `N = 2, 3, 4` (docs/decisions.md, "The switch time in the
//! scheduler's bounds (issue 41)"), and the continuous cell's plan with the switch time and
//! the load cap; the rounds scheduler's `T_total` with the switch time and the load cap
//! against its bound, and a re-schedule with against without `δ = 2` s (docs/decisions.md,
//! "Rounds schedules with the switch time and the load cap (issue 41)").
//! `cargo bench -p tandem-schedule --bench switch` re-measures.
#![allow(
    clippy::print_stdout,
    reason = "a bench reports its problem and bounds"
)]
#![allow(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

#[path = "support/fixture.rs"]
mod fixture;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use tandem_schedule::{
    CyclicParams, ExactParams, SamplerParams, busy_share, cyclic_plan, margin_free_bound,
    period_lower_bound_with_switch_s, sample_schedule, sample_schedule_n, validate_with_switch,
};

/// The operator's busy share of a cyclic plan with its switches: the supervised share plus
/// `δ` per change of robot around the order, over the period.
fn busy_with_switches(plan: &tandem_schedule::CyclicPlan, switch_s: f64) -> f64 {
    let len = plan.order.len();
    let changes = (0..len)
        .filter(|&q| plan.order[q].robot != plan.order[(q + 1) % len].robot)
        .count();
    plan.operator_share + changes as f64 * switch_s / plan.period_s
}

fn bench(c: &mut Criterion) {
    let (problem, label) = fixture::mid_study_problem();
    let exact = ExactParams::default();
    println!("switch on {label}: T_ref = {}", problem.n_ref());
    for n in [2usize, 3, 4] {
        for switch_s in [0.0, 0.5, 2.0, 7.0] {
            let b = margin_free_bound(&problem, n, &exact, switch_s).expect("valid");
            println!(
                "  N = {n}, δ = {switch_s} s: bound {:.3} s (proven {}, order {:?})",
                b.lower_bound_s, b.proven_optimal, b.order
            );
        }
    }
    // The continuous cell's plan with the switch time and the load cap (the token rule's
    // hand-overs counted at Δt_s, as the study's cell).
    for n in [2usize, 3] {
        for (switch_s, cap) in [(0.0, 1.0), (2.0, 1.0), (0.0, 0.7), (2.0, 0.7)] {
            let params = CyclicParams {
                handover_tick_s: Some(problem.dt_s()),
                switch_s,
                max_busy_share: cap,
                ..CyclicParams::default()
            };
            let plan = cyclic_plan(&problem, n, &params).expect("valid");
            println!(
                "  cyclic N = {n}, δ = {switch_s} s, u_max = {cap}: period {:.3} s, {:.2} \
                 tasks/h, bound {:.3} s (gap {:.2} %), supervised share {:.3}",
                plan.period_s,
                plan.tasks_per_hour,
                plan.lower_bound_s,
                100.0 * plan.gap,
                plan.operator_share
            );
        }
    }
    // The same with the fixture's transitions as hold points (the study's task: a hold between
    // every two passes, so every order is runnable), against the chain bound and the bound of
    // one switch per robot (docs/decisions.md, "The continuous cell's chain bound with the
    // switch time (issue 41)"), and with the load cap 0.7 against the uncapped plan.
    let (held, _, _) = fixture::mid_study_problem_with_holds();
    for n in [2usize, 3] {
        for switch_s in [0.0, 1.0, 2.0, 5.0, 7.0] {
            let params = CyclicParams {
                handover_tick_s: Some(held.dt_s()),
                switch_s,
                ..CyclicParams::default()
            };
            let plan = cyclic_plan(&held, n, &params).expect("valid");
            let capped = cyclic_plan(
                &held,
                n,
                &CyclicParams {
                    max_busy_share: 0.7,
                    ..params
                },
            )
            .expect("valid");
            let one_switch = period_lower_bound_with_switch_s(&held, n, switch_s).expect("valid");
            println!(
                "  cyclic with holds N = {n}, δ = {switch_s} s: period {:.3} s, {:.2} tasks/h, \
                 bound {:.3} s (gap {:.2} %, {:.2} % above one switch per robot {:.3} s), \
                 order {:?}; u_max = 0.7: period {:.3} s, {:.2} tasks/h (gap {:.2} %), \
                 busy share with the switches {:.3}",
                plan.period_s,
                plan.tasks_per_hour,
                plan.lower_bound_s,
                100.0 * plan.gap,
                100.0 * (plan.period_s / one_switch - 1.0),
                one_switch,
                plan.order
                    .iter()
                    .map(|s| (s.robot, s.lc))
                    .collect::<Vec<_>>(),
                capped.period_s,
                capped.tasks_per_hour,
                100.0 * capped.gap,
                busy_with_switches(&capped, switch_s)
            );
        }
    }
    let scheduler = SamplerParams {
        samples: 5000,
        seed: 1,
        ..SamplerParams::default()
    };
    let out = sample_schedule(&problem, &scheduler, None).expect("the fixture problem is valid");
    for switch_s in [0.0, 0.5, 2.0] {
        println!(
            "  the scheduler's schedule ({:.3} s) at δ = {switch_s} s: {:?}",
            out.t_total_s,
            validate_with_switch(&problem, &out.schedule, switch_s).map_err(|v| v.to_string())
        );
    }
    // The rounds scheduler with the switch time and the load cap (docs/decisions.md, "Rounds
    // schedules with the switch time and the load cap (issue 41)"): T_total against the
    // certificate's δ-bound, its source and the operator's busy share.
    for n in [2usize, 3] {
        for (switch_s, cap) in [
            (0.0, 1.0),
            (0.5, 1.0),
            (2.0, 1.0),
            (7.0, 1.0),
            (0.0, 0.7),
            (2.0, 0.7),
        ] {
            let params = SamplerParams {
                switch_s,
                max_busy_share: cap,
                ..scheduler.clone()
            };
            match sample_schedule_n(&problem, n, &params, None) {
                Ok(o) => println!(
                    "  rounds N = {n}, δ = {switch_s} s, u_max = {cap}: T_total {:.3} s ({}), \
                     bound {:.3} s (proven {}), gap {:.2} %, busy share {:.3}, valid with δ: {}",
                    o.t_total_s,
                    o.source.name(),
                    o.lower_bound_s,
                    o.bound_is_optimum,
                    100.0 * o.gap,
                    busy_share(&o.schedule, &problem, switch_s).expect("laid out"),
                    validate_with_switch(&problem, &o.schedule, switch_s).is_ok()
                ),
                Err(e) => println!("  rounds N = {n}, δ = {switch_s} s, u_max = {cap}: {e}"),
            }
        }
    }
    let mut g = c.benchmark_group("switch");
    g.sample_size(20);
    for n in [2usize, 4] {
        for switch_s in [0.0, 2.0] {
            g.bench_with_input(
                BenchmarkId::new(format!("bound_{n}"), switch_s),
                &switch_s,
                |b, &d| b.iter(|| margin_free_bound(&problem, n, &exact, d)),
            );
        }
    }
    // A re-schedule (5000 samples, the exact search and the completion beside them) with
    // against without δ = 2 s, same run.
    for switch_s in [0.0, 2.0] {
        let params = SamplerParams {
            switch_s,
            ..scheduler.clone()
        };
        g.bench_with_input(
            BenchmarkId::new("reschedule_2", switch_s),
            &params,
            |b, params| b.iter(|| sample_schedule_n(&problem, 2, params, None)),
        );
    }
    for switch_s in [0.0, 2.0] {
        g.bench_with_input(
            BenchmarkId::new("validate_2", switch_s),
            &switch_s,
            |b, &d| b.iter(|| validate_with_switch(&problem, &out.schedule, d)),
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
