"""How well the logger's period of an irregular log is estimated (docs/decisions.md,
"Timestamps: the mean period, jitter within 25 %"): the median step against the span over
the counted steps (tandem-lfd `Demonstration::regrid_csv_str`), both snapped to a whole rate
within 0.1 % like `period_from_times`. 1000 simulated logs per row, uniform jitter, 3 rows
dropped, seed 1. Standard library only: `python3 bench/resample_period.py`."""
import random


def snap(p):
    r = round(1 / p)
    return 1 / r if r >= 1 and abs(1 / r - p) <= 1e-3 * p else p


def estimates(t):
    steps = [b - a for a, b in zip(t, t[1:])]
    median = sorted(steps)[len(steps) // 2]
    count = sum(max(1, round(s / median)) for s in steps)
    return snap(median), snap((t[-1] - t[0]) / count)


for rate, amp, rows in [(100, 0.0015, 1000), (100, 0.0015, 200), (250, 0.0008, 1000), (250, 0.0008, 100)]:
    p = 1 / rate
    exact, worst = [0, 0], [0.0, 0.0]
    trials = 1000
    rng = random.Random(1)
    for _ in range(trials):
        t = [k * p + rng.uniform(-amp, amp) for k in range(rows)]
        for d in sorted(rng.sample(range(1, rows - 1), 3), reverse=True):
            del t[d]
        for i, e in enumerate(estimates(t)):
            exact[i] += abs(e - p) < 1e-12
            worst[i] = max(worst[i], abs(e - p) / p)
    print(
        f"{rate} Hz ±{amp * 1e3} ms, {rows} rows, 3 dropped: exact: median step "
        f"{exact[0] / trials:.1%}, span over counted steps {exact[1] / trials:.1%}; worst "
        f"error {worst[0]:.2%} vs {worst[1]:.2%}"
    )
