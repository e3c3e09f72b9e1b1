//! Piecewise-linear functions of one variable, the value functions of the search.
//!
//! A function is a list of closed pieces sorted by `(lo, hi)`; non-degenerate pieces have
//! disjoint interiors (they may share end points, with different values: the function may jump),
//! degenerate pieces (`lo == hi`) are isolated points. The value at `x` is the least value of
//! the pieces that contain `x`; outside every piece it is `+∞` (unreachable).

use std::collections::VecDeque;

/// Which transition of the search produced a piece (see `search.rs`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Step {
    /// The initial state: no predecessor.
    Start,
    /// The same robot placed its previous LC run too.
    Same,
    /// The other robot placed its LC run last.
    Cross,
}

/// Where a piece's value comes from: the predecessor state (by [`Step`]) at the argument
/// `x = sign·y + offset` of the predecessor's function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Origin {
    pub(crate) step: Step,
    pub(crate) sign: f64,
    pub(crate) offset: f64,
}

impl Origin {
    /// The initial state's origin.
    pub(crate) const START: Origin = Origin {
        step: Step::Start,
        sign: 0.0,
        offset: 0.0,
    };

    /// The predecessor's argument for argument `y`.
    pub(crate) fn pred(&self, y: f64) -> f64 {
        if self.sign == 0.0 {
            self.offset
        } else {
            self.sign * y + self.offset
        }
    }
}

/// One closed linear piece: `f(x) = at_lo + slope·(x − lo)` on `[lo, hi]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Piece {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    pub(crate) at_lo: f64,
    pub(crate) slope: f64,
    pub(crate) origin: Origin,
}

impl Piece {
    pub(crate) fn at(&self, x: f64) -> f64 {
        self.at_lo + self.slope * (x - self.lo)
    }

    pub(crate) fn at_hi(&self) -> f64 {
        self.at(self.hi)
    }

    /// The same line on `[lo, hi]` (a sub-interval).
    fn sub(&self, lo: f64, hi: f64) -> Piece {
        Piece {
            lo,
            hi,
            at_lo: self.at(lo),
            ..*self
        }
    }

    /// Least value on the piece (its pieces are monotone).
    pub(crate) fn min_value(&self) -> f64 {
        self.at_lo.min(self.at_hi())
    }
}

/// The least value of `f` at `x` with its piece, accepting pieces within `tol` of `x` (clamped
/// into the piece); `None` if no piece is that close.
pub(crate) fn value_at(f: &[Piece], x: f64, tol: f64) -> Option<(f64, &Piece)> {
    let end = f.partition_point(|p| p.lo <= x + tol);
    let mut best: Option<(f64, &Piece)> = None;
    for p in f[..end].iter().rev() {
        if p.hi < x - tol {
            // Pieces before a non-degenerate piece ending left of x end there too.
            if p.lo < p.hi {
                break;
            }
            continue;
        }
        let v = p.at(x.clamp(p.lo, p.hi));
        if best.is_none_or(|(b, _)| v < b) {
            best = Some((v, p));
        }
    }
    best
}

/// The non-degenerate piece of `f` that covers `[x0, x1]`, advancing the cursor `k`.
fn cover<'a>(f: &'a [Piece], k: &mut usize, x0: f64, x1: f64) -> Option<&'a Piece> {
    while *k < f.len() && f[*k].hi <= x0 {
        *k += 1;
    }
    f.get(*k).filter(|p| p.lo <= x0 && p.hi >= x1)
}

/// Appends `p` to `out`, merging it into the last piece when it continues the same line.
fn push(out: &mut Vec<Piece>, p: Piece) {
    if let Some(last) = out.last_mut()
        && last.hi == p.lo
        && last.lo < last.hi
        && p.lo < p.hi
        && last.slope == p.slope
        && last.origin == p.origin
        && (last.at_hi() - p.at_lo).abs() <= 1e-12 * (1.0 + p.at_lo.abs())
    {
        last.hi = p.hi;
        return;
    }
    out.push(p);
}

