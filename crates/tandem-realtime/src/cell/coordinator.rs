//! The continuous cell's run-time coordinator, [`ContinuousCoordinator`] (the token rule of
//! [the cell's docs](crate::cell)), and its adversary run [`run_cell`].

use std::sync::Arc;

use rand::Rng;

use super::groups::{Group, Token, groups, mixed_token_sequence, token_sequence};
use super::nest;
use super::pace::Pace;
use crate::adversary::{Adversary, AdversaryRun};
use crate::contract::{Controller, Operator, Tick, check_tick};
use crate::cursor::{Cursors, operator_step};
use crate::error::{Error, Result};
use crate::monitor::{Fault, Monitor};
use crate::prealert::{self, Reach};
use crate::robots::{MAX_ROBOTS, PerRobot, RobotFlags, check_count};
use crate::timeline::Timeline;
use crate::tol::clock_tolerance_s;

/// The operators of a cell (issue 44): who holds which entry of the token sequence, and each
/// operator's and robot's history for the switch time and the preferred operator.
#[derive(Clone, Debug, Default)]
struct Staff {
    /// Per operator, the entry it was granted and has not released (the robot has not left
    /// the group yet), with the entry's `(pos, passes)`: at most `M` robots inside.
    slot: [Option<(Token, usize, u64)>; MAX_ROBOTS],
    /// Per robot, the operator it is assigned to (the inverse of `slot`).
    assigned: [Option<u8>; MAX_ROBOTS],
    /// Per robot, the operator it was last assigned to (preferred at its next grant).
    last_op: [Option<u8>; MAX_ROBOTS],
    /// Per operator, the robot it last released (that left its group) and the index of the
    /// first tick after the one in which it left (`None`: nobody yet). The operator is granted
    /// to another robot only from tick `left + k` on (carried over by a hand-over).
    last_left: [Option<(usize, u64)>; MAX_ROBOTS],
    /// `M > 1` only: per robot, the `(pos, passes)` of its next entry of the token sequence
    /// not yet granted (`None`: no entry, a task without low confidence). Granted in the
    /// order of these among the robots waiting at their gates ([`ContinuousCoordinator::grant`]).
    next_entry: [Option<(usize, u64)>; MAX_ROBOTS],
    /// A sectored cell only: per operator, the `(pos, passes)` of its sector's next entry to
    /// grant (`pos` in the operator's range of the token sequence, `passes` the completed
    /// passes through that range): each sector's one-operator token.
    cursor: [(usize, u64); MAX_ROBOTS],
}

/// The sectors of a sectored cell (issue 44, [`ContinuousCoordinator::sectored`]): a fixed
/// partition of the robots to the operators, operator `o` serving only sector `o`'s robots in
/// its own one-operator token sequence.
#[derive(Clone, Copy, Debug)]
struct Sectors {
    /// Per robot, its sector (its operator).
    of: [u8; MAX_ROBOTS],
    /// Per operator, its sector's token sequence: `tokens[start..end]` (empty: no robots).
    range: [(usize, usize); MAX_ROBOTS],
}

/// One sector of a sectored continuous cell ([`ContinuousCoordinator::sectored`]): its robots
/// (ascending cell indices) and its one-operator cyclic order of stretches `(j, lc)`, `j`
/// indexing the sector's robots.
pub type SectorOrder = (Vec<usize>, Vec<(usize, usize)>);

/// What one [`ContinuousCoordinator::tick`] did: the one [`Tick`] of every controller (its
/// `at_gate` is [`Tick::waiting`]).
#[deprecated(
    note = "the one tick type of every controller is `tandem_realtime::Tick` (`at_gate` is its `waiting`)"
)]
pub type CellTick = Tick;

/// The run-time coordinator of a continuous cell ([cell docs](crate::cell)): `1 ≤ N ≤ MAX_ROBOTS`
/// robots repeating one task plan for ever under the token rule, one control period
/// `tick_s` (real s) per [`tick`](ContinuousCoordinator::tick).
///
/// Per tick, robot `i` steps from its schedule clock `s` (task-plan clock, s, reset to 0 at
/// each task start) read at its sample at the tick start: on a high-confidence sample it runs
/// its plan (`tick_s` of schedule clock); on a low-confidence one at the operator's rate, the
/// [`Operator`]'s gradient `g` clamped to `[ψ̇min, ψ̇max]` giving `(ψ̇_E/g)·tick_s`
/// ([`Operator::Scheduled`]: `tick_s`). The step is capped at the gate it may not pass, at
/// the task's end, and, from a high-confidence sample, at the start of the next
/// low-confidence sample: a robot never crosses a low-confidence sample (a one-sample island,
/// say) inside a tick that started on high-confidence ground, so every low-confidence sample
/// it passes is supervised at the operator's rate for at least one tick (without the cap a
/// robot running fast on high confidence jumps over short stretches, which then get no
/// observation and never clear). `tick` is O(N) (amortized; the first pass may skip tokens) and never
/// allocates.
#[derive(Clone, Debug)]
pub struct ContinuousCoordinator {
    /// The task plans (one per task of the cell; a one-task cell has one), each with its
    /// groups and tables ([`Plan`]).
    plans: Arc<[Plan]>,
    /// Per robot, the index of its task's plan in `plans`.
    plan_of: [u8; MAX_ROBOTS],
    tokens: Arc<[Token]>,
    skip_first: Arc<[bool]>,
    n: usize,
    tick_s: f64,
    tol_s: f64,
    clock_s: [f64; MAX_ROBOTS],
    /// Each robot's next group in its current task (`groups.len()`: none left).
    next_group: [usize; MAX_ROBOTS],
    pub(super) tasks: [u64; MAX_ROBOTS],
    cursors: [Cursors; MAX_ROBOTS],
    /// Index of the next entry of the token sequence to grant an operator (`tokens[pos]`).
    pos: usize,
    /// Completed passes of `pos` through the token sequence.
    passes: u64,
    /// `M`: the number of operators (tokens), `1..=MAX_ROBOTS`.
    m: usize,
    /// The operators' state (inline: a clone of the cell allocates nothing).
    staff: Staff,
    /// Per robot, the stamp of its last *service* (the token moving on after it left a
    /// group): larger is more recent. Before its first service a robot's stamp is its rank
    /// among the robots' first tokens at the start (`0..N`); services stamp `N, N + 1, …`.
    /// Carried over by [`take_over`](Self::take_over), which gives the new plan's token to
    /// the least recently served robot (liveness, docs/decisions.md).
    pub(super) served: [u64; MAX_ROBOTS],
    /// The next service's stamp.
    stamp: u64,
    /// The run-time fault monitor (its tick count is the ticks run since the start or the
    /// last reset, carried over by a hand-over).
    monitor: Monitor,
    /// `k`: the operator's switch time in whole ticks ([`crate::switch_ticks`]; 0: none).
    switch_ticks: u64,
    /// The operator's load cap at run time, the token's pace (`None`: no cap;
    /// [`ContinuousCoordinator::with_max_busy_share`]; carried over by a hand-over).
    pace: Option<Pace>,
    /// `None`: a pooled cell (every operator serves every robot). `Some`: a sectored cell
    /// ([`ContinuousCoordinator::sectored`]).
    sectors: Option<Sectors>,
    /// A sectored cell only: per robot, the stamp of its last service counted within its
    /// sector (`served` of the sector's own one-operator cell).
    sector_served: [u64; MAX_ROBOTS],
    /// A sectored cell only: per operator, its sector's next service stamp.
    sector_stamp: [u64; MAX_ROBOTS],
    /// Whether the next entry may be granted *nested* inside the token's group
    /// ([`ContinuousCoordinator::with_nesting`]).
    nest: bool,
    /// The entry granted nested and not yet left, with its `(pos, passes)`.
    nested: Option<(Token, usize, u64)>,
    /// Nested grants since the start or the last reset.
    nested_grants: u64,
    /// Per robot, one past the index of its last low-confidence tick (0: none yet).
    last_lc: [u64; MAX_ROBOTS],
}

/// One task's plan in a continuous cell and what the token rule reads of it: its timeline
/// (schedule clock from 0), groups, the schedule clock of each group's gate and leave point,
/// the next low-confidence sample's clock per sample, the pre-alert's tables.
#[derive(Clone, Debug)]
struct Plan {
    task: Timeline,
    groups: Vec<Group>,
    /// Schedule clock (s) of each group's gate.
    gate_s: Vec<f64>,
    /// Schedule clock (s) at which each group is left (start of its `ref_end` sample).
    leave_s: Vec<f64>,
    /// Per reference sample `k`, the schedule clock (s) of the start of the first
    /// low-confidence sample after `k` (the task's end if none): a robot on high-confidence
    /// ground stops there at the end of its tick, so that no low-confidence sample is crossed
    /// without a tick that starts on it (the operator supervises every one).
    next_lc_s: Vec<f64>,
    /// The pre-alert's tables of the task ([`crate::prealert`]).
    reach: Reach,
    /// Per reference sample, the group its low-confidence sample belongs to (unused on
    /// high-confidence samples).
    group_of: Vec<usize>,
    /// Per group, `W` of [`nest::span_ticks`]: the most ticks from its gate until it is left.
    span_ticks: Vec<u64>,
    /// Per group, the whole ticks a robot surely travels from its gate before it is first
    /// low-confidence in it (`Reach::to_run_from_sample` at the fastest, rounded down).
    entry_ticks: Vec<u64>,
}

impl Plan {
    /// The plan of `task` (re-based to clock 0 by the caller) with its `groups`, at a tick of
    /// `tick_s` and the cell's clock tolerance `tol_s`.
    fn new(task: Timeline, groups: Vec<Group>, tick_s: f64, tol_s: f64) -> Plan {
        let c = task.sample_clock_s();
        let gate_s: Vec<f64> = groups.iter().map(|g| c[g.gate]).collect();
        let leave_s: Vec<f64> = groups.iter().map(|g| c[g.ref_end]).collect();
        let n_ref = task.n_ref();
        let mut next_lc_s = vec![task.end_s(); n_ref];
        for k in (0..n_ref.saturating_sub(1)).rev() {
            next_lc_s[k] = if task.conf()[k + 1] {
                next_lc_s[k + 1]
            } else {
                c[k + 1]
            };
        }
        // A tick moves a robot by `tick_s` of clock on high confidence (capped) and between
        // `S·h` and `F·h` on low confidence: at most `M = h·max(1, max F)`.
        let reach = Reach::new(
            &task,
            |n| {
                if task.conf()[n] {
                    1.0
                } else {
                    task.rate_slow(n)
                }
            },
            |n| {
                if task.conf()[n] {
                    1.0
                } else {
                    task.rate_fast(n)
                }
            },
            tick_s * task.max_rate_fast(),
            tol_s,
        );
        let mut group_of = vec![0; n_ref];
        for (k, g) in groups.iter().enumerate() {
            for x in &mut group_of[g.ref_start..g.ref_end] {
                *x = k;
            }
        }
        let span_ticks = groups
            .iter()
            .map(|g| nest::span_ticks(&task, g, tick_s, tol_s))
            .collect();
        let entry_ticks = groups
            .iter()
            .map(|g| {
                let (fast_s, _) = reach.to_run_from_sample(g.gate, g.ref_start);
                prealert::ticks_before_at_least(fast_s, tick_s)
            })
            .collect();
        Plan {
            task,
            groups,
            gate_s,
            leave_s,
            next_lc_s,
            reach,
            group_of,
            span_ticks,
            entry_ticks,
        }
    }
}

