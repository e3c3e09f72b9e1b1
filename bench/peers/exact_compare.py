#!/usr/bin/env python3
"""Peer check of tandem-schedule's exact margin-free search (`solve_exact`): the same problems
solved by CP-SAT (OR-Tools) and by HiGHS (MILP), optima compared to 1e-6 relative.

The problems are those of `cargo run --release -p tandem-schedule --example fragmented`
(the fixture problem and mid-study-like problems with fragmented confidence), written as CSV by
its `--write DIR`; its Markdown table gives our optimum T*0 and the search's wall time.

The model (docs/decisions.md, "Certified schedules"), identical for both peers: the LC runs
k = 0..m of each robot have fixed durations L_k (sum of grad_mean * dt), the HC gaps g = 0..m
(head, between runs, tail; [0, 0] if absent) durations in [a_g, b_g] (sums of grad_min and
grad_max times dt). Robot 1 starts at 0, robot 2 at tau with 0 <= tau <= end_1; no LC interval
of robot 1 overlaps one of robot 2; minimize T >= end_1, end_2.

The two peers cannot share a process (OR-Tools and highspy bundle different HiGHS builds), so
each solve runs in a child process of this script (`--solve cpsat|highs FILE`).

CP-SAT works on integers: times in nanoseconds (rounding error < 1e-8 s per duration),
one NoOverlap over both robots' LC intervals. HiGHS: one binary per pair of LC runs (i, j)
of the two robots, big-M disjunctions, mip_rel_gap = 0.

Run (in a virtual environment outside the repository):
    python3 -m venv /tmp/peers && /tmp/peers/bin/pip install -r bench/peers/requirements.txt
    /tmp/peers/bin/python bench/peers/exact_compare.py [--time-limit 60] [--problems fixture,painted]
"""

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time


def load(path, dt=0.01):
    """LC durations and HC gap ranges (s) of a problem CSV (grad_mean,grad_min,grad_max,conf)."""
    rows = list(csv.DictReader(open(path)))
    conf = [r["conf"] == "1" for r in rows]
    mean = [float(r["grad_mean"]) for r in rows]
    lo = [float(r["grad_min"]) for r in rows]
    hi = [float(r["grad_max"]) for r in rows]
    lc, gaps = [], []
    n, pend = 0, (0.0, 0.0)
    while n < len(rows):
        start = n
        while n < len(rows) and conf[n] == conf[start]:
            n += 1
        if conf[start]:
            pend = (sum(lo[start:n]) * dt, sum(hi[start:n]) * dt)
        else:
            gaps.append(pend)
            pend = (0.0, 0.0)
            lc.append(sum(mean[start:n]) * dt)
    gaps.append(pend)
    return lc, gaps


def solve_cpsat(lc, gaps, time_limit, workers):
    from ortools.sat.python import cp_model

    scale = 1e9
    m = len(lc)
    L = [round(d * scale) for d in lc]
    A = [round(g[0] * scale) for g in gaps]
    B = [round(g[1] * scale) for g in gaps]
    horizon = 2 * (sum(L) + sum(B)) + 1
    md = cp_model.CpModel()
    tau = md.NewIntVar(0, horizon, "tau")
    ends, intervals = [], []
    for r in range(2):
        start = 0 if r == 0 else tau
        prev, prev_len = start, 0
        for k in range(m):
            s = md.NewIntVar(0, horizon, f"s{r}_{k}")
            md.Add(s - prev >= prev_len + A[k])
            md.Add(s - prev <= prev_len + B[k])
            intervals.append(md.NewFixedSizeIntervalVar(s, L[k], f"i{r}_{k}"))
            prev, prev_len = s, L[k]
        e = md.NewIntVar(0, horizon, f"e{r}")
        md.Add(e - prev >= prev_len + A[m])
        md.Add(e - prev <= prev_len + B[m])
        ends.append(e)
    md.Add(tau <= ends[0])
    md.AddNoOverlap(intervals)
    t = md.NewIntVar(0, horizon, "T")
    md.AddMaxEquality(t, ends)
    md.Minimize(t)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = time_limit
    solver.parameters.num_workers = workers
    t0 = time.perf_counter()
    status = solver.Solve(md)
    wall = time.perf_counter() - t0
    proven = status == cp_model.OPTIMAL
    value = solver.ObjectiveValue() / scale if status in (cp_model.OPTIMAL, cp_model.FEASIBLE) else None
    bound = solver.BestObjectiveBound() / scale
    return value, bound, proven, wall


