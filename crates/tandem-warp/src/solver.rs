//! Dynamic programming over the node × candidate grid (Deriso & Boyd's GDTW solver).

use rayon::prelude::*;

use crate::Result;
use crate::fill;
use crate::objective::Prepared;
use crate::params::WarpParams;
use crate::signal::SignalRef;
use crate::warp::Warp;

/// Reference samples at which a coarse pass (one with fewer nodes than the final `N`: the first
/// pass and the early refinement passes) evaluates the loss inside each segment between two nodes;
/// such a pass may also interpolate the loss linearly between query samples a quarter candidate
/// spacing apart. Coarse passes only steer the search; the last pass integrates the exact loss
/// over every reference sample, and [`crate::Warp::objective`] is always exact.
pub const COARSE_POINTS_PER_SEGMENT: usize = 4;

/// Largest difference of slope `φ'` (normalized time) between two neighbouring candidate paths
/// of the first pass: its candidate spacing at a node is at most this times the node spacing
/// (in query samples at slope 1). More first-pass nodes therefore bring more candidates, so a
/// finer time grid never makes the first pass unable to follow a slope that a coarser one could.
pub const COARSE_SLOPE_STEP: f64 = 0.5;

/// Ratio of a refinement pass's candidate spacing to the previous pass's resolution. It is fixed,
/// so more refinement candidates or a larger [`refine_radius`](crate::WarpParams::refine_radius)
/// widen the searched range and never coarsen it. `5/14` is the ratio of the former defaults
/// (15 candidates over ±2.5 previous spacings).
pub const REFINE_SPACING_RATIO: f64 = 5.0 / 14.0;

/// Candidate spacings, in query samples, of the two polish passes that end every alignment.
/// After the refinements, the best warp so far is moved by at most [`POLISH_RADIUS`] such
/// spacings at every one of the `N` nodes (dynamic programming over the exact objective), first
/// by whole query samples, then by half samples. A pass keeps the warp unless it lowers the
/// objective. These passes make the result depend less on where the refinements ended, and so
/// on the search effort.
pub const POLISH_STEPS: [f64; 2] = [1.0, 0.5];

/// Spacings searched either side of the current warp at every node in a polish pass.
pub const POLISH_RADIUS: usize = 1;

/// Largest candidate count of one node (back pointers are `u16`).
pub(crate) const MAX_CANDIDATES: usize = 65535;

/// Candidate grid of one pass: node `i` sits at reference sample `nodes[i]` and has `count[i]`
/// candidates `lo[i] + j * step[i]` (query samples), except that the outermost ones may be
/// moved inwards onto the edges of the feasible band: candidate 0 is `bottom[i]` and candidate
/// `count[i] − 1` is `top[i]` (see [`snap_to_band`]). `center[i]` is the candidate equal to
/// the previous pass's solution (the identity's in the first pass).
struct Grid {
    nodes: Vec<usize>,
    lo: Vec<f64>,
    step: Vec<f64>,
    count: Vec<usize>,
    center: Vec<usize>,
    bottom: Vec<f64>,
    top: Vec<f64>,
}

impl Grid {
    /// A grid of `n` nodes with one candidate each (filled in by the grid builders).
    fn with_nodes(nodes: Vec<usize>, lo: Vec<f64>) -> Self {
        let n = nodes.len();
        Self {
            bottom: lo.clone(),
            top: lo.clone(),
            lo,
            step: vec![0.0; n],
            count: vec![1; n],
            center: vec![0; n],
            nodes,
        }
    }

    #[inline]
    fn cand(&self, i: usize, j: usize) -> f64 {
        if j == 0 {
            self.bottom[i]
        } else if j + 1 == self.count[i] {
            self.top[i]
        } else {
            let jf = j as f64;
            self.lo[i] + jf * self.step[i]
        }
    }
    fn hi(&self, i: usize) -> f64 {
        self.top[i]
    }
}

