//! The discretized GDTW objective and its direct evaluation.

use std::borrow::Cow;

use crate::params::{NOISE_PENALTY, WarpParams};
use crate::signal::SignalRef;
use crate::smooth::smooth;
use crate::warp::check_values;
use crate::{Error, Result};

/// Reference and query prepared for fast loss evaluation (one alignment).
pub(crate) struct Prepared<'a> {
    /// Reference samples, sample-major, smoothed ([`WarpParams::smooth_width`]).
    pub(crate) r: Cow<'a, [f64]>,
    /// Query samples, sample-major, smoothed ([`WarpParams::smooth_width`]).
    pub(crate) q: Cow<'a, [f64]>,
    /// Reference samples as given (sample-major, unsmoothed).
    pub(crate) r_raw: &'a [f64],
    /// Query samples as given (sample-major, unsmoothed).
    pub(crate) q_raw: &'a [f64],
    /// Estimated white-noise standard deviation of every reference channel as given
    /// ([`noise_sd`]; 0 for channels of weight 0), in the channel's units.
    pub(crate) sd_r: Vec<f64>,
    /// The same for the query.
    pub(crate) sd_q: Vec<f64>,
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
    /// `λ_inst` in effect: `params.lambda_inst + NOISE_PENALTY · ν̂` ([`noise_floor`] of the
    /// signals as given, before smoothing: the smoothing removes the noise finer than the warp
    /// can follow, the penalty is for the coarser noise it leaves, which the white noise's
    /// power measures; docs/decisions.md, "tandem-warp: smoothing before alignment").
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
        let width = params.smooth_width;
        let smoothed = |x: &'a [f64]| -> Cow<'a, [f64]> {
            if width > 1 {
                Cow::Owned(smooth(x, nc, width))
            } else {
                Cow::Borrowed(x)
            }
        };
        let (r, q) = (smoothed(reference.data()), smoothed(query.data()));
        let (nr, nq) = (reference.n_samples(), query.n_samples());
        let dq: Vec<f64> = q[nc..].iter().zip(q.iter()).map(|(b, a)| b - a).collect();
        let d2 = dq
            .chunks_exact(nc)
            .map(|d| d.iter().zip(&w).map(|(d, w)| w * d * d).sum())
            .collect();
        let (h, qscale) = (1.0 / (nr - 1) as f64, (nq - 1) as f64);
        let (sd_r, sd_q) = (
            noise_sd(reference.data(), nc, &w),
            noise_sd(query.data(), nc, &w),
        );
        let lambda_inst = params.lambda_inst + NOISE_PENALTY * noise_floor(&sd_r, &sd_q, &w);
        Ok(Self {
            r,
            q,
            r_raw: reference.data(),
            q_raw: query.data(),
            sd_r,
            sd_q,
            dq,
            d2,
            w,
            nc,
            nr,
            nq,
            h,
            qscale,
            lambda_inst,
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

/// `ν̂ = Σ_c W_c (σ̂²_{1,c} + σ̂²_{2,c})`, the estimated noise floor of the loss: the expected
/// `ℓ` of two perfectly aligned signals whose channels carry independent white noise of
/// standard deviations `σ_{1,c}` (reference) and `σ_{2,c}` (query), each estimated by
/// [`noise_sd`].
fn noise_floor(sd_r: &[f64], sd_q: &[f64], w: &[f64]) -> f64 {
    w.iter()
        .zip(sd_r.iter().zip(sd_q))
        .map(|(wc, (a, b))| wc * (a * a + b * b))
        .sum()
}

/// Estimated white-noise standard deviation `σ̂_c` of every channel of the sample-major `x`
/// (`nc` channels), in the channel's units: the median absolute second difference
/// `|x[t+1] − 2 x[t] + x[t−1]|` divided by `0.6745 √6`. White noise's second differences have
/// standard deviation `√6 σ` and, being Gaussian, median absolute value `0.6745` times that;
/// smooth motion adds only its second derivative times the squared sample period, and steps (a
/// gripper) or spikes are too rare to move the median. Channels of weight 0 and signals of
/// fewer than 4 samples get 0.
pub(crate) fn noise_sd(x: &[f64], nc: usize, w: &[f64]) -> Vec<f64> {
    let n = x.len() / nc;
    let mut out = vec![0.0; nc];
    if n < 4 {
        return out;
    }
    let mut d: Vec<f64> = Vec::with_capacity(n - 2);
    for (c, (&wc, sd)) in w.iter().zip(out.iter_mut()).enumerate() {
        if wc == 0.0 {
            continue;
        }
        d.clear();
        d.extend(
            (1..n - 1)
                .map(|t| (x[(t + 1) * nc + c] - 2.0 * x[t * nc + c] + x[(t - 1) * nc + c]).abs()),
        );
        let mid = d.len() / 2;
        let (_, median, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
        *sd = *median / (0.6745 * 6f64.sqrt());
    }
    out
}

/// The `λ_inst` an alignment of `query` to `reference` uses: `params.lambda_inst +
/// NOISE_PENALTY · ν̂` ([`crate::NOISE_PENALTY`]), with `ν̂` the estimated noise floor of the
/// loss (the expected `ℓ` of the two signals perfectly aligned: `Σ_c W_c (σ̂²_{ref,c} +
/// σ̂²_{query,c})`, each `σ̂` from the median absolute second difference of that signal's
/// channel, `/ (0.6745 √6)`), estimated on the signals as given, before the smoothing of
/// [`WarpParams::smooth_width`]. [`crate::align`] and [`objective_of`] both use it in place of
/// `λ_inst`.
///
/// # Errors
/// Signal and parameter errors as for [`crate::align`].
pub fn effective_lambda_inst(
    reference: SignalRef<'_>,
    query: SignalRef<'_>,
    params: &WarpParams,
) -> Result<f64> {
    Ok(Prepared::new(reference, query, params, "query")?.lambda_inst)
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
