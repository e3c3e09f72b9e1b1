//! Shared generators for the integration tests; the operator policies are
//! `tandem_realtime::adversary`'s.
#![allow(
    dead_code,
    unreachable_pub,
    reason = "shared by several test crates, each using a different subset"
)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_realtime::adversary::{Adversary, SET_SIZE, adversary_set, run_adversary};
use tandem_realtime::{Coordinator, Timeline};

/// A random two-robot problem: shared confidence and bounds, one execution warp per robot.
#[derive(Clone, Debug)]
pub struct Problem {
    pub conf: Vec<bool>,
    pub mean: Vec<f64>,
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
    pub exec: [Vec<f64>; 2],
    pub dt_s: f64,
}

impl Problem {
    /// Random problem: T_ref in 20..=300, 1–8 LC regions, bounds with zero-flexibility stretches.
    pub fn random(rng: &mut ChaCha8Rng) -> Problem {
        let n = rng.random_range(20..=300usize);
        let dt_s = [0.01, 0.1, 1.0][rng.random_range(0..3)];
        let mut conf = vec![true; n];
        let k = rng.random_range(1..=8usize);
        let max_len = (n / (2 * k)).max(1);
        for _ in 0..k {
            let len = rng.random_range(1..=max_len);
            let start = rng.random_range(0..n);
            for c in conf.iter_mut().skip(start).take(len) {
                *c = false;
            }
        }
        let mut mean = Vec::with_capacity(n);
        let mut lo = Vec::with_capacity(n);
        let mut hi = Vec::with_capacity(n);
        for _ in 0..n {
            let m: f64 = rng.random_range(0.5..2.0);
            mean.push(m);
            lo.push(m * rng.random_range(0.25..=1.0));
            hi.push(m * rng.random_range(1.0..=3.0));
        }
        // Zero-flexibility stretches: ψ̇min = ψ̇max = mean.
        for _ in 0..rng.random_range(0..=3usize) {
            let len = rng.random_range(1..=(n / 4).max(1));
            let start = rng.random_range(0..n);
            let end = (start + len).min(n);
            lo[start..end].copy_from_slice(&mean[start..end]);
            hi[start..end].copy_from_slice(&mean[start..end]);
        }
        let exec = [0, 1].map(|_| {
            (0..n)
                .map(|i| {
                    if conf[i] && lo[i] < hi[i] {
                        rng.random_range(lo[i]..=hi[i])
                    } else {
                        mean[i]
                    }
                })
                .collect()
        });
        Problem {
            conf,
            mean,
            lo,
            hi,
            exec,
            dt_s,
        }
    }

    pub fn timeline(&self, robot: usize, start_s: f64) -> Timeline {
        Timeline::new(
            &self.conf,
            &self.exec[robot],
            &self.lo,
            &self.hi,
            start_s,
            self.dt_s,
        )
        .expect("generated timelines are valid")
    }

    /// Both timelines, robot 1 starting at 0 and robot 2 at `tau`.
    pub fn robots(&self, tau: f64) -> [Timeline; 2] {
        [self.timeline(0, 0.0), self.timeline(1, tau)]
    }

    /// `|ψ_E1|` (s).
    pub fn duration0(&self) -> f64 {
        self.timeline(0, 0.0).end_s()
    }
}

pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

impl Problem {
    /// `[min ψ̇min, max ψ̇max]` over the reference: the range random adversaries draw from.
    pub fn grad_range(&self) -> [f64; 2] {
        [
            self.lo.iter().copied().fold(f64::INFINITY, f64::min),
            self.hi.iter().copied().fold(0.0, f64::max),
        ]
    }
}

/// The full adversary set of `tandem_realtime::adversary` for this problem at tick `tick_s`
/// (random parameters from `rng`).
pub fn adversaries(
    problem: &Problem,
    robots: &[Timeline; 2],
    tick_s: f64,
    rng: &mut ChaCha8Rng,
) -> [Adversary; SET_SIZE] {
    let ticks = (robots[1].end_s().max(robots[0].end_s()) / tick_s).ceil() as u64;
    adversary_set(problem.grad_range(), ticks, rng)
}

/// Runs every adversary to the end; returns the first (adversary, tick) at which both robots
/// were low-confidence. Panics if an execution does not finish within a generous budget.
pub fn find_overlap(
    robots: &[Timeline; 2],
    tick_s: f64,
    adversaries: &[Adversary],
    rng: &mut ChaCha8Rng,
) -> Option<(Adversary, u64)> {
    let total =
        robots[0].end_s().max(robots[1].end_s()) - robots[0].start_s().min(robots[1].start_s());
    // Slowest rate is ≥ 1/12 here (ψ̇_E ≥ ψ̇max/12 for the generated bounds) — be generous.
    let budget = (total / tick_s * 40.0).ceil() as u64 + 100;
    for &a in adversaries {
        let c = Coordinator::new(robots.clone(), tick_s).expect("valid tick");
        let run = run_adversary(c, a, rng, budget).expect("admissible adversaries");
        assert!(run.finished, "coordinator did not finish under {a:?}");
        if let Some(k) = run.first_overlap {
            return Some((a, k));
        }
    }
    None
}
