#!/usr/bin/env python3
"""Families of demonstrations with known warps: tandem-warp vs. `gdtw` 1.2.1, family by family.

`warp_truth.py` scores the two tools on one synthetic family; a default tuned there may not hold
elsewhere.  This script generates pairs of demonstrations from several *families*, each with its
own reason why alignment is hard (see FAMILIES), aligns every pair with both tools on the same
data and the same weights, and scores each warp against the true one (absolute error in query
samples at every reference sample: mean and 95th percentile over all samples of a family, and over
the samples outside dwells, where every channel is flat and the warp is not identifiable).

Seeds: every family draws its cases from NumPy's `default_rng([2027, family index, seed])`.
Seeds 0-7 (SELECT_SEEDS) are the ones tandem-warp's defaults were chosen on; seeds 1000-1023
were used for nothing but the reported tables: 1000-1005 (HELD_OUT_SEEDS, `--seeds held-out`)
and all 24 (HELD_OUT_SEEDS_24, `--seeds held-out-24`), six cases per family giving a noisy ratio
where single cases differ a lot (the dwell family).

Scaling and weights, as tandem-lfd aligns demonstrations: every channel is divided by its range
over both demonstrations (tandem-lfd's `W = diag(1/r_j^2)` with `r_j` the range over all
demonstrations); the scaled channels then have unit weight on both sides.  Both tools get these
scaled arrays; gdtw's own per-signal re-scaling is switched off (`Signal(scale_signals=False)`).

gdtw runs with one node per reference sample (N = T_ref), M = 301 and its own unbounded slopes
(see README.md, "Fairness"); tandem-warp with its slope bounds [0.25, 4].  Every true warp's slope
stays in [0.3, 3.6].  Wall times: `align()` alone (the example's --report) and `gdtw.warp(...)`,
one thread each, in the same process run, on the same case, one after the other.

Run from the repository root, in a virtual environment with the pinned packages (git-ignored
.venv; nothing of gdtw is committed):
    python3 -m venv .venv && .venv/bin/pip install -r bench/peers/requirements.txt
    .venv/bin/python bench/peers/warp_families.py --seeds held-out --gdtw all --tandem '{}'
"""
import argparse
import hashlib
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

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gdtw_compare import ROOT, build_tandem  # noqa: E402

SELECT_SEEDS = list(range(0, 8))
HELD_OUT_SEEDS = list(range(1000, 1006))
HELD_OUT_SEEDS_24 = list(range(1000, 1024))
T_REF = 3000
S_MIN, S_MAX = 0.25, 4.0  # tandem-warp's slope bounds
TRUE_SLOPE = (0.3, 3.6)  # every true warp's slope stays inside
GDTW_SETTINGS = {
    # gdtw's own defaults: lambda_inst = 0.1, lambda_cum = 1, unbounded slopes, its stopping rule
    "default": {},
    # weaker regularization, gdtw's own stopping rule
    "lambda0.01": {"lambda_inst": 0.01, "lambda_cum": 0.01},
    # weaker regularization, all max_iters = 10 refinements (its most accurate on warp_truth.py)
    "best": {"lambda_inst": 0.01, "lambda_cum": 0.01, "epsilon_abs": 0.0, "epsilon_rel": 0.0},
}

