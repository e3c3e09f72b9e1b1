//! Benchmark: certified re-scheduling of the fixture problem (`fixtures/sanding/problem.csv`,
//! passes 1–3 sanding low-confidence, tick = `Δt_s`) — the exact margin-free search alone
//! (`solve_exact`), the search plus the margin-aware completion (no sampled candidate:
//! `SamplerBaselines::completion_only`), and the scheduler the planner runs (sampler and completion in parallel,
//! `sample_schedule`) — against the sampler alone exactly as `reschedule_5000`'s
//! `single_pass_lazy`, in the same run. Results and the ratio: `docs/decisions.md`
//! ("Certified schedules").
#![allow(clippy::print_stdout, reason = "a bench reports which problem it used")]
#![allow(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

#[path = "support/fixture.rs"]
mod fixture;

use criterion::{Criterion, criterion_group, criterion_main};
use tandem_schedule::{
    ExactParams, SamplerBaselines, SamplerParams, sample_schedule, sample_schedule_with_baselines,
    solve_exact, validate,
};

fn bench(c: &mut Criterion) {
    let (problem, label) = fixture::mid_study_problem();
    let exact = ExactParams::default();
    let scheduler = SamplerParams {
        samples: 5000,
        seed: 1,
        ..SamplerParams::default()
    };
    let completion_only = SamplerBaselines::COMPLETION_ONLY;
    let sampler_only = SamplerBaselines::SAMPLER_ONLY;
    let free = solve_exact(&problem, &exact).expect("the fixture problem is valid");
    let done = sample_schedule_with_baselines(&problem, &scheduler, &completion_only, None)
        .expect("the fixture problem is valid");
    let both = sample_schedule(&problem, &scheduler, None).expect("the fixture problem is valid");
    let sampled = sample_schedule_with_baselines(&problem, &scheduler, &sampler_only, None)
        .expect("the fixture problem is valid");
    assert!(
        validate(&problem, &done.schedule).is_ok() && validate(&problem, &both.schedule).is_ok()
    );
    assert!(both.t_total_s <= sampled.t_total_s);
    println!(
        "certify on {label}: T_ref = {}, {} threads, T*0 = {:.3} s (proven {}), completion \
         T_total = {:.3} s (gap {:.2} %, {} margin checks, {:?}), scheduler {:.3} s ({:?}), \
         sampler alone {:.3} s",
        problem.n_ref(),
        rayon::current_num_threads(),
        free.lower_bound_s,
        free.proven_optimal,
        done.t_total_s,
        100.0 * done.gap,
        done.stats.completion_margin_checks,
        done.source,
        both.t_total_s,
        both.source,
        sampled.t_total_s,
    );
    let mut group = c.benchmark_group("certify");
    group.sample_size(20);
    group.bench_function("solve_exact", |b| b.iter(|| solve_exact(&problem, &exact)));
    group.bench_function("completion", |b| {
        b.iter(|| sample_schedule_with_baselines(&problem, &scheduler, &completion_only, None))
    });
    group.bench_function("scheduler", |b| {
        b.iter(|| sample_schedule(&problem, &scheduler, None))
    });
    group.bench_function("reschedule_5000_single_pass_lazy", |b| {
        b.iter(|| sample_schedule_with_baselines(&problem, &scheduler, &sampler_only, None))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
