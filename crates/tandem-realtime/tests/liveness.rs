//! Liveness of rounds with hold points (docs/decisions.md, "Hand-over liveness" for the
//! continuous cell, whose property test is `src/continuous/liveness.rs`; "Hold points: a
//! wait instead of a margin", point 4, for rounds): no robot waits for ever at a hold.
//! A release rule whose awaited leg does not start strictly before the held one is refused
//! when the plans are built, so among the legs not finished the one with the earliest start
//! can always start or move. Tested: random plans of the test kit's families, N = 2…6, with
//! random usable holds, their release rules and random planned dwells, whether the margin
//! check accepts them or not, under every policy of the adversary set: every robot finishes
//! its round, within the ticks of the robots run one after the other at their slowest.

use std::cell::Cell;

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use tandem_realtime::adversary::{Adversary, run_adversary};
use tandem_realtime::testkit::{Family, HeldRound, rng};
use tandem_realtime::{Hold, Timeline};

/// The ticks of the round run serially at the slowest admissible rates: each robot's plan
/// with every sample at `ψ̇max` (the slowest an operator or the strategy can make it), plus
/// the planned dwells and the latest start, plus a tick per leg and robot.
fn serial_bound(robots: &[Timeline], holds: &[Vec<Hold>], tick_s: f64) -> u64 {
    let slow: f64 = robots
        .iter()
        .map(|tl| {
            (0..tl.n_ref())
                .map(|k| tl.grad_max()[k].max(tl.grad_exec()[k]))
                .sum::<f64>()
                * tl.dt_s()
        })
        .sum();
    let dwell: f64 = holds.iter().flatten().map(|h| h.dwell_s).sum();
    let latest = robots.iter().map(Timeline::start_s).fold(0.0, f64::max);
    let legs = holds.iter().map(Vec::len).sum::<usize>() + robots.len();
    ((slow + dwell + latest) / tick_s).ceil() as u64 + 2 * legs as u64 + 2
}

#[test]
fn every_robot_finishes_its_round_with_holds_under_every_adversary() {
    let cases: u32 = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(48);
    for n in 2..=6_usize {
        let (checked, worst) = (Cell::new(0_u32), Cell::new(0.0_f64));
        let config = Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        };
        let mut runner =
            TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha));
        let result = runner.run(&any::<u64>(), |seed| {
            let mut r = rng(seed);
            let round = HeldRound::random(Family::of_seed(seed), n, true, &mut r);
            if !round.has_holds() {
                return Ok(());
            }
            let coordinator = round.coordinator();
            let bound = serial_bound(&round.robots, &round.holds, round.case.tick_s);
            for a in round.case.adversaries(&round.robots, &mut r) {
                // The beam search is a search over operators, not one operator's run.
                if matches!(a, Adversary::Beam { .. }) {
                    continue;
                }
                let run = run_adversary(coordinator.clone(), a, &mut r, bound).unwrap();
                prop_assert!(
                    run.finished,
                    "N = {n}, seed {seed}, {a:?}: a robot still waits after {bound} ticks"
                );
                worst.set(worst.get().max(run.ticks as f64 / bound as f64));
            }
            checked.set(checked.get() + 1);
            Ok(())
        });
        if let Err(e) = result {
            panic!("{e}");
        }
        // Not vacuous: most cases have holds with release rules.
        assert!(
            checked.get() >= cases / 2,
            "N = {n}: {} cases",
            checked.get()
        );
        eprintln!(
            "N = {n}: {} plans with holds, the slowest round took {:.0} % of the serial bound",
            checked.get(),
            100.0 * worst.get()
        );
    }
}
