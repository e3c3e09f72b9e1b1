"""Type stubs of the Rust extension module ``tandem._tandem`` (crates/tandem-py).

Shapes: ``T_ref`` reference samples, ``C`` channels, ``d`` tangent coordinates (``C`` with
quaternion blocks as rotation vectors, plus the rate), ``K`` correction components, ``N``
robots (1 to ``MAX_ROBOTS`` = 16; ``fit(robots=...)``, default ``N_ROBOTS`` = 2). Times in seconds unless named in samples.
"""

from os import PathLike
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]
Bool = npt.NDArray[np.bool_]
I64 = npt.NDArray[np.int64]
ArrayLike = npt.ArrayLike
Path = Union[str, PathLike]
Params = Union[None, Mapping[str, Any], str, PathLike]
Demo = Union[Path, ArrayLike]

N_ROBOTS: int
MAX_ROBOTS: int
__version__: str

class TandemError(Exception):
    """Base class of every error tandem raises (never a panic or an abort)."""

class InputError(TandemError):
    """Bad input data; ``file`` (or the argument, e.g. ``demos[2]``), ``line``, ``column``."""

    file: Optional[str]
    line: Optional[int]
    column: Optional[int]

class ParamError(TandemError):
    """A parameter out of range, or an unknown or ill-typed key; ``name``."""

    name: Optional[str]

class StateFileError(TandemError):
    """A state file that cannot be read or written; ``path``. The file is left as it was."""

    path: Optional[str]

class ScheduleError(TandemError):
    """An infeasible problem, a schedule that violates Eq. 20, or one run at another tick."""

    violation: Optional[str]

class InternalError(TandemError):
    """A bug in tandem (a Rust panic caught at the Python boundary)."""

class DataWarning(UserWarning):
    """Data taken in, but not as given: an assumed period, a resampled execution, an unusual
    demonstration length. The message names the file and the fix."""

def fit(
    demos: Sequence[Demo],
    channels: Optional[Sequence[str]] = None,
    params: Params = None,
    dt_s: Optional[float] = None,
    robots: int = 2,
    holds: Optional[Union[Sequence[Union[float, str]], Dict[str, Any]]] = None,
    rate_term: Optional[str] = None,
    switch_s: Optional[float] = None,
    max_busy_share: Optional[float] = None,
    resample: bool = False,
    operators: Optional[int] = None,
) -> Planner:
    """Learns the task from demonstrations (paths or ``(T_i, C)`` arrays) and makes the first
    schedule (Fig. 2); the same inputs and parameters as ``tandem fit`` give the same state.
    ``holds``: reference times (s) and rules (``"gripper>0.5"``) where a robot may wait, as
    ``tandem fit --hold-at/--hold-where``; ``[]`` declares none, ``None`` keeps ``params``'.
    ``dt_s``: the arrays' sample period (s); without it arrays are taken to be 0.01 s apart
    with a ``DataWarning`` (deprecated). ``rate_term``: how the speeds enter ``σ²_D``
    (``"relative"``, ``"absolute"``, ``"relative:opening=13,window=49"``), as
    ``tandem fit --rate-term``; ``None`` keeps ``params``'. ``switch_s``: the operator's
    switch time δ (s, ≥ 0) between two robots' low-confidence stretches; ``max_busy_share``:
    its load cap in (0, 1] (``tandem fit --switch-s/--max-busy``); ``None`` keeps
    ``params["sampler"]``'. ``resample``: put CSV files with an irregular ``t`` column on an
    even grid first, as ``tandem fit --resample`` (a ``DataWarning`` per file).
    ``operators``: the cell's operators M, 1 to 16 (``tandem fit --operators``): M tokens in a
    continuous cell, M sectors in rounds (:meth:`Planner.sectored_rounds`); ``None`` keeps
    ``params["sampler"]``'."""

