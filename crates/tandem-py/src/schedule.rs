//! `tandem.Problem` and `tandem.Schedule` (§II-B4/6, Eq. 13, 15–16, 19–20).

use std::sync::{Arc, OnceLock};

use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::arrays::{flags, matrix, out_flags, out_matrix, out_vector, vector};
use crate::errors::{Error, Result, guard};
use crate::facade::{
    CheckedSchedule, GlobalTimeline, LcInterval, MAX_ROBOTS, Outcome, Problem, SamplerParams,
    Schedule, Source, sample_schedule_n,
};
use crate::planner::N_ROBOTS;

/// The name of a schedule's source in records ([`Source::name`]): `sampled`, `completed`,
/// `previous`, `repaired` (the previous schedule re-projected onto a new problem) or `serial`.
pub(crate) fn source_name(source: Source) -> &'static str {
    source.name()
}

/// The scheduling problem of Eq. 13–20: per reference sample ``n`` (period ``dt_s``) the
/// confidence (Eq. 12) and the mean, minimum and maximum warp gradients (Eq. 5, 14).
#[pyclass(module = "tandem", name = "Problem", frozen)]
#[derive(Clone)]
pub(crate) struct PyProblem {
    pub(crate) inner: Arc<Problem>,
}

impl PyProblem {
    pub(crate) fn new(inner: Arc<Problem>) -> Self {
        Self { inner }
    }
}

#[pymethods]
impl PyProblem {
    /// Checks and builds a problem from ``(T_ref,)`` arrays: ``conf`` (bool, ``True`` =
    /// high confidence), ``grad_mean``, ``grad_min``, ``grad_max`` (execution samples per
    /// reference sample, ``0 < ψ̇min ≤ ψ̇̄ ≤ ψ̇max``) and the period ``dt_s`` (s).
    #[new]
    fn py_new(
        conf: &Bound<'_, PyAny>,
        grad_mean: &Bound<'_, PyAny>,
        grad_min: &Bound<'_, PyAny>,
        grad_max: &Bound<'_, PyAny>,
        dt_s: f64,
    ) -> PyResult<Self> {
        let axis = "one value per reference sample";
        let problem = Problem::new(
            flags(conf, "conf", axis)?,
            vector(grad_mean, "grad_mean", axis)?,
            vector(grad_min, "grad_min", axis)?,
            vector(grad_max, "grad_max", axis)?,
            dt_s,
        )
        .map_err(Error::from)?;
        Ok(Self::new(Arc::new(problem)))
    }

    /// ``T_ref``: reference samples.
    #[getter]
    fn n_ref(&self) -> usize {
        self.inner.n_ref()
    }

    /// Reference sample period ``Δt_s`` (s).
    #[getter]
    fn dt_s(&self) -> f64 {
        self.inner.dt_s()
    }

    /// ``conf(n)`` (Eq. 12), ``(T_ref,)`` bool: ``True`` = high confidence.
    #[getter]
    fn conf<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<bool>> {
        out_flags(py, self.inner.conf().to_vec())
    }

