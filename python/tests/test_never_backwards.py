"""A robot never moves backwards (docs/decisions.md): the issue-38 witness, a two-robot
dispensing task of a user's own with five holds per robot, planned dwells and release rules at
a 5 ms tick (the state file is the Rust test's copy,
``crates/tandem-sim/tests/data/backwards_at_hold.tandem``). Before the fix, ticking its
Coordinator with a constant operator input moved a robot's reference time backwards in 8 ticks
(up to 73 samples), and the guide's control loop logged a reference time that
``record_round`` refused."""

from __future__ import annotations

import numpy as np
import pytest

import tandem

from conftest import ROOT

WITNESS = ROOT / "crates" / "tandem-sim" / "tests" / "data" / "backwards_at_hold.tandem"


@pytest.fixture(scope="module")
def witness() -> tandem.Planner:
    return tandem.Planner.load(WITNESS)


@pytest.mark.parametrize("operator", [None, "slowest", "fastest", 0.8])
def test_no_robot_moves_backwards_for_a_constant_operator(witness, operator):
    coordinator = tandem.Coordinator(witness.schedule)
    previous = coordinator.ref_time_now.copy()
    clock = coordinator.clock_s.copy()
    ticks = 0
    while not coordinator.is_finished:
        tick = coordinator.tick(operator)
        ticks += 1
        now = coordinator.ref_time_now
        assert np.all(now >= previous), (ticks, previous, now)
        assert np.all(coordinator.clock_s >= clock), (ticks, clock, coordinator.clock_s)
        # The tick reports where the coordinator says the robot is.
        assert np.array_equal(tick.ref_time, now)
        assert coordinator.sample_now == [
            min(int(t), witness.model.n_ref - 1) for t in now
        ]
        previous, clock = now.copy(), coordinator.clock_s.copy()
    assert ticks > 1000
    assert coordinator.ref_time_now.tolist() == [witness.model.n_ref] * 2


def test_the_guide_s_control_loop_records_its_round(witness):
    """The guide's loop (docs/guide.md) without operator input: each running robot logs its
    command at ``ref_time_now``; robots at a hold do not run and log nothing; the round is
    accepted."""
    planner = tandem.Planner.load(WITNESS)
    coordinator = tandem.Coordinator(planner.schedule)
    last = planner.model.n_ref - 1
    logs = [{"x": [], "ref": []} for _ in range(planner.n_robots)]
    while not coordinator.is_finished:
        ref = np.minimum(coordinator.ref_time_now, last)
        for i in np.flatnonzero(coordinator.running_now):
            logs[i]["x"].append(planner.command(ref[i])[:-1])
            logs[i]["ref"].append(ref[i])
        coordinator.tick(None)
    for log in logs:
        assert np.all(np.diff(log["ref"]) >= 0.0)
    report = planner.record_round(
        executions=[np.array(log["x"]) for log in logs],
        ref_time_logs=[np.array(log["ref"]) for log in logs],
        supervised=[np.zeros(len(log["ref"]), dtype=bool) for log in logs],
        corrected=[np.zeros(len(log["ref"]), dtype=bool) for log in logs],
    )
    assert report["t_total_s"] > 0.0
