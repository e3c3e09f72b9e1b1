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
//! # N robots
//! For `N ≥ 3` robots (`many.rs`) the dynamic program's state, one lead, no longer suffices.
//! A depth-first branch and bound over machine orders places one LC run at a time (the
//! operator's next), keeping each node's earliest times by incremental longest paths over
//! the same difference constraints (a positive cycle: the order is infeasible). A node's times
//! are the least in every variable, so `max(latest end, operator free + LC time left + fastest
//! tail)` bounds every completion and prunes against the best found. Robots are
//! interchangeable, so their first LC runs come in robot order; children are tried earliest
//! start first, after a dive that puts robots about to overrun their HC gap first and stops at
//! its first leaf (the serial order if it finds none), so an order always exists. A node where
//! some robot's next run cannot go next is dead (it cannot go later either). Finished within
//! [`MAX_SEARCH_NODES`] nodes, its optimum is the certificate's bound; otherwise the bound is
//! the least bound of the nodes it left open, or [`operator_bound_s`] if that is higher
//! (docs/decisions.md, "The three-robot search: a dive that reaches a leaf and the open nodes'
//! bound (issue 38)"). With hold points the chain's gaps that
//! contain one are unbounded (capped at `N × fastest`), and the best order, with planned
//! dwells and release rules, is the scheduler's `Held` candidate for every `N`
//! (docs/decisions.md, "N robots in the margin-free search").
//!
//! # Margin-aware completion
//! The optimum packs LC runs back to back, which the worst-case margin check
//! (`tandem_realtime::sufficient_margins`, Alg. 2) rejects: it simulates, from `τ`, the current
//! robot `c` rushing while LC and the previous robot `p` dragging while LC, and needs `c` to stay
//! one maximal step `M` (the largest step of any robot in one tick) short of its LC run until
//! `p` has left its own. The completion (`complete.rs`) keeps that check as its only oracle:
//! `tandem_realtime::pair_slacks` runs the same simulation and reports, for every pair, how much
//! room `c` has left when `p` leaves (negative: the clearance missing). From there:
//! 1. **Clearances from the check.** An LC run `k` placed right after the other robot's run
//!    `j` gets a clearance `δ(j, k)` (the search's difference constraint "starts `δ` after the
//!    other's run ends"; one table for both robots, since both traverse the same chain and a
//!    pair and its mirror image need the same room; robot 2's first run needs none if robot 2
//!    starts after robot 1's run ended, as the check accepts such pairs outright). The search
//!    places the runs with these clearances (switching robots costs a clearance, so the order
//!    may change), the order's earliest times are shaped into speeds (below), the check reads
//!    every pair's slack, and each pair's clearance moves towards a slack of `M/10`: a secant
//!    step inside the bracket of the clearances seen failing and passing, raising failing
//!    pairs and, once all pass, lowering those with room to spare. The deficit of a later
//!    pair of the same role includes the lead carried over from an earlier failing one, so
//!    only the first failing pair of each role moves by its whole deficit per round, the
//!    others at most double. Pairs never tried start from the median clearance raised so far
//!    (the typical cost of a switch), so that with hundreds of LC islands the search does not
//!    run from one untried switch to the next. The best schedule whose pairs all pass is kept.
//! 2. **Speed shaping within HC runs** (`shape.rs`). A run's duration is fixed by the times;
//!    how it is spread over the run's samples decides how much lead the worst case builds.
//!    One speed factor per sample `u_i = u₀ + θ·(1 − 2i/(N − 1))` (clamped to `[0, 1]`, between
//!    `ψ̇min` and `ψ̇max`) with `u₀` set by the duration: at tilt `θ = 0` one factor for the
//!    whole run; at `θ > 0` slow first, fast last — slow early helps the robot, as `p`, follow
//!    the other robot rushing through the LC run this HC run spans, fast late gives it, as `c`,
//!    room to slow down while the other drags out of it. The tilt trades the two roles'
//!    leads and the best one is problem-dependent. (Edges of fixed speed next to the robot's
//!    own LC runs, `ψ̇min` before and slow after, are gone: they left the responding robot
//!    less room in the run's body, and late in the study no clearance passed; docs/decisions.md,
//!    "The margin-aware completion".)
//! 3. **Starts.** Iterations start cold (every clearance at `M`) at the tilts `θ ∈ {0, ¼, ½}`,
//!    and warm from a schedule that already passes — the previous schedule, and the sampler's
//!    winner once it is known — at its own clearances, no other pair allowed, so the search
//!    begins from that schedule's order and tightens it. Every start gets a few checks in
//!    parallel; the two most promising continue with the rest of the budget
//!    ([`ExactParams::max_margin_checks`]).
//!
//! 4. **With hold points** (two robots) the completion runs a second time on the chain with
//!    the problem's usable holds: a robot entering LC run `k` right after the other robot's
//!    run waits at the hold of gap `k` until that run has ended (the release rule
//!    `tandem_realtime::holds::release_rules` makes) and then travels to run `k` at its fastest
//!    speeds, so that pair's clearance is fixed at that travel and the check accepts it without
//!    a margin; the pairs without a hold iterate as above, on the margin check with holds,
//!    each step starting from the room the schedule kept between the pair (other lags may keep
//!    it further apart than its clearance). Robot 2 entering the first run after robot 1's,
//!    without a hold in gap 0, starts after that run ends (its start rule cannot be a dwell).
//!    The held runs' samples after the hold run fastest, the rest is spread before it and what
//!    the slowest speeds cannot fill is a planned dwell; the release rules' waits are planned
//!    too, so the candidate's `T_total` ([`crate::Source::Held`]) is what the cell does
//!    (docs/decisions.md, "Two robots with holds near their bound").
//!
//! Every schedule the scheduler returns passes [`crate::validate`] at its own tick
//! (`Schedule::tick_s`); the completion is one of its candidates ([`crate::sample_schedule`]),
//! beside the sampler and the previous or serial schedule, and the returned
//! [`crate::Outcome`] carries the bound and the gap.
//!
//! ```
//! use tandem_schedule::{
//!     ExactParams, Problem, SamplerBaselines, SamplerParams, Source, sample_schedule_with_baselines,
//!     solve_exact, validate,
//! };
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
//! // The completion alone (no sampled candidates): certified against the same bound.
//! let alone = SamplerBaselines::COMPLETION_ONLY;
//! let out = sample_schedule_with_baselines(&p, &SamplerParams::default(), &alone, None)?;
//! assert!(validate(&p, &out.schedule).is_ok());
//! assert!(out.bound_is_optimum && (out.lower_bound_s - 0.4).abs() < 1e-9);
//! assert!(out.t_total_s >= out.lower_bound_s);
//! assert!(matches!(out.source, Source::Completed | Source::Serial));
//! # Ok::<(), tandem_schedule::Error>(())
//! ```

