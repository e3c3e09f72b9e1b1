//! Choosing the schedule: the one place that decides which schedule a re-schedule returns, and
//! the certificate that comes with it.
//!
//! [`sample_schedule`] runs, for one problem and control tick:
//! 1. **the incumbent**: the previous schedule if it is still valid at the tick, else its
//!    repair (gradients clamped into the new bounds, the new mean on low-confidence samples,
//!    `τ` clamped into `[0, |ψ_E1|]`) if that is valid, else nothing; the fastest serial
//!    schedule ([`Problem::serial_schedule`]) replaces it if it is faster or there is none;
//! 2. in parallel (rayon, deterministic whatever the thread count), **the sampler** of §II-C
//!    (`crate::sampler`, its candidates cut at the incumbent's `T_total`) and **the exact
//!    search with the margin-aware completion** (`crate::exact`): the margin-free optimum
//!    `T*₀` (a lower bound on every schedule of Eq. 20) and a schedule built from it that
//!    passes the margin check;
//!    The completion starts both cold and warm from the incumbent (when that is not the
//!    serial schedule, which keeps no pair of LC runs);
//! 3. with a quarter of the completion's budget on top, the completion warm-started from the
//!    sampler's winner, if that beats the incumbent: it tightens the winner's clearances;
//! 4. **the choice**: the least `T_total` of the three, ties going to the incumbent, then to
//!    the sampler's winner. The sampler and the completion run exactly as they would alone
//!    (same seed, same incumbent, same budget), so the result is never worse than either's.
//!
//! For `N` robots ([`sample_schedule_n`]) the bound, the completion and the candidates are one
//! row of `STRATEGIES` per robot count (`N = 1`, `2`, `≥ 3`): for `N ≥ 3` the bound of
//! `exact::bound_many_switch` and the staggered candidate (`stagger.rs`) in every re-schedule, no
//! margin-aware completion; for `N = 2` the staggered candidate beside the completion (every
//! robot on its fastest warp at the least offset the check accepts: with one low-confidence run
//! per robot the best single-switch schedule the check allows, which the completion's shaped
//! speeds and the sampler's fitted robot 2 missed by 4–6 %; not with the benchmark baselines).
//!
//! Every candidate is checked with [`crate::validate`] at the tick before it can win. The
//! [`Outcome`] carries the schedule, its `T_total`, where it came from, and its certificate:
//! the bound and the gap `(T_total − bound)/bound`.

use serde::{Deserialize, Serialize};
use tandem_realtime::{clock_end_s, tol};

use crate::exact;
use crate::operator;
use crate::problem::{Problem, check_robot_count};
use crate::retime::retime;
use crate::sampler::{self, SamplerBaselines, SamplerParams, SamplerStats};
use crate::schedule::Schedule;
use crate::stagger;
use crate::validate::{Violation, validate_with_switch};
use crate::{Error, Result};

mod room;

/// Where the returned schedule came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Source {
    /// Sampled candidate number `candidate` (ChaCha8 stream of the seed).
    Sampled {
        /// Candidate index `k`.
        candidate: u64,
    },
    /// The margin-aware completion of the exact margin-free optimum
    /// ([`crate::exact`], "Margin-aware completion"; two robots).
    Completed,
    /// The previous schedule's warps and offset, unchanged (still valid at the scheduler's
    /// tick, nothing better found).
    Previous,
    /// The previous schedule repaired for the new problem (gradients clamped into the new
    /// bounds, new mean on low-confidence samples, `τ` clamped to `[0, |ψ_E1|]`).
    RepairedPrevious,
    /// The fastest serial schedule ([`Problem::serial_schedule`]).
    Serial,
    /// The exact optimum with hold points (two robots: the margin-free optimum of
    /// [`crate::solve_exact`] on a problem with holds, planned dwells included; `N ≥ 3`: the
    /// best order of the `N`-robot search, see [`crate::exact`]) with release rules from its
    /// order of low-confidence stretches ([`Problem::with_release_rules`]), which enforce that
    /// order at run time instead of margins; for two robots also the held completion (release
    /// rules on the switches into a run with a hold, margins on the others, every rule's wait
    /// planned; "Margin-aware completion" in [`crate::exact`]).
    Held,
    /// `N ≥ 2` robots on their fastest warps at the least start offsets the full check accepts
    /// (greedy robot by robot, or equally spaced), tried in every re-schedule (`stagger.rs`;
    /// docs/decisions.md, "N robots in the margin-free search", "An N-robot margin-aware
    /// completion"; for two robots "Two robots on their fastest warps at the least offset the
    /// check accepts (issue 38)").
    Staggered,
}

impl Source {
    /// The short name of the source in records (the study's JSON and CSV, the Python
    /// package): `sampled`, `completed`, `previous`, `repaired`, `serial`, `held` or
    /// `staggered`.
    pub fn name(self) -> &'static str {
        match self {
            Source::Sampled { .. } => "sampled",
            Source::Completed => "completed",
            Source::Previous => "previous",
            Source::RepairedPrevious => "repaired",
            Source::Serial => "serial",
            Source::Held => "held",
            Source::Staggered => "staggered",
        }
    }
}

/// What a serial fallback ([`Source::Serial`]) is, read off its schedule (the state file stores
/// only the source, so the label of a serial schedule that idles or is slowed for the
/// operator's switch time or load cap comes from the schedule, not from a source of its own):
/// see [`SerialForm::of`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SerialForm {
    /// [`Problem::serial_schedule_n`]: every robot on [`Problem::fastest_warp`], each starting
    /// when the one before it ends.
    Fastest,
    /// Robots one after another with some warp slower than the fastest (heads and tails slowed
    /// for the switch time, or a tail slowed for the load cap), no idle time between them.
    Slowed,
    /// Some robot starts after the robot before it has ended: idle time between them for the
    /// switch time or the load cap (Eq. 20 constraint 2 relaxed by the start allowance,
    /// [`crate::start_allowance_s`]); its warps may be slowed too.
    Idling,
}

impl SerialForm {
    /// The form of `schedule` taken as a serial schedule of `problem`: [`SerialForm::Idling`]
    /// when some robot `i + 1` starts more than `10⁻⁶·h` (`h` = [`Schedule::tick_s`]) after
    /// robot `i`'s end (the later of its clock end and `τ_i + Σ ψ̇·Δt_s`, as
    /// [`Problem::serial_schedule_n`] places it; the threshold is above that end's rounding,
    /// ≈ 10⁻¹¹ s on the study's schedules, and below the least gap the fallback adds, `h/2¹⁵`),
    /// else [`SerialForm::Slowed`] when some warp differs from [`Problem::fastest_warp`], else
    /// [`SerialForm::Fastest`].
    pub fn of(schedule: &Schedule, problem: &Problem) -> SerialForm {
        let dt_s = problem.dt_s();
        let mut start_s = 0.0;
        let mut idles = false;
        for (warp, next_s) in schedule.grad_exec.iter().zip(&schedule.offsets_s) {
            let end_s =
                clock_end_s(warp, start_s, dt_s).max(start_s + warp.iter().sum::<f64>() * dt_s);
            idles |= *next_s - end_s > 1e-6 * schedule.tick_s;
            start_s = *next_s;
        }
        if idles {
            return SerialForm::Idling;
        }
        let fastest = problem.fastest_warp();
        if schedule.grad_exec.iter().all(|w| *w == fastest) {
            SerialForm::Fastest
        } else {
            SerialForm::Slowed
        }
    }

