//! Handing a running continuous cell over to a new plan
//! (`ContinuousCoordinator::take_over`): by hand, the refusals; and a property test over
//! random tasks whose confidence is then refined (some low-confidence samples become high,
//! more holds become usable, as recorded executions do through the latch), N = 2…5, random
//! runnable orders before and after, operators that rush, drag and switch at random: the
//! hand-over succeeds at the first tick at which the token moves, and neither cell ever has
//! two robots low-confidence in one tick, before or after it.

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_realtime::continuous::{ContinuousCoordinator, Group, groups};
use tandem_realtime::holds::usable_holds;
use tandem_realtime::{Error, Operator, Timeline};

/// A task of confidence `conf` at Δt_s = 1 s, ψ̇ = 1, bounds [½, 2].
fn task(conf: &[bool]) -> Timeline {
    let n = conf.len();
    Timeline::new(conf, &vec![1.0; n], &vec![0.5; n], &vec![2.0; n], 0.0, 1.0).unwrap()
}

#[test]
fn by_hand_a_robot_inside_a_group_blocks_the_hand_over_and_the_positions_carry_over() {
    // [HC, LC, LC, HC, HC, LC, HC] with a hold at 4: groups (gate 0: stretch 0) and
    // (gate 4: stretch 1). Robot 0 first, then robot 1, each group in turn.
    let conf = [true, false, false, true, true, false, true];
    let order = [(0, 0), (1, 0), (0, 1), (1, 1)];
    let mut old = ContinuousCoordinator::new(task(&conf), &[4], &order, 2, 1.0).unwrap();
    // The refined plan: stretch 0 is trusted now; one group (gate 4: stretch at 5).
    let refined = [true, true, true, true, true, false, true];
    let mut new =
        ContinuousCoordinator::new(task(&refined), &[4], &[(0, 0), (1, 0)], 2, 1.0).unwrap();
    // Tick 0: robot 0 moves to 1 s (before its old stretch), robot 1 waits at 0.
    old.tick(Operator::Scheduled).unwrap();
    assert_eq!(old.clock_s(), [1.0, 0.0]);
    // Both are before gate 4 of the new plan: a hand-over point of it.
    let mut try_new = new.clone();
    try_new.take_over(&old).unwrap();
    assert_eq!(try_new.clock_s(), [1.0, 0.0]);
    // Ticks 1–3: robot 0 crosses its stretch (1 → 3 s) to its next gate, 4 s, and has left
    // group 0 at the end of tick 3, so the token goes to robot 1; tick 4: robot 1 0 → 1 s.
    for _ in 1..5 {
        old.tick(Operator::Scheduled).unwrap();
    }
    assert_eq!(old.clock_s(), [4.0, 1.0]);
    // Robot 1 holds the token and is 1 s from its old stretch; in the new plan everything
    // before 4 s is high confidence and gate 4 is the next gate of both: a hand-over point.
    new.take_over(&old).unwrap();
    assert_eq!(new.clock_s(), [4.0, 1.0]);
    assert_eq!(new.tasks_completed(), old.tasks_completed());
    // The new plan's token: robot 0's group (the first entry of the order, nothing skipped).
    let t = new.tick(Operator::Scheduled).unwrap();
    assert_eq!(t.running, [true, true]);
    assert_eq!(new.clock_s(), [5.0, 2.0]);
    // A plan in which a robot's position is inside a group is refused: the old plan
    // itself, taken over from a cell in which robot 0 is on its stretch.
    let mut old2 = ContinuousCoordinator::new(task(&conf), &[4], &order, 2, 1.0).unwrap();
    // Robot 0 to 1, then on its stretch (1 → 2): inside group 0 of the same plan.
    old2.tick(Operator::Scheduled).unwrap();
    old2.tick(Operator::Scheduled).unwrap();
    assert_eq!(old2.clock_s()[0], 2.0);
    let mut same = ContinuousCoordinator::new(task(&conf), &[4], &order, 2, 1.0).unwrap();
    let before = same.clone();
    let err = same.take_over(&old2).unwrap_err();
    assert!(matches!(err, Error::HandOver { robot: 0, .. }), "{err}");
    assert_eq!(same.clock_s(), before.clock_s(), "unchanged on error");
    // Other robot counts and ticks are refused too.
    let three = ContinuousCoordinator::new(
        task(&conf),
        &[4],
        &[(0, 0), (1, 0), (2, 0), (0, 1), (1, 1), (2, 1)],
        3,
        1.0,
    )
    .unwrap();
    assert!(matches!(
        same.clone().take_over(&three),
        Err(Error::HandOver { .. })
    ));
    let other_tick = ContinuousCoordinator::new(task(&conf), &[4], &order, 2, 0.5).unwrap();
    assert!(matches!(
        same.clone().take_over(&other_tick),
        Err(Error::HandOver { .. })
    ));
}

