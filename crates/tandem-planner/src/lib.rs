//! The iterative loop of the paper's Fig. 2 (§II-C, Eq. 21).
//!
//! A [`Planner`] holds what the system has learned so far: the task model fitted on the
//! expert demonstrations (`tandem_lfd`, §II-B1/2), the operator's correction observations
//! and the latched confidence (`tandem_confidence`, Eq. 8–12), the scheduling problem and the
//! current schedule (`tandem_schedule`, §II-B4/6, §II-C). After every round (one execution of
//! each of the `N` robots, two in the paper), [`Planner::record_round`] adds the round's
//! executions to the model with their known
//! reference-time logs (Eq. 21), adds their supervised samples to the observations, updates
//! the confidence and re-schedules, warm-started by the previous schedule. The robots run the
//! schedule through [`Planner::coordinator`] (`tandem_realtime`, Eq. 17–18, Alg. 1/2), at the
//! control tick the schedule was checked with.
//!
//! The planner is saved as a versioned, checksummed, atomically written file ([`state`]):
//! a crash while saving never loses the recorded executions, and every writer holds the
//! file's advisory lock ([`state::StateLock`]) for its whole read–modify–write, so two
//! writers never lose each other's rounds. Executions are checked where they enter
//! ([`Planner::check_execution`]): resampled to the model's period, complete, of a plausible
//! duration; a round recorded twice is refused.
//!
//! ```
//! use tandem_lfd::{Demonstration, Execution};
//! use tandem_planner::{ExecutionRecord, Planner, PlannerParams};
//! use tandem_schedule::SamplerParams;
//!
//! // Three demonstrations of a one-channel task (force, N) at 10 ms: the experts agree
//! // except over samples 10..20, where they press 2, 5 or 8 N.
//! let demo = |press: f64| {
//!     let force = (0..40).map(|n| if (10..20).contains(&n) { press } else { 1.0 }).collect();
//!     Demonstration::new(vec!["force".into()], force, 0.01)
//! };
//! let demos = [demo(2.0)?, demo(5.0)?, demo(8.0)?];
//! let sampler = SamplerParams { samples: 200, seed: 7, ..SamplerParams::default() };
//! let mut planner = Planner::new(&demos, PlannerParams { sampler, ..PlannerParams::default() })?;
//! // Where the experts disagree the robots may need help: low confidence there (Eq. 10–12).
//! let low = planner.confidence().conf().iter().filter(|c| !**c).count();
//! assert!(low >= 10);
//!
//! // A round of two executions that replay the reference demonstration, supervised on the
//! // low-confidence samples, never corrected: the operator was not needed there.
//! let record = ExecutionRecord {
//!     execution: Execution {
//!         demonstration: demos[0].clone(),
//!         ref_time_log: (0..40).map(f64::from).collect(),
//!     },
//!     supervised: planner.confidence().conf().iter().map(|c| !c).collect(),
//!     corrected: vec![false; 40],
//! };
//! let report = planner.record_round(&[record.clone(), record])?;
//! assert_eq!(planner.rounds_recorded(), 1);
//! assert_eq!(planner.model().count(), 5, "three demonstrations and two executions (Eq. 21)");
//! assert_eq!(report.t_total_s, planner.outcome().t_total_s);
//! // The new schedule runs at the tick it was checked with.
//! assert_eq!(planner.coordinator()?.tick_s(), planner.schedule().tick_s);
//! # Ok::<(), tandem_planner::Error>(())
//! ```

mod cell;
mod error;
mod explain;
mod holds;
pub mod json;
mod mixed;
mod planner;
pub mod state;

pub use cell::{AnyController, Cell, FleetCell, FleetPick, Plan};
pub use error::{Error, Result};
pub use explain::{ChannelShare, LowCause, LowRegion};
pub use mixed::{
    CellPlanner, CellRecordReport, CellSchedule, CellTask, DEFAULT_TASK_NAME, TaskSpec,
};
pub use planner::{ExecutionRecord, Planner, PlannerParams, RecordReport, RefitReport};

/// A seed for item `index` of a seeded family (trial `k` of a study, the schedule after
/// `k` recorded rounds): SplitMix64 of both, so items are independent of each other and of
/// the order in which threads process them.
pub fn derive_seed(seed: u64, index: u64) -> u64 {
    splitmix64(seed ^ splitmix64(index.wrapping_add(1)))
}

/// Offset of the seed streams of a re-schedule asked for without a seed (see
/// [`reschedule_seed`]): past every stream `record_round` uses (one per recorded round).
const RESCHEDULE_STREAM: u64 = 1 << 32;

/// The seed of a re-schedule a user asks for without one (`tandem schedule` without
/// `--seed`, Python `Planner.reschedule()` without `seed`) after `rounds_recorded` rounds,
/// from the master seed `seed` (`[sampler] seed`): `derive_seed(seed, 2³² + rounds_recorded)`.
/// [`Planner::record_round`] used stream `rounds_recorded` for the saved schedule, so a
/// plain re-run draws new, still deterministic, candidates instead of repeating those; the
/// command line and Python share this one rule, so both return the same schedule.
pub fn reschedule_seed(seed: u64, rounds_recorded: usize) -> u64 {
    derive_seed(seed, RESCHEDULE_STREAM + rounds_recorded as u64)
}

/// One SplitMix64 output for state `x` (Steele, Lea & Flood 2014).
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
