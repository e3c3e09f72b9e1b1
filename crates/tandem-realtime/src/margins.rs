//! Worst-case margins between low-confidence regions (Alg. 2, §II-B5).
//!
//! # Pairs and roles
//! The low-confidence (LC) regions of both robots are taken as exact schedule-clock intervals
//! `[c_{n0}, c_{n1+1})` (see [`Timeline::lc_intervals`]) and merged by start time. Every two
//! consecutive regions of *different* robots form a pair: the earlier region's robot is the
//! previous robot `p`, whose region ends at `T_p`; the later one is the current robot `c`, whose
//! region starts at `T_c`. The pair is safe when `c` can never enter its region before `p` has
//! left its own. (Non-consecutive regions are implied: robot clocks only move forward.)
//!
//! # The printed check
//! [`sufficient_margins_printed`] is Alg. 2 as printed (typos fixed as in docs/decisions.md,
//! "Typos of Eq. 17 and Alg. 1": the rates of Eq. 17 are `F = ψ̇_E/ψ̇min`, `S = ψ̇_E/ψ̇max`, and
//! Alg. 1 line 9 uses the behind robot's own `F`): for each pair, both schedule clocks start at `τ` (the later start); each step, if `c` is
//! LC it rushes (`F`) and `p` responds (Eq. 18), else if `p` is LC it drags (`S`) and `c`
//! responds, else `HIGH-CONF`; after the step, reject if `t_c ≥ T_c`, accept if `t_p ≥ T_p`.
//! **It is not sound on a tick grid** (docs/decisions.md, "Alg. 2 as printed is not sound on a
//! tick grid"; the 3-sample case [HC, LC, HC] with gradients 1, bounds `[½, 2]`, one sample per
//! tick and `τ = 3/2` is accepted yet overlaps when the operator rushes the previous robot). It
//! is kept only as a named, documented-unsafe baseline.
//!
//! # The conservative check
//! [`sufficient_margins`] keeps the paper's worst case (current robot rushing while LC,
//! previous robot dragging while LC, the strategy everywhere else) and makes the discrete
//! simulation conservative against the three ways a tick grid breaks it (docs/decisions.md):
//! the exit tick, rate aliasing and mode aliasing. With `M = tick_s · max(1, max F)` the
//! largest step any robot can take in one tick (maximum over *both* robots and *all* samples,
//! a superset of the local maxima the design-time fix used) and `ε` four times
//! [`clock_tolerance_s`]:
//!
//! 1. **Stop test, `c` first.** After each step, reject if `t_c + M ≥ T_c − ε`, else accept the
//!    pair if `t_p ≥ T_p + ε`. The real robots' tick phase is set by the operator, not by the
//!    check, and `p` is LC for the *whole* tick in which it leaves its region while `c` may move
//!    a full step in that tick: requiring `c` to be a full step short of `T_c` at the first
//!    simulated clock where `p` is out covers the exit tick whatever its phase.
//! 2. **Conservative rates.** At each clock, `c` uses the largest `F` and `S`, and `p` the
//!    smallest, over all samples whose interval meets `[t − M − ε, t + M + ε]`: a real tick may
//!    read its rates up to one step away from the simulated clock (rate aliasing); larger rates
//!    for `c` and smaller for `p` only move the simulated `c` further ahead.
//! 3. **Widened LC regions.** A robot counts as LC in the simulation when any LC sample meets
//!    the same window (mode aliasing: the real coordinator reads modes at the tick start, up to
//!    a step away). Where both robots then count as LC, both branches (`c` rushing with `p`
//!    responding, `p` dragging with `c` responding) are simulated and the one leaving `c`
//!    further ahead (larger `t_c − t_p`) is kept.
//! 4. **Pairs decided before the later robot starts.** The coordinator starts the later robot at
//!    a tick boundary once the earlier robot's clock reaches `τ`, so a pair whose previous region
//!    ends at `T_p ≤ τ − ε` (or at the previous robot's end, `≤ τ`) can never overlap and is
//!    accepted without simulation (the printed loop steps once before testing and needlessly
//!    rejects such pairs). Conversely the earlier robot may be up to one step ahead when the
//!    later one starts, so when `c` is the earlier robot its simulated clock starts at `τ + M`.
//!
//! Any other pair whose regions already overlap on schedule (`T_c < T_p + ε`) is rejected outright.
//!
//! In continuous time the extreme policy bounds every admissible operator; the fixes above only
//! widen the discrete check by at most one maximal step in clock, rate and mode. This is a
//! conservative construction validated by search (the property test `tests/safety.rs`: random
//! problems, schedules, tick lengths and random/extreme/switching operators, no accepted schedule
//! ever has both robots LC in one tick), not a machine-checked proof.
//!
//! # Single pass
//! The simulated dynamics do not depend on `T_p` or `T_c` (only the stop test does), and the
//! pairs of one role `(p, c)` are ordered in both `T_p` and `T_c`. So one simulation per role,
//! with a pointer over that role's pairs (test the current pair after each step; when it is
//! accepted, test the next one at the same state), decides every pair exactly as a fresh
//! simulation per pair would: at every earlier state the earlier pair was undecided, so
//! `t_c + M < T_c ≤ T_c'` and `t_p < T_p ≤ T_p'`, and the later pair was undecided too.
//! [`sufficient_margins_per_pair`] is that per-pair loop (a benchmark baseline).
//!
//! # Slacks
//! [`pair_slacks`] runs the same two simulations to the end of each role instead of stopping at
//! the first rejection and reports, per pair, rule 1's room left when `p` is out:
//! `(T_c − ε) − (t_c + M)` at the deciding step (`t_c` only grows, so that is the smallest room
//! of the pair's whole stretch). The check accepts exactly when every slack is positive; a
//! scheduler reads from the slacks how much clearance each pair lacks or has to spare, with
//! the check itself as the only owner of the worst case.