impl ContinuousCoordinator {
    /// A continuous cell of `n_robots` robots repeating `task` (its plan; re-based to start at
    /// schedule clock 0), waiting at the usable holds `holds` ([`groups`]), the operator taking
    /// the stretches `(robot, lc)` in the cyclic `order` ([`token_sequence`]), at a control
    /// tick of `tick_s` real seconds. Every robot starts at sample 0 of its first task.
    ///
    /// # Errors
    /// [`Error::RobotCount`] unless `1 ≤ N ≤ MAX_ROBOTS`; [`Error::BadParam`] for a `tick_s`
    /// not finite and > 0; [`Error::BadGate`] for a bad hold; [`Error::BadOrder`] for an
    /// order that is malformed or not runnable.
    pub fn new(
        task: Timeline,
        holds: &[usize],
        order: &[(usize, usize)],
        n_robots: usize,
        tick_s: f64,
    ) -> Result<ContinuousCoordinator> {
        check_count(n_robots)?;
        check_tick(tick_s)?;
        let task = task.sub(0, task.n_ref(), 0.0)?;
        let groups = groups(task.conf(), holds)?;
        let (tokens, skip_first) = token_sequence(order, &groups, n_robots)?;
        let tol_s = clock_tolerance_s(std::slice::from_ref(&task), tick_s);
        let plan = Plan::new(task, groups, tick_s, tol_s);
        Ok(Self::assemble(
            vec![plan],
            [0; MAX_ROBOTS],
            tokens,
            skip_first,
            n_robots,
            tick_s,
            tol_s,
        ))
    }

    /// A continuous cell of different tasks (issue 45): robot `i` repeats its own task
    /// `tasks[robot_task[i]]` (a plan, re-based to schedule clock 0, with its usable holds),
    /// `ratios[i]` times per pass of the operator's cyclic `order` of stretches `(robot, lc)`,
    /// `lc` counting robot `i`'s stretches over its `r_i` tasks
    /// (`tandem_schedule::cyclic::MixedCyclicPlan`'s order; the token sequence is
    /// [`mixed_token_sequence`](crate::cell::mixed_token_sequence)'s), at a control tick of
    /// `tick_s` real seconds. Every robot starts at sample 0 of its first task.
    ///
    /// Everything the token rule reads of a task (its groups, gates, leave points, the next
    /// low-confidence sample, the pre-alert's tables) is robot `i`'s own; the clock tolerance
    /// is the cell's, over every task. The rule's argument ([module docs](crate::cell)) reads
    /// each robot's own timeline only, so it holds as for one task: at most one robot (with
    /// `M` operators, `M`) inside a group in any tick, the switch time from the entered
    /// robot's gate. A cell of one task with ratios 1 is [`new`](Self::new)'s, tick for tick.
    ///
    /// # Errors
    /// [`Error::RobotCount`] unless `1 ≤ N ≤ MAX_ROBOTS` (`N = robot_task.len()`);
    /// [`Error::BadParam`] for a `tick_s` not finite and > 0, `ratios` not one per robot
    /// (each ≥ 1), a `robot_task` entry naming no task, or a task no robot does;
    /// [`Error::BadGate`] for a bad hold; [`Error::BadOrder`] for an order that is malformed
    /// or not runnable.
    pub fn mixed(
        tasks: &[(Timeline, Vec<usize>)],
        robot_task: &[usize],
        ratios: &[usize],
        order: &[(usize, usize)],
        tick_s: f64,
    ) -> Result<ContinuousCoordinator> {
        let n_robots = robot_task.len();
        check_count(n_robots)?;
        check_tick(tick_s)?;
        if robot_task.iter().any(|&t| t >= tasks.len())
            || (0..tasks.len()).any(|t| !robot_task.contains(&t))
        {
            return Err(Error::BadParam {
                name: "robot_task",
                why: "must name one of the tasks for each robot, and every task must have a robot",
            });
        }
        let mut timelines = Vec::with_capacity(tasks.len());
        let mut task_groups = Vec::with_capacity(tasks.len());
        for (task, holds) in tasks {
            let task = task.sub(0, task.n_ref(), 0.0)?;
            task_groups.push(groups(task.conf(), holds)?);
            timelines.push(task);
        }
        let per_robot: Vec<&[Group]> = robot_task.iter().map(|&t| &task_groups[t][..]).collect();
        let (tokens, skip_first) = mixed_token_sequence(order, &per_robot, ratios)?;
        let tol_s = clock_tolerance_s(&timelines, tick_s);
        let plans: Vec<Plan> = timelines
            .into_iter()
            .zip(task_groups)
            .map(|(task, groups)| Plan::new(task, groups, tick_s, tol_s))
            .collect();
        let mut plan_of = [0u8; MAX_ROBOTS];
        for (p, &t) in plan_of.iter_mut().zip(robot_task) {
            *p = t as u8;
        }
        Ok(Self::assemble(
            plans, plan_of, tokens, skip_first, n_robots, tick_s, tol_s,
        ))
    }

    /// The coordinator of `plans` (robot `i` runs `plans[plan_of[i]]`) with the token
    /// sequence `tokens` (`skip_first` its first pass's skipped entries), reset to the start.
    fn assemble(
        plans: Vec<Plan>,
        plan_of: [u8; MAX_ROBOTS],
        tokens: Vec<Token>,
        skip_first: Vec<bool>,
        n_robots: usize,
        tick_s: f64,
        tol_s: f64,
    ) -> ContinuousCoordinator {
        let mut out = ContinuousCoordinator {
            plans: plans.into(),
            plan_of,
            tokens: tokens.into(),
            skip_first: skip_first.into(),
            n: n_robots,
            tick_s,
            tol_s,
            clock_s: [0.0; MAX_ROBOTS],
            next_group: [0; MAX_ROBOTS],
            tasks: [0; MAX_ROBOTS],
            cursors: [Cursors::default(); MAX_ROBOTS],
            pos: 0,
            passes: 0,
            m: 1,
            staff: Staff::default(),
            served: [0; MAX_ROBOTS],
            stamp: 0,
            monitor: Monitor::new(n_robots),
            switch_ticks: 0,
            pace: None,
            sectors: None,
            sector_served: [0; MAX_ROBOTS],
            sector_stamp: [0; MAX_ROBOTS],
            nest: false,
            nested: None,
            nested_grants: 0,
            last_lc: [0; MAX_ROBOTS],
        };
        out.reset();
        out
    }

    /// A *sectored* continuous cell (issue 44): the robots `0..N` of `task` (re-based to
    /// schedule clock 0, waiting at the usable `holds`) split into sectors, `sectors[o] =
    /// (robots, order)` served by operator `o` alone: `robots` (ascending) are the sector's,
    /// and `order` is the sector's own one-operator cyclic order of stretches `(j, lc)`, `j`
    /// indexing `robots` (the order of `tandem_schedule::cyclic_plan` for `robots.len()`
    /// robots). Operator `o` grants only its sector's robots, in its sector's token sequence,
    /// by the one-operator rule: each sector ticks exactly as its own one-operator cell
    /// ([`new`](Self::new) of its robots and order), so each keeps that cell's guarantee — at
    /// most one of its robots low-confidence in a tick, under operator `o`, never handed to
    /// another operator (a robot's operator is its sector's), operator `o`'s stretches of
    /// different robots `k` ticks apart ([`with_switch_s`](Self::with_switch_s)) — and at
    /// most `M` robots are low-confidence in all. The fault monitor latches when two robots of
    /// one sector are low-confidence. [`with_operators`](Self::with_operators) may add
    /// operators without robots (never below the sectors' number); the pre-alert
    /// ([`Tick::next`]) and the load cap are not built for sectors (`None`, refused).
    ///
    /// # Errors
    /// [`Error::RobotCount`] unless `1 ≤ N ≤ MAX_ROBOTS`; [`Error::BadParam`] (`sectors`)
    /// unless the sectors' robots, each ascending and non-empty, are `0..N` once each and
    /// there are at most `MAX_ROBOTS` sectors; otherwise as [`new`](Self::new) for the tick,
    /// the holds and each sector's order.
    pub fn sectored(
        task: Timeline,
        holds: &[usize],
        sectors: &[SectorOrder],
        n_robots: usize,
        tick_s: f64,
    ) -> Result<ContinuousCoordinator> {
        check_count(n_robots)?;
        check_tick(tick_s)?;
        let bad = |why| Error::BadParam {
            name: "sectors",
            why,
        };
        if sectors.is_empty() || sectors.len() > MAX_ROBOTS {
            return Err(bad("must be 1 to MAX_ROBOTS sectors, one per operator"));
        }
        let mut of = [0u8; MAX_ROBOTS];
        let mut seen = [false; MAX_ROBOTS];
        for (o, (robots, _)) in sectors.iter().enumerate() {
            if robots.is_empty() || robots.windows(2).any(|w| w[0] >= w[1]) {
                return Err(bad("each sector's robots must be non-empty and ascending"));
            }
            for &r in robots {
                if r >= n_robots || std::mem::replace(&mut seen[r], true) {
                    return Err(bad("must name each robot 0..N exactly once"));
                }
                of[r] = o as u8;
            }
        }
        if seen[..n_robots].iter().any(|s| !s) {
            return Err(bad("must name each robot 0..N exactly once"));
        }
        let task = task.sub(0, task.n_ref(), 0.0)?;
        let groups = groups(task.conf(), holds)?;
        let mut tokens = Vec::new();
        let mut skip_first = Vec::new();
        let mut range = [(0usize, 0usize); MAX_ROBOTS];
        for (o, (robots, order)) in sectors.iter().enumerate() {
            let (t, skip) = token_sequence(order, &groups, robots.len())?;
            let start = tokens.len();
            tokens.extend(t.into_iter().map(|t| Token {
                robot: robots[t.robot],
                ..t
            }));
            skip_first.extend(skip);
            range[o] = (start, tokens.len());
        }
        let tol_s = clock_tolerance_s(std::slice::from_ref(&task), tick_s);
        let plan = Plan::new(task, groups, tick_s, tol_s);
        let mut out = Self::assemble(
            vec![plan],
            [0; MAX_ROBOTS],
            tokens,
            skip_first,
            n_robots,
            tick_s,
            tol_s,
        );
        out.m = sectors.len();
        out.sectors = Some(Sectors { of, range });
        out.monitor = Monitor::new(n_robots).with_sectors(out.m, of);
        out.reset();
        Ok(out)
    }

    /// The sectors of a sectored cell ([`sectored`](Self::sectored)): per robot its sector
    /// (its operator); `None` for a pooled cell.
    pub fn sector_of(&self) -> Option<PerRobot<u8>> {
        self.sectors.map(|s| {
            let mut out = PerRobot::new(self.n);
            out.as_mut_slice().copy_from_slice(&s.of[..self.n]);
            out
        })
    }

    /// The same cell with the operator's switch time `switch_s` (real s, finite and ≥ 0),
    /// reset to the start: the token lets a robot pass its gate no sooner than `k` =
    /// [`switch_ticks`](crate::switch_ticks)`(switch_s, tick_s)` ticks after the tick in which
    /// *another* robot left its group (the token's move), less the whole ticks it surely
    /// travels from that gate to its stretch (at most `k`), so between two robots' stretches at
    /// least `k` ticks pass in which neither is low-confidence (docs/decisions.md, "The switch
    /// time at run time (issue 41)"). Consecutive groups of one robot wait for nothing.
    /// `switch_s = 0` changes nothing.
    ///
    /// # Errors
    /// [`Error::BadParam`] for a `switch_s` not finite and ≥ 0 or of more than 1e8 ticks.
    pub fn with_switch_s(mut self, switch_s: f64) -> Result<ContinuousCoordinator> {
        self.switch_ticks = crate::switch_ticks(switch_s, self.tick_s)?;
        self.reset();
        Ok(self)
    }

