//! `tandem.CyclicPlan` and `tandem.cyclic_plan`: the plan of a continuous cell (issue 21;
//! Rust `tandem::schedule::cyclic`), also `Planner.cyclic_plan`.

use numpy::ndarray::Array2;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;

use crate::arrays::out_vector;
use crate::continuous::{self, PyContinuousCoordinator};
use crate::errors::{Error, Result, guard};
use crate::facade::{
    CheckedCyclicPlan, CyclicParams, CyclicPlan, GapPlan, Problem, Stretch, cyclic_plan as plan_of,
    cyclic_plan_for_order,
};
use crate::planner::N_ROBOTS;
use crate::schedule::PyProblem;

/// The search's parameters from Python: the defaults, with `max_enumerated`,
/// `runnable_only` and `handover_tick_s` as [`compute`] takes them.
pub(crate) fn params(
    max_enumerated: Option<u64>,
    runnable_only: bool,
    handover_tick_s: Option<f64>,
) -> CyclicParams {
    let mut params = CyclicParams {
        runnable_only,
        handover_tick_s,
        ..CyclicParams::default()
    };
    if let Some(k) = max_enumerated {
        params.max_enumerated = k;
    }
    params
}

/// The cyclic plan of `n_robots` robots on `problem` ([`plan_of`]), with `max_enumerated`
/// replacing [`CyclicParams::max_enumerated`] when given, `runnable_only`
/// [`CyclicParams::runnable_only`] and `handover_tick_s` (the tick of the cell that will run
/// it, when known) [`CyclicParams::handover_tick_s`], the GIL released.
pub(crate) fn compute(
    py: Python<'_>,
    problem: &Problem,
    n_robots: usize,
    max_enumerated: Option<u64>,
    runnable_only: bool,
    handover_tick_s: Option<f64>,
) -> PyResult<PyCyclicPlan> {
    let params = params(max_enumerated, runnable_only, handover_tick_s);
    let plan = py.detach(|| guard(|| Ok(plan_of(problem, n_robots, &params)?)))?;
    Ok(PyCyclicPlan { plan, tick_s: None })
}

/// The plan of a continuous cell (no rounds): ``N`` robots repeating the task with one
/// operator, one task per robot every period. Read-only; times in seconds of the schedule
/// clock, measured from the start of period 0; robots and stretches 0-based.
///
/// It assumes that the operator supervises every low-confidence stretch at the demonstrated
/// mean speed ``ψ̇̄`` and that the robots run at their planned rates: a plan, not yet checked
/// against correction drift across cycle boundaries (rounds remain what the planner records
/// and the :class:`Coordinator` runs). Make one with :meth:`Planner.cyclic_plan` or
/// :func:`cyclic_plan`.
#[pyclass(module = "tandem", name = "CyclicPlan", frozen)]
pub(crate) struct PyCyclicPlan {
    plan: CyclicPlan,
    /// The cell's tick it was checked at (a planner's plan), `None` for one of
    /// [`cyclic_plan`].
    tick_s: Option<f64>,
}

impl PyCyclicPlan {
    /// A plan the planner checked at its cell's tick (`Planner::cyclic_plan`).
    pub(crate) fn checked(checked: CheckedCyclicPlan) -> Self {
        let tick_s = Some(checked.tick_s());
        PyCyclicPlan {
            plan: checked.into_plan(),
            tick_s,
        }
    }

    /// Per robot, one value per gap of its task (head, between stretches, tail): an
    /// ``(N, m + 1)`` array.
    fn per_gap<'py>(
        &self,
        py: Python<'py>,
        value: impl Fn(&GapPlan) -> f64,
    ) -> Result<Bound<'py, PyArray2<f64>>> {
        let cols = self.plan.robots.first().map_or(0, |r| r.gaps.len());
        let values: Vec<f64> = self
            .plan
            .robots
            .iter()
            .flat_map(|r| r.gaps.iter().map(&value))
            .collect();
        matrix_out(py, values, self.plan.robots.len(), cols)
    }
}

/// A `rows × cols` array from row-major `values`, also with zero columns (a task without
/// low-confidence stretches).
fn matrix_out(
    py: Python<'_>,
    values: Vec<f64>,
    rows: usize,
    cols: usize,
) -> Result<Bound<'_, PyArray2<f64>>> {
    let a = Array2::from_shape_vec((rows, cols), values)
        .map_err(|e| Error::Panic(format!("cyclic plan array {rows} × {cols}: {e}")))?;
    Ok(PyArray2::from_owned_array(py, a))
}

#[pymethods]
impl PyCyclicPlan {
    /// Number of robots ``N``.
    #[getter]
    fn n_robots(&self) -> usize {
        self.plan.n_robots
    }

    /// The period ``P`` (s): every period each robot does one task and the operator
    /// supervises each of the ``N·m`` low-confidence stretches once. The least period of
    /// :attr:`order` (exact).
    #[getter]
    fn period_s(&self) -> f64 {
        self.plan.period_s
    }

