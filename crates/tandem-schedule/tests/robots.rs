//! N robots in the schedule: schedules from the N-robot scheduler (`sample_schedule_n`) pass
//! `validate` and, run through `tandem_realtime::Coordinator` at their own tick under the full
//! adversary set for N robots, never have two robots low-confidence in one control tick; the
//! N = 2 case is `sample_schedule` itself; the operator-limited lower bound
//! (`operator_bound_s`) is never above a schedule that satisfies Eq. 20 constraints 1–4.

mod common;
mod runtime;

use proptest::prelude::*;
use proptest::strategy::ValueTree;
use runtime::{adversaries, run, run_unchecked};
use tandem_schedule::{
    ExactParams, Problem, SamplerParams, Schedule, Source, Violation, operator_bound_s,
    sample_schedule, sample_schedule_n, solve_exact, validate,
};

/// Random small problems for N robots: 1–6 runs of 1–9 samples.
fn random_problem() -> impl Strategy<Value = Problem> {
    runtime::random_problem(10, 7)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn n_robot_schedules_are_valid_and_never_overlap_at_runtime(
        p in random_problem(),
        n in 3usize..=5,
        seed in any::<u64>(),
        tick_frac in 0.25f64..=1.0,
        samples in 20usize..120,
    ) {
        let tick_s = tick_frac * p.dt_s();
        let params = SamplerParams {
            samples,
            seed,
            tick_s: Some(tick_s),
            ..SamplerParams::default()
        };
        let out = sample_schedule_n(&p, n, &params, None).unwrap();
        let s = &out.schedule;
        prop_assert_eq!((s.n_robots(), s.offsets_s.len(), s.tick_s), (n, n - 1, tick_s));
        prop_assert_eq!(validate(&p, s), Ok(()));
        prop_assert_eq!(out.t_total_s, s.t_total_s(p.dt_s()));
        // Never slower than serial, never below the bound.
        let serial = p.serial_schedule_n(n, tick_s).unwrap().t_total_s(p.dt_s());
        prop_assert!(out.t_total_s <= serial);
        // The certificate is the operator bound, as computed (no clamping). The bound and the
        // clock sum the same durations in other orders: the schedule is never shorter than
        // the bound by more than rounding (here exact gradients, so far below 1e-12).
        // For `N ≥ 3` it is the N-robot search's optimum or the operator bound: never below
        // the latter (up to the same rounding).
        let operator = operator_bound_s(&p, n).unwrap();
        prop_assert!(out.lower_bound_s >= operator * (1.0 - 1e-12), "{} vs {}", out.lower_bound_s, operator);
        // Unproven, it is the largest of the operator bound and the bounds of fewer robots
        // (never below the two-robot margin-free optimum, whatever the N-robot search did).
        let two = solve_exact(&p, &ExactParams::default()).unwrap();
        if two.proven_optimal {
            prop_assert!(out.lower_bound_s >= two.lower_bound_s, "{} vs {}", out.lower_bound_s, two.lower_bound_s);
        }
        prop_assert!(
            out.lower_bound_s <= out.t_total_s * (1.0 + 1e-12) && out.gap >= -1e-12,
            "bound {} T_total {} gap {:e}", out.lower_bound_s, out.t_total_s, out.gap
        );
        for op in adversaries(&p, s, seed) {
            let hit = run(&p, s, op, seed);
            prop_assert!(
                hit.is_none(),
                "two robots LC at tick {:?} with {:?} (source {:?})", hit, op, out.source
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// The certificate's bound never decreases when a robot is added (docs/decisions.md, "A
    /// bound that never decreases when a robot is added"), with and without holds.
    #[test]
    fn the_bound_never_decreases_when_a_robot_is_added(
        p in random_problem(),
        hold_bits in any::<u64>(),
        seed in any::<u64>(),
    ) {
        let holds: Vec<usize> = (1..p.n_ref()).filter(|&n| (hold_bits >> (n % 64)) & 1 == 1).collect();
        for p in [p.clone(), p.with_holds(holds).unwrap()] {
            let params = SamplerParams { samples: 20, seed, ..SamplerParams::default() };
            let mut below = 0.0;
            for n in 1..=5 {
                let out = sample_schedule_n(&p, n, &params, None).unwrap();
                prop_assert!(out.lower_bound_s >= below, "N = {n}: {} < {below}", out.lower_bound_s);
                below = out.lower_bound_s;
                // Where the gap goes: the search's share and the margins' add up to the gap,
                // neither is negative beyond rounding, and a proven bound leaves the search
                // nothing open (docs/decisions.md, "A bound that never decreases …").
                if n >= 3 {
                    let g = out.gap_split().expect("a fresh outcome knows its margin-free schedule");
                    prop_assert!((g.search + g.margins - out.gap).abs() < 1e-9, "N = {n}: {g:?} against {}", out.gap);
                    prop_assert!(g.search >= -1e-9 && g.margins >= -1e-9, "N = {n}: {g:?}");
                    if out.bound_is_optimum {
                        prop_assert!(g.search < 1e-6, "N = {n}: proven, yet {g:?}");
                    }
                }
            }
        }
    }
}

/// The user's case, on a problem of our own: fragmented confidence (40 low-confidence islands
/// between short moves, at the search's budget) where the `N`-robot search stops before it
/// proves an optimum while the one for fewer robots finishes, so the operator bound alone
/// would drop below the bound of fewer robots.
#[test]
fn the_bound_of_more_robots_is_never_below_that_of_fewer_on_fragmented_confidence() {
    let n_ref = 40 * 5;
    let conf: Vec<bool> = (0..n_ref).map(|k| k % 5 != 2).collect();
    let mean: Vec<f64> = (0..n_ref)
        .map(|k| 1.0 + 0.3 * ((k * 7 % 11) as f64 / 11.0))
        .collect();
    let lo = mean.iter().map(|m| 0.6 * m).collect();
    let hi = mean.iter().map(|m| 1.6 * m).collect();
    let p = Problem::new(conf, mean, lo, hi, 0.01).unwrap();
    let params = SamplerParams {
        samples: 50,
        seed: 1,
        ..SamplerParams::default()
    };
    let mut below = 0.0;
    for n in 2..=5 {
        let out = sample_schedule_n(&p, n, &params, None).unwrap();
        let operator = operator_bound_s(&p, n).unwrap();
        eprintln!(
            "N = {n}: bound {:.4} s (proven {}), operator bound {operator:.4} s, T_total {:.4} s",
            out.lower_bound_s, out.bound_is_optimum, out.t_total_s
        );
        assert!(out.lower_bound_s >= below && out.lower_bound_s >= operator);
        assert!(out.lower_bound_s <= out.t_total_s * (1.0 + 1e-9));
        below = out.lower_bound_s;
    }
}

/// Non-vacuity: the proptest above must see overlapping (sampled) schedules of N robots, not
/// only serial ones, and the runtime check must see the overlap of a schedule that breaks
/// constraint 3.
#[test]
fn most_random_problems_get_sampled_n_robot_schedules() {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strategy = random_problem();
    let mut sampled = 0;
    for seed in 0..30 {
        let p = strategy.new_tree(&mut runner).unwrap().current();
        let n = 3 + (seed as usize % 3);
        let params = SamplerParams {
            samples: 100,
            seed,
            ..SamplerParams::default()
        };
        let out = sample_schedule_n(&p, n, &params, None).unwrap();
        // Overlapping schedules come from the sampler or the staggered candidate.
        if matches!(out.source, Source::Sampled { .. } | Source::Staggered) {
            sampled += 1;
            let serial = p.serial_schedule_n(n, p.dt_s()).unwrap();
            assert!(out.t_total_s < serial.t_total_s(p.dt_s()));
        }
    }
    eprintln!("{sampled} of 30 sampled or staggered");
    assert!(sampled >= 15, "only {sampled} of 30 sampled or staggered");

    // Three robots at once in one LC stretch: validate names it, the coordinator sees it.
    let conf: Vec<bool> = (0..30).map(|n| !(10..20).contains(&n)).collect();
    let p = Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01).unwrap();
    let mut s = p.serial_schedule_n(3, p.dt_s()).unwrap();
    s.offsets_s = vec![0.0, 0.05];
    assert!(matches!(
        validate(&p, &s),
        Err(Violation::BothLowConfidence { .. })
    ));
    for op in adversaries(&p, &s, 0) {
        assert!(run_unchecked(&p, &s, op, 0).is_some(), "{op:?}");
    }
}

/// The two-robot scheduler is the N = 2 case of the N-robot one, to the bit.
#[test]
fn two_robots_are_the_n_robot_scheduler_with_n_2() {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strategy = random_problem();
    for seed in 0..12 {
        let p = strategy.new_tree(&mut runner).unwrap().current();
        let params = SamplerParams {
            samples: 200,
            seed,
            ..SamplerParams::default()
        };
        let two = sample_schedule(&p, &params, None).unwrap();
        assert_eq!(sample_schedule_n(&p, 2, &params, None).unwrap(), two);
        // Warm-started from it, too.
        let again = sample_schedule(&p, &params, Some(&two.schedule)).unwrap();
        assert_eq!(
            sample_schedule_n(&p, 2, &params, Some(&two.schedule)).unwrap(),
            again
        );
    }
}

/// One robot: the fastest execution is both the schedule and the bound.
#[test]
fn one_robot_runs_its_fastest_execution() {
    let conf: Vec<bool> = (0..30).map(|n| !(10..20).contains(&n)).collect();
    let p = Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01).unwrap();
    let out = sample_schedule_n(&p, 1, &SamplerParams::default(), None).unwrap();
    // 20 HC samples at 0.5 and 10 LC at 1: 0.2 s.
    assert!((out.t_total_s - 0.2).abs() < 1e-12, "{}", out.t_total_s);
    assert!(out.schedule.offsets_s.is_empty());
    // The bound (0.05 + 0.1 + 0.05, the fastest execution) is the schedule, up to rounding.
    assert!(
        (out.lower_bound_s - 0.2).abs() < 1e-12,
        "{}",
        out.lower_bound_s
    );
    assert!(out.bound_is_optimum && out.gap.abs() < 1e-12, "{}", out.gap);
    for bad in [0, tandem_realtime::MAX_ROBOTS + 1] {
        assert!(sample_schedule_n(&p, bad, &SamplerParams::default(), None).is_err());
        assert!(operator_bound_s(&p, bad).is_err());
    }
}

/// The bound by hand, and where it is tight: with one LC run the robots can pass it back to
/// back, each at its fastest around it, and that schedule (constraints 1–4) has `T_total`
/// equal to the bound.
#[test]
fn the_operator_bound_by_hand_and_tight_for_one_lc_run() {
    // [HC ×10, LC ×10, HC ×10] at 10 ms, gradients 1 in [0.5, 2]: a_0 = a_m = 0.05 s, L = 0.1 s.
    let conf: Vec<bool> = (0..30).map(|n| !(10..20).contains(&n)).collect();
    let p = Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01).unwrap();
    for n in 1..=tandem_realtime::MAX_ROBOTS {
        let bound = operator_bound_s(&p, n).unwrap();
        // max(0.05 + N·0.1 + 0.05, fastest execution 0.2).
        let want = (0.1 + 0.1 * n as f64).max(0.2);
        assert!((bound - want).abs() < 1e-12, "N = {n}: {bound} vs {want}");
        // Robot i starts at i·L: its LC run follows robot i − 1's back to back.
        let s = Schedule {
            grad_exec: vec![p.fastest_warp(); n],
            offsets_s: (1..n).map(|i| 0.1 * i as f64).collect(),
            tick_s: p.dt_s(),
            holds: Vec::new(),
        };
        let free = validate(&p, &s);
        assert!(
            matches!(free, Ok(()) | Err(Violation::InsufficientMargins { .. })),
            "N = {n}: {free:?}"
        );
        assert!((s.t_total_s(p.dt_s()) - bound).abs() < 1e-9, "N = {n}");
    }
}

