"""tandem: coordinated multi-robot shared autonomy (Hagenow et al., RA-L 2023).

One operator, several robots doing the same task in parallel. tandem learns the task from
expert demonstrations, learns from the operator's past corrections *when* each robot may need
help, and schedules the robots so that at most one is ever low-confidence, robust to the
timing changes the operator's corrections cause. This package is the Rust implementation with
NumPy arrays in and out (docs/python.md):

- :func:`fit` → :class:`Planner` (the paper's Fig. 2 loop): :attr:`Planner.model`,
  :attr:`Planner.confidence`, :attr:`Planner.schedule`, :meth:`Planner.record_round`,
  :meth:`Planner.reschedule`, :meth:`Planner.save` / :meth:`Planner.load` (the command
  line's state file), :meth:`Planner.command` (Eq. 7).
- :func:`fit_cell` → :class:`CellPlanner`: different tasks on different robots (one planner
  per task, one rounds schedule; the command line's ``fit --task … --robots …`` state file).
- :meth:`Planner.cyclic_plan` / :func:`cyclic_plan` → :class:`CyclicPlan`: the plan of a
  continuous cell (no rounds): its period, throughput, the operator's order and busy share.
- :class:`Coordinator`: the real-time coordinator of a schedule (§II-B5), one control tick
  per :meth:`Coordinator.tick`.
- :class:`ContinuousCoordinator`: the run-time coordinator of a continuous cell (the token
  rule), from :meth:`CyclicPlan.coordinator` or :meth:`Planner.continuous_coordinator`, one
  control tick per :meth:`ContinuousCoordinator.tick` (a :class:`CellTick`).
- :meth:`Planner.plan` / :meth:`Planner.controller` with ``cell="rounds"`` or
  ``"continuous"``: the plan of either kind of cell and its run-time coordinator (a
  :class:`Controller`), both at the schedule's control tick.
- :class:`Console`: the operator's console (a local web page: which robot needs the operator
  now, the coordinator's pre-alert of the next) fed by your own loop: :meth:`Console.apply`
  the operator's controls at each tick boundary, :meth:`Console.publish` each tick.
- :mod:`tandem.study`: the simulated study of §III; :mod:`tandem.sim`: its workcell.
- :func:`align`: GDTW time warping (Eq. 2–3).
- :func:`read_bag`: a ROS 2 bag (rosbag2 MCAP) on one grid; :func:`fit` takes ``.mcap`` paths.

Every error is a :class:`TandemError`: :class:`InputError`, :class:`ParamError`,
:class:`StateFileError`, :class:`ScheduleError`, :class:`InternalError`. Data taken in but
not as given (a period assumed for a file without time column, a resampled execution, a
demonstration of unusual length) raises a :class:`DataWarning`.
"""

import abc

from ._tandem import (
    MAX_ROBOTS,
    N_ROBOTS,
    CellPlanner,
    CellTick,
    Confidence,
    Console,
    ContinuousCoordinator,
    Coordinator,
    CyclicPlan,
    DataWarning,
    InputError,
    InternalError,
    Model,
    Observations,
    ParamError,
    Planner,
    Problem,
    Schedule,
    ScheduleError,
    StateEdit,
    StateFileError,
    TandemError,
    Tick,
    Warp,
    __version__,
    align,
    cyclic_plan,
    default_params,
    fit,
    fit_cell,
    fit_model,
    read_bag,
)
from . import sim, study


class Controller(abc.ABC):
    """The run-time coordinator of a cell of either kind, as :meth:`Planner.controller` gives
    it: a :class:`Coordinator` (rounds) or a :class:`ContinuousCoordinator` (a continuous
    cell); both are registered as its subclasses, so ``isinstance(c, tandem.Controller)``
    holds for either. What they share: :meth:`tick` (one control tick of :attr:`tick_s` real
    seconds, the operator's input for the low-confidence robot), :meth:`reset`,
    :attr:`fault` and :meth:`clear_fault`, :attr:`n_robots`, :attr:`clock_s`,
    :attr:`ref_time_now`, :attr:`sample_now` and :attr:`low_conf_now`.
    """

    __slots__ = ()


Controller.register(Coordinator)
Controller.register(ContinuousCoordinator)

__all__ = [
    "MAX_ROBOTS",
    "N_ROBOTS",
    "CellPlanner",
    "CellTick",
    "Confidence",
    "Console",
    "ContinuousCoordinator",
    "Controller",
    "Coordinator",
    "CyclicPlan",
    "DataWarning",
    "InputError",
    "InternalError",
    "Model",
    "Observations",
    "ParamError",
    "Planner",
    "Problem",
    "Schedule",
    "ScheduleError",
    "StateEdit",
    "StateFileError",
    "TandemError",
    "Tick",
    "Warp",
    "__version__",
    "align",
    "cyclic_plan",
    "default_params",
    "fit",
    "fit_cell",
    "fit_model",
    "read_bag",
    "sim",
    "study",
]
