"""The simulated study of the paper's §III (Fig. 5), as ``cargo xtask study`` runs it.

A trial starts from the demonstrations, schedules, runs a round (one execution of each of the
``N`` robots, a pair in the paper) in the simulated workcell (:mod:`tandem.sim`), records it
(Eq. 21), re-schedules, and so on for ``executions / N`` rounds. Iteration ``k`` is the schedule
made after ``k`` recorded rounds (iteration 0: demonstrations only) with the outcome of running
the next round under it (``"pair"`` in each iteration of ``study.json``, the files' name).

The configuration is the one of ``fixtures/study.toml`` (``tandem::study::StudyConfig``): a
dict, the path of such a TOML file, or ``None`` for the paper's study (5 trials × 300
executions, 5000 samples per schedule). Trial ``k`` depends only on ``(seed, k)``, so
:func:`run_trial` gives exactly trial ``k`` of :func:`run`, on any machine and thread count —
which is what lets a sweep spread trials over a cluster (``examples/python/sweep_dask.py``).

The demonstrations: a folder with the layout of ``fixtures/sanding/`` (``demo_<i>.csv`` and
``demo_<i>.labels.csv``; ``cargo xtask study`` reads that folder), or, with ``demos_dir=None``,
the same six demonstrations generated in memory by the task generator with the fixtures' seed
(the committed CSV files round them to 6 decimals, so results differ slightly from the
folder's). The fitted task is cached per process, keyed by the folder and the ``fit`` and
``task`` parameters.
"""

from __future__ import annotations

import functools
import json
import warnings
from os import PathLike, fspath
from typing import Any, Dict, List, Mapping, Optional, Union

import numpy as np

from ._tandem import (
    StudyTask,
    study_config,
    study_prepare,
    study_run,
    study_run_cell_trial,
    study_run_trial,
)

__all__ = [
    "CellTrialResult",
    "StudyResult",
    "TrialResult",
    "default_config",
    "run",
    "run_cell_trial",
    "run_trial",
]

Config = Union[None, Mapping[str, Any], str, PathLike]

_ROUND_FIELDS = (
    "overlap_ticks",
    "operator_idle_share",
    "duration_s",
    "supervised_ticks",
    "corrected_ticks",
)


def default_config() -> dict:
    """The paper's study as a dict (every key of ``fixtures/study.toml`` with its default)."""
    return study_config(None)


def _normalized(config: Config) -> dict:
    """The configuration with every default filled in, checked (raises ParamError)."""
    return study_config(config)


@functools.lru_cache(maxsize=4)
def _task(demos_dir: Optional[str], fit_json: str, task_json: str) -> StudyTask:
    config = {"planner": {"fit": json.loads(fit_json)}, "task": json.loads(task_json)}
    return study_prepare(config, demos_dir)


def _prepared(config: dict, demos_dir: Union[None, str, PathLike]) -> StudyTask:
    return _task(
        None if demos_dir is None else fspath(demos_dir),
        json.dumps(config["planner"]["fit"], sort_keys=True),
        json.dumps(config["task"], sort_keys=True),
    )


