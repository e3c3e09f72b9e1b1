//! The lead bound for `N ≥ 3` robots: upper bounds on how far robot `c`'s schedule clock can be
//! ahead of robot `p`'s when `p`'s clock is at `u`, over every operator strategy, integrated
//! along `p`'s progress (the argument is in the [module docs](super), "Three or more robots: the
//! lead bound").

use super::window::Sliding;
use super::{PairSlack, Windows};
use crate::holds::Plans;
use crate::timeline::Timeline;

/// The bound of one ordered pair `(p, c)` on `p`'s sample grid: for every tick start at which
/// `p` and `c` both run, no two robots have been low-confidence in one tick, and `p`'s clock
/// lies in the cell `(u_s[k − 1], u_s[k]]` (the first cell includes its left end), `c`'s clock
/// is at most `reach_s[k]` (schedule-clock s). `reach_s` is non-decreasing: the largest
/// `u + Λ_pc(u)` over the cells up to `k`.
#[derive(Clone, Debug, Default)]
pub(super) struct Lead {
    /// Cell ends (p's schedule clock, s), increasing; `u_s[0]` is where the analysis starts.
    u_s: Vec<f64>,
    /// The largest `c`-clock (s) at a tick start with `p` in any cell up to this one.
    reach_s: Vec<f64>,
}

impl Lead {
    /// Where the analysis starts: the later start of `p` and `c` (s).
    pub(super) fn start_s(&self) -> f64 {
        self.u_s[0]
    }

    /// Whether the pair has been integrated.
    fn is_done(&self) -> bool {
        !self.u_s.is_empty()
    }

    /// The largest `c`-clock (s) at any tick start with `p`'s clock below `u` (or at the start
    /// of the analysis).
    pub(super) fn reach_below(&self, u: f64) -> f64 {
        // The cell containing u, or the last one.
        let k = self.u_s.partition_point(|&x| x < u).min(self.u_s.len() - 1);
        self.reach_s[k]
    }
}

/// What one pair's analysis needs besides the two timelines.
#[derive(Clone, Copy, Debug)]
pub(super) struct PairInputs<'a> {
    /// `M_p`: the largest step of `p` in one tick (schedule-clock s).
    pub(super) max_step_p: f64,
    /// Per robot `r` other than `p` and `c`, the `p`-clocks (s) between which `r` may run at
    /// a tick start, `(τ_r, R_rp)`: from `u = τ_r` on (a robot that runs started when every
    /// running robot had reached its start) up to `R_rp`, the largest `p`-clock at a tick
    /// start at which `r` still runs (`+∞` in the first pass, the reach of `Λ_rp` below `r`'s
    /// end in the second: a robot at or past its end is finished and sets no pace). Empty
    /// when only `p` and `c` run.
    pub(super) thirds: &'a [(f64, f64)],
    /// Where the analysis starts (s): `max(τ_p, τ_c)`.
    pub(super) u0_s: f64,
    /// The lead of `c` over `p` there (s).
    pub(super) lead0_s: f64,
}

/// One robot's Eq. 17 rates per reference sample, computed once per check: `S` and `F`, and
/// the same restricted to the high- or low-confidence samples (`−∞` elsewhere).
pub(super) struct RateTable {
    slow: Vec<f64>,
    fast: Vec<f64>,
    slow_hc: Vec<f64>,
    fast_hc: Vec<f64>,
    fast_lc: Vec<f64>,
}

impl RateTable {
    pub(super) fn new(tl: &Timeline) -> Self {
        let n = tl.n_ref();
        let (slow, fast): (Vec<f64>, Vec<f64>) =
            (0..n).map(|i| (tl.rate_slow(i), tl.rate_fast(i))).unzip();
        let only = |v: &[f64], hc: bool| -> Vec<f64> {
            v.iter()
                .zip(tl.conf())
                .map(|(&x, &c)| if c == hc { x } else { f64::NEG_INFINITY })
                .collect()
        };
        RateTable {
            slow_hc: only(&slow, true),
            fast_hc: only(&fast, true),
            fast_lc: only(&fast, false),
            slow,
            fast,
        }
    }
}

