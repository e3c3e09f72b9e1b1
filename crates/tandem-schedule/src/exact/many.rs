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
    /// The room arc out of each LC variable ([`search_with_room`]), set with its operator edge.
    room_op: Vec<Option<(usize, f64)>>,
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
    /// Propagations stopped at their raise limit so far.
    gave_ups: usize,
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
            room_op: vec![None; vars],
            x: vec![f64::NEG_INFINITY; vars],
            trail: Vec::new(),
            queue: Vec::new(),
            eps: 0.0,
            gave_up: false,
            raises: 0,
            gave_ups: 0,
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
            let (op, room) = (self.op[y], self.room_op[y]);
            for &(z, w) in self.out[y].iter().chain(op.iter()).chain(room.iter()) {
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
                        self.gave_ups += 1;
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
    /// its start) with the room arc `room` (`(to, w)`: `x[to] ≥ x[prev] + w`, see
    /// [`search_with_room`]) out of the same LC variable, if any; `false` if the order becomes
    /// infeasible (the caller backtracks either way).
    fn place_with(
        &mut self,
        prev: Option<(usize, f64)>,
        r: usize,
        k: usize,
        room: Option<(usize, f64)>,
    ) -> bool {
        let Some((p, l)) = prev else {
            return true;
        };
        let v = self.lc(r, k);
        self.op[p] = Some((v, l));
        let mut raised = false;
        if self.x[p] + l > self.x[v] + self.eps {
            self.trail.push((v, self.x[v]));
            self.x[v] = self.x[p] + l;
            self.queue.push(v);
            raised = true;
        }
        if let Some((to, w)) = room {
            self.room_op[p] = Some((to, w));
            if self.x[p] + w > self.x[to] + self.eps {
                if to == p {
                    self.queue.clear();
                    return false;
                }
                self.trail.push((to, self.x[to]));
                self.x[to] = self.x[p] + w;
                self.queue.push(to);
                raised = true;
            }
        }
        if raised {
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
            self.room_op[p] = None;
        }
    }
}

/// What [`search_with_switch`] returns: the best order found, whether it is proven optimal,
/// the nodes visited and a lower bound on the optimum.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ManyOutcome {
    /// The best order found below the cap, if any.
    pub(crate) found: Option<ManyFound>,
    /// Whether the search finished: no order is shorter than [`ManyOutcome::found`]'s (or,
    /// when `None`, below the cap), so its `T_total` is the optimum.
    pub(crate) proven: bool,
    /// Nodes visited, the dive's and the exact search's.
    pub(crate) nodes: usize,
    /// A lower bound (s) on the `T_total` of every order (every schedule of Eq. 20
    /// constraints 1–4 on the chain), or on the cap when no order beats it: the least of the
    /// best `T_total` found (or the cap) and the bounds of the nodes the exact search left open
    /// (see [`search_with_switch`]); the optimum itself when [`ManyOutcome::proven`] and an
    /// order was found.
    pub(crate) lower_bound_s: f64,
}

/// The best interleaving of `n` robots' LC runs on `chain` (all robots traverse it, each
/// starting at any time `≥ 0`, no two LC runs overlapping, `T_total` the latest end), by
/// depth-first branch and bound over machine orders: each node's earliest times (longest
/// paths, kept incrementally) are lower bounds on every completion's, so a node is cut when
/// the operator's free time plus the LC time left plus the fastest tail, or a robot's
/// earliest end, reaches the incumbent `cap_s` (s) or the best found. Robots are
/// interchangeable, so their first LC runs come in robot order. The exact search tries
/// children earliest next start first (the greedy list order) after a dive (see
/// [`search_with_switch`]). At most `max_nodes` nodes and about
/// `max_nodes · MAX_RAISES_PER_NODE` raises of the longest paths (a node's work grows with the
/// number of LC runs); no order found if none beats `cap_s` (proven only if the search
/// finished).
#[cfg(test)]
pub(crate) fn search(chain: &Chain, n: usize, cap_s: f64, max_nodes: usize) -> ManyOutcome {
    search_with_switch(chain, n, cap_s, max_nodes, 0.0)
}

