//! Criterion bench: align one fixture demonstration (demo 1) to demo 0 with the crate defaults,
//! and without smoothing (`smooth_width = 1`).
//!
//! Fixtures are found at `CARGO_MANIFEST_DIR/../../fixtures/sanding/demo_{0,1}.csv`.
#![expect(
    missing_docs,
    reason = "criterion_group! generates an undocumented pub fn"
)]

use std::path::{Path, PathBuf};

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use tandem_warp::{SignalRef, WarpParams, align};

/// Tiny CSV loader: header row, numeric columns, a column named `t` is dropped.
/// Returns (sample-major data, channel count).
fn load(path: &Path) -> (Vec<f64>, usize) {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read fixture {}: {e}", path.display()));
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .expect("fixture has a header")
        .split(',')
        .collect();
    let keep: Vec<usize> = (0..header.len())
        .filter(|&i| header[i].trim() != "t")
        .collect();
    let mut data = Vec::new();
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let cells: Vec<&str> = line.split(',').collect();
        for &i in &keep {
            data.push(
                cells[i]
                    .trim()
                    .parse::<f64>()
                    .expect("numeric fixture cell"),
            );
        }
    }
    (data, keep.len())
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sanding")
}

fn bench(c: &mut Criterion) {
    let (r, nc) = load(&fixtures().join("demo_0.csv"));
    let (q, nq) = load(&fixtures().join("demo_1.csv"));
    assert_eq!(nc, nq, "fixtures have the same channels");
    let reference = SignalRef::new(&r, nc).expect("valid fixture");
    let query = SignalRef::new(&q, nc).expect("valid fixture");
    let params = WarpParams::default();
    let id = format!(
        "align_fixture/demo1_to_demo0/{}x{}x{}ch",
        reference.n_samples(),
        query.n_samples(),
        nc
    );
    c.bench_function(&id, |b| {
        b.iter(|| align(black_box(reference), black_box(query), &params).expect("aligns"));
    });
    // The same alignment without smoothing: what the smoothing of both signals costs (or
    // saves: smoother signals can take other paths through the search).
    let unsmoothed = WarpParams {
        smooth_width: 1,
        ..params
    };
    c.bench_function(&format!("{id}/unsmoothed"), |b| {
        b.iter(|| align(black_box(reference), black_box(query), &unsmoothed).expect("aligns"));
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
