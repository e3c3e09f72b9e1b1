"""The examples under examples/python run (reduced sizes) and say what they promise."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

from conftest import ROOT

EXAMPLES = ROOT / "examples" / "python"


def run(script: str, *args: str) -> str:
    out = subprocess.run(
        [sys.executable, str(EXAMPLES / script), *args],
        capture_output=True,
        text=True,
        check=False,
        cwd=ROOT,
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_quickstart(tmp_path: Path) -> None:
    state = tmp_path / "cell.tandem"
    out = run("quickstart.py", "--rounds", "2", "--samples", "100", "--save", str(state))
    assert re.search(r"round  2: T_total +\d+\.\d+ s", out), out
    assert "overlap ticks 0" in out
    assert state.exists()


def test_control_loop_reports_latency_and_no_overlap() -> None:
    out = run("control_loop.py", "--calls", "20000", "--samples", "100")
    assert "20000 ticks" in out
    # Rounds of every robot, never "the pair" (the loop runs any number of robots).
    assert re.search(r"\d+ complete rounds \(both robots to the end\)", out), out
    assert "pair" not in out
    assert "0 ticks with two robots low-confidence" in out
    assert re.search(r"Coordinator\.tick: p50 [\d.]+ µs, p99 [\d.]+ µs", out), out
