//! A cyclic plan at run time (`CyclicPlan::coordinator`, issue 21 item 3): on a problem shaped
//! like the sanding task the continuous coordinator of the searched plan, with the operator
//! following the plan, settles at the plan's throughput (within 1 % over the last 20 % of
//! ≥ 50 tasks per robot) when the holds lie next to the passes; under rushing, dragging and
//! the adversary policies it stays sound. Non-runnable orders are refused.
#![allow(
    clippy::print_stdout,
    reason = "the test reports the throughputs it measured"
)]

use rand::SeedableRng;
use tandem_realtime::Operator;
use tandem_realtime::adversary::adversary_set;
use tandem_realtime::continuous::{ContinuousCoordinator, run_cell};
use tandem_schedule::cyclic::is_runnable;
use tandem_schedule::{CyclicParams, Error, Problem, Stretch, cyclic_plan, cyclic_plan_for_order};

/// Head 600, pass 1280, transition 480, pass 1280, transition 480, pass 1280, tail 600
/// samples at 10 ms (the bench's sanding-shaped task): high confidence at `ψ̇min = 1`
/// (`ψ̇̄ = 1.343`, `ψ̇max = 2`), the passes at `ψ̇̄ = 1` within `[0.7, 1.5]` (the operator may
/// rush or drag them). Holds `holds`.
fn sanding_like(holds: Vec<usize>) -> Problem {
    let runs = [
        (600, true),
        (1280, false),
        (480, true),
        (1280, false),
        (480, true),
        (1280, false),
        (600, true),
    ];
    let conf: Vec<bool> = runs
        .iter()
        .flat_map(|&(l, c)| std::iter::repeat_n(c, l))
        .collect();
    let pick =
        |hc: f64, lc: f64| -> Vec<f64> { conf.iter().map(|&c| if c { hc } else { lc }).collect() };
    let (mean, min, max) = (pick(1.343, 1.0), pick(1.0, 0.7), pick(2.0, 1.5));
    Problem::new(conf.clone(), mean, min, max, 0.01)
        .unwrap()
        .with_holds(holds)
        .unwrap()
}

/// First sample of each pass.
const PASS_START: [usize; 3] = [600, 600 + 1280 + 480, 600 + 2 * (1280 + 480)];

/// Holds on the last high-confidence sample before each pass (the gate next to the stretch).
fn holds_next_to_the_passes() -> Vec<usize> {
    PASS_START.iter().map(|s| s - 1).collect()
}

/// Holds in the middle of each transition (the bench's), none in the head.
fn holds_mid_transition() -> Vec<usize> {
    vec![PASS_START[1] - 240, PASS_START[2] - 240]
}

/// Runs `cell` with `op` until every robot has completed `tasks` tasks: the steady throughput
/// (tasks per hour: per robot, its completions over the last 20 % of its tasks divided by
/// their span, real time = ticks × tick; summed over the robots) and the number of ticks with
/// two robots low-confidence.
fn steady_throughput(cell: &mut ContinuousCoordinator, op: Operator, tasks: u64) -> (f64, u64) {
    let n = cell.n_robots();
    let mut done_s: Vec<Vec<f64>> = vec![Vec::new(); n];
    let mut overlaps = 0;
    let mut k = 0_u64;
    while cell.tasks_completed().iter().any(|&t| t < tasks) {
        let t = cell.tick(op).unwrap();
        k += 1;
        overlaps += u64::from(t.overlap());
        assert!(t.fault.is_none());
        for (i, d) in done_s.iter_mut().enumerate() {
            if t.tasks[i] > d.len() as u64 {
                d.push(k as f64 * cell.tick_s());
            }
        }
        assert!(k < 100_000_000, "no progress");
    }
    let per_h = done_s
        .iter()
        .map(|d| {
            let from = d.len() * 4 / 5;
            (d.len() - 1 - from) as f64 / (d[d.len() - 1] - d[from]) * 3600.0
        })
        .sum();
    (per_h, overlaps)
}

#[test]
fn the_planned_operator_reaches_the_plans_throughput_with_gates_next_to_the_passes() {
    let p = sanding_like(holds_next_to_the_passes());
    for n in [2, 3] {
        let plan = cyclic_plan(&p, n, &CyclicParams::default()).unwrap();
        assert!(plan.is_runnable(&p));
        // The operator bound: 3600 / 38.4 s.
        assert!((plan.tasks_per_hour - 93.75).abs() < 1e-6, "{plan:?}");
        let mut cell = plan.coordinator(&p, 0.01).unwrap();
        let (per_h, overlaps) = steady_throughput(&mut cell, Operator::Scheduled, 50);
        println!(
            "N = {n}, gates next to the passes: {per_h:.3} tasks/h at run time, plan {:.3}",
            plan.tasks_per_hour
        );
        assert_eq!(overlaps, 0);
        assert!(
            (per_h / plan.tasks_per_hour - 1.0).abs() < 0.01,
            "{per_h} vs {}",
            plan.tasks_per_hour
        );
        // No faster than the operator can work.
        assert!(per_h <= 93.75 * (1.0 + 1e-3));
    }
}

