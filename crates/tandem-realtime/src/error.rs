//! Error type of the crate.

/// Everything that can go wrong when building timelines, checking margins or coordinating.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A timeline needs at least one reference sample.
    #[error("timeline is empty: at least one reference sample is required")]
    EmptyTimeline,
    /// Two per-sample slices of one timeline have different lengths.
    #[error("`{what}` has {found} samples, expected {expected} (length of `conf`)")]
    LengthMismatch {
        /// Name of the offending slice.
        what: &'static str,
        /// Expected length (T_ref, the length of `conf`).
        expected: usize,
        /// Length found.
        found: usize,
    },
    /// A value is NaN or infinite.
    #[error("`{what}` is not finite at reference sample {index}")]
    NonFinite {
        /// Name of the offending input.
        what: &'static str,
        /// Reference sample index (0 for scalars).
        index: usize,
    },
    /// Gradients at one reference sample violate `0 < ψ̇min ≤ ψ̇_E ≤ ψ̇max`.
    #[error("gradients at reference sample {index}: {why}")]
    BadGradient {
        /// Reference sample index.
        index: usize,
        /// What is wrong.
        why: &'static str,
    },
    /// The operator's gradient for a control tick is NaN, infinite or not positive (e.g. from
    /// a degenerate command); "no correction" is `Operator::Scheduled`.
    #[error(
        "operator gradient {gradient} must be finite and > 0 (no correction is `Operator::Scheduled`)"
    )]
    BadOperator {
        /// The gradient given (execution samples per reference sample).
        gradient: f64,
    },
    /// The number of robots is not in `1..=MAX_ROBOTS` ([`RobotCount::new`](crate::RobotCount::new),
    /// the one check of a robot count in the workspace).
    #[error("{n} robots: a cell has 1 to {max} robots")]
    RobotCount {
        /// The robot count given.
        n: usize,
        /// The largest count, [`MAX_ROBOTS`](crate::MAX_ROBOTS).
        max: usize,
    },
    /// The number of operators is not in `1..=MAX_ROBOTS`
    /// ([`OperatorCount::new`](crate::OperatorCount::new), issue 44).
    #[error("{m} operators: a cell has 1 to {max} operators (use 1 for one operator)")]
    OperatorCount {
        /// The operator count given.
        m: usize,
        /// The largest count, [`MAX_ROBOTS`](crate::MAX_ROBOTS).
        max: usize,
    },
    /// A tick was given another number of operator inputs than the controller has operators
    /// ([`Controller::tick_many`](crate::Controller::tick_many): one input per operator).
    #[error(
        "{got} operator inputs for a cell of {want} operators: pass one `Operator` per operator, in operator order"
    )]
    OperatorInputs {
        /// The number of inputs given.
        got: usize,
        /// The controller's operators `M`.
        want: usize,
    },
    /// The margin check rejects the robots' plans at this control tick: some admissible operator
    /// could make two robots low-confidence in one tick (build the coordinator from a schedule
    /// that passes the check, or with `Coordinator::new_unchecked` to study what it does).
    #[error(
        "the margin check rejects these plans at a tick of {tick_s} s: two robots could be low-confidence in one tick"
    )]
    Unsafe {
        /// The control tick checked (real s).
        tick_s: f64,
    },
    /// A hold of a robot's plan is out of range, out of order, next to a low-confidence sample,
    /// has a bad dwell or a release rule naming no valid robot or sample
    /// (`crate::holds::check_holds`).
    #[error("robot {}: hold at reference sample {ref_idx} {why}", robot + 1)]
    BadHold {
        /// The robot (0-based; shown 1-based).
        robot: usize,
        /// The hold's reference sample.
        ref_idx: usize,
        /// What is wrong.
        why: &'static str,
    },
    /// A hold given to a continuous cell (`crate::cell::groups`) is out of range, out of
    /// order, or inside or next to a low-confidence stretch: a robot cannot wait there.
    #[error("gate at reference sample {ref_idx} {why}")]
    BadGate {
        /// The hold's reference sample.
        ref_idx: usize,
        /// What is wrong.
        why: &'static str,
    },
    /// The operator's cyclic order of a continuous cell (`crate::cell::token_sequence`)
    /// is malformed or not runnable.
    #[error("operator order, position {position}: {why}")]
    BadOrder {
        /// Position in the order (0-based).
        position: usize,
        /// What is wrong.
        why: &'static str,
    },
    /// A continuous cell cannot be handed over to a new plan now
    /// (`crate::cell::ContinuousCoordinator::take_over`): a robot is inside, or past
    /// the gate of, a group of the new plan, or the two cells do not match.
    #[error("cannot hand the cell over to the new plan now: robot {}: {why}", robot + 1)]
    HandOver {
        /// The robot (0-based; shown 1-based).
        robot: usize,
        /// What is wrong.
        why: &'static str,
    },
    /// A scalar parameter is out of its valid range.
    #[error("parameter `{name}` {why}")]
    BadParam {
        /// Parameter name.
        name: &'static str,
        /// What is wrong.
        why: &'static str,
    },
}

/// Result alias of the crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
