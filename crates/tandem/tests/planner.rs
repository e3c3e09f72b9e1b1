//! The Fig. 2 loop through the public API: recording pairs, saving and loading state.

mod common;

use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use tandem::schedule::{SamplerParams, validate};
use tandem::sim::task::{TaskParams, Workpiece};
use tandem::sim::workcell::{OperatorParams, run_pair};
use tandem::{Error, ExecutionRecord, Planner, PlannerParams};

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
    let run = run_pair(
        planner.model(),
        planner.problem(),
        planner.schedule(),
        &fixtures().0.reference_labels,
        &workpieces,
        &OperatorParams::default(),
        &mut rng,
    )
    .unwrap();
    assert!(!run.overlapped());
    let model = planner.model();
    run.robots.map(|r| ExecutionRecord {
        execution: r.execution(model.channel_names(), model.dt_s()).unwrap(),
        supervised: r.supervised,
        corrected: r.corrected,
    })
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
    let n_supervised: usize = records
        .iter()
        .map(|r| r.supervised.iter().filter(|s| **s).count())
        .sum();
    let report = p.record_pair(&records).unwrap();
    assert_eq!(p.pairs_recorded(), 1);
    assert_eq!(
        p.model().count(),
        count0 + 2,
        "both executions join the model (Eq. 21)"
    );
    // Every supervised sample adds one unit of observation mass (Eq. 9).
    assert!((p.observations().total_supervised() - n_supervised as f64).abs() < 1e-6);
    assert_eq!(p.confidence().n_high(), high0 + report.newly_high);
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
    let err = p.record_pair(&records).unwrap_err();
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
    assert_eq!(p.pairs_recorded(), 0);
}

fn same(a: &Planner, b: &Planner) {
    assert_eq!(a.schedule(), b.schedule());
    assert_eq!(a.outcome(), b.outcome());
    assert_eq!(a.confidence(), b.confidence());
    assert_eq!(a.observations(), b.observations());
    assert_eq!(a.pairs_recorded(), b.pairs_recorded());
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
    p.record_pair(&pair(&p, 3)).unwrap();
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
    p.record_pair(&records).unwrap();
    q.record_pair(&records).unwrap();
    same(&p, &q);
    std::fs::remove_dir_all(&dir).unwrap();
}

fn assert_names(err: &Error, path: &Path) {
    assert!(
        err.to_string().contains(&path.display().to_string()),
        "error does not name the file: {err}"
    );
}

#[test]
fn damaged_state_files_give_clear_errors() {
    let dir = tmp_dir("damaged");
    let good = dir.join("good.tandem");
    let p = planner();
    p.save(&good).unwrap();
    let bytes = std::fs::read(&good).unwrap();

    let truncated = dir.join("truncated.tandem");
    std::fs::write(&truncated, &bytes[..bytes.len() - 17]).unwrap();
    let err = Planner::load(&truncated).unwrap_err();
    assert!(matches!(err, Error::Truncated { .. }), "{err}");
    assert_names(&err, &truncated);

    let noise = dir.join("noise.tandem");
    let mut x = 0x2545_F491_4F6C_DD1D_u64;
    let junk: Vec<u8> = (0..4096)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x as u8
        })
        .collect();
    std::fs::write(&noise, &junk).unwrap();
    let err = Planner::load(&noise).unwrap_err();
    assert!(matches!(err, Error::NotAStateFile { .. }), "{err}");
    assert_names(&err, &noise);

    let flipped = dir.join("flipped.tandem");
    let mut bad = bytes.clone();
    let mid = bad.len() / 2;
    bad[mid] ^= 0x01;
    std::fs::write(&flipped, &bad).unwrap();
    let err = Planner::load(&flipped).unwrap_err();
    assert!(matches!(err, Error::Corrupt { .. }), "{err}");
    assert_names(&err, &flipped);

    let version = dir.join("version.tandem");
    let mut other = bytes.clone();
    other[8..12].copy_from_slice(&(tandem::state::FORMAT_VERSION + 1).to_le_bytes());
    std::fs::write(&version, &other).unwrap();
    let err = Planner::load(&version).unwrap_err();
    assert!(matches!(err, Error::UnsupportedVersion { .. }), "{err}");
    assert_names(&err, &version);

    let missing = dir.join("missing.tandem");
    let err = Planner::load(&missing).unwrap_err();
    assert!(matches!(err, Error::Io { .. }), "{err}");
    assert_names(&err, &missing);

    // None of this touched the good file.
    same(&p, &Planner::load(&good).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}
