//! Random problems and runs under the adversary set, shared by the runtime safety tests
//! (`coordinator_safety.rs` for two robots, `robots.rs` for N).

use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_realtime::Coordinator;
use tandem_realtime::adversary::{Adversary, adversary_set, run_adversary};
use tandem_schedule::{Problem, Schedule};

use crate::common;

/// Tick budget of one execution: every robot at its slowest, run serially, twice over.
fn max_ticks(p: &Problem, s: &Schedule) -> u64 {
    let slowest_s: f64 = p.grad_max().iter().sum::<f64>() * p.dt_s();
    (slowest_s * 2.0 * s.n_robots() as f64 / s.tick_s) as u64 + 100
}

/// The full adversary set for `s` (its `N` robots) on `p`, its random parameters from `seed`.
pub(crate) fn adversaries(p: &Problem, s: &Schedule, seed: u64) -> Vec<Adversary> {
    let lo = p.grad_min().iter().copied().fold(f64::INFINITY, f64::min);
    let hi = p.grad_max().iter().copied().fold(0.0, f64::max);
    let ticks = (s.t_total_s(p.dt_s()) / s.tick_s) as u64;
    adversary_set(
        s.n_robots(),
        [lo, hi],
        ticks,
        &mut ChaCha8Rng::seed_from_u64(seed),
    )
}

/// Runs one execution at the schedule's tick; returns the first tick with two robots
/// low-confidence (a robot counts as low-confidence in a tick when any reference sample it
/// traverses in it is).
pub(crate) fn run(p: &Problem, s: &Schedule, op: Adversary, seed: u64) -> Option<u64> {
    let c = s.check(p).unwrap().coordinator().unwrap();
    run_coordinator(p, s, c, op, seed)
}

/// [`run`] for a schedule that fails the check (the non-vacuity tests): its plans run without
/// it, as `Coordinator::new_unchecked` allows; the adversary loop releases the robot the
/// fault monitor holds, so the run goes on past the first overlap.
pub(crate) fn run_unchecked(p: &Problem, s: &Schedule, op: Adversary, seed: u64) -> Option<u64> {
    let c = Coordinator::new_unchecked(s.timelines(p).unwrap(), s.tick_s).unwrap();
    run_coordinator(p, s, c, op, seed)
}

fn run_coordinator(
    p: &Problem,
    s: &Schedule,
    c: Coordinator,
    op: Adversary,
    seed: u64,
) -> Option<u64> {
    assert_eq!(c.tick_s(), s.tick_s);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let max_ticks = max_ticks(p, s);
    let r = run_adversary(c, op, &mut rng, max_ticks).unwrap();
    assert!(
        r.finished,
        "execution did not finish within {max_ticks} ticks"
    );
    r.first_overlap
}

/// Random small problems: confidence in `1..max_blocks` runs of `1..max_len` samples (HC
/// runs about twice as likely), random means and bounds per sample ([`common::gradients`]).
pub(crate) fn random_problem(max_len: usize, max_blocks: usize) -> impl Strategy<Value = Problem> {
    proptest::collection::vec((1usize..max_len, prop::bool::weighted(0.65)), 1..max_blocks)
        .prop_flat_map(|blocks| {
            let conf: Vec<bool> = blocks
                .iter()
                .flat_map(|&(len, hc)| std::iter::repeat_n(hc, len))
                .collect();
            let n = conf.len();
            (Just(conf), common::gradients(n))
        })
        .prop_map(|(conf, g)| common::problem(conf, &g))
}
