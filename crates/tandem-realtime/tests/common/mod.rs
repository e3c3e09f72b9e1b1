//! Shared generators and operator policies for the integration tests.
#![allow(
    dead_code,
    unreachable_pub,
    reason = "shared by several test crates, each using a different subset"
)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_realtime::{Coordinator, Tick, Timeline};

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

/// An operator policy: picks the operator gradient for the next tick from the coordinator's
/// state (which robot is low-confidence at its current sample).
#[derive(Clone, Copy, Debug)]
pub enum Policy {
    /// Always the fastest gradient (clamped to ψ̇min).
    Fastest,
    /// Always the slowest gradient (clamped to ψ̇max).
    Slowest,
    /// Always the scheduled gradient.
    Nominal,
    /// Uniform random gradient in [0.1, 6] per tick (clamped).
    Uniform,
    /// Fastest or slowest, chosen at random per tick.
    RandomExtreme,
    /// Fastest for `period` ticks, then slowest for `period` ticks, from phase `phase`.
    Periodic { period: u32, phase: u32 },
    /// Fastest until tick `at`, slowest after (or the reverse if `rev`).
    SwitchOnce { at: u32, rev: bool },
    /// Rush whichever robot is LC if it is `rush`, drag the other (the worst case of one role).
    RushRobot { rush: usize },
    /// Per-robot extreme chosen at random per LC region entry.
    RandomPerRobot,
}

pub const FAST: f64 = 0.0;
pub const SLOW: f64 = f64::INFINITY;

/// Index of the robot that is low-confidence at its current sample, if any.
pub fn lc_robot(c: &Coordinator) -> Option<usize> {
    let clocks = c.clock_s();
    (0..2).find(|&i| !c.robots()[i].conf_at(clocks[i]))
}

/// Runs the coordinator to completion under `policy`; calls `on_tick` for each tick.
/// Returns the number of ticks. Panics if it does not finish within a generous budget.
pub fn run(
    robots: [Timeline; 2],
    tick_s: f64,
    policy: Policy,
    rng: &mut ChaCha8Rng,
    mut on_tick: impl FnMut(u32, &Tick),
) -> u32 {
    let total =
        robots[0].end_s().max(robots[1].end_s()) - robots[0].start_s().min(robots[1].start_s());
    // Slowest rate is ≥ 1/12 here (ψ̇_E ≥ ψ̇max/12 for the generated bounds) — be generous.
    let budget = (total / tick_s * 40.0).ceil() as u32 + 100;
    let mut c = Coordinator::new(robots, tick_s).expect("valid tick");
    let mut k = 0u32;
    let mut per_robot = [FAST, SLOW];
    let mut last_lc = None;
    while !c.is_finished() {
        assert!(k < budget, "coordinator did not finish");
        let lc = lc_robot(&c);
        let g = match policy {
            Policy::Fastest => FAST,
            Policy::Slowest => SLOW,
            Policy::Nominal => f64::NAN,
            Policy::Uniform => rng.random_range(0.1..6.0),
            Policy::RandomExtreme => {
                if rng.random_bool(0.5) {
                    FAST
                } else {
                    SLOW
                }
            }
            Policy::Periodic { period, phase } => {
                if ((k + phase) / period) % 2 == 0 {
                    FAST
                } else {
                    SLOW
                }
            }
            Policy::SwitchOnce { at, rev } => {
                if (k < at) != rev {
                    FAST
                } else {
                    SLOW
                }
            }
            Policy::RushRobot { rush } => match lc {
                Some(i) if i == rush => FAST,
                _ => SLOW,
            },
            Policy::RandomPerRobot => {
                if lc != last_lc {
                    if let Some(i) = lc {
                        per_robot[i] = if rng.random_bool(0.5) { FAST } else { SLOW };
                    }
                }
                lc.map_or(f64::NAN, |i| per_robot[i])
            }
        };
        last_lc = lc;
        let t = c.tick(g);
        on_tick(k, &t);
        k += 1;
    }
    k
}

/// A varied set of policies for one case (extremes, role-worst-cases and random ones).
pub fn policies(rng: &mut ChaCha8Rng) -> Vec<Policy> {
    vec![
        Policy::Fastest,
        Policy::Slowest,
        Policy::Nominal,
        Policy::RushRobot { rush: 0 },
        Policy::RushRobot { rush: 1 },
        Policy::Uniform,
        Policy::RandomExtreme,
        Policy::RandomPerRobot,
        Policy::Periodic {
            period: rng.random_range(1..=8),
            phase: rng.random_range(0..16),
        },
        Policy::SwitchOnce {
            at: rng.random_range(0..400),
            rev: rng.random_bool(0.5),
        },
    ]
}

/// Runs every policy; returns the first (policy, tick) at which both robots were LC.
pub fn find_overlap(
    robots: &[Timeline; 2],
    tick_s: f64,
    policies: &[Policy],
    rng: &mut ChaCha8Rng,
) -> Option<(Policy, u32)> {
    for &p in policies {
        let mut hit = None;
        run(robots.clone(), tick_s, p, rng, |k, t| {
            if hit.is_none() && t.low_conf[0] && t.low_conf[1] {
                hit = Some(k);
            }
        });
        if let Some(k) = hit {
            return Some((p, k));
        }
    }
    None
}
