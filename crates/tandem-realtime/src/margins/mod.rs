//! Worst-case margins between low-confidence regions (Alg. 2, §II-B5), for `1 ≤ N ≤ MAX_ROBOTS`
//! robots: [`sufficient_margins`] is `true` only when no admissible operator can make two robots
//! low-confidence (LC) in the same control tick.
//!
//! Two robots are checked by a worst-case *simulation* (Alg. 2 with fixes 1–4, below); three or
//! more by a *lead bound* integrated along each robot's progress (section "Three or more robots:
//! the lead bound"). The simulation's extension to `N ≥ 3` robots (fixes 5–6) was found to accept
//! schedules that overlap and is kept only as the named baseline [`baseline::greedy_pace`].
//!
//! Notation: `h` = `tick_s`; robot `i`'s schedule clock `s_i` (s); at its current sample the
//! Eq. 17 rates `S_i = ψ̇_E/ψ̇max ≤ 1 ≤ F_i = ψ̇_E/ψ̇min`; `M_i = h · max(1, max_n F_i)` the
//! largest step robot `i` can take in one tick (over *all* its samples); `ε` four times
//! [`clock_tolerance_s`]. An LC region of robot `i` is the exact
//! schedule-clock interval of a maximal LC run, `[c_{n0}, c_{n1+1})` (see
//! [`Timeline::lc_intervals`]); `p` leaves its region `P` at `T_p`, `c` enters its region `C` at
//! `T_c`.
//!
//! # The first overlap
//! Everything below looks at the *first* tick in which two robots are LC. Before it, at most one
//! robot is LC at every tick start: a running robot moves every tick (at least `S·h > 0`), so a
//! robot whose clock is in an LC sample at a tick start traverses that sample and is LC in that
//! tick. So every tick before the first overlap follows the coordinator's single-pace rules
//! (`strategy`, rules 1–4), and it suffices to show that no tick start reachable under those
//! rules lets two robots traverse LC samples in the next tick.
//!
//! # Two robots: the worst-case simulation (fixes 1–4)
//! The regions of both robots are merged by start time; every two consecutive regions of
//! different robots form a pair `(p, c)`, safe when `c` can never enter its region before `p`
//! has left its own. Non-consecutive pairs are implied: if every consecutive pair is safe and `A`
//! before `B` overlap first, the region `X` right after `A` cannot start before `A` ends (its
//! pair, or the same robot's order), and by induction along the merged order neither can `B`.
//!
//! Alg. 2 as printed ([`baseline::printed`]) simulates from the later start `τ`, each step: if
//! `c` is LC it rushes (`F`) and `p` responds (Eq. 18), else if `p` is LC it drags (`S`) and `c`
//! responds, else `HIGH-CONF`; after the step it rejects if `t_c ≥ T_c` and accepts if
//! `t_p ≥ T_p`. **It is not sound on a tick grid** (the 3-sample case [HC, LC, HC] with gradients
//! 1, bounds `[½, 2]`, one sample per tick and `τ = 3/2` is accepted yet overlaps when the
//! operator rushes the previous robot; tests/regression.rs). The conservative check keeps the
//! paper's worst case and widens the discrete simulation against the three ways a tick grid
//! breaks it — the exit tick, rate aliasing and mode aliasing (`M` = the larger step of the two
//! robots):
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
//!    a step away). Where both robots then count as LC, both branches (`c` rushing, `p`
//!    dragging) are simulated and the one leaving `c` furthest ahead (larger `t_c − t_p`, the
//!    first on a tie) is kept.
//! 4. **Pairs decided before the later robot starts.** A robot starts at a tick boundary once
//!    the running robot has reached its start `τ`, so when the later of `p` and `c` starts, `p`
//!    has reached `τ`: a pair whose previous region ends at `T_p ≤ t_p − ε` (or at `p`'s end,
//!    `≤ t_p`) can never overlap and is accepted without simulation (the printed loop steps once
//!    before testing and needlessly rejects such pairs). Conversely the earlier robot may be up
//!    to one step ahead when the later one starts, so when `c` is the earlier robot its clock
//!    starts a full step `M` ahead. Any other pair whose regions already overlap on schedule
//!    (`T_c < T_p + ε`) is rejected outright.
//!
//! In continuous time the extreme policy bounds every admissible operator; fixes 1–4 only widen
//! the discrete check by at most one maximal step in clock, rate and mode. Branches of fix 3 are
//! chosen per tick, but they exist only where both robots are within one maximal step of LC
//! samples, and there the stop test already demands a full step of room; the search adversary
//! ([`adversary::Adversary::Beam`](crate::adversary::Adversary::Beam)), the property tests
//! `tests/safety.rs` and `tests/safety_n.rs` and `cargo xtask stress` find no overlap
//! (docs/decisions.md, "The N-robot margin check: a lead bound per unit of progress").
//!
//! **Single pass.** The simulated dynamics do not depend on `T_p` or `T_c` (only the stop test
//! does), and the pairs of one role `(p, c)` are ordered in both `T_p` and `T_c`. So one
//! simulation per ordered role, with a pointer over that role's pairs, decides every pair
//! exactly as a fresh simulation per pair would ([`sufficient_margins_per_pair`], the oracle of
//! `tests/agreement.rs`).
//!
//! # Three or more robots: the lead bound
//! With a third robot the pace of `p` and `c` is no longer theirs: while neither is LC both
//! respond to a pace set by another robot (the operator's rate for a third LC robot, or
//! `HIGH-CONF`'s target, which a robot far behind holds back), and two robots that track one
//! pace within different bounds drift apart. The lead `L = s_c − s_p` that `c` gains is bounded
//! here per unit of `p`'s progress, which holds over any operator strategy however many ticks it
//! takes.
//!
//! **(a) One common pace.** In a tick with at most one LC robot, every running HC robot `i` ends
//! at `clamp(x, s_i + S_i·h, s_i + F_i·h)` for one common `x`, and an LC robot at `x` itself with
//! `x` in its own range: with an LC robot `x` is its new clock and every other robot responds
//! with Eq. 18, which is that clamp; with none, Alg. 1 between the leader `a` and the robot `b`
//! that can reach least far either moves `a` fastest and lands `b` on it, or moves `b` fastest and
//! lands `a` on `b` or as slowly as it can (then above `b`), so both are the clamp of
//! `x = min(s_a', s_b')`, to which every other robot responds.
//!
//! **(b) The gain of one tick.** For an ordered pair `(p, c)` with `Δp = s_p' − s_p` and rates
//! read at the tick start, `max(0, L') ≤ max(0, L + ρ·Δp)`, where `ρ` depends on the modes:
//!
//! - `c` LC: `c` sets the pace (`x = s_c'`), `p` (HC, by the first overlap) responds. `p` lands
//!   on `x` (`L' = 0`), cannot go slowly enough (`L' < 0`), or cannot go fast enough:
//!   `L' = L + Δc − F_p·h ≤ L + (F_c − F_p)·h = L + (F_c/F_p − 1)·Δp`. So `ρ = F_c/F_p − 1`.
//! - `c` HC, `p` LC: `p` sets the pace, `c` responds. `c` lands on `x`, cannot go fast enough
//!   (`L' < 0`), or cannot go slowly enough: `L' = L + S_c·h − Δp ≤ L + (S_c/S_p − 1)·Δp` since
//!   `Δp ≥ S_p·h`. So `ρ = S_c/S_p − 1`: the paper's drag.
//! - both HC and another robot may set the pace (a robot that runs started when every running
//!   robot had reached its start, so this needs `τ_r ≤ s_p`): of `p` and `c` at most one is
//!   clamped away from `x` in the direction that makes `L` grow; `c` held at its slowest gives
//!   the drag term, `p` held at its fastest `L + (F_c − F_p)·h`; so
//!   `ρ = max(S_c/S_p, F_c/F_p) − 1`.
//! - both HC and only `p` and `c` run: Alg. 1 between the two. With `c` ahead, `p` goes fastest
//!   and `c` lands on it or goes as slowly as it can: `L' ≤ max(0, L + (S_c − F_p)·h)`, so
//!   `ρ = S_c/F_p − 1 < 0` — the pull that brings a robot ahead back; with `c` behind, `L' ≤ 0`.
//!
//! The lead can only become positive from `c`-positions with `s_c > s_p − M_c`, and `ρ ≥ −1`
//! always. None of these bounds depends on how many ticks a stretch takes: they are per unit of
//! `p`'s progress, which is what the simulation of fixes 5–6 got wrong. It picked, per tick,
//! the pace leaving `c` furthest ahead *after that tick*; the operator picks the pace that
//! leaves `c` furthest ahead when `p` leaves its region, and dragging a third robot, which gains
//! less lead per tick than rushing it, can gain more per unit of `p`'s progress (four times
//! more in the reproducers of `tests/reproducers.rs`).
//!
//! **(c) The frontier.** `Λ_pc(u)` bounds `L` at every tick start with `p` at `u`; it is
//! integrated along `p`'s clock, `Λ' = ρ̄` (floored at 0), where `ρ̄(u)` is the largest `ρ` over
//! the ticks that can cover `u` — starting with `p` in `[u − M_p, u]`, `p`'s mode and smallest
//! rates over those samples, whether a robot other than `p` and `c` may run — and with `c`
//! within `δ` of the frontier, `c ∈ [s_p + Λ(s_p) − δ, s_p + Λ(s_p)]`, `c`'s mode and largest
//! rates over those samples. A state on the frontier gains at most `ρ̄·Δp`; a state further than
//! `δ` below it gains at most `ρ_max·Δp` (`ρ_max`: the largest `ρ` over the two robots' extreme
//! rates) and so stays below when `δ = (ρ_max + 1)·M_p`. Taking `c`'s rates only near the
//! frontier, not over every position `c` could be in, keeps the bound from feeding on its own
//! width; it is the envelope of every trajectory, and the simulated worst case of two robots
//! is one of them. `u + Λ(u)` is non-decreasing (`ρ̄ ≥ −1`).
//!
//! **(d) Starts.** When `c` starts after `p`, it starts at `τ_c` once every running robot has
//! reached `τ_c`, so `L ≤ 0` there and `Λ_pc` starts at 0. When `p` starts after `c`, it starts
//! at `τ_p` in the tick in which the running robot furthest behind, `m`, passes `τ_p`: at that
//! tick's start `s_m < τ_p` and `s_c ≤ s_m + Λ_mc(s_m)` (or `m = c`), and `c` moves at most
//! `M_c`, so `L ≤ M_c + max(0, max_m (s + Λ_mc(s)) − τ_p)` over `s < τ_p`. The ordered pairs
//! are integrated in the order of their later start, so every `Λ_mc` needed is known.
//!
//! **(e) The test.** `p` can traverse its region `P` in a tick that starts at `s_p` only if
//! `s_p < u_max = min(T_p + ε, end_p)`, and `c` can traverse `C` only if `s_c + M_c ≥ T_c − ε`.
//! So the pair is safe when the largest `u + Λ_pc(u)` over `u < u_max`, plus `M_c`, is below
//! `T_c − ε`, or when `u_max` is at or before the later start (then `p` has left `P` before both
//! run). This excludes `c` being in `C` — entering, inside, or already past it — while `p` has
//! not left `P`, so for each `P` only the first region of `c` starting at or after `P` needs the
//! test; a region of `c` starting before `P` is the pair `(c, p)`. Cost: `O(N² · T_ref)` with
//! sliding extremes, independent of the tick.
//!
//! **(f) Finished robots set no pace (a second pass).** A robot whose clock is at or past its
//! end at a tick start is finished (`coordinator`, `phase`): it does not move and sets nothing
//! (strategy rule 4); one not yet started follows (rule 3). So in a tick in which no robot
//! other than `p` and `c` runs, (b)'s two-robot cases apply even after a third robot started.
//! The first pass assumes a third robot `r` may run from `τ_r` to the end of the task. Its
//! bounds are sound, and `r` runs only while `s_r < end_r`, where `s_p ≤ R_rp`: the largest
//! `u + Λ_rp(u)` for `u ≤ end_r` (`+ ε` for the coordinator's clock rounding; a larger `R_rp`
//! only lets `r` run longer). Where the first pass rejects, a second pass integrates every
//! pair again with "another robot may run in the cell `[u_a, u_b]`" read as: some `r` has
//! `τ_r ≤ u_b` and `R_rp ≥ u_a − M_p` (a tick covering the cell starts with `p` in
//! `[u_a − M_p, u_b]`). Every lead read at a start (d) is the smaller of the two passes' and
//! every slack the larger: the minimum of two sound bounds is sound. Two robots have no third
//! robot, and their check is unchanged.
//!
//! This is a proof on paper, checked by search (the property tests `tests/safety_n.rs` over the
//! test kit's problem families, the search adversary, `cargo xtask stress`), not a
//! machine-checked one. For two robots [`lead_bound`] is sound too, but neither it nor the
//! simulation is uniformly tighter (docs/decisions.md, "The N-robot margin check: a lead bound
//! per unit of progress"), so two robots keep the simulation, bit for bit.
//!
//! # The operator's switch time
//! [`check_margins`] takes a switch time `δ` ([`MarginParams::switch_s`], real s): between a
//! tick in which one robot traverses a low-confidence sample and a later tick in which another
//! does, at least `k` = [`switch_ticks`]`(δ, h)` ticks pass. Each test above then keeps `c` a
//! further `k·M_c` short of its region when `p` has left its own (`c` moves at most `M_c` a
//! tick), a pair decided before the later robot starts counts the ticks `p` needed to reach that
//! start. With holds the check is that of a coordinator that waits the switch time at run time
//! ([`Coordinator::with_switch_s`](crate::Coordinator::with_switch_s)): a held robot leaves its
//! hold `k` ticks after the tick start at which its release rules first held, so a pair whose
//! order a chain of rules enforces is still exempt, and a leg delayed by rules starts with `c`
//! up to `k·M_c` further ahead (test (d)). With `δ = 0` no term is added: the same float
//! operations (docs/decisions.md, "The operator's switch time in the margin check (issue 41)",
//! "The switch time at run time (issue 41)").
//!
//! # Slacks
//! [`pair_slacks`] reports, per pair, the room rule 1 (two robots) or the test (d) (three or
//! more) leaves: `> 0` exactly when the pair is accepted, its negative the clearance missing. A
//! scheduler reads from the slacks how much clearance each pair lacks or has to spare, with the
//! check itself as the only owner of the worst case.