def read_bag(
    path: Path,
    topics: Optional[Sequence[str]] = None,
    rate: Optional[float] = None,
    namespace: Optional[str] = None,
) -> Dict[str, Any]:
    """A ROS 2 bag (rosbag2 MCAP) on one grid, as ``tandem fit`` reads it: ``samples``
    ``(T, C)``, ``channels``, ``t`` ``(T,)`` bag times (s), ``dt_s``, ``topics``, ``quaternions``."""

def fit_model(
    demos: Sequence[Demo],
    channels: Optional[Sequence[str]] = None,
    params: Params = None,
    dt_s: Optional[float] = None,
    rate_term: Optional[str] = None,
    resample: bool = False,
) -> Model:
    """The task model alone (alignment and statistics, §II-B1/2)."""

def default_params() -> Dict[str, Any]:
    """The default parameters ``{"fit": …, "confidence": …, "sampler": …}``."""

def align(reference: ArrayLike, query: ArrayLike, params: Params = None) -> Warp:
    """GDTW (Eq. 2–3): the warp from reference samples to query samples."""

def fit_cell(
    tasks: Dict[str, Sequence[Demo]],
    robots: Optional[Dict[str, int]] = None,
    channels: Optional[Union[Sequence[str], Dict[str, Sequence[str]]]] = None,
    params: Params = None,
    dt_s: Optional[Union[float, Dict[str, float]]] = None,
    resample: bool = False,
) -> CellPlanner:
    """A cell of different tasks on different robots (``tandem fit --task … --robots …``)."""

class CellPlanner:
    """A cell of task models: one planner per task, each robot's task, one rounds schedule."""

    @staticmethod
    def load(path: Path) -> CellPlanner:
        """Loads a cell (format 12) or a one-task state file (a cell of task ``"task"``)."""
    def save(self, path: Path, timeout_s: Optional[float] = None) -> None:
        """Saves atomically under the file's lock; never discards recorded rounds."""
    @property
    def tasks(self) -> List[str]:
        """The tasks' names, in the cell's order."""
    @property
    def robot_tasks(self) -> List[str]:
        """Each robot's task (robot 1 first)."""
    @property
    def n_robots(self) -> int:
        """The number of robots."""
    @property
    def rounds_recorded(self) -> int:
        """Rounds recorded (one execution of each robot)."""
    @property
    def t_total_s(self) -> float:
        """The current schedule's ``T_total`` (s)."""
    @property
    def schedule(self) -> Dict[str, Any]:
        """``t_total_s``, ``starts_s``, ``ends_s``, ``lc_intervals`` and, for two or more
        tasks, ``lower_bound_s``, ``gap_s``, ``tick_s``, ``margin_checks`` (global s)."""
    def planner(self, name: str) -> Planner:
        """A snapshot of task ``name``'s planner."""
    def record_round(
        self,
        executions: Sequence[Demo],
        ref_time_logs: Sequence[ArrayLike],
        supervised: Sequence[ArrayLike],
        corrected: Sequence[ArrayLike],
        dt_s: Optional[float] = None,
        resample: bool = False,
    ) -> Dict[str, Any]:
        """Records one execution of each robot into its task, then re-schedules the cell."""
    def coordinator(self) -> Coordinator:
        """The run-time coordinator of the cell's rounds schedule (a snapshot)."""