/// [`search`] with the operator's switch time `switch_s` (s, ≥ 0): an LC run placed right after
/// *another* robot's run starts at least `switch_s` after that run ends (consecutive runs of
/// one robot need none), and a node's bound adds `switch_s` for every robot other than the
/// last placed one that still has runs to place (each needs one switch to it at least).
///
/// **The dive.** The greedy list order (earliest next start first) runs into gaps whose
/// slowest traversal cannot cover the other robots' runs and backtracks deep: on random
/// problems of 11–21 LC runs it found no order at all within its budget (docs/decisions.md,
/// "The three-robot search: a dive that reaches a leaf and the open nodes' bound (issue 38)").
/// So a first depth-first search (at most `max_nodes / DIVE_SHARE` nodes, stopping at its
/// first leaf) puts *urgent* robots first: robot `r`, in the HC gap before its next LC run
/// `k`, must start it by its deadline `x(k − 1) + L_{k−1} + b_k` (the gap's slowest
/// traversal); when the greedy child would end after another robot's deadline, the robots
/// whose deadlines it passes go first, earliest deadline first. If the dive finds no leaf,
/// the serial order (each robot's runs after the previous robot's, always feasible: starts
/// have no upper bound) is the leaf. The leaf is the exact search's incumbent; every node
/// of the dive and the serial order counts against the budget.
///
/// **The open nodes' bound.** A node's bound is a lower bound on the `T_total` of every leaf
/// below it (its earliest times are the least of every completion's, and placing a run never
/// lowers `operator free + LC time left`), so when the exact search stops on its budget the
/// optimum is either the best found or a leaf below a node it left open: the node it stopped
/// at, the children not yet tried at every node of its path (each bounded by placing it, or by
/// its parent's bound when the placement stopped on its raise limit), and the children whose
/// placement stopped on the raise limit. [`ManyOutcome::lower_bound_s`] is the least of these
/// and of the best found: a valid lower bound on the optimum. Closed nodes (bound at or above
/// the best found, or an infeasible order proven by a positive cycle) hold no better leaf.
///
/// With `switch_s = 0` the same float operations as without a switch time.
pub(crate) fn search_with_switch(
    chain: &Chain,
    n: usize,
    cap_s: f64,
    max_nodes: usize,
    switch_s: f64,
) -> ManyOutcome {
    search_with_room(chain, n, cap_s, max_nodes, switch_s, &[])
}

/// [`search_with_switch`] with *room arcs*: when robot `c`'s run `k ≥ 1` is placed right after
/// another robot's run `j` (a switch) and `guard[k]` is `Some(w_k)`, the network also gets
/// `x(c, k − 1) ≥ x(j) + L_j + δ + w_k`; with `w_k = e − L_{k−1} − a_k` that is
/// `x(c, k − 1) + L_{k−1} + a_k ≥ x(j) + L_j + δ + e`: even at its fastest traversal of the HC gap
/// `k` (`a_k`) from the end of its previous run, `c` could not reach run `k` before `δ + e` after
/// run `j` ends. `guard` empty (or `switch_s = 0`) is [`search_with_switch`], the same float
/// operations.
///
/// The arcs are a *candidate generator's* constraint, not one of Eq. 20: the orders and times
/// found satisfy constraints 1–4 with the switch time (every other edge is the plain search's),
/// but the `T_total` and [`ManyOutcome::lower_bound_s`] bound only the problem with the arcs,
/// never the margin-free optimum, so the certificate's bound is never taken from it
/// (docs/decisions.md, "Three robots at δ ≥ 1 s: a room-aware order (issue 41)"). The node
/// bound is [`search_with_switch`]'s, computed on the raised times (still a lower bound on every
/// completion's: arcs only raise times). The forward check ([`Search::dead`]) stays valid: a
/// path of operator edges from the last run to a later predecessor `q` of run `k` weighs at
/// least `L_last + δ`, so `q`'s room arc into `x(c, k − 1)` is at least as heavy as the last
/// run's.
pub(crate) fn search_with_room(
    chain: &Chain,
    n: usize,
    cap_s: f64,
    max_nodes: usize,
    switch_s: f64,
    guard: &[Option<f64>],
) -> ManyOutcome {
    search_with_room_travel(chain, n, cap_s, max_nodes, switch_s, guard, &[])
}

