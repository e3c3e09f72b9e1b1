//! `cargo xtask stress --executions E [--robots N] [--seed S] [--holds] [--switch-s S]`: the
//! safety invariant
//! under load.
//!
//! Draws random problems and schedules each at a random control tick, then runs `E` executions
//! in all through each schedule's own `Coordinator` (at the tick it was checked with) under the
//! full adversary set of `tandem::realtime::adversary` (no correction, always fastest, always
//! slowest, Alg. 2's worst case with each robot as the current one, the favoured robot switching
//! at random times, switching every tick, periodic, one switch, random switching, random
//! extremes per tick and per robot, random gradients per tick and held, and the beam search over
//! per-tick choices), in parallel, and counts ticks in which two or more robots were
//! low-confidence and ticks in which a robot moved backwards (its reference time or its clock
//! decreased; `AdversaryRun::backward_steps`); it fails on any of either (expected: 0). Every
//! number depends only on `E`, `N` and the seed.
//!
//! Half the problems are this task's own (200–400 samples in runs, a smooth mean, per-run bound
//! factors); the other half cycle through the test kit's eight families
//! (`tandem::realtime::testkit::Family`: one mask with uniform or styled gradients, a few long
//! regions, per-run bound ratios, per-robot plans of different lengths and bounds, one robot's
//! long low-confidence stretch, and the two families built like the reproducers of a dragged
//! third robot). Every shared-mask problem is scheduled by the production scheduler
//! (`tandem::schedule::sample_schedule_n`, for any `N`); per-robot plans, which no
//! `tandem-schedule` problem describes, get a tight schedule at an edge of
//! `sufficient_margins`' acceptance (`testkit::tight_starts`).
//!
//! With `--holds` every problem gets hold points in the middle of each high-confidence run of
//! at least three samples (`tandem_schedule::testkit::hold_points`): the scheduler plans with them (release rules on its
//! candidates, the exact optimum with dwells for two robots), and per-robot plans get
//! interleaved random starts with release rules (`tandem::realtime::holds::release_rules`)
//! accepted by `sufficient_margins_with_holds` (20 draws, else the tight schedule without holds).
//!
//! `--cell continuous [--tasks K]` stresses the continuous cell instead ([`run_continuous`]):
//! random problems (this task's, with hold points on two problems of three, and the test
//! kit's shared-mask families with hold points), each planned by `cyclic_plan` (runnable
//! orders) and run by `CyclicPlan::coordinator` at a random tick; every execution runs one
//! adversary policy (`tandem::realtime::continuous::run_cell`: the policies of the adversary
//! set, the beam search replaced by a switching favourite) until every robot has completed
//! `K` tasks (default 50), so the clocks' drift runs across many cycles. It counts the ticks
//! with two or more robots low-confidence and the ticks in which a robot moved backwards
//! (expected 0 of both; `AdversaryRun::backward_steps`) and the tasks per robot.
//!
//! `--switch-s S` (issue 41) adds the operator's switch time `δ = S` s: in rounds, half the
//! problems are this task's, scheduled by the production scheduler at `δ`
//! (`SamplerParams::switch_s`) and run as the planner runs them (`check_with_operator`, the
//! coordinator `with_switch_s`), the other half the test kit's families with tight schedules at
//! an edge of `check_margins` at `δ` (with `--holds`, release rules it accepts), run by
//! coordinators that wait `δ` at their holds (`Coordinator::with_margins`); the continuous
//! cell's plan counts `δ` per change of robot (`CyclicParams::switch_s`) and its token waits
//! it (`ContinuousCoordinator::with_switch_s`). Each execution's shortest switch is measured
//! on the ticks the robots traversed (`AdversaryRun::min_switch_gap_ticks`; the beam search
//! of rounds over every sequence it expanded), and the run fails if one is shorter than
//! `k = switch_ticks(δ, tick)`. `--max-busy U` (continuous cell) adds the operator's load cap:
//! the plans keep it and the token paces the operator to it
//! (`ContinuousCoordinator::with_max_busy_share`), so the same checks run on the paced cell.
//!
//! `--operators M` (issue 44) runs `M` operators in either cell instead: [`operators`].
//!
//! A policy that draws nothing from its random stream (no correction, the extremes, rush,
//! periodic, one switch, and in rounds the beam search: [`is_deterministic`]) gives the same
//! execution every time it runs on one case, so it runs once per case and its run is counted
//! again for the case's other executions under it ([`Replays`]; every count as before, bit
//! for bit). Each run prints a digest of the per-execution counts ([`execution_digest`]), the
//! executions run and replayed, and the time per policy kind.

pub(crate) mod operators;

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use anyhow::{Context, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use tandem::realtime::adversary::{Adversary, AdversaryRun, adversary_set, run_adversary};
use tandem::realtime::continuous::{ContinuousCoordinator, run_cell};
use tandem::realtime::holds::{release_rules, usable_holds};
use tandem::realtime::testkit::{self, Family};
use tandem::realtime::{
    Coordinator, MarginParams, Timeline, check_margins, sufficient_margins,
    sufficient_margins_with_holds,
};
use tandem::schedule::{
    CyclicParams, Problem, SamplerParams, Source, cyclic_plan, sample_schedule_n,
};
use tandem_schedule::testkit::hold_points;

pub(crate) mod mixed;

/// Executions per scheduled problem (the number of problems is `N / this`, at least 1 and at
/// most [`MAX_PROBLEMS`]).
const EXECUTIONS_PER_PROBLEM: u64 = 1_000;
/// Upper bound on the number of sampled problems.
const MAX_PROBLEMS: u64 = 200;
/// Sampler candidates per problem.
const SAMPLES: usize = 500;
/// Executions per parallel batch (a progress line may follow each batch).
const BATCH: u64 = 50_000;
/// Executions per parallel batch of the continuous cell (each runs `--tasks` tasks per robot).
const CELL_BATCH: u64 = BATCH / 50;
/// Draws of a test kit case per problem with a switch time (`--switch-s`).
const MAX_DRAWS: u64 = 50;
/// Reference sample period of this task's random problems (s).
const DT_S: f64 = 0.01;

/// One scheduled random problem, ready to run.
struct Case {
    /// The schedule's coordinator, at the tick the schedule was checked with (cloned per
    /// execution).
    coordinator: Coordinator,
    max_ticks: u64,
    /// The full adversary set for this case (random gradients over the problem's whole
    /// `[min ψ̇min, max ψ̇max]`).
    adversaries: Vec<Adversary>,
    /// Whether the executions overlap (a sampled or completed schedule, or a tight one in which
    /// some robot starts before the robots placed before it have ended).
    overlapping: bool,
    /// The problem's family (`stress` for this task's own).
    family: &'static str,
    /// How the schedule was made.
    made: Made,
    /// `k`: the switch time in ticks of this case's tick (0 without `--switch-s`).
    switch_ticks: u64,
    /// Draws skipped before this one for want of a schedule at the switch time.
    skipped: u64,
}

/// A random problem of 200–400 samples ([`tandem_schedule::testkit::random_problem`], the
/// generator of the property tests).
fn random_problem(rng: &mut ChaCha8Rng) -> anyhow::Result<Problem> {
    Ok(tandem_schedule::testkit::random_problem(
        rng,
        200..=400,
        DT_S,
    )?)
}

/// `problem` with hold points ([`hold_points`]) when `holds`.
fn with_holds(problem: Problem, holds: bool) -> anyhow::Result<Problem> {
    if !holds {
        return Ok(problem);
    }
    let points = hold_points(problem.conf());
    Ok(problem.with_holds(points)?)
}

/// How the schedule of a case was made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Made {
    /// By the production scheduler (`sample_schedule_n`) on a shared-mask problem.
    Scheduled,
    /// Bisected to an acceptance edge of `sufficient_margins` (`testkit::tight_starts`).
    Tight,
}