    /// `k`: the switch time in whole ticks ([`ContinuousCoordinator::with_switch_s`]).
    pub fn switch_ticks(&self) -> u64 {
        self.switch_ticks
    }

    /// The same cell with `operators` operators (`M` tokens; issue 44), reset to the start:
    /// at most `M` robots are inside a group at once, each assigned to one operator from the
    /// tick it may pass its group's gate until it leaves the group, whose input
    /// ([`tick_many`](Self::tick_many)) sets its rate (module docs, [`crate::cell`]). The
    /// switch time is per operator. `M = 1` is the one-operator cell, bit for bit.
    #[must_use]
    ///
    /// The run-time load cap ([`with_max_busy_share`](Self::with_max_busy_share)) paces one
    /// operator only: with `M > 1` it is dropped ([`max_busy_share`](Self::max_busy_share)
    /// reads 1 then) and setting it afterwards is refused.
    pub fn with_operators(mut self, operators: crate::OperatorCount) -> ContinuousCoordinator {
        self.m = operators.get();
        if let Some(sec) = self.sectors {
            // Operators beyond the sectors have empty ranges (no robots); never fewer.
            let sectors = 1
                + (0..self.n)
                    .map(|r| usize::from(sec.of[r]))
                    .max()
                    .unwrap_or(0);
            self.m = self.m.max(sectors);
        }
        if self.m > 1 {
            self.pace = None;
        }
        self.monitor = self.monitor.with_operators(self.m);
        self.reset();
        self
    }

    /// `M`: the number of operators ([`with_operators`](Self::with_operators)).
    pub fn operators(&self) -> usize {
        self.m
    }

    /// The same cell with *nested groups* (issue 45), reset to the start: while the token's
    /// robot `i` is on high-confidence ground inside its group, the next entry's robot `j`,
    /// waiting at its gate, may go through its whole group then — when the least time before
    /// `i` can be low-confidence again covers the most ticks `j` needs to leave its group, at
    /// the slowest input, plus the switch time back, and the switch time since the last
    /// low-confidence tick of every other robot has passed by `j`'s first possible
    /// low-confidence tick (the rule and its proof: `cell/nest.rs`). The operator so fills the
    /// high-confidence gaps of a group that no hold splits with another robot's whole group;
    /// the entries keep their order, and a check that fails leaves the entry to the token rule.
    /// For any operator, at most one robot is low-confidence in a tick and the switch time is
    /// kept. One operator only: in a cell of `M > 1` operators, a sectored cell or one with a
    /// load cap nothing is nested. The pre-alert ([`Tick::next`]) is not computed for a cell
    /// with nesting (`None`). Without this call nothing changes.
    #[must_use]
    pub fn with_nesting(mut self) -> ContinuousCoordinator {
        self.nest = true;
        self.reset();
        self
    }

    /// Whether groups may be nested ([`with_nesting`](Self::with_nesting)).
    pub fn nesting(&self) -> bool {
        self.nest
    }

    /// The groups granted nested since the start or the last reset (or hand-over)
    /// ([`with_nesting`](Self::with_nesting)).
    pub fn nested_grants(&self) -> u64 {
        self.nested_grants
    }

    /// With nesting ([`with_nesting`](Self::with_nesting)), at tick index `tick` (the start of
    /// the next tick): grants the next entry nested inside the token's group when the rule of
    /// `cell/nest.rs` allows it. At most one nested entry at a time; O(N).
    fn grant_nested(&mut self, tick: u64) {
        if !self.nest
            || self.m > 1
            || self.sectors.is_some()
            || self.pace.is_some()
            || self.nested.is_some()
        {
            return;
        }
        let Some((t, _, _)) = self.staff.slot[0] else {
            return;
        };
        let (i, g) = (t.robot, t.group);
        let Some(&next) = self.tokens.get(self.pos) else {
            return;
        };
        let (j, gj) = (next.robot, next.group);
        let held = self.monitor.held();
        if j == i || self.next_group[i] != g || held.is_some() {
            return;
        }
        let (pi, pj) = (self.plan(i), self.plan(j));
        // `j` waits at its next group's gate, the entry's.
        if self.staff.assigned[j].is_some()
            || self.next_group[j] != gj
            || gj >= pj.groups.len()
            || self.clock_s[j] < pj.gate_s[gj]
        {
            return;
        }
        // `i` is inside `G` on high-confidence ground: every sample from its clock less the
        // tolerance to its clock, and its next low-confidence sample lies in `G`.
        let (task, c) = (&pi.task, pi.task.sample_clock_s());
        let s = self.clock_s[i];
        if s >= task.end_s() || s - self.tol_s >= pi.leave_s[g] {
            return;
        }
        let lo = c
            .partition_point(|&x| x <= s - self.tol_s)
            .saturating_sub(1);
        let at = c.partition_point(|&x| x <= s).saturating_sub(1);
        let at = at.min(task.n_ref() - 1);
        if !task.conf()[lo.min(at)..=at].iter().all(|&h| h) {
            return;
        }
        let a = pi.next_lc_s[at];
        if a >= pi.leave_s[g] {
            return;
        }
        let k = self.switch_ticks;
        // 1. Back in time: `j` has left before `i` can be low-confidence, `k` ticks to spare.
        let n_i = nest::ticks_before_lc(s, a, self.tick_s, self.tol_s);
        let w_j = pj.span_ticks[gj];
        if n_i < w_j.saturating_add(k).saturating_add(1) {
            return;
        }
        // 2. The switch to `j`: `k` ticks after every other robot's last low-confidence tick.
        let e_j = pj.entry_ticks[gj];
        let last = (0..self.n)
            .filter(|&r| r != j)
            .map(|r| self.last_lc[r])
            .max()
            .unwrap_or(0);
        if tick.saturating_add(e_j) < last.saturating_add(k) {
            return;
        }
        self.nested = Some((next, self.pos, self.passes));
        self.staff.assigned[j] = Some(0);
        self.staff.last_op[j] = Some(0);
        self.nested_grants += 1;
        self.advance_token();
    }

    /// Whether robot `i` may pass its next group's gate: an operator is assigned to it.
    fn may_pass(&self, i: usize) -> bool {
        self.staff.assigned[i].is_some()
    }

    /// Robot `i`'s task plan.
    fn plan(&self, i: usize) -> &Plan {
        &self.plans[usize::from(self.plan_of[i])]
    }

    /// The same cell with the operator's load cap `max_busy_share` (`u_max` in `(0, 1]`,
    /// `tandem_schedule::SamplerParams::max_busy_share`), reset to the start: the token paces
    /// the operator so that its busy share — the ticks with a low-confidence robot plus `k`
    /// ticks per change of robot — is at most `u_max` over every window of whole passes
    /// through the token sequence (the plan's cycle; and over every prefix of a pass that ends
    /// where the token's robot may start waiting for its gate), for any operator. After a robot
    /// leaves its group, the next one passes its gate no sooner than `n` ticks after the pass
    /// began, `n` the least with `B ≤ u_max·n` for the pass's `B` busy ticks so far (plus the
    /// switch time if it is another robot): docs/decisions.md, "The load cap at run time: the
    /// token's pace (issue 41)". `1` changes nothing.
    ///
    /// # Errors
    /// [`Error::BadParam`] for a `max_busy_share` not in `(0, 1]`.
    pub fn with_max_busy_share(mut self, max_busy_share: f64) -> Result<ContinuousCoordinator> {
        super::pace::check_max_busy_share(max_busy_share)?;
        if (self.m > 1 || self.sectors.is_some()) && max_busy_share < 1.0 {
            return Err(Error::BadParam {
                name: "max_busy_share",
                why: "the run-time load cap paces one operator; a cell of several operators has none yet (issue 44)",
            });
        }
        self.pace = (max_busy_share < 1.0).then(|| Pace::new(max_busy_share));
        self.reset();
        Ok(self)
    }

    /// The operator's load cap `u_max` ([`ContinuousCoordinator::with_max_busy_share`]; 1: none).
    pub fn max_busy_share(&self) -> f64 {
        self.pace.map_or(1.0, |p| p.cap())
    }

    /// The first tick (index: ticks since the start) of the operator's current episode under
    /// the load cap ([`ContinuousCoordinator::with_max_busy_share`]): the token's robot waits
    /// for its gate from there (and the switch time after it, if it is another robot than the
    /// one that left a group last). May lie ahead of [`ticks`](Self::ticks) (the operator's
    /// pause). `None` without a cap.
    pub fn episode_start(&self) -> Option<u64> {
        self.pace.map(|p| p.start())
    }

    /// The first tick of the load cap's current accounting window (a pass through the token
    /// sequence, begun at an episode start): from there to every later
    /// [`episode_start`](Self::episode_start) the busy share is at most the cap. `None` without
    /// a cap.
    pub fn pace_window_start(&self) -> Option<u64> {
        self.pace.map(|p| p.segment())
    }

    /// Ticks operator `o` must still wait at tick index `tick` before it may be granted to
    /// robot `i` (the switch time after it released another robot; 0 without one).
    ///
    /// The switch time is counted where it protects the operator, at the robot's stretch,
    /// not at its gate: the robot is let go [`entry_ticks`](Self::entry_ticks) early (at
    /// most `k`), the whole ticks it surely needs from its gate to its group's first
    /// low-confidence tick, so that it travels while the operator switches and still enters
    /// no sooner than `k` ticks after the other robot left (docs/decisions.md, "The token
    /// passes early by the travel to the stretch (issue 41)").
    fn op_wait(&self, o: usize, i: usize, tick: u64) -> u64 {
        if let Some(p) = &self.pace {
            let early = self.entry_ticks(i);
            return p.wait(self.staff.last_left[o], i, self.switch_ticks, early, tick);
        }
        match self.staff.last_left[o] {
            Some((r, left)) if self.switch_ticks > 0 && r != i => {
                let early = self.entry_ticks(i).min(self.switch_ticks);
                (left + self.switch_ticks - early).saturating_sub(tick)
            }
            _ => 0,
        }
    }

    /// Whole ticks that surely pass, from the tick start at which robot `i` may pass the gate
    /// of its next group, before the tick in which it is first low-confidence in that group:
    /// the least real time from the gate's sample to the group's first stretch less the clock
    /// tolerance (`Reach::to_run_from_sample`, every sample between them high-confidence, run
    /// at its plan), in ticks rounded down (`prealert::ticks_before_at_least`). A robot not
    /// inside is at or before its next gate, so it needs at least that. 0 without a switch
    /// time (nothing to shorten) and for a robot with no group left in its task.
    fn entry_ticks(&self, i: usize) -> u64 {
        if self.switch_ticks == 0 {
            return 0;
        }
        let plan = self.plan(i);
        plan.groups.get(self.next_group[i]).map_or(0, |g| {
            let (fast_s, _) = plan.reach.to_run_from_sample(g.gate, g.ref_start);
            prealert::ticks_before_at_least(fast_s, self.tick_s)
        })
    }