/// [`search_with_room`] where a switch into run `k` also charges `travel_s[k]` (s, ≥ 0): the
/// operator edge from another robot's run `j` is `x(c, k) ≥ x(j) + L_j + δ + travel_s[k]`.
/// `travel_s` empty (or `switch_s = 0`) is [`search_with_room`], the same float operations.
///
/// **Why** (docs/decisions.md, "Three robots at δ ≥ 2 s: a switch into a held stretch costs
/// the travel from its hold (issue 41)"): a robot that waits at a hold for the run before it
/// leaves by a release rule `δ` after that run's robot has *left* its stretch, and only then
/// travels from the hold to its own stretch (at best its fastest), so such a switch lasts
/// `δ` plus that travel, not `δ`. An order planned with `δ` alone has the later robots of a
/// chain of such releases later than planned, and a robot released earlier, on a hold-less
/// approach, further ahead of them than the margin check allows.
///
/// Like the room arcs, the travel is the candidate generator's, never the certificate's: the
/// node bound stays [`search_with_switch`]'s (extra weight only raises times), and the forward
/// check ([`Search::dead`]) stays valid (a path of operator edges into run `k` of robot `c`
/// from another robot's run ends with a switch into `k`, which carries the same travel).
pub(crate) fn search_with_room_travel(
    chain: &Chain,
    n: usize,
    cap_s: f64,
    max_nodes: usize,
    switch_s: f64,
    guard: &[Option<f64>],
    travel_s: &[f64],
) -> ManyOutcome {
    let Some(mut net) = Net::new(chain, n, switch_s) else {
        // The chain alone is infeasible: no order at all.
        return ManyOutcome {
            found: None,
            proven: true,
            nodes: 0,
            lower_bound_s: cap_s,
        };
    };
    let m = chain.n_lc();
    let mut s = Search {
        next: vec![0; n],
        order: Vec::with_capacity(n * m),
        best: None,
        best_t: cap_s,
        nodes: 0,
        max_nodes: (max_nodes / DIVE_SHARE).max(1),
        out_of_budget: false,
        rem_lc: chain.lc_s.iter().sum::<f64>() * n as f64,
        switch_s,
        guard: if switch_s > 0.0 {
            guard.to_vec()
        } else {
            Vec::new()
        },
        travel: if switch_s > 0.0 {
            travel_s.to_vec()
        } else {
            Vec::new()
        },
        dive: true,
        open_lb: f64::INFINITY,
    };
    s.dfs(&mut net, None);
    if s.best.is_none() {
        s.serial(&mut net);
    }
    // The exact search from the dive's leaf: a fresh node budget (the dive's nodes count),
    // the raises so far too.
    s.dive = false;
    s.out_of_budget = false;
    s.max_nodes = max_nodes;
    s.open_lb = f64::INFINITY;
    net.gave_up = false;
    if s.nodes < max_nodes {
        s.dfs(&mut net, None);
    } else {
        // No budget left for the exact search: its root stays open.
        s.out_of_budget = true;
        s.open_lb = s.bound(&net, None);
    }
    let proven = !s.out_of_budget && !net.gave_up && s.open_lb == f64::INFINITY;
    let nodes = s.nodes;
    let lower_bound_s = if proven {
        s.best_t
    } else {
        s.best_t.min(s.open_lb)
    };
    let found = s
        .best
        .map(|(order, x)| relabel(&net, &order, &x, proven, nodes));
    ManyOutcome {
        found,
        proven,
        nodes,
        lower_bound_s,
    }
}

/// The search's work budget in raises per node of [`search`]'s node budget: 200,000 nodes of
/// the fixture problem (3 LC runs, at most 5 raises a node) are far inside it; 8 robots on
/// 385 LC runs stop after ≈ 0.7 s on 2 cores instead of 205 s (docs/decisions.md, "N robots
/// in the margin-free search").
const MAX_RAISES_PER_NODE: usize = 10;

