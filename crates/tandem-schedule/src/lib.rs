//! Scheduling `N` robots (two in the paper) around low confidence (paper §II-B4, §II-B6, §II-C).
//!
//! A [`Problem`] holds, per reference sample `n` (period `Δt_s`), whether the learned model is
//! high-confidence (Eq. 12) and the mean, minimum and maximum demonstration warp gradients
//! (Eq. 14). A [`Schedule`] gives each robot an execution warp (one gradient per reference
//! sample) and robots 2..N start offsets `τ_i`. [`GlobalTimeline`] lays a schedule out in global
//! time (Eq. 15, 16, 19), [`Schedule::t_total_s`] is Eq. 13, [`validate`] checks every
//! constraint of Eq. 20 (the margin check of Alg. 2 through `tandem_realtime`), and
//! [`sample_schedule`] is the scheduler (for two robots; [`sample_schedule_n`] for `N`): the paper's anytime sampler — robot 1's speeds are
//! sampled and `τ` and robot 2's speeds fitted to them exactly (the measured alternatives are
//! [`SamplerBaselines`]) — and, beside it, the margin-aware completion of the exact
//! margin-free optimum ([`exact`]), the shorter of the two (or of the previous or serial
//! schedule) winning; parallel, and deterministic for a seed whatever the thread count. Every
//! [`Outcome`] is certified: it carries the margin-free lower bound `T*₀` ([`solve_exact`])
//! and the gap to it. A schedule carries the control tick it was checked at
//! ([`Schedule::tick_s`]); [`Schedule::check`] re-checks it on its problem and the
//! [`CheckedSchedule`] it returns is the only form the runtime coordinator is built from, at
//! that tick. For a continuous cell (robots repeating the task, no rounds), [`cyclic`] gives
//! the repeated plan of one operator order, its exact least period ([`max_cycle_ratio`]),
//! the order search ([`cyclic_plan`]) and the period's lower bound.
//!
//! ```
//! use tandem_schedule::{
//!     Problem, SamplerParams, Source, operator_bound_s, sample_schedule, sample_schedule_n, validate,
//! };
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
//! assert_eq!(out.schedule.check(&problem)?.coordinator()?.tick_s(), 0.01);
//! assert!(matches!(out.source, Source::Sampled { .. } | Source::Completed));
//! // The certificate: no schedule of Eq. 20 is shorter than the margin-free optimum T*₀.
//! assert!(out.bound_is_optimum && out.lower_bound_s <= out.t_total_s);
//! assert_eq!(out.gap, (out.t_total_s - out.lower_bound_s) / out.lower_bound_s);
//!
//! // Three robots, one operator: robot 1 sampled, robots 2 and 3 placed in turn, certified
//! // against the operator-limited bound: 3 × 0.05 s of low confidence after the fastest
//! // head (10 samples at 0.5: 0.05 s) and before the fastest tail (15 samples: 0.075 s).
//! let three = sample_schedule_n(&problem, 3, &params, None)?;
//! assert_eq!((three.schedule.n_robots(), three.schedule.offsets_s.len()), (3, 2));
//! assert!(validate(&problem, &three.schedule).is_ok());
//! assert!((operator_bound_s(&problem, 3)? - 0.275).abs() < 1e-12);
//! assert!(three.lower_bound_s <= three.t_total_s);
//! assert!(three.t_total_s <= problem.serial_schedule_n(3, 0.01)?.t_total_s(0.01));
//! # Ok::<(), tandem_schedule::Error>(())
//! ```

mod checked;
mod choose;
mod clearance;
pub mod cyclic;
mod error;
pub mod exact;
mod operator;
mod problem;
mod retime;
mod sampler;
mod schedule;
mod sectors;
mod stagger;
#[cfg(feature = "testkit")]
pub mod testkit;
mod validate;

pub use checked::CheckedSchedule;
pub use choose::{
    GapSplit, Outcome, PreviousFate, SerialForm, Source, sample_schedule, sample_schedule_n,
    sample_schedule_with_baselines,
};
pub use cyclic::{
    CheckedCyclicPlan, CycleRatio, CyclicParams, CyclicPlan, FleetCellChoice, SectoredPlan,
    Stretch, cyclic_plan, cyclic_plan_for_order, fleet_cell_choice, handover_bound_s,
    max_cycle_ratio, nominal_tasks_per_hour, period_lower_bound_s,
    period_lower_bound_with_switch_s, pooled_period_lower_bound_s, sectored_coordinator,
    sectored_plan,
};
pub use error::{Error, Result};
pub use exact::{
    ExactParams, MarginFree, SearchStats, SwitchCharged, drag_charged_bound, earliest_schedule,
    held_charged_bound, margin_free_bound, operator_bound_s, operator_bound_with_switch_s,
    solve_exact, solve_exact_with_switch, switch_charged_bound,
};
pub use operator::{busy_share, start_allowance_s};
pub use problem::Problem;
pub use sampler::{DrawnOffset, SamplerBaselines, SamplerParams, SamplerStats};
pub use schedule::{GlobalTimeline, LcOverlap, Schedule};
pub use sectors::{SectoredRounds, even_sector_sizes, fleet_operator_bound_s, sectored_rounds};
pub use tandem_confidence::Run;
pub use tandem_realtime::LcInterval;
pub use validate::{
    MarginCheck, Violation, validate, validate_with_operator, validate_with_switch,
};
