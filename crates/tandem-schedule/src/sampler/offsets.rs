//! Interval geometry of the candidates: whether two robots' low-confidence intervals overlap,
//! merging forbidden intervals, and the admissible offsets of the drawn-offset baselines.

use tandem_realtime::{LcInterval, tol};

use super::Scratch;

/// Whether robot 2's low-confidence intervals `b` shifted by `offset_s` overlap robot 1's `a`
/// (positive-length intersection; both lists in time order).
pub(super) fn overlaps(a: &[LcInterval], b: &[LcInterval], offset_s: f64) -> bool {
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        let bj = b[j].shifted(offset_s);
        if a[i].overlap_s(&bj) > 0.0 {
            return true;
        }
        if a[i].end_s <= bj.end_s {
            i += 1;
        } else {
            j += 1;
        }
    }
    false
}

/// Sorts intervals `(lo, hi)` by start and merges, in place, those that overlap or touch.
pub(super) fn sort_and_merge(intervals: &mut Vec<(f64, f64)>) {
    intervals.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
    let mut merged = 0;
    for i in 0..intervals.len() {
        let cur = intervals[i];
        if merged > 0 && cur.0 <= intervals[merged - 1].1 {
            intervals[merged - 1].1 = intervals[merged - 1].1.max(cur.1);
        } else {
            intervals[merged] = cur;
            merged += 1;
        }
    }
    intervals.truncate(merged);
}

/// The point at fraction `v ∈ [0, 1)` of the measure of the admissible offsets:
/// `[0, max_s = |ψ_E1|]` without every open interval `(a_i − d_j, b_i − c_j)` that would make robot 1's interval
/// `[a_i, b_i)` and robot 2's `[c_j, d_j)` overlap. `None` if that set has measure zero.
pub(super) fn feasible_offset(scratch: &mut Scratch, max_s: f64, v: f64) -> Option<f64> {
    let forbidden = &mut scratch.forbidden;
    forbidden.clear();
    for &LcInterval {
        start_s: a,
        end_s: b,
        ..
    } in &scratch.lc[0]
    {
        for &LcInterval {
            start_s: c,
            end_s: d,
            ..
        } in &scratch.lc[1]
        {
            let (lo, hi) = ((a - d).max(0.0), (b - c).min(max_s));
            if lo < hi {
                forbidden.push((lo, hi));
            }
        }
    }
    // Merge, then walk the gaps.
    sort_and_merge(forbidden);
    let blocked: f64 = forbidden.iter().map(|(lo, hi)| hi - lo).sum();
    let free = max_s - blocked;
    if free <= tol::MEASURE_ZERO_REL * max_s.max(1.0) {
        return None;
    }
    let mut target = v * free;
    let mut lo = 0.0;
    for &(f0, f1) in forbidden.iter() {
        let gap = f0 - lo;
        if target < gap {
            return Some(lo + target);
        }
        target -= gap;
        lo = f1;
    }
    Some((lo + target).min(max_s))
}

#[cfg(test)]
mod tests {
    use super::super::tests::{ivs, scratch};
    use super::*;

    #[test]
    fn feasible_offset_by_hand() {
        // Robot 1 LC [1, 2), robot 2 LC [0, 1) after its start: τ ∈ (0, 2) overlaps, so the
        // admissible offsets in [0, 3] are {0} ∪ [2, 3], of measure 1.
        let mut s = scratch(&[(1.0, 2.0)], &[(0.0, 1.0)]);
        assert_eq!(feasible_offset(&mut s, 3.0, 0.0), Some(2.0));
        assert_eq!(feasible_offset(&mut s, 3.0, 0.5), Some(2.5));
        // Two forbidden stretches: robot 2 LC [0, 1) and [2, 3) against robot 1 LC [4, 5):
        // τ ∈ (3, 5) and (1, 3) → free [0, 1] ∪ [5, 6] within [0, 6].
        let mut s = scratch(&[(4.0, 5.0)], &[(0.0, 1.0), (2.0, 3.0)]);
        assert_eq!(feasible_offset(&mut s, 6.0, 0.25), Some(0.5));
        assert_eq!(feasible_offset(&mut s, 6.0, 0.75), Some(5.5));
        // Everything forbidden: one LC run covering each whole execution.
        let mut s = scratch(&[(0.0, 3.0)], &[(0.0, 3.0)]);
        assert_eq!(feasible_offset(&mut s, 3.0, 0.5), None);
    }

    #[test]
    fn overlap_test_by_hand() {
        let (a, b) = (ivs(&[(1.0, 2.0)]), ivs(&[(0.0, 1.0)]));
        assert!(overlaps(&a, &b, 0.5));
        assert!(!overlaps(&a, &b, 2.0)); // touching
        assert!(!overlaps(&a, &b, 0.0)); // touching
    }
}
