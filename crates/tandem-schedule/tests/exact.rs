//! The exact margin-free search, the margin-aware completion and the scheduler that chooses
//! between it, the sampler and the fallbacks, through the public API.

mod common;
#[path = "../benches/support/fixture.rs"]
#[allow(
    dead_code,
    reason = "the synthetic fallback is only called without the fixture file"
)]
mod fixture;

use proptest::prelude::*;
use tandem_schedule::{
    ExactParams, Outcome, Problem, SamplerBaselines, SamplerParams, Source, Violation,
    earliest_schedule, sample_schedule, sample_schedule_with_baselines, solve_exact, validate,
};

/// The completion alone (no sampled candidate), with `exact`.
fn complete(p: &Problem, exact: ExactParams) -> Outcome {
    let params = SamplerParams {
        exact,
        ..SamplerParams::default()
    };
    sample_schedule_with_baselines(p, &params, &SamplerBaselines::COMPLETION_ONLY, None).unwrap()
}

/// The certificate's fields agree with the schedule and the bound, and the bound (reported as
/// computed, never clamped) is not above the schedule: the scheduler's schedules have their
/// gradients inside the bounds, so only summation order separates the two (far below
/// 1e-12 relative).
fn check_certificate(p: &Problem, out: &Outcome) {
    assert_eq!(validate(p, &out.schedule), Ok(()));
    assert_eq!(out.t_total_s, out.schedule.t_total_s(p.dt_s()));
    assert!(
        out.lower_bound_s <= out.t_total_s * (1.0 + 1e-12),
        "bound {} above T_total {}",
        out.lower_bound_s,
        out.t_total_s
    );
    assert!(out.gap >= -1e-12, "gap {:e}", out.gap);
    assert!((out.gap - (out.t_total_s - out.lower_bound_s) / out.lower_bound_s).abs() <= 1e-12);
}

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

    /// Every schedule the scheduler returns passes `validate` (margins included), lies above
    /// the proven bound, is never worse than the sampler alone with the same seed nor than the
    /// completion alone, and says where it came from (the sampler's, the completion's or the
    /// staggered candidate's).
    #[test]
    fn scheduled_schedules_pass_validate_and_beat_the_sampler(p in small_problem(), seed in 0u64..4) {
        let params = SamplerParams { samples: 200, seed, ..SamplerParams::default() };
        let alone = sample_schedule_with_baselines(&p, &params, &SamplerBaselines::SAMPLER_ONLY, None).unwrap();
        let both = sample_schedule(&p, &params, None).unwrap();
        let done = complete(&p, ExactParams::default());
        for out in [&alone, &both, &done] {
            check_certificate(&p, out);
            prop_assert!(out.bound_is_optimum);
        }
        prop_assert!(both.t_total_s <= alone.t_total_s);
        prop_assert!(both.t_total_s <= done.t_total_s);
        prop_assert!(
            both.source == alone.source
                || both.source == Source::Completed
                || both.source == Source::Staggered
        );
        let free = solve_exact(&p, &ExactParams::default()).unwrap();
        prop_assert!((both.lower_bound_s - free.lower_bound_s).abs() <= 1e-9 * free.lower_bound_s.max(1.0));
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
    assert!((s.offsets_s[0] - 0.1).abs() < 1e-12);
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
    let out = complete(&p, ExactParams::default());
    check_certificate(&p, &out);
    assert!(out.bound_is_optimum);
    assert!((out.lower_bound_s - 0.4).abs() < 1e-12);
    // Never worse than serial (here the margins leave no room to overlap the robots).
    assert!(out.t_total_s <= 0.5 + 1e-12);
    // No completion allowed: the serial schedule, with the same bound.
    let none = ExactParams {
        max_margin_checks: 0,
        ..ExactParams::default()
    };
    let out = complete(&p, none);
    assert_eq!(out.source, Source::Serial);
    assert!((out.t_total_s - 0.5).abs() < 1e-12);
    assert!((out.gap - 0.25).abs() < 1e-12);
    assert_eq!(out.stats.completion_margin_checks, 0);
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
    let out = complete(&p, tiny);
    assert!(!out.bound_is_optimum);
    check_certificate(&p, &out);
}

#[test]
fn no_low_confidence_means_both_fastest_at_once() {
    let p = Problem::new(vec![true; 5], vec![1.0; 5], vec![0.5; 5], vec![2.0; 5], 0.1).unwrap();
    let free = solve_exact(&p, &ExactParams::default()).unwrap();
    assert!((free.lower_bound_s - 0.25).abs() < 1e-12);
    assert!(free.order.is_empty());
    let out = complete(&p, ExactParams::default());
    check_certificate(&p, &out);
    assert_eq!(out.source, Source::Completed);
    assert!((out.t_total_s - 0.25).abs() < 1e-12);
    assert_eq!(out.gap, 0.0);
}

