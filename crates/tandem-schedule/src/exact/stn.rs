//! Earliest times of one interleaving: a simple temporal network (difference constraints)
//! solved by longest paths.

use super::chain::Chain;
use super::search::{Clearance, Robot};

/// Event times (s, global time) of a two-robot schedule on a [`Chain`].
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Times {
    /// `τ`: robot 2's start.
    pub(crate) tau_s: f64,
    /// Start of each LC run, per robot.
    pub(crate) lc_start_s: [Vec<f64>; 2],
    /// End of each robot.
    pub(crate) end_s: [f64; 2],
}

impl Times {
    /// `T_total` (Eq. 13).
    pub(crate) fn t_total_s(&self) -> f64 {
        self.end_s[0].max(self.end_s[1])
    }

    /// Duration (s) of each HC gap `g ∈ 0..=m` of robot `r`.
    pub(crate) fn gaps_s(&self, chain: &Chain, r: usize) -> Vec<f64> {
        let start = if r == 0 { 0.0 } else { self.tau_s };
        let starts = &self.lc_start_s[r];
        let mut out = Vec::with_capacity(chain.n_lc() + 1);
        let mut free = start;
        for (&s, &l) in starts.iter().zip(&chain.lc_s) {
            out.push(s - free);
            free = s + l;
        }
        out.push(self.end_s[r] - free);
        out
    }
}

/// One difference constraint `x[to] ≥ x[from] + w`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Edge {
    pub(crate) from: usize,
    pub(crate) to: usize,
    pub(crate) w: f64,
}

/// The earliest times of the machine order `order` (robot per LC run in time order, `m` of
/// each) with clearances `clear`, or `None` if the order is infeasible.
///
/// Variables: the origin (robot 1's start, pinned at 0), `τ`, both robots' ends and the starts
/// of all LC runs. Constraints: each robot's HC gaps within `[a_g, b_g]` (minimum and maximum
/// time lags between consecutive events of one robot), `0 ≤ τ ≤ |ψ_E1|` (Eq. 20 constraint 2)
/// and, for consecutive runs in `order`, the later starts after the earlier ends (plus the
/// clearance when the robots differ; with `clear.after_start = Some(ε)`, robot 2's first run
/// may instead have `τ ≥ end + ε`, and the better of the two is kept). The earliest solution
/// (longest paths from the origin; a positive cycle means infeasible) is the least solution in
/// every variable at once, so it also minimizes `T_total`. A positive cycle found with exact
/// comparisons is re-checked ignoring gains within rounding (`relax_tolerance`), so a cycle
/// of weight 0 (a rigid HC run) never reads as positive.
pub(crate) fn earliest(chain: &Chain, order: &[Robot], clear: &Clearance) -> Option<Times> {
    earliest_with_allowance(chain, order, clear, 0.0)
}

/// [`earliest`] with Eq. 20 constraint 2 relaxed by the start allowance `allowance_s` (s,
/// ≥ 0): `0 ≤ τ ≤ |ψ_E1| + A`, as [`crate::validate_with_operator`] relaxes it
/// ([`crate::start_allowance_s`]; docs/decisions.md, "A schedule always exists with a switch
/// time: constraint 2 relaxed (issue 41)"). With a switch time the margin-free optimum may
/// start robot 2 after robot 1's end (a task that ends and starts low-confidence), which the
/// printed constraint makes infeasible. `A = 0` is [`earliest`], the same float operations.
pub(crate) fn earliest_with_allowance(
    chain: &Chain,
    order: &[Robot],
    clear: &Clearance,
    allowance_s: f64,
) -> Option<Times> {
    let m = chain.n_lc();
    if order.len() != 2 * m || order.iter().filter(|&&r| r == 0).count() != m {
        return None;
    }
    let plain = solve(chain, order, clear, false, allowance_s);
    if clear.after_start.is_none() {
        return plain;
    }
    let early = solve(chain, order, clear, true, allowance_s);
    match (plain, early) {
        (Some(a), Some(b)) => Some(if b.t_total_s() < a.t_total_s() { b } else { a }),
        (a, b) => a.or(b),
    }
}

