//! faer and nalgebra give the same per-sample eigendecompositions on the committed sanding
//! fixtures (the input of the correction directions, paper §II-B2): every eigenvalue to
//! 1e-12 of the matrix's largest, and the eigenvectors that the corrections use to 1e-12 up
//! to sign wherever they are determined (docs/decisions.md, "nalgebra, not faer, for the per-sample eigendecompositions").

mod common;

use faer::{Mat, Side};
use nalgebra::{DMatrix, SymmetricEigen};

use common::fixture_matrices;

/// Eigenvalues (descending) and eigenvectors (columns in the same order) of a symmetric
/// row-major matrix, with nalgebra.
fn nalgebra_eigen(d: usize, a: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let eig = SymmetricEigen::new(DMatrix::from_row_slice(d, d, a));
    let mut order: Vec<usize> = (0..d).collect();
    order.sort_by(|&x, &y| eig.eigenvalues[y].total_cmp(&eig.eigenvalues[x]));
    (
        order.iter().map(|&o| eig.eigenvalues[o]).collect(),
        order
            .iter()
            .map(|&o| eig.eigenvectors.column(o).iter().copied().collect())
            .collect(),
    )
}

/// The same with faer (eigenvalues come ascending; reversed here).
fn faer_eigen(d: usize, a: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let m = Mat::from_fn(d, d, |i, j| a[i * d + j]);
    let eig = m
        .self_adjoint_eigen(Side::Lower)
        .expect("symmetric and finite");
    let (s, u) = (eig.S(), eig.U());
    (
        (0..d).rev().map(|k| s[k]).collect(),
        (0..d)
            .rev()
            .map(|k| (0..d).map(|i| u[(i, k)]).collect())
            .collect(),
    )
}

#[test]
fn faer_and_nalgebra_agree_on_the_fixture_matrices() {
    let (d, k, matrices) = fixture_matrices();
    assert_eq!(
        (d, k),
        (9, 3),
        "fixtures: 9 tangent coordinates, 3 components"
    );
    let (mut worst_value, mut worst_vector, mut undetermined) = (0.0f64, 0.0f64, 0);
    for a in &matrices {
        let (ln, vn) = nalgebra_eigen(d, a);
        let (lf, vf) = faer_eigen(d, a);
        let scale = ln[0].abs().max(f64::MIN_POSITIVE);
        for (x, y) in ln.iter().zip(&lf) {
            worst_value = worst_value.max((x - y).abs() / scale);
        }
        // An eigenvector is determined to 1e-12 only where its eigenvalue is apart from its
        // neighbours by more than about 1e-4 of the largest (perturbation ≈ ε‖A‖ / gap).
        for c in 0..k {
            let gap = (ln[c] - ln[c + 1]).min(if c > 0 { ln[c - 1] - ln[c] } else { f64::MAX });
            if gap < 1e-4 * scale {
                undetermined += 1;
                continue;
            }
            let dot: f64 = vn[c].iter().zip(&vf[c]).map(|(x, y)| x * y).sum();
            let sign = dot.signum();
            for (x, y) in vn[c].iter().zip(&vf[c]) {
                worst_vector = worst_vector.max((x - sign * y).abs());
            }
        }
    }
    eprintln!(
        "{} matrices {d}x{d}: largest eigenvalue difference {worst_value:.2e} (of the largest), \
         largest eigenvector difference {worst_vector:.2e}, {undetermined} of {} used \
         eigenvectors not determined (gap < 1e-4 of the largest)",
        matrices.len(),
        matrices.len() * k
    );
    assert!(
        worst_value <= 1e-12,
        "eigenvalues differ by {worst_value:e}"
    );
    assert!(
        worst_vector <= 1e-12,
        "eigenvectors differ by {worst_vector:e}"
    );
    assert!(
        undetermined * 100 < matrices.len() * k,
        "{undetermined} undetermined eigenvectors: the comparison would be vacuous"
    );
}
