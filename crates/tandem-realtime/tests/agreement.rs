//! The single-pass conservative check decides exactly like the per-pair re-simulation.

mod common;

use std::cell::Cell;

use common::{Problem, rng};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use rand::Rng;
use tandem_realtime::{pair_slacks, sufficient_margins, sufficient_margins_per_pair};

#[test]
fn single_pass_equals_per_pair_on_random_schedules() {
    let config = Config {
        cases: 1000,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let counts = Cell::new([0u32; 2]);
    let result = runner.run(&(any::<u64>(), 0.0..=1.0f64), |(seed, frac)| {
        let mut r = rng(seed);
        let problem = Problem::random(&mut r);
        let tick_s = problem.dt_s * r.random_range(0.25..=1.5);
        // Offsets from simultaneous starts to fully serial, biased to the interesting upper half.
        let tau = problem.duration0() * frac.sqrt();
        let robots = problem.robots(tau);
        let single = sufficient_margins(&robots, tick_s).unwrap();
        let per_pair = sufficient_margins_per_pair(&robots, tick_s).unwrap();
        prop_assert_eq!(
            single,
            per_pair,
            "seed {} tau {} tick {}",
            seed,
            tau,
            tick_s
        );
        // The slacks come from the same simulation: all positive exactly when accepted.
        let slacks = pair_slacks(&robots, tick_s).unwrap();
        prop_assert_eq!(
            slacks.iter().all(|s| s.slack_s > 0.0),
            single,
            "slacks {:?}",
            slacks
        );
        let mut c = counts.get();
        c[usize::from(single)] += 1;
        counts.set(c);
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
    let [rejected, accepted] = counts.get();
    assert!(
        rejected >= 100 && accepted >= 100,
        "both decisions must be exercised: {accepted} accepted, {rejected} rejected"
    );
}

/// The fastest serial schedule (`τ = |ψ_E1|`, robot 2 starting at `robots[0].end_s()`) is always
/// accepted: the scheduler's fallback of last resort (`tandem_schedule::Problem::serial_schedule`,
/// fix 4 of docs/decisions.md, "Alg. 2 as printed is not sound on a tick grid").
#[test]
fn serial_schedule_is_always_accepted() {
    let config = Config {
        cases: 500,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    let result = runner.run(&(any::<u64>(), 0.25..=1.5f64), |(seed, tick_frac)| {
        let mut r = rng(seed);
        let problem = Problem::random(&mut r);
        let tick_s = problem.dt_s * tick_frac;
        let robots = problem.robots(problem.duration0());
        prop_assert!(sufficient_margins(&robots, tick_s).unwrap());
        prop_assert!(sufficient_margins_per_pair(&robots, tick_s).unwrap());
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
}
