//! The robot count: at most [`MAX_ROBOTS`] robots share one operator, and per-robot values of
//! one tick live in a fixed-capacity [`PerRobot`] or, for flags, a [`RobotFlags`] bit set (no
//! allocation in the control loop).

use std::fmt;
use std::ops::{Deref, Index};

use crate::error::{Error, Result};

/// Largest number of robots one [`Coordinator`](crate::Coordinator) or one
/// [`sufficient_margins`](crate::sufficient_margins) call takes (the per-tick state lives in
/// arrays of this size; [`RobotFlags`] is a 16-bit set). 16 since issue 44 (8 before): what
/// limits it is docs/decisions.md, "Up to 16 robots: what limits N (issue 44)".
pub const MAX_ROBOTS: usize = 16;

/// A checked robot count `N`, `1 ≤ N ≤` [`MAX_ROBOTS`]: the one place the workspace checks
/// how many robots one cell (its `M ≥ 1` operators) may have, and the one error it gives
/// ([`Error::RobotCount`]). The schedule, the cyclic plan, the planner and the front ends
/// convert a count they are given into it where it enters (their own errors wrap this one),
/// so the rule and its message live here only.
///
/// ```
/// use tandem_realtime::{Error, MAX_ROBOTS, RobotCount};
/// assert_eq!(RobotCount::new(3)?.get(), 3);
/// assert!(matches!(RobotCount::new(0), Err(Error::RobotCount { n: 0, .. })));
/// let err = RobotCount::new(MAX_ROBOTS + 1).unwrap_err();
/// assert_eq!(err.to_string(), "17 robots: a cell has 1 to 16 robots");
/// # Ok::<(), Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct RobotCount(u8);

impl RobotCount {
    /// The count `n` once checked.
    ///
    /// # Errors
    /// [`Error::RobotCount`] with `n` unless `1 ≤ n ≤ MAX_ROBOTS`.
    pub fn new(n: usize) -> Result<Self> {
        if (1..=MAX_ROBOTS).contains(&n) {
            Ok(RobotCount(n as u8))
        } else {
            Err(Error::RobotCount { n, max: MAX_ROBOTS })
        }
    }

    /// The number of robots, in `1..=MAX_ROBOTS`.
    #[must_use]
    pub const fn get(self) -> usize {
        self.0 as usize
    }
}

impl TryFrom<usize> for RobotCount {
    type Error = Error;

    fn try_from(n: usize) -> Result<Self> {
        RobotCount::new(n)
    }
}

impl From<RobotCount> for usize {
    fn from(n: RobotCount) -> usize {
        n.get()
    }
}

/// A checked operator count `M`, `1 ≤ M ≤` [`MAX_ROBOTS`] (issue 44): how many operators
/// share the cell's robots, each correcting one robot at a time. The one check of an operator
/// count in the workspace ([`Error::OperatorCount`]); `M = 1` is the paper's one operator.
///
/// ```
/// use tandem_realtime::{Error, OperatorCount};
/// assert_eq!(OperatorCount::new(2)?.get(), 2);
/// assert_eq!(OperatorCount::ONE.get(), 1);
/// assert!(matches!(OperatorCount::new(0), Err(Error::OperatorCount { m: 0, .. })));
/// # Ok::<(), Error>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct OperatorCount(u8);

impl OperatorCount {
    /// One operator: the paper's cell.
    pub const ONE: OperatorCount = OperatorCount(1);

    /// The count `m` once checked.
    ///
    /// # Errors
    /// [`Error::OperatorCount`] with `m` unless `1 ≤ m ≤ MAX_ROBOTS`.
    pub fn new(m: usize) -> Result<Self> {
        if (1..=MAX_ROBOTS).contains(&m) {
            Ok(OperatorCount(m as u8))
        } else {
            Err(Error::OperatorCount { m, max: MAX_ROBOTS })
        }
    }

    /// The number of operators, in `1..=MAX_ROBOTS`.
    #[must_use]
    pub const fn get(self) -> usize {
        self.0 as usize
    }
}

impl Default for OperatorCount {
    fn default() -> Self {
        OperatorCount::ONE
    }
}

