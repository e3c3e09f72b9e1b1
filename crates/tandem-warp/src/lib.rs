//! GDTW time warping (paper §II-B1, Eq. 2–3).
//!
//! Deriso & Boyd's generalized dynamic time warping, the "parametric optimizer \[5\]" the paper
//! uses to align every demonstration to the reference demonstration. A warp `φ` maps normalized
//! reference time `t ∈ [0, 1]` to normalized query time; it is piecewise linear on `N` time nodes,
//! each node taking one of `M` candidate values inside the band the slope bounds allow, and
//! dynamic programming minimizes
//!
//! `∫ (x₂(φ(t)) − x₁(t))ᵀ W (x₂(φ(t)) − x₁(t)) dt + λ_inst ∫ (φ'(t) − 1)² dt + λ_cum ∫ (φ(t) − t)² dt`
//!
//! subject to `s_min ≤ φ' ≤ s_max`, `φ(0) = 0`, `φ(1) = 1`; the candidate grid is then refined
//! around the solution ([`WarpParams`]). `x₁` is the reference, `x₂` the query, linearly
//! interpolated at fractional times, and `W` a diagonal weight matrix. Before they are compared,
//! both signals are smoothed over a few samples ([`WarpParams::smooth_width`], default 7;
//! 1 = none), which keeps sensor noise and vibration from steering the warp. Where neither
//! signal moves beyond its noise (a dwell), no channel identifies the warp and the slope
//! penalty alone would draw a straight line; there the warp is replaced by its smoothest
//! continuation from the warp around it ([`WarpParams::fill_length`], default 0.1; 0 = none).
//! The result is a [`Warp`] holding the query time (in query samples) at every reference
//! sample.
//!
//! ```
//! use tandem_warp::{align, SignalRef, WarpParams};
//! // One channel; the query is the reference played back 1.5× slower.
//! let reference: Vec<f64> = (0..200).map(|n| (n as f64 / 20.0).sin()).collect();
//! let query: Vec<f64> = (0..300).map(|n| (n as f64 / 30.0).sin()).collect();
//! let w = align(
//!     SignalRef::new(&reference, 1)?,
//!     SignalRef::new(&query, 1)?,
//!     &WarpParams::default(),
//! )?;
//! assert_eq!(w.values().len(), reference.len());
//! assert_eq!((w.values()[0], w.values()[199]), (0.0, 299.0));
//! assert!((w.eval(100.0) - 150.0).abs() < 1.5); // reference sample 100 ↔ query sample 150
//! # Ok::<(), tandem_warp::Error>(())
//! ```

mod error;
mod fill;
mod objective;
mod params;
mod signal;
mod smooth;
mod solver;
mod warp;

pub use error::{Error, Result};
pub use fill::{FLAT_HALF_WINDOW, FLAT_NOISE_MULTIPLE, FLAT_RANGE_FRACTION};
pub use objective::{effective_lambda_inst, objective_of};
pub use params::{DEFAULT_NODE_SPACING, NOISE_PENALTY, WarpParams};
pub use signal::{MAX_ABS_VALUE, SignalRef};
pub use smooth::{MAX_SMOOTH_WIDTH, smooth_sigma};
pub use solver::{
    COARSE_POINTS_PER_SEGMENT, COARSE_SLOPE_STEP, POLISH_RADIUS, POLISH_STEPS,
    REFINE_SPACING_RATIO, align, align_many,
};
pub use warp::Warp;