class TrialResult:
    """One trial: its seed and every iteration, as arrays.

    Attributes:
        trial: the trial index ``k``.
        seed: the trial's seed, derived from ``(config seed, k)``.
        data: the trial as a dict (the ``trials[k]`` entry of ``study.json``).
        iteration: ``(n_rounds + 1,)`` int: rounds recorded before each schedule.
        t_total_s: ``(n_rounds + 1,)`` planned ``T_total`` (Eq. 13, s).
        offset_s: ``(n_rounds + 1,)`` planned offset ``τ`` of robot 2 (s).
        high_conf_pct: ``(n_rounds + 1,)`` percent of high-confidence reference samples.
        source: where each schedule came from (``sampled``, ``completed``, ``previous``, ``repaired``,
            ``serial``).
        lc_intervals_s: per iteration, a list of one ``(k_i, 2)`` array per robot: planned
            low-confidence intervals ``[start, end)`` in s of global time.
        overlap_ticks, operator_idle_share, duration_s, supervised_ticks, corrected_ticks:
            ``(n_rounds,)`` arrays, what running the round under each schedule gave (the last
            schedule is not run).
    """

    def __init__(self, data: Mapping[str, Any]) -> None:
        self.data = dict(data)
        self.trial: int = data["trial"]
        self.seed: int = data["seed"]
        its = data["iterations"]
        self.iteration = np.array([r["iteration"] for r in its], dtype=np.int64)
        self.t_total_s = np.array([r["t_total_s"] for r in its], dtype=np.float64)
        self.offset_s = np.array([r["offset_s"] for r in its], dtype=np.float64)
        self.high_conf_pct = np.array([r["high_conf_pct"] for r in its], dtype=np.float64)
        self.source: List[str] = [r["source"] for r in its]
        self.lc_intervals_s = [
            [np.array(robot, dtype=np.float64).reshape(-1, 2) for robot in r["lc_intervals_s"]]
            for r in its
        ]
        rounds = [r["pair"] for r in its if r["pair"] is not None]
        for name in _ROUND_FIELDS:
            dtype = np.float64 if name in ("operator_idle_share", "duration_s") else np.int64
            setattr(self, name, np.array([p[name] for p in rounds], dtype=dtype))

    @property
    def n_rounds(self) -> int:
        """Rounds run in the trial (one execution of each robot each)."""
        return len(self.overlap_ticks)

    @property
    def n_pairs(self) -> int:
        """Deprecated (kept one release): :attr:`n_rounds` under its two-robot name; emits a
        ``DeprecationWarning``."""
        warnings.warn(
            "TrialResult.n_pairs is deprecated: use TrialResult.n_rounds (a round is one "
            "execution of each robot)",
            DeprecationWarning,
            stacklevel=2,
        )
        return self.n_rounds

    def to_dict(self) -> dict:
        """The trial as a dict (JSON-compatible)."""
        return dict(self.data)

    def to_pandas(self) -> Any:
        """One row per iteration (``iteration``, ``t_total_s``, ``offset_s``,
        ``high_conf_pct``, ``source`` and the round columns, NaN for the last iteration).
        Needs pandas."""
        pd = _pandas()
        frame = pd.DataFrame(
            {
                "trial": self.trial,
                "iteration": self.iteration,
                "t_total_s": self.t_total_s,
                "offset_s": self.offset_s,
                "high_conf_pct": self.high_conf_pct,
                "source": self.source,
            }
        )
        for name in _ROUND_FIELDS:
            values = getattr(self, name).astype(np.float64)
            frame[name] = np.append(values, np.nan)
        return frame

    def __repr__(self) -> str:
        return (
            f"TrialResult(trial={self.trial}, rounds={self.n_rounds}, "
            f"t_total_s {self.t_total_s[0]:.1f} -> {self.t_total_s[-1]:.1f})"
        )


class StudyResult:
    """The whole study.

    Attributes:
        data: everything as a dict: the content of ``study.json`` (``config``, ``n_ref``,
            ``dt_s``, ``ground_truth_pct``, ``trials``).
        config: the configuration it ran with (every key).
        trials: one :class:`TrialResult` per trial.
        summary: per iteration across trials (Fig. 5): ``iteration``, ``t_total_mean_s``,
            ``t_total_std_s`` (sample standard deviation, 0 for one trial),
            ``high_conf_pct_mean``, ``high_conf_pct_std``, ``overlap_ticks``; arrays of
            shape ``(n_rounds + 1,)``.
        phase_times: wall time (s) per phase summed over trials: ``alignment_s``,
            ``model_update_s``, ``confidence_s``, ``scheduling_s``, ``simulation_s``.
        ground_truth_pct: percent of reference samples that never need the operator.
        t_total_s, high_conf_pct, offset_s: ``(n_trials, n_rounds + 1)`` arrays.
    """

    def __init__(
        self,
        data: Mapping[str, Any],
        summary: List[Mapping[str, Any]],
        phase_times: Dict[str, float],
    ) -> None:
        self.data = dict(data)
        self.config: dict = data["config"]
        self.n_ref: int = data["n_ref"]
        self.dt_s: float = data["dt_s"]
        self.ground_truth_pct: float = data["ground_truth_pct"]
        self.trials = [TrialResult(t) for t in data["trials"]]
        self.summary = {
            key: np.array([row[key] for row in summary])
            for key in (summary[0].keys() if summary else ())
        }
        self.phase_times = dict(phase_times)
        self.t_total_s = np.stack([t.t_total_s for t in self.trials])
        self.high_conf_pct = np.stack([t.high_conf_pct for t in self.trials])
        self.offset_s = np.stack([t.offset_s for t in self.trials])

    @property
    def total_overlap_ticks(self) -> int:
        """Ticks with two robots low-confidence over every round of every trial (must be 0)."""
        return int(sum(int(t.overlap_ticks.sum()) for t in self.trials))

    def to_dict(self) -> dict:
        """The study as a dict (the content of ``study.json``)."""
        return dict(self.data)

    def to_pandas(self) -> Any:
        """One row per trial and iteration (as :meth:`TrialResult.to_pandas`). Needs pandas."""
        pd = _pandas()
        return pd.concat([t.to_pandas() for t in self.trials], ignore_index=True)

    def __repr__(self) -> str:
        last = self.t_total_s[:, -1]
        return (
            f"StudyResult(trials={len(self.trials)}, final t_total_s "
            f"{last.mean():.1f} ± {last.std(ddof=1) if len(last) > 1 else 0.0:.1f}, "
            f"overlap_ticks={self.total_overlap_ticks})"
        )