use std::collections::VecDeque;

use crate::error::{Error, Result};
use crate::strategy::{high_conf_steps, response_step};
use crate::timeline::{LcInterval, Rates, Timeline};
use crate::tol::clock_tolerance_s;

/// Upper bound on simulated ticks per role; a `tick_s` needing more is rejected as invalid.
const MAX_SIM_TICKS: f64 = 1e8;

/// A pair of consecutive LC regions of different robots: the previous robot's region `prev`
/// (it leaves it at `T_p = prev.end_s`) and the current robot's `cur` (it enters it at
/// `T_c = cur.start_s`), schedule clock.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Pair {
    prev: LcInterval,
    cur: LcInterval,
}

impl Pair {
    /// `T_p` (s): where the previous robot leaves its region.
    fn t_p_end(&self) -> f64 {
        self.prev.end_s
    }

    /// `T_c` (s): where the current robot enters its region.
    fn t_c_start(&self) -> f64 {
        self.cur.start_s
    }
}

/// Shared set-up of the three checks.
struct Setup {
    /// `τ`: the later start (s).
    tau: f64,
    /// Index of the robot that starts first (robot 0 on a tie).
    first: usize,
    /// `M`: largest step of any robot in one tick (schedule-clock s).
    max_step: f64,
    /// Comparison tolerance of the checks (schedule-clock s).
    eps: f64,
    /// Pairs per role, indexed by the previous robot `p` (so `c = 1 − p`).
    pairs: [Vec<Pair>; 2],
}

impl Setup {
    fn new(robots: &[Timeline; 2], tick_s: f64) -> Result<Setup> {
        if !(tick_s.is_finite() && tick_s > 0.0) {
            return Err(Error::BadParam {
                name: "tick_s",
                why: "must be finite and > 0",
            });
        }
        let first = usize::from(robots[1].start_s() < robots[0].start_s());
        let tau = robots[1 - first].start_s();
        let max_rate = robots[0].max_rate_fast().max(robots[1].max_rate_fast());
        let min_slow = robots[0].min_rate_slow().min(robots[1].min_rate_slow());
        let horizon = robots[0].end_s().max(robots[1].end_s()) - tau;
        if horizon / (min_slow * tick_s) > MAX_SIM_TICKS {
            return Err(Error::BadParam {
                name: "tick_s",
                why: "too small: the margin simulation would need more than 1e8 ticks",
            });
        }
        let mut regions: Vec<(LcInterval, usize)> = Vec::new();
        for (i, r) in robots.iter().enumerate() {
            regions.extend(r.lc_intervals().iter().map(|&iv| (iv, i)));
        }
        regions.sort_by(|x, y| x.0.start_s.total_cmp(&y.0.start_s).then(x.1.cmp(&y.1)));
        let mut pairs: [Vec<Pair>; 2] = [Vec::new(), Vec::new()];
        for w in regions.windows(2) {
            let ((prev, p), (cur, c)) = (w[0], w[1]);
            if p != c {
                pairs[p].push(Pair { prev, cur });
            }
        }
        Ok(Setup {
            tau,
            first,
            max_step: tick_s * max_rate,
            eps: 4.0 * clock_tolerance_s(robots, tick_s),
            pairs,
        })
    }

