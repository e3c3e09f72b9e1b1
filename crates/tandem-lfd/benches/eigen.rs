//! faer against nalgebra for the per-sample eigendecompositions of the corrections (paper
//! §II-B2): the scaled scatter matrices `D·S·D` of every reference sample of the committed
//! sanding fixtures (9 × 9, 9873 of them), one sweep over all of them per iteration, single
//! thread. `tests/eigen_faer.rs` checks that both give the same results to 1e-12.
//! Decision and numbers: docs/decisions.md ("faer or nalgebra").
#![expect(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{Criterion, criterion_group, criterion_main};
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{self, ComputeEigenvectors};
use faer::{Mat, Par, Side};
use nalgebra::{DMatrix, SymmetricEigen};
use tandem_lfd::{Demonstration, FitParams, TaskModel};

/// The scaled scatter of every reference sample of the fixture model, row-major `d × d`.
fn fixture_matrices() -> (usize, Vec<Vec<f64>>) {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sanding");
    let demos: Vec<Demonstration> = (0..6)
        .map(|i| {
            Demonstration::from_csv_path(dir.join(format!("demo_{i}.csv")), None)
                .expect("committed fixture parses")
        })
        .collect();
    let model = TaskModel::fit(&demos, &FitParams::default()).expect("fixtures fit");
    let (d, r, dof) = (
        model.ranges().len(),
        model.ranges(),
        (model.count() - 1) as f64,
    );
    let matrices = (0..model.n_ref())
        .map(|n| {
            let cov = model.covariance(n);
            (0..d * d)
                .map(|ij| cov[ij] * dof / (r[ij / d] * r[ij % d]))
                .collect()
        })
        .collect();
    (d, matrices)
}

fn benches(c: &mut Criterion) {
    let (d, matrices) = fixture_matrices();
    let mut group = c.benchmark_group("eigen_fixtures");
    group.sample_size(20);
    let id = |lib: &str| format!("{lib}/{}x{d}x{d}", matrices.len());
    // What the corrections do today: a fresh matrix per sample, nalgebra's symmetric QR.
    group.bench_function(id("nalgebra_symmetric_eigen"), |b| {
        b.iter(|| {
            for a in &matrices {
                let eig = SymmetricEigen::new(DMatrix::from_row_slice(d, d, a));
                black_box(&eig);
            }
        })
    });
    // faer's convenience call (allocates its matrices and scratch per sample).
    group.bench_function(id("faer_self_adjoint_eigen"), |b| {
        b.iter(|| {
            for a in &matrices {
                let m = Mat::from_fn(d, d, |i, j| a[i * d + j]);
                let eig = m.self_adjoint_eigen(Side::Lower).expect("finite symmetric");
                black_box(&eig);
            }
        })
    });
    // faer with caller-owned buffers and scratch, reused across samples, sequential.
    group.bench_function(id("faer_evd_reused_scratch"), |b| {
        let mut m = Mat::<f64>::zeros(d, d);
        let mut u = Mat::<f64>::zeros(d, d);
        let mut s = Diag::<f64>::zeros(d);
        let req = evd::self_adjoint_evd_scratch::<f64>(
            d,
            ComputeEigenvectors::Yes,
            Par::Seq,
            Default::default(),
        );
        let mut buf = MemBuffer::new(req);
        b.iter(|| {
            for a in &matrices {
                for i in 0..d {
                    for j in 0..d {
                        m[(i, j)] = a[i * d + j];
                    }
                }
                evd::self_adjoint_evd(
                    m.as_ref(),
                    s.as_mut(),
                    Some(u.as_mut()),
                    Par::Seq,
                    MemStack::new(&mut buf),
                    Default::default(),
                )
                .expect("finite symmetric");
                black_box((&s, &u));
            }
        })
    });
    group.finish();
}

criterion_group!(eigen, benches);
criterion_main!(eigen);
