//! The fast and the straightforward forms of the margin check decide alike — for two robots the
//! single-pass simulation and one simulation per pair, for three or more the lead bound with
//! sliding extremes and with every window scanned — and `pair_slacks` agrees with both; serial
//! schedules are always accepted.

use std::cell::Cell;

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use rand::Rng;
use tandem_realtime::testkit::{Case, Family, rng};
use tandem_realtime::{Timeline, pair_slacks, sufficient_margins, sufficient_margins_per_pair};

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
        let case = Case::random(Family::of_seed(seed), 2, &mut r);
        let tick_s = case.tick_s;
        // Offsets from simultaneous starts to fully serial, biased to the interesting upper half.
        let tau = case.plans[0].timeline(0.0).end_s() * frac.sqrt();
        let robots = case.robots_at(&[0.0, tau]);
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
        let case = Case::random(Family::of_seed(seed), 2, &mut r);
        let tick_s = case.plans[0].dt_s * tick_frac;
        let robots = case.robots_at(&[0.0, case.plans[0].timeline(0.0).end_s()]);
        prop_assert!(sufficient_margins(&robots, tick_s).unwrap());
        prop_assert!(sufficient_margins_per_pair(&robots, tick_s).unwrap());
        Ok(())
    });
    if let Err(e) = result {
        panic!("{e}");
    }
}

#[test]
fn single_pass_equals_per_pair_for_n_robots() {
    for n in 3..=5usize {
        let mut counts = [0u32; 2];
        for seed in 0..200u64 {
            let mut r = rng(0xA6 + seed);
            let case = Case::random(Family::of_seed(seed), n, &mut r);
            let tick_s = case.tick_s;
            // Each robot from simultaneous with the first to after the latest end so far.
            let mut starts = vec![0.0];
            for _ in 1..n {
                let end = case
                    .robots_at(&starts)
                    .iter()
                    .map(Timeline::end_s)
                    .fold(0.0, f64::max);
                starts.push(end * r.random::<f64>().powf(0.25) * 1.05);
            }
            let robots = case.robots_at(&starts);
            let single = sufficient_margins(&robots, tick_s).unwrap();
            let per_pair = sufficient_margins_per_pair(&robots, tick_s).unwrap();
            assert_eq!(single, per_pair, "N = {n}, seed {seed}, starts {starts:?}");
            // The slacks come from the same simulations: all positive exactly when accepted.
            let slacks = pair_slacks(&robots, tick_s).unwrap();
            assert_eq!(
                slacks.iter().all(|s| s.slack_s > 0.0),
                single,
                "N = {n}, seed {seed}, slacks {slacks:?}"
            );
            assert!(slacks.iter().all(|s| s.prev_robot != s.cur_robot));
            counts[usize::from(single)] += 1;
        }
        let [rejected, accepted] = counts;
        assert!(
            rejected >= 20 && accepted >= 20,
            "N = {n}: {accepted} accepted, {rejected} rejected"
        );
    }
}

/// The serial schedule of N robots (each starting when the one before it ends) is always
/// accepted: robots not yet started follow the running robot furthest behind, so each starts
/// only once the others have finished.
#[test]
fn serial_schedules_of_n_robots_are_always_accepted() {
    for n in 1..=6usize {
        for seed in 0..60u64 {
            let mut r = rng(0x5E + seed);
            let case = Case::random(Family::of_seed(seed), n, &mut r);
            let tick_s = case.tick_s;
            let mut starts: Vec<f64> = vec![0.0];
            for _ in 1..n {
                let latest_end = case
                    .robots_at(&starts)
                    .iter()
                    .map(Timeline::end_s)
                    .fold(0.0, f64::max);
                starts.push(latest_end);
            }
            let robots = case.robots_at(&starts);
            assert!(
                sufficient_margins(&robots, tick_s).unwrap(),
                "N = {n}, seed {seed}"
            );
            assert!(sufficient_margins_per_pair(&robots, tick_s).unwrap());
        }
    }
}

/// Serial schedules of executions of one to three samples, at ticks of ¼ to 2 samples (so an
/// execution may be shorter than a tick), are accepted for 2 to 5 robots: robots start one
/// start time at a time (strategy rule 3), so the check never sees two waiting robots start
/// together. (Before that rule, 921 of these 20,000 schedules were rejected.)
#[test]
fn serial_schedules_of_executions_shorter_than_a_tick_are_accepted() {
    let mut r = rng(0x5407);
    for case in 0..20_000 {
        let len = r.random_range(1..=3usize);
        let conf: Vec<bool> = (0..len).map(|_| r.random_bool(0.5)).collect();
        let g: Vec<f64> = (0..len).map(|_| r.random_range(0.5..1.5)).collect();
        let lo: Vec<f64> = g.iter().map(|x| x * r.random_range(0.5..1.0)).collect();
        let hi: Vec<f64> = g.iter().map(|x| x * r.random_range(1.0..2.0)).collect();
        let tick_s = 0.01 * r.random_range(0.25..=2.0);
        let n = r.random_range(2..=5usize);
        let mut robots: Vec<Timeline> = Vec::new();
        for _ in 0..n {
            let start = robots.last().map_or(0.0, Timeline::end_s);
            robots.push(Timeline::new(&conf, &g, &lo, &hi, start, 0.01).unwrap());
        }
        assert!(
            sufficient_margins(&robots, tick_s).unwrap(),
            "case {case}: N = {n}, conf {conf:?}, ψ̇_E {g:?}, bounds {lo:?} {hi:?}, tick {tick_s}"
        );
    }
}
