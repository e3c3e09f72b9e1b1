"""More than two robots from Python: ``tandem.fit(robots=3)`` schedules three robots, the
schedule runs through the Rust coordinator under adversarial operators with never two robots
low-confidence in one tick, and rounds of three executions are recorded."""

from __future__ import annotations

import numpy as np
import pytest

import tandem
from conftest import DEMOS, LABELS, QUICK_CONFIDENCE, SAMPLES


@pytest.fixture(scope="module")
def three() -> tandem.Planner:
    """Three robots, quick confidence, two rounds recorded: a schedule that overlaps them."""
    p = tandem.fit(
        DEMOS,
        params={"sampler": {"samples": SAMPLES, "seed": 3}, "confidence": QUICK_CONFIDENCE},
        robots=3,
    )
    for k in range(2):
        needs = tandem.sim.sanding_needs(LABELS, seed=k, planner=p)
        run = tandem.sim.run_round(p, needs, seed=k)
        assert len(run.robots) == 3 and run.overlap_ticks == 0
        assert 0.0 < run.operator_busy_share <= 1.0
        # A robot moves one sample per tick it runs; every other robot-tick it waits.
        moving = sum(len(r.ref_time_log) for r in run.robots)
        assert run.robot_wait_share == pytest.approx(1.0 - moving / (3 * run.ticks))
        assert 0.0 < run.robot_wait_share < 1.0
        p.record_round(**run.record_args())
    return p


def test_a_three_robot_planner_has_three_warps_and_two_offsets(three: tandem.Planner) -> None:
    s = three.schedule
    assert three.n_robots == s.n_robots == 3
    assert s.gradients.shape == (3, three.model.n_ref)
    assert s.offsets.shape == (2,)
    assert len(s.lc_intervals) == 3
    assert three.rounds_recorded == 2
    s.validate()


def one_stretch_problem() -> tandem.Problem:
    """300 reference samples at 10 ms, low-confidence over samples 100..140 (mean speed 1,
    bounds [0.5, 2]): three robots can overlap, each passing the stretch while the others run
    high-confidence."""
    n = 300
    conf = np.ones(n, dtype=bool)
    conf[100:140] = False
    return tandem.Problem(conf, np.ones(n), np.full(n, 0.5), np.full(n, 2.0), 0.01)


@pytest.fixture(scope="module")
def three_robot_schedule() -> tandem.Schedule:
    s = one_stretch_problem().sample_schedule(samples=SAMPLES, seed=1, robots=3)
    assert s.n_robots == 3 and s.gradients.shape == (3, 300) and s.offsets.shape == (2,)
    s.validate()
    serial = one_stretch_problem().serial_schedule(robots=3)
    assert s.t_total_s < serial.t_total_s, "the scheduler overlaps the robots"
    return s


@pytest.mark.parametrize("policy", ["scheduled", "fastest", "slowest", "alternating"])
def test_a_three_robot_schedule_never_has_two_robots_low_confidence_in_a_tick(
    three_robot_schedule: tandem.Schedule, policy: str
) -> None:
    coord = tandem.Coordinator(three_robot_schedule)
    assert coord.n_robots == 3
    ticks = together = 0
    while not coord.is_finished:
        if policy == "alternating":
            operator = "fastest" if (ticks // 7) % 2 == 0 else "slowest"
        else:
            operator = None if policy == "scheduled" else policy
        tick = coord.tick(operator)
        assert tick.low_conf.shape == (3,)
        assert int(tick.low_conf.sum()) <= 1, (policy, ticks, tick)
        assert not tick.overlap
        together += int(tick.running.sum() >= 2)
        ticks += 1
    # Not vacuous: the robots run at the same time for a good part of the schedule.
    assert together > 0.1 * ticks, (together, ticks)


def test_the_planner_coordinates_its_three_robots(three: tandem.Planner) -> None:
    coord = tandem.Coordinator(three.schedule)
    assert coord.n_robots == 3
    while not coord.is_finished:
        assert int(coord.tick("slowest").low_conf.sum()) <= 1


def test_rounds_take_one_execution_per_robot(three: tandem.Planner) -> None:
    needs = tandem.sim.sanding_needs(LABELS, seed=9, planner=three)
    run = tandem.sim.run_round(three, needs, seed=9)
    args = run.record_args()
    short = {k: v[:2] for k, v in args.items()}
    before = three.rounds_recorded
    with pytest.raises(tandem.InputError, match="3 robots"):
        three.record_round(**short)
    assert three.rounds_recorded == before
    with pytest.raises(tandem.InputError):
        tandem.sim.run_round(three, tandem.sim.sanding_needs(LABELS, seed=9, planner=three, robots=2), seed=9)
    with pytest.raises(tandem.ParamError):
        tandem.fit(DEMOS[:2], robots=tandem.MAX_ROBOTS + 1)
    assert np.array_equal(needs.shape, (3, three.model.n_ref))
