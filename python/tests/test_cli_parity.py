"""The bindings and the command line share one planner and one state file: the same inputs and
parameters give byte-identical state files, and a file written by one opens in the other."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np

import tandem
from conftest import DEMOS, LABELS, SAMPLES, cli, load_arrays

PARAMS = {"sampler": {"samples": SAMPLES, "seed": 5}}


def run_cli(*args: object) -> str:
    out = subprocess.run(
        [str(cli()), *map(str, args)], capture_output=True, text=True, check=False
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def cli_fit(path: Path) -> None:
    run_cli("fit", *DEMOS, "--output", path, "--samples", SAMPLES, "--seed", 5)


def test_fit_from_paths_writes_the_clis_state_bytes(tmp_path: Path) -> None:
    cli_fit(tmp_path / "cli.state")
    tandem.fit(DEMOS, params=PARAMS).save(tmp_path / "py.state")
    assert (tmp_path / "py.state").read_bytes() == (tmp_path / "cli.state").read_bytes()


def test_fit_from_arrays_equals_fit_from_files(planner: tandem.Planner, tmp_path: Path) -> None:
    loaded = [load_arrays(p) for p in DEMOS]
    channels = loaded[0][0]
    from_arrays = tandem.fit([x for _, x in loaded], channels=channels, params=PARAMS, dt_s=0.01)
    m, a = planner.model, from_arrays.model
    assert a.channels == m.channels and a.n_ref == m.n_ref and a.dt_s == m.dt_s
    for name in ("mean", "sigma2_d", "grad_mean", "grad_min", "grad_max", "ranges"):
        np.testing.assert_allclose(getattr(a, name), getattr(m, name), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(from_arrays.confidence.high, planner.confidence.high)
    np.testing.assert_array_equal(from_arrays.schedule.gradients, planner.schedule.gradients)
    # NumPy parses the CSV text to the same doubles, and the fixtures' `t` column spacing is
    # exactly 0.01 s: the whole state is the same.
    from_arrays.save(tmp_path / "a.state")
    planner.save(tmp_path / "p.state")
    assert (tmp_path / "a.state").read_bytes() == (tmp_path / "p.state").read_bytes()


def test_each_side_opens_the_others_state(planner: tandem.Planner, tmp_path: Path) -> None:
    cli_fit(tmp_path / "cli.state")
    loaded = tandem.Planner.load(tmp_path / "cli.state")
    np.testing.assert_array_equal(loaded.model.mean, planner.model.mean)
    assert loaded.schedule.t_total_s == planner.schedule.t_total_s
    planner.save(tmp_path / "py.state")
    doc = json.loads(run_cli("inspect", tmp_path / "py.state", "--json"))
    assert doc["model"]["n_ref"] == planner.model.n_ref
    # `rounds_recorded`, and its deprecated duplicate `pairs_recorded` (kept one release).
    assert doc["rounds_recorded"] == doc["pairs_recorded"] == 0
    assert doc["schedule"]["t_total_s"] == planner.schedule.t_total_s


def write_execution(folder: Path, robot: int, run, channels) -> list:
    """One robot's execution as the command line's three files (exact float text)."""
    r = run.robots[robot]
    exe, log, corr = (folder / f"r{robot}.{n}.csv" for n in ("exec", "log", "corr"))
    np.savetxt(exe, r.samples, delimiter=",", header=",".join(channels), comments="", fmt="%.17g")
    np.savetxt(log, r.ref_time_log, header="ref_sample", comments="", fmt="%.17g")
    flags = np.column_stack([r.supervised, r.corrected]).astype(int)
    np.savetxt(corr, flags, delimiter=",", header="supervised,corrected", comments="", fmt="%d")
    return [exe, log, corr]


def test_record_round_equals_tandem_record(tmp_path: Path) -> None:
    cli_fit(tmp_path / "cli.state")
    py = tandem.fit(DEMOS, params=PARAMS)
    run = tandem.sim.run_round(py, tandem.sim.sanding_needs(LABELS, seed=1, planner=py), seed=1)
    files = [write_execution(tmp_path, i, run, py.model.channels) for i in range(2)]
    run_cli(
        "record", tmp_path / "cli.state",
        "--execution", files[0][0], "--execution", files[1][0],
        "--log", files[0][1], "--log", files[1][1],
        "--corrections", files[0][2], "--corrections", files[1][2],
    )
    report = py.record_round(**run.record_args())
    py.save(tmp_path / "py.state")
    assert (tmp_path / "py.state").read_bytes() == (tmp_path / "cli.state").read_bytes()
    assert report["t_total_s"] == py.schedule.t_total_s
    assert py.rounds_recorded == 1 and py.model.count == 8


def test_reschedule_equals_tandem_schedule(
    overlapping_planner: tandem.Planner, tmp_path: Path
) -> None:
    overlapping_planner.save(tmp_path / "p.state")
    doc = json.loads(run_cli("schedule", tmp_path / "p.state", "--json", "--samples", 300))
    mine = tandem.Planner.load(tmp_path / "p.state")
    s = mine.reschedule(samples=300)
    assert s.t_total_s == doc["t_total_s"]
    assert s.offsets[0] == doc["offset_s"]
    assert s.t_total_s <= overlapping_planner.schedule.t_total_s


def test_memory_layout_of_arrays_does_not_matter() -> None:
    t = np.linspace(0.0, 1.0, 60)
    demos = [np.column_stack([np.sin(3 * t + k), t**2, np.cos(t * k)]) for k in range(3)]
    channels = ["a", "b", "c"]
    # Three unrelated signals, not one task: demo 0 is the reference (on another's axis it
    # would look cut off); the test is about the arrays' layout, not the reference choice.
    first = {"fit": {"reference": "first"}}
    reference = tandem.fit_model(demos, channels=channels, params=first)
    fortran = [np.asfortranarray(d) for d in demos]
    strided = [np.repeat(d, 2, axis=0)[::2] for d in demos]
    transposed = [np.ascontiguousarray(d.T).T for d in demos]
    as_lists = [d.tolist() for d in demos]
    for variant in (fortran, strided, transposed, as_lists):
        other = tandem.fit_model(variant, channels=channels, params=first)
        np.testing.assert_array_equal(other.mean, reference.mean)
        np.testing.assert_array_equal(other.sigma2_d, reference.sigma2_d)


def test_record_round_takes_execution_files_with_columns_in_any_order(tmp_path: Path) -> None:
    from_arrays = tandem.fit(DEMOS, params=PARAMS)
    from_files = tandem.fit(DEMOS, params=PARAMS)
    run = tandem.sim.run_round(from_arrays, tandem.sim.sanding_needs(LABELS, seed=2, planner=from_arrays), seed=2)
    channels = from_arrays.model.channels
    files = []
    for i, r in enumerate(run.robots):
        path = tmp_path / f"exec{i}.csv"
        np.savetxt(path, r.samples[:, ::-1], delimiter=",", header=",".join(channels[::-1]),
                   comments="", fmt="%.17g")
        files.append(path)
    args = run.record_args()
    from_arrays.record_round(**args)
    from_files.record_round(**{**args, "executions": files})
    from_arrays.save(tmp_path / "a.state")
    from_files.save(tmp_path / "f.state")
    assert (tmp_path / "a.state").read_bytes() == (tmp_path / "f.state").read_bytes()


def test_low_confidence_explanations_equal_tandem_inspect(
    planner: tandem.Planner, tmp_path: Path
) -> None:
    planner.save(tmp_path / "py.state")
    doc = json.loads(run_cli("inspect", tmp_path / "py.state", "--json"))
    regions = planner.confidence.explain_low_confidence()
    assert regions == doc["confidence"]["low_regions"]
    starts = [r["ref_start"] for r in regions]
    assert starts == [int(a) for a, _ in planner.confidence.low_regions]
    assert all(r["cause"] in ("variance", "corrections") for r in regions)
    assert planner.confidence.error_rates == doc["confidence"]["error_rates"]
    t = planner.confidence.sigma2_d_prior_threshold
    assert t == doc["confidence"]["sigma2_d_prior_threshold"]
    # Where the prior alone is high, sigma2_d is at most the threshold (latched from the fit).
    s2 = planner.model.sigma2_d
    assert np.all(s2[planner.confidence.high] <= t)
