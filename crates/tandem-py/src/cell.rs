//! `tandem.fit_cell` and `tandem.CellPlanner`: a cell of different tasks on different robots
//! (issue 45; Rust `tandem_planner::CellPlanner`), with the command line's state file
//! (`tandem fit --task NAME=FILES … --robots NAME=K,…`, format 12 for two or more tasks).

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::errors::{Error, Result, guard};
use crate::facade::{CellPlanner, CellSchedule, PlannerParams, StateLock, TaskSpec};
use crate::planner::{
    Channels, PyPlanner, execution_record, lock_timeout, per_robot, planner_params, report_dict,
};

/// A per-task argument: one value for every task, or a dict `{task name: value}` (tasks
/// not in the dict get `None`). `what` names the argument in errors.
fn per_task<'py, T: FromPyObjectOwned<'py>>(
    x: Option<&Bound<'py, PyAny>>,
    task: &str,
    names: &[String],
    what: &str,
) -> Result<Option<T>> {
    let Some(x) = x.filter(|x| !x.is_none()) else {
        return Ok(None);
    };
    if let Ok(d) = x.cast::<PyDict>() {
        for k in d.keys() {
            let k: String = k
                .extract()
                .map_err(|_| Error::param(what, "its keys must be task names (str)"))?;
            if !names.contains(&k) {
                return Err(Error::param(
                    what,
                    format!("no task {k:?} (the tasks: {})", names.join(", ")),
                ));
            }
        }
        return match d
            .get_item(task)
            .map_err(|e| Error::param(what, e.to_string()))?
        {
            None => Ok(None),
            Some(v) if v.is_none() => Ok(None),
            Some(v) => v
                .extract::<T>()
                .map(Some)
                .map_err(|e| Error::param(what, format!("task {task:?}: {}", e.into()))),
        };
    }
    x.extract::<T>().map(Some).map_err(|e| {
        Error::param(
            what,
            format!("{}; or give a dict {{task: value}}", e.into()),
        )
    })
}

/// Fits a cell of different tasks on different robots (issue 45): one task model,
/// confidence and recorded rounds per task; robots that share a task share its learning;
/// one rounds schedule over all robots (each robot one execution of its own task per round,
/// ``T_total`` the last robot's end), checked by the margin check for every robot's own
/// timeline. The command line's ``tandem fit --task NAME=FILES… --robots NAME=K,…``.
///
/// Args:
///     tasks: a dict ``{name: demos}`` in the cell's order: each task's name (letters,
///         digits, ``_`` and ``-``) and its demonstrations as :func:`fit` takes them (paths
///         or ``(T, C)`` arrays, at least 2).
///     robots: a dict ``{name: K}``, how many robots do each task (default 1 each). The
///         robots are numbered in the order of ``tasks``: task 1's robots first.
///     channels: the arrays' column names: one list for every task, or a dict
///         ``{name: [...]}`` (tasks may have different channels).
///     params: planner parameters (as :func:`fit`'s) for every task.
///     dt_s: the arrays' sample period (s): one for every task or a dict ``{name: dt}``.
///     resample: as :func:`fit`'s, for every task.
///
/// Returns:
///     A :class:`CellPlanner`. With one task it is that task's planner in a cell
///     (``save`` writes the plain state file of :func:`fit`).
///
/// Raises:
///     InputError: a bad demonstration (``what`` names the task and the demonstration).
///     ParamError: an empty ``tasks``, a bad task name, a ``robots``/``channels``/``dt_s``
///         key that names no task, a robot count out of range, a bad parameter.
#[pyfunction]
#[pyo3(signature = (tasks, robots=None, channels=None, params=None, dt_s=None, resample=false))]
pub(crate) fn fit_cell(
    py: Python<'_>,
    tasks: &Bound<'_, PyDict>,
    robots: Option<&Bound<'_, PyAny>>,
    channels: Option<&Bound<'_, PyAny>>,
    params: Option<&Bound<'_, PyAny>>,
    dt_s: Option<&Bound<'_, PyAny>>,
    resample: bool,
) -> PyResult<PyCellPlanner> {
    let params = planner_params(params)?;
    let mut names = Vec::with_capacity(tasks.len());
    for k in tasks.keys() {
        if !k.is_instance_of::<PyString>() {
            return Err(Error::param("tasks", "its keys must be task names (str)").into());
        }
        names.push(k.extract::<String>()?);
    }
    if names.is_empty() {
        return Err(Error::param(
            "tasks",
            "no task: give {name: demos, ...} with at least one task",
        )
        .into());
    }
    let robots = robots.filter(|r| !r.is_none());
    if let Some(r) = robots
        && !r.is_instance_of::<PyDict>()
    {
        return Err(Error::param(
            "robots",
            "give a dict {task: number of robots}, e.g. robots={\"sanding\": 2}",
        )
        .into());
    }
    let mut specs = Vec::with_capacity(names.len());
    for name in &names {
        let demos = tasks
            .get_item(name)?
            .ok_or_else(|| Error::param("tasks", format!("no task {name:?}")))?;
        let ch: Option<Vec<String>> = per_task(channels, name, &names, "channels")?;
        let dt: Option<f64> = per_task(dt_s, name, &names, "dt_s")?;
        let k: Option<usize> = per_task(robots, name, &names, "robots")?;
        let mut task_params: PlannerParams = params.clone();
        let loaded =
            crate::planner::demonstrations(&demos, ch.as_deref(), dt, resample, &mut task_params)
                .map_err(|e| e.in_task(name))?;
        specs.push(TaskSpec {
            name: name.clone(),
            demos: loaded.warned(py)?,
            params: task_params,
            robots: k.unwrap_or(1),
        });
    }
    let inner = py.detach(|| guard(|| Ok(CellPlanner::fit(&specs)?)))?;
    Ok(PyCellPlanner { inner })
}