/// One robot's rate window of the lead bound: the samples meeting a schedule-clock interval whose
/// ends never decrease, and extreme rates over them, overall or over the samples of one
/// confidence.
struct RateWindow<'a> {
    windows: Windows,
    table: &'a RateTable,
    /// Largest rates (`c`) or smallest (`p`).
    largest: bool,
    lo: usize,
    hi: usize,
    slow: Sliding,
    fast: Sliding,
    /// `c` only: over its high-confidence samples (`−∞` where there is none).
    slow_hc: Sliding,
    fast_hc: Sliding,
    /// `c` only: over its low-confidence samples.
    fast_lc: Sliding,
}

/// What a [`RateWindow`] read: the samples `lo..=hi` and extreme rates over them.
struct Read {
    lo: usize,
    hi: usize,
    /// Extreme `S` and `F` over all the samples.
    slow: f64,
    fast: f64,
    /// Largest `S` and `F` over the high-confidence samples, largest `F` over the
    /// low-confidence ones (`−∞` where there is none; `c`'s window only).
    slow_hc: f64,
    fast_hc: f64,
    fast_lc: f64,
}

impl<'a> RateWindow<'a> {
    fn new(windows: Windows, table: &'a RateTable, largest: bool) -> Self {
        RateWindow {
            windows,
            table,
            largest,
            lo: 0,
            hi: 0,
            slow: Sliding::default(),
            fast: Sliding::default(),
            slow_hc: Sliding::default(),
            fast_hc: Sliding::default(),
            fast_lc: Sliding::default(),
        }
    }

