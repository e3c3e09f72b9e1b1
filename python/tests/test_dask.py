"""examples/python/sweep_dask.py: the sweep on a 2-worker dask LocalCluster gives exactly the
numbers of the serial loop."""

from __future__ import annotations

import importlib.util
import sys

from conftest import ROOT

from dask import distributed


def load_example(name: str = "sweep_dask"):
    """examples/python/NAME.py as a module (registered under NAME, as a script's import of it)."""
    path = ROOT / "examples" / "python" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def test_sweep_on_a_local_cluster_equals_the_serial_loop() -> None:
    sweep = load_example()
    points = sweep.grid(mu_c=[0.05, 0.3], error_rates=[0.0, 0.05], replicates=2)
    assert len(points) == 8
    base = {"executions": 4, "samples": 40, "seed": 11, "trials": 2}
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, dashboard_address=None, processes=True
    ) as cluster, distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        on_cluster = sweep.sweep(client, points, base)
    in_loop = sweep.serial(points, base)
    assert sweep.same_numbers(on_cluster, in_loop)
    # The grid is not degenerate: μ_c changes what is learned.
    finals = {(r["mu_c"], r["error_rate"], r["replicate"]): r["high_conf_final_pct"] for r in in_loop}
    assert finals[(0.3, 0.0, 0)] > finals[(0.05, 0.0, 0)]
    assert all(r["overlap_ticks"] == 0 for r in in_loop)


def test_fleet_sweep_on_a_local_cluster_equals_the_serial_loop() -> None:
    """Issue 44: a sweep over (N, M, δ, seeds) of the continuous cell, on a 2-worker cluster,
    gives exactly the serial loop's numbers; no point ever has more robots low-confidence than
    operators."""
    sweep = load_example("sweep_fleet_dask")
    points = sweep.grid(robots=[2, 3], operators=[1, 2, 3], switch_s=[0.0, 1.0], replicates=1)
    # M ≤ N only: (2,1), (2,2), (3,1), (3,2), (3,3), each at two switch times.
    assert [(p["robots"], p["operators"]) for p in points[::2]] == [
        (2, 1), (2, 2), (3, 1), (3, 2), (3, 3)
    ]
    base = {"executions": 12, "samples": 40, "seed": 5, "trials": 1}
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, dashboard_address=None, processes=True
    ) as cluster, distributed.Client(cluster) as client:
        on_cluster = sweep.sweep(client, points, base)
    in_loop = sweep.serial(points, base)
    assert sweep.same_numbers(on_cluster, in_loop)
    for r in in_loop:
        assert r["tasks"] >= 12
        assert r["overlap_ticks"] == 0 and r["faults"] == 0
        assert r["steady_tasks_per_h"] > 0.0
    # The grid is not degenerate: a second operator changes what three robots deliver.
    by = {(r["robots"], r["operators"], r["switch_s"]): r for r in in_loop}
    assert by[(3, 2, 0.0)]["steady_tasks_per_h"] != by[(3, 1, 0.0)]["steady_tasks_per_h"]


def test_a_rounds_configuration_is_refused_by_the_cell_trial() -> None:
    import pytest

    import tandem

    with pytest.raises(tandem.ParamError, match="continuous"):
        tandem.study.run_cell_trial({"executions": 4, "samples": 20, "trials": 1}, 0)