/// The dive's share of the node budget: at most `max_nodes / DIVE_SHARE` nodes before the
/// serial order is taken as the first leaf.
const DIVE_SHARE: usize = 4;

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
    /// Per LC run `k`, the room arc's offset `w_k` (s) when a switch into it is guarded (see
    /// [`search_with_room`]; empty: none).
    guard: Vec<Option<f64>>,
    /// Per LC run `k`, the travel (s) a switch into it charges on top of `δ` (see
    /// [`search_with_room_travel`]; empty: none).
    travel: Vec<f64>,
    /// The dive: urgent robots first, stop at the first leaf, no open nodes kept.
    dive: bool,
    /// The least bound (s) of the nodes left open (`+∞`: none).
    open_lb: f64,
}

impl Search {
    /// The node's bound (s): the latest earliest end, or the operator's free time plus the LC
    /// time left (plus a switch to every robot with runs left other than the last one) plus
    /// the fastest tail.
    fn bound(&self, net: &Net, last: Option<(usize, f64)>) -> f64 {
        let (n, m) = (net.n, net.m);
        let op_free = last.map_or(0.0, |(v, l)| net.x[v] + l);
        let latest_end = (0..n).map(|r| net.x[net.end(r)]).fold(0.0, f64::max);
        let tail = if self.rem_lc > 0.0 {
            net.chain.gap_s[m].0
        } else {
            0.0
        };
        let last_robot = self.order.last().copied();
        if self.switch_s > 0.0 {
            let switches = (0..n)
                .filter(|&r| Some(r) != last_robot && self.next[r] < m)
                .count();
            latest_end.max(op_free + self.rem_lc + self.switch_s * switches as f64 + tail)
        } else {
            latest_end.max(op_free + self.rem_lc + tail)
        }
    }

    /// The operator edge for robot `r`'s next run after the last run: its length, plus δ on
    /// a switch.
    fn edge(&self, last: Option<(usize, f64)>, r: usize) -> Option<(usize, f64)> {
        self.edge_into(last, r, self.next[r], self.order.last().copied())
    }

    /// [`Search::edge_serial`] into run `k` of robot `r`, with the travel of a switch into it
    /// ([`search_with_room_travel`]) when there is one.
    fn edge_into(
        &self,
        last: Option<(usize, f64)>,
        r: usize,
        k: usize,
        last_robot: Option<usize>,
    ) -> Option<(usize, f64)> {
        let edge = self.edge_serial(last, r, last_robot);
        match (edge, self.travel.get(k)) {
            (Some((v, w)), Some(&t)) if last.is_some() && Some(r) != last_robot && t > 0.0 => {
                Some((v, w + t))
            }
            _ => edge,
        }
    }

    /// The room arc of placing robot `r`'s next run right after the last run (see
    /// [`search_with_room`]): `None` unless it is a switch into a guarded run `k ≥ 1`.
    fn room_arc(&self, net: &Net, last: Option<(usize, f64)>, r: usize) -> Option<(usize, f64)> {
        self.room_arc_serial(net, last, r, self.next[r], self.order.last().copied())
    }

    /// [`Search::room_arc`] into run `k` of robot `r` when the last placed robot is
    /// `last_robot` (the serial order's too).
    fn room_arc_serial(
        &self,
        net: &Net,
        last: Option<(usize, f64)>,
        r: usize,
        k: usize,
        last_robot: Option<usize>,
    ) -> Option<(usize, f64)> {
        let (_, l) = last?;
        let w = (*self.guard.get(k)?)?;
        (k >= 1 && self.switch_s > 0.0 && Some(r) != last_robot)
            .then(|| (net.lc(r, k - 1), l + self.switch_s + w))
    }

    /// Leaves a node open with bound `lb` (s) (nothing during the dive).
    fn open(&mut self, lb: f64) {
        if !self.dive {
            self.open_lb = self.open_lb.min(lb);
        }
    }

