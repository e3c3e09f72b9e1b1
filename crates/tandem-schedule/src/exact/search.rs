//! The exact search over interleavings: a dynamic program over `(i, j, last)` whose value
//! functions are piecewise linear in the lead `d` (see the module docs of [`super`]).

use std::collections::BTreeMap;

use super::chain::Chain;
use super::pl::{self, Origin, Piece, Step};

/// Robot index in a machine order (0 = robot 1, 1 = robot 2).
pub(crate) type Robot = u8;

/// Clearances of the search (s): an LC run `k` placed right after the other robot's LC run `j`
/// on the operator must start [`Clearance::between`]`(j, k)` after that run ends (0 for the
/// margin-free problem). The table is the same for both robots: the two robots traverse the
/// same chain, and a pair and its mirror image (robots swapped) need the same room.
/// `after_start`: robot 2's first LC run needs no clearance from a robot-1 run that ended at
/// least this long before robot 2 started (`Some(ε)`), mirroring the margin check's rule that
/// such pairs cannot overlap; `None`: no such exception.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Clearance {
    /// Clearance (s) of the pairs `(j, k)` listed; [`Clearance::base`] for the others.
    pub(crate) pairs: BTreeMap<(usize, usize), f64>,
    /// Clearance (s) of every pair not in [`Clearance::pairs`].
    pub(crate) base: f64,
    pub(crate) after_start: Option<f64>,
    /// Release rules (s), per LC run `k` (empty: none): `Some(c)` fixes the clearance of
    /// every pair `(j, k)` at `c` whatever [`Clearance::pairs`] says. With hold points
    /// (`complete.rs`, the held completion) a robot entering run `k` right after the other
    /// robot's run waits at the hold of gap `k` until that run has ended (a release rule,
    /// `tandem_realtime::holds::release_rules`), then travels to run `k`: `c` is that travel
    /// at the fastest speeds; `+∞` for a run the robot entering it cannot wait for (gap 0 without
    /// a hold: only robot 2's start may wait, by the `after_start` exception).
    pub(crate) rules: Vec<Option<f64>>,
}

impl Clearance {
    /// No clearance at all: the margin-free problem.
    pub(crate) fn zero() -> Clearance {
        Clearance::uniform(0.0, None)
    }

    /// Clearance `base_s` (s) between every two runs, with the exception `after_start`.
    pub(crate) fn uniform(base_s: f64, after_start: Option<f64>) -> Clearance {
        Clearance {
            pairs: BTreeMap::new(),
            base: base_s,
            after_start,
            rules: Vec::new(),
        }
    }

    /// Clearance (s) before LC run `k` placed right after the other robot's LC run `j`.
    pub(crate) fn between(&self, j: usize, k: usize) -> f64 {
        if let Some(&Some(rule)) = self.rules.get(k) {
            return rule;
        }
        self.pairs.get(&(j, k)).copied().unwrap_or(self.base)
    }

    /// Whether run `k`'s clearance is fixed by a release rule ([`Clearance::rules`]).
    pub(crate) fn is_rule(&self, k: usize) -> bool {
        matches!(self.rules.get(k), Some(Some(_)))
    }

    /// Per LC run `k ∈ 0..m`, the least clearance it can need after any run of the other robot.
    fn least_before(&self, m: usize) -> Vec<f64> {
        let mut least = vec![self.base; m];
        for (&(_, k), &v) in &self.pairs {
            if k < m {
                least[k] = least[k].min(v);
            }
        }
        for (k, rule) in self.rules.iter().enumerate().take(m) {
            if let Some(v) = rule {
                least[k] = *v;
            }
        }
        least
    }
}

/// What the search found.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Found {
    /// Least `T_total` (s) over all interleavings, exact when `complete`.
    pub(crate) t_total_s: f64,
    /// The machine order reaching it: which robot places each LC run, in time order.
    pub(crate) order: Vec<Robot>,
}

/// Outcome of [`search`].
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Outcome {
    /// The optimum (no schedule beats `cap`, the incumbent, when `None`).
    Done(Option<Found>),
    /// The piece budget ran out.
    OutOfBudget,
}

/// Counts of one search.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Counts {
    pub(crate) states: usize,
    pub(crate) pieces: usize,
}

/// Index of state `(i, j, last)` in the flat tables.
fn sidx(m: usize, i: usize, j: usize, last: usize) -> usize {
    ((i * (m + 1)) + j) * 2 + last
}

