//! "A plan is what the cell does" (docs/decisions.md): with the nominal operator (no
//! correction, the planned speed: `Operator::Scheduled` every tick) a round of a schedule the
//! production scheduler made never ends more than 1 % after its planned `T_total`, with and
//! without hold points, for N = 2…4 robots on random problems.
//!
//! Before the release rules' waits were planned as dwells (`holds::release_rules`), rounds
//! with holds ran 12–74 % over their plan: a rule makes a robot wait at its hold until the
//! robot it awaits has left its low-confidence stretch, and the plan had it leave the hold
//! earlier, as if it could travel from the hold to its own stretch while the other was still
//! inside. Rounds may end earlier than planned: with no robot low-confidence, Alg. 1 runs the
//! robots as fast as the demonstrations allow.

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_realtime::Operator;
use tandem_schedule::{SamplerParams, sample_schedule_n, testkit};

/// Reference sample period and control tick (s).
const DT_S: f64 = 0.01;

/// The planned and the realized `T_total` (s) of a round under the nominal operator.
fn planned_and_realized(seed: u64, n_robots: usize, holds: bool) -> (f64, f64, bool) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut problem = testkit::random_problem(&mut rng, 600..=1200, DT_S).unwrap();
    if holds {
        let points = testkit::hold_points(problem.conf());
        problem = problem.with_holds(points).unwrap();
    }
    let params = SamplerParams {
        samples: 200,
        seed,
        tick_s: Some(DT_S),
        ..SamplerParams::default()
    };
    let out = sample_schedule_n(&problem, n_robots, &params, None).unwrap();
    let mut c = out.schedule.check(&problem).unwrap().coordinator().unwrap();
    let mut ticks = 0_u64;
    while !c.is_finished() {
        let t = c.tick(Operator::Scheduled).unwrap();
        assert!(!t.overlap());
        ticks += 1;
    }
    (
        out.schedule.t_total_s(DT_S),
        ticks as f64 * DT_S,
        out.schedule.has_holds(),
    )
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 48,
        rng_seed: RngSeed::Fixed(38),
        ..ProptestConfig::default()
    })]

    #[test]
    fn the_nominal_operator_ends_a_round_within_one_percent_of_its_plan(
        seed in any::<u64>(),
        n_robots in 2_usize..=4,
        holds in any::<bool>(),
    ) {
        let (planned, realized, held) = planned_and_realized(seed, n_robots, holds);
        prop_assert!(
            realized <= planned * 1.01,
            "N = {}, holds {} (schedule with holds: {}): planned {:.3} s, realized {:.3} s (+{:.2} %)",
            n_robots,
            holds,
            held,
            planned,
            realized,
            (realized / planned - 1.0) * 100.0
        );
    }
}

/// The spread, for the record (`cargo test -p tandem-sim --test plan_is_what_the_cell_does
/// -- --nocapture`): realized against planned over 24 seeds per case (with holds, more until
/// three schedules use them).
#[test]
fn realized_against_planned_by_case() {
    for holds in [false, true] {
        for n_robots in 2..=4 {
            let (mut lo, mut hi, mut with_holds) = (f64::INFINITY, f64::NEG_INFINITY, 0);
            // 24 seeds, and with holds more (up to 96) until three schedules use them: the
            // staggered candidate (no holds) runs in every re-schedule of N ≥ 3 robots and
            // often wins (docs/decisions.md, "N ≥ 3 robots: the staggered candidate always").
            let mut seeds = 0_u64;
            while seeds < 24 || (holds && with_holds < 3 && seeds < 96) {
                let seed = seeds;
                seeds += 1;
                let (planned, realized, held) = planned_and_realized(seed, n_robots, holds);
                let r = realized / planned - 1.0;
                (lo, hi) = (lo.min(r), hi.max(r));
                with_holds += usize::from(held);
                assert!(r <= 0.01, "seed {seed}: {r}");
            }
            // Not vacuous: the scheduler uses holds on some of these problems.
            assert!(
                !holds || with_holds >= 3,
                "N = {n_robots}: {with_holds} of {seeds} with holds"
            );
            eprintln!(
                "holds {holds}, N = {n_robots}: realized − planned from {:+.2} % to {:+.2} % ({with_holds} of {seeds} schedules with holds)",
                lo * 100.0,
                hi * 100.0
            );
        }
    }
}
