//! The exact margin-free search and the certified completion through the public API.

mod common;
#[path = "../benches/support/fixture.rs"]
#[allow(
    dead_code,
    reason = "the synthetic fallback is only called without the fixture file"
)]
mod fixture;

use proptest::prelude::*;
use tandem_schedule::{
    CertifiedSource, ExactParams, Problem, SamplerParams, Violation, certify, earliest_schedule,
    sample_schedule, solve_exact, validate,
};

/// Every machine order with `m` runs per robot (robot of each LC run in time order).
fn all_orders(m: usize) -> Vec<Vec<usize>> {
    fn rec(left: [usize; 2], cur: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
        if left == [0, 0] {
            out.push(cur.clone());
            return;
        }
        for r in 0..2 {
            if left[r] > 0 {
                let mut l = left;
                l[r] -= 1;
                cur.push(r);
                rec(l, cur, out);
                cur.pop();
            }
        }
    }
    let mut out = Vec::new();
    rec([m, m], &mut Vec::new(), &mut out);
    out
}

/// Constraints 1–4 of Eq. 20 hold (the margin check, constraint 5, may still reject).
fn margin_free_valid(p: &Problem, s: &tandem_schedule::Schedule) -> Result<(), Violation> {
    match validate(p, s) {
        Ok(()) | Err(Violation::InsufficientMargins { .. }) => Ok(()),
        Err(v) => Err(v),
    }
}

/// Brute force: the least `T_total` over all machine orders, each at its earliest times.
fn brute_force(p: &Problem, m: usize) -> Option<f64> {
    all_orders(m)
        .iter()
        .filter_map(|o| earliest_schedule(p, o).unwrap())
        .map(|s| {
            margin_free_valid(p, &s).unwrap();
            s.t_total_s(p.dt_s())
        })
        .reduce(f64::min)
}

fn lc_runs(p: &Problem) -> usize {
    p.runs().iter().filter(|r| !r.high_conf).count()
}

/// Random problems with 1–6 LC runs: alternating runs of 1–6 samples, starting HC or LC, with
/// gradient bounds as in `common::gradients` or rigid (`ψ̇min = ψ̇max`) ones.
fn small_problem() -> impl Strategy<Value = Problem> {
    (
        1usize..=6,
        any::<bool>(),
        any::<bool>(),
        proptest::collection::vec(1usize..=6, 13),
    )
        .prop_flat_map(|(m, lc_first, hc_last, lens)| {
            let mut conf = Vec::new();
            let mut high = !lc_first;
            let mut runs = 0;
            for len in lens {
                if !high && runs == m {
                    break;
                }
                conf.extend(std::iter::repeat_n(high, len));
                runs += usize::from(!high);
                high = !high;
            }
            if hc_last && !conf.last().copied().unwrap_or(false) {
                conf.push(true);
            }
            let n = conf.len();
            (
                Just(conf),
                common::gradients(n),
                proptest::collection::vec(prop::bool::weighted(0.1), n),
            )
        })
        .prop_map(|(conf, g, rigid)| {
            let g: Vec<(f64, f64, f64)> = g
                .iter()
                .zip(&rigid)
                .map(|(&(mean, lo, hi), &r)| if r { (mean, 1.0, 1.0) } else { (mean, lo, hi) })
                .collect();
            common::problem(conf, &g)
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(160))]

    /// The search's optimum is the least `T_total` over all machine orders at their earliest
    /// times (an exact brute force), and its schedule satisfies constraints 1–4 with that
    /// `T_total`.
    #[test]
    fn search_equals_brute_force_over_all_orders(p in small_problem()) {
        let m = lc_runs(&p);
        let free = solve_exact(&p, &ExactParams::default()).unwrap();
        prop_assert!(free.proven_optimal);
        let brute = brute_force(&p, m).expect("the serial order is always feasible");
        let tol = 1e-9 * brute.max(1.0);
        prop_assert!((free.lower_bound_s - brute).abs() <= tol, "search {} brute {}", free.lower_bound_s, brute);
        let s = free.schedule.expect("proven optimum comes with its schedule");
        prop_assert!(margin_free_valid(&p, &s).is_ok(), "{:?}", validate(&p, &s));
        prop_assert!((s.t_total_s(p.dt_s()) - brute).abs() <= tol);
        prop_assert_eq!(free.order.len(), 2 * m);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Every certified schedule passes `validate` (margins included), lies above the bound,
    /// and is never worse than the incumbent it was given.
    #[test]
    fn certified_schedules_pass_validate_and_beat_the_incumbent(p in small_problem(), seed in 0u64..4) {
        let sampled = sample_schedule(&p, &SamplerParams { samples: 200, seed, ..SamplerParams::default() }, None).unwrap();
        let cert = certify(&p, &ExactParams::default(), Some(&sampled.schedule)).unwrap();
        prop_assert_eq!(validate(&p, &cert.schedule), Ok(()));
        prop_assert!((cert.schedule.t_total_s(p.dt_s()) - cert.t_total_s).abs() <= 1e-12);
        prop_assert!(cert.t_total_s <= sampled.t_total_s);
        prop_assert!(cert.t_total_s >= cert.lower_bound_s);
        prop_assert!(cert.bound_is_optimum);
        prop_assert!(cert.gap >= 0.0);
        let free = solve_exact(&p, &ExactParams::default()).unwrap();
        prop_assert!((cert.lower_bound_s - free.lower_bound_s).abs() <= 1e-9 * free.lower_bound_s.max(1.0));
    }
}

/// `[LC, HC, LC]`: 10 samples each at 10 ms, gradients 1 in `[0.5, 2]`.
fn lhl() -> Problem {
    let conf: Vec<bool> = (0..30).map(|n| (10..20).contains(&n)).collect();
    Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01).unwrap()
}

