//! Two robots with hold points and several low-confidence runs: the margin-free optimum
//! re-timed with each switch at the room the margin check asks (`clearance::pair_traded`,
//! docs/decisions.md, "Two robots with holds: clearances traded between switches (issue 38)").

use tandem_schedule::{Problem, SamplerParams, Schedule, Source, sample_schedule_n, validate};

/// A problem dumped by the zoo's `rounds_trace --dump` (`tests/data/NAME`: the fields
/// `problem`, `tick_s` (s), `seed`), with the sampler parameters of the re-schedule that met it.
fn dumped(name: &str) -> (Problem, SamplerParams) {
    #[derive(serde::Deserialize)]
    struct Data {
        problem: Problem,
        tick_s: f64,
        seed: u64,
    }
    let path = format!("{}/tests/data/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    let Data {
        problem,
        tick_s,
        seed,
    } = serde_json::from_str(&text).unwrap();
    let params = SamplerParams {
        seed,
        tick_s: Some(tick_s),
        ..SamplerParams::default()
    };
    (problem, params)
}

/// The problem of a zoo deburring task (selection seed 6, two robots, after 30 rounds: three
/// low-confidence runs of 5.43, 0.02 and 0.15 s, holds `spindle<0.5`; written by `cargo run
/// --release -p tandem-zoo --example rounds_trace -- deburring 6 2 30 --dump 30 PATH`, the
/// re-schedule's seed and tick). Before the candidate the scheduler returned the held
/// completion's 29.319 s (robot 2 waits at a hold until robot 1 has left its long run; the
/// margin-free optimum 24.357 s, gap 20.4 %); the optimum re-timed with the three switches'
/// clearances set from the check's slacks passes at 26.659 s.
#[test]
fn a_zoo_deburring_task_gets_each_switch_the_room_the_check_asks() {
    let (p, params) = dumped("zoo_deburring_select6_round30.json");
    let out = sample_schedule_n(&p, 2, &params, None).unwrap();
    assert_eq!(validate(&p, &out.schedule), Ok(()));
    assert!(out.bound_is_optimum);
    assert!(
        (out.lower_bound_s - 24.357).abs() < 1e-3,
        "{}",
        out.lower_bound_s
    );
    assert!(out.lower_bound_s <= out.t_total_s);
    assert_eq!(out.source, Source::Held);
    // Before: 29.319 s; the candidate's 26.659 s.
    assert!(out.t_total_s < 27.0, "{} s", out.t_total_s);
}

/// A zoo dispensing problem (selection seed 5, two robots, after 30 rounds; written by `cargo
/// run --release -p tandem-zoo --example rounds_trace -- dispensing 5 2 30 --dump 30 PATH`,
/// the fields `problem`, `tick_s`, `seed` kept): LC runs `A` = 722–816 and `B` = 1329–1701,
/// between them an HC gap `G` = 817–1328 without a usable hold (holds `valve<0.5` at 1–267,
/// 440–722 and 2235–2814). The scheduler runs robot 2's runs first and holds robot 1 at 721
/// (27.07 s, the least of that order: robot 2's fastest way to `B`'s end plus robot 1's fastest
/// way from 721 to the end); the margin-free optimum alternates the runs (22.692 s). Every
/// alternating timing robot 2's gap can hold fails the margin check — robot 2 started at an
/// offset (no holds) or held at 721 until robot 1 has left `A` (a release rule), through `G`
/// at its fastest, halfway or its slowest: the room between robot 2 leaving `A` and robot 1
/// entering `B` plus the room between robot 1 leaving `B` and robot 2 entering it is at most
/// `G`'s slowest traversal less `B` (1.515 s), and no split of it passes (docs/decisions.md,
/// "Two robots with holds: the alternating order that dispensing loses (issue 38)"). If this
/// test fails, the check accepts an alternating schedule up to 4.4 s shorter than the
/// scheduler's: a candidate that builds it then wins.
#[test]
fn the_alternating_order_of_a_zoo_dispensing_task_fails_the_check_at_every_tried_timing() {
    let (p, params) = dumped("zoo_dispensing_select5_round30.json");
    let tick_s = params.tick_s.expect("the dump names its tick");
    let out = sample_schedule_n(&p, 2, &params, None).unwrap();
    assert_eq!(validate(&p, &out.schedule), Ok(()));
    assert!(out.bound_is_optimum);
    assert!(
        (out.lower_bound_s - 22.692).abs() < 1e-3,
        "{}",
        out.lower_bound_s
    );
    assert!((out.t_total_s - 27.075).abs() < 0.01, "{}", out.t_total_s);
    let fast = p.fastest_warp();
    let (gap, b) = (817..1329, 1329..1702);
    let secs = |w: &[f64], r: std::ops::Range<usize>| w[r].iter().sum::<f64>() * p.dt_s();
    // Robot 1's fastest way to `B`'s end: every alternating schedule ends at least that plus
    // robot 2's `B` and tail, `T*₀`.
    let b_end_s = secs(&fast, 0..1702);
    let mut tried = 0;
    for alpha in [0.0, 0.5, 1.0] {
        let mut slow = fast.clone();
        for n in gap.clone() {
            slow[n] = p.grad_min()[n] + alpha * (p.grad_max()[n] - p.grad_min()[n]);
        }
        // Robot 2 on `slow` started at `τ` enters `B` at `τ + to_b` and leaves `A` at
        // `τ + to_g`: the window where it enters `B` after robot 1 left it and left `A` before
        // robot 1 enters `B`.
        let (to_b, to_g) = (secs(&slow, 0..b.start), secs(&slow, 0..gap.start));
        let b_start_s = secs(&fast, 0..b.start);
        let (lo, hi) = (b_end_s - to_b, b_start_s - to_g);
        assert!(hi > lo, "alpha {alpha}: no window");
        let steps = 12;
        for k in 1..steps {
            let tau = lo + (hi - lo) * k as f64 / steps as f64;
            let offset = Schedule {
                grad_exec: vec![fast.clone(), slow.clone()],
                offsets_s: vec![tau],
                tick_s,
                holds: Vec::new(),
            };
            // The same timing with robot 2 waiting at 721 (the latest usable hold before `A`)
            // until robot 1 has passed 817, its planned dwell `τ`.
            let held = Schedule {
                offsets_s: vec![0.0],
                holds: serde_json::from_value(serde_json::json!([[], [{
                    "ref_idx": 721,
                    "dwell_s": tau,
                    "after": [{"robot": 0, "ref_idx": 817}],
                }]]))
                .unwrap(),
                ..offset.clone()
            };
            for s in [&offset, &held] {
                tried += 1;
                let t = s.t_total_s(p.dt_s());
                assert!(t < out.t_total_s, "alpha {alpha} tau {tau}: {t} s");
                assert!(
                    validate(&p, s).is_err(),
                    "alpha {alpha}, tau {tau} s: an alternating schedule of {t} s passes"
                );
            }
        }
    }
    assert_eq!(tried, 66);
}
