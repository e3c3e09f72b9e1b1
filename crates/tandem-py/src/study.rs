//! The simulated study of §III (Fig. 5) for `tandem.study` (python/tandem/study.py wraps
//! these functions in result objects).
//!
//! A study learns from demonstrations: the six sanding demonstrations in a folder with the
//! layout of `fixtures/sanding/` (`demo_<i>.csv`, `demo_<i>.labels.csv`), or, without a
//! folder, the same six generated in memory by the task generator with the fixtures' seed
//! (`tandem::sim::task::FIXTURE_SEED`; the committed CSV files round those samples to 6
//! decimals, so the two differ in the last digits).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

use pyo3::prelude::*;
use pyo3::types::PyDict;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::errors::{Error, Result, guard};
use crate::facade::{
    Cell, FIXTURE_SEED, Label, N_FIXTURE_DEMOS, PhaseTimes, StudyConfig, StudyInputs, TaskDemo,
    TaskModel, demonstrations, run_cell_trial, run_trial, run_trials,
};
use crate::params::{from_py, serialize_to_py};

/// A study's configuration from Python (`None`, a dict or a TOML path), checked.
fn config(x: Option<&Bound<'_, PyAny>>) -> Result<StudyConfig> {
    let c: StudyConfig = from_py(x, "config")?;
    c.validate()?;
    Ok(c)
}

/// The configuration with every default filled in, checked, as a nested dict (the keys of
/// `fixtures/study.toml` and `tandem::study::StudyConfig`).
#[pyfunction]
#[pyo3(signature = (config=None))]
pub(crate) fn study_config<'py>(
    py: Python<'py>,
    config: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    serialize_to_py(py, &self::config(config)?)
}

/// The task a study learns: the fitted model and the reference demonstration's labels.
/// Made once by `study_prepare` and shared by every trial (Python caches it per process).
#[pyclass(module = "tandem", name = "StudyTask", frozen)]
pub(crate) struct PyStudyTask {
    model: Arc<TaskModel>,
    labels: Arc<Vec<Label>>,
    alignment: Duration,
}

/// Reads or generates the demonstrations (each with its labels), fits the model with
/// `config.planner.fit` and takes the labels of whichever demonstration the fit chose as the
/// reference (`StudyInputs::reference_labels`).
fn prepare(config: &StudyConfig, demos_dir: Option<&Path>) -> Result<PyStudyTask> {
    let t = Instant::now();
    let inputs = match demos_dir {
        Some(dir) => StudyInputs::from_dir(dir)?,
        None => {
            let mut rng = ChaCha8Rng::seed_from_u64(FIXTURE_SEED);
            let set = demonstrations(&config.task, N_FIXTURE_DEMOS, &mut rng)?;
            let task_demos: Vec<TaskDemo> = set.into_iter().map(|(_, d)| d).collect();
            StudyInputs::from_task_demos(&task_demos)?
        }
    };
    let model = TaskModel::fit(&inputs.demos, &config.planner.fit)?;
    model.prepare_corrections();
    let labels = inputs.reference_labels(&model)?;
    Ok(PyStudyTask {
        model: Arc::new(model),
        labels: Arc::new(labels),
        alignment: t.elapsed(),
    })
}

/// Fits the study's task: from `demos_dir` (the layout of `fixtures/sanding/`) or, when
/// `None`, from the six demonstrations the generator makes with the fixtures' seed.
#[pyfunction]
#[pyo3(signature = (config=None, demos_dir=None))]
pub(crate) fn study_prepare(
    py: Python<'_>,
    config: Option<&Bound<'_, PyAny>>,
    demos_dir: Option<PathBuf>,
) -> PyResult<PyStudyTask> {
    let config = self::config(config)?;
    Ok(py.detach(|| guard(|| prepare(&config, demos_dir.as_deref())))?)
}

/// Phase wall times (s) as a dict.
fn times_dict<'py>(py: Python<'py>, t: &PhaseTimes) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("alignment_s", t.alignment.as_secs_f64())?;
    d.set_item("model_update_s", t.model_update.as_secs_f64())?;
    d.set_item("confidence_s", t.confidence.as_secs_f64())?;
    d.set_item("scheduling_s", t.scheduling.as_secs_f64())?;
    d.set_item("simulation_s", t.simulation.as_secs_f64())?;
    Ok(d)
}