fn solve(
    chain: &Chain,
    order: &[Robot],
    clear: &Clearance,
    after_start: bool,
    allowance_s: f64,
) -> Option<Times> {
    let m = chain.n_lc();
    const ORIGIN: usize = 0;
    const TAU: usize = 1;
    let end = |r: usize| 2 + r;
    let lc = |r: usize, k: usize| 4 + r * m + k;
    let n = 4 + 2 * m;
    let mut edges: Vec<Edge> = Vec::with_capacity(8 * m + 8);
    let mut lag = |from: usize, to: usize, lo: f64, hi: f64| {
        edges.push(Edge { from, to, w: lo });
        edges.push(Edge {
            from: to,
            to: from,
            w: -hi,
        });
    };
    for r in 0..2 {
        let start = if r == 0 { ORIGIN } else { TAU };
        let mut prev = (start, 0.0);
        for k in 0..m {
            let (a, b) = chain.gap_s[k];
            lag(prev.0, lc(r, k), prev.1 + a, prev.1 + b);
            prev = (lc(r, k), chain.lc_s[k]);
        }
        let (a, b) = chain.gap_s[m];
        lag(prev.0, end(r), prev.1 + a, prev.1 + b);
    }
    edges.push(Edge {
        from: ORIGIN,
        to: TAU,
        w: 0.0,
    });
    // `τ ≤ |ψ_E1| + A`: `end_1 ≥ τ − A` (`A = 0`: the printed constraint, weight `0.0`).
    edges.push(Edge {
        from: TAU,
        to: end(0),
        w: if allowance_s > 0.0 { -allowance_s } else { 0.0 },
    });
    let mut next = [0usize; 2];
    let mut prev: Option<(usize, usize)> = None;
    for &robot in order {
        let r = usize::from(robot);
        let k = next[r];
        next[r] += 1;
        if let Some((pr, pk)) = prev {
            let end_prev = chain.lc_s[pk];
            let w = if pr == r {
                end_prev
            } else if after_start && r == 1 && k == 0 {
                let eps = clear.after_start.unwrap_or(0.0);
                edges.push(Edge {
                    from: lc(pr, pk),
                    to: TAU,
                    w: end_prev + eps,
                });
                end_prev
            } else {
                end_prev + clear.between(pk, k)
            };
            if w == f64::INFINITY {
                // A pair a release rule forbids (`Clearance::rules`).
                return None;
            }
            edges.push(Edge {
                from: lc(pr, pk),
                to: lc(r, k),
                w,
            });
        }
        prev = Some((r, k));
    }
    // Exact comparisons first: when they converge, the earliest solution to the last bit.
    // Their verdict "positive cycle" is re-checked with gains within rounding ignored.
    let x = match longest_paths(&edges, n, 0.0) {
        Some(x) => x,
        None => longest_paths(&edges, n, relax_tolerance(&edges, n))?,
    };
    if x.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some(Times {
        tau_s: x[TAU],
        lc_start_s: [
            (0..m).map(|k| x[lc(0, k)]).collect(),
            (0..m).map(|k| x[lc(1, k)]).collect(),
        ],
        end_s: [x[end(0)], x[end(1)]],
    })
}

/// Longest paths from the origin (variable 0, pinned at 0) over the `n` variables by
/// Bellman–Ford, relaxing an edge only for a gain above `eps` (s); `None` on a positive cycle
/// (a relaxation still happening in round `n + 1`, or one that would move the origin).
pub(crate) fn longest_paths(edges: &[Edge], n: usize, eps: f64) -> Option<Vec<f64>> {
    const ORIGIN: usize = 0;
    let mut x = vec![f64::NEG_INFINITY; n];
    x[ORIGIN] = 0.0;
    let mut changed = true;
    let mut rounds = 0;
    while changed {
        changed = false;
        rounds += 1;
        if rounds > n + 1 {
            return None;
        }
        for e in edges {
            let cand = x[e.from] + e.w;
            if cand > x[e.to] + eps {
                if e.to == ORIGIN {
                    return None;
                }
                x[e.to] = cand;
                changed = true;
            }
        }
    }
    Some(x)
}

