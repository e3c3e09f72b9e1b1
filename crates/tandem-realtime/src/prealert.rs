//! The pre-alert of every [`Tick`](crate::Tick) (issue 41): which robot needs the operator next
//! and how soon, so that a display can warn the operator ahead of time.
//!
//! **What is announced.** At the end of a tick, each robot's *next stretch* is the first maximal
//! run of low-confidence samples of its plan (rounds: its task, on its current or a later leg;
//! a continuous cell: its current task, else the next one) whose start `c_m` lies beyond its
//! clock widened by the clock tolerance, `c_m > s + tol` — a run it has not touched yet (a robot
//! low-confidence now is inside its current run, so its next stretch is the one after). The
//! stretch *starts* in the first tick that reports the robot low-confidence on it: the first
//! tick whose end clock reaches `c_m − tol`. [`PreAlert`] names the robot whose next stretch can
//! start soonest (the smallest `earliest_s`, the lowest index on a tie) and bounds that start
//! in seconds of real time from the end of the tick: the start of that tick is at least
//! `earliest_s` and at most `latest_s` away, under every admissible operator.
//!
//! **Earliest, conservatively.** A tick moves a robot's clock by at most `F_j·h` for the sample
//! `j` it starts in (`h` the tick; `F_j ≥ 1` the fast rate, 1 on schedule), and a tick reaching
//! sample `k` started within one largest step `M` before it. So the real time to move the clock
//! from `x` to `y` is at least `∫ dc / F'(c)` with `F'_k` the largest rate over that window of
//! samples (`Reach::fast`). The first tick reaching `c_m − tol` is the `j`-th from now with
//! `j·h ≥` that time, and it starts `(j − 1)·h` from now. Time waiting (for a start, at a hold,
//! at a gate, for the token) counts as 0, except the ticks a release or a token must still wait
//! for the switch time, which are certain. The dwells of holds count as 0 too.
//!
//! **Latest.** A running robot moves at least `S_j·h` per tick (Eq. 18's clamp, the operator's
//! slowest), so the ticks before the one that reaches `c_m − tol` take at most `∫ dc / S'(c)`
//! (`S'` the smallest slow rate over the same window). Only when nothing else can stop it: the
//! stretch is on the robot's current leg (rounds) or in the group whose token it holds (a
//! continuous cell), the robot is released or counting down its switch wait, and it is not
//! held by the fault monitor. Otherwise the start waits on another robot (a hold's rules, the
//! next leg's start, the token), which no bound on this robot's rates limits: `latest_s` is
//! `+∞`.
//!
//! Both are rounded to whole ticks with a relative slack of `1e-9` towards the safe side
//! (earliest down, latest up), so a rounding error of the prefix sums never makes the bound
//! wrong. Per tick the work is O(N) with the robots' monotone cursors, no allocation: the
//! tables are built with the plan.

/// The pre-alert of a [`Tick`](crate::Tick): robot `robot` (0-based) is the robot whose next
/// low-confidence stretch can start soonest, in `[earliest_s, latest_s]` seconds of real time
/// from the end of the tick (the start of the first tick that reports it low-confidence on
/// that stretch), under every admissible operator (module docs of `tandem_realtime::prealert`
/// define "next stretch" precisely). `latest_s` is `+∞` when the start waits on another robot
/// (a hold's release rules, a leg's start, the continuous cell's token) or on the fault
/// monitor. Both are whole multiples of the tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreAlert {
    /// The robot (0-based).
    pub robot: usize,
    /// Lower bound on the real time (s) from the end of this tick until the stretch starts.
    pub earliest_s: f64,
    /// Upper bound on the same time (s); `f64::INFINITY` when unbounded.
    pub latest_s: f64,
}

/// Relative slack of the rounding to whole ticks (module docs).
const SLACK: f64 = 1e-9;

