"""Nothing silently wrong on a user's own data (issue 39, item 3): Python runs the command
line's checks of an execution's flags, and arrays without a period are not taken at 0.01 s
without a word."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import tandem
from conftest import DEMOS, LABELS, QUICK_CONFIDENCE, SAMPLES, load_arrays, record_rounds

PARAMS = {"sampler": {"samples": SAMPLES, "seed": 5}}


def test_a_correction_on_an_unsupervised_sample_is_refused(tmp_path: Path) -> None:
    # Two rounds with a quick confidence, so that the schedule runs samples unsupervised.
    planner = tandem.fit(DEMOS, params={**PARAMS, "confidence": QUICK_CONFIDENCE})
    record_rounds(planner, 2)
    run = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=9, planner=planner), seed=9)
    args = run.record_args()
    unsupervised = np.flatnonzero(~np.asarray(args["supervised"][1]))
    assert unsupervised.size, "the schedule runs some samples unsupervised"
    k = int(unsupervised[0])
    corrected = [np.array(c, dtype=bool) for c in args["corrected"]]
    corrected[1][k] = True
    planner.save(tmp_path / "before.tandem")
    with pytest.raises(tandem.InputError) as e:
        planner.record_round(**{**args, "corrected": corrected})
    msg = str(e.value)
    # The command line's words (`corr.csv:2: `corrected` is 1 but `supervised` is 0 (…)`),
    # located at the array's sample.
    assert f"executions[1]: sample {k}: `corrected` is 1 but `supervised` is 0" in msg, msg
    assert "only a supervised, low-confidence sample can be corrected" in msg
    # Nothing was recorded, nothing dropped.
    assert planner.rounds_recorded == 2
    planner.save(tmp_path / "after.tandem")
    assert (tmp_path / "after.tandem").read_bytes() == (tmp_path / "before.tandem").read_bytes()
    # The round as it ran records.
    report = planner.record_round(**args)
    assert planner.rounds_recorded == 3 and report["reopened"] >= 0


def test_a_correction_on_an_unsupervised_row_is_refused_before_regridding(
    tmp_path: Path,
) -> None:
    planner = tandem.fit(DEMOS, params=PARAMS)
    n = planner.model.n_ref
    channels = planner.model.channels
    mean = planner.model.mean
    rows = ["t," + ",".join(channels)]
    rows += [f"{k * 0.01:.4f}," + ",".join(f"{v:.9g}" for v in mean[k]) for k in range(n)]
    path = tmp_path / "exec.csv"
    path.write_text("\n".join(rows) + "\n")
    log = np.arange(n, dtype=float)
    sup = np.ones(n, dtype=bool)
    sup[7] = False
    cor = np.zeros(n, dtype=bool)
    cor[7] = True
    with pytest.raises(tandem.InputError, match="row 7: `corrected` is 1 but `supervised` is 0"):
        planner.record_round([path, path], [log, log], [sup, sup], [cor, cor], resample=True)
    assert planner.rounds_recorded == 0


def test_arrays_without_dt_s_warn_naming_the_assumed_period() -> None:
    loaded = [load_arrays(p) for p in DEMOS]
    channels = loaded[0][0]
    arrays = [x for _, x in loaded]
    with pytest.warns(tandem.DataWarning) as caught:
        tandem.fit_model(arrays, channels=channels)
    said = [str(w.message) for w in caught if "dt_s" in str(w.message)]
    assert len(said) == 1, said
    assert said[0].startswith("demos[0], demos[1] and 4 more are arrays without dt_s")
    assert "0.01 s apart (100 Hz)" in said[0] and "Pass dt_s=" in said[0]
    assert "deprecated" in said[0]
    # With the period given, nothing is assumed and nothing said about it.
    with warnings.catch_warnings():
        warnings.simplefilter("error", tandem.DataWarning)
        tandem.fit_model(arrays, channels=channels, dt_s=0.01)
    # Files carry their time: no such warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error", tandem.DataWarning)
        tandem.fit_model(DEMOS)


def test_200_hz_arrays_are_only_right_with_their_period() -> None:
    """The issue's case: arrays logged at 200 Hz, given without dt_s, were taken at 100 Hz
    without a word (the model ran twice as slow). Now it is said, a strict warning filter
    makes it an error, and with dt_s the model has the arrays' period."""
    loaded = [load_arrays(p) for p in DEMOS[:3]]
    channels = loaded[0][0]
    arrays = [x for _, x in loaded]
    with warnings.catch_warnings():
        warnings.simplefilter("error", tandem.DataWarning)
        with pytest.raises(tandem.DataWarning, match="without dt_s"):
            tandem.fit_model(arrays, channels=channels)
    right = tandem.fit_model(arrays, channels=channels, dt_s=0.005)
    with pytest.warns(tandem.DataWarning):
        assumed = tandem.fit_model(arrays, channels=channels)
    assert right.dt_s == 0.005 and assumed.dt_s == 0.01
    assert right.n_ref == assumed.n_ref


def test_rounds_run_concurrently_give_one_confidence_in_any_order(tmp_path: Path) -> None:
    """The issue's scenario in the workcell: six rounds run with the schedule of one state
    (several cells recording into one file, so in any order), recorded in three orders, give
    one confidence (docs/decisions.md, "The same rounds in any order")."""
    start = tandem.fit(DEMOS, params={**PARAMS, "confidence": QUICK_CONFIDENCE})
    start.save(tmp_path / "start.tandem")
    runs = [
        tandem.sim.run_round(start, tandem.sim.sanding_needs(LABELS, seed=k, planner=start), seed=k)
        for k in range(6)
    ]
    highs = []
    for order in ([0, 1, 2, 3, 4, 5], [5, 4, 3, 2, 1, 0], [2, 5, 0, 3, 1, 4]):
        planner = tandem.Planner.load(tmp_path / "start.tandem")
        for k in order:
            planner.record_round(**runs[k].record_args())
        highs.append(np.asarray(planner.confidence.high))
    assert highs[0].any() and not highs[0].all()
    for other in highs[1:]:
        np.testing.assert_array_equal(other, highs[0])
