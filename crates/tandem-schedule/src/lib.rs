//! Scheduling two robots around low confidence (paper §II-B4, §II-B6, §II-C).
//!
//! A [`Problem`] holds, per reference sample `n` (period `Δt_s`), whether the learned model is
//! high-confidence (Eq. 12) and the mean, minimum and maximum demonstration warp gradients
//! (Eq. 14). A [`Schedule`] gives each robot an execution warp (one gradient per reference
//! sample) and robot 2 a start offset `τ`. [`GlobalTimeline`] lays a schedule out in global
//! time (Eq. 15, 16, 19), [`Schedule::t_total_s`] is Eq. 13, [`validate`] checks every
//! constraint of Eq. 20 (the margin check of Alg. 2 through `tandem_realtime`), and
//! [`sample_schedule`] is the paper's anytime sampler — robot 1's speeds are sampled and `τ`
//! and robot 2's speeds fitted to them exactly (the measured alternatives are
//! [`SamplerBaselines`]) — parallel, and deterministic for a seed whatever the thread count.
//! A schedule carries the control tick it was checked at ([`Schedule::tick_s`]); the
//! runtime [`Schedule::coordinator`] runs at that tick.
//!
//! ```
//! use tandem_schedule::{Problem, SamplerParams, Source, sample_schedule, validate};
//!
//! // 30 reference samples at 10 ms: low confidence on samples 10..15, loose bounds elsewhere.
//! let conf: Vec<bool> = (0..30).map(|n| !(10..15).contains(&n)).collect();
//! let problem = Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01)?;
//! let params = SamplerParams { samples: 500, seed: 7, ..SamplerParams::default() };
//! let out = sample_schedule(&problem, &params, None)?;
//! assert!(validate(&problem, &out.schedule).is_ok());
//! // Serial: each robot takes 25·0.5 + 5·1 = 17.5 samples, 0.35 s in all; overlapping the
//! // robots does better.
//! assert!(out.t_total_s < problem.serial_schedule(0.01)?.t_total_s(0.01));
//! // The schedule was checked at the default control tick, Δt_s, and runs at it.
//! assert_eq!(out.schedule.tick_s, 0.01);
//! assert_eq!(out.schedule.coordinator(&problem)?.tick_s(), 0.01);
//! assert!(matches!(out.source, Source::Sampled { .. }));
//! # Ok::<(), tandem_schedule::Error>(())
//! ```

mod error;
pub mod exact;
mod problem;
mod sampler;
mod schedule;
mod validate;

pub use error::{Error, Result};
pub use exact::{
    Certificate, CertifiedSource, ExactParams, MarginFree, SearchStats, certify, earliest_schedule,
    solve_exact,
};
pub use problem::Problem;
pub use sampler::{
    DrawnOffset, Outcome, SamplerBaselines, SamplerParams, SamplerStats, Source, sample_schedule,
    sample_schedule_with_baselines,
};
pub use schedule::{GlobalTimeline, Schedule};
pub use tandem_confidence::Run;
pub use tandem_realtime::LcInterval;
pub use validate::{MarginCheck, Violation, validate};