    /// One operator: ticks robot `i` must still wait at tick index `tick` before the token
    /// may let it pass ([`Self::op_wait`] of operator 0).
    fn switch_wait(&self, i: usize, tick: u64) -> u64 {
        self.op_wait(0, i, tick)
    }

    /// The operator to grant robot `i` at tick index `tick`: a free one whose switch time has
    /// passed, the robot's last operator first, else the lowest index.
    fn free_operator(&self, i: usize, tick: u64) -> Option<usize> {
        let ok = |o: usize| self.staff.slot[o].is_none() && self.op_wait(o, i, tick) == 0;
        match self.staff.last_op[i] {
            Some(o) if ok(usize::from(o)) => Some(usize::from(o)),
            _ => (0..self.m).find(|&o| ok(o)),
        }
    }

    /// Grants operators to the token sequence's entries in order, from `pos`, at tick index
    /// `tick` (the start of that tick): while the next entry's robot has the entry's group
    /// next, holds no operator, and a free operator may take it. Stops at the first entry that
    /// cannot be granted (the order is kept). At most `N` grants; no allocation.
    ///
    /// `M > 1`: [`grant_waiting`](Self::grant_waiting) instead — an entry whose robot has not
    /// reached its gate holds back neither a free operator nor the robots behind it.
    fn grant(&mut self, tick: u64) {
        if let Some(sec) = self.sectors {
            self.grant_sectors(tick, &sec);
            return;
        }
        if self.m > 1 {
            self.grant_waiting(tick);
            return;
        }
        while let Some(&t) = self.tokens.get(self.pos) {
            if self.staff.assigned[t.robot].is_some() || self.next_group[t.robot] != t.group {
                return;
            }
            let Some(o) = self.free_operator(t.robot, tick) else {
                return;
            };
            self.staff.slot[o] = Some((t, self.pos, self.passes));
            self.staff.assigned[t.robot] = Some(o as u8);
            self.staff.last_op[t.robot] = Some(o as u8);
            self.advance_token();
        }
    }

    /// `M > 1`: grants operators, at tick index `tick`, to the robots that wait at the gate of
    /// their next group and hold none, in the order of their next entries in the token
    /// sequence (`Staff::next_entry`), each a free operator whose switch time for it is over
    /// ([`free_operator`](Self::free_operator)); stops at the first such robot that cannot be
    /// granted (so a robot is overtaken only by robots whose entries come before its own).
    /// Unlike the one-operator rule, a robot still on its way to its gate holds neither an
    /// operator nor the grants behind it: with `M` operators the sequence's next robot is
    /// often still finishing its previous group or travelling, while other robots wait at
    /// their gates and operators idle (docs/decisions.md, "The pooled cell grants the robots
    /// at their gates (issue 44)"). Soundness does not depend on the order (each robot inside
    /// holds one operator). Liveness: a robot waiting with entry key `K` is overtaken only by
    /// grants of smaller keys, each entry granted once, so finitely many; operators free
    /// up as their robots leave, and a switch wait lasts at most `k` ticks. O(N²) comparisons
    /// for `N ≤ MAX_ROBOTS`, O(len) to advance a granted robot's entry; no allocation.
    fn grant_waiting(&mut self, tick: u64) {
        let mut tried = [false; MAX_ROBOTS];
        loop {
            let waiting = (0..self.n).filter(|&i| {
                let g = self.next_group[i];
                let plan = self.plan(i);
                !tried[i]
                    && self.staff.assigned[i].is_none()
                    && g < plan.groups.len()
                    && self.clock_s[i] >= plan.gate_s[g]
                    && self.staff.next_entry[i].is_some()
            });
            let Some(i) = waiting.min_by_key(|&i| {
                let (pos, passes) = self.staff.next_entry[i].expect("filtered");
                (passes, pos)
            }) else {
                return;
            };
            tried[i] = true;
            let (pos, passes) = self.staff.next_entry[i].expect("filtered");
            let t = self.tokens[pos];
            debug_assert_eq!(
                (t.robot, t.group),
                (i, self.next_group[i]),
                "robot {i}'s next entry is its next group"
            );
            let Some(o) = self.free_operator(i, tick) else {
                return;
            };
            self.staff.slot[o] = Some((t, pos, passes));
            self.staff.assigned[i] = Some(o as u8);
            self.staff.last_op[i] = Some(o as u8);
            self.staff.next_entry[i] = Some(self.entry_after(i, pos, passes));
            self.sync_oldest_entry();
        }
    }

    /// A sectored cell: each operator `o` grants its sector's token sequence by the
    /// one-operator rule ([`grant`](Self::grant) with `M = 1`, word for word, on the range
    /// `sec.range[o]`): while its next entry's robot has that group next, holds no operator,
    /// `o` is free and its switch time for the robot is over, `o` takes the entry and its
    /// cursor moves on; the first entry that cannot be granted stops the sector's grants.
    /// Operator `o` grants no robot of another sector, and a robot's state is touched only by
    /// its own sector's operator, so each sector runs as its own one-operator cell. At most
    /// `N` grants; no allocation.
    fn grant_sectors(&mut self, tick: u64, sec: &Sectors) {
        for o in 0..self.m {
            self.grant_sector(tick, sec, o);
        }
        self.sync_sector_cursors(sec);
    }

    /// A sectored cell: operator `o`'s grants of [`grant_sectors`](Self::grant_sectors), on
    /// its range only (touches only operator `o`'s slot and cursor and its sector's robots).
    fn grant_sector(&mut self, tick: u64, sec: &Sectors, o: usize) {
        let (start, end) = sec.range[o];
        if start == end {
            return;
        }
        loop {
            let (pos, passes) = self.staff.cursor[o];
            let t = self.tokens[pos];
            if self.staff.assigned[t.robot].is_some()
                || self.next_group[t.robot] != t.group
                || self.staff.slot[o].is_some()
                || self.op_wait(o, t.robot, tick) > 0
            {
                break;
            }
            self.staff.slot[o] = Some((t, pos, passes));
            self.staff.assigned[t.robot] = Some(o as u8);
            self.staff.last_op[t.robot] = Some(o as u8);
            self.staff.cursor[o] = self.sector_after(sec, o, pos, passes);
        }
    }

    /// A sectored cell: operator `o`'s entry after `(pos, passes)` in its range (skipping the
    /// first pass's skipped entries). O(range).
    fn sector_after(
        &self,
        sec: &Sectors,
        o: usize,
        mut pos: usize,
        mut passes: u64,
    ) -> (usize, u64) {
        let (start, end) = sec.range[o];
        loop {
            pos += 1;
            if pos == end {
                pos = start;
                passes += 1;
            }
            if passes > 0 || !self.skip_first[pos] {
                return (pos, passes);
            }
        }
    }

    /// A sectored cell: `(pos, passes)` is the least of the sectors' cursors, so
    /// [`token`](Self::token) names an entry not granted yet when no operator holds one.
    fn sync_sector_cursors(&mut self, sec: &Sectors) {
        if let Some(&(pos, passes)) = (0..self.m)
            .filter(|&o| sec.range[o].0 < sec.range[o].1)
            .map(|o| &self.staff.cursor[o])
            .min_by_key(|&&(pos, passes)| (passes, pos))
        {
            (self.pos, self.passes) = (pos, passes);
        }
    }

    /// A sectored cell: each sector's cursor at its first entry not skipped in the first pass,
    /// and its service stamps ranked as its own one-operator cell ranks them at a reset (by
    /// the sector's first entries, then its robots in order).
    fn init_sectors(&mut self, sec: &Sectors) {
        for o in 0..self.m {
            let (start, end) = sec.range[o];
            let mut rank = 0;
            let mut ranked = [false; MAX_ROBOTS];
            let firsts = (start..end)
                .filter(|&k| !self.skip_first[k])
                .map(|k| self.tokens[k].robot);
            let members = (0..self.n).filter(|&r| usize::from(sec.of[r]) == o);
            for r in firsts.chain(members) {
                if !std::mem::replace(&mut ranked[r], true) {
                    self.sector_served[r] = rank;
                    rank += 1;
                }
            }
            self.sector_stamp[o] = rank;
        }
        self.init_sector_cursors(sec);
    }

    /// A sectored cell: each sector's cursor at its first entry not skipped in the first pass
    /// (at a reset or a hand-over).
    fn init_sector_cursors(&mut self, sec: &Sectors) {
        for o in 0..self.m {
            let (start, end) = sec.range[o];
            let first = (start..end).find(|&k| !self.skip_first[k]).unwrap_or(start);
            self.staff.cursor[o] = (first, 0);
        }
        self.sync_sector_cursors(sec);
    }

    /// `M > 1`: robot `r`'s entry after `(pos, passes)` in the token sequence (skipping the
    /// first pass's skipped entries). O(len).
    fn entry_after(&self, r: usize, mut pos: usize, mut passes: u64) -> (usize, u64) {
        let len = self.tokens.len();
        loop {
            pos += 1;
            if pos == len {
                pos = 0;
                passes += 1;
            }
            if self.tokens[pos].robot == r && (passes > 0 || !self.skip_first[pos]) {
                return (pos, passes);
            }
        }
    }

    /// `M > 1`: each robot's next entry from the start of the sequence (at a reset or a
    /// hand-over: its first entry not skipped in the first pass, the one of its next group).
    fn init_next_entries(&mut self) {
        for r in 0..self.n {
            self.staff.next_entry[r] = (0..self.tokens.len())
                .find(|&k| self.tokens[k].robot == r && !self.skip_first[k])
                .map(|k| (k, 0));
        }
        self.sync_oldest_entry();
    }

    /// `M > 1`: `(pos, passes)` is the oldest entry not granted yet (the least of the robots'
    /// next entries), so [`token`](Self::token) and [`token_position`](Self::token_position)
    /// keep their meaning.
    fn sync_oldest_entry(&mut self) {
        if let Some((pos, passes)) = self.staff.next_entry[..self.n]
            .iter()
            .flatten()
            .min_by_key(|&&(pos, passes)| (passes, pos))
        {
            (self.pos, self.passes) = (*pos, *passes);
        }
    }

