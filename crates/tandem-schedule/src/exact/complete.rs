//! Margin-aware completion: clearances between the robots' LC runs derived from the margin
//! check's own worst-case slacks (`tandem_realtime::pair_slacks`), placed by the exact search,
//! iterated (see "Margin-aware completion" in the module docs of [`super`]).

use std::collections::BTreeMap;

use rayon::prelude::*;
use tandem_realtime::{
    MarginParams, PairSlack, margin_slacks, pair_slacks, pair_slacks_with_holds,
};

use super::chain::Chain;
use super::search::{self, Clearance, Robot};
use super::shape::{held_schedule, shaped_schedule};
use super::stn;
use crate::problem::Problem;
use crate::schedule::Schedule;

/// A schedule whose margins the check accepted, with its `T_total` (s).
#[derive(Clone, Debug)]
pub(crate) struct Completed {
    pub(crate) schedule: Schedule,
    pub(crate) t_total_s: f64,
}

/// Tilts of the HC body shaping tried from a cold start (`shape::shaped_schedule`): one factor per
/// run, and two steps towards "slow first, fast last".
const FIRST_TILTS: [f64; 3] = [0.0, 0.25, 0.5];

/// Margin checks every start gets before the two most promising continue: enough for most
/// iterations to reach a first passing schedule (docs/decisions.md).
const FIRST_ROUND: usize = 4;

/// The completion's context: the problem, its chain and the margin check's scale.
pub(crate) struct Completion<'a> {
    problem: &'a Problem,
    chain: &'a Chain,
    tick_s: f64,
    /// `M` (schedule-clock s): `tick_s · max(1, largest F = ψ̇̄/ψ̇min of an LC sample)`, the
    /// least maximal step in one tick of any schedule (LC samples run at the mean); the check
    /// needs `c` at least that far short of its LC run when `p` leaves its own.
    max_step_s: f64,
    /// `ε` of the "robot 2 starts after robot 1's run ended" exception (s).
    after_start_s: f64,
    /// Piece budget of each search.
    max_pieces: usize,
    /// The held completion ([`Completion::held`]): `chain` has the usable holds, every switch
    /// into a run whose gap holds one is a release rule, the schedules plan their dwells.
    held: bool,
    /// The operator's switch time `δ` (s, ≥ 0; [`Completion::with_switch`]).
    switch_s: f64,
    /// The least clearance (s) between two robots' runs: `M`, plus `δ` with a switch time.
    min_clear_s: f64,
}

/// One pair of LC regions the margin check measured: the previous robot, the runs `(j, k)` of
/// the previous and the current region (`None` where not found), the slack (s) and the time
/// (s) from the end of the previous region to the start of the current one on schedule.
type Measured = (usize, Option<usize>, Option<usize>, f64, f64);

/// One clearance iteration (at one tilt, from one start), resumable: its clearances, every
/// pair's search state, the last order, the best schedule found and the checks spent.
#[derive(Clone, Debug)]
struct Trial {
    tilt: f64,
    clear: Clearance,
    pairs: BTreeMap<(usize, usize), PairState>,
    order: Option<Vec<Robot>>,
    best: Option<Completed>,
    checks: usize,
    /// Whether the iteration stopped by itself (no clearance moves, or no order left).
    done: bool,
}

impl Trial {
    fn new(tilt: f64, clear: Clearance) -> Trial {
        Trial {
            tilt,
            clear,
            pairs: BTreeMap::new(),
            order: None,
            best: None,
            checks: 0,
            done: false,
        }
    }

    /// `T_total` (s) of the best schedule found, `+∞` if none.
    fn t_total_s(&self) -> f64 {
        self.best.as_ref().map_or(f64::INFINITY, |b| b.t_total_s)
    }
}

