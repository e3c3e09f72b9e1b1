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
//!
//! The group `reschedule_5000_robots` times the whole scheduler for `N` robots
//! (`sample_schedule_n`, default parameters, 5000 samples, seed 1) on the same problem for
//! N = 2, 4, 8 in one run (N = 2: sampler and margin-aware completion; N ≠ 2: the sampler
//! with robots 2..N placed in turn); the figures and their ratio to N = 2 are in
//! docs/decisions.md, "N robots in the schedule"
//! (`cargo bench -p tandem-schedule --bench reschedule_5000 -- robots`).
//! `reschedule_5000_robots_holds` is the same with the fixture's transitions as hold points
//! (N ≥ 2: the exact optimum with holds and release rules is a candidate; docs/decisions.md,
//! "N robots in the margin-free search").
#![allow(clippy::print_stdout, reason = "a bench reports which problem it used")]
#![allow(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

#[path = "support/fixture.rs"]
mod fixture;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use tandem_schedule::{
    MarginCheck, SamplerBaselines, SamplerParams, sample_schedule_n, sample_schedule_with_baselines,
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

fn bench_robots(c: &mut Criterion) {
    let (problem, label) = fixture::mid_study_problem();
    robots_group(c, "reschedule_5000_robots", &problem, &label);
    let (held, label, n) = fixture::mid_study_problem_with_holds();
    let label = format!("{label} with {n} hold points");
    robots_group(c, "reschedule_5000_robots_holds", &held, &label);
}

/// The group `name`: `sample_schedule_n` on `problem` for N = 2, 4, 8.
fn robots_group(c: &mut Criterion, name: &str, problem: &tandem_schedule::Problem, label: &str) {
    let params = SamplerParams {
        samples: 5000,
        seed: 1,
        ..SamplerParams::default()
    };
    let mut group = c.benchmark_group(name);
    group.sample_size(10);
    for n in [2, 4, 8] {
        let out = sample_schedule_n(problem, n, &params, None).expect("the fixture is valid");
        println!(
            "{name} on {label}: N = {n}, T_total = {:.2} s, lower bound {:.2} s \
             (gap {:.1} %), serial {:.2} s, source {}",
            out.t_total_s,
            out.lower_bound_s,
            100.0 * out.gap,
            problem
                .serial_schedule_n(n, problem.dt_s())
                .expect("Δt_s is a valid tick")
                .t_total_s(problem.dt_s()),
            out.source.name(),
        );
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |bch, &n| {
            bch.iter(|| sample_schedule_n(problem, n, &params, None))
        });
    }
    group.finish();
}

criterion_group!(benches, bench, bench_robots);
criterion_main!(benches);