#[test]
fn bad_parameters_are_errors() {
    let p = lhl();
    let bad = ExactParams {
        max_pieces: 0,
        ..ExactParams::default()
    };
    assert!(matches!(
        solve_exact(&p, &bad),
        Err(tandem_schedule::Error::BadParam {
            name: "max_pieces",
            ..
        })
    ));
    let params = SamplerParams {
        exact: bad,
        ..SamplerParams::default()
    };
    assert!(matches!(
        sample_schedule(&p, &params, None),
        Err(tandem_schedule::Error::BadParam {
            name: "max_pieces",
            ..
        })
    ));
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
        let out = complete(&p, ExactParams::default());
        check_certificate(&p, &out);
        assert!(out.t_total_s >= free.lower_bound_s - 1e-9);
        assert!(out.t_total_s <= p.serial_schedule(0.01).unwrap().t_total_s(0.01));
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
    let out = complete(&p, ExactParams::default());
    check_certificate(&p, &out);
    assert!(out.bound_is_optimum);
    assert_eq!(out.source, Source::Completed);
    // The worst-case margins' cost depends on the demonstrated speed range, which the warp
    // and fit decide (on the fixture since tandem-warp's band-edge fix: 3.96 %, pass 1's
    // fastest samples, docs/decisions.md "The margin-aware completion"); the completion's own
    // target is checked on the pinned problem below.
    let serial = p.serial_schedule(0.01).unwrap().t_total_s(0.01);
    assert!(
        out.t_total_s < serial,
        "{label}: {} ≥ serial {serial}",
        out.t_total_s
    );
}

#[test]
fn pinned_mid_study_problem_is_completed_within_one_percent_of_its_bound() {
    // The fixture problem as the fit made it on 2026-12-01, before tandem-warp's band-edge fix,
    // pinned so that the completion's target does not move with the warp. The target is 0.6 %
    // on the problem first measured (the fixture before an earlier regeneration: 0.45 % now);
    // on this one, with wider gradient bounds, the margins cost more (0.72 %). 1 % catches a
    // completion that falls apart.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/mid_study_problem_2026-12-01.csv");
    let p = fixture::mid_study_problem_at(&path);
    let free = solve_exact(&p, &ExactParams::default()).unwrap();
    assert!(free.proven_optimal);
    let out = complete(&p, ExactParams::default());
    check_certificate(&p, &out);
    assert!(out.bound_is_optimum);
    assert_eq!(out.source, Source::Completed);
    assert!(out.gap < 0.01, "gap {}", out.gap);
}

#[test]
fn same_seed_same_outcome_with_1_and_2_threads() {
    let (p, _) = fixture::mid_study_problem();
    let params = SamplerParams {
        samples: 500,
        seed: 3,
        ..SamplerParams::default()
    };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| sample_schedule(&p, &params, None).unwrap())
    };
    let one = run(1);
    assert_eq!(one, run(2));
    check_certificate(&p, &one);
}

/// Regression (found by `search_equals_brute_force_over_all_orders`, about 1 case in 2,400):
/// 21 samples, a rigid head (sample 0, `ψ̇min = ψ̇max`) and a rigid one-sample HC run between
/// the first two LC runs. Rounding made the zero-weight cycles of the rigid lags read as
/// positive in the earliest-times network, so every order, the optimal one included, was
/// declared infeasible and the search's optimum was not proven.
#[test]
fn rigid_runs_are_solved_and_certified() {
    let conf: Vec<bool> = [
        1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 1, 1, 1, 1, 1,
    ]
    .iter()
    .map(|&c| c == 1)
    .collect();
    let g0 = 0.6749386554742198;
    let mut mean = vec![0.5; 21];
    mean[0] = g0;
    let mut min = vec![0.15; 21];
    min[0] = g0;
    min[4] = 0.5;
    let max = mean.clone();
    let p = Problem::new(conf, mean, min, max, 0.01).unwrap();
    // LC runs 0.015, 0.03, 0.015 s; gaps [a_0, a_0], [0.005, 0.005], [0.003, 0.01],
    // [0.0075, 0.025] s with a_0 = 0.01·g0. Robot 1's runs and its rigid gap fill
    // [a_0, a_0 + 0.05]; robot 2's first two runs (0.05 s with its rigid gap) fit neither in
    // robot 1's head nor in its gap of at most 0.01 s, so robot 2 goes after robot 1's last
    // run: τ = 0.068, T*₀ = τ + the fastest execution a_0 + 0.0755.
    let a0 = 0.01 * g0;
    let optimum = 0.068 + a0 + 0.0755;
    let free = solve_exact(&p, &ExactParams::default()).unwrap();
    assert!(free.proven_optimal);
    assert!(
        (free.lower_bound_s - optimum).abs() < 1e-12,
        "{}",
        free.lower_bound_s
    );
    assert_eq!(free.order, vec![0, 0, 0, 1, 1, 1]);
    let brute = brute_force(&p, lc_runs(&p)).unwrap();
    assert!((brute - optimum).abs() < 1e-12, "{brute}");
    let s = free.schedule.unwrap();
    assert!(margin_free_valid(&p, &s).is_ok());
    let params = SamplerParams {
        samples: 200,
        ..SamplerParams::default()
    };
    for out in [
        sample_schedule(&p, &params, None).unwrap(),
        complete(&p, ExactParams::default()),
    ] {
        check_certificate(&p, &out);
        assert!(out.bound_is_optimum);
    }
}
