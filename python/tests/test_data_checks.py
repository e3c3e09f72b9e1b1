"""Data is checked where it enters, in the library, the same from Python as from the command
line: the sample period of executions (resampled or refused), complete executions, outlier
demonstrations, time-like columns, rounds recorded twice, the chosen tick; and the state file's
lock (no writer overwrites another's round)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import tandem
from conftest import DEMOS, LABELS, SAMPLES, load_arrays

PARAMS = {"sampler": {"samples": SAMPLES, "seed": 5}}


def mean_execution_s(planner: tandem.Planner) -> float:
    """The model's mean execution duration ``Σ_n ψ̄̇(n)·Δt_s`` (s)."""
    return float(planner.model.grad_mean.sum() * planner.model.dt_s)


def at_1khz(args: dict) -> dict:
    """A simulated round's ``record_args`` as a 1 kHz logger would have taken them: every
    array interpolated at 1 ms (flags of the nearest 10 ms tick), ten samples per tick."""
    out = {k: [] for k in ("executions", "ref_time_logs", "supervised", "corrected")}
    for x, log, sup, cor in zip(
        args["executions"], args["ref_time_logs"], args["supervised"], args["corrected"]
    ):
        n = len(log)
        fine = np.arange(10 * (n - 1) + 1) / 10.0
        out["executions"].append(
            np.column_stack([np.interp(fine, np.arange(n), x[:, j]) for j in range(x.shape[1])])
        )
        out["ref_time_logs"].append(np.interp(fine, np.arange(n), log))
        nearest = np.rint(fine).astype(int)
        out["supervised"].append(np.asarray(sup)[nearest])
        # A correction lasts its whole 10 ms tick.
        out["corrected"].append(np.asarray(cor)[nearest])
    return out


def test_a_1_khz_log_is_resampled_never_a_model_whose_mean_execution_triples() -> None:
    planner = tandem.fit(DEMOS, params=PARAMS)
    before = mean_execution_s(planner)
    run = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=4, planner=planner), seed=4)
    args = run.record_args()
    fast = at_1khz(args)
    # The same round at 100 Hz, for comparison.
    reference = tandem.fit(DEMOS, params=PARAMS)
    reference.record_round(**args)
    # Given as ticks of the 10 ms schedule, the 1 kHz log would last ten times too long:
    # refused, with the fix, and nothing recorded.
    with pytest.raises(tandem.InputError, match="give its sample period"):
        planner.record_round(**fast)
    assert planner.rounds_recorded == 0
    # With its period it is resampled to the model's 10 ms, and said.
    with pytest.warns(tandem.DataWarning, match=r"logged 0\.001 s apart, resampled to the model's 0\.01 s"):
        report = planner.record_round(**fast, dt_s=0.001)
    assert len(report["notices"]) == 2
    after = mean_execution_s(planner)
    assert after < 1.05 * before, (before, after)
    assert abs(after - mean_execution_s(reference)) < 0.01 * after
    np.testing.assert_allclose(
        planner.confidence.observations.supervised.sum(),
        reference.confidence.observations.supervised.sum(),
        rtol=0.01,
    )


def stamped_at_250hz(args: dict, channels: list, tmp: Path, rng: np.random.Generator) -> dict:
    """A simulated round as a 250 Hz logger with its own clock would have written it: each
    robot's execution a CSV file with a `t` column (stamps ±1.2 ms off their 4 ms grid, 30 %
    of a period, and three rows dropped), its log and flags arrays with one entry per row
    (flags of the nearest 10 ms tick)."""
    out = {k: [] for k in ("executions", "ref_time_logs", "supervised", "corrected")}
    for i, (x, log, sup, cor) in enumerate(
        zip(args["executions"], args["ref_time_logs"], args["supervised"], args["corrected"])
    ):
        n = len(log)
        m = int(round((n - 1) * 0.01 / 0.004))
        t = 0.004 * np.arange(m + 1)
        t[1:-1] += rng.uniform(-0.0012, 0.0012, m - 1)
        keep = np.ones(m + 1, bool)
        keep[rng.choice(np.arange(10, m - 10), 3, replace=False)] = False
        t = t[keep]
        tick = np.minimum(t / 0.01, n - 1)
        cols = [np.interp(tick, np.arange(n), x[:, j]) for j in range(x.shape[1])]
        path = tmp / f"robot_{i + 1}.csv"
        np.savetxt(path, np.column_stack([t] + cols), delimiter=",", header=",".join(["t"] + channels), comments="")
        nearest = np.rint(tick).astype(int)
        out["executions"].append(path)
        out["ref_time_logs"].append(np.interp(tick, np.arange(n), log))
        out["supervised"].append(np.asarray(sup)[nearest])
        out["corrected"].append(np.asarray(cor)[nearest])
    return out