    /// Throughput (tasks per hour): ``3600·N / P``.
    #[getter]
    fn tasks_per_hour(&self) -> f64 {
        self.plan.tasks_per_hour
    }

    /// The operator's busy share ``N·L / P`` in ``[0, 1]`` (``L``: a task's low-confidence
    /// time at ``ψ̇̄``, s).
    #[getter]
    fn operator_share(&self) -> f64 {
        self.plan.operator_share
    }

    /// A lower bound (s) on the period of every repeated plan of ``N`` robots, whatever the
    /// operator's order: ``max(N·(L + I), D_min)`` (the operator's load and forced idle time,
    /// a robot's fastest task).
    #[getter]
    fn lower_bound_s(&self) -> f64 {
        self.plan.lower_bound_s
    }

    /// ``period_s / lower_bound_s − 1`` (dimensionless; 0 when the plan is at its bound).
    #[getter]
    fn gap(&self) -> f64 {
        self.plan.gap
    }

    /// Whether every operator order was searched, so that no repeated plan with one task per
    /// robot per period has a shorter period; ``False`` after the local search (too many
    /// orders to enumerate).
    #[getter]
    fn order_exhaustive(&self) -> bool {
        self.plan.order_exhaustive
    }

    /// Operator orders whose period was computed to choose this one.
    #[getter]
    fn orders_evaluated(&self) -> usize {
        self.plan.orders_evaluated
    }

    /// The operator's cyclic order within one period: a list of ``N·m`` pairs
    /// ``(robot, stretch)``, both 0-based (``stretch``: the robot's ``k``-th low-confidence
    /// stretch in task order); empty for a task without low confidence.
    #[getter]
    fn order(&self) -> Vec<(usize, usize)> {
        self.plan.order.iter().map(|s| (s.robot, s.lc)).collect()
    }

    /// Duration (s) of each low-confidence stretch at ``ψ̇̄``, ``(m,)``.
    #[getter]
    fn lc_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.plan.lc_s.clone())
    }

    /// When each robot leaves its task start for the task of period 0 (its phase, s, in
    /// ``[0, P)``), ``(N,)``; it starts again every ``P``.
    #[getter]
    fn start_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.plan.robots.iter().map(|r| r.start_s).collect())
    }

    /// When each robot enters each low-confidence stretch of that task (s), ``(N, m)``;
    /// may exceed ``P`` when the task straddles the period's end (the phase is modulo ``P``).
    #[getter]
    fn lc_start_s<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let m = self.plan.lc_s.len();
        let values = self
            .plan
            .robots
            .iter()
            .flat_map(|r| r.lc_start_s.iter().copied())
            .collect();
        Ok(matrix_out(py, values, self.plan.robots.len(), m)?)
    }

    /// Planned duration (s) of each robot's high-confidence gaps (head, between stretches,
    /// tail), waits included, ``(N, m + 1)``.
    #[getter]
    fn gap_duration_s<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.per_gap(py, |g| g.duration_s)?)
    }

    /// The part of each gap spent waiting at its hold point (s), ``(N, m + 1)``; 0 in a gap
    /// without a hold.
    #[getter]
    fn gap_wait_s<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        Ok(self.per_gap(py, |g| g.wait_s)?)
    }

    /// Per gap, the hold point where the robot may wait (reference sample) or ``None``; the
    /// same for every robot (``m + 1`` entries).
    #[getter]
    fn gap_hold(&self) -> Vec<Option<usize>> {
        self.plan
            .robots
            .first()
            .map(|r| r.gaps.iter().map(|g| g.hold).collect())
            .unwrap_or_default()
    }

    /// Each robot's wait at its task start before its next task (s), ``(N,)``.
    #[getter]
    fn start_wait_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(
            py,
            self.plan.robots.iter().map(|r| r.start_wait_s).collect(),
        )
    }

    /// The continuous coordinator that runs this plan on ``problem`` (the problem it was
    /// planned for) at a control tick of ``tick_s`` real seconds (default: :attr:`tick_s`,
    /// the planner's tick, for a plan of :meth:`Planner.plan`; ``problem.dt_s`` otherwise):
    /// every robot on the fastest warp, waiting at the usable hold points, the operator's
    /// token passed in :attr:`order`; every robot at sample 0 of its first task.
    ///
    /// Under the planned operator (``tick(None)``) its steady throughput is
    /// :attr:`tasks_per_hour` less the hand-over cost (a robot leaves its gate only once the
    /// previous group has been left, plus the tick quantization); under drift only
    /// soundness is guaranteed: two robots are never low-confidence in one tick.
    ///
    /// Raises:
    ///     ScheduleError: an order the token rule cannot run (``violation`` is
    ///         ``"NotRunnable"``: another robot's stretch between two stretches of one robot
    ///         with no usable hold between them; only a plan made with
    ///         ``runnable_only=False`` or a given ``order`` can have one), or another
    ///         malformed order.
    ///     ParamError: ``tick_s`` not finite and > 0 (``name`` is ``"tick_s"``), or a
    ///         ``problem`` with another number of low-confidence stretches than the plan's
    ///         (``name`` is ``"problem"``).
    #[pyo3(signature = (problem, tick_s=None))]
    fn coordinator(
        &self,
        problem: PyRef<'_, PyProblem>,
        tick_s: Option<f64>,
    ) -> PyResult<PyContinuousCoordinator> {
        Ok(continuous::make(
            &self.plan,
            &problem.inner,
            tick_s.or(self.tick_s),
        )?)
    }

    /// The control tick (real s) of the cell the plan was checked for, its hand-overs
    /// counted at it: the planner's schedule's tick for a plan of :meth:`Planner.plan`
    /// (and :meth:`Planner.cyclic_plan`); ``None`` for a plan of :func:`cyclic_plan`.
    #[getter]
    fn tick_s(&self) -> Option<f64> {
        self.tick_s
    }

    /// Whether the continuous coordinator can run this plan's order on ``problem`` (no
    /// other robot's stretch between two stretches of one robot with no usable hold between
    /// them); always ``True`` for a plan searched with ``runnable_only=True``, the default.
    fn is_runnable(&self, problem: PyRef<'_, PyProblem>) -> bool {
        self.plan.is_runnable(&problem.inner)
    }

    /// The plan as JSON, exactly what ``tandem schedule --cell continuous --json`` prints
    /// (docs/formats.md, "Cyclic plan JSON"): the planner's documented form, the one type both
    /// print (``tandem::planner::json::CyclicPlanJson``), not the library type's serde form.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&tandem::planner::json::CyclicPlanJson::from(&self.plan))
            .map_err(|e| Error::Panic(format!("cannot write the cyclic plan as JSON: {e}")).into())
    }

    fn __repr__(&self) -> String {
        format!(
            "CyclicPlan(n_robots={}, period_s={:.3}, tasks_per_hour={:.2}, operator_share={:.3}, \
             gap={:.4}, order_exhaustive={})",
            self.plan.n_robots,
            self.plan.period_s,
            self.plan.tasks_per_hour,
            self.plan.operator_share,
            self.plan.gap,
            if self.plan.order_exhaustive {
                "True"
            } else {
                "False"
            }
        )
    }
}