#[test]
fn alternation_by_hand() {
    // LC runs of 0.1 s, HC gap [0.05, 0.2] s. Order 1 2 1 2 back to back: robot 2 starts at
    // 0.1 s, robot 1's gap lasts 0.1 s: T*₀ = 0.4 s. Serial: 2 × 0.25 = 0.5 s.
    let p = lhl();
    let free = solve_exact(&p, &ExactParams::default()).unwrap();
    assert!((free.lower_bound_s - 0.4).abs() < 1e-12);
    assert_eq!(free.order, vec![0, 1, 0, 1]);
    assert_eq!(free.stats.lc_runs, 2);
    let s = free.schedule.unwrap();
    assert!((s.offset_s - 0.1).abs() < 1e-12);
    // 1 1 2 2: robot 1's gap at its fastest (0.05 s), robot 2 starts at 0.25 s: 0.5 s.
    let serial_like = earliest_schedule(&p, &[0, 0, 1, 1]).unwrap().unwrap();
    assert!((serial_like.t_total_s(0.01) - 0.5).abs() < 1e-12);
    // Robot 2's gap cannot hold robot 1's run plus its gap: 2 1 1 2 has no schedule (robot 1
    // has no head to wait in).
    assert_eq!(earliest_schedule(&p, &[1, 0, 0, 1]).unwrap(), None);
    assert!(earliest_schedule(&p, &[0, 0, 0, 1]).is_err());
}

#[test]
fn certificate_by_hand() {
    let p = lhl();
    let cert = certify(&p, &ExactParams::default(), None).unwrap();
    assert_eq!(validate(&p, &cert.schedule), Ok(()));
    assert!(cert.bound_is_optimum);
    assert!((cert.lower_bound_s - 0.4).abs() < 1e-12);
    // Never worse than serial (here the margins leave no room to overlap the robots).
    assert!(cert.t_total_s <= 0.5 + 1e-12);
    assert!((cert.gap - (cert.t_total_s - 0.4) / 0.4).abs() < 1e-12);
    // No completion allowed: the serial schedule, with the same bound.
    let none = ExactParams {
        max_margin_checks: 0,
        ..ExactParams::default()
    };
    let cert = certify(&p, &none, None).unwrap();
    assert_eq!(cert.source, CertifiedSource::Serial);
    assert!((cert.t_total_s - 0.5).abs() < 1e-12);
    assert!((cert.gap - 0.25).abs() < 1e-12);
}

#[test]
fn out_of_budget_gives_the_simple_bound() {
    // One piece allowed: the search stops; the bound is a_0 + 2·Σ L + a_m = 0 + 0.4 + 0 and is
    // not proven optimal (here it happens to be tight).
    let p = lhl();
    let tiny = ExactParams {
        max_pieces: 1,
        ..ExactParams::default()
    };
    let free = solve_exact(&p, &tiny).unwrap();
    assert!(!free.proven_optimal);
    assert!(free.schedule.is_none());
    assert!((free.lower_bound_s - 0.4).abs() < 1e-12);
    let cert = certify(&p, &tiny, None).unwrap();
    assert!(!cert.bound_is_optimum);
    assert_eq!(validate(&p, &cert.schedule), Ok(()));
}