class Planner:
    """The loop of Fig. 2: model, observations, latched confidence and schedule."""

    @staticmethod
    def load(path: Path) -> Planner:
        """Loads a state file (written here or by the command line)."""
    @staticmethod
    def locked(path: Path, timeout_s: Optional[float] = None) -> StateEdit:
        """``with Planner.locked(path) as planner:`` loads, and saves at the end, under the
        state file's lock (waiting up to ``timeout_s``, default 60 s, for another writer)."""
    def save(
        self, path: Path, timeout_s: Optional[float] = None, force: bool = False
    ) -> None:
        """Saves the state file atomically under its lock (the previous file survives any
        error); never replaces a non-state file or what another process saved since the load,
        nor, without ``force=True``, a state file holding rounds this planner does not hold."""
    def refit(
        self,
        demos: Sequence[Demo],
        channels: Optional[Sequence[str]] = None,
        params: Params = None,
        dt_s: Optional[float] = None,
        holds: Optional[Union[Sequence[Union[float, str]], Dict[str, Any]]] = None,
        resample: bool = False,
    ) -> Planner:
        """Fits the task again from ``demos`` and replays every recorded round onto the new
        fit (the operator's corrections kept); returns the new planner, which saves into the
        file this one was loaded from."""
    def set_holds(
        self, holds: Union[Sequence[Union[float, str]], Dict[str, Any]]
    ) -> Schedule:
        """Declares hold points (as ``fit``'s ``holds``) and re-schedules; a hold where the
        recorded corrections show the operator is needed is refused."""
    def record_round(
        self,
        executions: Sequence[Demo],
        ref_time_logs: Sequence[ArrayLike],
        supervised: Sequence[ArrayLike],
        corrected: Sequence[ArrayLike],
        channels: Optional[Sequence[str]] = None,
        dt_s: Optional[float] = None,
        resample: bool = False,
    ) -> Dict[str, Any]:
        """Records one execution per robot (``N`` of each argument; Eq. 21, 9–12) and
        re-schedules (§II-C). ``dt_s``: the logs' sample period (default: the schedule's
        tick); a finer log is resampled to the model's period. ``resample``: CSV executions
        with an irregular ``t`` column are put on an even grid first, their logs and flags
        (one entry per row) with them. A sample ``corrected`` but not ``supervised`` is an
        ``InputError``. The dict's ``reopened`` counts latched samples the round's
        corrections turned low-confidence again (e.g. rounds recorded out of order)."""
    def record_pair(
        self,
        executions: Sequence[Demo],
        ref_time_logs: Sequence[ArrayLike],
        supervised: Sequence[ArrayLike],
        corrected: Sequence[ArrayLike],
        channels: Optional[Sequence[str]] = None,
        dt_s: Optional[float] = None,
    ) -> Dict[str, Any]:
        """Deprecated (kept one release): :meth:`record_round` under its two-robot name;
        emits a ``DeprecationWarning``."""
    def reschedule(
        self,
        samples: Optional[int] = None,
        seed: Optional[int] = None,
        tick_s: Optional[float] = None,
        switch_s: Optional[float] = None,
        max_busy_share: Optional[float] = None,
        operators: Optional[int] = None,
    ) -> Schedule:
        """Re-runs the sampler warm-started by the current schedule and keeps the result;
        ``switch_s``/``max_busy_share``/``operators`` given become the planner's."""
    def sectored_rounds(self) -> Dict[str, Any]:
        """The round of ``params()["sampler"]["operators"]`` operators in sectors:
        ``{"sizes", "sector_of", "t_total_s", "lower_bound_s"}`` (issue 44)."""
    def plan(self, cell: str = "rounds") -> Union[Schedule, CyclicPlan]:
        """The plan of this planner's ``cell`` (``"rounds"``: the current schedule, checked;
        ``"continuous"``: the cyclic plan), at the current schedule's tick; a snapshot."""
    def controller(
        self, cell: str = "rounds"
    ) -> Union[Coordinator, ContinuousCoordinator]:
        """The run-time coordinator of :meth:`plan` (a ``tandem.Controller``), at the
        current schedule's tick, every robot at its start."""
    def cyclic_plan(self, max_enumerated: Optional[int] = None) -> CyclicPlan:
        """The plan of a continuous cell (no rounds) on the current problem for this
        planner's robots; does not change the planner (``tandem schedule --cell continuous``)."""
    def continuous_coordinator(
        self, max_enumerated: Optional[int] = None, tick_s: Optional[float] = None
    ) -> ContinuousCoordinator:
        """:meth:`cyclic_plan` run on the current problem by :meth:`CyclicPlan.coordinator`;
        ``tick_s`` defaults to the current schedule's tick."""
    @property
    def schedule(self) -> Schedule:
        """The current schedule (a snapshot)."""
    @property
    def problem(self) -> Problem:
        """The current scheduling problem."""
    @property
    def model(self) -> Model:
        """The task model (a live view)."""
    @property
    def confidence(self) -> Confidence:
        """The latched confidence and the observations (a live view)."""
    @property
    def params(self) -> Dict[str, Any]:
        """The parameters as a nested dict."""
    @property
    def rounds_recorded(self) -> int:
        """Rounds recorded so far (a round is one execution of each robot)."""
    @property
    def pairs_recorded(self) -> int:
        """Deprecated (kept one release): :attr:`rounds_recorded`; emits a
        ``DeprecationWarning``."""
    @property
    def n_robots(self) -> int:
        """Robots scheduled (``N``)."""
    def command(self, ref_time: float, u: Optional[ArrayLike] = None) -> F64:
        """Eq. 7: ``(C + 1,)``, the channel values then the rate (warp gradient)."""

