//! Lazily tabulated decision boundary of Eq. 12, used to skip incomplete-beta evaluations
//! whose outcome is already certain.
//!
//! For fixed `x = μ_c`, `I_x(α, β)` is strictly decreasing in `α` and strictly increasing
//! in `β`. So the set `{I_x(α, β) > γ_c}` lies above a curve `β = B*(α)` that increases
//! with `α`. At grid nodes `α_k = k·H` this module brackets `B*(α_k)` by two values that
//! statrs has classified with a margin `M = 1e-6`: `β_lo` with `I(α_k, β_lo) ≤ γ_c − M` and `β_hi` with
//! `I(α_k, β_hi) ≥ γ_c + M`. For a sample with `α_k ≤ α < α_{k+1}`:
//!
//! - `β ≤ β_lo(α_k)` ⇒ `I(α, β) ≤ I(α_k, β) ≤ I(α_k, β_lo) ≤ γ_c − M`: low confidence;
//! - `β ≥ β_hi(α_{k+1})` ⇒ `I(α, β) ≥ I(α_{k+1}, β) ≥ I(α_{k+1}, β_hi) ≥ γ_c + M`: high.
//!
//! Otherwise statrs is evaluated at the sample itself. Because every certificate clears
//! `γ_c` by `M`, far above statrs' error, the result equals evaluating statrs everywhere.
//! Nodes are computed on first use (about 20 statrs calls each) and kept; the table is a
//! cache only (never serialized, ignored by equality).

use crate::beta::{SHORTCUT_MARGIN, cantelli, decide_exact};

/// Node spacing in `α` (a power of two, so node positions are exact).
const H: f64 = 1.0 / 32.0;
/// Number of nodes: `α ∈ [0, 64]`. Larger `α` (many corrections) is left to the Cantelli
/// bound and statrs.
const N_NODES: usize = 64 * 32 + 1;
/// Bracket search gives up beyond this `β` (leaving `β_hi = ∞`, a vacuous certificate).
const B_CAP: f64 = 1e7;

/// The cache: per node `[β_lo, β_hi]`, or `None` before first use.
#[derive(Clone, Debug, Default)]
pub(crate) struct Boundary {
    nodes: Vec<Option<[f64; 2]>>,
}

/// Statrs classification of one point with margin `M`.
enum Side {
    Low,
    High,
    Unsure,
}

fn classify(alpha: f64, beta: f64, mu_c: f64, gamma_c: f64) -> Side {
    match statrs::function::beta::checked_beta_reg(alpha, beta, mu_c) {
        Ok(v) if v <= gamma_c - SHORTCUT_MARGIN => Side::Low,
        Ok(v) if v >= gamma_c + SHORTCUT_MARGIN => Side::High,
        _ => Side::Unsure,
    }
}

/// Brackets `B*(alpha)`; `β_lo = 0` and `β_hi = ∞` are the vacuous certificates (`β > 0`
/// always).
fn bracket(alpha: f64, mu_c: f64, gamma_c: f64) -> [f64; 2] {
    let (mut lo, mut hi) = (0.0_f64, f64::INFINITY);
    // Exponential search upwards.
    let mut b = 0.25;
    while b <= B_CAP {
        match classify(alpha, b, mu_c, gamma_c) {
            Side::Low => lo = b,
            Side::High => {
                hi = b;
                break;
            }
            Side::Unsure => break,
        }
        b *= 2.0;
    }
    if !hi.is_finite() {
        return [lo, hi];
    }
    // Bisection down to a relative width of 1e-3 (narrower than the band between
    // neighbouring nodes, so finer would not help).
    while hi - lo > 1e-3 * hi {
        let mid = 0.5 * (lo + hi);
        match classify(alpha, mid, mu_c, gamma_c) {
            Side::Low => lo = mid,
            Side::High => hi = mid,
            Side::Unsure => break,
        }
    }
    [lo, hi]
}

impl Boundary {
    fn node(&mut self, k: usize, mu_c: f64, gamma_c: f64) -> [f64; 2] {
        if self.nodes.is_empty() {
            self.nodes = vec![None; N_NODES];
        }
        *self.nodes[k].get_or_insert_with(|| {
            // k = 0 is alpha = 0, where I = 1 for every beta: only the (vacuous) low side.
            if k == 0 {
                [0.0, f64::INFINITY]
            } else {
                bracket(k as f64 * H, mu_c, gamma_c)
            }
        })
    }

    /// Eq. 12 for `Beta(alpha, beta)` (finite, > 0): identical to [`decide_exact`].
    pub(crate) fn decide(&mut self, alpha: f64, beta: f64, mu_c: f64, gamma_c: f64) -> bool {
        if let Some(high) = cantelli(alpha, beta, mu_c, gamma_c) {
            return high;
        }
        let pos = alpha / H;
        if pos < (N_NODES - 1) as f64 {
            // 0 <= pos < N_NODES - 1, so k and k + 1 are valid nodes and
            // alpha_k <= alpha < alpha_{k+1} exactly (H is a power of two).
            let k = pos as usize;
            // beta > 0, so the vacuous beta_lo = 0 never matches.
            if beta <= self.node(k, mu_c, gamma_c)[0] {
                return false;
            }
            if beta >= self.node(k + 1, mu_c, gamma_c)[1] {
                return true;
            }
        }
        decide_exact(alpha, beta, mu_c, gamma_c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brackets_straddle_the_threshold() {
        let (mu_c, gamma_c) = (0.05, 0.95);
        for k in [1, 10, 64, 128, 130, 1000, 4096] {
            let a = k as f64 * H;
            let [lo, hi] = bracket(a, mu_c, gamma_c);
            assert!(lo < hi && hi.is_finite(), "{a}: {lo} {hi}");
            assert!(hi - lo <= 1e-3 * hi, "{a}: {lo} {hi}");
            if lo > 0.0 {
                assert!(statrs::function::beta::beta_reg(a, lo, mu_c) <= gamma_c - SHORTCUT_MARGIN);
            }
            assert!(statrs::function::beta::beta_reg(a, hi, mu_c) >= gamma_c + SHORTCUT_MARGIN);
        }
        // alpha = 2: the worked example's boundary lies between beta = 91 and 92.
        let [lo, hi] = bracket(2.0, mu_c, gamma_c);
        assert!(lo > 91.0 && hi <= 92.0, "{lo} {hi}");
    }

    #[test]
    fn cached_decisions_equal_statrs() {
        for (mu_c, gamma_c) in [(0.05, 0.95), (0.2, 0.6)] {
            let mut cache = Boundary::default();
            for i in 0..300 {
                let alpha = 0.013 + 0.0113 * f64::from(i);
                for j in 0..300 {
                    let beta = 0.5 + 0.37 * f64::from(j);
                    assert_eq!(
                        cache.decide(alpha, beta, mu_c, gamma_c),
                        decide_exact(alpha, beta, mu_c, gamma_c),
                        "alpha {alpha} beta {beta}"
                    );
                }
            }
        }
    }
}