def _pandas() -> Any:
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("to_pandas() needs pandas (pip install pandas)") from e
    return pandas


def run(
    config: Config = None,
    demos_dir: Union[None, str, PathLike] = None,
    threads: Optional[int] = None,
) -> StudyResult:
    """Runs the study: every trial, in parallel on ``threads`` threads (default: all cores;
    the result does not depend on the number). The GIL is released while it runs.

    Raises:
        ParamError: a bad configuration key or value.
        InputError: a bad demonstration or labels file in ``demos_dir``.
    """
    cfg = _normalized(config)
    data, summary, times = study_run(_prepared(cfg, demos_dir), cfg, threads)
    return StudyResult(data, summary, times)


def run_trial(
    config: Config,
    trial: int,
    demos_dir: Union[None, str, PathLike] = None,
) -> TrialResult:
    """Runs trial ``trial`` of the study alone (seeded by ``(seed, trial)`` only, so it is
    exactly that trial of :func:`run`, wherever it runs)."""
    cfg = _normalized(config)
    data, _times = study_run_trial(_prepared(cfg, demos_dir), cfg, trial)
    return TrialResult(data)


class CellTrialResult:
    """One trial of the continuous study (``config["cell"] = "continuous"``): ``N`` robots and
    ``M`` operators, each robot starting its next task as soon as the operators' order
    allows, the plan re-made every ``N`` completed tasks.

    Attributes:
        data: the trial's record as a dict (``study.json``'s ``result.trials[k]`` of
            ``cargo xtask study --cell continuous``): ``iterations`` (the plans), ``completions``
            (every task), ``stats``, ``steady``.
        trial, seed: the trial's index and seed.
        steady_tasks_per_h: tasks per hour of the whole cell over the steady window (the last
            10 % of the tasks, whole periods).
        steady_busy_share: share of the window's ticks in which a robot was low-confidence.
        steady_wait_share: share of the robots' time in the window spent waiting at gates.
        tasks: tasks completed.
        ticks, overlap_ticks, faults: the cell's control ticks, the ticks with more robots
            low-confidence than operators (must be 0) and the faults latched (must be 0).
        plan_tasks_per_h, plan_bound_tasks_per_h: the last plan's throughput and its bound
            (``3600·N / lower_bound_s``).
        high_conf_pct: ``(n_plans,)`` array, percent of high-confidence samples of each plan.
    """

    def __init__(self, data: Mapping[str, Any]) -> None:
        self.data = dict(data)
        self.trial: int = data["trial"]
        self.seed: int = data["seed"]
        steady = data["steady"]
        stats = data["stats"]
        self.steady_tasks_per_h: float = float(steady["throughput_per_h"])
        self.steady_busy_share: float = float(steady["operator_busy_share"])
        self.steady_wait_share: float = float(steady["robot_wait_share"])
        self.tasks: int = len(data["completions"])
        self.ticks: int = int(stats["ticks"])
        self.overlap_ticks: int = int(stats["overlap_ticks"])
        self.faults: int = int(stats["faults"])
        its = data["iterations"]
        self.plan_tasks_per_h: float = float(its[-1]["tasks_per_hour"])
        period, bound = its[-1]["period_s"], its[-1]["lower_bound_s"]
        self.plan_bound_tasks_per_h: float = (
            float(its[-1]["tasks_per_hour"]) * period / bound if bound > 0 else float("nan")
        )
        self.high_conf_pct = np.array([r["high_conf_pct"] for r in its], dtype=np.float64)

    def to_dict(self) -> dict:
        """The trial as a dict (JSON-compatible)."""
        return dict(self.data)

    def __repr__(self) -> str:
        return (
            f"CellTrialResult(trial={self.trial}, tasks={self.tasks}, "
            f"steady {self.steady_tasks_per_h:.1f} tasks/h, overlap_ticks={self.overlap_ticks})"
        )


def run_cell_trial(
    config: Config,
    trial: int,
    demos_dir: Union[None, str, PathLike] = None,
) -> CellTrialResult:
    """Runs trial ``trial`` of the continuous study alone (``config["cell"]`` must be
    ``"continuous"``; seeded by ``(seed, trial)`` only, so it is exactly that trial of
    ``cargo xtask study --cell continuous``, wherever it runs: a sweep over robots, operators
    and switch times spreads such trials over a cluster, ``examples/python/sweep_fleet_dask.py``).

    Raises:
        ParamError: a bad configuration key or value, or a configuration of rounds.
        InputError: a bad demonstration or labels file in ``demos_dir``.
    """
    cfg = _normalized(config)
    data, _times = study_run_cell_trial(_prepared(cfg, demos_dir), cfg, trial)
    return CellTrialResult(data)
