//! How the robots repeat the task ([`Cell`]), the plan of either kind of cell ([`Plan`]) and
//! its run-time coordinator ([`AnyController`]), as [`Planner::plan`] and
//! [`Planner::controller`] make them (issue 40: the planner owns the plan, and every front
//! end — CLI, Python, the simulator's study, xtask — asks it instead of building one).
//!
//! **One tick.** Both kinds of cell run at the current schedule's control tick
//! ([`Schedule::tick_s`](tandem_schedule::Schedule::tick_s): `ScheduleParams`' tick, `Δt_s`
//! by default), the tick the rounds schedule was checked at; the continuous plan counts the
//! token rule's hand-overs at it ([`CheckedCyclicPlan::search`]), so its period is what the
//! cell does at that tick (docs/decisions.md, "The planner owns the plan: one cell type, one
//! tick").

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use tandem_realtime::adversary::AdversaryRun;
use tandem_realtime::{
    ContinuousCoordinator, Controller, Coordinator, Fault, Operator, PerRobot, RobotFlags, Tick,
};
use tandem_schedule::{CheckedCyclicPlan, CheckedSchedule, CyclicParams};

use crate::{Error, Planner, Result};

/// How the robots of a cell repeat the task. Its text form (serde, the CLI's `--cell`,
/// Python's `cell=`, a study's `cell = "…"`) is the lowercase name: `rounds`, `continuous`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Cell {
    /// In rounds (the paper): all `N` robots start a round together; the next round starts
    /// when the last one finishes. Planned by the schedule (Eq. 20), run by the coordinator of
    /// §II-B5.
    #[default]
    Rounds,
    /// A continuous cell (issue 21): each robot starts its next task as soon as it is safe.
    /// Planned by the cyclic plan, run by the token rule's continuous coordinator.
    Continuous,
}

impl Cell {
    /// Every kind, rounds first.
    pub const ALL: [Cell; 2] = [Cell::Rounds, Cell::Continuous];

    /// Its text form: `rounds` or `continuous`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Cell::Rounds => "rounds",
            Cell::Continuous => "continuous",
        }
    }

    /// A one-line description for a command line's help.
    #[must_use]
    pub fn help(self) -> &'static str {
        match self {
            Cell::Rounds => {
                "Rounds: all robots start together; the next round starts when the last one \
                 finishes"
            }
            Cell::Continuous => {
                "A continuous cell: each robot starts its next task once the cyclic plan lets it"
            }
        }
    }

    /// Whether it is [`Cell::Rounds`].
    #[must_use]
    pub fn is_rounds(&self) -> bool {
        *self == Cell::Rounds
    }
}

impl fmt::Display for Cell {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Cell {
    type Err = Error;

    /// `rounds` or `continuous` (exactly; [`Error::UnknownCell`] otherwise).
    fn from_str(s: &str) -> Result<Cell> {
        Cell::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| Error::UnknownCell {
                given: s.to_string(),
            })
    }
}

/// Which continuous cell `M > 1` operators run (issue 44): its text form (serde, the study's
/// `[operator] fleet_cell`, xtask's `--fleet-cell`) is the lowercase name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FleetCell {
    /// The cell of the larger measured throughput ([`Planner::fleet_coordinator`]): the
    /// sectors only when they are strictly better, else the pooled cell.
    #[default]
    Auto,
    /// The pooled cell: every operator serves every robot (the plan's order, `M` tokens).
    Pooled,
    /// The even sectors, each a one-operator cell of its own plan.
    Sectored,
}

impl FleetCell {
    /// Every choice, `auto` first.
    pub const ALL: [FleetCell; 3] = [FleetCell::Auto, FleetCell::Pooled, FleetCell::Sectored];

    /// Its text form: `auto`, `pooled` or `sectored`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            FleetCell::Auto => "auto",
            FleetCell::Pooled => "pooled",
            FleetCell::Sectored => "sectored",
        }
    }

    /// Whether it is [`FleetCell::Auto`] (serde's `skip_serializing_if`).
    #[must_use]
    pub fn is_auto(&self) -> bool {
        *self == FleetCell::Auto
    }
}

impl fmt::Display for FleetCell {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for FleetCell {
    type Err = Error;

    /// `auto`, `pooled` or `sectored` (exactly; [`Error::UnknownFleetCell`] otherwise).
    fn from_str(s: &str) -> Result<FleetCell> {
        FleetCell::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| Error::UnknownFleetCell {
                given: s.to_string(),
            })
    }
}