    /// The pre-alert now ([`Tick::next`], [`crate::prealert`]): per robot its next
    /// low-confidence run (its current task, else the next one), the least real time until the
    /// tick that starts it (the switch wait of a token holder included, gates counted as 0)
    /// and, for a robot holding the token of the group the run is in and not held by the fault
    /// monitor, the most (else the token's next move, set by the others, bounds it: `+∞`).
    /// A stretch whose token is not the current one (another robot's, or a later group of
    /// the same robot) cannot start before the token moves on, which is no sooner than the
    /// tick after the one that takes the token's robot past its group at its fastest, plus
    /// the run from the stretch's gate: its earliest is at least that. Of the robots with the
    /// same earliest (several waiting at their gates) the one named is the robot the token
    /// passes to first.
    /// O(N) plus a scan of the token sequence up to the last robot's next turn; no allocation.
    pub fn pre_alert(&self) -> Option<crate::PreAlert> {
        if self.m > 1 || self.sectors.is_some() || self.nest {
            return None;
        }
        let h = self.tick_s;
        let next_tick = self.monitor.ticks();
        let tok = self.token();
        let held = self.monitor.held();
        // Ticks before the token can move on: its robot must first pass the end of its group
        // (less the clock tolerance, on the safe side) at its fastest.
        let token_moves = tok.map_or(0, |t| {
            let p = self.plan(t.robot);
            let c = p.task.sample_clock_s();
            let s = self.clock_s[t.robot];
            let x = (p.leave_s[t.group].min(p.task.end_s()) - self.tol_s).max(0.0);
            let lo = p
                .reach
                .fast_between(c, self.cursors[t.robot].at, s, p.task.sample_at(x), x);
            prealert::ticks_before_at_least(lo, h)
        });
        // Each robot's next turn after the current token's: token positions from the current
        // one to its first token after it.
        let mut turn = [usize::MAX; MAX_ROBOTS];
        let len = self.tokens.len();
        let (tok_pos, tok_passes) = self.token_position();
        let (mut k, mut pass, mut found) = (tok_pos, tok_passes, 0);
        for step in 0..len {
            k += 1;
            if k == len {
                k = 0;
                pass += 1;
            }
            if pass > 0 || !self.skip_first[k] {
                let r = self.tokens[k].robot;
                if turn[r] == usize::MAX {
                    turn[r] = step;
                    found += 1;
                    if found == self.n {
                        break;
                    }
                }
            }
        }
        let cands = (0..self.n).filter_map(|i| {
            let plan = self.plan(i);
            let (c, reach) = (plan.task.sample_clock_s(), &plan.reach);
            // A stretch in group `G` starts only after its robot passes `G`'s gate with the
            // token `(robot, G)`. Unless that is the current token and the robot's next group,
            // the token must move on first: the robot passes the gate no sooner than the tick
            // after, then runs from the gate to the stretch (run `m`; `next_task`: `m` is in the
            // robot's next task, after this one's end).
            // The rank on a tie: 0 with the token, else the robot's next turn.
            let after_token = |e: u64, m: usize, next_task: bool| {
                let g = plan.group_of[m];
                let next_group = if next_task { 0 } else { self.next_group[i] };
                let past_groups = !next_task || self.next_group[i] >= plan.groups.len();
                if tok.is_some_and(|t| t.robot == i && t.group == g)
                    && next_group == g
                    && past_groups
                {
                    return (e, 0);
                }
                let (from_gate, _) = reach.to_run_from_sample(plan.groups[g].gate, m);
                let e = e.max(token_moves + 1 + prealert::ticks_before_at_least(from_gate, h));
                (e, turn[i])
            };
            let s = self.clock_s[i];
            let at = self.cursors[i].at;
            let holder = tok.is_some_and(|t| t.robot == i && t.group == self.next_group[i]);
            let wait = if holder {
                self.switch_wait(i, next_tick)
            } else {
                0
            };
            // At a task's start (clock 0) the robot has touched nothing of it.
            let touched_s = if s <= 0.0 { f64::NEG_INFINITY } else { s };
            if let Some(m) = reach.next_run(c, at, touched_s, self.tol_s) {
                let (lo, hi) = reach.to_run(c, at, s, m);
                let mut earliest = prealert::ticks_before_at_least(lo, h);
                let mut slack = 0;
                if wait > 0 {
                    // The robot may run up to its gate while it waits for the switch time, and
                    // passes it `wait` ticks from now at the soonest; the tick that stops it at
                    // the gate may be short (one tick more at the latest).
                    let gate = plan.groups[self.next_group[i]].gate;
                    let (lo_gate, _) = reach.to_run_from_sample(gate, m);
                    earliest = earliest.max(wait + prealert::ticks_before_at_least(lo_gate, h));
                    slack = wait + 1;
                }
                let latest = (holder && held != Some(i) && plan.group_of[m] == self.next_group[i])
                    .then(|| prealert::ticks_before_at_most(hi, h).map(|t| t + slack))
                    .flatten();
                let (earliest, rank) = after_token(earliest, m, false);
                return Some((i, earliest, latest, rank));
            }
            reach.fast_to_first_run().map(|first| {
                let lo = reach.fast_to_end(c, at, s) + first;
                let earliest = wait + prealert::ticks_before_at_least(lo, h);
                let m = reach.first_run().unwrap_or(0);
                let (earliest, rank) = after_token(earliest, m, true);
                (i, earliest, None, rank)
            })
        });
        // The token passes in its fixed order: a robot whose next turn comes later cannot
        // start its stretch before the robots with earlier turns have started theirs (each
        // takes the token at its gate and passes it on after its group), so its earliest
        // start is at least theirs plus a tick. Without this the pre-alert could name a robot
        // of a later turn whose loose bound was smaller (issue 42: a three-robot cell named
        // robot 1 while robot 3's turn came first, 100 of 901 stretches pre-alerted late).
        let mut ranked = [(0usize, 0u64, None, 0usize); MAX_ROBOTS];
        let mut n = 0;
        for c in cands {
            ranked[n] = c;
            n += 1;
        }
        let ranked = &mut ranked[..n];
        ranked.sort_unstable_by_key(|c| c.3);
        // The latest earliest start over the ranks below the current one (none yet), and
        // over the current rank so far.
        let (mut below, mut rank, mut at_rank) = (None::<u64>, None, 0u64);
        for c in ranked.iter_mut() {
            if rank != Some(c.3) {
                if rank.is_some() {
                    below = Some(below.map_or(at_rank, |b| b.max(at_rank)));
                }
                rank = Some(c.3);
                at_rank = 0;
            }
            if let Some(b) = below {
                c.1 = c.1.max(b + 1);
            }
            at_rank = at_rank.max(c.1);
        }
        prealert::pick_ranked(ranked.iter().copied(), h)
    }

    /// Every robot back at sample 0 of its first task, the token at its first entry, the
    /// counters and the fault cleared (no allocation).
    pub fn reset(&mut self) {
        self.clock_s = [0.0; MAX_ROBOTS];
        self.next_group = [0; MAX_ROBOTS];
        self.tasks = [0; MAX_ROBOTS];
        self.cursors = [Cursors::default(); MAX_ROBOTS];
        self.pos = 0;
        self.passes = 0;
        while !self.tokens.is_empty() && self.skip_first[self.pos] {
            self.pos += 1;
        }
        // Before any service, the robots rank by their first token: an immediate hand-over
        // to the same plan keeps the token where it is.
        let mut rank = 0;
        let mut ranked = [false; MAX_ROBOTS];
        let first_tokens = (self.pos..self.tokens.len())
            .filter(|&k| !self.skip_first[k])
            .map(|k| self.tokens[k].robot);
        for r in first_tokens.chain(0..self.n) {
            if !std::mem::replace(&mut ranked[r], true) {
                self.served[r] = rank;
                rank += 1;
            }
        }
        self.stamp = rank;
        self.monitor.reset();
        self.staff = Staff::default();
        self.nested = None;
        self.nested_grants = 0;
        self.last_lc = [0; MAX_ROBOTS];
        if let Some(p) = &mut self.pace {
            p.reset();
        }
        if let Some(sec) = self.sectors {
            self.init_sectors(&sec);
        } else if self.m > 1 {
            self.init_next_entries();
        }
        self.grant(0);
    }

    /// Number of robots `N`.
    pub fn n_robots(&self) -> usize {
        self.n
    }

    /// Control period (real s).
    pub fn tick_s(&self) -> f64 {
        self.tick_s
    }

    /// The task plan every robot repeats (schedule clock from 0); in a cell of different
    /// tasks ([`ContinuousCoordinator::mixed`]), or a sectored cell whose sectors took their
    /// new plans one at a time ([`take_over_sector`](Self::take_over_sector)), robot 0's
    /// ([`task_of`](Self::task_of)).
    pub fn task(&self) -> &Timeline {
        &self.plan(0).task
    }

    /// The task's groups ([`groups`]); in a cell of different tasks robot 0's
    /// ([`groups_of`](Self::groups_of)).
    pub fn groups(&self) -> &[Group] {
        &self.plan(0).groups
    }

    /// The task plan robot `robot` repeats (schedule clock from 0; robot 0's for a robot
    /// index of `N` or more).
    pub fn task_of(&self, robot: usize) -> &Timeline {
        &self.plan(if robot < self.n { robot } else { 0 }).task
    }

    /// The groups of robot `robot`'s task ([`groups`]; robot 0's for a robot index of `N`
    /// or more).
    pub fn groups_of(&self, robot: usize) -> &[Group] {
        &self.plan(if robot < self.n { robot } else { 0 }).groups
    }

    /// The cyclic token sequence ([`token_sequence`]).
    pub fn tokens(&self) -> &[Token] {
        &self.tokens
    }

    /// Whether the first pass skips token `k` ([`token_sequence`]).
    pub fn skipped_in_first_pass(&self, k: usize) -> bool {
        self.skip_first.get(k).copied().unwrap_or(false)
    }

    /// The current token: the oldest entry of the sequence the operators have not finished —
    /// the oldest one an operator holds, else the next to grant (`None` for a task without low
    /// confidence). One operator: the token of the one-operator rule.
    pub fn token(&self) -> Option<Token> {
        match self.oldest_held() {
            Some((t, _, _)) => Some(t),
            None => self.tokens.get(self.pos).copied(),
        }
    }

    /// Index of the current [`token`](Self::token) in [`tokens`](Self::tokens) and the number
    /// of completed passes through the sequence when it was reached.
    pub fn token_position(&self) -> (usize, u64) {
        match self.oldest_held() {
            Some((_, pos, passes)) => (pos, passes),
            None => (self.pos, self.passes),
        }
    }

    /// The entries the operators hold now, per operator (`None`: operator free).
    pub fn held_tokens(&self) -> &[Option<(Token, usize, u64)>] {
        &self.staff.slot[..self.m]
    }

    /// The operator's entry granted earliest in the sequence.
    fn oldest_held(&self) -> Option<(Token, usize, u64)> {
        self.staff.slot[..self.m]
            .iter()
            .flatten()
            .min_by_key(|&&(_, pos, passes)| (passes, pos))
            .copied()
    }

    /// Each robot's number of completed tasks.
    pub fn tasks_completed(&self) -> &[u64] {
        &self.tasks[..self.n]
    }

    /// Each robot's schedule clock in its current task (s, task-plan clock from 0).
    pub fn clock_s(&self) -> &[f64] {
        &self.clock_s[..self.n]
    }

    /// Ticks run since the start or the last reset.
    pub fn ticks(&self) -> u64 {
        self.monitor.ticks()
    }

    /// The latched fault, if any.
    pub fn fault(&self) -> Option<Fault> {
        self.monitor.fault()
    }

    /// Clears the latched fault: the held robot moves again from the next tick.
    pub fn clear_fault(&mut self) {
        self.monitor.clear();
    }

    /// Whether each robot is on a low-confidence sample and may move (it holds the token) at
    /// the tick start: the robot the next tick moves at the operator's rate. O(N).
    pub fn low_conf_now(&self) -> RobotFlags {
        let mut out = RobotFlags::new(self.n);
        for i in 0..self.n {
            out.set(
                i,
                self.may_pass(i) && !self.plan(i).task.conf()[self.cursors[i].at],
            );
        }
        out
    }

    /// The operator of each robot of [`low_conf_now`](Self::low_conf_now) (`None` for the
    /// others). O(N).
    pub fn operator_now(&self) -> PerRobot<Option<u8>> {
        let lc = self.low_conf_now();
        let mut out = PerRobot::new(self.n);
        for (i, o) in out.as_mut_slice().iter_mut().enumerate() {
            *o = if lc[i] { self.staff.assigned[i] } else { None };
        }
        out
    }