    /// ``ψ̄̇(n)``, the gradient of low-confidence samples (Eq. 20 constraint 4), ``(T_ref,)``.
    #[getter]
    fn grad_mean<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.grad_mean().to_vec())
    }

    /// The hold points: reference samples where a robot may dwell, its clock stopped
    /// (increasing, without the task start, which always is one); empty without holds.
    #[getter]
    fn holds(&self) -> Vec<usize> {
        self.inner.holds().to_vec()
    }

    /// The hold points on high-confidence samples, where a robot may dwell now (a hold on a
    /// low-confidence sample is inactive until the sample is trusted).
    #[getter]
    fn active_holds(&self) -> Vec<usize> {
        self.inner.active_holds().collect()
    }

    /// ``ψ̇min(n)`` (Eq. 14), ``(T_ref,)``.
    #[getter]
    fn grad_min<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.grad_min().to_vec())
    }

    /// ``ψ̇max(n)`` (Eq. 14), ``(T_ref,)``.
    #[getter]
    fn grad_max<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.grad_max().to_vec())
    }

    /// The fastest serial schedule (§II-C fallback): every robot as fast as allowed, each
    /// starting when the one before it ends; valid at any tick. ``tick_s`` (real s) defaults
    /// to ``dt_s``; ``robots`` is ``N`` (1 to 16, default 2).
    #[pyo3(signature = (tick_s=None, robots=N_ROBOTS))]
    fn serial_schedule(&self, tick_s: Option<f64>, robots: usize) -> PyResult<PySchedule> {
        let tick_s = tick_s.unwrap_or(self.inner.dt_s());
        let s = self
            .inner
            .serial_schedule_n(robots, tick_s)
            .map_err(Error::from)?;
        Ok(PySchedule {
            from_scheduler: true,
            ..PySchedule::new(self.inner.clone(), s, "serial".into(), None)
        })
    }

    /// The scheduler (§II-C) on this problem for ``robots`` robots (1 to 16, default 2):
    /// ``samples`` candidates from ``seed`` (deterministic for a seed whatever the thread
    /// count), margins checked at control tick ``tick_s`` (real s, default ``dt_s``),
    /// warm-started by ``previous``.
    #[pyo3(signature = (samples=5000, seed=0, tick_s=None, previous=None, robots=N_ROBOTS))]
    fn sample_schedule(
        &self,
        py: Python<'_>,
        samples: usize,
        seed: u64,
        tick_s: Option<f64>,
        previous: Option<PyRef<'_, PySchedule>>,
        robots: usize,
    ) -> PyResult<PySchedule> {
        let params = SamplerParams {
            samples,
            seed,
            tick_s,
            ..SamplerParams::default()
        };
        let previous = previous.map(|p| p.schedule.clone());
        let problem = &*self.inner;
        let outcome = py.detach(|| {
            guard(|| {
                Ok(sample_schedule_n(
                    problem,
                    robots,
                    &params,
                    previous.as_ref(),
                )?)
            })
        })?;
        Ok(PySchedule::from_outcome(self.inner.clone(), &outcome))
    }

    fn __repr__(&self) -> String {
        let conf = self.inner.conf();
        format!(
            "Problem(n_ref={}, dt_s={}, high_share={:.3})",
            conf.len(),
            self.inner.dt_s(),
            conf.iter().filter(|c| **c).count() as f64 / conf.len() as f64
        )
    }
}

/// A schedule (§II-B4): one execution warp per robot (a gradient per reference sample),
/// the start offsets, and the control tick its margins were checked at, on the problem it
/// was made for.
///
/// Shaped for ``N`` robots: ``gradients`` is ``(N, T_ref)``, ``offsets`` holds the ``N − 1``
/// start offsets of robots 2…N (``1 ≤ N ≤ MAX_ROBOTS``).
#[pyclass(module = "tandem", name = "Schedule", frozen)]
pub(crate) struct PySchedule {
    pub(crate) schedule: Schedule,
    pub(crate) problem: Arc<Problem>,
    source: String,
    stats: Option<[usize; 3]>,
    /// `(lower bound T*₀ or the simple bound (s), relative gap)` of a scheduler's outcome.
    certificate: Option<(f64, f64)>,
    /// The schedule as this build checked it on `problem`: set by [`PySchedule::checked`]
    /// (the first time a coordinator is built from a scheduler's schedule) or by a
    /// successful `validate()`; a user's schedule has none until then.
    checked: OnceLock<CheckedSchedule>,
    /// Whether the schedule came from this build's scheduler, planner or serial construction
    /// (valid when made), so that a coordinator checks it itself instead of asking for
    /// `validate()`.
    from_scheduler: bool,
    /// The operator's `(switch_s, max_busy_share)` the schedule was planned for (a planner's;
    /// `(0, 1)` otherwise): its check relaxes Eq. 20 constraint 2 by their allowance
    /// ([`Schedule::check_with_operator`]).
    operator: (f64, f64),
}

impl PySchedule {
    /// Every robot's low-confidence intervals in global time, from its legs (the plan split at
    /// its holds, each leg after its planned dwell; one leg without holds).
    fn lc_by_robot(&self) -> Result<Vec<Vec<LcInterval>>> {
        Ok(self.schedule.lc_intervals(&self.problem)?)
    }

    fn new(
        problem: Arc<Problem>,
        schedule: Schedule,
        source: String,
        stats: Option<[usize; 3]>,
    ) -> Self {
        Self {
            schedule,
            problem,
            source,
            stats,
            certificate: None,
            checked: OnceLock::new(),
            from_scheduler: false,
            operator: (0.0, 1.0),
        }
    }

