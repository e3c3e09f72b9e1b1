//! Rounds at run time: the [`Coordinator`] advances N robots, each doing its one task, one
//! control tick at a time (§II-B5), under the run-time contract ([`Controller`]).

use std::sync::Arc;

use crate::adversary::AdversaryRun;
use crate::contract::{Controller, check_tick};
use crate::contract::{Operator, Tick};
use crate::cursor::{Cursors, operator_step};
use crate::error::{Error, Result};
use crate::holds::{Hold, Plans};
use crate::margins::operators::OperatorPlan;
use crate::monitor::Fault;
use crate::monitor::Monitor;
use crate::prealert::{self, Reach};
use crate::robots::{MAX_ROBOTS, OperatorCount, PerRobot, RobotFlags, check_count};
use crate::strategy::{Member, Mode, advance, first_waiting_start};
use crate::timeline::Timeline;
use crate::tol::clock_tolerance_s;

/// Phase of one robot at the start of a tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Schedule clock before `τ_i`: its start shifts with the running robots.
    Waiting,
    /// Running; `low_conf` is the confidence of the sample it is in at the tick start.
    Active { low_conf: bool },
    /// Schedule clock at its end.
    Finished,
}

/// Runtime coordinator (§II-B5): holds the timelines of `1 ≤ N ≤ MAX_ROBOTS` robots and
/// advances every robot's schedule clock one control period `tick_s` (real seconds) per
/// [`tick`](Coordinator::tick).
///
/// Rules per tick (modes, rates and bounds are read at each robot's sample at the tick start;
/// the rules are those of the `strategy` module, argued in docs/decisions.md):
/// - a low-confidence robot steps at the operator's rate: the [`Operator`]'s gradient `g`
///   (`ψ̇_E` when there is no correction), clamped to `[ψ̇min, ψ̇max]`, gives the
///   schedule-clock step `(ψ̇_E/g)·tick_s ∈ [S·tick_s, F·tick_s]`; it sets the pace;
/// - every other running high-confidence robot responds to it with Eq. 18 (its lead measured
///   after the low-confidence robot's step);
/// - no robot low-confidence: `HIGH-CONF` for N robots — the robot furthest ahead leads (robot
///   with the lowest index on a tie), Alg. 1 is run between it and the robot that can reach
///   least far this tick, and every other robot responds to the resulting pace, the furthest
///   clock all of them can reach (for two robots this is Alg. 1 exactly);
/// - two or more robots low-confidence (a state `sufficient_margins` excludes): every one of
///   them follows the operator, the one with the lowest index sets the pace;
/// - a robot running alone needs no adaptation: it runs on schedule (step `tick_s`) when
///   high-confidence, at the operator's rate when low-confidence;
/// - before a robot starts, its schedule clock moves to the new clock of the running robot
///   furthest behind, capped at its start `τ_i`: it starts at a tick boundary at its first
///   sample once every running robot has reached `τ_i` (its start shifts by the deviation of
///   the slowest running robot); with no robot running it runs on schedule;
/// - a finished robot drops out.
///
/// `low_conf[i]` is true when robot `i` moved during the tick and any low-confidence reference
/// sample intersects its traversed schedule-clock interval `[s_start − tol, s_end + tol]` (clipped
/// to `[τ_i, τ_i + |ψ_E|)`), `tol` = [`clock_tolerance_s`]: the tolerance only ever *adds*
/// low-confidence reports.
///
/// With one robot the coordinator just runs it (on schedule, or at the operator's rate while
/// low-confidence). [`tick`](Coordinator::tick) never allocates and is O(N) amortized: state is
/// kept in arrays of [`MAX_ROBOTS`], confidence is looked up through prefix counts and monotone
/// cursors (schedule clocks never decrease).
#[derive(Clone, Debug)]
pub struct Coordinator {
    /// The plans, shared: cloning a coordinator (to run the same schedule again, or to search
    /// over operator sequences) copies only its clocks.
    robots: Arc<[Timeline]>,
    /// The plans split at their holds (`crate::holds`): one leg per robot without holds.
    plans: Arc<Plans>,
    tick_s: f64,
    tol_s: f64,
    /// Each robot's rule clock on its current leg: the clock the rules of the tick move (at a
    /// hold, the clock of the legs not started, which follows the robots behind and may be
    /// below where the robot's previous leg ended).
    clock_s: [f64; MAX_ROBOTS],
    /// Each robot's schedule clock as reported ([`Coordinator::clock_s`]): its rule clock, but
    /// never below `floor_s` — non-decreasing from tick to tick.
    shown_s: [f64; MAX_ROBOTS],
    /// Per robot, the clock at which its previous leg ended (`−∞` on its first leg): where it
    /// stands on schedule while it waits at the hold.
    floor_s: [f64; MAX_ROBOTS],
    /// Each robot's current leg (index into `plans.legs`).
    leg: [usize; MAX_ROBOTS],
    /// Whether each robot's current leg has had its release rules met (latched).
    released: RobotFlags,
    /// The clock of every leg not yet started (they all follow the same rule 3, so they
    /// share it): the clock a robot's next leg has when its current leg ends.
    wait_clock_s: f64,
    cursors: [Cursors; MAX_ROBOTS],
    /// The run-time fault monitor (its tick count is the ticks run since the start or the
    /// last reset).
    monitor: Monitor,
    /// `k`: the operator's switch time in whole ticks ([`crate::switch_ticks`]; 0: none). A
    /// robot whose current leg has release rules leaves its hold `k` ticks after the tick
    /// start at which they all first held.
    switch_ticks: u64,
    /// Per robot, the ticks its current leg still waits for the switch time after its release
    /// rules all held (0: not counting).
    release_wait: [u64; MAX_ROBOTS],
    /// The pre-alert's tables, per leg ([`crate::prealert`]).
    reach: Arc<[Reach]>,
    /// Per leg, the least real time (s) from its end to the tick that reaches the first
    /// low-confidence run of its robot's later legs (`+∞`: none).
    after_fast_s: Arc<[f64]>,
    /// `M > 1` operators: the operator of every low-confidence run
    /// ([`crate::margins::operators`]); `None`: one operator, today's coordinator.
    operators: Option<Arc<OperatorPlan>>,
    /// `M > 1` operators in fixed sectors ([`Coordinator::sectored`]); `None` otherwise.
    sectors: Option<Arc<Sectors>>,
    /// Per sector (operator index), the clock of its legs not yet started: each sector's own
    /// `wait_clock_s`, moved by its robots alone. Unused without sectors.
    sector_wait_s: [f64; MAX_ROBOTS],
    /// The operator's load cap at run time ([`Coordinator::with_max_busy_share`]): the busy
    /// count of the round so far; `None` without a cap (`u = 1`), when nothing is counted.
    pace: Option<RoundPace>,
}

/// The load cap's count of a round (issue 41; docs/decisions.md, "The load cap in rounds at
/// run time: the rest after a round (issue 41)"): per operator, its busy ticks (ticks in which
/// a robot it supervises is low-confidence) and its changes of robot (a low-confidence tick of
/// another robot than its last one; each costs the switch time `k` ticks). The round's first
/// stretch is no change (its robot's previous stretch was in another round, which the rest
/// after that round paid for).
#[derive(Clone, Copy, Debug, PartialEq)]
struct RoundPace {
    /// `u`: the load cap, in `(0, 1)`.
    cap: f64,
    /// Per operator, the ticks with one of its robots low-confidence.
    busy: [u64; MAX_ROBOTS],
    /// Per operator, its changes of low-confidence robot.
    changes: [u64; MAX_ROBOTS],
    /// Per operator, the robot of its last low-confidence tick.
    last: [Option<u8>; MAX_ROBOTS],
}

impl RoundPace {
    fn new(cap: f64) -> RoundPace {
        RoundPace {
            cap,
            busy: [0; MAX_ROBOTS],
            changes: [0; MAX_ROBOTS],
            last: [None; MAX_ROBOTS],
        }
    }

    /// Counts a tick: each operator with a low-confidence robot in it is busy once (its first
    /// such robot; a second is a fault the monitor latches).
    fn observe(&mut self, tick: &Tick) {
        let mut seen = 0_u32;
        for i in 0..tick.low_conf.len() {
            if !tick.low_conf[i] {
                continue;
            }
            let o = usize::from(tick.operator[i].unwrap_or(0));
            if seen & (1 << o) != 0 {
                continue;
            }
            seen |= 1 << o;
            self.busy[o] += 1;
            // Robot indices are below MAX_ROBOTS = 16.
            let r = i as u8;
            if self.last[o].is_some_and(|q| q != r) {
                self.changes[o] += 1;
            }
            self.last[o] = Some(r);
        }
    }

    /// `B_o = busy_o + k·changes_o`: operator `o`'s busy ticks with `k` switch ticks per
    /// change.
    fn busy_ticks(&self, o: usize, k: u64) -> u64 {
        self.busy[o].saturating_add(k.saturating_mul(self.changes[o]))
    }

    /// The rest after `ticks` ticks of the round: `max_o n(B_o) − ticks`, 0 when negative.
    fn rest_ticks(&self, ticks: u64, k: u64) -> u64 {
        (0..MAX_ROBOTS)
            .map(|o| crate::cell::pace::ticks_for_share(self.busy_ticks(o, k), self.cap))
            .max()
            .unwrap_or(0)
            .saturating_sub(ticks)
    }
}

/// A rounds cell of `M` operators split into fixed sectors ([`Coordinator::sectored`]): each
/// robot belongs to one operator's sector, and each sector runs as its own one-operator round.
#[derive(Clone, Debug)]
struct Sectors {
    /// `M`, the operators (some may have an empty sector).
    m: usize,
    /// Robot `i`'s operator, `< m`.
    of: [u8; MAX_ROBOTS],
    /// The hold points as given to [`Coordinator::sectored`] (global robot indices; empty:
    /// none), kept to check the sectors again at another switch time.
    holds: Vec<Vec<Hold>>,
}