    /// Leaves robot `r`'s next run open as a child of the node `last` of bound `parent_lb`:
    /// bounded by placing it, closed if the placement proves it infeasible or its bound
    /// reaches the best found.
    fn open_child(&mut self, net: &mut Net, last: Option<(usize, f64)>, r: usize, parent_lb: f64) {
        if self.dive {
            return;
        }
        let k = self.next[r];
        let mark = net.trail.len();
        let edge = self.edge(last, r);
        let room = self.room_arc(net, last, r);
        let gave_ups = net.gave_ups;
        if net.place_with(edge, r, k, room) {
            let l = net.chain.lc_s[k];
            self.next[r] += 1;
            self.order.push(r);
            self.rem_lc -= l;
            let lb = self.bound(net, Some((net.lc(r, k), l)));
            self.rem_lc += l;
            self.order.pop();
            self.next[r] -= 1;
            if lb < self.best_t * (1.0 - 1e-12) {
                self.open(lb);
            }
        } else if net.gave_ups > gave_ups {
            self.open(parent_lb);
        }
        net.undo(mark, edge);
    }

    fn dfs(&mut self, net: &mut Net, last: Option<(usize, f64)>) {
        self.nodes += 1;
        let (n, m) = (net.n, net.m);
        let lb = self.bound(net, last);
        let cut = self.best_t * (1.0 - 1e-12);
        if lb >= cut {
            return;
        }
        if self.order.len() == n * m {
            self.best_t = (0..n).map(|r| net.x[net.end(r)]).fold(0.0, f64::max);
            self.best = Some((self.order.clone(), net.x.clone()));
            return;
        }
        if self.nodes >= self.max_nodes
            || net.raises > self.max_nodes.saturating_mul(MAX_RAISES_PER_NODE)
        {
            self.out_of_budget = true;
            self.open(lb);
            return;
        }
        let kids = self.children(net, last);
        // Forward check: a robot whose next run cannot go next cannot go later either (see
        // [`Search::dead`]), so the node has no feasible completion.
        if kids.iter().any(|&r| self.dead(net, last, r)) {
            return;
        }
        for (i, &r) in kids.iter().enumerate() {
            if self.out_of_budget || (self.dive && self.best.is_some()) {
                for &rest in &kids[i..] {
                    self.open_child(net, last, rest, lb);
                }
                return;
            }
            let k = self.next[r];
            let mark = net.trail.len();
            let edge = self.edge(last, r);
            let room = self.room_arc(net, last, r);
            let gave_ups = net.gave_ups;
            if net.place_with(edge, r, k, room) {
                let l = net.chain.lc_s[k];
                self.next[r] += 1;
                self.order.push(r);
                self.rem_lc -= l;
                self.dfs(net, Some((net.lc(r, k), l)));
                self.rem_lc += l;
                self.order.pop();
                self.next[r] -= 1;
            } else if net.gave_ups > gave_ups {
                // Not proven infeasible: open, bounded by this node.
                self.open(lb);
            }
            net.undo(mark, edge);
        }
    }

    /// Whether placing robot `r`'s next run right after the last run is proven infeasible
    /// (a positive cycle, not the raise limit). Then so is placing it after any further runs:
    /// the cycle runs through the operator edge from the last run to it, and any further runs
    /// replace that edge by a path of operator edges at least as long (each run's length is
    /// ≥ 0, and a path into another robot's run holds a switch as the edge does), while the
    /// cycle's other edges stay. So no completion of the node exists.
    fn dead(&self, net: &mut Net, last: Option<(usize, f64)>, r: usize) -> bool {
        let k = self.next[r];
        if k == 0 {
            // A robot's first run: its start has no upper bound, never infeasible.
            return false;
        }
        let mark = net.trail.len();
        let edge = self.edge(last, r);
        let room = self.room_arc(net, last, r);
        let gave_ups = net.gave_ups;
        let ok = net.place_with(edge, r, k, room);
        let dead = !ok && net.gave_ups == gave_ups;
        net.undo(mark, edge);
        dead
    }