    /// Fix 4, then the on-schedule overlap test, for pairs that need no simulation:
    /// `Some(decision)` or `None` (simulate). Fix 4 comes first: in the serial schedule the
    /// previous robot may end in an LC sample exactly where the later robot starts in one.
    fn prefilter(&self, robots: &[Timeline; 2], p: usize, pair: Pair) -> Option<bool> {
        let end_p = robots[p].end_s();
        if p == self.first
            && (pair.t_p_end() + self.eps <= self.tau
                || (pair.t_p_end() >= end_p && end_p <= self.tau))
        {
            return Some(true);
        }
        if pair.t_c_start() < pair.t_p_end() + self.eps {
            return Some(false);
        }
        None
    }

    /// Initial simulated clocks `(t_p, t_c)` of role `(p, c)`.
    fn initial(&self, robots: &[Timeline; 2], c: usize) -> (f64, f64) {
        let lead = if c == self.first && robots[c].start_s() < self.tau {
            self.max_step
        } else {
            0.0
        };
        (self.tau, self.tau + lead)
    }
}

/// Sliding extreme (max or min) over index windows whose ends never decrease.
#[derive(Default)]
struct Sliding {
    dq: VecDeque<usize>,
    next: usize,
}

impl Sliding {
    fn query(&mut self, lo: usize, hi: usize, val: impl Fn(usize) -> f64, max: bool) -> f64 {
        while self.next <= hi {
            let v = val(self.next);
            while let Some(&b) = self.dq.back() {
                let vb = val(b);
                if (max && vb <= v) || (!max && vb >= v) {
                    self.dq.pop_back();
                } else {
                    break;
                }
            }
            self.dq.push_back(self.next);
            self.next += 1;
        }
        while self.dq.front().is_some_and(|&f| f < lo) {
            self.dq.pop_front();
        }
        self.dq.front().map_or(1.0, |&f| val(f))
    }
}

/// One robot's view in a simulation: either the exact point look-up of the printed check or
/// the conservative window look-up (fixes 2 and 3).
struct Side<'a> {
    tl: &'a Timeline,
    /// `true` for `c` (largest rates), `false` for `p` (smallest rates).
    maximize: bool,
    lo: usize,
    hi: usize,
    fast: Sliding,
    slow: Sliding,
}

impl<'a> Side<'a> {
    fn new(tl: &'a Timeline, maximize: bool) -> Self {
        Side {
            tl,
            maximize,
            lo: 0,
            hi: 0,
            fast: Sliding::default(),
            slow: Sliding::default(),
        }
    }

    /// Conservative mode and rates over the window `[t − w, t + w]` (`t` never decreases).
    fn window(&mut self, t: f64, w: f64) -> (bool, Rates) {
        let tl = self.tl;
        let lo = tl.advance_cursor(&mut self.lo, t - w);
        let hi = tl.advance_cursor(&mut self.hi, t + w);
        let lc = tl.any_low_conf(lo, hi);
        let fast = self.fast.query(lo, hi, |n| tl.rate_fast(n), self.maximize);
        let slow = self.slow.query(lo, hi, |n| tl.rate_slow(n), self.maximize);
        (lc, Rates { fast, slow })
    }

    /// Printed check: mode (Eq. 16, not running = high confidence) and rates at the point `t`.
    fn point(&mut self, t: f64) -> (bool, Rates) {
        let tl = self.tl;
        let n = tl.advance_cursor(&mut self.hi, t);
        let running = t >= tl.start_s() && t < tl.end_s();
        (running && !tl.conf()[n], tl.rates(n))
    }
}

