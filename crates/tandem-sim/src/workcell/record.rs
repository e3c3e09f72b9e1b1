//! What a round records: one [`RobotRun`] per robot and the round's tick counts
//! ([`RoundRun`]), and the execution records the planner takes from them (Eq. 21).

use serde::{Deserialize, Serialize};
use tandem_lfd::{Demonstration, Execution, TaskModel};
use tandem_planner::ExecutionRecord;

use crate::Result;

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
    /// Needed corrections the operator missed (by its miss rate, or while switching).
    pub missed: usize,
    /// Of [`RobotRun::missed`], those missed because the operator was still switching its
    /// attention to this robot (its switch time `δ_true`,
    /// [`OperatorParams::switch_true_s`](crate::workcell::OperatorParams::switch_true_s);
    /// issue 41). 0 without a switch time, and then not serialized.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub switch_missed: usize,
    /// Corrections given where none was needed.
    pub false_corrections: usize,
    /// The robot's schedule clock `s_i` (global schedule time, s) at the start of every
    /// control tick of the round, running or not (`RoundRun::ticks` entries): before the robot
    /// starts it follows the pace of the running robots (its start shifts), after it finishes
    /// it stays at its end.
    pub clock_s: Vec<f64>,
    /// The round's control tick (0-based) of the robot's first sample: ticks
    /// `0..start_tick` it waited for its start, ticks `start_tick..start_tick + n` it ran
    /// (`n` samples, minus its ticks at holds), later ticks it had finished. `RoundRun::ticks`
    /// when it never ran.
    pub start_tick: usize,
    /// Control ticks the robot stood at a hold point of the schedule (`Schedule::holds`),
    /// waiting for its release rules or for the robots behind it (0 without holds, and then
    /// not serialized).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub hold_ticks: usize,
    /// What the robot did in every control tick of the round (`RoundRun::ticks` entries, read
    /// at the tick start, beside [`RobotRun::clock_s`]): waiting for its start, running (one
    /// sample of [`RobotRun::ref_time_log`] per such tick), standing at a hold, held by the
    /// fault monitor, or finished. Where the round's time went, tick by tick; the waits at
    /// holds are the [`TickPhase::AtHold`] ticks ([`RobotRun::hold_ticks`] counts them).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub phases: Vec<TickPhase>,
}

/// What one robot did in one control tick of a round ([`RobotRun::phases`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum TickPhase {
    /// Not started: it waits for its start (the start offset, shifted by the robots before
    /// it, and its start rules).
    Waiting,
    /// Running: it executed one sample.
    Running,
    /// Standing at a hold point: for its planned dwell, its release rules or the robots
    /// behind it.
    AtHold,
    /// Held by the coordinator's fault monitor (two robots were low-confidence at once).
    Held,
    /// Finished its task.
    Finished,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl RobotRun {
    /// Time (real s) the robot stood at hold points, for control tick `tick_s` (s).
    pub fn hold_wait_s(&self, tick_s: f64) -> f64 {
        self.hold_ticks as f64 * tick_s
    }

    /// Control ticks of the round the robot spent in `phase` ([`RobotRun::phases`]).
    #[must_use]
    pub fn ticks_in(&self, phase: TickPhase) -> usize {
        self.phases.iter().filter(|&&p| p == phase).count()
    }

    /// The round's control tick at whose start the robot had finished (the number of ticks
    /// it took, waits included), or the round's length if it never finished in it.
    #[must_use]
    pub fn end_tick(&self) -> usize {
        self.phases
            .iter()
            .position(|&p| p == TickPhase::Finished)
            .unwrap_or(self.phases.len())
    }

    /// The execution record for
    /// [`Planner::record_round`](tandem_planner::Planner::record_round) (Eq. 21): the
    /// samples as a demonstration with `model`'s channel names and sample period, the
    /// reference-time log, and the supervised and corrected flags.
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
    /// Ticks in which more robots traversed a low-confidence sample than the round has
    /// operators (one operator: two or more; must be 0).
    pub overlap_ticks: usize,
    /// Ticks in which no robot traversed a low-confidence sample.
    pub idle_ticks: usize,
    /// Faults latched by the coordinator's run-time monitor (two robots low-confidence in one
    /// tick; `tandem_realtime::Fault`), each released by the simulated operator once no robot
    /// was low-confidence (must be 0: a checked schedule never has one).
    #[serde(default)]
    pub faults: usize,
    /// The schedule's planned `T_total` (s, Eq. 13, planned dwells included), measured from
    /// the earliest start as the round's ticks are: [`RoundRun::duration_s`] is what the
    /// cell did against it ([`RoundRun::over_plan_s`]). 0 in records written before it was
    /// kept.
    #[serde(default)]
    pub planned_t_total_s: f64,
    /// Each robot's planned end (s, from the earliest start, planned dwells included): its
    /// realized end is [`RobotRun::end_tick`] times the tick. Empty in older records.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub planned_ends_s: Vec<f64>,
    /// Where the round's time went against its plan ([`PlanGap`]): realized minus planned
    /// `T_total` split into corrections, holds, the response strategy and the tick grid.
    /// All zero in older records.
    #[serde(default)]
    pub plan_gap: PlanGap,
    /// The operator's rest after the round (control ticks) under the load cap `u_max < 1`
    /// (issue 41, [`tandem_realtime::Coordinator::rest_ticks`]): the next round starts that
    /// many ticks after this one ended, so that the operator's busy ticks (low-confidence
    /// ticks and the switch time per change of robot) are at most `u_max` of the round and
    /// its rest. 0 without a cap, and then left out of the JSON.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rest_ticks: usize,
}

