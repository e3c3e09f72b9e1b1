//! One run of the loop: a prepared task, `N` robots, rounds or a continuous cell, through the
//! study's own loops (`tandem_sim::study::run_trial_on`, `run_cell_trial_on`), with what the
//! report needs read from the study's records and from every round's per-tick logs.

use std::sync::{Mutex, PoisonError};

use serde::{Deserialize, Serialize};
use tandem_planner::{Planner, derive_seed};
use tandem_schedule::PreviousFate;
use tandem_sim::study::{Cell, RoundView, StudyConfig, run_cell_trial_on, run_trial_on};
use tandem_sim::workcell::{FinishedTask, PlanGap};

use super::prepare::{Prepared, falsely_trusted_split};
use crate::Result;

/// What one run of the loop did (one family, seed, robot count and cell). Times in seconds;
/// for a continuous cell the "`T_total`" of a plan is its period `P` (the time of `N` tasks,
/// one per robot, as a round's `T_total` is).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunReport {
    /// The family.
    pub family: String,
    /// The seed.
    pub seed: u64,
    /// Robots `N`.
    pub robots: usize,
    /// Rounds or continuous.
    pub cell: Cell,
    /// Rounds recorded (continuous: re-plans after `N` completed tasks each).
    pub rounds: usize,
    /// `T_total` (rounds) or period (continuous) of every plan, the fit's first.
    pub t_total_s: Vec<f64>,
    /// High confidence (%) of every plan.
    pub high_pct: Vec<f64>,
    /// The last plan's lower bound (s): the margin-free bound of its certificate
    /// (`Outcome::lower_bound_s`; continuous: `CyclicPlan::lower_bound_s`).
    pub bound_s: f64,
    /// Whether that bound is the proven margin-free optimum (rounds only; `false` for a cell).
    pub bound_is_optimum: bool,
    /// The least `T_total` (s) known of a schedule without margins on the last plan's problem
    /// (`Outcome::margin_free_s`): the bound and it split the gap into what the margin-free
    /// search left open and what the margins (or what the scheduler did not find) cost
    /// (`Outcome::gap_split`). Rounds only; `None` for a cell and in reports saved before it.
    #[serde(default)]
    pub margin_free_s: Option<f64>,
    /// The last plan's bound that charges every switch between the two robots' low-confidence
    /// runs its least margin and the drag lead the check must see there (s,
    /// `tandem_schedule::held_charged_bound` at the plan's tick, with usable hold points the
    /// least of the drag lead and what a wait at the follower's last hold saves; reports saved
    /// before it hold `drag_charged_bound` or `switch_charged_bound`): no schedule the margin
    /// check accepts (with holds: whose planned dwells cover its release rules, as the
    /// scheduler's do) is shorter, so `T_total` above it is what the completion did not find,
    /// and it above [`RunReport::margin_free_s`] is what the margins cost every schedule.
    /// Rounds of two robots only; `None` otherwise and in reports saved before it.
    #[serde(default)]
    pub switch_charged_s: Option<f64>,
    /// The serial schedule's `T_total` on the last plan's problem (`N` fastest executions one
    /// after the other, `Problem::serial_schedule_n`).
    pub serial_s: f64,
    /// Truth: percent of the reference that never needs the operator.
    pub truth_high_pct: f64,
    /// High-confidence reference samples where the operator can be needed and the
    /// demonstrations vary (a variable section), after the last round.
    pub falsely_trusted: usize,
    /// The same where every demonstration agrees (no variance reveals the need there).
    pub falsely_trusted_agreeing: usize,
    /// Rounds recorded before the first schedule in which the robots overlap (its `T_total`
    /// is below the serial schedule's on the same problem by more than half a tick); `None`
    /// when no schedule did, or for a continuous cell (not measured).
    pub first_overlap_round: Option<usize>,
    /// The largest increase of `T_total` (period) from one plan to the next (s; ≤ 0 when it
    /// never increased).
    pub max_increase_s: f64,
    /// The plan after which that increase came (rounds recorded; `None` with a single plan).
    pub max_increase_at: Option<usize>,
    /// The round-to-round changes of `T_total` split by what became of the previous schedule
    /// in the re-schedule that made the later plan (`Outcome::previous`): still valid, re-timed
    /// (repaired) or invalid on the updated model. Rounds only; all empty for a cell and in
    /// reports saved before it.
    #[serde(default)]
    pub by_fate: FateIncreases,
    /// Mean over rounds of realized duration over planned `T_total` (continuous: the last
    /// plan's planned throughput over the steady realized one).
    pub realized_over_planned: f64,
    /// The same for the last round alone (continuous: as `realized_over_planned`).
    pub realized_over_planned_last: f64,
    /// Planned throughput of the last round run (tasks per hour per operator).
    pub planned_per_h: f64,
    /// Its realized throughput (tasks per hour per operator; continuous: the steady window).
    pub realized_per_h: f64,
    /// Realized against planned time and its causes (s; `tandem_sim::workcell::PlanGap`):
    /// rounds: every round's gap summed (realized − planned `T_total`); continuous: the
    /// steady window's tasks against the plan's period (`Steady::plan_gap`).
    #[serde(default)]
    pub plan_gap: PlanGap,
    /// Samples run at high confidence where the truth needed the operator: over every round
    /// (continuous: the steady window).
    #[serde(default)]
    pub needed_unsupervised: usize,
    /// Ticks in which a robot's reference time decreased, over every robot and round (must
    /// be 0), counted from the reference-time logs.
    pub backward_steps: usize,
    /// The largest such decrease (reference samples; 0 without one).
    pub max_backward_samples: f64,
    /// Ticks with two or more robots low-confidence (must be 0).
    pub overlap_ticks: u64,
    /// Faults of the coordinators' monitors (must be 0).
    pub faults: u64,
    /// Control tick (s).
    pub tick_s: f64,
}