/// The gain (s) below which the re-check of a "positive cycle" verdict ignores a relaxation:
/// `4·n·ε_f64·Σ|w|` for `n` variables and edge weights `w`.
///
/// **Why.** A cycle of weight 0 in exact arithmetic can have a positive weight of a few
/// rounding errors in floating point. A rigid HC run (`a_g = b_g`, one sample with
/// `ψ̇min = ψ̇max`) gives the pair `x_k ≥ x_j + w`, `x_j ≥ x_k − w`, and `(x + w) − w` can
/// exceed `x` by an ulp; exact comparisons then relax around the cycle round after round
/// and report a feasible order as infeasible. Proptest found such problems (about one in
/// 2,400 of `tests/exact.rs`'s generator): every order, the optimal one included, read as
/// infeasible, so the search's optimum was not proven.
///
/// **Bound.** Suppose some value is still raised by more than `eps` in round `n + 1`. Follow
/// each relaxation back to the one that set the value it used (that value changed after the
/// edge was last examined, so at most one round earlier): a chain of at least `n` edges, so a
/// variable repeats, and the cycle between its two visits raised it by more than `eps`: its
/// floating-point weight exceeds `eps`. A simple cycle has at most `n` edges; each sum along
/// it is rounded by at most `ε_f64/2` of the largest value, at most `Σ|w|` (a value is a sum
/// of weights along a path), so its floating-point weight exceeds its exact weight by at most
/// `n·ε_f64·Σ|w| < eps`. So a network without a positive cycle in exact arithmetic converges
/// within `n` rounds, while a cycle of exact weight above `2·eps` is still caught. At
/// convergence every constraint holds up to `eps` (1.1e-10 to 1.6e-10 s on the study's
/// networks of 120 to 180 LC runs per robot, ≈ 1e-12 of their `T_total`), far inside the
/// schedule tolerances (`tol::GRADIENT_REL`, `tol::CLOCK_REL`: 1e-9), and the schedule is
/// built with its gradients clamped into their bounds.
///
/// The exact comparisons run first because their solution, when they converge, is exact to
/// the last bit: always relaxing with `eps` moved 10 of the study's network solutions by at
/// most 4e-13 s, and that, through the margin check and the supervised samples, changed
/// one trial's outcome (docs/decisions.md, "Certified schedules", "Rounding in the
/// earliest-times network").
pub(crate) fn relax_tolerance(edges: &[Edge], n: usize) -> f64 {
    let scale: f64 = edges.iter().map(|e| e.w.abs()).sum();
    4.0 * n as f64 * f64::EPSILON * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two LC runs of 1 s around an HC gap of `[0.5, 2]` s, no head or tail.
    fn lhl() -> Chain {
        Chain {
            lc_s: vec![1.0, 1.0],
            gap_s: vec![(0.0, 0.0), (0.5, 2.0), (0.0, 0.0)],
            lc_ref: vec![(0, 1), (2, 3)],
            gap_ref: vec![(0, 0), (1, 2), (3, 3)],
            gap_hold: vec![None; 3],
        }
    }

    #[test]
    fn alternation_by_hand() {
        // 1 2 1 2: robot 1 LC [0, 1), robot 2 LC [1, 2) (τ = 1), robot 1's gap 1 s → LC
        // [2, 3), robot 2's gap 1 s → LC [3, 4): T_total 4.
        let c = lhl();
        let t = earliest(&c, &[0, 1, 0, 1], &Clearance::zero()).unwrap();
        assert_eq!(t.tau_s, 1.0);
        assert_eq!(t.lc_start_s, [vec![0.0, 2.0], vec![1.0, 3.0]]);
        assert_eq!(t.t_total_s(), 4.0);
        assert_eq!(t.gaps_s(&c, 1), vec![0.0, 1.0, 0.0]);
        // Clearance 0.25 before every run: robot 2 at 1.25, robot 1's second run at 2.5,
        // robot 2's at 3.75: 4.75.
        let clear = Clearance::uniform(0.25, None);
        let t = earliest(&c, &[0, 1, 0, 1], &clear).unwrap();
        assert_eq!(t.t_total_s(), 4.75);
    }

    #[test]
    fn rigid_runs_do_not_read_as_a_positive_cycle() {
        // The chain of a problem proptest found: a rigid head (`a_0 = b_0`) and a rigid gap
        // between LC runs 0 and 1. Robot 1's first LC start is pinned by `x ≥ 0 + a_0` and
        // `0 ≥ x − a_0`, and by the rigid lag to its second run; in floating point
        // `(x + w) − w` exceeded `x` by one ulp, and the exact comparison declared every order
        // infeasible. Serial order by hand: robot 1's last LC run ends at
        // `a_0 + 0.015 + 0.005 + 0.03 + 0.003 + 0.015 = a_0 + 0.068`, robot 2 starts `a_0`
        // before that (τ = 0.068) and runs its fastest, `a_0 + 0.0755`.
        let a0 = 0.006749386554742199;
        let c = Chain {
            lc_s: vec![0.015, 0.03, 0.015],
            gap_s: vec![(a0, a0), (0.005, 0.005), (0.003, 0.01), (0.0075, 0.025)],
            lc_ref: vec![(1, 4), (5, 11), (13, 16)],
            gap_ref: vec![(0, 1), (4, 5), (11, 13), (16, 21)],
            gap_hold: vec![None; 4],
        };
        let t = earliest(&c, &[0, 0, 0, 1, 1, 1], &Clearance::zero()).unwrap();
        assert!((t.tau_s - 0.068).abs() < 1e-15, "{}", t.tau_s);
        assert!((t.t_total_s() - (0.068 + a0 + 0.0755)).abs() < 1e-15);
        // The rigid gaps keep their length up to the tolerance.
        for r in 0..2 {
            let g = t.gaps_s(&c, r);
            assert!(
                (g[0] - a0).abs() < 1e-15 && (g[1] - 0.005).abs() < 1e-15,
                "{g:?}"
            );
        }
        // Robot 2 inside robot 1's rigid stretch is still infeasible: 1 2 1 ... needs robot
        // 2's 0.015 s run in robot 1's 0.005 s gap.
        assert!(earliest(&c, &[0, 1, 0, 0, 1, 1], &Clearance::zero()).is_none());
    }

    #[test]
    fn a_small_positive_cycle_is_still_a_positive_cycle() {
        // x1 ≥ x0 + 1 and x0 ≥ x1 − (1 − 1e-9): a cycle of weight 1e-9 s, far above the
        // tolerance (4·2·ε_f64·2 ≈ 3.6e-15 s), is infeasible with and without it; with
        // weight 0 (the pair of a rigid lag) it is solved, x1 = 1.
        let edge = |from, to, w| Edge { from, to, w };
        let pos = [edge(0, 1, 1.0), edge(1, 0, -(1.0 - 1e-9))];
        assert!(relax_tolerance(&pos, 2) < 1e-14);
        assert_eq!(longest_paths(&pos, 2, 0.0), None);
        assert_eq!(longest_paths(&pos, 2, relax_tolerance(&pos, 2)), None);
        let zero = [edge(0, 1, 1.0), edge(1, 0, -1.0)];
        assert_eq!(
            longest_paths(&zero, 2, relax_tolerance(&zero, 2)),
            Some(vec![0.0, 1.0])
        );
    }

    #[test]
    fn the_start_allowance_relaxes_constraint_2() {
        // One LC run of 1 s, no head or tail; clearance 2 s (a switch time): robot 2's run
        // starts at 1 + 2 = 3 s, so τ = 3 s, 2 s after robot 1's end (|ψ_E1| = 1 s).
        let c = Chain {
            lc_s: vec![1.0],
            gap_s: vec![(0.0, 0.0), (0.0, 0.0)],
            lc_ref: vec![(0, 1)],
            gap_ref: vec![(0, 0), (1, 1)],
            gap_hold: vec![None; 2],
        };
        let clear = Clearance::uniform(2.0, None);
        // The printed constraint `τ ≤ |ψ_E1|`: infeasible; so with an allowance below 2 s.
        assert!(earliest(&c, &[0, 1], &clear).is_none());
        assert!(earliest_with_allowance(&c, &[0, 1], &clear, 1.9).is_none());
        // Allowance 2 s or more: τ = 3 s, robot 1 ends at 1 s, T_total 4 s.
        for a in [2.0, 2.5] {
            let t = earliest_with_allowance(&c, &[0, 1], &clear, a).unwrap();
            assert_eq!((t.tau_s, t.end_s, t.t_total_s()), (3.0, [1.0, 4.0], 4.0));
        }
        // Allowance 0 is `earliest` (the lhl orders, to the bit).
        let l = lhl();
        let z = Clearance::zero();
        let (a, b) = (
            earliest(&l, &[0, 0, 1, 1], &z).unwrap(),
            earliest_with_allowance(&l, &[0, 0, 1, 1], &z, 0.0).unwrap(),
        );
        assert_eq!((a.tau_s.to_bits(), a.end_s), (b.tau_s.to_bits(), b.end_s));
    }

    #[test]
    fn infeasible_orders() {
        // 1 1 2 2: robot 1's runs at 0 and 1.5, robot 2 starts when robot 1 ends (τ = 2.5 =
        // |ψ_E1|), its second run at 4: T_total 5.
        let c = lhl();
        let t = earliest(&c, &[0, 0, 1, 1], &Clearance::zero()).unwrap();
        assert_eq!((t.tau_s, t.end_s), (2.5, [2.5, 5.0]));
        // Robot 2's gap cannot hold both of robot 1's runs (1 + 0.5 + 1 > 2): 2 1 1 2 fails.
        assert!(earliest(&c, &[1, 0, 0, 1], &Clearance::zero()).is_none());
        // Wrong counts.
        assert!(earliest(&c, &[0, 0, 0, 1], &Clearance::zero()).is_none());
    }
}