/// Deprecated: [`RoundRun`] under its two-robot name (a round is one execution of each
/// robot, two in the paper). Kept for one release at the crate's public edge.
#[deprecated(note = "use `RoundRun` (a round is one execution of each robot)")]
pub type PairRun = RoundRun;

impl RoundRun {
    /// Every robot's execution record, robot 1 first, for
    /// [`Planner::record_round`](tandem_planner::Planner::record_round) (see
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

    /// Share of the robots' time in the round spent not moving along their tasks, in
    /// `[0, 1]`: waiting for a start offset, standing at a hold point, or done before the
    /// round's last robot (robot-ticks without a sample over `N ×` the round's ticks). The
    /// rounds counterpart of the continuous cell's gate waiting
    /// ([`CellStats`](super::CellStats)).
    #[must_use]
    pub fn robot_wait_share(&self) -> f64 {
        let n = self.robots.len();
        if self.ticks == 0 || n == 0 {
            return 0.0;
        }
        let moving: usize = self.robots.iter().map(|r| r.ref_time_log.len()).sum();
        1.0 - moving as f64 / (n * self.ticks) as f64
    }

    /// Actual duration of the round (s): ticks times the control period.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        self.ticks as f64 * self.tick_s
    }

    /// How much longer the round took than planned (s): [`RoundRun::duration_s`] minus
    /// [`RoundRun::planned_t_total_s`] (negative when it ended early, e.g. when the robots
    /// ran high-confidence stretches faster than planned, Alg. 1).
    #[must_use]
    pub fn over_plan_s(&self) -> f64 {
        self.duration_s() - self.planned_t_total_s
    }

    /// Samples the robots ran unsupervised (high confidence) where `needs(robot, ref_idx)`
    /// (the truth, as for [`run_round_with`](super::run_round_with), at `round(t_i)`) says
    /// the operator is needed: nobody watched a robot that needed watching. Summed over the
    /// robots; asked once per unsupervised sample.
    #[must_use]
    pub fn needed_unsupervised(&self, mut needs: impl FnMut(usize, usize) -> bool) -> usize {
        let mut count = 0;
        for (i, r) in self.robots.iter().enumerate() {
            for (&t, &sup) in r.ref_time_log.iter().zip(&r.supervised) {
                if !sup && needs(i, t.max(0.0).round() as usize) {
                    count += 1;
                }
            }
        }
        count
    }
}

