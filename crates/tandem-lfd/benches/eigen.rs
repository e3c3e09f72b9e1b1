//! faer against nalgebra for the per-sample eigendecompositions of the corrections (paper
//! §II-B2): the scaled scatter matrices `D·S·D` of every reference sample of the committed
//! sanding fixtures (9 × 9, 9873 of them), one sweep over all of them per iteration, single
//! thread. `tests/eigen_faer.rs` checks that both give the same results to 1e-12.
//! Decision and numbers: docs/decisions.md ("nalgebra, not faer, for the per-sample
//! eigendecompositions").
#![expect(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use faer::diag::Diag;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{self, ComputeEigenvectors};
use faer::{Mat, Par, Side};
use nalgebra::{DMatrix, SymmetricEigen};

use common::fixture_matrices;

fn benches(c: &mut Criterion) {
    let (d, _, matrices) = fixture_matrices();
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