impl Coordinator {
    /// Builds a coordinator of `robots` (robot `i` at index `i`, e.g. an array of
    /// [`Timeline`]s) with every schedule clock at the earliest start `min_i τ_i`, after
    /// checking with [`sufficient_margins`](crate::sufficient_margins) at `tick_s` that no
    /// admissible operator can make two robots low-confidence in one tick.
    ///
    /// # Errors
    /// [`Error::RobotCount`] unless `1 ≤ N ≤ MAX_ROBOTS`; [`Error::BadParam`] if `tick_s` is
    /// not finite and > 0; [`Error::Unsafe`] if the margin check rejects the robots' plans at
    /// that tick.
    pub fn new(robots: impl Into<Vec<Timeline>>, tick_s: f64) -> Result<Coordinator> {
        let c = Coordinator::new_unchecked(robots, tick_s)?;
        if !crate::sufficient_margins(&c.robots, tick_s)? {
            return Err(Error::Unsafe { tick_s });
        }
        Ok(c)
    }

    /// [`Coordinator::new`] for plans with hold points (`crate::holds`): robot `i` stops at
    /// each of `holds[i]` and leaves as a robot starts, once its release rules hold; `holds`
    /// is empty (no holds: exactly [`Coordinator::new`]) or has one list per robot. The margin
    /// check is [`sufficient_margins_with_holds`](crate::margins::sufficient_margins_with_holds).
    ///
    /// # Errors
    /// As [`Coordinator::new`]; [`Error::BadHold`] or [`Error::LengthMismatch`] for holds
    /// that [`crate::holds::check_holds`] rejects or a wrong number of hold lists.
    pub fn with_holds(
        robots: impl Into<Vec<Timeline>>,
        holds: &[Vec<Hold>],
        tick_s: f64,
    ) -> Result<Coordinator> {
        let c = Coordinator::with_holds_unchecked(robots, holds, tick_s)?;
        if !crate::margins::check_plans(&c.plans, c.robots.len(), tick_s)? {
            return Err(Error::Unsafe { tick_s });
        }
        Ok(c)
    }

    /// [`Coordinator::with_holds`] without the margin check (see
    /// [`Coordinator::new_unchecked`]): the run-time rules of the holds apply all the same.
    ///
    /// # Errors
    /// As [`Coordinator::with_holds`], but never [`Error::Unsafe`].
    pub fn with_holds_unchecked(
        robots: impl Into<Vec<Timeline>>,
        holds: &[Vec<Hold>],
        tick_s: f64,
    ) -> Result<Coordinator> {
        let robots: Vec<Timeline> = robots.into();
        check_count(robots.len())?;
        let plans = Plans::new(&robots, holds)?;
        Coordinator::build(robots.into(), plans, tick_s)
    }

    /// [`Coordinator::new`] without the margin check: for tests and studies of what a schedule
    /// the check rejects does at run time, and for callers that have just run the check on the
    /// same plans and tick (`tandem_schedule::CheckedSchedule`). The run-time monitor still
    /// latches a [`Fault`] and holds a robot if two are ever low-confidence together.
    ///
    /// # Errors
    /// [`Error::RobotCount`] unless `1 ≤ N ≤ MAX_ROBOTS`; [`Error::BadParam`] if `tick_s` is
    /// not finite and > 0.
    pub fn new_unchecked(robots: impl Into<Vec<Timeline>>, tick_s: f64) -> Result<Coordinator> {
        Coordinator::with_holds_unchecked(robots, &[], tick_s)
    }

    fn build(robots: Arc<[Timeline]>, plans: Plans, tick_s: f64) -> Result<Coordinator> {
        check_tick(tick_s)?;
        // Without holds the legs are the robots' timelines: the same tolerance.
        let tol_s = clock_tolerance_s(&plans.legs, tick_s);
        let n = robots.len();
        let (reach, after_fast_s) = reach_tables(&plans, tick_s, tol_s);
        let mut c = Coordinator {
            robots,
            plans: Arc::new(plans),
            tick_s,
            tol_s,
            clock_s: [0.0; MAX_ROBOTS],
            shown_s: [0.0; MAX_ROBOTS],
            floor_s: [f64::NEG_INFINITY; MAX_ROBOTS],
            leg: [0; MAX_ROBOTS],
            released: RobotFlags::new(n),
            wait_clock_s: 0.0,
            cursors: [Cursors::default(); MAX_ROBOTS],
            monitor: Monitor::new(n),
            switch_ticks: 0,
            release_wait: [0; MAX_ROBOTS],
            reach: reach.into(),
            after_fast_s: after_fast_s.into(),
            operators: None,
            sectors: None,
            sector_wait_s: [0.0; MAX_ROBOTS],
            pace: None,
        };
        c.reset();
        Ok(c)
    }

    /// [`Coordinator::with_holds`] with the margin check and the run time of `params`
    /// ([`check_margins`](crate::check_margins)): with the operator's switch time
    /// `params.switch_s`, a robot leaves a hold with release rules no sooner than `k` =
    /// [`switch_ticks`](crate::switch_ticks) ticks after the tick start at which its rules all
    /// held, so a released robot's stretch starts at least `k` ticks after the awaited robots
    /// left theirs ([`Coordinator::with_switch_s`]). `holds` is empty or one list per robot.
    ///
    /// # Errors
    /// As [`Coordinator::with_holds`]; [`Error::BadParam`] for a bad `switch_s`.
    pub fn with_margins(
        robots: impl Into<Vec<Timeline>>,
        holds: &[Vec<Hold>],
        params: &crate::MarginParams,
    ) -> Result<Coordinator> {
        let c = Coordinator::with_holds_unchecked(robots, holds, params.tick_s)?
            .with_switch_s(params.switch_s)?;
        if !crate::margins::check_plans_switch(
            &c.plans,
            c.robots.len(),
            params.tick_s,
            c.switch_ticks,
        )? {
            return Err(Error::Unsafe {
                tick_s: params.tick_s,
            });
        }
        Ok(c)
    }

    /// The same coordinator with the operator's switch time `switch_s` (real s, finite and
    /// ≥ 0) at run time, reset to the start: a robot leaves a hold with release rules no
    /// sooner than `k` = [`switch_ticks`](crate::switch_ticks)`(switch_s, tick_s)` ticks after
    /// the tick start at which its rules all first held (docs/decisions.md, "The switch time
    /// at run time (issue 41)"). `switch_s = 0` changes nothing. The margin check that goes
    /// with it is [`check_margins`](crate::check_margins) at the same `switch_s`.
    ///
    /// # Errors
    /// [`Error::BadParam`] for a `switch_s` not finite and ≥ 0 or of more than 1e8 ticks.
    pub fn with_switch_s(mut self, switch_s: f64) -> Result<Coordinator> {
        if let Some(sec) = &self.sectors {
            // Sectors are checked at their switch time: check them again at this one.
            let of: Vec<usize> = (0..self.robots.len())
                .map(|i| usize::from(sec.of[i]))
                .collect();
            let params = crate::MarginParams {
                tick_s: self.tick_s,
                switch_s,
            };
            let mut c = Coordinator::sectored(
                self.robots.to_vec(),
                &sec.holds,
                &of,
                OperatorCount::new(sec.m)?,
                &params,
            )?;
            c.pace = self.pace.map(|p| RoundPace::new(p.cap));
            return Ok(c);
        }
        self.switch_ticks = crate::switch_ticks(switch_s, self.tick_s)?;
        if let Some(p) = &self.operators {
            let m = OperatorCount::new(p.operators())?;
            self = self.with_operators(m)?;
        }
        self.reset();
        Ok(self)
    }

    /// The same round run by `operators` = `M` operators, reset to the start (issue 44): every
    /// low-confidence run of every robot is assigned to one operator by
    /// [`assign_operators`](crate::margins::operators::assign_operators) at this coordinator's
    /// tick and switch time, which proves that no admissible inputs make more than `M` robots
    /// low-confidence in one tick, an operator supervise two robots at once, or a stretch
    /// change operator; [`tick_many`](Coordinator::tick_many) then takes one input per operator
    /// and [`Tick::operator`] reports the assignment. The fault monitor latches at more than
    /// `M`. `M = 1` returns the coordinator unchanged (today's check and rules, bit for bit).
    ///
    /// # Errors
    /// [`Error::BadParam`] (`operators`) for plans with holds (the hold rules of `M > 1`
    /// operators are not built); [`Error::Unsafe`] when the assignment needs more than `M`
    /// operators; those of [`assign_operators`](crate::margins::operators::assign_operators).
    pub fn with_operators(mut self, operators: OperatorCount) -> Result<Coordinator> {
        self.sectors = None;
        if operators.get() == 1 {
            self.operators = None;
            self.monitor = Monitor::new(self.robots.len());
            self.reset();
            return Ok(self);
        }
        if self.plans.has_holds() {
            return Err(Error::BadParam {
                name: "operators",
                why: "is more than 1 with hold points: rounds with holds run one operator; drop \
                      the holds or set operators to 1",
            });
        }
        let plan = crate::margins::operators::assign_operators(
            &self.robots,
            self.tick_s,
            operators,
            self.switch_ticks,
        )?
        .ok_or(Error::Unsafe {
            tick_s: self.tick_s,
        })?;
        self.operators = Some(Arc::new(plan));
        self.monitor = Monitor::new(self.robots.len()).with_operators(operators.get());
        self.reset();
        Ok(self)
    }