mod build;
mod chain;
mod complete;
mod drag;
mod many;
mod pl;
mod search;
mod shape;
pub(crate) mod stn;

pub(crate) use build::dwelled;

use serde::{Deserialize, Serialize};

use crate::problem::Problem;
use crate::schedule::Schedule;
use crate::{Error, Result};

/// Parameters of the exact search ([`solve_exact`]) and of the margin-aware completion that
/// [`crate::sample_schedule`] runs beside the sampler (see the [module docs](self)).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ExactParams {
    /// Largest number of value-function pieces the exact search may hold (memory ~48 bytes
    /// each); past it the search returns the simple lower bound, not proven optimal. ≥ 1.
    /// Default: 4,000,000.
    pub max_pieces: usize,
    /// Largest number of margin checks (Alg. 2, ~1 ms each on the 9873-sample fixture
    /// problem) the completion may run per re-schedule (plus a quarter of it to refine the
    /// sampler's winner); 0 switches the completion off (the bound is still computed).
    /// Default: 24 (docs/decisions.md: the fixture and fragmented problems' gaps against the
    /// budget).
    pub max_margin_checks: usize,
}

impl Default for ExactParams {
    fn default() -> Self {
        ExactParams {
            max_pieces: 4_000_000,
            max_margin_checks: 24,
        }
    }
}

impl ExactParams {
    /// Checks the parameters.
    ///
    /// # Errors
    /// [`Error::BadParam`] naming the field.
    pub fn validate(&self) -> Result<()> {
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

/// Solves the margin-free problem exactly (see the [module docs](self)); the optimal schedule
/// carries the control tick `Δt_s`.
///
/// # Errors
/// [`Error::BadParam`] for invalid parameters.
pub fn solve_exact(problem: &Problem, params: &ExactParams) -> Result<MarginFree> {
    params.validate()?;
    Ok(margin_free(
        problem,
        &bound_chain(problem, 2),
        params.max_pieces,
        0.0,
    ))
}

/// [`solve_exact`] with the operator's switch time `switch_s` (s, ≥ 0): the margin-free
/// problem plus "an LC run of one robot starts at least `switch_s` after the other robot's
/// previous LC run ended" (consecutive runs of one robot need none), which every schedule that
/// [`crate::validate_with_switch`] accepts meets. The search is the same dynamic program with
/// the uniform clearance `switch_s` between the two robots' runs (the clearance the completion
/// already uses for its margins), from no incumbent. Its value is a lower bound on every such
/// schedule (docs/decisions.md, "The switch time in the scheduler's bounds (issue 41)"); it is marked
/// optimal, with its schedule, only when that schedule also meets `τ ≤ |ψ_E1|` (Eq. 20
/// constraint 2, which the program leaves out and which a switch time can break). Without LC
/// runs the bound is the fastest execution; past the piece budget it is
/// [`operator_bound_with_switch_s`] for two robots. `switch_s = 0` is [`solve_exact`].
///
/// # Errors
/// [`Error::BadParam`] for invalid parameters or a `switch_s` not finite and ≥ 0.
pub fn solve_exact_with_switch(
    problem: &Problem,
    params: &ExactParams,
    switch_s: f64,
) -> Result<MarginFree> {
    params.validate()?;
    check_switch(switch_s)?;
    Ok(margin_free(
        problem,
        &bound_chain(problem, 2),
        params.max_pieces,
        switch_s,
    ))
}

/// `Err` unless `switch_s` is finite and ≥ 0.
fn check_switch(switch_s: f64) -> Result<()> {
    if switch_s.is_finite() && switch_s >= 0.0 {
        Ok(())
    } else {
        Err(Error::BadParam {
            name: "switch_s",
            why: "must be finite and >= 0 (the operator's switch time in seconds; 0 for none)",
        })
    }
}

/// The chain the bound of `n_robots` robots is computed on: with the problem's usable hold
/// points an HC run that contains one has no upper duration bound
/// ([`chain::Chain::with_holds`], capped at the serial incumbent `N × fastest`, which no gap
/// of a better schedule exceeds), so `T*₀` is the optimum with holds; without them
/// [`chain::Chain::new`].
fn bound_chain(problem: &Problem, n_robots: usize) -> chain::Chain {
    let plain = chain::Chain::new(problem);
    if problem.usable_holds().is_empty() {
        return plain;
    }
    chain::Chain::with_holds(problem, n_robots as f64 * plain.fastest_s())
}

fn margin_free(
    problem: &Problem,
    chain: &chain::Chain,
    max_pieces: usize,
    switch_s: f64,
) -> MarginFree {
    let m = chain.n_lc();
    let zero = if switch_s > 0.0 {
        search::Clearance::uniform(switch_s, None)
    } else {
        search::Clearance::zero()
    };
    // The incumbent: the fastest serial schedule, 2 × the fastest execution (feasible for the
    // margin-free problem, so the optimum is never above it). With a switch time the serial
    // order may not be feasible (robot 1 ending and robot 2 starting low-confidence): none.
    let serial_s = if switch_s > 0.0 {
        f64::INFINITY
    } else {
        2.0 * chain.fastest_s()
    };
    let (outcome, counts) = search::search(chain, &zero, serial_s, max_pieces);
    let stats = SearchStats {
        lc_runs: m,
        states: counts.states,
        pieces: counts.pieces,
    };
    let found = match outcome {
        search::Outcome::Done(found) => found,
        search::Outcome::OutOfBudget => None,
    };
    // With a switch time the program's optimum may start robot 2 after robot 1's end: its
    // network relaxes constraint 2 by the start allowance at the schedule's tick `Δt_s` (what
    // `validate_with_operator` accepts; 0 without a switch time). Should the network still be
    // infeasible (robot 2 beyond the allowance), the search's value is the optimum of a
    // relaxation, so a lower bound, but neither a schedule nor proven.
    let allowance_s = crate::operator::start_allowance_s(problem, 2, problem.dt_s(), switch_s, 1.0);
    if switch_s > 0.0
        && let Some(f) = &found
        && stn::earliest_with_allowance(chain, &f.order, &zero, allowance_s).is_none()
    {
        return MarginFree {
            lower_bound_s: f.t_total_s.max(operator_bound_of(chain, 2, switch_s)),
            proven_optimal: false,
            schedule: None,
            order: f.order.iter().map(|&r| usize::from(r)).collect(),
            stats,
        };
    }
    let exact = found.and_then(|f| {
        let times = stn::earliest_with_allowance(chain, &f.order, &zero, allowance_s)?;
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
                problem.dt_s(),
            )),
            order: f.order.iter().map(|&r| usize::from(r)).collect(),
            stats,
        },
        None => MarginFree {
            lower_bound_s: operator_bound_of(chain, 2, switch_s),
            proven_optimal: false,
            schedule: None,
            order: Vec::new(),
            stats,
        },
    }
}

