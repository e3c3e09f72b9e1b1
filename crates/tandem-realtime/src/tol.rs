//! The tolerance policy: every floating-point comparison of schedule times and gradients that
//! is not exact uses one of these, and each says which way it errs.
//!
//! - **Gradients** ([`GRADIENT_REL`]): `ψ̇min ≤ ψ̇_E ≤ ψ̇max` (Eq. 20 constraint 1, and
//!   [`Timeline::new`](crate::Timeline::new)), "`ψ̇_E` is the mean" on low-confidence samples
//!   (constraint 4) and `τ ≤ |ψ_E1|` (constraint 2) are tested relative to the bound. They err
//!   on the permissive side, by at most `1e-9` of the bound: a mean computed in floating point
//!   can exceed the maximum of identical demonstrations by an ulp, and a schedule read back
//!   from text may differ in its last digit. The safety of such a schedule does not rest on
//!   these tests but on the margin check, which runs on the same numbers the coordinator runs.
//! - **Schedule clock** ([`clock_tolerance_s`]): where a comparison of schedule-clock times
//!   decides low-confidence membership, the tolerance is `CLOCK_REL = 1e-9` times the largest
//!   time involved (every robot's start and end, and the tick). It errs on the safe side: the
//!   [`Coordinator`](crate::Coordinator) widens every traversed interval by it (reporting
//!   *more* low-confidence ticks) and the margin check widens by four times it (rejecting
//!   *more* schedules).
//! - **Scheduled overlaps** ([`overlap_tolerance_s`]): constraint 3 ignores an overlap of two
//!   scheduled low-confidence intervals shorter than `CLOCK_REL·max(1 s, T_total)`. It errs on
//!   the permissive side (touching intervals computed in two summation orders pass); the
//!   margin check (constraint 5) is what keeps the robots apart at run time.
//! - **Ticks** ([`same_tick`]): a schedule checked at one control tick runs in a loop of
//!   another period only if the two agree to `CLOCK_REL` relative: permissive by a rounding
//!   error, never by a different tick.
//! - **Empty measure** ([`MEASURE_ZERO_REL`]): the sampler treats a set of admissible offsets
//!   shorter than `1e-12·max(1 s, |ψ_E1|)` as empty, erring on proposing no candidate.
//! - **Certificates** ([`BOUND_REL`]): a correct lower bound on `T_total` may exceed the
//!   `T_total` of a valid schedule by at most `2·GRADIENT_REL` relative (the gradient test's
//!   slack plus summing the two in different orders); the bound is reported as computed, and
//!   one above that is a bug, never a rounding.
//!
//! Everything else is compared exactly: the clock's breakpoints (one summation,
//! [`clock_s`](crate::clock_s)), the coordinator's cursors and modes, the sampler's
//! `T_total` ordering and choice (ties keep the earlier candidate or the incumbent).

use crate::Timeline;

/// Relative tolerance of the gradient bounds, the mean gradient and the offset bound
/// (dimensionless; see the [module docs](self)).
pub const GRADIENT_REL: f64 = 1e-9;

/// Relative tolerance of schedule-clock comparisons (dimensionless; see the
/// [module docs](self)).
pub const CLOCK_REL: f64 = 1e-9;

/// Relative size (dimensionless) below which a set of offsets counts as empty (see the
/// [module docs](self)).
pub const MEASURE_ZERO_REL: f64 = 1e-12;

/// Relative amount (dimensionless) by which a valid schedule's `T_total` may lie below a
/// correct lower bound on it: `2·GRADIENT_REL`. A schedule's gradients may lie up to
/// [`GRADIENT_REL`] outside their bounds and the mean (a schedule read back from text, the
/// previous one), which shortens `T_total` by at most that much; the other `GRADIENT_REL`
/// covers summing the bound and `T_total` in different orders. So a certificate's gap
/// `(T_total − bound)/bound` is never below `−BOUND_REL` (up to its own rounding), and a gap
/// of magnitude below it is zero (see the [module docs](self)).
pub const BOUND_REL: f64 = 2.0 * GRADIENT_REL;

/// `true` when `value` lies in `[lo, hi]` up to [`GRADIENT_REL`] of the bounds
/// (`lo·(1 − 1e-9) ≤ value ≤ hi·(1 + 1e-9)`, for positive bounds); `false` for NaN.
#[must_use]
pub fn within_bounds(value: f64, lo: f64, hi: f64) -> bool {
    value >= lo * (1.0 - GRADIENT_REL) && value <= hi * (1.0 + GRADIENT_REL)
}

/// `true` when `value` equals `target` up to [`GRADIENT_REL`] of `|target|`.
#[must_use]
pub fn close_to(value: f64, target: f64) -> bool {
    (value - target).abs() <= GRADIENT_REL * target.abs()
}

/// Absolute tolerance (schedule-clock s) used where floating-point comparisons decide
/// low-confidence membership: `CLOCK_REL × max(|τ_i|, |end_i|, tick_s)` over all robots
/// (`tick_s` in real seconds). Errs on the safe side (see the [module docs](self)).
#[must_use]
pub fn clock_tolerance_s(robots: &[Timeline], tick_s: f64) -> f64 {
    let scale = robots
        .iter()
        .flat_map(|r| [r.start_s().abs(), r.end_s().abs()])
        .fold(tick_s.abs(), f64::max);
    CLOCK_REL * scale
}

/// Shortest overlap (s) of two scheduled low-confidence intervals that constraint 3 counts,
/// for a schedule of `t_total_s` seconds: `CLOCK_REL·max(1 s, T_total)`.
#[must_use]
pub fn overlap_tolerance_s(t_total_s: f64) -> f64 {
    CLOCK_REL * t_total_s.max(1.0)
}

/// Whether two control ticks (real s) are the same tick up to rounding:
/// `|a − b| ≤ CLOCK_REL·max(|a|, |b|)`. `false` if either is NaN.
#[must_use]
pub fn same_tick(a_s: f64, b_s: f64) -> bool {
    (a_s - b_s).abs() <= CLOCK_REL * a_s.abs().max(b_s.abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_tolerance_by_hand() {
        assert!(within_bounds(2.0 * (1.0 + 1e-12), 1.0, 2.0));
        assert!(!within_bounds(2.0 * (1.0 + 1e-6), 1.0, 2.0));
        assert!(!within_bounds(f64::NAN, 1.0, 2.0));
        assert!(close_to(1.0 + 1e-12, 1.0) && !close_to(1.0 + 1e-6, 1.0));
        assert!(same_tick(0.01, 0.01 * (1.0 + 1e-12)));
        assert!(!same_tick(0.01, 0.005) && !same_tick(f64::NAN, 0.01));
        assert_eq!(overlap_tolerance_s(0.5), 1e-9);
        assert_eq!(overlap_tolerance_s(100.0), CLOCK_REL * 100.0);
    }
}
