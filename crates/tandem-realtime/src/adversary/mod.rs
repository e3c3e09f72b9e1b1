//! Adversarial operators: the one set of operator policies that the safety checks draw from
//! (`cargo xtask stress`, the schedule crate's `coordinator_safety` test and this crate's
//! property test `tests/safety.rs`).
//!
//! The invariant they test: for every schedule [`sufficient_margins`](crate::sufficient_margins)
//! accepts and every admissible operator, no two robots are low-confidence in one tick. An
//! [`Adversary`] picks the [`Operator`] input of each control tick, possibly from the
//! coordinator's state (which robot is low-confidence now); the set contains the extremes,
//! random and switching sequences, and — as [`Adversary::RushRobot`], one per robot — exactly
//! Alg. 2's worst case for every role whose current robot is that robot (rush it while it is
//! low-confidence, drag every other robot while it is), and, as
//! [`Adversary::SwitchFavourite`], the same with the favoured robot changing at random times.
//! [`Adversary::Beam`] is not a policy but a search: a beam search over the per-tick choices
//! that compares operator sequences at equal progress and keeps those with the smallest
//! clearance between regions ([`search`]).
//! [`adversary_set`] returns the full set for one case of `N` robots, [`run_adversary`] runs one
//! execution under one adversary and counts the ticks with two or more robots low-confidence.
//! The driver is the one for every controller ([`Controller`]: rounds and the continuous cell,
//! [`run_adversary_on`] for a number of tasks); [`operators::run_operators_on`] drives `M ≥ 1`
//! operators, each with its own copy of a policy, and checks the `M`-operator invariant.
//!
//! ```
//! use rand::SeedableRng;
//! use tandem_realtime::adversary::{adversary_set, run_adversary};
//! use tandem_realtime::{Coordinator, Timeline};
//!
//! let conf = [true, false, false, true, true, true];
//! let (mean, lo, hi) = ([1.0; 6], [0.8; 6], [1.25; 6]);
//! let robots = [
//!     Timeline::new(&conf, &mean, &lo, &hi, 0.0, 0.1)?,
//!     Timeline::new(&conf, &mean, &lo, &hi, 0.45, 0.1)?,
//! ];
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! for adversary in adversary_set(2, [0.8, 1.25], 20, &mut rng) {
//!     let coordinator = Coordinator::new(robots.clone(), 0.05)?;
//!     let run = run_adversary(coordinator, adversary, &mut rng, 1000)?;
//!     assert!(run.finished && run.overlap_ticks == 0 && run.first_overlap.is_none());
//! }
//! # Ok::<(), tandem_realtime::Error>(())
//! ```

pub mod operators;
pub mod search;

use rand::Rng;

use crate::{Controller, MAX_ROBOTS, Operator, Result};

/// An operator policy: which [`Operator`] input the operator gives at each control tick.
/// Extremes are clamped by the coordinator to the low-confidence robot's `[ψ̇min, ψ̇max]` at
/// its sample, so [`Operator::Fastest`] / [`Operator::Slowest`] mean "as fast / as slowly as
/// admissible" everywhere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Adversary {
    /// Never corrects ([`Operator::Scheduled`]).
    Nominal,
    /// Always [`Operator::Fastest`] (rushing).
    Fastest,
    /// Always [`Operator::Slowest`] (dragging).
    Slowest,
    /// Fastest for `period` ticks, then slowest for `period` ticks, and so on, shifted by
    /// `phase` ticks; `period: 1, phase: 0` switches every tick (fastest on even ticks).
    Periodic {
        /// Ticks per half period (≥ 1).
        period: u32,
        /// Ticks by which the pattern is shifted.
        phase: u32,
    },
    /// Fastest until tick `at`, slowest from then on (`rev`: slowest first).
    SwitchOnce {
        /// Index of the first tick of the second half.
        at: u64,
        /// Slowest first, fastest after.
        rev: bool,
    },
    /// Holds one extreme for a uniform `1..=max_hold` ticks, then the other (starting with
    /// slowest).
    RandomSwitching {
        /// Longest hold, ticks (≥ 1).
        max_hold: u32,
    },
    /// Fastest or slowest, drawn afresh every tick.
    RandomExtreme,
    /// A fresh gradient uniform in `[lo, hi]` every tick (choose a range covering the bounds;
    /// `lo > 0`).
    Random {
        /// Lowest gradient (execution samples per reference sample).
        lo: f64,
        /// Highest gradient.
        hi: f64,
    },
    /// A gradient uniform in `[lo, hi]` held for a uniform `1..=max_hold` ticks.
    RandomHeld {
        /// Lowest gradient (> 0).
        lo: f64,
        /// Highest gradient.
        hi: f64,
        /// Longest hold, ticks (≥ 1).
        max_hold: u32,
    },
    /// Alg. 2's worst case for every role whose current robot is `rush`: rush robot `rush`
    /// whenever it is the low-confidence one, drag any other robot whenever it is.
    RushRobot {
        /// Robot (index `0..N`) to rush.
        rush: usize,
    },
    /// Each time the low-confidence robot changes, an extreme drawn at random for it, held
    /// while it stays low-confidence.
    RandomPerRobot,
    /// [`Adversary::RushRobot`] with the favoured robot changing at random times: a robot drawn
    /// uniformly from the `N` robots is favoured (rushed while it is low-confidence, every other
    /// dragged) for a uniform `1..=max_hold` ticks, then another draw, and so on.
    SwitchFavourite {
        /// Longest hold, ticks (≥ 1).
        max_hold: u32,
    },
    /// Not a fixed policy: the beam search of [`search::beam_search`] over fastest, slowest and
    /// no correction at every tick, keeping `width` sequences per progress cell, those with the
    /// smallest clearance between low-confidence regions; it reports the first sequence found
    /// that overlaps.
    Beam {
        /// Sequences kept per progress cell (≥ 1).
        width: u32,
    },
}