/// Schedules `problem` for `n_robots` with the production scheduler at `tick_s` and the
/// operator's switch time `switch_s` (`SamplerParams::switch_s`): its coordinator and whether
/// the executions overlap (a sampled or completed schedule). At `switch_s = 0` the schedule is
/// checked by `Schedule::check` as before; with a switch time it is run as the planner runs it
/// (`Planner::coordinator`: `check_with_operator` at `switch_s`, the coordinator
/// `with_switch_s`).
fn scheduled(
    problem: &Problem,
    n_robots: usize,
    tick_s: f64,
    switch_s: f64,
    rng: &mut ChaCha8Rng,
) -> anyhow::Result<(Coordinator, bool)> {
    let params = SamplerParams {
        samples: SAMPLES,
        seed: rng.random(),
        tick_s: Some(tick_s),
        switch_s,
        ..SamplerParams::default()
    };
    let out = sample_schedule_n(problem, n_robots, &params, None)?;
    let sampled = matches!(
        out.source,
        Source::Sampled { .. } | Source::Completed | Source::Held | Source::Staggered
    );
    let coordinator = if switch_s == 0.0 {
        out.schedule.check(problem)?.coordinator()?
    } else {
        out.schedule
            .check_with_operator(problem, switch_s, 1.0)?
            .coordinator()?
            .with_switch_s(switch_s)?
    };
    Ok((coordinator, sampled))
}

/// Per-robot plans with holds: up to 20 draws of interleaved starts (each robot at a random
/// point of the span of the robots before it) with release rules on the plans' hold points,
/// the first that `sufficient_margins_with_holds` accepts; `None` if none is.
fn held_plans(
    case: &testkit::Case,
    switch_s: f64,
    rng: &mut ChaCha8Rng,
) -> anyhow::Result<Option<Coordinator>> {
    for _ in 0..20 {
        let mut starts = vec![0.0];
        for _ in 1..case.plans.len() {
            let end = last_end_s(&case.robots_at(&starts));
            starts.push(end * rng.random::<f64>());
        }
        let robots = case.robots_at(&starts);
        let usable: Vec<Vec<usize>> = robots
            .iter()
            .map(|r| usable_holds(r.conf(), &hold_points(r.conf())))
            .collect();
        let holds = release_rules(&robots, &[], &usable);
        if holds.is_empty() {
            continue;
        }
        if switch_s == 0.0 {
            if sufficient_margins_with_holds(&robots, &holds, case.tick_s)? {
                return Ok(Some(Coordinator::with_holds(robots, &holds, case.tick_s)?));
            }
        } else {
            let params = MarginParams::new(case.tick_s).with_switch_s(switch_s);
            if check_margins(&robots, &holds, &params)? {
                return Ok(Some(Coordinator::with_margins(robots, &holds, &params)?));
            }
        }
    }
    Ok(None)
}