    /// The samples of `tl` meeting `[a_s, b_s]` and their extreme rates.
    fn read(&mut self, tl: &Timeline, a_s: f64, b_s: f64) -> Read {
        let max = self.largest;
        let t = self.table;
        match self.windows {
            Windows::Sliding => {
                let lo = tl.advance_cursor(&mut self.lo, a_s);
                let hi = tl.advance_cursor(&mut self.hi, b_s);
                let (mut slow_hc, mut fast_hc, mut fast_lc) = (0.0, 0.0, 0.0);
                if max {
                    slow_hc = self.slow_hc.query(lo, hi, |n| t.slow_hc[n], true);
                    fast_hc = self.fast_hc.query(lo, hi, |n| t.fast_hc[n], true);
                    fast_lc = self.fast_lc.query(lo, hi, |n| t.fast_lc[n], true);
                }
                Read {
                    lo,
                    hi,
                    slow: self.slow.query(lo, hi, |n| t.slow[n], max),
                    fast: self.fast.query(lo, hi, |n| t.fast[n], max),
                    slow_hc,
                    fast_hc,
                    fast_lc,
                }
            }
            Windows::Scanned => {
                // The oracle reads the timeline itself, not the table.
                let (lo, hi) = (tl.sample_at(a_s), tl.sample_at(b_s));
                let pick = |a: f64, b: f64| if max { a.max(b) } else { a.min(b) };
                let first = tl.rates(lo);
                let (mut slow, mut fast) = (first.slow, first.fast);
                let (mut slow_hc, mut fast_hc, mut fast_lc) =
                    (f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
                for n in lo..=hi {
                    let r = tl.rates(n);
                    (slow, fast) = (pick(slow, r.slow), pick(fast, r.fast));
                    if tl.conf()[n] {
                        slow_hc = slow_hc.max(r.slow);
                        fast_hc = fast_hc.max(r.fast);
                    } else {
                        fast_lc = fast_lc.max(r.fast);
                    }
                }
                Read {
                    lo,
                    hi,
                    slow,
                    fast,
                    slow_hc,
                    fast_hc,
                    fast_lc,
                }
            }
        }
    }
}

/// Integrates the bound `Λ_pc` of `(p, c)` over `p`'s samples from `inputs.u0_s` to `p`'s end,
/// as a piecewise-linear function of `p`'s clock `u`.
///
/// `Λ` grows along the *frontier*: on each cell `[u_a, u_b]` (between two of `p`'s breakpoints)
/// its slope `ρ̄` is the largest gain per unit of `p`'s progress of every tick that can start
/// with `p` at `u ∈ [u_a − M_p, u_b]` (a tick moves `p` by at most `M_p`) and `c` within `δ` of
/// the frontier, `c ∈ [u + Λ(u) − δ, u + Λ(u)]`: `p`'s mode and smallest rates over the samples
/// meeting `[u_a − M_p, u_b]`, `c`'s mode and largest rates over the samples meeting
/// `[u_a − M_p + Λ(u_a − M_p) − δ, u_b + Λ(u_b)]`, and whether another robot may already run
/// (`τ_r ≤ u_b`). Per unit of `p`'s progress (module docs, (b)):
///
/// - `c` low-confidence (it sets the pace): `F_c/F_p − 1`;
/// - `c` high-confidence and `p` low-confidence: `S_c/S_p − 1`;
/// - both high-confidence, another robot may set the pace: `max(S_c/S_p, F_c/F_p) − 1`; only
///   `p` and `c` run: `S_c/F_p − 1` (Alg. 1 pulls a robot ahead back).
///
/// A state further than `δ` below the frontier cannot overtake it in one tick when
/// `δ ≥ (ρ_max + 1)·M_p`, with `ρ_max` the largest gain of any state (`≥ −1` everywhere): so
/// `δ = (ρ_max + 1)·M_p` over the two robots' extreme rates. `Λ` is floored at 0 (a robot
/// behind does not matter) and `u + Λ(u)` is non-decreasing (`ρ̄ ≥ −1`). Cost O(T_ref).
pub(super) fn integrate(
    (tp, rates_p): (&Timeline, &RateTable),
    (tc, rates_c): (&Timeline, &RateTable),
    inputs: PairInputs,
    windows: Windows,
) -> Lead {
    let PairInputs {
        max_step_p: mp,
        thirds,
        u0_s,
        lead0_s,
    } = inputs;
    let end = tp.end_s();
    let mut lead = Lead {
        u_s: vec![u0_s],
        reach_s: vec![u0_s + lead0_s],
    };
    if u0_s >= end {
        return lead;
    }
    // The largest gain of any state, from the two robots' extreme rates.
    let rho_max = (tc.max_rate_slow() / tp.min_rate_slow())
        .max(tc.max_rate_fast() / tp.min_rate_fast())
        - 1.0;
    let delta = (rho_max.max(-1.0) + 1.0) * mp;
    let bp = tp.sample_clock_s();
    let mut k = bp.partition_point(|&b| b <= u0_s);
    let mut p_win = RateWindow::new(windows, rates_p, false);
    let mut c_win = RateWindow::new(windows, rates_c, true);
    let mut c_top_s = f64::NEG_INFINITY;
    // (u, u + Λ(u)) at the grid points of the last M_p, for the near window's lower end.
    let mut history: std::collections::VecDeque<(f64, f64)> = [(u0_s, u0_s + lead0_s)].into();
    let mut lam = lead0_s;
    let mut reach = u0_s + lead0_s;
    let mut u_a = u0_s;
    loop {
        let u_b = if k < bp.len() { bp[k].min(end) } else { end };
        let du = u_b - u_a;
        let left = u_a - mp;
        let p_read = p_win.read(tp, left, u_b);
        let p_lc = tp.any_low_conf(p_read.lo, p_read.hi);
        let p_hc = tp.any_high_conf(p_read.lo, p_read.hi);
        let (s_p, f_p) = (p_read.slow, p_read.fast);
        // The frontier's c-clock at the last grid point at or before `left` bounds it from
        // below there (u + Λ(u) is non-decreasing).
        while history.len() >= 2 && history[1].0 <= left {
            history.pop_front();
        }
        let near_lo = history[0].1 - delta;
        c_top_s = c_top_s.max(u_b + lam + rho_max.max(0.0) * du);
        let c_read = c_win.read(tc, near_lo, c_top_s);
        let c_lc = tc.any_low_conf(c_read.lo, c_read.hi);
        let c_hc = tc.any_high_conf(c_read.lo, c_read.hi);
        // A robot other than p and c may run at a tick start with p in [u_a − M_p, u_b].
        let third_runs = thirds
            .iter()
            .any(|&(from, until)| from <= u_b && until >= left && from <= until);
        let mut rho = f64::NEG_INFINITY;
        if c_lc {
            rho = rho.max(c_read.fast_lc / f_p - 1.0);
        }
        if c_hc {
            let drag = c_read.slow_hc / s_p - 1.0;
            if p_lc {
                rho = rho.max(drag);
            }
            if p_hc {
                if third_runs {
                    rho = rho.max(drag).max(c_read.fast_hc / f_p - 1.0);
                } else {
                    rho = rho.max(c_read.slow_hc / f_p - 1.0);
                }
            }
        }
        lam = (lam + rho * du).max(0.0);
        reach = reach.max(u_b + lam);
        history.push_back((u_b, u_b + lam));
        lead.u_s.push(u_b);
        lead.reach_s.push(reach);
        if u_b >= end {
            return lead;
        }
        u_a = u_b;
        k += 1;
    }
}

/// The slacks of every pair of regions of `robots` (`N ≥ 2`) under the lead bound.
///
/// The ordered pairs `(p, c)` are integrated in the order of their later start `max(τ_p, τ_c)`,
/// so that the lead with which `c` can be ahead when a later `p` starts is read from pairs
/// already done; each pair's regions are tested as soon as its bound is known (and with
/// `stop_at_first` the check stops at the first slack `≤ 0`). `max_step_of[i]` is `M_i`, `eps`
/// the comparison tolerance `ε` (schedule-clock s), `(switch_ticks, tick_s)` the switch time in
/// whole ticks (0: none) and the control tick (real s).
///
/// For every region `P` of `p` and the first region `C` of `c` starting at or after `P` starts
/// (later regions of `c` are implied): `slack = (T_c − ε) − (reach + M_c)` with `T_c` where `c`
/// enters `C` and `reach` the largest `c`-clock at a tick start with `p` below
/// `u_max = min(T_p + ε, end_p)` (the largest `p`-clock at a tick start from which `p` can still
/// traverse `P`); `+∞` when `u_max` is at or before the later start of `p` and `c` (`p` has left
/// `P` before both run). The result is sorted by `C`'s start, then `P`'s.
pub(super) fn slacks(
    robots: &[Timeline],
    max_step_of: &[f64],
    eps: f64,
    windows: Windows,
    stop_at_first: bool,
    passes: Passes,
    (switch_ticks, tick_s): (u64, f64),
) -> Vec<PairSlack> {
    let robot_of: Vec<usize> = (0..robots.len()).collect();
    slacks_of_legs(
        &Legs {
            legs: robots,
            robot_of: &robot_of,
            plans: None,
            switch_ticks,
            tick_s,
        },
        max_step_of,
        eps,
        windows,
        stop_at_first,
        passes,
    )
}

/// Which passes of the lead bound run ([`slacks_of_legs`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Passes {
    /// Both: the second, where the first rejects, ends other robots' running where the first
    /// pass's bounds say they have finished.
    Both,
    /// The first only: every other robot may set the pace from its start on (the check before
    /// docs/decisions.md, "Robots that have finished set no pace"; a sound, looser baseline).
    First,
}