mod lead;
pub mod operators;
mod sim;
mod window;

use crate::error::{Error, Result};
use crate::robots::check_count;
use crate::timeline::{LcInterval, Timeline};
use crate::tol::clock_tolerance_s;
use sim::Variant;

/// The conservative, discretization-safe worst-case margin check for `1 ≤ N ≤ MAX_ROBOTS`
/// robots: `true` when no admissible operator can make two robots low-confidence in the same
/// control tick of `tick_s` real seconds. Robot `i` is `robots[i]`; one robot is always
/// accepted.
///
/// Two robots: the single-pass worst-case simulation (Alg. 2 with fixes 1–4), O(T_ref · steps
/// per sample). Three or more: the lead bound, O(N² · T_ref). See the [module docs](self) for the
/// arguments.
///
/// # Errors
/// [`Error::RobotCount`] unless `1 ≤ N ≤ MAX_ROBOTS`; [`Error::BadParam`] for `tick_s` not
/// finite and > 0, or (two robots) so small that the horizon spans more than 1e8 ticks. A
/// simulation still undecided after 1e8 ticks (extreme demonstrated rates, e.g. a sample one
/// demonstration dwelt on) rejects the schedule: `Ok(false)`.
pub fn sufficient_margins(robots: &[Timeline], tick_s: f64) -> Result<bool> {
    match robots.len() {
        0..=2 => sim::check_single_pass(robots, tick_s, Variant::Conservative, 0),
        _ => lead_bound(robots, tick_s),
    }
}