/// Problem `index` of the run: even indices are this task's random problems, odd ones cycle
/// through the test kit's families (`tandem::realtime::testkit::Family`). Shared-mask problems
/// are scheduled by the production scheduler; per-robot plans (which no `tandem-schedule`
/// problem describes) get a tight schedule at an acceptance edge of `sufficient_margins`.
///
/// With a switch time (`switch_s > 0`) the even indices are this task's random problems
/// scheduled by the production scheduler at that switch time and run as the planner runs them
/// ([`scheduled`]); the odd ones a test kit family's, with a tight schedule at an edge of
/// `check_margins`' acceptance at that switch time (with `--holds` interleaved starts and
/// release rules accepted by it), run by a coordinator that waits the switch time
/// (`Coordinator::with_margins`): the edge is where a wrong rule would show.
fn make_case(
    seed: u64,
    index: u64,
    n_robots: usize,
    holds: bool,
    switch_s: f64,
) -> anyhow::Result<Case> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(index);
    let mut skipped = 0;
    let (coordinator, overlapping, family, made) = if index % 2 == 0 {
        let problem = with_holds(random_problem(&mut rng)?, holds)?;
        let tick_s = DT_S * rng.random_range(0.25..=1.0);
        let (c, o) = scheduled(&problem, n_robots, tick_s, switch_s, &mut rng)?;
        (c, o, "stress", Made::Scheduled)
    } else if switch_s > 0.0 {
        // A case whose robots end and start low-confidence may have no schedule the check
        // accepts at this switch time (not even the serial one): the next draw is taken.
        let mut found = None;
        for attempt in 0..MAX_DRAWS {
            let family = Family::ALL[((index / 2 + attempt) % Family::ALL.len() as u64) as usize];
            let case = testkit::Case::random(family, n_robots, &mut rng);
            if let Some(c) = holds
                .then(|| held_plans(&case, switch_s, &mut rng))
                .transpose()?
                .flatten()
            {
                found = Some((c, true, family.name(), Made::Tight));
                break;
            }
            let check = |r: &[Timeline], h: f64| {
                check_margins(r, &[], &MarginParams::new(h).with_switch_s(switch_s))
            };
            if let Some((starts, o)) = testkit::tight_starts(&case, check, &mut rng) {
                let params = MarginParams::new(case.tick_s).with_switch_s(switch_s);
                let c = Coordinator::with_margins(case.robots_at(&starts), &[], &params)?;
                found = Some((c, o, family.name(), Made::Tight));
                break;
            }
            skipped += 1;
        }
        found.with_context(|| {
            format!("no case of {MAX_DRAWS} draws has a schedule accepted at this switch time")
        })?
    } else {
        let family = Family::ALL[((index / 2) % Family::ALL.len() as u64) as usize];
        let case = testkit::Case::random(family, n_robots, &mut rng);
        if let Some(m) = case.shared_mask() {
            let problem = with_holds(Problem::new(m.conf, m.mean, m.lo, m.hi, m.dt_s)?, holds)?;
            let (c, o) = scheduled(&problem, n_robots, case.tick_s, 0.0, &mut rng)?;
            (c, o, family.name(), Made::Scheduled)
        } else if let Some(c) = holds
            .then(|| held_plans(&case, 0.0, &mut rng))
            .transpose()?
            .flatten()
        {
            (c, true, family.name(), Made::Tight)
        } else {
            let check: testkit::Check = sufficient_margins;
            let (starts, o) = testkit::tight_starts(&case, check, &mut rng)
                .context("no start accepted, not even the serial one")?;
            let c = Coordinator::new(case.robots_at(&starts), case.tick_s)?;
            (c, o, family.name(), Made::Tight)
        }
    };
    let robots = coordinator.robots();
    let tick_s = coordinator.tick_s();
    let all = |f: fn(&Timeline) -> &[f64]| robots.iter().flat_map(move |r| f(r).iter().copied());
    let grad_range = [
        all(Timeline::grad_min).fold(f64::INFINITY, f64::min),
        all(Timeline::grad_max).fold(0.0, f64::max),
    ];
    // With holds the legs carry the planned dwells: the latest leg end of each robot.
    let dwell_s: f64 = (0..coordinator.n_robots())
        .map(|i| coordinator.current_plan(i).end_s() - robots[i].end_s())
        .fold(0.0, f64::max);
    let ticks = ((last_end_s(robots) + dwell_s) / tick_s) as u64;
    let k = coordinator.switch_ticks();
    Ok(Case {
        max_ticks: tick_budget(&coordinator),
        switch_ticks: k,
        skipped,
        adversaries: adversary_set(n_robots, grad_range, ticks, &mut rng),
        coordinator,
        overlapping,
        family,
        made,
    })
}

/// The tick budget of one execution of `coordinator`'s round: an execution that has not ended
/// within it is counted "unfinished". In a tick in which some robot runs, that robot moves on
/// by at least its slowest step, so such ticks number at most `Σ_i` (robot `i` at its slowest,
/// `Σ_n ψ̇max[n]·Δt_s`) over the tick; in a tick in which no robot runs (all waiting to start,
/// at a hold or finished), the clocks of the robots waiting to start move on by the tick
/// (rule 3), so before the last start there are at most `(max_i τ_i − min_i τ_i)` over the tick
/// of them (the start offsets: at a switch time `δ` the scheduler may leave about `δ` between
/// one robot's end and the next one's start, "A schedule always exists with a switch time:
/// constraint 2 relaxed (issue 41)"); at holds, the planned dwells (the latest leg end of any
/// robot past its plan's end) and each leg's switch wait `k` (a robot has at most one leg per
/// sample). Twice the serial time and offsets plus dwells, plus 100 ticks for the tick grid
/// (every partial step of a sample), plus the switch waits: `2·(Σ slowest + offsets + dwells)/h
/// + 100 + k·legs` (legs only with holds), in whole ticks.
fn tick_budget(coordinator: &Coordinator) -> u64 {
    let robots = coordinator.robots();
    let slowest_s: f64 = robots
        .iter()
        .map(|r| r.grad_max().iter().sum::<f64>() * r.dt_s())
        .sum();
    let first_start = robots
        .iter()
        .map(Timeline::start_s)
        .fold(f64::INFINITY, f64::min);
    let offsets_s = robots
        .iter()
        .map(|r| r.start_s() - first_start)
        .fold(0.0, f64::max);
    let dwell_s: f64 = (0..coordinator.n_robots())
        .map(|i| coordinator.current_plan(i).end_s() - robots[i].end_s())
        .fold(0.0, f64::max);
    let switch_waits = if coordinator.has_holds() {
        let legs = robots.iter().map(Timeline::n_ref).sum::<usize>() as u64;
        coordinator.switch_ticks().saturating_mul(legs)
    } else {
        0
    };
    (2.0 * (slowest_s + offsets_s + dwell_s) / coordinator.tick_s()) as u64 + 100 + switch_waits
}