/// Makes the edges of the feasible band `[l, u]` candidates of node `i` where its candidate
/// range ends less than one spacing inside them: the outermost candidate on that side is moved
/// onto the edge if it is within a millionth of a spacing of it, and otherwise one candidate is
/// added there (closer to its neighbour than the spacing); the centre candidate never moves.
/// Without this, a path along an edge (slope `s_max` from `(0, 0)`, or `s_min` into `(1, 1)`) is
/// not on the grid, and the grid's nearest path at the bounding slope loses up to one spacing at
/// every node, which adds up along the edge: rounding in the band's bounds then excludes valid
/// paths, as it did in the initial bounds `l₀`, `u₀` of an independent GDTW implementation.
fn snap_to_band(g: &mut Grid, i: usize, (l, u): (f64, f64)) {
    let step = g.step[i];
    g.bottom[i] = g.lo[i];
    g.top[i] = g.lo[i] + (g.count[i] - 1) as f64 * step;
    if step <= 0.0 {
        return;
    }
    let tiny = 1e-6 * step;
    let gap = g.bottom[i] - l;
    if gap.abs() <= tiny && g.center[i] > 0 {
        g.bottom[i] = l;
    } else if gap > tiny && gap < step && g.count[i] < MAX_CANDIDATES {
        g.lo[i] -= step;
        g.count[i] += 1;
        g.center[i] += 1;
        g.bottom[i] = l;
    }
    let last = g.count[i] - 1;
    let gap = u - (g.lo[i] + last as f64 * step);
    if gap.abs() <= tiny && last != g.center[i] {
        g.top[i] = u;
    } else if gap > tiny && gap < step && g.count[i] < MAX_CANDIDATES {
        g.count[i] += 1;
        g.top[i] = u;
    }
}

/// `N` node positions spread evenly over `0..n_ref` (first and last sample included).
fn spread_nodes(n_ref: usize, n_nodes: usize) -> Vec<usize> {
    let n_nodes = n_nodes.clamp(2, n_ref);
    (0..n_nodes)
        .map(|i| (i * (n_ref - 1) + (n_nodes - 1) / 2) / (n_nodes - 1))
        .collect()
}

/// Feasible band `[l, u]` of `ψ` (query samples) at reference sample `n`: the values reachable
/// from `(0, 0)` and able to reach `(1, 1)` with slopes in `[s_min, s_max]`.
fn band(prep: &Prepared<'_>, s_min: f64, s_max: f64, n: usize) -> (f64, f64) {
    if n == 0 {
        return (0.0, 0.0);
    }
    if n == prep.nr - 1 {
        return (prep.qscale, prep.qscale);
    }
    let t = n as f64 * prep.h;
    let l = (s_min * t).max(1.0 - s_max * (1.0 - t)).clamp(0.0, 1.0);
    let u = (s_max * t).min(1.0 - s_min * (1.0 - t)).clamp(0.0, 1.0);
    (l * prep.qscale, u.max(l) * prep.qscale)
}

/// First pass: equally spaced candidates covering the whole feasible band at every node, at least
/// `m` of them and at most `max_step` query samples apart, anchored so that the identity warp
/// `φ(t) = t` is one of them (candidate `center[i]`).
fn first_grid(
    prep: &Prepared<'_>,
    nodes: Vec<usize>,
    m: usize,
    max_step: f64,
    s: (f64, f64),
) -> Grid {
    let n = nodes.len();
    let mut g = Grid::with_nodes(nodes, vec![0.0; n]);
    for i in 0..n {
        let (l, u) = band(prep, s.0, s.1, g.nodes[i]);
        let c = (g.nodes[i] as f64 * prep.h * prep.qscale).clamp(l, u);
        g.lo[i] = c;
        g.bottom[i] = c;
        g.top[i] = c;
        if u - l > 1e-9 {
            // at most MAX_CANDIDATES candidates: back pointers are u16
            let step = ((u - l) / (m - 1) as f64)
                .min(max_step)
                .max((u - l) / (MAX_CANDIDATES - 1) as f64);
            let steps = |room: f64| (room / step + 1e-9).floor().max(0.0) as usize;
            let (down, up) = (steps(c - l), steps(u - c));
            let lo = c - down as f64 * step;
            g.lo[i] = lo;
            g.step[i] = step;
            g.count[i] = down + up + 1;
            g.center[i] = down;
            snap_to_band(&mut g, i, (l, u));
        }
    }
    g
}