# One family = overrides of BASE.  Units: positions m, force N, torque N m, gripper 0/1; "noise"
# is the standard deviation of white Gaussian sensor noise per channel (both demonstrations).
BASE = {
    "reaches": (4, 6),            # minimum-jerk reaches between random waypoints
    "dwell": (0.04, 0.10),        # relative width of each dwell (before, between, after reaches)
    "reach": (0.10, 0.22),        # relative width of each reach
    "box": (0.6, 0.6, 0.6),       # waypoint box per position axis (m)
    "force": (5.0, 20.0),         # contact force plateau (N), during about half the reaches
    "ripple": (0.03, 4.0, 10.0),  # force ripple: relative amplitude, cycles per reach (min, max)
    "wiggle": (0.0, 0.0, 0.0),    # task-locked position wiggle: amplitude (m), cycles per reach
    "vibration": (0.0, 0.0, 0.0),  # own-time vibration of positions (m) and force (x 100 N), Hz-like
    "torque": None,               # extra channel: torque about the tool (range, noise) if given
    "grip_in_reach": False,       # gripper also toggles in the middle of reaches
    "noise": (0.0015, 0.0015, 0.0015, 0.25),  # x, y, z, force
    "profile": "smooth",          # speed profile: smooth harmonics + local slow-downs, or abrupt
    "harmonics": 0.12,            # +- log-speed amplitude of each of 3 harmonics
    "slowdowns": (2, 3, 0.5, 0.7),  # count range, depth range (fraction of speed removed)
    "abrupt": (0.3, 3.0, 4, 8),   # abrupt profile: speed factor range, segment count range
    "length": ((0.7, 1.4),),      # T_query / T_ref drawn uniformly from one of these intervals
    "pauses": None,               # (lo, hi): the query stays in every dwell lo..hi times as long
    "segments": None,             # (lo, hi): both take every dwell and reach at their own pace
}
FAMILIES = {
    # warp_truth.py's task: 3-D reaches, a contact force with small ripples, a gripper, dwells
    "base": {},
    # the same task with 10 % of the noise (near-clean sensors)
    "clean": {"noise": (0.00015, 0.00015, 0.00015, 0.025)},
    # noisy force sensor (2 N on 5-20 N) and noisy positions (6 mm)
    "noisy": {"noise": (0.006, 0.006, 0.006, 2.0)},
    # high-frequency content: task-locked sanding strokes (force ripple of 20 % at 20-40 cycles
    # per reach, 4 mm position wiggle at 10-20 cycles) and machine vibration in own time
    # (1 mm and 0.5 N at 150-300 cycles per demonstration)
    "ripple": {"ripple": (0.2, 20.0, 40.0), "wiggle": (0.004, 10.0, 20.0),
               "vibration": (0.001, 150.0, 300.0)},
    # long dwells (about 70 % of the task): the warp is not identifiable most of the time
    "dwell": {"dwell": (0.15, 0.35), "reach": (0.05, 0.12), "reaches": (3, 5)},
    # large and abrupt speed changes: the query's speed jumps between 0.3x and 3x in 4-8 pieces
    "speed": {"profile": "abrupt"},
    # very different lengths: the query is 0.6-0.7 or 1.45-1.6 times the reference
    "length": {"length": ((0.6, 0.7), (1.45, 1.6))},
    # channels of very different scales: y moves only 3-6 mm (noise 1.5 mm), a torque channel of
    # 0.05 N m range with 0.01 N m noise, force up to 50 N, and a gripper that also toggles
    # mid-reach; after range scaling the small channels' noise is large and the binary step sharp
    "scales": {"box": (0.6, 0.006, 0.6), "force": (10.0, 50.0), "torque": (0.05, 0.01),
               "grip_in_reach": True},
    # pauses of independent length: the query stays in every dwell 0.5-2 times as long as its
    # speed profile says (drawn per dwell), so the speed ratio jumps at every dwell's edges and is
    # constant inside it; there the straight line of the slope penalty is right
    "pauses": {"pauses": (0.5, 2.0)},
    # every segment at its own pace: both demonstrations take every dwell and every reach 0.5-2
    # times as long (drawn per segment and demonstration) at an otherwise constant speed, so the
    # speed ratio is constant inside each segment and jumps at every edge, as when a demonstrator
    # times each motion separately; a smooth speed ratio is the wrong prior here
    "segments": {"harmonics": 0.0, "slowdowns": (0, 0, 0.5, 0.7), "segments": (0.5, 2.0)},
}


def min_jerk(tau):
    return 10 * tau**3 - 15 * tau**4 + 6 * tau**5


def smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def family_params(name):
    return dict(BASE, **FAMILIES[name])


