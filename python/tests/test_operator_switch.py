"""The operator's switch time and load cap from Python (issue 41): ``switch_s=`` and
``max_busy_share=`` of ``fit`` and ``Planner.reschedule``, stored in the state file and read
back, and refused by name when out of range."""

from __future__ import annotations

from pathlib import Path

import pytest

import tandem

from conftest import DEMOS, SAMPLES


def test_fit_sets_them_save_and_load_read_them_back(tmp_path: Path) -> None:
    p = tandem.fit(
        DEMOS,
        params={"sampler": {"samples": SAMPLES, "seed": 5}},
        switch_s=2.5,
        max_busy_share=0.7,
    )
    sampler = p.params["sampler"]
    assert (sampler["switch_s"], sampler["max_busy_share"]) == (2.5, 0.7)
    path = tmp_path / "cell.tandem"
    p.save(path)
    back = tandem.Planner.load(path).params["sampler"]
    assert (back["switch_s"], back["max_busy_share"]) == (2.5, 0.7)
    # Without the keywords: the parameters' values (none given: no switch time, no cap).
    plain = tandem.fit(DEMOS, params={"sampler": {"samples": SAMPLES, "seed": 5}})
    sampler = plain.params["sampler"]
    assert (sampler["switch_s"], sampler["max_busy_share"]) == (0.0, 1.0)
    # The keywords win over the parameters' dict.
    both = tandem.fit(
        DEMOS,
        params={"sampler": {"samples": SAMPLES, "seed": 5, "switch_s": 1.0}},
        switch_s=3.0,
    )
    assert both.params["sampler"]["switch_s"] == 3.0


def test_reschedule_makes_them_the_planners_and_they_are_saved(tmp_path: Path) -> None:
    p = tandem.fit(DEMOS, params={"sampler": {"samples": SAMPLES, "seed": 5}})
    p.reschedule(samples=50, switch_s=1.5)
    sampler = p.params["sampler"]
    assert (sampler["switch_s"], sampler["max_busy_share"]) == (1.5, 1.0)
    p.reschedule(samples=50, max_busy_share=0.9)
    sampler = p.params["sampler"]
    assert (sampler["switch_s"], sampler["max_busy_share"]) == (1.5, 0.9)
    path = tmp_path / "cell.tandem"
    p.save(path)
    back = tandem.Planner.load(path).params["sampler"]
    assert (back["switch_s"], back["max_busy_share"]) == (1.5, 0.9)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        ({"switch_s": -1.0}, "switch_s"),
        ({"switch_s": float("nan")}, "switch_s"),
        ({"max_busy_share": 0.0}, "max_busy_share"),
        ({"max_busy_share": 1.5}, "max_busy_share"),
    ],
)
def test_out_of_range_values_are_refused_by_name(kwargs: dict, name: str) -> None:
    with pytest.raises(tandem.ParamError) as e:
        tandem.fit(DEMOS, params={"sampler": {"samples": SAMPLES}}, **kwargs)
    assert e.value.name == name
    p = tandem.fit(DEMOS, params={"sampler": {"samples": SAMPLES, "seed": 5}})
    before = p.params
    with pytest.raises(tandem.ParamError) as e:
        p.reschedule(samples=50, **kwargs)
    assert e.value.name == name
    assert p.params == before
