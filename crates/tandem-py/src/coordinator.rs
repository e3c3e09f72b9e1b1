//! `tandem.Coordinator` and `tandem.Tick`: the Rust runtime coordinator (§II-B5, Eq. 15–18,
//! Alg. 1), the same object the safety property tests run, one control tick per call.

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};

use crate::arrays::{PyBool, out_flags, out_vector, repr_list};
use crate::errors::{Error, Result, guard};
use crate::facade::{Coordinator, Fault, Operator, Tick, Timeline};
use crate::schedule::PySchedule;

/// The operator's input from Python: `None`/`"scheduled"`, a gradient, `"fastest"` or
/// `"slowest"`.
pub(crate) fn operator(x: Option<&Bound<'_, PyAny>>) -> Result<Operator> {
    let Some(x) = x.filter(|x| !x.is_none()) else {
        return Ok(Operator::Scheduled);
    };
    if let Ok(s) = x.cast::<PyString>() {
        return match s.to_cow().unwrap_or_default().as_ref() {
            "scheduled" => Ok(Operator::Scheduled),
            "fastest" => Ok(Operator::Fastest),
            "slowest" => Ok(Operator::Slowest),
            other => Err(Error::input(
                "operator",
                format!(
                    "'{other}': expected None, a gradient, 'fastest', 'slowest' or 'scheduled'"
                ),
            )),
        };
    }
    let g: f64 = x.extract().map_err(|_| {
        Error::input(
            "operator",
            "expected None, a gradient (float), 'fastest', 'slowest' or 'scheduled'",
        )
    })?;
    Operator::Gradient(g).validate().map_err(|_| {
        Error::input(
            "operator",
            format!("gradient {g} must be finite and > 0 (None means no correction)"),
        )
    })
}

/// The operators' inputs from Python (issue 44): a list or tuple of `M` inputs, input `o`
/// for operator `o`'s robot, each as [`operator`] takes it; `None` for anything else (one
/// operator's single input).
pub(crate) fn operator_inputs(x: Option<&Bound<'_, PyAny>>) -> Result<Option<Vec<Operator>>> {
    let Some(x) = x else {
        return Ok(None);
    };
    let items: Vec<Bound<'_, PyAny>> = if let Ok(l) = x.cast::<PyList>() {
        l.iter().collect()
    } else if let Ok(t) = x.cast::<PyTuple>() {
        t.iter().collect()
    } else {
        return Ok(None);
    };
    items
        .iter()
        .map(|i| operator(Some(i)))
        .collect::<Result<Vec<_>>>()
        .map(Some)
}

/// One tick of `c` with the input(s) `x`: a single input ([`operator`]) through
/// `Controller::tick`, a list of one per operator ([`operator_inputs`]) through
/// `Controller::tick_many` (a count other than the controller's `M` is refused by the
/// realtime crate, the controller unchanged).
pub(crate) fn tick_with(
    c: &mut impl crate::facade::Controller,
    x: Option<&Bound<'_, PyAny>>,
) -> PyResult<Tick> {
    match operator_inputs(x)? {
        Some(inputs) => Ok(guard(|| Ok(c.tick_many(&inputs)?))?),
        None => {
            let op = operator(x)?;
            Ok(guard(|| Ok(c.tick(op)?))?)
        }
    }
}

/// Each robot's operator in `tick` (issue 44), `None` for a robot not low-confidence.
pub(crate) fn operator_list(tick: &Tick) -> Vec<Option<u8>> {
    tick.operator.to_vec()
}

/// The runtime coordinator of a schedule (§II-B5): advances every robot's schedule clock by
/// one control tick of ``schedule.tick_s`` real seconds per :meth:`tick`, the
/// low-confidence robot at the operator's rate, the others responding (Eq. 18, Alg. 1) so
/// that no two robots are ever low-confidence in the same tick — the guarantee of the
/// margin check that accepted the schedule, at that tick.
///
/// It wraps the Rust ``tandem_realtime::Coordinator`` (no re-implementation): a tick is
/// O(1) and allocates nothing on the Rust side.
#[pyclass(module = "tandem", name = "Coordinator")]
pub(crate) struct PyCoordinator {
    pub(crate) inner: Coordinator,
}

impl PyCoordinator {
    /// The Python object of a Rust coordinator (`Planner.controller`).
    pub(crate) fn from_inner(inner: Coordinator) -> Self {
        Self { inner }
    }

