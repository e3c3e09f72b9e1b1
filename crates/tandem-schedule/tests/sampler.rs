//! The anytime sampler (§II-C) through the public API: the sampler alone
//! (`SamplerBaselines::sampler_only`), as the benchmarks measure it; the scheduler with the
//! completion beside it is tested in `tests/exact.rs`.

mod common;

use proptest::prelude::*;
use tandem_schedule::{
    DrawnOffset, ExactParams, MarginCheck, Problem, SamplerBaselines, SamplerParams, Schedule,
    Source, sample_schedule_with_baselines, validate,
};

/// `n` samples, low confidence on `lc`, bounds `[lo, hi]`×mean around a wobbling mean.
fn problem(n: usize, lc: &[std::ops::Range<usize>], lo: f64, hi: f64) -> Problem {
    let mean: Vec<f64> = (0..n).map(|i| 1.0 + 0.2 * (i as f64 / 7.0).sin()).collect();
    let conf = (0..n).map(|i| !lc.iter().any(|r| r.contains(&i))).collect();
    Problem::new(
        conf,
        mean.clone(),
        mean.iter().map(|m| lo * m).collect(),
        mean.iter().map(|m| hi * m).collect(),
        0.01,
    )
    .unwrap()
}

/// The sampler alone (no completion beside it).
fn sample_schedule(
    p: &Problem,
    params: &SamplerParams,
    previous: Option<&Schedule>,
) -> tandem_schedule::Result<tandem_schedule::Outcome> {
    sample_schedule_with_baselines(p, params, &sampler_only(), previous)
}

fn sampler_only() -> SamplerBaselines {
    SamplerBaselines::SAMPLER_ONLY
}

fn params(samples: usize, seed: u64) -> SamplerParams {
    SamplerParams {
        samples,
        seed,
        ..SamplerParams::default()
    }
}

