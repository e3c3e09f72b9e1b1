"""The simulated workcell of the paper's §III: run a schedule once with a simulated operator.

:func:`run_round` runs the planner's current schedule through the Rust real-time coordinator at
the schedule's tick, one control tick per reference sample period, while a simulated operator
supervises the low-confidence robot: it corrects the samples that need it (missing 1 %), and
corrects unneeded ones 1 % of the time in short episodes (``tandem_sim::workcell``). Each
correction is a joystick input along the model's correction directions that raises the force
and slows the robot (:func:`correction_input`); the rate of the resulting command (Eq. 7)
is the operator's gradient for the coordinator. The result feeds
:meth:`tandem.Planner.record_round`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from os import PathLike
from typing import Any, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from ._tandem import (
    Planner,
    sim_correction_input,
    sim_needs,
    sim_run_round,
    sim_sanding_needs,
)

__all__ = [
    "PairRun",
    "RobotRun",
    "RoundRun",
    "correction_input",
    "low_confidence_regions",
    "needs",
    "run_pair",
    "run_round",
    "sanding_needs",
]


@dataclass(frozen=True)
class RobotRun:
    """One robot's execution as the system records it (Eq. 21).

    Attributes:
        samples: ``(T, C)`` commanded samples, one per control tick the robot ran, in the
            model's channels (channel units).
        ref_time_log: ``(T,)`` fractional reference time of each sample (reference samples).
        supervised: ``(T,)`` bool: the robot was low-confidence (the operator watched).
        corrected: ``(T,)`` bool: the operator corrected (only where supervised).
        needed: supervised samples that needed a correction.
        missed: needed corrections the operator missed.
        false_corrections: corrections given where none was needed.
        hold_ticks: control ticks the robot stood at a hold point of the schedule.
    """

    samples: np.ndarray
    ref_time_log: np.ndarray
    supervised: np.ndarray
    corrected: np.ndarray
    needed: int
    missed: int
    false_corrections: int
    hold_ticks: int = 0


@dataclass(frozen=True)
class RoundRun:
    """A round of executions, one per robot, run under one schedule.

    Attributes:
        robots: one :class:`RobotRun` per robot.
        ticks: control ticks until every robot finished.
        tick_s: the control tick (s).
        overlap_ticks: ticks in which two robots traversed low-confidence samples (0 for a
            schedule that passed the margin check).
        idle_ticks: ticks in which no robot was low-confidence (the operator was free).
        duration_s: ``ticks · tick_s`` (s).
        operator_idle_share: ``idle_ticks / ticks``.
        operator_busy_share: ``1 − idle_ticks / ticks``: the share of the round's ticks in
            which some robot was low-confidence (the operator was needed).
        robot_wait_share: the share of the robots' time (robot-ticks over ``N · ticks``) in
            which they did not move along the task: waiting for their start, standing at a
            hold point, or done before the round's last robot.
    """

    robots: list
    ticks: int
    tick_s: float
    overlap_ticks: int
    idle_ticks: int
    duration_s: float
    operator_idle_share: float
    operator_busy_share: float
    robot_wait_share: float = 0.0

    def record_args(self) -> dict:
        """The keyword arguments of :meth:`tandem.Planner.record_round` (and
        :meth:`tandem.Planner.record_round`) for this run."""
        return {
            "executions": [r.samples for r in self.robots],
            "ref_time_logs": [r.ref_time_log for r in self.robots],
            "supervised": [r.supervised for r in self.robots],
            "corrected": [r.corrected for r in self.robots],
        }


#: Deprecated (kept one release): :class:`RoundRun` under its two-robot name.
PairRun = RoundRun


def run_round(
    planner: Planner,
    needs: Any,
    seed: int,
    operator: Optional[Mapping[str, Any]] = None,
) -> RoundRun:
    """Runs the planner's current schedule once in the simulated workcell (§III): one
    execution per robot (``planner.n_robots``).

    Args:
        planner: the planner whose model, problem and schedule to run.
        needs: ``(N, T_ref)`` bool array: robot ``i`` needs a correction at reference sample
            ``n`` (e.g. :func:`sanding_needs`).
        seed: seed of the operator's draws (ChaCha8); the same seed gives the same run.
        operator: the simulated operator's parameters (``miss_rate`` 0.01,
            ``false_correction_rate`` 0.01, ``false_correction_s`` 0.5 s, ``force_channel``
            ``"force"``, ``gain`` 1/3).

    Raises:
        InputError: ``needs`` of the wrong shape or dtype.
        ScheduleError: a schedule made for another tick than the reference period.
    """
    raw = sim_run_round(planner, needs, seed, operator)
    robots = [RobotRun(**r) for r in raw.pop("robots")]
    return RoundRun(robots=robots, **raw)


def run_pair(
    planner: Planner,
    needs: Any,
    seed: int,
    operator: Optional[Mapping[str, Any]] = None,
) -> RoundRun:
    """Deprecated (kept one release): :func:`run_round` under its two-robot name; emits a
    ``DeprecationWarning``."""
    warnings.warn(
        "tandem.sim.run_pair is deprecated: use tandem.sim.run_round (a round is one "
        "execution of each robot)",
        DeprecationWarning,
        stacklevel=2,
    )
    return run_round(planner, needs, seed, operator)


def sanding_needs(
    labels: Union[str, PathLike, Sequence[Union[str, PathLike]]],
    seed: int,
    task: Optional[Mapping[str, Any]] = None,
    robots: Optional[int] = None,
    planner: Optional[Planner] = None,
) -> np.ndarray:
    """Which reference samples need a correction on ``N`` random sanding workpieces (§III).

    A sample needs one when it is sanding in passes 1–3 over a painted section of the robot's
    own workpiece (half the sections of passes 1–3 are painted at random).

    The needs are per sample of the model's reference demonstration, so they come from that
    demonstration's labels: with ``planner``, the labels of the demonstration its fit chose as
    the reference (``planner.model.reference_idx``; the default reference is the medoid, which
    need not be the first file). Each demonstration of the fixtures has its own labels file,
    so every reference choice has exact ground truth (nothing is mapped through a warp).

    Args:
        labels: the ground-truth labels (CSV ``pass,section,painted,phase``, one row per
            sample): the folder with ``demo_<i>.labels.csv`` of the fixtures' layout
            (``demo_<i>`` the ``i``-th demonstration given to the fit, counted from 0), a list
            of labels files, one per demonstration in the fit's order, or the reference
            demonstration's own labels file. A folder or a list needs ``planner``.
        seed: seed of the workpieces' draw.
        task: task parameters (dict; only ``n_sections`` matters).
        robots: ``N``, one workpiece per robot (1 to 16; default: the planner's, else 2).
        planner: the planner whose model the needs are for; picks its reference's labels and
            checks that they are one per reference sample.

    Returns:
        ``(N, T_ref)`` bool array.

    Raises:
        InputError: a labels file that cannot be read, or labels that are not one per sample
            of the planner's reference (the message names the file and the demonstration).
        ParamError: a folder or a list without ``planner``, or ``robots`` out of range.
    """
    if isinstance(labels, (list, tuple)):
        files = [str(f) for f in labels]
    else:
        files = [str(labels)]
    if robots is None:
        robots = planner.n_robots if planner is not None else 2
    return sim_sanding_needs(files, seed, task, int(robots), planner)


def needs(
    regions: Optional[Sequence[Tuple[float, float, float]]] = None,
    *,
    levels: Any = None,
    need_file: Union[str, PathLike, None] = None,
    planner: Optional[Planner] = None,
    n_ref: Optional[int] = None,
    dt_s: Optional[float] = None,
    robots: Optional[int] = None,
    seed: int = 0,
) -> np.ndarray:
    """Which reference samples need the operator on ``N`` workpieces of your own task: the
    ``needs`` argument of :func:`run_round`, for any task (``tandem need`` and
    ``tandem simulate --need`` on the command line).

    Give exactly one need profile:

    * ``regions``: ``[(start_s, end_s, level), …]`` in reference seconds (sample ``n`` is at
      ``n · dt_s``; ``start_s`` inclusive, ``end_s`` exclusive; regions must not overlap):
      the workpiece needs the operator over the whole region with probability ``level``;
    * ``levels``: one probability per reference sample; every run of equal values is a region;
    * ``need_file``: a need file (the CSV ``tandem need`` writes and ``tandem simulate --need``
      reads).

    Each region is drawn once per workpiece (a defect covers its whole region or none of it):
    one uniform draw per region, robot 1 first (ChaCha8 seeded with ``seed``), in the order
    ``tandem simulate`` draws a round.

    Args:
        planner: takes ``n_ref``, ``dt_s`` and ``robots`` from it (its model and robot count).
        n_ref: ``T_ref``, reference samples (without ``planner``).
        dt_s: reference sample period (s) (without ``planner``).
        robots: ``N``, one workpiece per robot (default: the planner's, else 2).
        seed: seed of the draw.

    Returns:
        ``(N, T_ref)`` bool array.

    Raises:
        InputError: a region, level or need-file row that is unusable (the message names it).
        ParamError: not exactly one profile, or neither ``planner`` nor ``n_ref``/``dt_s``.
    """
    if planner is not None:
        n_ref = planner.model.n_ref if n_ref is None else n_ref
        dt_s = planner.model.dt_s if dt_s is None else dt_s
        robots = planner.n_robots if robots is None else robots
    if n_ref is None or dt_s is None:
        from . import ParamError

        raise ParamError("tandem.sim.needs: give planner=… or both n_ref=… and dt_s=…")
    # The reference period without floating-point noise (0.01, not 0.009999999999999998), so
    # that region bounds in printed seconds hit the samples they name.
    dt_s = round(float(dt_s), 9)
    lv = None if levels is None else [float(v) for v in np.asarray(levels, dtype=float).ravel()]
    rg = None if regions is None else [(float(a), float(b), float(p)) for a, b, p in regions]
    return sim_needs(
        int(n_ref),
        dt_s,
        2 if robots is None else int(robots),
        seed,
        regions=rg,
        levels=lv,
        need_file=None if need_file is None else str(need_file),
    )


def low_confidence_regions(planner: Planner) -> list:
    """The planner's current low-confidence regions as ``[(start_s, end_s), …]`` in reference
    seconds (``end_s`` exclusive): where the operator may be needed, the starting point of a
    need profile for :func:`needs` when you do not know yet where your task needs help."""
    dt = round(planner.model.dt_s, 9)
    return [(int(a) * dt, int(b) * dt) for a, b in planner.confidence.low_regions]


def correction_input(
    planner: Planner,
    ref_time: float,
    force_channel: str = "force",
    gain: float = 1.0 / 3.0,
) -> Optional[np.ndarray]:
    """The simulated operator's joystick input ``u`` (``(K,)``) for a correction at fractional
    reference time ``ref_time``: ``±gain`` along each correction component, the sign that
    raises ``force_channel``, without the components that would speed the robot up. ``None``
    when no component moves the force (the workcell then commands ``u = 0``).

    ``planner.command(ref_time, u)[-1]``, clamped to ``[ψ̇min, ψ̇max]`` at the robot's sample,
    is the gradient the workcell gives :meth:`tandem.Coordinator.tick`.
    """
    return sim_correction_input(planner, ref_time, force_channel, gain)
