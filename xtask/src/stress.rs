//! `cargo xtask stress --executions N [--seed S]`: the safety invariant under load.
//!
//! Samples random problems of a few hundred reference samples, schedules each with the
//! scheduler of `tandem-schedule` (the anytime sampler and the margin-aware completion beside
//! it) at a random control tick, then runs `N` executions in all
//! through each schedule's own `Coordinator` (at the tick it was checked with) under the full
//! adversary set of `tandem::realtime::adversary` (no correction, always fastest, always
//! slowest, Alg. 2's worst case for each role, switching every tick, periodic, one switch,
//! random switching, random extremes per tick and per robot, random gradients per tick and
//! held), in parallel, and counts ticks in which both robots were low-confidence (expected:
//! 0). Every number depends only on `N` and the seed.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use anyhow::{Context, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use tandem::realtime::Coordinator;
use tandem::realtime::adversary::{
    Adversary, AdversaryRun, SET_SIZE, adversary_set, run_adversary,
};
use tandem::schedule::{Problem, SamplerParams, Source, sample_schedule};

/// Executions per scheduled problem (the number of problems is `N / this`, at least 1 and at
/// most [`MAX_PROBLEMS`]).
const EXECUTIONS_PER_PROBLEM: u64 = 10_000;
/// Upper bound on the number of sampled problems.
const MAX_PROBLEMS: u64 = 200;
/// Sampler candidates per problem.
const SAMPLES: usize = 500;
/// Executions per parallel batch (a progress line may follow each batch).
const BATCH: u64 = 50_000;
/// Reference sample period of the random problems (s).
const DT_S: f64 = 0.01;

/// One scheduled random problem, ready to run.
struct Case {
    /// The schedule's coordinator, at the tick the schedule was checked with (cloned per
    /// execution).
    coordinator: Coordinator,
    max_ticks: u64,
    /// The full adversary set for this case (random gradients over the problem's whole
    /// `[min ψ̇min, max ψ̇max]`).
    adversaries: [Adversary; SET_SIZE],
    /// The schedule overlaps the robots: sampled or completed, not a serial fallback.
    sampled: bool,
}

/// A random problem: 200–400 samples, confidence in runs (LC runs 5–60 samples, HC runs 5–80),
/// a smooth random mean gradient and random per-run bound factors.
fn random_problem(rng: &mut ChaCha8Rng) -> anyhow::Result<Problem> {
    let n_ref = rng.random_range(200..=400);
    let (mut conf, mut mean, mut min, mut max) = (vec![], vec![], vec![], vec![]);
    let mut hc = rng.random_bool(0.5);
    let (freq, phase) = (rng.random_range(0.01..0.2), rng.random_range(0.0..6.3));
    while conf.len() < n_ref {
        let len = if hc {
            rng.random_range(5..=80)
        } else {
            rng.random_range(5..=60)
        };
        let lo = rng.random_range(0.3..1.0);
        let hi = rng.random_range(1.0..2.5);
        for _ in 0..len.min(n_ref - conf.len()) {
            let m = 1.0 + 0.5 * (freq * conf.len() as f64 + phase).sin();
            conf.push(hc);
            mean.push(m);
            min.push(lo * m);
            max.push(hi * m);
        }
        hc = !hc;
    }
    Ok(Problem::new(conf, mean, min, max, DT_S)?)
}

fn make_case(seed: u64, index: u64) -> anyhow::Result<Case> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    let problem = random_problem(&mut rng)?;
    let tick_s = DT_S * rng.random_range(0.25..=1.0);
    let params = SamplerParams {
        samples: SAMPLES,
        seed: rng.random(),
        tick_s: Some(tick_s),
        ..SamplerParams::default()
    };
    let out = sample_schedule(&problem, &params, None)?;
    // Every robot at its slowest, one after the other, plus slack.
    let slowest_s = problem.grad_max().iter().sum::<f64>() * DT_S * 2.0;
    let fold = |f: fn(f64, f64) -> f64, init: f64, v: &[f64]| v.iter().copied().fold(init, f);
    let grad_range = [
        fold(f64::min, f64::INFINITY, problem.grad_min()),
        fold(f64::max, 0.0, problem.grad_max()),
    ];
    let ticks = (out.t_total_s / tick_s) as u64;
    Ok(Case {
        coordinator: out.schedule.coordinator(&problem)?,
        max_ticks: (2.0 * slowest_s / tick_s) as u64 + 100,
        adversaries: adversary_set(grad_range, ticks, &mut rng),
        sampled: matches!(out.source, Source::Sampled { .. } | Source::Completed),
    })
}

