//! `tandem.ContinuousCoordinator` and `tandem.CellTick`: the Rust run-time coordinator of a
//! continuous cell (issue 21; `tandem_realtime::continuous`, the token rule), made by
//! `CyclicPlan.coordinator` (Rust `CyclicPlan::coordinator`) or
//! `Planner.continuous_coordinator`, one control tick per call.

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::arrays::{out_flags, out_vector, repr_list};
use crate::coordinator::{fault_dict, operator_list, pre_alert_dict, tick_with};
use crate::errors::{Result, guard};
use crate::facade::{ContinuousCoordinator, CyclicPlan, Group, Problem, Tick, Token};

/// The continuous coordinator of `plan` on `problem` at `tick_s` (default: the problem's
/// `dt_s`), through [`CyclicPlan::coordinator`].
pub(crate) fn make(
    plan: &CyclicPlan,
    problem: &Problem,
    tick_s: Option<f64>,
) -> Result<PyContinuousCoordinator> {
    let tick_s = tick_s.unwrap_or(problem.dt_s());
    let inner = guard(|| Ok(plan.coordinator(problem, tick_s)?))?;
    Ok(PyContinuousCoordinator { inner })
}

/// A token as the tuple ``(robot, group)``.
fn token_tuple(t: Token) -> (usize, usize) {
    (t.robot, t.group)
}

/// A group as the dict :attr:`ContinuousCoordinator.groups` lists.
fn group_dict<'py>(py: Python<'py>, g: &Group) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("gate", g.gate)?;
    d.set_item("first_lc", g.first_lc)?;
    d.set_item("end_lc", g.end_lc)?;
    d.set_item("ref_start", g.ref_start)?;
    d.set_item("ref_end", g.ref_end)?;
    Ok(d)
}

/// Task counts as an int64 array (a count never reaches `i64::MAX`).
fn out_counts<'py>(py: Python<'py>, counts: &[u64]) -> Bound<'py, PyArray1<i64>> {
    PyArray1::from_vec(
        py,
        counts
            .iter()
            .map(|&k| i64::try_from(k).unwrap_or(i64::MAX))
            .collect(),
    )
}

/// The run-time coordinator of a continuous cell: ``N`` robots each repeating the task for
/// ever, one operator taking their low-confidence stretches in the cyclic plan's order, no
/// rounds. One control tick of :attr:`tick_s` real seconds per :meth:`tick`.
///
/// Every robot runs the task on the problem's fastest warp (``ψ̇min`` on high-confidence
/// samples; the operator's rate, ``ψ̇̄`` when scheduled, on low-confidence ones). The
/// stretches between two usable hold points form a *group*, entered at its *gate* (the last
/// usable hold before it, or the task start); the operator's order becomes a cyclic sequence
/// of *tokens* ``(robot, group)``. A robot waits at the gate of its next group until the token
/// is its own, and the token moves on once its robot has left the group. So two robots are
/// never low-confidence in the same tick, for any operator input and any number of tasks
/// (the token rule of ``tandem_realtime::continuous``); the robots never rely on a margin,
/// they wait.
///
/// It wraps the Rust ``tandem_realtime::continuous::ContinuousCoordinator`` (no
/// re-implementation): a tick is O(N) and allocates nothing on the Rust side. Make one with
/// :meth:`CyclicPlan.coordinator` or :meth:`Planner.continuous_coordinator`.
#[pyclass(module = "tandem", name = "ContinuousCoordinator")]
pub(crate) struct PyContinuousCoordinator {
    pub(crate) inner: ContinuousCoordinator,
}

impl PyContinuousCoordinator {
    /// The Python object of a Rust continuous coordinator (`Planner.controller`,
    /// `Planner.continuous_coordinator`).
    pub(crate) fn from_inner(inner: ContinuousCoordinator) -> Self {
        Self { inner }
    }
}

