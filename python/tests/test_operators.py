"""M operators from Python (issue 44): ``operators=`` of ``fit`` and ``Planner.reschedule``,
the sectored round in rounds (``Planner.sectored_rounds``, ``Planner.controller``), one input
per operator per tick, and each low-confidence robot's operator in ``Tick.operator``."""

from __future__ import annotations

from pathlib import Path

import pytest

import tandem

from conftest import SAMPLES
from test_operator_switch import small_demos


def test_rounds_with_two_operators_run_in_sectors(tmp_path: Path) -> None:
    demos = small_demos(tmp_path)
    p = tandem.fit(
        demos, params={"sampler": {"samples": SAMPLES, "seed": 5}}, robots=4, operators=2
    )
    assert p.params["sampler"]["operators"] == 2
    s = p.sectored_rounds()
    # Four robots, two operators: two sectors of two, robots 0-1 and 2-3.
    assert s["sizes"] == [2, 2]
    assert s["sector_of"] == [0, 0, 1, 1]
    assert s["lower_bound_s"] <= s["t_total_s"]
    # One operator's round of all four robots is longer than the sectors' (each sector has
    # half the stretches to take in turn).
    assert s["t_total_s"] < p.schedule.t_total_s
    c = p.controller("rounds")
    assert c.operators == 2
    with pytest.raises(tandem.InputError):
        c.tick("fastest")  # one input for two operators: refused, the coordinator unchanged
    lc_ticks = 0
    max_lc = 0
    ticks = 0
    while not c.is_finished:
        t = c.tick(["fastest", "slowest"])
        ticks += 1
        assert t.fault is None
        low = [i for i in range(4) if t.low_conf[i]]
        max_lc = max(max_lc, len(low))
        for i in range(4):
            # Each low-confidence robot under its sector's operator, the others under none.
            assert t.operator[i] == (s["sector_of"][i] if t.low_conf[i] else None)
        # At most one robot per operator.
        assert len({t.operator[i] for i in low}) == len(low)
        lc_ticks += len(low)
        assert ticks < 100_000
    assert lc_ticks > 0 and max_lc <= 2
    # The round ran no longer than its slowest sector at the slowest inputs allow, and its
    # sectors' robots ended at their own schedule's ends: the coordinator's ends are the
    # sectored round's, the latest at its T_total.
    assert max(c.ends_s) == pytest.approx(s["t_total_s"], abs=1e-9)


def test_reschedule_sets_operators_saved_and_refused_by_name(tmp_path: Path) -> None:
    p = tandem.fit(small_demos(tmp_path), params={"sampler": {"samples": SAMPLES, "seed": 5}})
    assert p.params["sampler"]["operators"] == 1
    assert p.controller("rounds").operators == 1
    p.reschedule(samples=SAMPLES, operators=2)
    assert p.params["sampler"]["operators"] == 2
    path = tmp_path / "cell.tandem"
    p.save(path)
    assert tandem.Planner.load(path).params["sampler"]["operators"] == 2
    for bad in (0, 17):
        with pytest.raises(tandem.ParamError) as e:
            p.reschedule(samples=SAMPLES, operators=bad, switch_s=0.1)
        assert "operators" in str(e.value)
        # Refused: the planner as it was, its switch time too.
        assert p.params["sampler"]["operators"] == 2
        assert p.params["sampler"]["switch_s"] == 0.0
    with pytest.raises(tandem.ParamError):
        tandem.fit(small_demos(tmp_path), operators=0)
    # The continuous cell's M tokens take one input per operator too.
    cc = p.controller("continuous")
    assert cc.operators == 2
    t = cc.tick([None, None])
    assert len(t.operator) == 2