def solve_highs(lc, gaps, time_limit, threads):
    import highspy

    m = len(lc)
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("time_limit", float(time_limit))
    h.setOptionValue("mip_rel_gap", 0.0)
    h.setOptionValue("mip_abs_gap", 1e-9)
    h.setOptionValue("threads", threads)
    big = 2 * (sum(lc) + sum(g[1] for g in gaps)) + 1.0
    inf = highspy.kHighsInf
    cols = []

    def var(lo, hi, integer=False):
        h.addVar(lo, hi)
        idx = h.getNumCol() - 1
        if integer:
            h.changeColIntegrality(idx, highspy.HighsVarType.kInteger)
        return idx

    def row(lo, hi, coefs):
        idx = [c for c, _ in coefs]
        val = [v for _, v in coefs]
        h.addRow(lo, hi, len(idx), idx, val)

    def after(prev, prev_len, g):
        """A new time at a lag in gap g's range after prev (robot 1's start 0 when None)."""
        x = var(0.0, inf)
        lo, hi = prev_len + gaps[g][0], prev_len + gaps[g][1]
        row(lo, hi, [(x, 1.0)] + ([] if prev is None else [(prev, -1.0)]))
        return x

    tau = var(0.0, inf)
    starts, ends = [], []
    for r in range(2):
        prev, prev_len = (None, 0.0) if r == 0 else (tau, 0.0)
        st = []
        for k in range(m):
            st.append(after(prev, prev_len, k))
            prev, prev_len = st[-1], lc[k]
        starts.append(st)
        ends.append(after(prev, prev_len, m))
    row(-inf, 0.0, [(tau, 1.0), (ends[0], -1.0)])
    t = var(0.0, inf)
    for e in ends:
        row(0.0, inf, [(t, 1.0), (e, -1.0)])
    # One binary per pair of runs (robot 2's start tau is free, so every pair can meet).
    for i in range(m):
        for j in range(m):
            y = var(0.0, 1.0, integer=True)
            s1, s2 = starts[0][i], starts[1][j]
            # y = 1: run i of robot 1 before run j of robot 2.
            row(-inf, big - lc[i], [(s1, 1.0), (s2, -1.0), (y, big)])
            row(-inf, -lc[j], [(s2, 1.0), (s1, -1.0), (y, -big)])
    h.changeColCost(t, 1.0)
    t0 = time.perf_counter()
    h.run()
    wall = time.perf_counter() - t0
    status = h.getModelStatus()
    info = h.getInfo()
    proven = status == highspy.HighsModelStatus.kOptimal
    value = info.objective_function_value if info.primal_solution_status == 2 else None
    bound = info.mip_dual_bound
    return value, bound, proven, wall


def ours(root, out_dir):
    """Writes the problems and returns {name: (T*0, proven, search ms)} from the example."""
    cmd = ["cargo", "run", "--release", "-q", "-p", "tandem-schedule", "--example", "fragmented", "--", "--write", out_dir]
    text = subprocess.run(cmd, cwd=root, check=True, capture_output=True, text=True).stdout
    res = {}
    for line in text.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 6 or cells[0] in ("problem", "---"):
            continue
        res[cells[0]] = (float(cells[2]), cells[3] == "yes", float(cells[5]), int(cells[1]))
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--time-limit", type=float, default=60.0, help="per solver and problem (s)")
    ap.add_argument("--workers", type=int, default=2, help="threads of each peer")
    ap.add_argument("--problems", default="", help="comma-separated names (default: all)")
    ap.add_argument("--solve", nargs=2, metavar=("SOLVER", "FILE"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.solve:
        solver, path = args.solve
        lc, gaps = load(path)
        fn = solve_cpsat if solver == "cpsat" else solve_highs
        value, bound, ok, wall = fn(lc, gaps, args.time_limit, args.workers)
        print(json.dumps({"value": value, "bound": bound, "proven": ok, "wall": wall}))
        return 0
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    with tempfile.TemporaryDirectory() as out_dir:
        mine = ours(root, out_dir)
        names = [n for n in mine if not args.problems or n in args.problems.split(",")]
        print("| problem | LC runs | ours T*0 (s) | ours (ms) | CP-SAT (s) | CP-SAT proven | CP-SAT (ms) | agree | HiGHS (s) | HiGHS proven | HiGHS (ms) | agree |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for name in names:
            t_ours, proven, ms, runs = mine[name]
            path = os.path.join(out_dir, f"{name}.csv")
            cells = [name, str(runs), f"{t_ours:.6f}" + ("" if proven else " (bound)"), f"{ms:.1f}"]
            for solver in ("cpsat", "highs"):
                cmd = [sys.executable, os.path.abspath(__file__), "--solve", solver, path,
                       "--time-limit", str(args.time_limit), "--workers", str(args.workers)]
                r = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
                value, bound, ok, wall = r["value"], r["bound"], r["proven"], r["wall"]
                agree = value is not None and abs(value - t_ours) <= 1e-6 * t_ours
                shown = f"{value:.6f}" if value is not None else "—"
                if not ok:
                    shown += f" (bound {bound:.3f})"
                cells += [shown, "yes" if ok else "no", f"{wall * 1e3:.0f}", "yes" if agree else "no"]
            print("| " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    sys.exit(main())