/// What [`Planner::fleet_coordinator`] ran for `M > 1` operators and why: the cell, the
/// sectors' sizes, and the throughputs (tasks per hour) measured with the planned operator
/// ([`tandem_schedule::nominal_tasks_per_hour`]; `None` where a forced choice measured
/// nothing).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FleetPick {
    /// [`FleetCell::Pooled`] or [`FleetCell::Sectored`]: the cell that runs.
    pub cell: FleetCell,
    /// The even sectors' sizes (the sectored candidate; robots `0..k₀`, then the next `k₁`, …).
    pub sectors: Vec<usize>,
    /// The pooled cell's measured throughput.
    pub pooled_tasks_per_hour: Option<f64>,
    /// The sectored cell's measured throughput.
    pub sectored_tasks_per_hour: Option<f64>,
    /// The sectors' planned throughput, the sum of their one-operator plans'.
    pub sectored_planned_tasks_per_hour: Option<f64>,
}

/// The plan of a cell on the planner's current problem ([`Planner::plan`]), checked on it at
/// the tick it runs at.
#[derive(Clone, Debug)]
pub enum Plan {
    /// In rounds: the current schedule, checked ([`Planner::checked_schedule`]).
    Rounds(CheckedSchedule),
    /// A continuous cell: the cyclic plan of the planner's robots, checked at the schedule's
    /// tick ([`Planner::cyclic_plan`]).
    Continuous(CheckedCyclicPlan),
}

impl Plan {
    /// The kind of cell it plans.
    #[must_use]
    pub fn cell(&self) -> Cell {
        match self {
            Plan::Rounds(_) => Cell::Rounds,
            Plan::Continuous(_) => Cell::Continuous,
        }
    }

    /// The control tick (real s) it was checked at and runs at.
    #[must_use]
    pub fn tick_s(&self) -> f64 {
        match self {
            Plan::Rounds(s) => s.schedule().tick_s,
            Plan::Continuous(c) => c.tick_s(),
        }
    }

    /// Robots `N` it plans.
    #[must_use]
    pub fn n_robots(&self) -> usize {
        match self {
            Plan::Rounds(s) => s.schedule().n_robots(),
            Plan::Continuous(c) => c.n_robots(),
        }
    }

    /// Its run-time coordinator, every robot at its start, at [`Plan::tick_s`].
    ///
    /// # Errors
    /// None in practice (the plan was checked); the coordinator's own argument checks for
    /// rounds ([`CheckedSchedule::coordinator`]).
    pub fn controller(&self) -> Result<AnyController> {
        Ok(match self {
            Plan::Rounds(s) => AnyController::Rounds(s.coordinator()?),
            Plan::Continuous(c) => AnyController::Continuous(c.coordinator()),
        })
    }

    /// The rounds schedule, if it is one.
    #[must_use]
    pub fn as_rounds(&self) -> Option<&CheckedSchedule> {
        match self {
            Plan::Rounds(s) => Some(s),
            Plan::Continuous(_) => None,
        }
    }

    /// The cyclic plan, if it is one.
    #[must_use]
    pub fn as_continuous(&self) -> Option<&CheckedCyclicPlan> {
        match self {
            Plan::Rounds(_) => None,
            Plan::Continuous(c) => Some(c),
        }
    }
}

/// The run-time coordinator of either kind of cell ([`Planner::controller`]), with what both
/// share forwarded; each tick is its own coordinator's (`tick` of the variant).
#[derive(Clone, Debug)]
// Both coordinators are kept inline (the continuous one carries its operators' state, issue
// 44): boxing one would allocate at every clone, which the cell's no-allocation tests forbid.
#[allow(clippy::large_enum_variant)]
pub enum AnyController {
    /// Rounds: the coordinator of §II-B5 (Eq. 17–18, Alg. 1).
    Rounds(Coordinator),
    /// A continuous cell: the token rule's coordinator.
    Continuous(ContinuousCoordinator),
}

impl AnyController {
    /// The kind of cell it runs.
    #[must_use]
    pub fn cell(&self) -> Cell {
        match self {
            AnyController::Rounds(_) => Cell::Rounds,
            AnyController::Continuous(_) => Cell::Continuous,
        }
    }