    /// The form's label for people (what `tandem schedule` prints after `schedule:`).
    pub fn label(self) -> &'static str {
        match self {
            SerialForm::Fastest => "fastest serial schedule (fallback)",
            SerialForm::Slowed => {
                "serial schedule slowed for the switch time or load cap (fallback)"
            }
            SerialForm::Idling => {
                "serial schedule idling for the switch time or load cap (fallback)"
            }
        }
    }
}

/// A re-schedule's result: the schedule and its certificate.
///
/// Two outcomes are equal (`==`) when what the state file stores is: the schedule, `T_total`,
/// source, counts and certificate. [`Outcome::margin_free_s`] and [`Outcome::previous`]
/// describe the run that made the outcome and are not compared (a saved and reloaded outcome
/// equals the original).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Outcome {
    /// The schedule; its [`Schedule::tick_s`] is the scheduler's tick, at which it passes
    /// [`crate::validate`].
    pub schedule: Schedule,
    /// Its `T_total` (Eq. 13), s: exactly `schedule.t_total_s(Δt_s)`, read from the one
    /// clock.
    pub t_total_s: f64,
    /// Where it came from.
    pub source: Source,
    /// Counts.
    pub stats: SamplerStats,
    /// A lower bound (s) on the `T_total` of every schedule satisfying Eq. 20: the margin-free
    /// optimum `T*₀` (constraints 1–4, [`crate::solve_exact`]) when
    /// [`Outcome::bound_is_optimum`], else the simple bound of an unfinished search; for
    /// one robot its fastest execution; for `N ≥ 3` the `N`-robot search's optimum when it
    /// finished, else the larger of [`crate::operator_bound_s`] and the least bound of the
    /// nodes it left open (never below the bound of fewer robots). Reported as computed, never clamped: it is
    /// not above [`Outcome::t_total_s`] except by the rounding a valid schedule is allowed
    /// (at most `tol::BOUND_REL` = `2·tol::GRADIENT_REL` relative: `validate` accepts
    /// gradients that far outside their bounds, and the bound and `T_total` are summed in
    /// different orders); a bound above that is a bug, and in debug builds the scheduler
    /// returns [`Error::BoundAboveSchedule`] instead of the outcome.
    pub lower_bound_s: f64,
    /// Whether [`Outcome::lower_bound_s`] is the proven margin-free optimum `T*₀`.
    pub bound_is_optimum: bool,
    /// `(T_total − lower_bound_s)/lower_bound_s` (dimensionless; ≥ 0 up to the rounding of
    /// [`Outcome::lower_bound_s`], so never below `−tol::BOUND_REL`): the schedule is at most
    /// this much (relative) above the optimum of Eq. 20; what it is above `T*₀` is what the
    /// margins (constraint 5) cost, plus whatever the search left.
    pub gap: f64,
    /// The least `T_total` (s) known of a schedule satisfying Eq. 20 constraints 1–4 (no
    /// margins): the margin-free search's best schedule (for `N ≥ 3` its best order, proven
    /// or not), or [`Outcome::t_total_s`] if that is less (a valid schedule satisfies them
    /// too). The margin-free optimum `T*₀` lies in `[lower_bound_s, margin_free_s]`: equal to
    /// the bound when it is proven. `None` for an outcome read from a state file (not stored).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub margin_free_s: Option<f64>,
    /// What became of the previous schedule given to the scheduler: still valid, re-timed
    /// for the new problem, or invalid and why. While it (or its re-timing) is valid the
    /// returned `T_total` is never above its `T_total`. Not serialized (the state file keeps
    /// its format; a loaded or deserialized outcome reads [`PreviousFate::NotGiven`]).
    #[serde(skip)]
    pub previous: PreviousFate,
}

impl PartialEq for Outcome {
    fn eq(&self, other: &Self) -> bool {
        self.schedule == other.schedule
            && self.t_total_s == other.t_total_s
            && self.source == other.source
            && self.stats == other.stats
            && self.lower_bound_s == other.lower_bound_s
            && self.bound_is_optimum == other.bound_is_optimum
            && self.gap == other.gap
    }
}

/// Where the certificate's gap goes ([`Outcome::gap_split`]), both relative to
/// [`Outcome::lower_bound_s`] like [`Outcome::gap`], which is their sum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GapSplit {
    /// `(margin_free_s − lower_bound_s)/lower_bound_s`: how far the margin-free search left
    /// the optimum `T*₀` open (0 when it finished: the bound is `T*₀`). Time that may or may
    /// not be lost: a longer search, not a better schedule, would tell.
    pub search: f64,
    /// `(T_total − margin_free_s)/lower_bound_s`: what the schedule costs above the best
    /// schedule known without margins: the worst-case margins between the robots' low-confidence
    /// stretches (Eq. 20 constraint 5) or the waits of their release rules, plus whatever the
    /// scheduler did not find.
    pub margins: f64,
}

impl Outcome {
    /// The gap split into the search's share and the margins' share (see [`GapSplit`]);
    /// `None` for an outcome read from a state file ([`Outcome::margin_free_s`] is not
    /// stored).
    pub fn gap_split(&self) -> Option<GapSplit> {
        let free = self.margin_free_s?;
        let bound = self.lower_bound_s;
        Some(GapSplit {
            search: (free - bound) / bound,
            margins: (self.t_total_s - free) / bound,
        })
    }
}

/// The certificate of a valid schedule of `t_total_s` seconds against the lower bound
/// `bound_s` (s): `(lower_bound_s, gap)`, the bound as computed (no clamping) and
/// `(T_total − bound)/bound`.
///
/// # Errors
/// In debug builds, [`Error::BoundAboveSchedule`] if `bound_s` exceeds `t_total_s` by more
/// than [`tol::BOUND_REL`]: the bound is wrong (a bug in the search or the bound), and a
/// certificate must not hide it. Release builds return the certificate as computed, whose
/// negative gap shows the wrong bound to whoever reads it.
fn certificate(bound_s: f64, t_total_s: f64) -> Result<(f64, f64)> {
    if cfg!(debug_assertions) && bound_above(bound_s, t_total_s) {
        return Err(Error::BoundAboveSchedule { bound_s, t_total_s });
    }
    Ok((bound_s, (t_total_s - bound_s) / bound_s))
}

/// `true` when the lower bound `bound_s` (s) lies above the `T_total` `t_total_s` (s) of a
/// valid schedule by more than the rounding [`tol::BOUND_REL`] allows (or either is NaN).
fn bound_above(bound_s: f64, t_total_s: f64) -> bool {
    bound_s.is_nan() || t_total_s.is_nan() || bound_s > t_total_s * (1.0 + tol::BOUND_REL)
}

/// A schedule that passed every constraint of Eq. 20 at the scheduler's tick, with its
/// `T_total` (s) and where it came from.
type Candidate = (Schedule, f64, Source);

