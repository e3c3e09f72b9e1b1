//! Criterion benches of the task model on the six sanding fixtures: full fit (alignment
//! included) with the first and the medoid reference, statistics from known warps,
//! correction directions, and one incremental update.
#![expect(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use tandem_lfd::{Demonstration, Execution, FitParams, Reference, TaskModel};

fn fixtures() -> Vec<Demonstration> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sanding");
    (0..6)
        .map(|i| {
            Demonstration::from_csv_path(dir.join(format!("demo_{i}.csv")), None)
                .expect("committed fixture parses")
        })
        .collect()
}

/// The model's mean behaviour replayed at the reference rate, as a recorded execution.
fn mean_execution(model: &TaskModel) -> Execution {
    let demo = Demonstration::new(
        model.channel_names().to_vec(),
        model.mean().to_vec(),
        model.dt_s(),
    )
    .expect("mean is finite");
    Execution {
        demonstration: demo,
        ref_time_log: (0..model.n_ref()).map(|n| n as f64).collect(),
    }
}

fn benches(c: &mut Criterion) {
    let demos = fixtures();
    let params = FitParams::default();
    let n_ref = demos[0].n_samples();
    let mut group = c.benchmark_group("fit_fixtures");
    group.sample_size(10);
    group.bench_function(format!("fit/6x{n_ref}"), |b| {
        b.iter(|| TaskModel::fit(black_box(&demos), &params).expect("fixtures fit"))
    });
    // The medoid reference: every demonstration tried as the reference (6 alignment passes).
    let medoid = FitParams {
        reference: Reference::Medoid,
        ..params.clone()
    };
    group.bench_function(format!("fit_medoid/6x{n_ref}"), |b| {
        b.iter(|| TaskModel::fit(black_box(&demos), &medoid).expect("fixtures fit"))
    });
    // Statistics only, from warps computed once (the split: alignment = fit − this).
    let m = demos[0].n_channels();
    let signals: Vec<tandem_warp::SignalRef<'_>> = demos
        .iter()
        .map(|d| tandem_warp::SignalRef::new(d.samples(), m).expect("valid signal"))
        .collect();
    let warps = tandem_warp::align_many(signals[0], &signals[1..], &params.warp).expect("aligns");
    let mut values: Vec<Vec<f64>> = vec![(0..n_ref).map(|n| n as f64).collect()];
    values.extend(warps.iter().map(|w| w.values().to_vec()));
    group.bench_function(format!("fit_aligned/6x{n_ref}"), |b| {
        b.iter(|| TaskModel::fit_aligned(black_box(&demos), &values, &params).expect("fits"))
    });
    let model = TaskModel::fit(&demos, &params).expect("fixtures fit");
    group.bench_function(format!("corrections/{n_ref}"), |b| {
        b.iter_batched(
            || model.clone(),
            |fresh| {
                fresh.prepare_corrections();
                fresh
            },
            criterion::BatchSize::LargeInput,
        )
    });
    group.finish();

    let exec = mean_execution(&model);
    c.bench_function(&format!("update_one/{n_ref}"), |b| {
        b.iter_batched(
            || model.clone(),
            |mut fresh| {
                fresh.update(black_box(&exec)).expect("valid execution");
                fresh
            },
            criterion::BatchSize::LargeInput,
        )
    });
    model.prepare_corrections();
    let k = model.n_components();
    let u = vec![0.5; k];
    let mut out = vec![0.0; model.channel_names().len() + 1];
    c.bench_function("command_into", |b| {
        b.iter(|| {
            model
                .command_into(black_box(&u), black_box(1234.5), &mut out)
                .expect("valid")
        })
    });
}

criterion_group!(lfd, benches);
criterion_main!(lfd);