#[pymethods]
impl PyContinuousCoordinator {
    /// Advances one control tick.
    ///
    /// Args:
    ///     operator: the operator's input for the robot on a low-confidence sample (the
    ///         token's robot; ignored when none is): ``None`` (its scheduled gradient
    ///         ``ψ̇̄``), a gradient ``g > 0`` (execution samples per reference sample, e.g.
    ///         the rate component of :meth:`Planner.command`; clamped to
    ///         ``[ψ̇min, ψ̇max]``), ``"fastest"`` (``ψ̇min``) or ``"slowest"`` (``ψ̇max``).
    ///         With :attr:`operators` ``M > 1`` (issue 44: ``M`` tokens) a list of ``M`` such
    ///         inputs, input ``o`` for the robot of operator ``o`` (:attr:`CellTick.operator`).
    ///
    /// Returns:
    ///     CellTick: each robot's reference time and completed tasks at the end of the tick,
    ///     who was low-confidence (and under which operator), who ran, who waits at a gate.
    ///
    /// Raises:
    ///     InputError: a gradient that is NaN, infinite or ≤ 0 (the coordinator is then
    ///         unchanged), or another kind of input; a single input or a list of a length
    ///         other than ``M`` to a coordinator of ``M`` operators.
    #[pyo3(signature = (operator=None))]
    fn tick(&mut self, operator: Option<&Bound<'_, PyAny>>) -> PyResult<PyCellTick> {
        let tick = tick_with(&mut self.inner, operator)?;
        Ok(PyCellTick { inner: tick })
    }

    /// The number of operators ``M`` (tokens) this coordinator takes inputs from
    /// (``params()["sampler"]["operators"]`` of the planner that made it; issue 44).
    #[getter]
    fn operators(&self) -> usize {
        self.inner.operators()
    }

    /// Puts every robot back at sample 0 of its first task, the token at its first entry;
    /// clears the task counts, the tick count and a latched fault.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// The latched fault of the run-time monitor, or ``None``: a dict ``{"tick": int,
    /// "low_conf": (N,) bool, "stopped": int}`` if a tick ever had two robots
    /// low-confidence (the token rule excludes it: a bug, never expected). Robot ``stopped``
    /// is then held where it is until :meth:`clear_fault`.
    #[getter]
    fn fault<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.inner.fault().map(|f| fault_dict(py, &f)).transpose()
    }

    /// Releases the robot the fault monitor holds; the fault is no longer reported.
    fn clear_fault(&mut self) {
        self.inner.clear_fault();
    }

    /// Number of robots ``N``.
    #[getter]
    fn n_robots(&self) -> usize {
        self.inner.n_robots()
    }

    /// Control tick (real s) per :meth:`tick`.
    #[getter]
    fn tick_s(&self) -> f64 {
        self.inner.tick_s()
    }

    /// Ticks run since the start or the last :meth:`reset`.
    #[getter]
    fn ticks(&self) -> u64 {
        self.inner.ticks()
    }

    /// Duration (s of schedule clock) of one task on the fastest warp, with the
    /// low-confidence samples at ``ψ̇̄`` and no wait.
    #[getter]
    fn task_s(&self) -> f64 {
        self.inner.task().end_s()
    }

    /// Each robot's number of completed tasks, ``(N,)`` int64.
    #[getter]
    fn tasks_completed<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        out_counts(py, self.inner.tasks_completed())
    }

    /// Each robot's schedule clock in its current task, ``(N,)``, s from the task's start.
    #[getter]
    fn clock_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.clock_s().to_vec())
    }

    /// Each robot's fractional reference time in its current task now, ``(N,)``, reference
    /// samples in ``[0, T_ref)``: where to read its command (:meth:`Planner.command`).
    #[getter]
    fn ref_time_now<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let task = self.inner.task();
        let now = self.inner.clock_s().iter().map(|&s| task.ref_time_at(s));
        out_vector(py, now.collect())
    }

    /// Each robot's reference sample now (the sample its clock is in), a list of ``N`` ints.
    #[getter]
    fn sample_now(&self) -> Vec<usize> {
        let task = self.inner.task();
        self.inner
            .clock_s()
            .iter()
            .map(|&s| task.sample_at(s))
            .collect()
    }

    /// Whether each robot is on a low-confidence sample and holds the token now, ``(N,)``
    /// bool: the robot the next tick moves at the operator's rate (at most one).
    #[getter]
    fn low_conf_now<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        out_flags(py, self.inner.low_conf_now().iter().collect())
    }

    /// The current token ``(robot, group)``: the one robot that may go through a group now
    /// (its next group), or ``None`` for a task without low confidence.
    #[getter]
    fn token(&self) -> Option<(usize, usize)> {
        self.inner.token().map(token_tuple)
    }

    /// ``(index, passes)``: the current token's index in :attr:`tokens` and the number of
    /// completed passes through the sequence.
    #[getter]
    fn token_position(&self) -> (usize, u64) {
        self.inner.token_position()
    }

    /// The cyclic token sequence: a list of ``(robot, group)`` tuples, the plan's operator
    /// order cut into groups (empty for a task without low confidence).
    #[getter]
    fn tokens(&self) -> Vec<(usize, usize)> {
        self.inner
            .tokens()
            .iter()
            .copied()
            .map(token_tuple)
            .collect()
    }

    /// The task's groups in reference order, a list of dicts: ``gate`` (the reference
    /// sample at whose start a robot waits for the group's token), ``first_lc`` and
    /// ``end_lc`` (its stretches are ``first_lc…end_lc − 1``, 0-based), ``ref_start`` (the
    /// first sample of its first stretch) and ``ref_end`` (one past its last low-confidence
    /// sample).
    #[getter]
    fn groups<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let dicts = self
            .inner
            .groups()
            .iter()
            .map(|g| group_dict(py, g))
            .collect::<PyResult<Vec<_>>>()?;
        PyList::new(py, dicts)
    }

    fn __repr__(&self) -> String {
        format!(
            "ContinuousCoordinator(n_robots={}, tick_s={:?}, ticks={}, tasks_completed={}, \
             token={})",
            self.inner.n_robots(),
            self.inner.tick_s(),
            self.inner.ticks(),
            repr_counts(self.inner.tasks_completed()),
            self.inner.token().map_or_else(
                || "None".to_owned(),
                |t| format!("({}, {})", t.robot, t.group)
            )
        )
    }
}

