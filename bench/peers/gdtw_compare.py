#!/usr/bin/env python3
"""Peer comparison: tandem-warp vs. the authors' `gdtw` 1.2.1 on the six sanding fixtures.

Aligns fixtures/sanding/demo_{1..5}.csv to demo_0.csv with both implementations on the *same
problem* (one node per reference sample, M = 301 candidates, same lambdas, slope bounds and W)
and prints, per demo, both wall times, both objective values and their ratios.  Both warps are
scored by ONE function, `objective()` below, which is an independent re-implementation of
`tandem_warp::objective_of` (trapezoid rule for the loss over reference samples, exact integrals
of (phi' - 1)^2 and (phi - t)^2 for the piecewise-linear warp).

Fairness notes (see README.md):
* gdtw min-max scales every channel of each signal to [-1, 1] internally; we apply that same
  scaling first and feed the identical scaled data to both solvers (gdtw's own re-scaling of
  already-scaled data is then the identity).  Channels that are constant in any demonstration
  cannot be min-max scaled and are dropped for both.
* gdtw has no weight matrix, so W = I for both.
* gdtw penalises the raw slope phi'^2; with pinned endpoints that has the same minimiser as
  (phi' - 1)^2 (the objectives differ by the constant lambda_inst).  We score with (phi' - 1)^2.
* gdtw's default epsilon_abs = 0.1 stops refinement after ~2 passes; we set both tolerances to 0
  so it runs all max_iters = 10 passes.
Run from the repository root:  python3 bench/peers/gdtw_compare.py [--demos 1,2,3,4,5] [--python]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
FIX = os.path.join(ROOT, "fixtures", "sanding")

LAMBDA_INST = 0.1
LAMBDA_CUM = 1.0
S_MIN, S_MAX = 0.25, 4.0
M = 301


def load(i):
    with open(os.path.join(FIX, f"demo_{i}.csv")) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(os.path.join(FIX, f"demo_{i}.csv"), delimiter=",", skiprows=1)
    keep = [k for k, h in enumerate(header) if h != "t"]
    return [header[k] for k in keep], data[:, keep]


def minmax(x):
    """gdtw's per-channel scaling of one signal to [-1, 1]."""
    lo, hi = x.min(axis=0), x.max(axis=0)
    return 2.0 * (x - lo) / (hi - lo) - 1.0


def objective(x1, x2, psi, w, lam_inst, lam_cum):
    """The common score: J(psi) for psi = query samples at every reference sample."""
    t1, t2 = len(x1), len(x2)
    h = 1.0 / (t1 - 1)
    s = np.clip(np.floor(psi).astype(int), 0, t2 - 2)
    f = psi - s
    x2i = x2[s] + f[:, None] * (x2[s + 1] - x2[s])
    loss = ((x2i - x1) ** 2 * w).sum(axis=1)
    om = np.full(t1, h)
    om[0] = om[-1] = h / 2
    phi = psi / (t2 - 1)
    t = np.arange(t1) * h
    slope = np.diff(phi) / h
    d = phi - t
    inst = (h * (slope - 1.0) ** 2).sum()
    cum = (h * (d[:-1] ** 2 + d[:-1] * d[1:] + d[1:] ** 2) / 3.0).sum()
    return (om * loss).sum() + lam_inst * inst + lam_cum * cum


def run_gdtw(x_ref, x_query):
    import gdtw

    params = {
        "N": len(x_ref), "M": M, "lambda_inst": LAMBDA_INST, "lambda_cum": LAMBDA_CUM,
        "s_min": S_MIN, "s_max": S_MAX, "epsilon_abs": 0.0, "epsilon_rel": 0.0, "max_iters": 10,
    }
    start = time.perf_counter()
    # directional warping in gdtw: x(phi(t)) ~ y(t), so x = query, y = reference
    _, _, f_tau, g = gdtw.warp(x=x_query, y=x_ref, params=params)
    wall = time.perf_counter() - start
    psi = np.asarray(g.tau) * (len(x_query) - 1)
    return psi, wall, float(f_tau)


def run_tandem(x_ref, x_query, names, exe, tandem_params, repeat=1):
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for tag, x in (("ref", x_ref), ("query", x_query)):
            p = os.path.join(tmp, f"{tag}.csv")
            np.savetxt(p, x, delimiter=",", header=",".join(names), comments="", fmt="%.17g")
            paths.append(p)
        out = subprocess.run(
            [exe, paths[0], paths[1], "--params", json.dumps(tandem_params), "--report",
             "--repeat", str(repeat)],
            capture_output=True, text=True, check=True,
        )
    psi = np.loadtxt(out.stdout.splitlines()[1:], delimiter=",")[:, 1]
    rep = dict(kv.split("=") for kv in out.stderr.split())
    return psi, float(rep["wall_s"]), float(rep["objective"])


