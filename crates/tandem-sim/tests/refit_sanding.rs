//! `Planner::refit` on the sanding fixtures: rounds run in the simulated workcell on a fit of
//! three demonstrations, then the task fitted again keeping them (docs/decisions.md, "A refit
//! keeps the recorded rounds"). Prints the measurements the decision records.

mod common;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_lfd::Demonstration;
use tandem_planner::{ExecutionRecord, Planner, PlannerParams};
use tandem_schedule::SamplerParams;
use tandem_sim::task::{Label, TaskParams, Workpiece};
use tandem_sim::workcell::{OperatorParams, run_round};

use common::fixtures;

const ROUNDS: u64 = 8;

/// The defaults with 100 sampler candidates, seed 5, and the first demonstration as the
/// reference (the labels are on its axis; the medoid is the default).
fn params() -> PlannerParams {
    let mut p = PlannerParams {
        sampler: SamplerParams {
            samples: 100,
            seed: 5,
            ..SamplerParams::default()
        },
        ..PlannerParams::default()
    };
    p.fit.reference = tandem_lfd::Reference::First;
    p
}

/// One round of two robots in the simulated workcell (seeded workpieces and operator), the
/// planner's reference labelled by `labels`.
fn simulated_round(planner: &Planner, labels: &[Label], seed: u64) -> Vec<ExecutionRecord> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let task = TaskParams::default();
    let workpieces = [
        Workpiece::random(&task, &mut rng).unwrap(),
        Workpiece::random(&task, &mut rng).unwrap(),
    ];
    run_round(
        planner,
        labels,
        &workpieces,
        &OperatorParams::default(),
        &mut rng,
    )
    .unwrap()
    .records(planner.model())
    .unwrap()
}

fn demos(order: &[usize]) -> Vec<Demonstration> {
    order
        .iter()
        .map(|&i| fixtures().0.demos[i].clone())
        .collect()
}

/// Simulated rounds `0..ROUNDS` (seeds `100 + k`) recorded into `planner`; returns them.
fn run_rounds(planner: &mut Planner, labels: &[Label]) -> Vec<Vec<ExecutionRecord>> {
    (0..ROUNDS)
        .map(|k| {
            let r = simulated_round(planner, labels, 100 + k);
            planner.record_round(&r).unwrap();
            r
        })
        .collect()
}

#[test]
fn a_refit_of_the_sanding_cell_keeps_its_rounds() {
    // The cell: demonstrations 0–2, eight simulated rounds.
    let mut cell = Planner::new(&demos(&[0, 1, 2]), params()).unwrap();
    let rounds = run_rounds(&mut cell, &fixtures().0.labels[0]);

    // Refit with a fourth demonstration (the reference stays demo 0) against a fresh fit of
    // the four with the same rounds recorded: the same confidence, sample for sample.
    let four = demos(&[0, 1, 2, 3]);
    let (refit, report) = cell.refit(&four, params()).unwrap();
    assert!(!report.reference_changed);
    let mut fresh = Planner::new(&four, params()).unwrap();
    let prior = fresh.confidence().high_share();
    for r in &rounds {
        fresh.record_round(r).unwrap();
    }
    assert_eq!(refit.confidence().conf(), fresh.confidence().conf());
    assert_eq!(refit.model().mean(), fresh.model().mean());
    assert_eq!(refit.schedule(), fresh.schedule());
    assert_eq!(refit.rounds_recorded(), ROUNDS as usize);
    eprintln!(
        "sanding, same reference: cell {:.1} % high after {ROUNDS} rounds; refit on four \
         demonstrations {:.1} %, fresh fit of the four with the rounds recorded {:.1} % (its \
         prior {:.1} %)",
        100.0 * report.high_share_before,
        100.0 * refit.confidence().high_share(),
        100.0 * fresh.confidence().high_share(),
        100.0 * prior
    );

    // Another reference (demo 1 first): each execution aligned to demo 1, against the fresh fit of that order whose rounds ran on it (the same
    // workpieces and operator draws, demo 1's labels as the reference's).
    let order = demos(&[1, 0, 2]);
    let (moved, report) = cell.refit(&order, params()).unwrap();
    assert!(report.reference_changed);
    assert_eq!(moved.rounds_recorded(), ROUNDS as usize);
    let labels_1 = &fixtures().0.labels[1];
    let mut rerun = Planner::new(&order, params()).unwrap();
    let prior = rerun.confidence().high_share();
    run_rounds(&mut rerun, labels_1);
    let (a, b) = (moved.confidence().conf(), rerun.confidence().conf());
    let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
    eprintln!(
        "sanding, reference demo 1: refit {:.1} % high, the rounds run on a fresh fit of the \
         new order {:.1} % ({differ} of {} samples differ; its prior {:.1} %)",
        100.0 * moved.confidence().high_share(),
        100.0 * rerun.confidence().high_share(),
        a.len(),
        100.0 * prior
    );
    let sigma2 = |p: &Planner| p.model().sigma2_d().iter().sum::<f64>() / p.model().n_ref() as f64;
    eprintln!(
        "sanding, reference demo 1: mean σ²_D refit {:.4}, rounds run on the new order {:.4}, \
         the cell {:.4}",
        sigma2(&moved),
        sigma2(&rerun),
        sigma2(&cell)
    );
    assert!(moved.confidence().high_share() > prior);
}
