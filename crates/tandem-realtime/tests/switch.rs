//! The operator's switch time `δ` in the margin check (`check_margins`, docs/decisions.md,
//! "The operator's switch time in the margin check"): with `δ = 0` it decides and reports
//! exactly as the check without it, bit for bit; a schedule valid at `δ = 0` whose robots
//! switch within `δ` is rejected; and on the ticks the robots actually traverse, every schedule
//! it accepts keeps at least `k = switch_ticks(δ, tick)` ticks between one robot's
//! low-confidence stretch and another's, for every operator of the adversary set, N = 2…4,
//! with and without holds.

use rand::SeedableRng;
use tandem_realtime::adversary::{Adversary, SwitchGaps, adversary_set, run_adversary};
use tandem_realtime::holds::{release_rules, usable_holds};
use tandem_realtime::testkit::{Case, Check, Family, rng, tight_starts};
use tandem_realtime::{
    Coordinator, Error, Hold, MarginParams, RobotFlags, Timeline, check_margins, margin_slacks,
    pair_slacks, pair_slacks_with_holds, sufficient_margins, sufficient_margins_with_holds,
    switch_ticks,
};

#[test]
fn switch_ticks_by_hand() {
    // 20·0.1 = 2.0000000000000004 ≥ 2 and 19·0.1 = 1.9000000000000001 < 2.
    assert_eq!(switch_ticks(2.0, 0.1).unwrap(), 20);
    assert_eq!(switch_ticks(0.25, 0.1).unwrap(), 3);
    assert_eq!(switch_ticks(0.1, 0.1).unwrap(), 1);
    assert_eq!(switch_ticks(0.0, 0.1).unwrap(), 0);
    assert_eq!(switch_ticks(7.0, 0.05).unwrap(), 140);
    assert_eq!(switch_ticks(1e-9, 0.05).unwrap(), 1);
    for k in [
        switch_ticks(0.3, 0.1).unwrap(),
        switch_ticks(0.7, 0.1).unwrap(),
    ] {
        assert!(k == 3 || k == 7, "{k}");
    }
    // The smallest k with k·h ≥ δ as computed, whatever the rounding of δ/h.
    for (d, h) in [
        (0.3, 0.1),
        (0.7, 0.1),
        (1.1, 0.01),
        (2.0, 0.03),
        (5.0, 1.0 / 3.0),
    ] {
        let k = switch_ticks(d, h).unwrap();
        assert!(
            k as f64 * h >= d && (k - 1) as f64 * h < d,
            "{d} / {h}: {k}"
        );
    }
    for bad in [-1.0, f64::NAN, f64::INFINITY, 1e9] {
        assert!(matches!(
            switch_ticks(bad, 0.1),
            Err(Error::BadParam {
                name: "switch_s",
                ..
            })
        ));
    }
    assert!(matches!(
        switch_ticks(1.0, 0.0),
        Err(Error::BadParam { name: "tick_s", .. })
    ));
}

/// 10 HC, 10 LC and 40 HC samples of 0.1 s, gradients 1, bounds [0.8, 1.25]; robot 2 at `tau`.
fn ten_ten_forty(tau: f64) -> Vec<Timeline> {
    let conf: Vec<bool> = (0..60).map(|n| !(10..20).contains(&n)).collect();
    let (g, lo, hi) = ([1.0; 60], [0.8; 60], [1.25; 60]);
    vec![
        Timeline::new(&conf, &g, &lo, &hi, 0.0, 0.1).unwrap(),
        Timeline::new(&conf, &g, &lo, &hi, tau, 0.1).unwrap(),
    ]
}

