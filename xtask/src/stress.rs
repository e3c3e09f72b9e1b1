//! `cargo xtask stress --executions E [--robots N] [--seed S]`: the safety invariant under load.
//!
//! Samples random problems of a few hundred reference samples and schedules each at a random
//! control tick, then runs `E` executions in all through each schedule's own `Coordinator` (at
//! the tick it was checked with) under the full adversary set of
//! `tandem::realtime::adversary` (no correction, always fastest, always slowest, Alg. 2's
//! worst case with each robot as the current one, the favoured robot switching at random
//! times, switching every tick, periodic, one switch, random switching, random extremes per
//! tick and per robot, random gradients per tick and held), in parallel, and counts ticks in
//! which two or more robots were low-confidence (expected: 0). Every number depends only on
//! `E`, `N` and the seed.
//!
//! Two robots (the default) are scheduled by the scheduler of `tandem-schedule` (the anytime
//! sampler and the margin-aware completion beside it). For
//! other robot counts the schedules are drawn here, because the N-robot sampler is a later
//! step: random warps (per robot and high-confidence run a fraction of the gradient bounds,
//! fastest with probability ½), robot 1 at 0 and each further robot at the earliest of a few
//! random offsets that `sufficient_margins` accepts with the robots before it, bisected towards
//! the last rejected one (so most schedules sit at the acceptance boundary).

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use anyhow::{Context, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use tandem::realtime::adversary::{Adversary, AdversaryRun, adversary_set, run_adversary};
use tandem::realtime::{Coordinator, Timeline, sufficient_margins};
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
/// Random candidate offsets per drawn robot (besides the serial start).
const OFFSET_CANDIDATES: usize = 6;
/// Bisection steps towards the acceptance boundary per drawn robot.
const OFFSET_BISECTIONS: usize = 8;

/// One scheduled random problem, ready to run.
struct Case {
    /// The schedule's coordinator, at the tick the schedule was checked with (cloned per
    /// execution).
    coordinator: Coordinator,
    max_ticks: u64,
    /// The full adversary set for this case (random gradients over the problem's whole
    /// `[min ψ̇min, max ψ̇max]`).
    adversaries: Vec<Adversary>,
    /// Whether the executions overlap (a sampled or completed two-robot schedule, or a drawn schedule in
    /// which some robot starts before the robots placed before it have ended).
    overlapping: bool,
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

/// One robot's timeline on `problem`: its warp `grad_exec`, started at `start_s`.
fn timeline(problem: &Problem, grad_exec: &[f64], start_s: f64) -> anyhow::Result<Timeline> {
    Ok(Timeline::new(
        problem.conf(),
        grad_exec,
        problem.grad_min(),
        problem.grad_max(),
        start_s,
        problem.dt_s(),
    )?)
}

/// Latest end (s) of `robots`.
fn last_end_s(robots: &[Timeline]) -> f64 {
    robots.iter().map(Timeline::end_s).fold(0.0, f64::max)
}

/// A drawn schedule of `n_robots` robots (see the module docs) as their timelines, and whether
/// the executions overlap. A robot for which no offset is accepted (a decision of the earlier
/// robots at the edge of the tolerance) makes the whole schedule serial, which is always
/// accepted.
fn draw_schedule(
    problem: &Problem,
    n_robots: usize,
    tick_s: f64,
    rng: &mut ChaCha8Rng,
) -> anyhow::Result<(Vec<Timeline>, bool)> {
    let warps: Vec<Vec<f64>> = (0..n_robots)
        .map(|_| {
            let mut warp = problem.grad_mean().to_vec();
            for run in problem.runs().iter().filter(|r| r.high_conf) {
                let frac = if rng.random_bool(0.5) {
                    0.0
                } else {
                    rng.random::<f64>()
                };
                let bounds = problem.grad_min()[run.start..run.end]
                    .iter()
                    .zip(&problem.grad_max()[run.start..run.end]);
                for (w, (lo, hi)) in warp[run.start..run.end].iter_mut().zip(bounds) {
                    *w = lo + frac * (hi - lo);
                }
            }
            warp
        })
        .collect();
    let mut robots = vec![timeline(problem, &warps[0], 0.0)?];
    let mut overlapping = false;
    for warp in &warps[1..] {
        let latest_end = last_end_s(&robots);
        let mut offsets: Vec<f64> = (0..OFFSET_CANDIDATES)
            .map(|_| latest_end * rng.random::<f64>().sqrt())
            .collect();
        offsets.push(latest_end);
        offsets.sort_by(f64::total_cmp);
        let mut accepts = |t: f64| -> anyhow::Result<bool> {
            robots.push(timeline(problem, warp, t)?);
            let ok = sufficient_margins(&robots, tick_s)?;
            robots.pop();
            Ok(ok)
        };
        let mut first = None;
        for (k, &t) in offsets.iter().enumerate() {
            if accepts(t)? {
                first = Some(k);
                break;
            }
        }
        let Some(k) = first else {
            let mut start_s = 0.0;
            let serial = warps
                .iter()
                .map(|w| {
                    let tl = timeline(problem, w, start_s)?;
                    start_s = tl.end_s();
                    Ok(tl)
                })
                .collect::<anyhow::Result<Vec<_>>>()?;
            return Ok((serial, false));
        };
        let mut tau = offsets[k];
        if k > 0 {
            let mut lo = offsets[k - 1];
            for _ in 0..OFFSET_BISECTIONS {
                let m = 0.5 * (lo + tau);
                if accepts(m)? {
                    tau = m;
                } else {
                    lo = m;
                }
            }
        }
        overlapping |= tau < latest_end;
        robots.push(timeline(problem, warp, tau)?);
    }
    Ok((robots, overlapping))
}

fn make_case(seed: u64, index: u64, n_robots: usize) -> anyhow::Result<Case> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    let problem = random_problem(&mut rng)?;
    let tick_s = DT_S * rng.random_range(0.25..=1.0);
    let (coordinator, overlapping) = if n_robots == 2 {
        let params = SamplerParams {
            samples: SAMPLES,
            seed: rng.random(),
            tick_s: Some(tick_s),
            ..SamplerParams::default()
        };
        let out = sample_schedule(&problem, &params, None)?;
        let sampled = matches!(out.source, Source::Sampled { .. } | Source::Completed);
        (out.schedule.coordinator(&problem)?, sampled)
    } else {
        let (robots, overlapping) = draw_schedule(&problem, n_robots, tick_s, &mut rng)?;
        (Coordinator::new(robots, tick_s)?, overlapping)
    };
    // Every robot at its slowest, one after the other, plus slack.
    let slowest_s = problem.grad_max().iter().sum::<f64>() * DT_S * n_robots as f64;
    let fold = |f: fn(f64, f64) -> f64, init: f64, v: &[f64]| v.iter().copied().fold(init, f);
    let grad_range = [
        fold(f64::min, f64::INFINITY, problem.grad_min()),
        fold(f64::max, 0.0, problem.grad_max()),
    ];
    let ticks = (last_end_s(coordinator.robots()) / tick_s) as u64;
    Ok(Case {
        max_ticks: (2.0 * slowest_s / tick_s) as u64 + 100,
        adversaries: adversary_set(n_robots, grad_range, ticks, &mut rng),
        coordinator,
        overlapping,
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

/// Runs the stress test with `n_robots` robots; fails if any tick had two or more robots
/// low-confidence.
pub(crate) fn run(executions: u64, seed: u64, n_robots: usize) -> anyhow::Result<()> {
    if executions == 0 {
        bail!("--executions must be ≥ 1");
    }
    if !(1..=tandem::realtime::MAX_ROBOTS).contains(&n_robots) {
        bail!("--robots must be in 1..={}", tandem::realtime::MAX_ROBOTS);
    }
    let start = Instant::now();
    let n_problems = (executions / EXECUTIONS_PER_PROBLEM).clamp(1, MAX_PROBLEMS);
    let cases: Vec<Case> = (0..n_problems)
        .into_par_iter()
        .map(|i| make_case(seed, i, n_robots).with_context(|| format!("scheduling problem {i}")))
        .collect::<anyhow::Result<_>>()?;
    let n_overlapping = cases.iter().filter(|c| c.overlapping).count();
    let how = if n_robots == 2 {
        format!(
            "{SAMPLES} sampler candidates each: {n_overlapping} overlapping sampled or completed schedules"
        )
    } else {
        format!("drawn schedules: {n_overlapping} with overlapping executions")
    };
    println!(
        "stress: {n_robots} robots, {n_problems} random problems (200–400 samples, tick 0.25–1 \
         sample), {how}, {} serial; scheduling took {:.1} s",
        n_problems as usize - n_overlapping,
        start.elapsed().as_secs_f64()
    );
    let set_size = cases[0].adversaries.len() as u64;
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
            let op = case.adversaries[((e / n_problems) % set_size) as usize];
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
        "stress: {executions} executions of {n_robots} robots ({set_size} operator policies, \
         seed {seed}), {ticks} ticks, {threads} threads: {overlap_ticks} ticks with two or more \
         robots low-confidence (expected 0) in {overlap_runs} executions; {unfinished} \
         unfinished; {secs:.1} s, {:.0} executions/s, {:.1} M ticks/s",
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
