//! Rounds schedules with the operator's switch time `δ` and the load cap `u_max` (issue 41;
//! docs/decisions.md, "Rounds schedules with the switch time and the load cap (issue 41)"):
//! `δ = 0` and `u_max = 1` reproduce the scheduler before them bit for bit, every schedule the
//! scheduler returns keeps `δ` (`validate_with_switch`) and the cap (`busy_share`), and its
//! certificate's bound is the `δ`-bound.

use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_schedule::testkit::random_problem;
use tandem_schedule::{
    Error, ExactParams, Outcome, Problem, SamplerParams, Source, Violation, busy_share,
    margin_free_bound, sample_schedule_n, validate_with_switch,
};

/// FNV-1a over 64-bit words.
fn fnv(hash: &mut u64, word: u64) {
    for b in word.to_le_bytes() {
        *hash ^= u64::from(b);
        *hash = hash.wrapping_mul(0x0100_0000_01b3);
    }
}

/// Every bit of an outcome the state file keeps: warps, offsets, tick, `T_total`, source,
/// bound, gap.
fn digest(hash: &mut u64, out: &Outcome) {
    for w in &out.schedule.grad_exec {
        for g in w {
            fnv(hash, g.to_bits());
        }
    }
    for o in &out.schedule.offsets_s {
        fnv(hash, o.to_bits());
    }
    fnv(hash, out.schedule.tick_s.to_bits());
    fnv(hash, out.t_total_s.to_bits());
    for b in out.source.name().bytes() {
        fnv(hash, u64::from(b));
    }
    if let Source::Sampled { candidate } = out.source {
        fnv(hash, candidate);
    }
    fnv(hash, out.lower_bound_s.to_bits());
    fnv(hash, out.gap.to_bits());
    fnv(hash, u64::from(out.bound_is_optimum));
}

/// The scheduler's outcomes on 24 random problems (`testkit::random_problem`, 60–300
/// samples at 0.1 s), `N = 2, 3, 4` in turn, 300 samples each, default parameters otherwise.
fn outcomes_digest(params: impl Fn(u64) -> SamplerParams) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325;
    for case in 0..24u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(case);
        let p = random_problem(&mut rng, 60..=300, 0.1).unwrap();
        let n = 2 + (case % 3) as usize;
        match sample_schedule_n(&p, n, &params(case), None) {
            Ok(out) => digest(&mut hash, &out),
            Err(e) => {
                for b in e.to_string().bytes() {
                    fnv(&mut hash, u64::from(b));
                }
            }
        }
    }
    hash
}

/// The digest of [`outcomes_digest`] computed on the scheduler before the switch time and
/// the cap entered it (commit 02b5bad, the same test file run there).
const BEFORE_SWITCH: u64 = 0xde94_33d2_94e7_2203;

#[test]
fn zero_switch_time_and_no_cap_are_the_scheduler_before_bit_for_bit() {
    let params = |case| SamplerParams {
        samples: 300,
        seed: case,
        ..SamplerParams::default()
    };
    let got = outcomes_digest(params);
    assert_eq!(got, BEFORE_SWITCH, "{got:#x}");
}

/// [HC ×h, LC ×10, HC ×h] at 0.1 s, gradients 1 in [0.5, 2]: every robot has one LC
/// stretch of 1 s between a head and a tail of `h/20`–`h/5` s.
fn hlh(h: usize) -> Problem {
    let n = 2 * h + 10;
    let conf: Vec<bool> = (0..n).map(|i| !(h..h + 10).contains(&i)).collect();
    Problem::new(conf, vec![1.0; n], vec![0.5; n], vec![2.0; n], 0.1).unwrap()
}

#[test]
fn two_robots_one_stretch_each_by_hand() {
    // Heads and tails of 1.5–6 s.
    let p = hlh(30);
    let ex = ExactParams::default();
    for (switch_s, bound_s) in [(0.0, 5.0), (0.5, 5.5), (2.0, 7.0)] {
        // The δ-bound: head 1.5 s, the two stretches 2 s, one switch δ, tail 1.5 s; robot 2
        // starts at 1 + δ ≤ |ψ_E1| = 4 s at the fastest.
        let b = margin_free_bound(&p, 2, &ex, switch_s).unwrap();
        assert!(b.proven_optimal);
        assert!(
            (b.lower_bound_s - bound_s).abs() < 1e-9,
            "δ = {switch_s}: {}",
            b.lower_bound_s
        );
        let params = SamplerParams {
            samples: 500,
            switch_s,
            ..SamplerParams::default()
        };
        let out = sample_schedule_n(&p, 2, &params, None).unwrap();
        assert_eq!(validate_with_switch(&p, &out.schedule, switch_s), Ok(()));
        assert_eq!(out.lower_bound_s.to_bits(), b.lower_bound_s.to_bits());
        assert!(out.t_total_s >= bound_s - 1e-9, "{}", out.t_total_s);
        // Never worse than the serial schedule, 8 s: its tail and head, 3 s at their fastest
        // (as the worst case may run them), keep even δ = 2 s.
        assert!(out.t_total_s <= 8.0 + 1e-9, "{}", out.t_total_s);
        assert!(
            (out.gap - (out.t_total_s - bound_s) / bound_s).abs() < 1e-9,
            "{}",
            out.gap
        );
    }
    // Heads and tails of 0.5–2 s: the worst case may run robot 1's tail and robot 2's head at
    // their fastest, 1 s together, so no schedule keeps δ = 2 s (k = 20 ticks of 0.1 s): the
    // bound (0.5 + 2 + 2 + 0.5 = 5 s) stands, and the scheduler says why it has no schedule.
    let p = hlh(10);
    let b = margin_free_bound(&p, 2, &ex, 2.0).unwrap();
    assert!((b.lower_bound_s - 5.0).abs() < 1e-9, "{}", b.lower_bound_s);
    let params = SamplerParams {
        samples: 200,
        switch_s: 2.0,
        ..SamplerParams::default()
    };
    let e = sample_schedule_n(&p, 2, &params, None).unwrap_err();
    assert!(
        matches!(
            e,
            Error::NoFeasibleSchedule {
                serial: Violation::InsufficientSwitchTime { .. }
            }
        ),
        "{e}"
    );
    // δ = 0.5 s (5 ticks): the serial schedule's 5 + 5 ticks of tail and head keep it.
    let out = sample_schedule_n(
        &p,
        2,
        &SamplerParams {
            switch_s: 0.5,
            ..params
        },
        None,
    )
    .unwrap();
    assert_eq!(validate_with_switch(&p, &out.schedule, 0.5), Ok(()));
    assert!(out.t_total_s <= 4.0 + 1e-9);
}