/// The same decisions as [`sufficient_margins`], computed the straightforward way: for two
/// robots one fresh worst-case simulation per pair; for three or more the lead bound with every
/// window scanned sample by sample instead of by sliding extremes. O(pairs) or O(window) times
/// the cost; a benchmark baseline and the oracle of `tests/agreement.rs`.
///
/// # Errors
/// As [`sufficient_margins`].
pub fn sufficient_margins_per_pair(robots: &[Timeline], tick_s: f64) -> Result<bool> {
    match robots.len() {
        0..=2 => sim::check_per_pair(robots, tick_s, Variant::Conservative),
        _ => Ok(lead_slacks(robots, tick_s, false, Windows::Scanned, 0)?
            .iter()
            .all(|s| s.slack_s > 0.0)),
    }
}

/// The lead bound alone (section "Three or more robots: the lead bound" of the
/// [module docs](self)) for any `1 ≤ N ≤ MAX_ROBOTS`: `true` when it shows that no admissible
/// operator can make two robots low-confidence in one tick. Sound for every `N`;
/// [`sufficient_margins`] uses it for `N ≥ 3`. For two robots it is more conservative than the
/// simulation, which sees how `HIGH-CONF` pulls the robots together between regions.
///
/// # Errors
/// [`Error::RobotCount`] unless `1 ≤ N ≤ MAX_ROBOTS`; [`Error::BadParam`] for `tick_s` not
/// finite and > 0.
pub fn lead_bound(robots: &[Timeline], tick_s: f64) -> Result<bool> {
    Ok(lead_slacks(robots, tick_s, true, Windows::Sliding, 0)?
        .iter()
        .all(|s| s.slack_s > 0.0))
}

