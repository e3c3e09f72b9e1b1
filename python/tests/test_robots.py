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
        needs = tandem.sim.sanding_needs(LABELS, seed=k, robots=3)
        run = tandem.sim.run_round(p, needs, seed=k)
        assert len(run.robots) == 3 and run.overlap_ticks == 0
        assert 0.0 < run.operator_busy_share <= 1.0
        p.record_round(**run.record_args())
    return p


def test_a_three_robot_planner_has_three_warps_and_two_offsets(three: tandem.Planner) -> None:
    s = three.schedule
    assert three.n_robots == s.n_robots == 3
    assert s.gradients.shape == (3, three.model.n_ref)
    assert s.offsets.shape == (2,)
    assert len(s.lc_intervals) == 3
    assert three.pairs_recorded == 2
    s.validate()


@pytest.mark.parametrize("policy", ["scheduled", "fastest", "slowest", "alternating"])
def test_a_three_robot_schedule_never_has_two_robots_low_confidence_in_a_tick(
    three: tandem.Planner, policy: str
) -> None:
    s = three.schedule
    coord = tandem.Coordinator(s)
    assert coord.n_robots == 3
    ticks = together = 0
    while not coord.is_finished:
        if policy == "alternating":
            operator = "fastest" if (ticks // 50) % 2 == 0 else "slowest"
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


def test_rounds_take_one_execution_per_robot(three: tandem.Planner) -> None:
    needs = tandem.sim.sanding_needs(LABELS, seed=9, robots=3)
    run = tandem.sim.run_round(three, needs, seed=9)
    args = run.record_args()
    short = {k: v[:2] for k, v in args.items()}
    before = three.pairs_recorded
    with pytest.raises(tandem.InputError, match="3 robots"):
        three.record_round(**short)
    assert three.pairs_recorded == before
    with pytest.raises(tandem.InputError):
        tandem.sim.run_round(three, tandem.sim.sanding_needs(LABELS, seed=9), seed=9)
    with pytest.raises(tandem.ParamError):
        tandem.fit(DEMOS[:2], robots=9)
    assert np.array_equal(needs.shape, (3, three.model.n_ref))