impl RunReport {
    /// The last plan's `T_total` (period).
    #[must_use]
    pub fn final_t_s(&self) -> f64 {
        self.t_total_s.last().copied().unwrap_or(f64::NAN)
    }

    /// The last plan's high confidence (%).
    #[must_use]
    pub fn final_high_pct(&self) -> f64 {
        self.high_pct.last().copied().unwrap_or(f64::NAN)
    }

    /// `T_total / bound − 1`, percent.
    #[must_use]
    pub fn gap_pct(&self) -> f64 {
        100.0 * (self.final_t_s() / self.bound_s - 1.0)
    }

    /// [`RunReport::gap_pct`] split as `Outcome::gap_split` splits it, percent of the bound:
    /// `(search, margins)`, the margin-free search's open interval `(margin_free − bound)` and
    /// the rest `(T_total − margin_free)`; they add up to the gap. `None` without
    /// [`RunReport::margin_free_s`].
    #[must_use]
    pub fn gap_split_pct(&self) -> Option<(f64, f64)> {
        let free = self.margin_free_s?;
        Some((
            100.0 * (free - self.bound_s) / self.bound_s,
            100.0 * (self.final_t_s() - free) / self.bound_s,
        ))
    }

    /// The part of the margins' share of [`RunReport::gap_split_pct`] that no valid schedule
    /// avoids, percent of the bound: `(switch_charged − margin_free)/bound`. `None` without
    /// [`RunReport::switch_charged_s`] or [`RunReport::margin_free_s`].
    #[must_use]
    pub fn unavoidable_pct(&self) -> Option<f64> {
        let free = self.margin_free_s?;
        let charged = self.switch_charged_s?;
        Some(100.0 * (charged - free) / self.bound_s)
    }
}

/// [`RunReport::switch_charged_s`] of the planner's last problem at control tick `tick_s` (s).
fn switch_charged_s(planner: &Planner, robots: usize, tick_s: f64) -> Option<f64> {
    if robots != 2 {
        return None;
    }
    let exact = tandem_schedule::ExactParams::default();
    tandem_schedule::held_charged_bound(planner.problem(), &exact, tick_s)
        .ok()
        .filter(|b| b.charged)
        .map(|b| b.lower_bound_s)
}