fn random_problem() -> impl Strategy<Value = Problem> {
    (3usize..60).prop_flat_map(|n| {
        (
            proptest::collection::vec(prop::bool::weighted(0.7), n),
            common::gradients(n),
        )
            .prop_map(|(conf, g)| common::problem(conf, &g))
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Every returned schedule passes `validate`, and it is never slower than the serial one.
    #[test]
    fn returned_schedules_are_valid_and_no_slower_than_serial(
        p in random_problem(),
        seed in any::<u64>(),
        tick_frac in 0.3f64..=1.0,
        pieces in 0usize..4,
        uniform_offset in any::<bool>(),
        p_fastest in 0.0f64..=1.0,
    ) {
        let tick_s = tick_frac * p.dt_s();
        let params = SamplerParams {
            samples: 200,
            seed,
            tick_s: Some(tick_s),
            pieces: pieces.max(1),
            p_fastest,
            ..SamplerParams::default()
        };
        let baselines = SamplerBaselines {
            per_sample: pieces == 0,
            drawn_offset: Some(if uniform_offset {
                DrawnOffset::Uniform
            } else {
                DrawnOffset::UniformFeasible
            }),
            ..sampler_only()
        };
        let out = sample_schedule_with_baselines(&p, &params, &baselines, None).unwrap();
        // The schedule carries the sampler's tick and is valid at it.
        prop_assert_eq!(out.schedule.tick_s, tick_s);
        prop_assert_eq!(validate(&p, &out.schedule), Ok(()));
        let serial = p.serial_schedule(tick_s).unwrap();
        prop_assert!(out.t_total_s <= serial.t_total_s(p.dt_s()));
        // The returned T_total is the schedule's own, read from the one clock.
        prop_assert_eq!(out.t_total_s, out.schedule.t_total_s(p.dt_s()));
        if out.source == Source::Serial {
            prop_assert_eq!(&out.schedule, &serial);
        }
    }
}

#[test]
fn sampler_beats_serial_on_a_schedulable_problem() {
    let p = problem(120, &[10..30, 70..90], 0.5, 2.0);
    let out = sample_schedule(&p, &params(2000, 3), None).unwrap();
    assert!(matches!(out.source, Source::Sampled { .. }));
    assert_eq!(validate(&p, &out.schedule), Ok(()));
    let serial = p.serial_schedule(0.01).unwrap();
    assert!(out.t_total_s < 0.9 * serial.t_total_s(0.01));
}

#[test]
fn all_low_confidence_gives_the_serial_schedule() {
    let all = std::slice::from_ref(&(0..50));
    let p = problem(50, all, 0.5, 2.0);
    let out = sample_schedule(&p, &params(1000, 1), None).unwrap();
    assert_eq!(out.source, Source::Serial);
    assert_eq!(out.schedule, p.serial_schedule(p.dt_s()).unwrap());
    // Serial at the mean gradient: T_total = 2·Σ mean·dt.
    let single: f64 = p.grad_mean().iter().sum::<f64>() * 0.01;
    assert!((out.t_total_s - 2.0 * single).abs() < 1e-9);
}

#[test]
fn all_high_confidence_overlaps_fully() {
    let p = problem(80, &[], 0.5, 2.0);
    let out = sample_schedule(&p, &params(5000, 2), None).unwrap();
    let fastest: f64 = p.grad_min().iter().sum::<f64>() * 0.01;
    // Nearly both robots at ψ̇min, started nearly together: T_total ≈ fastest single run.
    assert!(
        out.t_total_s <= 1.02 * fastest,
        "{} vs {fastest}",
        out.t_total_s
    );
    assert!(out.schedule.offsets_s[0] <= 0.02 * fastest);
}

#[test]
fn same_seed_same_schedule_with_1_and_2_threads() {
    let p = problem(300, &[20..60, 120..160, 220..250], 0.6, 1.8);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| sample_schedule(&p, &params(3000, 42), None).unwrap())
    };
    let one = run(1);
    let two = run(2);
    assert_eq!(one, two);
    assert!(matches!(one.source, Source::Sampled { .. }));
    // And another seed gives another schedule.
    let other = sample_schedule(&p, &params(3000, 43), None).unwrap();
    assert_ne!(other.schedule, one.schedule);
}

#[test]
fn lazy_and_exhaustive_margins_agree_with_both_checks() {
    let p = problem(200, &[20..50, 100..130], 0.7, 1.5);
    let base = params(1500, 9);
    let lazy = sample_schedule(&p, &base, None).unwrap();
    for (margin_check, exhaustive_margins) in [
        (MarginCheck::SinglePass, true),
        (MarginCheck::PerPair, false),
        (MarginCheck::PerPair, true),
    ] {
        let baselines = SamplerBaselines {
            margin_check,
            exhaustive_margins,
            ..sampler_only()
        };
        let out = sample_schedule_with_baselines(&p, &base, &baselines, None).unwrap();
        assert_eq!(out.schedule, lazy.schedule);
        assert_eq!(out.source, lazy.source);
    }
}

#[test]
fn previous_schedule_is_kept_when_nothing_better_is_found() {
    let p = problem(120, &[10..30, 70..90], 0.5, 2.0);
    let first = sample_schedule(&p, &params(2000, 5), None).unwrap();
    // The same candidates again: the best ties with the previous one, which is kept.
    let again = sample_schedule(&p, &params(2000, 5), Some(&first.schedule)).unwrap();
    assert_eq!(again.source, Source::Previous);
    assert_eq!(again.schedule, first.schedule);
    // A single fresh candidate cannot beat 2000.
    let one = sample_schedule(&p, &params(1, 6), Some(&first.schedule)).unwrap();
    assert_eq!(one.source, Source::Previous);
    assert_eq!(one.schedule, first.schedule);
}