    /// The rounds coordinator, if it is one.
    #[must_use]
    pub fn as_rounds(&self) -> Option<&Coordinator> {
        match self {
            AnyController::Rounds(c) => Some(c),
            AnyController::Continuous(_) => None,
        }
    }

    /// The continuous coordinator, if it is one.
    #[must_use]
    pub fn as_continuous(&self) -> Option<&ContinuousCoordinator> {
        match self {
            AnyController::Rounds(_) => None,
            AnyController::Continuous(c) => Some(c),
        }
    }
}

/// Both kinds of cell behind the one run-time contract: every method is the variant's own.
macro_rules! each {
    ($self:expr, $c:ident => $e:expr) => {
        match $self {
            AnyController::Rounds($c) => $e,
            AnyController::Continuous($c) => $e,
        }
    };
}

impl Controller for AnyController {
    fn n_robots(&self) -> usize {
        each!(self, c => c.n_robots())
    }
    fn tick_s(&self) -> f64 {
        each!(self, c => c.tick_s())
    }
    fn tick(&mut self, operator: Operator) -> tandem_realtime::Result<Tick> {
        each!(self, c => Controller::tick(c, operator))
    }
    fn operators(&self) -> usize {
        each!(self, c => Controller::operators(c))
    }
    fn tick_many(&mut self, inputs: &[Operator]) -> tandem_realtime::Result<Tick> {
        each!(self, c => Controller::tick_many(c, inputs))
    }
    fn operator_now(&self) -> tandem_realtime::PerRobot<Option<u8>> {
        each!(self, c => Controller::operator_now(c))
    }
    fn reset(&mut self) {
        each!(self, c => Controller::reset(c))
    }
    fn fault(&self) -> Option<Fault> {
        each!(self, c => Controller::fault(c))
    }
    fn clear_fault(&mut self) {
        each!(self, c => Controller::clear_fault(c))
    }
    fn low_conf_now(&self) -> RobotFlags {
        each!(self, c => Controller::low_conf_now(c))
    }
    fn running_now(&self) -> RobotFlags {
        each!(self, c => Controller::running_now(c))
    }
    fn waiting_now(&self) -> RobotFlags {
        each!(self, c => Controller::waiting_now(c))
    }
    fn pre_alert(&self) -> Option<tandem_realtime::PreAlert> {
        each!(self, c => Controller::pre_alert(c))
    }
    fn ref_time_now(&self) -> PerRobot<f64> {
        each!(self, c => Controller::ref_time_now(c))
    }
    fn tasks_now(&self) -> PerRobot<u64> {
        each!(self, c => Controller::tasks_now(c))
    }
    fn clock_s(&self) -> &[f64] {
        each!(self, c => Controller::clock_s(c))
    }
    fn is_finished(&self) -> bool {
        each!(self, c => Controller::is_finished(c))
    }
    fn ticks(&self) -> u64 {
        each!(self, c => Controller::ticks(c))
    }
    fn beam_search(
        &self,
        width: u32,
        max_ticks: u64,
    ) -> Option<tandem_realtime::Result<AdversaryRun>> {
        each!(self, c => Controller::beam_search(c, width, max_ticks))
    }
}

impl Planner {
    /// The plan of a `cell` of this planner's robots on the current problem, at the current
    /// schedule's control tick ([`Schedule::tick_s`](tandem_schedule::Schedule::tick_s), the
    /// one tick of both kinds of cell: the tick the rounds schedule was checked at, and the
    /// continuous plan counts the token rule's hand-overs at it): in rounds the current schedule
    /// checked on the problem ([`Planner::checked_schedule`]), for a continuous cell the
    /// cyclic plan ([`Planner::cyclic_plan`] with the default [`CyclicParams`] and the
    /// operator's switch time and load cap of the sampler's parameters,
    /// [`tandem_schedule::SamplerParams::switch_s`] and `max_busy_share`). A snapshot:
    /// the planner is not changed, and the state file keeps the rounds schedule it records
    /// from.
    ///
    /// # Errors
    /// As [`Planner::checked_schedule`] and [`Planner::cyclic_plan`].
    pub fn plan(&self, cell: Cell) -> Result<Plan> {
        Ok(match cell {
            Cell::Rounds => Plan::Rounds(self.checked_schedule()?),
            Cell::Continuous => {
                let params = CyclicParams {
                    switch_s: self.params().sampler.switch_s,
                    max_busy_share: self.params().sampler.max_busy_share,
                    ..CyclicParams::default()
                };
                Plan::Continuous(self.cyclic_plan(&params, None)?)
            }
        })
    }