/// The previous schedule re-projected onto `problem` at control tick `tick_s` (s): gradients
/// clamped into the new bounds, the new mean on low-confidence samples, each `τ_i` clamped into
/// `[0, max_{j<i}(τ_j + |ψ_Ej|)]` (for two robots `[0, |ψ_E1|]`). `None` for a schedule of
/// the wrong shape or warps of the wrong length.
pub(crate) fn repair(problem: &Problem, previous: &Schedule, tick_s: f64) -> Option<Schedule> {
    let n_ref = problem.n_ref();
    if previous.check_shape().is_err() || previous.grad_exec.iter().any(|g| g.len() != n_ref) {
        return None;
    }
    let warps: Vec<Vec<f64>> = previous
        .grad_exec
        .iter()
        .map(|g| {
            (0..n_ref)
                .map(|n| {
                    if problem.conf()[n] {
                        let x = if g[n].is_finite() {
                            g[n]
                        } else {
                            problem.grad_mean()[n]
                        };
                        x.clamp(problem.grad_min()[n], problem.grad_max()[n])
                    } else {
                        problem.grad_mean()[n]
                    }
                })
                .collect()
        })
        .collect();
    let dt_s = problem.dt_s();
    let mut latest_end_s = clock_end_s(&warps[0], 0.0, dt_s);
    let mut offsets_s = Vec::with_capacity(previous.offsets_s.len());
    for (warp, &offset_s) in warps[1..].iter().zip(&previous.offsets_s) {
        let offset_s = if offset_s.is_finite() {
            offset_s.clamp(0.0, latest_end_s)
        } else {
            latest_end_s
        };
        offsets_s.push(offset_s);
        latest_end_s = latest_end_s.max(clock_end_s(warp, offset_s, dt_s));
    }
    Some(Schedule {
        grad_exec: warps,
        offsets_s,
        tick_s,
        holds: Vec::new(),
    })
}

/// What became of the previous schedule in a re-schedule ([`Outcome::previous`]): whether it
/// (or its re-timing for the new problem) was still valid, and so bounded the result, or why
/// not. Never stored in the state file (a loaded outcome reads [`PreviousFate::NotGiven`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub enum PreviousFate {
    /// No previous schedule of this robot count was given (a first schedule, a load, or a
    /// previous schedule of another robot count).
    #[default]
    NotGiven,
    /// The previous schedule passes every constraint of Eq. 20 on the new problem at the
    /// scheduler's tick as it is; the result is never longer.
    Valid {
        /// Its `T_total` (Eq. 13, s) on the new problem.
        t_total_s: f64,
    },
    /// The previous schedule no longer passes on the new problem (`why`: the model update
    /// moved the mean gradient of its low-confidence samples, Eq. 20 constraint 4, or its
    /// bounds), but its re-timing or repair for the new problem does; the result is never
    /// longer than that.
    Repaired {
        /// The first constraint the previous schedule broke as it was.
        why: Violation,
        /// `T_total` (Eq. 13, s) of the valid re-timed schedule (the least of the tries).
        t_total_s: f64,
    },
    /// Neither the previous schedule nor any re-timing or repair of it passes on the new
    /// problem: the result is not bounded by the previous schedule and may be longer.
    Invalid {
        /// The first constraint the previous schedule broke as it was.
        why: Violation,
        /// The first constraint its re-timing broke (`None` when it could not be re-timed:
        /// robot 1 would have to start later, or the shape does not fit the problem).
        retimed_why: Option<Violation>,
    },
}

impl PreviousFate {
    /// One sentence for a report: whether the previous schedule bounded the new one, and why
    /// not. `None` for [`PreviousFate::NotGiven`].
    pub fn describe(&self) -> Option<String> {
        match self {
            PreviousFate::NotGiven => None,
            PreviousFate::Valid { t_total_s } => Some(format!(
                "the previous schedule is still valid ({t_total_s:.3} s)"
            )),
            PreviousFate::Repaired { why, t_total_s } => Some(format!(
                "the previous schedule no longer fits the updated model ({why}); re-timed it \
                 passes ({t_total_s:.3} s)"
            )),
            PreviousFate::Invalid { why, retimed_why } => Some(match retimed_why {
                Some(r) => format!(
                    "the previous schedule became invalid ({why}), and so did its re-timing ({r})"
                ),
                None => format!(
                    "the previous schedule became invalid ({why}) and could not be re-timed"
                ),
            }),
        }
    }
}

/// The incumbent at control tick `tick_s` (see the module docs, step 1), and what became of
/// the previous schedule; or, if there is no incumbent, why the serial schedule failed.
fn incumbent(
    problem: &Problem,
    serial: &Schedule,
    previous: Option<&Schedule>,
    tick_s: f64,
    switch_s: f64,
) -> std::result::Result<(Candidate, PreviousFate), Violation> {
    let dt_s = problem.dt_s();
    let mut found: Option<Candidate> = None;
    let mut fate = PreviousFate::NotGiven;
    // A previous schedule of another robot count is no incumbent (the sampler still starts
    // from its robot 1).
    if let Some(prev) = previous.filter(|p| p.n_robots() == serial.n_robots()) {
        // The previous schedule is valid at its own tick; re-check it at this one.
        let prev = Schedule {
            tick_s,
            ..prev.clone()
        };
        match validate_with_switch(problem, &prev, switch_s) {
            Ok(()) => {
                let t = prev.t_total_s(dt_s);
                fate = PreviousFate::Valid { t_total_s: t };
                found = Some((prev, t, Source::Previous));
            }
            Err(why) => {
                let (best, retimed_why) = repaired(problem, &prev, tick_s, switch_s);
                fate = match &best {
                    Some((_, t)) => PreviousFate::Repaired { why, t_total_s: *t },
                    None => PreviousFate::Invalid { why, retimed_why },
                };
                found = best.map(|(s, t)| (s, t, Source::RepairedPrevious));
            }
        }
    }
    let serial_t = serial.t_total_s(dt_s);
    if found.as_ref().is_none_or(|inc| serial_t < inc.1) {
        match validate_with_switch(problem, serial, switch_s) {
            Ok(()) => found = Some((serial.clone(), serial_t, Source::Serial)),
            // With a switch time a task can have schedules but no serial one (a robot that
            // ends low-confidence leaves the next no time to switch): no incumbent, `T_total`
            // +∞, and the scheduler reports the serial schedule's violation if nothing passes.
            Err(_) if found.is_none() && switch_s > 0.0 => {
                found = Some((serial.clone(), f64::INFINITY, Source::Serial));
            }
            Err(v) if found.is_none() => return Err(v),
            Err(_) => {}
        }
    }
    Ok((
        found.expect("the serial schedule or an earlier incumbent was kept"),
        fate,
    ))
}

/// Halvings of the raise [`repaired`] bisects between the ladder's last refused clearance and
/// its first passing one: at most one re-timing per halving (two with holds: with its release
/// rules re-derived, and as it is) and so at most `2 · REPAIR_HALVINGS` margin checks. Five
/// halvings leave the raise within `M/32` of the least passing one in the bracket `[0, M]`
/// (`3M/32` in `[M, 4M]`; `M` of [`max_step_s`], the room one tick can take), below a tick
/// of the check's fastest low-confidence step (docs/decisions.md, "A repaired schedule
/// re-timed at the least raise the check accepts (issue 38)").
pub(crate) const REPAIR_HALVINGS: usize = 5;

/// The re-timings of `prev` for `problem` with every clearance raised by `extra_s` (s;
/// [`retime`]): with holds, the one with its release rules re-derived from the re-timed order
/// ([`Problem::with_release_rules`]; re-timed dwells can reorder the legs a rule relies on, and
/// a rule that would wait for a leg starting no earlier is refused) after the one as it is;
/// empty when the re-timing has no solution.
fn retimings(problem: &Problem, prev: &Schedule, tick_s: f64, extra_s: f64) -> Vec<Schedule> {
    let Some(re) = retime(problem, prev, tick_s, extra_s) else {
        return Vec::new();
    };
    let rederived = re
        .has_holds()
        .then(|| problem.with_release_rules(&without_rules(&re)).ok())
        .flatten();
    std::iter::once(re).chain(rederived).collect()
}