    /// Whether each robot waits at the gate of its next group at the tick start (the token is
    /// another's): the next tick does not move it. O(N).
    pub fn at_gate_now(&self) -> RobotFlags {
        let mut out = RobotFlags::new(self.n);
        for i in 0..self.n {
            let g = self.next_group[i];
            let plan = self.plan(i);
            let waits =
                g < plan.groups.len() && self.clock_s[i] >= plan.gate_s[g] && !self.may_pass(i);
            out.set(i, waits);
        }
        out
    }

    /// Whether each robot moves in the next tick if the rules let it: not at its gate and not
    /// held by the fault monitor (a robot of the cell never finishes). O(N).
    pub fn running_now(&self) -> RobotFlags {
        let mut out = self.at_gate_now();
        let held = self.monitor.held();
        for i in 0..self.n {
            out.set(i, !out[i] && held != Some(i));
        }
        out
    }

    /// Advances every robot one control period with the operator's input `operator` for the
    /// low-confidence robot: [`tick_many`](Self::tick_many) with one input (one operator).
    /// Never allocates; O(N).
    ///
    /// # Errors
    /// [`Error::OperatorInputs`] for a cell of `M > 1` operators; [`Error::BadOperator`] for
    /// an [`Operator::Gradient`] that is NaN, infinite or ≤ 0; the coordinator is then
    /// unchanged.
    pub fn tick(&mut self, operator: Operator) -> Result<Tick> {
        self.tick_many(std::slice::from_ref(&operator))
    }

    /// Advances every robot one control period with one input per operator: `inputs[o]` sets
    /// the rate of the robot operator `o` is assigned to ([`Tick::operator`]). Never
    /// allocates; O(N) (amortized).
    ///
    /// # Errors
    /// [`Error::OperatorInputs`] unless `inputs.len() == M`; [`Error::BadOperator`] for an
    /// [`Operator::Gradient`] that is NaN, infinite or ≤ 0; the coordinator is then unchanged.
    pub fn tick_many(&mut self, inputs: &[Operator]) -> Result<Tick> {
        if inputs.len() != self.m {
            return Err(Error::OperatorInputs {
                got: inputs.len(),
                want: self.m,
            });
        }
        let mut ops = [Operator::Scheduled; MAX_ROBOTS];
        for (o, op) in ops.iter_mut().zip(inputs) {
            *o = op.validate()?;
        }
        let n = self.n;
        // "A robot never moves backwards", checked in debug builds: each robot's (tasks
        // completed, reference time) at the tick end is at least that at its start.
        #[cfg(debug_assertions)]
        let before = self.position_now();
        let plans = Arc::clone(&self.plans);
        let held = self.monitor.held();
        let this_tick = self.monitor.ticks();
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
        for i in 0..n {
            if held == Some(i) {
                continue;
            }
            let plan = &plans[usize::from(self.plan_of[i])];
            let (task, end_s) = (&plan.task, plan.task.end_s());
            let s_old = self.clock_s[i];
            let g = self.next_group[i];
            let holder = self.may_pass(i);
            let cap = if g >= plan.groups.len() {
                end_s
            } else if holder {
                plan.gate_s.get(g + 1).copied().unwrap_or(end_s)
            } else {
                plan.gate_s[g]
            };
            let cur = &mut self.cursors[i];
            let at = task.advance_cursor(&mut cur.at, s_old);
            let step = if task.conf()[at] {
                self.tick_s
            } else {
                // The robot's operator's input (a robot on low confidence without one — only
                // in a state the rule excludes, `place_unchecked` — takes operator 0's).
                let o = self.staff.assigned[i].map_or(0, usize::from);
                operator_step(task, at, ops[o], self.tick_s)
            };
            // On high-confidence ground the robot stops at the next low-confidence sample:
            // the tick after starts on it, at the operator's rate.
            let cap = if task.conf()[at] {
                cap.min(plan.next_lc_s[at])
            } else {
                cap
            };
            let mut s_new = (s_old + step).min(cap).max(s_old);
            // A rounding error never costs a tick: a robot that ends within the clock
            // tolerance short of its cap (k steps of `tick_s` summing a few ulps below the
            // sample clock of a gate or a stretch) is at the cap, where the next tick would
            // only have moved it by that error. The cap is the furthest it may go this tick,
            // so the token rule's argument is unchanged.
            if s_new < cap && cap - s_new <= self.tol_s {
                s_new = cap;
            }
            if s_new > s_old {
                out.running.set(i, true);
                let lo = task.advance_cursor(&mut cur.lo, s_old - self.tol_s);
                let hi = task.advance_cursor(&mut cur.hi, s_new + self.tol_s);
                let lc = task.any_low_conf(lo, hi);
                out.low_conf.set(i, lc);
                if lc {
                    out.operator.as_mut_slice()[i] = self.staff.assigned[i];
                    self.last_lc[i] = this_tick + 1;
                }
            }
            self.clock_s[i] = s_new;
        }
        if let Some(p) = &mut self.pace {
            p.observe(out.low_conf.count() > 0);
        }
        // A nested entry is released once its robot has left its group (before the token's
        // robot can: `cell/nest.rs`); the operator's last robot is then the nested one.
        if let Some((t, _, _)) = self.nested {
            let (r, g) = (t.robot, t.group);
            let plan = &plans[usize::from(self.plan_of[r])];
            let s = self.clock_s[r];
            if self.next_group[r] == g
                && (s >= plan.task.end_s() || s - self.tol_s >= plan.leave_s[g])
            {
                self.staff.last_left[0] = Some((r, this_tick + 1));
                self.next_group[r] = g + 1;
                self.served[r] = self.stamp;
                self.stamp += 1;
                self.staff.assigned[r] = None;
                self.nested = None;
            }
        }
        // An operator is released once its robot has left its group (operators in index
        // order; one operator: the token moves).
        for o in 0..self.m {
            let Some((t, _, entry_passes)) = self.staff.slot[o] else {
                continue;
            };
            let (r, g) = (t.robot, t.group);
            let s = self.clock_s[r];
            let plan = &plans[usize::from(self.plan_of[r])];
            let end_s = plan.task.end_s();
            if self.next_group[r] == g && (s >= end_s || s - self.tol_s >= plan.leave_s[g]) {
                // The episode's gate waited the switch time iff its robot is not the one
                // the operator released before (`op_wait`).
                let switched = self.staff.last_left[o].is_some_and(|(q, _)| q != r);
                self.staff.last_left[o] = Some((r, this_tick + 1));
                self.next_group[r] = g + 1;
                self.served[r] = self.stamp;
                self.stamp += 1;
                self.sector_served[r] = self.sector_stamp[o];
                self.sector_stamp[o] += 1;
                self.staff.slot[o] = None;
                self.staff.assigned[r] = None;
                // The load cap (one operator): the pass ended iff the grant of this entry
                // wrapped the token sequence (`advance_token` at the grant).
                if let Some(p) = &mut self.pace {
                    let switch = if switched { self.switch_ticks } else { 0 };
                    p.end_episode(this_tick + 1, switch, self.passes > entry_passes);
                }
            }
        }
        for i in 0..n {
            let plan = &plans[usize::from(self.plan_of[i])];
            if self.clock_s[i] >= plan.task.end_s() && self.next_group[i] >= plan.groups.len() {
                self.tasks[i] += 1;
                self.clock_s[i] = 0.0;
                self.cursors[i] = Cursors::default();
                self.next_group[i] = 0;
            }
        }
        // The freed operators take the next entries, for the next tick.
        self.grant(this_tick + 1);
        self.grant_nested(this_tick + 1);
        for i in 0..n {
            let plan = &plans[usize::from(self.plan_of[i])];
            let task = &plan.task;
            let s = self.clock_s[i];
            let at = task.advance_cursor(&mut self.cursors[i].at, s);
            out.ref_time.as_mut_slice()[i] = task.ref_time_in(at, s);
            out.tasks.as_mut_slice()[i] = self.tasks[i];
            let g = self.next_group[i];
            let waits = g < plan.groups.len() && s >= plan.gate_s[g] && !self.may_pass(i);
            out.waiting.set(i, waits);
        }
        #[cfg(debug_assertions)]
        for i in 0..n {
            let after = (out.tasks[i], out.ref_time[i]);
            debug_assert!(
                after.0 > before[i].0 || (after.0 == before[i].0 && after.1 >= before[i].1),
                "robot {i} moved backwards in tick {}: (task, reference time) {:?} -> {after:?}",
                self.monitor.ticks(),
                before[i]
            );
        }
        out.fault = self.monitor.observe(out.low_conf);
        out.next = self.pre_alert();
        Ok(out)
    }

    /// Each robot's position now: (tasks completed, reference time in its current task,
    /// reference samples in `[0, T_ref)`), the value the last [`Tick`] reported. Never
    /// decreases (lexicographically) from tick to tick, nor at a
    /// [`take_over`](Self::take_over). O(N log T_ref).
    pub fn position_now(&self) -> PerRobot<(u64, f64)> {
        let mut out = PerRobot::new(self.n);
        for (i, p) in out.as_mut_slice().iter_mut().enumerate() {
            *p = (
                self.tasks[i],
                self.plan(i).task.ref_time_at(self.clock_s[i]),
            );
        }
        out
    }