/// Whole ticks of `h` (s) that surely pass before a robot needing at least `t_s` (s) of motion
/// starts the tick that completes it: `max(0, ⌈t/h⌉ − 1)`, rounded down by the slack.
pub(crate) fn ticks_before_at_least(t_s: f64, h: f64) -> u64 {
    let q = t_s / h * (1.0 - SLACK) - SLACK;
    if q.is_finite() && q > 0.0 {
        (q.ceil() as u64).saturating_sub(1)
    } else if q.is_infinite() && q > 0.0 {
        u64::MAX / 4
    } else {
        0
    }
}

/// Whole ticks of `h` (s) that at most pass before a robot needing at most `t_s` (s) of motion
/// starts the tick that completes it: `⌊t/h⌋`, rounded up by the slack (`None` if not finite).
pub(crate) fn ticks_before_at_most(t_s: f64, h: f64) -> Option<u64> {
    let q = t_s / h * (1.0 + SLACK) + SLACK;
    (q.is_finite() && q < 1e15).then(|| q.max(0.0).floor() as u64)
}

/// The reach tables of one plan (a [`Timeline`](crate::Timeline): a leg, or a cell's task):
/// per sample, the real-time bounds of moving through it and the next low-confidence run.
#[derive(Clone, Debug, Default)]
pub(crate) struct Reach {
    /// `G_fast(c_n)`: the least real time (s) from the plan's start to clock `c_n`, `n ∈
    /// 0..=T_ref` (module docs).
    fast: Vec<f64>,
    /// `F'_n`: the largest clock rate a tick can have in sample `n`.
    fast_rate: Vec<f64>,
    /// `G_slow(c_n)`: the most real time (s) the ticks take from the start to `c_n`.
    slow: Vec<f64>,
    /// `S'_n`: the smallest clock rate a tick can have in sample `n`.
    slow_rate: Vec<f64>,
    /// Per sample `n`, the first `m ≥ n` that starts a low-confidence run (`T_ref`: none).
    run_from: Vec<usize>,
    /// Per run start `m`, `G_fast(c_m − tol)` (other entries unused).
    fast_to_run: Vec<f64>,
    /// Per run start `m`, `G_slow(c_m − tol)`.
    slow_to_run: Vec<f64>,
}

impl Reach {
    /// The tables of `tl` for a robot whose tick moves the clock between `lo(n)·h` and
    /// `hi(n)·h` from sample `n` (at most `max_step_s` in any tick), reports low confidence
    /// `tol_s` around its traversed interval.
    pub(crate) fn new(
        tl: &crate::Timeline,
        lo: impl Fn(usize) -> f64,
        hi: impl Fn(usize) -> f64,
        max_step_s: f64,
        tol_s: f64,
    ) -> Reach {
        let n_ref = tl.n_ref();
        let c = tl.sample_clock_s();
        let conf = tl.conf();
        // Sliding extremes over the window `j ≤ k` with `c_{j+1} > c_k − M`.
        let mut fast_rate = vec![0.0; n_ref];
        let mut slow_rate = vec![0.0; n_ref];
        let mut maxq = std::collections::VecDeque::new();
        let mut minq = std::collections::VecDeque::new();
        let mut left = 0;
        for k in 0..n_ref {
            let (h, l) = (hi(k), lo(k));
            while maxq.back().is_some_and(|&(_, v)| v <= h) {
                maxq.pop_back();
            }
            maxq.push_back((k, h));
            while minq.back().is_some_and(|&(_, v)| v >= l) {
                minq.pop_back();
            }
            minq.push_back((k, l));
            while left < k && c[left + 1] <= c[k] - max_step_s {
                left += 1;
            }
            while maxq.front().is_some_and(|&(j, _)| j < left) {
                maxq.pop_front();
            }
            while minq.front().is_some_and(|&(j, _)| j < left) {
                minq.pop_front();
            }
            fast_rate[k] = maxq.front().map_or(h, |&(_, v)| v);
            slow_rate[k] = minq.front().map_or(l, |&(_, v)| v);
        }
        let mut fast = vec![0.0; n_ref + 1];
        let mut slow = vec![0.0; n_ref + 1];
        for k in 0..n_ref {
            let d = c[k + 1] - c[k];
            fast[k + 1] = fast[k] + d / fast_rate[k];
            slow[k + 1] = slow[k] + d / slow_rate[k];
        }
        let mut run_from = vec![n_ref; n_ref + 1];
        for k in (0..n_ref).rev() {
            let starts = !conf[k] && (k == 0 || conf[k - 1]);
            run_from[k] = if starts { k } else { run_from[k + 1] };
        }
        let mut out = Reach {
            fast,
            fast_rate,
            slow,
            slow_rate,
            run_from,
            fast_to_run: vec![0.0; n_ref],
            slow_to_run: vec![0.0; n_ref],
        };
        for m in 0..n_ref {
            if out.run_from[m] == m {
                let x = c[m] - tol_s;
                let at = tl.sample_at(x);
                out.fast_to_run[m] = out.fast_at(c, at, x);
                out.slow_to_run[m] = out.slow_at(c, at, x);
            }
        }
        out
    }

