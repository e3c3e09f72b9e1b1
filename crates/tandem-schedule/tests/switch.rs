//! The operator's switch time `δ` in the scheduler's bounds and validation (docs/decisions.md,
//! "The switch time in the scheduler's bounds (issue 41)"): numbers derived by hand on small
//! problems, `δ = 0` unchanged, and every bound below every schedule `validate_with_switch`
//! accepts.

use tandem_schedule::{
    ExactParams, Problem, Violation, margin_free_bound, operator_bound_s,
    operator_bound_with_switch_s, solve_exact, solve_exact_with_switch, validate,
    validate_with_switch,
};

/// [LC, HC, LC], 10 samples each at 10 ms, gradients 1 in [0.5, 2]: LC runs of 0.1 s, an HC
/// gap of [0.05, 0.2] s, no head or tail (the example of `tandem_schedule::exact`).
fn lhl() -> Problem {
    let conf: Vec<bool> = (0..30).map(|n| (10..20).contains(&n)).collect();
    Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01).unwrap()
}

#[test]
fn bounds_with_a_switch_time_by_hand() {
    let p = lhl();
    let params = ExactParams::default();
    // The operator's LC time 2 × 0.2 s, plus one switch per extra robot.
    assert!((operator_bound_with_switch_s(&p, 2, 0.02).unwrap() - 0.42).abs() < 1e-12);
    assert!((operator_bound_with_switch_s(&p, 3, 0.02).unwrap() - 0.64).abs() < 1e-12);
    assert_eq!(
        operator_bound_with_switch_s(&p, 3, 0.0).unwrap().to_bits(),
        operator_bound_s(&p, 3).unwrap().to_bits()
    );
    // δ = 0.02 s. Order 1 2 1 2: robot 1's runs [0, 0.1] and [0.24, 0.34] (its second run
    // waits for robot 2's first, [0.12, 0.22], plus δ; its gap 0.14 s is within [0.05, 0.2]),
    // robot 2's second [0.36, 0.46]: 0.4 + 3δ = 0.46 s. Order 1 1 2 2: 0.25 + δ + 0.25 =
    // 0.52 s. Order 1 2 2 1 is infeasible (robot 1 cannot wait 0.25 + 2δ s in its gap).
    let f = solve_exact_with_switch(&p, &params, 0.02).unwrap();
    assert!(f.proven_optimal);
    assert!((f.lower_bound_s - 0.46).abs() < 1e-9, "{}", f.lower_bound_s);
    assert_eq!(f.order, vec![0, 1, 0, 1]);
    let s = f.schedule.as_ref().unwrap();
    assert!((s.t_total_s(p.dt_s()) - 0.46).abs() < 1e-9);
    // It keeps the switch time on schedule; only the worst-case margins can reject it.
    match validate_with_switch(&p, s, 0.02) {
        Ok(())
        | Err(Violation::InsufficientMargins { .. } | Violation::InsufficientSwitchTime { .. }) => {
        }
        Err(v) => panic!("{v}"),
    }
    assert!(matches!(
        validate_with_switch(&p, s, 0.05),
        Err(Violation::SwitchTooShort { robots: [0, 1], .. })
    ));
    // δ = 0.1 s: order 1 2 1 2 needs δ ≤ 0.05; 1 1 2 2 gives 0.5 + δ = 0.6 s only with robot 2
    // starting after robot 1 ended (τ = 0.35 > |ψ_E1| = 0.25 s). Eq. 20 constraint 2 is
    // relaxed by the start allowance at the schedule's tick 0.01 s, `A = δ + h + h·2/0.5 =
    // 0.15` s ≥ 0.1 s, so the network finds that schedule and the optimum is proven (before
    // the allowance: a bound, not proven, no schedule).
    let f = solve_exact_with_switch(&p, &params, 0.1).unwrap();
    assert!(f.proven_optimal);
    assert_eq!(f.order, vec![0, 0, 1, 1]);
    assert!((f.lower_bound_s - 0.6).abs() < 1e-9, "{}", f.lower_bound_s);
    let s = f.schedule.as_ref().unwrap();
    assert!((s.offsets_s[0] - 0.35).abs() < 1e-9, "{:?}", s.offsets_s);
    assert!((s.t_total_s(p.dt_s()) - 0.6).abs() < 1e-9);
    // Valid under the relaxed constraint 2 (only the worst-case margins may refuse it), and
    // refused by the printed one.
    match validate_with_switch(&p, s, 0.1) {
        Ok(())
        | Err(Violation::InsufficientMargins { .. } | Violation::InsufficientSwitchTime { .. }) => {
        }
        Err(v) => panic!("{v}"),
    }
    assert!(matches!(validate(&p, s), Err(Violation::Offset { .. })));
    let b = margin_free_bound(&p, 2, &params, 0.1).unwrap();
    assert_eq!(b.lower_bound_s.to_bits(), f.lower_bound_s.to_bits());
    // δ = 0: the search without a switch time, bit for bit.
    let zero = solve_exact_with_switch(&p, &params, 0.0).unwrap();
    assert_eq!(zero, solve_exact(&p, &params).unwrap());
    for bad in [-1.0, f64::NAN, f64::INFINITY] {
        assert!(solve_exact_with_switch(&p, &params, bad).is_err());
        assert!(operator_bound_with_switch_s(&p, 2, bad).is_err());
    }
}