/// [`operator_bound_s`] of the chain of runs (for two robots the simple bound of
/// [`solve_exact`]), with the switch time `switch_s` ([`operator_bound_with_switch_s`]; 0: none,
/// the same float operations).
fn operator_bound_of(chain: &chain::Chain, n_robots: usize, switch_s: f64) -> f64 {
    let m = chain.n_lc();
    let operator = if m == 0 {
        0.0
    } else if switch_s > 0.0 {
        chain.gap_s[0].0
            + n_robots as f64 * chain.lc_s.iter().sum::<f64>()
            + (n_robots - 1) as f64 * switch_s
            + chain.gap_s[m].0
    } else {
        chain.gap_s[0].0 + n_robots as f64 * chain.lc_s.iter().sum::<f64>() + chain.gap_s[m].0
    };
    operator.max(chain.fastest_s())
}

/// The operator-limited lower bound (s, global time) on the `T_total` of every schedule of
/// `n_robots` robots that satisfies Eq. 20 constraints 1–4 on `problem` (so also of every
/// valid schedule): `max(a_0 + N·Σ_k L_k + a_m, fastest execution)`, where `L_k = Σ ψ̇̄·Δt_s`
/// is the duration of LC run `k` (constraint 4 fixes it), `a_0` the fastest head (the HC
/// samples before the first LC sample at `ψ̇min`, constraint 1) and `a_m` the fastest tail.
///
/// **Why it is a lower bound.** With `m ≥ 1` LC runs, each of the `N` robots traverses
/// every LC run once, so the schedule has `N·m` LC intervals of total length `N·Σ L_k`.
/// Constraint 3 makes them pairwise disjoint, so they cover `N·Σ L_k` seconds of global time.
/// None starts before `a_0`: every robot starts at `τ_i ≥ 0` (constraint 2) and spends at
/// least `a_0` on its head. So the interval that ends last ends at `T_end ≥ a_0 + N·Σ L_k`,
/// and its robot then still has to traverse at least the tail after the last LC run,
/// `≥ a_m` (what follows any LC run contains the tail), before it ends, which is `≤ T_total`
/// (Eq. 13). And robot 1 starts at 0 and needs its fastest execution. For `N = 1` the
/// bound is the optimum (the fastest execution); for `N = 2` it is the simple bound of
/// [`solve_exact`], never above `T*₀`. (Durations are the clock's sums; constraint 4 holds
/// up to `tol::GRADIENT_REL`, so a valid schedule can be shorter by that relative rounding.)
///
/// # Errors
/// [`Error::Realtime`] (`RobotCount`) for `n_robots` outside `1..=MAX_ROBOTS`.
pub fn operator_bound_s(problem: &Problem, n_robots: usize) -> Result<f64> {
    crate::problem::check_robot_count(n_robots)?;
    Ok(operator_bound_of(
        &chain::Chain::new(problem),
        n_robots,
        0.0,
    ))
}