/// The least-`T_total` valid schedule among the re-timings of the previous schedule `prev` for
/// `problem` ([`retimings`]: with the old clearances and with them raised by one and by four
/// maximal steps `M` of the margin check) and its plain [`repair`] (with its holds, and
/// without); with the first violation of the plain re-timing when none passes. When the old
/// clearances fail but a raised one passes, the raise is bisected between the last refused
/// rung and the first passing one ([`REPAIR_HALVINGS`] halvings): the ladder alone raised every
/// clearance by `M` or `4M` where the model update had moved a low-confidence gradient by
/// 1e-4 relative, and the re-timed schedule cost more than the update
/// (docs/decisions.md, "A repaired schedule re-timed at the least raise the check accepts
/// (issue 38)"). Every schedule returned passed [`validate_with_switch`].
fn repaired(
    problem: &Problem,
    prev: &Schedule,
    tick_s: f64,
    switch_s: f64,
) -> (Option<(Schedule, f64)>, Option<Violation>) {
    let dt_s = problem.dt_s();
    let step_s = max_step_s(problem, tick_s);
    let mut best: Option<(Schedule, f64)> = None;
    let mut first_why = None;
    // Whether one of `tries` passes (or none was shorter than the best, so none was checked:
    // `None`), keeping the shortest that passes in `best`.
    let try_all = |tries: Vec<Schedule>,
                   best: &mut Option<(Schedule, f64)>,
                   first_why: &mut Option<Violation>,
                   plain: bool|
     -> Option<bool> {
        let mut verdict = None;
        for (q, s) in tries.into_iter().enumerate() {
            let t = s.t_total_s(dt_s);
            if best.as_ref().is_some_and(|b| b.1 <= t) {
                continue;
            }
            match validate_with_switch(problem, &s, switch_s) {
                Ok(()) => {
                    *best = Some((s, t));
                    verdict = Some(true);
                }
                Err(v) => {
                    if plain && q == 0 && first_why.is_none() {
                        *first_why = Some(v);
                    }
                    verdict = verdict.or(Some(false));
                }
            }
        }
        verdict
    };
    // The ladder: the last raise refused below the first that passes, and that one.
    let mut refused: Option<f64> = None;
    let mut passed: Option<f64> = None;
    let mut retimed = false;
    for extra_s in [0.0, step_s, 4.0 * step_s] {
        let tries = retimings(problem, prev, tick_s, extra_s);
        let first = !retimed;
        retimed |= !tries.is_empty();
        let verdict = try_all(tries, &mut best, &mut first_why, first);
        match verdict {
            Some(true) if passed.is_none() => passed = Some(extra_s),
            Some(false) if passed.is_none() => refused = Some(extra_s),
            _ => {}
        }
    }
    // The raise bisected between the two (a larger raise never re-times earlier, so one whose
    // re-timing is no shorter than the best found is not checked and the search goes lower).
    if let (Some(mut lo), Some(mut hi)) = (refused, passed) {
        for _ in 0..REPAIR_HALVINGS {
            let mid = 0.5 * (lo + hi);
            let tries = retimings(problem, prev, tick_s, mid);
            if tries.is_empty() {
                lo = mid;
                continue;
            }
            match try_all(tries, &mut best, &mut first_why, false) {
                Some(false) => lo = mid,
                Some(true) | None => hi = mid,
            }
        }
    }
    if let Some(fixed) = repair(problem, prev, tick_s) {
        let mut tries = Vec::new();
        if prev.has_holds() {
            tries.push(Schedule {
                holds: prev.holds.clone(),
                ..fixed.clone()
            });
        }
        tries.push(fixed);
        try_all(tries, &mut best, &mut first_why, false);
    }
    (best, first_why)
}

/// The room-aware candidates' extra rooms in units of the switch time `δ`, beside the rooms
/// the check asks (`room::room_from_slacks`): a switch into a stretch behind a high-confidence
/// run with no usable hold needs the robot's fastest arrival `δ + c·δ` after the previous
/// stretch ends ([`exact::room_aware_many`]; docs/decisions.md, "Three robots at δ ≥ 1 s: a
/// room-aware order (issue 41)", "Three robots at δ ≥ 1 s: the room the check asks (issue 41)").
const ROOM_STEPS: [f64; 4] = [0.0, 0.5, 1.0, 2.0];

/// Node budget of each room-aware search (a quarter of the bound's own, [`exact::MAX_SEARCH_NODES`]).
const ROOM_NODES: usize = exact::MAX_SEARCH_NODES / 4;

/// A room-aware order's schedule made a candidate: with usable holds its waits as dwells
/// ([`exact::dwelled`]) and release rules derived, then the first of it and its re-timings with
/// growing clearances ([`cleared_optimum`]) that passes [`validate_with_switch`] at `switch_s`
/// below `cap_s` (s); with its `T_total`. Counts the margin checks in `checks`.
fn settle_room_aware(
    problem: &Problem,
    order: Schedule,
    tick_s: f64,
    cap_s: f64,
    switch_s: f64,
    checks: &mut usize,
) -> Option<(Schedule, f64)> {
    let dwelled = if problem.usable_holds().is_empty() {
        order
    } else {
        exact::dwelled(problem, &order, tick_s).unwrap_or(order)
    };
    let held = problem.with_release_rules(&dwelled).ok()?;
    let t = held.t_total_s(problem.dt_s());
    if t >= cap_s {
        return None;
    }
    *checks += 1;
    if validate_with_switch(problem, &held, switch_s).is_ok() {
        return Some((held, t));
    }
    let (cleared, used) = cleared_optimum(problem, &held, tick_s, cap_s, switch_s);
    *checks += used;
    cleared
}

/// The relative gap `T_total / T*₀ − 1` above which two robots try the margin-free optimum
/// with clearances traded between switches (`clearance::pair_traded`) after every other
/// candidate; below it its up to `MAX_TRADE_CHECKS + 1` margin checks are not spent. Not tuned
/// on the zoo: the default study ends its `--trials 1 --executions 40` run 2.2 % above `T*₀`
/// (and its full run 0.1 %), below it (docs/decisions.md, "Two robots with holds: clearances
/// traded between switches (issue 38)").
pub(crate) const TRADE_GAP_TRIGGER: f64 = 0.03;

/// Clearance steps of [`cleared_optimum`]: `M·2^k` for `k = 0..CLEAR_STEPS`.
const CLEAR_STEPS: i32 = 8;

/// `held`, the margin-free optimum of `N ≥ 3` robots with its release rules, when it fails the
/// margin check: re-timed ([`retime`]) with every clearance between two consecutive
/// low-confidence runs of different robots raised by `M·2^k` (`k = 0, 1, …`, `M` of
/// [`max_step_s`]), each with its release rules re-derived from the re-timed order and as it
/// is; the first that passes [`validate`] with `T_total` below `cap_s` (s), and the checks
/// used. Stops at the first re-timing not below `cap_s` (larger clearances only delay).
///
/// Why (docs/decisions.md, "The stuck incumbent"): when learning makes a stretch
/// high-confidence, the optimum drops below the re-timed incumbent, whose events never move
/// earlier; if the optimum itself fails the margins, no other `N ≥ 3` candidate is built from
/// it, and the incumbent stays far above the bound for every later round.
pub(crate) fn cleared_optimum(
    problem: &Problem,
    held: &Schedule,
    tick_s: f64,
    cap_s: f64,
    switch_s: f64,
) -> (Option<(Schedule, f64)>, usize) {
    let dt_s = problem.dt_s();
    let step_s = max_step_s(problem, tick_s);
    let mut checks = 0;
    for k in 0..CLEAR_STEPS {
        let Some(re) = retime(problem, held, tick_s, step_s * 2f64.powi(k)) else {
            continue;
        };
        if re.t_total_s(dt_s) >= cap_s {
            break;
        }
        let rederived = re
            .has_holds()
            .then(|| problem.with_release_rules(&without_rules(&re)).ok())
            .flatten();
        for s in rederived.into_iter().chain([re]) {
            let t = s.t_total_s(dt_s);
            if t >= cap_s {
                continue;
            }
            checks += 1;
            if validate_with_switch(problem, &s, switch_s).is_ok() {
                return (Some((s, t)), checks);
            }
        }
    }
    (None, checks)
}