#[test]
fn three_robots_bound_by_hand_and_monotone_in_robots() {
    let p = lhl();
    let params = ExactParams::default();
    let two = margin_free_bound(&p, 2, &params, 0.02)
        .unwrap()
        .lower_bound_s;
    let three = margin_free_bound(&p, 3, &params, 0.02).unwrap();
    assert!(three.lower_bound_s >= two);
    assert!(
        three.lower_bound_s >= 0.64 - 1e-12,
        "{}",
        three.lower_bound_s
    );
    // Without a switch time the certificate's bounds of the scheduler.
    for n in 1..=4 {
        let b = margin_free_bound(&p, n, &params, 0.0)
            .unwrap()
            .lower_bound_s;
        let with = margin_free_bound(&p, n, &params, 0.01)
            .unwrap()
            .lower_bound_s;
        assert!(with >= b, "{n}: {with} < {b}");
    }
}

/// The serial schedule of two robots on a problem that starts and ends high-confidence:
/// 20 HC, 10 LC, 20 HC samples at 10 ms, gradients 1 in [0.5, 2].
#[test]
fn validation_with_a_switch_time_by_hand() {
    let conf: Vec<bool> = (0..50).map(|n| !(20..30).contains(&n)).collect();
    let p = Problem::new(conf, vec![1.0; 50], vec![0.5; 50], vec![2.0; 50], 0.01).unwrap();
    let serial = p.serial_schedule(0.01).unwrap();
    // The serial schedule runs high confidence at its fastest (0.1 s per 20 samples): robot 1's
    // run [0.1, 0.2], its end 0.3 s = τ, robot 2's run [0.4, 0.5]: 0.2 s apart.
    assert!((serial.offsets_s[0] - 0.3).abs() < 1e-12);
    assert_eq!(
        validate_with_switch(&p, &serial, 0.0),
        validate(&p, &serial)
    );
    assert!(matches!(
        validate_with_switch(&p, &serial, 0.25),
        Err(Violation::SwitchTooShort { robots: [0, 1], .. })
    ));
    // The margin check (M = 0.02 s for both: F = 2 on the LC samples): robot 2 starts at least
    // e = ⌊(0.3 − 0.2 − ε)/0.02⌋ = 4 ticks after robot 1's exit tick; with the steps of the
    // samples robot 1 runs after its run (F = 1, 0.01 s), at least 1 + ⌊(0.1 − ε − 0.02)/0.01⌋
    // = 8 (the exit tick, then 0.01 s per tick); and robot 2 moves 0.01 s per tick before its
    // run. δ = 0.05 s, k = 5: robot 2 does not run in them. δ = 0.15 s, k = 15: 15 + 1 − 8 = 8
    // ticks, 0.3 + 0.08 < 0.4. δ = 0.18 s, k = 18: 11 ticks, 0.3 + 0.11 ≥ 0.4, rejected
    // though the schedule keeps 0.2 s (the exit tick is charged `M`, and its phase is unknown).
    // (With the largest step over all samples, before the tighter steps, 0.15 s was rejected:
    // 15 + 1 − 4 = 12 ticks of 0.02 s.)
    assert!(validate_with_switch(&p, &serial, 0.05).is_ok());
    assert!(validate_with_switch(&p, &serial, 0.15).is_ok());
    assert_eq!(
        validate_with_switch(&p, &serial, 0.18),
        Err(Violation::InsufficientSwitchTime {
            tick_s: 0.01,
            switch_s: 0.18
        })
    );
    assert!(matches!(
        validate_with_switch(&p, &serial, -1.0),
        Err(Violation::MarginCheck { .. })
    ));
}

