//! Shared generators for the integration tests; the operator policies are
//! `tandem_realtime::adversary`'s.
#![allow(
    dead_code,
    unreachable_pub,
    reason = "shared by several test crates, each using a different subset"
)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_realtime::adversary::{Adversary, adversary_set, run_adversary};
use tandem_realtime::{Coordinator, Timeline};

/// A random problem: shared confidence and bounds, one execution warp per robot.
#[derive(Clone, Debug)]
pub struct Problem {
    pub conf: Vec<bool>,
    pub mean: Vec<f64>,
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
    pub exec: Vec<Vec<f64>>,
    pub dt_s: f64,
}

impl Problem {
    /// Random two-robot problem: T_ref in 20..=300, 1–8 LC regions, bounds with
    /// zero-flexibility stretches.
    pub fn random(rng: &mut ChaCha8Rng) -> Problem {
        Problem::random_n(rng, 2)
    }

    /// [`Problem::random`] with `n_robots` execution warps (the same draws for the first two).
    pub fn random_n(rng: &mut ChaCha8Rng, n_robots: usize) -> Problem {
        Problem::random_with(rng, n_robots, false)
    }

    /// [`Problem::random_n`] where, with `styled`, each robot's high-confidence gradients
    /// follow a style drawn per robot: uniform in the bounds per sample (as unstyled), all at
    /// `ψ̇min` (fastest: `F = 1`, no room to speed up), all at `ψ̇max` (slowest: `S = 1`, no room
    /// to slow down), or one uniform draw per high-confidence run. Robots of different styles
    /// track a common pace differently over whole stretches (systematic drift).
    pub fn random_styled(rng: &mut ChaCha8Rng, n_robots: usize) -> Problem {
        Problem::random_with(rng, n_robots, true)
    }

    /// A random problem of a few long low-confidence regions: 1–4 LC regions of 1–30 samples
    /// separated by HC stretches of 3–60 samples, bounds a common factor `[¼…1, 1…3]` of a mean
    /// gradient in `[0.8, 1.25]`, and per robot and HC run a gradient fraction of the bounds that
    /// is kept or, with probability ½ at each run, redrawn from {fastest, slowest, uniform}: long
    /// stretches in which robots track a common pace differently.
    pub fn random_structured(rng: &mut ChaCha8Rng, n_robots: usize) -> Problem {
        let dt_s = [0.01, 0.1, 1.0][rng.random_range(0..3)];
        let mut conf = Vec::new();
        for _ in 0..rng.random_range(1..=4) {
            let gap = rng.random_range(3..=60);
            conf.extend(std::iter::repeat_n(true, gap));
            let len = rng.random_range(1..=30);
            conf.extend(std::iter::repeat_n(false, len));
        }
        let tail = rng.random_range(0..=30);
        conf.extend(std::iter::repeat_n(true, tail));
        let n = conf.len();
        let (lo_f, hi_f) = (rng.random_range(0.25..=1.0), rng.random_range(1.0..=3.0));
        let mean: Vec<f64> = (0..n).map(|_| rng.random_range(0.8..1.25)).collect();
        let lo: Vec<f64> = mean.iter().map(|m| m * lo_f).collect();
        let hi: Vec<f64> = mean.iter().map(|m| m * hi_f).collect();
        let exec = (0..n_robots)
            .map(|_| {
                let mut frac: f64 = rng.random();
                (0..n)
                    .map(|i| {
                        if i > 0 && conf[i] != conf[i - 1] && rng.random_bool(0.5) {
                            frac = [0.0, 1.0, rng.random()][rng.random_range(0..3)];
                        }
                        if conf[i] {
                            lo[i] + frac * (hi[i] - lo[i])
                        } else {
                            mean[i]
                        }
                    })
                    .collect()
            })
            .collect();
        Problem {
            conf,
            mean,
            lo,
            hi,
            exec,
            dt_s,
        }
    }