    /// The schedule as checked on its problem ([`Schedule::check`]), for the coordinator: a
    /// user's schedule must have passed `validate()` first; a scheduler's is checked here
    /// once (the check is this build's; a schedule the scheduler made passes it).
    ///
    /// # Errors
    /// [`Error::Unchecked`] for a user's schedule that was not validated; the check's
    /// violation otherwise.
    pub(crate) fn checked(&self) -> Result<&CheckedSchedule> {
        if let Some(c) = self.checked.get() {
            return Ok(c);
        }
        if !self.from_scheduler {
            return Err(Error::Unchecked);
        }
        let c = checked_or_violation(&self.problem, &self.schedule, self.operator)?;
        Ok(self.checked.get_or_init(|| c))
    }

    pub(crate) fn from_outcome(problem: Arc<Problem>, outcome: &Outcome) -> Self {
        let s = &outcome.stats;
        Self {
            certificate: Some((outcome.lower_bound_s, outcome.gap)),
            from_scheduler: true,
            ..Self::new(
                problem,
                outcome.schedule.clone(),
                source_name(outcome.source).into(),
                Some([s.candidates, s.cheap_feasible, s.margin_checks]),
            )
        }
    }

    /// The operator's switch time `δ` (s) the schedule was planned for (0 unless a planner
    /// made it with `switch_s > 0`), which its coordinator keeps at the holds' release rules.
    pub(crate) fn planned_switch_s(&self) -> f64 {
        self.operator.0
    }

    /// The same schedule, planned for an operator with `switch_s` and `max_busy_share` (a
    /// planner's parameters): its check relaxes constraint 2 by their allowance.
    pub(crate) fn with_operator(self, switch_s: f64, max_busy_share: f64) -> Self {
        Self {
            operator: (switch_s, max_busy_share),
            ..self
        }
    }

    fn timeline(&self) -> Result<GlobalTimeline> {
        Ok(GlobalTimeline::new(&self.problem, &self.schedule)?)
    }
}

/// [`Schedule::check`], a broken constraint as [`Error::Violation`] (``ScheduleError`` with
/// the rule's name).
fn checked_or_violation(
    problem: &Problem,
    schedule: &Schedule,
    (switch_s, max_busy_share): (f64, f64),
) -> Result<CheckedSchedule> {
    let checked = if switch_s == 0.0 && max_busy_share >= 1.0 {
        schedule.check(problem)
    } else {
        schedule.check_with_operator(problem, switch_s, max_busy_share)
    };
    checked.map_err(|e| match e {
        crate::facade::errors::Schedule::Invalid(v) => Error::Violation(v),
        other => other.into(),
    })
}

#[pymethods]
impl PySchedule {
    /// A schedule of your own on ``problem``: ``gradients`` of shape ``(N, T_ref)``
    /// (execution samples per reference sample), ``offsets`` of shape ``(N − 1,)`` (s,
    /// global time; robot 1 starts at 0) and the control tick ``tick_s`` (real s). Check it
    /// with :meth:`validate` before running it.
    #[new]
    fn py_new(
        problem: PyRef<'_, PyProblem>,
        gradients: &Bound<'_, PyAny>,
        offsets: &Bound<'_, PyAny>,
        tick_s: f64,
    ) -> PyResult<Self> {
        let n_ref = problem.inner.n_ref();
        let (g, cols) = matrix(gradients, "gradients", "robots × reference samples")?;
        let rows = g.len().checked_div(cols).unwrap_or(0);
        if !(1..=MAX_ROBOTS).contains(&rows) || cols != n_ref {
            let expected = if (1..=MAX_ROBOTS).contains(&rows) {
                format!("({rows}, {n_ref})")
            } else {
                format!("(N, {n_ref}) with 1 ≤ N ≤ {MAX_ROBOTS}")
            };
            return Err(Error::input(
                "gradients",
                format!("shape ({rows}, {cols}), expected {expected} (robots × reference samples)"),
            )
            .into());
        }
        let offsets = vector(offsets, "offsets", "robots 2…N")?;
        if offsets.len() != rows - 1 {
            return Err(Error::input(
                "offsets",
                format!(
                    "{} offsets, expected {} (one per robot after the first)",
                    offsets.len(),
                    rows - 1
                ),
            )
            .into());
        }
        let schedule = Schedule {
            grad_exec: g.chunks_exact(n_ref).map(<[f64]>::to_vec).collect(),
            offsets_s: offsets.to_vec(),
            tick_s,
            holds: Vec::new(),
        };
        Ok(Self::new(
            problem.inner.clone(),
            schedule,
            "user".into(),
            None,
        ))
    }

    /// Number of robots ``N``.
    #[getter]
    fn n_robots(&self) -> usize {
        self.schedule.n_robots()
    }

