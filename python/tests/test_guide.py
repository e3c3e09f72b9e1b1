"""docs/guide.md, "Your own task, end to end", runs as printed on a generated task that is not
sanding (``own_task.py``: other channels, two variable sections, demonstrations of different
lengths): every ``$ `` command of its console blocks through the ``tandem`` command line, then
its Python loop; and ``examples/python/quickstart.py --demos-dir`` works on that folder."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

import tandem
from conftest import ROOT, cli
from own_task import CHANNELS, INSERT_S, SEARCH_S, write_task

GUIDE = ROOT / "docs" / "guide.md"
SECTION = "## Your own task, end to end"


def section() -> str:
    text = GUIDE.read_text()
    start = text.index(SECTION)
    end = text.find("\n## ", start + len(SECTION))
    return text[start : end if end > 0 else len(text)]


def blocks(kind: str) -> list:
    return re.findall(rf"```{kind}\n(.*?)```", section(), flags=re.S)


def commands() -> list:
    return [
        line[2:]
        for block in blocks("console")
        for line in block.splitlines()
        if line.startswith("$ ")
    ]


def shell(cmd: str, cwd: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ, PATH=f"{cli().parent}{os.pathsep}{os.environ['PATH']}")
    out = subprocess.run(
        ["bash", "-c", cmd], cwd=cwd, env=env, capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, f"$ {cmd}\n{out.stdout}\n{out.stderr}"
    return out


def low_regions_s(state: Path, cwd: Path) -> list:
    doc = json.loads(shell(f"tandem inspect {state} --json", cwd).stdout)
    return [(r["start_s"], r["end_s"]) for r in doc["confidence"]["low_regions"]]


def test_the_generated_task_is_not_sanding(tmp_path: Path) -> None:
    paths = write_task(tmp_path)
    lengths = {len(p.read_text().splitlines()) - 1 for p in paths}
    assert 5 <= len(paths) <= 8 and len(lengths) == len(paths), lengths
    assert paths[0].read_text().splitlines()[0] == ",".join(["t", *CHANNELS])


def test_the_guides_commands_and_loop_run_on_a_task_of_your_own(tmp_path: Path) -> None:
    write_task(tmp_path)
    cmds = commands()
    # The section walks through every step: fit, inspect, need, simulate, record, schedule.
    for verb in ("fit", "inspect", "need", "simulate", "record", "schedule"):
        assert any(c.startswith(f"tandem {verb} ") for c in cmds), verb
    for cmd in cmds:
        shell(cmd, tmp_path)
    state = tmp_path / "peg.tandem"
    # The fit found the two variable sections and trusted most of the rest: the two longest
    # low-confidence regions are the search and the insertion, and the low-confidence time
    # more than 0.5 s away from both (one-sample islands of sensor noise) is under 5 %.
    lows = low_regions_s(state, tmp_path)
    longest = sorted(sorted(lows, key=lambda r: r[1] - r[0])[-2:])
    assert len(longest) == 2, lows
    for (a, b), (lo, hi) in zip(longest, (SEARCH_S, INSERT_S)):
        assert a < hi and b > lo, (a, b, lows)
    near = [(lo - 0.5, hi + 0.5) for lo, hi in (SEARCH_S, INSERT_S)]
    stray = sum(
        max(0.0, (b - a) - sum(max(0.0, min(b, hi) - max(a, lo)) for lo, hi in near))
        for a, b in lows
    )
    duration = json.loads(shell(f"tandem inspect {state} --json", tmp_path).stdout)["model"][
        "reference_duration_s"
    ]
    assert stray < 0.05 * duration, (stray, lows)
    # The need file marks exactly the two regions, at their levels.
    rows = (tmp_path / "need.csv").read_text().splitlines()
    assert rows[0] == "need,region"
    p = np.array([float(r.split(",")[0]) for r in rows[1:]])
    n = np.arange(len(p)) * 0.01
    np.testing.assert_array_equal(p[(n >= 1.0 - 1e-9) & (n < 2.5 - 1e-9)], 0.5)
    np.testing.assert_array_equal(p[(n >= 3.5 - 1e-9) & (n < 5.0 - 1e-9)], 0.3)
    assert p.sum() == 0.5 * 150 + 0.3 * 150
    schedule = json.loads((tmp_path / "schedule.json").read_text())
    assert schedule["t_total_s"] > 0
    # Python's profile of the same regions draws like `tandem simulate`, from the same file.
    planner = tandem.Planner.load(state)
    from_regions = tandem.sim.needs(
        regions=[(1.0, 2.5, 0.5), (3.5, 5.0, 0.3)], planner=planner, seed=4
    )
    from_file = tandem.sim.needs(need_file=tmp_path / "need.csv", planner=planner, seed=4)
    np.testing.assert_array_equal(from_regions, from_file)
    assert from_regions.shape == (planner.n_robots, planner.model.n_ref)
    # The Python loop: two rounds through the coordinator, recorded and saved.
    rounds_before = planner.rounds_recorded
    (python,) = blocks("python")
    out = subprocess.run(
        [sys.executable, "-c", python], cwd=tmp_path, capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr
    assert re.findall(r"round \d: T_total \d+\.\d+ s", out.stdout) and "round 2" in out.stdout
    assert tandem.Planner.load(state).rounds_recorded == rounds_before + 2


def test_quickstart_runs_on_any_demonstration_folder(tmp_path: Path) -> None:
    write_task(tmp_path / "demos")
    script = ROOT / "examples" / "python" / "quickstart.py"
    run = lambda *a: subprocess.run(  # noqa: E731
        [sys.executable, str(script), "--demos-dir", str(tmp_path / "demos"), "--rounds", "3",
         "--samples", "100", *a],
        capture_output=True, text=True, check=False,
    )
    # No label files: the operator channel is not `force`, and the needs come from the fit.
    missing = run()
    assert missing.returncode != 0 and "--channel" in missing.stderr, missing.stderr
    out = run("--channel", "fz")
    assert out.returncode == 0, out.stderr
    assert "low-confidence region(s)" in out.stdout and "round  3: T_total" in out.stdout
    assert "overlap ticks 0" in out.stdout
    need = tmp_path / "need.csv"
    shell(f"tandem fit demos/peg_?.csv --samples 100 -o cell.tandem", tmp_path)
    shell("tandem need cell.tandem --region 3.5-5.0=1 -o need.csv", tmp_path)
    out = run("--channel", "fz", "--need", str(need))
    assert out.returncode == 0, out.stderr
    assert f"needs: {need}" in out.stdout