    /// A round of `M = operators` operators in fixed sectors (issue 44; docs/decisions.md,
    /// "M operators in rounds: sectors end to end" and "M operators in rounds: sectors with
    /// hold points"): robot `i` (of `robots`, global schedule clock) belongs to operator
    /// `sector_of[i] < M`'s sector, and the robots of each sector are one one-operator round
    /// run side by side with the others: every rule of the tick (the pace of the sector's
    /// low-confidence robot, Eq. 18, Alg. 1, the waits before a start, and with hold points
    /// the clock of the legs not started, rule 3, and the release rules with their switch-time
    /// count-down) is applied within each sector alone — one wait clock per sector — and the
    /// sector's low-confidence robot follows its own operator's input
    /// ([`tick_many`](Coordinator::tick_many)`(&[op_0, …, op_{M−1}])`). `holds` is empty (no
    /// holds) or one list per robot (global robot indices, as [`Coordinator::with_holds`]);
    /// a release rule names a robot of the same sector. Each sector's timelines and holds
    /// (renumbered within the sector) are checked with [`check_margins`](crate::check_margins)
    /// at `params` (tick, switch time), so in every tick at most one robot of each sector is
    /// low-confidence under every admissible input: at most `M` in all, each sector's
    /// stretches with its one operator (never handed over), each operator's switch time
    /// kept. [`Tick::operator`] reports the sector; the fault monitor latches when two robots
    /// of one sector are low-confidence. Each sector ticks exactly as its own
    /// [`Coordinator::with_margins`] would when it has a robot starting at the round's
    /// earliest start (as the planner's sectors: each from 0); otherwise it idles until then.
    ///
    /// # Errors
    /// [`Error::RobotCount`]; [`Error::LengthMismatch`] unless `sector_of` has one entry per
    /// robot and `holds` none or one list per robot; [`Error::BadParam`] (`sector_of`) for an
    /// entry `≥ M`, or for a bad tick or switch time; [`Error::BadHold`] for a hold that
    /// [`crate::holds::check_holds`] rejects or a release rule naming a robot of another
    /// sector; [`Error::Unsafe`] when a sector's plans fail the margin check.
    pub fn sectored(
        robots: impl Into<Vec<Timeline>>,
        holds: &[Vec<Hold>],
        sector_of: &[usize],
        operators: OperatorCount,
        params: &crate::MarginParams,
    ) -> Result<Coordinator> {
        let robots: Vec<Timeline> = robots.into();
        check_count(robots.len())?;
        if sector_of.len() != robots.len() {
            return Err(Error::LengthMismatch {
                what: "sector_of (one sector per robot)",
                expected: robots.len(),
                found: sector_of.len(),
            });
        }
        if !holds.is_empty() && holds.len() != robots.len() {
            return Err(Error::LengthMismatch {
                what: "holds",
                expected: robots.len(),
                found: holds.len(),
            });
        }
        let m = operators.get();
        let mut of = [0_u8; MAX_ROBOTS];
        for (i, &o) in sector_of.iter().enumerate() {
            if o >= m {
                return Err(Error::BadParam {
                    name: "sector_of",
                    why: "names an operator not below the operator count M",
                });
            }
            of[i] = o as u8;
        }
        // The global plans first: they check every hold (robot indices, samples, dwells).
        let mut c = Coordinator::with_holds_unchecked(robots, holds, params.tick_s)?;
        for (i, list) in holds.iter().enumerate() {
            for h in list {
                if h.after.iter().any(|a| sector_of[a.robot] != sector_of[i]) {
                    return Err(Error::BadHold {
                        robot: i,
                        ref_idx: h.ref_idx,
                        why: "waits for a robot of another sector (a sector runs as its own \
                              round: its release rules name robots of the same sector)",
                    });
                }
            }
        }
        for o in 0..m {
            let members: Vec<usize> = (0..c.robots.len()).filter(|&i| sector_of[i] == o).collect();
            if members.is_empty() {
                continue;
            }
            let sub: Vec<Timeline> = members.iter().map(|&i| c.robots[i].clone()).collect();
            // The sector's holds, its robots renumbered `0..` as its own coordinator has them.
            let sub_holds: Vec<Vec<Hold>> = if holds.is_empty() {
                Vec::new()
            } else {
                members
                    .iter()
                    .map(|&i| {
                        let mut list = holds[i].clone();
                        for h in &mut list {
                            for a in &mut h.after {
                                a.robot = members
                                    .iter()
                                    .position(|&j| j == a.robot)
                                    .expect("checked above: the same sector");
                            }
                        }
                        list
                    })
                    .collect()
            };
            if !crate::check_margins(&sub, &sub_holds, params)? {
                return Err(Error::Unsafe {
                    tick_s: params.tick_s,
                });
            }
        }
        c.switch_ticks = params.switch_ticks()?;
        c.monitor = Monitor::new(c.robots.len()).with_sectors(m, of);
        c.sectors = Some(Arc::new(Sectors {
            m,
            of,
            holds: holds.to_vec(),
        }));
        c.reset();
        Ok(c)
    }

    /// Robot `robot`'s operator in a sectored round ([`Coordinator::sectored`]); `None`
    /// otherwise (or for `robot ≥ N`).
    pub fn sector_of(&self, robot: usize) -> Option<usize> {
        let s = self.sectors.as_ref()?;
        (robot < self.robots.len()).then(|| usize::from(s.of[robot]))
    }

    /// `M`, the number of operators ([`Coordinator::with_operators`],
    /// [`Coordinator::sectored`]; 1 by default).
    pub fn operators(&self) -> usize {
        if let Some(s) = &self.sectors {
            return s.m;
        }
        self.operators.as_ref().map_or(1, |p| p.operators())
    }

    /// The operators' assignment of `M > 1` operators ([`Coordinator::with_operators`]);
    /// `None` with one operator.
    pub fn operator_plan(&self) -> Option<&OperatorPlan> {
        self.operators.as_deref()
    }

    /// The operator each robot low-confidence now is assigned to ([`Tick::operator`]): the
    /// operator of the run its sample belongs to; `Some(0)` for each with one operator. O(N).
    pub fn operator_now(&self) -> PerRobot<Option<u8>> {
        let lc = self.low_conf_now();
        if let Some(sec) = &self.sectors {
            let mut out = PerRobot::new(self.robots.len());
            for (i, o) in out.as_mut_slice().iter_mut().enumerate() {
                *o = lc[i].then_some(sec.of[i]);
            }
            return out;
        }
        let Some(p) = &self.operators else {
            return crate::contract::one_operator(&lc);
        };
        let mut out = PerRobot::new(self.robots.len());
        for (i, o) in out.as_mut_slice().iter_mut().enumerate() {
            *o = lc[i].then(|| p.operator_from(i, self.cursors[i].at));
        }
        out
    }

    /// `k`: the switch time in whole ticks this coordinator waits at a hold with release
    /// rules ([`Coordinator::with_switch_s`]; 0: none).
    pub fn switch_ticks(&self) -> u64 {
        self.switch_ticks
    }

    /// The same round with the operator's load cap `u = max_busy_share` (in `(0, 1]`) kept at
    /// run time, reset to the start (issue 41; docs/decisions.md, "The load cap in rounds at
    /// run time: the rest after a round (issue 41)"): the coordinator counts, per operator, the
    /// round's busy ticks `B` — ticks in which a robot it supervises is low-confidence, plus
    /// the switch time `k` ([`Coordinator::switch_ticks`]) per change of robot — and
    /// [`Coordinator::rest_ticks`] is the rest after the round that brings `B` to at most `u`
    /// times the round's ticks and the rest. Nothing inside the round changes (the margin
    /// check, the switch time and the pre-alert are untouched); whoever starts the next round
    /// starts it after the rest. `u = 1` counts nothing and never asks a rest (the coordinator
    /// of before, bit for bit). Keeps the cap across [`Coordinator::with_switch_s`]; set it
    /// after [`Coordinator::with_operators`] and [`Coordinator::sectored`], which build anew.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming `max_busy_share` for a value not in `(0, 1]`.
    pub fn with_max_busy_share(mut self, max_busy_share: f64) -> Result<Coordinator> {
        crate::cell::pace::check_max_busy_share(max_busy_share)?;
        self.pace = (max_busy_share < 1.0).then(|| RoundPace::new(max_busy_share));
        self.reset();
        Ok(self)
    }

    /// The operator's load cap `u` kept at run time ([`Coordinator::with_max_busy_share`];
    /// 1: none).
    pub fn max_busy_share(&self) -> f64 {
        self.pace.map_or(1.0, |p| p.cap)
    }

    /// `B`: the busy ticks of operator `operator` (`< M`) in the round so far — its ticks with
    /// a low-confidence robot plus `k` per change of robot — as the load cap counts them
    /// ([`Coordinator::with_max_busy_share`]); `None` without a cap or for an operator `≥ M`.
    pub fn busy_ticks(&self, operator: usize) -> Option<u64> {
        let p = self.pace.as_ref()?;
        (operator < self.operators()).then(|| p.busy_ticks(operator, self.switch_ticks))
    }

    /// The rest (ticks) the operators must get after the round so far before the next round
    /// starts, under the load cap `u` ([`Coordinator::with_max_busy_share`]): the least whole
    /// `n` with `B_o ≤ u·n` for every operator `o` (as computed in floating point), less the
    /// round's ticks ([`Coordinator::ticks`]), 0 when the round alone keeps the cap; 0 without
    /// a cap. Read once the round [`is_finished`](Coordinator::is_finished): the share of the
    /// round and its rest, `B_o / (ticks + rest)`, is then at most `u` for every operator
    /// whatever the operator did, hence over every run of whole rounds with their rests.
    pub fn rest_ticks(&self) -> u64 {
        self.pace
            .map_or(0, |p| p.rest_ticks(self.monitor.ticks(), self.switch_ticks))
    }

    /// [`Coordinator::rest_ticks`] in seconds (ticks times the tick).
    pub fn rest_s(&self) -> f64 {
        self.rest_ticks() as f64 * self.tick_s
    }

    /// The latched fault, if two robots have been low-confidence in one tick since the start,
    /// the last reset or the last [`Coordinator::clear_fault`].
    pub fn fault(&self) -> Option<Fault> {
        self.monitor.fault()
    }

    /// Clears the latched fault: the held robot moves again from the next tick on (once the
    /// operator has dealt with the robot that kept running).
    pub fn clear_fault(&mut self) {
        self.monitor.clear();
    }

    /// The timelines, robot `i` at index `i`.
    pub fn robots(&self) -> &[Timeline] {
        &self.robots
    }

    /// Number of robots `N`.
    pub fn n_robots(&self) -> usize {
        self.robots.len()
    }

    /// Control period (real seconds).
    pub fn tick_s(&self) -> f64 {
        self.tick_s
    }

