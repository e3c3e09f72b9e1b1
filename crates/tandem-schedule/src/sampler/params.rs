//! What a user tunes ([`SamplerParams`]), the benchmark-only alternatives to the sampler's
//! design ([`SamplerBaselines`], [`DrawnOffset`]) and the counts of a run ([`SamplerStats`]).

use serde::{Deserialize, Serialize};

use crate::exact::SearchStats;
use crate::validate::MarginCheck;
use crate::{Error, ExactParams, Result};

/// Parameters of [`crate::sample_schedule`] (the sampler and, in [`SamplerParams::exact`], the
/// exact search and completion it runs beside): what a user tunes. They are stored in the
/// planner's state file and printed by `tandem params`; the benchmark-only alternatives
/// measured in the sampler's module docs are [`SamplerBaselines`], which are never stored.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SamplerParams {
    /// Number of sampled candidates (§II-C: the paper uses 5000). ≥ 1. Default: 5000.
    pub samples: usize,
    /// Seed; candidate `k` uses ChaCha8 stream `k` of this seed. Default: 0.
    pub seed: u64,
    /// Control tick (real s) of the margin check (Alg. 2), stored in the returned schedule
    /// ([`Schedule::tick_s`](crate::Schedule::tick_s)) as the only period the coordinator may run it at. `None` = the
    /// reference period `Δt_s`. Must be finite and > 0. Default: `None`.
    pub tick_s: Option<f64>,
    /// Pieces per maximal high-confidence run, each with one speed factor (the run is cut
    /// into `pieces` stretches of nearly equal sample count; see the module docs). ≥ 1.
    /// Default: 1.
    pub pieces: usize,
    /// Probability that a factor is exactly 0 (the run at `ψ̇min`, fastest), in `[0, 1]`.
    /// Default: 0.5.
    pub p_fastest: f64,
    /// Largest relative widening `w` of robot 1's low-confidence intervals when robot 2 is
    /// fitted to robot 1: each interval `[a, b)` is widened to `[a − δ, b + δ)` with
    /// `δ = w·(b − a) + 2·tick_s`, `w` drawn uniformly in `[0, widen_max]` per candidate
    /// (room for the operator's drag and rush, which the margin check then verifies). Finite
    /// and ≥ 0. Default: 0.1.
    pub widen_max: f64,
    /// At most this many cheap-feasible candidates go through the full constraints: the
    /// best half of them in `(T_total, k)` order, the rest at geometrically spaced ranks
    /// down to the last; the first to pass wins, and if none does the incumbent stays. `None` = no
    /// limit. Once the confidence is fragmented into many short low-confidence runs, most
    /// candidates that beat a good incumbent fail the margin check, and checking them all
    /// costs up to ~0.5 s per re-schedule for nothing (see the module docs). ≥ 1.
    /// Default: `Some(64)`.
    pub max_margin_checks: Option<usize>,
    /// The exact margin-free search (the lower bound `T*₀` every returned schedule is
    /// certified against) and the margin-aware completion run beside the sampler as its
    /// second opinion. Default: `ExactParams::default()`.
    pub exact: ExactParams,
    /// The operator's switch time `δ` (real s, issue 41), finite and ≥ 0: every schedule this
    /// planner makes leaves at least `δ` between the end of one robot's low-confidence
    /// stretch and the start of *another* robot's, in the worst case (the margin check with
    /// `tandem_realtime::MarginParams::switch_s`), and a continuous cell's cyclic plan counts
    /// it per change of robot ([`crate::CyclicParams::switch_s`]). One source for rounds and
    /// the continuous cell. Stored in the state file by name (only when not 0). Default 0:
    /// today's schedules, the same float operations.
    pub switch_s: f64,
    /// The load cap `u_max` (issue 41), in `(0, 1]`: the operator's busy share (supervised
    /// time plus `switch_s` per change of robot, over a round's `T_total` or a continuous
    /// cell's period) must not exceed it ([`crate::CyclicParams::max_busy_share`]). Stored in
    /// the state file by name (only when not 1). Default 1: no cap.
    pub max_busy_share: f64,
    /// The number of operators `M` of the cell (issue 44), in `1..=tandem_realtime::MAX_ROBOTS`:
    /// at most `M` robots are low-confidence in any tick. A continuous cell runs its cyclic
    /// plan's token order with `M` tokens (`tandem_realtime::ContinuousCoordinator::with_operators`);
    /// the schedules themselves are the one-operator ones (a rounds schedule safe for one
    /// operator is safe for any `M`; rounds that use `M > 1` are not built yet). One source
    /// for the planner, the CLI and the study. Stored in the state file by name (only when not
    /// 1). Default 1: the paper's cell, bit for bit (and not serialized when 1, so every
    /// JSON and TOML written before the parameter existed is written unchanged).
    #[serde(skip_serializing_if = "is_one")]
    pub operators: usize,
}

