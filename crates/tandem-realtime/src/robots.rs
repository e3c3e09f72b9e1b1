//! The robot count: at most [`MAX_ROBOTS`] robots share one operator, and per-robot values of
//! one tick live in a fixed-capacity [`PerRobot`] (no allocation in the control loop).

use std::fmt;
use std::ops::Deref;

use crate::error::{Error, Result};

/// Largest number of robots one [`Coordinator`](crate::Coordinator) or one
/// [`sufficient_margins`](crate::sufficient_margins) call takes (the per-tick state lives in
/// arrays of this size).
pub const MAX_ROBOTS: usize = 8;

/// Checks a robot count: `1 ≤ n ≤ MAX_ROBOTS`.
///
/// # Errors
/// [`Error::RobotCount`] with the count.
pub(crate) fn check_count(n: usize) -> Result<()> {
    if (1..=MAX_ROBOTS).contains(&n) {
        Ok(())
    } else {
        Err(Error::RobotCount { n, max: MAX_ROBOTS })
    }
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
    len: usize,
    items: [T; MAX_ROBOTS],
}

impl<T: Copy + Default> PerRobot<T> {
    /// `n` default values (`n ≤ MAX_ROBOTS`, larger counts are cut to `MAX_ROBOTS`).
    #[must_use]
    pub fn new(n: usize) -> Self {
        PerRobot {
            len: n.min(MAX_ROBOTS),
            items: [T::default(); MAX_ROBOTS],
        }
    }

    /// The first `MAX_ROBOTS` values of `values`.
    #[must_use]
    pub fn from_slice(values: &[T]) -> Self {
        let mut out = Self::new(values.len());
        let n = out.len;
        out.items[..n].copy_from_slice(&values[..n]);
        out
    }

    /// Mutable view of the `n` values.
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.items[..self.len]
    }
}

impl<T> Deref for PerRobot<T> {
    type Target = [T];

    fn deref(&self) -> &[T] {
        &self.items[..self.len]
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
        assert!(check_count(0).is_err() && check_count(9).is_err());
        assert!(check_count(1).is_ok() && check_count(MAX_ROBOTS).is_ok());
    }
}