/// [`operator_bound_s`] with the operator's switch time `switch_s` (s, ≥ 0):
/// `max(a_0 + N·Σ_k L_k + (N − 1)·δ + a_m, fastest execution)` with `m ≥ 1` LC runs.
///
/// **Why it is a lower bound** on every schedule that [`crate::validate_with_switch`] accepts.
/// Order the `N·m` LC intervals of such a schedule in time (they are disjoint, constraint 3).
/// Every robot has intervals, so grouping consecutive intervals of one robot gives at least
/// `N` groups and `N − 1` places where the robot changes; at each, the next interval starts at
/// least `δ` after the previous one ends (the scheduled switch time), and these gaps are
/// disjoint from the intervals and from each other. So the last interval ends at or after
/// `a_0 + N·Σ L_k + (N − 1)·δ`, and its robot still needs the fastest tail `a_m`, as in
/// [`operator_bound_s`]. (Consecutive runs of one robot need no switch time.)
///
/// # Errors
/// [`Error::BadParam`] for `n_robots` outside `1..=MAX_ROBOTS` or a `switch_s` not finite and
/// ≥ 0.
pub fn operator_bound_with_switch_s(
    problem: &Problem,
    n_robots: usize,
    switch_s: f64,
) -> Result<f64> {
    crate::problem::check_robot_count(n_robots)?;
    check_switch(switch_s)?;
    Ok(operator_bound_of(
        &chain::Chain::new(problem),
        n_robots,
        switch_s,
    ))
}

/// The certificate's lower bound with the operator's switch time `switch_s` (s, ≥ 0) for
/// `n_robots` robots: one robot the fastest execution, two the margin-free search with the
/// switch time ([`solve_exact_with_switch`]), three or more the maximum of the `k`-robot
/// bounds (`k = 2…N`), each the branch and bound over machine orders with the switch time, or
/// [`operator_bound_with_switch_s`] past its node budget; never below the bound at
/// `switch_s = 0` (a schedule that keeps the switch time keeps none). A lower bound on the `T_total` of
/// every schedule that [`crate::validate_with_switch`] accepts (docs/decisions.md, "The switch
/// time in the scheduler's bounds (issue 41)"); `switch_s = 0` gives the certificate's bound of
/// [`crate::sample_schedule_n`].
///
/// # Errors
/// [`Error::BadParam`] for invalid parameters, `n_robots` outside `1..=MAX_ROBOTS` or a
/// `switch_s` not finite and ≥ 0.
pub fn margin_free_bound(
    problem: &Problem,
    n_robots: usize,
    params: &ExactParams,
    switch_s: f64,
) -> Result<MarginFree> {
    crate::problem::check_robot_count(n_robots)?;
    params.validate()?;
    check_switch(switch_s)?;
    let mut bound = match n_robots {
        1 => operator_bound(problem, 1),
        2 => bound_switch(problem, params, switch_s),
        _ => bound_many_switch(problem, n_robots, params, switch_s),
    };
    if switch_s > 0.0 && n_robots >= 2 {
        // Every schedule that keeps `δ` keeps 0, so the bound without the switch time bounds
        // it too. The searches with `δ` can end looser than the one without (a random two-robot
        // problem of 10 samples: 0.1111 s at δ = 0.022 s against 0.1123 s at 0, the
        // regression of `tests/switch.rs`), so the larger of the two is the bound, and a
        // search result below it is no proven optimum.
        let plain = margin_free_bound(problem, n_robots, params, 0.0)?.lower_bound_s;
        if plain > bound.lower_bound_s {
            bound.lower_bound_s = plain;
            bound.proven_optimal = false;
        }
    }
    Ok(bound)
}

/// A two-robot lower bound that charges every switch between the robots' LC runs its least
/// margin ([`switch_charged_bound`]); all times in seconds of global (schedule-clock) time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SwitchCharged {
    /// The bound (s): no schedule of two robots that [`crate::validate`] accepts at the tick
    /// it was computed for has a smaller `T_total` (up to `tol::BOUND_REL`). Never below
    /// [`SwitchCharged::margin_free_s`].
    pub lower_bound_s: f64,
    /// The margin-free bound of [`solve_exact`] (s): `T*₀` when the search finished.
    pub margin_free_s: f64,
    /// The least room (s) every switch was charged: `M = tick · max(1, largest ψ̇̄/ψ̇min of an
    /// LC sample)`, the least step of the margin check (0 when [`SwitchCharged::charged`] is
    /// `false`).
    pub charge_s: f64,
    /// The largest room (s) one switch was charged: [`SwitchCharged::charge_s`] for
    /// [`switch_charged_bound`], the largest entry of the drag-lead table for
    /// [`drag_charged_bound`] (0 when not charged).
    #[serde(default)]
    pub max_charge_s: f64,
    /// Whether the switches were charged: `false` for a problem with usable hold points (its
    /// schedules are checked by the lead bound on legs with release rules, for which the
    /// argument below is not made), without LC runs, or when a search ran out of its budget;
    /// the bound is then [`SwitchCharged::margin_free_s`].
    pub charged: bool,
}

