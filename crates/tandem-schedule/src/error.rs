//! The crate's error type.

use crate::validate::Violation;

/// Everything that can go wrong when building a problem, laying out a schedule or sampling.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The problem has no reference sample.
    #[error("the problem has no reference sample")]
    Empty,
    /// A per-sample vector does not have `T_ref` entries.
    #[error("`{name}` has {len} entries, expected {expected} (one per reference sample)")]
    LengthMismatch {
        /// Which vector.
        name: &'static str,
        /// Its length.
        len: usize,
        /// `T_ref`.
        expected: usize,
    },
    /// A value is not finite (or a gradient not > 0).
    #[error("`{name}` is not finite (and > 0 for gradients) at reference sample {ref_idx}")]
    NonFinite {
        /// Which vector or value.
        name: &'static str,
        /// First offending reference sample (0 for scalars).
        ref_idx: usize,
    },
    /// The gradient bounds are not `0 < ψ̇min ≤ ψ̇̄ ≤ ψ̇max` at a reference sample.
    #[error(
        "reference sample {ref_idx}: need 0 < min ≤ mean ≤ max, got min {min}, mean {mean}, max {max}"
    )]
    BadBounds {
        /// Reference sample.
        ref_idx: usize,
        /// `ψ̇min`.
        min: f64,
        /// `ψ̇̄`.
        mean: f64,
        /// `ψ̇max`.
        max: f64,
    },
    /// A hold point is out of range or out of order ([`crate::Problem::with_holds`]).
    #[error("hold point at reference sample {ref_idx} {why}")]
    BadHold {
        /// The offending hold (reference sample).
        ref_idx: usize,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A parameter is out of range.
    #[error("parameter `{name}` {why}")]
    BadParam {
        /// Field name.
        name: &'static str,
        /// What is required.
        why: &'static str,
    },
    /// No schedule satisfies Eq. 20, not even the serial one.
    #[error("no feasible schedule: even the serial schedule fails: {serial}")]
    NoFeasibleSchedule {
        /// Why the serial schedule failed.
        serial: Violation,
    },
    /// No schedule the scheduler found keeps the operator's load cap
    /// ([`crate::SamplerParams::max_busy_share`]): none could be made long enough for its busy
    /// share ([`crate::busy_share`]) by slowing a robot's high-confidence tail.
    #[error(
        "no schedule keeps the operator's busy share at or below max_busy_share = {max_busy_share} (switch time {switch_s} s): no robot's high-confidence tail can be slowed enough; raise max_busy_share (to 1 for no cap) or lower switch_s"
    )]
    BusyShareUnreachable {
        /// The cap `u_max`.
        max_busy_share: f64,
        /// The switch time `δ` (s).
        switch_s: f64,
    },
    /// The schedule does not have `1 ≤ N ≤ MAX_ROBOTS` warps and `N − 1` start offsets
    /// ([`crate::Schedule::check_shape`]).
    #[error("schedule of the wrong shape: {0}")]
    Shape(Violation),
    /// One robot's plan cannot be laid out in schedule-clock time (Eq. 15–16): a warp of the
    /// wrong length, a non-finite value or a gradient outside its bounds.
    #[error("robot {}: {source}", .robot + 1)]
    Timeline {
        /// Robot index (0 = first robot).
        robot: usize,
        /// What the realtime crate rejected.
        source: tandem_realtime::Error,
    },
    /// The schedule breaks a constraint of Eq. 20 on its problem (the margin check of Alg. 2
    /// included), so it is not run ([`crate::Schedule::check`]).
    #[error("the schedule is not valid on its problem: {0}")]
    Invalid(Violation),
    /// A certificate's lower bound lies above the `T_total` of the valid schedule it certifies
    /// by more than the rounding `tandem_realtime::tol::BOUND_REL` allows: the bound is wrong
    /// (a bug in the exact search or the operator bound). Returned by the scheduler in debug
    /// builds only; release builds report the bound as computed, with its negative gap.
    #[error(
        "the lower bound {bound_s} s is above the T_total {t_total_s} s of a valid schedule (a wrong bound)"
    )]
    BoundAboveSchedule {
        /// The bound as computed (s).
        bound_s: f64,
        /// The schedule's `T_total` (s, Eq. 13).
        t_total_s: f64,
    },
    /// An arc of an event graph names a node that does not exist or has a non-finite weight
    /// ([`crate::max_cycle_ratio`]).
    #[error("arc {arc} {why}")]
    BadArc {
        /// Index of the arc.
        arc: usize,
        /// What is wrong with it.
        why: &'static str,
    },
    /// No cycle of the event graph carries tokens, so no period is bounded below
    /// ([`crate::max_cycle_ratio`]).
    #[error("no cycle of the event graph carries a token: the period is not bounded below")]
    NoTokenCycle,
    /// No period satisfies the event graph: a cycle with `Σh = 0` tokens and weight `Σw > 0`
    /// (e.g. contradictory exact durations), or with `Σh < 0` (maximum lags across period
    /// boundaries) whose bound lies below the least period ([`crate::max_cycle_ratio`]).
    #[error("no period is feasible: a cycle of {tokens} tokens and weight {weight_s} s ({arcs:?})")]
    InfeasibleCycle {
        /// The cycle's arcs (indices, in traversal order).
        arcs: Vec<usize>,
        /// Its weight `Σw` (s).
        weight_s: f64,
        /// Its tokens `Σh`.
        tokens: i64,
    },
    /// A cyclic plan's order cannot run on the continuous coordinator
    /// ([`crate::cyclic::is_runnable`]): another robot's stretch comes right before stretch
    /// `lc` of robot `robot`, at `position` of the order, and that robot has no usable hold
    /// between its stretches `lc − 1` and `lc` to wait for it. Plan with
    /// `CyclicParams::runnable_only` (the default).
    #[error(
        "the operator order is not runnable: at position {position}, robot {robot}'s stretch {lc} does not follow its stretch {} and there is no usable hold between them to wait at",
        lc - 1
    )]
    NotRunnable {
        /// Position in the order (0-based).
        position: usize,
        /// The robot (0-based).
        robot: usize,
        /// The stretch (index of the low-confidence run, ≥ 1).
        lc: usize,
    },
    /// The realtime crate (coordinator, margin check) rejected its input.
    #[error(transparent)]
    Realtime(#[from] tandem_realtime::Error),
}

/// Result alias of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
