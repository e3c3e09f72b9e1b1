//! Two robots on a task with one low-confidence run: the scheduler finds the best schedule
//! of both robots on their fastest warps that the margin check accepts, to within a tick of the
//! least offset on the tick grid (brute force over every offset), and what it returns passes
//! `validate` (docs/decisions.md, "Two robots on their fastest warps at the least offset the
//! check accepts (issue 38)").

use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tandem_schedule::{
    Problem, SamplerBaselines, SamplerParams, Schedule, Source, sample_schedule,
    sample_schedule_with_baselines, validate,
};

/// A task `[HC head, LC, HC tail]` of 10 ms samples: head 20–120 samples, the LC run 10–80,
/// tail 5–60; per run the mean gradient in `[0.6, 1.6)` and the bounds `[lo, hi]·mean` with
/// `lo` in `[0.3, 0.95)`, `hi` in `[1.05, 2.5)`.
fn one_run(rng: &mut ChaCha8Rng) -> Problem {
    let (mut conf, mut mean, mut min, mut max) = (vec![], vec![], vec![], vec![]);
    for (hc, len) in [(true, 20..=120), (false, 10..=80), (true, 5..=60)] {
        let n = rng.random_range(len);
        let m = rng.random_range(0.6..1.6);
        let (lo, hi) = (rng.random_range(0.3..0.95), rng.random_range(1.05..2.5));
        for _ in 0..n {
            conf.push(hc);
            mean.push(m);
            min.push(lo * m);
            max.push(hi * m);
        }
    }
    Problem::new(conf, mean, min, max, 0.01).unwrap()
}

/// The least `T_total` (s) of both robots on the fastest warp with robot 2 started at a
/// multiple of `tick_s` that `validate` accepts (every multiple up to robot 1's end tried).
fn brute_force(p: &Problem, tick_s: f64) -> f64 {
    let serial = p.serial_schedule_n(2, tick_s).unwrap();
    let warp = serial.grad_exec[0].clone();
    let dur_s = warp.iter().sum::<f64>() * p.dt_s();
    let steps = (dur_s / tick_s).ceil() as usize;
    (0..=steps)
        .map(|k| Schedule {
            grad_exec: vec![warp.clone(), warp.clone()],
            offsets_s: vec![(k as f64 * tick_s).min(dur_s)],
            tick_s,
            holds: Vec::new(),
        })
        .find(|s| validate(p, s).is_ok())
        .map_or(f64::INFINITY, |s| s.t_total_s(p.dt_s()))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(60))]

    /// The scheduler is valid and at most a tick above the brute force (its bisection stops
    /// within a tick of a failing offset), at the sample time and at a tick twice as long.
    #[test]
    fn within_a_tick_of_the_best_fastest_offset(seed in any::<u64>(), long in any::<bool>()) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let p = one_run(&mut rng);
        let tick_s = if long { 0.02 } else { 0.01 };
        let params = SamplerParams { samples: 300, seed, tick_s: Some(tick_s), ..SamplerParams::default() };
        let out = sample_schedule(&p, &params, None).unwrap();
        prop_assert_eq!(validate(&p, &out.schedule), Ok(()));
        let brute = brute_force(&p, tick_s);
        prop_assert!(
            out.t_total_s <= brute + tick_s + 1e-9,
            "scheduler {} s ({:?}) against {brute} s on the grid", out.t_total_s, out.source
        );
        prop_assert!(out.lower_bound_s <= out.t_total_s * (1.0 + 2e-9));
    }
}

/// The problem of a zoo painting task (selection seed 3, two robots, after 30 rounds: one
/// low-confidence run per robot; the last plan of `cargo xtask zoo --seeds select --robots 2
/// --families painting`, 37.26 s). Without the staggered candidate (the same scheduler with
/// `exhaustive_margins`, which gives the same result as the default and leaves the staggered
/// candidate out) the completion's shaped single switch is the best, 37.26 s; with it, both
/// robots on the fastest warp with robot 2 at the least offset the check accepts, 35.25 s (the
/// brute force over every 10 ms offset: 35.258 s; the margin-free optimum 33.73 s).
#[test]
fn a_zoo_painting_task_gets_the_best_fastest_offset() {
    #[derive(serde::Deserialize)]
    struct Data {
        problem: Problem,
        tick_s: f64,
        seed: u64,
    }
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/zoo_painting_select3_round30.json"
    ))
    .unwrap();
    let Data {
        problem: p,
        tick_s,
        seed,
    } = serde_json::from_str(&text).unwrap();
    let params = SamplerParams {
        seed,
        tick_s: Some(tick_s),
        ..SamplerParams::default()
    };
    let without = sample_schedule_with_baselines(
        &p,
        &params,
        &SamplerBaselines {
            exhaustive_margins: true,
            ..SamplerBaselines::default()
        },
        None,
    )
    .unwrap();
    let with = sample_schedule(&p, &params, None).unwrap();
    assert_eq!(validate(&p, &with.schedule), Ok(()));
    assert_eq!(with.source, Source::Staggered);
    let brute = brute_force(&p, tick_s);
    assert!((brute - 35.258).abs() < 1e-3, "{brute}");
    assert!(
        with.t_total_s <= brute + tick_s,
        "{} against {brute}",
        with.t_total_s
    );
    assert!(without.t_total_s > brute + 1.5, "{}", without.t_total_s);
    assert!(
        (with.lower_bound_s - 33.727).abs() < 1e-3,
        "{}",
        with.lower_bound_s
    );
}

/// Cases the property above once failed (fresh random seeds, about 3 in 10 000 draws): the
/// check is not monotone within a tick, so the bisection stopped above a failing offset while a
/// passing one lay below it (seed 4279067002966117699: robot 2 passes at 0.850 s, fails at
/// 0.851–0.855 s, the bisection returned 0.8615 s, 1.15 ticks above the brute force). The
/// staggered candidate now walks the tick grid down from its bisected start (`stagger.rs`,
/// `GRID_PROBES`); on 40 000 fresh draws it is then never above the brute force.
#[test]
fn within_a_tick_where_the_check_is_not_monotone_within_a_tick() {
    let cases = [
        (4279067002966117699, false),
        (2418424800052064475, false),
        (16603178174564097022, false),
        (9799827229265908445, false),
        (13210847555150328819, true),
        (11596435966442922161, true),
        (3537902021556005489, false),
        (13010714366824004160, true),
        (15377016297087092204, true),
        (10378632379795498408, false),
        (11654478210666368715, false),
        (7539278371808642403, false),
        (6538324555146705439, false),
    ];
    for (seed, long) in cases {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let p = one_run(&mut rng);
        let tick_s = if long { 0.02 } else { 0.01 };
        let params = SamplerParams {
            samples: 300,
            seed,
            tick_s: Some(tick_s),
            ..SamplerParams::default()
        };
        let out = sample_schedule(&p, &params, None).unwrap();
        assert_eq!(validate(&p, &out.schedule), Ok(()));
        let brute = brute_force(&p, tick_s);
        assert!(
            out.t_total_s <= brute + tick_s + 1e-9,
            "seed {seed}: scheduler {} s against {brute} s",
            out.t_total_s
        );
    }
}
