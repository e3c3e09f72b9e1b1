//! `T_total`, lower bound, gap and wall time of the N-robot scheduler
//! (`tandem_schedule::sample_schedule_n`) on the fixture problem (`fixtures/sanding/problem.csv`
//! with the mid-study confidence: sanding passes 1–3 low-confidence) for N = 1..=8, 5000
//! samples, seed 1, tick Δt_s; one JSON object per N:
//! `{"n_robots", "t_total_s", "lower_bound_s", "bound_is_optimum", "gap", "serial_t_total_s",
//! "source", "wall_ms", "accepted"}` (`accepted`: `validate` passes).
//!
//! `cargo run --release -p tandem-schedule --example robots [-- --holds]`: with `--holds`
//! every sample of the transitions between passes (the `phase` column of the fixture) is a
//! hold point of the problem (the tool is off and lifted), the scheduler plans with them.
#![allow(clippy::print_stdout, reason = "an example prints its measurements")]

#[path = "../benches/support/fixture.rs"]
mod fixture;

use std::time::Instant;

use tandem_schedule::{SamplerParams, sample_schedule_n, validate};

fn main() -> Result<(), tandem_schedule::Error> {
    let (problem, label) = if std::env::args().any(|a| a == "--holds") {
        let (problem, label, n) = fixture::mid_study_problem_with_holds();
        (
            problem,
            format!("{label}, {n} hold points (the transitions)"),
        )
    } else {
        fixture::mid_study_problem()
    };
    println!("# {label}, T_ref = {}", problem.n_ref());
    let params = SamplerParams {
        samples: 5000,
        seed: 1,
        ..SamplerParams::default()
    };
    let dt_s = problem.dt_s();
    for n in 1..=tandem_realtime::MAX_ROBOTS {
        let start = Instant::now();
        let out = sample_schedule_n(&problem, n, &params, None)?;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let serial = problem.serial_schedule_n(n, dt_s)?.t_total_s(dt_s);
        println!(
            "{{\"n_robots\": {n}, \"t_total_s\": {:.3}, \"lower_bound_s\": {:.3}, \
             \"bound_is_optimum\": {}, \"gap\": {:.4}, \"serial_t_total_s\": {serial:.3}, \
             \"source\": \"{}\", \"wall_ms\": {wall_ms:.1}, \"accepted\": {}}}",
            out.t_total_s,
            out.lower_bound_s,
            out.bound_is_optimum,
            out.gap,
            out.source.name(),
            validate(&problem, &out.schedule).is_ok(),
        );
    }
    Ok(())
}
