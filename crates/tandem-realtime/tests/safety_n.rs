//! The safety invariant for N ∈ {2, …, 6, 16} robots: for every schedule `sufficient_margins`
//! accepts and every operator of `tandem_realtime::adversary` (Alg. 2's worst case with each
//! robot as the current one, the favoured robot switching at random times, extremes, random and
//! switching sequences, and the beam search over per-tick choices), the coordinator never has
//! two robots traverse a low-confidence reference sample in the same tick.
//!
//! Problems cycle through the test kit's eight families (`tandem_realtime::testkit::Family`:
//! one mask with uniform or styled gradients, few long regions, per-run bound ratios, per-robot
//! plans of different lengths and bounds, a long low-confidence stretch of one robot, and the two
//! families built like the reproducers of a dragged third robot); schedules are tight
//! (`testkit::tight_starts`: every robot at a lower or upper edge of a window of accepted
//! offsets, bisected). The unsafe baselines (the two-robot check per pair, the printed Alg. 2,
//! the per-tick worst pace) accept schedules on which the same operators find overlaps.

use std::cell::Cell;

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use tandem_realtime::margins::baseline;
use tandem_realtime::testkit::{Case, Check, Family, find_overlap, rng, tight_starts};
use tandem_realtime::{sufficient_margins, sufficient_margins_per_pair};

/// Cases per robot count (2000 in all over N = 2..=6); `PROPTEST_CASES` overrides it.
fn cases_per_n() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(400)
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
    // N = 16 (MAX_ROBOTS): a few cases, a fortieth of the others' (each has 15 robots to
    // place at an edge, every adversary of 30).
    for (n, cases) in (2..=6usize)
        .map(|n| (n, cases))
        .chain([(16, (cases / 40).max(4))])
    {
        let (overlapping, edge) = (Cell::new(0u32), Cell::new(0u32));
        let result = runner(cases).run(&any::<u64>(), |seed| {
            let mut r = rng(seed);
            let case = Case::random(Family::of_seed(seed), n, &mut r);
            let check: Check = sufficient_margins;
            let Some((starts, overlaps)) = tight_starts(&case, check, &mut r) else {
                // Not even the serial start accepted: the tolerance grows with the schedule's
                // last end (tol::clock_tolerance_s), so a robot placed at an edge within ~1e-8 s
                // can flip. Counted below.
                edge.set(edge.get() + 1);
                return Ok(());
            };
            let robots = case.robots_at(&starts);
            prop_assert!(sufficient_margins_per_pair(&robots, case.tick_s).unwrap());
            overlapping.set(overlapping.get() + u32::from(overlaps));
            let set = case.adversaries(&robots, &mut r);
            let hit = find_overlap(&robots, case.tick_s, &set, &mut r);
            prop_assert!(
                hit.is_none(),
                "N = {n}: overlap {hit:?} for seed {seed} ({:?}), starts {starts:?}, tick {}",
                case.family,
                case.tick_s
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

/// Non-vacuity: schedules the unsafe baselines accept and the check rejects really do overlap
/// under some operator of the set. The two-robot check per pair misses the third robots' pace
/// over long regions; the per-tick worst pace misses a dragged third robot's lead per unit of
/// progress (the families built for it); the printed Alg. 2 fails much more often.
#[test]
fn unsafe_baselines_accept_schedules_that_overlap() {
    let baselines: [(&str, Check, Family, u64, u32); 3] = [
        ("pairwise", baseline::pairwise, Family::Structured, 400, 5),
        ("printed", baseline::printed, Family::Structured, 100, 30),
        (
            "greedy_pace",
            baseline::greedy_pace,
            Family::DraggedThird,
            200,
            3,
        ),
    ];
    for (name, check, family, seeds, need) in baselines {
        let n = 4;
        let (mut cases, mut overlaps) = (0, 0);
        for seed in 0..seeds {
            let mut r = rng(0xBAD + seed);
            let case = Case::random(family, n, &mut r);
            let Some((starts, _)) = tight_starts(&case, check, &mut r) else {
                continue;
            };
            let robots = case.robots_at(&starts);
            if sufficient_margins(&robots, case.tick_s).unwrap() {
                continue;
            }
            cases += 1;
            let set = case.adversaries(&robots, &mut r);
            if find_overlap(&robots, case.tick_s, &set, &mut r).is_some() {
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