/// Whether `m` is 1 (serde's `skip_serializing_if` of [`SamplerParams::operators`]).
#[expect(
    clippy::trivially_copy_pass_by_ref,
    reason = "serde's skip_serializing_if passes a reference"
)]
fn is_one(m: &usize) -> bool {
    *m == 1
}

impl Default for SamplerParams {
    fn default() -> Self {
        SamplerParams {
            samples: 5000,
            seed: 0,
            tick_s: None,
            pieces: 1,
            p_fastest: 0.5,
            widen_max: 0.1,
            max_margin_checks: Some(64),
            exact: ExactParams::default(),
            switch_s: 0.0,
            max_busy_share: 1.0,
            operators: 1,
        }
    }
}

impl SamplerParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field.
    pub fn validate(&self) -> Result<()> {
        self.exact.validate()?;
        if self.samples == 0 {
            return Err(Error::BadParam {
                name: "samples",
                why: "must be ≥ 1",
            });
        }
        if let Some(t) = self.tick_s
            && !(t.is_finite() && t > 0.0)
        {
            return Err(Error::BadParam {
                name: "tick_s",
                why: "must be finite and > 0",
            });
        }
        if self.pieces == 0 {
            return Err(Error::BadParam {
                name: "pieces",
                why: "must be ≥ 1",
            });
        }
        if self.max_margin_checks == Some(0) {
            return Err(Error::BadParam {
                name: "max_margin_checks",
                why: "must be ≥ 1 (or none for no limit)",
            });
        }
        if !(self.widen_max.is_finite() && self.widen_max >= 0.0) {
            return Err(Error::BadParam {
                name: "widen_max",
                why: "must be finite and ≥ 0",
            });
        }
        if !(0.0..=1.0).contains(&self.p_fastest) {
            return Err(Error::BadParam {
                name: "p_fastest",
                why: "must be in [0, 1]",
            });
        }
        if !(self.switch_s.is_finite() && self.switch_s >= 0.0) {
            return Err(Error::BadParam {
                name: "switch_s",
                why: "must be finite and ≥ 0 (seconds; 0: no switch time)",
            });
        }
        if !(self.max_busy_share > 0.0 && self.max_busy_share <= 1.0) {
            return Err(Error::BadParam {
                name: "max_busy_share",
                why: "must be in (0, 1] (1: no cap)",
            });
        }
        if !(1..=tandem_realtime::MAX_ROBOTS).contains(&self.operators) {
            return Err(Error::BadParam {
                name: "operators",
                why: "must be 1 to 16 (tandem_realtime::MAX_ROBOTS): the operators of the cell; 1: one operator",
            });
        }
        Ok(())
    }
}

