#!/usr/bin/env python3
"""The task zoo's alignment against its known warps: `gdtw` 1.2.1 on the demonstrations the fit aligns.

`cargo xtask zoo --export-alignments DIR` writes, per family and seed, the demonstrations exactly
as the fit's alignment sees them (channels in the model's order, the quaternion block sign-aligned
to the reference's first orientation, every channel multiplied by the square root of the fit's
weight `W_jj`, so that an unweighted squared distance is the fit's weighted one), the true task
progress of every row, and the fit's own warps (`tandem_<i>.npy`).  This script aligns every
demonstration but the reference to the reference with `gdtw` on those same arrays (its own
re-scaling off, `N = T_ref`, `M = 301`: the settings of `warp_families.py`, README "Fairness"),
and scores both warps against the truth with ONE definition, that of `tandem_zoo::eval::warps`:

    error(n) = | P_r^-1( P_i( psi(n) ) ) - n |      (reference samples)

with `psi(n)` the row of demo `i` paired with reference sample `n`, `P_i` demo `i`'s true progress
interpolated linearly between rows and `P_r^-1` the inverse of the reference's (strictly
increasing).  It checks that its score of the exported tandem warps equals the one the zoo
computed (`meta.json`), and writes a JSON that `cargo xtask zoo --peer-warps FILE` shows beside the
fit's error in docs/zoo.md.

Run from the repository root, in the virtual environment of README.md (`.venv`, git-ignored):
    cargo xtask zoo --seeds held-out --export-alignments results/zoo/align
    .venv/bin/python bench/peers/zoo_gdtw.py results/zoo/align --json results/zoo/gdtw.json
    cargo xtask zoo --from results/zoo/heldout/*/zoo.json --peer-warps results/zoo/gdtw.json --docs
(`--families`, `--seeds` restrict the tasks; `--setting` picks a gdtw setting of
warp_families.py: default, lambda0.01, best.)
"""
import argparse
import json
import os
import sys
import time
from importlib import metadata

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from warp_families import GDTW_SETTINGS, run_gdtw  # noqa: E402

GDTW_VERSION = "1.2.1"


def errors(psi, progress_demo, progress_ref):
    """Per reference sample, |P_r^-1(P_i(psi(n))) - n| in reference samples."""
    p = np.interp(psi, np.arange(len(progress_demo)), progress_demo)
    back = np.interp(p, progress_ref, np.arange(len(progress_ref)))
    return np.abs(back - np.arange(len(progress_ref)))


def score(warps, progress, r):
    """Mean and max error over every reference sample of every demonstration in `warps`."""
    errs = [errors(psi, progress[i], progress[r]) for i, psi in warps.items()]
    allerr = np.concatenate(errs)
    return float(allerr.mean()), float(allerr.max())


def tasks_in(root, families, seeds):
    for family in sorted(os.listdir(root)):
        if families and family not in families:
            continue
        fdir = os.path.join(root, family)
        for seed in sorted(os.listdir(fdir), key=int):
            if seeds and int(seed) not in seeds:
                continue
            yield family, int(seed), os.path.join(fdir, seed)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dir", help="the folder `cargo xtask zoo --export-alignments` wrote")
    ap.add_argument("--json", help="write the errors here (for `cargo xtask zoo --peer-warps`)")
    ap.add_argument("--setting", default="default", choices=sorted(GDTW_SETTINGS))
    ap.add_argument("--families", default="", help="comma-separated families (default: all)")
    ap.add_argument("--seeds", default="", help="comma-separated seeds (default: all exported)")
    args = ap.parse_args()
    version = metadata.version("gdtw")
    if version != GDTW_VERSION:
        sys.exit(f"gdtw {version} installed; this comparison is pinned to {GDTW_VERSION} "
                 "(bench/peers/requirements.txt)")
    families = [f for f in args.families.split(",") if f]
    seeds = [int(s) for s in args.seeds.split(",") if s]
    out = {"tool": f"gdtw {GDTW_VERSION}", "setting": args.setting, "tasks": []}
    print(f"{'family':<16} {'seed':>5} {'pairs':>5} {'T_ref':>6} | {'fit mean':>8} {'fit max':>8} | "
          f"{'gdtw mean':>9} {'gdtw max':>8} {'gdtw s':>7}")
    for family, seed, tdir in tasks_in(args.dir, families, seeds):
        with open(os.path.join(tdir, "meta.json")) as f:
            meta = json.load(f)
        r = meta["reference_idx"]
        n = meta["n_demos"]
        signal = [np.load(os.path.join(tdir, f"signal_{i}.npy")) for i in range(n)]
        progress = [np.load(os.path.join(tdir, f"progress_{i}.npy")) for i in range(n)]
        others = [i for i in range(n) if i != r]
        tandem = {i: np.load(os.path.join(tdir, f"tandem_{i}.npy")) for i in others}
        t_mean, t_max = score(tandem, progress, r)
        want = meta["tandem"]
        if not (np.isclose(t_mean, want["mean_samples"], rtol=1e-9, atol=1e-9)
                and np.isclose(t_max, want["max_samples"], rtol=1e-9, atol=1e-9)):
            sys.exit(f"{family} seed {seed}: this script scores the fit's warps {t_mean}, {t_max}; "
                     f"the zoo said {want['mean_samples']}, {want['max_samples']}: definitions differ")
        gd, wall = {}, 0.0
        for i in others:
            psi, w = run_gdtw(signal[r], signal[i], args.setting)
            gd[i] = psi
            wall += w
        g_mean, g_max = score(gd, progress, r)
        out["tasks"].append({"family": family, "seed": seed, "pairs": len(others),
                             "mean_samples": g_mean, "max_samples": g_max, "wall_s": wall})
        print(f"{family:<16} {seed:>5} {len(others):>5} {len(progress[r]):>6} | {t_mean:8.2f} "
              f"{t_max:8.1f} | {g_mean:9.2f} {g_max:8.1f} {wall:7.1f}", flush=True)
        if args.json:  # after every task, so that an interrupted run keeps what it measured
            with open(args.json, "w") as f:
                json.dump(out, f, indent=1)
                f.write("\n")


if __name__ == "__main__":
    start = time.perf_counter()
    main()
    print(f"({time.perf_counter() - start:.0f} s)")