/// Refinement pass: [`refine_count`] candidates centred on `centers[i]`, spacing
/// `REFINE_SPACING_RATIO · prev_res[i]`, truncated (not compressed) to the feasible band so the
/// centre stays a candidate.
fn refine_grid(
    prep: &Prepared<'_>,
    nodes: Vec<usize>,
    centers: &[f64],
    prev_res: &[f64],
    m: usize,
    radius: f64,
    s: (f64, f64),
) -> Grid {
    let m = refine_count(m, radius);
    let step: Vec<f64> = prev_res.iter().map(|r| REFINE_SPACING_RATIO * r).collect();
    tube_grid(prep, nodes, centers, &step, (m - 1) / 2, m / 2, s)
}

/// Candidate count of a refinement pass: at least `m`, and enough to reach `±radius` previous
/// resolutions at the spacing `REFINE_SPACING_RATIO` of one.
fn refine_count(m: usize, radius: f64) -> usize {
    let half = (radius / REFINE_SPACING_RATIO - 1e-9).ceil() as usize;
    m.max(2 * half + 1).min(MAX_CANDIDATES)
}

/// Candidates `centers[i] + j · step[i]` for `j` in `−down..=up`, truncated (not compressed) to
/// the feasible band so the centre stays a candidate (`center[i]`).
fn tube_grid(
    prep: &Prepared<'_>,
    nodes: Vec<usize>,
    centers: &[f64],
    step: &[f64],
    down: usize,
    up: usize,
    s: (f64, f64),
) -> Grid {
    let n = nodes.len();
    let mut g = Grid::with_nodes(nodes, centers.to_vec());
    for i in 0..n {
        let (l, u) = band(prep, s.0, s.1, g.nodes[i]);
        let st = step[i];
        if u - l <= 1e-9 || st <= 1e-12 {
            continue;
        }
        let c = centers[i];
        let steps = |room: f64| (room / st + 1e-9).floor().max(0.0) as usize;
        let d = steps(c - l).min(down);
        g.lo[i] = c - d as f64 * st;
        g.step[i] = st;
        g.count[i] = d + steps(u - c).min(up) + 1;
        g.center[i] = d;
        snap_to_band(&mut g, i, (l, u));
    }
    g
}

/// A feasible candidate `j` of node `i` in [`solve_pass`]: its DP value `fj`, query time `p`
/// (query samples), offset `da = p/(T_query − 1) − t_i` from the identity (normalized time), the
/// candidates `k_lo..=k_hi` of node `i + 1` it may move to, and the one tried first.
#[derive(Clone, Copy)]
struct Source {
    j: usize,
    fj: f64,
    p: f64,
    da: f64,
    k_lo: usize,
    k_hi: usize,
    first: usize,
}

/// Scratch for the per-segment cost table: `ℓ(n, s)` for interior reference samples `n` and
/// integer query samples `s` in a window.
struct Table {
    e: Vec<f64>,
    s0: usize,
    width: usize,
}

