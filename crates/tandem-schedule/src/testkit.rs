//! Test kit (feature `testkit`, for tests and `cargo xtask stress`; never for production): the
//! one random scheduling [`Problem`] generator of the workspace's property tests and stress
//! runs, and the hold points they place on it.
//!
//! The draws are part of the contract: a test's cases, and the `proptest-regressions` files
//! that name them by seed, depend on the exact sequence of values drawn from the generator's
//! random stream, so [`random_problem`] must keep drawing the same values in the same order.

use std::ops::{Range, RangeInclusive};

use rand::Rng;

use crate::error::Result;
use crate::problem::Problem;

/// A random problem of `n_ref` reference samples (drawn uniformly from `n_ref`) at period
/// `dt_s` (s): alternating high- and low-confidence runs (the first one's kind drawn fair),
/// high-confidence runs of 5–80 samples and low-confidence runs of 5–60 (the last one cut
/// at `T_ref`), a demonstrated mean gradient `ψ̇mean = 1 + ½·sin(f·n + φ)` (`f` in
/// `[0.01, 0.2)`, `φ` in `[0, 6.3)`, drawn once) and per run the bounds
/// `[lo·ψ̇mean, hi·ψ̇mean]` with `lo` in `[0.3, 1)` and `hi` in `[1, 2.5)`. No hold points
/// ([`hold_points`] places some).
///
/// Draws, in this order: `T_ref`, the first run's kind, `f`, `φ`, then per run its length,
/// `lo` and `hi`.
///
/// # Errors
/// As [`Problem::new`] for a `dt_s` that is not finite and > 0, or an empty `n_ref`.
pub fn random_problem(
    rng: &mut impl Rng,
    n_ref: RangeInclusive<usize>,
    dt_s: f64,
) -> Result<Problem> {
    random_problem_shaped(rng, n_ref, dt_s, &ProblemShape::default())
}

/// The shape of [`random_problem_shaped`]'s problems: the lengths (samples) of the high- and
/// low-confidence runs, the frequency `f` (per sample) of the mean gradient
/// `ψ̇mean = 1 + ½·sin(f·n + φ)`, and the per-run bound factors `lo` (`ψ̇min = lo·ψ̇mean`) and
/// `hi` (`ψ̇max = hi·ψ̇mean`). The default is [`random_problem`]'s.
#[derive(Clone, Debug, PartialEq)]
pub struct ProblemShape {
    /// Length of a high-confidence run (samples). Default 5–80.
    pub hc_run: RangeInclusive<usize>,
    /// Length of a low-confidence run (samples). Default 5–60.
    pub lc_run: RangeInclusive<usize>,
    /// Frequency `f` of the mean gradient (rad per sample). Default `[0.01, 0.2)`.
    pub freq: Range<f64>,
    /// Factor `lo` of `ψ̇min` per run. Default `[0.3, 1)`.
    pub lo: Range<f64>,
    /// Factor `hi` of `ψ̇max` per run. Default `[1, 2.5)`.
    pub hi: Range<f64>,
}

impl Default for ProblemShape {
    fn default() -> Self {
        ProblemShape {
            hc_run: 5..=80,
            lc_run: 5..=60,
            freq: 0.01..0.2,
            lo: 0.3..1.0,
            hi: 1.0..2.5,
        }
    }
}

/// [`random_problem`] of another `shape`: the same draws in the same order, from the shape's
/// ranges (`φ` stays in `[0, 6.3)`).
///
/// # Errors
/// As [`random_problem`]; also for bound factors that do not keep `ψ̇min ≤ ψ̇mean ≤ ψ̇max`.
///
/// # Panics
/// On an empty range of `n_ref` or of the shape (the generator draws from each).
pub fn random_problem_shaped(
    rng: &mut impl Rng,
    n_ref: RangeInclusive<usize>,
    dt_s: f64,
    shape: &ProblemShape,
) -> Result<Problem> {
    let n_ref = rng.random_range(n_ref);
    let (mut conf, mut mean, mut min, mut max) = (vec![], vec![], vec![], vec![]);
    let mut hc = rng.random_bool(0.5);
    let (freq, phase) = (
        rng.random_range(shape.freq.clone()),
        rng.random_range(0.0..6.3),
    );
    while conf.len() < n_ref {
        let len = if hc {
            rng.random_range(shape.hc_run.clone())
        } else {
            rng.random_range(shape.lc_run.clone())
        };
        let (lo, hi) = (
            rng.random_range(shape.lo.clone()),
            rng.random_range(shape.hi.clone()),
        );
        for _ in 0..len.min(n_ref - conf.len()) {
            let m = 1.0 + 0.5 * (freq * conf.len() as f64 + phase).sin();
            conf.push(hc);
            mean.push(m);
            min.push(lo * m);
            max.push(hi * m);
        }
        hc = !hc;
    }
    Problem::new(conf, mean, min, max, dt_s)
}

