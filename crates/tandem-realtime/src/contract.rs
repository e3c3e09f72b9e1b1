//! THE run-time contract of a cell: what every controller — the rounds
//! [`Coordinator`](crate::Coordinator) and the continuous cell's
//! [`ContinuousCoordinator`](crate::ContinuousCoordinator) — offers the code that drives it (the
//! adversary driver [`run_adversary`](crate::adversary::run_adversary), a workcell, a console):
//! one [`Operator`] input per operator per tick ([`Controller::tick_many`]; one operator:
//! [`Controller::tick`]), one [`Tick`] out, one fault monitor ([`Fault`]), and each robot's
//! position and state ([`Controller`]; docs/decisions.md, "One run-time contract" and "M
//! operators: the invariant and the continuous cell (issue 44)").

use crate::adversary::AdversaryRun;
use crate::error::{Error, Result};
use crate::monitor::Fault;
use crate::robots::{PerRobot, RobotFlags};

/// The operator's input to one control tick (§II-B5): how the correction given to the
/// low-confidence robot sets its timing. Ignored when no robot is low-confidence.
///
/// The three conventions that used to encode this in one `f64` (0 for fastest, a huge value
/// or infinity for slowest, NaN for "no correction") are gone: a NaN from a degenerate
/// command is now an error ([`Error::BadOperator`]), not a silent "no correction".
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operator {
    /// No correction: the low-confidence robot keeps its scheduled gradient `ψ̇_E`.
    Scheduled,
    /// The correction commands execution gradient `g` (execution samples per reference
    /// sample; finite and > 0), clamped to `[ψ̇min, ψ̇max]` at the robot's current sample.
    Gradient(f64),
    /// As fast as the demonstrations allow: the gradient `ψ̇min` (the operator rushes).
    Fastest,
    /// As slowly as the demonstrations allow: the gradient `ψ̇max` (the operator drags).
    Slowest,
}

impl Operator {
    /// Checks a [`Operator::Gradient`]: finite and > 0.
    ///
    /// # Errors
    /// [`Error::BadOperator`] with the gradient.
    pub fn validate(self) -> Result<Self> {
        match self {
            Operator::Gradient(g) if !(g.is_finite() && g > 0.0) => {
                Err(Error::BadOperator { gradient: g })
            }
            op => Ok(op),
        }
    }
}

/// What one [`Controller::tick`] did, one value per robot (robot `i` at index `i`), at the end
/// of the tick. The same type for rounds and the continuous cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tick {
    /// Each robot's fractional reference time (reference samples) at the end of the tick
    /// (Eq. 15 applied to its schedule clock): rounds, in `[0, T_ref]` of its one task; the
    /// continuous cell, in `[0, T_ref)` of its current task (a robot that finished a task in
    /// this tick is at 0 of the next).
    pub ref_time: PerRobot<f64>,
    /// Each robot's number of completed tasks at the end of the tick: the continuous cell
    /// counts them for ever; rounds, 0 until the robot has finished its task (its last leg),
    /// then 1.
    pub tasks: PerRobot<u64>,
    /// Whether each robot traversed ANY low-confidence reference sample during this tick (any
    /// low-confidence sample in its traversed schedule-clock interval widened by the clock
    /// tolerance, `[s_old − tol, s_new + tol]`: see [`Coordinator`](crate::Coordinator) for
    /// the exact, conservative definition, which both controllers share).
    pub low_conf: RobotFlags,
    /// The operator (index `0..M`) each robot was assigned to during the tick, for every
    /// robot flagged in [`low_conf`](Tick::low_conf) (`None` for the others; in a tick with a
    /// fault an extra robot may have none). One operator (rounds): `Some(0)` for each
    /// low-confidence robot. The continuous cell assigns a robot to one operator
    /// from the tick it may pass a group's gate until it leaves the group (never handed over
    /// mid-way; issue 44).
    pub operator: PerRobot<Option<u8>>,
    /// Whether each robot ran during the tick: its schedule clock moved (rounds: inside its
    /// plan, `[τ_i, τ_i + |ψ_E|)`).
    pub running: RobotFlags,
    /// Whether each robot waits for the other robots at the end of the tick: rounds, stopped at
    /// a hold point (not its start; `crate::holds`); the continuous cell, at the gate of its
    /// next group (the token is another's).
    pub waiting: RobotFlags,
    /// The latched fault, if any (this tick's or an earlier one's, until
    /// [`Controller::clear_fault`]): see [`Fault`].
    pub fault: Option<Fault>,
    /// The pre-alert (issue 41): the robot whose next low-confidence stretch (one it has not
    /// touched yet; for a robot low-confidence now, the one after its current one) can start
    /// soonest, and bounds on that start in real seconds from the end of this tick, worst case
    /// over admissible operators ([`PreAlert`](crate::PreAlert), module
    /// [`prealert`](crate::prealert)). `None` when no robot has a stretch ahead (rounds: every
    /// remaining stretch touched).
    pub next: Option<crate::PreAlert>,
}

