"""``tandem.align``: GDTW from Python (Eq. 2–3)."""

from __future__ import annotations

import numpy as np
import pytest

import tandem
from conftest import DEMOS, load_arrays


def test_a_warp_of_a_known_time_change_is_recovered() -> None:
    t = np.linspace(0.0, 1.0, 400)
    reference = np.column_stack([np.sin(6 * t), np.cos(4 * t)])
    # The query runs the same signal with the time map q(t) = t² + … (monotone).
    true_map = 0.6 * t**2 + 0.4 * t
    query_t = np.linspace(0.0, 1.0, 500)
    query = np.column_stack(
        [np.interp(query_t, true_map, reference[:, 0]), np.interp(query_t, true_map, reference[:, 1])]
    )
    w = tandem.align(reference, query)
    assert w.values.shape == (400,) and w.n_ref == 400
    assert w.values[0] == 0.0 and w.values[-1] == 499.0
    assert (np.diff(w.values) >= 0).all()
    expected = true_map * 499.0
    assert np.abs(w.values - expected).mean() < 3.0
    assert w.objective >= 0.0
    assert w.eval(399.0) == 499.0
    assert abs(w.inverse(w.eval(123.4)) - 123.4) < 1e-9


def test_one_channel_signals_and_identical_signals() -> None:
    x = np.sin(np.linspace(0, 7, 300))
    w = tandem.align(x, x)
    np.testing.assert_allclose(w.values, np.arange(300.0), atol=1e-9)
    np.testing.assert_allclose(w.gradient, 1.0, atol=1e-9)


def test_params_and_errors() -> None:
    _, ref = load_arrays(DEMOS[0])
    _, query = load_arrays(DEMOS[1])
    a = tandem.align(ref, query, params={"lambda_inst": 0.1, "lambda_cum": 1.0})
    assert a.n_ref == len(ref) and a.values[-1] == len(query) - 1
    with pytest.raises(tandem.ParamError) as e:
        tandem.align(ref, query, params={"slope_min": 2.0})
    assert e.value.name == "slope_min"
    with pytest.raises(tandem.ParamError, match="unknown field"):
        tandem.align(ref, query, params={"lambda": 1.0})
    bad = query.copy()
    bad[10, 0] = np.inf
    with pytest.raises(tandem.InputError):
        tandem.align(ref, bad)
    with pytest.raises(tandem.InputError):
        tandem.align(ref, query[:, :3])


def test_smoothing_is_a_parameter_and_helps_on_noisy_signals() -> None:
    # A known time change under white noise of a twentieth of each channel's amplitude: the
    # default smoothing (smooth_width 7) recovers the warp with clearly less error than none
    # (smooth_width 1): 1.46 against 2.65 query samples on this seed (2.08 against 3.22 on
    # seed 6).
    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 1.0, 1500)
    clean = np.column_stack([np.sin(9 * t), np.cos(5 * t) * (0.5 + t)])
    true_map = 0.5 * t**2 + 0.5 * t
    query_t = np.linspace(0.0, 1.0, 1800)
    query = np.column_stack([np.interp(query_t, true_map, clean[:, c]) for c in range(2)])
    reference = clean + rng.normal(0.0, 0.05, clean.shape)
    query = query + rng.normal(0.0, 0.05, query.shape)
    expected = true_map * 1799.0
    err = {
        w: np.abs(tandem.align(reference, query, params={"smooth_width": w}).values - expected).mean()
        for w in (1, 7)
    }
    default = np.abs(tandem.align(reference, query).values - expected).mean()
    assert default == err[7]
    assert err[7] < 0.8 * err[1], err
    with pytest.raises(tandem.ParamError) as e:
        tandem.align(reference, query, params={"smooth_width": 4})
    assert e.value.name == "smooth_width"


def test_flat_stretches_are_filled_unless_fill_length_is_zero() -> None:
    # Two channels that stop moving from task time 0.3 to 0.7 (a dwell), and a query that runs
    # through the task at a smoothly varying speed: inside the dwell no channel identifies the
    # warp, the slope penalty alone draws a straight line, and the default fill continues the
    # speed ratio instead (crates/tandem-warp/tests/fill.rs has the same task: 2.09 against
    # 3.84 query samples of error inside the dwell). Outside the dwell nothing changes.
    def task(u: np.ndarray) -> np.ndarray:
        v = np.where(u < 0.3, u, np.where(u < 0.7, 0.3, u - 0.4))
        return np.column_stack([np.sin(4 * np.pi * v), np.cos(3 * np.pi * v) * (0.5 + v)])

    t = np.linspace(0.0, 1.0, 1000)
    true_phi = t + 0.06 * np.sin(2 * np.pi * t)
    tau = np.linspace(0.0, 1.0, 800)
    reference, query = task(t), task(np.interp(tau, true_phi, t))
    truth = true_phi * 799.0
    plain = tandem.align(reference, query, params={"fill_length": 0.0}).values
    filled = tandem.align(reference, query).values
    dwell = (t >= 0.3) & (t <= 0.7)
    assert np.array_equal(plain[~dwell], filled[~dwell])
    err_plain = np.abs(plain - truth)[dwell].mean()
    err_filled = np.abs(filled - truth)[dwell].mean()
    assert err_filled < 0.7 * err_plain, (err_filled, err_plain)
    with pytest.raises(tandem.ParamError) as e:
        tandem.align(reference, query, params={"fill_length": -0.1})
    assert e.value.name == "fill_length"