/// The virtual robots the lead bound runs on: every robot's legs (`crate::holds`), each of
/// which starts as a robot starts, with the release rules of the plans (none without holds:
/// then the legs are the robots).
pub(super) struct Legs<'a> {
    /// The legs.
    pub(super) legs: &'a [Timeline],
    /// The robot of each leg.
    pub(super) robot_of: &'a [usize],
    /// The plans with their release rules (`None`: one leg per robot, no rules).
    pub(super) plans: Option<&'a Plans>,
    /// `k`: the operator's switch time in whole ticks (`super::switch_ticks`; 0: none).
    pub(super) switch_ticks: u64,
    /// The control tick `h` (real s).
    pub(super) tick_s: f64,
}

/// [`slacks`] of the legs of plans with holds ([`Legs`]), the pairs' indices being legs. The
/// additions to the lead bound (docs/decisions.md, "Hold points: a wait instead of a margin"):
/// - only legs of different robots pair up, and "a robot other than `p` and `c` may run"
///   counts only legs of other robots (a robot's legs never run at once);
/// - a leg `p` delayed by release rules starts at the first tick start at which they hold; at
///   the tick start before, some rule did not: robot `a` was on a leg `m ≤ l_a` with its clock
///   below the rule's threshold (`+ tol`) or that leg's end, so `c` was at most at
///   `reach_mc` below that clock (or, for `c` a leg of `a`, at that clock itself), and then
///   moves at most `M_c`;
/// - a pair `(P, C)` whose order a chain of release rules enforces ([`enforced`]) is safe
///   whatever the margins: its slack is `+∞`.
pub(super) fn slacks_of_legs(
    legs: &Legs<'_>,
    max_step_of: &[f64],
    eps: f64,
    windows: Windows,
    stop_at_first: bool,
    passes: Passes,
) -> Vec<PairSlack> {
    let robots = legs.legs;
    let robot_of = legs.robot_of;
    let n = robots.len();
    let start = |i: usize| robots[i].start_s();
    let mut order: Vec<(usize, usize)> = (0..n)
        .flat_map(|p| {
            (0..n)
                .filter(move |&c| robot_of[c] != robot_of[p])
                .map(move |c| (p, c))
        })
        .collect();
    order.sort_by(|&(p, c), &(q, d)| {
        start(p)
            .max(start(c))
            .total_cmp(&start(q).max(start(d)))
            .then((p, c).cmp(&(q, d)))
    });
    let tables: Vec<RateTable> = robots.iter().map(RateTable::new).collect();
    let fast: Vec<super::FastRates> = if legs.switch_ticks > 0 {
        robots.iter().map(super::FastRates::new).collect()
    } else {
        Vec::new()
    };
    let enforced = legs.plans.map(enforced);
    let setup = Setup {
        legs,
        order: &order,
        tables: &tables,
        fast: &fast,
        enforced: enforced.as_ref(),
        max_step_of,
        eps,
        windows,
    };
    // Robots other than p and c exist only with three or more robots; then the second pass
    // may end their running where the first pass's bounds say they are finished.
    let mut robots_seen: Vec<usize> = robot_of.to_vec();
    robots_seen.sort_unstable();
    robots_seen.dedup();
    let thirds_exist = robots_seen.len() >= 3 && passes == Passes::Both;
    let (mut out, first_leads) = pass(&setup, None, stop_at_first && !thirds_exist);
    if thirds_exist && out.iter().any(|s| s.slack_s <= 0.0) {
        // The finished-robot pass (docs/decisions.md, "Robots that have finished set no
        // pace"): every bound of the first pass is sound, so each robot's reach below its
        // end bounds the clocks at which it can still run.
        let (second, _) = pass(&setup, Some((&first_leads, &out)), stop_at_first);
        out = second;
    }
    out.sort_by(|x, y| {
        x.cur
            .start_s
            .total_cmp(&y.cur.start_s)
            .then(x.prev.start_s.total_cmp(&y.prev.start_s))
    });
    out
}