/// Backward steps of the reference-time logs: `(count, largest decrease)`.
fn backward_steps<'a>(logs: impl IntoIterator<Item = &'a [f64]>) -> (usize, f64) {
    logs.into_iter()
        .flat_map(|log| log.windows(2))
        .filter(|w| w[1] < w[0])
        .fold((0, 0.0), |(n, max), w| (n + 1, f64::max(max, w[0] - w[1])))
}

/// The serial schedule's `T_total` on the planner's problem, at its schedule's tick.
fn serial_s(planner: &Planner) -> Result<f64> {
    let problem = planner.problem();
    let schedule = problem
        .serial_schedule_n(planner.n_robots(), planner.schedule().tick_s)
        .map_err(tandem_sim::Error::from)?;
    Ok(schedule.t_total_s(problem.dt_s()))
}

/// The study seed of a run: the task's seed, the family and the robot count, mixed
/// (`derive_seed`), so that every run has its own sampler and operator streams and none
/// depends on which other runs are made.
fn run_seed(prep: &Prepared, robots: usize, cell: Cell) -> u64 {
    let family = prep.family.bytes().fold(0xcbf2_9ce4_8422_2325_u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    });
    let cell = match cell {
        Cell::Rounds => 0,
        Cell::Continuous => 1,
    };
    derive_seed(derive_seed(family, prep.seed), (robots as u64) << 1 | cell)
}

/// The study configuration of a run: one trial of `rounds` rounds (`rounds·N` tasks), the
/// prepared planner parameters (the defaults with the family's holds), the sampler's default
/// number of samples, the study's simulated operator.
fn config(prep: &Prepared, robots: usize, cell: Cell, rounds: usize) -> StudyConfig {
    StudyConfig {
        trials: 1,
        executions: rounds * robots,
        robots,
        samples: prep.planner.sampler.samples,
        seed: run_seed(prep, robots, cell),
        example_iterations: Vec::new(),
        planner: prep.planner.clone(),
        cell,
        ..StudyConfig::default()
    }
}

/// What became of the previous schedule in one re-schedule ([`PreviousFate`] without its
/// details), as [`FateIncreases`] counts it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fate {
    /// Still valid on the updated model ([`PreviousFate::Valid`]): the re-schedule is never
    /// longer, so an increase here is the scheduler's.
    Valid,
    /// Invalid as it was, valid re-timed ([`PreviousFate::Repaired`]): the re-schedule is never
    /// longer than the re-timing, so an increase is what the model update and the re-timing
    /// cost.
    Repaired,
    /// Invalid, re-timed too ([`PreviousFate::Invalid`]): nothing bounds the re-schedule.
    Invalid,
}

impl Fate {
    /// The fate of `previous`; `None` when no previous schedule was given.
    #[must_use]
    pub fn of(previous: &PreviousFate) -> Option<Fate> {
        match previous {
            PreviousFate::NotGiven => None,
            PreviousFate::Valid { .. } => Some(Fate::Valid),
            PreviousFate::Repaired { .. } => Some(Fate::Repaired),
            PreviousFate::Invalid { .. } => Some(Fate::Invalid),
        }
    }
}

/// Re-schedules of one [`Fate`] and the largest change of `T_total` over one of them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FateCount {
    /// Re-schedules with this fate.
    pub count: usize,
    /// The largest `T_total` after one minus `T_total` before it (s; ≤ 0 when none increased);
    /// `None` when [`FateCount::count`] is 0.
    pub max_increase_s: Option<f64>,
}

impl FateCount {
    fn add(&mut self, increase_s: f64) {
        self.count += 1;
        self.max_increase_s = Some(
            self.max_increase_s
                .map_or(increase_s, |m| m.max(increase_s)),
        );
    }

    /// The two counts as one (counts added, the larger increase).
    #[must_use]
    pub fn merged(self, other: FateCount) -> FateCount {
        FateCount {
            count: self.count + other.count,
            max_increase_s: match (self.max_increase_s, other.max_increase_s) {
                (Some(a), Some(b)) => Some(a.max(b)),
                (a, b) => a.or(b),
            },
        }
    }
}