/// The search over the chain `chain` with clearances `clear`, keeping only schedules with
/// `T_total ≤ cap` (s), stopping after `budget` pieces.
pub(crate) fn search(
    chain: &Chain,
    clear: &Clearance,
    cap: f64,
    budget: usize,
) -> (Outcome, Counts) {
    let m = chain.n_lc();
    let mut counts = Counts::default();
    if m == 0 {
        let t = chain.fastest_s();
        let found = (t <= cap).then(|| Found {
            t_total_s: t,
            order: Vec::new(),
        });
        return (Outcome::Done(found), counts);
    }
    let l = &chain.lc_s;
    let gap = &chain.gap_s;
    let tail_a = gap[m].0;
    // rest_lc[k]: Σ L over runs k..m; rest_robot[k]: fastest from the end of run k − 1
    // (gaps k..=m and runs k..m).
    let mut rest_lc = vec![0.0; m + 1];
    let mut rest_robot = vec![gap[m].0; m + 1];
    for k in (0..m).rev() {
        rest_lc[k] = rest_lc[k + 1] + l[k];
        rest_robot[k] = rest_robot[k + 1] + l[k] + gap[k].0;
    }
    let slowest = chain.slowest_s();
    let tol = 1e-9 * (1.0 + slowest);
    let cap = cap + tol;
    // Largest value a state may keep: T ≥ value + rest, rest from the machine and the robot.
    // Largest value (free time of the last robot) and largest free time of the other robot
    // (value − d) a state may keep: T ≥ value + rest of the operator's LC time and tail,
    // T ≥ value + the last robot's fastest rest, T ≥ (value − d) + the other's fastest rest.
    let caps = |i: usize, j: usize, last: usize| {
        let (mine, other) = if last == 0 { (i, j) } else { (j, i) };
        let machine = rest_lc[mine] + rest_lc[other] + tail_a;
        (cap - machine.max(rest_robot[mine]), cap - rest_robot[other])
    };

    let least_before = clear.least_before(m);
    let n_states = (m + 1) * (m + 1) * 2;
    let mut span: Vec<(usize, usize)> = vec![(0, 0); n_states];
    let mut arena: Vec<Piece> = Vec::new();
    let tau_max = slowest.min(cap);

    for sum in 1..=2 * m {
        for i in sum.saturating_sub(m)..=sum.min(m) {
            let j = sum - i;
            for last in 0..2 {
                // State (i, j, last): `last` placed its LC run k = (i or j) − 1 last.
                let (mine, other) = if last == 0 { (i, j) } else { (j, i) };
                if mine == 0 {
                    continue;
                }
                let k = mine - 1;
                // Predecessors: (same robot before, other robot before); skip unreachable states.
                let pred = if last == 0 { (i - 1, j) } else { (i, j - 1) };
                let same_n = if mine >= 2 {
                    span[sidx(m, pred.0, pred.1, last)].1
                } else {
                    0
                };
                let cross_n = if other >= 1 {
                    span[sidx(m, pred.0, pred.1, 1 - last)].1
                } else {
                    0
                };
                if same_n == 0 && cross_n == 0 && !(mine == 1 && other == 0) {
                    continue;
                }
                let (a, b) = gap[k];
                let (lo_a, lo_b) = (a + l[k], b + l[k]);
                // The clearance after the other robot's last run (when it placed one).
                let delta = if other >= 1 {
                    clear.between(other - 1, k)
                } else {
                    0.0
                };
                let mut f: Vec<Piece> = Vec::new();
                if mine == 1 && other == 0 {
                    f = initial(last, a, b, l[k], tau_max);
                }
                // Same robot placed its previous run: U'(y) = y + min_{x ∈ [y−B, y−A]} (U(x) − x).
                if mine >= 2 {
                    let p = if last == 0 { (i - 1, j) } else { (i, j - 1) };
                    let (s, n) = span[sidx(m, p.0, p.1, last)];
                    if n > 0 {
                        let mut w = arena[s..s + n].to_vec();
                        pl::add_linear(&mut w, -1.0);
                        let mut g = pl::slide_min(&w, lo_a, lo_b, false, Step::Same);
                        pl::add_linear(&mut g, 1.0);
                        f = pl::min_of(&f, &g);
                    }
                }
                // The other robot placed its run last: U'(y) = y + min_{x ∈ [A−y, B−y]} V(x),
                // y ≥ L + δ.
                if other >= 1 {
                    let p = if last == 0 { (i - 1, j) } else { (i, j - 1) };
                    let (s, n) = span[sidx(m, p.0, p.1, 1 - last)];
                    let pred = &arena[s..s + n];
                    let g = match clear.after_start {
                        // Robot 2's first run (x = u − τ): no clearance from a robot-1 run
                        // that ended at least ε before robot 2 started.
                        Some(eps) if last == 1 && mine == 1 => {
                            let early = pl::restrict(pred, f64::NEG_INFINITY, -eps, f64::INFINITY);
                            let late = pl::restrict(pred, -eps, f64::INFINITY, f64::INFINITY);
                            pl::min_of(
                                &cross(&early, lo_a, lo_b, l[k]),
                                &cross(&late, lo_a, lo_b, l[k] + delta),
                            )
                        }
                        _ => cross(pred, lo_a, lo_b, l[k] + delta),
                    };
                    f = pl::min_of(&f, &g);
                }
                // Domain: the waiting robot must still reach its next run in time.
                let hi = if other < m {
                    let wait_b = gap[other].1;
                    if other == 0 {
                        wait_b
                    } else {
                        wait_b - least_before[other]
                    }
                } else {
                    f64::INFINITY
                };
                let (value_cap, other_cap) = caps(i, j, last);
                let f = pl::restrict(&f, f64::NEG_INFINITY, hi, value_cap);
                let f = pl::restrict_lagging(&f, other_cap);
                counts.states += usize::from(!f.is_empty());
                counts.pieces += f.len();
                if counts.pieces > budget {
                    return (Outcome::OutOfBudget, counts);
                }
                span[sidx(m, i, j, last)] = (arena.len(), f.len());
                arena.extend_from_slice(&f);
            }
        }
    }

    // The best final state, then back along the origins.
    let mut best: Option<(f64, usize, f64)> = None;
    for last in 0..2 {
        let (s, n) = span[sidx(m, m, m, last)];
        for p in &arena[s..s + n] {
            let v = p.min_value();
            if best.is_none_or(|b| v < b.0) {
                let y = if p.at_lo <= p.at_hi() { p.lo } else { p.hi };
                best = Some((v, last, y));
            }
        }
    }
    let Some((value, last, y)) = best else {
        return (Outcome::Done(None), counts);
    };
    let mut order = Vec::with_capacity(2 * m);
    let (mut i, mut j, mut last, mut y) = (m, m, last, y);
    loop {
        let (s, n) = span[sidx(m, i, j, last)];
        let Some((_, piece)) = nearest(&arena[s..s + n], y, tol) else {
            break;
        };
        order.push(last as Robot);
        if last == 0 {
            i -= 1;
        } else {
            j -= 1;
        }
        match piece.origin.step {
            Step::Start => break,
            Step::Same => {}
            Step::Cross => last = 1 - last,
        }
        y = piece.origin.pred(y);
    }
    order.reverse();
    let found = Found {
        t_total_s: value + tail_a,
        order,
    };
    (Outcome::Done(Some(found)), counts)
}