/// The shortest switch (ticks) and whether any tick overlapped, over the whole adversary set.
fn shortest_switch(
    robots: &[Timeline],
    holds: &[Vec<Hold>],
    (tick_s, switch_s): (f64, f64),
    set: &[Adversary],
    r: &mut rand_chacha::ChaCha8Rng,
) -> (Option<u64>, bool) {
    let ends = robots.iter().map(Timeline::end_s).fold(0.0, f64::max);
    let dwell: f64 = holds.iter().flatten().map(|h| h.dwell_s).sum();
    let budget = ((ends + dwell) / tick_s * 40.0).ceil() as u64 + 100;
    let (mut gap, mut overlap) = (None::<u64>, false);
    for &a in set {
        let c = Coordinator::with_holds_unchecked(robots.to_vec(), holds, tick_s)
            .unwrap()
            .with_switch_s(switch_s)
            .unwrap();
        let run = run_adversary(c, a, r, budget).unwrap();
        assert!(run.finished, "{a:?} did not finish");
        overlap |= run.overlap_ticks > 0;
        if let Some(g) = run.min_switch_gap_ticks {
            gap = Some(gap.map_or(g, |x| x.min(g)));
        }
    }
    (gap, overlap)
}

#[test]
fn a_schedule_valid_without_switch_time_is_rejected_with_two_seconds() {
    let tick_s = 0.1;
    let at = |switch_s| MarginParams::new(tick_s).with_switch_s(switch_s);
    // The earliest accepted start of robot 2 on a 0.05 s grid, without and with δ = 2 s (k = 20).
    let earliest = |switch_s: f64| {
        (0..=120)
            .map(|i| 0.05 * f64::from(i))
            .find(|&tau| check_margins(&ten_ten_forty(tau), &[], &at(switch_s)).unwrap())
            .unwrap()
    };
    let (tau0, tau2) = (earliest(0.0), earliest(2.0));
    assert!(tau0 < tau2, "{tau0} vs {tau2}");
    // By hand at δ = 2 s: robot 2 starts after robot 1 left its region at 2 s (M = 0.125 s for
    // both), at least e = ⌊(τ − 2 − ε)/0.125⌋ ticks after robot 1's exit tick, so in the 20 ticks
    // after it robot 2 runs at most 21 − e ticks from τ and must stay short of τ + 1 − ε:
    // (21 − e)·0.125 < 1 − ε needs e ≥ 14, τ > 3.75. On the grid: 3.8 s.
    assert!((tau2 - 3.8).abs() < 1e-9, "{tau2}");
    let robots = ten_ten_forty(tau0);
    assert!(sufficient_margins(&robots, tick_s).unwrap());
    assert!(!check_margins(&robots, &[], &at(2.0)).unwrap());
    let slacks = margin_slacks(&robots, &[], &at(2.0)).unwrap();
    assert!(slacks.iter().any(|s| s.slack_s <= 0.0));
    // The rejected schedule does switch within 2 s under the adversaries (it is safe at δ = 0),
    // the accepted one never does. Robot 1 leaves its region at 2 s of its clock, robot 2
    // enters its own at τ + 1: nominally (τ + 1 − 2)/0.1 ticks apart.
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let set = adversary_set(2, [0.8, 1.25], 60, &mut r);
    let (gap0, overlap0) = shortest_switch(&robots, &[], (tick_s, 0.0), &set, &mut r);
    assert!(!overlap0);
    let gap0 = gap0.unwrap();
    assert!(gap0 < 5, "δ = 0 schedule keeps {gap0} ticks");
    let (gap2, overlap2) = shortest_switch(&ten_ten_forty(tau2), &[], (tick_s, 2.0), &set, &mut r);
    assert!(!overlap2);
    let gap2 = gap2.unwrap();
    assert!(gap2 >= 20, "δ = 2 s schedule keeps only {gap2} ticks");
    // Not vacuous: at the edge the worst operator comes within a few ticks of δ (c can rush
    // at 1.25 while the bound charges every tick with M = 0.125 s).
    assert!(
        gap2 <= 30,
        "δ = 2 s schedule keeps {gap2} ticks, far from 20"
    );
    // The serial schedule (robot 2 at robot 1's end, 6 s): robot 1 left its region 4 s of clock
    // (≥ 32 ticks at F = 1.25) before robot 2 starts, so it is accepted at δ = 2 s.
    assert!(check_margins(&ten_ten_forty(6.0), &[], &at(2.0)).unwrap());
}