/// The margin-free bound of two robots ([`solve_exact`]) raised by what the margin check
/// (Eq. 20 constraint 5, `tandem_realtime::sufficient_margins`) makes every switch cost at
/// control tick `tick_s` (s): the same dynamic program with a clearance of `M` (schedule-clock
/// s, `tick_s · max(1, largest ψ̇̄/ψ̇min of an LC sample)`) between an LC run of one robot and
/// the other robot's LC run right before it, except robot 2's first run after a run of robot 1
/// that ended by robot 2's start (docs/decisions.md, "A bound that charges every switch its
/// least margin (issue 38)").
///
/// **Why it is a lower bound** on every two-robot schedule without usable holds that the
/// margin check accepts at `tick_s`. Take two consecutive LC intervals of different robots, `p`
/// ending at `T_p` and `c` starting at `T_c`. The check either accepts the pair before
/// simulating it — only when `p` left it by the later robot's start, which makes it robot 1's
/// run before robot 2's first — or simulates both clocks from their starts and accepts only
/// after a step with `t_p ≥ T_p + ε` and `t_c + M_pc < T_c − ε` (`ε > 0`, `M_pc` the larger
/// largest step of the two robots, `≥ M` since an LC sample runs at `ψ̇̄` and `ψ̇min ≤ ψ̇̄`).
/// The simulated lead `t_c − t_p` starts at 0 (or at a step when `c` is the earlier robot)
/// and never becomes negative: with rates `S ≤ 1 ≤ F`, `c` rushing leaves `p` at or behind it,
/// `p` dragging leaves `c` at or ahead of it, and `HIGH-CONF` lands both on one pace no
/// further than the nearer robot's fastest reach, which the robot behind cannot overshoot. So
/// `T_c > T_p + M + 2ε`: every switch but the exception keeps a clearance of at least `M`, and
/// the schedule is a feasible point of the margin-free problem with that clearance, whose
/// optimum (the search is exact for any clearance table; `τ ≤ |ψ_E1|` is left out, a
/// relaxation) is at most its `T_total`. The margin-free bound bounds it too, so the maximum
/// of the two does.
///
/// # Errors
/// [`Error::BadParam`] for invalid parameters or a `tick_s` not finite and > 0.
pub fn switch_charged_bound(
    problem: &Problem,
    params: &ExactParams,
    tick_s: f64,
) -> Result<SwitchCharged> {
    params.validate()?;
    if !(tick_s.is_finite() && tick_s > 0.0) {
        return Err(Error::BadParam {
            name: "tick_s",
            why: "must be finite and > 0 (the control tick in seconds)",
        });
    }
    let free = bound_switch(problem, params, 0.0).lower_bound_s;
    let plain = SwitchCharged {
        lower_bound_s: free,
        margin_free_s: free,
        charge_s: 0.0,
        max_charge_s: 0.0,
        charged: false,
    };
    let chain = chain::Chain::new(problem);
    if !problem.usable_holds().is_empty() || chain.n_lc() == 0 {
        return Ok(plain);
    }
    // The check's step is `tick · F` with `F` at the schedule's gradient of an LC sample, the
    // mean up to `tol::GRADIENT_REL`: charge that much less.
    let charge_s =
        crate::choose::max_step_s(problem, tick_s) * (1.0 - tandem_realtime::tol::GRADIENT_REL);
    let clear = search::Clearance::uniform(charge_s, Some(0.0));
    match search::search(&chain, &clear, f64::INFINITY, params.max_pieces).0 {
        search::Outcome::Done(Some(found)) => Ok(SwitchCharged {
            lower_bound_s: found.t_total_s.max(free),
            margin_free_s: free,
            charge_s,
            max_charge_s: charge_s,
            charged: true,
        }),
        _ => Ok(plain),
    }
}

