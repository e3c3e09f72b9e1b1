#!/usr/bin/env python3
"""A parameter sweep of the paper's study on dask.distributed: μ_c × operator error rate × seed.

Each point of the grid is one trial of the study (§III: demonstrations, then rounds of
executions in the simulated workcell, re-scheduling after every round) with the confidence
threshold ``μ_c`` (Eq. 12) and an operator who misses needed corrections and gives unneeded
ones at the same ``error_rate``. Replicate ``r`` is trial ``r`` of that configuration, seeded by
``(seed, r)`` only: every point is independent of where and in which order it runs, so the
cluster gives exactly the numbers of the serial loop (``--check-serial`` verifies it).

The same code runs on a laptop and on a cluster: without ``--scheduler`` it starts a
``LocalCluster`` (``--workers`` processes, one thread each); with ``--scheduler
tcp://host:8786`` it connects to a running ``dask scheduler`` whose workers have ``tandem``
installed. Each worker fits the task once and reuses it for every point it runs (the fit does
not depend on ``μ_c`` or the operator).

    python examples/python/sweep_dask.py --executions 20 --samples 300 --replicates 2
    python examples/python/sweep_dask.py --scheduler tcp://10.0.0.5:8786 --executions 300
"""

from __future__ import annotations

import argparse
import itertools
import time
from typing import Iterable, List, Optional, Sequence

import numpy as np

import tandem


def grid(
    mu_c: Sequence[float], error_rates: Sequence[float], replicates: int
) -> List[dict]:
    """The grid's points: ``{"mu_c", "error_rate", "replicate"}``."""
    return [
        {"mu_c": m, "error_rate": e, "replicate": r}
        for m, e, r in itertools.product(mu_c, error_rates, range(replicates))
    ]


def config_of(point: dict, base: dict) -> dict:
    """The study configuration of one point: ``base`` with its ``μ_c`` and error rates."""
    config = {**base, "miss_rate": point["error_rate"], "false_correction_rate": point["error_rate"]}
    planner = dict(config.get("planner", {}))
    planner["confidence"] = {**planner.get("confidence", {}), "mu_c": point["mu_c"]}
    config["planner"] = planner
    return config


def row(point: dict, trial: tandem.study.TrialResult) -> dict:
    """What the sweep reports for one point."""
    return {
        **point,
        "t_total_first_s": float(trial.t_total_s[0]),
        "t_total_final_s": float(trial.t_total_s[-1]),
        "high_conf_final_pct": float(trial.high_conf_pct[-1]),
        "overlap_ticks": int(trial.overlap_ticks.sum()),
        "t_total_s": trial.t_total_s,
    }


def serial(points: Iterable[dict], base: dict, demos_dir: Optional[str] = None) -> List[dict]:
    """The sweep in a plain loop, in this process."""
    return [
        row(p, tandem.study.run_trial(config_of(p, base), p["replicate"], demos_dir))
        for p in points
    ]


def sweep(client, points: Sequence[dict], base: dict, demos_dir: Optional[str] = None) -> List[dict]:
    """The sweep on a dask.distributed ``client``: one task per point, results in grid order."""
    configs = [config_of(p, base) for p in points]
    futures = client.map(
        tandem.study.run_trial,
        configs,
        [p["replicate"] for p in points],
        demos_dir=demos_dir,
        pure=False,
    )
    return [row(p, t) for p, t in zip(points, client.gather(futures))]


def same_numbers(a: List[dict], b: List[dict]) -> bool:
    """Whether two sweeps gave identical numbers at every point (exact float equality)."""
    return len(a) == len(b) and all(
        x.keys() == y.keys()
        and all(
            np.array_equal(x[k], y[k]) if isinstance(x[k], np.ndarray) else x[k] == y[k]
            for k in x
        )
        for x, y in zip(a, b)
    )


def client_for(scheduler: Optional[str], workers: int):
    """A dask.distributed client: of the running scheduler at ``scheduler``
    (``tcp://host:8786``), else of a new ``LocalCluster`` of ``workers`` processes with one
    thread each."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        return Client(scheduler)
    return Client(LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=None))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scheduler", help="address of a running dask scheduler (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    ap.add_argument("--mu-c", type=float, nargs="+", default=[0.03, 0.05, 0.1])
    ap.add_argument("--error-rates", type=float, nargs="+", default=[0.0, 0.01, 0.05])
    ap.add_argument("--replicates", type=int, default=2, help="seeds (trials) per point")
    ap.add_argument("--executions", type=int, default=20, help="executions per trial (even)")
    ap.add_argument("--samples", type=int, default=300, help="sampler candidates per schedule")
    ap.add_argument("--seed", type=int, default=2023, help="master seed of the study")
    ap.add_argument("--demos-dir", help="demonstrations in the fixtures' layout (default: generated)")
    ap.add_argument("--check-serial", action="store_true", help="also run the serial loop and compare")
    args = ap.parse_args()

    base = {
        "executions": args.executions,
        "samples": args.samples,
        "seed": args.seed,
        "trials": args.replicates,
    }
    points = grid(args.mu_c, args.error_rates, args.replicates)
    with client_for(args.scheduler, args.workers) as client:
        print(f"# {len(points)} points on {client}")
        start = time.perf_counter()
        rows = sweep(client, points, base, args.demos_dir)
        wall = time.perf_counter() - start
    print("mu_c | error rate | replicate | T_total first s | T_total final s | high-conf final % | overlap ticks")
    print("---|---|---|---|---|---|---")
    for r in rows:
        print(
            f"{r['mu_c']} | {r['error_rate']} | {r['replicate']} | {r['t_total_first_s']:.2f} | "
            f"{r['t_total_final_s']:.2f} | {r['high_conf_final_pct']:.1f} | {r['overlap_ticks']}"
        )
    print(f"# cluster wall time {wall:.1f} s")
    if args.check_serial:
        start = time.perf_counter()
        same = same_numbers(rows, serial(points, base, args.demos_dir))
        print(f"# serial loop {time.perf_counter() - start:.1f} s; same numbers: {same}")
        if not same:
            raise SystemExit("the cluster and the serial loop disagree")


if __name__ == "__main__":
    main()