/// A cell of task models (issue 45): one planner per task (its model, confidence and
/// recorded rounds), each robot's task, and one rounds schedule over all robots. Make one
/// with :func:`fit_cell` or :meth:`CellPlanner.load`; the state file is the command line's
/// (``tandem inspect``/``schedule``/``record`` read it).
#[pyclass(module = "tandem", name = "CellPlanner")]
pub(crate) struct PyCellPlanner {
    inner: CellPlanner,
}

/// The cell's schedule as a dict (global s).
fn schedule_dict<'py>(
    py: Python<'py>,
    cell: &CellPlanner,
    s: Option<&CellSchedule>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let timelines = guard(|| Ok(cell.timelines()?))?;
    d.set_item("t_total_s", cell.t_total_s())?;
    d.set_item(
        "starts_s",
        timelines.iter().map(|t| t.start_s()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "ends_s",
        timelines.iter().map(|t| t.end_s()).collect::<Vec<_>>(),
    )?;
    d.set_item(
        "lc_intervals",
        timelines
            .iter()
            .enumerate()
            .flat_map(|(i, t)| {
                t.lc_intervals()
                    .iter()
                    .map(move |iv| (i, iv.start_s, iv.end_s, iv.ref_start, iv.ref_end))
            })
            .collect::<Vec<_>>(),
    )?;
    if let Some(s) = s {
        d.set_item("lower_bound_s", s.lower_bound_s)?;
        d.set_item("gap_s", s.gap_s())?;
        d.set_item("tick_s", s.tick_s)?;
        d.set_item("margin_checks", s.margin_checks)?;
    }
    Ok(d)
}