/// Counts as Python writes a list of ints: `[3, 4]`.
fn repr_counts(counts: &[u64]) -> String {
    let items: Vec<String> = counts.iter().map(u64::to_string).collect();
    format!("[{}]", items.join(", "))
}

/// What one :meth:`ContinuousCoordinator.tick` did, per robot.
#[pyclass(module = "tandem", name = "CellTick", frozen)]
pub(crate) struct PyCellTick {
    pub(crate) inner: Tick,
}

#[pymethods]
impl PyCellTick {
    /// The pre-alert (issue 41): ``{"robot": r, "earliest_s": e, "latest_s": l}`` for the
    /// robot (0-based) whose next low-confidence stretch can start soonest, ``e`` and ``l`` the
    /// least and most real seconds from the end of this tick until it starts, worst case over
    /// admissible operators (``l`` is ``inf`` when the start waits on another robot: a hold's
    /// release, a leg's start, the token); ``None`` when no robot has a stretch ahead.
    #[getter]
    fn next<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.inner.next.map(|a| pre_alert_dict(py, &a)).transpose()
    }

    /// Each robot's fractional reference time in its current task at the end of the tick,
    /// ``(N,)``, reference samples in ``[0, T_ref)`` (a robot that finished a task in this
    /// tick is at 0 of the next).
    #[getter]
    fn ref_time<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.ref_time.to_vec())
    }

    /// Each robot's number of completed tasks at the end of the tick, ``(N,)`` int64.
    #[getter]
    fn tasks<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        out_counts(py, &self.inner.tasks)
    }

    /// Whether each robot traversed any low-confidence reference sample during the tick,
    /// ``(N,)`` bool (conservative, as the rounds :class:`Tick` counts).
    #[getter]
    fn low_conf<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        out_flags(py, self.inner.low_conf.iter().collect())
    }

    /// Whether each robot's schedule clock moved during the tick, ``(N,)`` bool.
    #[getter]
    fn running<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        out_flags(py, self.inner.running.iter().collect())
    }

    /// Each robot's operator in this tick (issue 44): ``o`` (0-based) for a low-confidence
    /// robot, the operator whose token it holds; ``None`` for the others.
    #[getter]
    fn operator(&self) -> Vec<Option<u8>> {
        operator_list(&self.inner)
    }

    /// Whether each robot waits at the gate of its next group at the end of the tick (the
    /// token is another robot's), ``(N,)`` bool.
    #[getter]
    fn at_gate<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        out_flags(py, self.inner.waiting.iter().collect())
    }

    /// Whether more than one robot was low-confidence in this tick (never, under the token
    /// rule).
    #[getter]
    fn overlap(&self) -> bool {
        self.inner.overlap()
    }

    /// The coordinator's latched fault after this tick (see
    /// :attr:`ContinuousCoordinator.fault`), or ``None``.
    #[getter]
    fn fault<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.inner.fault.map(|f| fault_dict(py, &f)).transpose()
    }

    fn __repr__(&self) -> String {
        format!(
            "CellTick(ref_time={}, tasks={}, low_conf={}, running={}, at_gate={})",
            repr_list(&self.inner.ref_time),
            repr_counts(&self.inner.tasks),
            repr_list(&self.inner.low_conf.iter().collect::<Vec<_>>()),
            repr_list(&self.inner.running.iter().collect::<Vec<_>>()),
            repr_list(&self.inner.waiting.iter().collect::<Vec<_>>())
        )
    }
}