    /// Each robot's schedule clock `s_i` (s, global/schedule-clock frame; with holds, on its
    /// current leg, which includes the planned dwells before it). Non-decreasing from tick to
    /// tick: at a hold it stays between the clock at which the robot's previous leg ended and
    /// the start of its next leg (the planned dwell), however far behind the robots it waits
    /// for are. Read a robot's reference time with [`Coordinator::ref_time_now`], not through
    /// [`Coordinator::robots`]: with holds that plan has no dwells.
    pub fn clock_s(&self) -> &[f64] {
        &self.shown_s[..self.robots.len()]
    }

    /// The clocks the rules move (the beam search's progress and clearance): with holds, a
    /// robot at a hold has the clock of the legs not started (rule 3).
    pub(crate) fn rule_clock_s(&self) -> &[f64] {
        &self.clock_s[..self.robots.len()]
    }

    /// Each robot's fractional reference time now (reference samples of its whole plan, in
    /// `[0, T_ref]`): Eq. 15 at its clock on its current leg, plus the leg's first sample. A
    /// robot at a hold is at the hold's sample. The value [`Tick::ref_time`] reported for
    /// the last tick (0 at the start); never decreases from tick to tick. O(N).
    pub fn ref_time_now(&self) -> PerRobot<f64> {
        let mut out = PerRobot::new(self.robots.len());
        for (i, t) in out.as_mut_slice().iter_mut().enumerate() {
            *t = self.ref_time_of(i);
        }
        out
    }

    /// Each robot's reference sample now: the sample containing [`Coordinator::ref_time_now`]
    /// (its last sample once it has finished). O(N).
    pub fn sample_now(&self) -> PerRobot<usize> {
        let mut out = PerRobot::new(self.robots.len());
        for (i, n) in out.as_mut_slice().iter_mut().enumerate() {
            let last = self.robots[i].n_ref() - 1;
            *n = (self.ref_time_of(i).floor() as usize).min(last);
        }
        out
    }

    /// Whether each robot runs in the next tick if it moves: started on its current leg,
    /// released, not finished and not held by the fault monitor. A robot at a hold, waiting
    /// for its start or finished executes no sample (a control loop sends it no command and
    /// logs nothing for it). O(N).
    pub fn running_now(&self) -> RobotFlags {
        let mut out = RobotFlags::new(self.robots.len());
        let held = self.monitor.held();
        for i in 0..self.robots.len() {
            let (r, s) = (self.cur(i), self.clock_s[i]);
            out.set(
                i,
                s >= r.start_s() && s < r.end_s() && self.released[i] && held != Some(i),
            );
        }
        out
    }

    /// Robot `i`'s reference time (its cursor `at` is the sample of its rule clock).
    fn ref_time_of(&self, i: usize) -> f64 {
        let r = self.cur(i);
        r.ref_time_in(self.cursors[i].at, self.clock_s[i]) + self.plans.ref0[self.leg[i]] as f64
    }

    /// Ticks run since the start or the last reset ([`Controller::ticks`]).
    pub fn ticks(&self) -> u64 {
        self.monitor.ticks()
    }

    /// Whether every robot has finished (with holds: its last leg).
    pub fn is_finished(&self) -> bool {
        (0..self.robots.len()).all(|i| self.finished(i))
    }

    /// Whether robot `i` has finished its last leg.
    fn finished(&self, i: usize) -> bool {
        self.leg[i] + 1 == self.plans.first_leg[i + 1] && self.clock_s[i] >= self.cur(i).end_s()
    }

    /// Each robot's completed tasks ([`Tick::tasks`]): 1 once it has finished its last leg,
    /// else 0. O(N).
    pub fn tasks_now(&self) -> PerRobot<u64> {
        let mut out = PerRobot::new(self.robots.len());
        for (i, k) in out.as_mut_slice().iter_mut().enumerate() {
            *k = u64::from(self.finished(i));
        }
        out
    }

    /// Whether each robot is stopped at a hold ([`Coordinator::at_hold`], [`Tick::waiting`]).
    /// O(N).
    pub fn waiting_now(&self) -> RobotFlags {
        let mut out = RobotFlags::new(self.robots.len());
        for i in 0..self.robots.len() {
            out.set(i, self.at_hold(i));
        }
        out
    }

    /// Robot `robot`'s planned end (schedule clock, s): the end of its last leg, the planned
    /// dwells at its holds included (without holds, its timeline's end `τ_i + |ψ_E|`). The
    /// latest of them is the schedule's `T_total` (Eq. 13) when the first robot starts at 0.
    ///
    /// # Panics
    /// If `robot ≥ N`.
    pub fn planned_end_s(&self, robot: usize) -> f64 {
        assert!(
            robot < self.robots.len(),
            "robot {robot} of {}",
            self.robots.len()
        );
        self.plans.legs[self.plans.first_leg[robot + 1] - 1].end_s()
    }

    /// Whether the plans have hold points or release rules (`crate::holds`).
    pub fn has_holds(&self) -> bool {
        self.plans.has_holds()
    }

    /// Whether robot `robot` is stopped at a hold (not its start): its current leg, after the
    /// first, has not started moving. Always `false` without holds.
    pub fn at_hold(&self, robot: usize) -> bool {
        robot < self.robots.len()
            && self.leg[robot] > self.plans.first_leg[robot]
            && (self.clock_s[robot] < self.cur(robot).start_s() || !self.released[robot])
    }

    /// The plan robot `robot` is on now: its timeline, or with holds its current leg (reference
    /// samples numbered from the leg's first, schedule clock including the dwells before it).
    ///
    /// # Panics
    /// If `robot ≥ N`.
    pub fn current_plan(&self, robot: usize) -> &Timeline {
        assert!(
            robot < self.robots.len(),
            "robot {robot} of {}",
            self.robots.len()
        );
        self.cur(robot)
    }

    /// The current leg of robot `i`.
    fn cur(&self, i: usize) -> &Timeline {
        &self.plans.legs[self.leg[i]]
    }

    /// Latches `released` for every robot whose current leg's release rules hold on the
    /// robots' states now (between ticks: at the next tick start). O(rules of the current
    /// legs).
    ///
    /// With a switch time of `k ≥ 1` ticks, a leg with release rules whose rules first all
    /// hold after a tick (`after_tick`) is released `k` ticks later: it counts down one per
    /// tick end (the rules are monotone, they keep holding), so it moves from the tick start
    /// `k` ticks after the one at which they first held. At the start (no tick run, nobody has
    /// been low-confidence) and for a leg without rules it is released at once.
    fn update_released(&mut self, after_tick: bool) {
        for i in 0..self.robots.len() {
            if self.released[i] {
                continue;
            }
            if self.release_wait[i] > 0 {
                self.release_wait[i] -= 1;
                if self.release_wait[i] == 0 {
                    self.released.set(i, true);
                }
            } else if self.rules_met(i) {
                if self.switch_ticks == 0
                    || !after_tick
                    || self.plans.rules_of(self.leg[i]).is_empty()
                {
                    self.released.set(i, true);
                } else {
                    self.release_wait[i] = self.switch_ticks;
                }
            }
        }
    }

    /// Whether every release rule of robot `i`'s current leg holds now.
    fn rules_met(&self, i: usize) -> bool {
        self.plans.rules_of(self.leg[i]).iter().all(|r| {
            let (a, s) = (r.robot, self.clock_s[r.robot]);
            self.leg[a] > r.leg
                || (self.leg[a] == r.leg
                    && (s >= self.plans.legs[r.leg].end_s() || s >= r.threshold_s + self.tol_s))
        })
    }

    /// Puts every schedule clock back at the earliest start, as [`Coordinator::new`] left them
    /// (no allocation: to run the same plan again).
    pub fn reset(&mut self) {
        let t0 = self
            .robots
            .iter()
            .map(Timeline::start_s)
            .fold(f64::INFINITY, f64::min);
        self.clock_s = [t0; MAX_ROBOTS];
        self.shown_s = [t0; MAX_ROBOTS];
        self.floor_s = [f64::NEG_INFINITY; MAX_ROBOTS];
        self.wait_clock_s = t0;
        self.sector_wait_s = [t0; MAX_ROBOTS];
        let n = self.robots.len();
        for i in 0..n {
            self.leg[i] = self.plans.first_leg[i];
        }
        self.released = RobotFlags::new(n);
        self.release_wait = [0; MAX_ROBOTS];
        self.update_released(false);
        self.cursors = [Cursors::default(); MAX_ROBOTS];
        self.monitor.reset();
        if let Some(p) = &mut self.pace {
            *p = RoundPace::new(p.cap);
        }
    }

    /// Whether each robot is running and low-confidence at its current schedule clock (Eq. 16
    /// at the tick start): the robot the next [`tick`](Coordinator::tick) moves at the
    /// operator's rate. O(N), no allocation.
    pub fn low_conf_now(&self) -> RobotFlags {
        let mut out = RobotFlags::new(self.robots.len());
        for i in 0..self.robots.len() {
            let (r, s, cur) = (self.cur(i), self.clock_s[i], &self.cursors[i]);
            out.set(
                i,
                s >= r.start_s() && s < r.end_s() && self.released[i] && !r.conf()[cur.at],
            );
        }
        out
    }