/// The least value of `f` at `y`, or, if no piece is within `tol`, at the nearest piece.
fn nearest(f: &[Piece], y: f64, tol: f64) -> Option<(f64, &Piece)> {
    pl::value_at(f, y, tol).or_else(|| {
        f.iter()
            .min_by(|p, q| dist(p, y).total_cmp(&dist(q, y)))
            .map(|p| (p.at(y.clamp(p.lo, p.hi)), p))
    })
}

fn dist(p: &Piece, y: f64) -> f64 {
    (p.lo - y).max(y - p.hi).max(0.0)
}

/// Cross transition: `y + min_{x ∈ [a − y, b − y]} pred(x)` for `y ≥ y_min`.
/// An infinite `y_min` (a pair a release rule forbids) gives the empty function.
fn cross(pred: &[Piece], a: f64, b: f64, y_min: f64) -> Vec<Piece> {
    if pred.is_empty() || y_min == f64::INFINITY {
        return Vec::new();
    }
    let r = pl::reflect(pred);
    let mut g = pl::slide_min(&r, a, b, true, Step::Cross);
    pl::add_linear(&mut g, 1.0);
    pl::restrict(&g, y_min, f64::INFINITY, f64::INFINITY)
}

/// The first state's value function: robot `last` places its first LC run (duration `l`,
/// head gap `[a, b]`) before the other robot places any.
///
/// Robot 1 first (`last = 0`): `u = s + l` with `s ∈ [a, b]`, lead `d = u − τ` with
/// `0 ≤ τ ≤ τ_max`, so `U(d) = max(a + l, d)` for `d ≤ b + l`. Robot 2 first: `v = t + l`,
/// `t ∈ [τ + a, τ + b]`, lead over robot 1's start `d = v`, `V(d) = d` for
/// `a + l ≤ d ≤ τ_max + b + l`.
fn initial(last: usize, a: f64, b: f64, l: f64, tau_max: f64) -> Vec<Piece> {
    let mut f = Vec::new();
    if last == 0 {
        let lo = -tau_max + a + l;
        if lo < a + l {
            f.push(Piece {
                lo,
                hi: a + l,
                at_lo: a + l,
                slope: 0.0,
                origin: Origin::START,
            });
        }
        if b > a {
            f.push(Piece {
                lo: a + l,
                hi: b + l,
                at_lo: a + l,
                slope: 1.0,
                origin: Origin::START,
            });
        } else if f.is_empty() {
            f.push(Piece {
                lo: a + l,
                hi: a + l,
                at_lo: a + l,
                slope: 0.0,
                origin: Origin::START,
            });
        }
    } else {
        f.push(Piece {
            lo: a + l,
            hi: tau_max + b + l,
            at_lo: a + l,
            slope: 1.0,
            origin: Origin::START,
        });
    }
    f
}