/// Where a round's time went against its plan: realized minus planned `T_total` (s) split
/// into causes that add up to it exactly (docs/decisions.md, "Plans that say how optimistic
/// they are").
///
/// The split follows the *critical robot*: the robot that finished last (the round's end;
/// of several, the one planned to end last). Its realized end is `E·τ` (`E` ticks of `τ`
/// s); its planned end is its start offset, its run time `P(T_ref)` (the schedule clock of
/// its warp, Eq. 15, at the end) and its planned dwells at holds. Each of its ticks before
/// `E` contributes a *deficit*, the real time it took (`τ`) minus the planned time it
/// covered, to one cause:
///
/// - waiting for its start: `τ − Δs` (its schedule clock `s`, which follows the pace of the
///   running robots, advanced by `Δs`);
/// - running from reference time `t` to `t'` (the next logged sample, or `T_ref`):
///   `τ − (P(t') − P(t))`, with `P` the planned clock of the warp;
/// - at a hold: `τ` (less the planned dwells, once for the round); held by the fault
///   monitor: `τ`.
///
/// A running or waiting tick in which the operator corrected a robot goes to
/// [`PlanGap::corrections_s`] (the correction's rate drives the coordinator, Alg. 1 paces the
/// others after it); the last running tick before a hold or the finish, cut short where the
/// leg ends, goes to [`PlanGap::grid_s`]; every other running or waiting tick, run at the
/// rates the coordinator chose on its own (Alg. 1's rates ahead of or behind the warp), goes
/// to [`PlanGap::strategy_s`]. The deficits sum to the realized end minus the planned end
/// exactly, up to the start term `(s_W − s_0) − (τ_c − t_0) − P(t_first)` (the clock's
/// advance over the `W` waiting ticks against the planned start offset and the planned clock
/// already covered at the first logged sample; 0 up to rounding when the coordinator's clock
/// and the warp agree), which goes to
/// [`PlanGap::grid_s`]. [`PlanGap::critical_path_s`] is the critical robot's planned end
/// minus the planned `T_total` (≤ 0: another robot was planned to end last). So
/// `corrections + holds + strategy + grid + faults + critical_path = realized − planned`.
///
/// Approximations of the classification (the sum stays exact): a robot released from a hold
/// inside a tick moves in a tick logged at the hold, and that motion is credited to its
/// last tick before the hold (grid); a tick whose logged correction was decided after the
/// fact (a one-sample island crossed inside a high-confidence tick) counts as corrected
/// although its rate was the schedule's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PlanGap {
    /// Realized duration of the round (s): its ticks times `τ`.
    pub realized_s: f64,
    /// Planned `T_total` (s, from the earliest start, planned dwells included).
    pub planned_s: f64,
    /// The critical robot (0-based): the one that finished last.
    pub critical_robot: usize,
    /// Time lost (s; negative: gained) in ticks in which the operator corrected.
    pub corrections_s: f64,
    /// Time at hold points beyond the planned dwells (s).
    pub holds_s: f64,
    /// Time lost or gained (s) at the coordinator's own rates (Alg. 1: running ahead of or
    /// behind the warp, starts paced by the running robots) in ticks without a correction.
    pub strategy_s: f64,
    /// The tick grid (s): the unused part of the last tick of each leg and the start term.
    pub grid_s: f64,
    /// Ticks held by the coordinator's fault monitor (s; 0 for a checked schedule).
    pub faults_s: f64,
    /// The critical robot's planned end minus the planned `T_total` (s, ≤ 0).
    pub critical_path_s: f64,
}

impl PlanGap {
    /// Realized minus planned (s).
    #[must_use]
    pub fn total_s(&self) -> f64 {
        self.realized_s - self.planned_s
    }