/// The two-robot bound of [`switch_charged_bound`] with every switch charged the *drag lead*
/// on top of the check's step: per pair `(j, k)` of LC runs (robot `p` leaves run `j`, the
/// other robot `c` enters run `k` next on the operator) the least room `T_c − T_p` (s,
/// schedule clock) that any placement of the two robots the check accepts keeps, as a
/// clearance table of the same exact search (docs/decisions.md, "Two robots: a bound that
/// charges the drag lead (issue 38)"). [`SwitchCharged::charge_s`] is the step `M` as there;
/// [`SwitchCharged::max_charge_s`] the largest entry of the table.
///
/// **Why it is a lower bound** on every two-robot schedule without usable holds that
/// [`crate::validate`] accepts at `tick_s` (`h`). Notation: sample `n` is planned at
/// `d_n = ψ̇_E[n]·Δt` (s) with `ψ̇min ≤ ψ̇_E ≤ ψ̇max` on HC samples (Eq. 20 constraint 1) and
/// `ψ̇_E = ψ̇̄` on LC samples (constraint 4); `fast(u, v)`, `slow(u, v)`, `mean(u, v)` sum
/// `ψ̇min·Δt`, `ψ̇max·Δt`, `ψ̇̄·Δt` over the reference between positions `u` and `v`. The slow
/// rate of Eq. 17 is `S = ψ̇_E/ψ̇max`, so a clock moving at `S·h` per tick through sample `n`
/// spends `ψ̇max[n]·Δt` real seconds per sample: its *slow time*, fixed by the problem.
/// Take a pair `(p, c)` the check accepts by simulation (not the exception) and an entry point
/// `a`, the clock of `p` at position `q` of run `j` (ending at `e_j`, `T_p`).
/// 1. While `p`'s window holds its LC samples and `c`'s holds none, the two-robot simulation
///    (`tandem_realtime::margins`, fixes 1–4) has one branch, `p` dragging: `p` moves
///    `S_p^w·h` with `S_p^w` the least `S` of its window, `c` responds (Eq. 18) by at least
///    `S_c^w·h`, the largest `S` of its window. Both steps are at most `M` (`M` ≥ every step)
///    and the windows reach `M + ε` around the clocks, so every sample a step touches has
///    `S_p ≥ S_p^w` (p) and `S_c ≤ S_c^w` (c): `p` spends at least, `c` at most, the slow
///    time of what it crosses. Over the ticks from the last one with `p`'s clock at or before
///    `a` (at most one step, `≤ h`, before `a`) to the exit (`p`'s clock past `T_p`), `p`
///    crosses `[q, e_j]`, slow time `R = slow(q, e_j)`, so `c` crosses at least `R` of slow
///    time: from `y` to its exit position `x` with `y ≤ Y_R(x)` (`slow(Y_R(x), x) = R`).
/// 2. The lead `t_c − t_p` is never negative (the argument of [`switch_charged_bound`]), so
///    `c`'s clock at the first of those ticks is at least `a − h`, and at acceptance
///    `t_c + M < T_c − ε` with `M ≥ M_lo`. Hence `T_c ≥ a − h + planned(y, g₁)` with
///    `planned(y, g₁) ≥ fast(Y_R(x), x) + max(M_lo, fast(x, g₁))` (`g₁` run `k`'s start), and
///    `T_c − T_p ≥ Φ_k(R) − (1 + rel)·mean(q, e_j) − h`, `Φ_k` the least of that over `x` in
///    gap `k` (`drag::least_before`).
/// 3. If `c`'s window still held its previous run `k − 1` at the first tick, the one branch
///    begins later, when `c` is at most `2M + ε` past that run's end:
///    `T_c − T_p ≥ fast(gap k) − 2M − ε − (1 + rel)·mean(q, e_j) − h` (`M ≤ M_hi`, every
///    sample at its largest fast rate). The lesser of 2 and 3 holds for every `a`: the room is
///    at least the largest over `a`.
/// 4. `k = 0` with robot 2 as `c`: if robot 2 starts at `τ` inside run `j` (before `τ` the
///    rule does not apply, after `T_p` it is the exception), the simulation begins at `τ`
///    with both clocks there, so 1–2 hold from `a = τ` only, and robot 2's head takes at
///    least `fast(head)`: `T_c − T_p ≥ max(Φ₀(R(τ)), fast(head)) − (1 + rel)·mean(τ, e_j) − h`,
///    bounded on each cell of entry points by its least value there; the pair's room is the
///    lesser of that over every cell and the bound of 1–3 (robot 2 started before run `j`, or
///    robot 1 as `c`).
///
/// So every accepted schedule is a feasible point of the margin-free problem with this table
/// (and the step `M` at least, [`switch_charged_bound`]), and the exact search's optimum (a
/// relaxation, `τ ≤ |ψ_E1|` left out) is at most its `T_total`. Not claimed with usable holds
/// (then `charged = false` and the bound is the margin-free one).
///
/// # Errors
/// [`Error::BadParam`] for invalid parameters or a `tick_s` not finite and > 0.
pub fn drag_charged_bound(
    problem: &Problem,
    params: &ExactParams,
    tick_s: f64,
) -> Result<SwitchCharged> {
    let step = switch_charged_bound(problem, params, tick_s)?;
    if !step.charged {
        return Ok(step);
    }
    let chain = chain::Chain::new(problem);
    let rel = tandem_realtime::tol::GRADIENT_REL;
    let (gmean, gmin, gmax) = (problem.grad_mean(), problem.grad_min(), problem.grad_max());
    let fastest_rate = (0..problem.n_ref())
        .map(|n| {
            if problem.conf()[n] {
                gmax[n] / gmin[n]
            } else {
                gmean[n] / gmin[n]
            }
        })
        .fold(1.0, f64::max);
    // The check's `ε` (`4·CLOCK_REL·scale`), for schedules within ten times the slowest
    // serial execution (a longer one is above the bound anyway).
    let eps_s = 4.0 * tandem_realtime::tol::CLOCK_REL * (20.0 * chain.slowest_s() + tick_s + 1.0);
    let dp = drag::DragParams {
        step_lo_s: step.charge_s,
        step_hi_s: tick_s * fastest_rate * (1.0 + rel) + eps_s,
        tick_s,
        rel,
    };
    let room = drag::drag_room(problem, &chain, &dp);
    let max_charge_s = room.values().fold(step.charge_s, |a, &b| a.max(b));
    let clear = search::Clearance {
        pairs: room
            .into_iter()
            .map(|(pair, r)| (pair, r.max(step.charge_s)))
            .collect(),
        ..search::Clearance::uniform(step.charge_s, Some(0.0))
    };
    match search::search(&chain, &clear, f64::INFINITY, params.max_pieces).0 {
        search::Outcome::Done(Some(found)) => Ok(SwitchCharged {
            lower_bound_s: found.t_total_s.max(step.lower_bound_s),
            max_charge_s,
            ..step
        }),
        _ => Ok(step),
    }
}

/// The certificate of the scheduler for `n_robots ≠ 2` robots: [`operator_bound_s`], marked
/// as the optimum for one robot (the fastest execution is then both bound and schedule).
pub(crate) fn operator_bound(problem: &Problem, n_robots: usize) -> MarginFree {
    let chain = chain::Chain::new(problem);
    MarginFree {
        lower_bound_s: operator_bound_of(&chain, n_robots, 0.0),
        proven_optimal: n_robots == 1,
        schedule: None,
        order: Vec::new(),
        stats: SearchStats {
            lc_runs: chain.n_lc(),
            ..SearchStats::default()
        },
    }
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
    Ok(stn::earliest(&chain, &order, &search::Clearance::zero())
        .map(|t| build::uniform_schedule(problem, &chain, &t, problem.dt_s())))
}