    /// The pre-alert now ([`Tick::next`], [`crate::prealert`]): per robot not finished, its
    /// next low-confidence run on its current leg or a later one, the least real time until the
    /// tick that starts it (the switch wait of a counting release included, holds and starts
    /// counted as 0) and, when nothing but its own motion stands between (the run on its
    /// current leg, released or counting down, started, not held by the fault monitor), the
    /// most. O(N), no allocation.
    pub fn pre_alert(&self) -> Option<crate::PreAlert> {
        let h = self.tick_s;
        let held = self.monitor.held();
        let cands = (0..self.robots.len()).filter_map(|i| {
            if self.finished(i) {
                return None;
            }
            let l = self.leg[i];
            let r = self.cur(i);
            let c = r.sample_clock_s();
            let reach = &self.reach[l];
            // A leg not moved yet (its clock at or below its start) has touched nothing: even
            // a run at its first sample is ahead.
            let (s, at, touched_s) = if self.clock_s[i] <= r.start_s() {
                (r.start_s(), 0, f64::NEG_INFINITY)
            } else {
                (self.clock_s[i], self.cursors[i].at, self.clock_s[i])
            };
            let wait = self.release_wait[i];
            // A leg not started waits for the rule clock to reach its start (rule 3).
            let due = if self.clock_s[i] < r.start_s() {
                self.ticks_before_leg_start(i, r.start_s())
            } else {
                0
            };
            if let Some(m) = reach.next_run(c, at, touched_s, self.tol_s) {
                let (lo, hi) = reach.to_run(c, at, s, m);
                let earliest = wait.max(due) + prealert::ticks_before_at_least(lo, h);
                let moves = (self.released[i] || wait > 0)
                    && self.clock_s[i] >= r.start_s()
                    && held != Some(i);
                let latest = moves
                    .then(|| prealert::ticks_before_at_most(hi, h).map(|t| t + wait))
                    .flatten();
                return Some((i, earliest, latest));
            }
            let after = self.after_fast_s[l];
            after.is_finite().then(|| {
                let lo = reach.fast_to_end(c, at, s) + after;
                let mut earliest = wait.max(due) + prealert::ticks_before_at_least(lo, h);
                // The next leg (its run on it or a later one) waits for the rule clock too.
                if l + 1 < self.plans.first_leg[i + 1] {
                    let next = self.plans.legs[l + 1].start_s();
                    earliest = earliest.max(self.ticks_before_leg_start(i, next));
                }
                (i, earliest, None)
            })
        });
        prealert::pick(cands, h)
    }

    /// Ticks before the tick in which robot `i`'s leg starting at schedule clock `start_s`
    /// can start at the soonest (a lower bound; issue 42). A leg not started moves with the
    /// rule clock of rule 3, which follows the running robot furthest behind: it reaches
    /// `start_s` only once every robot running now (other than `i`, not held by the fault
    /// monitor) has reached `start_s` or stopped running at its leg's end (its task's end or
    /// a hold), whichever comes first, each at its fastest. Without this the pre-alert took
    /// the wait for a start as 0 and named a robot whose start the schedule put far off
    /// (the three-robot study's rounds: robot 3, starting after two more stretches, named
    /// for 13 s while robot 1's stretch came next; 2 of 8 stretches pre-alerted < 1 s ahead).
    /// O(N), no allocation.
    fn ticks_before_leg_start(&self, i: usize, start_s: f64) -> u64 {
        let held = self.monitor.held();
        let mut ticks = 0;
        for j in 0..self.robots.len() {
            let r = self.cur(j);
            let s = self.clock_s[j];
            if j == i || held == Some(j) || !self.released[j] || s < r.start_s() || s >= r.end_s() {
                continue;
            }
            // In sectors a leg follows the running robots of its own sector alone.
            if let Some(sec) = &self.sectors
                && sec.of[j] != sec.of[i]
            {
                continue;
            }
            let x = (start_s.min(r.end_s()) - self.tol_s).max(s);
            let c = r.sample_clock_s();
            let lo =
                self.reach[self.leg[j]].fast_between(c, self.cursors[j].at, s, r.sample_at(x), x);
            ticks = ticks.max(prealert::ticks_before_at_least(lo, self.tick_s));
        }
        ticks
    }

    fn phase(&mut self, i: usize) -> Phase {
        let r = &self.plans.legs[self.leg[i]];
        let s = self.clock_s[i];
        if s >= r.end_s() {
            Phase::Finished
        } else if s < r.start_s() || !self.released[i] {
            Phase::Waiting
        } else {
            let n = r.advance_cursor(&mut self.cursors[i].at, s);
            Phase::Active {
                low_conf: !r.conf()[n],
            }
        }
    }

    /// Advances one control period with the operator's input `operator` for the
    /// low-confidence robot (ignored when no robot is low-confidence). Never allocates; O(N).
    ///
    /// # Errors
    /// [`Error::BadOperator`] for an [`Operator::Gradient`] that is NaN, infinite or ≤ 0;
    /// the coordinator is then unchanged.
    pub fn tick(&mut self, operator: Operator) -> Result<Tick> {
        if self.operators.is_some() || self.sectors.is_some() {
            return Err(Error::OperatorInputs {
                got: 1,
                want: self.operators(),
            });
        }
        let g = operator.validate()?;
        self.step(&[g])
    }

    /// Advances one control period with one input per operator: `inputs[o]` sets the timing
    /// of the low-confidence robot operator `o` is assigned to ([`Tick::operator`]; ignored
    /// when it has none). With one operator, [`tick`](Coordinator::tick). Never allocates;
    /// O(N).
    ///
    /// # Errors
    /// [`Error::OperatorInputs`] unless `inputs.len() == M`; [`Error::BadOperator`] for an
    /// inadmissible gradient; the coordinator is then unchanged.
    pub fn tick_many(&mut self, inputs: &[Operator]) -> Result<Tick> {
        if inputs.len() != self.operators() {
            return Err(Error::OperatorInputs {
                got: inputs.len(),
                want: self.operators(),
            });
        }
        if self.operators.is_none() && self.sectors.is_none() {
            return self.tick(inputs[0]);
        }
        let mut ops = [Operator::Scheduled; MAX_ROBOTS];
        for (o, op) in ops.iter_mut().zip(inputs) {
            *o = op.validate()?;
        }
        self.step(&ops[..inputs.len()])
    }

    /// One tick with the validated inputs `ops` (one per operator).
    fn step(&mut self, ops: &[Operator]) -> Result<Tick> {
        let g = ops[0];
        let plan = self.operators.clone();
        let sectors = self.sectors.clone();
        let n = self.robots.len();
        // The invariant "a robot never moves backwards", checked in debug builds: every
        // robot's reference time and reported clock at the tick end are at least those at
        // its start (docs/decisions.md, "A robot never moves backwards").
        #[cfg(debug_assertions)]
        let before = (self.ref_time_now(), self.shown_s);
        let mut members = [Member::idle(0.0, Mode::Finished); MAX_ROBOTS];
        let mut next_s = [0.0_f64; MAX_ROBOTS];
        let mut pace_robot = None;
        let held = self.monitor.held();
        for i in 0..n {
            let s = self.clock_s[i];
            if held == Some(i) {
                // Held by the fault monitor: it does not move and sets nothing.
                members[i] = Member::idle(s, Mode::Finished);
                continue;
            }
            members[i] = match self.phase(i) {
                Phase::Waiting => Member::idle(s, Mode::Waiting),
                Phase::Finished => Member::idle(s, Mode::Finished),
                Phase::Active { low_conf: true } => {
                    let g = match (&plan, &sectors) {
                        (_, Some(sec)) => ops[usize::from(sec.of[i])],
                        (None, None) => g,
                        (Some(p), None) => ops[usize::from(p.operator_from(i, self.cursors[i].at))],
                    };
                    next_s[i] = s + operator_step(self.cur(i), self.cursors[i].at, g, self.tick_s);
                    pace_robot.get_or_insert(i);
                    Member::idle(s, Mode::Low)
                }
                Phase::Active { low_conf: false } => Member {
                    clock_s: s,
                    mode: Mode::High,
                    rates: self.cur(i).rates(self.cursors[i].at),
                },
            };
        }
        // Per sector, the least start of its robots waiting to start (all robots: one sector).
        let mut sector_waiting_start = [f64::INFINITY; MAX_ROBOTS];
        if let Some(sec) = &sectors {
            // Each sector is its own round: the rules of the tick within its robots alone.
            for (o, fws) in sector_waiting_start.iter_mut().enumerate().take(sec.m) {
                let mut idx = [0_usize; MAX_ROBOTS];
                let mut sub = [Member::idle(0.0, Mode::Finished); MAX_ROBOTS];
                let mut sub_next = [0.0_f64; MAX_ROBOTS];
                let mut k = 0;
                let mut pace = None;
                for i in (0..n).filter(|&i| usize::from(sec.of[i]) == o) {
                    idx[k] = i;
                    sub[k] = members[i];
                    sub_next[k] = next_s[i];
                    if members[i].mode == Mode::Low {
                        pace.get_or_insert(k);
                    }
                    k += 1;
                }
                advance(&sub[..k], pace, self.tick_s, &mut sub_next[..k]);
                for j in 0..k {
                    next_s[idx[j]] = sub_next[j];
                }
                *fws = first_waiting_start(&sub[..k], |j| self.cur(idx[j]).start_s());
                if self.plans.has_holds() {
                    // The sector's legs not started: due at their starts, and its own wait
                    // clock (rule 3 among its robots), as below for one round.
                    let mut follow = f64::INFINITY;
                    for &i in &idx[..k] {
                        let next = self.leg[i] + 1;
                        if members[i].mode != Mode::Waiting && next < self.plans.first_leg[i + 1] {
                            *fws = fws.min(self.plans.legs[next].start_s());
                        }
                        if matches!(members[i].mode, Mode::High | Mode::Low) {
                            follow = follow.min(next_s[i]);
                        }
                    }
                    let w = self.sector_wait_s[o];
                    let follow = if follow.is_finite() {
                        follow
                    } else {
                        w + self.tick_s
                    };
                    self.sector_wait_s[o] = follow.min(*fws).max(w);
                }
            }
        } else {
            advance(&members[..n], pace_robot, self.tick_s, &mut next_s[..n]);
        }
        let mut out = Tick {
            ref_time: PerRobot::new(n),
            tasks: PerRobot::new(n),
            low_conf: RobotFlags::new(n),
            operator: PerRobot::new(n),
            running: RobotFlags::new(n),
            waiting: RobotFlags::new(n),
            fault: None,
            next: None,
        };
        let mut first_waiting_start = first_waiting_start(&members[..n], |i| self.cur(i).start_s());
        let has_holds = self.plans.has_holds();
        if has_holds && sectors.is_none() {
            // Legs not started yet wait too (rule 3 for every leg): a robot's next leg is due
            // at its start.
            for (i, m) in members[..n].iter().enumerate() {
                let next = self.leg[i] + 1;
                if m.mode != Mode::Waiting && next < self.plans.first_leg[i + 1] {
                    first_waiting_start = first_waiting_start.min(self.plans.legs[next].start_s());
                }
            }
            // The clock of the legs not started: rule 3's follow clock, capped.
            let follow = members[..n]
                .iter()
                .zip(&next_s[..n])
                .filter(|(m, _)| matches!(m.mode, Mode::High | Mode::Low))
                .map(|(_, &x)| x)
                .fold(f64::INFINITY, f64::min);
            let follow = if follow.is_finite() {
                follow
            } else {
                self.wait_clock_s + self.tick_s
            };
            self.wait_clock_s = follow.min(first_waiting_start).max(self.wait_clock_s);
        }
        for (i, m) in members[..n].iter().enumerate() {
            let r = &self.plans.legs[self.leg[i]];
            let s_old = self.clock_s[i];
            let waiting = m.mode == Mode::Waiting;
            let cap = if waiting {
                let fws = match &sectors {
                    Some(sec) => sector_waiting_start[usize::from(sec.of[i])],
                    None => first_waiting_start,
                };
                r.start_s().min(fws)
            } else {
                r.end_s()
            };
            let s_new = next_s[i].min(cap).max(s_old);
            self.clock_s[i] = s_new;
            let moved = s_new > s_old;
            out.running
                .set(i, moved && s_new > r.start_s() && s_old < r.end_s());
            if moved
                && s_new + self.tol_s >= r.start_s()
                && !waiting
                && s_old - self.tol_s < r.end_s()
            {
                let cur = &mut self.cursors[i];
                let lo = r.advance_cursor(&mut cur.lo, s_old - self.tol_s);
                let hi = r.advance_cursor(&mut cur.hi, s_new + self.tol_s);
                out.low_conf.set(i, r.any_low_conf(lo, hi));
                if let Some(sec) = &sectors
                    && out.low_conf[i]
                {
                    out.operator.as_mut_slice()[i] = Some(sec.of[i]);
                } else if let Some(p) = &plan
                    && out.low_conf[i]
                {
                    // The first run the traversed samples touch: a run touched with the next
                    // in one tick shares its window, hence its operator.
                    out.operator.as_mut_slice()[i] = Some(p.operator_from(i, lo));
                }
            }
            r.advance_cursor(&mut self.cursors[i].at, s_new);
            if has_holds && s_new >= r.end_s() && self.leg[i] + 1 < self.plans.first_leg[i + 1] {
                // The leg ended at a hold: the robot's next leg is current, its rule clock the
                // one every leg not yet started has (rule 3: it follows the running robot
                // furthest behind, so it may be below `s_new`). The robot stands at the hold's
                // sample; its reported clock stays at `s_new` until the rule clock passes it.
                let wait_clock_s = match &sectors {
                    Some(sec) => self.sector_wait_s[usize::from(sec.of[i])],
                    None => self.wait_clock_s,
                };
                self.floor_s[i] = s_new;
                self.leg[i] += 1;
                self.clock_s[i] = wait_clock_s;
                self.cursors[i] = Cursors::default();
                let next = &self.plans.legs[self.leg[i]];
                next.advance_cursor(&mut self.cursors[i].at, wait_clock_s);
                self.released.set(i, false);
                self.release_wait[i] = 0;
            }
            self.shown_s[i] = self.clock_s[i].max(self.floor_s[i]);
            out.ref_time.as_mut_slice()[i] = self.ref_time_of(i);
        }
        #[cfg(debug_assertions)]
        for i in 0..n {
            debug_assert!(
                out.ref_time[i] >= before.0[i] && self.shown_s[i] >= before.1[i],
                "robot {i} moved backwards in tick {}: reference time {} -> {}, clock {} -> {}",
                self.monitor.ticks(),
                before.0[i],
                out.ref_time[i],
                before.1[i],
                self.shown_s[i]
            );
        }
        self.update_released(true);
        for i in 0..n {
            out.tasks.as_mut_slice()[i] = u64::from(self.finished(i));
            out.waiting.set(i, self.at_hold(i));
        }
        out.next = self.pre_alert();
        if plan.is_none() && sectors.is_none() {
            out.operator = crate::contract::one_operator(&out.low_conf);
        }
        out.fault = self.monitor.observe(out.low_conf);
        if let Some(p) = &mut self.pace {
            p.observe(&out);
        }
        Ok(out)
    }
}