class StateEdit:
    """The context manager of :meth:`Planner.locked`: the lock is held from ``__enter__``
    (which returns the loaded planner) to ``__exit__`` (which saves it if no exception)."""

    def __enter__(self) -> Planner: ...
    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> bool: ...

class Model:
    """The task model: per reference sample mean, variance, gradient bounds, corrections."""

    @property
    def channels(self) -> List[str]: ...
    @property
    def tangent_names(self) -> List[str]: ...
    @property
    def n_ref(self) -> int: ...
    @property
    def dt_s(self) -> float: ...
    @property
    def reference_idx(self) -> int: ...
    @property
    def count(self) -> int: ...
    @property
    def n_components(self) -> int: ...
    @property
    def mean(self) -> F64:
        """``μ̂``, ``(T_ref, C)``."""
    @property
    def sigma2_d(self) -> F64:
        """``σ²_D`` (Eq. 6), ``(T_ref,)``, dimensionless."""
    @property
    def grad_mean(self) -> F64:
        """``ψ̄̇_D`` (Eq. 5), ``(T_ref,)``."""
    @property
    def grad_min(self) -> F64:
        """``ψ̇min`` (Eq. 14), ``(T_ref,)``."""
    @property
    def grad_max(self) -> F64:
        """``ψ̇max`` (Eq. 14), ``(T_ref,)``."""
    @property
    def ranges(self) -> F64:
        """``r_j``, ``(d,)``; ``W⁺ = diag(1/r²)``."""
    def corrections_at(self, ref_time: float) -> Tuple[float, F64]:
        """``(scale, components (K, d))`` at a fractional reference time."""
    def command(self, ref_time: float, u: Optional[ArrayLike] = None) -> F64:
        """Eq. 7, ``(C + 1,)``."""

class Confidence:
    """Latched confidence (Eq. 9–12) per reference sample, and the observations."""

    @property
    def high(self) -> Bool:
        """``conf(n)``, ``(T_ref,)``: ``True`` = high confidence (latched)."""
    @property
    def n_high(self) -> int: ...
    @property
    def high_share(self) -> float: ...
    @property
    def low_regions(self) -> I64:
        """``(k, 2)`` ``[start, end)`` reference samples."""
    @property
    def params(self) -> Dict[str, Any]: ...
    @property
    def prior_alpha(self) -> F64: ...
    @property
    def prior_beta(self) -> F64: ...
    @property
    def posterior_alpha(self) -> F64: ...
    @property
    def posterior_beta(self) -> F64: ...
    @property
    def p_below_mu_c(self) -> F64:
        """``P(π < μ_c) = I_μ'c(α, β)``, the left side of Eq. 12, ``(T_ref,)``."""
    @property
    def error_rates(self) -> Dict[str, float]:
        """``{"false_correction_rate": f, "miss_rate": m}`` the confidence decides with."""
    @property
    def sigma2_d_prior_threshold(self) -> Optional[float]:
        """``σ²_D`` above which the prior alone is low-confidence."""
    def explain_low_confidence(self) -> List[Dict[str, Any]]:
        """Each low-confidence region: interval, cause, channels, what would change it."""
    @property
    def observations(self) -> Observations: ...