/// What both passes of [`slacks_of_legs`] share.
struct Setup<'a, 'b> {
    legs: &'a Legs<'b>,
    /// The ordered pairs, by their later start.
    order: &'a [(usize, usize)],
    tables: &'a [RateTable],
    /// Per leg, its largest fast rates over prefixes and suffixes ([`super::FastRates`]) when
    /// there is a switch time (else empty): the restricted steps of every pair read them.
    fast: &'a [super::FastRates],
    enforced: Option<&'a Enforced>,
    max_step_of: &'a [f64],
    eps: f64,
    windows: Windows,
}

/// One pass of the lead bound over every ordered pair of `setup.order`: the slacks in pair
/// order (unsorted) and the pairs' bounds (`n × n`, row `p`).
///
/// `prior`: the first pass's bounds and slacks (in the same pair order, complete). Without it
/// another robot `r` may set the pace from its start on; with it, only while `p`'s clock is at
/// most `R_rp`, the largest `p`-clock the first pass allows at a tick start with `r` below its
/// end (a robot at its end is finished, `coordinator::phase`, and sets no pace, strategy rule
/// 4); every lead read at a start is the smaller of the two passes' (both are sound), and so is
/// every slack (its larger value).
fn pass(
    setup: &Setup<'_, '_>,
    prior: Option<(&[Lead], &[PairSlack])>,
    stop_at_first: bool,
) -> (Vec<PairSlack>, Vec<Lead>) {
    let Setup {
        legs,
        order,
        tables,
        fast,
        enforced,
        max_step_of,
        eps,
        windows,
    } = *setup;
    let robots = legs.legs;
    let robot_of = legs.robot_of;
    let n = robots.len();
    let start = |i: usize| robots[i].start_s();
    let mut leads = vec![Lead::default(); n * n];
    let tol = eps / 4.0;
    let mut out = Vec::new();
    for &(p, c) in order {
        let (tau_p, tau_c) = (start(p), start(c));
        let rules = legs.plans.map_or(&[][..], |pl| pl.rules_of(p));
        let lead0_s = if tau_c > tau_p || (tau_c == tau_p && rules.is_empty()) {
            // c starts at τ_c once every running robot, p included, has reached τ_c.
            0.0
        } else {
            // p starts at τ_p in the tick in which the running robot furthest behind, m, passes
            // τ_p: at that tick's start s_m < τ_p and c is at most at reach_mc below τ_p (or
            // m = c, below τ_p), and c then moves at most M_c.
            let reach = |m: usize, u: f64| -> f64 {
                let lead = &leads[m * n + c];
                let now = if lead.is_done() {
                    lead.reach_below(u)
                } else {
                    f64::INFINITY
                };
                prior.map_or(now, |(first, _)| now.min(first[m * n + c].reach_below(u)))
            };
            let behind = (0..n)
                .filter(|&m| m != p && m != c && robot_of[m] != robot_of[c] && start(m) < tau_p)
                .filter(|&m| robots[m].end_s() > start(m).max(tau_c))
                .map(|m| reach(m, tau_p.min(robots[m].end_s())) - tau_p)
                .fold(0.0, f64::max);
            // Release rules: at the tick start before p moves, some rule did not hold.
            let plans = legs.plans;
            let delayed = rules
                .iter()
                .map(|r| {
                    let pl = plans.expect("rules come from plans");
                    let below = |m: usize| {
                        if m == r.leg {
                            (r.threshold_s + tol).min(robots[m].end_s())
                        } else {
                            robots[m].end_s()
                        }
                    };
                    (pl.first_leg[r.robot]..=r.leg)
                        .map(|m| {
                            if m == c {
                                below(m)
                            } else if robot_of[m] == robot_of[c] {
                                // Another leg of c's robot runs while a is on leg m: c has
                                // not started, so it is at most at its waiting clock, which
                                // is at most p's start.
                                tau_p
                            } else if start(m) >= tau_p {
                                f64::INFINITY
                            } else {
                                reach(m, below(m))
                            }
                        })
                        .fold(f64::NEG_INFINITY, f64::max)
                        .max(if robot_of[c] == r.robot && c > r.leg {
                            tau_p
                        } else {
                            f64::NEG_INFINITY
                        })
                        - tau_p
                })
                .fold(0.0, f64::max);
            // With a switch time the release comes `k` ticks after the tick start at which the
            // rules first held (the coordinator's count-down): c moves at most `k·M_c` more
            // before p can start. Without one nothing is added (the same float operations).
            let delayed = match switch_extra_s(legs.switch_ticks, max_step_of[c]) {
                Some(x) if !rules.is_empty() => delayed + x,
                _ => delayed,
            };
            max_step_of[c] + behind.max(delayed)
        };
        let thirds: Vec<(f64, f64)> = (0..n)
            .filter(|&r| robot_of[r] != robot_of[p] && robot_of[r] != robot_of[c])
            .map(|r| {
                // r runs only below its end, where s_p ≤ R_rp; ε covers the coordinator's
                // clock rounding (a larger `until` only lets r run longer).
                let until = prior.map_or(f64::INFINITY, |(first, _)| {
                    first[r * n + p].reach_below(robots[r].end_s()) + eps
                });
                (start(r), until)
            })
            .collect();
        let inputs = PairInputs {
            max_step_p: max_step_of[p],
            thirds: &thirds,
            u0_s: tau_p.max(tau_c),
            lead0_s,
        };
        let lead = integrate(
            (&robots[p], &tables[p]),
            (&robots[c], &tables[c]),
            inputs,
            windows,
        );
        let end_p = robots[p].end_s();
        let cur = robots[c].lc_intervals();
        let mut j = 0;
        for &prev in robots[p].lc_intervals() {
            while j < cur.len() && cur[j].start_s < prev.start_s {
                j += 1;
            }
            let Some(&c_iv) = cur.get(j) else { break };
            let u_max = (prev.end_s + eps).min(end_p);
            let is_enforced = enforced.is_some_and(|e| e.holds(p, &prev, c, &c_iv));
            let mut slack_s = match switch_extra_s(legs.switch_ticks, max_step_of[c]) {
                None if is_enforced || u_max <= lead.start_s() => f64::INFINITY,
                None => (c_iv.start_s - eps) - (lead.reach_below(u_max) + max_step_of[c]),
                // A chain of release rules orders the regions, and the coordinator releases a
                // held robot `k` ticks after the tick start at which its rules held, which is
                // after the exit tick: `k` ticks pass (docs/decisions.md, "The switch time at
                // run time (issue 41)").
                Some(_) if is_enforced => f64::INFINITY,
                // The switch time (docs/decisions.md, "The operator's switch time in the margin
                // check"): `c` stays out of `C` for `k` more ticks after `p`'s exit tick.
                Some(_) if u_max <= lead.start_s() => super::started_after_exit_slack(
                    super::SwitchRoom {
                        ticks: legs.switch_ticks,
                        step_p: max_step_of[p],
                        step_p_after: fast[p].step_within(
                            &robots[p],
                            max_step_of[p],
                            prev.ref_end..robots[p].n_ref(),
                        ),
                        step_c_before: fast[c].step_within(
                            &robots[c],
                            max_step_of[c],
                            0..c_iv.ref_start,
                        ),
                        idle_ticks: super::idle_ticks_before_start(
                            robots,
                            max_step_of,
                            c,
                            legs.tick_s,
                        ),
                    },
                    u_max,
                    (tau_c, end_p),
                    c_iv.start_s - eps,
                ),
                // `c` is at most at `y0 = reach + M_c` when the exit tick ends; the room of the
                // `k` ticks after it, `M_c + (k − 1)·M_c'` over its samples from `y0` to `C`
                // (`switch_room_after_s`), at most `x = k·M_c`.
                Some(x) => {
                    let y0 = lead.reach_below(u_max) + max_step_of[c];
                    let rest = fast[c].step_within(
                        &robots[c],
                        max_step_of[c],
                        robots[c].sample_at(y0)..c_iv.ref_start,
                    );
                    let room =
                        super::switch_room_after_s(legs.switch_ticks, max_step_of[c], rest).min(x);
                    (c_iv.start_s - eps) - (y0 + room)
                }
            };
            if let Some((_, first)) = prior {
                // The same pair in the same place of the same order.
                slack_s = slack_s.max(first[out.len()].slack_s);
            }
            out.push(PairSlack {
                prev_robot: p,
                cur_robot: c,
                prev,
                cur: c_iv,
                slack_s,
            });
            if stop_at_first && slack_s <= 0.0 {
                return (out, leads);
            }
        }
        leads[p * n + c] = lead;
    }
    (out, leads)
}

