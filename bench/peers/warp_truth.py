#!/usr/bin/env python3
"""Ground-truth benchmark: tandem-warp vs. `gdtw` 1.2.1 against KNOWN warps.

Generates pairs of synthetic multi-channel demonstrations of one task whose true correspondence is
known (`make_case(seed)`, deterministic), aligns each query to its reference with both tools on the
same (scaled, weighted) data, and scores each warp by the absolute error against the true warp, in
query samples, at every reference sample: mean and 95th percentile over all samples of all cases,
and over the samples outside dwells (where every channel is flat and the warp is not identifiable).

The task (task time u in [0, 1]): 4-6 minimum-jerk reaches between random 3-D waypoints, separated
by dwells (all channels flat); a contact force that rises to a plateau with small ripples during
about half the reaches; a binary gripper channel that toggles in the middle of some dwells.
Each demonstration runs through the task at its own speed: a random smooth speed profile
(3 harmonics, +-12 % each) times 2-3 local slow-downs to 30-50 % of the speed over 1-4 % of its
length.  Reference: 3000 samples; query: 0.7-1.4 times that.  Noise: 1.5 mm on positions, 0.25 N
on the force, none on the gripper.  Channels x, y, z, force, gripper; weights 1, 1, 1, 1, 0.5.

Both tools get the same data: every channel min-max scaled to [-1, 1] with the reference's range,
then multiplied by sqrt(weight) for gdtw (its L2 loss then equals tandem's W-weighted loss; gdtw's
own per-signal re-scaling is switched off for that, through its `Signal(scale_signals=False)`).

Run from the repository root (see README.md):
    python3 bench/peers/warp_truth.py --seeds 0-23 --gdtw default --gdtw lambda0.01 --gdtw best
"""
import argparse
import json
import os
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gdtw_compare import ROOT, build_tandem, run_tandem  # noqa: E402

T_REF = 3000
NAMES = ["x", "y", "z", "force", "gripper"]
WEIGHTS = np.array([1.0, 1.0, 1.0, 1.0, 0.5])
S_MIN, S_MAX = 0.25, 4.0
GDTW_SETTINGS = {
    # gdtw's own defaults: lambda_inst = 0.1, lambda_cum = 1, unbounded slopes, stops early
    "default": {},
    # the setting: weaker regularization, gdtw's own stopping rule
    "lambda0.01": {"lambda_inst": 0.01, "lambda_cum": 0.01},
    # its most accurate setting here: weaker regularization, all max_iters = 10 refinements
    "best": {"lambda_inst": 0.01, "lambda_cum": 0.01, "epsilon_abs": 0.0, "epsilon_rel": 0.0},
    # the slope bounds tandem-warp uses: its first grid cannot follow moderate slopes at N = T_ref
    "bounded": {"s_min": S_MIN, "s_max": S_MAX},
}


def min_jerk(tau):
    return 10 * tau**3 - 15 * tau**4 + 6 * tau**5


def smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def task(rng):
    """The task as a function of task time: returns (f(u) -> (len(u), 5) array, dwell intervals)."""
    k = int(rng.integers(4, 7))
    dwell_w = rng.uniform(0.04, 0.10, k + 1)
    reach_w = rng.uniform(0.10, 0.22, k)
    widths = np.empty(2 * k + 1)
    widths[0::2], widths[1::2] = dwell_w, reach_w
    edges = np.concatenate([[0.0], np.cumsum(widths)]) / widths.sum()
    dwells = [(edges[2 * i], edges[2 * i + 1]) for i in range(k + 1)]
    reaches = [(edges[2 * i + 1], edges[2 * i + 2]) for i in range(k)]
    way = rng.uniform(0.0, 0.6, (k + 1, 3))
    contact = rng.random(k) < 0.5
    contact[rng.integers(k)] = True
    level = rng.uniform(5.0, 20.0, k)
    ripple_f = rng.uniform(4.0, 10.0, k)
    ripple_ph = rng.uniform(0, 2 * np.pi, k)
    grip = rng.random(k - 1) < 0.5
    grip[rng.integers(k - 1)] = True  # at least one step
    toggles = [0.5 * (a + b) for (a, b), g in zip(dwells[1:-1], grip) if g]

    def f(u):
        u = np.asarray(u, dtype=float)
        out = np.zeros((len(u), 5))
        out[:, :3] = way[0]
        for i, (a, b) in enumerate(reaches):
            tau = np.clip((u - a) / (b - a), 0.0, 1.0)
            started = u >= a
            out[started, :3] = way[i] + (way[i + 1] - way[i]) * min_jerk(tau[started])[:, None]
            if contact[i]:
                ramp = smoothstep(tau / 0.15) * smoothstep((1 - tau) / 0.15)
                ripple = 1 + 0.03 * np.sin(2 * np.pi * ripple_f[i] * tau + ripple_ph[i])
                inside = (u > a) & (u < b)
                out[inside, 3] += level[i] * ramp[inside] * ripple[inside]
        grip = np.zeros(len(u))
        for t in toggles:
            grip = np.where(u >= t, 1.0 - grip, grip)
        out[:, 4] = grip
        return out

    return f, dwells


def time_map(rng, fine=200_001):
    """Task time u(s) of one demonstration over its own normalized time s, on a fine grid."""
    s = np.linspace(0.0, 1.0, fine)
    log_v = np.zeros(fine)
    for j in (1, 2, 3):
        log_v += rng.uniform(-0.12, 0.12) * np.sin(2 * np.pi * j * s + rng.uniform(0, 2 * np.pi))
    v = np.exp(log_v)
    for _ in range(int(rng.integers(2, 4))):
        c, w, d = rng.uniform(0.05, 0.95), rng.uniform(0.01, 0.04), rng.uniform(0.5, 0.7)
        inside = np.abs(s - c) < w / 2
        v[inside] *= 1 - d * np.cos(np.pi * (s[inside] - c) / w) ** 2
    u = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]))])
    return s, u / u[-1]


