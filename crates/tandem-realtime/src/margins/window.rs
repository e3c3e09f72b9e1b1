//! A sliding extreme (maximum or minimum) over index windows whose ends never decrease: the
//! conservative rate look-ups of the margin checks (amortized O(1) per query).

use std::collections::VecDeque;

/// Sliding extreme (max or min) over index windows whose ends never decrease.
#[derive(Default)]
pub(super) struct Sliding {
    dq: VecDeque<usize>,
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
            while let Some(&b) = self.dq.back() {
                let vb = val(b);
                if (max && vb <= v) || (!max && vb >= v) {
                    self.dq.pop_back();
                } else {
                    break;
                }
            }
            self.dq.push_back(self.next);
            self.next += 1;
        }
        while self.dq.front().is_some_and(|&f| f < lo) {
            self.dq.pop_front();
        }
        self.dq.front().map_or(1.0, |&f| val(f))
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
}
