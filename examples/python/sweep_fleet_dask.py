#!/usr/bin/env python3
"""A fleet sweep on dask.distributed: robots N × operators M × switch time δ × seed (issue 44).

Each point of the grid is one trial of the continuous study (each of the ``N`` robots starts
its next task as soon as the ``M`` operators' order allows; the plan is re-made every ``N``
completed tasks from what the simulated operators corrected) with ``M`` simulated operators
and the switch time ``δ`` (s) both planned with and taken by the simulated operators. Only
points with ``M ≤ N`` are run (an operator with no robot of its own adds nothing). Replicate
``r`` is trial ``r`` of its configuration, seeded by ``(seed, r)`` only: a point's numbers do
not depend on where or in which order it runs, so the cluster gives exactly the numbers of the
serial loop (``--check-serial`` verifies it, field by field).

Without ``--scheduler`` it starts a ``LocalCluster`` (``--workers`` processes, one thread
each); with ``--scheduler tcp://host:8786`` it connects to a running ``dask scheduler`` whose
workers have ``tandem`` installed. Each worker fits the task once and reuses it.

    python examples/python/sweep_fleet_dask.py --robots 2 4 --operators 1 2 --switch-s 0 2
    python examples/python/sweep_fleet_dask.py --scheduler tcp://10.0.0.5:8786 --executions 400
"""

from __future__ import annotations

import argparse
import itertools
import sys
import time
from pathlib import Path
from typing import Iterable, List, Optional, Sequence

import tandem

# The μ_c sweep beside this file owns the cluster's client and the exact comparison.
sys.path.insert(0, str(Path(__file__).resolve().parent))
from sweep_dask import client_for, same_numbers  # noqa: E402


def grid(
    robots: Sequence[int],
    operators: Sequence[int],
    switch_s: Sequence[float],
    replicates: int,
) -> List[dict]:
    """The grid's points ``{"robots", "operators", "switch_s", "replicate"}``, with
    ``operators ≤ robots``, in the order of the arguments."""
    return [
        {"robots": n, "operators": m, "switch_s": d, "replicate": r}
        for n, m, d, r in itertools.product(robots, operators, switch_s, range(replicates))
        if m <= n
    ]


def config_of(point: dict, base: dict) -> dict:
    """The continuous study's configuration of one point: ``base`` with its robots, operators
    and switch time (planned, ``switch_s``, and the simulated operators', ``switch_true_s``)."""
    operator = {
        **base.get("operator", {}),
        "operators": point["operators"],
        "switch_s": point["switch_s"],
        "switch_true_s": point["switch_s"],
    }
    return {**base, "cell": "continuous", "robots": point["robots"], "operator": operator}


def row(point: dict, trial: tandem.study.CellTrialResult) -> dict:
    """What the sweep reports for one point."""
    return {
        **point,
        "tasks": trial.tasks,
        "steady_tasks_per_h": trial.steady_tasks_per_h,
        "steady_busy_share": trial.steady_busy_share,
        "steady_wait_share": trial.steady_wait_share,
        "plan_tasks_per_h": trial.plan_tasks_per_h,
        "overlap_ticks": trial.overlap_ticks,
        "faults": trial.faults,
        "high_conf_pct": trial.high_conf_pct,
    }


def serial(points: Iterable[dict], base: dict, demos_dir: Optional[str] = None) -> List[dict]:
    """The sweep in a plain loop, in this process."""
    return [
        row(p, tandem.study.run_cell_trial(config_of(p, base), p["replicate"], demos_dir))
        for p in points
    ]


def sweep(client, points: Sequence[dict], base: dict, demos_dir: Optional[str] = None) -> List[dict]:
    """The sweep on a dask.distributed ``client``: one task per point, results in grid order."""
    futures = client.map(
        tandem.study.run_cell_trial,
        [config_of(p, base) for p in points],
        [p["replicate"] for p in points],
        demos_dir=demos_dir,
        pure=False,
    )
    return [row(p, t) for p, t in zip(points, client.gather(futures))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scheduler", help="address of a running dask scheduler (default: a LocalCluster)")
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes")
    ap.add_argument("--robots", type=int, nargs="+", default=[2, 4])
    ap.add_argument("--operators", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--switch-s", type=float, nargs="+", default=[0.0, 2.0])
    ap.add_argument("--replicates", type=int, default=1, help="seeds (trials) per point")
    ap.add_argument("--executions", type=int, default=40, help="tasks per trial (a multiple of every N)")
    ap.add_argument("--samples", type=int, default=300, help="sampler candidates per plan")
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
    points = grid(args.robots, args.operators, args.switch_s, args.replicates)
    if not points:
        raise SystemExit("no point has operators ≤ robots: raise --robots or lower --operators")
    with client_for(args.scheduler, args.workers) as client:
        print(f"# {len(points)} points on {client}")
        start = time.perf_counter()
        rows = sweep(client, points, base, args.demos_dir)
        wall = time.perf_counter() - start
    print("N | M | δ (s) | replicate | tasks | tasks/h (steady) | busy share | overlap ticks | faults")
    print("---|---|---|---|---|---|---|---|---")
    for r in rows:
        print(
            f"{r['robots']} | {r['operators']} | {r['switch_s']} | {r['replicate']} | {r['tasks']} | "
            f"{r['steady_tasks_per_h']:.1f} | {r['steady_busy_share']:.3f} | {r['overlap_ticks']} | "
            f"{r['faults']}"
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