class Observations:
    """Correction observations per reference sample (Eq. 9), fractional counts."""

    @property
    def supervised(self) -> F64: ...
    @property
    def corrections(self) -> F64: ...
    @property
    def total_supervised(self) -> float: ...
    @property
    def total_corrections(self) -> float: ...

class Problem:
    """The scheduling problem: confidence and gradient bounds per reference sample."""

    def __init__(
        self,
        conf: ArrayLike,
        grad_mean: ArrayLike,
        grad_min: ArrayLike,
        grad_max: ArrayLike,
        dt_s: float,
    ) -> None: ...
    @property
    def n_ref(self) -> int: ...
    @property
    def dt_s(self) -> float: ...
    @property
    def conf(self) -> Bool: ...
    @property
    def holds(self) -> List[int]:
        """Hold points: reference samples where a robot may dwell (without the start)."""
    @property
    def active_holds(self) -> List[int]:
        """The hold points on high-confidence samples (where a robot may dwell now)."""
    @property
    def grad_mean(self) -> F64: ...
    @property
    def grad_min(self) -> F64: ...
    @property
    def grad_max(self) -> F64: ...
    def serial_schedule(self, tick_s: Optional[float] = None, robots: int = 2) -> Schedule: ...
    def sample_schedule(
        self,
        samples: int = 5000,
        seed: int = 0,
        tick_s: Optional[float] = None,
        previous: Optional[Schedule] = None,
        robots: int = 2,
    ) -> Schedule: ...

class CyclicPlan:
    """The plan of a continuous cell: ``N`` robots repeating the task, one operator, one task
    per robot every period ``period_s``. Times in s from period 0's start; robots and
    stretches 0-based; ``m`` low-confidence stretches per task. Assumes the operator follows
    the demonstrated mean speed; not yet margin-checked across cycles."""

    @property
    def n_robots(self) -> int: ...
    @property
    def tick_s(self) -> Optional[float]:
        """The cell's control tick it was checked at (a planner's plan), else ``None``."""
    @property
    def period_s(self) -> float:
        """The period ``P`` (s), exact for :attr:`order`."""
    @property
    def tasks_per_hour(self) -> float:
        """``3600·N / P``."""
    @property
    def operator_share(self) -> float:
        """The operator's busy share ``N·L / P`` in ``[0, 1]``."""
    @property
    def lower_bound_s(self) -> float:
        """A lower bound (s) on the period of every order: ``max(N·(L + I), D_min)``."""
    @property
    def gap(self) -> float:
        """``period_s / lower_bound_s − 1``."""
    @property
    def order_exhaustive(self) -> bool:
        """Whether every operator order was searched."""
    @property
    def orders_evaluated(self) -> int: ...
    @property
    def order(self) -> List[Tuple[int, int]]:
        """The operator's cyclic order: ``N·m`` pairs ``(robot, stretch)``, 0-based."""
    @property
    def lc_s(self) -> F64:
        """``(m,)`` stretch durations at ``ψ̇̄`` (s)."""
    @property
    def start_s(self) -> F64:
        """``(N,)`` each robot's task start in period 0 (s, in ``[0, P)``)."""
    @property
    def lc_start_s(self) -> F64:
        """``(N, m)`` when each robot enters each stretch of that task (s; may exceed ``P``)."""
    @property
    def gap_duration_s(self) -> F64:
        """``(N, m + 1)`` planned gap durations (head, between stretches, tail), waits included (s)."""
    @property
    def gap_wait_s(self) -> F64:
        """``(N, m + 1)`` the part of each gap spent waiting at its hold (s)."""
    @property
    def gap_hold(self) -> List[Optional[int]]:
        """``m + 1`` entries: each gap's hold point (reference sample) or ``None``."""
    @property
    def start_wait_s(self) -> F64:
        """``(N,)`` each robot's wait at its task start before the next task (s)."""
    def coordinator(
        self, problem: Problem, tick_s: Optional[float] = None
    ) -> ContinuousCoordinator:
        """The continuous coordinator running this plan on ``problem`` (the problem it was
        planned for) at ``tick_s`` real s (default :attr:`tick_s`, else ``problem.dt_s``); ``ScheduleError``
        (``violation == "NotRunnable"``) for an order the token rule cannot run."""
    def is_runnable(self, problem: Problem) -> bool:
        """Whether :meth:`coordinator` can run this plan's order on ``problem``."""
    def to_json(self) -> str:
        """The plan as ``tandem schedule --cell continuous --json`` prints it."""