#[pymethods]
impl PyCellPlanner {
    /// Loads a cell from a state file written by :meth:`save` or by the command line (a
    /// state file of one task loads as a cell of that task, named ``"task"``).
    ///
    /// A task's stored schedule that fails this build's check is never run: it is replaced
    /// by a fresh schedule, with the ``DataWarning`` :meth:`Planner.load` raises (for a cell
    /// of two or more tasks it names the task).
    ///
    /// Raises:
    ///     StateFileError: the file is missing, not a state file, of another format version,
    ///         truncated or corrupt (``path`` names it).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<PyCellPlanner> {
        let inner = py.detach(|| guard(|| Ok(CellPlanner::load(&path)?)))?;
        warn_load_notices(py, &path, &inner)?;
        Ok(PyCellPlanner { inner })
    }

    /// Saves the cell to ``path`` atomically under the file's lock, waiting up to
    /// ``timeout_s`` seconds (default 60) for another writer; refuses to replace a file that
    /// is not a state file, a file another process saved into since this cell was loaded
    /// from it, or one that holds recorded rounds this cell does not hold.
    ///
    /// Raises:
    ///     StateFileError: the file cannot be written or is refused (``path`` names it).
    #[pyo3(signature = (path, timeout_s=None))]
    fn save(&self, py: Python<'_>, path: PathBuf, timeout_s: Option<f64>) -> PyResult<()> {
        let timeout = lock_timeout(timeout_s)?;
        let inner = &self.inner;
        py.detach(|| {
            guard(|| {
                let lock = StateLock::acquire(&path, timeout)?;
                Ok(inner.save_locked(&lock)?)
            })
        })?;
        Ok(())
    }

    /// The tasks' names, in the cell's order.
    #[getter]
    fn tasks(&self) -> Vec<String> {
        self.inner
            .tasks()
            .iter()
            .map(|t| t.name().to_owned())
            .collect()
    }

    /// Each robot's task (robot 1 first).
    #[getter]
    fn robot_tasks(&self) -> Vec<String> {
        self.inner
            .robot_task()
            .iter()
            .map(|&t| self.inner.tasks()[t].name().to_owned())
            .collect()
    }

    /// The number of robots.
    #[getter]
    fn n_robots(&self) -> usize {
        self.inner.n_robots()
    }

    /// Rounds recorded (one execution of each robot).
    #[getter]
    fn rounds_recorded(&self) -> usize {
        self.inner.rounds_recorded()
    }

    /// The current schedule's ``T_total`` (s): the last robot's planned end.
    #[getter]
    fn t_total_s(&self) -> f64 {
        self.inner.t_total_s()
    }

    /// The current rounds schedule as a dict (global time, s): ``t_total_s``, per robot
    /// ``starts_s`` and ``ends_s``, ``lc_intervals`` (tuples ``(robot, start_s, end_s,
    /// ref_start, ref_end)``: robot 0-based, reference samples of its own task) and, for two
    /// or more tasks, ``lower_bound_s`` (every rounds schedule of these robots and
    /// confidences takes at least this), ``gap_s``, ``tick_s`` and ``margin_checks``.
    #[getter]
    fn schedule<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        schedule_dict(py, &self.inner, self.inner.schedule())
    }

    /// A snapshot of task ``name``'s planner (its model, confidence, rounds; its own
    /// schedule is for its robots alone, not the cell's). Changing it does not change the
    /// cell.
    ///
    /// Raises:
    ///     ParamError: no task of that name.
    fn planner(&self, name: &str) -> PyResult<PyPlanner> {
        match self.inner.task(name) {
            Some(t) => Ok(PyPlanner {
                inner: t.planner().clone(),
            }),
            None => Err(Error::param(
                "name",
                format!("no task {name:?} (the tasks: {})", self.tasks().join(", ")),
            )
            .into()),
        }
    }

    /// Records one round (one execution of each robot, each of its own task) into each
    /// task's model and confidence, then re-schedules the cell; nothing is recorded if any
    /// robot's execution is refused. The arguments are :meth:`Planner.record_round`'s, one
    /// entry per robot (robot 1 first); an array execution's columns are its task's
    /// channels; ``dt_s`` defaults to the cell's control tick.
    ///
    /// Returns:
    ///     A dict: ``tasks`` (per task name, :meth:`Planner.record_round`'s report),
    ///     ``previous_t_total_s`` and ``t_total_s`` (s).
    ///
    /// Raises:
    ///     InputError: a wrong number of entries, a bad execution, log or flags.
    ///     ScheduleError: the round refused by a task's checks (nothing recorded).
    #[pyo3(signature = (executions, ref_time_logs, supervised, corrected, dt_s=None, resample=false))]
    #[expect(
        clippy::too_many_arguments,
        reason = "the Python signature of Planner.record_round"
    )]
    fn record_round<'py>(
        &mut self,
        py: Python<'py>,
        executions: &Bound<'py, PyAny>,
        ref_time_logs: &Bound<'py, PyAny>,
        supervised: &Bound<'py, PyAny>,
        corrected: &Bound<'py, PyAny>,
        dt_s: Option<f64>,
        resample: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        if let Some(dt) = dt_s
            && !(dt.is_finite() && dt > 0.0)
        {
            return Err(Error::param("dt_s", format!("{dt} s is not a finite period > 0")).into());
        }
        let tick_s = match self.inner.schedule() {
            Some(s) => s.tick_s,
            None => self.inner.tasks()[0].planner().schedule().tick_s,
        };
        let dt_s = dt_s.unwrap_or(tick_s);
        let n = self.inner.n_robots();
        let (execs, logs, sups, cors) = (
            per_robot(executions, "executions", n)?,
            per_robot(ref_time_logs, "ref_time_logs", n)?,
            per_robot(supervised, "supervised", n)?,
            per_robot(corrected, "corrected", n)?,
        );
        let records = (0..n)
            .map(|i| {
                let task = &self.inner.tasks()[self.inner.robot_task()[i]];
                let names = Channels {
                    array: Some(task.planner().model().channel_names()),
                    file: None,
                };
                execution_record(
                    py,
                    i,
                    [&execs[i], &logs[i], &sups[i], &cors[i]],
                    names,
                    dt_s,
                    resample,
                )
            })
            .collect::<PyResult<Vec<_>>>()?;
        let inner = &mut self.inner;
        let report = py.detach(|| guard(|| Ok(inner.record_round(&records)?)))?;
        let d = PyDict::new(py);
        let per = PyDict::new(py);
        for (task, r) in self.inner.tasks().iter().zip(&report.tasks) {
            for note in &r.notices {
                crate::errors::warn(py, note)?;
            }
            per.set_item(task.name(), report_dict(py, r)?)?;
        }
        d.set_item("tasks", per)?;
        d.set_item("previous_t_total_s", report.previous_t_total_s)?;
        d.set_item("t_total_s", report.t_total_s)?;
        Ok(d)
    }

    /// The run-time coordinator of the cell's rounds schedule (every robot on its own task's
    /// timeline, the margin check at the schedule's tick): a :class:`Coordinator`, every
    /// robot at its start. A snapshot: it does not follow the cell.
    fn coordinator(&self, py: Python<'_>) -> PyResult<crate::coordinator::PyCoordinator> {
        let inner = &self.inner;
        let c = py.detach(|| guard(|| Ok(inner.coordinator()?)))?;
        Ok(crate::coordinator::PyCoordinator::from_inner(c))
    }

    fn __repr__(&self) -> String {
        let tasks: Vec<String> = self
            .inner
            .tasks()
            .iter()
            .enumerate()
            .map(|(t, task)| {
                let k = self.inner.robot_task().iter().filter(|&&x| x == t).count();
                format!("{}×{k}", task.name())
            })
            .collect();
        format!(
            "CellPlanner(tasks=[{}], robots={}, rounds={}, T_total={:.2} s)",
            tasks.join(", "),
            self.inner.n_robots(),
            self.inner.rounds_recorded(),
            self.inner.t_total_s()
        )
    }
}

/// Warns (``DataWarning``) for each task whose stored schedule loading replaced because it
/// failed this build's check (`Planner::load_notice`): for a one-task cell the very warning
/// of `Planner.load`, for two or more tasks with the task's name.
fn warn_load_notices(py: Python<'_>, path: &std::path::Path, cell: &CellPlanner) -> PyResult<()> {
    let one = cell.tasks().len() == 1;
    for task in cell.tasks() {
        if let Some(notice) = task.planner().load_notice() {
            let text = if one {
                format!("{}: {notice}", path.display())
            } else {
                format!("{}: task `{}`: {notice}", path.display(), task.name())
            };
            crate::errors::warn(py, &text)?;
        }
    }
    Ok(())
}
