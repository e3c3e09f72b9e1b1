//! Maximal runs of equal confidence: the one place that cuts `conf` into stretches.
//!
//! The schedule's pieces (§II-C), the low-confidence intervals of a robot's plan (Eq. 19) and
//! the user's summaries all start from these runs; everything else is a view of them.

use std::ops::Range;

/// A maximal run of reference samples with the same confidence (Eq. 12).
///
/// Reference time frame: samples `start..end` (end exclusive) of the reference demonstration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Run {
    /// First reference sample of the run.
    pub start: usize,
    /// One past the last reference sample of the run.
    pub end: usize,
    /// `true` when every sample of the run is high-confidence (Eq. 12).
    pub high_conf: bool,
}

impl Run {
    /// The run's reference samples as a range.
    #[must_use]
    pub fn range(&self) -> Range<usize> {
        self.start..self.end
    }

    /// Number of reference samples in the run (≥ 1).
    #[must_use]
    pub fn len(&self) -> usize {
        self.end - self.start
    }

    /// Always `false`: a run has at least one sample (for clippy's `len` convention).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.end == self.start
    }
}

/// Maximal runs of equal confidence in `conf` (`true` = high, Eq. 12), in reference order,
/// covering `0..conf.len()` without gaps. Empty for an empty `conf`.
///
/// ```
/// use tandem_confidence::{Run, runs};
/// let conf = [false, true, true, false];
/// let r = runs(&conf);
/// assert_eq!(r.len(), 3);
/// assert_eq!(r[1], Run { start: 1, end: 3, high_conf: true });
/// ```
#[must_use]
pub fn runs(conf: &[bool]) -> Vec<Run> {
    let mut out = Vec::new();
    let mut start = 0;
    for n in 1..=conf.len() {
        if n == conf.len() || conf[n] != conf[start] {
            out.push(Run {
                start,
                end: n,
                high_conf: conf[start],
            });
            start = n;
        }
    }
    out
}

/// Maximal runs of `false` (low confidence) in `conf`, as half-open reference-sample
/// ranges in increasing order: the low-confidence [`runs`].
///
/// ```
/// let conf = [false, true, true, false, false, true, false];
/// assert_eq!(tandem_confidence::low_regions(&conf), vec![0..1, 3..5, 6..7]);
/// ```
#[must_use]
pub fn low_regions(conf: &[bool]) -> Vec<Range<usize>> {
    runs(conf)
        .iter()
        .filter(|r| !r.high_conf)
        .map(Run::range)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_cover_the_reference_in_order() {
        assert!(runs(&[]).is_empty());
        let conf = [true, false, false, true];
        let r = runs(&conf);
        let spans: Vec<_> = r.iter().map(|x| (x.start, x.end, x.high_conf)).collect();
        assert_eq!(spans, [(0, 1, true), (1, 3, false), (3, 4, true)]);
        assert_eq!(r[1].len(), 2);
        assert_eq!(
            runs(&[false]),
            [Run {
                start: 0,
                end: 1,
                high_conf: false
            }]
        );
        assert_eq!(low_regions(&conf), vec![1..3]);
        assert!(low_regions(&[true; 3]).is_empty());
    }
}