/// Number of adversaries [`adversary_set`] returns for `n_robots` robots: 14 families (the beam
/// search included) plus one [`Adversary::RushRobot`] per robot.
#[must_use]
pub fn set_size(n_robots: usize) -> usize {
    14 + n_robots
}

/// Sequences per progress cell of the [`Adversary::Beam`] in [`adversary_set`].
pub const BEAM_WIDTH: u32 = 8;

/// The full set of adversaries for one case of `n_robots` robots: the extremes, no correction,
/// Alg. 2's worst case with each robot as the current one ([`Adversary::RushRobot`]), the
/// favoured robot switching at random times (holds up to 50 ticks, and up to a quarter of
/// `ticks`), the beam search ([`BEAM_WIDTH`] sequences per progress cell), switching every tick, periodic with a random period (1–8 ticks) and phase, one
/// switch at a random tick below `ticks` (about one execution's length, in ticks), random
/// switching (holds up to 50 ticks), random extremes per tick and per robot, and random
/// gradients over `grad_range = [lo, hi]` (the problem's `[min ψ̇min, max ψ̇max]`, execution
/// samples per reference sample) per tick and held up to 50 ticks. The random parameters are
/// drawn from `rng`; [`set_size`] gives the length.
pub fn adversary_set(
    n_robots: usize,
    grad_range: [f64; 2],
    ticks: u64,
    rng: &mut impl Rng,
) -> Vec<Adversary> {
    let [lo, hi] = grad_range;
    let mut set = vec![Adversary::Nominal, Adversary::Fastest, Adversary::Slowest];
    set.extend((0..n_robots).map(|rush| Adversary::RushRobot { rush }));
    let slow_switch = u32::try_from(ticks / 4).unwrap_or(u32::MAX).max(1);
    set.extend([
        Adversary::SwitchFavourite { max_hold: 50 },
        Adversary::SwitchFavourite {
            max_hold: slow_switch,
        },
        Adversary::Beam { width: BEAM_WIDTH },
        Adversary::Periodic {
            period: 1,
            phase: 0,
        },
        Adversary::Periodic {
            period: rng.random_range(1..=8),
            phase: rng.random_range(0..16),
        },
        Adversary::SwitchOnce {
            at: rng.random_range(0..ticks.max(1)),
            rev: rng.random_bool(0.5),
        },
        Adversary::RandomSwitching { max_hold: 50 },
        Adversary::RandomExtreme,
        Adversary::RandomPerRobot,
        Adversary::Random { lo, hi },
        Adversary::RandomHeld {
            lo,
            hi,
            max_hold: 50,
        },
    ]);
    set
}