/// One pair of LC regions of different robots with its worst-case room (see [`pair_slacks`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairSlack {
    /// The previous robot `p` (index into the robots given, 0 = the first robot).
    pub prev_robot: usize,
    /// The current robot `c` (index into the robots given); for two robots `1 − prev_robot`.
    pub cur_robot: usize,
    /// `p`'s region (schedule clock); `p` leaves it at `T_p = prev.end_s`.
    pub prev: LcInterval,
    /// `c`'s region (schedule clock); `c` enters it at `T_c = cur.start_s`.
    pub cur: LcInterval,
    /// Schedule-clock s, `> 0` exactly when [`sufficient_margins`] accepts the pair; its
    /// negative is the clearance missing.
    ///
    /// Two robots: how much earlier `c`'s region could start before rule 1 rejects it on the
    /// same worst-case trajectory, `(T_c − ε) − (t_c + M)` at the first simulated step with
    /// `t_p ≥ T_p + ε`; `+∞` for a pair accepted without simulation (fix 4); for a pair whose
    /// regions already overlap on schedule, the smaller of that and `T_c − (T_p + ε) < 0`; `−∞`
    /// if the simulation budget ran out first. Three or more robots: the room of test (d),
    /// `(T_c − ε) − (u_max + Λ_pc(u_max) + M_c)`, `+∞` when `p` has left `P` before both run.
    pub slack_s: f64,
}

/// Every pair's worst-case slack ([`PairSlack`]), in the order of the current regions' starts,
/// from the same computation as [`sufficient_margins`] (run to the end instead of stopping at
/// the first rejection): `sufficient_margins(robots, tick_s)` is `true` exactly when every
/// `slack_s > 0`. Two robots: every pair of consecutive regions; three or more: for every region
/// `P` of every robot `p` and every other robot `c`, the first region of `c` starting at or after
/// `P`.
///
/// # Errors
/// As [`sufficient_margins`].
pub fn pair_slacks(robots: &[Timeline], tick_s: f64) -> Result<Vec<PairSlack>> {
    match robots.len() {
        0..=2 => sim::pair_slacks(robots, tick_s, 0),
        _ => lead_slacks(robots, tick_s, false, Windows::Sliding, 0),
    }
}

/// [`sufficient_margins`] for plans with hold points (`crate::holds`): `holds` is empty (then
/// exactly [`sufficient_margins`]) or one list per robot. With holds, the lead bound runs on
/// the robots' legs with their release rules (docs/decisions.md, "Hold points: a wait instead
/// of a margin"), for any `1 ≤ N ≤ MAX_ROBOTS`.
///
/// # Errors
/// As [`sufficient_margins`]; [`Error::BadHold`] or [`Error::LengthMismatch`] for holds that
/// `crate::holds::check_holds` rejects or a wrong number of hold lists.
pub fn sufficient_margins_with_holds(
    robots: &[Timeline],
    holds: &[Vec<crate::Hold>],
    tick_s: f64,
) -> Result<bool> {
    check_count(robots.len())?;
    let plans = crate::holds::Plans::new(robots, holds)?;
    check_plans(&plans, robots.len(), tick_s)
}

/// [`pair_slacks`] for plans with hold points (see [`sufficient_margins_with_holds`]); with
/// holds, `prev_robot`/`cur_robot` are robots (not legs) and a pair whose order the release
/// rules enforce has slack `+∞`.
///
/// # Errors
/// As [`sufficient_margins_with_holds`].
pub fn pair_slacks_with_holds(
    robots: &[Timeline],
    holds: &[Vec<crate::Hold>],
    tick_s: f64,
) -> Result<Vec<PairSlack>> {
    check_count(robots.len())?;
    let plans = crate::holds::Plans::new(robots, holds)?;
    if !plans.has_holds() {
        return pair_slacks(robots, tick_s);
    }
    robot_slacks_of_plans(&plans, tick_s, 0)
}

/// The slacks of split plans with holds, the pairs' indices being robots (not legs).
fn robot_slacks_of_plans(
    plans: &crate::holds::Plans,
    tick_s: f64,
    switch_ticks: u64,
) -> Result<Vec<PairSlack>> {
    let mut out = plan_slacks(plans, tick_s, false, switch_ticks)?;
    for s in &mut out {
        s.prev_robot = plans.robot_of[s.prev_robot];
        s.cur_robot = plans.robot_of[s.cur_robot];
    }
    Ok(out)
}

/// The margin check of split plans: without holds [`sufficient_margins`] on the robots.
pub(crate) fn check_plans(
    plans: &crate::holds::Plans,
    n_robots: usize,
    tick_s: f64,
) -> Result<bool> {
    check_plans_switch(plans, n_robots, tick_s, 0)
}

/// [`check_plans`] with the operator's switch time, `switch_ticks` whole ticks (0: none, the
/// same float operations as [`check_plans`]).
pub(crate) fn check_plans_switch(
    plans: &crate::holds::Plans,
    n_robots: usize,
    tick_s: f64,
    switch_ticks: u64,
) -> Result<bool> {
    check_count(n_robots)?;
    if !plans.has_holds() {
        return match plans.legs.len() {
            0..=2 => {
                sim::check_single_pass(&plans.legs, tick_s, Variant::Conservative, switch_ticks)
            }
            _ => Ok(
                lead_slacks(&plans.legs, tick_s, true, Windows::Sliding, switch_ticks)?
                    .iter()
                    .all(|s| s.slack_s > 0.0),
            ),
        };
    }
    Ok(plan_slacks(plans, tick_s, true, switch_ticks)?
        .iter()
        .all(|s| s.slack_s > 0.0))
}

/// The lead bound's slacks on the legs of `plans` (leg indices).
fn plan_slacks(
    plans: &crate::holds::Plans,
    tick_s: f64,
    stop_at_first: bool,
    switch_ticks: u64,
) -> Result<Vec<PairSlack>> {
    plan_slacks_with(
        plans,
        tick_s,
        stop_at_first,
        lead::Passes::Both,
        switch_ticks,
    )
}