/// The sorted, distinct end points of the pieces of `f` and `g`: each function's end points
/// come sorted (pieces sorted by `lo` with disjoint interiors) except for isolated points
/// inside another piece, so two sorted runs are merged and only those stragglers sorted in.
fn breakpoints(f: &[Piece], g: &[Piece]) -> Vec<f64> {
    let ends = |h: &[Piece]| -> (Vec<f64>, bool) {
        let mut v = Vec::with_capacity(2 * h.len());
        let mut sorted = true;
        for p in h {
            if v.last().is_some_and(|&x| p.lo < x) {
                sorted = false;
            }
            v.push(p.lo);
            v.push(p.hi);
        }
        (v, sorted)
    };
    let ((mut a, sa), (mut b, sb)) = (ends(f), ends(g));
    if !sa {
        a.sort_unstable_by(f64::total_cmp);
    }
    if !sb {
        b.sort_unstable_by(f64::total_cmp);
    }
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut i, mut j) = (0, 0);
    while i < a.len() || j < b.len() {
        let x = if j >= b.len() || (i < a.len() && a[i] <= b[j]) {
            i += 1;
            a[i - 1]
        } else {
            j += 1;
            b[j - 1]
        };
        if out.last() != Some(&x) {
            out.push(x);
        }
    }
    out
}

/// Pointwise minimum of two functions (ties go to `f`).
pub(crate) fn min_of(f: &[Piece], g: &[Piece]) -> Vec<Piece> {
    if f.is_empty() {
        return g.to_vec();
    }
    if g.is_empty() {
        return f.to_vec();
    }
    let xs = breakpoints(f, g);
    let mut out: Vec<Piece> = Vec::with_capacity(f.len() + g.len());
    let (mut i, mut j) = (0, 0);
    for w in xs.windows(2) {
        let (x0, x1) = (w[0], w[1]);
        match (cover(f, &mut i, x0, x1), cover(g, &mut j, x0, x1)) {
            (None, None) => {}
            (Some(p), None) | (None, Some(p)) => push(&mut out, p.sub(x0, x1)),
            (Some(p), Some(q)) => {
                let (p0, p1, q0, q1) = (p.at(x0), p.at(x1), q.at(x0), q.at(x1));
                if p0 <= q0 && p1 <= q1 {
                    push(&mut out, p.sub(x0, x1));
                } else if q0 <= p0 && q1 <= p1 {
                    push(&mut out, q.sub(x0, x1));
                } else {
                    // The lines cross strictly inside.
                    let c = (x0 + (q0 - p0) / (p.slope - q.slope)).clamp(x0, x1);
                    let (first, second) = if p0 < q0 { (p, q) } else { (q, p) };
                    if c > x0 {
                        push(&mut out, first.sub(x0, c));
                    }
                    if c < x1 {
                        push(&mut out, second.sub(c, x1));
                    }
                }
            }
        }
    }
    // Isolated points survive where they are below everything else.
    let points: Vec<Piece> = f
        .iter()
        .chain(g)
        .filter(|p| p.lo == p.hi)
        .copied()
        .collect();
    if !points.is_empty() {
        let mut extra = Vec::new();
        for p in points {
            if value_at(&out, p.lo, 0.0).is_none_or(|(v, _)| p.at_lo < v) {
                extra.push(p);
            }
        }
        out.extend(extra);
        out.sort_by(|a, b| a.lo.total_cmp(&b.lo).then(a.hi.total_cmp(&b.hi)));
        out.dedup_by(|b, a| {
            a.lo == a.hi && b.lo == b.hi && a.lo == b.lo && {
                if b.at_lo < a.at_lo {
                    *a = *b;
                }
                true
            }
        });
    }
    out
}

