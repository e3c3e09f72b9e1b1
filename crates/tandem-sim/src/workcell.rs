//! The simulated workcell of the study (§III): the `N` robots of the planner's schedule
//! (two in the paper) run one round, one execution each, through the real-time
//! coordinator while a simulated operator supervises the low-confidence robot.
//!
//! # One control tick
//!
//! The control period is the reference sample period `Δt_s`, so every tick gives each
//! running robot one execution sample, as in the demonstrations. The schedule must have been
//! checked at that tick ([`Schedule::tick_s`], the tick of its margin check): a schedule made
//! for another tick is rejected with [`Error::TickMismatch`] rather than run at a period its
//! safety check never saw.
//!
//! 1. Each running robot's position is read from the coordinator: its schedule clock
//!    `s_i` gives its reference sample `n_i` and fractional reference time `t_i` (Eq. 15).
//!    A robot whose sample `n_i` is low-confidence is *supervised* this tick; that is the
//!    robot the coordinator will move at the operator's rate.
//! 2. The operator decides for the supervised robot whether to correct. Whether the sample
//!    *needs* a correction is the caller's `needs(i, round(t_i))` in [`run_round_with`]; on
//!    the sanding task ([`run_round`]) it does when, on that robot's own workpiece, the
//!    reference demonstration's label at `round(t_i)` is sanding in pass 1–3 over a painted
//!    section. A needed correction is
//!    given with probability `1 − miss_rate` (§III: 1 % misses). Unneeded corrections
//!    cover `false_correction_rate` of the supervised time that needs none (§III: "1 % of
//!    the time") in episodes of mean length `false_correction_s` (default 0.5 s): a person
//!    who corrects by mistake holds the joystick for a moment, not for one 10 ms tick.
//!    Why it matters for the study: drawn per tick, the 1 % leaves hundreds of isolated
//!    one-sample low-confidence "islands" after 150 pairs (samples whose few observations
//!    happened to include several false corrections); every island of one robot forbids
//!    the other robot's low-confidence pass at that moment, so the schedule stays nearly
//!    serial. Measured on the default study (5 × 300 executions, seed 2023; `cargo xtask
//!    study`, and with `false_correction_s = 0` in its configuration for per-tick draws):
//!    per-tick draws leave 92–116 low-confidence runs per robot and schedule after 150
//!    pairs and end at `T_total` 136.63 ± 1.08 s; 0.5 s episodes leave 3–6 runs and end at
//!    106.22 ± 11.04 s (serial: 191.81 s). Episodes give each sample about the same 1 %
//!    chance per execution but make the islands contiguous and far fewer (docs/decisions.md,
//!    "Unneeded corrections come in 0.5 s episodes", with the figures of earlier commits).
//! 3. A correction is a joystick input `u` along the model's correction components
//!    (`TaskModel::corrections_at`), `u_k = ±gain` with the sign that raises the force; a
//!    component whose rate part would speed the robot up is left out when the combined
//!    input would otherwise speed it up, so a correction presses harder *and* slows the
//!    robot, as the expert did over paint. The command `x_f⁺ = μ̂⁺ + δx⁺(u)` (Eq. 7) comes
//!    from `TaskModel::command`; its last component, the warp gradient, is clamped to
//!    `[ψ̇min, ψ̇max]` at `n_i` and passed to `Coordinator::tick` as `Operator::Gradient`.
//!    That is what perturbs the timing. Without a correction the operator's input is
//!    `Operator::Scheduled` (the robot keeps its scheduled gradient, the mean on
//!    low-confidence samples); a degenerate command (NaN rate) is an error, not "no
//!    correction".
//! 4. Every running robot logs the command at `t_i` (`u = 0` unless corrected) as its
//!    execution sample, `t_i` in its reference-time log (Eq. 21), and its supervised and
//!    corrected flags.
//! 5. After the tick, `Tick::low_conf` says which robots traversed any low-confidence sample:
//!    two or more at once is an *overlap* (a valid schedule never has one), none is operator
//!    idle time, and any is operator busy time.

use rand::Rng;
use serde::{Deserialize, Serialize};
use tandem_lfd::{Demonstration, Execution, TaskModel};
use tandem_planner::{ExecutionRecord, Planner};
use tandem_realtime::{Operator, Timeline, tol};
use tandem_schedule::{Problem, Schedule};

use crate::task::{Label, N_PASSES, Phase, Workpiece};
use crate::{Error, Result};