    /// `f(timeline, schedule clock)` for every robot.
    fn per_robot<T>(&self, f: impl Fn(&Timeline, f64) -> T) -> Vec<T> {
        let clock = self.inner.clock_s();
        self.inner
            .robots()
            .iter()
            .zip(clock)
            .map(|(r, &s)| f(r, s))
            .collect()
    }
}

#[pymethods]
impl PyCoordinator {
    /// The coordinator of ``schedule`` on its problem, at its tick, both clocks at the
    /// earliest start, with the operator's switch time the schedule was planned for (a
    /// planner's ``schedule`` carries its ``switch_s``: a robot leaves a hold with release
    /// rules no sooner than that after the robots it waits for left their stretches, as in
    /// :meth:`Planner.controller`; 0 for a schedule of your own).
    ///
    /// Raises:
    /// ``schedule`` must be checked by this build: one the scheduler or a planner made, or
    /// one of your own that passed :meth:`Schedule.validate` (the margin check of Alg. 2 at
    /// its tick is what makes a run safe).
    ///
    /// Args:
    ///     schedule: the schedule to run.
    ///     max_busy_share: the operator's load cap ``u`` in ``(0, 1]`` kept at run time
    ///         (issue 41; default 1: no cap). The coordinator counts the round's busy ticks
    ///         ``B`` (ticks with a low-confidence robot, plus the switch time's ticks per change
    ///         of robot) and, once the round has ended, :attr:`rest_ticks` / :attr:`rest_s` is
    ///         the rest before the next round that keeps ``B ≤ u·(ticks + rest)``
    ///         (``tandem_realtime::Coordinator::with_max_busy_share``). Nothing inside the
    ///         round changes. :meth:`Planner.controller` sets the planner's
    ///         ``params["sampler"]["max_busy_share"]`` (stored in the state file).
    ///
    /// Raises:
    ///     ScheduleError: a schedule of your own not yet validated (``violation`` is
    ///         ``"Unchecked"``), or one that fails the check (``violation`` names the rule).
    ///     ParamError: ``max_busy_share`` not in ``(0, 1]`` (``name`` is
    ///         ``"max_busy_share"``; the text is the Rust error's).
    #[new]
    #[pyo3(signature = (schedule, max_busy_share=1.0))]
    fn py_new(schedule: PyRef<'_, PySchedule>, max_busy_share: f64) -> PyResult<Self> {
        let inner = guard(|| {
            let c = schedule
                .checked()?
                .coordinator()?
                .with_switch_s(schedule.planned_switch_s())?;
            Ok(c.with_max_busy_share(max_busy_share)?)
        })?;
        Ok(Self { inner })
    }

    /// The operator's load cap ``u`` this coordinator keeps at run time (``max_busy_share=``
    /// of the constructor, or the planner's for :meth:`Planner.controller`; 1: none).
    #[getter]
    fn max_busy_share(&self) -> f64 {
        self.inner.max_busy_share()
    }

    /// ``k``: the operator's switch time in whole ticks (0 for ``Coordinator(schedule)``; the
    /// planner's ``switch_s`` for :meth:`Planner.controller`), counted once per change of
    /// robot in :meth:`busy_ticks`.
    #[getter]
    fn switch_ticks(&self) -> u64 {
        self.inner.switch_ticks()
    }

    /// ``B``: the busy ticks of ``operator`` (0-based, ``< M``) in the round so far — its
    /// ticks with a low-confidence robot plus :attr:`switch_ticks` per change of robot (the
    /// round's first stretch is no change) — or ``None`` without a load cap or for an
    /// operator ``≥ M``.
    #[pyo3(signature = (operator=0))]
    fn busy_ticks(&self, operator: usize) -> Option<u64> {
        self.inner.busy_ticks(operator)
    }

    /// The rest (ticks) before the next round, under the load cap ``u``: the least whole
    /// ``n`` with ``B ≤ u·n`` for every operator, less the round's ticks, 0 when the round
    /// alone keeps the cap (always 0 at ``u = 1``). Read it once :attr:`is_finished`, before
    /// :meth:`reset` (which starts a new count): the share of the round and its rest is then
    /// at most ``u`` whatever the operator did.
    #[getter]
    fn rest_ticks(&self) -> u64 {
        self.inner.rest_ticks()
    }

