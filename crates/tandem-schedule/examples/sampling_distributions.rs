//! Compares the sampler's distributions on the fixture(-like) mid-study problem: best
//! `T_total` after 5000 samples and wall time per sample, for several seeds.
//!
//! `cargo run --release -p tandem-schedule --example sampling_distributions`
#![allow(clippy::print_stdout, reason = "an example reports to the terminal")]

#[path = "../benches/support/fixture.rs"]
mod fixture;

use std::time::Instant;

use tandem_schedule::{
    DrawnOffset, SamplerBaselines, SamplerParams, sample_schedule_with_baselines,
};

/// One row of the table: how robot 1's (and robot 2's) speeds and `τ` are drawn.
struct Setting {
    name: &'static str,
    /// One factor per sample instead of per piece.
    per_sample: bool,
    /// Pieces per high-confidence run.
    pieces: usize,
    p_fastest: f64,
    /// `None`: robot 2 fitted with widenings up to `widen_max`.
    drawn_offset: Option<DrawnOffset>,
    widen_max: f64,
}

const fn drawn(
    name: &'static str,
    per_sample: bool,
    pieces: usize,
    p_fastest: f64,
    offset: DrawnOffset,
) -> Setting {
    Setting {
        name,
        per_sample,
        pieces,
        p_fastest,
        drawn_offset: Some(offset),
        widen_max: 0.0,
    }
}

const fn fitted(name: &'static str, widen_max: f64) -> Setting {
    Setting {
        name,
        per_sample: false,
        pieces: 1,
        p_fastest: 0.5,
        drawn_offset: None,
        widen_max,
    }
}

fn main() -> Result<(), tandem_schedule::Error> {
    let (problem, label) = fixture::mid_study_problem();
    let serial = problem
        .serial_schedule(problem.dt_s())?
        .t_total_s(problem.dt_s());
    println!(
        "{label}: T_ref = {}, serial T_total = {serial:.2} s",
        problem.n_ref()
    );
    use DrawnOffset::{Uniform, UniformFeasible};
    let options = [
        drawn("per sample, τ uniform", true, 1, 0.0, Uniform),
        drawn("per sample, τ feasible", true, 1, 0.0, UniformFeasible),
        drawn("per run, τ uniform", false, 1, 0.0, Uniform),
        drawn("per run, p0 .25, τ uniform", false, 1, 0.25, Uniform),
        drawn("per run, τ feasible", false, 1, 0.0, UniformFeasible),
        drawn(
            "per run, p0 .25, τ feasible",
            false,
            1,
            0.25,
            UniformFeasible,
        ),
        drawn("per run, p0 .5, τ feasible", false, 1, 0.5, UniformFeasible),
        drawn(
            "2 pieces, p0 .25, τ feasible",
            false,
            2,
            0.25,
            UniformFeasible,
        ),
        drawn(
            "4 pieces, p0 .25, τ feasible",
            false,
            4,
            0.25,
            UniformFeasible,
        ),
        fitted("per run, p0 .5, robot 2 fitted, w 0", 0.0),
        fitted("per run, p0 .5, robot 2 fitted, w .1", 0.1),
        fitted("per run, p0 .5, robot 2 fitted, w .3", 0.3),
    ];
    let samples = 5000;
    println!(
        "best T_total (s) over seeds: mean ± std [min, max]; cheap-feasible; wall time per sample"
    );
    for setting in options {
        let name = setting.name;
        // Per-sample candidates cost ~0.2–0.3 ms each: fewer seeds there.
        let n_seeds: u64 = if setting.per_sample { 4 } else { 20 };
        // The sampler's own distributions, without the completion beside it.
        let baselines = SamplerBaselines {
            per_sample: setting.per_sample,
            drawn_offset: setting.drawn_offset,
            ..SamplerBaselines::SAMPLER_ONLY
        };
        let (mut best, mut feasible, mut total_time) = (Vec::new(), 0, 0.0);
        for seed in 0..n_seeds {
            let params = SamplerParams {
                samples,
                seed,
                pieces: setting.pieces,
                p_fastest: setting.p_fastest,
                widen_max: setting.widen_max,
                ..SamplerParams::default()
            };
            let start = Instant::now();
            let out = sample_schedule_with_baselines(&problem, &params, &baselines, None)?;
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