/// The switch count of every stress run (`SwitchGaps`, the ticks the robots traversed), on a
/// hand-built trace of two robots.
#[test]
fn switch_gaps_on_a_hand_built_trace() {
    let flags = |a, b| RobotFlags::from_slice(&[a, b]);
    let mut g = SwitchGaps::default();
    // Robot 0 low-confidence in ticks 0 and 1: one robot, no switch yet.
    g.record(0, &flags(true, false));
    g.record(1, &flags(true, false));
    g.record(2, &flags(false, false));
    assert_eq!(g.min_gap_ticks(), None);
    // Robot 1 in tick 4: ticks 2 and 3 had neither, a switch of 2 ticks.
    g.record(4, &flags(false, true));
    assert_eq!(g.min_gap_ticks(), Some(2));
    // Robot 1 again in tick 5: 3 ticks after robot 0's last, the least stays 2.
    g.record(5, &flags(false, true));
    assert_eq!(g.min_gap_ticks(), Some(2));
    // Robot 0 in tick 9 (3 ticks after robot 1's last), robot 1 right after in tick 10.
    g.record(9, &flags(true, false));
    assert_eq!(g.min_gap_ticks(), Some(2));
    g.record(10, &flags(false, true));
    assert_eq!(g.min_gap_ticks(), Some(0));
}

/// The beam search measures the switches of the sequences it expands (issue 41: the stress
/// counts it): on the earliest start of robot 2 that the check accepts at `δ = 0` (the schedule
/// of `a_schedule_valid_without_switch_time_is_rejected_with_two_seconds`) it finds a switch
/// shorter than `k = 20` ticks, and on the earliest accepted at `δ = 2` s none.
#[test]
fn the_beam_search_measures_the_switch_time() {
    let tick_s = 0.1;
    let at = |switch_s| MarginParams::new(tick_s).with_switch_s(switch_s);
    let earliest = |switch_s: f64| {
        (0..=120)
            .map(|i| 0.05 * f64::from(i))
            .find(|&tau| check_margins(&ten_ten_forty(tau), &[], &at(switch_s)).unwrap())
            .unwrap()
    };
    let beam = |tau: f64, switch_s: f64| {
        let c = Coordinator::with_margins(ten_ten_forty(tau), &[], &at(switch_s)).unwrap();
        run_adversary(c, Adversary::Beam { width: 4 }, &mut rng(1), 2_000).unwrap()
    };
    let tau0 = earliest(0.0);
    assert!(!check_margins(&ten_ten_forty(tau0), &[], &at(2.0)).unwrap());
    let short = beam(tau0, 0.0);
    assert_eq!(short.overlap_ticks, 0);
    let gap = short
        .min_switch_gap_ticks
        .expect("the beam measures its switches");
    // On schedule robot 1 leaves its region at 2 s and robot 2 enters its own at τ + 1: fewer
    // than 20 ticks of 0.1 s apart while τ < 3 s.
    assert!(tau0 < 3.0, "{tau0}");
    assert!(gap < 20, "{gap}");
    let kept = beam(earliest(2.0), 2.0);
    assert_eq!(kept.overlap_ticks, 0);
    let gap = kept
        .min_switch_gap_ticks
        .expect("the beam measures its switches");
    assert!(gap >= switch_ticks(2.0, tick_s).unwrap(), "{gap}");
}