/// Which variant of Alg. 2 a simulation runs.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Variant {
    Printed,
    Conservative,
}

/// The worst-case simulation of one role `(p, c)`.
struct RoleSim<'a> {
    variant: Variant,
    p: Side<'a>,
    c: Side<'a>,
    t_p: f64,
    t_c: f64,
    tick_s: f64,
    window_s: f64,
}

impl<'a> RoleSim<'a> {
    fn new(
        variant: Variant,
        robots: &'a [Timeline; 2],
        setup: &Setup,
        p: usize,
        tick_s: f64,
    ) -> Self {
        let c = 1 - p;
        let (t_p, t_c) = match variant {
            Variant::Printed => (setup.tau, setup.tau),
            Variant::Conservative => setup.initial(robots, c),
        };
        RoleSim {
            variant,
            p: Side::new(&robots[p], false),
            c: Side::new(&robots[c], true),
            t_p,
            t_c,
            tick_s,
            window_s: setup.max_step + setup.eps,
        }
    }

    /// `c` rushes (`F`), `p` responds with Eq. 18: new `(t_p, t_c)`.
    fn c_rushing(&self, rp: Rates, rc: Rates) -> (f64, f64) {
        let t_c = self.t_c + rc.fast * self.tick_s;
        (
            self.t_p + response_step(self.t_p - t_c, rp, self.tick_s),
            t_c,
        )
    }

    /// `p` drags (`S`), `c` responds with Eq. 18: new `(t_p, t_c)`.
    fn p_dragging(&self, rp: Rates, rc: Rates) -> (f64, f64) {
        let t_p = self.t_p + rp.slow * self.tick_s;
        (
            t_p,
            self.t_c + response_step(self.t_c - t_p, rc, self.tick_s),
        )
    }

    fn step(&mut self) {
        let ((lc_p, rp), (lc_c, rc)) = match self.variant {
            Variant::Printed => (self.p.point(self.t_p), self.c.point(self.t_c)),
            Variant::Conservative => (
                self.p.window(self.t_p, self.window_s),
                self.c.window(self.t_c, self.window_s),
            ),
        };
        let (t_p, t_c) = match (lc_p, lc_c) {
            (true, true) if self.variant == Variant::Conservative => {
                let rush = self.c_rushing(rp, rc);
                let drag = self.p_dragging(rp, rc);
                if drag.1 - drag.0 > rush.1 - rush.0 {
                    drag
                } else {
                    rush
                }
            }
            (_, true) => self.c_rushing(rp, rc),
            (true, false) => self.p_dragging(rp, rc),
            (false, false) => {
                let h = self.tick_s;
                if self.t_c - self.t_p > 0.0 {
                    let (dc, dp) = high_conf_steps(self.t_c - self.t_p, rc, rp, h);
                    (self.t_p + dp, self.t_c + dc)
                } else {
                    let (dp, dc) = high_conf_steps(self.t_p - self.t_c, rp, rc, h);
                    (self.t_p + dp, self.t_c + dc)
                }
            }
        };
        self.t_p = t_p;
        self.t_c = t_c;
    }

    /// Stop test of one pair after a step: `Some(false)` reject, `Some(true)` accept, `None`
    /// undecided.
    fn test(&self, pair: Pair, setup: &Setup) -> Option<bool> {
        match self.variant {
            Variant::Printed => {
                if self.t_c >= pair.t_c_start() {
                    Some(false)
                } else if self.t_p >= pair.t_p_end() {
                    Some(true)
                } else {
                    None
                }
            }
            Variant::Conservative => {
                if self.slack(pair, setup) <= 0.0 {
                    Some(false)
                } else if self.p_is_out(pair, setup) {
                    Some(true)
                } else {
                    None
                }
            }
        }
    }

    /// Rule 1's room left for `c` (conservative check): `(T_c − ε) − (t_c + M)`, schedule-clock
    /// s; `c` is a full step short of its region while this is > 0.
    fn slack(&self, pair: Pair, setup: &Setup) -> f64 {
        (pair.t_c_start() - setup.eps) - (self.t_c + setup.max_step)
    }