/// `schedule` with every hold's release rules removed (the holds and dwells kept).
fn without_rules(schedule: &Schedule) -> Schedule {
    Schedule {
        holds: schedule
            .holds
            .iter()
            .map(|hs| {
                hs.iter()
                    .map(|h| tandem_realtime::Hold {
                        after: Vec::new(),
                        ..h.clone()
                    })
                    .collect()
            })
            .collect(),
        ..schedule.clone()
    }
}

/// `M` (schedule-clock s): `tick_s · max(1, largest ψ̇̄/ψ̇min of a low-confidence sample)`, the
/// least maximal step in one tick of any schedule of `problem` (its LC samples run at the
/// mean): the margin check's unit of room.
pub(crate) fn max_step_s(problem: &Problem, tick_s: f64) -> f64 {
    let (gmean, gmin) = (problem.grad_mean(), problem.grad_min());
    tick_s
        * (0..problem.n_ref())
            .filter(|&n| !problem.conf()[n])
            .map(|n| gmean[n] / gmin[n])
            .fold(1.0, f64::max)
}

/// The scheduler (see the module docs): the least-`T_total` schedule among the incumbent
/// (previous schedule, its repair, the fastest serial schedule), the anytime sampler's winner
/// (§II-C, `params.samples` candidates) and the margin-aware completion of the exact
/// margin-free optimum, that satisfies every constraint of Eq. 20 at the control tick
/// `params.tick_s`, certified against the margin-free lower bound `T*₀`.
///
/// Runs on the current rayon thread pool; the result for a seed is the same whatever the
/// number of threads. Never worse than the sampler alone with the same seed, nor than the
/// completion alone ([`SamplerBaselines::sampler_only`], [`SamplerBaselines::completion_only`]).
///
/// # Errors
/// [`Error::BadParam`] for invalid parameters; [`Error::NoFeasibleSchedule`] if not even the
/// serial schedule passes (which would mean the margin check rejects a schedule with no
/// concurrent execution at all).
pub fn sample_schedule(
    problem: &Problem,
    params: &SamplerParams,
    previous: Option<&Schedule>,
) -> Result<Outcome> {
    sample_schedule_with_baselines(problem, params, &SamplerBaselines::default(), previous)
}

/// The scheduler for `n_robots` robots (`1 ≤ N ≤ MAX_ROBOTS`; [`sample_schedule`] is its
/// `N = 2` case, to the bit): the least-`T_total` schedule among the incumbent (the previous
/// schedule if it has `N` robots, its repair, the fastest serial schedule of `N` robots,
/// [`Problem::serial_schedule_n`]) and the sampler's winner, valid at `params.tick_s`
/// (every constraint of Eq. 20 for all `N` robots, the margins by
/// `tandem_realtime::sufficient_margins`), certified against a lower bound.
///
/// The sampler draws robot 1 as for two robots and places robots 2..N in turn, each by the
/// exact interval sweep against the union of the earlier robots' widened low-confidence
/// intervals (one widening `w` per candidate), its offset at most the latest end before it;
/// candidates are checked in `(T_total, k)` order as for two robots. The warm start keeps
/// robot 1 of the previous schedule (whatever its robot count). For `N = 2` the margin-aware
/// completion runs beside the sampler and the bound is the exact margin-free optimum `T*₀`.
/// For `N ≥ 3` the bound is the maximum of the `k`-robot bounds, `k ≤ N` (the margin-free
/// optimum of the `N`-robot branch and bound when it finishes within its node budget, else
/// [`crate::operator_bound_s`]; see "N robots" in [`crate::exact`]); there is no margin-aware
/// completion; the staggered schedule ([`Source::Staggered`]) is a candidate in every
/// re-schedule, and with hold points the best
/// order with release rules ([`Problem::with_release_rules`], [`Source::Held`]). For `N = 1`
/// the bound is the optimum itself, the fastest execution. Which strategies run for which
/// robot count is one table (`STRATEGIES` in `choose.rs`).
/// Deterministic for a seed whatever the thread count.
///
/// # Errors
/// As [`sample_schedule`]; [`Error::Realtime`] (`RobotCount`) for `n_robots` outside `1..=MAX_ROBOTS`.
pub fn sample_schedule_n(
    problem: &Problem,
    n_robots: usize,
    params: &SamplerParams,
    previous: Option<&Schedule>,
) -> Result<Outcome> {
    schedule_n(
        problem,
        n_robots,
        params,
        &SamplerBaselines::default(),
        previous,
    )
}

/// [`sample_schedule`] with benchmark-only alternatives to its design (see
/// [`SamplerBaselines`]); `SamplerBaselines::default()` is [`sample_schedule`] itself.
///
/// # Errors
/// As [`sample_schedule`].
pub fn sample_schedule_with_baselines(
    problem: &Problem,
    params: &SamplerParams,
    baselines: &SamplerBaselines,
    previous: Option<&Schedule>,
) -> Result<Outcome> {
    schedule_n(problem, 2, params, baselines, previous)
}

/// How the scheduler bounds and completes for one robot count: a row of [`STRATEGIES`].
///
/// Every row runs the incumbent (previous schedule, its re-timing or repair, the fastest
/// serial schedule) and the sampler, and with usable hold points the bound's margin-free
/// schedule with release rules ([`Source::Held`]); the row adds its bound, its completion and
/// whether the staggered candidate runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Strategies {
    /// The certificate's lower bound (and its margin-free schedule).
    pub(crate) bound: BoundBy,
    /// The margin-aware completion.
    pub(crate) completion: CompleteBy,
    /// Whether the staggered candidate ([`Source::Staggered`], `stagger.rs`) is tried.
    pub(crate) staggered: bool,
}

/// The lower bound of a row of [`STRATEGIES`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BoundBy {
    /// One robot: its fastest execution, the optimum itself ([`exact::operator_bound`]).
    Fastest,
    /// Two robots: the exact margin-free optimum `T*₀` ([`exact::bound_switch`], with `δ`).
    Pair,
    /// `N ≥ 3` robots: the maximum of the `k`-robot bounds ([`exact::bound_many_switch`], with `δ`).
    Many,
}

/// The margin-aware completion of a row of [`STRATEGIES`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CompleteBy {
    /// None: one robot has nothing to keep apart; for `N ≥ 3` no completion has won a
    /// re-schedule yet (docs/decisions.md, "An N-robot margin-aware completion, the staggered
    /// candidate always, and the strategies as a table").
    Nothing,
    /// The two-robot completion ([`exact::completion`]: per-pair clearances through the exact
    /// search, cold and warm from the incumbent, then warm from the sampler's winner).
    Pair,
}