/// Latest end (s) of `robots`.
fn last_end_s(robots: &[Timeline]) -> f64 {
    robots.iter().map(Timeline::end_s).fold(0.0, f64::max)
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
pub(crate) fn run(
    executions: u64,
    seed: u64,
    n_robots: usize,
    holds: bool,
    switch_s: f64,
    problems: Option<u64>,
) -> anyhow::Result<()> {
    if executions == 0 {
        bail!("--executions must be ≥ 1");
    }
    tandem::realtime::RobotCount::new(n_robots).map_err(|e| anyhow::anyhow!("--robots: {e}"))?;
    let start = Instant::now();
    let n_problems = n_problems(executions, problems)?;
    let cases: Vec<Case> = (0..n_problems)
        .into_par_iter()
        .map(|i| {
            make_case(seed, i, n_robots, holds, switch_s)
                .with_context(|| format!("scheduling problem {i}"))
        })
        .collect::<anyhow::Result<_>>()?;
    let count = |f: &dyn Fn(&Case) -> bool| cases.iter().filter(|c| f(c)).count();
    let n_overlapping = count(&|c| c.overlapping);
    println!(
        "stress: {n_robots} robots{}, {n_problems} random problems: {} scheduled by the production \
         scheduler ({SAMPLES} candidates), {} tight at an acceptance edge (per-robot plans); \
         {n_overlapping} with overlapping executions, {} serial; scheduling took {:.1} s",
        if holds { " with hold points" } else { "" },
        count(&|c| c.made == Made::Scheduled),
        count(&|c| c.made == Made::Tight),
        n_problems as usize - n_overlapping,
        start.elapsed().as_secs_f64()
    );
    if switch_s > 0.0 {
        println!(
            "  switch time {switch_s} s: {} test kit draws skipped without a schedule accepted \
             at it (robots that end and start low-confidence)",
            cases.iter().map(|c| c.skipped).sum::<u64>()
        );
    }
    let mut families: Vec<&str> = cases.iter().map(|c| c.family).collect();
    families.sort_unstable();
    families.dedup();
    let per_family: Vec<String> = families
        .iter()
        .map(|&f| {
            let of = |c: &Case| c.family == f;
            format!("{f} {}/{}", count(&|c| of(c) && c.overlapping), count(&of))
        })
        .collect();
    println!("  overlapping/all per family: {}", per_family.join(", "));
    if holds {
        println!(
            "  {} of {n_problems} schedules run with hold points or release rules",
            count(&|c| c.coordinator.has_holds())
        );
    }
    let set_size = cases[0].adversaries.len() as u64;
    let run_start = Instant::now();
    let tally = Tally::default();
    let replays = Replays::new(n_problems, set_size, true);
    run_batches(executions, BATCH, 5.0, &tally, |e| {
        let (c, p) = (e % n_problems, (e / n_problems) % set_size);
        let case = &cases[c as usize];
        let op = case.adversaries[p as usize];
        let t0 = Instant::now();
        let ((r, _), replayed) =
            replays.get_or_run(c, p, op, || Ok((execute(case, op, seed, e)?, 0)))?;
        tally.add_run(e, op, &r, 0, t0.elapsed().as_nanos() as u64, replayed);
        tally.add(r.ticks, r.overlap_ticks, r.finished);
        tally.add_backward(r.backward_steps);
        if switch_s > 0.0 {
            tally.add_switch(r.min_switch_gap_ticks, case.switch_ticks);
            if matches!(op, Adversary::Beam { .. }) {
                tally.beam[0].fetch_add(1, Ordering::Relaxed);
                let measured = u64::from(r.min_switch_gap_ticks.is_some());
                tally.beam[1].fetch_add(measured, Ordering::Relaxed);
            }
        }
        Ok(())
    })?;
    let secs = run_start.elapsed().as_secs_f64();
    report_time_split(&tally);
    let backward = tally.backward_steps.load(Ordering::Relaxed);
    let short = report_switches(
        &tally,
        switch_s,
        &cases.iter().map(|c| c.switch_ticks).collect::<Vec<_>>(),
    );
    let (ticks, overlap_ticks, overlap_runs, unfinished) = tally.into_counts();
    println!(
        "stress: {executions} executions of {n_robots} robots ({set_size} operator policies, \
         seed {seed}), {ticks} ticks, {threads} threads: {overlap_ticks} ticks with two or more \
         robots low-confidence (expected 0) in {overlap_runs} executions; {backward} ticks with \
         a robot moving backwards (expected 0); {unfinished} unfinished; {secs:.1} s, {:.0} \
         executions/s, {:.1} M ticks/s",
        executions as f64 / secs,
        ticks as f64 / secs / 1e6,
        threads = rayon::current_num_threads(),
    );
    if overlap_ticks > 0 || unfinished > 0 || backward > 0 || short > 0 {
        bail!(
            "safety invariant broken: {overlap_ticks} overlap ticks, {backward} backward steps, \
             {short} executions with a switch shorter than the switch time, {unfinished} \
             unfinished executions"
        );
    }
    Ok(())
}

/// Prints the switch-time line of a run with `--switch-s` (`ks`: each case's `k`) and returns
/// the executions with a switch shorter than `k` (0 without a switch time).
fn report_switches(tally: &Tally, switch_s: f64, ks: &[u64]) -> u64 {
    if switch_s == 0.0 {
        return 0;
    }
    let (short, measured, least) = tally.switches();
    let (k_min, k_max) = (
        ks.iter().copied().min().unwrap_or(0),
        ks.iter().copied().max().unwrap_or(0),
    );
    println!(
        "  switch time {switch_s} s (k = {k_min}…{k_max} ticks): {short} executions with two \
         robots' low-confidence ticks fewer than k ticks apart (expected 0), of {measured} \
         measured on the ticks traversed (the beam search of rounds: over every sequence it \
         expanded); least gap − k: {}",
        least.map_or("-".to_string(), |m| format!("{m} ticks"))
    );
    let beam = tally.beam.each_ref().map(|a| a.load(Ordering::Relaxed));
    if beam[0] > 0 {
        println!(
            "  the beam search: {} of its {} executions measured a switch",
            beam[1], beam[0]
        );
    }
    short
}

/// The number of problems of a run: `problems`, or one per [`EXECUTIONS_PER_PROBLEM`]
/// executions, in `1..=MAX_PROBLEMS` and at most `executions`.
fn n_problems(executions: u64, problems: Option<u64>) -> anyhow::Result<u64> {
    match problems {
        Some(p) if p == 0 || p > MAX_PROBLEMS || p > executions => {
            bail!("--problems must be in 1..={MAX_PROBLEMS} and at most --executions, got {p}")
        }
        Some(p) => Ok(p),
        None => Ok((executions / EXECUTIONS_PER_PROBLEM).clamp(1, MAX_PROBLEMS)),
    }
}

/// What the executions of a stress run add up to, from worker threads.
struct Tally {
    ticks: AtomicU64,
    overlap_ticks: AtomicU64,
    overlap_runs: AtomicU64,
    unfinished: AtomicU64,
    /// Ticks in which a robot moved backwards.
    backward_steps: AtomicU64,
    /// Executions with a switch shorter than the switch time (`AdversaryRun::min_switch_gap_ticks
    /// < k`, measured on the ticks traversed).
    short_switches: AtomicU64,
    /// Executions whose shortest switch was measured (one with fewer than two robots
    /// low-confidence measures none).
    switches_measured: AtomicU64,
    /// The least `gap − k` (ticks) over the measured executions, offset by `2^32` so that it
    /// is unsigned.
    least_margin: AtomicU64,
    /// Executions of the beam search (rounds) and those of them whose shortest switch was
    /// measured.
    beam: [AtomicU64; 2],
    /// The digest of every execution's counts ([`execution_digest`]), added up (wrapping): the
    /// same executions give the same digest in any order.
    digest: AtomicU64,
    /// Per policy kind ([`policy_kind`]): executions, ticks and the wall time of their runs
    /// on the worker threads (ns), for the time split of [`report_time_split`], and the
    /// executions and ticks replayed ([`Replays`]).
    per_policy: [[AtomicU64; 5]; POLICY_KINDS.len()],
}

/// Offset of [`Tally::least_margin`].
const MARGIN_OFFSET: u64 = 1 << 32;

/// The policy kinds of the time split ([`policy_kind`]).
const POLICY_KINDS: [&str; 6] = [
    "beam search",
    "fixed (no correction, extremes, rush, periodic, one switch)",
    "switching favourite",
    "random extremes",
    "random gradients",
    "random per robot",
];

/// The kind of `op` in [`POLICY_KINDS`].
fn policy_kind(op: Adversary) -> usize {
    match op {
        Adversary::Beam { .. } => 0,
        Adversary::Nominal
        | Adversary::Fastest
        | Adversary::Slowest
        | Adversary::RushRobot { .. }
        | Adversary::Periodic { .. }
        | Adversary::SwitchOnce { .. } => 1,
        Adversary::SwitchFavourite { .. } => 2,
        Adversary::RandomSwitching { .. } | Adversary::RandomExtreme => 3,
        Adversary::Random { .. } | Adversary::RandomHeld { .. } => 4,
        Adversary::RandomPerRobot => 5,
    }
}

/// Whether an execution under `op` draws nothing from its random stream, so that it is the
/// same for every execution of one case (`in_rounds`: the beam search is the rounds
/// coordinator's deterministic search; in the continuous cell it runs as a switching
/// favourite, which draws).
fn is_deterministic(op: Adversary, in_rounds: bool) -> bool {
    policy_kind(op) == 1 || (in_rounds && policy_kind(op) == 0)
}

/// The runs of the deterministic (case, policy) pairs of a stress run, each run once and
/// replayed for its other executions: `slots[case · policies + policy]`, with the cell's
/// tasks completed (0 in rounds).
struct Replays {
    slots: Vec<std::sync::OnceLock<(AdversaryRun, u64)>>,
    policies: u64,
    in_rounds: bool,
}

impl Replays {
    fn new(cases: u64, policies: u64, in_rounds: bool) -> Replays {
        Replays {
            slots: (0..cases * policies)
                .map(|_| std::sync::OnceLock::new())
                .collect(),
            policies,
            in_rounds,
        }
    }

    /// The run of policy `p` (`op`) on case `c`: its first run's, if `op` is deterministic and
    /// ran before (`true`), else `run()`'s (stored when deterministic; `false`).
    fn get_or_run(
        &self,
        c: u64,
        p: u64,
        op: Adversary,
        run: impl FnOnce() -> anyhow::Result<(AdversaryRun, u64)>,
    ) -> anyhow::Result<((AdversaryRun, u64), bool)> {
        if !is_deterministic(op, self.in_rounds) {
            return Ok((run()?, false));
        }
        let slot = &self.slots[(c * self.policies + p) as usize];
        if let Some(&r) = slot.get() {
            return Ok((r, true));
        }
        let r = run()?;
        // Two threads may run the same pair at once: both runs are the same.
        let _ = slot.set(r);
        Ok((r, false))
    }
}

/// SplitMix64's finaliser: a well-mixed 64-bit hash of `x`.
fn mix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// The digest of execution `e`'s counts: its ticks, overlap ticks, first overlap, whether it
/// finished, backward steps, fewest tasks, shortest switch and `extra` (the cell's tasks
/// completed), chained through [`mix`]. Summed over the executions it is the run's digest,
/// which a change of the harness must leave as it is for every seed.
fn execution_digest(e: u64, r: &AdversaryRun, extra: u64) -> u64 {
    let opt = |v: Option<u64>| v.map_or(u64::MAX, |x| x);
    [
        r.ticks,
        r.overlap_ticks,
        opt(r.first_overlap),
        u64::from(r.finished),
        r.backward_steps,
        r.min_tasks,
        opt(r.min_switch_gap_ticks),
        extra,
    ]
    .into_iter()
    .fold(mix(e), |h, v| mix(h ^ v))
}

/// Prints the run's digest ([`execution_digest`], summed) and where the executions' time went
/// per policy kind: executions run, ticks, the share of the worker threads' time and ticks
/// per second of one thread, and the executions replayed ([`Replays`]).
fn report_time_split(tally: &Tally) {
    let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
    let total_ns = tally
        .per_policy
        .iter()
        .map(|[_, _, w, _, _]| get(w))
        .sum::<u64>()
        .max(1);
    let parts: Vec<String> = POLICY_KINDS
        .iter()
        .zip(&tally.per_policy)
        .filter(|(_, [n, _, _, rn, _])| get(n) + get(rn) > 0)
        .map(|(name, [n, t, w, rn, rt])| {
            let secs = get(w) as f64 / 1e9;
            format!(
                "{name}: {} executions run, {} ticks, {:.1} % of the time, {:.2} M ticks/s per \
                 thread; {} replayed ({} ticks)",
                get(n),
                get(t),
                100.0 * get(w) as f64 / total_ns as f64,
                get(t) as f64 / secs.max(1e-9) / 1e6,
                get(rn),
                get(rt)
            )
        })
        .collect();
    let replayed: u64 = tally
        .per_policy
        .iter()
        .map(|[_, _, _, rn, _]| get(rn))
        .sum();
    let run: u64 = tally.per_policy.iter().map(|[n, _, _, _, _]| get(n)).sum();
    println!(
        "  digest of the per-execution counts: {:016x}; {run} executions run, {replayed} replayed \
         (a deterministic policy's run on a case, counted again without running it); time per \
         policy kind (thread time {:.1} s): {}",
        get(&tally.digest),
        total_ns as f64 / 1e9,
        parts.join("; ")
    );
}

impl Default for Tally {
    fn default() -> Tally {
        Tally {
            ticks: AtomicU64::new(0),
            overlap_ticks: AtomicU64::new(0),
            overlap_runs: AtomicU64::new(0),
            unfinished: AtomicU64::new(0),
            backward_steps: AtomicU64::new(0),
            short_switches: AtomicU64::new(0),
            switches_measured: AtomicU64::new(0),
            least_margin: AtomicU64::new(u64::MAX),
            beam: [AtomicU64::new(0), AtomicU64::new(0)],
            digest: AtomicU64::new(0),
            per_policy: std::array::from_fn(|_| std::array::from_fn(|_| AtomicU64::new(0))),
        }
    }
}

impl Tally {
    /// One execution: its ticks, its ticks with two or more robots low-confidence, whether
    /// it finished.
    fn add(&self, ticks: u64, overlap_ticks: u64, finished: bool) {
        self.ticks.fetch_add(ticks, Ordering::Relaxed);
        if overlap_ticks > 0 {
            self.overlap_ticks
                .fetch_add(overlap_ticks, Ordering::Relaxed);
            self.overlap_runs.fetch_add(1, Ordering::Relaxed);
        }
        if !finished {
            self.unfinished.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Execution `e`'s run `r` (and `extra`: the cell's tasks completed, 0 in rounds) into the
    /// digest, and its policy's ticks and run time `ns` into the time split.
    /// `replayed`: the run is a replay of the case's first run under the same deterministic
    /// policy ([`Replays`]).
    fn add_run(
        &self,
        e: u64,
        op: Adversary,
        r: &AdversaryRun,
        extra: u64,
        ns: u64,
        replayed: bool,
    ) {
        self.digest
            .fetch_add(execution_digest(e, r, extra), Ordering::Relaxed);
        let [n, t, w, rn, rt] = &self.per_policy[policy_kind(op)];
        if replayed {
            rn.fetch_add(1, Ordering::Relaxed);
            rt.fetch_add(r.ticks, Ordering::Relaxed);
        } else {
            n.fetch_add(1, Ordering::Relaxed);
            t.fetch_add(r.ticks, Ordering::Relaxed);
            w.fetch_add(ns, Ordering::Relaxed);
        }
    }

    /// One execution's ticks in which a robot moved backwards.
    fn add_backward(&self, steps: u64) {
        self.backward_steps.fetch_add(steps, Ordering::Relaxed);
    }

    /// One execution's shortest switch `gap` (ticks, `None` if not measured) against the
    /// switch time of `k` ticks.
    fn add_switch(&self, gap: Option<u64>, k: u64) {
        let Some(g) = gap else { return };
        self.switches_measured.fetch_add(1, Ordering::Relaxed);
        if g < k {
            self.short_switches.fetch_add(1, Ordering::Relaxed);
        }
        let m = (MARGIN_OFFSET + g).saturating_sub(k);
        self.least_margin.fetch_min(m, Ordering::Relaxed);
    }

    /// The switch report: executions with a short switch, executions measured, and the least
    /// `gap − k` (ticks; `None` if none measured).
    fn switches(&self) -> (u64, u64, Option<i64>) {
        let measured = self.switches_measured.load(Ordering::Relaxed);
        let least = self.least_margin.load(Ordering::Relaxed);
        (
            self.short_switches.load(Ordering::Relaxed),
            measured,
            (measured > 0).then(|| least as i64 - MARGIN_OFFSET as i64),
        )
    }

    /// Ticks, overlap ticks, executions with overlaps, unfinished executions.
    fn into_counts(self) -> (u64, u64, u64, u64) {
        (
            self.ticks.into_inner(),
            self.overlap_ticks.into_inner(),
            self.overlap_runs.into_inner(),
            self.unfinished.into_inner(),
        )
    }
}

/// Runs executions `0..executions` through `run_one` in parallel batches of `batch` (the
/// order of the batches is fixed; the results must not depend on the order within one) and
/// prints a progress line, with the overlap ticks `tally` counted so far, after a batch when
/// `report_s` seconds have passed since the last one. Stops at the first batch with an error.
fn run_batches(
    executions: u64,
    batch: u64,
    report_s: f64,
    tally: &Tally,
    run_one: impl Fn(u64) -> anyhow::Result<()> + Sync,
) -> anyhow::Result<()> {
    let start = Instant::now();
    let mut last_report = Instant::now();
    let mut done = 0;
    while done < executions {
        let end = (done + batch).min(executions);
        (done..end).into_par_iter().try_for_each(&run_one)?;
        done = end;
        if last_report.elapsed().as_secs_f64() >= report_s && done < executions {
            let rate = done as f64 / start.elapsed().as_secs_f64();
            println!(
                "  {done}/{executions} executions, {} overlap ticks, {} backward steps, \
                 {rate:.0} executions/s",
                tally.overlap_ticks.load(Ordering::Relaxed),
                tally.backward_steps.load(Ordering::Relaxed)
            );
            last_report = Instant::now();
        }
    }
    Ok(())
}

/// One planned random problem of the continuous stress run.
struct CellCase {
    run: PlannedCell,
    family: &'static str,
    /// The plan's throughput (tasks/h), for the report.
    plan_per_h: f64,
}

/// Problem `index` of the continuous run: index mod 3 = 0 this task's random problem with
/// hold points, 1 without, 2 a test kit family with a shared mask (with hold points; the
/// per-robot families, which no `Problem` describes, fall back to this task's problem with
/// hold points). Planned by `cyclic_plan` (runnable orders), run at a random tick.
fn make_cell_case(
    seed: u64,
    index: u64,
    n_robots: usize,
    tasks: u64,
    switch_s: f64,
    max_busy: f64,
) -> anyhow::Result<CellCase> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x00c0_ffee);
    rng.set_stream(index);
    let mut family = "stress";
    let problem = match index % 3 {
        0 => with_holds(random_problem(&mut rng)?, true)?,
        1 => random_problem(&mut rng)?,
        _ => {
            let f = Family::ALL[((index / 3) % Family::ALL.len() as u64) as usize];
            let case = testkit::Case::random(f, n_robots, &mut rng);
            if let Some(m) = case.shared_mask() {
                family = f.name();
                with_holds(Problem::new(m.conf, m.mean, m.lo, m.hi, m.dt_s)?, true)?
            } else {
                with_holds(random_problem(&mut rng)?, true)?
            }
        }
    };
    let dt_s = problem.dt_s();
    let tick_s = dt_s * rng.random_range(0.25..=1.0);
    let params = CyclicParams {
        switch_s,
        max_busy_share: max_busy,
        ..CyclicParams::default()
    };
    let plan = cyclic_plan(&problem, n_robots, &params)?;
    let cell = plan
        .coordinator(&problem, tick_s)?
        .with_switch_s(switch_s)?
        .with_max_busy_share(max_busy)?;
    let grad_range = [
        problem
            .grad_min()
            .iter()
            .copied()
            .fold(f64::INFINITY, f64::min),
        problem.grad_max().iter().copied().fold(0.0, f64::max),
    ];
    // A task at its slowest (high confidence on plan, low at ψ̇max), in ticks, per robot and
    // task, plus a tick per sample: a generous bound on the run.
    let slow_s: f64 = (0..problem.n_ref())
        .map(|k| {
            if problem.conf()[k] {
                cell.task().grad_exec()[k]
            } else {
                problem.grad_max()[k]
            }
        })
        .sum::<f64>()
        * dt_s;
    // Each of a task's groups may wait the switch time once for its token.
    let per_task = slow_s / tick_s
        + problem.n_ref() as f64
        + (cell.groups().len() as u64 * cell.switch_ticks()) as f64;
    // The load cap's pauses stretch the run by at most 1/u_max: a pass lasts at most the longer
    // of its run without pauses and n(B) ≤ B/u_max + 1 ticks, its busy ticks B at most the
    // ticks it ran.
    let max_ticks = ((tasks + 2) as f64 * n_robots as f64 * per_task / max_busy) as u64 + 1000;
    Ok(CellCase {
        run: PlannedCell {
            adversaries: adversary_set(
                n_robots,
                grad_range,
                (per_task * tasks as f64) as u64,
                &mut rng,
            ),
            cell,
            max_ticks,
        },
        family,
        plan_per_h: plan.tasks_per_hour,
    })
}

