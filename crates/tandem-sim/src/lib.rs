//! Simulation for the preliminary evaluation of Hagenow et al. (paper §III).
//!
//! The [`task`] module generates the experimental sanding task: four left-to-right sanding
//! passes over a plate, passes 1–3 painted in a random half of their sections and pass 4 fully
//! painted.
//! A simulated expert presses harder and moves slower over paint, and moves slowly along a
//! variable lift-off arc between passes.
//! Every demonstration comes with per-sample ground-truth labels (pass, section, painted, phase)
//! that the simulated study uses to decide whether a sample needs the operator's correction.
//!
//! The [`workcell`] runs a planner's schedule on its `N` robots through the real-time
//! coordinator while a simulated operator supervises the low-confidence robot
//! ([`workcell::run_round`]`(&planner, …)` reads model, problem, schedule and control tick from
//! the one `tandem_planner::Planner`), and turns the round into the planner's execution records
//! ([`workcell::RoundRun::records`]); [`workcell::CellSim`] runs a continuous cell.
//! A need profile ([`needs`]) says where a workpiece needs the operator, for any task: from
//! reference-time regions, per-sample levels or a need file.
//! The [`study`] is the paper's §III loop (Fig. 5): per trial, schedule, run a round, record
//! it, re-schedule, 150 times; trials in parallel, the same bytes for a seed on any number of
//! threads.
//!
//! All samples are 9-dimensional (see [`task::CHANNELS`]): tool position in metres and
//! orientation quaternion in the plate frame, normal force in newtons and tool on/off, sampled
//! every `Δt_s` seconds of *demo time* (default 0.01 s, i.e. 100 Hz).
//!
//! ```
//! use rand::SeedableRng;
//! use tandem_sim::task::{self, Phase, TaskParams, Workpiece};
//!
//! let params = TaskParams::default();
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
//! let workpiece = Workpiece::random(&params, &mut rng)?;
//! let demo = task::demonstrate(&params, &workpiece, &mut rng)?;
//!
//! // One label per sample; 40–90 s at 100 Hz.
//! assert_eq!(demo.samples.len(), demo.labels.len());
//! assert!((40.0..=90.0).contains(&demo.duration_s()));
//! // The expert presses hard over paint and lightly elsewhere.
//! let over_paint = demo.labels.iter().any(|l| l.phase == Phase::Sanding && l.painted);
//! assert!(over_paint);
//! // Share of samples that never need a correction (transitions and pass 4).
//! let share = task::ground_truth_share(&demo.labels);
//! assert!(share > 0.0 && share < 1.0);
//! # Ok::<(), tandem_sim::Error>(())
//! ```

mod error;
pub mod needs;
pub mod study;
pub mod task;
pub mod truth;
pub mod workcell;

pub use error::{Error, Result};