def make_case(seed, noise=1.0):
    """One benchmark case: reference, query (samples x 5), true warp, dwell mask (per ref sample).

    `noise` scales the noise of every channel (1 = the benchmark's).
    """
    rng = np.random.default_rng([2026, seed])
    f, dwells = task(rng)
    t_query = int(round(T_REF * rng.uniform(0.7, 1.4)))
    while True:
        # draw both speed profiles again until the true warp respects the slope bounds
        (s_r, u_r), (s_q, u_q) = time_map(rng), time_map(rng)
        u_ref = np.interp(np.linspace(0, 1, T_REF), s_r, u_r)
        truth = np.interp(u_ref, u_q, s_q) * (t_query - 1)  # psi(n) = s_q^-1(u_ref(n))
        slope = np.diff(truth) * (T_REF - 1) / (t_query - 1)
        if S_MIN * 1.2 <= slope.min() and slope.max() <= S_MAX * 0.9:
            break
    truth[0], truth[-1] = 0.0, t_query - 1.0
    x_ref, x_q = f(u_ref), f(np.interp(np.linspace(0, 1, t_query), s_q, u_q))
    for x in (x_ref, x_q):
        x[:, :3] += noise * rng.normal(0.0, 0.0015, (len(x), 3))
        x[:, 3] += noise * rng.normal(0.0, 0.25, len(x))
    in_dwell = np.zeros(T_REF, dtype=bool)
    for a, b in dwells:
        in_dwell |= (u_ref >= a) & (u_ref <= b)
    lo, hi = x_ref.min(axis=0), x_ref.max(axis=0)
    scale = lambda x: 2.0 * (x - lo) / (hi - lo) - 1.0  # noqa: E731
    return {"ref": scale(x_ref), "query": scale(x_q), "truth": truth, "in_dwell": in_dwell}


def run_gdtw(x_ref, x_query, setting):
    import gdtw
    import gdtw.gdtw as gdtw_core
    from gdtw.signal import Signal

    # the data is already scaled and weighted: keep it as given
    gdtw_core.signal = lambda z, name, n: Signal(z, name, n, scale_signals=False).get()
    sw = np.sqrt(WEIGHTS)
    params = dict(GDTW_SETTINGS[setting], N=len(x_ref), M=301)
    start = time.perf_counter()
    _, _, _, g = gdtw.warp(x=x_query * sw, y=x_ref * sw, params=params)
    wall = time.perf_counter() - start
    return np.asarray(g.tau) * (len(x_query) - 1), wall


def parse_seeds(text):
    out = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out.extend(range(int(a), int(b or a) + 1))
    return out


def summary(errors, masks):
    e, m = np.concatenate(errors), np.concatenate(masks)
    return e.mean(), np.percentile(e, 95), e[~m].mean(), np.percentile(e[~m], 95)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", default="0-11", help="case seeds, e.g. 0-11 or 100-119")
    ap.add_argument("--tandem", action="append", default=None, metavar="JSON",
                    help="tandem-warp WarpParams as JSON (repeatable; default: the crate defaults)")
    ap.add_argument("--gdtw", action="append", default=[], choices=sorted(GDTW_SETTINGS),
                    help="also run gdtw with this setting (repeatable)")
    ap.add_argument("--per-case", action="store_true", help="print one line per case")
    ap.add_argument("--no-build", action="store_true", help="use an already built example")
    args = ap.parse_args()
    exe = build_tandem(not args.no_build)
    seeds = parse_seeds(args.seeds)
    tandem_settings = args.tandem or ["{}"]
    tools = [("tandem " + t, t) for t in tandem_settings] + [("gdtw " + g, g) for g in args.gdtw]
    errs = {name: [] for name, _ in tools}
    walls = {name: [] for name, _ in tools}
    masks = []
    for seed in seeds:
        case = make_case(seed)
        masks.append(case["in_dwell"])
        line = [f"seed {seed} T_query {len(case['query'])}"]
        for name, setting in tools:
            if name.startswith("tandem"):
                tp = dict(json.loads(setting), weights=WEIGHTS.tolist())
                psi, wall, _ = run_tandem(case["ref"], case["query"], NAMES, exe, tp)
            else:
                psi, wall = run_gdtw(case["ref"], case["query"], setting)
            e = np.abs(psi - case["truth"])
            errs[name].append(e)
            walls[name].append(wall)
            line.append(f"{name}: {e.mean():.2f}/{e[~case['in_dwell']].mean():.2f}")
        if args.per_case:
            print(" | ".join(line), file=sys.stderr, flush=True)
    print(f"# {len(seeds)} cases (seeds {args.seeds}), T_ref = {T_REF}, weights {WEIGHTS.tolist()}, "
          f"slope bounds [{S_MIN}, {S_MAX}]; errors in query samples")
    print("tool | mean err | p95 err | mean err outside dwells | p95 outside dwells | "
          "mean wall s per case")
    print("---|---|---|---|---|---")
    for name, _ in tools:
        m, p, mo, po = summary(errs[name], masks)
        print(f"{name} | {m:.2f} | {p:.2f} | {mo:.2f} | {po:.2f} | {np.mean(walls[name]):.4f}")


if __name__ == "__main__":
    main()