/// The round-to-round changes of `T_total` by the previous schedule's [`Fate`] in the
/// re-schedule that made the later plan, so a reader tells the increases that learning forced
/// (the model changed where the old schedule relied on it) from the scheduler's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct FateIncreases {
    /// The previous schedule still valid.
    pub valid: FateCount,
    /// The previous schedule re-timed.
    pub repaired: FateCount,
    /// The previous schedule and its re-timing invalid.
    pub invalid: FateCount,
}

impl FateIncreases {
    /// Plan `k + 1`'s `T_total` minus plan `k`'s, filed by `fates[k + 1]` (the fate in the
    /// re-schedule that made plan `k + 1`; plans without one are left out).
    #[must_use]
    pub fn of(t_total_s: &[f64], fates: &[Option<Fate>]) -> FateIncreases {
        let mut out = FateIncreases::default();
        for (k, w) in t_total_s.windows(2).enumerate() {
            let slot = match fates.get(k + 1).copied().flatten() {
                Some(Fate::Valid) => &mut out.valid,
                Some(Fate::Repaired) => &mut out.repaired,
                Some(Fate::Invalid) => &mut out.invalid,
                None => continue,
            };
            slot.add(w[1] - w[0]);
        }
        out
    }

    /// The two as one, fate by fate ([`FateCount::merged`]).
    #[must_use]
    pub fn merged(self, other: FateIncreases) -> FateIncreases {
        FateIncreases {
            valid: self.valid.merged(other.valid),
            repaired: self.repaired.merged(other.repaired),
            invalid: self.invalid.merged(other.invalid),
        }
    }
}

/// What the observers collect while a run goes.
#[derive(Default)]
struct Trace {
    serial_s: Vec<f64>,
    /// `(round, fate of the re-schedule that made the plan the round ran)`.
    fates: Vec<(usize, Option<Fate>)>,
    backward: (usize, f64),
    error: Option<crate::Error>,
}

impl Trace {
    fn add_backward(&mut self, (n, max): (usize, f64)) {
        self.backward.0 += n;
        self.backward.1 = self.backward.1.max(max);
    }
}

/// The largest increase from one value to the next and after which value it came (`(0,
/// None)` for fewer than two values).
fn max_increase(t: &[f64]) -> (f64, Option<usize>) {
    t.windows(2).enumerate().fold((0.0, None), |best, (k, w)| {
        let d = w[1] - w[0];
        if best.1.is_none() || d > best.0 {
            (d, Some(k))
        } else {
            best
        }
    })
}

