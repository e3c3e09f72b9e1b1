"""``tandem.Coordinator`` is the Rust coordinator: driven from Python with the operator inputs
of a Rust workcell run, it reproduces that run tick for tick."""

from __future__ import annotations

import numpy as np
import pytest

import tandem
from conftest import LABELS


def replay(planner: tandem.Planner, run: tandem.sim.RoundRun) -> dict:
    """Drives a Python ``Coordinator`` through the workcell's protocol (tandem_sim::workcell,
    steps 1-5): each running robot reads its reference time, a supervised and corrected robot
    gets the rate of its command (Eq. 7) as the operator's gradient. Asserts at every tick that
    Python's reference times are the ones the Rust run logged, and counts like the workcell."""
    coord = tandem.Coordinator(planner.schedule)
    problem = planner.problem
    gmin, gmax, conf = problem.grad_min, problem.grad_max, problem.conf
    last_ref = planner.model.n_ref - 1
    k = [0] * coord.n_robots
    ticks = overlap = idle = 0
    while not coord.is_finished:
        running, ref_now = coord.running_now, coord.ref_time_now
        sample, low_now = coord.sample_now, coord.low_conf_now
        operator = None
        started_high = []
        for i in range(coord.n_robots):
            if not running[i]:
                assert not low_now[i]
                continue
            robot = run.robots[i]
            ref_time = min(ref_now[i], last_ref)
            assert ref_time == robot.ref_time_log[k[i]], (ticks, i)
            if low_now[i]:
                assert robot.supervised[k[i]], (ticks, i)
                if robot.corrected[k[i]]:
                    u = tandem.sim.correction_input(planner, ref_time)
                    rate = planner.command(ref_time, u)[-1]
                    n = sample[i]
                    operator = min(max(rate, gmin[n]), gmax[n])
            else:
                started_high.append((i, k[i], ref_now[i]))
            k[i] += 1
        tick = coord.tick(operator)
        # A tick started on high confidence is supervised after the fact exactly when the tick
        # was low-confidence and the robot crossed whole low-confidence samples inside it (the
        # samples after the start's and before the end's; docs/decisions.md, "Rounds: a
        # one-sample island is never jumped unobserved"); the operator's input did not apply.
        for i, row, t0 in started_high:
            lo = min(int(np.floor(t0)), last_ref) + 1
            hi = min(int(np.floor(tick.ref_time[i])), last_ref)
            crossed = bool(tick.low_conf[i]) and any(not conf[j] for j in range(lo, hi))
            assert run.robots[i].supervised[row] == crossed, (ticks, i)
        ticks += 1
        overlap += bool(tick.low_conf.all())
        idle += bool(not tick.low_conf.any())
    return {"ticks": ticks, "overlap": overlap, "idle": idle, "samples": k}


@pytest.mark.parametrize("seed", [21, 22])
def test_python_coordinator_reproduces_a_rust_workcell_run(
    overlapping_planner: tandem.Planner, seed: int
) -> None:
    needs = tandem.sim.sanding_needs(LABELS, seed=seed, planner=overlapping_planner)
    run = tandem.sim.run_round(overlapping_planner, needs, seed=seed)
    corrected = sum(int(r.corrected.sum()) for r in run.robots)
    assert corrected > 0, "the run exercises the operator's gradients"
    got = replay(overlapping_planner, run)
    assert got["samples"] == [len(r.ref_time_log) for r in run.robots]
    assert (got["ticks"], got["overlap"], got["idle"]) == (
        run.ticks,
        run.overlap_ticks,
        run.idle_ticks,
    )
    assert run.overlap_ticks == 0


def test_ticks_have_per_robot_arrays_and_reset_replays(overlapping_planner: tandem.Planner) -> None:
    coord = tandem.Coordinator(overlapping_planner.schedule)
    assert coord.tick_s == overlapping_planner.schedule.tick_s
    ops = ["fastest", "slowest", None, 0.9, "scheduled"]
    first = []
    while not coord.is_finished:
        t = coord.tick(ops[len(first) % len(ops)])
        assert t.ref_time.shape == (2,) and t.low_conf.dtype == bool and t.running.shape == (2,)
        assert not t.overlap
        first.append(t.ref_time.copy())
    assert coord.ref_time_now.tolist() == [overlapping_planner.model.n_ref] * 2
    coord.reset()
    assert coord.clock_s.tolist() == [0.0, 0.0]
    again = []
    while not coord.is_finished:
        again.append(coord.tick(ops[len(again) % len(ops)]).ref_time.copy())
    np.testing.assert_array_equal(np.array(first), np.array(again))


def test_a_bad_operator_is_an_error_and_changes_nothing(planner: tandem.Planner) -> None:
    coord = tandem.Coordinator(planner.schedule)
    # At iteration 0 every sample is low-confidence: robot 1 follows the operator.
    coord.tick(None)
    assert coord.low_conf_now.tolist() == [True, False]
    before = coord.clock_s.copy()
    for bad in (float("nan"), float("inf"), 0.0, -1.0):
        with pytest.raises(tandem.InputError, match="must be finite and > 0"):
            coord.tick(bad)
    # A list is one input per operator (issue 44): two inputs for one operator are refused.
    for bad in ("fast", [1.0, 1.0], object()):
        with pytest.raises(tandem.InputError):
            coord.tick(bad)
    np.testing.assert_array_equal(coord.clock_s, before)
    # The slowest operator drags the low-confidence robot: its clock moves by S·tick.
    n = coord.sample_now[0]
    coord.tick("slowest")
    g = planner.schedule.gradients[0][n]
    assert coord.clock_s[0] - before[0] == pytest.approx(g / planner.problem.grad_max[n] * 0.01)
