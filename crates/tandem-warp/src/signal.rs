//! Borrowed multichannel signal views.

use crate::{Error, Result};

/// Sample-major multichannel signal view: sample `t`, channel `j` at `data[t * n_channels + j]`.
///
/// Samples are equally spaced in the signal's own time frame (reference or query samples).
/// The constructor checks the shape only; finiteness is checked by [`crate::align`].
#[derive(Clone, Copy, Debug)]
pub struct SignalRef<'a> {
    data: &'a [f64],
    n_channels: usize,
}

impl<'a> SignalRef<'a> {
    /// Wraps a flat sample-major buffer.
    ///
    /// # Errors
    /// [`Error::ZeroChannels`] if `n_channels == 0`, [`Error::RaggedData`] if `data.len()` is not a
    /// multiple of `n_channels`, [`Error::TooShort`] if there are fewer than 2 samples.
    pub fn new(data: &'a [f64], n_channels: usize) -> Result<Self> {
        if n_channels == 0 {
            return Err(Error::ZeroChannels);
        }
        if data.len() % n_channels != 0 {
            return Err(Error::RaggedData {
                len: data.len(),
                n_channels,
            });
        }
        let n_samples = data.len() / n_channels;
        if n_samples < 2 {
            return Err(Error::TooShort { n_samples });
        }
        Ok(Self { data, n_channels })
    }

    /// Number of samples `T` (time steps).
    #[must_use]
    pub fn n_samples(&self) -> usize {
        self.data.len() / self.n_channels
    }

    /// Number of channels `m`.
    #[must_use]
    pub fn n_channels(&self) -> usize {
        self.n_channels
    }

    /// The flat sample-major buffer.
    #[must_use]
    pub fn data(&self) -> &'a [f64] {
        self.data
    }

    /// The channel values of sample `t` (panics if `t >= n_samples()`).
    #[must_use]
    pub fn sample(&self, t: usize) -> &'a [f64] {
        &self.data[t * self.n_channels..(t + 1) * self.n_channels]
    }

    /// First value the loss cannot use, as `(sample, channel, value)`: non-finite, or larger in
    /// magnitude than [`MAX_ABS_VALUE`] (its squared differences would overflow to infinity).
    pub(crate) fn first_unusable(&self) -> Option<(usize, usize, f64)> {
        self.data
            .iter()
            .position(|v| !(v.is_finite() && v.abs() <= MAX_ABS_VALUE))
            .map(|i| (i / self.n_channels, i % self.n_channels, self.data[i]))
    }
}

/// Largest sample magnitude the alignment accepts. Weighted squared differences of values up
/// to this size (and weights up to [`MAX_ABS_VALUE`]) stay finite in `f64`; anything larger is
/// rejected with [`Error::TooLarge`](crate::Error::TooLarge) instead of overflowing the loss.
pub const MAX_ABS_VALUE: f64 = 1e100;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_checks() {
        assert_eq!(
            SignalRef::new(&[1.0, 2.0], 0).unwrap_err(),
            Error::ZeroChannels
        );
        assert_eq!(
            SignalRef::new(&[1.0, 2.0, 3.0], 2).unwrap_err(),
            Error::RaggedData {
                len: 3,
                n_channels: 2
            }
        );
        assert_eq!(
            SignalRef::new(&[1.0, 2.0], 2).unwrap_err(),
            Error::TooShort { n_samples: 1 }
        );
        assert_eq!(
            SignalRef::new(&[], 1).unwrap_err(),
            Error::TooShort { n_samples: 0 }
        );
        let s = SignalRef::new(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0], 2).unwrap();
        assert_eq!((s.n_samples(), s.n_channels()), (3, 2));
        assert_eq!(s.sample(1), &[3.0, 4.0]);
    }

    #[test]
    fn finds_non_finite() {
        let d = [0.0, 1.0, 2.0, f64::NAN];
        assert_eq!(
            SignalRef::new(&d, 2)
                .unwrap()
                .first_unusable()
                .map(|(t, j, _)| (t, j)),
            Some((1, 1))
        );
    }
}