/// Runs `rounds` rounds of `robots` robots on the prepared task; `progress` is called after
/// every recorded round.
///
/// # Errors
/// The study's errors.
pub fn run_rounds(
    prep: &Prepared,
    robots: usize,
    rounds: usize,
    progress: &(dyn Fn() + Sync),
) -> Result<RunReport> {
    let config = config(prep, robots, Cell::Rounds, rounds);
    let trace = Mutex::new(Trace::default());
    let observe = |view: RoundView<'_>| {
        let serial = serial_s(view.planner);
        let backward = backward_steps(view.run.robots.iter().map(|r| &r.ref_time_log[..]));
        let fate = Fate::of(&view.planner.outcome().previous);
        let mut t = trace.lock().unwrap_or_else(PoisonError::into_inner);
        t.add_backward(backward);
        t.fates.push((view.round, fate));
        match serial {
            Ok(s) => t.serial_s.push(s),
            Err(e) => {
                t.error.get_or_insert(e);
            }
        }
    };
    let run = run_trial_on(
        &config,
        &prep.model,
        prep.truth.as_ref(),
        0,
        &|_| progress(),
        &observe,
    )?;
    let mut trace = trace.into_inner().unwrap_or_else(PoisonError::into_inner);
    if let Some(e) = trace.error.take() {
        return Err(e);
    }
    let last_serial = serial_s(&run.planner)?;
    trace.serial_s.push(last_serial);
    let its = &run.result.iterations;
    let t_total_s: Vec<f64> = its.iter().map(|i| i.t_total_s).collect();
    let tick_s = run.planner.schedule().tick_s;
    let first_overlap_round = t_total_s
        .iter()
        .zip(&trace.serial_s)
        .position(|(t, s)| *t < s - 0.5 * tick_s);
    let (max_increase_s, max_increase_at) = max_increase(&t_total_s);
    // Round `k` (1-based) ran plan `k − 1`; the last plan is the planner's after the trial.
    trace.fates.sort_by_key(|f| f.0);
    let fates: Vec<Option<Fate>> = trace
        .fates
        .iter()
        .map(|f| f.1)
        .chain([Fate::of(&run.planner.outcome().previous)])
        .collect();
    let by_fate = if fates.len() == t_total_s.len() {
        FateIncreases::of(&t_total_s, &fates)
    } else {
        FateIncreases::default()
    };
    let ran: Vec<(f64, f64)> = its
        .iter()
        .filter_map(|i| i.round.as_ref().map(|p| (i.t_total_s, p.duration_s)))
        .collect();
    let ratio = |(planned, realized): (f64, f64)| realized / planned;
    let realized_over_planned =
        ran.iter().copied().map(ratio).sum::<f64>() / ran.len().max(1) as f64;
    let (planned_last, realized_last) = ran.last().copied().unwrap_or((f64::NAN, f64::NAN));
    let per_h = |t: f64| 3600.0 * robots as f64 / t;
    let last = its.last().expect("a trial has its first schedule");
    let (falsely_trusted, falsely_trusted_agreeing) =
        falsely_trusted_split(run.planner.confidence().conf(), &prep.need_kind);
    let run_stats = its.iter().filter_map(|i| i.round.as_ref());
    Ok(RunReport {
        family: prep.family.to_string(),
        seed: prep.seed,
        robots,
        cell: Cell::Rounds,
        rounds,
        high_pct: its.iter().map(|i| i.high_conf_pct).collect(),
        bound_s: last.lower_bound_s,
        bound_is_optimum: last.bound_is_optimum,
        margin_free_s: run.planner.outcome().margin_free_s,
        switch_charged_s: switch_charged_s(&run.planner, robots, tick_s),
        serial_s: last_serial,
        truth_high_pct: prep.report.truth_high_pct,
        falsely_trusted,
        falsely_trusted_agreeing,
        first_overlap_round,
        max_increase_s,
        max_increase_at,
        by_fate,
        realized_over_planned,
        realized_over_planned_last: realized_last / planned_last,
        planned_per_h: per_h(planned_last),
        realized_per_h: per_h(realized_last),
        plan_gap: PlanGap::sum(run_stats.clone().map(|p| &p.plan_gap)),
        needed_unsupervised: run_stats.clone().map(|p| p.needed_unsupervised).sum(),
        backward_steps: trace.backward.0,
        max_backward_samples: trace.backward.1,
        overlap_ticks: run_stats.clone().map(|p| p.overlap_ticks as u64).sum(),
        faults: run_stats.map(|p| p.faults as u64).sum(),
        tick_s,
        t_total_s,
    })
}

