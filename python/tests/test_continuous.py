"""The continuous coordinator from Python (``CyclicPlan.coordinator``,
``Planner.continuous_coordinator``, ``tandem.ContinuousCoordinator``, ``tandem.CellTick``):
hand-derived ticks, the sanding planner under every operator mode, errors, and the runnable
examples of docs/python.md."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

import tandem

from conftest import DEMOS, QUICK_CONFIDENCE, ROOT, SAMPLES, record_rounds

#: Operator modes of ``tick``: scheduled, a gradient, the extremes (clamped per sample).
MODES = [None, "scheduled", 1.0, 0.3, 5.0, "fastest", "slowest"]


def doc_problem(hc_min: float = 0.5) -> tandem.Problem:
    """The task of the ``tandem_realtime::continuous`` example: ``[HC, LC, HC]`` at 1 s per
    sample, ``ψ̇̄ = 1``, ``ψ̇min = 0.5`` (``hc_min`` on the high-confidence samples), ``ψ̇max = 2``."""
    return tandem.Problem(
        [True, False, True], np.ones(3), [hc_min, 0.5, hc_min], np.full(3, 2.0), 1.0
    )


def state(cell: tandem.ContinuousCoordinator):
    """Everything a tick changes."""
    return (
        cell.clock_s.tolist(),
        cell.tasks_completed.tolist(),
        cell.ticks,
        cell.token,
        cell.token_position,
        cell.low_conf_now.tolist(),
        cell.fault,
    )


def test_the_doc_example_by_hand() -> None:
    # ψ̇min = 1 on the high-confidence samples: the fastest warp is 1 everywhere, the Rust
    # doc example's task. The operator's order: robot 0's stretch, then robot 1's.
    problem = doc_problem(hc_min=1.0)
    plan = tandem.cyclic_plan(problem, 2)
    assert plan.order == [(0, 0), (1, 0)] and plan.is_runnable(problem)
    cell = plan.coordinator(problem)
    assert isinstance(cell, tandem.ContinuousCoordinator)
    assert cell.n_robots == 2 and cell.tick_s == 1.0 and cell.task_s == pytest.approx(3.0)
    assert cell.groups == [{"gate": 0, "first_lc": 0, "end_lc": 1, "ref_start": 1, "ref_end": 2}]
    assert cell.tokens == [(0, 0), (1, 0)]
    assert cell.token == (0, 0) and cell.token_position == (0, 0)
    assert cell.ticks == 0 and cell.tasks_completed.tolist() == [0, 0]
    assert cell.tasks_completed.dtype == np.int64
    t = cell.tick(None)
    assert isinstance(t, tandem.CellTick)
    # Robot 0 moves one sample, to the start of its stretch; robot 1 waits at the task start.
    assert t.ref_time.tolist() == [1.0, 0.0]
    assert t.at_gate.tolist() == [False, True]
    assert t.running.tolist() == [True, False]
    # The traversed interval [0 − tol, 1 + tol] touches sample 1: low-confidence, robot 0 only.
    assert t.low_conf.tolist() == [True, False]
    assert t.tasks.tolist() == [0, 0] and not t.overlap and t.fault is None
    assert cell.low_conf_now.tolist() == [True, False]
    assert cell.ref_time_now.tolist() == [1.0, 0.0] and cell.sample_now == [1, 0]
    for _ in range(1000):
        t = cell.tick("fastest")
        assert not t.overlap
    assert (cell.tasks_completed > 100).all()
    np.testing.assert_array_equal(t.tasks, cell.tasks_completed)
    assert cell.ticks == 1001
    assert repr(cell).startswith("ContinuousCoordinator(n_robots=2, tick_s=1.0, ticks=1001,")
    assert repr(t).startswith("CellTick(ref_time=[")
    cell.reset()
    assert cell.ticks == 0 and cell.tasks_completed.tolist() == [0, 0]
    assert cell.clock_s.tolist() == [0.0, 0.0] and cell.token == (0, 0)


def test_the_fastest_warp_on_the_doc_problem_by_hand() -> None:
    # ψ̇min = 0.5 on the high-confidence samples: the fastest warp takes samples 0 and 2 in
    # 0.5 s, the stretch (sample 1, clock 0.5–1.5 s) in 1 s at ψ̇̄; a task takes 2 s. From a
    # high-confidence sample a step stops at the next low-confidence sample's start.
    problem = doc_problem()
    cell = tandem.cyclic_plan(problem, 2).coordinator(problem)
    assert cell.task_s == pytest.approx(2.0)
    # Tick 1: robot 0's clock 0 → 0.5 s (capped at the stretch's start), robot 1 at its gate.
    t = cell.tick()
    assert t.ref_time.tolist() == [1.0, 0.0]
    assert t.at_gate.tolist() == [False, True] and t.running.tolist() == [True, False]
    # Tick 2: across the stretch at ψ̇̄, 0.5 → 1.5 s (its end, not yet left by the tolerance).
    t = cell.tick()
    assert t.ref_time.tolist() == [2.0, 0.0] and cell.token == (0, 0)
    # Tick 3: sample 2 to the task's end (2 s): robot 0 has done a task and is back at its
    # task start, where it waits; the token is robot 1's.
    t = cell.tick()
    assert t.ref_time.tolist() == [0.0, 0.0]
    assert t.tasks.tolist() == [1, 0]
    assert t.at_gate.tolist() == [True, False]
    assert cell.token == (1, 0) and cell.token_position == (1, 0)
    # Tick 4: robot 1 goes to the stretch's start; robot 0 waits.
    t = cell.tick()
    assert t.ref_time.tolist() == [0.0, 1.0] and t.running.tolist() == [False, True]
    # A slower operator on the stretch: ψ̇max = 2 halves the rate, 0.5 s of clock per tick.
    t = cell.tick("slowest")
    assert t.ref_time.tolist() == [0.0, 1.5] and t.tasks.tolist() == [1, 0]
    # Tick 6: from the stretch at ψ̇̄, 1.0 → 2.0 s, the task's end.
    t = cell.tick()
    assert t.tasks.tolist() == [1, 1] and cell.token == (0, 0)
    assert cell.token_position == (0, 1)


def test_no_low_confidence_means_no_token() -> None:
    problem = tandem.Problem(np.ones(4, bool), np.ones(4), np.full(4, 0.5), np.full(4, 2.0), 1.0)
    cell = tandem.cyclic_plan(problem, 3).coordinator(problem, tick_s=0.5)
    assert cell.token is None and cell.tokens == [] and cell.groups == []
    for _ in range(40):
        t = cell.tick("fastest")
        assert not t.low_conf.any() and not t.at_gate.any()
    # 4 samples × 0.5 s = 2 s per task at 0.5 s per tick: 10 tasks in 40 ticks.
    assert cell.tasks_completed.tolist() == [10, 10, 10]


#: Control tick (s) of the sanding runs: the fixtures' task lasts 55–99 s on the fastest warp,
#: so 5000 ticks of 0.1 s (500 s) let each robot do several tasks (5000 of the fixtures'
#: 10 ms would not finish one).
TICK_S = 0.1


@pytest.fixture(scope="module")
def holds_planner() -> tandem.Planner:
    """The overlapping planner's fit with hold points between its low-confidence regions: five
    groups, robot 1 starting at its fourth (its first tokens skipped in the first pass)."""
    p = tandem.fit(
        DEMOS,
        params={"sampler": {"samples": SAMPLES, "seed": 3}, "confidence": QUICK_CONFIDENCE},
        holds=[4.0, 25.0, 55.0, 72.0],
    )
    record_rounds(p, 2)
    return p


@pytest.fixture(scope="module", params=["planner", "overlapping_planner", "holds_planner"])
def sanding(request) -> tandem.Planner:
    """The sanding planners: all low-confidence (no round recorded), high-confidence regions
    without holds (one group), and with holds (several groups)."""
    return request.getfixturevalue(request.param)


def test_the_planner_cell_is_its_cyclic_plan(sanding) -> None:
    cell = sanding.continuous_coordinator()
    assert cell.n_robots == sanding.n_robots
    assert cell.tick_s == sanding.schedule.tick_s
    plan = sanding.cyclic_plan()
    assert plan.is_runnable(sanding.problem)
    same = plan.coordinator(sanding.problem, tick_s=TICK_S)
    assert same.tick_s == TICK_S
    assert same.tokens == cell.tokens and same.groups == cell.groups
    # One token per group per robot and period; a group's gate is 0 or a usable hold.
    assert sorted(cell.tokens) == [
        (r, g) for r in range(sanding.n_robots) for g in range(len(cell.groups))
    ]
    holds = set(sanding.problem.active_holds) | {0}
    assert all(g["gate"] in holds for g in cell.groups)
    assert all(g["gate"] <= g["ref_start"] < g["ref_end"] for g in cell.groups)
    assert cell.groups[0]["first_lc"] == 0 and cell.groups[-1]["end_lc"] == len(plan.lc_s)
    for a, b in zip(cell.groups, cell.groups[1:]):
        assert a["end_lc"] == b["first_lc"] and a["ref_end"] <= b["gate"]


def test_the_planner_plans_and_runs_both_cells_at_its_schedules_tick(sanding) -> None:
    tick_s = sanding.schedule.tick_s
    rounds = sanding.plan()
    assert isinstance(rounds, tandem.Schedule)
    assert rounds.to_json() == sanding.schedule.to_json()
    assert sanding.plan(cell="rounds").to_json() == rounds.to_json()
    continuous = sanding.plan(cell="continuous")
    assert isinstance(continuous, tandem.CyclicPlan)
    # The cyclic plan of the planner, checked at (and carrying) the schedule's tick; a free
    # plan carries none.
    assert continuous.tick_s == tick_s and sanding.cyclic_plan().tick_s == tick_s
    assert continuous.to_json() == sanding.cyclic_plan().to_json()
    assert tandem.cyclic_plan(sanding.problem, sanding.n_robots).tick_s is None
    # Its coordinator runs at that tick by default.
    assert continuous.coordinator(sanding.problem).tick_s == tick_s
    for cell, kind in (("rounds", tandem.Coordinator), ("continuous", tandem.ContinuousCoordinator)):
        c = sanding.controller(cell=cell)
        assert isinstance(c, kind) and isinstance(c, tandem.Controller)
        assert (c.tick_s, c.n_robots) == (tick_s, sanding.n_robots)
    cell = sanding.controller(cell="continuous")
    same = sanding.continuous_coordinator()
    assert (cell.tokens, cell.groups) == (same.tokens, same.groups)
    with pytest.raises(tandem.ParamError) as e:
        sanding.plan(cell="Continuous")
    assert e.value.name == "cell"
    assert "give `rounds` or `continuous`" in str(e.value)


def test_the_holds_make_groups(holds_planner) -> None:
    cell = holds_planner.continuous_coordinator()
    holds = holds_planner.problem.active_holds
    gates = [g["gate"] for g in cell.groups]
    assert len(gates) > 1 and gates == sorted(set(gates))
    assert set(gates[1:]) <= set(holds)
    # The first pass skips the tokens that precede their robot's group 0 (they belong to a
    # task before its first): the cell starts at the first one it does not skip.
    k, passes = cell.token_position
    assert passes == 0
    first_zero = {r: cell.tokens.index((r, 0)) for r in range(cell.n_robots)}
    assert k == min(j for j, (r, _) in enumerate(cell.tokens) if j >= first_zero[r])
    assert cell.token == cell.tokens[k]


@pytest.mark.parametrize("mode", MODES, ids=str)
def test_sanding_cell_runs_5000_ticks_without_overlap(sanding, mode) -> None:
    cell = sanding.continuous_coordinator(tick_s=TICK_S)
    previous = cell.tasks_completed.copy()
    at_gate = np.zeros(cell.n_robots, bool)
    waited = 0
    for k in range(5000):
        t = cell.tick(mode)
        assert not t.overlap, k
        assert t.fault is None, k
        assert t.low_conf.sum() <= 1, k
        assert (t.tasks >= previous).all(), k
        # A robot waiting at its gate (the token another's) stays there in the next tick.
        assert not (at_gate & t.running).any(), k
        at_gate = t.at_gate
        waited += int(at_gate.any())
        previous = t.tasks
    assert waited > 0
    assert cell.ticks == 5000 and cell.fault is None
    done = cell.tasks_completed
    assert (done >= 1).all(), (mode, done)
    np.testing.assert_array_equal(done, previous)
    # And it goes on: more tasks after more ticks.
    for _ in range(2000):
        cell.tick(mode)
    assert cell.tasks_completed.sum() > done.sum()


def test_sanding_cell_under_a_random_operator(sanding) -> None:
    cell = sanding.continuous_coordinator(tick_s=TICK_S)
    rng = np.random.default_rng(21)
    lc_ticks = 0
    for k in range(5000):
        g = float(np.exp(rng.uniform(-1.5, 1.5)))  # clamped to [ψ̇min, ψ̇max] per sample
        t = cell.tick(g if k % 7 else "slowest")
        assert not t.overlap, k
        lc_ticks += int(t.low_conf.any())
    assert lc_ticks > 0
    assert (cell.tasks_completed >= 1).all()


@pytest.mark.parametrize("bad", [math.nan, -1.0, 0.0, math.inf, "bogus", [1.0, 1.0]], ids=repr)
def test_a_bad_operator_input_is_an_input_error_and_changes_nothing(planner, bad) -> None:
    cell = planner.continuous_coordinator()
    for _ in range(700):
        cell.tick()
    before = state(cell)
    with pytest.raises(tandem.InputError) as e:
        cell.tick(bad)
    assert "operator" in str(e.value)
    assert state(cell) == before
    cell.tick()
    assert cell.ticks == 701


def nonrunnable_problem() -> tandem.Problem:
    """Two stretches with no hold between them (the Rust test's task)."""
    conf = np.repeat([True, False, True, False, True], [2, 2, 3, 2, 2])
    n = len(conf)
    return tandem.Problem(conf, np.ones(n), np.full(n, 0.5), np.full(n, 3.0), 1.0)


def test_a_non_runnable_order_is_a_schedule_error() -> None:
    problem = nonrunnable_problem()
    # Robot 1's first stretch between robot 0's two: a valid plan, but robot 0 cannot wait
    # between its stretches.
    interleaved = tandem.cyclic_plan(problem, 2, order=[(0, 0), (1, 0), (0, 1), (1, 1)])
    assert interleaved.order == [(0, 0), (1, 0), (0, 1), (1, 1)]
    assert not interleaved.is_runnable(problem)
    with pytest.raises(tandem.ScheduleError) as e:
        interleaved.coordinator(problem, tick_s=0.1)
    assert e.value.violation == "NotRunnable"
    assert "at position 2, robot 0's stretch 1" in str(e.value)
    # The default search plans runnable orders only; every order is at least as short.
    runnable = tandem.cyclic_plan(problem, 2)
    assert runnable.is_runnable(problem)
    cell = runnable.coordinator(problem, tick_s=0.1)
    assert len(cell.groups) == 1 and cell.groups[0]["end_lc"] == 2
    free = tandem.cyclic_plan(problem, 2, runnable_only=False)
    assert free.period_s <= runnable.period_s * (1 + 1e-12)


@pytest.mark.parametrize("tick_s", [0.0, -0.01, math.nan, math.inf])
def test_a_bad_tick_is_a_param_error(planner, tick_s) -> None:
    problem = doc_problem()
    plan = tandem.cyclic_plan(problem, 2)
    with pytest.raises(tandem.ParamError) as e:
        plan.coordinator(problem, tick_s=tick_s)
    assert e.value.name == "tick_s"
    with pytest.raises(tandem.ParamError) as e:
        planner.continuous_coordinator(tick_s=tick_s)
    assert e.value.name == "tick_s"


def test_other_bad_arguments_raise_cleanly(planner) -> None:
    # A problem with another number of stretches than the plan's.
    plan = tandem.cyclic_plan(doc_problem(), 2)
    with pytest.raises(tandem.ParamError) as e:
        plan.coordinator(nonrunnable_problem())
    assert e.value.name == "problem"
    with pytest.raises(tandem.ParamError) as e:
        planner.continuous_coordinator(max_enumerated=0)
    assert e.value.name == "max_enumerated"
    problem = nonrunnable_problem()
    with pytest.raises(tandem.InputError):
        tandem.cyclic_plan(problem, 2, order="not an order")
    with pytest.raises(tandem.InputError):
        tandem.cyclic_plan(problem, 2, order=[(0, -1)])
    # Malformed orders: a stretch missing, repeated, an unknown robot or stretch.
    for order in (
        [(0, 0), (1, 0), (0, 1)],
        [(0, 0), (0, 0), (1, 0), (1, 1)],
        [(0, 0), (0, 1), (2, 0), (2, 1)],
        [(0, 0), (0, 1), (1, 0), (1, 2)],
    ):
        with pytest.raises(tandem.ParamError) as e:
            tandem.cyclic_plan(problem, 2, order=order)
        assert e.value.name == "order", order


def test_the_coordinator_is_exported_and_not_constructible() -> None:
    assert "ContinuousCoordinator" in tandem.__all__ and "CellTick" in tandem.__all__
    with pytest.raises(TypeError):
        tandem.ContinuousCoordinator()  # type: ignore[call-arg]


def python_md_blocks() -> list:
    text = (ROOT / "docs" / "python.md").read_text()
    start = text.index("### The continuous coordinator")
    end = text.index("\n### ", start + 1)
    return re.findall(r"```python\n(.*?)```", text[start:end], flags=re.S)


def test_the_docs_examples_run(planner) -> None:
    blocks = python_md_blocks()
    assert len(blocks) == 2
    exec(compile(blocks[0], "docs/python.md", "exec"), {})
    exec(compile(blocks[1], "docs/python.md", "exec"), {"planner": planner, "tandem": tandem})