    /// Rule 1's acceptance (conservative check): `p` has left its region, `t_p ≥ T_p + ε`.
    fn p_is_out(&self, pair: Pair, setup: &Setup) -> bool {
        self.t_p >= pair.t_p_end() + setup.eps
    }
}

/// Simulation budget: every step moves `t_p` by at least `S_min·tick_s > 0`.
fn step_budget(robots: &[Timeline; 2], setup: &Setup, tick_s: f64) -> u64 {
    let min_slow = robots[0].min_rate_slow().min(robots[1].min_rate_slow());
    let horizon = robots[0].end_s().max(robots[1].end_s()) + setup.max_step - setup.tau;
    // Bounded by MAX_SIM_TICKS (checked in Setup::new), so the cast cannot overflow.
    (horizon / (min_slow * tick_s)).ceil().max(0.0) as u64 + 4
}

/// Runs one role's simulation over `pairs` (already ordered) with a pointer; `false` as soon as
/// one pair is rejected.
fn run_role(
    variant: Variant,
    robots: &[Timeline; 2],
    setup: &Setup,
    p: usize,
    pairs: &[Pair],
    tick_s: f64,
) -> bool {
    if pairs.is_empty() {
        return true;
    }
    let budget = step_budget(robots, setup, tick_s);
    let mut sim = RoleSim::new(variant, robots, setup, p, tick_s);
    let mut k = 0;
    for _ in 0..budget {
        sim.step();
        while k < pairs.len() {
            match sim.test(pairs[k], setup) {
                Some(false) => return false,
                Some(true) => k += 1,
                None => break,
            }
        }
        if k == pairs.len() {
            return true;
        }
    }
    // Unreachable for valid timelines (the budget covers p reaching its end); reject to stay safe.
    false
}

/// The conservative, discretization-safe worst-case margin check (Alg. 2 with the fixes 1–4
/// of the module docs and docs/decisions.md, single pass): `true` when no admissible operator
/// can make both robots
/// low-confidence in the same control tick of `tick_s` real seconds.
///
/// Two simulations (one per role `(p, c)`), each deciding all pairs of its role with a pointer;
/// see the [module docs](self) for the argument. Cost O(T_ref · steps per sample).
///
/// # Errors
/// [`Error::BadParam`] for `tick_s` not finite and > 0, or so small that a simulation would need
/// more than 1e8 ticks.
pub fn sufficient_margins(robots: &[Timeline; 2], tick_s: f64) -> Result<bool> {
    let setup = Setup::new(robots, tick_s)?;
    for p in 0..2 {
        let mut sim_pairs = Vec::with_capacity(setup.pairs[p].len());
        for &pair in &setup.pairs[p] {
            match setup.prefilter(robots, p, pair) {
                Some(false) => return Ok(false),
                Some(true) => {}
                None => sim_pairs.push(pair),
            }
        }
        if !run_role(Variant::Conservative, robots, &setup, p, &sim_pairs, tick_s) {
            return Ok(false);
        }
    }
    Ok(true)
}

/// One pair of consecutive LC regions of different robots with its worst-case room, from the
/// simulation of [`sufficient_margins`] (see [`pair_slacks`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairSlack {
    /// The previous robot `p` (0 = the first robot, 1 = the second); the current robot `c` is
    /// the other one.
    pub prev_robot: usize,
    /// `p`'s region (schedule clock); `p` leaves it at `T_p = prev.end_s`.
    pub prev: LcInterval,
    /// `c`'s region (schedule clock); `c` enters it at `T_c = cur.start_s`.
    pub cur: LcInterval,
    /// Schedule-clock s, `> 0` exactly when [`sufficient_margins`] accepts the pair: how much
    /// earlier `c`'s region could start before rule 1 rejects it on the same worst-case
    /// trajectory, `(T_c − ε) − (t_c + M)` at the first simulated step with `t_p ≥ T_p + ε`
    /// (`t_c` is then the furthest the worst case has pushed `c`); its negative is the clearance
    /// missing. `+∞` for a pair accepted without simulation (rule 4); for a pair whose regions
    /// already overlap on schedule, the smaller of that and `T_c − (T_p + ε) < 0`; `−∞` if the
    /// simulation budget ran out first.
    pub slack_s: f64,
}

