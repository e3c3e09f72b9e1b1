//! Adversarial operators for testing schedules against the safety invariant (DESIGN.md: for
//! every accepted schedule and every admissible operator rate sequence, the robots are never
//! both low-confidence in one tick).
//!
//! An [`Adversary`] is the gradient the operator commands each control tick; the
//! [`Coordinator`] clamps it to the low-confidence robot's `[ψ̇min, ψ̇max]` at that sample, so
//! [`FASTEST`] and [`SLOWEST`] stand for "as fast / as slow as admissible" everywhere.
//! [`run_adversary`] runs one execution under one adversary and counts the ticks with both
//! robots low-confidence.
//!
//! ```
//! use rand::SeedableRng;
//! use tandem_realtime::adversary::{Adversary, run_adversary};
//! use tandem_realtime::{Coordinator, Timeline};
//!
//! let conf = [true, false, false, true, true, true];
//! let (mean, lo, hi) = ([1.0; 6], [0.8; 6], [1.25; 6]);
//! let robots = [
//!     Timeline::new(&conf, &mean, &lo, &hi, 0.0, 0.1)?,
//!     Timeline::new(&conf, &mean, &lo, &hi, 0.45, 0.1)?,
//! ];
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! let adversary = Adversary::RandomSwitching { max_hold: 5 };
//! let run = run_adversary(Coordinator::new(robots, 0.05)?, adversary, &mut rng, 1000);
//! assert!(run.finished && run.overlap_ticks == 0 && run.first_overlap.is_none());
//! # Ok::<(), tandem_realtime::Error>(())
//! ```

use rand::Rng;

use crate::Coordinator;

/// A gradient far below every `ψ̇min`: the coordinator clamps it to the fastest admissible.
pub const FASTEST: f64 = 0.0;
/// A gradient far above every `ψ̇max`: the coordinator clamps it to the slowest admissible.
pub const SLOWEST: f64 = 1e9;

/// An operator policy: which gradient (execution samples per reference sample) the operator
/// commands at each control tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Adversary {
    /// Always [`FASTEST`] (rushing).
    Fastest,
    /// Always [`SLOWEST`] (dragging).
    Slowest,
    /// [`FASTEST`] on even ticks, [`SLOWEST`] on odd ones.
    Switching,
    /// Holds one extreme for a uniform `1..=max_hold` ticks, then switches to the other
    /// (starting with [`SLOWEST`]). `max_hold ≥ 1`.
    RandomSwitching {
        /// Longest hold, ticks.
        max_hold: u32,
    },
    /// A fresh gradient uniform in `[lo, hi]` every tick (choose a range covering the bounds).
    Random {
        /// Lowest gradient.
        lo: f64,
        /// Highest gradient.
        hi: f64,
    },
    /// A gradient uniform in `[lo, hi]` held for a uniform `1..=max_hold` ticks.
    RandomHeld {
        /// Lowest gradient.
        lo: f64,
        /// Highest gradient.
        hi: f64,
        /// Longest hold, ticks (≥ 1).
        max_hold: u32,
    },
}

/// What one execution under an [`Adversary`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AdversaryRun {
    /// Control ticks run.
    pub ticks: u64,
    /// Ticks in which both robots traversed a low-confidence sample (0 for a safe schedule).
    pub overlap_ticks: u64,
    /// Index of the first such tick.
    pub first_overlap: Option<u64>,
    /// Whether both robots finished within the tick budget.
    pub finished: bool,
}

/// Uniform in `[lo, hi]`; `lo` itself when the range is empty or not finite.
fn uniform(rng: &mut impl Rng, lo: f64, hi: f64) -> f64 {
    if lo < hi && lo.is_finite() && hi.is_finite() {
        rng.random_range(lo..=hi)
    } else {
        lo
    }
}

/// Runs `coordinator` to the end (or for at most `max_ticks` ticks) with the operator
/// gradients of `adversary`, drawing from `rng` (deterministic for its state).
pub fn run_adversary(
    mut coordinator: Coordinator,
    adversary: Adversary,
    rng: &mut impl Rng,
    max_ticks: u64,
) -> AdversaryRun {
    let mut run = AdversaryRun::default();
    let (mut hold, mut current) = (0u32, FASTEST);
    while !coordinator.is_finished() {
        if run.ticks >= max_ticks {
            return run;
        }
        let g = match adversary {
            Adversary::Fastest => FASTEST,
            Adversary::Slowest => SLOWEST,
            Adversary::Switching => {
                if run.ticks % 2 == 0 {
                    FASTEST
                } else {
                    SLOWEST
                }
            }
            Adversary::RandomSwitching { max_hold } => {
                if hold == 0 {
                    current = if current == FASTEST { SLOWEST } else { FASTEST };
                    hold = rng.random_range(1..=max_hold.max(1));
                }
                hold -= 1;
                current
            }
            Adversary::Random { lo, hi } => uniform(rng, lo, hi),
            Adversary::RandomHeld { lo, hi, max_hold } => {
                if hold == 0 {
                    current = uniform(rng, lo, hi);
                    hold = rng.random_range(1..=max_hold.max(1));
                }
                hold -= 1;
                current
            }
        };
        let tick = coordinator.tick(g);
        if tick.low_conf[0] && tick.low_conf[1] {
            run.first_overlap.get_or_insert(run.ticks);
            run.overlap_ticks += 1;
        }
        run.ticks += 1;
    }
    run.finished = true;
    run
}