/// The simulated operator (§III).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OperatorParams {
    /// Probability of missing a needed correction, in `[0, 1]`. Default: 0.01 (§III).
    pub miss_rate: f64,
    /// Share of the supervised samples that need no correction on which the operator
    /// corrects anyway, in `[0, 1)`. Default: 0.01 (§III: "1 % of the time").
    pub false_correction_rate: f64,
    /// Mean duration (s) of one unneeded correction: a person who corrects by mistake
    /// holds the joystick for a while, so unneeded corrections come as episodes of
    /// geometric length with this mean, started at the rate that makes them cover
    /// `false_correction_rate` of the time. `0` (or anything up to one control tick) draws
    /// every tick independently. Finite and `≥ 0`. Default: 0.5 s.
    pub false_correction_s: f64,
    /// Channel whose increase a correction aims at. Default: `"force"` (the sanding
    /// task's normal force, N).
    pub force_channel: String,
    /// Joystick deflection `|u_k|` of a correction, in `(0, 1]`. The model's components
    /// span ±3σ at `|u_k| = 1`, so the default 1/3 moves the command about one standard
    /// deviation along each component: from the mean towards how the experts sanded over
    /// paint, not to the edge of what they ever did. Default: 1/3.
    pub gain: f64,
}

impl Default for OperatorParams {
    fn default() -> Self {
        Self {
            miss_rate: 0.01,
            false_correction_rate: 0.01,
            false_correction_s: 0.5,
            force_channel: "force".into(),
            gain: 1.0 / 3.0,
        }
    }
}

impl OperatorParams {
    /// Checks the rates.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field.
    pub fn validate(&self) -> Result<()> {
        for (name, p) in [
            ("miss_rate", self.miss_rate),
            ("false_correction_rate", self.false_correction_rate),
        ] {
            if !(0.0..=1.0).contains(&p) {
                return Err(Error::BadParam {
                    name,
                    why: "must be a probability in [0, 1]",
                });
            }
        }
        if !(0.0..1.0).contains(&self.false_correction_rate) {
            return Err(Error::BadParam {
                name: "false_correction_rate",
                why: "must be in [0, 1)",
            });
        }
        if !(self.false_correction_s.is_finite() && self.false_correction_s >= 0.0) {
            return Err(Error::BadParam {
                name: "false_correction_s",
                why: "must be finite and ≥ 0",
            });
        }
        if !(self.gain > 0.0 && self.gain <= 1.0) {
            return Err(Error::BadParam {
                name: "gain",
                why: "must be in (0, 1]",
            });
        }
        Ok(())
    }
}

/// Whether a reference sample with this label needs a correction on `workpiece`: sanding
/// in passes 1–3 over a painted section (pass 4 is always painted and never needs one).
#[must_use]
pub fn needs_correction(label: &Label, workpiece: &Workpiece) -> bool {
    label.phase == Phase::Sanding
        && (1..N_PASSES).contains(&usize::from(label.pass))
        && workpiece.painted_at(label)
}

/// One robot's execution as the system records it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RobotRun {
    /// Commanded samples, sample-major (`m` channels in the model's channel order), one per
    /// control tick in which the robot ran.
    pub samples: Vec<f64>,
    /// Reference time (reference samples, fractional, in `[0, T_ref − 1]`) of each sample.
    pub ref_time_log: Vec<f64>,
    /// Whether the robot was low-confidence (supervised) at each sample.
    pub supervised: Vec<bool>,
    /// Whether the operator corrected each sample (only ever true where supervised).
    pub corrected: Vec<bool>,
    /// Supervised samples that needed a correction.
    pub needed: usize,
    /// Needed corrections the operator missed.
    pub missed: usize,
    /// Corrections given where none was needed.
    pub false_corrections: usize,
    /// The robot's schedule clock `s_i` (global schedule time, s) at the start of every
    /// control tick of the round, running or not (`RoundRun::ticks` entries): before the robot
    /// starts it follows the pace of the running robots (its start shifts), after it finishes
    /// it stays at its end.
    pub clock_s: Vec<f64>,
    /// The round's control tick (0-based) of the robot's first sample: ticks
    /// `0..start_tick` it waited for its start, ticks `start_tick..start_tick + n` it ran
    /// (`n` samples), later ticks it had finished. `RoundRun::ticks` when it never ran.
    pub start_tick: usize,
}

impl RobotRun {
    /// The execution record for [`Planner::record_round`] (Eq. 21): the samples as a
    /// demonstration with `model`'s channel names and sample period, the reference-time log,
    /// and the supervised and corrected flags.
    ///
    /// # Errors
    /// The model crate's error if the samples do not form a valid demonstration.
    pub fn record(&self, model: &TaskModel) -> Result<ExecutionRecord> {
        let demonstration = Demonstration::new(
            model.channel_names().to_vec(),
            self.samples.clone(),
            model.dt_s(),
        )?;
        Ok(ExecutionRecord {
            execution: Execution {
                demonstration,
                ref_time_log: self.ref_time_log.clone(),
            },
            supervised: self.supervised.clone(),
            corrected: self.corrected.clone(),
        })
    }
}

