"""Hold points from Python on a task of its own (a pick-and-place with a gripper channel):
``tandem.fit(holds=...)`` resolves times and rules as ``tandem fit --hold-at/--hold-where``,
bad holds raise ``ParamError`` naming them, and the schedule's holds are exposed."""

from __future__ import annotations

import numpy as np
import pytest

import tandem

DT_S = 0.05
CHANNELS = ["x", "z", "force", "gripper"]


def demo(i: int) -> np.ndarray:
    """6 s: approach, grasp (contact force differs per demonstration), carry with the gripper
    closed, place (force differs), retreat; channels ``CHANNELS``."""
    grasp_n = [5.0, 8.0, 11.0, 14.0][i]
    place_n = [12.0, 6.0, 9.0, 3.0][i]
    rows = []
    for k in range(120):
        t = k * DT_S
        down = lambda s: 0.2 * (1.0 - np.sin(np.pi * min(max(s, 0.0), 1.0)))  # noqa: E731
        if t < 0.5:
            rows.append([0.3 * t / 0.5, down(t), 0.0, 0.0])
        elif t < 1.5:
            rows.append([0.3, 0.0, grasp_n, 0.0 if t < 1.0 else 1.0])
        elif t < 4.0:
            s = (t - 1.5) / 2.5
            rows.append([0.3 + 0.5 * s, down(0.5 + 0.5 * s), 0.0, 1.0])
        elif t < 5.0:
            rows.append([0.8, 0.0, place_n, 1.0 if t < 4.5 else 0.0])
        else:
            rows.append([0.8, down(0.5 * (t - 5.0)), 0.0, 0.0])
    return np.array(rows)


DEMOS = [demo(i) for i in range(4)]
PARAMS = {"sampler": {"samples": 200, "seed": 1}}


def fit(holds, robots: int = 2) -> tandem.Planner:
    return tandem.fit(
        DEMOS, channels=CHANNELS, params=PARAMS, dt_s=DT_S, robots=robots, holds=holds
    )


def test_times_and_rules_resolve_as_on_the_command_line() -> None:
    p = fit([2.0, 3.01])
    assert p.problem.holds == [40, 60]
    assert p.problem.active_holds == [40, 60]
    closed = [n for n, m in enumerate(p.model.mean) if m[3] > 0.5]
    assert fit(["gripper>0.5"]).problem.holds == closed
    # A dict is the parameter file's form; both give the same planner.
    same = fit({"at_s": [2.0, 3.01]})
    assert same.problem.holds == [40, 60]
    assert same.params["holds"] == {"at_s": [2.0, 3.01], "rules": []}


def test_no_holds_is_the_planner_of_before() -> None:
    a = tandem.fit(DEMOS, channels=CHANNELS, params=PARAMS, dt_s=DT_S)
    b = fit([])
    assert b.problem.holds == []
    assert np.array_equal(a.schedule.gradients, b.schedule.gradients)
    assert a.schedule.t_total_s == b.schedule.t_total_s


@pytest.mark.parametrize(
    "holds, says",
    [
        (["torque<3"], "no channel `torque`"),
        (["gripper=0.5"], "`=` is not a comparison"),
        (["gripper>2"], "holds nowhere"),
        ([100.0], "outside the task"),
        ([float("nan")], "finite"),
        ("gripper>0.5", "single string"),
        ([None], "holds[0]"),
    ],
)
def test_bad_holds_raise_param_error_naming_them(holds, says) -> None:
    with pytest.raises(tandem.ParamError, match=None) as e:
        fit(holds)
    assert says in str(e.value)


def test_the_schedule_exposes_its_holds() -> None:
    p = fit(["gripper>0.5"], robots=3)
    s = p.schedule
    assert len(s.holds) == 3
    assert any(s.holds)
    for robot in s.holds:
        for h in robot:
            assert set(h) == {"ref_idx", "dwell_s", "after"}
            assert h["dwell_s"] >= 0.0
            assert all(0 <= r < 3 for r, _ in h["after"])
    assert s.dwells_s.shape == (3,)
    s.validate()