    /// The causes with their names, in the order the summaries print them: `corrections`,
    /// `holds`, `strategy`, `grid`, `faults`, `critical path` (s each; they sum to
    /// [`PlanGap::total_s`]).
    #[must_use]
    pub fn parts(&self) -> [(&'static str, f64); 6] {
        [
            ("corrections", self.corrections_s),
            ("holds", self.holds_s),
            ("strategy", self.strategy_s),
            ("grid", self.grid_s),
            ("faults", self.faults_s),
            ("critical path", self.critical_path_s),
        ]
    }

    /// The sum of [`PlanGap::parts`] (s): [`PlanGap::total_s`] up to rounding.
    #[must_use]
    pub fn parts_sum_s(&self) -> f64 {
        self.parts().iter().map(|(_, s)| s).sum()
    }

    /// One line: `+1.20 s over plan (+3.4 %): corrections +0.90 s (75 %), holds +0.30 s
    /// (25 %)`: realized minus planned and each cause's seconds with its share of the
    /// difference (`part / total`; shares of offsetting causes can exceed 100 % or be
    /// negative). Causes under 5 ms are left out.
    #[must_use]
    pub fn describe(&self) -> String {
        let total = self.total_s();
        let pct = if self.planned_s > 0.0 {
            100.0 * total / self.planned_s
        } else {
            0.0
        };
        let word = if total >= 0.0 { "over" } else { "under" };
        let parts: Vec<String> = self
            .parts()
            .iter()
            .filter(|(_, s)| s.abs() >= 0.005)
            .map(|(name, s)| {
                if total.abs() > 1e-9 {
                    format!("{name} {s:+.2} s ({:.0} %)", 100.0 * s / total)
                } else {
                    format!("{name} {s:+.2} s")
                }
            })
            .collect();
        let causes = if parts.is_empty() {
            String::new()
        } else {
            format!(": {}", parts.join(", "))
        };
        format!("{:.2} s {word} plan ({pct:+.1} %){causes}", total.abs())
    }

    /// The cause with the largest magnitude and its seconds.
    #[must_use]
    pub fn dominant(&self) -> (&'static str, f64) {
        self.parts().into_iter().fold(
            ("none", 0.0),
            |a, b| if b.1.abs() > a.1.abs() { b } else { a },
        )
    }

    /// The mean of the gaps of several rounds, cause by cause (`None` for none; critical
    /// robot of the first).
    #[must_use]
    pub fn mean<'a>(gaps: impl IntoIterator<Item = &'a PlanGap>) -> Option<PlanGap> {
        let mut n = 0_usize;
        let sum = PlanGap::sum(gaps.into_iter().inspect(|_| n += 1));
        (n > 0).then(|| sum.scaled(1.0 / n as f64))
    }

    /// Every time of the gap times `factor` (the critical robot kept).
    #[must_use]
    pub fn scaled(&self, factor: f64) -> PlanGap {
        PlanGap {
            realized_s: self.realized_s * factor,
            planned_s: self.planned_s * factor,
            critical_robot: self.critical_robot,
            corrections_s: self.corrections_s * factor,
            holds_s: self.holds_s * factor,
            strategy_s: self.strategy_s * factor,
            grid_s: self.grid_s * factor,
            faults_s: self.faults_s * factor,
            critical_path_s: self.critical_path_s * factor,
        }
    }

    /// The sum of the gaps of several rounds, cause by cause (critical robot of the first).
    #[must_use]
    pub fn sum<'a>(gaps: impl IntoIterator<Item = &'a PlanGap>) -> PlanGap {
        let mut out = PlanGap::default();
        let mut first = true;
        for g in gaps {
            if first {
                out.critical_robot = g.critical_robot;
                first = false;
            }
            out.realized_s += g.realized_s;
            out.planned_s += g.planned_s;
            out.corrections_s += g.corrections_s;
            out.holds_s += g.holds_s;
            out.strategy_s += g.strategy_s;
            out.grid_s += g.grid_s;
            out.faults_s += g.faults_s;
            out.critical_path_s += g.critical_path_s;
        }
        out
    }
}

/// One robot's plan for [`plan_gap`]: its planned start `τ_i`, its planned end (dwells at
/// holds included) and the breakpoints `c_0 = τ_i, …, c_{T_ref}` of its warp's clock
/// ([`tandem_realtime::clock_s`]), all on the schedule clock (s).
#[derive(Clone, Debug, PartialEq)]
pub struct RobotPlan {
    /// Planned start (s, schedule clock).
    pub start_s: f64,
    /// Planned end (s, schedule clock, planned dwells included).
    pub end_s: f64,
    /// The warp's clock breakpoints (s, schedule clock; `T_ref + 1` values from `start_s`).
    pub sample_clock_s: Vec<f64>,
}