    /// The run-time coordinator of [`Planner::plan`]`(cell)`: every robot at its start, one
    /// control tick of the schedule's `tick_s` per tick, with the operator's switch time of
    /// the planner's parameters (`params().sampler.switch_s`): rounds wait it at a hold with
    /// release rules and ask a rest after the round under the load cap (it is
    /// [`Planner::coordinator`]), a continuous cell's token passes to
    /// another robot no sooner than that after a stretch ended, and paces the operator to the
    /// load cap `params().sampler.max_busy_share` (`ContinuousCoordinator::with_max_busy_share`).
    ///
    /// # Errors
    /// As [`Planner::plan`].
    ///
    /// With `params().sampler.operators = M > 1` (issue 44) a continuous cell runs `M` tokens
    /// ([`Planner::continuous_coordinator`]); rounds run the sectored round of
    /// [`Planner::sectored_rounds`] (`M` one-operator rounds side by side).
    pub fn controller(&self, cell: Cell) -> Result<AnyController> {
        let sp = &self.params().sampler;
        match self.plan(cell)? {
            Plan::Rounds(s) => {
                let c = if sp.operators > 1 {
                    self.sectored_rounds()?.1
                } else {
                    s.coordinator()?.with_switch_s(sp.switch_s)?
                };
                Ok(AnyController::Rounds(
                    c.with_max_busy_share(sp.max_busy_share)?,
                ))
            }
            Plan::Continuous(c) => Ok(AnyController::Continuous(self.continuous_coordinator(&c)?)),
        }
    }

    /// The run-time coordinator of a continuous cell's `plan` with this planner's operators:
    /// the switch time `params().sampler.switch_s` (the token passes to another robot no
    /// sooner than that after a stretch ended), the load cap `max_busy_share` (one operator
    /// only) and, for `operators = M > 1`, `M` tokens
    /// ([`ContinuousCoordinator::with_operators`](tandem_realtime::ContinuousCoordinator::with_operators),
    /// issue 44). The one place that builds it (the study's cell uses it too). One operator:
    /// no call of `with_operators`, the coordinator of before bit for bit.
    ///
    /// # Errors
    /// The realtime crate's for a bad switch time or load cap, or a load cap below 1 with
    /// `M > 1` (the run-time pace serves one operator), or an operator count out of range.
    ///
    /// With `M > 1` the cell is the pooled one (`plan`'s order served by `M` tokens) or the
    /// even sectors, whichever measures faster with the planned operator
    /// ([`Planner::fleet_coordinator`] with [`FleetCell::Auto`]): then each sector runs the
    /// one-operator plan of its size under its own operator
    /// ([`tandem_schedule::sectored_coordinator`]), and `plan` is not run.
    pub fn continuous_coordinator(
        &self,
        plan: &CheckedCyclicPlan,
    ) -> Result<tandem_realtime::ContinuousCoordinator> {
        Ok(self.fleet_coordinator(plan, FleetCell::Auto)?.0)
    }

