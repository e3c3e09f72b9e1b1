//! The margin-free problem for `N ≥ 3` robots: a branch and bound over machine orders (see
//! "N robots" in the module docs of [`super`]).

use super::chain::Chain;

/// What [`search`] found: the best machine order within its node budget and its earliest
/// times.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ManyFound {
    /// `T_total` (s) of the best order found: the optimum when [`ManyFound::proven`].
    pub(crate) t_total_s: f64,
    /// Whether the search finished, so that no schedule of Eq. 20 constraints 1–4 (with the
    /// chain's gap ranges) is shorter than [`ManyFound::t_total_s`].
    pub(crate) proven: bool,
    /// The times, robots relabelled by start (robot 0 starts at 0).
    pub(crate) times: ManyTimes,
    /// The robot of each LC run in time order (after the relabelling).
    pub(crate) order: Vec<usize>,
    /// Search nodes visited.
    pub(crate) nodes: usize,
}

/// Event times (s, global time) of `N` robots on one chain.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ManyTimes {
    /// Start of each robot (robot 0 at 0).
    pub(crate) start_s: Vec<f64>,
    /// Start of each LC run `k`, per robot.
    pub(crate) lc_start_s: Vec<Vec<f64>>,
    /// End of each robot.
    pub(crate) end_s: Vec<f64>,
}

impl ManyTimes {
    /// Duration (s) of each HC gap `g ∈ 0..=m` of robot `r`.
    pub(crate) fn gaps_s(&self, chain: &Chain, r: usize) -> Vec<f64> {
        let mut out = Vec::with_capacity(chain.n_lc() + 1);
        let mut free = self.start_s[r];
        for (&s, &l) in self.lc_start_s[r].iter().zip(&chain.lc_s) {
            out.push(s - free);
            free = s + l;
        }
        out.push(self.end_s[r] - free);
        out
    }
}

/// The network of one search: variables `0` (the origin), then per robot its start, its LC
/// runs' starts and its end; static edges (the chain's lags, `start ≥ origin`) as adjacency
/// lists, and one operator edge per placed LC run.
struct Net<'a> {
    chain: &'a Chain,
    n: usize,
    m: usize,
    /// Static out-edges `(to, w)`: `x[to] ≥ x[from] + w`.
    out: Vec<Vec<(usize, f64)>>,
    /// The operator edge out of each LC variable, set while its successor in the order is
    /// placed.
    op: Vec<Option<(usize, f64)>>,
    x: Vec<f64>,
    /// `(variable, old value)` of every raise, for backtracking.
    trail: Vec<(usize, f64)>,
    queue: Vec<usize>,
    eps: f64,
    /// A propagation stopped at its raise limit: its verdict "infeasible" is not proven, so
    /// neither is the search.
    gave_up: bool,
    /// Raises of all propagations so far (the search's work).
    raises: usize,
}

impl<'a> Net<'a> {
    fn start(&self, r: usize) -> usize {
        1 + r * (self.m + 2)
    }
    fn lc(&self, r: usize, k: usize) -> usize {
        self.start(r) + 1 + k
    }
    fn end(&self, r: usize) -> usize {
        self.start(r) + 1 + self.m
    }