    /// Start offsets of robots 2…N, ``(N − 1,)``, s of global time (``τ``, §II-B4).
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.schedule.offsets_s.clone())
    }

    /// Start time of every robot, ``(N,)``, s of global time: ``[0, τ_2, …, τ_N]``.
    #[getter]
    fn starts_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.schedule.starts_s().to_vec())
    }

    /// Execution warp gradients ``ψ̇_Ei(n)``, ``(N, T_ref)``: robot ``i`` spends
    /// ``ψ̇_Ei(n)·Δt_s`` seconds on reference sample ``n``.
    #[getter]
    fn gradients<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let flat = self.schedule.grad_exec.concat();
        Ok(out_matrix(py, flat, self.problem.n_ref())?)
    }

    /// Control tick (real s) of the margin check that accepted the schedule: the only
    /// period the :class:`Coordinator` runs it at.
    #[getter]
    fn tick_s(&self) -> f64 {
        self.schedule.tick_s
    }

    /// Reference sample period ``Δt_s`` (s) of the problem.
    #[getter]
    fn dt_s(&self) -> f64 {
        self.problem.dt_s()
    }

    /// ``T_total = max_i(τ_i + |ψ_Ei|)`` (Eq. 13), s of global time.
    #[getter]
    fn t_total_s(&self) -> f64 {
        self.schedule.t_total_s(self.problem.dt_s())
    }

    /// The hold points of the schedule per robot (empty lists without holds): a list of
    /// ``N`` lists of dicts ``{"ref_idx": n, "dwell_s": planned wait (s), "after": [(robot,
    /// ref_idx), …]}``; robot ``i`` stops at the start of reference sample ``n`` and leaves
    /// once every robot named in ``after`` (0-based) has passed that reference sample.
    #[getter]
    fn holds<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for robot in 0..self.schedule.n_robots() {
            let per = PyList::empty(py);
            for h in self.schedule.holds_of(robot) {
                let d = PyDict::new(py);
                d.set_item("ref_idx", h.ref_idx)?;
                d.set_item("dwell_s", h.dwell_s)?;
                let after: Vec<(usize, usize)> =
                    h.after.iter().map(|a| (a.robot, a.ref_idx)).collect();
                d.set_item("after", after)?;
                per.append(d)?;
            }
            list.append(per)?;
        }
        Ok(list)
    }

    /// Planned waiting at hold points per robot, ``(N,)``, s (zeros without holds).
    #[getter]
    fn dwells_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let n = self.schedule.n_robots();
        out_vector(py, (0..n).map(|i| self.schedule.dwell_s(i)).collect())
    }

    /// Execution durations ``|ψ_Ei|``, ``(N,)``, s.
    #[getter]
    fn durations_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.schedule.durations_s(self.problem.dt_s()).to_vec())
    }

    /// Scheduled end of every robot, ``(N,)``, s of global time.
    #[getter]
    fn ends_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.schedule.ends_s(self.problem.dt_s()).to_vec())
    }

    /// Low-confidence intervals per robot (Eq. 19): a list of ``N`` arrays of shape
    /// ``(k_i, 2)``, ``[start_s, end_s)`` in s of global time.
    #[getter]
    fn lc_intervals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for robot in self.lc_by_robot()? {
            let flat: Vec<f64> = robot.iter().flat_map(|i| [i.start_s, i.end_s]).collect();
            list.append(out_matrix(py, flat, 2)?)?;
        }
        Ok(list)
    }

    /// The same intervals in reference samples: a list of ``N`` int64 arrays ``(k_i, 2)``,
    /// ``[ref_start, ref_end)``.
    #[getter]
    fn lc_ref_intervals<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for robot in self.lc_by_robot()? {
            let flat: Vec<i64> = robot
                .iter()
                .flat_map(|i| [i.ref_start as i64, i.ref_end as i64])
                .collect();
            list.append(out_matrix(py, flat, 2)?)?;
        }
        Ok(list)
    }

    /// Where the schedule came from: ``sampled``, ``previous``, ``repaired``, ``serial``,
    /// or ``user`` (built from arrays).
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    /// The sampler's counts (``candidates``, ``cheap_feasible``, ``margin_checks``), or
    /// ``None`` for a schedule not made by the sampler.
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some([candidates, cheap, checks]) = self.stats else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("candidates", candidates)?;
        d.set_item("cheap_feasible", cheap)?;
        d.set_item("margin_checks", checks)?;
        Ok(Some(d))
    }

    /// A lower bound on ``T_total`` (s) over all schedules of the problem (the margin-free
    /// optimum ``T*₀`` of Eq. 20 constraints 1–4 when proven), for a schedule made by the
    /// scheduler (``Planner.schedule``, ``reschedule``); ``None`` for a schedule built by hand.
    #[getter]
    fn lower_bound_s(&self) -> Option<f64> {
        self.certificate.map(|c| c.0)
    }

    /// Relative gap ``(T_total − lower_bound_s) / lower_bound_s`` (dimensionless), or ``None``
    /// without a lower bound. The bound is reported as computed (never clamped), so the gap is
    /// ≥ 0 up to rounding: never below ``−2e-9`` (``tol::BOUND_REL``); e.g. ``−5.7e-15`` when
    /// the schedule is the optimum.
    #[getter]
    fn gap(&self) -> Option<f64> {
        self.certificate.map(|c| c.1)
    }

    /// The problem the schedule was made for.
    #[getter]
    fn problem(&self) -> PyProblem {
        PyProblem::new(self.problem.clone())
    }

    /// Checks every constraint of Eq. 20 at the schedule's own tick (gradient bounds, the
    /// offset, no low-confidence overlap, the mean gradient on low-confidence samples and
    /// the conservative margin check of Alg. 2).
    ///
    /// Raises:
    ///     ScheduleError: the first broken constraint; ``violation`` names it.
    ///
    /// A schedule that passes may then run in a :class:`Coordinator` (a schedule of your own
    /// must pass this first; the scheduler's and the planner's were checked when made).
    fn validate(&self, py: Python<'_>) -> PyResult<()> {
        if self.checked.get().is_some() {
            return Ok(());
        }
        let (problem, schedule, operator) = (&*self.problem, &self.schedule, self.operator);
        let checked = py.detach(|| guard(|| checked_or_violation(problem, schedule, operator)))?;
        let _ = self.checked.set(checked);
        Ok(())
    }

    /// Eq. 15: each robot's fractional reference time (reference samples) at global time
    /// ``t_global_s`` on schedule, ``(N,)``: 0 before its start, ``T_ref`` after its end.
    fn ref_time<'py>(
        &self,
        py: Python<'py>,
        t_global_s: f64,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let tl = self.timeline()?;
        Ok(out_vector(
            py,
            (0..self.schedule.n_robots())
                .map(|i| tl.ref_time(i, t_global_s))
                .collect(),
        ))
    }

    /// Eq. 16: each robot's confidence at global time ``t_global_s`` on schedule, ``(N,)``
    /// bool (a robot that is not running counts as high-confidence).
    fn conf_at<'py>(
        &self,
        py: Python<'py>,
        t_global_s: f64,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let tl = self.timeline()?;
        Ok(out_flags(py, tl.conf_at(t_global_s).to_vec()))
    }

    /// The schedule as JSON (``grad_exec``, ``offsets_s``, ``tick_s``), the form of the
    /// command line's ``tandem schedule --json`` schedule.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.schedule)
            .map_err(|e| Error::Panic(format!("schedule to JSON: {e}")).into())
    }

    /// A schedule read from :meth:`to_json`'s text, on ``problem``.
    #[staticmethod]
    fn from_json(problem: PyRef<'_, PyProblem>, text: &str) -> PyResult<Self> {
        let schedule: Schedule =
            serde_json::from_str(text).map_err(|e| Error::input("schedule JSON", e.to_string()))?;
        if let Err(v) = schedule.check_shape() {
            return Err(Error::input("schedule JSON", v.to_string()).into());
        }
        if schedule
            .grad_exec
            .iter()
            .any(|g| g.len() != problem.inner.n_ref())
        {
            return Err(Error::input(
                "schedule JSON",
                format!(
                    "warps of lengths {:?}, the problem has {} reference samples",
                    schedule.grad_exec.iter().map(Vec::len).collect::<Vec<_>>(),
                    problem.inner.n_ref()
                ),
            )
            .into());
        }
        Ok(Self::new(
            problem.inner.clone(),
            schedule,
            "user".into(),
            None,
        ))
    }

    fn __repr__(&self) -> String {
        format!(
            "Schedule(n_robots={}, offsets=[{}], t_total_s={:.3}, tick_s={}, source='{}')",
            self.schedule.n_robots(),
            self.schedule
                .offsets_s
                .iter()
                .map(|t| format!("{t:.3}"))
                .collect::<Vec<_>>()
                .join(", "),
            self.t_total_s(),
            self.schedule.tick_s,
            self.source
        )
    }
}