/// Every pair's worst-case slack ([`PairSlack`]), in the order of the current regions' starts,
/// from the same two simulations as [`sufficient_margins`] (one per role, run until every pair
/// of the role is decided): `sufficient_margins(robots, tick_s)` is `true` exactly when every
/// `slack_s > 0`. A scheduler uses it to see how much clearance each pair lacks or has to spare.
///
/// # Errors
/// As [`sufficient_margins`].
pub fn pair_slacks(robots: &[Timeline; 2], tick_s: f64) -> Result<Vec<PairSlack>> {
    let setup = Setup::new(robots, tick_s)?;
    let mut out = Vec::with_capacity(setup.pairs[0].len() + setup.pairs[1].len());
    for (p, pairs) in setup.pairs.iter().enumerate() {
        let mut slack = vec![f64::NEG_INFINITY; pairs.len()];
        if !pairs.is_empty() {
            let mut sim = RoleSim::new(Variant::Conservative, robots, &setup, p, tick_s);
            let mut k = 0;
            for _ in 0..step_budget(robots, &setup, tick_s) {
                sim.step();
                while k < pairs.len() && sim.p_is_out(pairs[k], &setup) {
                    slack[k] = sim.slack(pairs[k], &setup);
                    k += 1;
                }
                if k == pairs.len() {
                    break;
                }
            }
        }
        for (&pair, s) in pairs.iter().zip(slack) {
            let slack_s = match setup.prefilter(robots, p, pair) {
                Some(true) => f64::INFINITY,
                Some(false) => s.min(pair.t_c_start() - (pair.t_p_end() + setup.eps)),
                None => s,
            };
            out.push(PairSlack {
                prev_robot: p,
                prev: pair.prev,
                cur: pair.cur,
                slack_s,
            });
        }
    }
    out.sort_by(|x, y| x.cur.start_s.total_cmp(&y.cur.start_s));
    Ok(out)
}

/// The same conservative check as [`sufficient_margins`], written as the straightforward loop:
/// one fresh worst-case simulation per pair. Identical decisions, O(pairs) times the cost; kept
/// as a benchmark baseline and as an oracle for the single pass.
///
/// # Errors
/// As [`sufficient_margins`].
pub fn sufficient_margins_per_pair(robots: &[Timeline; 2], tick_s: f64) -> Result<bool> {
    let setup = Setup::new(robots, tick_s)?;
    for p in 0..2 {
        for &pair in &setup.pairs[p] {
            let ok = match setup.prefilter(robots, p, pair) {
                Some(d) => d,
                None => run_role(Variant::Conservative, robots, &setup, p, &[pair], tick_s),
            };
            if !ok {
                return Ok(false);
            }
        }
    }
    Ok(true)
}