#[test]
fn no_low_confidence_means_both_fastest_at_once() {
    let p = Problem::new(vec![true; 5], vec![1.0; 5], vec![0.5; 5], vec![2.0; 5], 0.1).unwrap();
    let free = solve_exact(&p, &ExactParams::default()).unwrap();
    assert!((free.lower_bound_s - 0.25).abs() < 1e-12);
    assert!(free.order.is_empty());
    let cert = certify(&p, &ExactParams::default(), None).unwrap();
    assert_eq!(validate(&p, &cert.schedule), Ok(()));
    assert!((cert.t_total_s - 0.25).abs() < 1e-12);
    assert_eq!(cert.gap, 0.0);
}

#[test]
fn bad_parameters_are_errors() {
    let p = lhl();
    for bad in [
        ExactParams {
            tick_s: Some(0.0),
            ..ExactParams::default()
        },
        ExactParams {
            tick_s: Some(f64::NAN),
            ..ExactParams::default()
        },
        ExactParams {
            max_pieces: 0,
            ..ExactParams::default()
        },
    ] {
        assert!(matches!(
            solve_exact(&p, &bad),
            Err(tandem_schedule::Error::BadParam { .. })
        ));
        assert!(certify(&p, &bad, None).is_err());
    }
}

/// Fragmented confidence like mid-study: `islands` one-sample LC islands spread over three
/// 600-sample passes (deterministic positions), joined by 400-sample HC transitions.
fn fragmented(islands_per_pass: usize) -> Problem {
    let mut conf = Vec::new();
    for pass in 0..4 {
        let mut seg = vec![true; 600];
        if pass < 3 {
            for i in 0..islands_per_pass {
                seg[(i * 7919 + pass * 31) % 600] = false;
            }
        }
        conf.extend(seg);
        if pass < 3 {
            conf.extend(vec![true; 400]);
        }
    }
    let n = conf.len();
    let mean: Vec<f64> = (0..n)
        .map(|i| 1.0 + 0.2 * (i as f64 / 50.0).sin())
        .collect();
    Problem::new(
        conf,
        mean.clone(),
        mean.iter().map(|m| 0.4 * m).collect(),
        mean.iter().map(|m| 1.8 * m).collect(),
        0.01,
    )
    .unwrap()
}

#[test]
fn fragmented_problems_are_solved_exactly_and_certified() {
    for islands in [5, 40, 120] {
        let p = fragmented(islands);
        let free = solve_exact(&p, &ExactParams::default()).unwrap();
        assert!(free.proven_optimal, "{islands} islands per pass");
        let s = free.schedule.as_ref().unwrap();
        assert!(margin_free_valid(&p, s).is_ok());
        assert!((s.t_total_s(0.01) - free.lower_bound_s).abs() < 1e-6);
        let cert = certify(&p, &ExactParams::default(), None).unwrap();
        assert_eq!(validate(&p, &cert.schedule), Ok(()));
        assert!(cert.t_total_s >= free.lower_bound_s - 1e-9);
        assert!(cert.t_total_s <= p.serial_schedule(0.01).unwrap().t_total_s(0.01));
    }
}

#[test]
fn fixture_problem_bound_matches_all_orders_and_the_certificate_passes() {
    // The fixture problem (or, without the file, the synthetic one shaped like it).
    let (p, label) = fixture::mid_study_problem();
    let m = lc_runs(&p);
    let free = solve_exact(&p, &ExactParams::default()).unwrap();
    let brute = brute_force(&p, m).unwrap();
    assert!((free.lower_bound_s - brute).abs() < 1e-9 * brute, "{label}");
    let cert = certify(&p, &ExactParams::default(), None).unwrap();
    assert_eq!(validate(&p, &cert.schedule), Ok(()));
    assert!(cert.bound_is_optimum);
    assert_eq!(cert.source, CertifiedSource::Completed);
    // Issue #15 asks for 0.6 % on this problem (measured: 0.49 %, docs/decisions.md); 1 % leaves
    // room for a regenerated fixture while still catching a completion that falls apart.
    assert!(cert.gap < 0.01, "{label}: gap {}", cert.gap);
}