/// One DP pass. Returns the optimal value at every node and the DP objective, or `None` if no
/// feasible path exists in the grid.
#[expect(
    clippy::too_many_lines,
    reason = "the hot loop is kept in one place on purpose"
)]
fn solve_pass(
    prep: &Prepared<'_>,
    grid: &Grid,
    s: (f64, f64),
    max_jump: Option<usize>,
    points: Option<usize>,
) -> Option<(Vec<f64>, f64)> {
    let n_nodes = grid.nodes.len();
    let mut off = Vec::with_capacity(n_nodes + 1);
    off.push(0usize);
    for &c in &grid.count {
        off.push(off[off.len() - 1] + c);
    }
    let mut back = vec![0u16; off[n_nodes]];
    let mut f_prev: Vec<f64> = (0..grid.count[0])
        .map(|j| prep.trap_weight(grid.nodes[0]) * prep.loss(grid.nodes[0], grid.cand(0, j)))
        .collect();
    let mut f_next: Vec<f64> = Vec::new();
    let mut rows: Vec<(usize, f64)> = Vec::new();
    let mut cum_b: Vec<f64> = Vec::new();
    let mut sources: Vec<Source> = Vec::new();
    let mut table = Table {
        e: Vec::new(),
        s0: 0,
        width: 0,
    };
    let g = prep.qscale * prep.h; // query samples per reference sample at slope 1
    let nq = prep.nq;

    for i in 0..n_nodes - 1 {
        let (a, b) = (grid.nodes[i], grid.nodes[i + 1]);
        let dr = b - a;
        let drf = dr as f64;
        let (dmin, dmax, tol) = (s.0 * drf * g, s.1 * drf * g, 1e-9 * drf * g);

        // interior reference samples of this segment and their weight
        rows.clear();
        let n_int = dr - 1;
        let take = points.map_or(n_int, |p| p.min(n_int));
        for r in 0..take {
            let n = if take == n_int {
                a + 1 + r
            } else {
                a + 1 + (2 * r + 1) * n_int / (2 * take)
            };
            let alpha = (n - a) as f64 / drf;
            rows.push((n, alpha));
        }
        let w_int = if take > 0 {
            prep.h * n_int as f64 / take as f64
        } else {
            0.0
        };

        let (ca, cb) = (grid.count[i], grid.count[i + 1]);
        // transitions searched per candidate j: limited by the slope band and by max_jump
        let slope_w = if grid.step[i + 1] > 0.0 {
            let w = ((dmax - dmin) / grid.step[i + 1]).min(cb as f64) as usize + 1;
            w.min(cb)
        } else {
            1
        };
        let jump_w = max_jump.map_or(slope_w, |k| (2 * k + 1).min(slope_w));
        let est_edges = ca * jump_w;
        let tmin = grid.lo[i].min(grid.lo[i + 1]).max(0.0);
        let tmax = grid.hi(i).max(grid.hi(i + 1)).min(prep.qscale);
        let (s0, s1) = (
            (tmin as usize).min(nq - 2),
            ((tmax as usize) + 1).min(nq - 1),
        );
        let width = s1 - s0 + 1;
        // Loss evaluation strategy for the interior samples of this segment:
        // - exact table (stride 1): ℓ at every integer query sample of the window, then
        //   ℓ(n, s + f) = (1 − f) ℓ(n, s) + f ℓ(n, s + 1) − f (1 − f) ‖x₂(s+1) − x₂(s)‖²_W exactly;
        // - strided table (approximate passes only): ℓ every `stride` query samples, linearly
        //   interpolated;
        // - direct evaluation otherwise.
        let stride = if rows.is_empty() {
            0
        } else if width + 1 < est_edges {
            1
        } else if points.is_some() {
            // resolve a quarter of the candidate spacing; use it only if cheaper than direct
            let min_step = grid.step[i].min(grid.step[i + 1]);
            let stride = ((min_step / 4.0) as usize).max(2);
            if (s1 - s0) / stride + 2 < est_edges {
                stride
            } else {
                0
            }
        } else {
            0
        };
        if stride > 0 {
            let cols = (s1 - s0).div_ceil(stride) + 1;
            table.s0 = s0;
            table.width = cols;
            table.e.clear();
            for &(n, _) in &rows {
                for c in 0..cols {
                    table
                        .e
                        .push(prep.loss_int(n, (s0 + c * stride).min(nq - 1)));
                }
            }
        }
        let inv_stride = if stride > 0 { 1.0 / stride as f64 } else { 0.0 };

        // regularizer constants of this segment (see Prepared::reg_cost)
        let (ta, tb) = (a as f64 * prep.h, b as f64 * prep.h);
        let dt = tb - ta;
        let kappa = 1.0 / (prep.qscale * dt);
        let (inst_c, cum_c) = (prep.lambda_inst * dt, prep.lambda_cum * dt / 3.0);
        cum_b.clear();
        cum_b.extend((0..cb).map(|k| grid.cand(i + 1, k) / prep.qscale - tb));
        f_next.clear();
        f_next.resize(cb, f64::INFINITY);
        let back_b = &mut back[off[i + 1]..off[i + 2]];
        let (lo_b, step_b) = (grid.lo[i + 1], grid.step[i + 1]);
        // the transitions of every feasible candidate j of node i: its k range and the k that
        // keeps its offset from the previous solution (tried first, see below)
        sources.clear();
        for (j, &fj) in f_prev.iter().enumerate() {
            if !fj.is_finite() {
                continue;
            }
            let p = grid.cand(i, j);
            // candidates k of node i+1 satisfying the slope bounds
            let (mut k_lo, mut k_hi) = if cb == 1 || step_b <= 0.0 {
                (0usize, 0usize)
            } else {
                // exact for the inner candidates; the outermost ones may sit up to one spacing
                // inside their uniform positions (snapped to the band), so each is also tried
                // when its neighbour is the first one out of range, and the slope check below
                // decides
                let lo = ((p + dmin - tol - lo_b) / step_b).ceil();
                let hi = ((p + dmax + tol - lo_b) / step_b).floor();
                if hi < 0.0 || lo > (cb - 1) as f64 {
                    continue;
                }
                let k_lo = if lo == 1.0 { 0 } else { lo.max(0.0) as usize };
                let k_hi = if hi == (cb - 2) as f64 {
                    cb - 1
                } else {
                    (hi as usize).min(cb - 1)
                };
                (k_lo, k_hi)
            };
            // relative offsets from the previous solution: (k − center_b) vs (j − center_a)
            let rel = j as isize - grid.center[i] as isize + grid.center[i + 1] as isize;
            if let Some(kj) = max_jump {
                let lo = (rel - kj as isize).max(0) as usize;
                let hi = rel + kj as isize;
                if hi < 0 {
                    continue;
                }
                k_lo = k_lo.max(lo);
                k_hi = k_hi.min(hi as usize);
            }
            let k_hi = k_hi.min(cb - 1);
            if k_lo > k_hi {
                continue;
            }
            let first = rel.clamp(k_lo as isize, k_hi as isize) as usize;
            sources.push(Source {
                j,
                fj,
                p,
                da: p / prep.qscale - ta,
                k_lo,
                k_hi,
                first,
            });
        }
        // Every transition is tried, in two sweeps: first each j's transition that keeps its
        // offset from the previous solution (usually close to the best into its k), then the
        // others. A transition wins its k if its cost is lower, or equal with a lower j, so the
        // result is the same as in any order (ties go to the lowest j). With the costs of the
        // first sweep as bounds, the direct evaluation stops adding a transition's loss (which
        // is never negative) as soon as the sum exceeds the best cost into its k.
        let mut edge = |src: &Source, k: usize| {
            let Source { j, fj, p, da, .. } = *src;
            let qv = grid.cand(i + 1, k);
            let d = qv - p;
            if d < dmin - tol || d > dmax + tol {
                return;
            }
            let slope_m1 = d * kappa - 1.0;
            let db = cum_b[k];
            let mut cost =
                fj + inst_c * slope_m1 * slope_m1 + cum_c * (da * da + da * db + db * db);
            let bound = f_next[k];
            if !rows.is_empty() {
                let mut acc = 0.0;
                if stride == 1 {
                    let e = &table.e;
                    for (r, &(_, alpha)) in rows.iter().enumerate() {
                        let tau = p + d * alpha;
                        let sq = (tau.max(0.0) as usize).clamp(s0, s1 - 1);
                        let f = tau - sq as f64;
                        let base = r * width + (sq - s0);
                        let (e0, e1) = (e[base], e[base + 1]);
                        acc += e0 + f * (e1 - e0) - f * (1.0 - f) * prep.d2[sq];
                    }
                } else if stride > 1 {
                    // each term interpolates two losses (f in [0, 1]): never negative
                    if cost > bound {
                        return;
                    }
                    let (e, cols) = (&table.e, table.width);
                    let s0f = s0 as f64;
                    for (r, &(_, alpha)) in rows.iter().enumerate() {
                        let u = ((p + d * alpha - s0f) * inv_stride).max(0.0);
                        let c = (u as usize).min(cols - 2);
                        let f = u - c as f64;
                        let base = r * cols + c;
                        acc += e[base] + f * (e[base + 1] - e[base]);
                    }
                } else {
                    // ℓ ≥ 0, and adding or scaling by non-negative numbers never lowers a sum
                    // in floating point: a partial sum above the bound cannot win
                    if cost > bound {
                        return;
                    }
                    for &(n, alpha) in &rows {
                        acc += prep.loss(n, p + d * alpha);
                        if cost + w_int * acc > bound {
                            return;
                        }
                    }
                }
                cost += w_int * acc;
            }
            if cost < bound || (cost == bound && usize::from(back_b[k]) > j) {
                f_next[k] = cost;
                back_b[k] = j as u16;
            }
        };
        for src in &sources {
            edge(src, src.first);
        }
        for src in &sources {
            for k in src.k_lo..=src.k_hi {
                if k != src.first {
                    edge(src, k);
                }
            }
        }
        let wb = prep.trap_weight(b);
        for (k, fk) in f_next.iter_mut().enumerate() {
            if fk.is_finite() {
                *fk += wb * prep.loss(b, grid.cand(i + 1, k));
            }
        }
        std::mem::swap(&mut f_prev, &mut f_next);
    }

    let last = n_nodes - 1;
    let total = f_prev[0];
    if !total.is_finite() {
        return None;
    }
    let mut vals = vec![0.0; n_nodes];
    let mut j = 0usize;
    for i in (0..=last).rev() {
        vals[i] = grid.cand(i, j);
        if i > 0 {
            j = usize::from(back[off[i] + j]);
        }
    }
    vals[0] = 0.0;
    vals[last] = prep.qscale;
    Some((vals, total))
}