#[test]
fn zero_switch_time_is_today_bit_for_bit() {
    let mut agreed = 0;
    for seed in 0..120_u64 {
        let mut r = rng(0x5E1 + seed);
        let n = 2 + (seed % 3) as usize;
        let case = Case::random(Family::of_seed(seed), n, &mut r);
        let starts = case.interleaved_starts(n, &mut r);
        let robots = case.robots_at(&starts);
        let p = MarginParams::new(case.tick_s);
        let bits = |s: &[tandem_realtime::PairSlack]| -> Vec<(usize, usize, u64)> {
            s.iter()
                .map(|x| (x.prev_robot, x.cur_robot, x.slack_s.to_bits()))
                .collect()
        };
        assert_eq!(
            check_margins(&robots, &[], &p).unwrap(),
            sufficient_margins(&robots, case.tick_s).unwrap()
        );
        assert_eq!(
            bits(&margin_slacks(&robots, &[], &p).unwrap()),
            bits(&pair_slacks(&robots, case.tick_s).unwrap())
        );
        let all: Vec<Vec<usize>> = robots
            .iter()
            .map(|tl| usable_holds(tl.conf(), &(1..tl.n_ref()).collect::<Vec<_>>()))
            .collect();
        let holds = release_rules(&robots, &[], &all);
        assert_eq!(
            check_margins(&robots, &holds, &p).unwrap(),
            sufficient_margins_with_holds(&robots, &holds, case.tick_s).unwrap()
        );
        assert_eq!(
            bits(&margin_slacks(&robots, &holds, &p).unwrap()),
            bits(&pair_slacks_with_holds(&robots, &holds, case.tick_s).unwrap())
        );
        // A switch time only ever removes schedules.
        let with = p.with_switch_s(3.0 * case.tick_s);
        if check_margins(&robots, &holds, &with).unwrap() {
            assert!(sufficient_margins_with_holds(&robots, &holds, case.tick_s).unwrap());
        }
        agreed += 1;
    }
    assert_eq!(agreed, 120);
}

/// Switch times of 1, 3½ and 12 ticks (fn pointers for `tight_starts`).
const CHECKS: [(f64, Check); 3] = [
    (1.0, |r, h| {
        check_margins(r, &[], &MarginParams::new(h).with_switch_s(h))
    }),
    (3.5, |r, h| {
        check_margins(r, &[], &MarginParams::new(h).with_switch_s(3.5 * h))
    }),
    (12.0, |r, h| {
        check_margins(r, &[], &MarginParams::new(h).with_switch_s(12.0 * h))
    }),
];

fn cases() -> u64 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(24)
}

#[test]
fn accepted_schedules_keep_the_switch_time_under_every_operator() {
    let cases = cases();
    for n in 2..=4usize {
        let (mut accepted, mut near, mut tight_at_zero) = (0, 0, 0);
        for seed in 0..cases {
            let (ticks_f, check) = CHECKS[(seed % 3) as usize];
            let mut r = rng(0xD5 + 1000 * n as u64 + seed);
            let case = Case::random(Family::of_seed(seed), n, &mut r);
            let Some((starts, _)) = tight_starts(&case, check, &mut r) else {
                continue;
            };
            let robots = case.robots_at(&starts);
            let k = switch_ticks(ticks_f * case.tick_s, case.tick_s).unwrap();
            let set = case.adversaries(&robots, &mut r);
            let (gap, overlap) = shortest_switch(&robots, &[], (case.tick_s, 0.0), &set, &mut r);
            assert!(!overlap, "N = {n}, seed {seed}: overlap");
            if let Some(g) = gap {
                assert!(
                    g >= k,
                    "N = {n}, seed {seed} ({}): a switch of {g} < {k} ticks, starts {starts:?}",
                    case.family.name()
                );
                near += u32::from(g <= 4 * k + 4);
            }
            accepted += 1;
            // The same case made tight without the switch time: the operators often switch
            // within k ticks there (the rule is what keeps them apart).
            let zero: Check = sufficient_margins;
            if let Some((starts0, _)) = tight_starts(&case, zero, &mut r) {
                let robots0 = case.robots_at(&starts0);
                let set0 = case.adversaries(&robots0, &mut r);
                if let (Some(g), _) =
                    shortest_switch(&robots0, &[], (case.tick_s, 0.0), &set0, &mut r)
                    && g < k
                {
                    tight_at_zero += 1;
                }
            }
        }
        eprintln!(
            "N = {n}: {accepted} accepted, {near} within 4k + 4 ticks of k, {tight_at_zero} \
             δ = 0 schedules switching within k"
        );
        // A case whose robots end and start low-confidence has no schedule at δ > 0 (the serial
        // one switches in one tick): tight_starts finds none.
        assert!(accepted >= cases / 2, "N = {n}: {accepted} accepted");
        assert!(near >= 1, "N = {n}: no accepted schedule came near k");
        assert!(
            tight_at_zero >= 1,
            "N = {n}: no δ = 0 schedule switched within k"
        );
    }
}

