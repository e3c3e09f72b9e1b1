"""Recorded rounds are never discarded without consent (``Planner.save`` onto a state file
holding rounds refuses unless ``force=True``; ``Planner.refit`` keeps them), and a
demonstration that does not reach the end of the task is refused (issue 39)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import tandem
from conftest import DEMOS, LABELS, SAMPLES, load_arrays

PARAMS = {"sampler": {"samples": SAMPLES, "seed": 5}}


def rounds_of(planner: tandem.Planner, seeds: range) -> list[dict]:
    """Runs and records one simulated round per seed; returns their ``record_round`` args."""
    args = []
    for k in seeds:
        run = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=k, planner=planner), seed=k)
        args.append(run.record_args())
        planner.record_round(**args[-1])
    return args


def test_a_save_over_recorded_rounds_needs_force_and_a_refit_keeps_them(tmp_path: Path) -> None:
    path = tmp_path / "cell.tandem"
    cell = tandem.fit(DEMOS[:3], params=PARAMS)
    recorded = rounds_of(cell, range(2))
    cell.save(path)
    before = path.read_bytes()
    fresh = tandem.fit(DEMOS[:3], params=PARAMS)
    with pytest.raises(tandem.StateFileError, match=r"holds 2 recorded round\(s\).*Planner\.refit.*force=True") as e:
        fresh.save(path)
    assert e.value.path == str(path)
    assert path.read_bytes() == before
    # A refit of the loaded cell keeps both rounds: the confidence of a fresh fit of the same
    # demonstrations with the same rounds recorded, and it saves into the file it came from.
    loaded = tandem.Planner.load(path)
    refit = loaded.refit(DEMOS[:4], params=PARAMS)
    assert refit.rounds_recorded == 2
    want = tandem.fit(DEMOS[:4], params=PARAMS)
    for args in recorded:
        want.record_round(**args)
    np.testing.assert_array_equal(refit.confidence.high, want.confidence.high)
    refit.save(path)
    assert tandem.Planner.load(path).rounds_recorded == 2
    # force=True replaces it and says what went.
    with pytest.warns(tandem.DataWarning, match=r"discarding its 2 recorded round\(s\)"):
        fresh.save(path, force=True)
    assert tandem.Planner.load(path).rounds_recorded == 0


def test_a_demonstration_cut_off_at_55_or_80_percent_is_refused() -> None:
    channels, _ = load_arrays(DEMOS[0])
    demos = [load_arrays(p)[1] for p in DEMOS[:3]]
    for share in (0.55, 0.8):
        cut = demos[1][: int(len(demos[1]) * share)]
        with pytest.raises(tandem.InputError, match=r"demos\[3\]: does not reach the end of the task") as e:
            tandem.fit_model(demos + [cut], channels=channels, dt_s=0.01)
        assert e.value.file == "demos[3]"