/// A round of executions, one per robot, run under one schedule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RoundRun {
    /// Robot 1, robot 2, …: one run per robot of the schedule.
    pub robots: Vec<RobotRun>,
    /// Control ticks until every robot finished.
    pub ticks: usize,
    /// Control period (s).
    pub tick_s: f64,
    /// Ticks in which two or more robots traversed a low-confidence sample (must be 0).
    pub overlap_ticks: usize,
    /// Ticks in which no robot traversed a low-confidence sample.
    pub idle_ticks: usize,
}

/// The two-robot round of the paper: a [`RoundRun`] with two robots ([`run_pair`]).
pub type PairRun = RoundRun;

impl RoundRun {
    /// Every robot's execution record, robot 1 first, for [`Planner::record_round`] (see
    /// [`RobotRun::record`]); `model` is the planner's model the round ran with.
    ///
    /// # Errors
    /// The model crate's error if a robot's samples do not form a valid demonstration.
    pub fn records(&self, model: &TaskModel) -> Result<Vec<ExecutionRecord>> {
        self.robots.iter().map(|r| r.record(model)).collect()
    }

    /// Whether two or more robots were ever low-confidence in the same tick.
    #[must_use]
    pub fn overlapped(&self) -> bool {
        self.overlap_ticks > 0
    }

    /// Operator idle time as a share of the round's duration (ticks), in `[0, 1]`.
    #[must_use]
    pub fn operator_idle_share(&self) -> f64 {
        if self.ticks == 0 {
            return 1.0;
        }
        self.idle_ticks as f64 / self.ticks as f64
    }

    /// Operator busy share, in `[0, 1]`: the share of the round's ticks in which at least
    /// one robot traversed a low-confidence sample (`1 − idle share`, counted in ticks).
    #[must_use]
    pub fn operator_busy_share(&self) -> f64 {
        if self.ticks == 0 {
            return 0.0;
        }
        (self.ticks - self.idle_ticks) as f64 / self.ticks as f64
    }

    /// Actual duration of the round (s): ticks times the control period.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        self.ticks as f64 * self.tick_s
    }
}

/// Unneeded corrections as episodes of geometric length with mean `l ≥ 1` ticks: outside
/// one, a tick starts one with probability `p_start`; each tick of an episode is followed
/// by another with probability `1 − 1/l`. Off runs last `(1 − p_start)/p_start` ticks on
/// average, so episodes cover `l·p_start / (l·p_start + 1 − p_start)` of the time, which
/// `p_start = rate / (l·(1 − rate) + rate)` makes equal to `rate`.
#[derive(Clone, Copy, Debug)]
struct Episodes {
    p_start: f64,
    p_end: f64,
    /// `l > 1`: episodes last more than one tick (else every tick is drawn alone).
    lasting: bool,
}

impl Episodes {
    /// `rate` in `[0, 1)`, mean length `ticks` (values below 1 mean 1).
    fn new(rate: f64, ticks: f64) -> Self {
        let l = ticks.max(1.0);
        Episodes {
            p_start: rate / (l * (1.0 - rate) + rate),
            p_end: 1.0 / l,
            lasting: l > 1.0,
        }
    }

    /// One supervised tick that needs no correction: `(corrected, in an episode after it)`
    /// from the state before it, the tick's draw `draw ∈ [0, 1)` and, for the length of an
    /// episode, one more draw from `rng`.
    fn tick(&self, in_episode: bool, draw: f64, rng: &mut impl Rng) -> (bool, bool) {
        let corrected = in_episode || draw < self.p_start;
        let goes_on = corrected && self.lasting && rng.random::<f64>() >= self.p_end;
        (corrected, goes_on)
    }
}

/// The simulated operator's joystick input for a force-raising, slowing correction at
/// fractional reference time `ref_time` (see the module docs, step 3): fills `u` (one entry
/// per correction component, [`TaskModel::n_components`]) with `±gain` or 0 and returns
/// whether any entry is non-zero. `force_idx` is the force channel's index in
/// [`TaskModel::tangent_names`]. The workcell passes `u` to [`TaskModel::command_into`]
/// (Eq. 7); it is public so that a replay of a run can recompute the operator's input.
///
/// # Errors
/// The model crate's error for `ref_time` outside `[0, T_ref − 1]`.
pub fn correction_input(
    model: &TaskModel,
    force_idx: usize,
    gain: f64,
    ref_time: f64,
    u: &mut [f64],
) -> Result<bool> {
    let corr = model.corrections_at(ref_time)?;
    let rate_idx = model.tangent_names().len() - 1;
    let mut rate_change = 0.0;
    let mut any = false;
    for (k, c) in corr.components.iter().enumerate() {
        u[k] = if c[force_idx] > 0.0 {
            gain
        } else if c[force_idx] < 0.0 {
            -gain
        } else {
            0.0
        };
        any |= u[k] != 0.0;
        rate_change += u[k] * c[rate_idx];
    }
    if rate_change < 0.0 {
        // Keep only the components that slow the robot down (or leave its rate alone).
        for (k, c) in corr.components.iter().enumerate() {
            if u[k] * c[rate_idx] < 0.0 {
                u[k] = 0.0;
            }
        }
        any = u.iter().any(|&x| x != 0.0);
    }
    Ok(any)
}

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