impl<'a> Completion<'a> {
    /// The completion of `problem` (whose chain is `chain`) for the margin check at `tick_s`
    /// (s), each search holding at most `max_pieces` pieces.
    pub(crate) fn new(
        problem: &'a Problem,
        chain: &'a Chain,
        tick_s: f64,
        max_pieces: usize,
    ) -> Self {
        let (gmean, gmin) = (problem.grad_mean(), problem.grad_min());
        let f_lc = (0..problem.n_ref())
            .filter(|&n| !problem.conf()[n])
            .map(|n| gmean[n] / gmin[n])
            .fold(1.0, f64::max);
        let scale = 2.0 * chain.slowest_s().max(1.0);
        Completion {
            problem,
            chain,
            tick_s,
            max_step_s: tick_s * f_lc,
            after_start_s: 1e-6 * scale,
            max_pieces,
            held: false,
            switch_s: 0.0,
            min_clear_s: tick_s * f_lc,
        }
    }

    /// The completion with the operator's switch time `switch_s` (s, ≥ 0; issue 41): every
    /// clearance between two robots' runs starts at and stays at least `M + δ` (the planned
    /// switch (3δ) and room for the worst case), a release rule's travel waits `δ` more at its
    /// hold, robot 2's start gets no exception from the clearance, and the slacks are the
    /// margin check's with the switch time (`tandem_realtime::margin_slacks`), so what it
    /// returns passes `check_margins` with `δ`. `switch_s = 0` changes nothing (the same float
    /// operations).
    pub(crate) fn with_switch(self, switch_s: f64) -> Self {
        if switch_s > 0.0 {
            Completion {
                switch_s,
                min_clear_s: self.max_step_s + switch_s,
                ..self
            }
        } else {
            self
        }
    }

    /// `after_start` of the clearances: none with a switch time (robot 2's first run keeps
    /// `δ` from robot 1's last one even when it starts after it).
    fn after_start(&self) -> Option<f64> {
        (self.switch_s == 0.0).then_some(self.after_start_s)
    }

    /// Every pair's slack of the margin check on the timelines `tl` with the plan's `holds`:
    /// without a switch time [`pair_slacks`] (no holds) or [`pair_slacks_with_holds`]; with
    /// one [`margin_slacks`].
    fn slacks(
        &self,
        tl: &[tandem_realtime::Timeline],
        holds: Option<&[Vec<tandem_realtime::Hold>]>,
    ) -> Option<Vec<PairSlack>> {
        if self.switch_s > 0.0 {
            let params = MarginParams::new(self.tick_s).with_switch_s(self.switch_s);
            return margin_slacks(tl, holds.unwrap_or(&[]), &params).ok();
        }
        match holds {
            None => pair_slacks(tl, self.tick_s).ok(),
            Some(h) => pair_slacks_with_holds(tl, h, self.tick_s).ok(),
        }
    }

    /// The held completion of `problem`, whose chain with its usable holds is `chain`
    /// (`Chain::with_holds`): as [`Completion::new`], but a robot entering LC run `k` right
    /// after the other robot's run waits for it at the hold of gap `k` (the release rule of
    /// `tandem_realtime::holds::release_rules`) and travels from there at its fastest speeds,
    /// so the pair's clearance is that travel and the margin check accepts it without margin;
    /// the clearances of the other pairs are iterated on the margin check with holds as
    /// without. Robot 2 entering the first run after robot 1's without a hold in gap 0 starts
    /// after that run (a start rule cannot be planned as a dwell). Every schedule carries its
    /// dwells and release rules ([`Problem::with_release_rules`]), so its `T_total` is what a
    /// cell whose operator never corrects does.
    pub(crate) fn held(
        problem: &'a Problem,
        chain: &'a Chain,
        tick_s: f64,
        max_pieces: usize,
    ) -> Self {
        Completion {
            held: true,
            ..Completion::new(problem, chain, tick_s, max_pieces)
        }
    }

