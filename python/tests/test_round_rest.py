"""The operator's rest after a round from Python (issue 41): ``Coordinator(schedule,
max_busy_share=u)`` and the planner's coordinator count the round's busy ticks and give the
rest that keeps the load cap, ``rest_ticks`` / ``rest_s`` (the Rust
``Coordinator::with_max_busy_share``); docs/python.md's example runs as printed."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import tandem
from conftest import ROOT, SAMPLES
from test_operator_switch import small_demos


def tiny_schedule(dt_s: float) -> tandem.Schedule:
    """Two rigid robots (ψ̇ = 1 everywhere) on [HC, LC, HC] at ``dt_s`` per sample, robot 1
    starting at robot 0's end (3 samples): 6 ticks of ``dt_s``."""
    problem = tandem.Problem([True, False, True], np.ones(3), np.ones(3), np.ones(3), dt_s)
    s = tandem.Schedule(problem, np.ones((2, 3)), [3 * dt_s], dt_s)
    s.validate()
    return s


def run_round(c: tandem.Coordinator, operator=None) -> list:
    """Ticks ``c`` to the round's end; each tick's low-confidence flags."""
    lows = []
    while not c.is_finished:
        lows.append(c.tick(operator).low_conf.copy())
    return lows


def busy_by_hand(lows: list, k: int) -> int:
    """``B``: the ticks with a low-confidence robot, plus ``k`` per change of low-confidence
    robot (the round's first stretch is none)."""
    busy, changes, last = 0, 0, None
    for low in lows:
        if low.any():
            busy += 1
            r = int(np.flatnonzero(low)[0])
            changes += last is not None and r != last
            last = r
    return busy + k * changes


def rest_by_hand(busy: int, ticks: int, u: float) -> int:
    """The least ``n ≥ 0`` with ``busy ≤ u·(ticks + n)``, searched from below."""
    n = 0
    while busy > u * (ticks + n):
        n += 1
    return n


@pytest.mark.parametrize("u, rest", [(1.0, 0), (0.5, 6), (0.25, 18), (0.7, 3)])
def test_the_rest_after_a_tiny_round_by_hand(u: float, rest: int) -> None:
    # 6 ticks of 1 s, each with a robot low-confidence (the coordinator reports a tick
    # low-confidence when a robot traverses a low-confidence sample in it: robot 0 in ticks
    # 1-3, robot 1 in ticks 4-6), no switch time: B = 6, and the round and its rest must
    # last ceil(6/u) ticks: 6, 12, 24 and 9 (6/0.7 = 8.57), less the round's 6.
    c = tandem.Coordinator(tiny_schedule(1.0), max_busy_share=u)
    assert c.max_busy_share == u and c.switch_ticks == 0
    lows = run_round(c)
    assert [np.flatnonzero(low).tolist() for low in lows] == [[0]] * 3 + [[1]] * 3
    busy = busy_by_hand(lows, 0)
    assert busy == 6
    assert rest == (0 if u == 1.0 else math.ceil(busy / u) - len(lows))
    assert rest == rest_by_hand(busy, len(lows), u)
    assert c.rest_ticks == rest and c.rest_s == rest * 1.0
    assert c.busy_ticks() == (None if u == 1.0 else busy)
    assert c.busy_ticks(1) is None, "one operator: operator 1 has no count"
    # A reset starts a new count.
    c.reset()
    assert c.rest_ticks == 0 and c.busy_ticks() == (None if u == 1.0 else 0)


def test_without_the_keyword_there_is_no_cap_and_no_rest() -> None:
    c = tandem.Coordinator(tiny_schedule(1.0))
    run_round(c)
    assert (c.max_busy_share, c.rest_ticks, c.rest_s, c.busy_ticks()) == (1.0, 0, 0.0, None)


@pytest.mark.parametrize("bad", [0.0, -0.5, 1.5, float("nan"), float("inf")])
def test_a_cap_out_of_range_is_refused_by_name_with_the_rust_text(bad: float) -> None:
    with pytest.raises(tandem.ParamError) as e:
        tandem.Coordinator(tiny_schedule(1.0), max_busy_share=bad)
    assert e.value.name == "max_busy_share"
    assert "must be in (0, 1]: the operator's busy share cap (1: no cap)" in str(e.value)


def test_the_planners_coordinator_has_the_state_files_cap(tmp_path: Path) -> None:
    p = tandem.fit(
        small_demos(tmp_path),
        params={"sampler": {"samples": SAMPLES, "seed": 5}},
        max_busy_share=0.2,
    )
    path = tmp_path / "cell.tandem"
    p.save(path)
    back = tandem.Planner.load(path)
    rests = []
    for operator in [None, "slowest", "fastest"]:
        c = back.controller("rounds")
        assert c.max_busy_share == 0.2 and c.switch_ticks == 0
        lows = run_round(c, operator)
        busy = busy_by_hand(lows, 0)
        assert c.busy_ticks() == busy > 0
        rest = c.rest_ticks
        assert rest == rest_by_hand(busy, len(lows), 0.2)
        assert busy <= 0.2 * (len(lows) + rest)
        assert rest == 0 or busy > 0.2 * (len(lows) + rest - 1)
        assert c.rest_s == pytest.approx(rest * c.tick_s, rel=1e-12)
        rests.append(rest)
    assert max(rests) > 0, f"the cap never binds: {rests}"
    # Without a cap the planner's coordinator asks no rest.
    plain = tandem.fit(small_demos(tmp_path), params={"sampler": {"samples": SAMPLES, "seed": 5}})
    c = plain.controller("rounds")
    run_round(c, "slowest")
    assert (c.max_busy_share, c.rest_ticks) == (1.0, 0)


def test_the_docs_example_runs() -> None:
    text = (ROOT / "docs" / "python.md").read_text()
    start = text.index("### The operator's rest between rounds")
    end = text.index("\n### ", start + 1)
    blocks = re.findall(r"```python\n(.*?)```", text[start:end], flags=re.S)
    assert len(blocks) == 1
    exec(compile(blocks[0], "docs/python.md", "exec"), {})


def test_a_planned_schedules_coordinator_keeps_the_planned_switch_time(tmp_path: Path) -> None:
    # A planner's schedule carries its switch time: ``Coordinator(p.schedule)`` runs exactly as
    # ``p.controller("rounds")`` (robots leave their holds δ after the robots they wait for left
    # their stretches), tick for tick under every operator.
    p = tandem.fit(
        small_demos(tmp_path),
        params={"sampler": {"samples": SAMPLES, "seed": 5}},
        switch_s=0.2,
    )
    for operator in [None, "slowest", "fastest"]:
        mine = tandem.Coordinator(p.schedule)
        planners = p.controller("rounds")
        k = 0  # the least k with k·h ≥ δ, as the coordinator counts the switch time
        while k * mine.tick_s < 0.2:
            k += 1
        assert mine.switch_ticks == planners.switch_ticks == k > 0
        a, b = run_round(mine, operator), run_round(planners, operator)
        assert len(a) == len(b) and all((x == y).all() for x, y in zip(a, b))
    # A schedule of its own carries none.
    assert tandem.Coordinator(tiny_schedule(0.1)).switch_ticks == 0