/// The scheduler's strategies per robot count (issue 40, item 5): row `min(N, 3) − 1`.
pub(crate) const STRATEGIES: [Strategies; 3] = [
    // N = 1.
    Strategies {
        bound: BoundBy::Fastest,
        completion: CompleteBy::Nothing,
        staggered: false,
    },
    // N = 2: the staggered candidate too, the best single-switch schedule where each robot
    // has one low-confidence run (docs/decisions.md, "Two robots on their fastest warps at the
    // least offset the check accepts (issue 38)").
    Strategies {
        bound: BoundBy::Pair,
        completion: CompleteBy::Pair,
        staggered: true,
    },
    // N ≥ 3.
    Strategies {
        bound: BoundBy::Many,
        completion: CompleteBy::Nothing,
        staggered: true,
    },
];

/// The row of [`STRATEGIES`] for `n_robots ≥ 1` robots.
pub(crate) fn strategies(n_robots: usize) -> Strategies {
    STRATEGIES[n_robots.clamp(1, STRATEGIES.len()) - 1]
}

/// `bound` (the margin-free bound with the switch time `params.switch_s`) raised to the bound
/// without it when that is larger, as [`exact::margin_free_bound`] does: every schedule that
/// keeps `δ` keeps 0, so both bound it (the searches with `δ` can end looser; docs/decisions.md,
/// "A schedule always exists with a switch time: constraint 2 relaxed (issue 41)"). A raised
/// bound is no proven optimum. Without a switch time `bound` itself (no added operation).
fn at_least_plain(
    mut bound: exact::MarginFree,
    problem: &Problem,
    n_robots: usize,
    params: &SamplerParams,
) -> exact::MarginFree {
    if params.switch_s > 0.0
        && let Ok(plain) = exact::margin_free_bound(problem, n_robots, &params.exact, 0.0)
        && plain.lower_bound_s > bound.lower_bound_s
    {
        bound.lower_bound_s = plain.lower_bound_s;
        bound.proven_optimal = false;
    }
    bound
}