    fn new(chain: &'a Chain, n: usize, switch_s: f64) -> Option<Net<'a>> {
        let m = chain.n_lc();
        let vars = 1 + n * (m + 2);
        let mut net = Net {
            chain,
            n,
            m,
            out: vec![Vec::new(); vars],
            op: vec![None; vars],
            x: vec![f64::NEG_INFINITY; vars],
            trail: Vec::new(),
            queue: Vec::new(),
            eps: 0.0,
            gave_up: false,
            raises: 0,
        };
        let mut scale = 0.0;
        for r in 0..n {
            let s = net.start(r);
            net.out[0].push((s, 0.0));
            let mut prev = (s, 0.0);
            for g in 0..=m {
                let to = if g < m { net.lc(r, g) } else { net.end(r) };
                let (a, b) = chain.gap_s[g];
                net.out[prev.0].push((to, prev.1 + a));
                net.out[to].push((prev.0, -(prev.1 + b)));
                scale += a.abs() + (prev.1 + b).abs() + prev.1;
                if g < m {
                    prev = (to, chain.lc_s[g]);
                }
            }
        }
        // Gains below this are rounding (as `stn::relax_tolerance`, for the edges of all
        // orders: the operator edges weigh at most Σ L_k each).
        let total_lc: f64 = chain.lc_s.iter().sum::<f64>() * n as f64;
        net.eps = 4.0 * vars as f64 * f64::EPSILON * (scale + total_lc * (1.0 + n as f64));
        if switch_s > 0.0 {
            // The operator edges of a switch weigh δ more.
            net.eps += 4.0 * vars as f64 * f64::EPSILON * (switch_s * (n * m) as f64);
        }
        net.x[0] = 0.0;
        net.queue.push(0);
        net.propagate(None).then_some(net)
    }

    /// Longest paths from the queued variables; `false` on a positive cycle (a raise of
    /// `closing`, the tail of the edge just added, or of the origin: no other cycle can have
    /// turned positive) or after `4·V² + 64` raises (then [`Net::gave_up`] is set).
    fn propagate(&mut self, closing: Option<usize>) -> bool {
        let limit = 4 * self.x.len() * self.x.len() + 64;
        let mut raises = 0usize;
        while let Some(y) = self.queue.pop() {
            let xy = self.x[y];
            let op = self.op[y];
            for &(z, w) in self.out[y].iter().chain(op.iter()) {
                let cand = xy + w;
                if cand > self.x[z] + self.eps {
                    if z == 0 || Some(z) == closing {
                        self.queue.clear();
                        return false;
                    }
                    raises += 1;
                    self.raises += 1;
                    if raises > limit {
                        self.queue.clear();
                        self.gave_up = true;
                        return false;
                    }
                    self.trail.push((z, self.x[z]));
                    self.x[z] = cand;
                    self.queue.push(z);
                }
            }
        }
        true
    }

    /// Places LC run `k` of robot `r` right after LC variable `prev` (ending `L_prev` after
    /// its start); `false` if the order becomes infeasible (the caller backtracks either way).
    fn place(&mut self, prev: Option<(usize, f64)>, r: usize, k: usize) -> bool {
        let Some((p, l)) = prev else {
            return true;
        };
        let v = self.lc(r, k);
        self.op[p] = Some((v, l));
        if self.x[p] + l > self.x[v] + self.eps {
            self.trail.push((v, self.x[v]));
            self.x[v] = self.x[p] + l;
            self.queue.push(v);
            return self.propagate(Some(p));
        }
        true
    }

    fn undo(&mut self, mark: usize, prev: Option<(usize, f64)>) {
        while self.trail.len() > mark {
            let (v, old) = self.trail.pop().expect("above the mark");
            self.x[v] = old;
        }
        if let Some((p, _)) = prev {
            self.op[p] = None;
        }
    }
}

/// The best interleaving of `n` robots' LC runs on `chain` (all robots traverse it, each
/// starting at any time `≥ 0`, no two LC runs overlapping, `T_total` the latest end), by
/// depth-first branch and bound over machine orders: each node's earliest times (longest
/// paths, kept incrementally) are lower bounds on every completion's, so a node is cut when
/// the operator's free time plus the LC time left plus the fastest tail, or a robot's
/// earliest end, reaches the incumbent `cap_s` (s) or the best found. Robots are
/// interchangeable, so their first LC runs come in robot order. Children are tried earliest
/// next start first, so the first leaf is the greedy list schedule. At most `max_nodes`
/// nodes and about `max_nodes · MAX_RAISES_PER_NODE` raises of the longest paths (a node's
/// work grows with the number of LC runs); `None` if no order beats `cap_s` (proven only if
/// the search finished).
#[cfg(test)]
pub(crate) fn search(
    chain: &Chain,
    n: usize,
    cap_s: f64,
    max_nodes: usize,
) -> (Option<ManyFound>, bool, usize) {
    search_with_switch(chain, n, cap_s, max_nodes, 0.0)
}

/// [`search`] with the operator's switch time `switch_s` (s, ≥ 0): an LC run placed right after
/// *another* robot's run starts at least `switch_s` after that run ends (consecutive runs of
/// one robot need none), and a node's bound adds `switch_s` for every robot other than the
/// last placed one that still has runs to place (each needs one switch to it at least). With
/// `switch_s = 0` it is [`search`], the same float operations.
pub(crate) fn search_with_switch(
    chain: &Chain,
    n: usize,
    cap_s: f64,
    max_nodes: usize,
    switch_s: f64,
) -> (Option<ManyFound>, bool, usize) {
    let Some(mut net) = Net::new(chain, n, switch_s) else {
        return (None, true, 0);
    };
    let m = chain.n_lc();
    let mut s = Search {
        next: vec![0; n],
        order: Vec::with_capacity(n * m),
        best: None,
        best_t: cap_s,
        nodes: 0,
        max_nodes,
        out_of_budget: false,
        rem_lc: chain.lc_s.iter().sum::<f64>() * n as f64,
        switch_s,
    };
    s.dfs(&mut net, None);
    let proven = !s.out_of_budget && !net.gave_up;
    let nodes = s.nodes;
    let found = s
        .best
        .map(|(order, x)| relabel(&net, &order, &x, proven, nodes));
    (found, proven, nodes)
}

/// The search's work budget in raises per node of [`search`]'s node budget: 200,000 nodes of
/// the fixture problem (3 LC runs, at most 5 raises a node) are far inside it; 8 robots on
/// 385 LC runs stop after ≈ 0.7 s on 2 cores instead of 205 s (docs/decisions.md, "N robots
/// in the margin-free search").
const MAX_RAISES_PER_NODE: usize = 10;

struct Search {
    next: Vec<usize>,
    order: Vec<usize>,
    best: Option<(Vec<usize>, Vec<f64>)>,
    best_t: f64,
    nodes: usize,
    max_nodes: usize,
    out_of_budget: bool,
    /// LC time not yet placed (s).
    rem_lc: f64,
    /// The operator's switch time (s, ≥ 0; see [`search_with_switch`]).
    switch_s: f64,
}

impl Search {
    fn dfs(&mut self, net: &mut Net, last: Option<(usize, f64)>) {
        self.nodes += 1;
        if net.raises > self.max_nodes.saturating_mul(MAX_RAISES_PER_NODE) {
            self.out_of_budget = true;
            return;
        }
        let (n, m) = (net.n, net.m);
        let op_free = last.map_or(0.0, |(v, l)| net.x[v] + l);
        let latest_end = (0..n).map(|r| net.x[net.end(r)]).fold(0.0, f64::max);
        let tail = if self.rem_lc > 0.0 {
            net.chain.gap_s[m].0
        } else {
            0.0
        };
        let last_robot = self.order.last().copied();
        let lb = if self.switch_s > 0.0 {
            let switches = (0..n)
                .filter(|&r| Some(r) != last_robot && self.next[r] < m)
                .count();
            latest_end.max(op_free + self.rem_lc + self.switch_s * switches as f64 + tail)
        } else {
            latest_end.max(op_free + self.rem_lc + tail)
        };
        let cut = self.best_t * (1.0 - 1e-12);
        if lb >= cut {
            return;
        }
        if self.order.len() == n * m {
            self.best_t = latest_end;
            self.best = Some((self.order.clone(), net.x.clone()));
            return;
        }
        if self.nodes >= self.max_nodes {
            self.out_of_budget = true;
            return;
        }
        // Robots that may go next, earliest possible start first.
        let mut kids: Vec<(f64, usize)> = (0..n)
            .filter(|&r| self.next[r] < m && (r == 0 || self.next[r] > 0 || self.next[r - 1] > 0))
            .map(|r| {
                let free = if self.switch_s > 0.0 && last.is_some() && Some(r) != last_robot {
                    op_free + self.switch_s
                } else {
                    op_free
                };
                (net.x[net.lc(r, self.next[r])].max(free), r)
            })
            .collect();
        kids.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (_, r) in kids {
            if self.out_of_budget {
                return;
            }
            let k = self.next[r];
            let mark = net.trail.len();
            // The operator edge from the last run: its length, plus δ on a switch.
            let edge = match last {
                Some((v, l)) if self.switch_s > 0.0 && Some(r) != last_robot => {
                    Some((v, l + self.switch_s))
                }
                other => other,
            };
            let ok = net.place(edge, r, k);
            if ok {
                let l = net.chain.lc_s[k];
                self.next[r] += 1;
                self.order.push(r);
                self.rem_lc -= l;
                self.dfs(net, Some((net.lc(r, k), l)));
                self.rem_lc += l;
                self.order.pop();
                self.next[r] -= 1;
            }
            net.undo(mark, edge);
        }
    }
}

/// The times of `x` with the robots relabelled by start (ties by index), and the order in the
/// new labels.
fn relabel(net: &Net, order: &[usize], x: &[f64], proven: bool, nodes: usize) -> ManyFound {
    let (n, m) = (net.n, net.m);
    let mut by_start: Vec<usize> = (0..n).collect();
    by_start.sort_by(|&a, &b| x[net.start(a)].total_cmp(&x[net.start(b)]).then(a.cmp(&b)));
    let mut label = vec![0; n];
    for (new, &old) in by_start.iter().enumerate() {
        label[old] = new;
    }
    let origin = x[net.start(by_start[0])];
    let times = ManyTimes {
        start_s: by_start.iter().map(|&r| x[net.start(r)] - origin).collect(),
        lc_start_s: by_start
            .iter()
            .map(|&r| (0..m).map(|k| x[net.lc(r, k)] - origin).collect())
            .collect(),
        end_s: by_start.iter().map(|&r| x[net.end(r)] - origin).collect(),
    };
    let t_total_s = times.end_s.iter().copied().fold(0.0, f64::max);
    ManyFound {
        t_total_s,
        proven,
        times,
        order: order.iter().map(|&r| label[r]).collect(),
        nodes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::problem::{Problem, unit_gradients};

    /// [LC, HC, LC] with gradients 1 in [0.5, 2] at 10 samples of 10 ms each: LC runs of 0.1 s,
    /// an HC gap of [0.05, 0.2] s, no head or tail.
    fn lhl() -> Chain {
        let conf: Vec<bool> = (0..30).map(|n| (10..20).contains(&n)).collect();
        Chain::new(&unit_gradients(conf, (0.5, 2.0), 0.01))
    }

    /// The search's optimum of [`lhl`] for `n` robots: proven, `expected` (s), and feasible.
    fn by_hand(n: usize, expected: f64) {
        let (found, proven, _) = search(&lhl(), n, f64::INFINITY, 1_000_000);
        let f = found.unwrap();
        assert!(proven);
        assert!((f.t_total_s - expected).abs() < 1e-12, "{}", f.t_total_s);
        check(&lhl(), &f);
    }

    #[test]
    fn three_robots_by_hand() {
        // Six LC runs of 0.1 s on one operator: at least 0.6 s. Robot A's gap must last
        // [0.05, 0.2] s, so its second run is at most 0.2 s after its first ends: with three
        // robots, A B C A B C back to back has A's gap 0.2 s, exactly its longest. 0.6 s.
        by_hand(3, 0.6);
    }

    /// The times satisfy the chain and one operator: robot 0 starts at 0, the others at
    /// `≥ 0`, every gap within its range, LC runs pairwise disjoint in the order given, and
    /// `T_total` the latest end.
    fn check(chain: &Chain, f: &ManyFound) {
        let t = &f.times;
        let n = t.start_s.len();
        assert_eq!(t.start_s[0], 0.0);
        for r in 0..n {
            assert!(t.start_s[r] >= 0.0);
            for (g, d) in t.gaps_s(chain, r).iter().enumerate() {
                let (a, b) = chain.gap_s[g];
                assert!(*d >= a - 1e-12 && *d <= b + 1e-12, "robot {r} gap {g}: {d}");
            }
        }
        let mut next = vec![0; n];
        let mut free = f64::NEG_INFINITY;
        for &r in &f.order {
            let k = next[r];
            next[r] += 1;
            assert!(t.lc_start_s[r][k] >= free - 1e-12);
            free = t.lc_start_s[r][k] + chain.lc_s[k];
        }
        let latest = t.end_s.iter().copied().fold(0.0, f64::max);
        assert_eq!(latest, f.t_total_s);
    }

    #[test]
    fn four_robots_leave_the_operator_idle() {
        // Four robots: A's gap would have to cover three runs, 0.3 s > 0.2 s. The best keeps
        // every gap ≤ 0.2 s. By hand: pairs (A B)(C D) each as for two robots: A B A B takes
        // 0.4 s with A's gap 0.1 s; C D C D back to back after it: 0.8 s, operator never idle.
        by_hand(4, 0.8);
    }

    #[test]
    fn a_cap_below_the_optimum_finds_nothing() {
        let (found, proven, _) = search(&lhl(), 3, 0.6, 100_000);
        assert!(found.is_none());
        assert!(proven);
    }

    #[test]
    fn the_budget_stops_the_search_unproven() {
        let (found, proven, nodes) = search(&lhl(), 3, f64::INFINITY, 3);
        assert!(!proven);
        assert!(nodes <= 3);
        assert!(found.is_none());
    }

    /// `T_total` (s) of the earliest solution of one machine order by plain Bellman–Ford over
    /// every edge (`None`: infeasible), written apart from [`Net`] to check it.
    fn order_t_total(chain: &Chain, n: usize, order: &[usize]) -> Option<f64> {
        order_t_total_switch(chain, n, order, 0.0)
    }

    /// [`order_t_total`] with the switch time `switch_s` (s) between runs of different robots.
    fn order_t_total_switch(
        chain: &Chain,
        n: usize,
        order: &[usize],
        switch_s: f64,
    ) -> Option<f64> {
        let m = chain.n_lc();
        let start = |r: usize| 1 + r * (m + 2);
        let lc = |r: usize, k: usize| start(r) + 1 + k;
        let end = |r: usize| start(r) + 1 + m;
        let vars = 1 + n * (m + 2);
        let mut e: Vec<(usize, usize, f64)> = Vec::new();
        for r in 0..n {
            e.push((0, start(r), 0.0));
            let mut prev = (start(r), 0.0);
            for g in 0..=m {
                let to = if g < m { lc(r, g) } else { end(r) };
                let (a, b) = chain.gap_s[g];
                e.push((prev.0, to, prev.1 + a));
                e.push((to, prev.0, -(prev.1 + b)));
                if g < m {
                    prev = (to, chain.lc_s[g]);
                }
            }
        }
        let mut next = vec![0; n];
        let mut last: Option<(usize, f64, usize)> = None;
        for &r in order {
            let v = lc(r, next[r]);
            if let Some((p, l, rp)) = last {
                e.push((p, v, if rp == r { l } else { l + switch_s }));
            }
            last = Some((v, chain.lc_s[next[r]], r));
            next[r] += 1;
        }
        let mut x = vec![f64::NEG_INFINITY; vars];
        x[0] = 0.0;
        for round in 0..=vars + 1 {
            let mut changed = false;
            for &(a, b, w) in &e {
                if x[a] + w > x[b] + 1e-9 {
                    x[b] = x[a] + w;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
            if round == vars + 1 || x[0] > 0.0 {
                return None;
            }
        }
        let origin = (0..n).map(|r| x[start(r)]).fold(f64::INFINITY, f64::min);
        Some((0..n).map(|r| x[end(r)]).fold(0.0, f64::max) - origin)
    }

    /// Every machine order of `n` robots with `m` LC runs each.
    fn all_orders(n: usize, m: usize) -> Vec<Vec<usize>> {
        fn go(left: &mut Vec<usize>, cur: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
            if left.iter().all(|&c| c == 0) {
                out.push(cur.clone());
                return;
            }
            for r in 0..left.len() {
                if left[r] > 0 {
                    left[r] -= 1;
                    cur.push(r);
                    go(left, cur, out);
                    cur.pop();
                    left[r] += 1;
                }
            }
        }
        let mut out = Vec::new();
        go(&mut vec![m; n], &mut Vec::new(), &mut out);
        out
    }

    /// A problem of `m` LC runs between HC runs of random lengths and gradient ranges (some
    /// rigid, `ψ̇min = ψ̇max`), at 10 ms.
    fn random_chain() -> impl Strategy<Value = Chain> {
        (
            1usize..=3,
            proptest::collection::vec((1usize..=4, 0.2f64..1.0, 1.0f64..3.0, 0u8..5), 8),
        )
            .prop_map(|(m, runs)| {
                let (mut conf, mut mean, mut lo, mut hi) = (vec![], vec![], vec![], vec![]);
                for (i, &(len, a, b, rigid)) in runs.iter().take(2 * m + 1).enumerate() {
                    let high = i % 2 == 0;
                    for _ in 0..len {
                        conf.push(high);
                        let (a, b) = if rigid == 0 { (1.0, 1.0) } else { (a, b) };
                        lo.push(a);
                        hi.push(b);
                        mean.push(0.5 * (a + b));
                    }
                }
                Chain::new(&Problem::new(conf, mean, lo, hi, 0.01).unwrap())
            })
    }

    /// The two-robot dynamic program's optimum with zero clearances (`search.rs`).
    fn dp_optimum(chain: &Chain) -> f64 {
        let serial = 2.0 * chain.fastest_s();
        match super::super::search::search(
            chain,
            &super::super::search::Clearance::zero(),
            serial * (1.0 + 1e-9),
            4_000_000,
        )
        .0
        {
            super::super::search::Outcome::Done(Some(found)) => found.t_total_s,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn rigid_gaps_back_to_back() {
        // Found by `search_equals_all_orders`: LC runs 0.02, 0.01, 0.01 s between rigid gaps
        // 0.01, 0.02, 0.02, 0.01 s (ψ̇min = ψ̇max). Robot B started 0.02 s after A has each run
        // right after A's: A [0.01, 0.03] [0.05, 0.06] [0.08, 0.09], B [0.03, 0.05]
        // [0.07, 0.08] [0.10, 0.11], B ends at 0.12 s. No order does better (B cannot start
        // before A's first run ends, 0.03 − 0.01). The dynamic program returns 0.18 s here
        // (every run touching the next, rounding on zero-width windows); kept as found.
        let conf = [
            true, false, false, true, true, false, true, true, false, true,
        ];
        let p = unit_gradients(conf.to_vec(), (1.0, 1.0), 0.01);
        let chain = Chain::new(&p);
        assert_eq!(chain.lc_s.len(), 3);
        let (found, proven, _) = search(&chain, 2, f64::INFINITY, 1_000_000);
        let f = found.unwrap();
        assert!(proven);
        assert!((f.t_total_s - 0.12).abs() < 1e-9, "{}", f.t_total_s);
        check(&chain, &f);
        assert!(dp_optimum(&chain) >= f.t_total_s - 1e-9);
    }

    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// The branch and bound finds the least `T_total` over all machine orders (three
        /// robots), and for two robots the dynamic program's optimum.
        #[test]
        fn search_equals_all_orders(chain in random_chain()) {
            let m = chain.n_lc();
            let brute = all_orders(3, m)
                .iter()
                .filter_map(|o| order_t_total(&chain, 3, o))
                .fold(f64::INFINITY, f64::min);
            let (found, proven, _) = search(&chain, 3, f64::INFINITY, 1_000_000);
            let f = found.unwrap();
            prop_assert!(proven);
            prop_assert!((f.t_total_s - brute).abs() <= 1e-9 * brute, "{} vs {}", f.t_total_s, brute);
            check(&chain, &f);
            // Two robots: the same against all orders, and never above the dynamic program's
            // optimum (which can exceed it on rigid gaps, see below).
            let brute2 = all_orders(2, m)
                .iter()
                .filter_map(|o| order_t_total(&chain, 2, o))
                .fold(f64::INFINITY, f64::min);
            let (two, proven, _) = search(&chain, 2, f64::INFINITY, 1_000_000);
            prop_assert!(proven);
            let two = two.unwrap().t_total_s;
            prop_assert!((two - brute2).abs() <= 1e-9 * brute2, "{} vs {}", two, brute2);
            let dp = dp_optimum(&chain);
            prop_assert!(two <= dp * (1.0 + 1e-9), "{} vs {}", two, dp);
        }

        /// With a switch time the branch and bound still finds the least `T_total` over all
        /// machine orders (each switch between different robots δ long), for three and two
        /// robots; it is never below the search without one, and for two robots never above
        /// the dynamic program with the same uniform clearance.
        #[test]
        fn search_with_switch_equals_all_orders(chain in random_chain(), delta in 0.0f64..0.05) {
            let m = chain.n_lc();
            for n in [2usize, 3] {
                let brute = all_orders(n, m)
                    .iter()
                    .filter_map(|o| order_t_total_switch(&chain, n, o, delta))
                    .fold(f64::INFINITY, f64::min);
                let (found, proven, _) =
                    search_with_switch(&chain, n, f64::INFINITY, 1_000_000, delta);
                prop_assert!(proven);
                match found {
                    Some(f) => {
                        prop_assert!((f.t_total_s - brute).abs() <= 1e-9 * brute,
                            "n {}: {} vs {}", n, f.t_total_s, brute);
                        let (free, _, _) = search(&chain, n, f64::INFINITY, 1_000_000);
                        let free = free.unwrap().t_total_s;
                        prop_assert!(f.t_total_s >= free * (1.0 - 1e-9), "{} < {}", f.t_total_s, free);
                    }
                    None => prop_assert!(brute.is_infinite(), "n {}: none found, brute {}", n, brute),
                }
            }
            let (two, _, _) = search_with_switch(&chain, 2, f64::INFINITY, 1_000_000, delta);
            let clear = super::super::search::Clearance::uniform(delta, None);
            if let (Some(two), (super::super::search::Outcome::Done(Some(dp)), _)) = (
                two,
                super::super::search::search(&chain, &clear, f64::INFINITY, 4_000_000),
            ) {
                prop_assert!(two.t_total_s <= dp.t_total_s * (1.0 + 1e-9),
                    "{} vs {}", two.t_total_s, dp.t_total_s);
            }
        }
    }
}