def cyclic_plan(
    problem: Problem,
    robots: int = 2,
    max_enumerated: Optional[int] = None,
    *,
    runnable_only: bool = True,
    order: Optional[Sequence[Tuple[int, int]]] = None,
    tick_s: Optional[float] = None,
) -> CyclicPlan:
    """The cyclic plan of ``robots`` robots on ``problem`` (every order searched up to
    ``max_enumerated``, default 100 000; a local search beyond); ``runnable_only``: only
    orders :meth:`CyclicPlan.coordinator` can run; ``order``: the plan of that order, no
    search; ``tick_s``: the control tick of the cell that will run it, to count the token
    rule's hand-overs (:meth:`Planner.cyclic_plan` uses the planner's)."""

class ContinuousCoordinator:
    """The Rust run-time coordinator of a continuous cell (the token rule), one control tick
    per call; from :meth:`CyclicPlan.coordinator` or :meth:`Planner.continuous_coordinator`."""

    def tick(
        self,
        operator: Union[None, float, str, Sequence[Union[None, float, str]]] = None,
    ) -> CellTick:
        """One tick; ``operator``: None, a gradient, ``"fastest"``, ``"slowest"``; with
        :attr:`operators` M > 1 a list of M of them, one per operator."""
    @property
    def operators(self) -> int: ...
    def reset(self) -> None: ...
    @property
    def fault(self) -> Optional[Dict[str, Any]]:
        """``{"tick", "low_conf", "stopped"}`` once two robots were low-confidence in a tick."""
    def clear_fault(self) -> None: ...
    @property
    def n_robots(self) -> int: ...
    @property
    def tick_s(self) -> float: ...
    @property
    def ticks(self) -> int: ...
    @property
    def task_s(self) -> float:
        """One task on the fastest warp (s of schedule clock), without waits."""
    @property
    def tasks_completed(self) -> I64:
        """``(N,)`` tasks each robot has completed."""
    @property
    def clock_s(self) -> F64:
        """``(N,)`` each robot's schedule clock in its current task (s)."""
    @property
    def ref_time_now(self) -> F64: ...
    @property
    def sample_now(self) -> List[int]: ...
    @property
    def low_conf_now(self) -> Bool: ...
    @property
    def token(self) -> Optional[Tuple[int, int]]:
        """``(robot, group)`` that may go through its group now, or ``None``."""
    @property
    def token_position(self) -> Tuple[int, int]:
        """``(index into tokens, completed passes)``."""
    @property
    def tokens(self) -> List[Tuple[int, int]]: ...
    @property
    def groups(self) -> List[Dict[str, int]]:
        """Per group ``{"gate", "first_lc", "end_lc", "ref_start", "ref_end"}``."""

class CellTick:
    """What one continuous tick did, per robot."""

    @property
    def ref_time(self) -> F64: ...
    @property
    def tasks(self) -> I64: ...
    @property
    def low_conf(self) -> Bool: ...
    @property
    def running(self) -> Bool: ...
    @property
    def at_gate(self) -> Bool: ...
    @property
    def overlap(self) -> bool: ...
    @property
    def operator(self) -> List[Optional[int]]:
        """Each robot's operator (0-based) when low-confidence, else ``None``."""
    @property
    def fault(self) -> Optional[Dict[str, Any]]: ...
    @property
    def next(self) -> Optional[Dict[str, Any]]:
        """The pre-alert: ``{"robot", "earliest_s", "latest_s"}`` or ``None``."""