#[test]
fn accepted_plans_with_holds_keep_the_switch_time_under_every_operator() {
    let cases = 3 * cases();
    for n in 2..=4usize {
        let mut accepted = 0;
        for seed in 0..cases {
            let mut r = rng(0x401D + 1000 * n as u64 + seed);
            let case = Case::random(Family::of_seed(seed), n, &mut r);
            let starts = case.interleaved_starts(n, &mut r);
            let robots = case.robots_at(&starts);
            let usable: Vec<Vec<usize>> = robots
                .iter()
                .map(|tl| usable_holds(tl.conf(), &(1..tl.n_ref()).collect::<Vec<_>>()))
                .collect();
            let holds = release_rules(&robots, &[], &usable);
            let switch_s = 2.5 * case.tick_s;
            let params = MarginParams::new(case.tick_s).with_switch_s(switch_s);
            if holds.is_empty() || !check_margins(&robots, &holds, &params).unwrap() {
                continue;
            }
            accepted += 1;
            let k = switch_ticks(switch_s, case.tick_s).unwrap();
            let set = case.adversaries(&robots, &mut r);
            let (gap, overlap) =
                shortest_switch(&robots, &holds, (case.tick_s, switch_s), &set, &mut r);
            assert!(!overlap, "N = {n}, seed {seed}: overlap with holds");
            assert!(
                gap.is_none_or(|g| g >= k),
                "N = {n}, seed {seed}: a switch of {gap:?} < {k} ticks with holds {holds:?}"
            );
        }
        eprintln!("N = {n}: {accepted} of {cases} plans with holds accepted at δ = 2.5 ticks");
        assert!(accepted >= 1, "N = {n}: no plan with holds accepted");
    }
}

/// Robot 1: 10 HC, 10 LC, 40 HC samples of 0.1 s; robot 2 the same, holding at sample 9 (one
/// HC sample before its stretch) until robot 1 has passed sample 20 (the end of its stretch),
/// with the planned dwell that makes it due then (1.1 s). Both start at 0, tick 0.1 s.
fn held_right_before_its_stretch() -> (Vec<Timeline>, Vec<Vec<Hold>>) {
    let robots = ten_ten_forty(0.0);
    let hold = Hold {
        dwell_s: 1.1,
        after: vec![tandem_realtime::After {
            robot: 0,
            ref_idx: 20,
        }],
        ..Hold::at(9)
    };
    (robots, vec![vec![], vec![hold]])
}

#[test]
fn a_held_robot_waits_the_switch_time_after_its_rule_holds() {
    let (robots, holds) = held_right_before_its_stretch();
    let tick_s = 0.1;
    let params = MarginParams::new(tick_s).with_switch_s(2.0);
    let k = params.switch_ticks().unwrap();
    assert_eq!(k, 20);
    // The check accepts it at δ = 2 s: the rule orders the two stretches and the coordinator
    // waits k ticks after it holds.
    assert!(check_margins(&robots, &holds, &params).unwrap());
    let c = Coordinator::with_margins(robots.clone(), &holds, &params).unwrap();
    assert_eq!(c.switch_ticks(), 20);
    let mut r = rng(41);
    let set = adversary_set(2, [0.8, 1.25], 2000, &mut r);
    let (gap, overlap) = shortest_switch(&robots, &holds, (tick_s, 2.0), &set, &mut r);
    assert!(!overlap);
    assert!(gap.is_some_and(|g| g >= k), "switch of {gap:?} ticks");
    // Regression: without the run-time wait (δ = 0 at run time) robot 2 enters its stretch one
    // or two ticks after robot 1 left its own.
    let (gap0, overlap0) = shortest_switch(&robots, &holds, (tick_s, 0.0), &set, &mut r);
    assert!(!overlap0);
    assert!(gap0.is_some_and(|g| g < 3), "switch of {gap0:?} ticks");
}