    /// The clearances of the release rules ([`Clearance::rules`]): per LC run `k`, the travel
    /// (s) from the hold of gap `k` to the run as `shape::held_schedule` plans it (its fastest
    /// plus one control tick of room, at most its slowest); `+∞` for run 0 without a hold;
    /// `None` elsewhere. Empty for the completion without holds.
    fn rule_clearances(&self) -> Vec<Option<f64>> {
        if !self.held {
            return Vec::new();
        }
        let dt = self.problem.dt_s();
        let (gmin, gmax) = (self.problem.grad_min(), self.problem.grad_max());
        (0..self.chain.n_lc())
            .map(|k| match self.chain.gap_hold[k] {
                Some(h) => {
                    let run = h..self.chain.lc_ref[k].0;
                    let fastest = gmin[run.clone()].iter().sum::<f64>() * dt;
                    let slowest = gmax[run].iter().sum::<f64>() * dt;
                    let travel = (fastest + self.tick_s).min(slowest);
                    Some(if self.switch_s > 0.0 {
                        travel + self.switch_s
                    } else {
                        travel
                    })
                }
                None if k == 0 => Some(f64::INFINITY),
                None => None,
            })
            .collect()
    }

    /// The schedule of `times` at `tilt`: shaped HC speeds; with holds, the planned dwells
    /// and the release rules (`None` if they cannot be made).
    fn schedule_of(&self, times: &stn::Times, tilt: f64) -> Option<Schedule> {
        if !self.held {
            return Some(shaped_schedule(
                self.problem,
                self.chain,
                times,
                tilt,
                self.tick_s,
            ));
        }
        let bare = held_schedule(self.problem, self.chain, times, tilt, self.tick_s);
        self.problem.with_release_rules(&bare).ok()
    }

    /// Every pair's slack from the margin check (with holds, the check with holds; a pair
    /// whose order a release rule enforces is left out), by the runs of its regions.
    fn measure(&self, schedule: &Schedule) -> Option<Vec<Measured>> {
        let tl = schedule.timelines(self.problem).ok()?;
        if !self.held || !schedule.has_holds() {
            let slacks = self.slacks(&tl, None)?;
            return Some(
                slacks
                    .iter()
                    .filter(|s| s.slack_s < f64::INFINITY)
                    .map(|s| {
                        (
                            s.prev_robot,
                            self.lc_index(s.prev.ref_start),
                            self.lc_index(s.cur.ref_start),
                            s.slack_s,
                            s.cur.start_s - s.prev.end_s,
                        )
                    })
                    .collect(),
            );
        }
        let slacks = self.slacks(&tl, Some(&schedule.holds))?;
        // The regions' runs: the check reports them on the robots' legs (a leg's samples
        // count from its hold), found back by robot and schedule-clock start.
        let mut run_of: BTreeMap<(usize, u64), usize> = BTreeMap::new();
        for (r, t) in tl.iter().enumerate() {
            let mut ref0 = 0;
            for leg in tandem_realtime::holds::legs(t, schedule.holds_of(r)).ok()? {
                for iv in leg.lc_intervals() {
                    if let Some(k) = self.lc_index(iv.ref_start + ref0) {
                        run_of.insert((r, iv.start_s.to_bits()), k);
                    }
                }
                ref0 += leg.n_ref();
            }
        }
        Some(
            slacks
                .iter()
                .filter(|s| s.slack_s < f64::INFINITY)
                .map(|s| {
                    (
                        s.prev_robot,
                        run_of
                            .get(&(s.prev_robot, s.prev.start_s.to_bits()))
                            .copied(),
                        run_of.get(&(s.cur_robot, s.cur.start_s.to_bits())).copied(),
                        s.slack_s,
                        s.cur.start_s - s.prev.end_s,
                    )
                })
                .collect(),
        )
    }