/// The margin-free bound of `problem` (see [`solve_exact`]) with the switch time `switch_s`
/// (s, ≥ 0; 0: none, [`solve_exact`]'s float operations; see [`solve_exact_with_switch`]).
pub(crate) fn bound_switch(problem: &Problem, params: &ExactParams, switch_s: f64) -> MarginFree {
    margin_free(
        problem,
        &bound_chain(problem, 2),
        params.max_pieces,
        switch_s,
    )
}

/// Node budget of the `N`-robot search (see "N robots" in the [module docs](self)): the
/// fixture problem needs 25–76 nodes for `N = 3…8`; the budget bounds the work on fragmented
/// confidence (docs/decisions.md, "N robots in the margin-free search").
pub const MAX_SEARCH_NODES: usize = 200_000;

/// The margin-free bound of `n_robots ≥ 3` robots (see "N robots" in the [module docs](self)):
/// the branch and bound over machine orders on the chain with the problem's usable holds; when
/// it finishes within [`MAX_SEARCH_NODES`] nodes the bound is the optimum `T*₀` (with holds,
/// if any), else the larger of the operator-limited bound ([`operator_bound_s`]) and the least
/// bound of the nodes the search left open (`many::ManyOutcome::lower_bound_s`: every order
/// better than the best found lies below one of them), both lower bounds on `T*₀`. The
/// schedule is the best order found (with planned dwells at holds), proven or not; `order` its
/// robots in time order.
///
/// With the switch time `switch_s` (s, ≥ 0; 0: none) the search places a switch's runs
/// `switch_s` apart ([`many::search_with_switch`]) and the fallback is
/// [`operator_bound_with_switch_s`].
fn bound_n_switch(problem: &Problem, n_robots: usize, switch_s: f64) -> MarginFree {
    let chain = bound_chain(problem, n_robots);
    let mut plain = operator_bound(problem, n_robots);
    if switch_s > 0.0 {
        plain.lower_bound_s = operator_bound_of(&chain::Chain::new(problem), n_robots, switch_s);
    }
    let out = many::search_with_switch(&chain, n_robots, f64::INFINITY, MAX_SEARCH_NODES, switch_s);
    let (proven, nodes) = (out.proven, out.nodes);
    let stats = SearchStats {
        states: nodes,
        ..plain.stats
    };
    // The open nodes' bound of an unfinished search (`many::ManyOutcome::lower_bound_s`), a
    // lower bound on the optimum like the operator bound: the larger of the two.
    let kept = plain.lower_bound_s.max(out.lower_bound_s);
    let Some(f) = out.found else {
        return MarginFree {
            lower_bound_s: kept,
            stats,
            ..plain
        };
    };
    let gaps: Vec<Vec<f64>> = (0..n_robots).map(|r| f.times.gaps_s(&chain, r)).collect();
    let schedule = build::gap_schedule(
        problem,
        &chain,
        &gaps,
        f.times.start_s[1..].to_vec(),
        problem.dt_s(),
    );
    MarginFree {
        lower_bound_s: if proven {
            f.t_total_s.max(plain.lower_bound_s)
        } else {
            kept
        },
        proven_optimal: proven,
        schedule: Some(schedule),
        order: f.order,
        stats,
    }
}

/// A room-aware candidate order of `n_robots ≥ 3` robots with the switch time `switch_s`
/// (s, > 0): [`many::search_with_room`] on the chain with the problem's usable holds, where every
/// LC run `k ≥ 1` whose HC gap before it has no usable hold (`Chain::gap_hold` is `None`) is
/// guarded with the extra room `extra_s` (s): a switch into it from run `j` needs the robot's
/// fastest arrival there (its previous run's end plus the gap's `a_k`) at least `δ + extra_s`
/// after run `j` ends. Its best order below `cap_s` (s) within `max_nodes` nodes as a schedule
/// (one speed factor per HC gap, the rest of a gap as a dwell at its hold, as the margin-free
/// optimum's), with the control tick `tick_s` (s); `None` if it found none. Never a bound.
///
/// **Why** (docs/decisions.md, "Three robots at δ ≥ 1 s: a room-aware order (issue 41)"): a
/// robot whose approach to its stretch has no hold cannot wait there by a dwell and a release
/// rule; the margin check's lead bound lets a worst-case operator, with a third robot setting the
/// pace, bring it through that approach as if at its fastest, so the room its switch needs grows
/// with the wait planned in the approach, and no clearance on the optimum's order provides it
/// when that approach must also cover other robots' stretches (a positive cycle).
pub(crate) fn room_aware_many(
    problem: &Problem,
    n_robots: usize,
    switch_s: f64,
    extra_s: f64,
    cap_s: f64,
    max_nodes: usize,
    tick_s: f64,
) -> Option<Schedule> {
    if switch_s <= 0.0 || n_robots < 3 {
        return None;
    }
    let chain = bound_chain(problem, n_robots);
    let guard: Vec<Option<f64>> = (0..chain.n_lc())
        .map(|k| {
            (k >= 1 && chain.gap_hold[k].is_none())
                .then(|| extra_s - chain.lc_s[k - 1] - chain.gap_s[k].0)
        })
        .collect();
    // Each switch planned one control tick longer than `δ`: a dwell at a hold ends at a tick
    // start, so a stretch after one may start up to a tick later than the order's times.
    let out = many::search_with_room(
        &chain,
        n_robots,
        cap_s,
        max_nodes,
        switch_s + tick_s,
        &guard,
    );
    let f = out.found?;
    let gaps: Vec<Vec<f64>> = (0..n_robots).map(|r| f.times.gaps_s(&chain, r)).collect();
    Some(build::gap_schedule(
        problem,
        &chain,
        &gaps,
        f.times.start_s[1..].to_vec(),
        tick_s,
    ))
}

