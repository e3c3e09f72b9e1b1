//! Benchmark: certifying the fixture problem (`fixtures/sanding/problem.csv`, passes 1–3
//! sanding low-confidence, tick = `Δt_s`) — the exact margin-free search alone (`solve_exact`)
//! and the search plus the margin-aware completion (`certify`) — against re-scheduling with
//! 5000 samples exactly as `reschedule_5000`'s `single_pass_lazy`, in the same run.
//! Results and the ratio: `docs/decisions.md` ("Certified schedules").
#![allow(clippy::print_stdout, reason = "a bench reports which problem it used")]
#![allow(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

#[path = "support/fixture.rs"]
mod fixture;

use criterion::{Criterion, criterion_group, criterion_main};
use tandem_schedule::{
    ExactParams, SamplerParams, certify, sample_schedule, solve_exact, validate,
};

fn bench(c: &mut Criterion) {
    let (problem, label) = fixture::mid_study_problem();
    let exact = ExactParams::default();
    let sampler = SamplerParams {
        samples: 5000,
        seed: 1,
        ..SamplerParams::default()
    };
    let free = solve_exact(&problem, &exact).expect("the fixture problem is valid");
    let cert = certify(&problem, &exact, None).expect("the fixture problem is valid");
    let sampled = sample_schedule(&problem, &sampler, None).expect("the fixture problem is valid");
    assert!(validate(&problem, &cert.schedule).is_ok());
    println!(
        "certify on {label}: T_ref = {}, {} threads, T*0 = {:.3} s (proven {}), certified \
         T_total = {:.3} s (gap {:.2} %, {} margin checks), sampler T_total = {:.3} s",
        problem.n_ref(),
        rayon::current_num_threads(),
        free.lower_bound_s,
        free.proven_optimal,
        cert.t_total_s,
        100.0 * cert.gap,
        cert.margin_checks,
        sampled.t_total_s,
    );
    let mut group = c.benchmark_group("certify");
    group.sample_size(20);
    group.bench_function("solve_exact", |b| b.iter(|| solve_exact(&problem, &exact)));
    group.bench_function("certify", |b| b.iter(|| certify(&problem, &exact, None)));
    group.bench_function("reschedule_5000_single_pass_lazy", |b| {
        b.iter(|| sample_schedule(&problem, &sampler, None))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
