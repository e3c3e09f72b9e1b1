"""Schedules from Python: shapes, Eq. 13/15/16 read back, and Eq. 20 checked by ``validate``."""

from __future__ import annotations

import numpy as np
import pytest

import tandem


def test_planner_schedule_passes_validate_and_has_n_robot_shapes(
    overlapping_planner: tandem.Planner,
) -> None:
    s = overlapping_planner.schedule
    s.validate()
    n_ref = overlapping_planner.model.n_ref
    assert s.n_robots == tandem.N_ROBOTS == 2
    assert s.gradients.shape == (2, n_ref)
    assert s.offsets.shape == (1,) and s.starts_s.tolist() == [0.0, s.offsets[0]]
    assert s.tick_s == s.dt_s == 0.01
    # Eq. 13 by hand from the arrays, summed sample by sample from each start as the one
    # clock of the coordinator does (c_0 = τ_i, c_{n+1} = c_n + ψ̇_E[n]·Δt_s).
    def clock_end(start: float, g: np.ndarray) -> float:
        return float(np.add.accumulate(np.concatenate([[start], g * s.dt_s]))[-1])

    ends = [clock_end(start, g) for start, g in zip(s.starts_s, s.gradients)]
    assert s.ends_s.tolist() == ends
    assert s.durations_s.tolist() == [clock_end(0.0, g) for g in s.gradients]
    assert s.t_total_s == max(ends)
    # The certificate: a lower bound no schedule can beat, and the relative gap to it. The
    # bound is reported unclamped: a valid schedule may lie below it by the rounding of
    # 2e-9 relative (``tol::BOUND_REL``), never by more. The serial schedule and fresh
    # schedules of the same problem (which certify the same bound) are above it too.
    problem = s.problem
    bound = s.lower_bound_s
    assert bound is not None and bound > 0.0
    others = [problem.serial_schedule()]
    others += [problem.sample_schedule(samples=200, seed=k) for k in range(3)]
    for other in [s, *others]:
        assert bound <= other.t_total_s * (1.0 + 2e-9), (bound, other.t_total_s)
    for fresh in others[1:]:
        assert fresh.lower_bound_s == pytest.approx(bound, rel=1e-12)
    assert s.gap == pytest.approx((s.t_total_s - s.lower_bound_s) / s.lower_bound_s, rel=1e-12)
    assert s.source in ("sampled", "completed", "previous", "repaired", "serial", "held", "staggered")
    assert set(s.stats) == {"candidates", "cheap_feasible", "margin_checks"}


def test_low_confidence_intervals_agree_with_eq16(overlapping_planner: tandem.Planner) -> None:
    s = overlapping_planner.schedule
    problem = s.problem
    for robot, (intervals, ref_intervals) in enumerate(zip(s.lc_intervals, s.lc_ref_intervals)):
        assert intervals.shape[1] == 2 and len(intervals) == len(ref_intervals) > 0
        for (a, b), (n0, n1) in zip(intervals, ref_intervals):
            assert not problem.conf[n0:n1].any()
            mid = 0.5 * (a + b)
            assert not s.conf_at(mid)[robot]
            assert n0 <= s.ref_time(mid)[robot] <= n1
    # Never both low-confidence at once (Eq. 20 constraint 3), on a fine grid of global time.
    for t in np.linspace(0.0, s.t_total_s, 4001):
        assert s.conf_at(t).any()


