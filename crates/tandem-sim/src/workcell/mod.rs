//! The simulated workcell of the study (§III): the `N` robots of the planner's schedule
//! (two in the paper) run one round, one execution each, through the real-time
//! coordinator while a simulated operator supervises the low-confidence robot.
//!
//! # One control tick
//!
//! The control period is the reference sample period `Δt_s`, so every tick gives each
//! running robot one execution sample, as in the demonstrations. The schedule must have been
//! checked at that tick ([`Schedule::tick_s`](tandem_schedule::Schedule::tick_s), the tick of
//! its margin check): a schedule made for another tick is rejected with
//! [`Error::TickMismatch`](crate::Error::TickMismatch) rather than run at a period its safety
//! check never saw.
//!
//! 1. Each robot the coordinator will move (`Controller::running_now`) has its fractional
//!    reference time `t_i` (Eq. 15) from the coordinator's last tick, and its sample
//!    `n_i = ⌊t_i⌋`. The robot the coordinator reports low-confidence
//!    (`Controller::low_conf_now`) is *supervised* this tick; that is the robot the
//!    coordinator will move at the operator's rate. The one tick of rounds and of the
//!    continuous cell ([`CellSim`]) is the same function, generic over
//!    `tandem_realtime::Controller`.
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
//!    one-sample low-confidence "islands" after 150 rounds (samples whose few observations
//!    happened to include several false corrections); every island of one robot forbids
//!    the other robot's low-confidence pass at that moment, so the schedule stays nearly
//!    serial. Measured on the default study (5 × 300 executions, seed 2023; `cargo xtask
//!    study`, and with `false_correction_s = 0` in its configuration for per-tick draws):
//!    per-tick draws leave 92–116 low-confidence runs per robot and schedule after 150
//!    rounds and end at `T_total` 136.63 ± 1.08 s; 0.5 s episodes leave 3–6 runs and end at
//!    106.22 ± 11.04 s (serial: 191.81 s). Episodes give each sample about the same 1 %
//!    chance per execution but make the islands contiguous and far fewer (docs/decisions.md,
//!    "Unneeded corrections come in 0.5 s episodes", with the figures of earlier commits).
//! 3. A correction is a joystick input `u` along the model's correction components
//!    (`TaskModel::local_corrections_at`: the components of `TaskModel::corrections_at` up to
//!    each one's sign, from the two reference samples around `t_i` only, so that a round right
//!    after a model update decomposes only the samples it corrects at), `u_k = ±gain` with the
//!    sign that raises the force; a
//!    component whose rate part would speed the robot up is left out when the combined
//!    input would otherwise speed it up, so a correction presses harder *and* slows the
//!    robot, as the expert did over paint. The command `x_f⁺ = μ̂⁺ + δx⁺(u)` (Eq. 7) comes
//!    from `TaskModel::local_command_into` (the same frame; the same command as
//!    `TaskModel::command` gives for the input chosen along `corrections_at`, since the rule
//!    is odd in each component); its last component, the warp gradient, is clamped to
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
//!    idle time, and any is operator busy time. A robot that started the tick on a
//!    high-confidence sample but crossed whole low-confidence samples inside it (a fast
//!    robot over a one-sample island) is supervised after the fact: the operator decides at
//!    the crossed samples and the tick's sample is recorded as supervised (its command
//!    unchanged), so that the island gets an observation (docs/decisions.md, "Rounds: a
//!    one-sample island is never jumped unobserved").
//! 6. An overlap latches a fault of the coordinator's run-time monitor (`Tick::fault`), which
//!    holds one robot in place; the round counts it (`RoundRun::faults`), the held robot
//!    logs nothing while held, and the operator releases it (`Coordinator::clear_fault`)
//!    after the first tick in which no robot is low-confidence, so every round finishes.

mod cell;
mod live;
mod mixed;
mod mixed_cell;
mod operator;
mod record;
mod run;
#[cfg(test)]
mod tests;

pub use cell::{CellSim, CellStats, FinishedTask};
pub use live::RoundSim;
pub use mixed::run_cell_round;
pub use mixed_cell::{MixedCellSim, mixed_record};
pub use operator::{OperatorParams, correction_channel, correction_input, needs_correction};
pub use record::{PlanGap, RobotPlan, RobotRun, RoundRun, TickPhase, plan_gap};
pub use run::{run_round, run_round_with};
// The two-robot names of one release ago, deprecated at the crate's public edge only.
#[expect(deprecated, reason = "re-exported for one release at the public edge")]
pub use {record::PairRun, run::run_pair, run::run_pair_with};