/// [`run_round`] for the paper's two robots: one workpiece per robot of a two-robot
/// schedule.
///
/// # Errors
/// As [`run_round`] ([`Error::Mismatch`] for a planner with another robot count).
pub fn run_pair(
    planner: &Planner,
    labels: &[Label],
    workpieces: &[Workpiece; 2],
    params: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<PairRun> {
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
    run_schedule(
        planner.model(),
        planner.problem(),
        planner.schedule(),
        needs,
        params,
        rng,
    )
}

/// [`run_round_with`] under its two-robot name.
///
/// # Errors
/// As [`run_round_with`].
pub fn run_pair_with(
    planner: &Planner,
    needs: impl FnMut(usize, usize) -> bool,
    params: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<PairRun> {
    run_round_with(planner, needs, params, rng)
}

/// Checks that the model and every robot's gradients have one entry per reference sample of
/// `problem`, in that order.
fn check_sizes(model: &TaskModel, problem: &Problem, schedule: &Schedule) -> Result<()> {
    let n_ref = problem.n_ref();
    let sizes = std::iter::once(("model reference samples", model.n_ref())).chain(
        schedule
            .grad_exec
            .iter()
            .map(|g| ("a robot's gradients", g.len())),
    );
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
/// made for, from `model`'s gradients (the unit tests build them by hand).
fn run_schedule(
    model: &TaskModel,
    problem: &Problem,
    schedule: &Schedule,
    mut needs: impl FnMut(usize, usize) -> bool,
    params: &OperatorParams,
    rng: &mut impl Rng,
) -> Result<RoundRun> {
    params.validate()?;
    check_sizes(model, problem, schedule)?;
    let n_ref = problem.n_ref();
    let force_idx = model
        .tangent_names()
        .iter()
        .position(|n| *n == params.force_channel)
        .ok_or_else(|| Error::NoForceChannel(params.force_channel.clone()))?;
    let dt_s = problem.dt_s();
    if !tol::same_tick(schedule.tick_s, dt_s) {
        return Err(Error::TickMismatch {
            schedule_tick_s: schedule.tick_s,
            workcell_tick_s: dt_s,
        });
    }
    let mut coord = schedule.check(problem)?.coordinator()?;
    let tick_s = coord.tick_s();

    let m = model.channel_names().len();
    let k = model.n_components();
    let u_zero = vec![0.0; k];
    let mut u_corr = vec![0.0; k];
    let mut cmd = vec![0.0; m + 1];
    let empty = || RobotRun {
        samples: Vec::with_capacity(n_ref * m * 2),
        ref_time_log: Vec::with_capacity(n_ref * 2),
        supervised: Vec::with_capacity(n_ref * 2),
        corrected: Vec::with_capacity(n_ref * 2),
        needed: 0,
        missed: 0,
        false_corrections: 0,
        clock_s: Vec::with_capacity(n_ref * 2),
        start_tick: usize::MAX,
    };
    let n_robots = coord.n_robots();
    let mut runs: Vec<RobotRun> = (0..n_robots).map(|_| empty()).collect();
    let (mut ticks, mut overlap_ticks, mut idle_ticks) = (0, 0, 0);
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
    let budget = ((max_end_s / tick_s) * max_ratio * 2.0) as usize + 1000;
    let last_ref = (n_ref - 1) as f64;
    // Unneeded corrections as episodes of mean length `l` ticks: each tick of an episode
    // ends it with probability 1/l; outside one, a new one starts with the probability that
    // makes episodes cover `false_correction_rate` of the time (per tick when l = 1).
    let episodes = Episodes::new(
        params.false_correction_rate,
        params.false_correction_s / tick_s,
    );
    let mut in_episode = vec![false; n_robots];

    while !coord.is_finished() {
        if ticks >= budget {
            return Err(Error::DidNotFinish { ticks: budget });
        }
        let clocks = coord.clock_s();
        let mut operator = Operator::Scheduled;
        for i in 0..n_robots {
            let tl = &coord.robots()[i];
            runs[i].clock_s.push(clocks[i]);
            if clocks[i] < tl.start_s() || clocks[i] >= tl.end_s() {
                continue;
            }
            if runs[i].start_tick == usize::MAX {
                runs[i].start_tick = ticks;
            }
            let n = tl.sample_at(clocks[i]);
            let ref_time = tl.ref_time_at(clocks[i]).min(last_ref);
            let supervised = !problem.conf()[n];
            let mut corrected = false;
            if supervised {
                let label_idx = (ref_time.round() as usize).min(n_ref - 1);
                let needed = needs(i, label_idx);
                let draw: f64 = rng.random();
                let run = &mut runs[i];
                if needed {
                    in_episode[i] = false;
                    run.needed += 1;
                    corrected = draw >= params.miss_rate;
                    run.missed += usize::from(!corrected);
                } else {
                    (corrected, in_episode[i]) = episodes.tick(in_episode[i], draw, rng);
                    run.false_corrections += usize::from(corrected);
                }
            } else {
                in_episode[i] = false;
            }
            let u = if corrected
                && correction_input(model, force_idx, params.gain, ref_time, &mut u_corr)?
            {
                &u_corr
            } else {
                &u_zero
            };
            model.command_into(u, ref_time, &mut cmd)?;
            if supervised && corrected {
                operator =
                    Operator::Gradient(cmd[m].clamp(problem.grad_min()[n], problem.grad_max()[n]));
            }
            let run = &mut runs[i];
            run.samples.extend_from_slice(&cmd[..m]);
            run.ref_time_log.push(ref_time);
            run.supervised.push(supervised);
            run.corrected.push(corrected);
        }
        let tick = coord.tick(operator)?;
        ticks += 1;
        match tick.low_conf.count() {
            0 => idle_ticks += 1,
            1 => {}
            _ => overlap_ticks += 1,
        }
    }
    for run in &mut runs {
        run.start_tick = run.start_tick.min(ticks);
    }
    Ok(RoundRun {
        robots: runs,
        ticks,
        tick_s,
        overlap_ticks,
        idle_ticks,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unneeded_corrections_cover_the_rate_in_episodes_of_the_mean_length() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for (rate, ticks) in [(0.01, 50.0), (0.01, 1.0), (0.2, 10.0)] {
            let e = Episodes::new(rate, ticks);
            let (mut state, mut on, mut starts) = (false, 0usize, 0usize);
            let n = 2_000_000;
            for _ in 0..n {
                let before = state;
                let draw: f64 = rng.random();
                let (corrected, next) = e.tick(state, draw, &mut rng);
                on += usize::from(corrected);
                starts += usize::from(corrected && !before);
                state = next;
            }
            let share = on as f64 / n as f64;
            let mean_len = on as f64 / starts as f64;
            assert!(
                (share - rate).abs() < 0.1 * rate,
                "{rate} {ticks}: share {share}"
            );
            assert!(
                (mean_len - ticks).abs() < 0.1 * ticks,
                "{rate} {ticks}: {mean_len}"
            );
        }
    }
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use tandem_lfd::FitParams;

    const N_REF: usize = 60;

    /// Three demonstrations of a one-channel "force" task aligned by known warps: demo 0
    /// (the reference) and demo 2 press lightly (1 N) everywhere; demo 1 presses hard (9 N)
    /// over reference samples 10..20 and takes two samples per reference sample there.
    /// So samples 10..20 vary (low confidence), force rising with the warp gradient.
    fn model() -> TaskModel {
        let names = vec!["force".to_string()];
        let light = Demonstration::new(names.clone(), vec![1.0; N_REF], 0.01).unwrap();
        let mut hard = Vec::new();
        let mut warp1 = Vec::new();
        for n in 0..N_REF {
            warp1.push(hard.len() as f64);
            let reps = if (10..20).contains(&n) { 2 } else { 1 };
            for _ in 0..reps {
                hard.push(if (10..20).contains(&n) { 9.0 } else { 1.0 });
            }
        }
        let hard = Demonstration::new(names, hard, 0.01).unwrap();
        let identity: Vec<f64> = (0..N_REF).map(|n| n as f64).collect();
        TaskModel::fit_aligned(
            &[light.clone(), hard, light],
            &[identity.clone(), warp1, identity],
            &FitParams::default(),
        )
        .unwrap()
    }

    fn problem(model: &TaskModel) -> Problem {
        let conf = (0..N_REF).map(|n| !(10..20).contains(&n)).collect();
        let (gmin, gmax) = (model.grad_min().to_vec(), model.grad_max().to_vec());
        let gmean = model
            .grad_mean()
            .iter()
            .zip(gmin.iter().zip(&gmax))
            .map(|(g, (lo, hi))| g.clamp(*lo, *hi))
            .collect();
        Problem::new(conf, gmean, gmin, gmax, model.dt_s()).unwrap()
    }

    fn painted_labels() -> Vec<Label> {
        vec![
            Label {
                pass: 1,
                section: 0,
                painted: true,
                phase: Phase::Sanding,
            };
            N_REF
        ]
    }

    fn all_painted() -> Workpiece {
        Workpiece {
            painted: vec![vec![true; 8]; N_PASSES],
        }
    }

    /// Whether robot `robot` needs the operator at reference sample `ref_idx` on the
    /// painted labels and workpieces ([`run_pair`]'s rule).
    fn painted_needs(robot: usize, ref_idx: usize) -> bool {
        needs_correction(
            &painted_labels()[ref_idx],
            &[all_painted(), all_painted()][robot],
        )
    }

    /// The serial schedule of the hand-made problem, run with `params`: the pair and its
    /// planned `T_total` (s).
    fn run(params: &OperatorParams, seed: u64) -> (PairRun, f64) {
        let model = model();
        let problem = problem(&model);
        let schedule = problem.serial_schedule(problem.dt_s()).unwrap();
        let planned_s = schedule.t_total_s(problem.dt_s());
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let run =
            run_schedule(&model, &problem, &schedule, painted_needs, params, &mut rng).unwrap();
        (run, planned_s)
    }

    /// A planner on the hand-made model: low confidence exactly where the demonstrations
    /// differ (samples 10..20), a sampled schedule at the workcell's tick.
    fn planner() -> Planner {
        let params = tandem_planner::PlannerParams {
            sampler: tandem_schedule::SamplerParams {
                samples: 50,
                seed: 3,
                ..Default::default()
            },
            ..Default::default()
        };
        Planner::from_model(model(), params).unwrap()
    }

    #[test]
    fn only_painted_sanding_of_passes_one_to_three_needs_a_correction() {
        let mut wp = all_painted();
        wp.painted[1][3] = false;
        let label = |pass, section, phase| Label {
            pass,
            section,
            painted: true,
            phase,
        };
        assert!(needs_correction(&label(1, 0, Phase::Sanding), &wp));
        assert!(needs_correction(&label(3, 7, Phase::Sanding), &wp));
        assert!(
            !needs_correction(&label(2, 3, Phase::Sanding), &wp),
            "unpainted"
        );
        assert!(
            !needs_correction(&label(4, 0, Phase::Sanding), &wp),
            "pass 4"
        );
        assert!(!needs_correction(&label(1, 0, Phase::Transition), &wp));
    }

    #[test]
    fn bad_rates_are_rejected() {
        let p = OperatorParams {
            miss_rate: 1.5,
            ..OperatorParams::default()
        };
        assert!(matches!(
            p.validate(),
            Err(Error::BadParam {
                name: "miss_rate",
                ..
            })
        ));
    }

    #[test]
    fn a_perfect_operator_corrects_every_needed_sample_and_slows_the_robots() {
        let perfect = OperatorParams {
            miss_rate: 0.0,
            false_correction_rate: 0.0,
            ..OperatorParams::default()
        };
        let (run, planned_s) = run(&perfect, 1);
        assert_eq!(run.overlap_ticks, 0);
        let model = model();
        for r in &run.robots {
            let n = r.ref_time_log.len();
            assert_eq!(r.samples.len(), n);
            assert!(r.ref_time_log.windows(2).all(|w| w[0] <= w[1]));
            assert!(
                r.ref_time_log
                    .iter()
                    .all(|t| (0.0..=(N_REF - 1) as f64).contains(t))
            );
            assert_eq!(r.missed + r.false_corrections, 0);
            for k in 0..n {
                let t = r.ref_time_log[k];
                assert_eq!(r.supervised[k], (10..20).contains(&(t as usize)), "t = {t}");
                assert_eq!(r.corrected[k], r.supervised[k]);
                // A correction presses harder than the mean. By hand, inside 10..19: one
                // component c = 2·(8, 1)/√2 (±3σ of the normalised residuals, ranges 8 N
                // and 1), admissible scale (4/3 − 1)/√2, u = 1/3: δforce = 8/9 N.
                let mean = model.command(&[0.0, 0.0], t).unwrap()[0];
                if r.corrected[k] {
                    if (10.0..=19.0).contains(&t) {
                        assert!((r.samples[k] - mean - 8.0 / 9.0).abs() < 1e-9, "t = {t}");
                    }
                    assert!(r.samples[k] > mean + 0.1, "{} vs {mean}", r.samples[k]);
                } else {
                    assert!((r.samples[k] - mean).abs() < 1e-9);
                }
            }
            assert_eq!(r.needed, r.supervised.iter().filter(|s| **s).count());
        }
        // Slower than planned: the corrected gradient is 4/3 + 1/9 instead of 4/3 on the 10
        // low-confidence samples, 10/9 samples (11 ms) more per robot, 22 ms in series.
        assert!(
            run.duration_s() > planned_s + 0.01,
            "{} vs {planned_s}",
            run.duration_s()
        );
        // The operator is idle while both robots are high-confidence.
        assert!(run.idle_ticks > 0 && run.operator_idle_share() < 1.0);
    }

    #[test]
    fn without_corrections_the_pair_runs_on_schedule() {
        let never = OperatorParams {
            miss_rate: 1.0,
            false_correction_rate: 0.0,
            ..OperatorParams::default()
        };
        let (run, planned_s) = run(&never, 2);
        assert_eq!(run.overlap_ticks, 0);
        assert!(run.robots.iter().all(|r| r.corrected.iter().all(|c| !c)));
        assert!(
            run.robots
                .iter()
                .all(|r| r.missed == r.needed && r.needed > 0)
        );
        assert!(
            (run.duration_s() - planned_s).abs() <= 2.0 * run.tick_s,
            "{} vs {planned_s}",
            run.duration_s()
        );
    }

    #[test]
    fn a_round_of_three_robots_runs_each_once_and_busies_the_operator_for_each() {
        let model = model();
        let problem = problem(&model);
        let schedule = problem.serial_schedule_n(3, problem.dt_s()).unwrap();
        let perfect = OperatorParams {
            miss_rate: 0.0,
            false_correction_rate: 0.0,
            ..OperatorParams::default()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let run = run_schedule(
            &model,
            &problem,
            &schedule,
            painted_needs_n,
            &perfect,
            &mut rng,
        )
        .unwrap();
        assert_eq!(run.robots.len(), 3);
        assert_eq!(run.overlap_ticks, 0);
        for r in &run.robots {
            assert!(r.needed > 0 && r.corrected == r.supervised);
        }
        // Serial: the operator is busy exactly while one robot is supervised, so the busy
        // ticks are the three robots' supervised ticks, up to one tick at each end of each
        // robot's one low-confidence stretch (a tick that enters or leaves it is busy).
        let supervised: usize = run
            .robots
            .iter()
            .map(|r| r.supervised.iter().filter(|s| **s).count())
            .sum();
        let busy = run.ticks - run.idle_ticks;
        assert!(busy.abs_diff(supervised) <= 6, "{busy} vs {supervised}");
        assert!(
            (run.operator_busy_share() - busy as f64 / run.ticks as f64).abs() < 1e-15
                && (run.operator_busy_share() + run.operator_idle_share() - 1.0).abs() < 1e-15
        );
        assert_eq!(run.records(&model).unwrap().len(), 3);
    }

    #[test]
    fn every_robot_logs_its_clock_every_tick_and_runs_from_its_start_tick() {
        let model = model();
        let problem = problem(&model);
        let schedule = problem.serial_schedule_n(3, problem.dt_s()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let params = OperatorParams::default();
        let run = run_schedule(
            &model,
            &problem,
            &schedule,
            painted_needs_n,
            &params,
            &mut rng,
        )
        .unwrap();
        let starts: Vec<f64> = std::iter::once(0.0)
            .chain(schedule.offsets_s.iter().copied())
            .collect();
        for (i, r) in run.robots.iter().enumerate() {
            assert_eq!(r.clock_s.len(), run.ticks, "robot {i}: one clock per tick");
            assert!(r.clock_s.windows(2).all(|w| w[0] <= w[1]), "robot {i}");
            let n = r.ref_time_log.len();
            assert!(n > 0 && r.start_tick + n <= run.ticks, "robot {i}");
            // Waiting before its start tick (clock short of its start τ_i), running from it.
            let tau = starts[i];
            assert!(
                r.clock_s[..r.start_tick].iter().all(|&c| c < tau),
                "robot {i}"
            );
            assert!(r.clock_s[r.start_tick] >= tau, "robot {i}");
        }
        assert_eq!(run.robots[0].start_tick, 0);
        // Serial: each robot starts once the one before it has finished.
        for w in run.robots.windows(2) {
            assert!(w[1].start_tick >= w[0].start_tick + w[0].ref_time_log.len());
        }
    }

    /// [`painted_needs`] for any robot index (every workpiece painted).
    fn painted_needs_n(_robot: usize, ref_idx: usize) -> bool {
        needs_correction(&painted_labels()[ref_idx], &all_painted())
    }

    #[test]
    fn run_pair_reads_everything_from_the_planner() {
        let planner = planner();
        let conf = planner.confidence().conf();
        assert!(
            (0..N_REF).all(|n| conf[n] != (10..20).contains(&n)),
            "{conf:?}"
        );
        let p = OperatorParams::default();
        let (labels, wp) = (painted_labels(), [all_painted(), all_painted()]);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let by_labels = run_pair(&planner, &labels, &wp, &p, &mut rng).unwrap();
        assert_eq!(by_labels.overlap_ticks, 0);
        assert_eq!(by_labels.tick_s, planner.schedule().tick_s);
        // The same as the caller's rule, and as the planner's parts run by hand.
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let by_rule = run_pair_with(&planner, painted_needs, &p, &mut rng).unwrap();
        assert_eq!(by_rule, by_labels);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let by_parts = run_schedule(
            planner.model(),
            planner.problem(),
            planner.schedule(),
            painted_needs,
            &p,
            &mut rng,
        )
        .unwrap();
        assert_eq!(by_parts, by_labels);
        // Its records are what the planner takes (Eq. 21): one per robot, flags per sample.
        let records = by_labels.records(planner.model()).unwrap();
        for (record, robot) in records.iter().zip(&by_labels.robots) {
            assert_eq!(record.execution.ref_time_log, robot.ref_time_log);
            assert_eq!(record.execution.demonstration.samples(), &robot.samples[..]);
            assert_eq!(record.supervised, robot.supervised);
            assert_eq!(record.corrected, robot.corrected);
        }
        let mut next = planner.clone();
        next.record_round(&records).unwrap();
        assert_eq!(next.model().count(), planner.model().count() + 2);
    }

    #[test]
    fn run_pair_with_asks_the_caller_only_about_supervised_samples() {
        let model = model();
        let problem = problem(&model);
        let schedule = problem.serial_schedule(problem.dt_s()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        // Only robot 1 needs the operator; a perfect operator corrects exactly its
        // supervised samples, and is asked about nothing but low-confidence samples.
        let perfect = OperatorParams {
            miss_rate: 0.0,
            false_correction_rate: 0.0,
            ..OperatorParams::default()
        };
        let mut asked = Vec::new();
        let run = run_schedule(
            &model,
            &problem,
            &schedule,
            |i, n| {
                asked.push((i, n));
                i == 0
            },
            &perfect,
            &mut rng,
        )
        .unwrap();
        let [r1, r2] = &run.robots[..] else {
            panic!("{} robots", run.robots.len())
        };
        assert!(r1.supervised.iter().any(|s| *s));
        assert_eq!(r1.corrected, r1.supervised);
        assert!(r2.supervised.iter().any(|s| *s));
        assert!(r2.corrected.iter().all(|c| !c));
        assert_eq!(r1.needed, r1.supervised.iter().filter(|s| **s).count());
        assert_eq!(r2.needed, 0);
        let supervised: usize = run
            .robots
            .iter()
            .map(|r| r.supervised.iter().filter(|s| **s).count())
            .sum();
        assert_eq!(asked.len(), supervised);
        assert!(
            asked.iter().all(|&(_, n)| (10..=20).contains(&n)),
            "{asked:?}"
        );
    }

    #[test]
    fn a_schedule_checked_at_another_tick_is_rejected() {
        let mut planner = planner();
        let dt_s = planner.problem().dt_s();
        // Re-scheduled at half the workcell's period: its margins say nothing about 10 ms ticks.
        let half = tandem_schedule::SamplerParams {
            tick_s: Some(dt_s / 2.0),
            ..planner.params().sampler.clone()
        };
        planner.reschedule(&half).unwrap();
        assert_eq!(planner.schedule().tick_s, dt_s / 2.0);
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let p = OperatorParams::default();
        let wp = [all_painted(), all_painted()];
        let err = run_pair(&planner, &painted_labels(), &wp, &p, &mut rng).unwrap_err();
        assert!(
            matches!(
                err,
                Error::TickMismatch {
                    schedule_tick_s,
                    workcell_tick_s,
                } if schedule_tick_s == dt_s / 2.0 && workcell_tick_s == dt_s
            ),
            "{err}"
        );
        let msg = err.to_string();
        assert!(msg.contains("0.005 s") && msg.contains("0.01 s"), "{msg}");
        let err = run_pair_with(&planner, |_, _| true, &p, &mut rng);
        assert!(matches!(err, Err(Error::TickMismatch { .. })));
        // Re-scheduled at the workcell's own tick it runs (`tick_s: None` would keep the
        // schedule's half tick: a re-schedule keeps the tick a user chose).
        let own = tandem_schedule::SamplerParams {
            tick_s: Some(dt_s),
            ..half
        };
        planner.reschedule(&own).unwrap();
        assert!(run_pair_with(&planner, |_, _| true, &p, &mut rng).is_ok());
    }

    #[test]
    fn same_seed_same_run_and_mismatches_are_errors() {
        let p = OperatorParams::default();
        assert_eq!(run(&p, 7).0, run(&p, 7).0);
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let err = run_pair(
            &planner(),
            &painted_labels()[..5],
            &[all_painted(), all_painted()],
            &p,
            &mut rng,
        )
        .unwrap_err();
        assert!(matches!(
            err,
            Error::Mismatch {
                what: "reference labels",
                expected: N_REF,
                found: 5,
            }
        ));
    }
}
