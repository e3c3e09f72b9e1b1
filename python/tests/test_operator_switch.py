"""The operator's switch time and load cap from Python (issue 41): ``switch_s=`` and
``max_busy_share=`` of ``fit`` and ``Planner.reschedule``, stored in the state file and read
back, and refused by name when out of range."""

from __future__ import annotations

from pathlib import Path

import pytest

import tandem

from conftest import DEMOS, SAMPLES


def small_demos(folder: Path) -> list[Path]:
    """Three demonstrations of a short task (0.55–0.65 s at 10 ms) whose middle third varies
    in force: low confidence there, high before and after, so a serial schedule of two robots
    keeps a short switch time (the CLI's small task, crates/tandem-cli/tests/common)."""
    paths = []
    for i, (n, bump) in enumerate([(60, 0.0), (66, 6.0), (56, 12.0)]):
        lines = ["t,x,force"]
        for k in range(n):
            u = k / (n - 1)
            f = 5.0 + bump if 1.0 / 3.0 <= u < 2.0 / 3.0 else 5.0
            lines.append(f"{k * 0.01:.2f},{u:.6f},{f:.4f}")
        path = folder / f"demo_{i}.csv"
        path.write_text("\n".join(lines) + "\n")
        paths.append(path)
    return paths


def test_fit_sets_them_save_and_load_read_them_back(tmp_path: Path) -> None:
    demos = small_demos(tmp_path)
    p = tandem.fit(
        demos,
        params={"sampler": {"samples": SAMPLES, "seed": 5}},
        switch_s=0.2,
        max_busy_share=0.9,
    )
    sampler = p.params["sampler"]
    assert (sampler["switch_s"], sampler["max_busy_share"]) == (0.2, 0.9)
    path = tmp_path / "cell.tandem"
    p.save(path)
    back = tandem.Planner.load(path).params["sampler"]
    assert (back["switch_s"], back["max_busy_share"]) == (0.2, 0.9)
    # Without the keywords: the parameters' values (none given: no switch time, no cap).
    plain = tandem.fit(demos, params={"sampler": {"samples": SAMPLES, "seed": 5}})
    sampler = plain.params["sampler"]
    assert (sampler["switch_s"], sampler["max_busy_share"]) == (0.0, 1.0)
    # The keywords win over the parameters' dict.
    both = tandem.fit(
        demos,
        params={"sampler": {"samples": SAMPLES, "seed": 5, "switch_s": 0.3}},
        switch_s=0.1,
    )
    assert both.params["sampler"]["switch_s"] == 0.1


def test_reschedule_makes_them_the_planners_and_they_are_saved(tmp_path: Path) -> None:
    p = tandem.fit(small_demos(tmp_path), params={"sampler": {"samples": SAMPLES, "seed": 5}})
    p.reschedule(samples=50, switch_s=0.2)
    sampler = p.params["sampler"]
    assert (sampler["switch_s"], sampler["max_busy_share"]) == (0.2, 1.0)
    p.reschedule(samples=50, max_busy_share=0.9)
    sampler = p.params["sampler"]
    assert (sampler["switch_s"], sampler["max_busy_share"]) == (0.2, 0.9)
    path = tmp_path / "cell.tandem"
    p.save(path)
    back = tandem.Planner.load(path).params["sampler"]
    assert (back["switch_s"], back["max_busy_share"]) == (0.2, 0.9)


def test_a_fresh_task_idles_between_the_robots_for_the_switch_time() -> None:
    # The sanding task just fitted is low-confidence from end to end: the robots' stretches
    # meet, so the serial schedule puts idle time between them (Eq. 20 constraint 2 relaxed
    # by the switch time; docs/decisions.md, "A schedule always exists with a switch time").
    p = tandem.fit(DEMOS, params={"sampler": {"samples": SAMPLES, "seed": 5}}, switch_s=2.5)
    s = p.schedule
    duration = s.t_total_s - s.offsets[0]
    # Robot 2 starts 2.5 s and a few ticks more after robot 1 ended (the least gap the
    # margin check accepts: `tandem fit --switch-s 2` gives 2.06 s at 10 ms).
    gap = s.offsets[0] - duration
    assert 2.5 <= gap <= 3.0, gap
    # The planner's schedule runs: its coordinator is built from it as checked.
    c = tandem.Coordinator(s)
    c.tick()
    # Without the switch time the robots meet; re-planning with one idles them again.
    q = tandem.fit(DEMOS, params={"sampler": {"samples": SAMPLES, "seed": 5}})
    q.reschedule(samples=50, switch_s=1.5)
    assert q.params["sampler"]["switch_s"] == 1.5
    assert q.schedule.offsets[0] - (q.schedule.t_total_s - q.schedule.offsets[0]) >= 1.5


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
