"""The plan of a continuous cell from Python (``Planner.cyclic_plan``, ``tandem.cyclic_plan``,
``tandem.CyclicPlan``): hand-derived periods, the command line's JSON, errors."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

import tandem

from conftest import cli


def doc_problem(high_everywhere: bool = False) -> tandem.Problem:
    """The example of ``tandem_schedule::cyclic``: 300 samples of 10 ms, 1 s high confidence
    (0.5 s at the fastest, ψ̇min 0.5), 1 s low, 1 s high; ψ̇̄ 1, ψ̇max 2."""
    n = np.arange(300)
    conf = np.ones(300, bool) if high_everywhere else ~((100 <= n) & (n < 200))
    return tandem.Problem(conf, np.ones(300), np.full(300, 0.5), np.full(300, 2.0), 0.01)


def intervals_mod_period(plan: tandem.CyclicPlan):
    """Every stretch as ``(start, end)`` folded into ``[0, P)``, split where it wraps."""
    out = []
    p = plan.period_s
    for r in range(plan.n_robots):
        for k, d in enumerate(plan.lc_s):
            a = plan.lc_start_s[r, k] % p
            if a + d <= p + 1e-12:
                out.append((a, a + d))
            else:
                out += [(a, p), (0.0, a + d - p)]
    return sorted(out)


def test_three_robots_saturate_the_operator_on_the_doc_example() -> None:
    plan = tandem.cyclic_plan(doc_problem(), 3)
    # Each robot's only stretch lasts 1 s; the operator supervises three per period, one
    # after the other, and nothing else limits the period (a robot's fastest task is 2 s).
    assert plan.n_robots == 3
    assert plan.period_s == pytest.approx(3.0, abs=1e-9)
    assert plan.tasks_per_hour == pytest.approx(3600.0, abs=1e-6)
    assert plan.operator_share == pytest.approx(1.0, abs=1e-9)
    assert plan.lower_bound_s == pytest.approx(3.0, abs=1e-9)
    assert abs(plan.gap) < 1e-9
    assert plan.order_exhaustive
    assert sorted(plan.order) == [(0, 0), (1, 0), (2, 0)]
    assert plan.order[0] == (0, 0)
    np.testing.assert_allclose(plan.lc_s, [1.0], atol=1e-12)
    assert plan.start_s.shape == (3,) and plan.start_s.dtype == np.float64
    assert plan.lc_start_s.shape == (3, 1)
    assert plan.gap_duration_s.shape == (3, 2) and plan.gap_wait_s.shape == (3, 2)
    assert plan.gap_hold == [None, None]
    assert np.all((0.0 <= plan.start_s) & (plan.start_s < plan.period_s))
    # No two stretches at once: the folded intervals tile [0, 3) without overlap.
    iv = intervals_mod_period(plan)
    for (a0, a1), (b0, b1) in zip(iv, iv[1:]):
        assert a1 <= b0 + 1e-9, iv
    assert sum(b - a for a, b in iv) == pytest.approx(3.0)
    # Every task with its wait at the start fills one period.
    np.testing.assert_allclose(
        plan.gap_duration_s.sum(axis=1) + plan.lc_s.sum() + plan.start_wait_s, 3.0, atol=1e-9
    )


def test_one_robot_runs_its_fastest_task_and_no_low_confidence_needs_no_order() -> None:
    one = tandem.cyclic_plan(doc_problem(), 1)
    # 0.5 s + 1 s + 0.5 s: the high-confidence second at ψ̇min = 0.5, no wait.
    assert one.period_s == pytest.approx(2.0, abs=1e-9)
    assert one.tasks_per_hour == pytest.approx(1800.0, abs=1e-6)
    assert one.operator_share == pytest.approx(0.5, abs=1e-9)
    np.testing.assert_allclose(one.gap_duration_s, [[0.5, 0.5]], atol=1e-9)
    np.testing.assert_allclose(one.lc_start_s - one.start_s[:, None], [[0.5]], atol=1e-9)
    np.testing.assert_allclose(one.start_wait_s, [0.0], atol=1e-9)
    high = tandem.cyclic_plan(doc_problem(high_everywhere=True), 2)
    # 3 s at ψ̇min 0.5: 1.5 s per task, nothing for the operator.
    assert high.order == []
    assert high.lc_start_s.shape == (2, 0)
    assert high.period_s == pytest.approx(1.5, abs=1e-9)
    assert high.operator_share == 0.0


def test_the_plan_is_read_only_and_prints_its_numbers() -> None:
    plan = tandem.cyclic_plan(doc_problem(), 2)
    with pytest.raises(AttributeError):
        plan.period_s = 1.0  # type: ignore[misc]
    text = repr(plan)
    assert text.startswith("CyclicPlan(n_robots=2, period_s=2.000")
    doc = json.loads(plan.to_json())
    # The documented form (docs/formats.md, "Cyclic plan JSON"), keys in the documented order:
    # the planner's CyclicPlanJson, the one type the command line prints too.
    assert list(doc) == [
        "n_robots", "order", "period_s", "lc_s", "robots", "tasks_per_hour",
        "operator_share", "lower_bound_s", "gap", "order_exhaustive", "orders_evaluated",
    ]
    assert list(doc["robots"][0]) == ["start_s", "lc_start_s", "gaps", "start_wait_s"]
    assert list(doc["robots"][0]["gaps"][0]) == ["duration_s", "wait_s", "hold"]
    assert doc["period_s"] == plan.period_s
    assert [(s["robot"], s["lc"]) for s in doc["order"]] == plan.order
    assert [r["start_s"] for r in doc["robots"]] == plan.start_s.tolist()


def test_bad_arguments_are_param_errors() -> None:
    problem = doc_problem()
    for robots in (0, tandem.MAX_ROBOTS + 1):
        with pytest.raises(tandem.ParamError) as e:
            tandem.cyclic_plan(problem, robots)
        assert e.value.name == "n_robots"
    with pytest.raises(tandem.ParamError) as e:
        tandem.cyclic_plan(problem, 2, max_enumerated=0)
    assert e.value.name == "max_enumerated"


def test_sanding_plan_equals_the_command_line_and_a_smaller_search(planner, tmp_path) -> None:
    offsets, t_total = planner.schedule.offsets.copy(), planner.schedule.t_total_s
    plan = planner.cyclic_plan()
    assert plan.n_robots == planner.n_robots
    # The same plan as the free function on the planner's problem at the planner's tick (the
    # cell's: the token rule's hand-overs counted at it).
    same = tandem.cyclic_plan(planner.problem, planner.n_robots, tick_s=planner.schedule.tick_s)
    assert plan.to_json() == same.to_json()
    # Without a tick the hand-overs are not counted: never a longer period.
    assert tandem.cyclic_plan(planner.problem, planner.n_robots).period_s <= plan.period_s
    state = tmp_path / "sanding.tandem"
    planner.save(state)
    out = subprocess.run(
        [str(cli()), "schedule", str(state), "--cell", "continuous", "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout.rstrip("\n") == plan.to_json()
    doc = json.loads(out.stdout)
    assert doc["period_s"] == plan.period_s and doc["gap"] == plan.gap
    assert plan.lower_bound_s <= plan.period_s * (1 + 1e-9)
    # Robots 0-based, each stretch of each robot exactly once per period.
    m = len(plan.lc_s)
    assert sorted(plan.order) == [(r, k) for r in range(plan.n_robots) for k in range(m)]
    # A search limited to one enumerated order falls back on the local search: never
    # shorter than the exhaustive optimum, and not claimed exhaustive.
    if plan.orders_evaluated > 1:
        local = planner.cyclic_plan(max_enumerated=1)
        assert not local.order_exhaustive
        assert local.period_s >= plan.period_s * (1 - 1e-9)
    # The planner is unchanged: its schedule is still the rounds one it had.
    np.testing.assert_array_equal(planner.schedule.offsets, offsets)
    assert planner.schedule.t_total_s == t_total