/// A previous schedule handed to the sampler at another tick is re-checked at the new tick
/// and comes back carrying it; the returned schedule never keeps a tick it was not checked at.
#[test]
fn a_previous_schedule_at_another_tick_is_rechecked_at_the_new_one() {
    let p = problem(120, &[10..30, 70..90], 0.5, 2.0);
    let first = sample_schedule(&p, &params(2000, 5), None).unwrap();
    assert_eq!(first.schedule.tick_s, p.dt_s());
    let half = SamplerParams {
        tick_s: Some(0.005),
        ..params(1, 6)
    };
    let out = sample_schedule(&p, &half, Some(&first.schedule)).unwrap();
    assert_eq!(out.schedule.tick_s, 0.005);
    assert_eq!(validate(&p, &out.schedule), Ok(()));
    if out.source == Source::Previous {
        assert_eq!(out.schedule.grad_exec, first.schedule.grad_exec);
        assert_eq!(out.schedule.offsets_s, first.schedule.offsets_s);
    }
    // A coarser tick (4 samples): the margin check needs more room than the previous
    // schedule left, so it is not kept as it is.
    let coarse = SamplerParams {
        tick_s: Some(0.04),
        ..params(1, 6)
    };
    let mut at_coarse = first.schedule.clone();
    at_coarse.tick_s = 0.04;
    let out = sample_schedule(&p, &coarse, Some(&first.schedule)).unwrap();
    assert_eq!(out.schedule.tick_s, 0.04);
    assert_eq!(validate(&p, &out.schedule), Ok(()));
    assert!(matches!(
        validate(&p, &at_coarse),
        Err(tandem_schedule::Violation::InsufficientMargins { tick_s: 0.04 })
    ));
    assert_ne!(out.source, Source::Previous);
}

#[test]
fn previous_schedule_is_repaired_after_the_model_moves() {
    let p = problem(120, &[10..30, 70..90], 0.5, 2.0);
    let first = sample_schedule(&p, &params(2000, 5), None).unwrap();
    // New model: mean 2 % slower everywhere (bounds scale with it), same confidence.
    let q = Problem::new(
        p.conf().to_vec(),
        p.grad_mean().iter().map(|m| 1.02 * m).collect(),
        p.grad_min().iter().map(|m| 1.02 * m).collect(),
        p.grad_max().iter().map(|m| 1.02 * m).collect(),
        0.01,
    )
    .unwrap();
    assert!(validate(&q, &first.schedule).is_err());
    let out = sample_schedule(&q, &params(1, 6), Some(&first.schedule)).unwrap();
    assert_eq!(validate(&q, &out.schedule), Ok(()));
    assert!(matches!(
        out.source,
        Source::RepairedPrevious | Source::Sampled { .. } | Source::Serial
    ));
    // A previous schedule of the wrong shape is ignored.
    let junk = Schedule {
        grad_exec: vec![vec![1.0; 3], vec![1.0; 3]],
        offsets_s: vec![0.0],
        tick_s: 0.01,
        holds: Vec::new(),
    };
    let out = sample_schedule(&q, &params(10, 6), Some(&junk)).unwrap();
    assert_eq!(validate(&q, &out.schedule), Ok(()));
}

#[test]
fn bad_params_are_rejected() {
    let p = problem(10, &[], 0.5, 2.0);
    for bad in [
        SamplerParams {
            samples: 0,
            ..SamplerParams::default()
        },
        SamplerParams {
            samples: 0,
            ..SamplerParams::default()
        },
        SamplerParams {
            exact: ExactParams {
                max_pieces: 0,
                ..ExactParams::default()
            },
            ..SamplerParams::default()
        },
        SamplerParams {
            tick_s: Some(f64::NAN),
            ..SamplerParams::default()
        },
        SamplerParams {
            p_fastest: 1.5,
            ..SamplerParams::default()
        },
        SamplerParams {
            pieces: 0,
            ..SamplerParams::default()
        },
        SamplerParams {
            widen_max: f64::NAN,
            ..SamplerParams::default()
        },
    ] {
        assert!(matches!(
            sample_schedule(&p, &bad, None),
            Err(tandem_schedule::Error::BadParam { .. })
        ));
    }
}