    /// Hands a running cell over to this coordinator, a new plan of the same task (after the
    /// confidence changed, say): every robot of `old` continues from where it is, in
    /// reference time, on this coordinator's task plan, groups and token order; the tasks
    /// completed carry over. `self`'s own state is replaced; `old` is not changed.
    ///
    /// It succeeds only at a *hand-over point* of the new plan: for every robot, its
    /// reference position `p` in `old` has left every group of the new plan that ends at or
    /// before `p` (by the clock tolerance) and is not past the gate of its next new group
    /// (schedule clock at most the gate's). So no robot is inside a group, every robot is
    /// on high-confidence samples of the new plan, and the state is one the token rule's
    /// argument covers (module docs), exactly as at the start: the hand-over keeps the
    /// guarantee, whatever the old plan's confidence was. Every tick at which the token
    /// moves is such a point for a new plan whose low-confidence samples are among the old
    /// plan's and whose usable holds include the old plan's (a refinement by recorded
    /// executions: the latch makes it so), since then each robot is at most at its old next
    /// gate, which is at or before its new one; a caller tries each tick until it succeeds.
    ///
    /// The new plan's token goes to the robot whose turn it was in the old plan (its token's
    /// robot), so the plan's flow goes on; but once some robot has seen `(N − 1)·G` services
    /// of others (`G` the new plan's groups per task; a service is the token moving on after
    /// its robot left a group) since its own last one, to the robot served least recently
    /// (the one whose last group, in whichever plan, was left the longest ago; a robot never
    /// served ranks by its first token at the start). The token sequence is rotated to start
    /// at that robot's entry for its next group (or group 0 of its next task), and in the
    /// first pass a robot's entries before its next group's are skipped, as at the start
    /// ([`token_sequence`]). So however often the plan is handed over, every robot keeps
    /// completing tasks: between two of a robot's services another robot is served at most
    /// `(2N − 1)·G` times (`G` the most groups a plan has), the bound and its proof in
    /// docs/decisions.md, "Hand-over liveness". Allocates (the rotated
    /// sequence); O(N + len) for a token sequence of `len` entries, plus O(log T_ref) per
    /// robot to place its cursors (a few microseconds for `N ≤ 8`, `benches/cyclic.rs` in
    /// tandem-schedule).
    ///
    /// # Errors
    /// [`Error::HandOver`] when `old` has another robot count, task length or control tick,
    /// has a latched fault, or a robot is not at a hand-over point; `self` is then unchanged.
    pub fn take_over(&mut self, old: &ContinuousCoordinator) -> Result<()> {
        let bad = |robot, why| Err(Error::HandOver { robot, why });
        if old.n != self.n {
            return bad(0, "the new plan has another number of robots");
        }
        check_hand_over(old, self, 0..self.n)?;
        if old.m != self.m {
            return bad(0, "the new plan has another number of operators");
        }
        let mut clock = [0.0; MAX_ROBOTS];
        let mut next = [0usize; MAX_ROBOTS];
        for i in 0..self.n {
            (clock[i], next[i]) = self.placement(old, i)?;
        }
        if let Some(sec) = self.sectors {
            self.take_over_sectors(old, &sec, &clock, &next);
            return Ok(());
        }
        let len = self.tokens.len();
        // The robot's first token: its next group, or group 0 of its next task.
        let wants = |t: &Token| t.group == next[t.robot] % self.plan(t.robot).groups.len().max(1);
        // The token goes to the robot whose turn it was in the old plan (the plan's flow
        // goes on), unless some robot has seen a whole pass's worth of others' services,
        // `(N − 1)·G`, since its own last one: then to the least recently served robot
        // (fairness: docs/decisions.md, "Hand-over liveness"). The sequence starts at the
        // chosen robot's first token.
        let lru = (0..self.n)
            .min_by_key(|&r| old.served[r])
            .expect("N ≥ 1 robots");
        let waited = old.stamp - 1 - old.served[lru];
        // The others' services in one pass of the new sequence: `(N − 1)·G` for one task.
        let others = len - self.tokens.iter().filter(|t| t.robot == lru).count();
        let lru = match old.token() {
            Some(t) if waited < others as u64 => t.robot,
            _ => lru,
        };
        let start = (0..len)
            .find(|&q| self.tokens[q].robot == lru && wants(&self.tokens[q]))
            .unwrap_or(0);
        // In the first pass, each robot's entries before its first token are skipped.
        let mut found = [false; MAX_ROBOTS];
        let skip: Vec<bool> = (0..len)
            .map(|k| {
                let t = self.tokens[(start + k) % len];
                found[t.robot] |= wants(&t);
                !found[t.robot]
            })
            .collect();
        let tokens: Vec<Token> = (0..len).map(|k| self.tokens[(start + k) % len]).collect();
        self.tokens = tokens.into();
        self.skip_first = skip.into();
        self.place_after_hand_over(old, &clock, &next);
        if self.m > 1 {
            self.init_next_entries();
        }
        self.grant(self.monitor.ticks());
        // The load cap's episode runs on too (from the start of the next one when the old cell
        // had no cap).
        if let Some(p) = &mut self.pace {
            match &old.pace {
                Some(o) => p.carry_over(o),
                None => p.reset(),
            }
        }
        Ok(())
    }

    /// Robot `i` of the running cell `old` placed on this coordinator's plan of it: its
    /// schedule clock here at its reference position in `old` (never behind it) and its next
    /// group here (the first it has not left).
    ///
    /// # Errors
    /// [`Error::HandOver`] when the robot is inside or past the gate of a group of this plan
    /// (not at a hand-over point).
    fn placement(&self, old: &ContinuousCoordinator, i: usize) -> Result<(f64, usize)> {
        let (plan, old_task) = (self.plan(i), &old.plan(i).task);
        let (c, n_groups) = (plan.task.sample_clock_s(), plan.groups.len());
        // The robot's reference position in `old`, and the same position's clock here.
        let s_old = old.clock_s[i];
        // `old`'s cursor is at or before the sample of its clock (it only advances to
        // the clock, and both reset together), so this is O(1) amortized, not O(position).
        let mut at = old.cursors[i].at;
        let n = old_task.advance_cursor(&mut at, s_old);
        let p = old_task.ref_time_in(n, s_old);
        let mut s = if p <= 0.0 {
            0.0
        } else if p >= plan.task.n_ref() as f64 {
            plan.task.end_s()
        } else {
            let k = p.floor() as usize;
            c[k] + (p - k as f64) * (c[k + 1] - c[k])
        };
        // The interpolation rounds: never place the robot behind where it is (a robot
        // never moves backwards, not even by a rounding error at a hand-over).
        while plan.task.ref_time_at(s) < p && s < plan.task.end_s() {
            // The next float up (`s ≥ 0`; `f64::next_up` is newer than the MSRV).
            s = f64::from_bits(s.to_bits() + 1);
        }
        // Its next group here: the first it has not left.
        let g = (0..n_groups)
            .find(|&g| s - self.tol_s < plan.leave_s[g])
            .unwrap_or(n_groups);
        if g < n_groups && s > plan.gate_s[g] {
            return Err(Error::HandOver {
                robot: i,
                why: "is inside or past the gate of a low-confidence group of the new plan",
            });
        }
        Ok((s, g))
    }

    /// [`take_over`](Self::take_over) of a sectored cell, the robots at `clock` with `next`
    /// their next groups (checked to be a hand-over point): each sector's token sequence is
    /// rotated as its own one-operator cell's `take_over` rotates it. When `old` has the same
    /// sectors, each sector's token goes to the robot whose turn it was in `old`'s sector,
    /// unless a robot of the sector has seen a pass's worth of its sector's services since its
    /// own last one, then to the sector's least recently served robot — the one-operator rule
    /// with the sector's own stamps, so each sector hands over exactly as its own cell. From
    /// a pooled cell or other sectors, each sector starts at its least recently served robot
    /// (`served`, one clock for every robot). Allocates the rotated sequence.
    fn take_over_sectors(
        &mut self,
        old: &ContinuousCoordinator,
        sec: &Sectors,
        clock: &[f64; MAX_ROBOTS],
        next: &[usize; MAX_ROBOTS],
    ) {
        let same = old
            .sectors
            .is_some_and(|o| o.of[..self.n] == sec.of[..self.n] && old.m == self.m);
        let wants = |t: &Token| t.group == next[t.robot] % self.plan(t.robot).groups.len().max(1);
        let mut tokens = Vec::with_capacity(self.tokens.len());
        let mut skip = Vec::with_capacity(self.tokens.len());
        let mut found = [false; MAX_ROBOTS];
        let mut sector_served = [0u64; MAX_ROBOTS];
        let mut sector_stamp = [0u64; MAX_ROBOTS];
        for o in 0..self.m {
            let (start, end) = sec.range[o];
            let members = || (0..self.n).filter(move |&r| usize::from(sec.of[r]) == o);
            let chosen = if same {
                sector_served = old.sector_served;
                sector_stamp = old.sector_stamp;
                let lru = members().min_by_key(|&r| old.sector_served[r]);
                lru.map(|lru| {
                    let waited = old.sector_stamp[o] - 1 - old.sector_served[lru];
                    let others = (end - start)
                        - (start..end)
                            .filter(|&k| self.tokens[k].robot == lru)
                            .count();
                    let old_token = old.staff.slot[o]
                        .map(|(t, _, _)| t)
                        .or_else(|| old.tokens.get(old.staff.cursor[o].0).copied());
                    match old_token {
                        Some(t) if waited < others as u64 => t.robot,
                        _ => lru,
                    }
                })
            } else {
                // The sector's robots ranked by their last service (one clock for all).
                let mut ranked = [0usize; MAX_ROBOTS];
                let mut k = 0;
                for r in members() {
                    ranked[k] = r;
                    k += 1;
                }
                ranked[..k].sort_by_key(|&r| old.served[r]);
                for (rank, &r) in ranked[..k].iter().enumerate() {
                    sector_served[r] = rank as u64;
                }
                sector_stamp[o] = k as u64;
                ranked[..k].first().copied()
            };
            let len = end - start;
            let first = chosen
                .and_then(|c| {
                    (0..len).find(|&q| {
                        let t = &self.tokens[start + q];
                        t.robot == c && wants(t)
                    })
                })
                .unwrap_or(0);
            for k in 0..len {
                let t = self.tokens[start + (first + k) % len];
                found[t.robot] |= wants(&t);
                tokens.push(t);
                skip.push(!found[t.robot]);
            }
        }
        self.tokens = tokens.into();
        self.skip_first = skip.into();
        self.place_after_hand_over(old, clock, next);
        self.sector_served = sector_served;
        self.sector_stamp = sector_stamp;
        self.monitor = self.monitor.with_sectors(self.m, sec.of);
        self.init_sector_cursors(sec);
        self.grant(self.monitor.ticks());
    }