/// Result of one execution.
fn execute(case: &Case, op: Adversary, seed: u64, exec: u64) -> anyhow::Result<AdversaryRun> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(0x9e37_79b9_7f4a_7c15));
    rng.set_stream(exec);
    Ok(run_adversary(
        case.coordinator.clone(),
        op,
        &mut rng,
        case.max_ticks,
    )?)
}

/// Runs the stress test; fails if any tick had both robots low-confidence.
pub(crate) fn run(executions: u64, seed: u64) -> anyhow::Result<()> {
    if executions == 0 {
        bail!("--executions must be ≥ 1");
    }
    let start = Instant::now();
    let n_problems = (executions / EXECUTIONS_PER_PROBLEM).clamp(1, MAX_PROBLEMS);
    let cases: Vec<Case> = (0..n_problems)
        .into_par_iter()
        .map(|i| make_case(seed, i).with_context(|| format!("scheduling problem {i}")))
        .collect::<anyhow::Result<_>>()?;
    let n_sampled = cases.iter().filter(|c| c.sampled).count();
    println!(
        "stress: {n_problems} random problems (200–400 samples, tick 0.25–1 sample), \
         {SAMPLES} sampler candidates each: {n_sampled} overlapping sampled or completed schedules, {} serial \
         fallbacks; scheduling took {:.1} s",
        n_problems as usize - n_sampled,
        start.elapsed().as_secs_f64()
    );
    let run_start = Instant::now();
    let (ticks, overlap_ticks, overlap_runs, unfinished) = (
        AtomicU64::new(0),
        AtomicU64::new(0),
        AtomicU64::new(0),
        AtomicU64::new(0),
    );
    let mut last_report = Instant::now();
    let mut done = 0;
    while done < executions {
        let end = (done + BATCH).min(executions);
        (done..end).into_par_iter().try_for_each(|e| {
            let case = &cases[(e % n_problems) as usize];
            let op = case.adversaries[((e / n_problems) % SET_SIZE as u64) as usize];
            let r = execute(case, op, seed, e)?;
            ticks.fetch_add(r.ticks, Ordering::Relaxed);
            if r.overlap_ticks > 0 {
                overlap_ticks.fetch_add(r.overlap_ticks, Ordering::Relaxed);
                overlap_runs.fetch_add(1, Ordering::Relaxed);
            }
            if !r.finished {
                unfinished.fetch_add(1, Ordering::Relaxed);
            }
            anyhow::Ok(())
        })?;
        done = end;
        if last_report.elapsed().as_secs_f64() >= 5.0 && done < executions {
            let rate = done as f64 / run_start.elapsed().as_secs_f64();
            println!(
                "  {done}/{executions} executions, {} overlap ticks, {rate:.0} executions/s",
                overlap_ticks.load(Ordering::Relaxed)
            );
            last_report = Instant::now();
        }
    }
    let secs = run_start.elapsed().as_secs_f64();
    let (ticks, overlap_ticks, overlap_runs, unfinished) = (
        ticks.into_inner(),
        overlap_ticks.into_inner(),
        overlap_runs.into_inner(),
        unfinished.into_inner(),
    );
    println!(
        "stress: {executions} executions ({} operator policies, seed {seed}), {ticks} ticks, \
         {threads} threads: {overlap_ticks} ticks with both robots low-confidence (expected 0) \
         in {overlap_runs} executions; {unfinished} unfinished; {secs:.1} s, {:.0} executions/s, \
         {:.1} M ticks/s",
        SET_SIZE,
        executions as f64 / secs,
        ticks as f64 / secs / 1e6,
        threads = rayon::current_num_threads(),
    );
    if overlap_ticks > 0 || unfinished > 0 {
        bail!(
            "safety invariant broken: {overlap_ticks} overlap ticks, {unfinished} unfinished executions"
        );
    }
    Ok(())
}
