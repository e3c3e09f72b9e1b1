//! The constraints of Eq. 20, checked in the paper's order.

use crate::problem::Problem;
use crate::schedule::{GlobalTimeline, Schedule};

/// Relative tolerance for the equality and bound tests on gradients and the offset: values
/// that went through a text round trip or a different summation order still pass.
const REL_TOL: f64 = 1e-9;

/// The first constraint of Eq. 20 that a schedule breaks.
///
/// Robot indices: 0 = first robot (starts at 0), 1 = second robot (starts at `τ`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Violation {
    /// A warp does not have one gradient per reference sample.
    #[error(
        "robot {robot}: execution warp has {len} gradients, the problem has {expected} reference samples"
    )]
    Length {
        /// Robot index.
        robot: usize,
        /// Number of gradients in the schedule.
        len: usize,
        /// `T_ref`.
        expected: usize,
    },
    /// Constraint 1: `ψ̇min[n] ≤ ψ̇_Ei[n] ≤ ψ̇max[n]` (also raised for a non-finite gradient).
    #[error(
        "robot {robot}, reference sample {ref_idx}: gradient {value} outside [{min}, {max}] (Eq. 20, constraint 1)"
    )]
    GradientOutOfBounds {
        /// Robot index.
        robot: usize,
        /// Reference sample.
        ref_idx: usize,
        /// Scheduled gradient (execution samples per reference sample).
        value: f64,
        /// `ψ̇min[n]`.
        min: f64,
        /// `ψ̇max[n]`.
        max: f64,
    },
    /// Constraint 2: `0 ≤ τ ≤ |ψ_E1|` (also raised for a non-finite offset).
    #[error("offset τ = {offset_s} s outside [0, |ψ_E1| = {max_s} s] (Eq. 20, constraint 2)")]
    Offset {
        /// The schedule's `τ` (s).
        offset_s: f64,
        /// `|ψ_E1|` (s).
        max_s: f64,
    },
    /// Constraint 3: both robots are scheduled low-confidence at once (global time).
    #[error(
        "both robots low-confidence from global time {start_s} s to {end_s} s (reference samples {:?} of robot 1, {:?} of robot 2) (Eq. 20, constraint 3)",
        .ref_ranges[0], .ref_ranges[1]
    )]
    BothLowConfidence {
        /// Global time (s) at which the overlap starts.
        start_s: f64,
        /// Global time (s) at which the overlap ends.
        end_s: f64,
        /// The overlapping low-confidence runs, as reference sample ranges `(start, end)` of
        /// robot 1 and robot 2.
        ref_ranges: [(usize, usize); 2],
    },
    /// Constraint 4: a low-confidence sample does not follow the mean gradient.
    #[error(
        "robot {robot}, low-confidence reference sample {ref_idx}: gradient {value} is not the mean {mean} (Eq. 20, constraint 4)"
    )]
    NotMeanGradient {
        /// Robot index.
        robot: usize,
        /// Reference sample.
        ref_idx: usize,
        /// Scheduled gradient.
        value: f64,
        /// `ψ̇̄[n]`.
        mean: f64,
    },
    /// Constraint 5: `SUFFICIENT_MARGINS` (Alg. 2, the conservative single-pass check of
    /// `tandem_realtime::sufficient_margins`) rejects the schedule at this control tick.
    #[error(
        "insufficient margins between low-confidence regions at control tick {tick_s} s (Eq. 20, constraint 5)"
    )]
    InsufficientMargins {
        /// Control tick (s) the check ran with.
        tick_s: f64,
    },
    /// The control tick given to [`validate_with_tick`] is not finite and > 0 (not a fault of
    /// the schedule).
    #[error("control tick {tick_s} s must be finite and > 0")]
    InvalidTick {
        /// The tick (s).
        tick_s: f64,
    },
}

/// Checks every constraint of Eq. 20 with the control tick equal to the reference sample
/// period `Δt_s`; see [`validate_with_tick`].
///
/// # Errors
/// The first [`Violation`], in the order of [`validate_with_tick`].
pub fn validate(problem: &Problem, schedule: &Schedule) -> Result<(), Violation> {
    validate_with_tick(problem, schedule, problem.dt_s())
}

