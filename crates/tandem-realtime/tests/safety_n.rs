//! The safety invariant for N ∈ {2, …, 6} robots: for every schedule `sufficient_margins`
//! accepts and every operator of `tandem_realtime::adversary` (Alg. 2's worst case with each
//! robot as the current one, the favoured robot switching at random times, extremes, random and
//! switching sequences), the coordinator never has two robots traverse a low-confidence
//! reference sample in the same tick.
//!
//! Problems alternate between two families (`common::Problem::random_styled`: many short
//! regions, per-robot gradient styles; `random_structured`: a few long regions, per-run styles),
//! schedules are random and tight (`common::tight_schedule`: N warps, N offsets in any order,
//! each robot bisected towards the acceptance boundary). The unsafe baselines
//! (`sufficient_margins_pairwise`, the two-robot check per pair; the printed Alg. 2) accept
//! schedules on which the same operators find overlaps.

mod common;

use std::cell::Cell;

use common::{Check, Problem, adversaries, find_overlap, rng, tight_schedule};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use tandem_realtime::{
    sufficient_margins, sufficient_margins_pairwise, sufficient_margins_per_pair,
    sufficient_margins_printed,
};

/// Cases per robot count (2000 in all over N = 2..=6); `PROPTEST_CASES` overrides it.
fn cases_per_n() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(400)
}

/// Problem `seed` of the alternating families, with its control tick (¼ to 1½ samples).
fn problem(seed: u64, n: usize, r: &mut ChaCha8Rng) -> (Problem, f64) {
    let p = if seed % 2 == 0 {
        Problem::random_styled(r, n)
    } else {
        Problem::random_structured(r, n)
    };
    let tick_s = p.dt_s * r.random_range(0.25..=1.5);
    (p, tick_s)
}

#[test]
fn accepted_schedules_of_n_robots_never_overlap_under_any_operator() {
    let cases = cases_per_n();
    let runner = |cases| {
        let config = Config {
            cases,
            failure_persistence: None,
            ..Config::default()
        };
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
    };
    for n in 2..=6usize {
        let (overlapping, edge) = (Cell::new(0u32), Cell::new(0u32));
        let result = runner(cases).run(&any::<u64>(), |seed| {
            let mut r = rng(seed);
            let (problem, tick_s) = problem(seed, n, &mut r);
            let check: Check = sufficient_margins;
            let Some((starts, overlaps)) = tight_schedule(&problem, n, tick_s, check, &mut r)
            else {
                // A serial start rejected: the tolerance grows with the schedule's last end
                // (tol::clock_tolerance_s), so a robot added after a boundary-tight one can
                // flip a decision that sat within ~1e-8 s of its threshold. Counted below.
                edge.set(edge.get() + 1);
                return Ok(());
            };
            let robots = problem.robots_at(&starts);
            prop_assert!(sufficient_margins_per_pair(&robots, tick_s).unwrap());
            overlapping.set(overlapping.get() + u32::from(overlaps));
            let set = adversaries(&problem, &robots, tick_s, &mut r);
            let hit = find_overlap(&robots, tick_s, &set, &mut r);
            prop_assert!(
                hit.is_none(),
                "N = {n}: overlap {hit:?} for seed {seed}, starts {starts:?}, tick {tick_s}"
            );
            Ok(())
        });
        if let Err(e) = result {
            panic!("{e}");
        }
        eprintln!(
            "N = {n}: {cases} cases, {} with overlapping executions, {} tolerance-edge skips",
            overlapping.get(),
            edge.get()
        );
        assert!(edge.get() <= cases / 100, "N = {n}: {} skips", edge.get());
        // The check must be exercised on schedules whose executions overlap, not only on
        // serial ones.
        assert!(
            overlapping.get() >= cases * 3 / 4,
            "N = {n}: only {} of {cases} accepted schedules overlap",
            overlapping.get()
        );
    }
}

/// Non-vacuity: schedules the unsafe baselines accept and the conservative check rejects
/// really do overlap under some operator of the set. The two-robot check per pair misses the
/// third robots' pace over long regions (`random_structured`; the smallest such case is in
/// tests/regression.rs); the printed Alg. 2 fails much more often.
#[test]
fn unsafe_baselines_accept_schedules_that_overlap() {
    let baselines: [(&str, Check, u64, u32); 2] = [
        ("pairwise", sufficient_margins_pairwise, 400, 5),
        ("printed", sufficient_margins_printed, 100, 50),
    ];
    let n = 4;
    for (name, baseline, seeds, need) in baselines {
        let (mut cases, mut overlaps) = (0, 0);
        for seed in 0..seeds {
            let mut r = rng(0xBAD + seed);
            let problem = Problem::random_structured(&mut r, n);
            let tick_s = problem.dt_s * r.random_range(0.25..=1.5);
            let Some((starts, _)) = tight_schedule(&problem, n, tick_s, baseline, &mut r) else {
                continue;
            };
            let robots = problem.robots_at(&starts);
            if sufficient_margins(&robots, tick_s).unwrap() {
                continue;
            }
            cases += 1;
            let set = adversaries(&problem, &robots, tick_s, &mut r);
            if find_overlap(&robots, tick_s, &set, &mut r).is_some() {
                overlaps += 1;
            }
        }
        eprintln!("{name}, N = {n}: {overlaps} of {cases} baseline-only cases overlap");
        assert!(
            overlaps >= need,
            "{name}, N = {n}: only {overlaps} of {cases} baseline-only cases overlapped"
        );
    }
}