/// Runs a continuous cell of `robots` robots on the prepared task for `rounds·N` tasks,
/// re-planned every `N` tasks; `progress` is called after every re-plan.
///
/// # Errors
/// The study's errors.
pub fn run_continuous(
    prep: &Prepared,
    robots: usize,
    rounds: usize,
    progress: &(dyn Fn() + Sync),
) -> Result<RunReport> {
    let config = config(prep, robots, Cell::Continuous, rounds);
    let trace = Mutex::new(Trace::default());
    let observe = |task: &FinishedTask| {
        let backward = backward_steps([&task.run.ref_time_log[..]]);
        trace
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .add_backward(backward);
    };
    let run = run_cell_trial_on(
        &config,
        &prep.model,
        prep.truth.as_ref(),
        0,
        &|_| progress(),
        &observe,
    )?;
    let trace = trace.into_inner().unwrap_or_else(PoisonError::into_inner);
    let its = &run.result.iterations;
    let t_total_s: Vec<f64> = its.iter().map(|i| i.period_s).collect();
    let (max_increase_s, max_increase_at) = max_increase(&t_total_s);
    let last = its.last().expect("a trial has its first plan");
    let realized_per_h = run.result.steady.throughput_per_h;
    let ratio = last.tasks_per_hour / realized_per_h;
    let (falsely_trusted, falsely_trusted_agreeing) =
        falsely_trusted_split(run.planner.confidence().conf(), &prep.need_kind);
    Ok(RunReport {
        family: prep.family.to_string(),
        seed: prep.seed,
        robots,
        cell: Cell::Continuous,
        rounds: its.len() - 1,
        high_pct: its.iter().map(|i| i.high_conf_pct).collect(),
        bound_s: last.lower_bound_s,
        bound_is_optimum: false,
        margin_free_s: None,
        switch_charged_s: None,
        serial_s: serial_s(&run.planner)?,
        truth_high_pct: prep.report.truth_high_pct,
        falsely_trusted,
        falsely_trusted_agreeing,
        first_overlap_round: None,
        max_increase_s,
        max_increase_at,
        by_fate: FateIncreases::default(),
        realized_over_planned: ratio,
        realized_over_planned_last: ratio,
        planned_per_h: last.tasks_per_hour,
        realized_per_h,
        plan_gap: run.result.steady.plan_gap,
        needed_unsupervised: run.result.steady.needed_unsupervised,
        backward_steps: trace.backward.0,
        max_backward_samples: trace.backward.1,
        overlap_ticks: run.result.stats.overlap_ticks,
        faults: run.result.stats.faults,
        tick_s: prep.model.dt_s(),
        t_total_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backward_steps_count_every_decrease() {
        let a = [0.0, 1.0, 0.75, 2.0, 2.0, 1.0];
        let b = [0.0, 0.5, 1.0];
        assert_eq!(backward_steps([&a[..], &b[..]]), (2, 1.0));
        assert_eq!(backward_steps([&b[..]]), (0, 0.0));
    }

    /// A two-robot rounds run ending at `t_total` against `bound`, with `margin_free`.
    fn run(t_total: f64, bound: f64, margin_free: Option<f64>) -> RunReport {
        RunReport {
            family: "f".into(),
            seed: 0,
            robots: 2,
            cell: Cell::Rounds,
            rounds: 1,
            t_total_s: vec![2.0 * t_total, t_total],
            high_pct: vec![50.0, 60.0],
            bound_s: bound,
            bound_is_optimum: margin_free.is_some(),
            margin_free_s: margin_free,
            switch_charged_s: None,
            serial_s: 2.0 * t_total,
            truth_high_pct: 60.0,
            falsely_trusted: 0,
            falsely_trusted_agreeing: 0,
            first_overlap_round: Some(0),
            max_increase_s: 0.0,
            max_increase_at: None,
            by_fate: FateIncreases::default(),
            realized_over_planned: 1.0,
            realized_over_planned_last: 1.0,
            planned_per_h: 1.0,
            realized_per_h: 1.0,
            plan_gap: PlanGap::default(),
            needed_unsupervised: 0,
            backward_steps: 0,
            max_backward_samples: 0.0,
            overlap_ticks: 0,
            faults: 0,
            tick_s: 0.01,
        }
    }

    #[test]
    fn the_gap_splits_into_search_and_margins_that_add_up() {
        // Bound 10 s, best margin-free schedule 10.5 s, T_total 12 s: gap 20 % = 5 % the search
        // left open + 15 % the margins.
        let r = run(12.0, 10.0, Some(10.5));
        let (search, margins) = r.gap_split_pct().unwrap();
        assert!((search - 5.0).abs() < 1e-12 && (margins - 15.0).abs() < 1e-12);
        assert!((search + margins - r.gap_pct()).abs() < 1e-12);
        assert_eq!(run(12.0, 10.0, None).gap_split_pct(), None);
        // Per family: the mean over the seeds that have it; proven bounds counted.
        let (a, b, c) = (
            run(12.0, 10.0, Some(10.5)),
            run(11.0, 10.0, Some(10.0)),
            run(20.0, 10.0, None),
        );
        let report = crate::eval::ZooReport {
            params: crate::eval::EvalParams::default(),
            families: vec!["f".into()],
            fits: Vec::new(),
            runs: vec![a, b, c],
        };
        let rows = crate::eval::family_rows(&report);
        let (search, margins) = rows[0].gap_split_pct.unwrap();
        assert!((search - 2.5).abs() < 1e-12 && (margins - 12.5).abs() < 1e-12);
        assert_eq!(rows[0].bound_proven, 2);
        assert_eq!(rows[0].unavoidable_pct, None);
    }

    #[test]
    fn the_unavoidable_part_of_the_margins() {
        // Bound 10 s, margin-free 10 s, charged switches 10.8 s, T_total 12 s: of the 20 %
        // margins, 8 % no valid schedule avoids.
        let mut a = run(12.0, 10.0, Some(10.0));
        a.switch_charged_s = Some(10.8);
        assert!((a.unavoidable_pct().unwrap() - 8.0).abs() < 1e-12);
        let mut b = run(12.0, 10.0, Some(10.0));
        b.switch_charged_s = Some(10.4);
        let c = run(12.0, 10.0, Some(10.0));
        assert_eq!(c.unavoidable_pct(), None);
        let report = crate::eval::ZooReport {
            params: crate::eval::EvalParams::default(),
            families: vec!["f".into()],
            fits: Vec::new(),
            runs: vec![a, b, c],
        };
        let (u, n) = crate::eval::family_rows(&report)[0]
            .unavoidable_pct
            .unwrap();
        assert!((u - 6.0).abs() < 1e-12 && n == 2);
    }

    #[test]
    fn increases_filed_by_the_previous_schedules_fate() {
        // Plans 30, 20, 20.5, 25, 24 s; plan 0 had no previous schedule, plan 1 came after a
        // repaired one (−10), plan 2 a repaired one (+0.5), plan 3 an invalid one (+4.5),
        // plan 4 a valid one (−1).
        let t = [30.0, 20.0, 20.5, 25.0, 24.0];
        let fates = [
            None,
            Some(Fate::Repaired),
            Some(Fate::Repaired),
            Some(Fate::Invalid),
            Some(Fate::Valid),
        ];
        let f = FateIncreases::of(&t, &fates);
        assert_eq!(
            f.repaired,
            FateCount {
                count: 2,
                max_increase_s: Some(0.5)
            }
        );
        assert_eq!(
            f.invalid,
            FateCount {
                count: 1,
                max_increase_s: Some(4.5)
            }
        );
        assert_eq!(
            f.valid,
            FateCount {
                count: 1,
                max_increase_s: Some(-1.0)
            }
        );
        // Merged with a run of one valid re-schedule of +0.25 s: 2 valid, the larger +0.25.
        let g = FateIncreases::of(&[10.0, 10.25], &[None, Some(Fate::Valid)]);
        let m = f.merged(g);
        assert_eq!(m.valid.count, 2);
        assert_eq!(m.valid.max_increase_s, Some(0.25));
        assert_eq!(m.invalid, f.invalid);
        // A report saved before the split reads all empty.
        let mut old = serde_json::to_value(run(12.0, 10.0, None)).unwrap();
        old.as_object_mut().unwrap().remove("by_fate");
        let back: RunReport = serde_json::from_value(old).unwrap();
        assert_eq!(back.by_fate, FateIncreases::default());
    }

    #[test]
    fn the_largest_increase_and_where() {
        assert_eq!(
            max_increase(&[30.0, 19.5, 30.3, 25.0]),
            (30.3 - 19.5, Some(1))
        );
        let (d, at) = max_increase(&[3.0, 2.0, 1.0]);
        assert_eq!((d, at), (-1.0, Some(0)));
        assert_eq!(max_increase(&[3.0]), (0.0, None));
    }
}