/// [`plan_slacks`] with the passes of the lead bound chosen.
fn plan_slacks_with(
    plans: &crate::holds::Plans,
    tick_s: f64,
    stop_at_first: bool,
    passes: lead::Passes,
    switch_ticks: u64,
) -> Result<Vec<PairSlack>> {
    if !(tick_s.is_finite() && tick_s > 0.0) {
        return Err(Error::BadParam {
            name: "tick_s",
            why: "must be finite and > 0",
        });
    }
    let legs = &plans.legs;
    let max_step_of: Vec<f64> = legs.iter().map(|r| tick_s * r.max_rate_fast()).collect();
    let eps = 4.0 * clock_tolerance_s(legs, tick_s);
    Ok(lead::slacks_of_legs(
        &lead::Legs {
            legs,
            robot_of: &plans.robot_of,
            plans: Some(plans),
            switch_ticks,
            tick_s,
        },
        &max_step_of,
        eps,
        Windows::Sliding,
        stop_at_first,
        passes,
    ))
}

/// How the lead bound reads its rate windows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Windows {
    /// Sliding extremes over monotone cursors (amortized O(1) per cell).
    Sliding,
    /// Every window scanned sample by sample (the oracle).
    Scanned,
}

/// Count, tick and steps shared by the checks: `M_i` per robot and `ε` (schedule-clock s).
fn steps_and_eps(robots: &[Timeline], tick_s: f64) -> Result<(Vec<f64>, f64)> {
    check_count(robots.len())?;
    if !(tick_s.is_finite() && tick_s > 0.0) {
        return Err(Error::BadParam {
            name: "tick_s",
            why: "must be finite and > 0",
        });
    }
    let max_step_of = robots.iter().map(|r| tick_s * r.max_rate_fast()).collect();
    Ok((max_step_of, 4.0 * clock_tolerance_s(robots, tick_s)))
}

/// The slacks of the lead bound (three or more robots).
fn lead_slacks(
    robots: &[Timeline],
    tick_s: f64,
    stop_at_first: bool,
    windows: Windows,
    switch_ticks: u64,
) -> Result<Vec<PairSlack>> {
    let (max_step_of, eps) = steps_and_eps(robots, tick_s)?;
    Ok(lead::slacks(
        robots,
        &max_step_of,
        eps,
        windows,
        stop_at_first,
        lead::Passes::Both,
        (switch_ticks, tick_s),
    ))
}

/// The inputs of a margin check besides the robots and their holds: the control tick and the
/// operator's switch time (docs/decisions.md, "The operator's switch time in the margin
/// check").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarginParams {
    /// Control tick `h` (real s per `Coordinator::tick`), finite and > 0: the guarantee holds
    /// at this tick only.
    pub tick_s: f64,
    /// The operator's switch time `δ` (real s), finite and ≥ 0: between the end of one robot's
    /// low-confidence stretch and the start of another robot's, at least `δ` seconds pass, in
    /// whole ticks ([`switch_ticks`]). Default 0: today's invariant, decided by exactly the same
    /// float operations as [`sufficient_margins`].
    pub switch_s: f64,
}

impl MarginParams {
    /// The check at `tick_s` with no switch time (`switch_s = 0`).
    #[must_use]
    pub fn new(tick_s: f64) -> MarginParams {
        MarginParams {
            tick_s,
            switch_s: 0.0,
        }
    }

    /// The same with switch time `switch_s` (real s).
    #[must_use]
    pub fn with_switch_s(self, switch_s: f64) -> MarginParams {
        MarginParams { switch_s, ..self }
    }

    /// `k`, the switch time in whole ticks ([`switch_ticks`]).
    ///
    /// # Errors
    /// As [`switch_ticks`].
    pub fn switch_ticks(&self) -> Result<u64> {
        switch_ticks(self.switch_s, self.tick_s)
    }
}

/// Largest switch time, in control ticks, that a check accepts.
const MAX_SWITCH_TICKS: f64 = 1e8;

/// The switch time `δ = switch_s` (real s) at control tick `h = tick_s` (real s) in whole ticks:
/// the smallest `k ≥ 0` with `k·h ≥ δ` in floating point (0 for `δ = 0`). A run keeps the
/// switch time when between a tick in which one robot traverses a low-confidence sample and a
/// later tick in which another robot does, at least `k` ticks pass in which neither does: the
/// gap `k·h` (real s) then is at least `δ` as the run measures it (tick count times tick).
///
/// # Errors
/// [`Error::BadParam`] for `tick_s` not finite and > 0, `switch_s` not finite and ≥ 0, or a
/// switch time of more than 1e8 ticks.
pub fn switch_ticks(switch_s: f64, tick_s: f64) -> Result<u64> {
    if !(tick_s.is_finite() && tick_s > 0.0) {
        return Err(Error::BadParam {
            name: "tick_s",
            why: "must be finite and > 0",
        });
    }
    if !(switch_s.is_finite() && switch_s >= 0.0) {
        return Err(Error::BadParam {
            name: "switch_s",
            why: "must be finite and >= 0 (the operator's switch time in seconds; 0 for none)",
        });
    }
    let q = switch_s / tick_s;
    if q > MAX_SWITCH_TICKS {
        return Err(Error::BadParam {
            name: "switch_s",
            why: "too large: more than 1e8 control ticks",
        });
    }
    // Bounded by 1e8 above, so the cast is exact; then the rounding of `q` is corrected so that
    // `k` is the smallest with `k·h ≥ δ` as computed.
    let mut k = q.ceil() as u64;
    while (k as f64) * tick_s < switch_s {
        k += 1;
    }
    while k > 0 && ((k - 1) as f64) * tick_s >= switch_s {
        k -= 1;
    }
    Ok(k)
}

