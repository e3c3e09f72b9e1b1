//! tandem: coordinated multi-robot shared autonomy (Hagenow et al., RA-L 2023).
//!
//! The facade of the workspace: one module per crate, each re-exporting that crate whole,
//! and the planner's types at the top level. It holds no logic of its own.
//!
//! | module | crate | paper |
//! |---|---|---|
//! | [`warp`] | `tandem-warp` | §II-B1, GDTW time warping (Eq. 2–3) |
//! | [`lfd`] | `tandem-lfd` | §II-B1/2, demonstrations, task model, corrections (Eq. 1, 4–7, 14, 21) |
//! | [`confidence`] | `tandem-confidence` | §II-B3, Beta prior and posterior, latched confidence (Eq. 8–12) |
//! | [`realtime`] | `tandem-realtime` | §II-B5, timing strategy, margin check, coordinator (Eq. 15–18, Alg. 1–2) |
//! | [`schedule`] | `tandem-schedule` | §II-B4/6, §II-C, execution warps, offset, anytime sampler (Eq. 13, 19–20) |
//! | [`planner`] | `tandem-planner` | Fig. 2, the loop and its state file |
//! | [`sim`] | `tandem-sim` | §III, sanding task, simulated workcell and operator, the study |
//! | [`bag`] | `tandem-bag` | ROS 2 bags: MCAP recordings as demonstrations and executions, runs as MCAP |
//!
//! The loop of Fig. 2: learn from demonstrations, run a round (one execution per robot)
//! under the schedule, record it, get the next schedule. A continuous cell, where each robot
//! starts its next task as soon as it is done, runs the cyclic plan of
//! [`schedule::cyclic`] through [`realtime::continuous`].
//!
//! ```
//! use rand::SeedableRng;
//! use tandem::lfd::Demonstration;
//! use tandem::schedule::SamplerParams;
//! use tandem::sim::workcell::{OperatorParams, run_round_with};
//! use tandem::{Planner, PlannerParams};
//!
//! // Three demonstrations of a one-channel task (force, N) at 10 ms. Over samples 10..20
//! // the experts pressed 2, 5 or 8 N: that is where the robots may need help.
//! let demo = |press: f64| {
//!     let force = (0..40).map(|n| if (10..20).contains(&n) { press } else { 1.0 }).collect();
//!     Demonstration::new(vec!["force".into()], force, 0.01)
//! };
//! let demos = [demo(2.0)?, demo(5.0)?, demo(8.0)?];
//! let sampler = SamplerParams { samples: 200, seed: 7, ..SamplerParams::default() };
//! let mut planner = Planner::new(&demos, PlannerParams { sampler, ..PlannerParams::default() })?;
//! let first_t_total_s = planner.outcome().t_total_s;
//!
//! // Run a round under the schedule in the simulated workcell (two robots, the default):
//! // robot 1's workpiece needs the operator over samples 10..20, robot 2's nowhere.
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
//! let needs = |robot: usize, n: usize| robot == 0 && (10..20).contains(&n);
//! let round = run_round_with(&planner, needs, &OperatorParams::default(), &mut rng)?;
//! assert!(!round.overlapped(), "never two low-confidence robots in one tick");
//!
//! // Record it (Eq. 21, Eq. 9–12) and get the next schedule (`record_round` takes one
//! // record per robot; `Planner::with_robots` makes a planner of N robots).
//! let report = planner.record_round(&round.records(planner.model())?)?;
//! assert_eq!(planner.rounds_recorded(), 1);
//! assert_eq!(report.t_total_s, planner.outcome().t_total_s);
//! // The new schedule satisfies every constraint of Eq. 20 on the updated problem.
//! tandem::schedule::validate(planner.problem(), planner.schedule())?;
//! assert!(planner.outcome().t_total_s <= first_t_total_s);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

/// GDTW time warping (paper §II-B1, Eq. 2–3): the crate `tandem-warp`.
pub mod warp {
    pub use tandem_warp::*;
}

/// Demonstrations, the task model and its corrections (paper §II-B1/2, Eq. 1, 4–7, 14, 21):
/// the crate `tandem-lfd`.
pub mod lfd {
    pub use tandem_lfd::*;
}

/// Beta prior and posterior per reference sample and the latched confidence (paper §II-B3,
/// Eq. 8–12): the crate `tandem-confidence`.
pub mod confidence {
    pub use tandem_confidence::*;
}

/// The real-time timing strategy, the worst-case margin check and the coordinator (paper
/// §II-B5, Eq. 15–18, Alg. 1–2): the crate `tandem-realtime`.
pub mod realtime {
    pub use tandem_realtime::*;
}

/// Execution warps, offset, global timeline, the constraints and the anytime sampler (paper
/// §II-B4/6, §II-C, Eq. 13, 19–20): the crate `tandem-schedule`.
pub mod schedule {
    pub use tandem_schedule::*;
}

/// The loop of Fig. 2 and its versioned state file: the crate `tandem-planner`.
pub mod planner {
    pub use tandem_planner::*;
}

/// The sanding task, the simulated workcell and operator, and the study of paper §III
/// (Fig. 5): the crate `tandem-sim`.
pub mod sim {
    pub use tandem_sim::*;
}

/// ROS 2 bags: rosbag2 MCAP recordings read as demonstrations and executions, simulated runs
/// written as MCAP for Foxglove: the crate `tandem-bag`.
pub mod bag {
    pub use tandem_bag::*;
}

pub use tandem_planner::{ExecutionRecord, Planner, PlannerParams, RecordReport, derive_seed};