/// Whether `s` satisfies Eq. 20 constraints 1–4 (everything `validate` checks before the
/// margins).
fn margin_free_feasible(p: &Problem, s: &Schedule) -> bool {
    matches!(
        validate(p, s),
        Ok(()) | Err(Violation::InsufficientMargins { .. })
    )
}

/// Brute force on small random problems: the bound is never above any schedule of
/// constraints 1–4 found on a grid (every robot's HC runs at one of three speed factors,
/// offsets on a grid over their admissible range), and for two robots never above the exact
/// margin-free optimum `T*₀`.
#[test]
fn the_operator_bound_is_below_every_margin_free_schedule() {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strategy = random_problem();
    let mut feasible_seen = 0;
    for case in 0..16 {
        let p = strategy.new_tree(&mut runner).unwrap().current();
        let exact = solve_exact(&p, &ExactParams::default()).unwrap();
        assert!(operator_bound_s(&p, 2).unwrap() <= exact.lower_bound_s * (1.0 + 1e-9));
        let n = 3;
        let bound = operator_bound_s(&p, n).unwrap();
        let warp = |u: f64| -> Vec<f64> {
            (0..p.n_ref())
                .map(|k| {
                    if p.conf()[k] {
                        p.grad_min()[k] + u * (p.grad_max()[k] - p.grad_min()[k])
                    } else {
                        p.grad_mean()[k]
                    }
                })
                .collect()
        };
        let speeds = [0.0, 0.5, 1.0];
        let grid = 10;
        let mut best = f64::INFINITY;
        for &u0 in &speeds {
            for &u1 in &speeds {
                for &u2 in &speeds {
                    let grad_exec = vec![warp(u0), warp(u1), warp(u2)];
                    let mut s = Schedule {
                        grad_exec,
                        offsets_s: vec![0.0, 0.0],
                        tick_s: p.dt_s(),
                        holds: Vec::new(),
                    };
                    let end0 = s.end_s(0, p.dt_s());
                    for a in 0..=grid {
                        s.offsets_s[0] = end0 * a as f64 / grid as f64;
                        let end1 = end0.max(s.end_s(1, p.dt_s()));
                        for b in 0..=grid {
                            s.offsets_s[1] = end1 * b as f64 / grid as f64;
                            if margin_free_feasible(&p, &s) {
                                feasible_seen += 1;
                                best = best.min(s.t_total_s(p.dt_s()));
                            }
                        }
                    }
                }
            }
        }
        assert!(
            best.is_finite(),
            "case {case}: the grid holds the serial schedule"
        );
        assert!(
            bound <= best * (1.0 + 1e-9),
            "case {case}: bound {bound} above a feasible {best}"
        );
    }
    assert!(feasible_seen > 1000, "{feasible_seen}");
}