def test_a_250_hz_log_with_its_own_jittered_clock_is_recorded_with_resample(tmp_path: Path) -> None:
    planner = tandem.fit(DEMOS, params=PARAMS)
    run = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=6, planner=planner), seed=6)
    args = run.record_args()
    stamped = stamped_at_250hz(args, list(planner.model.channels), tmp_path, np.random.default_rng(6))
    reference = tandem.fit(DEMOS, params=PARAMS)
    reference.record_round(**args)
    # The dropped rows put stamps half a period off the grid: refused, naming the option.
    with pytest.raises(tandem.InputError, match=r"off the even grid.*resample=True") as e:
        planner.record_round(**stamped)
    assert e.value.file == str(stamped["executions"][0])
    assert planner.rounds_recorded == 0
    with pytest.warns(tandem.DataWarning) as caught:
        report = planner.record_round(**stamped, resample=True)
    said = [str(w.message) for w in caught]
    assert any("its log and flags put on the same grid" in m for m in said), said
    assert any("resampled to the model's 0.01 s" in m for m in said), said
    assert len(report["notices"]) == 2
    # The same round as the 100 Hz logger's, within what interpolation changes.
    assert abs(mean_execution_s(planner) - mean_execution_s(reference)) < 0.01 * mean_execution_s(reference)
    obs, ref = planner.confidence.observations, reference.confidence.observations
    np.testing.assert_allclose(obs.supervised.sum(), ref.supervised.sum(), rtol=0.02)
    assert obs.total_corrections > 0 and ref.total_corrections > 0
    # Arrays carry no times to resample.
    with pytest.raises(tandem.InputError, match="resample=True needs the time of every row"):
        reference.record_round(**args, resample=True)
    # One log entry per row of the file, not per grid sample.
    short = {**stamped, "ref_time_logs": [v[:-1] for v in stamped["ref_time_logs"]]}
    with pytest.raises(tandem.InputError, match="one per row"):
        reference.record_round(**short, resample=True)


def test_a_coarser_log_is_refused() -> None:
    planner = tandem.fit(DEMOS, params=PARAMS)
    args = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=1, planner=planner), seed=1).record_args()
    with pytest.raises(tandem.InputError, match="coarser than the model's 0.01 s") as e:
        planner.record_round(**{**args, "dt_s": 0.02})
    assert e.value.file == "executions[0]"
    with pytest.raises(tandem.ParamError, match="dt_s"):
        planner.record_round(**{**args, "dt_s": -1.0})


def test_a_truncated_execution_is_refused() -> None:
    planner = tandem.fit(DEMOS, params=PARAMS)
    args = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=2, planner=planner), seed=2).record_args()
    half = len(args["ref_time_logs"][1]) // 2
    cut = {k: [v[0], v[1][:half]] for k, v in args.items()}
    with pytest.raises(tandem.InputError, match=r"ends at reference sample .*whole task") as e:
        planner.record_round(**cut)
    assert e.value.file == "executions[1]"
    assert planner.rounds_recorded == 0


def test_the_same_round_twice_is_refused() -> None:
    planner = tandem.fit(DEMOS, params=PARAMS)
    args = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=3, planner=planner), seed=3).record_args()
    planner.record_round(**args)
    before = planner.schedule.t_total_s
    with pytest.raises(tandem.InputError, match="already recorded as round 1"):
        planner.record_round(**args)
    swapped = {k: v[::-1] for k, v in args.items()}
    with pytest.raises(tandem.InputError, match="record each round once"):
        planner.record_round(**swapped)
    assert planner.rounds_recorded == 1 and planner.schedule.t_total_s == before


