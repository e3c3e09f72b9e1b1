#!/usr/bin/env python3
"""A 1 kHz control loop around ``tandem.Coordinator``: the skeleton of a robot node.

Every control tick (1 ms here) the loop

1. reads where each robot is in the task (``Coordinator.ref_time_now``) and which one is
   low-confidence (``Coordinator.low_conf_now``): that is the robot the operator supervises;
2. computes each running robot's command ``x_f⁺ = μ̂⁺ + δx⁺(u)`` (Eq. 7,
   ``Planner.command``), with the operator's joystick input ``u`` for the supervised robot
   — here a simulated operator who holds the joystick in short random episodes — and would
   send it to the robot;
3. passes the rate of the supervised robot's command (its warp gradient) to
   ``Coordinator.tick`` as the operator's gradient (``None`` without a correction), which
   advances every robot's schedule clock so that the other robot keeps its distance (Eq. 18,
   Alg. 1): never two robots low-confidence in the same tick.

The schedule is made for the loop's tick (``Planner.reschedule(tick_s=...)``): the margin check
guarantees safety at the tick it ran with, and the coordinator runs only at that tick.

It prints the latency of ``Coordinator.tick`` alone and of a whole iteration (p50, p99, max).
By default it runs as fast as it can (what the latency figures need); ``--realtime`` sleeps to
hold the 1 kHz period and counts missed deadlines.

    python examples/python/control_loop.py                      # one round of executions
    python examples/python/control_loop.py --calls 1000000      # the latency benchmark
    python examples/python/control_loop.py --state cell.tandem --realtime

Without ``--state`` it fits the repository's sanding fixtures with a quick-learning confidence
(``μ_c`` 0.3, ``γ_c`` 0.5) and records two simulated rounds, so that the schedule overlaps the
robots and both move in most ticks.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import tandem

ROOT = Path(__file__).resolve().parents[2]
SANDING = ROOT / "fixtures" / "sanding"


class SimulatedOperator:
    """Holds the joystick in episodes: while some robot is supervised, starts one with
    probability ``p_start`` per tick, lasting ``mean_ticks`` ticks on average, with a random
    input in ``[−1, 1]^K``."""

    def __init__(self, n_components: int, seed: int, p_start: float = 0.002, mean_ticks: float = 300):
        self.rng = np.random.default_rng(seed)
        self.k, self.p_start, self.p_end = n_components, p_start, 1.0 / mean_ticks
        self.u = None

    def input(self, supervising: bool):
        if not supervising:
            self.u = None
        elif self.u is None and self.rng.random() < self.p_start:
            self.u = self.rng.uniform(-1.0, 1.0, self.k)
        elif self.u is not None and self.rng.random() < self.p_end:
            self.u = None
        return self.u


def planner_for(args: argparse.Namespace) -> tandem.Planner:
    if args.state:
        return tandem.Planner.load(args.state)
    demos = [SANDING / f"demo_{i}.csv" for i in range(6)]
    planner = tandem.fit(
        demos,
        params={"sampler": {"samples": args.samples}, "confidence": {"mu_c": 0.3, "gamma_c": 0.5}},
    )
    for k in range(2):
        run = tandem.sim.run_round(planner, tandem.sim.sanding_needs(SANDING, k, planner=planner), k)
        planner.record_round(**run.record_args())
    return planner


def percentiles(ns: np.ndarray) -> str:
    p50, p99 = np.percentile(ns, [50, 99])
    return f"p50 {p50 / 1e3:.2f} µs, p99 {p99 / 1e3:.2f} µs, max {ns.max() / 1e3:.1f} µs"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--state", type=Path, help="a planner's state file (default: fit the fixtures)")
    ap.add_argument("--tick-s", type=float, default=0.001, help="control period (s)")
    ap.add_argument("--samples", type=int, default=300, help="sampler candidates")
    ap.add_argument("--calls", type=int, help="ticks to run (default: until every robot finishes)")
    ap.add_argument("--realtime", action="store_true", help="sleep to hold the control period")
    ap.add_argument("--seed", type=int, default=1, help="seed of the simulated operator")
    args = ap.parse_args()

    planner = planner_for(args)
    schedule = planner.reschedule(tick_s=args.tick_s, samples=args.samples)
    print(f"schedule at tick {schedule.tick_s * 1e3:g} ms: τ = {schedule.offsets[0]:.2f} s, "
          f"T_total = {schedule.t_total_s:.2f} s ({schedule.t_total_s / args.tick_s:.0f} ticks)")
    coord = tandem.Coordinator(schedule)
    planner.command(0.0)  # the correction directions are computed on first use: not in the loop
    operator = SimulatedOperator(planner.model.n_components, args.seed)
    problem = planner.problem
    gmin, gmax = problem.grad_min, problem.grad_max
    last_ref = planner.model.n_ref - 1
    calls = args.calls or int(2 * schedule.t_total_s / args.tick_s)
    tick_ns = np.empty(calls, dtype=np.int64)
    loop_ns = np.empty(calls, dtype=np.int64)
    overlaps = corrected = missed = executions = 0
    period_ns = int(args.tick_s * 1e9)
    deadline = time.perf_counter_ns() + period_ns
    for call in range(calls):
        t0 = time.perf_counter_ns()
        ref = np.minimum(coord.ref_time_now, last_ref)
        low, running = coord.low_conf_now, coord.running_now
        u = operator.input(bool(low.any()))
        gradient = None
        for i in np.flatnonzero(running):
            command = planner.command(ref[i], u if low[i] else None)  # → robot i
            if low[i] and u is not None:
                n = coord.sample_now[i]
                gradient = min(max(command[-1], gmin[n]), gmax[n])
        corrected += gradient is not None
        t1 = time.perf_counter_ns()
        tick = coord.tick(gradient)
        t2 = time.perf_counter_ns()
        tick_ns[call], loop_ns[call] = t2 - t1, t2 - t0
        overlaps += tick.overlap
        if coord.is_finished:
            executions += 1
            if args.calls is None:
                tick_ns, loop_ns = tick_ns[: call + 1], loop_ns[: call + 1]
                break
            coord.reset()
        if args.realtime:
            now = time.perf_counter_ns()
            if now > deadline:
                missed += 1
                deadline = now
            else:
                time.sleep((deadline - now) / 1e9)
            deadline += period_ns
    n = planner.n_robots
    robots = "the robot" if n == 1 else ("both robots" if n == 2 else f"all {n} robots")
    print(f"{len(tick_ns)} ticks, {executions} complete rounds ({robots} to the end), "
          f"{corrected} corrected ticks, {overlaps} ticks with two robots low-confidence")
    print(f"Coordinator.tick: {percentiles(tick_ns)}")
    print(f"whole iteration (commands + tick): {percentiles(loop_ns)}")
    if args.realtime:
        print(f"missed deadlines: {missed}")
    if overlaps:
        raise SystemExit("two robots were low-confidence in the same tick")


if __name__ == "__main__":
    main()
