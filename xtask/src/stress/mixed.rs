//! `cargo xtask stress --cell continuous --mixed` (issue 45): the continuous cell of
//! different tasks under the adversary policies.
//!
//! Every random cell gives each of its `N` robots its own random problem (the property
//! tests' generator, `tandem_schedule::testkit::random_problem`: 100–400 samples at a period
//! of 10, 5 or 4 ms, its own runs, gradients and bounds; hold points on two robots of three),
//! plans it with `mixed_cyclic_plan` (ratios `r ∈ {1..R}^N`, `R` = 3 for `N ≤ 6` and 2
//! above, runnable orders, the hand-overs counted at the cell's tick and the switch time)
//! and runs it with the plan's coordinator (`MixedCyclicPlan::coordinator`, per-robot
//! timelines) at a random tick of 25–100 % of the shortest task period. Every execution runs
//! one adversary policy (`run_cell`: the adversary set, the beam search replaced by a
//! switching favourite) until every robot has completed `--tasks` tasks. It counts the ticks
//! with two or more robots low-confidence and the ticks in which a robot moved backwards
//! (both expected 0), and with `--switch-s` the switches shorter than the switch time.

use std::time::Instant;

use anyhow::{Context, bail};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use tandem::realtime::adversary::adversary_set;
use tandem::schedule::Problem;
use tandem::schedule::cyclic::{MixedParams, mixed_cyclic_plan};

use super::{CellCounts, PlannedCell, n_problems, run_cell_executions, with_holds};

/// Reference sample periods (s) a robot's task is drawn at.
const PERIODS_S: [f64; 3] = [0.010, 0.005, 0.004];

/// One planned random mixed cell.
struct MixedCase {
    run: PlannedCell,
    /// The plan's throughput and its mixed operator-limited bound (tasks/h).
    plan_per_h: f64,
    operator_limited_per_h: f64,
    /// Tasks per period.
    tasks_per_period: usize,
}

/// Cell `index`: `n_robots` random problems, planned and ready to run.
fn make_case(
    seed: u64,
    index: u64,
    n_robots: usize,
    tasks: u64,
    switch_s: f64,
) -> anyhow::Result<MixedCase> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x0045_0045);
    rng.set_stream(index);
    let problems: Vec<Problem> = (0..n_robots)
        .map(|k| {
            let dt_s = PERIODS_S[rng.random_range(0..PERIODS_S.len())];
            let p = tandem_schedule::testkit::random_problem(&mut rng, 100..=400, dt_s)?;
            with_holds(p, k % 3 != 2)
        })
        .collect::<anyhow::Result<_>>()?;
    let refs: Vec<&Problem> = problems.iter().collect();
    let min_dt = problems
        .iter()
        .map(Problem::dt_s)
        .fold(f64::INFINITY, f64::min);
    let tick_s = min_dt * rng.random_range(0.25..=1.0);
    let params = MixedParams {
        max_ratio: if n_robots <= 6 { 3 } else { 2 },
        handover_tick_s: Some(tick_s),
        switch_s,
        ..MixedParams::default()
    };
    let plan = mixed_cyclic_plan(&refs, &params)?;
    let robot_task: Vec<usize> = (0..n_robots).collect();
    let cell = plan
        .coordinator(&refs, &robot_task, tick_s)?
        .with_switch_s(switch_s)?;
    let grad_range = [
        problems
            .iter()
            .flat_map(|p| p.grad_min().iter().copied())
            .fold(f64::INFINITY, f64::min),
        problems
            .iter()
            .flat_map(|p| p.grad_max().iter().copied())
            .fold(0.0, f64::max),
    ];
    // A task of robot `k` at its slowest (high confidence on plan, low at ψ̇max), in ticks,
    // plus a tick per sample and the switch time per group; a pass at most every robot's
    // `r_k` such tasks one after the other, and every robot has its `tasks` after at most
    // `tasks + 2` passes (`r_k ≥ 1`).
    let per_pass: f64 = (0..n_robots)
        .map(|k| {
            let (p, t) = (&problems[k], cell.task_of(k));
            let slow_s: f64 = (0..p.n_ref())
                .map(|n| {
                    if p.conf()[n] {
                        t.grad_exec()[n]
                    } else {
                        p.grad_max()[n]
                    }
                })
                .sum::<f64>()
                * p.dt_s();
            let per_task = slow_s / tick_s
                + p.n_ref() as f64
                + (cell.groups_of(k).len() as u64 * cell.switch_ticks()) as f64;
            plan.ratios[k] as f64 * per_task
        })
        .sum();
    let max_ticks = ((tasks + 2) as f64 * per_pass) as u64 + 1000;
    Ok(MixedCase {
        run: PlannedCell {
            adversaries: adversary_set(
                n_robots,
                grad_range,
                (per_pass * tasks as f64) as u64,
                &mut rng,
            ),
            cell,
            max_ticks,
        },
        plan_per_h: plan.tasks_per_hour,
        operator_limited_per_h: plan.operator_limited_per_hour,
        tasks_per_period: plan.ratios.iter().sum(),
    })
}

/// `cargo xtask stress --cell continuous --mixed`: `executions` executions of random mixed
/// cells of `n_robots` robots, each until every robot has completed `tasks` tasks; fails on
/// any tick with two or more robots low-confidence, a backward step, a switch shorter than
/// the switch time, or an execution that does not complete its tasks.
pub(crate) fn run_mixed(
    executions: u64,
    seed: u64,
    n_robots: usize,
    tasks: u64,
    switch_s: f64,
    problems: Option<u64>,
) -> anyhow::Result<()> {
    if executions == 0 || tasks == 0 {
        bail!("--executions and --tasks must be ≥ 1");
    }
    if n_robots < 2 {
        bail!("--mixed needs --robots of at least 2 (each robot its own task)");
    }
    tandem::realtime::RobotCount::new(n_robots).map_err(|e| anyhow::anyhow!("--robots: {e}"))?;
    let start = Instant::now();
    let n_cells = n_problems(executions, problems)?;
    let cases: Vec<MixedCase> = (0..n_cells)
        .into_par_iter()
        .map(|i| {
            make_case(seed, i, n_robots, tasks, switch_s)
                .with_context(|| format!("planning mixed cell {i}"))
        })
        .collect::<anyhow::Result<_>>()?;
    let mean = |f: fn(&MixedCase) -> f64| cases.iter().map(f).sum::<f64>() / cases.len() as f64;
    println!(
        "stress --cell continuous --mixed: {n_robots} robots, {n_cells} random cells (a random \
         task per robot), plans of {:.1} tasks per period and {:.1} tasks/h on average \
         ({:.1} % of their mixed operator-limited bounds); planning took {:.1} s",
        mean(|c| c.tasks_per_period as f64),
        mean(|c| c.plan_per_h),
        100.0 * mean(|c| (c.plan_per_h / c.operator_limited_per_h).min(1.0)),
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
        "stress --cell continuous --mixed: {executions} executions of {n_robots} robots \
         ({set_size} operator policies, seed {seed}), {ticks} ticks: {overlap_ticks} ticks \
         with two or more robots low-confidence (expected 0) in {overlap_runs} executions; \
         {backward} ticks with a robot moving backwards (expected 0); tasks per robot per \
         execution: at least {min_tasks}, {:.1} on average; {unfinished} unfinished; \
         {secs:.1} s",
        tasks_done as f64 / (executions * n_robots as u64) as f64,
    );
    counts.check()
}
