//! Random problems shared by the integration tests.

use proptest::prelude::*;

include!("pegs.rs");
use tandem_schedule::Problem;

/// `n` random gradient triples `(mean, min factor, max factor)`: mean in `[0.5, 2)`,
/// `ψ̇min = mean·[0.3, 1)`, `ψ̇max = mean·[1, 2.5)`.
pub(crate) fn gradients(n: usize) -> impl Strategy<Value = Vec<(f64, f64, f64)>> {
    proptest::collection::vec((0.5f64..2.0, 0.3f64..1.0, 1.0f64..2.5), n)
}

/// The problem with confidence `conf` and the gradient triples `g` of [`gradients`], 10 ms
/// reference samples.
pub(crate) fn problem(conf: Vec<bool>, g: &[(f64, f64, f64)]) -> Problem {
    Problem::new(
        conf,
        g.iter().map(|x| x.0).collect(),
        g.iter().map(|x| x.0 * x.1).collect(),
        g.iter().map(|x| x.0 * x.2).collect(),
        0.01,
    )
    .expect("positive bounds around the mean")
}