def test_broken_schedules_name_the_violated_constraint(overlapping_planner: tandem.Planner) -> None:
    s = overlapping_planner.schedule
    problem = s.problem
    g = s.gradients
    lc = np.flatnonzero(~problem.conf)[0]
    hc = np.flatnonzero(problem.conf)[0]
    cases = {
        "GradientOutOfBounds": (lambda g: g.__setitem__((0, hc), problem.grad_max[hc] * 2), s.offsets),
        "NotMeanGradient": (
            lambda g: g.__setitem__((0, lc), problem.grad_min[lc]),
            s.offsets,
        ),
        "Offset": (lambda g: None, np.array([-1.0])),
    }
    for name, (edit, offsets) in cases.items():
        bad = g.copy()
        edit(bad)
        broken = tandem.Schedule(problem, bad, offsets, s.tick_s)
        with pytest.raises(tandem.ScheduleError) as e:
            broken.validate()
        assert e.value.violation == name, (name, str(e.value))
        assert "Eq. 20" in str(e.value)
    # Starting robot 2 with robot 1 puts both low-confidence at once, or breaks the margins.
    with pytest.raises(tandem.ScheduleError) as e:
        tandem.Schedule(problem, g, [0.0], s.tick_s).validate()
    assert e.value.violation in ("BothLowConfidence", "InsufficientMargins")
    # Unchanged, it passes: the same arrays make the same schedule.
    same = tandem.Schedule(problem, g, s.offsets, s.tick_s)
    same.validate()
    assert same.t_total_s == s.t_total_s and same.source == "user"


def test_shapes_of_a_users_schedule_are_checked(overlapping_planner: tandem.Planner) -> None:
    s = overlapping_planner.schedule
    with pytest.raises(tandem.InputError, match=r"expected \(2, "):
        tandem.Schedule(s.problem, s.gradients[:, :-1], s.offsets, s.tick_s)
    with pytest.raises(tandem.InputError, match="one per robot after the first"):
        tandem.Schedule(s.problem, s.gradients, [1.0, 2.0], s.tick_s)


def test_json_round_trip_is_exact(overlapping_planner: tandem.Planner) -> None:
    s = overlapping_planner.schedule
    back = tandem.Schedule.from_json(s.problem, s.to_json())
    np.testing.assert_array_equal(back.gradients, s.gradients)
    assert back.offsets[0] == s.offsets[0] and back.tick_s == s.tick_s
    back.validate()


def test_problem_from_arrays_schedules_like_the_planner(overlapping_planner: tandem.Planner) -> None:
    p = overlapping_planner.problem
    again = tandem.Problem(p.conf, p.grad_mean, p.grad_min, p.grad_max, p.dt_s)
    serial = again.serial_schedule()
    serial.validate()
    assert serial.source == "serial"
    sampled = again.sample_schedule(samples=300, seed=11, previous=serial)
    sampled.validate()
    assert sampled.t_total_s <= serial.t_total_s
    # Deterministic for a seed.
    twice = again.sample_schedule(samples=300, seed=11, previous=serial)
    np.testing.assert_array_equal(twice.gradients, sampled.gradients)
    with pytest.raises(tandem.InputError):
        tandem.Problem(p.conf, p.grad_mean, p.grad_max, p.grad_min, p.dt_s)


def test_a_coordinator_runs_only_a_checked_schedule(overlapping_planner: tandem.Planner) -> None:
    s = overlapping_planner.schedule
    problem, g = s.problem, s.gradients
    # A schedule of your own, even a valid one, is refused until validate() passed on it.
    mine = tandem.Schedule(problem, g, s.offsets, s.tick_s)
    with pytest.raises(tandem.ScheduleError, match=r"validate\(\)") as e:
        tandem.Coordinator(mine)
    assert isinstance(e.value, tandem.TandemError) and e.value.violation == "Unchecked"
    mine.validate()
    coord = tandem.Coordinator(mine)
    assert coord.tick_s == s.tick_s and coord.fault is None
    # One that fails the check can never be run: validate() raises, and so does the
    # coordinator, naming the rule.
    together = tandem.Schedule(problem, g, [0.0], s.tick_s)
    with pytest.raises(tandem.ScheduleError):
        together.validate()
    with pytest.raises(tandem.ScheduleError) as e:
        tandem.Coordinator(together)
    assert e.value.violation == "Unchecked"
    # From JSON: unchecked again, however it was made.
    back = tandem.Schedule.from_json(problem, s.to_json())
    with pytest.raises(tandem.ScheduleError):
        tandem.Coordinator(back)
    # The scheduler's and the planner's schedules run as they are.
    tandem.Coordinator(s)
    tandem.Coordinator(problem.sample_schedule(samples=50, seed=1))
    # So does tandem's serial schedule (checked by the coordinator itself).
    tick = tandem.Coordinator(problem.serial_schedule()).tick()
    assert tick.fault is None
