//! Certified schedules: the exact margin-free optimum `T*₀` (a lower bound on every schedule of
//! Eq. 20) and a margin-aware completion that passes the whole of Eq. 20.
//!
//! # The margin-free problem
//! Drop constraint 5 (the margins) from Eq. 20 and what is left only depends on the runs of
//! equal confidence ([`Problem::runs`]). Both robots traverse the same chain: LC runs
//! `k = 0..m` of fixed duration `L_k = Σ ψ̇̄·Δt_s` (constraint 4) separated by HC gaps
//! `g = 0..=m` (gap 0 before the first LC run, gap `m` after the last, `[0, 0]` if absent) whose
//! duration can be anything in `[a_g, b_g] = [Σ ψ̇min·Δt_s, Σ ψ̇max·Δt_s]` (constraint 1: the
//! per-sample gradients of a run can be spread freely within their bounds). Robot 1 starts at
//! 0, robot 2 at `τ ∈ [0, |ψ_E1|]` (constraint 2), no two LC intervals of different robots may
//! overlap (constraint 3), and `T_total = max(|ψ_E1|, τ + |ψ_E2|)` (Eq. 13) is minimized. It is
//! a two-job shop on one machine (the operator) with minimum and maximum time lags between
//! consecutive operations of a job.
//!
//! **One interleaving.** Fix the *machine order*: which robot's LC run comes next, in time.
//! Then every constraint is a difference constraint `x_j ≥ x_i + w` (lags within a robot,
//! "the later run starts after the earlier ends" between consecutive runs of the order,
//! `0 ≤ τ ≤ |ψ_E1|`): a simple temporal network. Its earliest solution (longest paths from the
//! origin) is the least solution *in every variable at once*, hence the least `T_total` of
//! that order (`stn.rs`, Bellman–Ford; a positive cycle means the order is infeasible).
//!
//! **All interleavings, exactly** (`search.rs`). A dynamic program over states `(i, j, last)`:
//! robot 1 has placed `i` LC runs, robot 2 `j`, and `last` placed its run last (so the operator
//! is free when `last` leaves it). The future depends only on the two "free" times — `u`, when
//! robot 1 left its last LC run (or 0, its start), and `v`, when robot 2 left its own (or `τ`)
//! — and only through their difference, the lead `d` of the last robot over the other: every
//! future constraint is a difference of future times and these two. So the value of a state is
//! the function `d ↦` least free time of the last robot over all partial schedules reaching
//! the state with lead `d` (`+∞` where none does), and one state's function follows from its
//! two predecessors' (same robot again, or the other robot) by
//! - same robot, gap `[a, b]`, run `L`: `U'(y) = y + min { U(x) − x : x ∈ [y − b − L, y − a − L] }`;
//! - other robot: `U'(y) = y + min { V(x) : x ∈ [a + L − y, b + L − y] }` for `y ≥ L`;
//!
//! and the pointwise minimum of the two. Starting from the exact first states, every value
//! function is piecewise linear with slopes 0 and 1 (possibly discontinuous, on a union of
//! intervals), and both operations are a shift plus a sliding-window minimum of a function
//! whose pieces are non-increasing, which is the minimum of the shifted function and one
//! plateau per piece (`pl.rs`): exact, in time linear in the number of pieces. The least
//! `T_total` is the least value of the two final states plus the fastest tail `a_m`. It equals
//! the best earliest solution over all orders: every partial schedule is represented (no
//! relaxation), and nothing but the lead matters for the future. The constraint `τ ≤ |ψ_E1|`
//! is left out of the program: an order's earliest solution meets it anyway (if robot 2's
//! first run follows robot 1's last, it starts right after it, before robot 1 can end;
//! otherwise it ends before robot 1's last run starts) — the property test against all
//! orders (`tests/exact.rs`) checks it. The order is read back along the pieces' origins and
//! its times are the earliest solution of its network.
//!
//! Pruning keeps it fast on fragmented confidence (hundreds of one-sample LC islands): a robot
//! waiting in a gap must reach its next LC run within `b_g` (`d ≤ b_g`), and a piece is cut
//! where its value plus the least remaining work (the operator's remaining LC time plus the
//! tail, or the robot's own fastest rest) exceeds the incumbent (the fastest serial schedule).
//! A piece budget ([`ExactParams::max_pieces`]) bounds the work; past it the bound returned is
//! the simple one, `max(a_0 + 2·Σ L_k + a_m, fastest execution)` (the operator's LC time, with
//! the fastest head before and tail after), marked as not proven optimal.
//!
//! # Margin-aware completion
//! The optimum packs LC runs back to back, which the worst-case margin check
//! (`tandem_realtime::sufficient_margins`, Alg. 2) rejects: it simulates, from `τ`, the current
//! robot `c` rushing while LC and the previous robot `p` dragging while LC, and needs `c` to stay
//! one maximal step `M` (the largest step of any robot in one tick) short of its LC run until
//! `p` has left its own. [`certify`] therefore (`complete.rs`)
//! 1. re-solves the program with a clearance `δ` before every LC run that follows the other
//!    robot's (robot 2's first run needs none if robot 2 starts after robot 1's run ended, as
//!    the check accepts such pairs outright), shapes the HC speeds (below) and runs the check,
//!    growing `δ` geometrically from `2M` until it passes;
//! 2. then, on that order, bisects every pair's clearance at once between `M` and its current
//!    value, each pair judged by the check on the LC runs up to its own (later ones counted as
//!    HC), and keeps the result if the full check accepts it.
//!
//! Speed shaping within HC runs (`shape.rs`), by the global time at which a sample is entered:
//! right after the robot's own LC run it keeps that run's slow rate (it is the dragging robot
//! `p` there, and a robot scheduled fast right after its LC run drags even slower in the
//! check's rate window); in the last `20·M` before the other robot leaves an LC stretch it runs
//! at `ψ̇min`, so that as the responding robot `c` it can slow down as much as possible while
//! the pair is decided; elsewhere one speed level makes the run last as the times say, HC
//! samples kept at `F = ψ̇_E/ψ̇min` no larger than the largest `F` of an LC sample (so `M` does
//! not grow) unless the duration needs it.
//!
//! Every schedule returned passes [`crate::validate`] at its own tick (`Schedule::tick_s`);
//! when the completion finds nothing better, the caller's incumbent or the fastest serial
//! schedule is returned, with the same certificate.
//!
//! ```
//! use tandem_schedule::{ExactParams, Problem, certify, solve_exact, validate};
//!
//! // [LC, HC, LC] with gradients 1 in [0.5, 2], 10 samples each at 10 ms: LC runs of 0.1 s, an
//! // HC gap of [0.05, 0.2] s. Best: robot 1 LC, robot 2 LC, robot 1 LC, robot 2 LC, back to
//! // back, 0.4 s.
//! let conf: Vec<bool> = (0..30).map(|n| (10..20).contains(&n)).collect();
//! let p = Problem::new(conf, vec![1.0; 30], vec![0.5; 30], vec![2.0; 30], 0.01)?;
//! let free = solve_exact(&p, &ExactParams::default())?;
//! assert!(free.proven_optimal);
//! assert!((free.lower_bound_s - 0.4).abs() < 1e-9);
//! assert_eq!(free.order, vec![0, 1, 0, 1]);
//! let cert = certify(&p, &ExactParams::default(), None)?;
//! assert!(validate(&p, &cert.schedule).is_ok());
//! assert!(cert.t_total_s >= cert.lower_bound_s);
//! # Ok::<(), tandem_schedule::Error>(())
//! ```

