//! Two robots with hold points and several low-confidence runs: the margin-free optimum
//! re-timed with each switch at the room the margin check asks (`clearance::pair_traded`,
//! docs/decisions.md, "Two robots with holds: clearances traded between switches (issue 38)").

use tandem_schedule::{Problem, SamplerParams, Source, sample_schedule_n, validate};

/// The problem of a zoo deburring task (selection seed 6, two robots, after 30 rounds: three
/// low-confidence runs of 5.43, 0.02 and 0.15 s, holds `spindle<0.5`; written by `cargo run
/// --release -p tandem-zoo --example rounds_trace -- deburring 6 2 30 --dump 30 PATH`, the
/// re-schedule's seed and tick). Before the candidate the scheduler returned the held
/// completion's 29.319 s (robot 2 waits at a hold until robot 1 has left its long run; the
/// margin-free optimum 24.357 s, gap 20.4 %); the optimum re-timed with the three switches'
/// clearances set from the check's slacks passes at 26.659 s.
#[test]
fn a_zoo_deburring_task_gets_each_switch_the_room_the_check_asks() {
    #[derive(serde::Deserialize)]
    struct Data {
        problem: Problem,
        tick_s: f64,
        seed: u64,
    }
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/zoo_deburring_select6_round30.json"
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