    /// Hands sector `o` of this running sectored cell over to `new`'s plan of sector `o`
    /// (issue 44), the other sectors running on untouched: one hand-over per sector, each
    /// taken when *its own* robots are at a hand-over point, never waiting for the others'
    /// (a re-plan of `M` sectors calls it once per sector, each when it succeeds;
    /// [`take_over`](Self::take_over) needs every sector at a point at once, which sectors
    /// whose operators are busy almost all the time reach rarely). `new` is a sectored cell
    /// with the same sectors (a fresh [`sectored`](Self::sectored) of the new plan); sector
    /// `o`'s robots continue from where they are, in reference time, on `new`'s task plan,
    /// groups and sector-`o` token order, exactly as sector `o`'s own one-operator cell's
    /// [`take_over`](Self::take_over) places them and rotates its sequence (the token to the
    /// robot whose turn it was in the sector, unless a robot of the sector has seen a pass of
    /// the sector's services since its own last one, then to the sector's least recently
    /// served robot: the sector's own stamps, so its hand-over liveness is the one-operator
    /// cell's). Operator `o` keeps its switch state (the robot it last released and when);
    /// an entry it was granted whose robot has not reached its gate is dropped, as
    /// `take_over` drops it, and granted anew by the new order.
    ///
    /// **Why the guarantee holds.** Each sector keeps ticking exactly as its own one-operator
    /// cell (a robot's step reads only its own state, plan and its sector's operator), and a
    /// sector's hand-over is its own cell's `take_over`, at its own hand-over point: sector
    /// `o`'s robots are then all outside the new plan's groups, operator `o` holds nothing,
    /// so the one-operator argument starts afresh in sector `o` (at most one of its robots
    /// low-confidence in any tick, its stretches `k` ticks apart) while every other sector's
    /// state, including a robot in the middle of a stretch and its operator's slot, is not
    /// touched. The sectors' operators are disjoint and fixed, so at most one robot per
    /// sector, at most `M` in all, is low-confidence in any tick, and a robot's stretch is
    /// only ever under its sector's operator: no stretch is handed over, whatever the order in
    /// which the sectors take their plans. After the call the cell runs sector `o` on `new`'s
    /// plan and the others on theirs (per sector a plan; allocates the plans and the spliced
    /// token sequence, O(M·T_ref + len)).
    ///
    /// # Errors
    /// [`Error::HandOver`] when either cell is not sectored, the sectors differ, `o` is not a
    /// sector with robots, `new` has another robot count, task length or control tick, this
    /// cell has a latched fault, or a robot of sector `o` is not at a hand-over point of
    /// `new`; `self` is then unchanged.
    pub fn take_over_sector(&mut self, new: &ContinuousCoordinator, o: usize) -> Result<()> {
        let bad = |robot, why| Err(Error::HandOver { robot, why });
        let (Some(sec), Some(nsec)) = (self.sectors, new.sectors) else {
            return bad(0, "a sector's hand-over needs two sectored cells");
        };
        if new.n != self.n || new.m != self.m || nsec.of[..self.n] != sec.of[..self.n] {
            return bad(0, "the new plan has other sectors");
        }
        let members = (0..self.n).filter(|&r| usize::from(sec.of[r]) == o);
        let Some(first_robot) = members.clone().next() else {
            return bad(0, "names no sector with robots");
        };
        check_hand_over(self, new, members.clone())?;
        let mut clock = [0.0; MAX_ROBOTS];
        let mut next = [0usize; MAX_ROBOTS];
        for i in members.clone() {
            (clock[i], next[i]) = new.placement(self, i)?;
        }
        // Sector o's new sequence, rotated as its own cell's take_over rotates it.
        let (nstart, nend) = nsec.range[o];
        let nlen = nend - nstart;
        let n_groups = new.plan(first_robot).groups.len().max(1);
        let wants = |t: &Token| t.group == next[t.robot] % n_groups;
        let lru = members
            .clone()
            .min_by_key(|&r| self.sector_served[r])
            .expect("a sector with robots");
        let waited = self.sector_stamp[o] - 1 - self.sector_served[lru];
        let others = nlen
            - (nstart..nend)
                .filter(|&k| new.tokens[k].robot == lru)
                .count();
        let old_token = self.staff.slot[o]
            .map(|(t, _, _)| t)
            .or_else(|| self.tokens.get(self.staff.cursor[o].0).copied());
        let chosen = match old_token {
            Some(t) if waited < others as u64 => t.robot,
            _ => lru,
        };
        let first = (0..nlen)
            .find(|&q| {
                let t = &new.tokens[nstart + q];
                t.robot == chosen && wants(t)
            })
            .unwrap_or(0);
        // Splice it in place of the sector's old range; the later ranges shift.
        let (start, end) = sec.range[o];
        let mut tokens = Vec::with_capacity(self.tokens.len() - (end - start) + nlen);
        let mut skip = Vec::with_capacity(tokens.capacity());
        tokens.extend_from_slice(&self.tokens[..start]);
        skip.extend_from_slice(&self.skip_first[..start]);
        let mut found = [false; MAX_ROBOTS];
        for k in 0..nlen {
            let t = new.tokens[nstart + (first + k) % nlen];
            found[t.robot] |= wants(&t);
            tokens.push(t);
            skip.push(!found[t.robot]);
        }
        tokens.extend_from_slice(&self.tokens[end..]);
        skip.extend_from_slice(&self.skip_first[end..]);
        let shift = |p: usize| {
            if p >= end {
                p + nlen - (end - start)
            } else {
                p
            }
        };
        let mut sec2 = sec;
        for q in 0..self.m {
            let (a, b) = sec.range[q];
            if q == o || a == b {
                continue;
            }
            sec2.range[q] = (shift(a), shift(b));
            self.staff.cursor[q].0 = shift(self.staff.cursor[q].0);
            if let Some((_, pos, _)) = &mut self.staff.slot[q] {
                *pos = shift(*pos);
            }
        }
        sec2.range[o] = (start, start + nlen);
        // One plan per sector: sector o's is new's, the others keep theirs.
        let plans: Vec<Plan> = (0..self.m)
            .map(|q| {
                let r = (0..self.n).find(|&r| usize::from(sec.of[r]) == q);
                match r {
                    Some(r) if q != o => self.plan(r).clone(),
                    _ => new.plan(first_robot).clone(),
                }
            })
            .collect();
        self.plans = plans.into();
        for r in 0..self.n {
            self.plan_of[r] = sec.of[r];
        }
        self.tokens = tokens.into();
        self.skip_first = skip.into();
        self.sectors = Some(sec2);
        // One clock tolerance for all the plans (the larger errs on the safe side: module
        // docs of `tol`); the same task's plans have the same, bit for bit.
        self.tol_s = self.tol_s.max(new.tol_s);
        // Sector o's robots where they are on the new plan, none granted; the rest is kept.
        for i in members {
            self.clock_s[i] = clock[i];
            self.next_group[i] = next[i];
            let task = &self.plans[o].task;
            let (c, last) = (task.sample_clock_s(), task.n_ref() - 1);
            let k = c
                .partition_point(|&x| x <= clock[i] - self.tol_s)
                .saturating_sub(1)
                .min(last);
            self.cursors[i] = Cursors::at(k);
            self.staff.assigned[i] = None;
        }
        self.staff.slot[o] = None;
        let f = (start..start + nlen)
            .find(|&k| !self.skip_first[k])
            .unwrap_or(start);
        self.staff.cursor[o] = (f, 0);
        self.grant_sector(self.monitor.ticks(), &sec2, o);
        self.sync_sector_cursors(&sec2);
        Ok(())
    }

    /// The common part of a hand-over: every robot at `clock` with `next` its next group, the
    /// tasks, service stamps, fault monitor's tick count and the operators' switch state and
    /// preferred operators carried over from `old`, no operator holding an entry.
    fn place_after_hand_over(
        &mut self,
        old: &ContinuousCoordinator,
        clock: &[f64; MAX_ROBOTS],
        next: &[usize; MAX_ROBOTS],
    ) {
        self.clock_s = *clock;
        self.next_group = *next;
        self.tasks = old.tasks;
        // Cursors at or before each robot's sample (the tolerance below it), so the next
        // tick advances them by a few samples instead of from the task start.
        self.cursors = [Cursors::default(); MAX_ROBOTS];
        let plans = Arc::clone(&self.plans);
        for i in 0..self.n {
            let task = &plans[usize::from(self.plan_of[i])].task;
            let (c, s, last) = (task.sample_clock_s(), clock[i], task.n_ref() - 1);
            let k = c
                .partition_point(|&x| x <= s - self.tol_s)
                .saturating_sub(1)
                .min(last);
            self.cursors[i] = Cursors::at(k);
        }
        self.pos = 0;
        self.passes = 0;
        self.served = old.served;
        self.stamp = old.stamp;
        self.monitor = Monitor::resumed_at(self.n, self.m, old.monitor.ticks());
        // The switch time runs on across the hand-over: the robot each operator last released,
        // and when, are the old cell's; so is each robot's preferred operator.
        self.staff = Staff {
            last_left: old.staff.last_left,
            last_op: old.staff.last_op,
            ..Staff::default()
        };
        self.nested = None;
        self.last_lc = old.last_lc;
    }

    /// Test only: puts robot `robot` at schedule clock `clock_s` of its current task with
    /// `next_group` its next group (cursors from the task start), whatever the token rule
    /// allows — the way to a state the rule excludes (two robots inside groups at once).
    #[cfg(test)]
    pub(crate) fn place_unchecked(&mut self, robot: usize, clock_s: f64, next_group: usize) {
        self.clock_s[robot] = clock_s;
        self.next_group[robot] = next_group;
        self.cursors[robot] = Cursors::default();
    }

    fn advance_token(&mut self) {
        let len = self.tokens.len();
        loop {
            self.pos += 1;
            if self.pos == len {
                self.pos = 0;
                self.passes += 1;
            }
            if self.passes > 0 || !self.skip_first[self.pos] {
                return;
            }
        }
    }
}

impl Controller for ContinuousCoordinator {
    fn n_robots(&self) -> usize {
        ContinuousCoordinator::n_robots(self)
    }

    fn tick_s(&self) -> f64 {
        ContinuousCoordinator::tick_s(self)
    }

    fn tick(&mut self, operator: Operator) -> Result<Tick> {
        ContinuousCoordinator::tick(self, operator)
    }

    fn operators(&self) -> usize {
        self.m
    }

    fn tick_many(&mut self, inputs: &[Operator]) -> Result<Tick> {
        ContinuousCoordinator::tick_many(self, inputs)
    }

    fn operator_now(&self) -> PerRobot<Option<u8>> {
        ContinuousCoordinator::operator_now(self)
    }

    fn reset(&mut self) {
        ContinuousCoordinator::reset(self);
    }

    fn fault(&self) -> Option<Fault> {
        ContinuousCoordinator::fault(self)
    }

    fn clear_fault(&mut self) {
        ContinuousCoordinator::clear_fault(self);
    }

    fn low_conf_now(&self) -> RobotFlags {
        ContinuousCoordinator::low_conf_now(self)
    }

    fn running_now(&self) -> RobotFlags {
        ContinuousCoordinator::running_now(self)
    }

    fn waiting_now(&self) -> RobotFlags {
        self.at_gate_now()
    }

    fn pre_alert(&self) -> Option<crate::PreAlert> {
        ContinuousCoordinator::pre_alert(self)
    }

    /// O(N log T_ref): each robot's reference time at its clock ([`Self::position_now`]).
    fn ref_time_now(&self) -> PerRobot<f64> {
        let mut out = PerRobot::new(self.n);
        for (i, t) in out.as_mut_slice().iter_mut().enumerate() {
            *t = self.plan(i).task.ref_time_at(self.clock_s[i]);
        }
        out
    }

    fn tasks_now(&self) -> PerRobot<u64> {
        PerRobot::from_slice(self.tasks_completed())
    }

    fn clock_s(&self) -> &[f64] {
        ContinuousCoordinator::clock_s(self)
    }

    /// Never: the robots repeat the task for ever.
    fn is_finished(&self) -> bool {
        false
    }

    fn ticks(&self) -> u64 {
        ContinuousCoordinator::ticks(self)
    }
}

/// What [`run_cell`] measured: the one [`AdversaryRun`] of every controller.
#[deprecated(
    note = "the one run of the adversary driver is `tandem_realtime::adversary::AdversaryRun`"
)]
pub type CellRun = AdversaryRun;

/// Runs `cell` from its current state until every robot has completed `min_tasks` tasks (or
/// for at most `max_ticks` ticks) with the operator inputs of the policy `adversary`, drawing
/// from `rng`: the one adversary driver of every controller,
/// [`run_adversary_on`](crate::adversary::run_adversary_on) (the beam search
/// [`Adversary::Beam`] runs as [`Adversary::SwitchFavourite`] with holds up to 50 ticks; a
/// fault is counted and cleared). Allocates nothing.
///
/// # Errors
/// [`Error::BadOperator`] for a policy producing an inadmissible gradient.
pub fn run_cell(
    cell: &mut ContinuousCoordinator,
    adversary: Adversary,
    rng: &mut impl Rng,
    min_tasks: u64,
    max_ticks: u64,
) -> Result<AdversaryRun> {
    crate::adversary::run_adversary_on(cell, adversary, rng, min_tasks, max_ticks)
}

/// The hand-over preconditions that [`ContinuousCoordinator::take_over`] (every robot) and
/// [`ContinuousCoordinator::take_over_sector`] (a sector's robots) share: each robot of
/// `robots` has a task of the same length (reference samples) in `old` and `new`, both run at
/// the same control tick (s, to 1e-12 relative), and `old` has no latched fault.
fn check_hand_over(
    old: &ContinuousCoordinator,
    new: &ContinuousCoordinator,
    mut robots: impl Iterator<Item = usize>,
) -> Result<()> {
    let bad = |robot, why| Err(Error::HandOver { robot, why });
    if let Some(i) = robots.find(|&i| old.plan(i).task.n_ref() != new.plan(i).task.n_ref()) {
        return bad(
            i,
            "the new plan's task has another number of reference samples",
        );
    }
    if (old.tick_s - new.tick_s).abs() > 1e-12 * new.tick_s.max(old.tick_s) {
        return bad(0, "the new plan runs at another control tick");
    }
    if let Some(f) = old.monitor.fault() {
        return bad(f.stopped, "the old cell has a latched fault");
    }
    Ok(())
}