/// [`sample_schedule_n`] with benchmark-only baselines (for two robots only, the default
/// otherwise): the strategies of [`strategies`]`(n_robots)`, the least `T_total` winning.
fn schedule_n(
    problem: &Problem,
    n_robots: usize,
    params: &SamplerParams,
    baselines: &SamplerBaselines,
    previous: Option<&Schedule>,
) -> Result<Outcome> {
    params.validate()?;
    check_robot_count(n_robots)?;
    let plan = strategies(n_robots);
    if plan.bound != BoundBy::Pair && *baselines != SamplerBaselines::default() {
        return Err(Error::BadParam {
            name: "baselines",
            why: "the benchmark baselines are for two robots only",
        });
    }
    let tick_s = params.tick_s.unwrap_or(problem.dt_s());
    // The operator (issue 41): the switch time `δ` every candidate is checked with, and the
    // load cap `u_max` (1: none). `δ = 0` and `u_max = 1` run today's float operations.
    let (sw, u_max) = (params.switch_s, params.max_busy_share);
    let fastest_serial = problem.serial_schedule_n(n_robots, tick_s)?;
    // With a switch time the serial fallback may fail (why, of its slowed form, kept for the
    // error if nothing else passes either).
    let (serial, serial_why) = if sw > 0.0 {
        match operator::serial_with_switch(problem, n_robots, tick_s, sw) {
            Ok(s) => (s, None),
            Err(Error::NoFeasibleSchedule { serial }) => (fastest_serial.clone(), Some(serial)),
            Err(e) => return Err(e),
        }
    } else {
        (fastest_serial.clone(), None)
    };
    let (incumbent, previous_fate) = match incumbent(problem, &serial, previous, tick_s, sw) {
        Ok(inc) => inc,
        Err(serial) => return Err(Error::NoFeasibleSchedule { serial }),
    };
    let cap_s = incumbent.1;
    let pair = plan.completion == CompleteBy::Pair;
    let budget = if baselines.sampler_only || !pair {
        0
    } else {
        params.exact.max_margin_checks
    };
    // Refining the sampler's winner gets a quarter of the completion's budget on top, so the
    // completion itself runs exactly as it would alone.
    let refine_budget = if baselines.completion_only {
        0
    } else {
        budget / 4
    };
    let warm: Vec<&Schedule> = (incumbent.2 != Source::Serial)
        .then_some(&incumbent.0)
        .into_iter()
        .collect();
    let ((winner, mut stats), (bound, (done, mut checks), held_done)) = rayon::join(
        || {
            if baselines.completion_only {
                (None, SamplerStats::default())
            } else {
                sampler::run(
                    problem, n_robots, params, baselines, tick_s, previous, cap_s,
                )
            }
        },
        || match plan.bound {
            BoundBy::Fastest => (
                exact::operator_bound(problem, n_robots),
                (None, 0),
                (None, 0),
            ),
            BoundBy::Many => (
                at_least_plain(
                    exact::bound_many_switch(problem, n_robots, &params.exact, sw),
                    problem,
                    n_robots,
                    params,
                ),
                (None, 0),
                (None, 0),
            ),
            BoundBy::Pair => {
                let bound = at_least_plain(
                    exact::bound_switch(problem, &params.exact, sw),
                    problem,
                    2,
                    params,
                );
                let done = if pair && bound.lower_bound_s < cap_s {
                    exact::completion(
                        problem,
                        &params.exact,
                        tick_s,
                        cap_s,
                        budget,
                        true,
                        &warm,
                        sw,
                    )
                } else {
                    (None, 0)
                };
                // With hold points, the held completion: release rules instead of margins on
                // the switches into a run with a hold, their waits planned as dwells.
                let cap = done.0.as_ref().map_or(cap_s, |d| d.t_total_s.min(cap_s));
                let held = if pair && bound.lower_bound_s < cap {
                    exact::held_completion(problem, &params.exact, tick_s, cap, budget, sw)
                } else {
                    (None, 0)
                };
                (bound, done, held)
            }
        },
    );
    // With a load cap every valid candidate is kept: the cap lengthens each by its own switches,
    // so the least `T_total` before it need not be the least after it.
    let capping = u_max < 1.0;
    let mut pool: Vec<Candidate> = Vec::new();
    if capping && incumbent.1 < f64::INFINITY {
        pool.push(incumbent.clone());
        if incumbent.2 != Source::Serial
            && let Ok(()) = validate_with_switch(problem, &serial, sw)
        {
            pool.push((
                serial.clone(),
                serial.t_total_s(problem.dt_s()),
                Source::Serial,
            ));
        }
    }
    let mut best = incumbent;
    let mut completed = done.map(|d| (d.schedule, d.t_total_s));
    if let Some((s, t, k)) = winner
        && t < best.1
    {
        if pair {
            // The sampler's winner as a warm start: the completion tightens its clearances.
            let cap = completed.as_ref().map_or(t, |c| c.1.min(t));
            let (better, more) = exact::completion(
                problem,
                &params.exact,
                tick_s,
                cap,
                refine_budget,
                false,
                &[&s],
                sw,
            );
            checks += more;
            if let Some(b) = better {
                completed = Some((b.schedule, b.t_total_s));
            }
        }
        if capping {
            pool.push((s.clone(), t, Source::Sampled { candidate: k }));
        }
        best = (s, t, Source::Sampled { candidate: k });
    }
    stats.search = bound.stats;
    if let Some((schedule, t)) = completed
        && t < best.1
        && validate_with_switch(problem, &schedule, sw).is_ok()
    {
        if capping {
            pool.push((schedule.clone(), t, Source::Completed));
        }
        best = (schedule, t, Source::Completed);
    }
    checks += held_done.1;
    if let Some(h) = held_done.0
        && h.t_total_s < best.1
        && validate_with_switch(problem, &h.schedule, sw).is_ok()
    {
        if capping {
            pool.push((h.schedule.clone(), h.t_total_s, Source::Held));
        }
        best = (h.schedule, h.t_total_s, Source::Held);
    }
    // With hold points, the margin-free optimum itself with release rules (for `N ≥ 3` the
    // best order the search found, proven or not).
    if let Some(optimum) = bound.schedule.as_ref()
        && !problem.usable_holds().is_empty()
    {
        let timed = Schedule {
            tick_s,
            ..optimum.clone()
        };
        if let Ok(held) = problem.with_release_rules(&timed) {
            let t = held.t_total_s(problem.dt_s());
            if t < best.1 {
                if validate_with_switch(problem, &held, sw).is_ok() {
                    if capping {
                        pool.push((held.clone(), t, Source::Held));
                    }
                    best = (held, t, Source::Held);
                } else if plan.bound == BoundBy::Many {
                    // N ≥ 3: the optimum re-timed with growing clearances, its rules
                    // re-derived (docs/decisions.md, "The stuck incumbent").
                    let (cleared, used) = cleared_optimum(problem, &held, tick_s, best.1, sw);
                    checks += used;
                    if let Some((s, t)) = cleared {
                        if capping {
                            pool.push((s.clone(), t, Source::Held));
                        }
                        best = (s, t, Source::Held);
                    }
                }
            }
        }
    }
    // N ≥ 3 with a switch time and hold points: the optimum with its waits as dwells at holds
    // (its approaches at their fastest, `exact::dwelled`) and release rules re-derived, then
    // re-timed with clearances (docs/decisions.md, "Three robots at δ ≥ 1 s: waits as dwells
    // (issue 41)"). Not at `δ = 0` (the scheduler of before, bit for bit).
    if plan.bound == BoundBy::Many
        && sw > 0.0
        && let Some(optimum) = bound.schedule.as_ref()
        && optimum.t_total_s(problem.dt_s()) < best.1
        && let Some(dwelled) = exact::dwelled(
            problem,
            &Schedule {
                tick_s,
                ..optimum.clone()
            },
            tick_s,
        )
        && let Ok(held) = problem.with_release_rules(&dwelled)
    {
        let t = held.t_total_s(problem.dt_s());
        if t < best.1 {
            checks += 1;
            let found = if validate_with_switch(problem, &held, sw).is_ok() {
                Some((held, t))
            } else {
                let (cleared, used) = cleared_optimum(problem, &held, tick_s, best.1, sw);
                checks += used;
                cleared
            };
            if let Some((s, t)) = found {
                if capping {
                    pool.push((s.clone(), t, Source::Held));
                }
                best = (s, t, Source::Held);
            }
        }
    }
    // N ≥ 3 with a switch time: room-aware orders, where a switch into a stretch behind a
    // high-confidence run with no usable hold needs the robot's fastest arrival `δ + e` after
    // the previous stretch ends, `e` from 0 up over the rooms the check asks and `ROOM_STEPS`
    // (the first that passes, then bisected), each dwelled with release rules as the optimum
    // above, then re-timed with clearances; judged by the unchanged check (docs/decisions.md,
    // "Three robots at δ ≥ 1 s: the room the check asks (issue 41)"). Not at `δ = 0`.
    if plan.bound == BoundBy::Many
        && sw > 0.0
        && let Some((s, t)) =
            room::room_from_slacks(problem, n_robots, tick_s, best.1, sw, &mut checks)
    {
        if capping {
            pool.push((s.clone(), t, Source::Held));
        }
        best = (s, t, Source::Held);
    }
    // The staggered candidate, always (its checks see all robots: at most
    // `MAX_STAGGER_CHECKS` of them). Before, it ran only when nothing beat the serial
    // schedule, and a schedule with holds that overlapped the robots hid a shorter staggered
    // one without holds (docs/decisions.md, "An N-robot margin-aware completion").
    // The benchmark baselines of two robots measure the sampler or the completion alone.
    if plan.staggered
        && *baselines == SamplerBaselines::default()
        && let Some((schedule, t, used)) = stagger::staggered(problem, &fastest_serial, sw)
    {
        checks += used;
        if capping {
            pool.push((schedule.clone(), t, Source::Staggered));
        }
        if t < best.1 {
            best = (schedule, t, Source::Staggered);
        }
    }
    // N = 2 with at least two LC runs, when the best so far is more than `TRADE_GAP_TRIGGER`
    // above the bound: the margin-free optimum without release rules re-timed with every
    // switch at the room the check asks, room traded between switches (`clearance::
    // pair_traded`; docs/decisions.md, "Two robots with holds: clearances traded between
    // switches (issue 38)"). Not with the benchmark baselines.
    if plan.bound == BoundBy::Pair
        && *baselines == SamplerBaselines::default()
        && best.1 > (1.0 + TRADE_GAP_TRIGGER) * bound.lower_bound_s
        && problem.runs().iter().filter(|r| !r.high_conf).count() >= 2
        && let Some(optimum) = bound.schedule.as_ref()
        && optimum.t_total_s(problem.dt_s()) < best.1
    {
        let timed = Schedule {
            tick_s,
            ..optimum.clone()
        };
        let (traded, used) = crate::clearance::pair_traded(
            problem,
            &timed,
            tick_s,
            best.1,
            crate::clearance::MAX_TRADE_CHECKS,
            sw,
        );
        checks += used;
        if let Some((s, t)) = traded {
            if capping {
                pool.push((s.clone(), t, Source::Held));
            }
            best = (s, t, Source::Held);
        }
    }
    // N ≥ 3 with hold points: the optimum without release rules (whose planned waits cost the
    // way from each hold to the next run at every switch), re-timed with clearances only where
    // the check's pairs lack room, below the best so far (docs/decisions.md, "Per-pair
    // clearances for N ≥ 3 (issue 38)").
    if plan.bound == BoundBy::Many
        && let Some(optimum) = bound.schedule.as_ref()
        && !problem.usable_holds().is_empty()
        && optimum.t_total_s(problem.dt_s()) < best.1
    {
        let timed = Schedule {
            tick_s,
            ..optimum.clone()
        };
        let (paired, used) = crate::clearance::pair_cleared(
            problem,
            &timed,
            tick_s,
            best.1,
            crate::clearance::MAX_PAIR_CHECKS,
            sw,
        );
        checks += used;
        if let Some((s, t)) = paired {
            if capping {
                pool.push((s.clone(), t, Source::Held));
            }
            best = (s, t, Source::Held);
        }
    }
    stats.completion_margin_checks = checks;
    if best.1 == f64::INFINITY {
        // No incumbent (the serial schedule fails with the switch time) and nothing passed.
        let why = serial_why.unwrap_or_else(|| {
            validate_with_switch(problem, &serial, sw)
                .expect_err("a valid serial schedule is the incumbent, of finite T_total")
        });
        return Err(Error::NoFeasibleSchedule { serial: why });
    }
    // The load cap: every kept candidate lengthened to its share ([`operator::capped`]), the
    // least `T_total` winning (ties to the earlier kept).
    if capping {
        let pooled = pool
            .iter()
            .filter_map(|(s, _, src)| {
                operator::capped(problem, s, sw, u_max).map(|(s, t)| (s, t, *src))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        // The serial schedule with idle gaps for the cap, which always exists (constraint 2
        // relaxed, `operator::start_allowance_s`): kept when it is shorter or nothing else is.
        let serial = operator::serial_capped(problem, n_robots, tick_s, sw, u_max).map(|s| {
            let t = s.t_total_s(problem.dt_s());
            (s, t, Source::Serial)
        });
        best = match (pooled, serial) {
            (Some(a), Some(b)) => {
                if b.1 < a.1 {
                    b
                } else {
                    a
                }
            }
            (a, b) => a.or(b).ok_or(Error::BusyShareUnreachable {
                max_busy_share: u_max,
                switch_s: sw,
            })?,
        };
    }
    let (schedule, t_total_s, source) = best;
    let margin_free_s = bound
        .schedule
        .as_ref()
        .map_or(t_total_s, |s| s.t_total_s(problem.dt_s()).min(t_total_s))
        .max(bound.lower_bound_s.min(t_total_s));
    // With a load cap the bound is at least the cap's (`operator::cap_bound_s`); it is then
    // no longer the margin-free optimum when the cap's is above it.
    let (bound_s, bound_is_optimum) = if capping {
        let cap_s = operator::cap_bound_s(problem, n_robots, sw, u_max);
        if cap_s > bound.lower_bound_s {
            (cap_s, false)
        } else {
            (bound.lower_bound_s, bound.proven_optimal)
        }
    } else {
        (bound.lower_bound_s, bound.proven_optimal)
    };
    let (lower_bound_s, gap) = certificate(bound_s, t_total_s)?;
    Ok(Outcome {
        schedule,
        t_total_s,
        source,
        stats,
        lower_bound_s,
        bound_is_optimum,
        gap,
        margin_free_s: Some(margin_free_s),
        previous: previous_fate,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_certificate_reports_the_bound_as_computed() {
        // T_total 0.5 s against the bound 0.4 s: gap 0.1/0.4 = 0.25.
        let (bound, gap) = certificate(0.4, 0.5).unwrap();
        assert_eq!(bound, 0.4);
        assert!((gap - 0.25).abs() < 1e-15, "{gap}");
        // A schedule shorter than the bound by rounding (1e-12 relative, inside the slack)
        // keeps the bound as computed and a negative gap: nothing is clamped.
        let (bound, gap) = certificate(1.0 + 1e-12, 1.0).unwrap();
        assert_eq!(bound, 1.0 + 1e-12);
        assert!(gap < 0.0 && gap > -2e-12, "{gap}");
        // The edge of the slack still passes.
        let (_, gap) = certificate(1.0 + 0.75 * tol::BOUND_REL, 1.0).unwrap();
        assert!(gap < 0.0);
    }

    #[test]
    fn a_bound_above_t_total_is_an_error_in_debug_builds() {
        // 1e-6 relative above the schedule: far beyond rounding, a wrong bound.
        let wrong = certificate(0.5 * (1.0 + 1e-6), 0.5);
        // Just beyond the allowance, and a NaN bound, are wrong too.
        let edge = certificate(1.0 + 1.5 * tol::BOUND_REL, 1.0);
        let nan = certificate(f64::NAN, 1.0);
        if cfg!(debug_assertions) {
            for (got, bound_s) in [
                (wrong, 0.5 * (1.0 + 1e-6)),
                (edge, 1.0 + 1.5 * tol::BOUND_REL),
            ] {
                match got {
                    Err(Error::BoundAboveSchedule {
                        bound_s: b,
                        t_total_s: _,
                    }) => assert_eq!(b, bound_s),
                    other => panic!("expected BoundAboveSchedule, got {other:?}"),
                }
            }
            assert!(
                matches!(nan, Err(Error::BoundAboveSchedule { .. })),
                "{nan:?}"
            );
        } else {
            // Release builds report it as computed: the negative gap shows it.
            let (bound, gap) = wrong.unwrap();
            assert_eq!(bound, 0.5 * (1.0 + 1e-6));
            assert!(gap < -9e-7, "{gap}");
            assert!(edge.unwrap().1 < 0.0);
        }
        assert!(bound_above(1.0 + 3.0 * tol::BOUND_REL, 1.0));
        assert!(!bound_above(1.0 + 0.5 * tol::BOUND_REL, 1.0));
    }

    // `pegs`: the peg-in-hole problem the integration tests with hold points share.
    include!("../tests/common/pegs.rs");

    use crate::retime::tests::slowed;

    /// Issue 38's "schedules get worse as the robots learn", by hand: two robots on the
    /// peg-in-hole problem (20 s at 20 Hz, two low-confidence inserts of 2 s), the sampler's
    /// schedule with robot 2's offset bisected down to the least the margin check accepts (a
    /// schedule at its margins, as the completion and the staggered candidate leave them); the
    /// model update then slows the inserts by 1e-4 relative (0.2 ms each). The old schedule
    /// breaks Eq. 20 constraint 4, its re-timing with the old clearances the margin check; the
    /// ladder's next rung (every clearance raised by `M` = 71 ms) passes 0.215 s (4 ticks)
    /// above the old `T_total`, the bisected raise 7.5 ms above it (measured when the
    /// bisection was added). The re-schedule must stay within a tick of the old schedule.
    #[test]
    fn a_tiny_model_update_costs_a_schedule_at_its_margins_less_than_a_tick() {
        let p = pegs(false);
        let tick_s = 0.05;
        let params = SamplerParams {
            samples: 400,
            seed: 0,
            tick_s: Some(tick_s),
            ..SamplerParams::default()
        };
        let mut prev = sample_schedule_n(&p, 2, &params, None).unwrap().schedule;
        let (mut lo, mut hi) = (0.0, prev.offsets_s[0]);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            prev.offsets_s = vec![mid];
            if validate_with_switch(&p, &prev, 0.0).is_ok() {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        prev.offsets_s = vec![hi];
        validate_with_switch(&p, &prev, 0.0).unwrap();
        let t_prev = prev.t_total_s(p.dt_s());
        let q = slowed(&p, 1.0001);
        assert!(matches!(
            validate_with_switch(&q, &prev, 0.0),
            Err(Violation::NotMeanGradient { .. })
        ));
        let plain = retime(&q, &prev, tick_s, 0.0).unwrap();
        assert!(matches!(
            validate_with_switch(&q, &plain, 0.0),
            Err(Violation::InsufficientMargins { .. })
        ));
        let m = max_step_s(&q, tick_s);
        let rung = retime(&q, &prev, tick_s, m).unwrap();
        validate_with_switch(&q, &rung, 0.0).unwrap();
        assert!(rung.t_total_s(q.dt_s()) > t_prev + tick_s);
        let out = sample_schedule_n(&q, 2, &params, Some(&prev)).unwrap();
        let PreviousFate::Repaired { t_total_s, .. } = out.previous else {
            panic!(
                "expected a repaired previous schedule, got {:?}",
                out.previous
            );
        };
        assert!(
            t_total_s <= t_prev + tick_s && out.t_total_s <= t_total_s,
            "previous {t_prev}, re-timed {t_total_s}, re-scheduled {}",
            out.t_total_s
        );
        validate_with_switch(&q, &out.schedule, 0.0).unwrap();
    }

    #[test]
    fn one_row_of_strategies_per_robot_count() {
        let row = |n| {
            let s = strategies(n);
            (s.bound, s.completion, s.staggered)
        };
        assert_eq!(row(1), (BoundBy::Fastest, CompleteBy::Nothing, false));
        assert_eq!(row(2), (BoundBy::Pair, CompleteBy::Pair, true));
        for n in 3..=tandem_realtime::MAX_ROBOTS {
            assert_eq!(
                row(n),
                (BoundBy::Many, CompleteBy::Nothing, true),
                "N = {n}"
            );
        }
    }
}
