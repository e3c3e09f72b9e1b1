//! A sliding extreme (maximum or minimum) over index windows whose ends never decrease: the
//! conservative rate look-ups of the margin checks (amortized O(1) per query).

/// Sliding extreme (max or min) over index windows whose ends never decrease.
#[derive(Default)]
pub(super) struct Sliding {
    /// The monotone queue `queue[head..]`: candidate indices with their values, values
    /// strictly monotone from the front (each value read once, when its index enters the
    /// window). Entries before `head` have left the window; the buffer grows to at most one
    /// entry per index.
    queue: Vec<(usize, f64)>,
    head: usize,
    next: usize,
}

impl Sliding {
    /// The extreme of `val(n)` over `n ∈ lo..=hi` (`max` or min); `lo` and `hi` never
    /// decrease between calls on one window. 1 for an empty window.
    pub(super) fn query(
        &mut self,
        lo: usize,
        hi: usize,
        val: impl Fn(usize) -> f64,
        max: bool,
    ) -> f64 {
        while self.next <= hi {
            let v = val(self.next);
            while self.queue.len() > self.head {
                let vb = self.queue[self.queue.len() - 1].1;
                if (max && vb <= v) || (!max && vb >= v) {
                    self.queue.pop();
                } else {
                    break;
                }
            }
            self.queue.push((self.next, v));
            self.next += 1;
        }
        while self.head < self.queue.len() && self.queue[self.head].0 < lo {
            self.head += 1;
        }
        self.queue.get(self.head).map_or(1.0, |&(_, v)| v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sliding_extremes_match_brute_force() {
        let v = [3.0, 1.0, 4.0, 1.0, 5.0, 9.0, 2.0, 6.0];
        let mut mx = Sliding::default();
        let mut mn = Sliding::default();
        for (lo, hi) in [(0, 0), (0, 2), (1, 3), (1, 5), (4, 5), (5, 7), (7, 7)] {
            let bmax = v[lo..=hi].iter().copied().fold(f64::MIN, f64::max);
            let bmin = v[lo..=hi].iter().copied().fold(f64::MAX, f64::min);
            assert_eq!(mx.query(lo, hi, |n| v[n], true), bmax);
            assert_eq!(mn.query(lo, hi, |n| v[n], false), bmin);
        }
    }

    #[test]
    fn sliding_extremes_match_brute_force_on_long_windows_with_ties() {
        // Values with many ties (0..5) and windows whose ends advance by 0..3 each query.
        let v: Vec<f64> = (0..2000u64).map(|i| ((i * 7919) % 11 % 5) as f64).collect();
        let (mut mx, mut mn) = (Sliding::default(), Sliding::default());
        let (mut lo, mut hi) = (0, 0);
        for q in 0..1500u64 {
            hi = (hi + (q * 31 % 4) as usize).min(v.len() - 1);
            lo = (lo + (q * 17 % 3) as usize).min(hi);
            let bmax = v[lo..=hi].iter().copied().fold(f64::MIN, f64::max);
            let bmin = v[lo..=hi].iter().copied().fold(f64::MAX, f64::min);
            assert_eq!(mx.query(lo, hi, |n| v[n], true), bmax, "{lo}..={hi}");
            assert_eq!(mn.query(lo, hi, |n| v[n], false), bmin, "{lo}..={hi}");
        }
        assert!(hi > 1000, "the windows reach far: {hi}");
    }
}
