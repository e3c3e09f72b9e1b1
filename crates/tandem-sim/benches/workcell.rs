//! Benchmarks of the simulated workcell per round-tick (one control tick of a two-robot
//! round: the operator's decision, the commands, the logs and one `Coordinator::tick`), next
//! to one bare `Coordinator::tick` on the same schedule, on the study's own inputs: the model
//! fitted to the committed sanding fixtures, after 10 recorded rounds (so the schedule
//! overlaps the robots and part of the task is high-confidence). Run with
//! `cargo bench -p tandem-sim --bench workcell`.
//!
//! - `workcell_tick/prepared`: [`run_round`] on a model whose correction directions are
//!   already computed, divided by the round's ticks (the per-tick cost proper);
//! - `workcell_tick/after_update`: the same right after a model update, as every round of the
//!   study runs, so that computing the correction directions is part of the round (one
//!   eigendecomposition per reference sample the operator corrects at, on first use);
//! - `round_parts/prepare_corrections` and `round_parts/coordinator_checked`: costs that do
//!   not scale with the ticks (every sample's correction directions and their task-wide
//!   table, which a round no longer needs; the coordinator with its margin check);
//! - `coordinator_tick/scheduled`: one `Coordinator::tick` with the scheduled operator input
//!   on the same schedule (the floor the workcell is compared with).

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_lfd::TaskModel;
use tandem_planner::{Planner, PlannerParams};
use tandem_realtime::Operator;
use tandem_sim::study::StudyInputs;
use tandem_sim::task::{Label, TaskParams, Workpiece};
use tandem_sim::workcell::{OperatorParams, RoundRun, run_round};

/// Rounds recorded before the benchmarked round.
const ROUNDS: usize = 10;

struct Setup {
    /// The planner right after its last update (correction directions not yet computed).
    planner: Planner,
    labels: Vec<Label>,
    workpieces: Vec<Workpiece>,
    operator: OperatorParams,
}

fn setup() -> Setup {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/sanding");
    let inputs = StudyInputs::from_dir(&dir).expect("the committed fixtures load");
    let mut params = PlannerParams::default();
    params.sampler.samples = 200;
    params.sampler.seed = 2023;
    let model = TaskModel::fit(&inputs.demos, &params.fit).expect("the fixtures fit");
    let labels = inputs
        .reference_labels(&model)
        .expect("every fixture has its labels");
    let mut planner = Planner::from_model_with_robots(model, params, 2).expect("plans");
    let operator = OperatorParams::default();
    let task = TaskParams::default();
    let mut rng = ChaCha8Rng::seed_from_u64(2023);
    let draw = |rng: &mut ChaCha8Rng| -> Vec<Workpiece> {
        (0..2)
            .map(|_| Workpiece::random(&task, rng).expect("valid task"))
            .collect()
    };
    for _ in 0..ROUNDS {
        let wp = draw(&mut rng);
        let run = run_round(&planner, &labels, &wp, &operator, &mut rng).expect("runs");
        let records = run.records(planner.model()).expect("valid records");
        planner.record_round(&records).expect("records");
    }
    Setup {
        planner,
        workpieces: draw(&mut rng),
        labels,
        operator,
    }
}

/// Runs one round of `s` on `planner` with a fixed operator seed.
fn round(s: &Setup, planner: &Planner) -> RoundRun {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    run_round(planner, &s.labels, &s.workpieces, &s.operator, &mut rng).expect("runs")
}

/// Measures `iters` round-ticks: whole rounds of `planner()` (made outside the timer), the
/// time scaled to `iters` ticks.
fn per_tick(iters: u64, ticks: usize, mut run: impl FnMut() -> Duration) -> Duration {
    let rounds = iters.div_ceil(ticks as u64).max(1);
    let mut total = Duration::ZERO;
    for _ in 0..rounds {
        total += run();
    }
    total.mul_f64(iters as f64 / (rounds as f64 * ticks as f64))
}

fn bench(c: &mut Criterion) {
    let s = setup();
    let prepared = s.planner.clone();
    prepared.model().prepare_corrections();
    let reference = round(&s, &prepared);
    let ticks = reference.ticks;
    let supervised: usize = reference
        .robots
        .iter()
        .map(|r| r.supervised.iter().filter(|b| **b).count())
        .sum();
    eprintln!(
        "round of {ticks} ticks ({:.2} s), {supervised} supervised robot-ticks, {:.1} % high \
         confidence",
        reference.duration_s(),
        100.0 * s.planner.confidence().high_share()
    );
    let mut group = c.benchmark_group("workcell_tick");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    group.bench_function("prepared", |b| {
        b.iter_custom(|iters| {
            per_tick(iters, ticks, || {
                let t = Instant::now();
                black_box(round(&s, &prepared));
                t.elapsed()
            })
        })
    });
    group.bench_function("after_update", |b| {
        b.iter_custom(|iters| {
            per_tick(iters, ticks, || {
                let fresh = s.planner.clone();
                let t = Instant::now();
                black_box(round(&s, &fresh));
                t.elapsed()
            })
        })
    });
    group.finish();
    // The parts of a round that do not scale with its ticks.
    let mut group = c.benchmark_group("round_parts");
    group.sample_size(10);
    group.bench_function("prepare_corrections", |b| {
        b.iter_batched(
            || s.planner.model().clone(),
            |fresh| {
                fresh.prepare_corrections();
                fresh
            },
            criterion::BatchSize::LargeInput,
        )
    });
    group.bench_function("coordinator_checked", |b| {
        b.iter(|| black_box(prepared.coordinator().expect("a checked schedule")))
    });
    group.finish();
    let coord = prepared.coordinator().expect("a checked schedule");
    c.bench_function("coordinator_tick/scheduled", |b| {
        let mut coord = coord.clone();
        b.iter(|| {
            if coord.is_finished() {
                coord.reset();
            }
            black_box(
                coord
                    .tick(black_box(Operator::Scheduled))
                    .expect("valid input"),
            )
        })
    });
}

/// Runs every benchmark of this file (configured from the command line).
pub fn benches() {
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
}

criterion_main!(benches);