    /// The least-`T_total` schedule this completion finds that the margin check accepts and
    /// that beats `cap_s`, spending at most `budget` margin checks; with the number spent.
    ///
    /// Clearance iterations from several starts: with `cold`, one per tilt of [`FIRST_TILTS`]
    /// from every clearance at `M`; and one per schedule of `warm` (schedules that pass the
    /// check, e.g. the previous one or the sampler's), at tilt 0, from the clearances that
    /// schedule keeps between its pairs and no other pair allowed (so the search starts from
    /// that schedule's order). All run [`FIRST_ROUND`] checks in parallel; then the two best
    /// (least `T_total`, unfinished first) continue in parallel with the rest of the budget.
    pub(crate) fn run(
        &self,
        cap_s: f64,
        budget: usize,
        cold: bool,
        warm: &[&Schedule],
    ) -> (Option<Completed>, usize) {
        let mut trials: Vec<Trial> = Vec::new();
        if cold {
            let all = Clearance {
                rules: self.rule_clearances(),
                ..Clearance::uniform(self.min_clear_s, self.after_start())
            };
            trials.extend(FIRST_TILTS.iter().map(|&t| Trial::new(t, all.clone())));
        }
        if !self.held {
            trials.extend(
                warm.iter()
                    .filter_map(|s| Some(Trial::new(0.0, self.clearances_of(s)?))),
            );
        }
        if budget == 0 || trials.is_empty() {
            return (None, 0);
        }
        let first = FIRST_ROUND.min(budget / trials.len()).max(1);
        trials
            .par_iter_mut()
            .for_each(|t| self.iterate(t, cap_s, first));
        let mut spent: usize = trials.iter().map(|t| t.checks).sum();
        // The two most promising continue: unfinished before finished, then by T_total (the
        // start order on ties).
        let mut rank: Vec<usize> = (0..trials.len()).collect();
        rank.sort_by(|&a, &b| {
            let (ta, tb) = (&trials[a], &trials[b]);
            ta.done
                .cmp(&tb.done)
                .then(ta.t_total_s().total_cmp(&tb.t_total_s()))
        });
        rank.truncate(2);
        rank.retain(|&i| !trials[i].done);
        if spent < budget && !rank.is_empty() {
            let share = (budget - spent) / rank.len();
            let mut go: Vec<Trial> = rank.iter().map(|&i| trials[i].clone()).collect();
            go.par_iter_mut()
                .for_each(|t| self.iterate(t, cap_s, t.checks + share));
            for (&i, t) in rank.iter().zip(go) {
                spent += t.checks - trials[i].checks;
                trials[i] = t;
            }
        }
        let best = trials
            .iter()
            .filter(|t| t.best.is_some())
            .min_by(|a, b| a.t_total_s().total_cmp(&b.t_total_s()));
        (best.and_then(|t| t.best.clone()), spent)
    }

