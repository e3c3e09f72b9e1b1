//! The discretized GDTW objective and its direct evaluation.

use crate::params::WarpParams;
use crate::signal::SignalRef;
use crate::warp::check_values;
use crate::{Error, Result};

/// Reference and query prepared for fast loss evaluation (one alignment).
pub(crate) struct Prepared<'a> {
    /// Reference samples, sample-major.
    pub(crate) r: &'a [f64],
    /// Query samples, sample-major.
    pub(crate) q: &'a [f64],
    /// Query forward differences `q[s+1] − q[s]`, sample-major, `n_query − 1` samples.
    pub(crate) dq: Vec<f64>,
    /// `Σ_c W_c dq[s, c]²` per query sample `s < n_query − 1`.
    pub(crate) d2: Vec<f64>,
    /// Diagonal of `W`.
    pub(crate) w: Vec<f64>,
    /// Channels.
    pub(crate) nc: usize,
    /// Reference samples `T_ref`.
    pub(crate) nr: usize,
    /// Query samples `T_query`.
    pub(crate) nq: usize,
    /// Reference sample period in normalized time, `1 / (T_ref − 1)`.
    pub(crate) h: f64,
    /// Query samples per unit of normalized query time, `T_query − 1`.
    pub(crate) qscale: f64,
    /// `λ_inst`.
    pub(crate) lambda_inst: f64,
    /// `λ_cum`.
    pub(crate) lambda_cum: f64,
}

impl<'a> Prepared<'a> {
    /// Checks signals and parameters and precomputes query differences.
    pub(crate) fn new(
        reference: SignalRef<'a>,
        query: SignalRef<'a>,
        params: &WarpParams,
        query_name: &str,
    ) -> Result<Self> {
        if reference.n_channels() != query.n_channels() {
            return Err(Error::ChannelMismatch {
                reference: reference.n_channels(),
                query: query.n_channels(),
            });
        }
        let nc = reference.n_channels();
        params.validate_for(nc)?;
        for (signal, name) in [(reference, "reference"), (query, query_name)] {
            if let Some((sample, channel, value)) = signal.first_unusable() {
                let signal = name.into();
                return Err(if value.is_finite() {
                    Error::TooLarge {
                        signal,
                        sample,
                        channel,
                        value,
                    }
                } else {
                    Error::NonFinite {
                        signal,
                        sample,
                        channel,
                    }
                });
            }
        }
        let w = params.weight_vec(nc);
        let (r, q) = (reference.data(), query.data());
        let (nr, nq) = (reference.n_samples(), query.n_samples());
        let dq: Vec<f64> = q[nc..].iter().zip(q).map(|(b, a)| b - a).collect();
        let d2 = dq
            .chunks_exact(nc)
            .map(|d| d.iter().zip(&w).map(|(d, w)| w * d * d).sum())
            .collect();
        let (h, qscale) = (1.0 / (nr - 1) as f64, (nq - 1) as f64);
        Ok(Self {
            r,
            q,
            dq,
            d2,
            w,
            nc,
            nr,
            nq,
            h,
            qscale,
            lambda_inst: params.lambda_inst,
            lambda_cum: params.lambda_cum,
        })
    }

    /// `ℓ(n, τ) = (x₂(τ) − x₁(n))ᵀ W (x₂(τ) − x₁(n))` at reference sample `n` and query time
    /// `tau ∈ [0, T_query − 1]` (query samples), with `x₂` linearly interpolated.
    #[inline]
    pub(crate) fn loss(&self, n: usize, tau: f64) -> f64 {
        let nc = self.nc;
        let s = (tau.max(0.0) as usize).min(self.nq - 2);
        let f = tau - s as f64;
        let qs = &self.q[s * nc..(s + 1) * nc];
        let ds = &self.dq[s * nc..(s + 1) * nc];
        let rn = &self.r[n * nc..(n + 1) * nc];
        let mut acc = 0.0;
        for c in 0..nc {
            let e = qs[c] + f * ds[c] - rn[c];
            acc += self.w[c] * e * e;
        }
        acc
    }