impl TryFrom<usize> for OperatorCount {
    type Error = Error;

    fn try_from(m: usize) -> Result<Self> {
        OperatorCount::new(m)
    }
}

/// Checks a robot count ([`RobotCount::new`], the count dropped).
///
/// # Errors
/// [`Error::RobotCount`] with the count.
pub(crate) fn check_count(n: usize) -> Result<()> {
    RobotCount::new(n).map(drop)
}

/// One value per robot (robot `i` at index `i`), for the `n ≤ MAX_ROBOTS` robots of one
/// coordinator: a fixed-capacity array that reads as the slice `[T]` of length `n`, so it is
/// returned by value from [`Coordinator::tick`](crate::Coordinator::tick) without allocating.
///
/// ```
/// use tandem_realtime::PerRobot;
/// let flags = PerRobot::from_slice(&[true, false, false]);
/// assert_eq!(flags.len(), 3);
/// assert_eq!(flags, [true, false, false]);
/// assert_eq!(flags.iter().filter(|&&f| f).count(), 1);
/// ```
#[derive(Clone, Copy)]
pub struct PerRobot<T> {
    len: u8,
    items: [T; MAX_ROBOTS],
}

impl<T: Copy + Default> PerRobot<T> {
    /// `n` default values (`n ≤ MAX_ROBOTS`, larger counts are cut to `MAX_ROBOTS`).
    #[must_use]
    pub fn new(n: usize) -> Self {
        PerRobot {
            len: n.min(MAX_ROBOTS) as u8,
            items: [T::default(); MAX_ROBOTS],
        }
    }

    /// The first `MAX_ROBOTS` values of `values`.
    #[must_use]
    pub fn from_slice(values: &[T]) -> Self {
        let mut out = Self::new(values.len());
        let n = usize::from(out.len);
        out.items[..n].copy_from_slice(&values[..n]);
        out
    }

    /// Mutable view of the `n` values.
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.items[..usize::from(self.len)]
    }
}

impl<T> Deref for PerRobot<T> {
    type Target = [T];

    fn deref(&self) -> &[T] {
        &self.items[..usize::from(self.len)]
    }
}

impl<T: PartialEq> PartialEq for PerRobot<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

impl<T: PartialEq, const K: usize> PartialEq<[T; K]> for PerRobot<T> {
    fn eq(&self, other: &[T; K]) -> bool {
        **self == other[..]
    }
}

impl<T: fmt::Debug> fmt::Debug for PerRobot<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&**self, f)
    }
}

/// One flag per robot (robot `i` at index `i`) for the `n ≤ MAX_ROBOTS` robots of one
/// coordinator, as a bit set: four bytes, copied for free with every
/// [`Tick`](crate::Tick). Reads like a `[bool]` of length `n`: `flags[i]`, `iter`, comparison
/// with a `[bool; n]`.
///
/// ```
/// use tandem_realtime::RobotFlags;
/// let flags = RobotFlags::from_slice(&[true, false, true]);
/// assert!(flags[0] && !flags[1]);
/// assert_eq!(flags, [true, false, true]);
/// assert_eq!((flags.len(), flags.count()), (3, 2));
/// assert_eq!(flags.first(), Some(0));
/// ```
#[derive(Clone, Copy, Default, PartialEq, Eq)]
pub struct RobotFlags {
    len: u8,
    bits: u16,
}

impl RobotFlags {
    /// `n` flags, all `false` (`n ≤ MAX_ROBOTS`, larger counts are cut to `MAX_ROBOTS`).
    #[must_use]
    pub fn new(n: usize) -> Self {
        RobotFlags {
            len: n.min(MAX_ROBOTS) as u8,
            bits: 0,
        }
    }

    /// The first `MAX_ROBOTS` values of `values`.
    #[must_use]
    pub fn from_slice(values: &[bool]) -> Self {
        let mut out = Self::new(values.len());
        for (i, &v) in values.iter().take(MAX_ROBOTS).enumerate() {
            out.set(i, v);
        }
        out
    }

    /// Number of robots `n`.
    #[must_use]
    pub fn len(&self) -> usize {
        usize::from(self.len)
    }