/// Linear interpolation of `vals` given at sorted reference samples `xs`, at sample `n`.
fn interp_at(xs: &[usize], vals: &[f64], n: usize) -> f64 {
    let i = xs.partition_point(|&x| x <= n).clamp(1, xs.len() - 1);
    let (a, b) = (xs[i - 1], xs[i]);
    let alpha = (n.clamp(a, b) - a) as f64 / (b - a) as f64;
    vals[i - 1] + alpha * (vals[i] - vals[i - 1])
}

/// Per-reference-sample warp from node values (linear between nodes).
fn expand(nodes: &[usize], vals: &[f64], n_ref: usize) -> Vec<f64> {
    let mut out = vec![0.0; n_ref];
    for (seg, w) in nodes.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        let (p, q) = (vals[seg], vals[seg + 1]);
        let dr = (b - a) as f64;
        for (n, o) in out.iter_mut().enumerate().take(b + 1).skip(a) {
            let alpha = (n - a) as f64 / dr;
            *o = p + (q - p) * alpha;
        }
    }
    out[n_ref - 1] = vals[vals.len() - 1];
    // rounding can never make a valid warp decrease, but guard the invariant anyway
    for n in 1..n_ref {
        if out[n] < out[n - 1] {
            out[n] = out[n - 1];
        }
    }
    out
}