/// `S(y) = min { f(z) : z ∈ [y − b, y − a] }` for `f` whose pieces are all non-increasing
/// (slopes ≤ 0) and `a ≤ b`: on each piece the least value in the window is at the window's
/// right end or at the piece's right end, so `S` is the minimum of `f` shifted by `a` and of
/// one plateau `f(hi_p)` on `[hi_p + a, hi_p + b]` per piece `p`. `reflect` says the
/// predecessor's argument is `x = −z` (else `x = z`); origins are set accordingly with `step`.
pub(crate) fn slide_min(f: &[Piece], a: f64, b: f64, reflect: bool, step: Step) -> Vec<Piece> {
    let sign = if reflect { -1.0 } else { 1.0 };
    let shifted: Vec<Piece> = f
        .iter()
        .map(|p| Piece {
            lo: p.lo + a,
            hi: p.hi + a,
            at_lo: p.at_lo,
            slope: p.slope,
            origin: Origin {
                step,
                sign,
                offset: -sign * a,
            },
        })
        .collect();
    if b <= a {
        return shifted;
    }
    // Plateaus: a sliding-window minimum over the pieces' right ends (enter at hi + a, leave
    // after hi + b; entering and leaving orders are both the order of `hi`).
    let mut ends: Vec<(f64, f64)> = f.iter().map(|p| (p.hi, p.at_hi())).collect();
    ends.sort_by(|x, y| x.0.total_cmp(&y.0));
    let n = ends.len();
    let mut steps: Vec<Piece> = Vec::with_capacity(2 * n);
    let mut dq: VecDeque<usize> = VecDeque::new();
    let (mut e, mut l) = (0, 0);
    let mut y_prev = f64::NEG_INFINITY;
    while l < n {
        let y_enter = if e < n { ends[e].0 + a } else { f64::INFINITY };
        let y = y_enter.min(ends[l].0 + b);
        if let Some(&front) = dq.front()
            && y > y_prev
        {
            let (x, w) = ends[front];
            push(
                &mut steps,
                Piece {
                    lo: y_prev,
                    hi: y,
                    at_lo: w,
                    slope: 0.0,
                    origin: Origin {
                        step,
                        sign: 0.0,
                        offset: sign * x,
                    },
                },
            );
        }
        while l < n && ends[l].0 + b <= y {
            if dq.front() == Some(&l) {
                dq.pop_front();
            }
            l += 1;
        }
        while e < n && ends[e].0 + a <= y {
            while dq.back().is_some_and(|&k| ends[k].1 >= ends[e].1) {
                dq.pop_back();
            }
            dq.push_back(e);
            e += 1;
        }
        y_prev = y;
    }
    min_of(&shifted, &steps)
}

/// `f` restricted to `[lo, hi]` and to where its value is at most `cap`.
pub(crate) fn restrict(f: &[Piece], lo: f64, hi: f64, cap: f64) -> Vec<Piece> {
    let mut out = Vec::with_capacity(f.len());
    for p in f {
        let (mut a, mut b) = (p.lo.max(lo), p.hi.min(hi));
        if a > b {
            continue;
        }
        // Where at(x) ≤ cap on a monotone piece.
        if p.slope > 0.0 {
            b = b.min(p.lo + (cap - p.at_lo) / p.slope);
        } else if p.slope < 0.0 {
            a = a.max(p.lo + (cap - p.at_lo) / p.slope);
        } else if p.at_lo > cap {
            continue;
        }
        if a > b || (p.slope != 0.0 && p.sub(a, b).min_value() > cap) {
            continue;
        }
        out.push(p.sub(a, b));
    }
    out
}

/// `f` restricted to where `f(x) − x ≤ cap` (the search's bound on the other robot's free
/// time `value − lead`).
pub(crate) fn restrict_lagging(f: &[Piece], cap: f64) -> Vec<Piece> {
    let mut out = Vec::with_capacity(f.len());
    for p in f {
        // f(x) − x has slope `slope − 1` on the piece.
        let s = p.slope - 1.0;
        let g0 = p.at_lo - p.lo;
        let (mut a, mut b) = (p.lo, p.hi);
        if s > 0.0 {
            b = b.min(p.lo + (cap - g0) / s);
        } else if s < 0.0 {
            a = a.max(p.lo + (cap - g0) / s);
        } else if g0 > cap {
            continue;
        }
        if a > b {
            continue;
        }
        out.push(p.sub(a, b));
    }
    out
}

/// Maps every piece `f(x)` to `f(x) + k·x` (`k` = ±1 in the search).
pub(crate) fn add_linear(f: &mut [Piece], k: f64) {
    for p in f {
        p.at_lo += k * p.lo;
        p.slope += k;
    }
}