    /// The clearances `schedule` keeps: for every two consecutive LC regions of different
    /// robots, the time from the end of the earlier to the start of the later (s), by the
    /// pair `(j, k)` of their runs (the larger if the pair comes twice); every other pair
    /// forbidden (infinite clearance). `None` if the schedule cannot be laid out, has no such
    /// pair, or overlaps.
    fn clearances_of(&self, schedule: &Schedule) -> Option<Clearance> {
        let tl = schedule.timelines(self.problem).ok()?;
        let mut regions: Vec<(f64, f64, usize, usize)> = Vec::new();
        for (r, t) in tl.iter().enumerate() {
            for iv in t.lc_intervals() {
                regions.push((iv.start_s, iv.end_s, r, self.lc_index(iv.ref_start)?));
            }
        }
        regions.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.2.cmp(&b.2)));
        let mut clear = Clearance::uniform(f64::INFINITY, self.after_start());
        for w in regions.windows(2) {
            let ((_, end, pr, j), (start, _, r, k)) = (w[0], w[1]);
            if pr != r {
                let gap = start - end;
                if gap.is_nan() || gap < 0.0 {
                    return None;
                }
                let entry = clear.pairs.entry((j, k)).or_insert(gap);
                *entry = entry.max(gap).max(self.min_clear_s);
            }
        }
        (!clear.pairs.is_empty()).then_some(clear)
    }

    /// Runs the clearance iteration `trial` until it has spent `until` margin checks or stops:
    /// solve the search with the clearances (its best order below `cap_s`), time the order,
    /// shape it at the trial's tilt, read every pair's worst-case slack from the check, and
    /// move each pair's clearance towards a slack of a tenth of `M` ([`PairState::update`]);
    /// keep the best schedule whose pairs all pass. Stops when no clearance moves.
    fn iterate(&self, trial: &mut Trial, cap_s: f64, until: usize) {
        let tilt = trial.tilt;
        let target = 0.1 * self.max_step_s;
        let Trial {
            clear,
            pairs,
            order,
            best,
            checks,
            done,
            ..
        } = trial;
        while *checks < until && !*done {
            *done = true;
            match search::search(self.chain, clear, cap_s, self.max_pieces).0 {
                search::Outcome::Done(Some(found)) => {
                    *order = Some(found.order);
                }
                // Nothing beats the cap with these clearances (or the budget ran out): keep
                // timing the last order, whose clearances may still come down.
                _ if order.is_some() => {}
                _ => break,
            }
            let Some(times) = order
                .as_deref()
                .and_then(|o| stn::earliest(self.chain, o, clear))
            else {
                break;
            };
            let Some(schedule) = self.schedule_of(&times, tilt) else {
                break;
            };
            *checks += 1;
            let Some(slacks) = self.measure(&schedule) else {
                break;
            };
            let t = schedule.t_total_s(self.problem.dt_s());
            let passes = slacks.iter().all(|s| s.3 > 0.0);
            if passes && t < cap_s && best.as_ref().is_none_or(|b| t < b.t_total_s) {
                *best = Some(Completed {
                    schedule,
                    t_total_s: t,
                });
            }
            // Per role (the previous robot), whether a failing pair came already: a later
            // pair's deficit includes the lead carried over from the earlier one, so only the
            // first failing pair of each role moves by its whole deficit, the others at most
            // double their clearance per round.
            let mut failed = [false; 2];
            let mut raised: Vec<f64> = Vec::new();
            for &(prev_robot, j, k, slack, apart_s) in &slacks {
                let (Some(j), Some(k)) = (j, k) else {
                    continue;
                };
                if clear.is_rule(k) {
                    continue;
                }
                let slack = slack.max(-self.chain.slowest_s());
                // Raise failing pairs; once all pass, lower those with room to spare.
                let aim = slack <= 0.0 || (passes && slack > 2.0 * target);
                let delta = clear.between(j, k);
                // With holds, the clearance the schedule kept (other lags can keep the pair
                // further apart than its clearance asks): steps start from there, not from a
                // clearance that did not bind.
                let delta = if self.held && apart_s.is_finite() {
                    delta.max(apart_s)
                } else {
                    delta
                };
                let max_growth = if failed[prev_robot] {
                    2.0
                } else {
                    f64::INFINITY
                };
                failed[prev_robot] |= slack <= 0.0;
                let next = pairs.entry((j, k)).or_insert(PairState::NEW).update(
                    delta,
                    slack,
                    aim.then_some(target),
                    target,
                    max_growth,
                );
                let next = next.max(self.min_clear_s);
                if next > delta {
                    raised.push(next);
                }
                if next != delta {
                    clear.pairs.insert((j, k), next);
                    *done = false;
                }
            }
            // Pairs the search has not tried yet start from what a switch of robots has
            // typically needed so far (the median of this round's raised clearances): with
            // hundreds of LC islands, learning every pair from `M` would let the search run
            // from one untried switch to the next.
            if !raised.is_empty() {
                raised.sort_by(f64::total_cmp);
                clear.base = clear.base.max(raised[raised.len() / 2]);
            }
        }
    }

    /// Index `k` of the LC run starting at reference sample `ref_start`.
    fn lc_index(&self, ref_start: usize) -> Option<usize> {
        self.chain
            .lc_ref
            .binary_search_by_key(&ref_start, |r| r.0)
            .ok()
    }
}

/// One pair's clearance search (s): the largest clearance seen failing, the smallest seen
/// passing, and the last measurement `(clearance, slack)`.
#[derive(Clone, Copy, Debug)]
struct PairState {
    fail: f64,
    pass: f64,
    last: Option<(f64, f64)>,
}

impl PairState {
    const NEW: PairState = PairState {
        fail: f64::NEG_INFINITY,
        pass: f64::INFINITY,
        last: None,
    };