/// Issue "hold points", item 4: three robots overlap wherever a plain grid search over the two
/// start offsets (every robot on its fastest warp, `τ_2, τ_3` on a grid of a twelfth of one
/// execution) finds a schedule that passes `validate` and beats the serial one; the scheduler
/// then returns a schedule shorter than serial too (sampled, staggered or otherwise).
#[test]
fn three_robots_overlap_wherever_a_grid_search_finds_an_overlap() {
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strategy = random_problem();
    let (mut grid_found, mut checked) = (0, 0);
    for seed in 0..60 {
        let p = strategy.new_tree(&mut runner).unwrap().current();
        let serial = p.serial_schedule_n(3, p.dt_s()).unwrap();
        let serial_t = serial.t_total_s(p.dt_s());
        let one = serial.grad_exec[0]
            .iter()
            .map(|g| g * p.dt_s())
            .sum::<f64>();
        const G: usize = 12;
        let mut best_grid = f64::INFINITY;
        for i in 0..=2 * G {
            for j in 0..=2 * G {
                let mut s = serial.clone();
                s.offsets_s = vec![i as f64 * one / G as f64, j as f64 * one / G as f64];
                if validate(&p, &s).is_ok() {
                    best_grid = best_grid.min(s.t_total_s(p.dt_s()));
                }
            }
        }
        checked += 1;
        if best_grid >= serial_t * (1.0 - 1e-9) {
            continue;
        }
        grid_found += 1;
        let params = SamplerParams {
            samples: 100,
            seed,
            ..SamplerParams::default()
        };
        let out = sample_schedule_n(&p, 3, &params, None).unwrap();
        assert!(
            out.t_total_s < serial_t * (1.0 - 1e-9),
            "problem {seed}: the grid overlaps at {best_grid} s, the scheduler returns serial \
             {} s ({:?})",
            out.t_total_s,
            out.source
        );
    }
    eprintln!("{grid_found} of {checked} problems overlap on the grid");
    assert!(
        grid_found >= 20,
        "only {grid_found} of {checked} overlap on the grid"
    );
}