mod build;
mod chain;
mod complete;
mod pl;
mod search;
mod shape;
mod stn;

use serde::{Deserialize, Serialize};

use crate::problem::Problem;
use crate::schedule::Schedule;
use crate::validate::validate;
use crate::{Error, Result};

/// Parameters of [`solve_exact`] and [`certify`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExactParams {
    /// Control tick (s) of the margin check (Alg. 2). `None` = the reference period `Δt_s`.
    /// Must be finite and > 0. Default: `None`.
    pub tick_s: Option<f64>,
    /// Largest number of value-function pieces the exact search may hold (memory ~48 bytes
    /// each); past it [`solve_exact`] returns the simple lower bound, not proven optimal. ≥ 1.
    /// Default: 4,000,000.
    pub max_pieces: usize,
    /// Largest number of margin checks (Alg. 2) the completion of [`certify`] may run. The
    /// fixture problem needs about 24 for per-pair clearances; 0 skips the completion. Default:
    /// 32.
    pub max_margin_checks: usize,
}

impl Default for ExactParams {
    fn default() -> Self {
        ExactParams {
            tick_s: None,
            max_pieces: 4_000_000,
            max_margin_checks: 32,
        }
    }
}

impl ExactParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field.
    pub fn validate(&self) -> Result<()> {
        if let Some(t) = self.tick_s
            && !(t.is_finite() && t > 0.0)
        {
            return Err(Error::BadParam {
                name: "tick_s",
                why: "must be finite and > 0",
            });
        }
        if self.max_pieces == 0 {
            return Err(Error::BadParam {
                name: "max_pieces",
                why: "must be ≥ 1",
            });
        }
        Ok(())
    }
}

