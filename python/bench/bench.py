#!/usr/bin/env python3
"""Speed of the Python bindings, measured from Python (run by hand, not in CI).

    python python/bench/bench.py tick [--calls 1000000]   # Coordinator.tick latency, p50/p99
    python python/bench/bench.py fit [--repeat 20] [--rust]  # tandem.fit on the fixtures

``tick``: one call of ``Coordinator.tick`` timed with ``time.perf_counter_ns`` around it, over
``--calls`` calls on the fixtures' planner after two recorded pairs (the robots overlap, so most
ticks move both), cycling the operator through ``None``, a gradient, ``"fastest"`` and
``"slowest"``; the coordinator is reset whenever both robots finish. The timer's own cost
(two back-to-back reads) is reported beside it and included in the figures.

``fit``: ``tandem.fit_model`` (alignment and statistics, the work of the Rust criterion bench
``fit_fixtures/fit``) on the six fixtures as arrays, ``--repeat`` calls after one warm-up, and
``tandem.fit`` (the same plus confidence and the first schedule). With ``--rust`` it also runs
``cargo bench -p tandem-lfd --bench lfd -- fit/6x``, reads criterion's per-iteration samples
(``target/criterion/.../sample.json``), ``--rounds`` times, each followed by Python's calls,
and prints the ratios of the medians and of the minima over all rounds: both sides in one
session, interleaved, since other processes on a shared machine move all of these figures. ``--threads 1`` runs both on one
rayon thread, which is less sensitive to that load than the default pool of all cores.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import time
from pathlib import Path

import numpy as np

import tandem

ROOT = Path(__file__).resolve().parents[2]
SANDING = ROOT / "fixtures" / "sanding"
DEMOS = [SANDING / f"demo_{i}.csv" for i in range(6)]


def fixture_arrays():
    header = DEMOS[0].read_text().split("\n", 1)[0].split(",")
    keep = [k for k, h in enumerate(header) if h != "t"]
    arrays = [np.loadtxt(p, delimiter=",", skiprows=1)[:, keep] for p in DEMOS]
    return [header[k] for k in keep], [np.ascontiguousarray(a) for a in arrays]


def bench_tick(calls: int) -> None:
    planner = tandem.fit(
        DEMOS, params={"sampler": {"samples": 300}, "confidence": {"mu_c": 0.3, "gamma_c": 0.5}}
    )
    for k in range(2):
        run = tandem.sim.run_round(planner, tandem.sim.sanding_needs(SANDING, k, planner=planner), k)
        planner.record_round(**run.record_args())
    coord = tandem.Coordinator(planner.schedule)
    ops = [None, 0.9, "fastest", "slowest"]
    out = np.empty(calls, dtype=np.int64)
    timer = np.empty(calls, dtype=np.int64)
    clock = time.perf_counter_ns
    both = resets = 0
    for i in range(calls):
        op = ops[i & 3]
        t0 = clock()
        tick = coord.tick(op)
        t1 = clock()
        out[i] = t1 - t0
        if coord.is_finished:
            coord.reset()
            resets += 1
        both += i % 64 == 0 and bool(tick.running.all())
    for i in range(calls):
        t0 = clock()
        t1 = clock()
        timer[i] = t1 - t0
    p50, p99, p999 = np.percentile(out, [50, 99, 99.9]) / 1e3
    print(f"Coordinator.tick over {calls} calls ({resets} complete runs of the pair; both robots "
          f"running in {100 * both / ((calls + 63) // 64):.0f} % of sampled ticks):")
    print(f"  p50 {p50:.3f} µs, p99 {p99:.3f} µs, p99.9 {p999:.3f} µs, mean {out.mean() / 1e3:.3f} µs, "
          f"max {out.max() / 1e3:.1f} µs")
    print(f"  timer alone (two perf_counter_ns reads): p50 {np.percentile(timer, 50) / 1e3:.3f} µs")


def call_times_s(f, repeat: int) -> np.ndarray:
    """Wall time (s) of each of ``repeat`` calls of ``f``, after one warm-up call."""
    f()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return np.array(times)


def rust_fit_times_s() -> np.ndarray:
    """Per-iteration times (s) of criterion's samples of ``fit_fixtures/fit/6x…``."""
    subprocess.run(
        ["cargo", "bench", "-q", "-p", "tandem-lfd", "--bench", "lfd", "--", "fit/6x"],
        cwd=ROOT, capture_output=True, text=True, check=True,
    )
    folder = next((ROOT / "target" / "criterion" / "fit_fixtures").glob("fit_6x*"))
    sample = json.loads((folder / "new" / "sample.json").read_text())
    return np.array(sample["times"]) / np.array(sample["iters"]) / 1e9


def stats_ms(times_s: np.ndarray) -> str:
    return f"median {np.median(times_s) * 1e3:.1f} ms, min {times_s.min() * 1e3:.1f} ms (n = {len(times_s)})"


def bench_fit(repeat: int, rust: bool, rounds: int) -> None:
    channels, arrays = fixture_arrays()
    model = call_times_s(lambda: tandem.fit_model(arrays, channels=channels), repeat)
    paths = call_times_s(lambda: tandem.fit_model(DEMOS), repeat)
    planner = call_times_s(lambda: tandem.fit(arrays, channels=channels), max(3, repeat // 4))
    print(f"tandem.fit_model, 6 fixture arrays ({len(arrays[0])} reference samples): {stats_ms(model)}")
    print(f"tandem.fit_model, 6 CSV paths (parsing included): {stats_ms(paths)}")
    print(f"tandem.fit (model + confidence + first schedule, 5000 samples): {stats_ms(planner)}")
    if rust:
        rust_s, python_s = [], [model]
        for _ in range(rounds):
            rust_s.append(rust_fit_times_s())
            python_s.append(call_times_s(lambda: tandem.fit_model(arrays, channels=channels), repeat))
        rust_all, python_all = np.concatenate(rust_s), np.concatenate(python_s)
        print(f"cargo bench -p tandem-lfd --bench lfd -- fit/6x, {rounds} runs interleaved with "
              f"Python's (criterion samples): {stats_ms(rust_all)}")
        print(f"tandem.fit_model, all rounds: {stats_ms(python_all)}")
        print(f"Python / Rust: median {np.median(python_all) / np.median(rust_all):.3f}, "
              f"min {python_all.min() / rust_all.min():.3f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    t = sub.add_parser("tick")
    t.add_argument("--calls", type=int, default=1_000_000)
    f = sub.add_parser("fit")
    f.add_argument("--repeat", type=int, default=20)
    f.add_argument("--rust", action="store_true", help="also run the Rust criterion bench")
    f.add_argument("--threads", type=int, help="RAYON_NUM_THREADS for both sides")
    f.add_argument("--rounds", type=int, default=3, help="Rust bench runs, each followed by Python's")
    args = ap.parse_args()
    if getattr(args, "threads", None):
        # Read when the rayon pool first starts (the first fit), here and in `cargo bench`.
        os.environ["RAYON_NUM_THREADS"] = str(args.threads)
    if args.cmd == "tick":
        bench_tick(args.calls)
    else:
        bench_fit(args.repeat, args.rust, args.rounds)


if __name__ == "__main__":
    main()