    /// Records that clearance `delta` gave `slack` and returns the next clearance (s): `delta`
    /// without a `goal`; else a secant step towards slack `goal` (the first one assuming the
    /// slack moves one for one with the clearance), at most halving the clearance and at most
    /// multiplying it by `max_growth`, kept strictly inside the bracket of failing and passing
    /// clearances (bisecting it when the step leaves it). A bracket narrower than
    /// `resolution` settles on its passing end; an end the new measurement contradicts (the
    /// other pairs' clearances move too) is dropped.
    fn update(
        &mut self,
        delta: f64,
        slack: f64,
        goal: Option<f64>,
        resolution: f64,
        max_growth: f64,
    ) -> f64 {
        // The other pairs move too, so an old end of the bracket the new measurement
        // contradicts is dropped.
        if slack > 0.0 {
            self.pass = self.pass.min(delta);
            if self.fail >= delta {
                self.fail = f64::NEG_INFINITY;
            }
        } else {
            self.fail = self.fail.max(delta);
            if self.pass <= delta {
                self.pass = f64::INFINITY;
            }
        }
        let last = self.last.replace((delta, slack));
        let Some(goal) = goal else {
            return delta;
        };
        if self.pass - self.fail <= resolution {
            return self.pass;
        }
        // Below this measured sensitivity, a clearance is raised by at most 10× its deficit.
        const MIN_SENSITIVITY: f64 = 0.1;
        let sens = match last {
            Some((d0, s0)) if d0 != delta && (slack - s0) / (delta - d0) > 0.0 => {
                ((slack - s0) / (delta - d0)).max(MIN_SENSITIVITY)
            }
            _ => 1.0,
        };
        let step = (delta + (goal - slack) / sens).clamp(0.5 * delta, max_growth * delta);
        if step > self.fail && step < self.pass {
            step
        } else if self.fail.is_finite() && self.pass.is_finite() {
            0.5 * (self.fail + self.pass)
        } else {
            step
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pair_state_brackets_and_settles() {
        let mut s = PairState::NEW;
        // Fails at 1 by 0.5: first step assumes one for one, 1 + 0.6 = 1.6.
        assert_eq!(s.update(1.0, -0.5, Some(0.1), 0.01, 2.0), 1.6);
        // Passes at 1.6 with 0.7 to spare: measured sensitivity (0.7 + 0.5)/0.6 = 2, so
        // lowering to 1.6 − 0.6/2 = 1.3, inside the bracket (1, 1.6).
        let next = s.update(1.6, 0.7, Some(0.1), 0.01, 2.0);
        assert!((next - 1.3).abs() < 1e-12, "{next}");
        // A step leaving the bracket bisects it: passing at 2 (nothing asked), then failing at
        // 1 by 1: the secant (sensitivity 1.05/1) says 2.05, capped at double, 2, which is the
        // passing end: the midpoint 1.5.
        let mut s = PairState::NEW;
        assert_eq!(s.update(2.0, 0.05, None, 0.01, 2.0), 2.0);
        assert_eq!(s.update(1.0, -1.0, Some(0.1), 0.01, 2.0), 1.5);
        // Growth is capped: failing at 0.1 by 1 would step to 1.2, at most doubling: 0.2;
        // uncapped, 1.2.
        let mut s = PairState::NEW;
        assert_eq!(s.update(0.1, -1.0, Some(0.1), 0.01, 2.0), 0.2);
        let mut s = PairState::NEW;
        assert!((s.update(0.1, -1.0, Some(0.1), 0.01, f64::INFINITY) - 1.2).abs() < 1e-12);
        // A bracket narrower than the resolution settles on its passing end.
        let mut s = PairState::NEW;
        s.update(1.0, -0.1, Some(0.1), 0.5, 2.0);
        assert_eq!(s.update(1.2, 0.05, Some(0.1), 0.5, 2.0), 1.2);
        // A measurement contradicting the bracket drops the stale end: passing at 1, then
        // failing at 1 (other pairs moved): no passing end left, a plain secant step up.
        let mut s = PairState::NEW;
        s.update(1.0, 0.5, None, 0.01, 2.0);
        assert_eq!(s.update(1.0, -0.1, Some(0.1), 0.01, 2.0), 1.2);
        // Without a goal the clearance stays.
        let mut s = PairState::NEW;
        assert_eq!(s.update(0.7, 0.3, None, 0.01, 2.0), 0.7);
    }
}