/// Work counts of the exact search (identical for a problem whatever the thread count).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct SearchStats {
    /// Number of LC runs `m` per robot.
    pub lc_runs: usize,
    /// States `(i, j, last)` with a non-empty value function.
    pub states: usize,
    /// Value-function pieces created.
    pub pieces: usize,
}

/// The margin-free optimum (Eq. 20 constraints 1–4, Eq. 13) of [`solve_exact`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MarginFree {
    /// `T*₀` (s) when [`MarginFree::proven_optimal`], else a proven lower bound on it (and so
    /// on the `T_total` of every schedule satisfying Eq. 20).
    pub lower_bound_s: f64,
    /// Whether [`MarginFree::lower_bound_s`] is the exact optimum (the search finished).
    pub proven_optimal: bool,
    /// An optimal schedule when proven: it satisfies Eq. 20 constraints 1–4 and has
    /// `T_total = T*₀` (up to rounding); the margin check (constraint 5) usually rejects it.
    pub schedule: Option<Schedule>,
    /// Its machine order: the robot (0 or 1) of each LC run, in time order (`2m` entries).
    pub order: Vec<usize>,
    /// Work counts.
    pub stats: SearchStats,
}

/// Where a [`Certificate`]'s schedule comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum CertifiedSource {
    /// The margin-aware completion of the exact search.
    Completed,
    /// The incumbent passed to [`certify`] (e.g. the sampler's schedule).
    Incumbent,
    /// The fastest serial schedule ([`Problem::serial_schedule`]).
    Serial,
}

/// A schedule that satisfies every constraint of Eq. 20, with how far it can be from optimal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Certificate {
    /// The schedule; it passes [`crate::validate`] at its own tick (`Schedule::tick_s`).
    pub schedule: Schedule,
    /// Its `T_total` (Eq. 13), s.
    pub t_total_s: f64,
    /// A lower bound (s) on the `T_total` of every schedule satisfying Eq. 20: the margin-free
    /// optimum `T*₀` when [`Certificate::bound_is_optimum`].
    pub lower_bound_s: f64,
    /// Whether the bound is the proven margin-free optimum `T*₀`.
    pub bound_is_optimum: bool,
    /// `(T_total − bound)/bound`: the schedule is at most this much (relative) above optimal.
    pub gap: f64,
    /// Where the schedule comes from.
    pub source: CertifiedSource,
    /// Margin checks (Alg. 2) the completion ran.
    pub margin_checks: usize,
    /// Work counts of the exact search.
    pub stats: SearchStats,
}

/// Solves the margin-free problem exactly (see the [module docs](self)).
///
/// # Errors
/// [`Error::BadParam`] for invalid parameters.
pub fn solve_exact(problem: &Problem, params: &ExactParams) -> Result<MarginFree> {
    params.validate()?;
    let chain = chain::Chain::new(problem);
    Ok(margin_free(problem, &chain, params))
}

fn margin_free(problem: &Problem, chain: &chain::Chain, params: &ExactParams) -> MarginFree {
    let m = chain.n_lc();
    let zero = search::Clearance::zero(m);
    // The incumbent: the fastest serial schedule, 2 × the fastest execution (feasible for the
    // margin-free problem, so the optimum is never above it).
    let serial_s = 2.0 * chain.fastest_s();
    let (outcome, counts) = search::search(chain, &zero, serial_s, params.max_pieces);
    let stats = SearchStats {
        lc_runs: m,
        states: counts.states,
        pieces: counts.pieces,
    };
    let found = match outcome {
        search::Outcome::Done(found) => found,
        search::Outcome::OutOfBudget => None,
    };
    let exact = found.and_then(|f| {
        let times = stn::earliest(chain, &f.order, &zero)?;
        Some((f, times))
    });
    match exact {
        Some((f, times)) => MarginFree {
            lower_bound_s: f.t_total_s,
            proven_optimal: true,
            schedule: Some(build::uniform_schedule(
                problem,
                chain,
                &times,
                params.tick_s.unwrap_or(problem.dt_s()),
            )),
            order: f.order.iter().map(|&r| usize::from(r)).collect(),
            stats,
        },
        None => MarginFree {
            lower_bound_s: simple_bound(chain),
            proven_optimal: false,
            schedule: None,
            order: Vec::new(),
            stats,
        },
    }
}

