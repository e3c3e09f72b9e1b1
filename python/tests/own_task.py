"""A generated task that is not sanding, for the tests of docs/guide.md ("Your own task") and of
``examples/python/quickstart.py --demos-dir``: a peg insertion with other channels, two variable
sections and demonstrations of different lengths.

The task (100 Hz, time column ``t`` in seconds): channels ``px``, ``py``, ``pz`` (gripper
position, m), ``grip`` (gripper opening, m) and ``fz`` (insertion force, N).

1. Approach: ``px`` from 0 to 0.30 m (fixed).
2. **Search** (variable): a lateral ``py`` oscillation whose amplitude (2–15 mm) and number of
   turns differ between demonstrations, as a person feeling for the hole.
3. Descend: ``pz`` from 0.10 to 0.02 m (fixed).
4. **Insert** (variable): ``fz`` ramps to a level of 4–24 N that differs between
   demonstrations and holds it.
5. Retract: ``pz`` back to 0.10 m, ``grip`` opens (fixed).

The first demonstration (``peg_1.csv``, the reference of ``tandem fit``) has fixed phase
durations, so its search runs over 1.00–2.50 s and its insertion over 3.50–5.00 s of reference
time (the regions the guide's ``tandem need`` names); the others do the fixed phases at the
reference's pace within ±3 % and draw the durations of the search and the insertion (1.2–2.6 s
each), so they last from about 5.5 s to 8.3 s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

CHANNELS = ["px", "py", "pz", "grip", "fz"]
DT_S = 0.01
#: Phase durations of the reference demonstration (s): approach, search, descend, insert, retract.
REFERENCE_PHASES = (1.0, 1.5, 1.0, 1.5, 1.0)
#: Reference-time regions of the variable sections in the reference demonstration (s).
SEARCH_S = (1.0, 2.5)
INSERT_S = (3.5, 5.0)


def smooth(u: np.ndarray) -> np.ndarray:
    """Smoothstep from 0 to 1 over ``u`` in [0, 1]."""
    u = np.clip(u, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def demonstration(rng: np.random.Generator, phases=None) -> np.ndarray:
    """One demonstration as ``(T, 6)`` rows ``t, px, py, pz, grip, fz``."""
    if phases is None:
        # The fixed phases at the reference's pace within ±3 %, the variable ones freely.
        fixed = lambda d: d * rng.uniform(0.97, 1.03)  # noqa: E731
        phases = (
            fixed(REFERENCE_PHASES[0]),
            rng.uniform(1.2, 2.6),
            fixed(REFERENCE_PHASES[2]),
            rng.uniform(1.2, 2.6),
            fixed(REFERENCE_PHASES[4]),
        )
    amp = rng.uniform(0.002, 0.015)
    turns = rng.integers(1, 4)
    force = rng.uniform(4.0, 24.0)
    rows = []
    for k, dur in enumerate(phases):
        n = int(round(dur / DT_S))
        u = np.arange(n) / n
        s = smooth(u)
        px = 0.30 * s if k == 0 else np.full(n, 0.30)
        py = amp * np.sin(2 * np.pi * turns * u) * np.sin(np.pi * u) if k == 1 else np.zeros(n)
        if k < 2:
            pz = np.full(n, 0.10)
        elif k == 2:
            pz = 0.10 - 0.08 * s
        elif k == 3:
            pz = np.full(n, 0.02)
        else:
            pz = 0.02 + 0.08 * s
        grip = np.full(n, 0.01) if k < 4 else 0.01 + 0.03 * s
        if k == 3:
            fz = force * smooth(4 * u) * (1 - smooth(4 * u - 3))
        else:
            fz = np.zeros(n)
        rows.append(np.column_stack([px, py, pz, grip, fz]))
    x = np.vstack(rows)
    # Sensor noise: 30 µm on the positions, 0.1 N on the force.
    x[:, :4] += rng.normal(0.0, 0.00003, (len(x), 4))
    x[:, 4] += rng.normal(0.0, 0.1, len(x))
    t = np.arange(len(x)) * DT_S
    return np.column_stack([t, x])


def write_task(folder: Path, count: int = 6, seed: int = 11) -> list:
    """Writes ``peg_1.csv`` … ``peg_<count>.csv`` into ``folder``; returns their paths."""
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    paths = []
    for i in range(count):
        data = demonstration(rng, REFERENCE_PHASES if i == 0 else None)
        path = folder / f"peg_{i + 1}.csv"
        lines = [",".join(["t", *CHANNELS])]
        lines += [f"{r[0]:.2f}," + ",".join(f"{v:.6f}" for v in r[1:]) for r in data]
        path.write_text("\n".join(lines) + "\n")
        paths.append(path)
    return paths