/// The margin check with the operator's switch time: `true` when no admissible operator can
/// make two robots low-confidence in one control tick of `params.tick_s`, nor make one robot's
/// low-confidence stretch start fewer than [`switch_ticks`] ticks after another robot's ended.
/// `holds` is empty (no holds) or one list per robot (as [`sufficient_margins_with_holds`]).
/// With `switch_s = 0` it is [`sufficient_margins_with_holds`], bit for bit.
///
/// Two robots without holds: the simulation, `c` a further `k·M_c` short of its region when `p`
/// has left its own; otherwise the lead bound with the same room. With holds the guarantee is
/// that of a coordinator waiting the switch time at its holds ([`Coordinator::with_margins`] or
/// [`Coordinator::with_switch_s`] at the same `switch_s`): a pair whose order release rules
/// enforce is exempt, and a leg delayed by rules may start `k` ticks later (module docs).
///
/// [`Coordinator::with_margins`]: crate::Coordinator::with_margins
/// [`Coordinator::with_switch_s`]: crate::Coordinator::with_switch_s
///
/// # Errors
/// As [`sufficient_margins_with_holds`]; [`Error::BadParam`] for a bad `switch_s`
/// ([`switch_ticks`]).
pub fn check_margins(
    robots: &[Timeline],
    holds: &[Vec<crate::Hold>],
    params: &MarginParams,
) -> Result<bool> {
    check_count(robots.len())?;
    let k = params.switch_ticks()?;
    let plans = crate::holds::Plans::new(robots, holds)?;
    check_plans_switch(&plans, robots.len(), params.tick_s, k)
}

/// Every pair's slack under [`check_margins`]: [`pair_slacks_with_holds`] with the switch
/// time's room taken off (`check_margins` is `true` exactly when every `slack_s > 0`). With
/// `switch_s = 0` it is [`pair_slacks_with_holds`], bit for bit.
///
/// # Errors
/// As [`check_margins`].
pub fn margin_slacks(
    robots: &[Timeline],
    holds: &[Vec<crate::Hold>],
    params: &MarginParams,
) -> Result<Vec<PairSlack>> {
    check_count(robots.len())?;
    let k = params.switch_ticks()?;
    let plans = crate::holds::Plans::new(robots, holds)?;
    if plans.has_holds() {
        return robot_slacks_of_plans(&plans, params.tick_s, k);
    }
    match robots.len() {
        0..=2 => sim::pair_slacks(robots, params.tick_s, k),
        _ => lead_slacks(robots, params.tick_s, false, Windows::Sliding, k),
    }
}

/// The switch time of a check on one pair `(p, c)`: `k` whole ticks and the two robots'
/// largest steps (schedule-clock s).
#[derive(Clone, Copy, Debug)]
pub(super) struct SwitchRoom {
    /// `k ≥ 1`.
    pub(super) ticks: u64,
    /// `M_p`.
    pub(super) step_p: f64,
    /// `p`'s largest step over its samples after its region `P` ([`FastRates::step_within`]), `≤ M_p`.
    pub(super) step_p_after: f64,
    /// `c`'s largest step over its samples before its region `C` ([`FastRates::step_within`]), `≤ M_c`.
    pub(super) step_c_before: f64,
    /// Whole ticks in which nobody runs before `c` starts, after `p` has finished
    /// ([`idle_ticks_before_start`]; 0 when `c` starts before every earlier robot has ended).
    pub(super) idle_ticks: f64,
}

/// A lower bound on the whole ticks in which no robot runs before robot `c` of `robots` starts
/// at `τ_c` (its plan's start, schedule clock), after the last tick in which a robot that
/// starts before it ran: 0 unless `τ_c` lies beyond `E = max end` of those robots (Eq. 20
/// constraint 2 relaxed by the operator's switch time, docs/decisions.md, "A schedule always
/// exists with a switch time: constraint 2 relaxed (issue 41)").
///
/// Why (the coordinator's rule 3, `strategy`): until `c` starts its clock is the smallest new
/// clock of the running robots, capped at `τ_c` and at the starts of the robots still waiting,
/// and runs on schedule (`+h` a tick) when none runs. Before `c` starts only robots with a start
/// below `τ_c` run (the others wait, capped at the earliest start waiting, at most `τ_c`), each
/// below its end and moving at most its largest step `M_r`; so at the end of the last tick in
/// which one of them runs `c`'s clock is at most `E + M` (`M` their largest step), and it needs
/// at least `(τ_c − E − M)/h` more ticks, all of them with nobody running, to reach `τ_c`. The
/// count is a whole number, so its quotient's ceiling, taken after lowering the quotient by
/// `1e-9` relative, by the clocks' rounding (`8·ε·(|τ_c| + |E|)/h` relative: each tick's sum
/// rounds by half an ulp) and by `1e-6` absolute, is a lower bound: it errs towards fewer ticks.
pub(super) fn idle_ticks_before_start(
    robots: &[Timeline],
    max_step_of: &[f64],
    c: usize,
    tick_s: f64,
) -> f64 {
    let tau_c = robots[c].start_s();
    let (end_s, step_s) = robots
        .iter()
        .zip(max_step_of)
        .enumerate()
        .filter(|&(r, (tl, _))| r != c && tl.start_s() < tau_c)
        .fold((f64::NEG_INFINITY, 0.0_f64), |(e, m), (_, (tl, &s))| {
            (e.max(tl.end_s()), m.max(s))
        });
    if end_s == f64::NEG_INFINITY {
        return 0.0;
    }
    let quotient = (tau_c - end_s - step_s) / tick_s;
    if !(quotient > 0.0 && quotient.is_finite()) {
        return 0.0;
    }
    let rel = 1e-9 + 8.0 * f64::EPSILON * (tau_c.abs() + end_s.abs()) / tick_s;
    (quotient * (1.0 - rel) - 1e-6).ceil().max(0.0)
}

/// `max_step·(within/all)`, raised by `1e-12` relative and capped at `max_step`: the step of
/// [`FastRates::step_within`] from the largest fast rates over the range (`within`) and over
/// all samples (`all`).
pub(super) fn scaled_step(max_step: f64, within: f64, all: f64) -> f64 {
    (max_step * (within / all) * (1.0 + 1e-12)).min(max_step)
}

