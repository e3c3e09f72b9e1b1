//! Running a round: the control loop of the module docs of [`crate::workcell`], with the
//! checks of its inputs.

use rand::Rng;
use tandem_lfd::TaskModel;
use tandem_planner::Planner;
use tandem_realtime::{Controller, Coordinator, Operator, Tick, Timeline, tol};
use tandem_schedule::{Problem, Schedule};

use super::live::RoundSim;
use super::operator::{
    Attention, Episodes, OperatorParams, local_correction_input, needs_correction,
};
use super::record::{PlanGap, RobotPlan, RobotRun, RoundRun, plan_gap};
use crate::task::{Label, Workpiece};
use crate::{Error, Result};

/// Runs every robot of the planner's current schedule to the end with a simulated operator
/// on the sanding task (see the module docs): [`run_round_with`] where a sample needs a
/// correction when [`needs_correction`] says so for the reference label at the sample and the
/// robot's own workpiece. `labels` are the reference demonstration's labels (one per
/// reference sample); `workpieces[i]` is robot `i`'s workpiece, one per robot of the
/// schedule. Deterministic for the state of `rng`.
///
/// # Errors
/// As [`run_round_with`], and [`Error::Mismatch`] for labels that are not one per reference
/// sample or workpieces that are not one per robot.
pub fn run_round(
    planner: &Planner,
    labels: &[Label],
    workpieces: &[Workpiece],
    params: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<RoundRun> {
    let n_ref = planner.model().n_ref();
    if labels.len() != n_ref {
        return Err(Error::Mismatch {
            what: "reference labels",
            expected: n_ref,
            found: labels.len(),
        });
    }
    let n_robots = planner.n_robots();
    if workpieces.len() != n_robots {
        return Err(Error::Mismatch {
            what: "workpieces (one per robot)",
            expected: n_robots,
            found: workpieces.len(),
        });
    }
    run_round_with(
        planner,
        |robot, ref_idx| needs_correction(&labels[ref_idx], &workpieces[robot]),
        params,
        rng,
    )
}

/// Deprecated: [`run_round`] under its two-robot name (one workpiece per robot of a
/// two-robot schedule). Kept for one release at the crate's public edge.
///
/// # Errors
/// As [`run_round`] ([`Error::Mismatch`] for a planner with another robot count).
#[deprecated(note = "use `run_round` (a round is one execution of each robot)")]
pub fn run_pair(
    planner: &Planner,
    labels: &[Label],
    workpieces: &[Workpiece; 2],
    params: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<RoundRun> {
    run_round(planner, labels, workpieces, params, rng)
}

/// Runs every robot of the planner's current schedule to the end with a simulated operator
/// (see the module docs), the caller deciding which samples need a correction:
/// `needs(robot, ref_idx)` says whether robot `robot` (`0..N`) needs the operator at
/// reference sample `ref_idx` (`round(t_i)`, in `0..n_ref`). It is asked once per supervised
/// sample, just before the operator's draw from `rng`; samples of high confidence are never
/// asked about. Model, problem, schedule and control tick are the planner's, so they agree
/// by construction. Deterministic for the state of `rng` (and a deterministic `needs`).
///
/// # Errors
/// Invalid parameters, a model without the force channel, a schedule checked at a tick other
/// than the workcell's ([`Error::TickMismatch`]), a degenerate command, or a round that does
/// not finish ([`Error::DidNotFinish`]).
pub fn run_round_with(
    planner: &Planner,
    needs: impl FnMut(usize, usize) -> bool,
    params: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<RoundRun> {
    let (model, problem) = (planner.model(), planner.problem());
    params.validate()?;
    check_sizes(model, problem, planner.schedule())?;
    check_tick(planner.schedule().tick_s, problem.dt_s())?;
    // The planner's coordinator: checked at the planner's switch time and load cap (the
    // schedule was planned with them; a check at δ = 0 would refuse the serial schedule's idle
    // gap and accept switches shorter than δ) and waiting δ at its holds. At δ = 0 and
    // u_max = 1 it is exactly `schedule.check(problem)?.coordinator()?`.
    let coord = planner.coordinator()?;
    run_coordinator(model, problem, coord, needs, params, rng)
}

/// Deprecated: [`run_round_with`] under its two-robot name. Kept for one release at the
/// crate's public edge.
///
/// # Errors
/// As [`run_round_with`].
#[deprecated(note = "use `run_round_with` (a round is one execution of each robot)")]
pub fn run_pair_with(
    planner: &Planner,
    needs: impl FnMut(usize, usize) -> bool,
    params: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<RoundRun> {
    run_round_with(planner, needs, params, rng)
}

/// Checks that the model and every robot's gradients have one entry per reference sample of
/// `problem`, in that order.
fn check_sizes(model: &TaskModel, problem: &Problem, schedule: &Schedule) -> Result<()> {
    let sizes = std::iter::once(("model reference samples", model.n_ref())).chain(
        schedule
            .grad_exec
            .iter()
            .map(|g| ("a robot's gradients", g.len())),
    );
    check_n_ref(problem.n_ref(), sizes)
}

/// Checks that a schedule (or coordinator) made for a control tick of `schedule_tick_s` runs
/// at the workcell's `workcell_tick_s` (s): [`Error::TickMismatch`] otherwise.
pub(super) fn check_tick(schedule_tick_s: f64, workcell_tick_s: f64) -> Result<()> {
    if tol::same_tick(schedule_tick_s, workcell_tick_s) {
        Ok(())
    } else {
        Err(Error::TickMismatch {
            schedule_tick_s,
            workcell_tick_s,
        })
    }
}

/// Checks that each `(what, found)` of `sizes` has `n_ref` reference samples, in order:
/// [`Error::Mismatch`] naming the first that has not.
pub(super) fn check_n_ref(
    n_ref: usize,
    sizes: impl IntoIterator<Item = (&'static str, usize)>,
) -> Result<()> {
    for (what, found) in sizes {
        if found != n_ref {
            return Err(Error::Mismatch {
                what,
                expected: n_ref,
                found,
            });
        }
    }
    Ok(())
}

/// [`run_round_with`] on the parts of a planner: `problem` must be the one `schedule` was
/// made for, from `model`'s gradients (the unit tests build them by hand). Checked at `δ = 0`
/// and without a cap ([`Schedule::check`]): the planner's own rounds run
/// [`Planner::coordinator`] instead ([`run_round_with`]).
#[cfg(test)]
pub(super) fn run_schedule(
    model: &TaskModel,
    problem: &Problem,
    schedule: &Schedule,
    needs: impl FnMut(usize, usize) -> bool,
    params: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<RoundRun> {
    params.validate()?;
    check_sizes(model, problem, schedule)?;
    check_tick(schedule.tick_s, problem.dt_s())?;
    // The one place the workcell builds its coordinator (with the margin check).
    let coord = schedule.check(problem)?.coordinator()?;
    run_coordinator(model, problem, coord, needs, params, rng)
}

/// The control loop of the module docs on a coordinator of `problem`'s robots at its own
/// tick (`Δt_s`; checked by the caller, as are the parameters and sizes): a [`RoundSim`]
/// ticked to the end, recording each robot's clock and phase before every tick. A tick that
/// latches a fault of the coordinator's run-time monitor (two robots low-confidence at once,
/// which a checked schedule never has) is counted in [`RoundRun::faults`]; the held robot
/// logs no samples while held, and the simulated operator releases it
/// ([`Coordinator::clear_fault`]) after the first tick in which no robot is low-confidence,
/// so that every round finishes.
pub(super) fn run_coordinator(
    model: &TaskModel,
    problem: &Problem,
    coord: Coordinator,
    mut needs: impl FnMut(usize, usize) -> bool,
    params: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<RoundRun> {
    let tick_s = coord.tick_s();
    let n_robots = coord.n_robots();
    let mut counts = RoundCounts {
        operators: coord.operators(),
        ..RoundCounts::default()
    };
    let max_end_s = coord
        .robots()
        .iter()
        .map(Timeline::end_s)
        .fold(0.0, f64::max);
    // The slowest admissible execution is bounded by ψ̇max/ψ̇min per sample; a generous cap
    // on top of that only guards against a bug looping forever.
    let max_ratio = problem
        .grad_max()
        .iter()
        .zip(problem.grad_min())
        .map(|(hi, lo)| hi / lo)
        .fold(1.0, f64::max);
    let mut budget = ((max_end_s / tick_s) * max_ratio * 2.0) as usize + 1000;
    if coord.has_holds() {
        // A robot at a hold waits at most for the others to run (and its planned dwells,
        // which a schedule caps at the serial schedule's length).
        budget *= n_robots + 2;
    }
    let mut sim = RoundSim::new(model, problem, coord, params)?;
    // Whether the operator's input in each tick was a correction (for the round's PlanGap).
    let mut corrected_tick: Vec<bool> = Vec::new();
    while !sim.coordinator().is_finished() {
        if counts.ticks >= budget {
            return Err(Error::DidNotFinish { ticks: budget });
        }
        sim.record_phases();
        let (tick, corrected) = sim.step(model, &mut needs, rng)?;
        corrected_tick.push(corrected);
        if counts.count(&tick) {
            // The operator has dealt with the robot that kept running: release the held one.
            sim.clear_fault();
        }
    }
    let (coord, runs) = sim.into_parts();
    Ok(finished_round(
        &coord,
        runs,
        counts,
        tick_s,
        &corrected_tick,
    ))
}

/// What a round's loop counted, tick by tick ([`RoundRun`]'s fields of the same names).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct RoundCounts {
    /// Control ticks run.
    pub(super) ticks: usize,
    /// Ticks with more robots low-confidence than operators (one operator: two or more).
    pub(super) overlap_ticks: usize,
    /// Ticks with no robot low-confidence.
    pub(super) idle_ticks: usize,
    /// Faults the monitor latched.
    pub(super) faults: usize,
    /// The operators `M` of the coordinator (0 is taken as 1): a tick is counted in
    /// `overlap_ticks` when more than `M` robots are low-confidence.
    pub(super) operators: usize,
}

impl RoundCounts {
    /// Counts one finished tick `tick` (the `counts.ticks`-th): idle (no robot
    /// low-confidence), overlapping (two or more), a fault the monitor latched in it. Returns
    /// whether a fault latched earlier may be released: no robot is low-confidence any more.
    pub(super) fn count(&mut self, tick: &Tick) -> bool {
        let low_conf = tick.low_conf.count();
        if low_conf == 0 {
            self.idle_ticks += 1;
        } else if low_conf > self.operators.max(1) {
            self.overlap_ticks += 1;
        }
        let release = match tick.fault {
            Some(f) if f.tick == self.ticks as u64 => {
                self.faults += 1;
                false
            }
            Some(_) => low_conf == 0,
            None => false,
        };
        self.ticks += 1;
        release
    }
}

/// The record of a round that ran `counts.ticks` ticks of `coord`'s plan at `tick_s` (s):
/// the robots' runs (a robot that never started gets the last tick as its start), the
/// planned ends on the round's clock, and the gap to the plan by cause ([`plan_gap`], from the
/// ticks in which a correction was given, `corrected_tick`). Shared by the one-task round
/// ([`run_round_with`]) and the cell of tasks ([`super::run_cell_round`]).
pub(super) fn finished_round(
    coord: &Coordinator,
    mut runs: Vec<RobotRun>,
    counts: RoundCounts,
    tick_s: f64,
    corrected_tick: &[bool],
) -> RoundRun {
    let n_robots = runs.len();
    for run in &mut runs {
        run.start_tick = run.start_tick.min(counts.ticks);
    }
    let t0 = coord
        .robots()
        .iter()
        .map(Timeline::start_s)
        .fold(f64::INFINITY, f64::min);
    let planned_ends_s: Vec<f64> = (0..n_robots).map(|i| coord.planned_end_s(i) - t0).collect();
    let plans: Vec<RobotPlan> = (0..n_robots)
        .map(|i| {
            let tl = &coord.robots()[i];
            RobotPlan {
                start_s: tl.start_s(),
                end_s: coord.planned_end_s(i),
                sample_clock_s: tl.sample_clock_s().to_vec(),
            }
        })
        .collect();
    let mut round = RoundRun {
        robots: runs,
        ticks: counts.ticks,
        tick_s,
        overlap_ticks: counts.overlap_ticks,
        idle_ticks: counts.idle_ticks,
        faults: counts.faults,
        planned_t_total_s: planned_ends_s.iter().copied().fold(0.0, f64::max),
        planned_ends_s,
        plan_gap: PlanGap::default(),
        rest_ticks: usize::try_from(coord.rest_ticks()).unwrap_or(usize::MAX),
    };
    round.plan_gap = plan_gap(&round, &plans, corrected_tick);
    round
}

/// The low-confidence reference samples a robot crossed whole inside one tick, from reference
/// time `t0` at the tick start to `t1` at its end: the samples after `⌊t0⌋` and before `⌊t1⌋`
/// (no tick starts on them), empty when there are none.
pub(super) fn crossed_lc_samples(
    conf: &[bool],
    t0: f64,
    t1: f64,
) -> impl Iterator<Item = usize> + '_ {
    let last = conf.len().saturating_sub(1);
    let lo = (t0.max(0.0).floor() as usize).min(last) + 1;
    let hi = (t1.max(0.0).floor() as usize).min(last);
    (lo..hi).filter(|&j| !conf[j])
}

/// Each robot's side of the simulated operator across ticks, for [`step`]: its execution in
/// progress, whether an unneeded-correction episode is running, and its fractional reference
/// time (reference samples) at the tick start, as the controller's last [`Tick::ref_time`].
#[derive(Debug)]
pub(super) struct Robots {
    /// Each robot's execution in progress.
    pub(super) runs: Vec<RobotRun>,
    /// Whether an unneeded-correction episode runs for each robot.
    pub(super) in_episode: Vec<bool>,
    /// Each robot's fractional reference time at the tick start.
    pub(super) ref_now: Vec<f64>,
}

/// One control tick of the simulated workcell on any controller (steps 1–5 of the module
/// docs of [`crate::workcell`]), the one loop body of rounds ([`run_coordinator`]) and of the
/// continuous cell ([`CellSim::tick`](super::CellSim::tick)): every robot the controller will
/// move ([`Controller::running_now`]) logs one execution sample at its reference time; the
/// robot the controller reports low-confidence ([`Controller::low_conf_now`]) is supervised,
/// with `bounds(coord, i, n)` the `(ψ̇min, ψ̇max)` of robot `i`'s reference sample `n`, and the operator's
/// input drives it. With `crossings = Some(conf)` (rounds), a robot that started the tick
/// unsupervised but traversed low-confidence samples of `conf` inside it is supervised after
/// the fact (step 5). `ticks` is the tick's index (a run's `start_tick`). Returns the tick
/// and whether the operator's input was a correction; `robots.ref_now` is updated.
#[allow(clippy::too_many_arguments)]
pub(super) fn step<C: Controller + ?Sized>(
    coord: &mut C,
    model: &TaskModel,
    op: &mut Operate,
    bounds: impl Fn(&C, usize, usize) -> (f64, f64),
    crossings: Option<&[bool]>,
    robots: &mut Robots,
    ticks: usize,
    needs: &mut impl FnMut(usize, usize) -> bool,
    rng: &mut impl Rng,
) -> Result<(Tick, bool)> {
    let n_ref = model.n_ref();
    let running = coord.running_now();
    let low_conf = coord.low_conf_now();
    let mut operator = Operator::Scheduled;
    // With `M > 1` operators (issue 44) one simulated operator per operator index: the robot
    // operator `o` supervises takes `o`'s attention and `o`'s input (`tick_many`); the draws
    // stay in robot order on the one stream.
    let m = coord.operators();
    let assigned = coord.operator_now();
    let mut inputs = [Operator::Scheduled; tandem_realtime::MAX_ROBOTS];
    // Each robot that logged an unsupervised sample this tick, and that sample's reference
    // time (for the crossings of step 5).
    let mut unsupervised_at = [None; tandem_realtime::MAX_ROBOTS];
    for i in 0..coord.n_robots() {
        if !running[i] {
            continue;
        }
        let run = &mut robots.runs[i];
        if run.start_tick == usize::MAX {
            run.start_tick = ticks;
        }
        let ref_now = robots.ref_now[i];
        let n = (ref_now.floor() as usize).min(n_ref - 1);
        let supervised = low_conf[i].then(|| bounds(coord, i, n));
        if supervised.is_none() {
            unsupervised_at[i] = Some(ref_now);
        }
        let who = if m > 1 {
            assigned[i].map_or(0, usize::from)
        } else {
            0
        };
        let switching = low_conf[i] && op.attend_as(who, i, ticks);
        if let Some(input) = op.robot_tick(
            model,
            run,
            &mut robots.in_episode[i],
            ref_now,
            supervised,
            switching,
            |idx| needs(i, idx),
            rng,
        )? {
            operator = input;
            inputs[who] = input;
        }
    }
    let (corrected, tick) = if m > 1 {
        let corrected = inputs[..m]
            .iter()
            .any(|o| !matches!(o, Operator::Scheduled));
        (corrected, coord.tick_many(&inputs[..m])?)
    } else {
        (
            !matches!(operator, Operator::Scheduled),
            coord.tick(operator)?,
        )
    };
    if let Some(conf) = crossings {
        for (i, t0) in unsupervised_at.iter().enumerate().take(coord.n_robots()) {
            // A robot that started the tick on high-confidence ground may have crossed
            // whole low-confidence samples inside it (a one-sample island, say, under a fast
            // warp): no tick starts on them, so without this they are never supervised, get
            // no observation and never clear. The coordinator reports the tick low-confidence
            // (the operator watches it); the operator decides at the crossed samples, and
            // the tick's sample is recorded as supervised (docs/decisions.md, "Rounds: a
            // one-sample island is never jumped").
            if let (Some(t0), true) = (*t0, tick.low_conf[i]) {
                let mut crossed = crossed_lc_samples(conf, t0, tick.ref_time[i]);
                if let Some(first) = crossed.next() {
                    // Asked once per crossed sample (any that needs one is a need).
                    let needed = needs(i, first) | crossed.fold(false, |a, j| a | needs(i, j));
                    let switching = op.attend(i, ticks);
                    op.supervise_crossing(
                        &mut robots.runs[i],
                        &mut robots.in_episode[i],
                        needed,
                        switching,
                        rng,
                    );
                }
            }
        }
    }
    robots.ref_now.copy_from_slice(&tick.ref_time);
    Ok((tick, corrected))
}

/// The simulated operator and the robot's logging, one robot and tick at a time (steps 2–4
/// of the module docs of [`crate::workcell`]): the one implementation for rounds and for the
/// continuous cell.
#[derive(Debug)]
pub(super) struct Operate {
    params: OperatorParams,
    force_idx: usize,
    /// Unneeded corrections as episodes of mean length `l` ticks: each tick of an episode
    /// ends it with probability 1/l; outside one, a new one starts with the probability that
    /// makes episodes cover `false_correction_rate` of the time (per tick when l = 1).
    episodes: Episodes,
    u_zero: Vec<f64>,
    u_corr: Vec<f64>,
    cmd: Vec<f64>,
    /// The operator's switch time `δ_true` in whole control ticks
    /// ([`OperatorParams::switch_true_s`], [`tandem_realtime::switch_ticks`]); 0: none.
    switch_ticks: usize,
    /// Where each operator's attention is (only kept with a switch time): index `o` for the
    /// operator `o` of [`Tick::operator`] (one entry per operator; one operator: one entry).
    attention: [Attention; tandem_realtime::MAX_ROBOTS],
}

impl Operate {
    /// The operator `params` on `model` at a control tick of `tick_s` (s).
    pub(super) fn new(model: &TaskModel, params: &OperatorParams, tick_s: f64) -> Result<Self> {
        let force_idx = params.channel_index(model)?;
        let k = model.n_components();
        let switch_ticks = tandem_realtime::switch_ticks(params.switch_true_s, tick_s)? as usize;
        Ok(Operate {
            params: params.clone(),
            force_idx,
            episodes: Episodes::new(
                params.false_correction_rate,
                params.false_correction_s / tick_s,
            ),
            u_zero: vec![0.0; k],
            u_corr: vec![0.0; k],
            cmd: vec![0.0; model.channel_names().len() + 1],
            switch_ticks,
            attention: [Attention::default(); tandem_realtime::MAX_ROBOTS],
        })
    }

    /// Robot `robot` is supervised in control tick `tick` (the run's tick index, not
    /// decreasing): whether the operator is still switching its attention to it, so that its
    /// corrections this tick are not effective ([`Attention`]). Always `false` without a
    /// switch time (and nothing is kept).
    pub(super) fn attend(&mut self, robot: usize, tick: usize) -> bool {
        self.attend_as(0, robot, tick)
    }

    /// [`attend`](Self::attend) for the operator `operator` of a cell of several (issue 44):
    /// each operator turns its own attention, with the same switch time. `attend` is
    /// operator 0's.
    pub(super) fn attend_as(&mut self, operator: usize, robot: usize, tick: usize) -> bool {
        self.switch_ticks > 0 && self.attention[operator].supervise(robot, tick, self.switch_ticks)
    }

    /// An empty run with room for about two executions of `n_ref` samples.
    pub(super) fn empty_run(&self, n_ref: usize) -> RobotRun {
        let m = self.cmd.len() - 1;
        RobotRun {
            samples: Vec::with_capacity(n_ref * m * 2),
            ref_time_log: Vec::with_capacity(n_ref * 2),
            supervised: Vec::with_capacity(n_ref * 2),
            corrected: Vec::with_capacity(n_ref * 2),
            needed: 0,
            missed: 0,
            switch_missed: 0,
            false_corrections: 0,
            clock_s: Vec::with_capacity(n_ref * 2),
            start_tick: usize::MAX,
            hold_ticks: 0,
            phases: Vec::with_capacity(n_ref * 2),
        }
    }

    /// The operator's decision for a tick that the robot started on a high-confidence sample
    /// and in which it crossed whole low-confidence samples (`needed`: any of them needs a
    /// correction): drawn as for a supervised sample (`switching`: the operator is still
    /// switching to the robot, so a needed correction is missed and no unneeded one given),
    /// and the tick's logged sample (the last of `run`) becomes supervised with that decision. Its command is not changed: the robot
    /// started the tick on high confidence, so neither its rate nor its command took the
    /// operator's input; the record keeps what the operator would have done there.
    pub(super) fn supervise_crossing(
        &mut self,
        run: &mut RobotRun,
        in_episode: &mut bool,
        needed: bool,
        switching: bool,
        rng: &mut impl Rng,
    ) {
        let draw: f64 = rng.random();
        let corrected = if switching {
            // Still turning to this robot: the draw is taken (the same stream as without the
            // switch), a needed correction is missed, no episode runs.
            *in_episode = false;
            run.needed += usize::from(needed);
            run.missed += usize::from(needed);
            run.switch_missed += usize::from(needed);
            false
        } else if needed {
            *in_episode = false;
            run.needed += 1;
            let corrected = draw >= self.params.miss_rate;
            run.missed += usize::from(!corrected);
            corrected
        } else {
            let corrected;
            (corrected, *in_episode) = self.episodes.tick(*in_episode, draw, rng);
            run.false_corrections += usize::from(corrected);
            corrected
        };
        if let (Some(s), Some(c)) = (run.supervised.last_mut(), run.corrected.last_mut()) {
            *s = true;
            *c = corrected;
        }
    }

    /// One running robot's tick at fractional reference time `ref_time` (capped at the last
    /// sample): with `bounds = Some((ψ̇min, ψ̇max))` of its sample it is supervised (its sample
    /// is low-confidence) and the operator decides — `needs(round(t))` asked once, then the
    /// draw from `rng` — whether to correct (never while `switching` to the robot: a needed
    /// correction is then missed and counted in [`RobotRun::switch_missed`]); the command is logged into `run` with its flags.
    /// Returns the operator's input for the coordinator when it corrected (the command's rate,
    /// clamped to `bounds`), else `None` (`Operator::Scheduled`).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn robot_tick(
        &mut self,
        model: &TaskModel,
        run: &mut RobotRun,
        in_episode: &mut bool,
        ref_time: f64,
        bounds: Option<(f64, f64)>,
        switching: bool,
        needs: impl FnOnce(usize) -> bool,
        rng: &mut impl Rng,
    ) -> Result<Option<Operator>> {
        let n_ref = model.n_ref();
        // A model update can add correction components (`K = min(n − 1, k_max, d)` grows
        // with the executions recorded while a task has fewer than `k_max + 1`
        // demonstrations): a continuous cell keeps its operator across re-plans, so the
        // inputs follow the model that commands now (allocates only when `K` changes).
        let k = model.n_components();
        if self.u_zero.len() != k {
            self.u_zero.resize(k, 0.0);
            self.u_corr.resize(k, 0.0);
        }
        let ref_time = ref_time.min((n_ref - 1) as f64);
        let supervised = bounds.is_some();
        let mut corrected = false;
        if supervised {
            let label_idx = (ref_time.round() as usize).min(n_ref - 1);
            let needed = needs(label_idx);
            let draw: f64 = rng.random();
            if switching {
                // Still turning to this robot (see `supervise_crossing`).
                *in_episode = false;
                run.needed += usize::from(needed);
                run.missed += usize::from(needed);
                run.switch_missed += usize::from(needed);
            } else if needed {
                *in_episode = false;
                run.needed += 1;
                corrected = draw >= self.params.miss_rate;
                run.missed += usize::from(!corrected);
            } else {
                (corrected, *in_episode) = self.episodes.tick(*in_episode, draw, rng);
                run.false_corrections += usize::from(corrected);
            }
        } else {
            *in_episode = false;
        }
        // The input in the frame of the two reference samples around `ref_time` (only they
        // are decomposed); the command equals the task frame's bit for bit.
        let m = self.cmd.len() - 1;
        if corrected
            && local_correction_input(
                model,
                self.force_idx,
                self.params.gain,
                ref_time,
                &mut self.u_corr,
            )?
        {
            model.local_command_into(&self.u_corr, ref_time, &mut self.cmd)?;
        } else {
            model.command_into(&self.u_zero, ref_time, &mut self.cmd)?;
        }
        run.samples.extend_from_slice(&self.cmd[..m]);
        run.ref_time_log.push(ref_time);
        run.supervised.push(supervised);
        run.corrected.push(corrected);
        Ok(match bounds {
            Some((lo, hi)) if corrected => Some(Operator::Gradient(self.cmd[m].clamp(lo, hi))),
            _ => None,
        })
    }
}