/// A random task (6–60 samples in runs, HC 1–8, LC 1–5; ψ̇̄ in [0.5, 2], bounds factors in
/// [0.3, 1] and [1, 3], Δt_s 0.05, HC at ψ̇min) and the hold candidates; plus its
/// refinement: every LC sample turns HC with probability `q` (at least one stays LC).
fn random_pair(rng: &mut ChaCha8Rng) -> ((Timeline, Vec<usize>), (Timeline, Vec<usize>)) {
    let mut conf = Vec::new();
    let mut hc = rng.random_bool(0.5);
    let len = rng.random_range(6..=60);
    while conf.len() < len {
        let run = if hc {
            rng.random_range(1..=8)
        } else {
            rng.random_range(1..=5)
        };
        conf.extend(std::iter::repeat_n(hc, run));
        hc = !hc;
    }
    if conf.iter().all(|&c| c) {
        conf[0] = false;
    }
    let n = conf.len();
    let q = rng.random_range(0.0..0.7);
    let mut refined: Vec<bool> = conf.iter().map(|&c| c || rng.random_bool(q)).collect();
    if refined.iter().all(|&c| c) {
        let k = conf.iter().position(|&c| !c).unwrap();
        refined[k] = false;
    }
    let mean: Vec<f64> = (0..n).map(|_| rng.random_range(0.5..2.0)).collect();
    let lo: Vec<f64> = mean
        .iter()
        .map(|m| m * rng.random_range(0.3..1.0))
        .collect();
    let hi: Vec<f64> = mean
        .iter()
        .map(|m| m * rng.random_range(1.0..3.0))
        .collect();
    let p = rng.random_range(0.0..1.0);
    let candidates: Vec<usize> = (1..n).filter(|_| rng.random_bool(p)).collect();
    let make = |conf: &[bool]| {
        let exec: Vec<f64> = (0..n)
            .map(|k| if conf[k] { lo[k] } else { mean[k] })
            .collect();
        (
            Timeline::new(conf, &exec, &lo, &hi, 0.0, 0.05).unwrap(),
            usable_holds(conf, &candidates),
        )
    };
    (make(&conf), make(&refined))
}

/// A random runnable order: each robot's groups in task order from a random first group,
/// interleaved at random as whole groups, flattened to stretches.
fn random_order(gs: &[Group], n: usize, rng: &mut ChaCha8Rng) -> Vec<(usize, usize)> {
    let g = gs.len();
    let first: Vec<usize> = (0..n).map(|_| rng.random_range(0..g)).collect();
    let mut taken = vec![0; n];
    let mut out = Vec::new();
    while taken.iter().any(|&k| k < g) {
        let r = loop {
            let r = rng.random_range(0..n);
            if taken[r] < g {
                break r;
            }
        };
        let gr = gs[(first[r] + taken[r]) % g];
        out.extend((gr.first_lc..gr.end_lc).map(|lc| (r, lc)));
        taken[r] += 1;
    }
    out
}

fn operator(rng: &mut ChaCha8Rng, policy: u8) -> Operator {
    match policy {
        0 => Operator::Fastest,
        1 => Operator::Slowest,
        2 if rng.random_bool(0.5) => Operator::Fastest,
        2 => Operator::Slowest,
        _ => Operator::Gradient(rng.random_range(0.1..6.0)),
    }
}

fn hand_over_is_sound(seed: u64, n: usize, policy: u8) -> Result<(), TestCaseError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let ((task0, holds0), (task1, holds1)) = random_pair(&mut rng);
    let order0 = random_order(&groups(task0.conf(), &holds0).unwrap(), n, &mut rng);
    let order1 = random_order(&groups(task1.conf(), &holds1).unwrap(), n, &mut rng);
    let tick_s = 0.05 * rng.random_range(0.2..2.0);
    let mut old = ContinuousCoordinator::new(task0, &holds0, &order0, n, tick_s).unwrap();
    let fresh = ContinuousCoordinator::new(task1, &holds1, &order1, n, tick_s).unwrap();
    // The old plan runs for a random while (a few tasks at most).
    let warm = rng.random_range(0..20_000_u64);
    for k in 0..warm {
        let t = old.tick(operator(&mut rng, policy)).unwrap();
        prop_assert!(!t.overlap(), "old plan, tick {k}");
    }
    // Then the hand-over is tried after every tick; it must succeed at the latest right
    // after the token's next move (every token move is a hand-over point of a refinement).
    let mut new = fresh.clone();
    let mut moved = false;
    let mut tries = 0_u64;
    while new.take_over(&old).is_err() {
        prop_assert!(!moved, "refused after the token moved ({tries} tries)");
        let before = old.token_position();
        let t = old.tick(operator(&mut rng, policy)).unwrap();
        prop_assert!(!t.overlap());
        moved = old.token_position() != before;
        tries += 1;
        prop_assert!(tries < 1_000_000, "no hand-over point");
    }
    prop_assert_eq!(new.tasks_completed(), old.tasks_completed());
    // The new plan runs until every robot has done 20 more tasks, soundly.
    let target: Vec<u64> = old.tasks_completed().iter().map(|k| k + 20).collect();
    let mut ticks = 0_u64;
    while new
        .tasks_completed()
        .iter()
        .zip(&target)
        .any(|(k, t)| k < t)
    {
        let t = new.tick(operator(&mut rng, policy)).unwrap();
        prop_assert!(
            !t.overlap() && t.fault.is_none(),
            "new plan, tick {ticks}: {t:?}"
        );
        ticks += 1;
        prop_assert!(ticks < 50_000_000, "deadlock after the hand-over");
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 200,
        rng_seed: RngSeed::Fixed(2121),
        ..ProptestConfig::default()
    })]

    #[test]
    fn a_refined_plan_takes_over_at_the_next_token_move_and_stays_sound(
        seed in any::<u64>(),
        n in 2_usize..=5,
        policy in 0_u8..4,
    ) {
        hand_over_is_sound(seed, n, policy)?;
    }
}
