//! The safety invariant end to end: schedules FOUND BY THE SAMPLER, run through
//! `tandem_realtime::Coordinator` under random and extreme operator gradient sequences, never
//! have both robots low-confidence in the same control tick.

mod common;

use proptest::prelude::*;
use proptest::strategy::ValueTree;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_realtime::Coordinator;
use tandem_realtime::adversary::{Adversary, run_adversary};
use tandem_schedule::{OffsetSampling, Problem, SamplerParams, Schedule, Source, sample_schedule};

/// The adversaries of these tests: the extremes, switching every tick or after 1–20 ticks,
/// and a fresh random gradient in a range covering all bounds every tick.
const FASTEST: Adversary = Adversary::Fastest;
const SLOWEST: Adversary = Adversary::Slowest;
const SWITCHING: Adversary = Adversary::Switching;
const RANDOM_SWITCHING: Adversary = Adversary::RandomSwitching { max_hold: 20 };
const RANDOM: Adversary = Adversary::Random { lo: 0.1, hi: 3.0 };

/// Runs one execution; returns the first tick index with both robots low-confidence.
fn run(p: &Problem, s: &Schedule, tick_s: f64, op: Adversary, seed: u64) -> Option<u64> {
    let c = Coordinator::new(s.timelines(p).unwrap(), tick_s).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    // Generous cap: every robot at its slowest, run serially, plus slack.
    let slowest_s: f64 = p.grad_max().iter().sum::<f64>() * p.dt_s() * 4.0;
    let max_ticks = (slowest_s / tick_s) as u64 + 100;
    let r = run_adversary(c, op, &mut rng, max_ticks);
    assert!(
        r.finished,
        "execution did not finish within {max_ticks} ticks"
    );
    r.first_overlap
}

/// Random small problems: confidence in runs (1–12 samples, HC runs twice as likely), random
/// means and bounds per sample.
/// The sampler's default (robot 2 fitted) or the uniform-feasible offsets.
fn offset_mode(fitted: bool) -> OffsetSampling {
    if fitted {
        OffsetSampling::default()
    } else {
        OffsetSampling::UniformFeasible
    }
}

fn random_problem() -> impl Strategy<Value = Problem> {
    proptest::collection::vec((1usize..12, prop::bool::weighted(0.65)), 1..8)
        .prop_flat_map(|blocks| {
            let conf: Vec<bool> = blocks
                .iter()
                .flat_map(|&(len, hc)| std::iter::repeat_n(hc, len))
                .collect();
            let n = conf.len();
            (Just(conf), common::gradients(n))
        })
        .prop_map(|(conf, g)| common::problem(conf, &g))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn sampled_schedules_never_overlap_at_runtime(
        p in random_problem(),
        seed in any::<u64>(),
        tick_frac in 0.25f64..=1.0,
        samples in 20usize..150,
        fitted in any::<bool>(),
    ) {
        let tick_s = tick_frac * p.dt_s();
        let params = SamplerParams {
            samples,
            seed,
            tick_s: Some(tick_s),
            offset: offset_mode(fitted),
            ..SamplerParams::default()
        };
        let out = sample_schedule(&p, &params, None).unwrap();
        for op in [
            FASTEST,
            SLOWEST,
            SWITCHING,
            RANDOM_SWITCHING,
            RANDOM,
        ] {
            for rep in 0..2u64 {
                let hit = run(&p, &out.schedule, tick_s, op, seed ^ rep);
                prop_assert!(
                    hit.is_none(),
                    "both LC at tick {:?} with {:?} (source {:?})", hit, op, out.source
                );
            }
        }
    }
}

/// The proptest above must exercise sampled (overlapping) schedules, not only serial ones.
#[test]
fn most_random_problems_get_sampled_schedules() {
    for fitted in [false, true] {
        let mut runner = proptest::test_runner::TestRunner::deterministic();
        let strategy = random_problem();
        let mut sampled = 0;
        for seed in 0..40 {
            let p = strategy.new_tree(&mut runner).unwrap().current();
            let params = SamplerParams {
                samples: 100,
                seed,
                offset: offset_mode(fitted),
                ..SamplerParams::default()
            };
            let out = sample_schedule(&p, &params, None).unwrap();
            if matches!(out.source, Source::Sampled { .. }) {
                sampled += 1;
                for op in [FASTEST, SLOWEST, SWITCHING] {
                    assert_eq!(run(&p, &out.schedule, p.dt_s(), op, seed), None);
                }
            }
        }
        eprintln!("fitted {fitted}: {sampled} of 40 sampled");
        // Fitted robot 2 keeps 2 ticks + 10 % clear around each region, a lot on these
        // problems of a few dozen 10 ms samples, so fewer beat the serial schedule there.
        let need = if fitted { 12 } else { 20 };
        assert!(
            sampled >= need,
            "fitted {fitted}: only {sampled} of 40 sampled"
        );
    }
}

/// Non-vacuity: the runtime check does see overlaps when a schedule breaks constraint 3.
#[test]
fn an_overlapping_schedule_is_caught_at_runtime() {
    let conf: Vec<bool> = (0..30).map(|n| !(10..20).contains(&n)).collect();
    let p = Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01).unwrap();
    let mut s = p.serial_schedule();
    s.offset_s = 0.0;
    assert!(tandem_schedule::validate(&p, &s).is_err());
    for op in [FASTEST, SLOWEST, SWITCHING] {
        assert!(run(&p, &s, p.dt_s(), op, 0).is_some(), "{op:?}");
    }
}
