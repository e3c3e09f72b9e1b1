//! Compares the sampler's distributions on the fixture(-like) mid-study problem: best
//! `T_total` after 5000 samples and wall time per sample, for several seeds.
//!
//! `cargo run --release -p tandem-schedule --example sampling_distributions`
#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

#[path = "../benches/support/fixture.rs"]
mod fixture;

use std::time::Instant;

use tandem_schedule::{Distribution, OffsetSampling, SamplerParams, sample_schedule};

fn main() -> Result<(), tandem_schedule::Error> {
    let (problem, label) = fixture::mid_study_problem();
    let serial = problem.serial_schedule().t_total_s(problem.dt_s());
    println!(
        "{label}: T_ref = {}, serial T_total = {serial:.2} s",
        problem.n_ref()
    );
    use OffsetSampling::{Fitted, Uniform, UniformFeasible};
    let options = [
        (
            "per sample, τ uniform",
            Distribution::PerSample,
            0.0,
            Uniform,
        ),
        (
            "per sample, τ feasible",
            Distribution::PerSample,
            0.0,
            UniformFeasible,
        ),
        (
            "per run, τ uniform",
            Distribution::PerRun { pieces: 1 },
            0.0,
            Uniform,
        ),
        (
            "per run, p0 .25, τ uniform",
            Distribution::PerRun { pieces: 1 },
            0.25,
            Uniform,
        ),
        (
            "per run, τ feasible",
            Distribution::PerRun { pieces: 1 },
            0.0,
            UniformFeasible,
        ),
        (
            "per run, p0 .25, τ feasible",
            Distribution::PerRun { pieces: 1 },
            0.25,
            UniformFeasible,
        ),
        (
            "per run, p0 .5, τ feasible",
            Distribution::PerRun { pieces: 1 },
            0.5,
            UniformFeasible,
        ),
        (
            "2 pieces, p0 .25, τ feasible",
            Distribution::PerRun { pieces: 2 },
            0.25,
            UniformFeasible,
        ),
        (
            "4 pieces, p0 .25, τ feasible",
            Distribution::PerRun { pieces: 4 },
            0.25,
            UniformFeasible,
        ),
        (
            "per run, p0 .5, robot 2 fitted, w 0",
            Distribution::PerRun { pieces: 1 },
            0.5,
            Fitted { widen_max: 0.0 },
        ),
        (
            "per run, p0 .5, robot 2 fitted, w .1",
            Distribution::PerRun { pieces: 1 },
            0.5,
            Fitted { widen_max: 0.1 },
        ),
        (
            "per run, p0 .5, robot 2 fitted, w .3",
            Distribution::PerRun { pieces: 1 },
            0.5,
            Fitted { widen_max: 0.3 },
        ),
    ];
    let samples = 5000;
    println!(
        "best T_total (s) over seeds: mean ± std [min, max]; cheap-feasible; wall time per sample"
    );
    for (name, distribution, p_fastest, offset) in options {
        // Per-sample candidates cost ~0.2–0.3 ms each: fewer seeds there.
        let n_seeds: u64 = if distribution == Distribution::PerSample {
            4
        } else {
            20
        };
        let (mut best, mut feasible, mut total_time) = (Vec::new(), 0, 0.0);
        for seed in 0..n_seeds {
            let params = SamplerParams {
                samples,
                seed,
                distribution,
                p_fastest,
                offset,
                ..SamplerParams::default()
            };
            let start = Instant::now();
            let out = sample_schedule(&problem, &params, None)?;
            total_time += start.elapsed().as_secs_f64();
            best.push(out.t_total_s);
            feasible += out.stats.cheap_feasible;
        }
        let n = best.len() as f64;
        let mean = best.iter().sum::<f64>() / n;
        let std = (best.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let (lo, hi) = best.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &b| {
            (lo.min(b), hi.max(b))
        });
        println!(
            "{name:<38} {mean:6.2} ± {std:5.2} [{lo:6.2}, {hi:6.2}]  {:6.1}  {:7.2} µs",
            feasible as f64 / n,
            total_time / (n * samples as f64) * 1e6
        );
    }
    Ok(())
}