impl Tick {
    /// Whether two or more robots traversed a low-confidence sample in this tick: one
    /// operator was needed by two robots at once (a schedule that
    /// [`sufficient_margins`](crate::sufficient_margins) accepts, and the continuous cell's
    /// token rule, never have such a tick). With `M > 1` operators use
    /// [`over`](Tick::over).
    #[must_use]
    pub fn overlap(&self) -> bool {
        crate::monitor::overlap(&self.low_conf)
    }

    /// Whether more than `operators` robots traversed a low-confidence sample in this tick:
    /// more robots needed help than there are operators (the fault of a cell of `M`
    /// operators; `over(1)` is [`overlap`](Tick::overlap)).
    #[must_use]
    pub fn over(&self, operators: usize) -> bool {
        self.low_conf.count() > operators
    }
}

/// A cell at run time: `1 ≤ N ≤` [`MAX_ROBOTS`](crate::MAX_ROBOTS) robots advanced one control
/// period `tick_s` (real seconds) per [`tick`](Controller::tick) under one operator, or per
/// [`tick_many`](Controller::tick_many) under `M` ([`operators`](Controller::operators)), with
/// the one fault monitor ([`Fault`]: a tick with more than `M` robots low-confidence holds the
/// robot whose low-confidence run began last until [`clear_fault`](Controller::clear_fault)).
///
/// Implemented by the rounds [`Coordinator`](crate::Coordinator) (every robot does its one
/// task; [`is_finished`](Controller::is_finished) once all have) and the continuous cell's
/// [`ContinuousCoordinator`](crate::ContinuousCoordinator) (robots repeat the task for ever;
/// never finished). Object safe: `Box<dyn Controller>` drives either. Every method is O(N) (the
/// cell's reference times O(N log T_ref)) and none allocates.
pub trait Controller {
    /// Number of robots `N`.
    fn n_robots(&self) -> usize;

    /// Control period (real seconds).
    fn tick_s(&self) -> f64;

    /// Number of operators `M` (`1 ≤ M`; [`OperatorCount`](crate::OperatorCount)): at most
    /// `M` robots are low-confidence in any tick. The default: one.
    fn operators(&self) -> usize {
        1
    }

    /// Advances every robot one control period with one input per operator: `inputs[o]` sets
    /// the timing of the robot operator `o` supervises ([`Tick::operator`]; ignored when it
    /// supervises none). `tick_many(&[op])` is [`tick(op)`](Controller::tick). Never
    /// allocates; O(N). The default (one operator) checks the count and calls `tick`.
    ///
    /// # Errors
    /// [`Error::OperatorInputs`] unless `inputs.len() == M`; [`Error::BadOperator`] for an
    /// inadmissible gradient; the controller is then unchanged.
    fn tick_many(&mut self, inputs: &[Operator]) -> Result<Tick> {
        match inputs {
            [op] if self.operators() == 1 => self.tick(*op),
            _ => Err(Error::OperatorInputs {
                got: inputs.len(),
                want: self.operators(),
            }),
        }
    }

    /// The operator each robot is assigned to now, for the robots of
    /// [`low_conf_now`](Controller::low_conf_now) ([`Tick::operator`]). The default (one
    /// operator): `Some(0)` for each of them.
    fn operator_now(&self) -> PerRobot<Option<u8>> {
        one_operator(&self.low_conf_now())
    }

    /// Advances every robot one control period with the operator's input `operator` for the
    /// low-confidence robot (ignored when no robot is low-confidence). Never allocates; O(N).
    ///
    /// # Errors
    /// [`Error::BadOperator`] for an [`Operator::Gradient`] that is NaN, infinite or ≤ 0; the
    /// controller is then unchanged.
    fn tick(&mut self, operator: Operator) -> Result<Tick>;

    /// Back to the start (every robot at the start of its first task, no fault, tick count
    /// 0), without allocating: to run the same plan again.
    fn reset(&mut self);

    /// The latched fault, if two robots have been low-confidence in one tick since the start,
    /// the last reset or the last [`clear_fault`](Controller::clear_fault).
    fn fault(&self) -> Option<Fault>;

    /// Clears the latched fault: the held robot moves again from the next tick on.
    fn clear_fault(&mut self);

    /// Whether each robot is low-confidence at the tick start and may move: the robot the next
    /// tick moves at the operator's rate (the robot an operator supervises now).
    fn low_conf_now(&self) -> RobotFlags;

