"""A cell of different tasks on different robots from Python (issue 45): ``tandem.fit_cell``
writes the command line's ``fit --task … --robots …`` state file byte for byte, each side
opens the other's, a round records each robot's execution into its own task, and bad
arguments name the fix."""

from __future__ import annotations

import json
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest

import tandem
from conftest import ROOT, cli

EXAMPLES = ROOT / "fixtures" / "examples"
PARAMS = EXAMPLES / "params.toml"
A = [EXAMPLES / f"demo_{i}.csv" for i in (0, 1, 2)]
B = [EXAMPLES / f"demo_{i}.csv" for i in (0, 2)]


def run_cli(*args: object) -> str:
    out = subprocess.run(
        [str(cli()), *map(str, args)], capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def fit_ab() -> tandem.CellPlanner:
    return tandem.fit_cell({"a": A, "b": B}, robots={"a": 2}, params=PARAMS)


def test_fit_cell_writes_the_clis_cell_bytes(tmp_path: Path) -> None:
    run_cli(
        "fit",
        "--task", "a=" + ",".join(map(str, A)),
        "--task", "b=" + ",".join(map(str, B)),
        "--robots", "a=2,b=1",
        "--params", PARAMS,
        "-o", tmp_path / "cli.tandem",
    )  # fmt: skip
    cell = fit_ab()
    cell.save(tmp_path / "py.tandem")
    assert (tmp_path / "py.tandem").read_bytes() == (tmp_path / "cli.tandem").read_bytes()
    assert cell.tasks == ["a", "b"]
    assert cell.robot_tasks == ["a", "a", "b"]
    assert cell.n_robots == 3 and cell.rounds_recorded == 0
    assert "a×2" in repr(cell) and "b×1" in repr(cell)
    assert "fit_cell" in tandem.__all__ and "CellPlanner" in tandem.__all__
    # The command line reads the file Python wrote: the same schedule.
    doc = json.loads(run_cli("schedule", tmp_path / "py.tandem", "--json"))
    s = cell.schedule
    assert doc["robot_tasks"] == cell.robot_tasks
    assert doc["schedule"]["t_total_s"] == s["t_total_s"] == cell.t_total_s
    assert [r["start_s"] for r in doc["schedule"]["robots"]] == s["starts_s"]
    assert s["lower_bound_s"] <= s["t_total_s"]
    assert max(s["ends_s"]) == pytest.approx(s["t_total_s"], abs=1e-9)
    # Each robot's low-confidence stretches lie on its own task's reference samples.
    for robot, start, end, r0, r1 in s["lc_intervals"]:
        task = cell.planner(cell.robot_tasks[robot])
        assert 0 <= r0 < r1 <= task.model.n_ref and start < end


def test_a_round_goes_into_each_robots_task(tmp_path: Path) -> None:
    cell = fit_ab()
    path = tmp_path / "cell.tandem"
    cell.save(path)
    # The example round was logged on demo 0, the reference of both tasks: robot 3 (task b)
    # records robot 1's execution.
    files = [1, 2, 1]
    ex = [EXAMPLES / f"pair_1_robot_{k}.csv" for k in files]
    logs = [np.loadtxt(EXAMPLES / f"pair_1_robot_{k}.reflog.csv", skiprows=1) for k in files]
    flags = [
        np.loadtxt(EXAMPLES / f"pair_1_robot_{k}.corr.csv", skiprows=1, delimiter=",")
        for k in files
    ]
    a_before = cell.planner("a").confidence.high.copy()
    report = cell.record_round(
        ex, logs, [f[:, 0].astype(bool) for f in flags], [f[:, 1].astype(bool) for f in flags]
    )
    assert set(report["tasks"]) == {"a", "b"}
    assert report["t_total_s"] == cell.t_total_s
    assert cell.rounds_recorded == 1
    # Task a got robots 1 and 2's executions, task b robot 3's: one round each.
    assert cell.planner("a").rounds_recorded == cell.planner("b").rounds_recorded == 1
    assert cell.planner("a").confidence.high.shape == a_before.shape
    cell.save(path)
    # The command line records the same round into the file Python saved, from the same
    # files: its state then equals Python's (one planner, one state file).
    again = tandem.CellPlanner.load(path)
    assert again.rounds_recorded == 1 and again.t_total_s == cell.t_total_s
    fresh = tmp_path / "cli.tandem"
    fit_ab().save(fresh)
    args = []
    for k in files:
        args += [
            "--execution", EXAMPLES / f"pair_1_robot_{k}.csv",
            "--log", EXAMPLES / f"pair_1_robot_{k}.reflog.csv",
            "--corrections", EXAMPLES / f"pair_1_robot_{k}.corr.csv",
        ]  # fmt: skip
    run_cli("record", fresh, *args)
    assert fresh.read_bytes() == path.read_bytes()
    # A round of two executions for three robots: nothing recorded.
    with pytest.raises(tandem.InputError, match="3 robots"):
        cell.record_round(ex[:2], logs[:2], [f[:, 0] for f in flags[:2]], [f[:, 1] for f in flags[:2]])
    assert cell.rounds_recorded == 1


def test_a_cells_coordinator_runs_every_robot_on_its_own_task() -> None:
    cell = fit_ab()
    c = cell.coordinator()
    assert c.n_robots == 3
    np.testing.assert_allclose(c.starts_s, cell.schedule["starts_s"], atol=1e-9)
    ticks = 0
    while not c.is_finished and ticks < 10_000:
        t = c.tick(None)
        assert not t.overlap and t.fault is None
        ticks += 1
    # The passive operator runs every robot at its planned speed: the round ends at the
    # planned T_total, to a tick.
    assert ticks * c.tick_s == pytest.approx(cell.t_total_s, abs=2 * c.tick_s)


def test_bad_cell_arguments_name_the_fix() -> None:
    with pytest.raises(tandem.ParamError, match="no task"):
        tandem.fit_cell({})
    with pytest.raises(tandem.ParamError, match='robots: no task "c"'):
        tandem.fit_cell({"a": A, "b": B}, robots={"c": 1}, params=PARAMS)
    with pytest.raises(tandem.ParamError, match="robots"):
        tandem.fit_cell({"a": A, "b": B}, robots=2, params=PARAMS)
    with pytest.raises(tandem.InputError, match='task "b", demos'):
        tandem.fit_cell({"a": A, "b": B[:1]}, params=PARAMS)
    with pytest.raises(tandem.ParamError, match='no task "z"'):
        fit_ab().planner("z")
    # A plain planner's loader refuses a cell, naming the cell's loader.
    with pytest.raises(tandem.StateFileError, match="CellPlanner.load"):
        tandem.Planner.load(ROOT / "fixtures" / "state" / "mixed.tandem")


def zero_stored_offset(path: Path, offset: float) -> None:
    """Sets the stored start offset ``offset`` (its one occurrence in the file) to 0 and
    rewrites the header's CRC-32 of the payload (bytes 20..24, the payload from byte 24)."""
    data = bytearray(path.read_bytes())
    needle = struct.pack("<d", offset)
    assert data.count(needle) == 1
    i = data.index(needle)
    data[i : i + 8] = struct.pack("<d", 0.0)
    data[20:24] = struct.pack("<I", zlib.crc32(bytes(data[24:])))
    path.write_bytes(bytes(data))


def test_a_stored_schedule_that_fails_the_check_warns_as_planner_load_does(
    tmp_path: Path,
) -> None:
    # Robot 2 moved to start with robot 1: both low-confidence at once (Eq. 20, constraint 3).
    one = tmp_path / "one.tandem"
    planner = tandem.fit(A, robots=2, params=PARAMS)
    planner.save(one)
    assert planner.schedule.offsets[0] > 0.0
    zero_stored_offset(one, float(planner.schedule.offsets[0]))
    with pytest.warns(tandem.DataWarning, match="fails this build's check") as want:
        tandem.Planner.load(one)
    with pytest.warns(tandem.DataWarning, match="fails this build's check") as got:
        cell = tandem.CellPlanner.load(one)
    assert [str(w.message) for w in got] == [str(w.message) for w in want]
    assert str(one) in str(got[0].message)
    assert cell.tasks == ["task"]
    # A cell of two tasks: the warning names the task whose stored schedule was replaced.
    two = tmp_path / "two.tandem"
    ab = fit_ab()
    ab.save(two)
    offset = float(ab.planner("a").schedule.offsets[0])
    assert offset > 0.0
    zero_stored_offset(two, offset)
    with pytest.warns(tandem.DataWarning, match="task `a`: the stored schedule fails") as got:
        loaded = tandem.CellPlanner.load(two)
    assert len(got) == 1 and str(two) in str(got[0].message)
    assert loaded.tasks == ["a", "b"]