    /// `ℓ(n, s)` at an integer query sample `s`.
    #[inline]
    pub(crate) fn loss_int(&self, n: usize, s: usize) -> f64 {
        let nc = self.nc;
        let qs = &self.q[s * nc..(s + 1) * nc];
        let rn = &self.r[n * nc..(n + 1) * nc];
        let mut acc = 0.0;
        for c in 0..nc {
            let e = qs[c] - rn[c];
            acc += self.w[c] * e * e;
        }
        acc
    }

    /// Trapezoid weight of reference sample `n` in the loss integral (normalized time).
    #[inline]
    pub(crate) fn trap_weight(&self, n: usize) -> f64 {
        if n == 0 || n == self.nr - 1 {
            0.5 * self.h
        } else {
            self.h
        }
    }

    /// Regularizer cost of one linear piece from `(ra, p)` to `(rb, qv)` (reference samples,
    /// query samples): `λ_inst Δt (s − 1)² + λ_cum Δt (d_a² + d_a d_b + d_b²) / 3`.
    #[inline]
    pub(crate) fn reg_cost(&self, ra: usize, p: f64, rb: usize, qv: f64) -> f64 {
        let (ta, tb) = (ra as f64 * self.h, rb as f64 * self.h);
        let dt = tb - ta;
        let (pa, pb) = (p / self.qscale, qv / self.qscale);
        let slope = (pb - pa) / dt;
        let (da, db) = (pa - ta, pb - tb);
        self.lambda_inst * dt * (slope - 1.0) * (slope - 1.0)
            + self.lambda_cum * dt * (da * da + da * db + db * db) / 3.0
    }

    /// Objective of a warp given at every reference sample (query samples).
    pub(crate) fn objective(&self, values: &[f64]) -> f64 {
        let mut total = 0.0;
        for (n, &v) in values.iter().enumerate() {
            total += self.trap_weight(n) * self.loss(n, v);
        }
        for (n, w) in values.windows(2).enumerate() {
            total += self.reg_cost(n, w[0], n + 1, w[1]);
        }
        total
    }
}

/// Evaluates the GDTW objective `J(ψ)` of a warp given at every reference sample.
///
/// `warp_values[n]` is the query time (query samples) at reference sample `n`, as in
/// [`crate::Warp::values`]. With `h = 1/(T_ref − 1)`, `t_n = n h`, `φ_n = warp_values[n] / (T_query − 1)`,
/// `d_n = φ_n − t_n` and `ℓ_n = (x₂(warp_values[n]) − x₁[n])ᵀ W (x₂(warp_values[n]) − x₁[n])`
/// (query linearly interpolated):
///
/// `J = Σ_n ω_n ℓ_n + λ_inst Σ_{n<T_ref−1} h ((φ_{n+1} − φ_n)/h − 1)² + λ_cum Σ_{n<T_ref−1} h (d_n² + d_n d_{n+1} + d_{n+1}²)/3`
///
/// with trapezoid weights `ω_n = h` (`h/2` at both ends). The two regularizer sums are the exact
/// integrals `∫ (φ' − 1)² dt` and `∫ (φ − t)² dt` of the piecewise-linear `φ`; the loss sum is
/// the trapezoid rule for `∫ ℓ dt`. [`crate::align`] minimizes exactly this quantity (its last
/// pass integrates the loss over every reference sample) and [`crate::Warp::objective`] reports it.
///
/// # Errors
/// Signal and parameter errors as for [`crate::align`]; [`Error::BadWarp`] if `warp_values` does
/// not have `T_ref` finite, non-decreasing values from `0` to `T_query − 1`.
pub fn objective_of(
    reference: SignalRef<'_>,
    query: SignalRef<'_>,
    warp_values: &[f64],
    params: &WarpParams,
) -> Result<f64> {
    let prep = Prepared::new(reference, query, params, "query")?;
    if warp_values.len() != prep.nr {
        return Err(Error::BadWarp {
            why: format!(
                "has {} values but the reference has {} samples",
                warp_values.len(),
                prep.nr
            ),
        });
    }
    check_values(warp_values, Some(prep.nq))?;
    Ok(prep.objective(warp_values))
}