    /// Whether each robot moves in the next tick if the rules let it: started, not waiting
    /// for the others, not finished and not held by the fault monitor.
    fn running_now(&self) -> RobotFlags;

    /// Whether each robot waits for the other robots now ([`Tick::waiting`]): at a hold
    /// (rounds) or at its next group's gate (the continuous cell).
    fn waiting_now(&self) -> RobotFlags;

    /// The pre-alert now: the value the last [`Tick::next`] reported (the next low-confidence
    /// stretch of any robot and the bounds on its start, real s from the end of the last tick;
    /// [`crate::prealert`]), for a caller that reads the controller between ticks. O(N), no
    /// allocation.
    fn pre_alert(&self) -> Option<crate::PreAlert>;

    /// Each robot's fractional reference time now (reference samples, in its current task):
    /// the value the last [`Tick::ref_time`] reported (0 at the start). Never decreases within
    /// a task.
    fn ref_time_now(&self) -> PerRobot<f64>;

    /// Each robot's number of completed tasks now ([`Tick::tasks`]).
    fn tasks_now(&self) -> PerRobot<u64>;

    /// Each robot's schedule clock (s) in its current task: rounds, the global schedule clock
    /// (non-decreasing); the continuous cell, the task-plan clock from 0 at each task start.
    /// `(tasks, clock)` never decreases lexicographically from tick to tick.
    fn clock_s(&self) -> &[f64];

    /// Whether every robot has finished: rounds, once every robot has done its task; the
    /// continuous cell, never.
    fn is_finished(&self) -> bool;

    /// Ticks run since the start or the last reset: the index the next tick will have (a
    /// [`Fault::tick`] counts in it, so a fault latched in the last tick has `tick + 1 ==
    /// ticks()`).
    fn ticks(&self) -> u64;

    /// The run of the worst operator sequence the beam search of
    /// [`Adversary::Beam`](crate::adversary::Adversary::Beam) finds from this state, for a
    /// controller that has one (rounds: [`beam_search`](crate::adversary::search::beam_search));
    /// `None`, the default: [`run_adversary`](crate::adversary::run_adversary) runs the beam as
    /// a switching policy. `self` is not changed.
    ///
    /// # Errors
    /// Those of the search (none in practice).
    fn beam_search(&self, width: u32, max_ticks: u64) -> Option<Result<AdversaryRun>> {
        let _ = (width, max_ticks);
        None
    }
}

/// `Some(0)` for each robot flagged in `low_conf`: the operator of every low-confidence robot
/// of a one-operator controller ([`Tick::operator`]).
pub(crate) fn one_operator(low_conf: &RobotFlags) -> PerRobot<Option<u8>> {
    let mut out = PerRobot::new(low_conf.len());
    for (i, o) in out.as_mut_slice().iter_mut().enumerate() {
        *o = low_conf[i].then_some(0);
    }
    out
}