/// `cargo xtask stress --cell continuous`: `executions` executions of the continuous cell of
/// `n_robots` robots, each until every robot has completed `tasks` tasks; fails on any tick
/// with two or more robots low-confidence, or an execution that does not complete its tasks.
pub(crate) fn run_continuous(
    executions: u64,
    seed: u64,
    n_robots: usize,
    tasks: u64,
    switch_s: f64,
    max_busy: f64,
    problems: Option<u64>,
) -> anyhow::Result<()> {
    if executions == 0 || tasks == 0 {
        bail!("--executions and --tasks must be ≥ 1");
    }
    tandem::realtime::RobotCount::new(n_robots).map_err(|e| anyhow::anyhow!("--robots: {e}"))?;
    let start = Instant::now();
    let n_problems = n_problems(executions, problems)?;
    let cases: Vec<CellCase> = (0..n_problems)
        .into_par_iter()
        .map(|i| {
            make_cell_case(seed, i, n_robots, tasks, switch_s, max_busy)
                .with_context(|| format!("planning problem {i}"))
        })
        .collect::<anyhow::Result<_>>()?;
    let mut families: Vec<&str> = cases.iter().map(|c| c.family).collect();
    families.sort_unstable();
    families.dedup();
    let mean_plan = cases.iter().map(|c| c.plan_per_h).sum::<f64>() / cases.len() as f64;
    println!(
        "stress --cell continuous: {n_robots} robots, {n_problems} random problems ({}), cyclic plans of {:.1} tasks/h on average{}; planning took {:.1} s",
        families.join(", "),
        mean_plan,
        if max_busy < 1.0 {
            format!(" (load cap {max_busy}, paced)")
        } else {
            String::new()
        },
        start.elapsed().as_secs_f64()
    );
    let runs: Vec<&PlannedCell> = cases.iter().map(|c| &c.run).collect();
    let counts = run_cell_executions(&runs, executions, seed, tasks, switch_s)?;
    let CellCounts {
        ticks,
        overlap_ticks,
        overlap_runs,
        unfinished,
        backward,
        tasks_done,
        min_tasks,
        secs,
        ..
    } = counts;
    let set_size = runs[0].adversaries.len();
    println!(
        "stress --cell continuous: {executions} executions of {n_robots} robots ({set_size} \
         operator policies, seed {seed}), {ticks} ticks, {threads} threads: {overlap_ticks} \
         ticks with two or more robots low-confidence (expected 0) in {overlap_runs} \
         executions; {backward} ticks with a robot moving backwards (expected 0); tasks per robot per execution: at least {min_tasks}, {:.1} on average; \
         {unfinished} unfinished; {secs:.1} s, {:.0} executions/s, {:.1} M ticks/s",
        tasks_done as f64 / (executions * n_robots as u64) as f64,
        executions as f64 / secs,
        ticks as f64 / secs / 1e6,
        threads = rayon::current_num_threads(),
    );
    counts.check()
}

