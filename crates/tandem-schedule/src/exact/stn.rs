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
struct Edge {
    from: usize,
    to: usize,
    w: f64,
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
/// every variable at once, so it also minimizes `T_total`.
pub(crate) fn earliest(chain: &Chain, order: &[Robot], clear: &Clearance) -> Option<Times> {
    let m = chain.n_lc();
    if order.len() != 2 * m || order.iter().filter(|&&r| r == 0).count() != m {
        return None;
    }
    let plain = solve(chain, order, clear, false);
    if clear.after_start.is_none() {
        return plain;
    }
    let early = solve(chain, order, clear, true);
    match (plain, early) {
        (Some(a), Some(b)) => Some(if b.t_total_s() < a.t_total_s() { b } else { a }),
        (a, b) => a.or(b),
    }
}

fn solve(chain: &Chain, order: &[Robot], clear: &Clearance, after_start: bool) -> Option<Times> {
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
    edges.push(Edge {
        from: TAU,
        to: end(0),
        w: 0.0,
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
            edges.push(Edge {
                from: lc(pr, pk),
                to: lc(r, k),
                w,
            });
        }
        prev = Some((r, k));
    }
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
        for e in &edges {
            let cand = x[e.from] + e.w;
            if cand > x[e.to] {
                if e.to == ORIGIN {
                    return None;
                }
                x[e.to] = cand;
                changed = true;
            }
        }
    }
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