/// `x ↦ f(−x)`.
pub(crate) fn reflect(f: &[Piece]) -> Vec<Piece> {
    f.iter()
        .rev()
        .map(|p| Piece {
            lo: -p.hi,
            hi: -p.lo,
            at_lo: p.at_hi(),
            slope: -p.slope,
            origin: p.origin,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn piece(lo: f64, hi: f64, at_lo: f64, slope: f64) -> Piece {
        Piece {
            lo,
            hi,
            at_lo,
            slope,
            origin: Origin::START,
        }
    }

    fn eval(f: &[Piece], x: f64) -> Option<f64> {
        value_at(f, x, 0.0).map(|(v, _)| v)
    }

    /// Brute force of the least value over pieces containing x.
    fn naive(fs: &[&[Piece]], x: f64) -> Option<f64> {
        fs.iter()
            .flat_map(|f| f.iter())
            .filter(|p| p.lo <= x && x <= p.hi)
            .map(|p| p.at(x))
            .reduce(f64::min)
    }

    #[test]
    fn min_of_by_hand() {
        // f = x on [0, 2], g = 1 on [1, 3]: min is x on [0, 1], 1 on [1, 3].
        let f = [piece(0.0, 2.0, 0.0, 1.0)];
        let g = [piece(1.0, 3.0, 1.0, 0.0)];
        let m = min_of(&f, &g);
        for x in [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0] {
            assert_eq!(eval(&m, x), naive(&[&f, &g], x), "x = {x}");
        }
        assert_eq!(eval(&m, 3.5), None);
        // An isolated point below the rest survives; one above it does not.
        let h = [piece(2.0, 2.0, 0.5, 0.0), piece(2.5, 2.5, 7.0, 0.0)];
        let m = min_of(&m, &h);
        assert_eq!(eval(&m, 2.0), Some(0.5));
        assert_eq!(eval(&m, 2.5), Some(1.0));
        assert_eq!(m.len(), 3);
    }

    #[test]
    fn slide_min_matches_brute_force() {
        // Non-increasing pieces with a gap and a jump.
        let f = [
            piece(0.0, 1.0, 3.0, -1.0),
            piece(1.0, 2.0, 4.0, 0.0),
            piece(3.0, 5.0, 2.5, -1.0),
        ];
        for (a, b) in [(0.0, 0.0), (0.5, 1.5), (1.0, 4.0), (0.0, 0.25)] {
            let s = slide_min(&f, a, b, false, Step::Same);
            for k in 0..=80 {
                let y = -0.5 + k as f64 * 0.125;
                // Brute force over a fine grid of the window plus the piece ends.
                let mut best: Option<f64> = None;
                let mut zs: Vec<f64> = (0..=400)
                    .map(|t| y - b + (b - a) * t as f64 / 400.0)
                    .collect();
                zs.extend(f.iter().flat_map(|p| [p.lo, p.hi]));
                for z in zs {
                    if z >= y - b
                        && z <= y - a
                        && let Some(v) = naive(&[&f], z)
                    {
                        best = Some(best.map_or(v, |w: f64| w.min(v)));
                    }
                }
                let got = eval(&s, y);
                match (got, best) {
                    (Some(g), Some(w)) => {
                        assert!((g - w).abs() < 1e-9, "a {a} b {b} y {y}: {g} vs {w}")
                    }
                    _ => assert_eq!(got, best, "a {a} b {b} y {y}"),
                }
            }
        }
    }

    #[test]
    fn restrict_cuts_domain_and_values() {
        let f = [piece(0.0, 4.0, 0.0, 1.0), piece(4.0, 6.0, 1.0, 0.0)];
        let r = restrict(&f, 1.0, 5.0, 2.0);
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].lo, r[0].hi, r[0].at_lo), (1.0, 2.0, 1.0));
        assert_eq!((r[1].lo, r[1].hi), (4.0, 5.0));
        assert!(restrict(&f, 0.0, 6.0, 0.5).iter().all(|p| p.hi <= 0.5));
    }

    #[test]
    fn reflect_and_add_linear() {
        let mut f = reflect(&[piece(1.0, 2.0, 5.0, 1.0)]);
        assert_eq!(
            (f[0].lo, f[0].hi, f[0].at_lo, f[0].slope),
            (-2.0, -1.0, 6.0, -1.0)
        );
        add_linear(&mut f, 1.0);
        assert_eq!((f[0].at_lo, f[0].slope), (4.0, 0.0));
        assert_eq!(f[0].at(-1.0), 4.0);
    }
}