def test_outlier_demonstrations_are_refused_or_warned_with_the_fix() -> None:
    channels, demo0 = load_arrays(DEMOS[0])
    demos = [load_arrays(p)[1] for p in DEMOS]
    # 0.4 s: 40 samples of a ~99 s task.
    with pytest.raises(tandem.InputError, match=r"0\.39 s long, 0\.00× the median.*leave it out"):
        tandem.fit_model(demos + [demo0[:40]], channels=channels, dt_s=0.01)
    # Half the task: 0.53× the median, inside the length band (a warning), but it does not
    # reach the end of the task: refused with the fix (issue 39).
    with pytest.warns(tandem.DataWarning, match=r"demos\[6\]: .* 0\.53× the median demonstration .*trim it or leave it out"):
        with pytest.raises(tandem.InputError, match=r"demos\[6\]: does not reach the end of the task.*demonstrate the whole task again"):
            tandem.fit_model(demos + [demos[1][: len(demos[1]) // 2]], channels=channels, dt_s=0.01)
    # The fixtures themselves raise no warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tandem.fit_model(DEMOS)


def test_a_time_column_under_another_name_is_refused(tmp_path: Path) -> None:
    text = DEMOS[1].read_text()
    header, rest = text.split("\n", 1)
    assert header.startswith("t,")
    bad = tmp_path / "demo_time.csv"
    bad.write_text("time," + header[2:] + "\n" + rest)
    with pytest.raises(tandem.InputError, match=r"column `time` looks like a time column.*rename it to `t`") as e:
        tandem.fit([DEMOS[0], bad], params=PARAMS)
    assert (e.value.file, e.value.line, e.value.column) == (str(bad), 1, 1)
    channels, x = load_arrays(DEMOS[0])
    with pytest.raises(tandem.InputError, match="`stamp` looks like a time column"):
        tandem.fit_model([x, x], channels=["stamp"] + channels[1:], dt_s=0.01)


def test_a_file_without_t_states_its_assumed_period(tmp_path: Path) -> None:
    planner = tandem.fit(DEMOS, params=PARAMS)
    run = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=5, planner=planner), seed=5)
    args = run.record_args()
    files = []
    for i, x in enumerate(args["executions"]):
        path = tmp_path / f"exec{i}.csv"
        np.savetxt(path, x, delimiter=",", header=",".join(planner.model.channels), comments="", fmt="%.17g")
        files.append(path)
    with pytest.warns(tandem.DataWarning, match=r"exec0\.csv: no time column `t`: its samples are taken to be 0\.01 s apart \(100 Hz\)"):
        planner.record_round(**{**args, "executions": files})


def test_the_tick_a_user_chose_survives_record_round() -> None:
    planner = tandem.fit(DEMOS, params=PARAMS)
    args = tandem.sim.run_round(planner, tandem.sim.sanding_needs(LABELS, seed=6, planner=planner), seed=6).record_args()
    planner.reschedule(tick_s=0.005)
    assert planner.schedule.tick_s == 0.005
    planner.record_round(**args, dt_s=0.01)  # logged at the 10 ms tick it ran at
    assert planner.schedule.tick_s == 0.005
    planner.reschedule(samples=50)
    assert planner.schedule.tick_s == 0.005


def test_the_state_file_is_locked_and_never_overwritten_by_accident(tmp_path: Path) -> None:
    path = tmp_path / "cell.tandem"
    tandem.fit(DEMOS, params=PARAMS).save(path)
    loaded = tandem.Planner.load(path)
    args = tandem.sim.run_round(loaded, tandem.sim.sanding_needs(LABELS, seed=7, planner=loaded), seed=7).record_args()
    with tandem.Planner.locked(path) as planner:
        planner.record_round(**args)
        # Another writer waits for the lock, then gives up with a clear error.
        other = tandem.Planner.load(path)
        with pytest.raises(tandem.StateFileError, match="another process has been writing") as e:
            other.save(path, timeout_s=0.05)
        assert e.value.path == str(path)
    assert tandem.Planner.load(path).rounds_recorded == 1
    # A planner loaded before that save does not overwrite the recorded round.
    with pytest.raises(tandem.StateFileError, match="changed since this planner was loaded"):
        other.save(path)
    assert tandem.Planner.load(path).rounds_recorded == 1
    # An exception inside the block saves nothing.
    with pytest.raises(RuntimeError):
        with tandem.Planner.locked(path) as planner:
            planner.reschedule(samples=50)
            raise RuntimeError("abandon")
    assert tandem.Planner.load(path).rounds_recorded == 1
    # Saving over a file that is not a state file is refused.
    csv = tmp_path / "demo_3.csv"
    csv.write_text(DEMOS[3].read_text())
    with pytest.raises(tandem.StateFileError, match="refusing to overwrite.*not a tandem state file"):
        other.save(csv)
    assert csv.read_text() == DEMOS[3].read_text()


def test_a_time_column_wins_and_a_contradicting_dt_s_is_refused(tmp_path: Path) -> None:
    """A file's own ``t`` column sets the period; ``dt_s`` (for arrays and files without time)
    that contradicts it is a ParamError naming the file, not silently ignored. A logger's
    jitter within 25 % of a period is accepted with a warning naming the worst line."""
    with pytest.raises(tandem.ParamError, match=r"dt_s.*0\.02 s, but .*demo_0\.csv has its own time .* 0\.01 s"):
        tandem.fit(DEMOS[:3], params=PARAMS, dt_s=0.02)
    channels, x = load_arrays(DEMOS[0])
    n = 1500
    t = np.arange(n) * 0.01 + np.where((np.arange(n) % 7 == 3), 0.0015, 0.0)
    rows = [",".join(["t", *channels])] + [
        f"{float(ti)!r}," + ",".join(repr(float(v)) for v in xi) for ti, xi in zip(t, x[:n])
    ]
    jittered = tmp_path / "jittered.csv"
    jittered.write_text("\n".join(rows) + "\n")
    short = [tmp_path / f"s{k}.csv" for k in range(2)]
    for k, p in enumerate(short):
        _, xk = load_arrays(DEMOS[k + 1])
        p.write_text("\n".join([",".join(["t", *channels])] + [
            f"{i * 0.01:.2f}," + ",".join(repr(float(v)) for v in xi) for i, xi in enumerate(xk[:n])
        ]) + "\n")
    with pytest.warns(tandem.DataWarning, match=r"jittered\.csv:\d+: time column `t`: times deviate from the even grid of period 0\.01 s"):
        planner = tandem.fit([jittered, *short], params=PARAMS)
    assert planner.model.dt_s == 0.01
