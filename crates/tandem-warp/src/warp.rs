//! The [`Warp`] result type.

use serde::{Deserialize, Serialize};

use crate::{Error, Result};

/// A warp `ψ`: reference → query (paper Eq. 2), sampled at every reference sample.
///
/// `values()[n]` is the query time, in query samples (fractional), at reference sample `n`.
/// It is non-decreasing, `values()[0] = 0` and `values()[T_ref − 1] = T_query − 1`.
/// Between reference samples `ψ` is linear.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "WarpRaw", into = "WarpRaw")]
pub struct Warp {
    values: Vec<f64>,
    objective: f64,
}

/// Serialized form of [`Warp`], validated on deserialization.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct WarpRaw {
    values: Vec<f64>,
    objective: f64,
}

impl TryFrom<WarpRaw> for Warp {
    type Error = Error;
    fn try_from(raw: WarpRaw) -> Result<Self> {
        check_values(&raw.values, None)?;
        Ok(Self {
            values: raw.values,
            objective: raw.objective,
        })
    }
}

impl From<Warp> for WarpRaw {
    fn from(w: Warp) -> Self {
        Self {
            values: w.values,
            objective: w.objective,
        }
    }
}

/// Checks that `values` is a valid warp: ≥ 2 finite values, starting at 0, non-decreasing,
/// and (if `n_query` is given) ending at `n_query − 1`.
pub(crate) fn check_values(values: &[f64], n_query: Option<usize>) -> Result<()> {
    let bad = |why: String| Err(Error::BadWarp { why });
    if values.len() < 2 {
        return bad(format!("needs at least 2 values, got {}", values.len()));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return bad(format!("value {i} is not finite"));
    }
    if values[0] != 0.0 {
        return bad(format!("value 0 must be 0 (got {})", values[0]));
    }
    if let Some(i) = values.windows(2).position(|w| w[1] < w[0]) {
        return bad(format!(
            "decreases between reference samples {i} and {}",
            i + 1
        ));
    }
    if let Some(nq) = n_query {
        let last = values[values.len() - 1];
        let end = (nq - 1) as f64;
        if last != end {
            return bad(format!(
                "last value must be T_query - 1 = {end} (got {last})"
            ));
        }
    }
    Ok(())
}

impl Warp {
    /// Builds a warp from values already known to be valid.
    pub(crate) fn from_parts(values: Vec<f64>, objective: f64) -> Self {
        Self { values, objective }
    }

    /// `ψ[n]`: query time (query samples) at every reference sample `n`, length `T_ref`.
    #[must_use]
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// `ψ̇[n]` in query samples per reference sample, length `T_ref`: the forward difference
    /// `values[n+1] − values[n]`; the last entry repeats the previous one.
    /// Positive for warps returned by [`crate::align`] (`slope_min > 0`).
    #[must_use]
    pub fn gradient(&self) -> Vec<f64> {
        let v = &self.values;
        let mut g: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
        g.push(g[g.len() - 1]);
        g
    }

    /// `ψ(t)` at fractional reference time `ref_time` (reference samples), by linear
    /// interpolation, clamped to `[0, T_ref − 1]`. Returns query samples.
    #[must_use]
    pub fn eval(&self, ref_time: f64) -> f64 {
        interp(&self.values, ref_time)
    }

    /// `ψ⁻¹(q)`: fractional reference time (reference samples) at fractional query time
    /// `query_time` (query samples), clamped to `[0, T_query − 1]`. Where `ψ` is flat the
    /// first reference time reaching `q` is returned.
    #[must_use]
    pub fn inverse(&self, query_time: f64) -> f64 {
        let v = &self.values;
        let last = v[v.len() - 1];
        if query_time.is_nan() {
            return f64::NAN;
        }
        let q = query_time.clamp(0.0, last);
        let idx = v.partition_point(|&x| x < q);
        if idx == 0 {
            return 0.0;
        }
        let (a, b) = (v[idx - 1], v[idx]);
        let base = (idx - 1) as f64;
        base + (q - a) / (b - a)
    }

    /// The objective value (weighted loss + regularizers, [`crate::objective_of`]) of this warp,
    /// as minimized by [`crate::align`]. Dimensionless (normalized time, `W`-weighted units).
    #[must_use]
    pub fn objective(&self) -> f64 {
        self.objective
    }

    /// Number of reference samples `T_ref` (length of [`values`](Self::values)).
    #[must_use]
    pub fn n_ref(&self) -> usize {
        self.values.len()
    }
}

/// Linear interpolation of `v` (indexed by sample) at fractional index `x`, clamped to the ends.
pub(crate) fn interp(v: &[f64], x: f64) -> f64 {
    if x.is_nan() {
        return f64::NAN;
    }
    let last = (v.len() - 1) as f64;
    let x = x.clamp(0.0, last);
    let i = (x.floor() as usize).min(v.len() - 2);
    let f = x - i as f64;
    v[i] + f * (v[i + 1] - v[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w() -> Warp {
        Warp::from_parts(vec![0.0, 2.0, 3.0, 3.0, 6.0], 1.5)
    }

    #[test]
    fn gradient_eval_inverse() {
        let w = w();
        assert_eq!(w.gradient(), vec![2.0, 1.0, 0.0, 3.0, 3.0]);
        assert_eq!(w.eval(0.5), 1.0);
        assert_eq!(w.eval(-3.0), 0.0);
        assert_eq!(w.eval(10.0), 6.0);
        assert_eq!(w.eval(3.5), 4.5);
        assert_eq!(w.inverse(1.0), 0.5);
        assert_eq!(w.inverse(3.0), 2.0);
        assert_eq!(w.inverse(4.5), 3.5);
        assert_eq!(w.inverse(100.0), 4.0);
        assert_eq!(w.inverse(-1.0), 0.0);
        assert_eq!(w.objective(), 1.5);
        for t in [0.0, 0.3, 1.7, 3.9] {
            assert!((w.inverse(w.eval(t)) - t).abs() < 1e-12);
        }
    }

    #[test]
    fn serde_round_trip_and_validation() {
        let s = serde_json::to_string(&w()).unwrap();
        assert_eq!(serde_json::from_str::<Warp>(&s).unwrap(), w());
        let bad = r#"{"values":[0.0,2.0,1.0],"objective":0.0}"#;
        assert!(serde_json::from_str::<Warp>(bad).is_err());
        let bad = r#"{"values":[1.0,2.0],"objective":0.0}"#;
        assert!(serde_json::from_str::<Warp>(bad).is_err());
    }
}
