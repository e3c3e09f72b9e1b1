//! Benchmark: re-scheduling with 5000 samples on the fixture task model with the mid-study
//! confidence pattern (passes 1–3 sanding low-confidence, the rest high-confidence), the
//! sampler alone (`SamplerBaselines::sampler_only`; the scheduler with the completion beside it
//! is the `certify` bench): the sampler with the single-pass margin check run lazily in
//! `(T_total, k)` order, against the
//! baseline that runs the per-pair margin check on every cheap-feasible candidate within the
//! margin budget (`SamplerParams::max_margin_checks`, 64 by default; same result, asserted
//! below and in `tests/sampler.rs`). `single_pass_exhaustive` separates the two gains.
//! Measured (2 cores, at commit `2ff2944`, on that commit's fixtures): 5.0 ms lazy, 35 ms
//! single-pass exhaustive, 43.5 ms per-pair exhaustive; best `T_total` 93.66 s against
//! 145.75 s serial. `cargo bench -p tandem-schedule --bench reschedule_5000` re-measures.
#![allow(clippy::print_stdout, reason = "a bench reports which problem it used")]
#![allow(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

#[path = "support/fixture.rs"]
mod fixture;

use criterion::{Criterion, criterion_group, criterion_main};
use tandem_schedule::{
    MarginCheck, SamplerBaselines, SamplerParams, sample_schedule_with_baselines,
};

fn bench(c: &mut Criterion) {
    let (problem, label) = fixture::mid_study_problem();
    let fast = SamplerParams {
        samples: 5000,
        seed: 1,
        ..SamplerParams::default()
    };
    let lazy = SamplerBaselines::SAMPLER_ONLY;
    let baseline = SamplerBaselines {
        margin_check: MarginCheck::PerPair,
        exhaustive_margins: true,
        ..lazy
    };
    let single_exhaustive = SamplerBaselines {
        exhaustive_margins: true,
        ..lazy
    };
    let a = sample_schedule_with_baselines(&problem, &fast, &lazy, None)
        .expect("the fixture problem is valid");
    let b = sample_schedule_with_baselines(&problem, &fast, &baseline, None)
        .expect("the fixture problem is valid");
    assert!(
        a.schedule == b.schedule && a.source == b.source,
        "both strategies must pick the same schedule"
    );
    println!(
        "reschedule_5000 on {label}: T_ref = {}, {} threads, serial T_total = {:.2} s, \
         best T_total = {:.2} s ({:?}); cheap-feasible {}, margin checks lazy {} / exhaustive {}",
        problem.n_ref(),
        rayon::current_num_threads(),
        problem
            .serial_schedule(problem.dt_s())
            .expect("Δt_s is a valid tick")
            .t_total_s(problem.dt_s()),
        a.t_total_s,
        a.source,
        a.stats.cheap_feasible,
        a.stats.margin_checks,
        b.stats.margin_checks,
    );
    let mut group = c.benchmark_group("reschedule_5000");
    group.sample_size(10);
    group.bench_function("single_pass_lazy", |bch| {
        bch.iter(|| sample_schedule_with_baselines(&problem, &fast, &lazy, None))
    });
    group.bench_function("single_pass_exhaustive", |bch| {
        bch.iter(|| sample_schedule_with_baselines(&problem, &fast, &single_exhaustive, None))
    });
    group.bench_function("per_pair_exhaustive_baseline", |bch| {
        bch.iter(|| sample_schedule_with_baselines(&problem, &fast, &baseline, None))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
