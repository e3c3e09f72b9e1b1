//! `tandem.align` and `tandem.Warp`: GDTW time warping (§II-B1, Eq. 2–3, Deriso & Boyd).

use numpy::PyArray1;
use pyo3::prelude::*;

use crate::arrays::{out_vector, signal};
use crate::errors::{Error, guard};
use crate::facade::{SignalRef, Warp, WarpParams, align as gdtw};
use crate::params::from_py;

/// Aligns ``query`` to ``reference`` with generalized dynamic time warping (Eq. 2–3):
/// the monotone warp ``ψ`` (reference samples → query samples, pinned at both ends, slopes
/// within the bounds) minimizing ``∫ (x_q(ψ(t)) − x_r(t))ᵀ W (x_q(ψ(t)) − x_r(t)) dt`` plus
/// ``λ_inst ∫ (φ' − 1)²`` and ``λ_cum ∫ (φ − t)²`` (normalized time).
///
/// Args:
///     reference: ``(T_ref, C)`` float array (or ``(T_ref,)`` for one channel).
///     query: ``(T_q, C)`` float array (or ``(T_q,)``).
///     params: ``None`` (defaults) or a dict of ``tandem_warp::WarpParams`` (``n_nodes``,
///         ``n_candidates``, ``lambda_inst``, ``lambda_cum``, ``slope_min``, ``slope_max``,
///         ``refinements``, ``refine_radius``, ``max_jump``, ``coarse_nodes``,
///         ``coarse_candidates``, ``weights``, ``smooth_width``, ``fill_length``), or the path
///         of a TOML file.
///
/// Returns:
///     Warp: ``values`` (query samples at each reference sample) and ``objective``.
#[pyfunction]
#[pyo3(signature = (reference, query, params=None))]
pub(crate) fn align(
    py: Python<'_>,
    reference: &Bound<'_, PyAny>,
    query: &Bound<'_, PyAny>,
    params: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyWarp> {
    let (r, rc) = signal(reference, "reference")?;
    let (q, qc) = signal(query, "query")?;
    let params: WarpParams = from_py(params, "params")?;
    let warp = py.detach(|| {
        guard(|| {
            let r = SignalRef::new(&r, rc).map_err(Error::from)?;
            let q = SignalRef::new(&q, qc).map_err(Error::from)?;
            Ok(gdtw(r, q, &params)?)
        })
    })?;
    Ok(PyWarp { inner: warp })
}

/// A time warp ``ψ`` from reference samples to query samples (monotone, ``ψ(0) = 0``,
/// ``ψ(T_ref − 1) = T_q − 1``).
#[pyclass(module = "tandem", name = "Warp", frozen)]
pub(crate) struct PyWarp {
    inner: Warp,
}

#[pymethods]
impl PyWarp {
    /// ``ψ(n)`` for every reference sample ``n``, ``(T_ref,)``, query samples.
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.values().to_vec())
    }

    /// The gradient ``ψ̇(n)``, ``(T_ref,)``, query samples per reference sample.
    #[getter]
    fn gradient<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out_vector(py, self.inner.gradient())
    }

    /// The objective of Eq. 3 with the regularizers at this warp.
    #[getter]
    fn objective(&self) -> f64 {
        self.inner.objective()
    }

    /// ``T_ref``.
    #[getter]
    fn n_ref(&self) -> usize {
        self.inner.n_ref()
    }

    /// ``ψ`` at fractional reference time ``ref_time`` (linear between samples).
    fn eval(&self, ref_time: f64) -> f64 {
        self.inner.eval(ref_time)
    }

    /// ``ψ⁻¹``: the reference time at fractional query time ``query_time``.
    fn inverse(&self, query_time: f64) -> f64 {
        self.inner.inverse(query_time)
    }

    fn __repr__(&self) -> String {
        format!(
            "Warp(n_ref={}, objective={})",
            self.inner.n_ref(),
            self.inner.objective()
        )
    }
}
