"""Shared fixtures of the Python tests: the repository's sanding demonstrations, planners fitted
on them with reduced sampler sizes, and the command line built by ``cargo xtask test``."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

import tandem

ROOT = Path(__file__).resolve().parents[2]
SANDING = ROOT / "fixtures" / "sanding"
DEMOS = [SANDING / f"demo_{i}.csv" for i in range(6)]
#: The ground-truth labels, one file per demonstration: `tandem.sim.sanding_needs` takes the
#: planner's reference's (the fit's default reference is the medoid, not demo 0).
LABELS = SANDING

#: Sampler size of the tests' planners (the paper's 5000 is not needed to test the plumbing).
SAMPLES = 200
#: A confidence that latches as soon as the votes allow (ten, five pairs), so that schedules
#: overlap quickly.
QUICK_CONFIDENCE = {"mu_c": 0.3, "gamma_c": 0.5}


def cli() -> Path:
    """The ``tandem`` command line: ``$TANDEM_CLI`` (set by ``cargo xtask test``), else the
    debug build under target/."""
    path = Path(os.environ.get("TANDEM_CLI", ROOT / "target" / "debug" / "tandem"))
    if not path.exists():
        raise FileNotFoundError(f"{path}: build the command line first (cargo build -p tandem-cli)")
    return path


def load_arrays(path: Path):
    """A fixture CSV as ``(channels, samples)`` without its ``t`` column, read by NumPy."""
    header = path.read_text().split("\n", 1)[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    keep = [k for k, h in enumerate(header) if h != "t"]
    return [header[k] for k in keep], data[:, keep]


def record_rounds(planner: tandem.Planner, rounds: int, seed0: int = 0) -> None:
    """Runs and records ``rounds`` rounds in the simulated workcell."""
    for k in range(seed0, seed0 + rounds):
        needs = tandem.sim.sanding_needs(LABELS, seed=k, planner=planner)
        run = tandem.sim.run_round(planner, needs, seed=k)
        planner.record_round(**run.record_args())


@pytest.fixture(scope="session")
def planner() -> tandem.Planner:
    """The fixtures fitted with the default model and confidence, 200 samples per schedule."""
    return tandem.fit(DEMOS, params={"sampler": {"samples": SAMPLES, "seed": 5}})


@pytest.fixture(scope="session")
def overlapping_planner() -> tandem.Planner:
    """A planner whose schedule overlaps the robots (quick confidence, six rounds recorded:
    twelve votes, past the ten on which a supervised sample is trusted, `MIN_VOTES`; at five
    rounds the prior-trusted runs between needed samples still yield, so robot 2 starts at
    71 % of robot 1's execution, at six at 12 %)."""
    p = tandem.fit(
        DEMOS,
        params={"sampler": {"samples": SAMPLES, "seed": 3}, "confidence": QUICK_CONFIDENCE},
    )
    record_rounds(p, 6)
    assert p.schedule.offsets[0] < p.schedule.durations_s[0] / 2, "the robots overlap"
    return p