/// The pre-alert's tables of every leg of `plans` at tick `h` and clock tolerance `tol_s`:
/// per leg its [`Reach`] (a tick moves a robot between `S_n·h` and `max(1, F_n)·h`, at most
/// its largest step `M`) and the least real time from its end to its robot's next run on a
/// later leg (dwells and waits counted as 0).
fn reach_tables(plans: &Plans, h: f64, tol_s: f64) -> (Vec<Reach>, Vec<f64>) {
    let reach: Vec<Reach> = plans
        .legs
        .iter()
        .map(|leg| {
            let m = h * leg.max_rate_fast();
            Reach::new(
                leg,
                |n| leg.rate_slow(n).min(1.0),
                |n| leg.rate_fast(n).max(1.0),
                m,
                tol_s,
            )
        })
        .collect();
    let mut after = vec![f64::INFINITY; plans.legs.len()];
    for l in (0..plans.legs.len()).rev() {
        let robot = plans.robot_of[l];
        if l + 1 < plans.first_leg[robot + 1] {
            let next = &reach[l + 1];
            after[l] = next
                .fast_to_first_run()
                .unwrap_or_else(|| next.fast_total() + after[l + 1]);
        }
    }
    (reach, after)
}

impl Controller for Coordinator {
    fn n_robots(&self) -> usize {
        Coordinator::n_robots(self)
    }

    fn tick_s(&self) -> f64 {
        Coordinator::tick_s(self)
    }

    fn tick(&mut self, operator: Operator) -> Result<Tick> {
        Coordinator::tick(self, operator)
    }

    fn operators(&self) -> usize {
        Coordinator::operators(self)
    }

    fn tick_many(&mut self, inputs: &[Operator]) -> Result<Tick> {
        Coordinator::tick_many(self, inputs)
    }

    fn operator_now(&self) -> PerRobot<Option<u8>> {
        Coordinator::operator_now(self)
    }

    fn reset(&mut self) {
        Coordinator::reset(self);
    }

    fn fault(&self) -> Option<Fault> {
        Coordinator::fault(self)
    }

    fn clear_fault(&mut self) {
        Coordinator::clear_fault(self);
    }

    fn low_conf_now(&self) -> RobotFlags {
        Coordinator::low_conf_now(self)
    }

    fn running_now(&self) -> RobotFlags {
        Coordinator::running_now(self)
    }

    fn waiting_now(&self) -> RobotFlags {
        Coordinator::waiting_now(self)
    }

    fn pre_alert(&self) -> Option<crate::PreAlert> {
        Coordinator::pre_alert(self)
    }

    fn ref_time_now(&self) -> PerRobot<f64> {
        Coordinator::ref_time_now(self)
    }

    fn tasks_now(&self) -> PerRobot<u64> {
        Coordinator::tasks_now(self)
    }

    fn clock_s(&self) -> &[f64] {
        Coordinator::clock_s(self)
    }

    fn is_finished(&self) -> bool {
        Coordinator::is_finished(self)
    }

    fn ticks(&self) -> u64 {
        Coordinator::ticks(self)
    }