/// `max(a_0 + 2·Σ L_k + a_m, fastest execution)` (s): the operator serves `2·Σ L_k` of LC time,
/// not before the fastest head and followed by at least the fastest tail; and each robot needs
/// its fastest execution.
fn simple_bound(chain: &chain::Chain) -> f64 {
    let m = chain.n_lc();
    let operator = if m == 0 {
        0.0
    } else {
        chain.gap_s[0].0 + 2.0 * chain.lc_s.iter().sum::<f64>() + chain.gap_s[m].0
    };
    operator.max(chain.fastest_s())
}

/// The margin-free schedule of one machine order: `order[q]` is the robot (0 or 1) whose LC
/// run comes `q`-th in time (each robot `m` times, `m` = number of LC runs). Its earliest event
/// times (see the [module docs](self)) with one speed factor per HC run; `None` if no schedule
/// has that order. The schedule satisfies Eq. 20 constraints 1–4; its `T_total` is the least of
/// all schedules with that order.
///
/// # Errors
/// [`Error::BadParam`] if `order` does not have `m` zeros and `m` ones.
pub fn earliest_schedule(problem: &Problem, order: &[usize]) -> Result<Option<Schedule>> {
    let chain = chain::Chain::new(problem);
    let m = chain.n_lc();
    let zeros = order.iter().filter(|&&r| r == 0).count();
    let ones = order.iter().filter(|&&r| r == 1).count();
    if zeros != m || ones != m || order.len() != 2 * m {
        return Err(Error::BadParam {
            name: "order",
            why: "must name robot 0 and robot 1 once per LC run each",
        });
    }
    let order: Vec<search::Robot> = order.iter().map(|&r| u8::from(r == 1)).collect();
    Ok(stn::earliest(&chain, &order, &search::Clearance::zero(m))
        .map(|t| build::uniform_schedule(problem, &chain, &t, problem.dt_s())))
}

/// A schedule satisfying every constraint of Eq. 20 with its certificate: the margin-free
/// lower bound `T*₀` ([`solve_exact`]) and the gap to it. The schedule is the best of the
/// margin-aware completion (see the [module docs](self)), `incumbent` (if it passes
/// [`crate::validate`] at the certificate's tick) and the fastest serial schedule; so it is never worse than
/// the incumbent.
///
/// Deterministic: the same problem and parameters give the same certificate whatever the
/// number of threads.
///
/// # Errors
/// [`Error::BadParam`] for invalid parameters; [`Error::NoFeasibleSchedule`] if nothing passes,
/// not even the serial schedule.
pub fn certify(
    problem: &Problem,
    params: &ExactParams,
    incumbent: Option<&Schedule>,
) -> Result<Certificate> {
    params.validate()?;
    let tick_s = params.tick_s.unwrap_or(problem.dt_s());
    let dt = problem.dt_s();
    let chain = chain::Chain::new(problem);
    let free = margin_free(problem, &chain, params);

    let serial = problem.serial_schedule(tick_s)?;
    let serial_violation = validate(problem, &serial).err();
    let mut best: Option<(Schedule, f64, CertifiedSource)> =
        serial_violation.is_none().then(|| {
            let t = serial.t_total_s(dt);
            (serial, t, CertifiedSource::Serial)
        });
    // The incumbent is re-checked at this certificate's tick (it may have been made for another).
    if let Some(inc) = incumbent {
        let inc = Schedule {
            tick_s,
            ..inc.clone()
        };
        if validate(problem, &inc).is_ok() {
            let t = inc.t_total_s(dt);
            if best.as_ref().is_none_or(|b| t <= b.1) {
                best = Some((inc, t, CertifiedSource::Incumbent));
            }
        }
    }
    let cap_s = best.as_ref().map_or(f64::INFINITY, |b| b.1);
    let mut completion = complete::Completion::new(problem, &chain, tick_s, params.max_pieces);
    if params.max_margin_checks > 0
        && let Some(done) = completion.run(cap_s, params.max_margin_checks)
        && best.as_ref().is_none_or(|b| done.t_total_s < b.1)
    {
        best = Some((done.schedule, done.t_total_s, CertifiedSource::Completed));
    }
    let Some((schedule, t_total_s, source)) = best else {
        return Err(Error::NoFeasibleSchedule {
            serial: serial_violation.expect("no incumbent means the serial schedule failed"),
        });
    };
    let lower_bound_s = free.lower_bound_s.min(t_total_s);
    Ok(Certificate {
        schedule,
        t_total_s,
        lower_bound_s,
        bound_is_optimum: free.proven_optimal,
        gap: (t_total_s - lower_bound_s) / lower_bound_s,
        source,
        margin_checks: completion.checks,
        stats: free.stats,
    })
}