    /// [`Planner::continuous_coordinator`] with the cell of `M > 1` operators chosen by
    /// `fleet`, and what was chosen (`None` for one operator). [`FleetCell::Auto`] builds both
    /// cells — the pooled one (`plan`'s order, `M` tokens) and the even sectors
    /// (`even_sector_sizes`, contiguous robots, each the one-operator plan of its size,
    /// searched here with the planner's cyclic parameters at `plan`'s tick) — and measures
    /// each from its start with the planned operator over 30 periods of the pooled bound after
    /// 5 to settle ([`tandem_schedule::nominal_tasks_per_hour`]): the sectors run only when
    /// strictly faster. The pooled plan is searched in any case (it is `plan`, the one the
    /// study records), so nothing is searched for the comparison but the sectors' plans.
    /// [`FleetCell::Pooled`] and [`FleetCell::Sectored`] force the cell, measuring nothing.
    ///
    /// # Errors
    /// As [`Planner::continuous_coordinator`]; the schedule crate's for a sector's plan.
    pub fn fleet_coordinator(
        &self,
        plan: &CheckedCyclicPlan,
        fleet: FleetCell,
    ) -> Result<(tandem_realtime::ContinuousCoordinator, Option<FleetPick>)> {
        let sp = &self.params().sampler;
        if sp.operators <= 1 {
            let c = plan.coordinator().with_switch_s(sp.switch_s)?;
            return Ok((c.with_max_busy_share(sp.max_busy_share)?, None));
        }
        let m = tandem_realtime::OperatorCount::new(sp.operators)?;
        let n = self.n_robots();
        let pooled = || -> Result<tandem_realtime::ContinuousCoordinator> {
            Ok(plan
                .coordinator()
                .with_switch_s(sp.switch_s)?
                .with_operators(m))
        };
        let sizes = tandem_schedule::even_sector_sizes(n, m.get());
        let sectored = || -> Result<(tandem_realtime::ContinuousCoordinator, f64)> {
            let params = CyclicParams {
                switch_s: sp.switch_s,
                max_busy_share: sp.max_busy_share,
                ..CyclicParams::default()
            };
            let mut plans: Vec<CheckedCyclicPlan> = Vec::new();
            for &k in &sizes {
                if !plans.iter().any(|p| p.n_robots() == k) {
                    plans.push(CheckedCyclicPlan::search(
                        self.problem(),
                        k,
                        &params,
                        plan.tick_s(),
                    )?);
                }
            }
            let (c, planned) = tandem_schedule::sectored_coordinator(
                self.problem(),
                &sizes,
                &plans,
                plan.tick_s(),
            )?;
            Ok((c.with_switch_s(sp.switch_s)?.with_operators(m), planned))
        };
        let mut pick = FleetPick {
            cell: FleetCell::Pooled,
            sectors: sizes.clone(),
            pooled_tasks_per_hour: None,
            sectored_tasks_per_hour: None,
            sectored_planned_tasks_per_hour: None,
        };
        let c = match fleet {
            FleetCell::Pooled => pooled()?,
            FleetCell::Sectored => {
                let (c, planned) = sectored()?;
                pick.cell = FleetCell::Sectored;
                pick.sectored_planned_tasks_per_hour = Some(planned);
                c
            }
            FleetCell::Auto => {
                let period_s =
                    tandem_schedule::pooled_period_lower_bound_s(self.problem(), n, m.get())?;
                let p = pooled()?;
                let p_rate = tandem_schedule::nominal_tasks_per_hour(&p, period_s, 5, 30)?;
                pick.pooled_tasks_per_hour = Some(p_rate);
                if n > 1 {
                    let (s, planned) = sectored()?;
                    let s_rate = tandem_schedule::nominal_tasks_per_hour(&s, period_s, 5, 30)?;
                    pick.sectored_tasks_per_hour = Some(s_rate);
                    pick.sectored_planned_tasks_per_hour = Some(planned);
                    if s_rate > p_rate {
                        pick.cell = FleetCell::Sectored;
                        s
                    } else {
                        p
                    }
                } else {
                    p
                }
            }
        };
        Ok((c.with_max_busy_share(sp.max_busy_share)?, Some(pick)))
    }

    /// The ceilings (tasks per hour) of the pooled cell and the even sectors of this planner's
    /// `M = params().sampler.operators` operators on the current problem
    /// ([`tandem_schedule::fleet_cell_choice`]). Which cell runs is measured, not read from
    /// these: [`Planner::fleet_coordinator`].
    ///
    /// # Errors
    /// The schedule crate's for a robot or operator count out of range.
    pub fn fleet_cell(&self) -> Result<tandem_schedule::FleetCellChoice> {
        Ok(tandem_schedule::fleet_cell_choice(
            self.problem(),
            self.n_robots(),
            self.params().sampler.operators,
        )?)
    }

    /// The cyclic plan of a continuous cell of this planner's robots on the current problem
    /// (`tandem_schedule::cyclic_plan` with `params`), its hand-overs counted at and checked
    /// for the cell's tick: `tick_s` (real s), by default the current schedule's
    /// ([`CheckedCyclicPlan::search`]).
    ///
    /// # Errors
    /// The schedule crate's [`tandem_schedule::Error::BadParam`] for bad `params` or a
    /// `tick_s` not finite and > 0 (naming it).
    pub fn cyclic_plan(
        &self,
        params: &CyclicParams,
        tick_s: Option<f64>,
    ) -> Result<CheckedCyclicPlan> {
        let tick_s = tick_s.unwrap_or(self.schedule().tick_s);
        Ok(CheckedCyclicPlan::search(
            self.problem(),
            self.n_robots(),
            params,
            tick_s,
        )?)
    }
}