/// What one execution under an [`Adversary`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AdversaryRun {
    /// Control ticks run.
    pub ticks: u64,
    /// Ticks in which two or more robots traversed a low-confidence sample (0 for a safe
    /// schedule).
    pub overlap_ticks: u64,
    /// Index of the first such tick.
    pub first_overlap: Option<u64>,
    /// Whether the run reached its goal within the tick budget: every robot finished (rounds),
    /// or completed the tasks asked ([`run_adversary_on`]).
    pub finished: bool,
    /// Ticks in which some robot moved backwards: its (tasks completed, reference time)
    /// ([`Tick`](crate::Tick)) or its (tasks completed, clock) ([`Controller::clock_s`])
    /// decreased (0: a robot never moves backwards; debug builds assert it in every tick).
    pub backward_steps: u64,
    /// The fewest tasks any robot completed at the end ([`Controller::tasks_now`]; rounds: 1
    /// once every robot has finished).
    pub min_tasks: u64,
    /// The shortest switch seen ([`SwitchGaps`]): the fewest ticks between a tick in which one
    /// robot traversed a low-confidence sample and a later tick in which another robot did, in
    /// which neither did (`None`: no such pair of ticks; [`Adversary::Beam`]: the shortest over
    /// every sequence the search expanded, [`search::beam_search`]). A schedule that
    /// [`check_margins`](crate::check_margins) accepts with switch time `δ` keeps it
    /// `≥ switch_ticks(δ, tick_s)`.
    pub min_switch_gap_ticks: Option<u64>,
}

/// The switches of one run, measured on the ticks the robots actually traversed: for each tick
/// in which a robot is low-confidence, the ticks since the last tick in which *another* robot
/// was (a tick with two low-confidence robots is an overlap, counted apart, not a switch).
#[derive(Clone, Debug, Default)]
pub struct SwitchGaps {
    /// Per robot, the last tick (index) in which it was low-confidence.
    last_lc: [Option<u64>; MAX_ROBOTS],
    /// The shortest gap so far (ticks).
    min_gap: Option<u64>,
}

impl SwitchGaps {
    /// Records tick `tick` (index, increasing) with its low-confidence robots.
    pub fn record(&mut self, tick: u64, low_conf: &crate::RobotFlags) {
        for r in (0..low_conf.len()).filter(|&r| low_conf.get(r)) {
            let other_last = (0..low_conf.len())
                .filter(|&q| q != r)
                .filter_map(|q| self.last_lc[q])
                .filter(|&t| t < tick)
                .max();
            if let Some(t) = other_last {
                let gap = tick - t - 1;
                self.min_gap = Some(self.min_gap.map_or(gap, |g| g.min(gap)));
            }
        }
        for r in (0..low_conf.len()).filter(|&r| low_conf.get(r)) {
            self.last_lc[r] = Some(tick);
        }
    }

    /// The shortest gap recorded (ticks), `None` if no robot followed another.
    #[must_use]
    pub fn min_gap_ticks(&self) -> Option<u64> {
        self.min_gap
    }
}