/// Checks a control period: finite and > 0 (the one check of every controller's `tick_s`).
///
/// # Errors
/// [`Error::BadParam`] naming `tick_s`.
pub(crate) fn check_tick(tick_s: f64) -> Result<()> {
    if tick_s.is_finite() && tick_s > 0.0 {
        Ok(())
    } else {
        Err(Error::BadParam {
            name: "tick_s",
            why: "must be finite and > 0",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ContinuousCoordinator, Coordinator, Timeline};

    /// Runs `c` through the trait object for `ticks` ticks (or until finished) rushing the
    /// operator, checking the contract at every tick: the tick agrees with the `*_now` readers,
    /// `(tasks, clock)` and `(tasks, reference time)` never decrease, no overlap.
    fn drive(c: &mut dyn Controller, ticks: usize) -> Tick {
        let mut last: Option<Vec<(u64, f64, f64)>> = None;
        let mut out = None;
        for _ in 0..ticks {
            if c.is_finished() {
                break;
            }
            let t = c.tick(Operator::Fastest).unwrap();
            assert!(!t.overlap() && t.fault.is_none() && c.fault().is_none());
            assert_eq!(t.ref_time, c.ref_time_now());
            assert_eq!(t.tasks, c.tasks_now());
            assert_eq!(t.waiting, c.waiting_now());
            assert!(c.ticks() >= 1);
            let now: Vec<_> = (0..c.n_robots())
                .map(|i| (t.tasks[i], c.clock_s()[i], t.ref_time[i]))
                .collect();
            if let Some(last) = &last {
                for (a, b) in now.iter().zip(last) {
                    assert!(a.0 > b.0 || (a.0 == b.0 && a.1 >= b.1 && a.2 >= b.2));
                }
            }
            last = Some(now);
            out = Some(t);
        }
        out.expect("at least one tick")
    }

    #[test]
    fn both_controllers_keep_the_contract() {
        // [HC, LC, HC] at Δt_s = 1, bounds [½, 2].
        let conf = [true, false, true];
        let (g, lo, hi) = ([1.0; 3], [0.5; 3], [2.0; 3]);
        let task = Timeline::new(&conf, &g, &lo, &hi, 0.0, 1.0).unwrap();
        let second = Timeline::new(&conf, &g, &lo, &hi, 3.0, 1.0).unwrap();
        let mut rounds = Coordinator::new([task.clone(), second], 1.0).unwrap();
        let mut cell = ContinuousCoordinator::new(task, &[], &[(0, 0), (1, 0)], 2, 1.0).unwrap();
        let controllers: [&mut dyn Controller; 2] = [&mut rounds, &mut cell];
        let mut last = Vec::new();
        for c in controllers {
            assert_eq!((c.n_robots(), c.tick_s()), (2, 1.0));
            // Robot 1 waits (rounds: for its start; the cell: at its gate, robot 0 has the
            // token), robot 0 runs into its low-confidence sample.
            assert_eq!(c.running_now(), [true, false]);
            last.push(drive(c, 200));
            c.reset();
            assert_eq!(c.ticks(), 0);
            assert_eq!(c.tasks_now(), [0, 0]);
            assert_eq!(c.ref_time_now(), [0.0, 0.0]);
        }
        // Rounds: both robots done their one task, at its end; the cell runs for ever.
        assert_eq!(last[0].tasks, [1, 1]);
        assert_eq!(last[0].ref_time, [3.0, 3.0]);
        assert!(
            last[1].tasks.iter().all(|&k| k >= 20),
            "{:?}",
            last[1].tasks
        );
    }

    /// The same forced overlap in both controllers: two robots of `[LC, LC, HC, HC]` (Δt_s = 1,
    /// bounds [½, 2], tick 1 s) both on their first low-confidence sample at the start —
    /// rounds started together without the margin check, and a cell whose robot 1 is placed
    /// inside the group without the token (as if it had already been let through).
    fn forced_overlaps() -> [Box<dyn Controller>; 2] {
        let conf = [false, false, true, true];
        let (g, lo, hi) = ([1.0; 4], [0.5; 4], [2.0; 4]);
        let task = Timeline::new(&conf, &g, &lo, &hi, 0.0, 1.0).unwrap();
        let rounds = Coordinator::new_unchecked([task.clone(), task.clone()], 1.0).unwrap();
        let mut cell = ContinuousCoordinator::new(task, &[], &[(0, 0), (1, 0)], 2, 1.0).unwrap();
        // One group (gate 0); robot 0 has its token; robot 1 "has left" it: no cap.
        cell.place_unchecked(1, 0.0, 1);
        [Box::new(rounds), Box::new(cell)]
    }

    /// Both controllers' faults and the held robot's clock over two ticks of dragging.
    fn faults_of(mut c: Box<dyn Controller>) -> (Option<Fault>, bool) {
        // (The cell reports only its token's robot as the one to supervise.)
        assert!(c.low_conf_now()[0]);
        let t = c.tick(Operator::Slowest).unwrap();
        assert!(t.overlap());
        let held = t.fault.expect("an overlap latches a fault").stopped;
        let before = c.clock_s()[held];
        let t2 = c.tick(Operator::Slowest).unwrap();
        assert_eq!(t2.fault, t.fault);
        // The held robot does not move; the other one does.
        let still = c.clock_s()[held] == before && !t2.running[held] && t2.running[1 - held];
        (t.fault, still)
    }

    #[test]
    fn one_monitor_two_controllers() {
        // The policy: hold the robot whose run began last, the higher index on a tie (here
        // both runs begin in tick 0).
        let want = |stopped| {
            Some(Fault {
                tick: 0,
                low_conf: RobotFlags::from_slice(&[true, true]),
                stopped,
            })
        };
        for c in forced_overlaps() {
            assert_eq!(faults_of(c), (want(1), true));
        }
        // A change of the policy in one place — the monitor's tie rule, through its test
        // hook — changes both controllers alike.
        crate::monitor::hold_lowest_on_tie(true);
        let changed: Vec<_> = forced_overlaps().into_iter().map(faults_of).collect();
        crate::monitor::hold_lowest_on_tie(false);
        assert_eq!(changed, [(want(0), true), (want(0), true)]);
    }

    #[test]
    fn a_bad_tick_is_one_error() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(matches!(
                check_tick(bad),
                Err(Error::BadParam { name: "tick_s", .. })
            ));
        }
        assert!(check_tick(0.01).is_ok());
    }
}
