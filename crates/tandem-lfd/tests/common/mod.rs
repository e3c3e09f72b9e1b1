//! The inputs of the eigendecomposition comparison (`tests/eigen_faer.rs`,
//! `benches/eigen.rs`): the committed sanding fixtures' model and its per-sample matrices.

use std::path::PathBuf;

use tandem_lfd::{Demonstration, FitParams, TaskModel};

/// The scaled scatter `D·S·D`, `D = diag(1/r)`, of every reference sample of the model
/// fitted on the six sanding fixtures, row-major `d × d` (what `TaskModel`'s corrections
/// decompose); returns `(d, K, matrices)` with `K` the model's number of components.
pub(crate) fn fixture_matrices() -> (usize, usize, Vec<Vec<f64>>) {
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
    (d, model.n_components(), matrices)
}