/// Query samples spanned by a slope change of [`COARSE_SLOPE_STEP`] over `seg` reference samples.
fn slope_step_span(prep: &Prepared<'_>, seg: f64) -> f64 {
    COARSE_SLOPE_STEP * seg * prep.qscale * prep.h
}

/// The best warp found so far (values at every reference sample) and its exact objective.
struct Best {
    values: Vec<f64>,
    objective: f64,
}

impl Best {
    /// Keeps `values` if its exact objective is lower.
    fn offer(&mut self, prep: &Prepared<'_>, values: &[f64]) {
        let objective = prep.objective(values);
        if objective < self.objective {
            self.objective = objective;
            self.values.clear();
            self.values.extend_from_slice(values);
        }
    }
}

fn align_prepared(prep: &Prepared<'_>, params: &WarpParams) -> Warp {
    let s = (params.slope_min, params.slope_max);
    let n_final = params.nodes_for(prep.nr);
    let nodes = spread_nodes(prep.nr, n_final);
    let n0 = params.coarse_nodes.min(n_final);
    let points_for = |n_pass: usize| (n_pass < n_final).then_some(COARSE_POINTS_PER_SEGMENT);
    // first pass: the whole band, candidates at most COARSE_SLOPE_STEP of slope apart
    let nodes0 = spread_nodes(prep.nr, n0);
    let min_seg = nodes0.windows(2).map(|w| w[1] - w[0]).min().unwrap_or(1);
    let max_step = slope_step_span(prep, min_seg as f64);
    let grid0 = first_grid(prep, nodes0, params.coarse_candidates, max_step, s);
    let (vals0, _) = solve_pass(prep, &grid0, s, None, points_for(n0))
        .expect("the identity warp is a feasible path of the first grid");
    let mut current = expand(&grid0.nodes, &vals0, prep.nr);
    let mut best = Best {
        objective: prep.objective(&current),
        values: current.clone(),
    };
    let mut prev = grid0;
    for pass in 1..=params.refinements {
        // node count doubles every pass from the coarse count; the last pass uses all N nodes
        let n_pass = if pass == params.refinements {
            n_final
        } else {
            n0.saturating_mul(1usize << pass.min(40)).min(n_final)
        };
        let pass_nodes = if n_pass == n_final {
            nodes.clone()
        } else {
            spread_nodes(prep.nr, n_pass)
        };
        // resolution of the previous pass at each new node: its candidate spacing, but at least
        // the span of COARSE_SLOPE_STEP of slope over its node spacing (what its nodes and
        // quadrature could not resolve, whatever its candidate count)
        let prev_seg = (prep.nr - 1) as f64 / (prev.nodes.len() - 1) as f64;
        let seg_res = slope_step_span(prep, prev_seg);
        let prev_res: Vec<f64> = pass_nodes
            .iter()
            .map(|&n| interp_at(&prev.nodes, &prev.step, n).max(seg_res))
            .collect();
        let centers: Vec<f64> = pass_nodes.iter().map(|&n| current[n]).collect();
        let grid = refine_grid(
            prep,
            pass_nodes,
            &centers,
            &prev_res,
            params.n_candidates,
            params.refine_radius,
            s,
        );
        let Some((vals, _)) = solve_pass(prep, &grid, s, params.max_jump, points_for(n_pass))
        else {
            break;
        };
        current = expand(&grid.nodes, &vals, prep.nr);
        best.offer(prep, &current);
        prev = grid;
    }
    // polish the best warp at fixed spacings on all N nodes (see POLISH_STEPS)
    for step in POLISH_STEPS {
        let centers: Vec<f64> = nodes.iter().map(|&n| best.values[n]).collect();
        let steps = vec![step; nodes.len()];
        let grid = tube_grid(
            prep,
            nodes.clone(),
            &centers,
            &steps,
            POLISH_RADIUS,
            POLISH_RADIUS,
            s,
        );
        if let Some((vals, _)) = solve_pass(prep, &grid, s, None, None) {
            best.offer(prep, &expand(&grid.nodes, &vals, prep.nr));
        }
    }
    // the smoothest continuation inside flat stretches (WarpParams::fill_length)
    let Best {
        mut values,
        mut objective,
    } = best;
    if fill::fill_flats(
        prep,
        &mut values,
        params.fill_length,
        params.smooth_width,
        s,
    ) {
        objective = prep.objective(&values);
    }
    Warp::from_parts(values, objective)
}