/// Checks every constraint of Eq. 20 and names the first one broken, in this order:
/// warp lengths, (1) gradient bounds (robot 1 then robot 2, in reference order), (2) offset
/// `0 ≤ τ ≤ |ψ_E1|`, (3) no global time with both robots low-confidence, (4) mean gradient on
/// low-confidence samples, (5) `tandem_realtime::sufficient_margins` at control tick `tick_s`
/// (s).
///
/// Gradient bounds, the mean and the offset bound are tested with a relative tolerance of
/// `1e-9`; overlaps shorter than `1e-9·max(1, T_total)` s are ignored.
///
/// # Errors
/// The first [`Violation`] found.
pub fn validate_with_tick(
    problem: &Problem,
    schedule: &Schedule,
    tick_s: f64,
) -> Result<(), Violation> {
    if !(tick_s.is_finite() && tick_s > 0.0) {
        return Err(Violation::InvalidTick { tick_s });
    }
    validate_cheap(problem, schedule)?;
    if !margins_ok(problem, schedule, tick_s, MarginCheck::SinglePass)? {
        return Err(Violation::InsufficientMargins { tick_s });
    }
    Ok(())
}

/// Which implementation of `SUFFICIENT_MARGINS` (Alg. 2) to run; both decide identically.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum MarginCheck {
    /// `tandem_realtime::sufficient_margins`: two worst-case simulations decide every pair.
    #[default]
    SinglePass,
    /// `tandem_realtime::sufficient_margins_per_pair`: one simulation per pair of consecutive
    /// low-confidence regions (the straightforward reading of Alg. 2; a speed baseline).
    PerPair,
}

/// Constraints 1–4 (everything but the margins).
pub(crate) fn validate_cheap(problem: &Problem, schedule: &Schedule) -> Result<(), Violation> {
    let n_ref = problem.n_ref();
    for (robot, grad) in schedule.grad_exec.iter().enumerate() {
        if grad.len() != n_ref {
            return Err(Violation::Length {
                robot,
                len: grad.len(),
                expected: n_ref,
            });
        }
    }
    let (gmin, gmax, gmean) = (problem.grad_min(), problem.grad_max(), problem.grad_mean());
    for (robot, grad) in schedule.grad_exec.iter().enumerate() {
        for (ref_idx, &value) in grad.iter().enumerate() {
            let (min, max) = (gmin[ref_idx], gmax[ref_idx]);
            if !(value >= min * (1.0 - REL_TOL) && value <= max * (1.0 + REL_TOL)) {
                return Err(Violation::GradientOutOfBounds {
                    robot,
                    ref_idx,
                    value,
                    min,
                    max,
                });
            }
        }
    }
    let max_s = crate::schedule::execution_s(&schedule.grad_exec[0], problem.dt_s());
    let offset_s = schedule.offset_s;
    if !(offset_s >= 0.0 && offset_s <= max_s * (1.0 + REL_TOL)) {
        return Err(Violation::Offset { offset_s, max_s });
    }
    let timeline = GlobalTimeline::new(problem, schedule)
        .expect("lengths, bounds (> 0, finite) and offset were checked just above");
    if let Some((a, b)) = timeline.first_lc_overlap() {
        return Err(Violation::BothLowConfidence {
            start_s: a.start_s.max(b.start_s),
            end_s: a.end_s.min(b.end_s),
            ref_ranges: [(a.ref_start, a.ref_end), (b.ref_start, b.ref_end)],
        });
    }
    for (robot, grad) in schedule.grad_exec.iter().enumerate() {
        for (ref_idx, &value) in grad.iter().enumerate() {
            let mean = gmean[ref_idx];
            if !problem.conf()[ref_idx] && (value - mean).abs() > REL_TOL * mean {
                return Err(Violation::NotMeanGradient {
                    robot,
                    ref_idx,
                    value,
                    mean,
                });
            }
        }
    }
    Ok(())
}