#[test]
fn gates_far_from_the_passes_cost_the_travel_from_the_gate_at_every_hand_over() {
    // Holds in the middle of the transitions and none in the head: the token's robot leaves
    // its gate only once the previous group is left, so the operator waits 6 s (the head, from
    // the start) before every pass 0 and 2.4 s before passes 1 and 2. With every robot at its
    // gate when its token comes (it is, here), a pass of the tokens takes N·(38.4 + 6 + 2·2.4)
    // = N·49.2 s: 3600/49.2 = 73.17 tasks/h, whatever N ≥ 2 — against the plan's 93.75.
    let p = sanding_like(holds_mid_transition());
    for n in [2, 3] {
        let plan = cyclic_plan(&p, n, &CyclicParams::default()).unwrap();
        let mut cell = plan.coordinator(&p, 0.01).unwrap();
        let (per_h, overlaps) = steady_throughput(&mut cell, Operator::Scheduled, 50);
        println!(
            "N = {n}, gates mid-transition: {per_h:.3} tasks/h at run time, plan {:.3}",
            plan.tasks_per_hour
        );
        assert_eq!(overlaps, 0);
        assert!((per_h / (3600.0 / 49.2) - 1.0).abs() < 0.01, "{per_h}");
    }
}

#[test]
fn rushing_dragging_and_the_adversary_policies_stay_sound() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(21);
    for holds in [holds_next_to_the_passes(), holds_mid_transition(), vec![]] {
        let p = sanding_like(holds.clone());
        for n in [2, 3] {
            let plan = cyclic_plan(&p, n, &CyclicParams::default()).unwrap();
            let cell = plan.coordinator(&p, 0.01).unwrap();
            for op in [Operator::Slowest, Operator::Fastest] {
                let mut c = cell.clone();
                let (per_h, overlaps) = steady_throughput(&mut c, op, 50);
                assert_eq!(overlaps, 0, "{holds:?} {n} {op:?}");
                assert!(per_h > 0.0);
            }
            for a in adversary_set(n, [0.7, 2.0], 400_000, &mut rng) {
                let mut c = cell.clone();
                let run = run_cell(&mut c, a, &mut rng, 50, 100_000_000).unwrap();
                assert!(
                    run.finished && run.overlap_ticks == 0,
                    "{holds:?} {n} {a:?}"
                );
            }
        }
    }
}

#[test]
fn a_non_runnable_order_is_refused_and_the_default_search_plans_runnable_orders() {
    // Two passes without a hold between them; robot 1's pass between robot 0's two is a valid
    // plan when the gap is long enough for it, but not runnable.
    let conf: Vec<bool> = [(2, true), (2, false), (3, true), (2, false), (2, true)]
        .iter()
        .flat_map(|&(l, c)| std::iter::repeat_n(c, l))
        .collect();
    let n = conf.len();
    let p = Problem::new(conf, vec![1.0; n], vec![0.5; n], vec![3.0; n], 1.0).unwrap();
    let st = |robot, lc| Stretch { robot, lc };
    let interleaved = [st(0, 0), st(1, 0), st(0, 1), st(1, 1)];
    assert!(!is_runnable(&p, &interleaved));
    let plan = cyclic_plan_for_order(&p, 2, &interleaved).unwrap();
    assert!(matches!(
        plan.coordinator(&p, 0.1),
        Err(Error::NotRunnable {
            position: 2,
            robot: 0,
            lc: 1
        })
    ));
    let every = CyclicParams {
        runnable_only: false,
        ..CyclicParams::default()
    };
    let free = cyclic_plan(&p, 2, &every).unwrap();
    let runnable = cyclic_plan(&p, 2, &CyclicParams::default()).unwrap();
    assert!(runnable.is_runnable(&p) && runnable.coordinator(&p, 0.1).is_ok());
    assert!(free.period_s <= runnable.period_s * (1.0 + 1e-12));
    // The local search with runnable units keeps every order runnable too (N = 4).
    let local = cyclic_plan(
        &p,
        4,
        &CyclicParams {
            max_enumerated: 1,
            ..CyclicParams::default()
        },
    )
    .unwrap();
    assert!(!local.order_exhaustive && local.is_runnable(&p));
    assert!(local.coordinator(&p, 0.1).is_ok());
    // A plan of another problem, a bad tick.
    let other = sanding_like(vec![]);
    assert!(matches!(
        runnable.coordinator(&other, 0.1),
        Err(Error::BadParam { .. })
    ));
    assert!(matches!(
        runnable.coordinator(&p, f64::NAN),
        Err(Error::Realtime(_))
    ));
}