mod common;

use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// The bound with a switch time is below every schedule that `validate_with_switch`
    /// accepts: random problems, two and three robots, the fastest plan of every robot at
    /// random offsets (and serial), the switch time up to 5 reference samples.
    #[test]
    fn the_bound_is_below_every_schedule_that_keeps_the_switch_time(
        (conf, g) in (8usize..30).prop_flat_map(|n| (
            proptest::collection::vec(proptest::bool::weighted(0.6), n),
            common::gradients(n),
        )),
        delta in 0.0f64..0.05,
        fractions in proptest::collection::vec(0.0f64..=1.0, 40),
    ) {
        prop_assume!(conf.iter().any(|&c| !c));
        let p = common::problem(conf, &g);
        for n in [2usize, 3] {
            let bound = margin_free_bound(&p, n, &ExactParams::default(), delta)
                .unwrap()
                .lower_bound_s;
            let plain = margin_free_bound(&p, n, &ExactParams::default(), 0.0)
                .unwrap()
                .lower_bound_s;
            prop_assert!(bound >= plain, "N = {}: {} < {}", n, bound, plain);
            let serial = p.serial_schedule_n(n, 0.01).unwrap();
            let mut candidates = vec![serial.clone()];
            for w in fractions.chunks(n - 1) {
                let mut s = serial.clone();
                let mut latest = s.end_s(0, p.dt_s());
                for (i, &f) in w.iter().enumerate() {
                    s.offsets_s[i] = f * latest;
                    latest = latest.max(s.end_s(i + 1, p.dt_s()));
                }
                candidates.push(s);
            }
            for s in &candidates {
                if validate_with_switch(&p, s, delta).is_ok() {
                    let t = s.t_total_s(p.dt_s());
                    prop_assert!(t >= bound * (1.0 - 1e-9), "n {}: T {} < bound {}", n, t, bound);
                }
            }
        }
    }
}