/// Alg. 2 exactly as printed (with the typo fixes of docs/decisions.md, "Typos of Eq. 17 and
/// Alg. 1"), one simulation per pair from `τ`.
///
/// **UNSAFE on a tick grid**: it can accept schedules on which an admissible operator makes both
/// robots low-confidence in the same tick (see the [module docs](self)). Use only as a baseline.
///
/// # Errors
/// As [`sufficient_margins`].
pub fn sufficient_margins_printed(robots: &[Timeline; 2], tick_s: f64) -> Result<bool> {
    let setup = Setup::new(robots, tick_s)?;
    for p in 0..2 {
        for &pair in &setup.pairs[p] {
            if !run_role(Variant::Printed, robots, &setup, p, &[pair], tick_s) {
                return Ok(false);
            }
        }
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 3-sample case of docs/decisions.md: [HC, LC, HC], gradients 1, bounds [½, 2],
    /// Δt_s = 1.
    fn three_sample(tau: f64) -> [Timeline; 2] {
        let conf = [true, false, true];
        let g = [1.0; 3];
        let lo = [0.5; 3];
        let hi = [2.0; 3];
        [
            Timeline::new(&conf, &g, &lo, &hi, 0.0, 1.0).unwrap(),
            Timeline::new(&conf, &g, &lo, &hi, tau, 1.0).unwrap(),
        ]
    }

    #[test]
    fn pairs_of_three_sample_case() {
        let r = three_sample(1.5);
        let s = Setup::new(&r, 1.0).unwrap();
        assert_eq!(s.tau, 1.5);
        assert_eq!(s.first, 0);
        assert_eq!(s.max_step, 2.0);
        let iv = |start_s, end_s| LcInterval {
            ref_start: 1,
            ref_end: 2,
            start_s,
            end_s,
        };
        assert_eq!(
            s.pairs[0],
            vec![Pair {
                prev: iv(1.0, 2.0),
                cur: iv(2.5, 3.5)
            }]
        );
        assert_eq!(
            (s.pairs[0][0].t_p_end(), s.pairs[0][0].t_c_start()),
            (2.0, 2.5)
        );
        assert!(s.pairs[1].is_empty());
    }

    #[test]
    fn printed_accepts_conservative_rejects_three_sample_case() {
        let r = three_sample(1.5);
        // Printed: t = 1.5; p LC drags 0.5 → 2.0, c responds to a lag of 0.5 → 2.0;
        // t_c = 2.0 < 2.5 and t_p = 2.0 ≥ 2.0 → accepted.
        assert!(sufficient_margins_printed(&r, 1.0).unwrap());
        // Conservative: after the first step t_c ≥ 1.5 + 0.5 and 2.0 + M(2) ≥ 2.5 → rejected.
        assert!(!sufficient_margins(&r, 1.0).unwrap());
        assert!(!sufficient_margins_per_pair(&r, 1.0).unwrap());
    }

    #[test]
    fn slack_of_three_sample_case_by_hand() {
        // τ = 1.5, tick 1, M = 2: at the first step both robots count as LC (widened windows);
        // c rushing (t_c = 3.5, p follows to 3.5) and p dragging (both to 2.0) leave c level,
        // so the tie keeps the rush. p is then out (3.5 ≥ T_p = 2): slack = 2.5 − (3.5 + 2) = −3
        // (less ε).
        let s = pair_slacks(&three_sample(1.5), 1.0).unwrap();
        assert_eq!(s.len(), 1);
        assert_eq!(
            (s[0].prev_robot, s[0].prev.end_s, s[0].cur.start_s),
            (0, 2.0, 2.5)
        );
        assert!(
            s[0].slack_s < -3.0 && s[0].slack_s > -3.0 - 1e-6,
            "{}",
            s[0].slack_s
        );
        // Serial: rule 4 accepts the pair without simulating it.
        let s = pair_slacks(&three_sample(3.0), 1.0).unwrap();
        assert_eq!(s[0].slack_s, f64::INFINITY);
        assert!(pair_slacks(&three_sample(1.5), 0.0).is_err());
    }

    #[test]
    fn serial_schedule_is_accepted() {
        // τ = |ψ_E1| = 3: the previous region ends before robot 2 starts (fix 4).
        let r = three_sample(3.0);
        assert!(sufficient_margins(&r, 1.0).unwrap());
        assert!(sufficient_margins_per_pair(&r, 1.0).unwrap());
    }

    #[test]
    fn bad_tick_is_an_error() {
        let r = three_sample(1.5);
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e-12] {
            assert!(matches!(
                sufficient_margins(&r, t),
                Err(Error::BadParam { name: "tick_s", .. })
            ));
            assert!(sufficient_margins_printed(&r, t).is_err());
            assert!(sufficient_margins_per_pair(&r, t).is_err());
        }
    }

    #[test]
    fn sliding_extremes_match_brute_force() {
        let v = [3.0, 1.0, 4.0, 1.0, 5.0, 9.0, 2.0, 6.0];
        let mut mx = Sliding::default();
        let mut mn = Sliding::default();
        for (lo, hi) in [(0, 0), (0, 2), (1, 3), (1, 5), (4, 5), (5, 7), (7, 7)] {
            let bmax = v[lo..=hi].iter().copied().fold(f64::MIN, f64::max);
            let bmin = v[lo..=hi].iter().copied().fold(f64::MAX, f64::min);
            assert_eq!(mx.query(lo, hi, |n| v[n], true), bmax);
            assert_eq!(mn.query(lo, hi, |n| v[n], false), bmin);
        }
    }
}