    /// :attr:`rest_ticks` in seconds (ticks × :attr:`tick_s`): how long the operator rests
    /// before the next round starts.
    #[getter]
    fn rest_s(&self) -> f64 {
        self.inner.rest_s()
    }

    /// Advances one control tick.
    ///
    /// Args:
    ///     operator: the operator's input for the low-confidence robot (ignored when no
    ///         robot is low-confidence): ``None`` (no correction: its scheduled gradient),
    ///         a gradient ``g > 0`` (execution samples per reference sample, e.g. the rate
    ///         component of :meth:`Planner.command`; clamped to ``[ψ̇min, ψ̇max]``),
    ///         ``"fastest"`` (``ψ̇min``) or ``"slowest"`` (``ψ̇max``). With
    ///         :attr:`operators` ``M > 1`` (issue 44) a list of ``M`` such inputs, input ``o``
    ///         for the robot of operator ``o`` (:attr:`Tick.operator`).
    ///
    /// Returns:
    ///     Tick: each robot's reference time at the end of the tick, who was
    ///     low-confidence during it (and under which operator), who was running.
    ///
    /// Raises:
    ///     InputError: a gradient that is NaN, infinite or ≤ 0 (the coordinator is then
    ///         unchanged), or another kind of input; a single input or a list of a length
    ///         other than ``M`` to a coordinator of ``M`` operators.
    #[pyo3(signature = (operator=None))]
    fn tick(&mut self, operator: Option<&Bound<'_, PyAny>>) -> PyResult<PyTick> {
        let tick = tick_with(&mut self.inner, operator)?;
        Ok(PyTick { inner: tick })
    }

    /// The number of operators ``M`` this coordinator takes inputs from (1, or the
    /// sectors of :meth:`Planner.controller` with ``params()["sampler"]["operators"] > 1``;
    /// issue 44).
    #[getter]
    fn operators(&self) -> usize {
        self.inner.operators()
    }

    /// Puts every clock back at the earliest start (to run the same plan again); clears a
    /// latched fault.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// The latched fault of the run-time monitor, or ``None``: a dict ``{"tick": int,
    /// "low_conf": (N,) bool, "stopped": int}`` if a tick ever had two robots
    /// low-confidence (a state the margin check excludes, so a bug, never expected). The
    /// coordinator then fails safe: robot ``stopped`` (the one whose low-confidence stretch
    /// began last) is held where it is until :meth:`clear_fault`, and
    /// :attr:`is_finished` stays false while it is held.
    #[getter]
    fn fault<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.inner.fault().map(|f| fault_dict(py, &f)).transpose()
    }

    /// Releases the robot the fault monitor holds (once the operator has dealt with the
    /// other one); the fault is no longer reported.
    fn clear_fault(&mut self) {
        self.inner.clear_fault();
    }

    /// Whether every robot has finished.
    #[getter]
    fn is_finished(&self) -> bool {
        self.inner.is_finished()
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

    /// Each robot's schedule clock ``s_i``, ``(N,)``, s of global time.
    #[getter]
    fn clock_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.clock_s().to_vec())
    }

    /// Scheduled start of every robot, ``(N,)``, s of global time.
    #[getter]
    fn starts_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.per_robot(|r, _| r.start_s()))
    }

    /// Planned end of every robot, ``(N,)``, s of global time: its start, its execution and
    /// the planned dwells at its holds (the Rust coordinator's ``planned_end_s``; the same as
    /// ``Schedule.ends_s``). Without holds, the end of its timeline.
    #[getter]
    fn ends_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let n = self.inner.n_robots();
        out_vector(py, (0..n).map(|i| self.inner.planned_end_s(i)).collect())
    }

    /// Whether each robot is running now (its clock in ``[start, end)`` of its current leg,
    /// not at a hold, not held by the fault monitor), ``(N,)`` bool: the robots that execute
    /// a sample in the next tick.
    #[getter]
    fn running_now<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        out_flags(py, self.inner.running_now().iter().collect())
    }

    /// Whether each robot is running and low-confidence now (Eq. 16 at the tick start),
    /// ``(N,)`` bool: the robot the next tick moves at the operator's rate.
    #[getter]
    fn low_conf_now<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        out_flags(py, self.inner.low_conf_now().iter().collect())
    }

    /// Each robot's fractional reference time now (Eq. 15 at its clock, on its current leg
    /// with holds), ``(N,)``, reference samples in ``[0, T_ref]``, never decreasing: where to
    /// read its command (:meth:`Planner.command`).
    #[getter]
    fn ref_time_now<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.ref_time_now().to_vec())
    }

    /// Each robot's reference sample now (the sample its clock is in), a list of ``N`` ints.
    #[getter]
    fn sample_now(&self) -> Vec<usize> {
        self.inner.sample_now().to_vec()
    }

    fn __repr__(&self) -> String {
        format!(
            "Coordinator(n_robots={}, tick_s={}, clock_s={}, is_finished={})",
            self.inner.n_robots(),
            self.inner.tick_s(),
            repr_list(self.inner.clock_s()),
            PyBool(self.inner.is_finished())
        )
    }
}