/// One planned continuous cell of a stress run: its coordinator (cloned per execution), the
/// operator policies it runs under and its tick cap per execution.
pub(crate) struct PlannedCell {
    pub(crate) cell: ContinuousCoordinator,
    pub(crate) adversaries: Vec<Adversary>,
    pub(crate) max_ticks: u64,
}

/// What the executions of [`run_cell_executions`] add up to.
#[derive(Clone, Copy)]
pub(crate) struct CellCounts {
    pub(crate) ticks: u64,
    /// Ticks with two or more robots low-confidence, and the executions they fell in.
    pub(crate) overlap_ticks: u64,
    pub(crate) overlap_runs: u64,
    pub(crate) unfinished: u64,
    /// Ticks in which a robot's reference time decreased.
    pub(crate) backward: u64,
    /// Executions with a switch shorter than the switch time (0 when `switch_s` is 0).
    pub(crate) short: u64,
    /// Tasks completed over all executions and robots, and the fewest of one robot in one
    /// execution.
    pub(crate) tasks_done: u64,
    pub(crate) min_tasks: u64,
    /// Wall time of the executions (s).
    pub(crate) secs: f64,
}

/// Runs `executions` executions of `tasks` tasks per robot in batches on rayon's threads:
/// execution `e` runs cell `e mod cells` under policy `(e / cells) mod policies` with the
/// random stream `e` of `seed`, so the counts do not depend on the thread count. Every cell
/// has as many policies as the first.
pub(crate) fn run_cell_executions(
    cases: &[&PlannedCell],
    executions: u64,
    seed: u64,
    tasks: u64,
    switch_s: f64,
) -> anyhow::Result<CellCounts> {
    let n_cells = cases.len() as u64;
    let set_size = cases[0].adversaries.len() as u64;
    let run_start = Instant::now();
    let (tally, tasks_done) = (Tally::default(), AtomicU64::new(0));
    let min_tasks = AtomicU64::new(u64::MAX);
    let replays = Replays::new(n_cells, set_size, false);
    run_batches(executions, CELL_BATCH, 10.0, &tally, |e| {
        let (c, p) = (e % n_cells, (e / n_cells) % set_size);
        let case = &cases[c as usize];
        let op = case.adversaries[p as usize];
        let t0 = Instant::now();
        let ((r, done), replayed) = replays.get_or_run(c, p, op, || {
            let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(0x9e37_79b9_7f4a_7c15));
            rng.set_stream(e);
            let mut cell = case.cell.clone();
            let r = run_cell(&mut cell, op, &mut rng, tasks, case.max_ticks)?;
            Ok((r, cell.tasks_completed().iter().sum()))
        })?;
        tally.add_run(e, op, &r, done, t0.elapsed().as_nanos() as u64, replayed);
        tally.add(r.ticks, r.overlap_ticks, r.finished);
        tally.add_backward(r.backward_steps);
        if switch_s > 0.0 {
            tally.add_switch(r.min_switch_gap_ticks, case.cell.switch_ticks());
        }
        tasks_done.fetch_add(done, Ordering::Relaxed);
        min_tasks.fetch_min(r.min_tasks, Ordering::Relaxed);
        Ok(())
    })?;
    let secs = run_start.elapsed().as_secs_f64();
    report_time_split(&tally);
    let backward = tally.backward_steps.load(Ordering::Relaxed);
    let ks: Vec<u64> = cases.iter().map(|c| c.cell.switch_ticks()).collect();
    let short = report_switches(&tally, switch_s, &ks);
    let (ticks, overlap_ticks, overlap_runs, unfinished) = tally.into_counts();
    Ok(CellCounts {
        ticks,
        overlap_ticks,
        overlap_runs,
        unfinished,
        backward,
        short,
        tasks_done: tasks_done.into_inner(),
        min_tasks: min_tasks.into_inner(),
        secs,
    })
}

