#!/usr/bin/env python3
"""Quickstart: fit the six sanding demonstrations, run a few rounds in the simulated workcell,
and watch the schedule shorten as the planner learns where the operator is needed.

    python examples/python/quickstart.py                 # 40 rounds, ~2 s
    python examples/python/quickstart.py --plot schedule.png   # needs matplotlib

The demonstrations are the repository's ``fixtures/sanding/demo_{0..5}.csv`` (4 sanding
passes, 100 Hz, channels x, y, z, qx, qy, qz, qw, force, tool). After every round (one
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
    ap.add_argument("--rounds", type=int, default=40, help="rounds to run (one execution per robot)")
    ap.add_argument("--every", type=int, default=5, help="print every this many rounds")
    ap.add_argument("--samples", type=int, default=1000, help="sampler candidates per schedule")
    ap.add_argument("--save", type=Path, help="save the planner's state file here")
    ap.add_argument("--plot", type=Path, help="draw the final schedule (PNG/SVG) with matplotlib")
    args = ap.parse_args()

    demos = sorted(args.demos_dir.glob("demo_[0-9].csv"))
    planner = tandem.fit(demos, params={"sampler": {"samples": args.samples}})
    model = planner.model
    print(f"fitted {len(demos)} demonstrations: T_ref = {model.n_ref} samples × {model.dt_s} s, "
          f"channels {model.channels}")
    print(f"round  0: T_total {planner.schedule.t_total_s:7.2f} s, "
          f"high confidence {100 * planner.confidence.high_share:5.1f} %")
    labels = args.demos_dir / "demo_0.labels.csv"
    for k in range(1, args.rounds + 1):
        # Two fresh workpieces (random paint), one per robot, and one run of the schedule.
        needs = tandem.sim.sanding_needs(labels, seed=k)
        run = tandem.sim.run_round(planner, needs, seed=k)
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