    /// The robots that may go next: earliest possible start first (ties by index); in the
    /// dive, the robots whose deadlines the first one's run would pass go before it, earliest
    /// deadline first (see [`search_with_switch`]).
    fn children(&self, net: &Net, last: Option<(usize, f64)>) -> Vec<usize> {
        let (n, m) = (net.n, net.m);
        let op_free = last.map_or(0.0, |(v, l)| net.x[v] + l);
        let last_robot = self.order.last().copied();
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
        if !self.dive || kids.len() < 2 {
            return kids.into_iter().map(|(_, r)| r).collect();
        }
        // The latest start of robot r's next run k ≥ 1: its gap's slowest traversal after
        // the end of run k − 1 at its earliest.
        let deadline = |r: usize| {
            let k = self.next[r];
            if k == 0 {
                f64::INFINITY
            } else {
                net.x[net.lc(r, k - 1)] + net.chain.lc_s[k - 1] + net.chain.gap_s[k].1
            }
        };
        let (first_start, first) = kids[0];
        let mut first_end = first_start + net.chain.lc_s[self.next[first]];
        if self.switch_s > 0.0 {
            first_end += self.switch_s;
        }
        let mut urgent: Vec<(f64, usize)> = kids
            .iter()
            .filter(|&&(_, r)| r != first && deadline(r) < first_end)
            .map(|&(_, r)| (deadline(r), r))
            .collect();
        if urgent.is_empty() {
            return kids.into_iter().map(|(_, r)| r).collect();
        }
        urgent.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut out: Vec<usize> = urgent.iter().map(|&(_, r)| r).collect();
        let rest: Vec<usize> = kids
            .iter()
            .map(|&(_, r)| r)
            .filter(|r| !out.contains(r))
            .collect();
        out.extend(rest);
        out
    }