#[test]
fn the_token_passes_the_switch_time_after_a_stretch_ended() {
    use tandem_realtime::continuous::{ContinuousCoordinator, run_cell};
    // [HC, LC, HC] of 1 s each at ψ̇ = 1, bounds [½, 2]; both gates at the start; tick ¼ s.
    let task = Timeline::new(
        &[true, false, true],
        &[1.0; 3],
        &[0.5; 3],
        &[2.0; 3],
        0.0,
        1.0,
    )
    .unwrap();
    let gap_of = |switch_s: f64| {
        let mut r = rng(7);
        let set = adversary_set(2, [0.5, 2.0], 4000, &mut r);
        let mut gap = None::<u64>;
        for a in set {
            let mut cell =
                ContinuousCoordinator::new(task.clone(), &[], &[(0, 0), (1, 0)], 2, 0.25)
                    .unwrap()
                    .with_switch_s(switch_s)
                    .unwrap();
            let run = run_cell(&mut cell, a, &mut r, 20, 40_000).unwrap();
            assert_eq!(run.overlap_ticks, 0);
            assert!(cell.tasks_completed().iter().all(|&t| t >= 20), "{a:?}");
            let g = run.min_switch_gap_ticks.expect("the robots switch");
            gap = Some(gap.map_or(g, |x| x.min(g)));
        }
        gap.unwrap()
    };
    // δ = 2 s is k = 8 ticks of ¼ s: no switch is shorter.
    assert!(gap_of(2.0) >= 8);
    // Regression: without the wait robot 1 leaves its gate in the tick after robot 0 left its
    // stretch, and its tolerance-widened interval reaches the stretch within four ticks.
    assert!(gap_of(0.0) < 8);
}

#[test]
fn the_token_passes_early_by_the_travel_to_the_stretch() {
    use tandem_realtime::continuous::{ContinuousCoordinator, run_cell};
    // [HC ×4, LC, HC] of 1 s each at ψ̇ = 1, bounds [½, 2]; both gates at the start, 4 s of
    // high-confidence travel before the stretch; tick ¼ s, δ = 2 s (k = 8). From its gate a
    // robot surely needs 15 whole ticks before the tick in which it is first low-confidence
    // (4 s less the clock tolerance is just under 16 ticks), more than k: the token lets it go
    // as soon as the other robot left, and it still reaches its stretch more than k ticks
    // later.
    let task = Timeline::new(
        &[true, true, true, true, false, true],
        &[1.0; 6],
        &[0.5; 6],
        &[2.0; 6],
        0.0,
        1.0,
    )
    .unwrap();
    let cell_at = |switch_s: f64| {
        ContinuousCoordinator::new(task.clone(), &[], &[(0, 0), (1, 0)], 2, 0.25)
            .unwrap()
            .with_switch_s(switch_s)
            .unwrap()
    };
    let mut r = rng(11);
    for a in adversary_set(2, [0.5, 2.0], 4000, &mut r) {
        let mut cell = cell_at(2.0);
        let run = run_cell(&mut cell, a, &mut r, 10, 40_000).unwrap();
        assert_eq!(run.overlap_ticks, 0);
        assert!(cell.tasks_completed().iter().all(|&t| t >= 10), "{a:?}");
        let g = run.min_switch_gap_ticks.expect("the robots switch");
        assert!(g >= 8, "{a:?}: a switch of {g} ticks < k = 8");
    }
    // The planned operator: the switch costs the travel alone, as without a switch time
    // (16 ticks from the gate, the last of them touching the stretch within the tolerance),
    // not the switch time and then the travel (8 + 16 ticks), which the cyclic plan does not
    // charge (it charges max(δ, travel + tick) per change).
    let mut gap_nominal = |switch_s: f64| {
        let mut cell = cell_at(switch_s);
        let run = run_cell(&mut cell, Adversary::Nominal, &mut r, 10, 40_000).unwrap();
        (run.min_switch_gap_ticks.unwrap(), cell.ticks())
    };
    let (with_delta, ticks_with) = gap_nominal(2.0);
    let (without, ticks_without) = gap_nominal(0.0);
    assert!(with_delta >= 8, "{with_delta}");
    assert_eq!(with_delta, without, "the travel covers the switch time");
    assert_eq!(ticks_with, ticks_without, "no tick lost to δ = 2 s");
}