impl CellCounts {
    /// An error naming every broken count (overlapping ticks, backward steps, unfinished
    /// executions, switches shorter than the switch time), or `Ok`.
    pub(crate) fn check(&self) -> anyhow::Result<()> {
        let CellCounts {
            overlap_ticks,
            backward,
            unfinished,
            short,
            ..
        } = *self;
        if overlap_ticks > 0 || unfinished > 0 || backward > 0 || short > 0 {
            bail!(
                "safety invariant broken: {overlap_ticks} overlap ticks, {backward} backward \
                 steps, {unfinished} unfinished executions, {short} with a switch shorter than \
                 the switch time"
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A robot of ten samples at `Δt_s` = 0.25 s (`ψ̇` in [0.5, 2], samples 3–5
    /// low-confidence) starting at `start_s`.
    fn robot(start_s: f64) -> Timeline {
        let conf: Vec<bool> = (0..10).map(|n| !(3..6).contains(&n)).collect();
        Timeline::new(&conf, &[1.0; 10], &[0.5; 10], &[2.0; 10], start_s, 0.25).unwrap()
    }

    /// The budget by hand: two robots of 10 samples at most 2 s per sample's 0.25 s (5 s
    /// each at their slowest, 10 s serial), the second starting 60 s after the first, at a
    /// tick of 0.25 s: `2·(10 + 60)/0.25 + 100 = 660` ticks. Without the start offset it was
    /// `2·10/0.25 + 100 = 180`, while the second robot waits at least `(60 − 2.5)/0.25 = 230`
    /// ticks after the first one's end (2.5 s on schedule) before it starts: every execution
    /// of such a round was "unfinished". Each policy ends within the new budget, after more
    /// ticks than the old one.
    /// The replays are sound: every policy [`is_deterministic`] names gives the same run (and
    /// the cell the same tasks) from two random streams, in rounds (the beam search included)
    /// and in the continuous cell. By hand, of the 16 policies of two robots: no correction,
    /// fastest, slowest, rush robot 0 and 1, the two periodic and one switch are fixed (8),
    /// and the beam search in rounds (9); [`Replays`] runs each once and the random ones every
    /// time.
    #[test]
    fn deterministic_policies_run_the_same_from_any_stream() {
        let c = Coordinator::new(vec![robot(0.0), robot(3.0)], 0.25).unwrap();
        let (g, lo, hi) = ([1.0; 3], [0.5; 3], [2.0; 3]);
        let task = Timeline::new(&[true, false, true], &g, &lo, &hi, 0.0, 1.0).unwrap();
        let cell = ContinuousCoordinator::new(task, &[], &[(0, 0), (1, 0)], 2, 1.0).unwrap();
        let set = adversary_set(2, [0.5, 2.0], 40, &mut ChaCha8Rng::seed_from_u64(3));
        assert_eq!(set.len(), 16);
        let (mut fixed_rounds, mut fixed_cell) = (0, 0);
        let replays = Replays::new(1, set.len() as u64, true);
        for (p, &op) in set.iter().enumerate() {
            let rounds: Vec<AdversaryRun> = (0..2)
                .map(|s| run_adversary(c.clone(), op, &mut ChaCha8Rng::seed_from_u64(s), 1000))
                .collect::<Result<_, _>>()
                .unwrap();
            let cells: Vec<(AdversaryRun, u64)> = (0..2)
                .map(|s| {
                    let mut cell = cell.clone();
                    let rng = &mut ChaCha8Rng::seed_from_u64(s);
                    let r = run_cell(&mut cell, op, rng, 3, 1000).unwrap();
                    (r, cell.tasks_completed().iter().sum())
                })
                .collect();
            assert!(rounds[0].finished && cells[0].0.finished, "{op:?}");
            if is_deterministic(op, true) {
                assert_eq!(rounds[0], rounds[1], "{op:?}");
                fixed_rounds += 1;
            }
            if is_deterministic(op, false) {
                assert_eq!(cells[0], cells[1], "{op:?}");
                fixed_cell += 1;
            }
            // The first call runs, the second replays a fixed policy and runs a random one.
            for (call, rng_seed) in [(0, 0), (1, 1)] {
                let (r, replayed) = replays
                    .get_or_run(0, p as u64, op, || {
                        let rng = &mut ChaCha8Rng::seed_from_u64(rng_seed);
                        Ok((run_adversary(c.clone(), op, rng, 1000)?, 0))
                    })
                    .unwrap();
                assert_eq!(replayed, call == 1 && is_deterministic(op, true), "{op:?}");
                assert_eq!(r.0, rounds[call], "{op:?}");
            }
        }
        assert_eq!((fixed_rounds, fixed_cell), (9, 8));
    }

    #[test]
    fn the_tick_budget_counts_the_start_offsets() {
        let c = Coordinator::new(vec![robot(0.0), robot(60.0)], 0.25).unwrap();
        assert_eq!(tick_budget(&c), 660);
        for op in [Adversary::Nominal, Adversary::Fastest, Adversary::Slowest] {
            let mut rng = ChaCha8Rng::seed_from_u64(1);
            let run = run_adversary(c.clone(), op, &mut rng, tick_budget(&c)).unwrap();
            assert!(run.finished, "{op:?}");
            assert!(run.ticks > 230 && run.ticks <= 660, "{op:?}: {}", run.ticks);
        }
    }
}