    /// `G_fast(x)` for a clock `x` in sample `at` (clamped to the plan).
    fn fast_at(&self, c: &[f64], at: usize, x: f64) -> f64 {
        let x = x.clamp(c[0], c[c.len() - 1]);
        self.fast[at] + (x - c[at]).max(0.0) / self.fast_rate[at]
    }

    /// `G_slow(x)` for a clock `x` in sample `at` (clamped to the plan).
    fn slow_at(&self, c: &[f64], at: usize, x: f64) -> f64 {
        let x = x.clamp(c[0], c[c.len() - 1]);
        self.slow[at] + (x - c[at]).max(0.0) / self.slow_rate[at]
    }

    /// The next run of a robot at clock `s` in sample `at` of plan `c` (its breakpoints):
    /// the first run start `m` with `c_m > s + tol`, or `None`.
    pub(crate) fn next_run(&self, c: &[f64], at: usize, s: f64, tol_s: f64) -> Option<usize> {
        let n_ref = self.run_from.len() - 1;
        let mut m = self.run_from[at.min(n_ref)];
        while m < n_ref && c[m] <= s + tol_s {
            m = self.run_from[m + 1];
        }
        (m < n_ref).then_some(m)
    }

    /// Least and most real time (s) of motion from clock `s` (sample `at`) to the tick that
    /// reaches run `m`'s start less `tol`.
    pub(crate) fn to_run(&self, c: &[f64], at: usize, s: f64, m: usize) -> (f64, f64) {
        (
            (self.fast_to_run[m] - self.fast_at(c, at, s)).max(0.0),
            (self.slow_to_run[m] - self.slow_at(c, at, s)).max(0.0),
        )
    }

    /// Least and most real time (s) of motion from the start of sample `n` to the tick that
    /// reaches run `m`'s start less `tol`.
    pub(crate) fn to_run_from_sample(&self, n: usize, m: usize) -> (f64, f64) {
        (
            (self.fast_to_run[m] - self.fast[n]).max(0.0),
            (self.slow_to_run[m] - self.slow[n]).max(0.0),
        )
    }

    /// Least real time (s) of motion from clock `s` (sample `at`) to clock `x` (sample
    /// `x_at`) of plan `c`; 0 when `x ≤ s`.
    pub(crate) fn fast_between(&self, c: &[f64], at: usize, s: f64, x_at: usize, x: f64) -> f64 {
        (self.fast_at(c, x_at, x) - self.fast_at(c, at, s)).max(0.0)
    }

    /// Least real time (s) from clock `s` (sample `at`) to the plan's end.
    pub(crate) fn fast_to_end(&self, c: &[f64], at: usize, s: f64) -> f64 {
        (self.fast[self.fast.len() - 1] - self.fast_at(c, at, s)).max(0.0)
    }