    fn beam_search(&self, width: u32, max_ticks: u64) -> Option<Result<AdversaryRun>> {
        // The search drives one operator's input; a round of `M > 1` operators has none.
        if self.operators.is_some() || self.sectors.is_some() {
            return None;
        }
        Some(crate::adversary::search::beam_search(
            self.clone(),
            width as usize,
            max_ticks,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [HC, LC, HC], gradients 1, bounds [½, 2], Δt_s = 1 (the 3-sample case of
    /// docs/decisions.md, "Alg. 2 as printed is not sound on a tick grid").
    fn three_sample(tau: f64) -> [Timeline; 2] {
        let conf = [true, false, true];
        let (g, lo, hi) = ([1.0; 3], [0.5; 3], [2.0; 3]);
        [
            Timeline::new(&conf, &g, &lo, &hi, 0.0, 1.0).unwrap(),
            Timeline::new(&conf, &g, &lo, &hi, tau, 1.0).unwrap(),
        ]
    }

    #[test]
    fn three_sample_case_drag_then_rush_overlaps() {
        let mut c = Coordinator::new_unchecked(three_sample(1.5), 1.0).unwrap();
        // Tick 0: robot 0 alone and HC runs on schedule (step 1); robot 1 waits, its clock
        // follows. Robot 0 ends exactly where its LC sample starts: the tolerance reports it LC.
        let t = c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s(), [1.0, 1.0]);
        assert_eq!(t.ref_time, [1.0, 0.0]);
        assert_eq!(t.running, [true, false]);
        assert_eq!(t.low_conf, [true, false]);
        // Tick 1: robot 0 LC, operator drags (g → ψ̇max = 2, step ½); robot 1's clock reaches
        // its start 1.5 (capped) and starts at the next tick boundary.
        let t = c.tick(Operator::Slowest).unwrap();
        assert_eq!(c.clock_s(), [1.5, 1.5]);
        assert_eq!(t.ref_time, [1.5, 0.0]);
        assert_eq!(t.low_conf, [true, false]);
        assert_eq!(t.running, [true, false]);
        // Tick 2: operator rushes robot 0 (g → ψ̇min = ½, step 2); robot 1 (HC) matches the
        // step (Eq. 18) and enters its LC sample (clock 2.5) while robot 0 is still in its own.
        let t = c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s(), [3.0, 3.5]);
        assert_eq!(t.ref_time, [3.0, 2.0]);
        assert_eq!(t.low_conf, [true, true]);
        assert!(c.robots()[0].end_s() <= c.clock_s()[0]);
        // The monitor latches the fault and holds robot 1, whose run of LC ticks began last
        // (in this tick; robot 0's in tick 0).
        let fault = Fault {
            tick: 2,
            low_conf: RobotFlags::from_slice(&[true, true]),
            stopped: 1,
        };
        assert_eq!(t.fault, Some(fault));
        assert_eq!(c.fault(), Some(fault));
        // Held: robot 1 does not move while the fault stands, and every tick reports it.
        let held_at = c.clock_s()[1];
        for _ in 0..3 {
            let t = c.tick(Operator::Slowest).unwrap();
            assert_eq!(t.fault, Some(fault));
            assert!(!t.running[1] && !t.low_conf[1]);
            assert_eq!(c.clock_s()[1], held_at);
        }
        assert!(!c.is_finished());
        // Cleared: robot 1 moves again and finishes; no new fault (robot 0 has finished).
        c.clear_fault();
        while !c.is_finished() {
            let t = c.tick(Operator::Slowest).unwrap();
            assert_eq!(t.fault, None);
        }
        // A reset clears everything.
        c.reset();
        assert_eq!(c.fault(), None);
    }

    /// Robot 0: six HC samples but sample 4, bounds [1, 1] (it can neither rush nor drag),
    /// a hold at 3 with a planned dwell of 1 s, released once robot 1 has passed sample 4;
    /// robot 1: LC on samples 1–3, bounds [½, 2]. Both start at 0, Δt_s = 1, tick ½.
    fn held_ahead() -> Coordinator {
        let g = [1.0; 6];
        let r0 = Timeline::new(&[true, true, true, true, false, true], &g, &g, &g, 0.0, 1.0);
        let conf1 = [true, false, false, false, true, true];
        let r1 = Timeline::new(&conf1, &g, &[0.5; 6], &[2.0; 6], 0.0, 1.0);
        let hold = Hold {
            dwell_s: 1.0,
            after: vec![crate::After {
                robot: 1,
                ref_idx: 4,
            }],
            ..Hold::at(3)
        };
        let holds = [vec![hold], vec![]];
        Coordinator::with_holds_unchecked([r0.unwrap(), r1.unwrap()], &holds, 0.5).unwrap()
    }

    #[test]
    fn a_robot_at_a_hold_never_moves_backwards() {
        let mut c = held_ahead();
        // Ticks 0–1: level, HC, both at robot 0's pace (its F = 1). Ticks 2–5: robot 1 is
        // dragged (step ¼), robot 0 cannot go slower than ½ and ends its leg at 3 in tick 5.
        let mut t = c.tick(Operator::Slowest).unwrap();
        for _ in 1..6 {
            t = c.tick(Operator::Slowest).unwrap();
        }
        assert!(c.at_hold(0));
        assert_eq!(t.ref_time, [3.0, 2.0]);
        // The tick reports robot 0 waiting at its hold, no task done yet.
        assert_eq!(t.waiting, [true, false]);
        assert_eq!(t.tasks, [0, 0]);
        assert_eq!(c.waiting_now(), t.waiting);
        // Cause 1: the held leg's rule clock is that of the legs not started, which follows
        // robot 1 (at 2); the reported clock stays where robot 0 is on schedule, 3.
        assert_eq!(c.rule_clock_s(), [2.0, 2.0]);
        assert_eq!(c.clock_s(), [3.0, 2.0]);
        assert_eq!(c.ref_time_now(), t.ref_time);
        assert_eq!(c.running_now(), [false, true]);
        assert_eq!(c.sample_now(), [3, 2]);
        let (mut last_ref, mut last_clock) = (c.ref_time_now(), c.clock_s().to_vec());
        let mut dwelt = 0;
        while !c.is_finished() {
            let t = c.tick(Operator::Slowest).unwrap();
            assert_eq!(t.ref_time, c.ref_time_now());
            for i in 0..2 {
                assert!(t.ref_time[i] >= last_ref[i] && c.clock_s()[i] >= last_clock[i]);
            }
            if c.at_hold(0) {
                assert_eq!(t.ref_time[0], 3.0);
                assert!(!c.running_now()[0]);
                // Cause 2: inside the dwell (clock in (3, 4]) the robot's plan without dwells
                // would place it past its hold.
                if c.clock_s()[0] > 3.0 {
                    dwelt += 1;
                    assert!(c.robots()[0].ref_time_at(c.clock_s()[0]) > 3.0);
                }
            }
            (last_ref, last_clock) = (t.ref_time, c.clock_s().to_vec());
        }
        assert!(dwelt > 0);
        assert_eq!(c.ref_time_now(), [6.0, 6.0]);
        assert_eq!(c.tasks_now(), [1, 1]);
        assert_eq!(c.waiting_now(), [false, false]);
        // The leg after the hold ends one dwell later than the plan without it.
        assert_eq!(c.clock_s()[0], c.robots()[0].end_s() + 1.0);
    }

    #[test]
    fn new_checks_the_margins_and_new_unchecked_does_not() {
        // τ = 3/2 is the unsafe three-sample case; τ = 3 (serial) is safe.
        assert!(matches!(
            Coordinator::new(three_sample(1.5), 1.0),
            Err(Error::Unsafe { tick_s }) if tick_s == 1.0
        ));
        assert!(Coordinator::new_unchecked(three_sample(1.5), 1.0).is_ok());
        let c = Coordinator::new(three_sample(3.0), 1.0).unwrap();
        assert_eq!(c.fault(), None);
        assert!(Coordinator::new(three_sample(3.0), 0.0).is_err());
    }

    #[test]
    fn start_shift_follows_the_first_robot() {
        // Robot 0: [LC, HC, HC, HC]; robot 1 scheduled to start at τ = 2; tick ½.
        let conf = [false, true, true, true];
        let (g, lo, hi) = ([1.0; 4], [0.5; 4], [2.0; 4]);
        let first_running_tick = |operator: Operator| {
            let r0 = Timeline::new(&conf, &g, &lo, &hi, 0.0, 1.0).unwrap();
            let r1 = Timeline::new(&conf, &g, &lo, &hi, 2.0, 1.0).unwrap();
            let mut c = Coordinator::new_unchecked([r0, r1], 0.5).unwrap();
            (0..100).find(|_| {
                let t = c.tick(operator).unwrap();
                // Until it starts, robot 1's clock equals robot 0's (capped at τ).
                assert!(t.running[1] || c.clock_s()[1] == c.clock_s()[0].min(2.0));
                t.running[1]
            })
        };
        // On schedule: LC sample in 2 ticks of ½, HC samples run on schedule → starts after 4.
        assert_eq!(first_running_tick(Operator::Scheduled), Some(4));
        // Dragged (step S·tick = ¼): the LC sample takes 4 ticks, robot 1 starts 1 s later.
        assert_eq!(first_running_tick(Operator::Slowest), Some(6));
        // Rushed (step F·tick = 1): one tick on the LC sample, robot 1 starts ½ s earlier.
        assert_eq!(first_running_tick(Operator::Fastest), Some(3));
    }

    /// The load cap's rest by hand: two rigid robots ([HC, LC, HC], gradients 1 with bounds
    /// [1, 1], Δt_s = 1 s, at a tick of 1 s), robot 1 starting where robot 0 ends (3 s). Each
    /// robot is low-confidence in all three of its ticks (its LC sample and the tick either side
    /// that touches it within the clock tolerance), so the round is 6 ticks, all busy, and one
    /// change of robot. At `u = ½` and no switch time `B = 6`, `n(B) = 12`: a rest of 6 ticks;
    /// with `δ = 2` s (`k = 2`) `B = 8`, `n = 16`, a rest of 10. Without a cap: no rest.
    #[test]
    fn the_rest_after_a_round_by_hand() {
        let conf = [true, false, true];
        let robot = |tau| Timeline::new(&conf, &[1.0; 3], &[1.0; 3], &[1.0; 3], tau, 1.0);
        let base =
            Coordinator::new_unchecked([robot(0.0).unwrap(), robot(3.0).unwrap()], 1.0).unwrap();
        for (switch_s, k, busy, rest) in [(0.0, 0, 6, 6), (2.0, 2, 8, 10)] {
            let mut c = base
                .clone()
                .with_switch_s(switch_s)
                .unwrap()
                .with_max_busy_share(0.5)
                .unwrap();
            assert_eq!(c.switch_ticks(), k);
            let mut lc = Vec::new();
            while !c.is_finished() {
                lc.push(c.tick(Operator::Scheduled).unwrap().low_conf.first());
            }
            assert_eq!(lc, [Some(0), Some(0), Some(0), Some(1), Some(1), Some(1)]);
            assert_eq!((c.busy_ticks(0), c.busy_ticks(1)), (Some(busy), None));
            assert_eq!(c.rest_ticks(), rest);
            assert_eq!(c.rest_s(), rest as f64);
            // The round and its rest keep the cap, and one tick less would not.
            assert!(busy as f64 <= 0.5 * (6 + rest) as f64);
            assert!(busy as f64 > 0.5 * (6 + rest - 1) as f64);
            // A reset starts a new round's count.
            c.reset();
            assert_eq!((c.busy_ticks(0), c.rest_ticks()), (Some(0), 0));
        }
        let mut free = base.clone().with_max_busy_share(1.0).unwrap();
        while !free.is_finished() {
            free.tick(Operator::Scheduled).unwrap();
        }
        assert_eq!((free.busy_ticks(0), free.rest_ticks()), (None, 0));
        assert_eq!(free.max_busy_share(), 1.0);
        for bad in [0.0, -0.5, 1.5, f64::NAN] {
            assert!(matches!(
                base.clone().with_max_busy_share(bad),
                Err(Error::BadParam {
                    name: "max_busy_share",
                    ..
                })
            ));
        }
    }

    #[test]
    fn both_high_confidence_follow_alg1() {
        // Robot 0: F = 2; robot 1: F = 1.5 (ψ̇min = 2/3); both HC, level → both step 1.5·tick.
        let conf = [true; 4];
        let g = [1.0; 4];
        let r0 = Timeline::new(&conf, &g, &[0.5; 4], &[2.0; 4], 0.0, 1.0).unwrap();
        let r1 = Timeline::new(&conf, &g, &[2.0 / 3.0; 4], &[2.0; 4], 0.0, 1.0).unwrap();
        let mut c = Coordinator::new_unchecked([r0, r1], 1.0).unwrap();
        let t = c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s(), [1.5, 1.5]);
        assert_eq!(t.ref_time, [1.5, 1.5]);
        assert_eq!(t.low_conf, [false, false]);
    }

    #[test]
    fn responder_matches_low_confidence_robot_and_stops_adapting_after_finish() {
        // Robot 0 is LC on sample 0 only and one sample long; robot 1 HC, both start at 0.
        let r0 = Timeline::new(&[false], &[1.0], &[0.5], &[2.0], 0.0, 1.0).unwrap();
        let r1 = Timeline::new(&[true; 4], &[1.0; 4], &[0.8; 4], &[1.25; 4], 0.0, 1.0).unwrap();
        let mut c = Coordinator::new_unchecked([r0, r1], 0.25).unwrap();
        // Operator gradient 0.8 (inside [½, 2]) → robot 0 steps (1/0.8)·¼ = 0.3125; robot 1
        // (F = 1.25) matches it exactly.
        let t = c.tick(Operator::Gradient(0.8)).unwrap();
        assert_eq!(c.clock_s(), [0.3125, 0.3125]);
        assert_eq!(t.low_conf, [true, false]);
        // Operator fastest: robot 0 steps 2·¼ = ½; robot 1 can only do 1.25·¼.
        c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s(), [0.8125, 0.625]);
        // Robot 0 finishes (clock capped at its end, 1.0); robot 1 then runs on schedule.
        c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s()[0], 1.0);
        let before = c.clock_s()[1];
        let t = c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s()[1], before + 0.25);
        assert_eq!(t.running, [false, true]);
        assert_eq!(t.low_conf, [false, false]);
        while !c.is_finished() {
            c.tick(Operator::Fastest).unwrap();
        }
        let t = c.tick(Operator::Fastest).unwrap();
        assert_eq!(t.ref_time, [1.0, 4.0]);
        assert_eq!(t.running, [false, false]);
    }

    #[test]
    fn bad_tick_and_bad_operator_are_errors() {
        let r = three_sample(1.5);
        assert!(matches!(
            Coordinator::new(r.clone(), 0.0),
            Err(Error::BadParam { name: "tick_s", .. })
        ));
        assert!(Coordinator::new(r.clone(), f64::NAN).is_err());
        let mut c = Coordinator::new_unchecked(r, 1.0).unwrap();
        c.tick(Operator::Scheduled).unwrap();
        // Robot 0 is now in its LC sample. A degenerate gradient is an error that leaves the
        // coordinator as it was, not "no correction".
        for g in [f64::NAN, f64::INFINITY, 0.0, -1.0] {
            let err = c.tick(Operator::Gradient(g)).unwrap_err();
            assert!(
                matches!(err, Error::BadOperator { gradient } if gradient.total_cmp(&g).is_eq()),
                "{err}"
            );
            assert_eq!(c.clock_s(), [1.0, 1.0]);
        }
        // No correction = the scheduled gradient: robot 0 steps exactly one tick.
        assert_eq!(c.low_conf_now(), [true, false]);
        c.tick(Operator::Scheduled).unwrap();
        assert_eq!(c.clock_s(), [2.0, 1.5]);
        // A gradient far outside the bounds is clamped: 1e9 drags like Slowest.
        let mut drag = Coordinator::new_unchecked(three_sample(1.5), 1.0).unwrap();
        let mut slow = drag.clone();
        drag.tick(Operator::Scheduled).unwrap();
        slow.tick(Operator::Scheduled).unwrap();
        drag.tick(Operator::Gradient(1e9)).unwrap();
        slow.tick(Operator::Slowest).unwrap();
        assert_eq!(drag.clock_s(), slow.clock_s());
    }

    #[test]
    fn reset_runs_the_same_plan_again() {
        let mut c = Coordinator::new_unchecked(three_sample(1.5), 0.5).unwrap();
        let ops = [
            Operator::Fastest,
            Operator::Slowest,
            Operator::Gradient(0.7),
        ];
        let run = |c: &mut Coordinator| {
            let mut ticks = Vec::new();
            let mut k = 0;
            while !c.is_finished() {
                let t = c.tick(ops[k % 3]).unwrap();
                // The plan is unsafe: release a held robot, as an operator would.
                if t.fault.is_some() {
                    c.clear_fault();
                }
                ticks.push(t);
                k += 1;
            }
            ticks
        };
        let first = run(&mut c);
        assert!(c.is_finished());
        c.reset();
        assert_eq!(c.clock_s(), [0.0, 0.0]);
        assert_eq!(c.low_conf_now(), [false, false]);
        assert_eq!(run(&mut c), first);
    }

    /// Robot 0: [LC, HC, HC, HC], F = 2, S = ½; robot 1: all HC with bounds [0.8, 1.25]
    /// (F = 1.25, S = 0.8); robot 2: all HC, F = 2, S = ½; robot 3 like robot 2 but starting at
    /// 3. Δt_s = 1, tick 1 s.
    fn four_robots() -> Vec<Timeline> {
        let (g, lo, hi) = ([1.0; 4], [0.5; 4], [2.0; 4]);
        vec![
            Timeline::new(&[false, true, true, true], &g, &lo, &hi, 0.0, 1.0).unwrap(),
            Timeline::new(&[true; 4], &g, &[0.8; 4], &[1.25; 4], 0.0, 1.0).unwrap(),
            Timeline::new(&[true; 4], &g, &lo, &hi, 0.0, 1.0).unwrap(),
            Timeline::new(&[true; 4], &g, &lo, &hi, 3.0, 1.0).unwrap(),
        ]
    }

    #[test]
    fn n_robots_respond_to_the_low_confidence_one_then_run_high_conf_together() {
        let mut c = Coordinator::new_unchecked(four_robots(), 1.0).unwrap();
        assert_eq!(c.n_robots(), 4);
        assert_eq!(c.low_conf_now(), [true, false, false, false]);
        // Tick 0: robot 0 LC, rushed (step F·tick = 2). Robot 1 cannot keep up (fastest
        // 1.25), robot 2 matches; robot 3 waits and follows the running robot furthest
        // behind (robot 1, at 1.25).
        let t = c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s(), [2.0, 1.25, 2.0, 1.25]);
        assert_eq!(t.low_conf, [true, false, false, false]);
        assert_eq!(t.running, [true, true, true, false]);
        assert!(!t.overlap());
        // Tick 1: nobody LC. Leader robot 0 (tie with robot 2, lowest index); robot 1 reaches
        // least far (2.5): Alg. 1 for (0, 1) lands both on 2.5, robot 2 responds to that pace
        // (step ½ = its slowest) — all level again; robot 3 follows to 2.5.
        c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s(), [2.5, 2.5, 2.5, 2.5]);
        // Tick 2: level, the pace is robot 1's fastest (3.75); robot 3 reaches its start 3.
        let t = c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s(), [3.75, 3.75, 3.75, 3.0]);
        assert_eq!(t.running, [true, true, true, false]);
        // Tick 3: robot 3 runs; robots 0 and 2 finish at 4 (capped), robot 1 too.
        let t = c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s()[..3], [4.0, 4.0, 4.0]);
        assert_eq!(t.running, [true, true, true, true]);
        // Then robot 3 runs alone, on schedule.
        let before = c.clock_s()[3];
        let t = c.tick(Operator::Fastest).unwrap();
        assert_eq!(c.clock_s()[3], before + 1.0);
        assert_eq!(t.running, [false, false, false, true]);
        while !c.is_finished() {
            c.tick(Operator::Scheduled).unwrap();
        }
        assert_eq!(c.clock_s(), [4.0, 4.0, 4.0, 7.0]);
    }

    #[test]
    fn two_low_confidence_robots_both_follow_the_operator() {
        // Robots 0 and 1 LC at sample 0 (a state a valid schedule excludes), robot 2 HC.
        let (g, lo, hi) = ([1.0; 2], [0.5; 2], [2.0; 2]);
        let lc = [false, true];
        let robots = vec![
            Timeline::new(&lc, &g, &lo, &hi, 0.0, 1.0).unwrap(),
            Timeline::new(&lc, &g, &[0.8; 2], &[1.25; 2], 0.0, 1.0).unwrap(),
            Timeline::new(&[true; 2], &g, &lo, &hi, 0.5, 1.0).unwrap(),
        ];
        let mut c = Coordinator::new_unchecked(robots, 1.0).unwrap();
        // Dragged: robot 0 steps ½, robot 1 steps 0.8; robot 2 waits for the robot furthest
        // behind (robot 0, at ½ = its start).
        let t = c.tick(Operator::Slowest).unwrap();
        assert_eq!(c.clock_s(), [0.5, 0.8, 0.5]);
        assert!(t.overlap());
        // The monitor holds robot 1 (both runs began in this tick: the higher index): robot 0
        // steps ½ to 1 and robot 2 (HC, at ½) responds to it and matches.
        assert_eq!(t.fault.map(|f| f.stopped), Some(1));
        c.tick(Operator::Slowest).unwrap();
        assert_eq!(c.clock_s(), [1.0, 0.8, 1.0]);
        // Released, robot 1 follows the operator again.
        c.clear_fault();
        c.tick(Operator::Slowest).unwrap();
        assert_eq!(c.clock_s()[1], 1.6);
    }

    #[test]
    fn one_robot_runs_alone_and_the_count_is_checked() {
        let r = three_sample(0.0);
        let mut c = Coordinator::new_unchecked(vec![r[0].clone()], 1.0).unwrap();
        let t = c.tick(Operator::Slowest).unwrap();
        assert_eq!(
            (c.clock_s(), t.low_conf),
            ([1.0].as_slice(), RobotFlags::from_slice(&[true]))
        );
        c.tick(Operator::Slowest).unwrap();
        assert_eq!(c.clock_s(), [1.5]);
        assert!(matches!(
            Coordinator::new(Vec::new(), 1.0),
            Err(Error::RobotCount { n: 0, .. })
        ));
        assert!(matches!(
            Coordinator::new(vec![r[0].clone(); MAX_ROBOTS + 1], 1.0),
            Err(Error::RobotCount { n: 17, max: 16 })
        ));
    }
}