/// Hold points for a problem of confidence `conf` (`true` = high): the middle sample
/// `⌊(start + end) / 2⌋` of every high-confidence run `start..end` of at least three samples,
/// in task order.
#[must_use]
pub fn hold_points(conf: &[bool]) -> Vec<usize> {
    let mut out = Vec::new();
    let mut start = 0;
    for n in 1..=conf.len() {
        if n == conf.len() || conf[n] != conf[start] {
            if conf[start] && n - start >= 3 {
                out.push((start + n) / 2);
            }
            start = n;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    use super::*;

    #[test]
    fn hold_points_sit_mid_run_on_runs_of_three_or_more() {
        // HC runs 0..3 (middle 1), 5..6 (too short), 7..11 (middle 9); LC elsewhere.
        let conf = [
            true, true, true, false, false, true, false, true, true, true, true,
        ];
        assert_eq!(hold_points(&conf), vec![1, 9]);
        assert!(hold_points(&[]).is_empty());
        assert_eq!(hold_points(&[false, false, false]), Vec::<usize>::new());
    }

    /// The problem's runs of one confidence in order: (high confidence, length).
    fn runs(p: &Problem) -> Vec<(bool, usize)> {
        p.conf()
            .chunk_by(|a, b| a == b)
            .map(|r| (r[0], r.len()))
            .collect()
    }

    #[test]
    fn random_problems_alternate_runs_within_their_bounds_and_repeat_for_a_seed() {
        for seed in 0..20 {
            let p = random_problem(&mut ChaCha8Rng::seed_from_u64(seed), 200..=400, 0.01).unwrap();
            assert!((200..=400).contains(&p.n_ref()), "{}", p.n_ref());
            assert_eq!(p.dt_s(), 0.01);
            // Runs of one kind are 5–80 (HC) or 5–60 (LC) samples, the last one cut.
            let runs = runs(&p);
            for (k, &(hc, len)) in runs.iter().enumerate() {
                let most = if hc { 80 } else { 60 };
                assert!(len <= most && (len >= 5 || k + 1 == runs.len()), "{runs:?}");
            }
            for n in 0..p.n_ref() {
                let (lo, m, hi) = (p.grad_min()[n], p.grad_mean()[n], p.grad_max()[n]);
                assert!((0.5..=1.5).contains(&m), "{m}");
                assert!(
                    0.3 * m <= lo && lo < m && m <= hi && hi < 2.5 * m,
                    "{lo} {m} {hi}"
                );
            }
            let again =
                random_problem(&mut ChaCha8Rng::seed_from_u64(seed), 200..=400, 0.01).unwrap();
            assert_eq!(again.conf(), p.conf());
            assert_eq!(again.grad_max(), p.grad_max());
        }
        assert!(random_problem(&mut ChaCha8Rng::seed_from_u64(0), 10..=10, 0.0).is_err());
    }

    #[test]
    fn a_shaped_problem_keeps_its_shape_and_the_default_is_random_problem() {
        let shape = ProblemShape {
            hc_run: 50..=80,
            lc_run: 20..=30,
            freq: 0.001..0.002,
            lo: 0.3..0.4,
            hi: 2.0..2.5,
        };
        for seed in 0..10 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let p = random_problem_shaped(&mut rng, 500..=600, 0.02, &shape).unwrap();
            assert!((500..=600).contains(&p.n_ref()) && p.dt_s() == 0.02);
            let runs = runs(&p);
            for (k, &(hc, len)) in runs.iter().enumerate() {
                let range = if hc { 50..=80 } else { 20..=30 };
                assert!(
                    range.contains(&len) || (k + 1 == runs.len() && len <= *range.end()),
                    "{runs:?}"
                );
            }
            for n in 0..p.n_ref() {
                let (lo, m, hi) = (p.grad_min()[n], p.grad_mean()[n], p.grad_max()[n]);
                assert!(0.3 * m <= lo && lo < 0.4 * m, "{lo} {m}");
                assert!(2.0 * m <= hi && hi < 2.5 * m, "{hi} {m}");
            }
            // The default shape draws what `random_problem` draws.
            let a = random_problem(&mut ChaCha8Rng::seed_from_u64(seed), 200..=400, 0.01);
            let b = random_problem_shaped(
                &mut ChaCha8Rng::seed_from_u64(seed),
                200..=400,
                0.01,
                &ProblemShape::default(),
            );
            let (a, b) = (a.unwrap(), b.unwrap());
            assert_eq!((a.conf(), a.grad_min()), (b.conf(), b.grad_min()));
        }
    }
}