/// The switch time's room `k·M_c` (schedule-clock s), `None` without a switch time.
fn switch_extra_s(switch_ticks: u64, max_step_c: f64) -> Option<f64> {
    (switch_ticks > 0).then_some(switch_ticks as f64 * max_step_c)
}

/// The pairs of low-confidence regions whose order the release rules enforce: `(P, C)` when
/// robot `c` can traverse `C` only after robot `p` has left `P`, at every tick start from the
/// first at which `C` can be traversed (docs/decisions.md, "Hold points: a wait instead of a
/// margin").
///
/// A region `C` of leg `l` is gated by every rule of its robot's legs up to `l` (the robot has
/// left each of those holds before it moves on leg `l`); a rule "robot `a` has passed
/// `threshold` on leg `l_a`" puts every region of `a` that ends at or before it (on `l_a` or an
/// earlier leg) before `C`, and with them everything before those; so does every earlier region
/// of `C`'s own robot (the robot traversed it before `C`, so what had to be left before that
/// had been left then). Clocks never decrease, so each of these holds at every later tick.
pub(super) struct Enforced {
    /// Per leg, the index of its first region in the flat list of regions (and the total at
    /// the end).
    first: Vec<usize>,
    /// Per region, the set of regions left before it can be entered (bit set, `words` words
    /// per region).
    before: Vec<u64>,
    words: usize,
    /// Per leg, the start clocks of its regions (to find a region's index).
    starts: Vec<Vec<f64>>,
}