impl RobotPlan {
    /// The planned time (s) from the start of the warp to reference time `t` (reference
    /// samples, clamped to `[0, T_ref]`): `P(t)`, linear within a sample (Eq. 15 inverted).
    #[must_use]
    pub fn clock_at(&self, t: f64) -> f64 {
        let c = &self.sample_clock_s;
        let n_ref = c.len().saturating_sub(1);
        if n_ref == 0 {
            return 0.0;
        }
        let t = t.clamp(0.0, n_ref as f64);
        let n = (t.floor() as usize).min(n_ref - 1);
        c[n] + (t - n as f64) * (c[n + 1] - c[n]) - c[0]
    }
}

/// The [`PlanGap`] of `round` against `plans` (one per robot), `corrected_tick[k]` saying
/// whether the operator's input in tick `k` was a correction (see [`PlanGap`] for the
/// rules). `round.planned_t_total_s` is the planned `T_total`; robots' clocks, phases and
/// logs are the round's.
#[must_use]
pub fn plan_gap(round: &RoundRun, plans: &[RobotPlan], corrected_tick: &[bool]) -> PlanGap {
    let tau = round.tick_s;
    let mut gap = PlanGap {
        realized_s: round.duration_s(),
        planned_s: round.planned_t_total_s,
        ..PlanGap::default()
    };
    if round.robots.is_empty() || plans.len() != round.robots.len() {
        gap.grid_s = gap.total_s();
        return gap;
    }
    let t0 = plans
        .iter()
        .map(|p| p.start_s)
        .fold(f64::INFINITY, f64::min);
    let c = (0..round.robots.len())
        .max_by(|&a, &b| {
            let key = |i: usize| (round.robots[i].end_tick(), plans[i].end_s);
            let (ea, pa) = key(a);
            let (eb, pb) = key(b);
            ea.cmp(&eb).then(pa.total_cmp(&pb))
        })
        .unwrap_or(0);
    gap.critical_robot = c;
    let (run, plan) = (&round.robots[c], &plans[c]);
    let n_ref = plan.sample_clock_s.len().saturating_sub(1) as f64;
    let end = run.end_tick();
    let corrected = |k: usize| corrected_tick.get(k).copied().unwrap_or(false);
    let mut j = 0;
    let mut first_t = None;
    let mut waited_clock_s = 0.0;
    for k in 0..end {
        match run.phases.get(k).copied().unwrap_or(TickPhase::Finished) {
            TickPhase::Waiting => {
                let ds = match (run.clock_s.get(k), run.clock_s.get(k + 1)) {
                    (Some(a), Some(b)) => b - a,
                    _ => 0.0,
                };
                waited_clock_s += ds;
                if corrected(k) {
                    gap.corrections_s += tau - ds;
                } else {
                    gap.strategy_s += tau - ds;
                }
            }
            TickPhase::Running => {
                let t = run.ref_time_log.get(j).copied().unwrap_or(n_ref);
                let next = run.ref_time_log.get(j + 1).copied().unwrap_or(n_ref);
                first_t.get_or_insert(t);
                j += 1;
                let d = tau - (plan.clock_at(next) - plan.clock_at(t));
                let last_of_leg = run.phases.get(k + 1) != Some(&TickPhase::Running);
                if last_of_leg {
                    gap.grid_s += d;
                } else if corrected(k) {
                    gap.corrections_s += d;
                } else {
                    gap.strategy_s += d;
                }
            }
            TickPhase::AtHold => gap.holds_s += tau,
            TickPhase::Held => gap.faults_s += tau,
            TickPhase::Finished => {}
        }
    }
    let run_s = plan.clock_at(n_ref);
    gap.holds_s -= plan.end_s - plan.start_s - run_s;
    // The start term: the clock's advance while waiting against the planned start offset
    // and the planned clock already covered at the first logged sample.
    gap.grid_s += waited_clock_s - (plan.start_s - t0) - plan.clock_at(first_t.unwrap_or(0.0));
    gap.critical_path_s = (plan.end_s - t0) - round.planned_t_total_s;
    gap
}