    /// Least real time (s) from the plan's start to the tick that reaches its first run, or
    /// `None` without a run.
    pub(crate) fn fast_to_first_run(&self) -> Option<f64> {
        let m = self.run_from[0];
        (m + 1 < self.run_from.len()).then(|| self.fast_to_run[m].max(0.0))
    }

    /// The plan's first run (the sample it starts at), or `None` without a run.
    pub(crate) fn first_run(&self) -> Option<usize> {
        let m = self.run_from[0];
        (m + 1 < self.run_from.len()).then_some(m)
    }

    /// Least real time (s) through the whole plan.
    pub(crate) fn fast_total(&self) -> f64 {
        self.fast[self.fast.len() - 1]
    }
}

/// Builds the alert from per-robot candidates `(robot, earliest ticks, latest ticks)` at tick
/// `h`: the smallest earliest, the lowest index on a tie.
pub(crate) fn pick(
    candidates: impl Iterator<Item = (usize, u64, Option<u64>)>,
    h: f64,
) -> Option<PreAlert> {
    pick_ranked(candidates.map(|(i, e, l)| (i, e, l, i)), h)
}

/// As [`pick`], with a tie on the earliest broken by the smallest `rank` (then the first
/// candidate): candidates `(robot, earliest ticks, latest ticks, rank)`.
pub(crate) fn pick_ranked(
    candidates: impl Iterator<Item = (usize, u64, Option<u64>, usize)>,
    h: f64,
) -> Option<PreAlert> {
    let mut best: Option<(usize, u64, Option<u64>, usize)> = None;
    for cand in candidates {
        if best.is_none_or(|b| cand.1 < b.1 || (cand.1 == b.1 && cand.3 < b.3)) {
            best = Some(cand);
        }
    }
    best.map(|(robot, e, l, _)| PreAlert {
        robot,
        earliest_s: e as f64 * h,
        latest_s: l.map_or(f64::INFINITY, |l| (l.max(e)) as f64 * h),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Timeline;

    #[test]
    fn tick_rounding_errs_to_the_safe_side() {
        // 2.5 ticks of motion: the completing tick is the 3rd, starting 2 ticks from now.
        assert_eq!(ticks_before_at_least(2.5, 1.0), 2);
        assert_eq!(ticks_before_at_most(2.5, 1.0), Some(2));
        // Exactly 3 ticks: the 3rd tick completes it (starts after 2); at most 3 before.
        assert_eq!(ticks_before_at_least(3.0, 1.0), 2);
        assert_eq!(ticks_before_at_most(3.0, 1.0), Some(3));
        assert_eq!(ticks_before_at_least(0.0, 1.0), 0);
        assert_eq!(ticks_before_at_most(f64::INFINITY, 1.0), None);
    }

    #[test]
    fn reach_of_a_plan_by_hand() {
        // [HC, HC, LC, HC, LC] of 1 s each, F = 2, S = ½ everywhere; M = 2 s.
        let conf = [true, true, false, true, false];
        let g = [1.0; 5];
        let tl = Timeline::new(&conf, &g, &[0.5; 5], &[2.0; 5], 0.0, 1.0).unwrap();
        let r = Reach::new(&tl, |n| tl.rate_slow(n), |n| tl.rate_fast(n), 2.0, 0.0);
        let c = tl.sample_clock_s();
        assert_eq!(r.next_run(c, 0, 0.0, 0.0), Some(2));
        // At clock 2 (start of the run) the run is touched: the next is 4.
        assert_eq!(r.next_run(c, 2, 2.0, 0.0), Some(4));
        assert_eq!(r.next_run(c, 4, 4.5, 0.0), None);
        // 2 s of clock at rate 2 → 1 s; at rate ½ → 4 s.
        assert_eq!(r.to_run(c, 0, 0.0, 2), (1.0, 4.0));
        assert_eq!(r.fast_to_first_run(), Some(1.0));
        assert_eq!(r.fast_total(), 2.5);
    }
}
