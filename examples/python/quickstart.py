#!/usr/bin/env python3
"""Quickstart: fit demonstrations, run a few rounds in the simulated workcell, and watch the
schedule shorten as the planner learns where the operator is needed.

    python examples/python/quickstart.py                 # 40 rounds, ~2 s
    python examples/python/quickstart.py --plot schedule.png   # needs matplotlib
    python examples/python/quickstart.py --demos-dir my_task/ --channel fz
    python examples/python/quickstart.py --demos-dir my_task/ --need need.csv

The demonstrations are by default the repository's ``fixtures/sanding/demo_{0..5}.csv`` (4
sanding passes, 100 Hz, channels x, y, z, qx, qy, qz, qw, force, tool), whose ground-truth
labels (``demo_<i>.labels.csv``, one file per demonstration; the simulation reads those of the
model's reference) say which samples of a random workpiece need the operator.
With ``--demos-dir`` any folder of demonstrations works: its ``demo_<digits>.csv`` files if
there are any, else every ``*.csv`` in it except label, log and correction files (in name
order, shorter names first, so ``peg_2`` before ``peg_10``; the fit's reference is the medoid, the
demonstration the others agree with best, so the order does not change the model). Where the workpieces need
the operator then comes from ``--need`` (a need file, ``tandem need`` writes one), or else
from the model's low-confidence regions right after the fit, each needed on a workpiece with
probability ``--need-level``. After every round (one
execution of each robot) the planner adds both executions to the model (Eq. 21), their supervised samples to the observations,
updates the confidence (Eq. 9–12) and re-schedules (§II-C): ``T_total`` (Eq. 13) falls as
stretches that never need the operator become high-confidence and the robots overlap.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import tandem

ROOT = Path(__file__).resolve().parents[2]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--demos-dir", type=Path, default=ROOT / "fixtures" / "sanding")
    ap.add_argument("--need", type=Path, help="need file (tandem need writes one)")
    ap.add_argument("--need-level", type=float, default=0.5,
                    help="without labels or --need: probability that a low-confidence region "
                         "of the fit needs the operator on a workpiece")
    ap.add_argument("--channel", help="channel the simulated operator's corrections raise "
                                      "(default: force)")
    ap.add_argument("--resample", action="store_true",
                    help="put demonstrations whose t column is irregular (a drifting logger) on "
                         "an even grid first, as tandem fit --resample")
    ap.add_argument("--rounds", type=int, default=40, help="rounds to run (one execution per robot)")
    ap.add_argument("--every", type=int, default=5, help="print every this many rounds")
    ap.add_argument("--samples", type=int, default=1000, help="sampler candidates per schedule")
    ap.add_argument("--save", type=Path, help="save the planner's state file here")
    ap.add_argument("--plot", type=Path, help="draw the final schedule (PNG/SVG) with matplotlib")
    args = ap.parse_args()

    demos = demonstrations(args.demos_dir)
    planner = tandem.fit(demos, params={"sampler": {"samples": args.samples}},
                         resample=args.resample)
    model = planner.model
    print(f"fitted {len(demos)} demonstrations: T_ref = {model.n_ref} samples × {model.dt_s} s, "
          f"channels {model.channels}")
    print(f"round  0: T_total {planner.schedule.t_total_s:7.2f} s, "
          f"high confidence {100 * planner.confidence.high_share:5.1f} %")
    channel = args.channel or "force"
    if channel not in model.channels:
        raise SystemExit(f"the model has no channel `{channel}` for the simulated operator to "
                         f"raise: give --channel NAME (channels: {', '.join(model.channels)})")
    # One labels file per demonstration, demo_<i>.labels.csv for the i-th file given to the fit.
    labels = [d.with_name(d.stem + ".labels.csv") for d in demos]
    if args.need is not None:
        source = {"need_file": args.need}
        print(f"needs: {args.need}")
    elif all(f.exists() for f in labels):
        source = None
        print(f"needs: sanding labels {labels[model.reference_idx]} (the reference's)")
    else:
        regions = tandem.sim.low_confidence_regions(planner)
        if not regions:
            raise SystemExit("every sample is trusted after the fit: nothing for the operator to do")
        source = {"regions": [(a, b, args.need_level) for a, b in regions]}
        shown = ", ".join(f"{a:.2f}–{b:.2f} s" for a, b in regions[:5])
        more = f" and {len(regions) - 5} more" if len(regions) > 5 else ""
        print(f"needs: the fit's {len(regions)} low-confidence region(s) ({shown}{more}), "
              f"each needed with probability {args.need_level}")
    operator = {"force_channel": channel}
    for k in range(1, args.rounds + 1):
        # Fresh workpieces, one per robot, and one run of the schedule.
        if source is None:
            needs = tandem.sim.sanding_needs(labels, seed=k, planner=planner)
        else:
            needs = tandem.sim.needs(planner=planner, seed=k, **source)
        run = tandem.sim.run_round(planner, needs, seed=k, operator=operator)
        report = planner.record_round(**run.record_args())
        if k % args.every and k != args.rounds:
            continue
        print(f"round {k:2d}: T_total {report['t_total_s']:7.2f} s, "
              f"high confidence {100 * planner.confidence.high_share:5.1f} %, "
              f"ran {run.duration_s:6.2f} s, operator idle {100 * run.operator_idle_share:4.1f} %, "
              f"overlap ticks {run.overlap_ticks}, schedule {report['source']}")
    schedule = planner.schedule
    print(f"final schedule: τ = {schedule.offsets[0]:.2f} s, T_total = {schedule.t_total_s:.2f} s, "
          f"low-confidence intervals per robot {[len(i) for i in schedule.lc_intervals]}")
    if args.save:
        planner.save(args.save)
        print(f"saved {args.save} (open it with `tandem inspect {args.save}`)")
    if args.plot:
        plot(schedule, args.plot)


def demonstrations(folder: Path) -> list:
    """The demonstration files of ``folder``, in name order: ``demo_<digits>.csv`` (the
    fixtures' layout) if there are any, else every ``*.csv`` without a second suffix (not
    ``.labels.csv``, ``.reflog.csv``, ``.corr.csv``)."""
    numbered = [p for p in folder.glob("demo_*.csv") if p.stem[5:].isdigit()]
    candidates = numbered or [p for p in folder.glob("*.csv") if "." not in p.stem]
    demos = sorted(candidates, key=lambda p: (len(p.name), p.name))
    if len(demos) < 2:
        raise SystemExit(f"{folder}: {len(demos)} demonstration file(s) (*.csv); at least 2 are needed")
    return demos


def plot(schedule: tandem.Schedule, path: Path) -> None:
    """The schedule as a Gantt chart (blue: robot 1 low-confidence, red: robot 2), as Fig. 5."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot (pip install matplotlib)")
        return
    fig, ax = plt.subplots(figsize=(9, 2.2))
    colors = ["tab:blue", "tab:red"]
    for robot, (start, end) in enumerate(zip(schedule.starts_s, schedule.ends_s)):
        ax.barh(robot, end - start, left=start, color="lightgray")
        for a, b in schedule.lc_intervals[robot]:
            ax.barh(robot, b - a, left=a, color=colors[robot])
    ax.set_yticks([0, 1], ["robot 1", "robot 2"])
    ax.set_xlabel("global time (s)")
    ax.set_title(f"T_total = {schedule.t_total_s:.1f} s")
    fig.tight_layout()
    fig.savefig(path)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