    /// Whether there are no robots.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Flag of robot `i` (`false` for `i ≥ n`).
    #[must_use]
    pub fn get(&self, i: usize) -> bool {
        i < self.len() && self.bits & (1 << i) != 0
    }

    /// Sets the flag of robot `i < n` (ignored for `i ≥ n`).
    pub fn set(&mut self, i: usize, value: bool) {
        if i < self.len() {
            if value {
                self.bits |= 1 << i;
            } else {
                self.bits &= !(1 << i);
            }
        }
    }

    /// Number of robots whose flag is set.
    #[must_use]
    pub fn count(&self) -> usize {
        self.bits.count_ones() as usize
    }

    /// The lowest-index robot whose flag is set.
    #[must_use]
    pub fn first(&self) -> Option<usize> {
        (self.bits != 0).then(|| self.bits.trailing_zeros() as usize)
    }

    /// The flags in robot order.
    pub fn iter(&self) -> impl Iterator<Item = bool> + '_ {
        (0..self.len()).map(|i| self.get(i))
    }
}

impl Index<usize> for RobotFlags {
    type Output = bool;

    /// Flag of robot `i`.
    ///
    /// # Panics
    /// If `i ≥ n`.
    fn index(&self, i: usize) -> &bool {
        assert!(i < self.len(), "robot {i} of {}", self.len());
        if self.get(i) { &true } else { &false }
    }
}

impl<const K: usize> PartialEq<[bool; K]> for RobotFlags {
    fn eq(&self, other: &[bool; K]) -> bool {
        K == self.len() && other.iter().enumerate().all(|(i, &v)| self.get(i) == v)
    }
}

impl fmt::Debug for RobotFlags {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_as_a_slice_of_its_length() {
        let mut v = PerRobot::<f64>::new(3);
        v.as_mut_slice()[2] = 1.5;
        assert_eq!(v, [0.0, 0.0, 1.5]);
        assert_eq!(format!("{v:?}"), "[0.0, 0.0, 1.5]");
        assert_ne!(v, PerRobot::from_slice(&[0.0, 0.0]));
        assert_eq!(PerRobot::<bool>::new(20).len(), MAX_ROBOTS);
        assert!(check_count(0).is_err() && check_count(MAX_ROBOTS + 1).is_err());
        let mut f = RobotFlags::new(3);
        f.set(2, true);
        f.set(5, true);
        assert_eq!(f, [false, false, true]);
        assert_eq!(
            (f.count(), f.first(), f[2], f.get(5)),
            (1, Some(2), true, false)
        );
        assert_eq!(format!("{f:?}"), "[false, false, true]");
        assert_ne!(f, [false, false, true, false]);
        assert_eq!(RobotFlags::new(2).first(), None);
        assert!(check_count(1).is_ok() && check_count(MAX_ROBOTS).is_ok());
    }

    #[test]
    fn a_robot_count_is_checked_once_and_reads_back() {
        for n in 1..=MAX_ROBOTS {
            let count = RobotCount::new(n).unwrap();
            assert_eq!((count.get(), usize::from(count)), (n, n));
            assert_eq!(RobotCount::try_from(n), Ok(count));
        }
        for n in [0, MAX_ROBOTS + 1, usize::MAX] {
            assert_eq!(
                RobotCount::new(n),
                Err(Error::RobotCount { n, max: MAX_ROBOTS })
            );
        }
        assert_eq!(
            RobotCount::new(0).unwrap_err().to_string(),
            "0 robots: a cell has 1 to 16 robots"
        );
    }

    #[test]
    fn an_operator_count_is_checked_once() {
        for m in 1..=MAX_ROBOTS {
            assert_eq!(OperatorCount::new(m).map(OperatorCount::get), Ok(m));
        }
        for m in [0, MAX_ROBOTS + 1] {
            assert_eq!(
                OperatorCount::try_from(m),
                Err(Error::OperatorCount { m, max: MAX_ROBOTS })
            );
        }
        assert_eq!(OperatorCount::default(), OperatorCount::ONE);
        assert_eq!(
            OperatorCount::new(17).unwrap_err().to_string(),
            "17 operators: a cell has 1 to 16 operators (use 1 for one operator)"
        );
    }
}