    fn random_with(rng: &mut ChaCha8Rng, n_robots: usize, styled: bool) -> Problem {
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
        let exec = (0..n_robots)
            .map(|_| {
                let style = if styled { rng.random_range(0..4u8) } else { 0 };
                let mut run_frac: f64 = if styled { rng.random() } else { 0.0 };
                (0..n)
                    .map(|i| {
                        if i > 0 && conf[i] != conf[i - 1] && styled {
                            run_frac = rng.random();
                        }
                        if !(conf[i] && lo[i] < hi[i]) {
                            mean[i]
                        } else {
                            match style {
                                1 => lo[i],
                                2 => hi[i],
                                3 => lo[i] + run_frac * (hi[i] - lo[i]),
                                _ => rng.random_range(lo[i]..=hi[i]),
                            }
                        }
                    })
                    .collect()
            })
            .collect();
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

    /// Every robot's timeline, robot `i` starting at `starts_s[i]`.
    pub fn robots_at(&self, starts_s: &[f64]) -> Vec<Timeline> {
        starts_s
            .iter()
            .enumerate()
            .map(|(i, &s)| self.timeline(i, s))
            .collect()
    }

    /// `|ψ_E1|` (s).
    pub fn duration0(&self) -> f64 {
        self.timeline(0, 0.0).end_s()
    }

    /// A problem of `n_robots` from the two families in turn ([`Problem::random_styled`] for
    /// an even `seed`, [`Problem::random_structured`] for an odd one) and a control tick of
    /// ¼ to 1½ reference samples (s), drawn from `rng` in that order.
    pub fn random_alternating(rng: &mut ChaCha8Rng, n_robots: usize, seed: u64) -> (Problem, f64) {
        let problem = if seed % 2 == 0 {
            Problem::random_styled(rng, n_robots)
        } else {
            Problem::random_structured(rng, n_robots)
        };
        let tick_s = problem.dt_s * rng.random_range(0.25..=1.5);
        (problem, tick_s)
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

/// Latest end (s) of any robot.
fn last_end_s(robots: &[Timeline]) -> f64 {
    robots.iter().map(Timeline::end_s).fold(0.0, f64::max)
}

/// The full adversary set of `tandem_realtime::adversary` for this problem and these robots at
/// tick `tick_s` (random parameters from `rng`).
pub fn adversaries(
    problem: &Problem,
    robots: &[Timeline],
    tick_s: f64,
    rng: &mut ChaCha8Rng,
) -> Vec<Adversary> {
    let ticks = (last_end_s(robots) / tick_s).ceil() as u64;
    adversary_set(robots.len(), problem.grad_range(), ticks, rng)
}

/// Runs every adversary to the end; returns the first (adversary, tick) at which two robots
/// were low-confidence. Panics if an execution does not finish within a generous budget.
pub fn find_overlap(
    robots: &[Timeline],
    tick_s: f64,
    adversaries: &[Adversary],
    rng: &mut ChaCha8Rng,
) -> Option<(Adversary, u64)> {
    let first_start = robots
        .iter()
        .map(Timeline::start_s)
        .fold(f64::INFINITY, f64::min);
    let total = last_end_s(robots) - first_start;
    // Slowest rate is ≥ 1/12 here (ψ̇_E ≥ ψ̇max/12 for the generated bounds) — be generous.
    let budget = (total / tick_s * 40.0).ceil() as u64 + 100;
    for &a in adversaries {
        let c = Coordinator::new(robots.to_vec(), tick_s).expect("valid tick");
        let run = run_adversary(c, a, rng, budget).expect("admissible adversaries");
        assert!(run.finished, "coordinator did not finish under {a:?}");
        if let Some(k) = run.first_overlap {
            return Some((a, k));
        }
    }
    None
}

/// A margin check of `tandem_realtime` (the conservative one or a baseline).
pub type Check = fn(&[Timeline], f64) -> tandem_realtime::Result<bool>;

/// A tight schedule of `n` robots accepted by `check`: robot 0 at 0; robot `i` at the earliest
/// of 6 random offsets in `[0, E_i]` and `E_i` (the latest end of the robots before it: a serial
/// start) that `check` accepts with robots `0..=i`, bisected 10 times towards the last rejected
/// offset. Returns the starts and whether some robot starts before its `E_i` (executions
/// overlap), or `None` if even a serial start is rejected.
pub fn tight_schedule(
    problem: &Problem,
    n: usize,
    tick_s: f64,
    check: Check,
    r: &mut ChaCha8Rng,
) -> Option<(Vec<f64>, bool)> {
    let mut starts = vec![0.0];
    let mut overlapping = false;
    for _ in 1..n {
        let latest_end = last_end_s(&problem.robots_at(&starts));
        let mut taus: Vec<f64> = (0..6)
            .map(|_| latest_end * r.random::<f64>().sqrt())
            .collect();
        taus.push(latest_end);
        taus.sort_by(f64::total_cmp);
        let accepts = |t: f64, starts: &mut Vec<f64>| {
            starts.push(t);
            let ok = check(&problem.robots_at(starts), tick_s).expect("valid tick");
            starts.pop();
            ok
        };
        let k = taus.iter().position(|&t| accepts(t, &mut starts))?;
        let mut tau = taus[k];
        if k > 0 {
            let mut lo = taus[k - 1];
            for _ in 0..10 {
                let m = 0.5 * (lo + tau);
                if accepts(m, &mut starts) {
                    tau = m;
                } else {
                    lo = m;
                }
            }
        }
        overlapping |= tau < latest_end;
        starts.push(tau);
    }
    Some((starts, overlapping))
}