/// The operator order from Python: a sequence of `(robot, stretch)` pairs.
fn order_of(order: &Bound<'_, PyAny>) -> Result<Vec<Stretch>> {
    let pairs: Vec<(usize, usize)> = order.extract().map_err(|_| {
        Error::input(
            "order",
            "expected a sequence of (robot, stretch) pairs of non-negative ints",
        )
    })?;
    Ok(pairs
        .into_iter()
        .map(|(robot, lc)| Stretch { robot, lc })
        .collect())
}

/// The cyclic plan of a continuous cell of ``robots`` robots (1 to 16, default 2) on
/// ``problem``: the operator order with the least period, every order searched while there
/// are at most ``max_enumerated`` (default 100 000), a local search beyond (see
/// :attr:`CyclicPlan.order_exhaustive`).
///
/// ``runnable_only`` (default ``True``): search only the orders the continuous coordinator
/// can run (:meth:`CyclicPlan.coordinator`); ``False`` searches every order, as a plan only.
/// ``order``: instead of a search, the plan of this cyclic order, a sequence of ``N·m``
/// pairs ``(robot, stretch)`` (0-based; each robot's stretches in task order around the
/// cycle); ``max_enumerated`` and ``runnable_only`` are then not used.
/// ``tick_s``: the control tick (real s) of the cell that will run the plan; when given, the
/// token rule's hand-overs are counted (a hand-over to another robot's group costs its travel
/// from the gate plus a tick), so the period is what the cell does with the planned operator
/// (:meth:`Planner.cyclic_plan` gives the planner's tick). Default: not counted.
///
/// Raises:
///     ParamError: ``robots`` outside 1…16, ``max_enumerated`` 0 or ``tick_s`` not finite and > 0.
///     InputError: an ``order`` that is not a sequence of pairs of non-negative ints.
///     ScheduleError: an ``order`` that does not list each robot's each stretch once in task
///         order, or that no period admits.
#[pyfunction]
#[pyo3(signature = (problem, robots=N_ROBOTS, max_enumerated=None, *, runnable_only=true, order=None, tick_s=None))]
pub(crate) fn cyclic_plan(
    py: Python<'_>,
    problem: PyRef<'_, PyProblem>,
    robots: usize,
    max_enumerated: Option<u64>,
    runnable_only: bool,
    order: Option<&Bound<'_, PyAny>>,
    tick_s: Option<f64>,
) -> PyResult<PyCyclicPlan> {
    let Some(order) = order.filter(|o| !o.is_none()) else {
        return compute(
            py,
            &problem.inner,
            robots,
            max_enumerated,
            runnable_only,
            tick_s,
        );
    };
    let order = order_of(order)?;
    let problem = &*problem.inner;
    let plan = py.detach(|| guard(|| Ok(cyclic_plan_for_order(problem, robots, &order)?)))?;
    Ok(PyCyclicPlan { plan, tick_s: None })
}