/// The check "a robot never moves backwards" from outside a controller: each robot's tasks
/// completed, reference time and clock at the end of the previous tick (or at the start),
/// compared with those at the end of the next.
#[derive(Clone, Copy, Debug)]
pub struct Backward {
    tasks: crate::PerRobot<u64>,
    ref_time: crate::PerRobot<f64>,
    clock_s: crate::PerRobot<f64>,
}

impl Backward {
    /// The robots' positions now ([`Controller::tasks_now`], [`Controller::ref_time_now`],
    /// [`Controller::clock_s`]).
    #[must_use]
    pub fn new<C: Controller + ?Sized>(controller: &C) -> Backward {
        Backward {
            tasks: controller.tasks_now(),
            ref_time: controller.ref_time_now(),
            clock_s: crate::PerRobot::from_slice(controller.clock_s()),
        }
    }

    /// After a tick of `controller` that returned `tick`: whether some robot's (tasks
    /// completed, reference time) or (tasks completed, clock) decreased lexicographically since
    /// the last call (or [`Backward::new`]), and remember the new positions. Also checks that
    /// the tick reported the tasks and reference time the controller reports now (a mismatch
    /// counts as a backward step: a caller reading one or the other would see the robot
    /// elsewhere).
    pub fn step<C: Controller + ?Sized>(&mut self, controller: &C, tick: &crate::Tick) -> bool {
        let now = Backward::new(controller);
        let mut back = false;
        for i in 0..controller.n_robots() {
            let same_task = now.tasks[i] == self.tasks[i];
            back |= now.tasks[i] < self.tasks[i]
                || (same_task
                    && (now.ref_time[i] < self.ref_time[i] || now.clock_s[i] < self.clock_s[i]))
                || tick.ref_time[i] != now.ref_time[i]
                || tick.tasks[i] != now.tasks[i];
        }
        *self = now;
        back
    }
}

/// Uniform in `[lo, hi]`; `lo` itself when the range is empty or not finite.
fn uniform(rng: &mut impl Rng, lo: f64, hi: f64) -> f64 {
    if lo < hi && lo.is_finite() && hi.is_finite() {
        rng.random_range(lo..=hi)
    } else {
        lo
    }
}

/// The extreme drawn at random.
fn random_extreme(rng: &mut impl Rng) -> Operator {
    if rng.random_bool(0.5) {
        Operator::Fastest
    } else {
        Operator::Slowest
    }
}

/// An adversary's memory between ticks (holds, per-robot choices).
pub(crate) struct PolicyState {
    /// Ticks left in the current hold.
    hold: u32,
    /// The input being held.
    current: Operator,
    /// [`Adversary::RandomPerRobot`]: each robot's extreme.
    per_robot: [Operator; MAX_ROBOTS],
    /// The low-confidence robot at the previous tick.
    last_lc: Option<usize>,
    /// Number of robots.
    n_robots: usize,
    /// [`Adversary::SwitchFavourite`]: the favoured robot.
    favourite: usize,
}

impl PolicyState {
    pub(crate) fn new(n_robots: usize) -> Self {
        let mut per_robot = [Operator::Slowest; MAX_ROBOTS];
        per_robot[0] = Operator::Fastest;
        PolicyState {
            hold: 0,
            current: Operator::Fastest,
            per_robot,
            last_lc: None,
            n_robots,
            favourite: 0,
        }
    }