/// One robot's largest fast rate `max(1, F_n)` (Eq. 17, `F = ψ̇_E/ψ̇min`) over all its samples,
/// every prefix `0..i` and every suffix `i..T_ref`, built once per check in O(T_ref), so that
/// the switch time's restricted steps ([`FastRates::step_within`], one or two per pair of
/// regions) cost O(1) for a prefix or a suffix instead of O(T_ref) each. The maxima are exact
/// (a maximum of floats does not round), so every step is the same value, bit for bit, as a
/// scan of the range would give (docs/decisions.md, "The margin check's cost with a switch time
/// (issue 41)").
pub(super) struct FastRates {
    /// `max(1, max_n F_n)`, exactly `Timeline::max_rate_fast`.
    all: f64,
    /// `before[i] = max(1, max_{n < i} F_n)`, `i = 0..=T_ref`.
    before: Vec<f64>,
    /// `from[i] = max(1, max_{n ≥ i} F_n)`, `i = 0..=T_ref`.
    from: Vec<f64>,
}

impl FastRates {
    /// The prefix and suffix maxima of `tl`'s fast rates.
    pub(super) fn new(tl: &Timeline) -> FastRates {
        let n_ref = tl.n_ref();
        let mut before = Vec::with_capacity(n_ref + 1);
        before.push(1.0_f64);
        for n in 0..n_ref {
            before.push(before[n].max(tl.rate_fast(n)));
        }
        let mut from = vec![1.0_f64; n_ref + 1];
        for n in (0..n_ref).rev() {
            from[n] = from[n + 1].max(tl.rate_fast(n));
        }
        FastRates {
            all: before[n_ref],
            before,
            from,
        }
    }

    /// `max(1, max_n F_n)` over all samples (the rate of the largest step `M`).
    pub(super) fn all(&self) -> f64 {
        self.all
    }

    /// The largest step (schedule-clock s) of robot `tl` (the timeline these rates were built
    /// from) in one tick while it traverses only the samples `range`: its largest step over all
    /// samples, `max_step = h·max(1, max_n F_n)`, scaled by
    /// `max(1, max_{n ∈ range} F_n)/max(1, max_n F_n) ≤ 1` and raised by `1e-12` relative (so
    /// the quotient's rounding can only make it larger than `h·max(1, max_range F)`). A robot
    /// whose clock stays inside the samples `range` during a tick moves at most this. A prefix
    /// or a suffix is read from the tables in O(1), another range scanned.
    pub(super) fn step_within(
        &self,
        tl: &Timeline,
        max_step: f64,
        range: std::ops::Range<usize>,
    ) -> f64 {
        let n_ref = self.before.len() - 1;
        let (a, b) = (range.start.min(n_ref), range.end.min(n_ref));
        let within = if a >= b {
            1.0
        } else if a == 0 {
            self.before[b]
        } else if b == n_ref {
            self.from[a]
        } else {
            (a..b).map(|n| tl.rate_fast(n)).fold(1.0, f64::max)
        };
        scaled_step(max_step, within, self.all)
    }
}

/// The switch time's room (schedule-clock s) that `c` may cover in the `k ≥ 1` ticks after
/// `p`'s exit tick, given that `c` is at most at `y0_s` when the exit tick ends: at most one
/// tick of its largest step `M_c` (the tick that may start below `y0`), then `k − 1` ticks
/// that start at or after `y0` and, while `c` is short of its region `C`, traverse only
/// samples in `[sample_at(y0), C)`: `M_c + (k − 1)·M_c'` with `M_c' = step_of_rest`, `c`'s
/// largest step over those samples ([`FastRates::step_within`]), `≤ M_c`. Below `k·M_c`, which charged
/// every tick the largest step over all samples (docs/decisions.md, "Rounds schedules with the
/// switch time and the load cap (issue 41)").
pub(super) fn switch_room_after_s(switch_ticks: u64, max_step_c: f64, step_of_rest: f64) -> f64 {
    max_step_c + (switch_ticks - 1) as f64 * step_of_rest
}

/// The room (schedule-clock s, `> 0` when safe) of a pair whose previous robot `p` left its
/// region before the current robot `c` started, under the switch time: `p`'s exit tick starts
/// with `p` below `u_max_s`, and `c` starts at `τ_c` (`tau_c_s`) only at a tick start at which
/// `p` has reached `min(τ_c, end_p)` (`end_p_s`), i.e. at least `e = ⌊(min(τ_c, end_p) −
/// u_max)/M_p⌋` and at least one tick after the exit tick's start. In the `k` ticks after the
/// exit tick `c` then runs at most `k + 1 − max(e, 1)` ticks from `τ_c`, so it cannot enter its
/// region at `t_c_lim_s = T_c − ε` when `τ_c + (k + 1 − max(e, 1))·M_c < T_c − ε`; `+∞` when it
/// does not run at all in them. `e` rounds down: a floor of a quotient off by an ulp is still
/// at most the true count.
///
/// Tighter steps (docs/decisions.md, "Rounds schedules with the switch time and the load cap
/// (issue 41)"): after its exit tick `p` is past `P` (a robot never moves backwards), so every
/// later tick moves it at most `M_p' = step_p_after`, its largest step over the samples after
/// `P`; the exit tick ends with `p` at most at `u_max + M_p`; so also `e ≥ 1 + ⌊(min(τ_c, end_p)
/// − u_max − M_p)/M_p'⌋`, and the larger count holds. And `c`, from `τ_c` until it reaches
/// `T_c − ε`, traverses only samples before `C`: while `τ_c + j·M_c' < T_c − ε` with `M_c' =
/// step_c_before` its largest step over them, `c` has not reached `C` after `j` ticks (by
/// induction: each tick starts and, moving at most `M_c'`, ends before `T_c − ε`).
pub(super) fn started_after_exit_slack(
    room: SwitchRoom,
    u_max_s: f64,
    (tau_c_s, end_p_s): (f64, f64),
    t_c_lim_s: f64,
) -> f64 {
    let reach_s = tau_c_s.min(end_p_s) - u_max_s;
    let after_exit = 1.0 + ((reach_s - room.step_p) / room.step_p_after).floor();
    // Ticks with nobody running after `p` finished come on top (`idle_ticks`, 0 when `c`
    // starts before every earlier robot has ended: the same value as without the term).
    let elapsed = (reach_s / room.step_p).floor().max(after_exit).max(1.0) + room.idle_ticks;
    let k = room.ticks as f64;
    if elapsed > k {
        f64::INFINITY
    } else {
        t_c_lim_s - (tau_c_s + (k + 1.0 - elapsed) * room.step_c_before)
    }
}