#[test]
fn the_load_cap_lengthens_the_round_to_its_share() {
    let p = hlh(10);
    let params = SamplerParams {
        samples: 300,
        ..SamplerParams::default()
    };
    let free = sample_schedule_n(&p, 2, &params, None).unwrap();
    let share = busy_share(&free.schedule, &p, 0.0).unwrap();
    // 2 s of low confidence over T_total.
    assert!((share - 2.0 / free.t_total_s).abs() < 1e-9, "{share}");
    let u_max = 0.9 * share;
    let capped = sample_schedule_n(
        &p,
        2,
        &SamplerParams {
            max_busy_share: u_max,
            ..params.clone()
        },
        None,
    )
    .unwrap();
    assert_eq!(validate_with_switch(&p, &capped.schedule, 0.0), Ok(()));
    let got = busy_share(&capped.schedule, &p, 0.0).unwrap();
    assert!(got <= u_max, "{got} > {u_max}");
    // The bound with the cap: 2 s / u_max, above the margin-free 3 s.
    assert!((capped.lower_bound_s - 2.0 / u_max).abs() < 1e-9);
    assert!(!capped.bound_is_optimum);
    assert!(capped.t_total_s >= capped.lower_bound_s - 1e-9);
    // A cap no tail can reach is an error naming the parameter.
    let e = sample_schedule_n(
        &p,
        2,
        &SamplerParams {
            max_busy_share: 0.05,
            ..params
        },
        None,
    )
    .unwrap_err();
    assert!(matches!(e, Error::BusyShareUnreachable { .. }), "{e}");
    assert!(e.to_string().contains("max_busy_share"), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Every schedule the scheduler returns keeps `δ` (and the cap), is at least its bound,
    /// and the bound with `δ` is at least the bound without; when the scheduler finds none,
    /// not even the fastest serial schedule keeps `δ`.
    #[test]
    fn every_schedule_keeps_the_switch_time_and_its_bound(
        seed in any::<u64>(),
        n in 2usize..=4,
        which in 0usize..4,
        capped in any::<bool>(),
    ) {
        let switch_s = [0.0, 0.5, 2.0, 7.0][which];
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let p = random_problem(&mut rng, 60..=300, 0.1).unwrap();
        let params = SamplerParams {
            samples: 100,
            seed,
            switch_s,
            max_busy_share: if capped { 0.6 } else { 1.0 },
            ..SamplerParams::default()
        };
        let zero = margin_free_bound(&p, n, &params.exact, 0.0).unwrap();
        let with = margin_free_bound(&p, n, &params.exact, switch_s).unwrap();
        prop_assert!(with.lower_bound_s >= zero.lower_bound_s * (1.0 - 1e-12));
        match sample_schedule_n(&p, n, &params, None) {
            Ok(out) => {
                prop_assert_eq!(validate_with_switch(&p, &out.schedule, switch_s), Ok(()));
                prop_assert!(out.lower_bound_s >= with.lower_bound_s);
                prop_assert!(out.t_total_s >= out.lower_bound_s * (1.0 - 1e-9));
                prop_assert!(out.t_total_s >= zero.lower_bound_s * (1.0 - 1e-9));
                let share = busy_share(&out.schedule, &p, switch_s).unwrap();
                prop_assert!(share <= params.max_busy_share, "{}", share);
            }
            Err(Error::NoFeasibleSchedule { .. }) => {
                let serial = p.serial_schedule_n(n, 0.1).unwrap();
                prop_assert!(switch_s > 0.0);
                prop_assert!(validate_with_switch(&p, &serial, switch_s).is_err());
            }
            Err(Error::BusyShareUnreachable { .. }) => prop_assert!(capped),
            Err(e) => prop_assert!(false, "{}", e),
        }
    }
}
