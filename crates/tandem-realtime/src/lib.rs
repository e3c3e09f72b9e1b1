//! Real-time timing strategy, worst-case margins and runtime coordinator (paper §II-B5,
//! Eq. 15–18, Alg. 1 and Alg. 2), for one operator and `1 ≤ N ≤` [`MAX_ROBOTS`] robots; the
//! readings and fixes of the paper behind it are in docs/decisions.md: "Typos of Eq. 17 and
//! Alg. 1", "Alg. 2 as printed is not sound on a tick grid", "Time frames").
//!
//! The robots do the same task in parallel under one operator. Each robot's plan is a
//! [`Timeline`] in *schedule-clock* time (global seconds at which the schedule planned a
//! reference position, Eq. 15–16). At run time the operator's corrections speed up or slow down
//! the low-confidence robot; the [`Coordinator`] lets every other robot respond (Eq. 18, and
//! Alg. 1 when none is low-confidence) so that the schedule clocks stay close; for two robots
//! these are the paper's rules exactly (docs/decisions.md, "N robots at run time").
//! [`sufficient_margins`] checks, before execution, that no admissible operator can make two
//! robots low-confidence in the same control tick — a conservative, discretization-safe
//! version of Alg. 2 extended to N robots (see [`margins`]).
//!
//! Time frames: reference sample index `n` (period `Δt_s`), schedule-clock/global time in
//! seconds, control tick `tick_s` in real seconds.
//!
//! One run-time contract: the rounds [`Coordinator`] and the
//! continuous cell's [`ContinuousCoordinator`] ([`cell`]) both implement [`Controller`] — one
//! [`Operator`] input and one [`Tick`] out per control tick, one fault monitor ([`Fault`]),
//! each robot's reference time, tasks and state — and [`adversary::run_adversary`] drives
//! either (docs/decisions.md, "One run-time contract").
//!
//! One owner per concept: [`clock_s`] is the only summation of the schedule clock (every
//! timeline, duration and `T_total` reads it); [`LcInterval`] is the one low-confidence
//! interval type; [`tol`] holds every tolerance and says which way each errs; the operator's
//! input to a tick is an explicit [`Operator`]; [`adversary`] is the one set of operator
//! policies the safety checks run.
//!
//! ```
//! use tandem_realtime::{Coordinator, Operator, Timeline, sufficient_margins};
//!
//! // 6 reference samples of 0.1 s; samples 1 and 2 are low confidence (false).
//! let conf = [true, false, false, true, true, true];
//! let mean = [1.0; 6];
//! let (lo, hi) = ([0.8; 6], [1.25; 6]);
//! let dt_s = 0.1;
//! // Robot 1 starts at 0; robot 2 starts τ = 0.45 s later on the same plan.
//! let r1 = Timeline::new(&conf, &mean, &lo, &hi, 0.0, dt_s)?;
//! let r2 = Timeline::new(&conf, &mean, &lo, &hi, 0.45, dt_s)?;
//! assert_eq!(r1.end_s(), 0.6);
//! let robots = [r1, r2];
//! let tick_s = 0.05;
//! assert!(sufficient_margins(&robots, tick_s)?);
//! // Too small an offset is rejected.
//! let r2_early = Timeline::new(&conf, &mean, &lo, &hi, 0.2, dt_s)?;
//! assert!(!sufficient_margins(&[robots[0].clone(), r2_early], tick_s)?);
//!
//! // A third robot 0.45 s after the second: three robots, one operator.
//! let r3 = Timeline::new(&conf, &mean, &lo, &hi, 0.9, dt_s)?;
//! let robots = [robots[0].clone(), robots[1].clone(), r3];
//! assert!(sufficient_margins(&robots, tick_s)?);
//!
//! // Run with an operator who slows the low-confidence robot down as much as allowed.
//! let mut coord = Coordinator::new(robots, tick_s)?;
//! while !coord.is_finished() {
//!     let tick = coord.tick(Operator::Slowest)?;
//!     assert!(!tick.overlap()); // never two robots low-confidence in one tick
//! }
//! # Ok::<(), tandem_realtime::Error>(())
//! ```

pub mod adversary;
pub mod cell;
/// The continuous cell's former path: every public item of [`cell`], for the code that names it.
pub mod continuous {
    #[allow(deprecated)]
    pub use crate::cell::*;
}
mod contract;
mod cursor;
mod error;
pub mod holds;
pub mod margins;
mod monitor;
pub mod prealert;
mod robots;
mod rounds;
pub mod strategy;
#[cfg(feature = "testkit")]
pub mod testkit;
mod timeline;
pub mod tol;

#[allow(deprecated)]
pub use cell::CellTick;
pub use cell::ContinuousCoordinator;
pub use contract::{Controller, Operator, Tick};
pub use error::{Error, Result};
pub use holds::{After, Hold};
pub use margins::{
    MarginParams, PairSlack, check_margins, margin_slacks, pair_slacks, pair_slacks_with_holds,
    sufficient_margins, sufficient_margins_per_pair, sufficient_margins_with_holds, switch_ticks,
};
pub use monitor::Fault;
pub use prealert::PreAlert;
pub use robots::{MAX_ROBOTS, OperatorCount, PerRobot, RobotCount, RobotFlags};
pub use rounds::Coordinator;
pub use strategy::{high_conf_steps, response_step};
pub use timeline::{LcInterval, Rates, Timeline, clock_end_s, clock_s};
