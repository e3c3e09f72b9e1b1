//! `cargo xtask <cmd>`: repeatable project tasks (see README.md and docs/ARCHITECTURE.md).
//!
//! Each subcommand lives in its own module; this file only parses the command line and
//! dispatches, so that tasks added by different changes do not touch each other's code.
#![allow(clippy::print_stdout, reason = "xtask reports to the terminal")]

#[macro_use]
mod legend;
mod bags;
mod capacity;
mod cellfig;
mod fig5;
mod fit_defaults;
mod fixtures;
mod fleet;
mod reference_order;
mod stress;
mod study;
mod study_cell;
mod test;
mod zoo;

use std::path::{Path, PathBuf};

use clap::{Parser, Subcommand};

/// The workspace root (the folder above `xtask/`): every path an xtask reads or writes by
/// default is relative to it.
pub(crate) fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask lives one folder below the workspace root")
        .to_path_buf()
}

/// Command line of `cargo xtask`.
#[derive(Parser)]
#[command(name = "cargo xtask", about = "tandem's repeatable tasks")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

/// The tasks.
#[derive(Subcommand)]
enum Cmd {
    /// Run the simulated study of §III and draw Fig. 5 (defaults: fixtures/study.toml).
    Study(study::StudyArgs),
    /// Measure ROS 2 bag support: the sanding fixtures as bags fitted against the CSV fit, and
    /// the time to read and fit bags against the same data as CSV (docs/decisions.md).
    Bags(bags::BagsArgs),
    /// Run the study for N = 1..--max-robots (default 8) robots with reduced sizes and draw throughput and operator
    /// busy share against N (results/capacity/capacity.svg and .png; docs/study.md).
    Capacity(capacity::CapacityArgs),
    /// Regenerate the generated fixtures: the sanding demonstrations in fixtures/sanding/
    /// and the golden state file in fixtures/state/ (see fixtures/README.md).
    Fixtures {
        /// Write nothing; fail, naming the files, if the committed fixtures differ.
        #[arg(long)]
        check: bool,
    },
    /// Fit the fixtures in each of their six rotations with each reference choice (first,
    /// medoid) and run a reduced study on each: how much the order of the demonstrations
    /// changes σ²_D, the speed bounds and the confidence (docs/decisions.md).
    ReferenceOrder(reference_order::ReferenceOrderArgs),
    /// Fit every zoo task with every choice of first file, the medoid and the default
    /// reference: high confidence from the prior, low-confidence regions and short islands
    /// against the truth (docs/decisions.md, "Fit defaults measured on the task zoo").
    FitDefaults(fit_defaults::FitDefaultsArgs),
    /// Run every test: `cargo test --workspace`, then build the Python wheel (maturin) into a
    /// virtual environment under target/ with the pinned packages of
    /// python/requirements-dev.txt and run pytest on python/tests (the README's test command).
    Test(test::TestArgs),
    /// The whole loop on every family of the task zoo (tandem-zoo): fit with the defaults,
    /// learn with a simulated operator who follows each family's truth, for N robots in rounds
    /// and in a continuous cell; tables in results/zoo/zoo.md and docs/zoo.md (--docs).
    Zoo(zoo::ZooArgs),
    /// Run E Coordinator executions of random schedules of N robots under adversarial operators
    /// and count ticks with two or more robots low-confidence (expected 0).
    Stress {
        /// Total number of executions.
        #[arg(long, default_value_t = 1_000_000)]
        executions: u64,
        /// Number of robots N (1 to 16): half the problems from the test kit's families, every
        /// shared-mask problem scheduled by the production scheduler (`sample_schedule_n`), the
        /// rest tight at an acceptance edge of the margin check.
        #[arg(long, default_value_t = 2)]
        robots: usize,
        /// Seed of the random problems, the sampler and the operators.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Give every problem hold points (the middle of each high-confidence run of at least
        /// three samples): the scheduler uses them (release rules, dwells), per-robot plans get
        /// interleaved starts with release rules accepted by the margin check with holds.
        #[arg(long)]
        holds: bool,
        /// `rounds` (default): one execution is one round of the N robots, as above.
        /// `continuous`: the continuous cell — every problem's cyclic plan
        /// (`cyclic_plan`, runnable orders) run by its `ContinuousCoordinator`, each execution
        /// until every robot has completed `--tasks` tasks, under the adversary policies.
        #[arg(long, default_value = "rounds", value_parser = ["rounds", "continuous"])]
        cell: String,
        /// With `--cell continuous`: tasks every robot completes per execution.
        #[arg(long, default_value_t = 50)]
        tasks: u64,
        /// The operator's switch time δ (real s, ≥ 0; issue 41): rounds get the production
        /// scheduler's schedules at δ (half the problems) and tight schedules at the edge of
        /// `check_margins` at δ (the other half), run by coordinators that wait δ at their holds;
        /// the continuous cell plans δ and its token waits it. Fails on any execution in which
        /// two robots' low-confidence ticks are fewer than `k = switch_ticks(δ, tick)` ticks
        /// apart. 0 (default): the run without it, unchanged.
        #[arg(long, default_value_t = 0.0)]
        switch_s: f64,
        /// With `--cell continuous`: the operator's load cap u_max in (0, 1] (issue 41): the
        /// plans keep it (`CyclicParams::max_busy_share`) and the token paces the operator to it
        /// (`ContinuousCoordinator::with_max_busy_share`). 1 (default): none.
        #[arg(long, default_value_t = 1.0)]
        max_busy: f64,
        /// Operators M (issue 44; default 1: the runs above). With M > 1 each execution runs M
        /// operators, each with its own copy of the execution's policy on the robot it
        /// supervises, and fails on a tick with more than M robots low-confidence, a stretch
        /// handed over mid-way, an operator on two robots, a fault or a backward step. Rounds:
        /// the sectored round (`Coordinator::sectored`, M even sectors, each a test kit case
        /// tight at the edge of the one-operator check, the beam search per sector), no holds;
        /// `--cell continuous`: the cyclic plans run with M tokens (no load cap).
        #[arg(long, default_value_t = 1)]
        operators: usize,
        /// Random problems to draw (default: one per 1000 executions, 1–200): more problems
        /// with fewer executions each for a reduced batch.
        #[arg(long)]
        problems: Option<u64>,
        /// With `--cell continuous`: a cell of different tasks (issue 45) — each robot its own
        /// random problem, the mixed cyclic plan (`mixed_cyclic_plan`, task ratios) run by its
        /// per-robot coordinator (`MixedCyclicPlan::coordinator`); `--problems` counts cells.
        #[arg(long)]
        mixed: bool,
    },
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.cmd {
        Cmd::Fixtures { check } => fixtures::run(check),
        Cmd::Study(args) => study::run(&args),
        Cmd::Capacity(args) => capacity::run(&args),
        Cmd::Bags(args) => bags::run(&args),
        Cmd::Stress {
            executions,
            robots,
            seed,
            holds,
            cell,
            tasks,
            switch_s,
            max_busy,
            operators,
            problems,
            mixed,
        } => {
            if !(switch_s.is_finite() && switch_s >= 0.0) {
                anyhow::bail!("--switch-s must be finite and ≥ 0 (seconds), got {switch_s}");
            }
            if !(max_busy > 0.0 && max_busy <= 1.0) {
                anyhow::bail!(
                    "--max-busy must be in (0, 1] (the operator's busy share cap), got {max_busy}"
                );
            }
            if mixed {
                if cell != "continuous" || max_busy < 1.0 {
                    anyhow::bail!(
                        "--mixed runs the continuous cell without a load cap: add --cell continuous and leave --max-busy at 1"
                    );
                }
                stress::mixed::run_mixed(executions, seed, robots, tasks, switch_s, problems)
            } else if operators != 1 {
                if max_busy < 1.0 {
                    anyhow::bail!(
                        "--max-busy with --operators {operators}: the load cap paces one operator"
                    );
                }
                stress::operators::run(
                    cell == "continuous",
                    executions,
                    seed,
                    robots,
                    operators,
                    holds,
                    tasks,
                    switch_s,
                    problems,
                )
            } else if cell == "continuous" {
                stress::run_continuous(
                    executions, seed, robots, tasks, switch_s, max_busy, problems,
                )
            } else if max_busy < 1.0 {
                anyhow::bail!(
                    "--max-busy is for --cell continuous (the rounds stress runs tight schedules at the margin check's edge, which has no load cap)"
                )
            } else {
                stress::run(executions, seed, robots, holds, switch_s, problems)
            }
        }
        Cmd::ReferenceOrder(args) => reference_order::run(&args),
        Cmd::FitDefaults(args) => fit_defaults::run(&args),
        Cmd::Test(args) => test::run_all(&args),
        Cmd::Zoo(args) => zoo::run(&args),
    }
}