/// The certificate's bound for `n_robots ≥ 3` robots, never below the bound of fewer robots:
/// `B(N) = max(own(N), B(N − 1))` with `own(k)` the `k`-robot search's bound ([`bound_n_switch`]) and
/// `B(2)` the two-robot margin-free bound ([`bound_switch`]); the schedule, order and counts are
/// `own(N)`'s, and it is marked optimal only when `own(N)` is proven and not exceeded.
///
/// **Why it is a lower bound.** Take any schedule of `N` robots that satisfies Eq. 20
/// constraints 1–4 (with holds: with any dwells at usable holds) and keep its robots `1..k`
/// (their warps, dwells and start offsets). Constraints 1 and 4 are per robot; constraint 2
/// bounds `τ_i` by the robots before `i` only; constraint 3 forbids overlaps between pairs of
/// robots, and a subset of pairwise disjoint intervals is pairwise disjoint. So the `k` robots
/// form a schedule of the same problem, and its `T_total`, the latest of fewer ends, is not
/// above the `N`-robot one. Every lower bound on `k`-robot schedules is therefore one on
/// `N`-robot schedules, and so is the maximum of them. (The searches cap gaps with a hold at
/// `k × fastest`; a `k`-robot schedule with a longer gap lasts longer than `k × fastest`, the
/// serial schedule, which no margin-free optimum exceeds, so the cap loses nothing.) Hence
/// `B(N + 1) ≥ B(N)` by construction, where the searches alone are not monotone: the
/// `N`-robot search may run out of its node budget where the `(N − 1)`-robot one finished,
/// leaving the operator-limited bound, lower than the proven `(N − 1)`-robot optimum.
///
/// With the switch time `switch_s` (s, ≥ 0; 0: none): the same maximum over `k = 2…N`
/// of the bounds with the switch time (a subset of the robots of a schedule that keeps the
/// switch time keeps it too: any two LC intervals of different robots are at least `switch_s`
/// apart, whichever robots are kept).
pub(crate) fn bound_many_switch(
    problem: &Problem,
    n_robots: usize,
    params: &ExactParams,
    switch_s: f64,
) -> MarginFree {
    let mut below = bound_switch(problem, params, switch_s).lower_bound_s;
    for k in 3..n_robots {
        below = below.max(bound_n_switch(problem, k, switch_s).lower_bound_s);
    }
    let own = bound_n_switch(problem, n_robots, switch_s);
    if below > own.lower_bound_s {
        // A proven `N`-robot optimum is never below the `(N − 1)`-robot one but by the
        // rounding of the two searches' sums.
        let rounding = below <= own.lower_bound_s * (1.0 + tandem_realtime::tol::BOUND_REL);
        MarginFree {
            lower_bound_s: below,
            proven_optimal: own.proven_optimal && rounding,
            ..own
        }
    } else {
        own
    }
}

/// The held completion (`complete::Completion::held`) of a problem with usable hold points
/// at control tick `tick_s` (s): the best schedule with planned dwells and release rules it
/// finds that passes the margin check and beats `cap_s` (s), with at most `budget` margin
/// checks; with the number of checks spent. `(None, 0)` without usable holds. With the
/// switch time `switch_s` (s, ≥ 0; 0: none, the same float operations) see
/// [`complete::Completion::with_switch`].
pub(crate) fn held_completion(
    problem: &Problem,
    params: &ExactParams,
    tick_s: f64,
    cap_s: f64,
    budget: usize,
    switch_s: f64,
) -> (Option<complete::Completed>, usize) {
    if problem.usable_holds().is_empty() || budget == 0 {
        return (None, 0);
    }
    let chain = bound_chain(problem, 2);
    complete::Completion::held(problem, &chain, tick_s, params.max_pieces)
        .with_switch(switch_s)
        .run(cap_s, budget, true, &[])
}

/// The margin-aware completion (see the [module docs](self)) at control tick `tick_s` (s):
/// the best schedule it finds that passes the margin check and beats `cap_s` (s), with at
/// most `budget` margin checks, from every clearance at `M` when `cold` and from the
/// clearances of each schedule of `warm`; with the number of checks spent. With the switch
/// time `switch_s` (s, ≥ 0; 0: none, the same float operations) every clearance includes it
/// and the slacks are the margin check's with it ([`complete::Completion::with_switch`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn completion(
    problem: &Problem,
    params: &ExactParams,
    tick_s: f64,
    cap_s: f64,
    budget: usize,
    cold: bool,
    warm: &[&Schedule],
    switch_s: f64,
) -> (Option<complete::Completed>, usize) {
    let chain = chain::Chain::new(problem);
    complete::Completion::new(problem, &chain, tick_s, params.max_pieces)
        .with_switch(switch_s)
        .run(cap_s, budget, cold, warm)
}