/// Runs every trial of the study on `task` (in parallel on `threads` threads, default all;
/// the result does not depend on the number). Returns `(result, summary, phase_times)`: the
/// dict `cargo xtask study` writes as `study.json`, the per-iteration mean and standard
/// deviation across trials (Fig. 5), and wall times per phase.
#[pyfunction]
#[pyo3(signature = (task, config=None, threads=None))]
pub(crate) fn study_run<'py>(
    py: Python<'py>,
    task: PyRef<'py, PyStudyTask>,
    config: Option<&Bound<'py, PyAny>>,
    threads: Option<usize>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let config = self::config(config)?;
    let (model, labels) = (task.model.clone(), task.labels.clone());
    let run = || guard(|| Ok(run_trials(&config, &model, &labels, &|_| {})?));
    let (result, mut times) = py.detach(|| match threads {
        None => run(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| Error::param("threads", e.to_string()))
            .and_then(|pool| pool.install(run)),
    })?;
    times.alignment = task.alignment;
    Ok((
        serialize_to_py(py, &result)?,
        serialize_to_py(py, &result.summary())?,
        times_dict(py, &times)?,
    ))
}

/// Runs trial `trial` of the study on `task` (seeded by `(config.seed, trial)` only, so it
/// equals that trial of a whole study). Returns `(trial_result, phase_times)`.
#[pyfunction]
#[pyo3(signature = (task, config, trial))]
pub(crate) fn study_run_trial<'py>(
    py: Python<'py>,
    task: PyRef<'py, PyStudyTask>,
    config: Option<&Bound<'py, PyAny>>,
    trial: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let config = self::config(config)?;
    let (model, labels) = (task.model.clone(), task.labels.clone());
    let (result, times) =
        py.detach(|| guard(|| Ok(run_trial(&config, &model, &labels, trial, &|_| {})?)))?;
    Ok((serialize_to_py(py, &result)?, times_dict(py, &times)?))
}

/// Runs trial `trial` of the continuous study (`config["cell"]` must be `"continuous"`) on
/// `task`: `N = config["robots"]` robots, `M = config["operator"]["operators"]` operators,
/// each robot starting its next task as soon as the operators' order allows, re-planned every
/// `N` tasks, for `config["executions"]` tasks (seeded by `(config.seed, trial)` only, so it
/// equals that trial of `cargo xtask study --cell continuous`). Returns `(trial_result,
/// phase_times)`: the trial's record as `study.json`'s `result.trials[trial]` holds it (its
/// `steady` window: tasks/h, operator busy share; `stats`: ticks, overlap ticks, faults).
#[pyfunction]
#[pyo3(signature = (task, config, trial))]
pub(crate) fn study_run_cell_trial<'py>(
    py: Python<'py>,
    task: PyRef<'py, PyStudyTask>,
    config: Option<&Bound<'py, PyAny>>,
    trial: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let config = self::config(config)?;
    if config.cell != Cell::Continuous {
        return Err(Error::param(
            "cell",
            format!(
                "study_run_cell_trial runs the continuous cell, the configuration says {:?}: \
                 set config[\"cell\"] = \"continuous\" (or use study_run_trial for rounds)",
                config.cell.name()
            ),
        )
        .into());
    }
    let (model, labels) = (task.model.clone(), task.labels.clone());
    let (result, times) =
        py.detach(|| guard(|| Ok(run_cell_trial(&config, &model, &labels, trial, &|_| {})?)))?;
    Ok((serialize_to_py(py, &result)?, times_dict(py, &times)?))
}

#[pymethods]
impl PyStudyTask {
    /// ``T_ref`` of the fitted model.
    #[getter]
    fn n_ref(&self) -> usize {
        self.model.n_ref()
    }

    /// Wall time (s) of reading or generating the demonstrations and fitting.
    #[getter]
    fn alignment_s(&self) -> f64 {
        self.alignment.as_secs_f64()
    }

    fn __repr__(&self) -> String {
        format!(
            "StudyTask(n_ref={}, reference_idx={})",
            self.model.n_ref(),
            self.model.reference_idx()
        )
    }
}