def make_task(rng, p):
    """The task as a function of task time u in [0, 1]: (f(u) -> (len(u), C) array, dwells)."""
    k = int(rng.integers(p["reaches"][0], p["reaches"][1] + 1))
    widths = np.empty(2 * k + 1)
    widths[0::2] = rng.uniform(*p["dwell"], k + 1)
    widths[1::2] = rng.uniform(*p["reach"], k)
    edges = np.concatenate([[0.0], np.cumsum(widths)]) / widths.sum()
    dwells = [(edges[2 * i], edges[2 * i + 1]) for i in range(k + 1)]
    reaches = [(edges[2 * i + 1], edges[2 * i + 2]) for i in range(k)]
    way = rng.uniform(0.0, 1.0, (k + 1, 3)) * np.array(p["box"])
    way[:, 1] = np.where(np.arange(k + 1) % 2 == 0, 0.0, 1.0) * p["box"][1]  # y alternates
    way[:, 1] *= rng.uniform(0.5, 1.0)
    contact = rng.random(k) < 0.5
    contact[rng.integers(k)] = True
    level = rng.uniform(*p["force"], k)
    rip_a, rip_lo, rip_hi = p["ripple"]
    rip_f, rip_ph = rng.uniform(rip_lo, rip_hi, k), rng.uniform(0, 2 * np.pi, k)
    wig_a, wig_lo, wig_hi = p["wiggle"]
    wig_f, wig_ph = rng.uniform(wig_lo, wig_hi if wig_hi > 0 else 1.0, k), rng.uniform(0, 2 * np.pi, k)
    grip = rng.random(k - 1) < 0.5
    grip[rng.integers(k - 1)] = True  # at least one step
    toggles = [0.5 * (a + b) for (a, b), g in zip(dwells[1:-1], grip) if g]
    if p["grip_in_reach"]:
        toggles += [a + rng.uniform(0.3, 0.7) * (b - a) for a, b in reaches if rng.random() < 0.5]
    torque_at = rng.uniform(0.2, 0.8, k)
    n_ch = 6 if p["torque"] else 5

    def f(u):
        u = np.asarray(u, dtype=float)
        out = np.zeros((len(u), n_ch))
        out[:, :3] = way[0]
        for i, (a, b) in enumerate(reaches):
            tau = np.clip((u - a) / (b - a), 0.0, 1.0)
            started = u >= a
            out[started, :3] = way[i] + (way[i + 1] - way[i]) * min_jerk(tau[started])[:, None]
            inside = (u > a) & (u < b)
            if wig_a > 0:
                env = np.sin(np.pi * tau) ** 2
                out[inside, 0] += wig_a * env[inside] * np.sin(2 * np.pi * wig_f[i] * tau[inside]
                                                               + wig_ph[i])
            if contact[i]:
                ramp = smoothstep(tau / 0.15) * smoothstep((1 - tau) / 0.15)
                ripple = 1 + rip_a * np.sin(2 * np.pi * rip_f[i] * tau + rip_ph[i])
                out[inside, 3] += level[i] * ramp[inside] * ripple[inside]
            if p["torque"]:
                # a short twist of the tool during the reach
                bump = np.exp(-0.5 * ((tau - torque_at[i]) / 0.08) ** 2)
                out[inside, 5] += p["torque"][0] * (1 if i % 2 else -1) * bump[inside]
        g = np.zeros(len(u))
        for t in sorted(toggles):
            g = np.where(u >= t, 1.0 - g, g)
        out[:, 4] = g
        return out

    return f, dwells