/// Benchmark-only alternatives to the sampler's design, measured in the module docs' table
/// (`sampling_distributions` example) and in the `reschedule_5000` bench.
///
/// They are not part of [`SamplerParams`] and have no serde form: an experiment never
/// changes the user's state file or what `tandem params` prints. The default is the
/// sampler's own design with its second opinion (what [`crate::sample_schedule`] runs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SamplerBaselines {
    /// The sampler alone: no margin-aware completion beside it (the bound `T*₀` is still
    /// computed for the certificate). For measuring the sampler itself.
    pub sampler_only: bool,
    /// The margin-aware completion alone: no candidate is sampled (the fallbacks stay). For
    /// measuring the completion itself (the `certify` bench and example).
    pub completion_only: bool,
    /// One independent factor per high-confidence reference sample instead of per piece of
    /// a run (the literal reading of §II-C; [`SamplerParams::pieces`] is then ignored).
    pub per_sample: bool,
    /// Draw `τ` (and sample robot 2's factors like robot 1's) instead of fitting robot 2 to
    /// robot 1 (`None`, the default; [`SamplerParams::widen_max`] is then ignored).
    pub drawn_offset: Option<DrawnOffset>,
    /// Margin-check implementation. Default: [`MarginCheck::SinglePass`].
    pub margin_check: MarginCheck,
    /// `false` (default): margins only in `(T_total, k)` order until the first candidate
    /// passes. `true`: check every cheap-feasible candidate within the margin budget (the
    /// straightforward baseline; the same result, slower).
    pub exhaustive_margins: bool,
}

impl SamplerBaselines {
    /// The sampler alone, as designed ([`SamplerBaselines::sampler_only`]).
    pub const SAMPLER_ONLY: SamplerBaselines = SamplerBaselines {
        sampler_only: true,
        completion_only: false,
        per_sample: false,
        drawn_offset: None,
        margin_check: MarginCheck::SinglePass,
        exhaustive_margins: false,
    };

    /// The margin-aware completion alone ([`SamplerBaselines::completion_only`]).
    pub const COMPLETION_ONLY: SamplerBaselines = SamplerBaselines {
        sampler_only: false,
        completion_only: true,
        ..SamplerBaselines::SAMPLER_ONLY
    };
}

/// How a [`SamplerBaselines::drawn_offset`] candidate draws its offset `τ` from `v` uniform in
/// `[0, 1)`, given its two warps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DrawnOffset {
    /// Uniform in `[0, |ψ_E1|]`; candidates whose low-confidence intervals overlap are
    /// rejected (the literal reading of §II-C).
    Uniform,
    /// Uniform over the offsets in `[0, |ψ_E1|]` at which the two robots' low-confidence
    /// intervals do not overlap (computed exactly from the intervals): the distribution of
    /// `Uniform` conditioned on passing constraint 3.
    UniformFeasible,
}

/// How a candidate's high-confidence gradients are drawn (from params and baselines).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Distribution {
    /// One factor per high-confidence reference sample.
    PerSample,
    /// `pieces` factors per maximal high-confidence run.
    PerRun { pieces: usize },
}

/// How a candidate's offset (and robot 2) is chosen (from params and baselines).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum OffsetSampling {
    /// A drawn offset (a baseline).
    Drawn(DrawnOffset),
    /// Robot 2 fitted to robot 1 with widenings up to `widen_max`.
    Fitted { widen_max: f64 },
}

/// Counts of one scheduler run (identical for a seed whatever the thread count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SamplerStats {
    /// Candidates sampled.
    pub candidates: usize,
    /// Candidates that beat the incumbent's `T_total` with no low-confidence overlap.
    pub cheap_feasible: usize,
    /// Candidates whose full constraints (incl. margins) were decided in `(T_total, k)` order
    /// (the parallel loop may check up to a few more, whose results are discarded).
    pub margin_checks: usize,
    /// Margin checks (Alg. 2) the margin-aware completion ran ([`crate::ExactParams`]), and
    /// the full checks of the staggered candidate ([`crate::Source::Staggered`], `N ≥ 2`).
    pub completion_margin_checks: usize,
    /// Work counts of the exact search behind the bound.
    pub search: SearchStats,
}