def run_tandem_python(x_ref, x_query, tandem_params, repeat=1):
    """The same alignment through the Python API (`tandem.align`, built from crates/tandem-py),
    timed around the call (array conversion, GIL release and the result's copy included); the
    mean over `repeat` calls, like the example's `--repeat`."""
    import tandem

    start = time.perf_counter()
    for _ in range(repeat):
        warp = tandem.align(x_ref, x_query, params=tandem_params)
    wall = (time.perf_counter() - start) / repeat
    return warp.values, wall, warp.objective


def build_tandem(build=True):
    """Path of the `align` example under $CARGO_TARGET_DIR (built first unless `build` is False)."""
    exe = os.path.join(os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target")),
                       "release", "examples", "align")
    if build:
        subprocess.run(["cargo", "build", "--release", "-q", "-p", "tandem-warp", "--example", "align"],
                       cwd=ROOT, check=True)
    return exe


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--demos", default="1,2,3,4,5")
    ap.add_argument("--max-jump", type=int, default=16,
                    help="tandem-warp max_jump in the refinement passes")
    ap.add_argument("--refinements", type=int, default=6)
    ap.add_argument("--refine-radius", type=float, default=22.5,
                    help="tandem-warp refine_radius (22.5 = gdtw's eta 0.15 at M = 301)")
    ap.add_argument("--no-build", action="store_true", help="use an already built example")
    ap.add_argument("--python", action="store_true",
                    help="also align through the Python API (tandem.align; the tandem package "
                         "installed, see docs/python.md) and report its wall time and speed-up")
    ap.add_argument("--tandem-repeat", type=int, default=1,
                    help="time tandem's same-problem alignment as the mean of this many runs "
                         "(both through the example and through Python); gdtw runs once")
    args = ap.parse_args()
    exe = build_tandem(not args.no_build)
    demos = [int(d) for d in args.demos.split(",")]
    raw = {i: load(i) for i in [0] + demos}
    names = raw[0][0]
    const = {k for i in raw for k in range(len(names)) if np.ptp(raw[i][1][:, k]) == 0}
    keep = [k for k in range(len(names)) if k not in const]
    names = [names[k] for k in keep]
    if const:
        print(f"# dropped constant channels: {sorted(const)}", file=sys.stderr)
    x_ref = minmax(raw[0][1][:, keep])
    w = np.ones(len(keep))
    print(f"# N = T_ref = {len(x_ref)}, M = {M}, lambda_inst = {LAMBDA_INST}, "
          f"lambda_cum = {LAMBDA_CUM}, s in [{S_MIN}, {S_MAX}], W = I, channels = {names}")
    py_head = " | tandem.align wall s | speed-up via Python" if args.python else ""
    print("demo | T_query | gdtw wall s | tandem wall s | speed-up | gdtw J | tandem J | "
          "J ratio (tandem/gdtw) | gdtw own f | tandem defaults: wall s, J" + py_head)
    print("---|---|---|---|---|---|---|---|---|---" + ("|---|---" if args.python else ""))
    for i in demos:
        x_q = minmax(raw[i][1][:, keep])
        tp = {
            "n_nodes": len(x_ref), "n_candidates": M, "lambda_inst": LAMBDA_INST,
            "lambda_cum": LAMBDA_CUM, "slope_min": S_MIN, "slope_max": S_MAX,
            "refinements": args.refinements, "max_jump": args.max_jump,
            "refine_radius": args.refine_radius,
            "smooth_width": 1,  # gdtw compares the signals as given
            "fill_length": 0,  # and returns its objective's minimizer everywhere
        }
        psi_t, wall_t, obj_rust = run_tandem(x_ref, x_q, names, exe, tp, args.tandem_repeat)
        # the crate's fast defaults on the same data and lambdas / slope bounds
        dp = {k: tp[k] for k in ("lambda_inst", "lambda_cum", "slope_min", "slope_max")}
        psi_d, wall_d, _ = run_tandem(x_ref, x_q, names, exe, dp)
        psi_g, wall_g, f_g = run_gdtw(x_ref, x_q)
        j_g = objective(x_ref, x_q, psi_g, w, LAMBDA_INST, LAMBDA_CUM)
        j_t = objective(x_ref, x_q, psi_t, w, LAMBDA_INST, LAMBDA_CUM)
        j_d = objective(x_ref, x_q, psi_d, w, LAMBDA_INST, LAMBDA_CUM)
        assert abs(j_t - obj_rust) <= 1e-6 * max(1.0, abs(j_t)), (j_t, obj_rust)
        py_cols = ""
        if args.python:
            psi_p, wall_p, _ = run_tandem_python(x_ref, x_q, tp, args.tandem_repeat)
            # Same data, same parameters, same solver: the same warp to the last bit.
            assert np.array_equal(psi_p, psi_t), "tandem.align differs from the align example"
            py_cols = f" | {wall_p:.3f} | {wall_g / wall_p:.1f}x"
        print(f"{i} | {len(x_q)} | {wall_g:.2f} | {wall_t:.3f} | {wall_g / wall_t:.1f}x | "
              f"{j_g:.6f} | {j_t:.6f} | {j_t / j_g:.4f} | {f_g:.6f} | {wall_d:.4f}, {j_d:.6f}"
              + py_cols, flush=True)


if __name__ == "__main__":
    main()