impl Enforced {
    /// Whether region `prev` of leg `p` is left before region `cur` of leg `c` is entered.
    fn holds(&self, p: usize, prev: &crate::LcInterval, c: usize, cur: &crate::LcInterval) -> bool {
        let (Some(i), Some(j)) = (self.index(p, prev), self.index(c, cur)) else {
            return false;
        };
        self.bit(j, i)
    }

    fn index(&self, leg: usize, iv: &crate::LcInterval) -> Option<usize> {
        let k = self.starts[leg].iter().position(|&x| x == iv.start_s)?;
        Some(self.first[leg] + k)
    }

    fn bit(&self, j: usize, i: usize) -> bool {
        self.before[j * self.words + i / 64] >> (i % 64) & 1 == 1
    }
}

/// The regions [`Enforced`] knows, for `plans`: a fixed point of the rules of its docs
/// (each pass only adds; at most one pass per region).
pub(super) fn enforced(plans: &Plans) -> Enforced {
    let n_legs = plans.legs.len();
    let mut first = Vec::with_capacity(n_legs + 1);
    let mut starts = Vec::with_capacity(n_legs);
    let mut region_leg = Vec::new();
    for (l, leg) in plans.legs.iter().enumerate() {
        first.push(region_leg.len());
        starts.push(
            leg.lc_intervals()
                .iter()
                .map(|iv| iv.start_s)
                .collect::<Vec<_>>(),
        );
        region_leg.extend(std::iter::repeat_n(l, leg.lc_intervals().len()));
    }
    first.push(region_leg.len());
    let n = region_leg.len();
    let words = n.div_ceil(64).max(1);
    let mut before = vec![0_u64; n * words];
    // The direct predecessors of each region: what its gating rules name and its robot's
    // earlier regions.
    let mut direct: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (j, &l) in region_leg.iter().enumerate() {
        let robot = plans.robot_of[l];
        direct[j].extend(first[plans.first_leg[robot]]..j);
        for gate in plans.first_leg[robot]..=l {
            for r in plans.rules_of(gate) {
                let legs_of_a = plans.first_leg[r.robot]..=r.leg;
                for (m, (leg, &first_m)) in legs_of_a.clone().zip(
                    plans.legs[legs_of_a]
                        .iter()
                        .zip(&first[plans.first_leg[r.robot]..]),
                ) {
                    for (k, iv) in leg.lc_intervals().iter().enumerate() {
                        if m < r.leg || iv.end_s <= r.threshold_s {
                            direct[j].push(first_m + k);
                        }
                    }
                }
            }
        }
    }
    let mut changed = true;
    while changed {
        changed = false;
        for j in 0..n {
            for &i in &direct[j] {
                // before(j) ∪= {i} ∪ before(i)
                let mut add = vec![0_u64; words];
                add[i / 64] |= 1 << (i % 64);
                for w in 0..words {
                    add[w] |= before[i * words + w];
                }
                for (w, a) in add.into_iter().enumerate() {
                    let cell = &mut before[j * words + w];
                    if *cell | a != *cell {
                        *cell |= a;
                        changed = true;
                    }
                }
            }
        }
    }
    Enforced {
        first,
        before,
        words,
        starts,
    }
}