    /// The input of tick `k` given the low-confidence robot at its start, `lc`.
    pub(crate) fn next(
        &mut self,
        adversary: Adversary,
        k: u64,
        lc: Option<usize>,
        rng: &mut impl Rng,
    ) -> Operator {
        let extreme = |fast: bool| {
            if fast {
                Operator::Fastest
            } else {
                Operator::Slowest
            }
        };
        let op = match adversary {
            Adversary::Nominal => Operator::Scheduled,
            Adversary::Fastest => Operator::Fastest,
            Adversary::Slowest => Operator::Slowest,
            Adversary::Periodic { period, phase } => {
                extreme(((k + u64::from(phase)) / u64::from(period.max(1))) % 2 == 0)
            }
            Adversary::SwitchOnce { at, rev } => extreme((k < at) != rev),
            Adversary::RandomSwitching { max_hold } => {
                if self.hold == 0 {
                    self.current = if self.current == Operator::Fastest {
                        Operator::Slowest
                    } else {
                        Operator::Fastest
                    };
                    self.hold = rng.random_range(1..=max_hold.max(1));
                }
                self.hold -= 1;
                self.current
            }
            Adversary::RandomExtreme => random_extreme(rng),
            Adversary::Random { lo, hi } => Operator::Gradient(uniform(rng, lo, hi)),
            Adversary::RandomHeld { lo, hi, max_hold } => {
                if self.hold == 0 {
                    self.current = Operator::Gradient(uniform(rng, lo, hi));
                    self.hold = rng.random_range(1..=max_hold.max(1));
                }
                self.hold -= 1;
                self.current
            }
            Adversary::RushRobot { rush } => extreme(lc == Some(rush)),
            Adversary::SwitchFavourite { max_hold } => {
                if self.hold == 0 {
                    self.favourite = rng.random_range(0..self.n_robots.max(1));
                    self.hold = rng.random_range(1..=max_hold.max(1));
                }
                self.hold -= 1;
                extreme(lc == Some(self.favourite))
            }
            // The search does not run through a policy (see `run_adversary`).
            Adversary::Beam { .. } => Operator::Scheduled,
            Adversary::RandomPerRobot => {
                if lc != self.last_lc
                    && let Some(i) = lc
                {
                    self.per_robot[i] = random_extreme(rng);
                }
                lc.map_or(Operator::Scheduled, |i| self.per_robot[i])
            }
        };
        self.last_lc = lc;
        op
    }
}

/// Runs `controller` until every robot has done its task — rounds: to the end; the continuous
/// cell: until every robot has completed one task — or for at most `max_ticks` ticks, with the
/// operator inputs of `adversary`, drawing from `rng` (deterministic for its state):
/// [`run_adversary_on`] with one task. [`Adversary::Beam`] runs the search instead where the
/// controller has one ([`Controller::beam_search`]: rounds) and reports its worst sequence.
///
/// # Errors
/// [`crate::Error::BadOperator`] when the adversary produces an inadmissible gradient (a
/// [`Adversary::Random`] range reaching 0 or beyond).
pub fn run_adversary<C: Controller>(
    mut controller: C,
    adversary: Adversary,
    rng: &mut impl Rng,
    max_ticks: u64,
) -> Result<AdversaryRun> {
    if let Adversary::Beam { width } = adversary
        && let Some(run) = controller.beam_search(width, max_ticks)
    {
        return run;
    }
    run_adversary_on(&mut controller, adversary, rng, 1, max_ticks)
}