/// Robots of 10 low-confidence samples of 0.1 s (the whole task), gradients 1, bounds
/// [0.8, 1.25], started at `starts`: no high-confidence time to switch in, only idle time
/// between one robot's end and the next one's start (Eq. 20 constraint 2 relaxed by `δ`).
fn all_low(starts: &[f64]) -> Vec<Timeline> {
    let conf = [false; 10];
    let (g, lo, hi) = ([1.0; 10], [0.8; 10], [1.25; 10]);
    starts
        .iter()
        .map(|&tau| Timeline::new(&conf, &g, &lo, &hi, tau, 0.1).unwrap())
        .collect()
}

#[test]
fn an_idle_gap_after_the_earlier_robot_ended_counts_towards_the_switch_time() {
    let tick_s = 0.1;
    let at = |switch_s| MarginParams::new(tick_s).with_switch_s(switch_s);
    // The serial start (robot 2 where robot 1 ends, 1 s) is safe without a switch time and
    // switches in consecutive ticks: refused at δ = 2 s (k = 20).
    assert!(sufficient_margins(&all_low(&[0.0, 1.0]), tick_s).unwrap());
    assert!(!check_margins(&all_low(&[0.0, 1.0]), &[], &at(2.0)).unwrap());
    // By hand: robot 1's exit tick is its last (e = 1); at its end robot 2's clock is at most
    // 1 + M = 1.125 s, then runs on schedule (0.1 s a tick, nobody running): it starts, low-
    // confidence at once, ⌈(τ − 1.125)/0.1⌉ ticks later. 1 + that > 20 needs τ > 3.025 s; on a
    // 0.05 s grid the earliest accepted start is 3.05 s.
    let earliest = (0..=120)
        .map(|i| 0.05 * f64::from(i))
        .find(|&tau| check_margins(&all_low(&[0.0, tau]), &[], &at(2.0)).unwrap())
        .unwrap();
    assert!((earliest - 3.05).abs() < 1e-9, "{earliest}");
    // Under every adversary the accepted schedule keeps 20 ticks; the one a grid step earlier
    // (which the check refuses) is where the worst operator comes closest.
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let set = adversary_set(2, [0.8, 1.25], 60, &mut r);
    let (gap, overlap) = shortest_switch(&all_low(&[0.0, 3.05]), &[], (tick_s, 2.0), &set, &mut r);
    assert!(!overlap);
    let gap = gap.unwrap();
    assert!((20..=22).contains(&gap), "{gap} ticks");
    let (early, _) = shortest_switch(&all_low(&[0.0, 2.9]), &[], (tick_s, 0.0), &set, &mut r);
    assert!(early.unwrap() < 20, "{early:?}");
    // Three robots, each after the one before ended plus the gap (the lead bound's rule 2 with
    // the idle ticks): accepted at δ = 2 s, refused with every gap one tick shorter.
    assert!(check_margins(&all_low(&[0.0, 3.05, 6.1]), &[], &at(2.0)).unwrap());
    assert!(!check_margins(&all_low(&[0.0, 3.05, 6.0]), &[], &at(2.0)).unwrap());
    let (gap3, overlap3) = shortest_switch(
        &all_low(&[0.0, 3.05, 6.1]),
        &[],
        (tick_s, 2.0),
        &adversary_set(3, [0.8, 1.25], 60, &mut r),
        &mut r,
    );
    assert!(!overlap3 && gap3.unwrap() >= 20, "{gap3:?}");
}
