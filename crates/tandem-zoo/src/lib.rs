//! The task zoo: deterministic generators of demonstrations for many kinds of task, each with
//! the ground truth of where, and how much, the operator is needed (issue 38, Deliver 1).
//!
//! The sanding fixture (`tandem_sim::task`) is one task; the defaults, the scheduler and the
//! tests must hold on the tasks users bring. Each [`Family`] here models one kind of task from
//! its own physics and practice, and generates for a seed what a user's recorder would write:
//! 3–12 demonstrations as CSV files (a `t` column with time-stamp jitter, then the channels),
//! at 50 Hz – 1 kHz, of lengths within ±20 % of each other, with speed profiles that differ
//! segment by segment, pauses of independent length and sensor noise. With them comes the
//! truth ([`ZooTask`]): each row's true task progress (so the true warp between any two
//! demonstrations), the spans of progress where the operator is needed with their
//! probability ([`NeedSpan`]), which spans vary between demonstrations, and the hold rules a
//! user would declare.
//!
//! ```
//! let family = tandem_zoo::family("dispensing")?;
//! let task = (family.generate)(tandem_zoo::HELD_OUT_SEEDS.start)?;
//! let demos = task.demos()?; // parsed exactly as `tandem fit` parses the files
//! assert_eq!(demos.len(), task.progress.len());
//! assert!(task.true_high_share(0) > 0.0 && task.true_high_share(0) < 1.0);
//! # Ok::<(), tandem_zoo::Error>(())
//! ```
//!
//! # Ground truth
//!
//! Every demonstration of a seed follows one underlying mean path through the task's
//! segments; they differ by (a) speed — each segment's duration drawn independently per
//! demonstration (`±8 %` for motions, `±40–60 %` for pauses and dwells), a monotone speed
//! wobble inside each segment, and a total length within `±(5–8.5) %` of nominal; (b) sensor
//! noise — white noise and a smooth tremor, about 0.5 % of each channel's range; and (c)
//! *variable sections* — per-demonstration offsets or waves in some channels over a span of
//! progress (a part placed elsewhere, a cable lying differently), and local events that
//! differ (a torque spike's height and moment, a search spiral's phase and radius). The
//! operator is needed exactly where (c) happens: [`ZooTask::variable`] lists those spans and
//! each lies inside a learnable [`NeedSpan`], with `p` graded from 0.2 to 1. Where every
//! demonstration agrees but the operator is still needed (a fragile feature, a cross-thread
//! risk), the span is marked `learnable: false`: no fit can see it, only corrections can.
//! Speed differences, pauses and noise never need the operator: a model that marks them
//! low-confidence is conservative, not wrong, and the zoo measures the cost.
//!
//! Deterministic: a seed gives the same bytes on every run and machine (ChaCha8 seeded from
//! the seed and the family's name). Defaults may be chosen on [`SELECTION_SEEDS`] only;
//! [`HELD_OUT_SEEDS`] are never tuned on and report what a user would see.
//!
//! # The families
//!
//! | family | channels | rate | variable sections (need p) | holds |
//! |---|---|---|---|---|
//! | `dispensing` | `x,y,z,qx,qy,qz,qw,flow,valve` | 100/125/200 Hz | bead start (0.2–0.4); one of three beads (0.6–1) | `valve<0.5` |
//!
//! ## dispensing
//!
//! A glue bead along three edges of a part. The nozzle leaves home, purges at a purge
//! station (valve open, flow 2 ml/s, a dwell whose length differs by ±45 % between
//! demonstrations: the operator waits for a clean stream), moves to the part, starts the
//! bead (valve open, flow building to 1.2 ml/s), runs bead A along `+x`, slows through a
//! corner (flow eased to 0.8 ml/s, the nozzle tilting to the new direction), bead B along
//! `+y`, a second corner, bead C along `−x`, lifts off (valve closed), hovers for an
//! inspection (a dwell of ±40 %) and returns. 22.8 s nominal at 100, 125 or 200 Hz, 4–10
//! demonstrations. Channels: position (m), the nozzle's orientation (quaternion; tilted
//! 0.2 rad towards the travel), `flow` (ml/s, never negative), `valve` (0/1).
//! Need: the bead's start (how much glue the first touch needs differs from part to part:
//! flow ±0.6 ml/s, height ±2 mm; p 0.2–0.4) and one of the three beads, chosen by the seed,
//! where the seam lies where a hand-placed insert put it (±5 cm across the bead, ±4 mm in
//! height, flow ±0.4 ml/s; a constant offset or a wandering seam; p 0.6–1). Holds:
//! `valve<0.5` — with the valve closed the nozzle can wait anywhere without a blob.

mod engine;
mod error;
pub mod eval;
mod families;
mod task;

pub use error::{Error, Result};
pub use task::{NeedSpan, ZooTask};

/// One family: a deterministic generator of demonstrations plus the truth of where and how
/// much the operator is needed.
#[derive(Clone, Copy, Debug)]
pub struct Family {
    /// Its name (`dispensing`, `peg_insertion`, …), as `cargo xtask zoo` and [`family`] take it.
    pub name: &'static str,
    /// One sentence: what the task is.
    pub summary: &'static str,
    /// The generator: the task for a seed; the same seed gives the same bytes.
    pub generate: fn(seed: u64) -> Result<ZooTask>,
}

/// Seeds the defaults may be chosen on.
pub const SELECTION_SEEDS: std::ops::Range<u64> = 0..8;

/// Held-out seeds: never tuned on; what the zoo reports as a user's experience.
pub const HELD_OUT_SEEDS: std::ops::Range<u64> = 1000..1008;

static FAMILIES: [Family; 1] = [Family {
    name: families::dispensing::NAME,
    summary: "a glue bead along three edges of a part, with a purge dwell, corners, and a seam that moves",
    generate: families::dispensing::generate,
}];

/// Every family, in a fixed order.
#[must_use]
pub fn families() -> &'static [Family] {
    &FAMILIES
}

/// The family named `name`.
///
/// # Errors
/// [`Error::UnknownFamily`] listing every family's name.
pub fn family(name: &str) -> Result<&'static Family> {
    FAMILIES
        .iter()
        .find(|f| f.name == name)
        .ok_or_else(|| Error::UnknownFamily {
            name: name.to_owned(),
            known: FAMILIES.iter().map(|f| f.name).collect(),
        })
}