class Console:
    """The operator's console of your own control loop: a local web page at ``url``."""

    def __init__(
        self,
        controller: Union[Coordinator, ContinuousCoordinator],
        port: int = 0,
        host: str = "127.0.0.1",
        lead_s: Optional[float] = None,
        max_hz: float = 30.0,
        horizon_s: float = 90.0,
    ) -> None:
        """Starts the server; ``InputError``/``ParamError`` for a bad argument or a taken port."""
    @property
    def url(self) -> str: ...
    @property
    def port(self) -> int: ...
    def apply(self, controller: Union[Coordinator, ContinuousCoordinator]) -> bool:
        """Applies the operator's controls at a tick boundary; ``False`` while paused."""
    def publish(
        self,
        tick: Union[Tick, CellTick],
        controller: Union[Coordinator, ContinuousCoordinator],
        corrected: Optional[bool] = None,
    ) -> None:
        """Hands the state after ``tick`` to the page (never blocks); ``corrected``: whether
        this tick's input was a correction (the strip counts them; ``None``: not reported)."""
    def round_done(self) -> None: ...
    @property
    def paused(self) -> bool: ...
    @property
    def published(self) -> int: ...
    @property
    def running(self) -> bool: ...
    def close(self) -> None: ...
    def __enter__(self) -> "Console": ...
    def __exit__(self, *args: Any) -> bool: ...

class Schedule:
    """Execution warps ``(N, T_ref)``, ``N − 1`` start offsets and the control tick."""

    def __init__(
        self, problem: Problem, gradients: ArrayLike, offsets: ArrayLike, tick_s: float
    ) -> None: ...
    @property
    def n_robots(self) -> int: ...
    @property
    def offsets(self) -> F64:
        """``(N − 1,)`` s: ``τ`` of robots 2…N."""
    @property
    def starts_s(self) -> F64: ...
    @property
    def gradients(self) -> F64:
        """``ψ̇_Ei(n)``, ``(N, T_ref)``."""
    @property
    def tick_s(self) -> float: ...
    @property
    def dt_s(self) -> float: ...
    @property
    def t_total_s(self) -> float:
        """Eq. 13, s."""
    @property
    def holds(self) -> List[List[Dict[str, Any]]]:
        """Per robot its holds: ``{"ref_idx", "dwell_s", "after": [(robot, ref_idx), …]}``."""
    @property
    def dwells_s(self) -> F64:
        """Planned waiting at hold points per robot, ``(N,)``, s."""
    @property
    def durations_s(self) -> F64: ...
    @property
    def ends_s(self) -> F64: ...
    @property
    def lc_intervals(self) -> List[F64]:
        """Per robot ``(k_i, 2)`` ``[start_s, end_s)`` global time (Eq. 19)."""
    @property
    def lc_ref_intervals(self) -> List[I64]: ...
    @property
    def source(self) -> str: ...
    @property
    def stats(self) -> Optional[Dict[str, int]]: ...
    @property
    def lower_bound_s(self) -> Optional[float]: ...
    @property
    def gap(self) -> Optional[float]: ...
    @property
    def problem(self) -> Problem: ...
    def validate(self) -> None:
        """Raises ScheduleError for the first broken constraint of Eq. 20."""
    def ref_time(self, t_global_s: float) -> F64:
        """Eq. 15, ``(N,)``."""
    def conf_at(self, t_global_s: float) -> Bool:
        """Eq. 16, ``(N,)``."""
    def to_json(self) -> str: ...
    @staticmethod
    def from_json(problem: Problem, text: str) -> Schedule: ...