/// The lead bound's first pass alone, with or without hold points (`holds` empty or one list
/// per robot): every robot other than `p` and `c` may set the pace from its start to the end
/// of the task, as [`sufficient_margins`] assumed for `N ≥ 3` before the finished-robot pass
/// (docs/decisions.md, "Robots that have finished set no pace"). Sound, and for three or more
/// robots looser: whatever it accepts, [`sufficient_margins_with_holds`] accepts (for two
/// robots without holds that check is the simulation, neither tighter nor looser). Kept for
/// tests and benchmarks.
///
/// # Errors
/// As [`sufficient_margins_with_holds`].
pub fn lead_bound_first_pass(
    robots: &[Timeline],
    holds: &[Vec<crate::Hold>],
    tick_s: f64,
) -> Result<bool> {
    check_count(robots.len())?;
    let plans = crate::holds::Plans::new(robots, holds)?;
    if !plans.has_holds() {
        let (max_step_of, eps) = steps_and_eps(robots, tick_s)?;
        return Ok(lead::slacks(
            robots,
            &max_step_of,
            eps,
            Windows::Sliding,
            true,
            lead::Passes::First,
            (0, tick_s),
        )
        .iter()
        .all(|s| s.slack_s > 0.0));
    }
    Ok(
        plan_slacks_with(&plans, tick_s, true, lead::Passes::First, 0)?
            .iter()
            .all(|s| s.slack_s > 0.0),
    )
}

/// Margin checks that are **not safe**, kept by name so that tests can show what they miss and
/// benchmarks can compare against them. Never use them to accept a schedule.
pub mod baseline {
    use super::sim::{self, Variant};
    use crate::error::Result;
    use crate::timeline::Timeline;

    /// Alg. 2 exactly as printed (with the typo fixes of docs/decisions.md), one simulation per
    /// pair from the later start of its two robots, the other robots ignored.
    ///
    /// **UNSAFE on a tick grid**: it can accept schedules on which an admissible operator makes
    /// two robots low-confidence in the same tick (see the [module docs](super)).
    ///
    /// # Errors
    /// As [`sufficient_margins`](super::sufficient_margins).
    pub fn printed(robots: &[Timeline], tick_s: f64) -> Result<bool> {
        sim::check_per_pair(robots, tick_s, Variant::Printed)
    }

    /// The two-robot conservative check (fixes 1–4) applied to every pair of robots as if the
    /// other robots were absent. For two robots it is
    /// [`sufficient_margins`](super::sufficient_margins).
    ///
    /// **UNSAFE for three or more robots**: a third robot that sets the pace can move `p` and
    /// `c` apart, and this check does not see it (tests/regression.rs).
    ///
    /// # Errors
    /// As [`sufficient_margins`](super::sufficient_margins).
    pub fn pairwise(robots: &[Timeline], tick_s: f64) -> Result<bool> {
        sim::check_single_pass(robots, tick_s, Variant::Pairwise, 0)
    }

    /// The worst-case simulation extended to N robots by choosing, at every simulated tick in
    /// which neither `p` nor `c` is LC and a third robot may run, the common pace that leaves
    /// `c` furthest ahead after that tick (fix 5), and by simulating the other robots' starts
    /// (fix 6). For two robots it is [`sufficient_margins`](super::sufficient_margins).
    ///
    /// **UNSAFE for three or more robots**: a per-tick maximum along one trajectory is not a
    /// bound over multi-tick strategies (the operator can drag a third robot, which gains less
    /// lead per tick but more per unit of `p`'s progress); the two reproducers in
    /// tests/regression.rs overlap under a constant slowest operator.
    ///
    /// # Errors
    /// As [`sufficient_margins`](super::sufficient_margins).
    pub fn greedy_pace(robots: &[Timeline], tick_s: f64) -> Result<bool> {
        sim::check_single_pass(robots, tick_s, Variant::Conservative, 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables give every range's step exactly as a scan of the range does (the maxima do
    /// not round), including empty and out-of-range ranges, so the switch time's restricted
    /// steps are unchanged bit for bit by reading them from the tables.
    #[test]
    fn fast_rates_match_a_scan_of_every_range() {
        let n_ref = 23;
        let conf: Vec<bool> = (0..n_ref).map(|n| n % 5 != 2).collect();
        let grad: Vec<f64> = (0..n_ref)
            .map(|n| 1.0 + 0.37 * ((n * 7 % 11) as f64))
            .collect();
        let lo: Vec<f64> = grad
            .iter()
            .enumerate()
            .map(|(n, g)| g * (0.3 + 0.05 * (n % 4) as f64))
            .collect();
        let hi: Vec<f64> = grad.iter().map(|g| 2.0 * g).collect();
        let tl = Timeline::new(&conf, &grad, &lo, &hi, 0.0, 0.1).unwrap();
        let fast = FastRates::new(&tl);
        assert_eq!(fast.all().to_bits(), tl.max_rate_fast().to_bits());
        let max_step = 0.1 * tl.max_rate_fast();
        for a in 0..=n_ref + 2 {
            for b in 0..=n_ref + 2 {
                let scan = (a..b)
                    .filter(|&n| n < n_ref)
                    .map(|n| tl.rate_fast(n))
                    .fold(1.0, f64::max);
                let want = (max_step * (scan / tl.max_rate_fast()) * (1.0 + 1e-12)).min(max_step);
                let got = fast.step_within(&tl, max_step, a..b);
                assert_eq!(got.to_bits(), want.to_bits(), "range {a}..{b}");
            }
        }
        // By hand: the largest fast rate of samples 0..3 is sample 0's, 1/0.3 (bound 0.3·ψ̇_E).
        let by_hand = max_step * ((1.0 / 0.3) / tl.max_rate_fast()) * (1.0 + 1e-12);
        assert!((fast.step_within(&tl, max_step, 0..3) - by_hand).abs() < 1e-12);
    }
}