/// Constraint 5 for a schedule that passed [`validate_cheap`].
pub(crate) fn margins_ok(
    problem: &Problem,
    schedule: &Schedule,
    tick_s: f64,
    check: MarginCheck,
) -> Result<bool, Violation> {
    // A rejection by the realtime crate of a schedule that passed constraints 1–4 can only
    // concern the tick (validated by the callers) or a degenerate timeline: count it as
    // insufficient margins rather than accept a schedule the margin check did not pass.
    let Ok(robots) = schedule.timelines(problem) else {
        return Ok(false);
    };
    let decided = match check {
        MarginCheck::SinglePass => tandem_realtime::sufficient_margins(&robots, tick_s),
        MarginCheck::PerPair => tandem_realtime::sufficient_margins_per_pair(&robots, tick_s),
    };
    decided.map_err(|_| Violation::InvalidTick { tick_s })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [HC, LC, LC, HC], gradients 1 in [0.5, 2], dt = 0.5 s.
    fn problem() -> Problem {
        crate::problem::hllh(0.5)
    }

    fn ok_schedule() -> Schedule {
        problem().serial_schedule()
    }

    #[test]
    fn serial_schedule_is_valid() {
        assert_eq!(validate(&problem(), &ok_schedule()), Ok(()));
    }

    #[test]
    fn names_each_constraint() {
        let p = problem();
        let mut s = ok_schedule();
        s.grad_exec[1].push(1.0);
        assert_eq!(
            validate(&p, &s),
            Err(Violation::Length {
                robot: 1,
                len: 5,
                expected: 4
            })
        );

        let mut s = ok_schedule();
        s.grad_exec[1][3] = 2.5;
        assert!(matches!(
            validate(&p, &s),
            Err(Violation::GradientOutOfBounds {
                robot: 1,
                ref_idx: 3,
                ..
            })
        ));
        s.grad_exec[1][3] = f64::NAN;
        assert!(matches!(
            validate(&p, &s),
            Err(Violation::GradientOutOfBounds { robot: 1, .. })
        ));

        let mut s = ok_schedule();
        s.offset_s = -0.1;
        assert!(matches!(validate(&p, &s), Err(Violation::Offset { .. })));
        // |ψ_E1| = (0.5 + 1 + 1 + 0.5)·0.5 = 1.5 s.
        s.offset_s = 1.6;
        assert_eq!(
            validate(&p, &s),
            Err(Violation::Offset {
                offset_s: 1.6,
                max_s: 1.5
            })
        );

        // τ = 0: both robots reach the LC run at 0.25 s.
        let mut s = ok_schedule();
        s.offset_s = 0.0;
        let v = validate(&p, &s).unwrap_err();
        assert_eq!(
            v,
            Violation::BothLowConfidence {
                start_s: 0.25,
                end_s: 1.25,
                ref_ranges: [(1, 3), (1, 3)]
            }
        );
        assert!(v.to_string().contains("(1, 3) of robot 1"), "{v}");

        let mut s = ok_schedule();
        s.grad_exec[0][2] = 1.5;
        assert_eq!(
            validate(&p, &s),
            Err(Violation::NotMeanGradient {
                robot: 0,
                ref_idx: 2,
                value: 1.5,
                mean: 1.0
            })
        );
        assert_eq!(
            validate_with_tick(&p, &ok_schedule(), 0.0),
            Err(Violation::InvalidTick { tick_s: 0.0 })
        );
    }

    #[test]
    fn tolerates_rounding_only() {
        let p = problem();
        let mut s = ok_schedule();
        s.grad_exec[0][0] = 0.5 * (1.0 - 1e-12);
        s.offset_s *= 1.0 + 1e-12;
        assert_eq!(validate_cheap(&p, &s), Ok(()));
        s.grad_exec[0][0] = 0.5 * (1.0 - 1e-6);
        assert!(validate_cheap(&p, &s).is_err());
    }
}