/// The cyclic plan with a switch time, by hand: 1 s of high confidence (0.5 s at the
/// fastest), 1 s of low confidence, 1 s of high confidence (the example of
/// `tandem_schedule::cyclic`).
#[test]
fn the_cyclic_period_with_a_switch_time_by_hand() {
    use tandem_schedule::{
        CyclicParams, cyclic_plan, period_lower_bound_s, period_lower_bound_with_switch_s,
    };
    let conf: Vec<bool> = (0..300).map(|n| !(100..200).contains(&n)).collect();
    let p = Problem::new(conf, vec![1.0; 300], vec![0.5; 300], vec![2.0; 300], 0.01).unwrap();
    let with = |switch_s| CyclicParams {
        switch_s,
        ..CyclicParams::default()
    };
    // One robot: no switch, its fastest task 2 s. Two and three robots: the operator's 1 s
    // stretch plus 0.2 s per change, N changes per period: 2.4 s and 3.6 s (the fastest task,
    // 2 s, is shorter).
    for (n, want) in [(1usize, 2.0), (2, 2.4), (3, 3.6)] {
        let b = period_lower_bound_with_switch_s(&p, n, 0.2).unwrap();
        assert!((b - want).abs() < 1e-9, "N = {n}: bound {b}");
        let plan = cyclic_plan(&p, n, &with(0.2)).unwrap();
        assert!(
            (plan.period_s - want).abs() < 1e-9,
            "N = {n}: {}",
            plan.period_s
        );
        assert!(plan.gap.abs() < 1e-9, "N = {n}: gap {}", plan.gap);
        // δ = 0: the plan and the bound without a switch time.
        let zero = cyclic_plan(&p, n, &with(0.0)).unwrap();
        assert_eq!(zero, cyclic_plan(&p, n, &CyclicParams::default()).unwrap());
        assert_eq!(
            period_lower_bound_with_switch_s(&p, n, 0.0)
                .unwrap()
                .to_bits(),
            period_lower_bound_s(&p, n).unwrap().to_bits()
        );
    }
    // With the token rule's hand-overs counted at 10 ms (the gate is the task start, 0.5 s
    // before the stretch at the fastest): each change costs max(0.5 + 0.01, δ); the plan
    // reaches the hand-over bound with the switch time, and it is never above the plan.
    for (switch_s, per_change) in [(0.2, 0.51), (2.0, 2.0)] {
        for n in [2usize, 3] {
            let params = CyclicParams {
                handover_tick_s: Some(0.01),
                switch_s,
                ..CyclicParams::default()
            };
            let plan = cyclic_plan(&p, n, &params).unwrap();
            let want = n as f64 * (1.0 + per_change);
            assert!(
                (plan.period_s - want).abs() < 1e-9,
                "N = {n}, δ = {switch_s}: {}",
                plan.period_s
            );
            assert!(
                plan.gap.abs() < 1e-9,
                "N = {n}, δ = {switch_s}: gap {}",
                plan.gap
            );
        }
    }
    assert!(cyclic_plan(&p, 2, &with(-1.0)).is_err());
    assert!(period_lower_bound_with_switch_s(&p, 2, f64::NAN).is_err());
}

/// The load cap on the cyclic plan, by hand on the same task: the busy share is the operator's
/// stretches plus a switch time per change of robot, over the period.
#[test]
fn the_cyclic_load_cap_by_hand() {
    use tandem_schedule::{CyclicParams, cyclic_plan};
    let conf: Vec<bool> = (0..300).map(|n| !(100..200).contains(&n)).collect();
    let p = Problem::new(conf, vec![1.0; 300], vec![0.5; 300], vec![2.0; 300], 0.01).unwrap();
    let capped = |switch_s, max_busy_share| CyclicParams {
        switch_s,
        max_busy_share,
        ..CyclicParams::default()
    };
    // Two robots, no switch time, u_max = 0.8: 2 × 1 s busy needs P ≥ 2.5 s (else 2 s).
    // With δ = 0.2 s: 2 × 1 + 2 × 0.2 = 2.4 s busy, P ≥ 3 s. Three robots at 0.7: 3/0.7 s.
    for (n, switch_s, cap, want) in [
        (2usize, 0.0, 0.8, 2.5),
        (2, 0.2, 0.8, 3.0),
        (3, 0.0, 0.7, 3.0 / 0.7),
        (1, 0.0, 0.5, 2.0),
    ] {
        let plan = cyclic_plan(&p, n, &capped(switch_s, cap)).unwrap();
        assert!(
            (plan.period_s - want).abs() < 1e-9,
            "N = {n}: {}",
            plan.period_s
        );
        assert!(plan.gap.abs() < 1e-9, "N = {n}: gap {}", plan.gap);
        let busy = n as f64 * 1.0 + if n >= 2 { n as f64 * switch_s } else { 0.0 };
        assert!(busy / plan.period_s <= cap + 1e-12, "N = {n}");
        // The robots' times are a plan of that period: each robot's task within it.
        for r in &plan.robots {
            assert!(r.start_s >= 0.0 && r.start_s < plan.period_s);
        }
    }
    // No cap: the plan without it.
    assert_eq!(
        cyclic_plan(&p, 2, &capped(0.0, 1.0)).unwrap(),
        cyclic_plan(&p, 2, &CyclicParams::default()).unwrap()
    );
    for bad in [0.0, -0.5, 1.5, f64::NAN] {
        assert!(cyclic_plan(&p, 2, &capped(0.0, bad)).is_err());
    }
}