/// THE adversary driver of every controller: runs `controller` from its current state until it
/// has finished ([`Controller::is_finished`]) or every robot has completed `min_tasks` tasks
/// ([`Controller::tasks_now`]), or for at most `max_ticks` ticks, with the operator inputs of
/// the policy `adversary` (given the robot low-confidence at each tick start,
/// [`Controller::low_conf_now`]), drawing from `rng`. The beam search [`Adversary::Beam`] is
/// not a policy and runs here as [`Adversary::SwitchFavourite`] with holds up to 50 ticks
/// ([`run_adversary`] runs the search itself where there is one). A [`Fault`](crate::Fault)
/// the controller latches is counted and cleared at once, so that the run goes on; a backward
/// step is counted ([`Backward`]). Allocates nothing; O(N) per tick (the cell's reference
/// times O(N log T_ref)).
///
/// # Errors
/// [`crate::Error::BadOperator`] when the adversary produces an inadmissible gradient.
pub fn run_adversary_on<C: Controller + ?Sized>(
    controller: &mut C,
    adversary: Adversary,
    rng: &mut impl Rng,
    min_tasks: u64,
    max_ticks: u64,
) -> Result<AdversaryRun> {
    let mut run = AdversaryRun::default();
    let mut state = PolicyState::new(controller.n_robots());
    let mut backward = Backward::new(controller);
    let mut gaps = SwitchGaps::default();
    let fewest = |c: &C| c.tasks_now().iter().copied().min().unwrap_or(0);
    // The beam search is not a policy: a switching favourite with holds up to 50 ticks.
    let policy = match adversary {
        Adversary::Beam { .. } => Adversary::SwitchFavourite { max_hold: 50 },
        other => other,
    };
    while !(controller.is_finished() || fewest(controller) >= min_tasks) {
        if run.ticks >= max_ticks {
            run.min_tasks = fewest(controller);
            run.min_switch_gap_ticks = gaps.min_gap_ticks();
            return Ok(run);
        }
        let lc = controller.low_conf_now().first();
        let op = state.next(policy, run.ticks, lc, rng);
        let tick = controller.tick(op)?;
        run.backward_steps += u64::from(backward.step(controller, &tick));
        gaps.record(run.ticks, &tick.low_conf);
        if tick.overlap() {
            run.first_overlap.get_or_insert(run.ticks);
            run.overlap_ticks += 1;
        }
        // A measurement runs to the end: the fault a run-time monitor latches (and the robot it
        // holds) is recorded above and released.
        if tick.fault.is_some() {
            controller.clear_fault();
        }
        run.ticks += 1;
    }
    run.min_tasks = fewest(controller);
    run.finished = true;
    run.min_switch_gap_ticks = gaps.min_gap_ticks();
    Ok(run)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Timeline;
    use rand::SeedableRng;

    /// [LC, HC, HC] for both robots, Δt_s = 1, started together: an unsafe schedule.
    fn robots() -> [Timeline; 2] {
        let (g, lo, hi) = ([1.0; 3], [0.5; 3], [2.0; 3]);
        let conf = [false, true, true];
        [
            Timeline::new(&conf, &g, &lo, &hi, 0.0, 1.0).unwrap(),
            Timeline::new(&conf, &g, &lo, &hi, 0.0, 1.0).unwrap(),
        ]
    }

    #[test]
    fn policies_by_hand() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
        let mut st = PolicyState::new(2);
        let seq = |st: &mut PolicyState, a, rng: &mut rand_chacha::ChaCha8Rng| {
            (0..6).map(|k| st.next(a, k, None, rng)).collect::<Vec<_>>()
        };
        use Operator::{Fastest as F, Slowest as S};
        let periodic = Adversary::Periodic {
            period: 2,
            phase: 1,
        };
        assert_eq!(seq(&mut st, periodic, &mut rng), [F, S, S, F, F, S]);
        let once = Adversary::SwitchOnce { at: 2, rev: true };
        assert_eq!(seq(&mut st, once, &mut rng), [S, S, F, F, F, F]);
        // Rushing robot 1 when it is LC, dragging robot 0 when it is.
        let rush = Adversary::RushRobot { rush: 1 };
        assert_eq!(st.next(rush, 0, Some(1), &mut rng), F);
        assert_eq!(st.next(rush, 1, Some(0), &mut rng), S);
        // Per robot: the extreme is drawn when the LC robot changes and held while it stays.
        let mut st = PolicyState::new(2);
        let a = st.next(Adversary::RandomPerRobot, 0, Some(0), &mut rng);
        assert!((1..20).all(|k| st.next(Adversary::RandomPerRobot, k, Some(0), &mut rng) == a));
        assert_eq!(
            st.next(Adversary::RandomPerRobot, 20, None, &mut rng),
            Operator::Scheduled
        );
    }

    #[test]
    fn a_bad_random_range_is_an_error_and_the_set_is_complete() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let c = crate::Coordinator::new_unchecked(robots(), 1.0).unwrap();
        let bad = Adversary::Random { lo: -1.0, hi: -0.5 };
        assert!(matches!(
            run_adversary(c, bad, &mut rng, 100),
            Err(crate::Error::BadOperator { .. })
        ));
        let set = adversary_set(2, [0.5, 2.0], 10, &mut rng);
        assert_eq!(set.len(), set_size(2));
        for want in [
            Adversary::Nominal,
            Adversary::RushRobot { rush: 0 },
            Adversary::RushRobot { rush: 1 },
            Adversary::RandomPerRobot,
            Adversary::SwitchFavourite { max_hold: 50 },
        ] {
            assert!(set.contains(&want), "{want:?}");
        }
        // Both robots are LC together from the start: every policy sees the overlap.
        for a in set {
            let c = crate::Coordinator::new_unchecked(robots(), 1.0).unwrap();
            let run = run_adversary(c, a, &mut rng, 100).unwrap();
            assert!(run.finished && run.first_overlap.is_some(), "{a:?}");
        }
    }

    #[test]
    fn one_driver_runs_both_controllers() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2);
        let (g, lo, hi) = ([1.0; 3], [0.5; 3], [2.0; 3]);
        let task = Timeline::new(&[true, false, true], &g, &lo, &hi, 0.0, 1.0).unwrap();
        let cell = crate::ContinuousCoordinator::new(task, &[], &[(0, 0), (1, 0)], 2, 1.0).unwrap();
        // One task each (a robot completes at most one task per tick: exactly one at the end).
        let run = run_adversary(cell.clone(), Adversary::Slowest, &mut rng, 1000).unwrap();
        assert!(run.finished && run.min_tasks == 1, "{run:?}");
        assert_eq!(
            (run.overlap_ticks, run.backward_steps, run.first_overlap),
            (0, 0, None)
        );
        // Five tasks, through a trait object.
        let mut boxed: Box<dyn Controller> = Box::new(cell);
        let run = run_adversary_on(&mut *boxed, Adversary::RandomExtreme, &mut rng, 5, 1000);
        let run = run.unwrap();
        assert!(
            run.finished && run.min_tasks == 5 && run.overlap_ticks == 0,
            "{run:?}"
        );
        assert_eq!(boxed.tasks_now().iter().min(), Some(&5));
        // A tick budget too small: not finished, the tasks done so far.
        boxed.reset();
        let run = run_adversary_on(&mut *boxed, Adversary::Fastest, &mut rng, 5, 3).unwrap();
        assert_eq!((run.finished, run.ticks, run.min_tasks), (false, 3, 0));
        // Rounds run to the end: every robot's one task (the unsafe plan overlaps, the fault is
        // counted and cleared).
        let c = crate::Coordinator::new_unchecked(robots(), 1.0).unwrap();
        let run = run_adversary(c, Adversary::Slowest, &mut rng, 100).unwrap();
        assert!(
            run.finished && run.min_tasks == 1 && run.overlap_ticks > 0,
            "{run:?}"
        );
    }

    #[test]
    fn the_favoured_robot_switches_and_is_the_one_rushed() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut st = PolicyState::new(4);
        let a = Adversary::SwitchFavourite { max_hold: 5 };
        let mut favourites = Vec::new();
        for k in 0..400 {
            let lc = Some((k % 4) as usize);
            let op = st.next(a, k, lc, &mut rng);
            // Rushed exactly when the low-confidence robot is the favoured one.
            assert_eq!(op == Operator::Fastest, lc == Some(st.favourite));
            favourites.push(st.favourite);
        }
        // Every robot is favoured at some time, and the favourite changes often.
        assert!((0..4).all(|i| favourites.contains(&i)));
        let changes = favourites.windows(2).filter(|w| w[0] != w[1]).count();
        assert!(changes > 50, "{changes}");
        assert_eq!(st.next(a, 400, None, &mut rng), Operator::Slowest);
    }
}