class Coordinator:
    """The Rust real-time coordinator of a schedule (§II-B5), one control tick per call."""

    def __init__(self, schedule: Schedule, max_busy_share: float = 1.0) -> None:
        """Raises ``ScheduleError`` for a schedule of your own not yet ``validate()``d,
        ``ParamError`` for ``max_busy_share`` not in (0, 1]."""
    @property
    def max_busy_share(self) -> float:
        """The operator's load cap ``u`` kept at run time (1: none)."""
    @property
    def switch_ticks(self) -> int: ...
    def busy_ticks(self, operator: int = 0) -> Optional[int]:
        """The round's busy ticks ``B`` of ``operator`` (``None`` without a cap)."""
    @property
    def rest_ticks(self) -> int:
        """The rest (ticks) after the round that keeps ``B ≤ u·(ticks + rest)``."""
    @property
    def rest_s(self) -> float:
        """``rest_ticks`` in seconds: sleep it before the next round."""
    def tick(
        self,
        operator: Union[None, float, str, Sequence[Union[None, float, str]]] = None,
    ) -> Tick:
        """One tick; ``operator``: None, a gradient, ``"fastest"``, ``"slowest"``; with
        :attr:`operators` M > 1 a list of M of them, one per operator."""
    @property
    def operators(self) -> int: ...
    def reset(self) -> None: ...
    @property
    def fault(self) -> Optional[Dict[str, Any]]:
        """``{"tick", "low_conf", "stopped"}`` once two robots were low-confidence in a tick."""
    def clear_fault(self) -> None: ...
    @property
    def is_finished(self) -> bool: ...
    @property
    def n_robots(self) -> int: ...
    @property
    def tick_s(self) -> float: ...
    @property
    def clock_s(self) -> F64: ...
    @property
    def starts_s(self) -> F64: ...
    @property
    def ends_s(self) -> F64: ...
    @property
    def running_now(self) -> Bool: ...
    @property
    def low_conf_now(self) -> Bool: ...
    @property
    def ref_time_now(self) -> F64: ...
    @property
    def sample_now(self) -> List[int]: ...

class Tick:
    """What one tick did, per robot."""

    @property
    def ref_time(self) -> F64: ...
    @property
    def low_conf(self) -> Bool: ...
    @property
    def running(self) -> Bool: ...
    @property
    def overlap(self) -> bool: ...
    @property
    def operator(self) -> List[Optional[int]]:
        """Each robot's operator (0-based) when low-confidence, else ``None``."""
    @property
    def fault(self) -> Optional[Dict[str, Any]]: ...
    @property
    def next(self) -> Optional[Dict[str, Any]]:
        """The pre-alert: ``{"robot", "earliest_s", "latest_s"}`` or ``None``."""

class Warp:
    """A time warp from reference samples to query samples."""

    @property
    def values(self) -> F64: ...
    @property
    def gradient(self) -> F64: ...
    @property
    def objective(self) -> float: ...
    @property
    def n_ref(self) -> int: ...
    def eval(self, ref_time: float) -> float: ...
    def inverse(self, query_time: float) -> float: ...

class StudyTask:
    """The fitted task of a study (model and reference labels)."""

    @property
    def n_ref(self) -> int: ...
    @property
    def alignment_s(self) -> float: ...

def study_config(config: Params = None) -> Dict[str, Any]: ...
def study_prepare(config: Params = None, demos_dir: Optional[Path] = None) -> StudyTask: ...
def study_run(
    task: StudyTask, config: Params = None, threads: Optional[int] = None
) -> Tuple[Dict[str, Any], List[Dict[str, Any]], Dict[str, float]]: ...
def study_run_trial(
    task: StudyTask, config: Params, trial: int
) -> Tuple[Dict[str, Any], Dict[str, float]]: ...
def study_run_cell_trial(
    task: StudyTask, config: Params, trial: int
) -> Tuple[Dict[str, Any], Dict[str, float]]: ...
def sim_run_round(
    planner: Planner,
    needs: ArrayLike,
    seed: int,
    operator: Optional[Mapping[str, Any]] = None,
) -> Dict[str, Any]: ...
def sim_sanding_needs(
    labels: List[Path],
    seed: int,
    task: Optional[Mapping[str, Any]] = None,
    robots: int = 2,
    planner: Optional[Planner] = None,
) -> Bool: ...
def sim_needs(
    n_ref: int,
    dt_s: float,
    robots: int,
    seed: int,
    regions: Optional[List[Tuple[float, float, float]]] = None,
    levels: Optional[List[float]] = None,
    need_file: Optional[str] = None,
) -> Bool: ...
def sim_correction_input(
    planner: Planner, ref_time: float, force_channel: str = "force", gain: float = ...
) -> Optional[F64]: ...