def time_map(rng, p, abrupt=False, fine=200_001):
    """Task time u(s) of one demonstration over its own normalized time s, on a fine grid."""
    s = np.linspace(0.0, 1.0, fine)
    if abrupt:
        lo, hi, n_lo, n_hi = p["abrupt"]
        n = int(rng.integers(n_lo, n_hi + 1))
        cuts = np.sort(rng.uniform(0.05, 0.95, n - 1))
        levels = np.exp(rng.uniform(np.log(lo), np.log(hi), n))
        v = levels[np.searchsorted(cuts, s)]
    else:
        log_v = np.zeros(fine)
        for j in (1, 2, 3):
            amp = rng.uniform(-p["harmonics"], p["harmonics"])
            log_v += amp * np.sin(2 * np.pi * j * s + rng.uniform(0, 2 * np.pi))
        v = np.exp(log_v)
        n_lo, n_hi, d_lo, d_hi = p["slowdowns"]
        for _ in range(int(rng.integers(n_lo, n_hi + 1))):
            c, w, d = rng.uniform(0.05, 0.95), rng.uniform(0.01, 0.04), rng.uniform(d_lo, d_hi)
            inside = np.abs(s - c) < w / 2
            v[inside] *= 1 - d * np.cos(np.pi * (s[inside] - c) / w) ** 2
    u = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]))])
    return s, u / u[-1]


def stretched(s, u, intervals, factors):
    """The time map `(s, u)` (own time, task time, fine grid) of a demonstration that stays in
    task-time interval `intervals[k]` `factors[k]` times as long: the own time spent on every step
    inside it is scaled, and own time normalized again to [0, 1]."""
    ds = np.diff(s)
    mid = 0.5 * (u[1:] + u[:-1])
    g = np.ones_like(ds)
    for (a, b), f in zip(intervals, factors):
        g[(mid >= a) & (mid <= b)] = f
    s2 = np.concatenate([[0.0], np.cumsum(ds * g)])
    return s2 / s2[-1], u


def make_case(family, seed):
    """One case of a family: scaled reference and query (samples x channels), the true warp
    (query samples at every reference sample) and the dwell mask (per reference sample)."""
    p = family_params(family)
    rng = np.random.default_rng([2027, list(FAMILIES).index(family), seed])
    f, dwells = make_task(rng, p)
    # every segment of the task, dwells and reaches, in task time
    edges = sorted({e for d in dwells for e in d})
    segments = list(zip(edges[:-1], edges[1:]))
    intervals = p["length"]
    lo, hi = intervals[int(rng.integers(len(intervals)))]
    t_query = int(round(T_REF * rng.uniform(lo, hi)))
    while True:
        # draw both speed profiles again until the true warp's slope stays in TRUE_SLOPE
        s_r, u_r = time_map(rng, p)
        s_q, u_q = time_map(rng, p, abrupt=p["profile"] == "abrupt")
        if p["pauses"]:
            s_q, u_q = stretched(s_q, u_q, dwells, rng.uniform(*p["pauses"], len(dwells)))
        if p["segments"]:
            s_r, u_r = stretched(s_r, u_r, segments, rng.uniform(*p["segments"], len(segments)))
            s_q, u_q = stretched(s_q, u_q, segments, rng.uniform(*p["segments"], len(segments)))
        u_ref = np.interp(np.linspace(0, 1, T_REF), s_r, u_r)
        truth = np.interp(u_ref, u_q, s_q) * (t_query - 1)  # psi(n) = s_q^-1(u_ref(n))
        slope = np.diff(truth) * (T_REF - 1) / (t_query - 1)
        if TRUE_SLOPE[0] <= slope.min() and slope.max() <= TRUE_SLOPE[1]:
            break
    truth[0], truth[-1] = 0.0, t_query - 1.0
    x_ref = f(u_ref)
    x_q = f(np.interp(np.linspace(0, 1, t_query), s_q, u_q))
    vib_a, vib_lo, vib_hi = p["vibration"]
    noise = list(p["noise"]) + [0.0] + ([p["torque"][1]] if p["torque"] else [])
    for x in (x_ref, x_q):
        s = np.linspace(0.0, 1.0, len(x))
        if vib_a > 0:
            for c, a in ((0, vib_a), (1, vib_a), (2, vib_a), (3, 500 * vib_a)):
                x[:, c] += a * np.sin(2 * np.pi * rng.uniform(vib_lo, vib_hi) * s
                                      + rng.uniform(0, 2 * np.pi))
        for c, sd in enumerate(noise):
            if sd > 0:
                x[:, c] += rng.normal(0.0, sd, len(x))
    in_dwell = np.zeros(T_REF, dtype=bool)
    for a, b in dwells:
        in_dwell |= (u_ref >= a) & (u_ref <= b)
    both = np.vstack([x_ref, x_q])
    r = both.max(axis=0) - both.min(axis=0)
    r[r < 1e-9] = 1.0
    return {"ref": x_ref / r, "query": x_q / r, "truth": truth, "in_dwell": in_dwell}