/// Aligns `query` to `reference` with GDTW (paper §II-B1, Eq. 2–3): finds the warp
/// `ψ: reference samples → query samples` minimizing [`crate::objective_of`] under the
/// slope bounds of `params`, then fills its flat stretches
/// ([`WarpParams::fill_length`]; the minimizer itself with `fill_length = 0`).
/// Single-threaded and deterministic (ties go to the lowest index).
///
/// # Errors
/// [`crate::Error::ChannelMismatch`], [`crate::Error::NonFinite`], [`crate::Error::BadParam`],
/// [`crate::Error::InfeasibleSlopes`].
pub fn align(reference: SignalRef<'_>, query: SignalRef<'_>, params: &WarpParams) -> Result<Warp> {
    let prep = Prepared::new(reference, query, params, "query")?;
    Ok(align_prepared(&prep, params))
}

/// Aligns every query to the one reference, in parallel with rayon (one alignment per task).
/// Output order = input order; each result is identical to [`align`] on that query, whatever the
/// thread count. On failure the error of the lowest-index failing query is returned.
///
/// # Errors
/// As [`align`]; non-finite values name the query as `"query #i"`.
pub fn align_many(
    reference: SignalRef<'_>,
    queries: &[SignalRef<'_>],
    params: &WarpParams,
) -> Result<Vec<Warp>> {
    params.validate()?;
    let results: Vec<Result<Warp>> = queries
        .par_iter()
        .enumerate()
        .map(|(i, &q)| {
            let prep = Prepared::new(reference, q, params, &format!("query #{i}"))?;
            Ok(align_prepared(&prep, params))
        })
        .collect();
    results.into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nodes_are_spread_and_pinned() {
        assert_eq!(spread_nodes(10, 4), vec![0, 3, 6, 9]);
        assert_eq!(spread_nodes(5, 5), vec![0, 1, 2, 3, 4]);
        assert_eq!(spread_nodes(5, 9), vec![0, 1, 2, 3, 4]);
        let n = spread_nodes(1001, 37);
        assert_eq!((n[0], n[36]), (0, 1000));
        assert!(n.windows(2).all(|w| w[1] > w[0]));
    }

    fn ramp(n: usize, f: impl Fn(f64) -> f64) -> Vec<f64> {
        (0..n).map(|i| f(i as f64 / (n - 1) as f64)).collect()
    }

    #[test]
    fn dp_cost_equals_objective_of_the_returned_warp() {
        // With every reference sample integrated (points = None), the DP's own total must be
        // exactly the discretized objective of the expanded warp, with and without the table.
        let r = ramp(200, |t| (6.0 * t).sin() + 0.3 * t);
        let q = ramp(260, |t| (6.0 * t.powf(1.3)).sin() + 0.3 * t);
        let (rs, qs) = (
            SignalRef::new(&r, 1).unwrap(),
            SignalRef::new(&q, 1).unwrap(),
        );
        let params = WarpParams {
            n_nodes: Some(23),
            ..Default::default()
        };
        let prep = Prepared::new(rs, qs, &params, "query").unwrap();
        let s = (params.slope_min, params.slope_max);
        let nodes = spread_nodes(200, 23);
        for m in [5, 41] {
            let grid = first_grid(&prep, nodes.clone(), m, f64::INFINITY, s);
            let (vals, dp) = solve_pass(&prep, &grid, s, None, None).unwrap();
            let obj = prep.objective(&expand(&nodes, &vals, 200));
            assert!(
                (dp - obj).abs() <= 1e-9 * obj.abs().max(1e-12),
                "m={m}: {dp} vs {obj}"
            );
        }
    }

    #[test]
    fn the_final_warp_is_never_worse_than_the_first_pass() {
        let r = ramp(300, |t| (9.0 * t).sin());
        let q = ramp(300, |t| (9.0 * t * t).sin());
        let (rs, qs) = (
            SignalRef::new(&r, 1).unwrap(),
            SignalRef::new(&q, 1).unwrap(),
        );
        let params = WarpParams::default();
        let prep = Prepared::new(rs, qs, &params, "query").unwrap();
        let s = (params.slope_min, params.slope_max);
        let nodes = spread_nodes(300, params.nodes_for(300));
        let grid = first_grid(
            &prep,
            nodes.clone(),
            params.coarse_candidates,
            f64::INFINITY,
            s,
        );
        let (vals, _) = solve_pass(&prep, &grid, s, None, None).unwrap();
        let first = prep.objective(&expand(&nodes, &vals, 300));
        let warp = align(rs, qs, &params).unwrap();
        assert!(warp.objective() <= first, "{} > {first}", warp.objective());
    }

    #[test]
    fn more_effort_widens_a_refinement_grid() {
        // the former defaults keep their grid: 15 candidates over ±2.5 previous spacings
        assert_eq!(refine_count(15, 2.5), 15);
        for m in [3, 4, 5, 15, 31] {
            for radius in [0.5, 1.0, 2.5, 4.0] {
                let count = refine_count(m, radius);
                // the range reaches ±radius previous resolutions
                let half = ((count - 1) / 2) as f64 * REFINE_SPACING_RATIO;
                assert!(half >= radius - 1e-9 && count >= m, "{m} {radius}: {count}");
                assert!(refine_count(m + 4, radius) >= count);
                assert!(refine_count(m, radius + 0.5) >= count);
            }
        }
    }

    #[test]
    fn more_coarse_nodes_bring_more_first_pass_candidates() {
        // the first pass keeps neighbouring candidates within COARSE_SLOPE_STEP of slope
        let r = ramp(600, |t| t);
        let rs = SignalRef::new(&r, 1).unwrap();
        let params = WarpParams::default();
        let prep = Prepared::new(rs, rs, &params, "query").unwrap();
        let s = (params.slope_min, params.slope_max);
        let mut last = 0;
        for n0 in [12, 48, 100, 200] {
            let nodes = spread_nodes(600, n0);
            let seg = nodes.windows(2).map(|w| w[1] - w[0]).min().unwrap() as f64;
            let max_step = slope_step_span(&prep, seg);
            let grid = first_grid(&prep, nodes, params.coarse_candidates, max_step, s);
            assert!(grid.step.iter().all(|&st| st <= max_step + 1e-9));
            let most = *grid.count.iter().max().unwrap();
            assert!(most >= last, "{n0} nodes: {most} < {last} candidates");
            last = most;
        }
    }
}