/// The pre-alert of a tick as Python sees it (``Tick.next``, ``CellTick.next``):
/// ``{"robot": r, "earliest_s": e, "latest_s": l}``.
pub(crate) fn pre_alert_dict<'py>(
    py: Python<'py>,
    a: &tandem::realtime::PreAlert,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("robot", a.robot)?;
    d.set_item("earliest_s", a.earliest_s)?;
    d.set_item("latest_s", a.latest_s)?;
    Ok(d)
}

/// A fault as the dict :attr:`Coordinator.fault` returns.
pub(crate) fn fault_dict<'py>(py: Python<'py>, f: &Fault) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("tick", f.tick)?;
    d.set_item("low_conf", out_flags(py, f.low_conf.iter().collect()))?;
    d.set_item("stopped", f.stopped)?;
    Ok(d)
}

/// What one :meth:`Coordinator.tick` did, per robot.
#[pyclass(module = "tandem", name = "Tick", frozen)]
pub(crate) struct PyTick {
    pub(crate) inner: Tick,
}

#[pymethods]
impl PyTick {
    /// The pre-alert (issue 41): ``{"robot": r, "earliest_s": e, "latest_s": l}`` for the
    /// robot (0-based) whose next low-confidence stretch can start soonest, ``e`` and ``l`` the
    /// least and most real seconds from the end of this tick until it starts, worst case over
    /// admissible operators (``l`` is ``inf`` when the start waits on another robot: a hold's
    /// release, a leg's start, the token); ``None`` when no robot has a stretch ahead.
    #[getter]
    fn next<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.inner.next.map(|a| pre_alert_dict(py, &a)).transpose()
    }

    /// Each robot's fractional reference time at the end of the tick, ``(N,)``, reference
    /// samples in ``[0, T_ref]`` (Eq. 15 at its schedule clock).
    #[getter]
    fn ref_time<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.ref_time.to_vec())
    }

    /// Whether each robot traversed any low-confidence reference sample during the tick,
    /// ``(N,)`` bool (conservative: a tolerance only adds reports).
    #[getter]
    fn low_conf<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        out_flags(py, self.inner.low_conf.iter().collect())
    }

    /// Whether each robot ran during the tick, ``(N,)`` bool.
    #[getter]
    fn running<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        out_flags(py, self.inner.running.iter().collect())
    }

    /// Whether more than one robot was low-confidence in this tick (never, for a schedule
    /// that passed the margin check).
    #[getter]
    fn overlap(&self) -> bool {
        self.inner.overlap()
    }

    /// Each robot's operator in this tick (issue 44): ``o`` (0-based) for a low-confidence
    /// robot, the operator whose input moved it; ``None`` for the others. With one operator
    /// every low-confidence robot's is 0.
    #[getter]
    fn operator(&self) -> Vec<Option<u8>> {
        operator_list(&self.inner)
    }

    /// The coordinator's latched fault after this tick (see :attr:`Coordinator.fault`), or
    /// ``None``.
    #[getter]
    fn fault<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        self.inner.fault.map(|f| fault_dict(py, &f)).transpose()
    }

    fn __repr__(&self) -> String {
        format!(
            "Tick(ref_time={}, low_conf={}, running={})",
            repr_list(&self.inner.ref_time),
            repr_list(&self.inner.low_conf.iter().collect::<Vec<_>>()),
            repr_list(&self.inner.running.iter().collect::<Vec<_>>())
        )
    }
}