def case_key(family, seed):
    """Digest of a case's data, so cached gdtw results are reused only for identical data."""
    c = make_case(family, seed)
    h = hashlib.sha256()
    for k in ("ref", "query"):
        h.update(np.ascontiguousarray(c[k]).tobytes())
    return c, h.hexdigest()[:16]


def run_gdtw(x_ref, x_query, setting):
    import gdtw
    import gdtw.gdtw as gdtw_core
    from gdtw.signal import Signal

    # the data is already scaled: keep it as given
    gdtw_core.signal = lambda z, name, n: Signal(z, name, n, scale_signals=False).get()
    params = dict(GDTW_SETTINGS[setting], N=len(x_ref), M=301)
    start = time.perf_counter()
    _, _, _, g = gdtw.warp(x=x_query, y=x_ref, params=params)
    wall = time.perf_counter() - start
    return np.asarray(g.tau) * (len(x_query) - 1), wall


def run_tandem_many(x_ref, x_query, exe, settings):
    """Aligns one pair with every tandem-warp setting (JSON strings); (warp, wall s) each."""
    names = [f"c{i}" for i in range(x_ref.shape[1])]
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for tag, x in (("ref", x_ref), ("query", x_query)):
            path = os.path.join(tmp, f"{tag}.csv")
            np.savetxt(path, x, delimiter=",", header=",".join(names), comments="", fmt="%.17g")
            paths.append(path)
        for setting in settings:
            res = subprocess.run([exe, *paths, "--params", setting, "--report"],
                                 capture_output=True, text=True, check=True)
            psi = np.loadtxt(res.stdout.splitlines()[1:], delimiter=",")[:, 1]
            rep = dict(kv.split("=") for kv in res.stderr.split())
            out.append((psi, float(rep["wall_s"])))
    return out


def parse_seeds(text):
    if text == "select":
        return SELECT_SEEDS
    if text == "held-out":
        return HELD_OUT_SEEDS
    if text == "held-out-24":
        return HELD_OUT_SEEDS_24
    out = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out.extend(range(int(a), int(b or a) + 1))
    return out


