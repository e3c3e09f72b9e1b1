//! A small state file for the tests: the hand-made one-channel task of the simulated cell's
//! tests (low confidence exactly where the demonstrations differ, reference samples 10..20 of
//! 60 at 10 ms), planned for `n` robots.

#![allow(dead_code)]

use std::path::PathBuf;

use tandem_lfd::{Demonstration, FitParams, TaskModel};
use tandem_planner::{Planner, PlannerParams};

pub(crate) const N_REF: usize = 60;

/// Three demonstrations aligned by known warps: demo 1 presses hard (9 N) over reference
/// samples 10..20 and takes two samples per reference sample there; the others 1 N.
pub(crate) fn model() -> TaskModel {
    model_at(0.01)
}

/// [`model`] sampled every `dt_s` (s): its schedule's control tick.
pub(crate) fn model_at(dt_s: f64) -> TaskModel {
    let names = vec!["force".to_string()];
    let light = Demonstration::new(names.clone(), vec![1.0; N_REF], dt_s).unwrap();
    let mut hard = Vec::new();
    let mut warp1 = Vec::new();
    for n in 0..N_REF {
        warp1.push(hard.len() as f64);
        let reps = if (10..20).contains(&n) { 2 } else { 1 };
        for _ in 0..reps {
            hard.push(if (10..20).contains(&n) { 9.0 } else { 1.0 });
        }
    }
    let hard = Demonstration::new(names, hard, dt_s).unwrap();
    let identity: Vec<f64> = (0..N_REF).map(|n| n as f64).collect();
    TaskModel::fit_aligned(
        &[light.clone(), hard, light],
        &[identity.clone(), warp1, identity],
        &FitParams::default(),
    )
    .unwrap()
}

/// A planner of `n` robots on [`model`].
pub(crate) fn planner(n: usize) -> Planner {
    planner_with(model(), n)
}

/// A planner of `n` robots on `model`.
pub(crate) fn planner_with(model: TaskModel, n: usize) -> Planner {
    let params = PlannerParams {
        sampler: tandem_schedule::SamplerParams {
            samples: 50,
            seed: 3,
            ..Default::default()
        },
        ..Default::default()
    };
    Planner::from_model_with_robots(model, params, n).unwrap()
}

/// A fresh folder for test `name` with the state file of [`planner`]`(n)` in it.
pub(crate) fn state_file(name: &str, n: usize) -> PathBuf {
    state_file_of(name, planner(n))
}

/// A fresh folder for test `name` with `planner`'s state file in it.
pub(crate) fn state_file_of(name: &str, planner: Planner) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("tandem-ros2-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("state.tandem");
    planner.save(&path).unwrap();
    path
}

/// Removes the folder [`state_file`] made for `path`.
pub(crate) fn remove(path: &std::path::Path) {
    if let Some(dir) = path.parent() {
        let _ = std::fs::remove_dir_all(dir);
    }
}
