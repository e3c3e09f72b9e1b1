//! The Fig. 2 loop on the sanding fixtures: pairs run in the simulated workcell and
//! recorded by the planner, saved and loaded.

mod common;

use std::path::PathBuf;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem_lfd::TaskModel;
use tandem_planner::{Error, ExecutionRecord, Planner, PlannerParams};
use tandem_schedule::{SamplerParams, validate};
use tandem_sim::task::{TaskParams, Workpiece};
use tandem_sim::workcell::{OperatorParams, correction_input, run_round};

use common::fixtures;

fn params() -> PlannerParams {
    PlannerParams {
        sampler: SamplerParams {
            samples: 100,
            seed: 5,
            ..SamplerParams::default()
        },
        ..PlannerParams::default()
    }
}

fn planner() -> Planner {
    Planner::from_model(fixtures().1.clone(), params()).expect("planner")
}

/// Runs one pair in the simulated workcell and returns its records.
fn pair(planner: &Planner, seed: u64) -> [ExecutionRecord; 2] {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let task = TaskParams::default();
    let workpieces = [
        Workpiece::random(&task, &mut rng).unwrap(),
        Workpiece::random(&task, &mut rng).unwrap(),
    ];
    let run = run_round(
        planner,
        common::labels(),
        &workpieces,
        &OperatorParams::default(),
        &mut rng,
    )
    .unwrap();
    assert!(!run.overlapped());
    run.records(planner.model()).unwrap().try_into().unwrap()
}

fn tmp_dir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tandem-planner-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn record_pair_updates_everything_and_keeps_schedules_valid() {
    let mut p = planner();
    assert!(validate(p.problem(), p.schedule()).is_ok());
    let count0 = p.model().count();
    let high0 = p.confidence().n_high();
    let records = pair(&p, 1);
    // One vote per execution (the default): each execution adds one unit of observation
    // mass on every reference sample its supervised control samples touched (⌊t⌋, and
    // ⌊t⌋ + 1 when t is not whole: the fractional split of Eq. 9; and every sample the robot
    // swept during the tick, before the next logged sample's ⌊t⌋).
    assert!(p.params().confidence.one_vote_per_execution);
    let n_supervised: usize = records
        .iter()
        .map(|r| {
            let (times, swept_to, _) = r.observation_spans().unwrap();
            let mut touched = std::collections::BTreeSet::new();
            for (t, end) in times.into_iter().zip(swept_to) {
                touched.insert(t.floor() as usize);
                if t.fract() > 0.0 {
                    touched.insert(t.floor() as usize + 1);
                }
                touched.extend(t.floor() as usize + 1..end.floor() as usize);
            }
            touched.len()
        })
        .sum();
    let report = p.record_round(&records).unwrap();
    assert_eq!(p.rounds_recorded(), 1);
    assert_eq!(
        p.model().count(),
        count0 + 2,
        "both executions join the model (Eq. 21)"
    );
    assert!(n_supervised > 0);
    assert!((p.observations().total_supervised() - n_supervised as f64).abs() < 1e-6);
    assert_eq!(
        p.confidence().n_high(),
        high0 + report.newly_high - report.reopened
    );
    assert!(validate(p.problem(), p.schedule()).is_ok());
    assert_eq!(report.t_total_s, p.outcome().t_total_s);
}

#[test]
fn a_bad_record_is_rejected_and_changes_nothing() {
    let mut p = planner();
    let mut records = pair(&p, 2);
    records[1].corrected.pop();
    let before = (
        p.model().count(),
        p.observations().clone(),
        p.schedule().clone(),
    );
    let err = p.record_round(&records).unwrap_err();
    assert!(
        matches!(
            err,
            Error::BadExecution {
                what: "corrected",
                ..
            }
        ),
        "{err}"
    );
    assert_eq!(
        (
            p.model().count(),
            p.observations().clone(),
            p.schedule().clone()
        ),
        before
    );
    assert_eq!(p.rounds_recorded(), 0);
}

fn same(a: &Planner, b: &Planner) {
    assert_eq!(a.schedule(), b.schedule());
    assert_eq!(a.outcome(), b.outcome());
    assert_eq!(a.confidence(), b.confidence());
    assert_eq!(a.observations(), b.observations());
    assert_eq!(a.rounds_recorded(), b.rounds_recorded());
    assert_eq!(a.params(), b.params());
    assert_eq!(a.problem(), b.problem());
    assert_eq!(a.model().mean(), b.model().mean());
    assert_eq!(a.model().sigma2_d(), b.model().sigma2_d());
    assert_eq!(a.model().count(), b.model().count());
}

#[test]
fn state_round_trips_and_the_loaded_planner_continues_identically() {
    let dir = tmp_dir("roundtrip");
    let path = dir.join("cell.tandem");
    let mut p = planner();
    p.record_round(&pair(&p, 3)).unwrap();
    p.save(&path).unwrap();
    let mut q = Planner::load(&path).unwrap();
    same(&p, &q);
    // Saving the loaded planner gives the same bytes.
    let again = dir.join("again.tandem");
    q.save(&again).unwrap();
    assert_eq!(
        std::fs::read(&path).unwrap(),
        std::fs::read(&again).unwrap()
    );
    // Both continue identically.
    let records = pair(&p, 4);
    p.record_round(&records).unwrap();
    q.record_round(&records).unwrap();
    same(&p, &q);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A round right after an update runs on the local correction frame (only the samples it
/// corrects at are decomposed); replaying it with the public operator input along
/// `corrections_at` and `command_into` gives every logged sample bit for bit.
#[test]
fn a_round_replays_exactly_with_the_public_operator_input() {
    let mut planner = planner();
    planner.record_round(&pair(&planner, 11)).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let task = TaskParams::default();
    let workpieces = [
        Workpiece::random(&task, &mut rng).unwrap(),
        Workpiece::random(&task, &mut rng).unwrap(),
    ];
    let operator = OperatorParams::default();
    let run = run_round(&planner, common::labels(), &workpieces, &operator, &mut rng).unwrap();
    // A fresh copy of the model: the replay builds the whole task frame's table.
    let model: TaskModel = planner.model().clone();
    let force = model
        .tangent_names()
        .iter()
        .position(|n| n == "force")
        .unwrap();
    let (m, k) = (model.channel_names().len(), model.n_components());
    let mut cmd = vec![0.0; m + 1];
    let mut corrected = 0;
    for robot in &run.robots {
        for (i, &t) in robot.ref_time_log.iter().enumerate() {
            let mut u = vec![0.0; k];
            if robot.corrected[i] {
                corrected += 1;
                correction_input(&model, force, operator.gain, t, &mut u).unwrap();
            }
            model.command_into(&u, t, &mut cmd).unwrap();
            let logged = &robot.samples[i * m..(i + 1) * m];
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(logged), bits(&cmd[..m]), "sample {i} at t {t}");
        }
    }
    assert!(corrected > 100, "{corrected} corrected samples");
}