def stats(errors, masks):
    e, m = np.concatenate(errors), np.concatenate(masks)
    return {"mean": e.mean(), "p95": np.percentile(e, 95),
            "mean_out": e[~m].mean(), "p95_out": np.percentile(e[~m], 95)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--families", default=",".join(FAMILIES), help="comma-separated families")
    ap.add_argument("--seeds", default="held-out",
                    help="'select' (0-7, defaults chosen on them), 'held-out' (1000-1005), "
                         "'held-out-24' (1000-1023), or a list such as 0-3,9")
    ap.add_argument("--tandem", action="append", default=None, metavar="JSON",
                    help="tandem-warp WarpParams as JSON (repeatable; default: the crate defaults)")
    ap.add_argument("--gdtw", action="append", default=[], choices=sorted(GDTW_SETTINGS) + ["all"],
                    help="also run gdtw with this setting (repeatable; 'all' = every setting)")
    ap.add_argument("--cache", metavar="DIR",
                    help="reuse gdtw warps stored here (keyed by the case data's digest); the "
                         "reported table is measured without it")
    ap.add_argument("--json", metavar="FILE", help="also write every figure as JSON")
    ap.add_argument("--per-case", action="store_true", help="print one line per case")
    ap.add_argument("--no-build", action="store_true", help="use an already built example")
    args = ap.parse_args()
    gdtw_settings = list(GDTW_SETTINGS) if "all" in args.gdtw else args.gdtw
    if gdtw_settings:
        from importlib.metadata import version
        if version("gdtw") != "1.2.1":
            sys.exit(f"gdtw {version('gdtw')} installed; the comparison is pinned to 1.2.1 "
                     "(bench/peers/requirements.txt)")
    exe = build_tandem(not args.no_build)
    families = args.families.split(",")
    seeds = parse_seeds(args.seeds)
    tandem_settings = args.tandem or ["{}"]
    tools = [("tandem " + t, t) for t in tandem_settings] + [("gdtw " + g, g) for g in gdtw_settings]
    table = {}
    for fam in families:
        errs = {name: [] for name, _ in tools}
        walls = {name: [] for name, _ in tools}
        masks = []
        for seed in seeds:
            case, key = case_key(fam, seed)
            masks.append(case["in_dwell"])
            line = [f"{fam} seed {seed} T_query {len(case['query'])}"]
            results = run_tandem_many(case["ref"], case["query"], exe, tandem_settings)
            for setting in gdtw_settings:
                path = args.cache and os.path.join(args.cache, f"{fam}-{seed}-{setting}-{key}.npz")
                if path and os.path.exists(path):
                    z = np.load(path)
                    psi, wall = z["psi"], float(z["wall"])
                else:
                    psi, wall = run_gdtw(case["ref"], case["query"], setting)
                    if path:
                        os.makedirs(args.cache, exist_ok=True)
                        np.savez(path, psi=psi, wall=wall)
                results.append((psi, wall))
            for (name, _), (psi, wall) in zip(tools, results):
                e = np.abs(psi - case["truth"])
                errs[name].append(e)
                walls[name].append(wall)
                line.append(f"{name}: {e.mean():.2f}/{e[~case['in_dwell']].mean():.2f}")
            if args.per_case:
                print(" | ".join(line), file=sys.stderr, flush=True)
        table[fam] = {name: dict(stats(errs[name], masks), wall=float(np.mean(walls[name])))
                      for name, _ in tools}
    print(f"# seeds {args.seeds} ({len(seeds)} per family), T_ref = {T_REF}, channels scaled by "
          f"their range over both demonstrations, unit weights; errors in query samples")
    print("family | tool | mean err | p95 err | mean outside dwells | p95 outside dwells | "
          "wall s per case")
    print("---|---|---|---|---|---|---")
    for fam, rows in table.items():
        for name, r in rows.items():
            print(f"{fam} | {name} | {r['mean']:.2f} | {r['p95']:.2f} | {r['mean_out']:.2f} | "
                  f"{r['p95_out']:.2f} | {r['wall']:.4f}")
    if gdtw_settings and tandem_settings:
        print("\n# tandem / gdtw's most accurate setting of the family (lowest of its settings, per "
              "figure); speed-up against that setting")
        print("family | tandem setting | mean | p95 | mean outside | p95 outside | speed-up")
        print("---|---|---|---|---|---|---")
        for fam, rows in table.items():
            g = {k: v for k, v in rows.items() if k.startswith("gdtw")}
            best = {m: min(v[m] for v in g.values()) for m in ("mean", "p95", "mean_out", "p95_out")}
            best_name = min(g, key=lambda k: g[k]["mean"])
            for t in tandem_settings:
                r = rows["tandem " + t]
                ratios = " | ".join(f"{r[m] / best[m]:.3f}" for m in best)
                print(f"{fam} | {t} | {ratios} | {g[best_name]['wall'] / r['wall']:.0f}x")
        print("\n# worst family: the largest of the ratios above over the families, per tandem setting")
        print("tandem setting | mean | p95 | mean outside | p95 outside")
        print("---|---|---|---|---")
        for t in tandem_settings:
            worst = []
            for m in ("mean", "p95", "mean_out", "p95_out"):
                worst.append(max(
                    rows["tandem " + t][m] / min(v[m] for k, v in rows.items() if k.startswith("gdtw"))
                    for rows in table.values()))
            print(f"{t} | " + " | ".join(f"{w:.3f}" for w in worst))
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"seeds": seeds, "table": table}, fh, indent=1)


if __name__ == "__main__":
    main()