    /// The serial order as a leaf: each robot's runs after the previous robot's (one node per
    /// run). Kept if it beats the best so far.
    fn serial(&mut self, net: &mut Net) {
        let (n, m) = (net.n, net.m);
        let base = net.trail.len();
        let mut last: Option<(usize, f64)> = None;
        let mut feasible = true;
        let mut placed = Vec::with_capacity(n * m);
        'robots: for r in 0..n {
            for k in 0..m {
                self.nodes += 1;
                let edge = self.edge_into(last, r, k, placed.last().copied());
                let room = self.room_arc_serial(net, last, r, k, placed.last().copied());
                if !net.place_with(edge, r, k, room) {
                    feasible = false;
                    net.undo(net.trail.len(), edge);
                    break 'robots;
                }
                placed.push(r);
                last = Some((net.lc(r, k), net.chain.lc_s[k]));
            }
        }
        if feasible {
            let t = (0..n).map(|r| net.x[net.end(r)]).fold(0.0, f64::max);
            if t < self.best_t {
                self.best_t = t;
                self.best = Some((placed.clone(), net.x.clone()));
            }
        }
        // Undo every placement: the trail back to the base and every operator edge.
        net.undo(base, None);
        for r in 0..n {
            for k in 0..m {
                let v = net.lc(r, k);
                net.op[v] = None;
                net.room_op[v] = None;
            }
        }
    }

    /// [`Search::edge`] for the serial order, whose last placed robot is `last_robot`.
    fn edge_serial(
        &self,
        last: Option<(usize, f64)>,
        r: usize,
        last_robot: Option<usize>,
    ) -> Option<(usize, f64)> {
        match last {
            Some((v, l)) if self.switch_s > 0.0 && Some(r) != last_robot => {
                Some((v, l + self.switch_s))
            }
            other => other,
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
        let out = search(&lhl(), n, f64::INFINITY, 1_000_000);
        let f = out.found.unwrap();
        assert!(out.proven);
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
        let out = search(&lhl(), 3, 0.6, 100_000);
        assert!(out.found.is_none());
        assert!(out.proven);
    }

    #[test]
    fn the_budget_stops_the_search_unproven_with_a_leaf_and_a_bound() {
        // Budget 3: the dive gets 1 node (no leaf), the serial order is the leaf (6 runs, 6
        // nodes), and the exact search has no budget left: its root stays open. The root's
        // bound is the operator's 6 × 0.1 s, here the optimum (three_robots_by_hand).
        let out = search(&lhl(), 3, f64::INFINITY, 3);
        assert!(!out.proven);
        assert_eq!(out.nodes, 1 + 6);
        let f = out.found.unwrap();
        check(&lhl(), &f);
        assert_eq!(f.order, vec![0, 0, 1, 1, 2, 2]);
        // Serial: each robot 0.1 + 0.05 + 0.1 s, robot r's first run right after robot
        // r − 1's last ends: robots end at 0.25, 0.5, 0.75 s.
        assert!((f.t_total_s - 0.75).abs() < 1e-12, "{}", f.t_total_s);
        assert!(
            (out.lower_bound_s - 0.6).abs() < 1e-12,
            "{}",
            out.lower_bound_s
        );
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
        let out = search(&chain, 2, f64::INFINITY, 1_000_000);
        let f = out.found.unwrap();
        assert!(out.proven);
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
            let out = search(&chain, 3, f64::INFINITY, 1_000_000);
            let f = out.found.unwrap();
            prop_assert!(out.proven);
            prop_assert!((f.t_total_s - brute).abs() <= 1e-9 * brute, "{} vs {}", f.t_total_s, brute);
            check(&chain, &f);
            // Two robots: the same against all orders, and never above the dynamic program's
            // optimum (which can exceed it on rigid gaps, see below).
            let brute2 = all_orders(2, m)
                .iter()
                .filter_map(|o| order_t_total(&chain, 2, o))
                .fold(f64::INFINITY, f64::min);
            let two = search(&chain, 2, f64::INFINITY, 1_000_000);
            prop_assert!(two.proven);
            let two = two.found.unwrap().t_total_s;
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
                let out = search_with_switch(&chain, n, f64::INFINITY, 1_000_000, delta);
                prop_assert!(out.proven);
                match out.found {
                    Some(f) => {
                        prop_assert!((f.t_total_s - brute).abs() <= 1e-9 * brute,
                            "n {}: {} vs {}", n, f.t_total_s, brute);
                        let free = search(&chain, n, f64::INFINITY, 1_000_000);
                        let free = free.found.unwrap().t_total_s;
                        prop_assert!(f.t_total_s >= free * (1.0 - 1e-9), "{} < {}", f.t_total_s, free);
                    }
                    None => prop_assert!(brute.is_infinite(), "n {}: none found, brute {}", n, brute),
                }
            }
            let two = search_with_switch(&chain, 2, f64::INFINITY, 1_000_000, delta).found;
            let clear = super::super::search::Clearance::uniform(delta, None);
            if let (Some(two), (super::super::search::Outcome::Done(Some(dp)), _)) = (
                two,
                super::super::search::search(&chain, &clear, f64::INFINITY, 4_000_000),
            ) {
                prop_assert!(two.t_total_s <= dp.t_total_s * (1.0 + 1e-9),
                    "{} vs {}", two.t_total_s, dp.t_total_s);
            }
        }

        /// On any budget the search returns an order (the dive's or the serial one) no shorter
        /// than the optimum over all orders, and a lower bound (the open nodes' and the best
        /// found) no longer than it; proven, the bound is the optimum.
        #[test]
        fn a_small_budget_keeps_a_leaf_and_a_lower_bound(
            chain in random_chain(),
            budget in 1usize..60,
            delta in prop_oneof![Just(0.0), 0.0f64..0.05],
        ) {
            let m = chain.n_lc();
            let brute = all_orders(3, m)
                .iter()
                .filter_map(|o| order_t_total_switch(&chain, 3, o, delta))
                .fold(f64::INFINITY, f64::min);
            let out = search_with_switch(&chain, 3, f64::INFINITY, budget, delta);
            let f = out.found.unwrap();
            check(&chain, &f);
            prop_assert!(f.t_total_s >= brute * (1.0 - 1e-9), "{} < {}", f.t_total_s, brute);
            prop_assert!(out.lower_bound_s <= brute * (1.0 + 1e-9),
                "bound {} above the optimum {}", out.lower_bound_s, brute);
            prop_assert!(out.lower_bound_s <= f.t_total_s);
            if out.proven {
                prop_assert!((out.lower_bound_s - brute).abs() <= 1e-9 * brute);
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Room arcs on every run `k ≥ 1` (issue 41): the order found keeps the chain, the
        /// switch time and every arc (a switch into run `k` of robot `c` after run `j`:
        /// `x(c, k − 1) + L_{k−1} + a_k ≥ x(j) + L_j + δ + e`), the serial order being always
        /// feasible; and, a restriction of the plain problem, it is never shorter than the plain
        /// optimum with the switch time.
        #[test]
        fn search_with_room_keeps_its_arcs(
            chain in random_chain(),
            delta in 0.001f64..0.05,
            extra in 0.0f64..0.05,
        ) {
            let m = chain.n_lc();
            let guard: Vec<Option<f64>> = (0..m)
                .map(|k| (k >= 1).then(|| extra - chain.lc_s[k - 1] - chain.gap_s[k].0))
                .collect();
            for n in [2usize, 3] {
                let out = search_with_room(&chain, n, f64::INFINITY, 1_000_000, delta, &guard);
                prop_assert!(out.proven);
                let f = out.found.expect("the serial order is feasible");
                check(&chain, &f);
                let t = &f.times;
                let mut next = vec![0; n];
                let mut last: Option<(usize, usize)> = None;
                for &r in &f.order {
                    let k = next[r];
                    next[r] += 1;
                    if let Some((p, j)) = last.filter(|&(p, _)| p != r) {
                        let prev_end = t.lc_start_s[p][j] + chain.lc_s[j];
                        prop_assert!(t.lc_start_s[r][k] >= prev_end + delta - 1e-9);
                        if k >= 1 {
                            let arrival = t.lc_start_s[r][k - 1] + chain.lc_s[k - 1] + chain.gap_s[k].0;
                            prop_assert!(arrival >= prev_end + delta + extra - 1e-9,
                                "robot {} run {}: arrival {} before {}", r, k, arrival,
                                prev_end + delta + extra);
                        }
                    }
                    last = Some((r, k));
                }
                let plain = search_with_switch(&chain, n, f64::INFINITY, 1_000_000, delta);
                let plain = plain.found.expect("the serial order is feasible").t_total_s;
                prop_assert!(f.t_total_s >= plain * (1.0 - 1e-9), "{} < {}", f.t_total_s, plain);
            }
        }

        /// [`search_with_room_travel`]: every switch into run `k` lasts at least `δ` plus its
        /// travel; empty travel is [`search_with_room`] to the bit; never shorter than
        /// without the travel.
        #[test]
        fn search_with_room_travel_keeps_its_travel(
            chain in random_chain(),
            delta in 0.001f64..0.05,
            travel in proptest::collection::vec(0.0f64..0.05, 8),
        ) {
            let m = chain.n_lc();
            let travel: Vec<f64> = (0..m).map(|k| travel[k % travel.len()]).collect();
            for n in [2usize, 3] {
                let out =
                    search_with_room_travel(&chain, n, f64::INFINITY, 1_000_000, delta, &[], &travel);
                prop_assert!(out.proven);
                let f = out.found.expect("the serial order is feasible");
                check(&chain, &f);
                let t = &f.times;
                let mut next = vec![0; n];
                let mut last: Option<(usize, usize)> = None;
                for &r in &f.order {
                    let k = next[r];
                    next[r] += 1;
                    if let Some((p, j)) = last.filter(|&(p, _)| p != r) {
                        let prev_end = t.lc_start_s[p][j] + chain.lc_s[j];
                        prop_assert!(t.lc_start_s[r][k] >= prev_end + delta + travel[k] - 1e-9,
                            "robot {} run {}: {} before {}", r, k, t.lc_start_s[r][k],
                            prev_end + delta + travel[k]);
                    }
                    last = Some((r, k));
                }
                let none = search_with_room_travel(&chain, n, f64::INFINITY, 1_000_000, delta, &[], &[]);
                prop_assert_eq!(
                    &none,
                    &search_with_room(&chain, n, f64::INFINITY, 1_000_000, delta, &[])
                );
                let none = none.found.expect("the serial order is feasible").t_total_s;
                prop_assert!(f.t_total_s >= none * (1.0 - 1e-9), "{} < {}", f.t_total_s, none);
            }
        }
    }
}
