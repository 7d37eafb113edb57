"""Delayed EMG splines: MATLAB ``spline``/``ppval`` equivalence and exact delay derivatives."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.tools.mtp import emg_spline


def test_coefficients_match_matlab_spline(shared_data):
    folder = shared_data / "mtp" / "cost_function_unit_2023" / "with_synergy_extrapolation" / "npz"
    d = np.load(folder / "initialValues.npz")
    stored = np.load(folder / "emgSplines.npz")
    times = d["inputData.emgTime"]
    data = d["inputData.emgDataExpanded"]
    for trial, muscle in ((0, 6), (1, 10), (3, 26)):
        coefs = emg_spline.spline_coefficients(times[trial], data[trial, muscle][:, None], stride=4)[:, :, 0]
        ref = stored[f"emgSplines{{{trial},{muscle}}}.coefs"]
        assert np.abs(coefs - ref).max() <= 1e-12 * np.abs(ref).max()
        assert np.array_equal(emg_spline.spline_breaks(times[trial], 4), stored[f"emgSplines{{{trial},{muscle}}}.breaks"])


def test_spline_matrix_is_linear_map():
    rng = np.random.default_rng(1)
    t = np.linspace(0.0, 1.0, 41)
    y = rng.random((41, 2))
    direct = emg_spline.spline_coefficients(t, y, 4)
    via = (emg_spline.spline_matrix(t, 4) @ y).reshape(-1, 4, 2)
    assert np.allclose(direct, via, atol=1e-12)


@pytest.mark.parametrize("stride", [1, 4])
def test_delayed_sampler_matches_ppval_with_extrapolation(stride):
    rng = np.random.default_rng(2)
    t = 0.3 + 0.01 * np.arange(61)
    y = np.sin(7 * t) + 0.1 * rng.random(61)
    coefs = emg_spline.spline_coefficients(t, y[:, None], stride)[:, :, 0]
    breaks = emg_spline.spline_breaks(t, stride)
    f = emg_spline.delayed_sampler(breaks, t, 0.125)
    for delay in (0.0, 0.013, 0.05, 0.125):
        ours = np.array(f(delay, coefs.ravel())).ravel()
        ref = emg_spline.evaluate_pp(breaks, coefs[:, :, None], t - delay)[:, 0]
        assert np.abs(ours - ref).max() <= 1e-12  # includes t - delay < t0 (end-piece extrapolation)


def test_delay_derivatives_are_exact():
    t = 0.01 * np.arange(81)
    y = np.exp(-((t - 0.4) / 0.1) ** 2)
    coefs = emg_spline.spline_coefficients(t, y[:, None], 4)[:, :, 0].ravel()
    f = emg_spline.delayed_sampler(emg_spline.spline_breaks(t, 4), t, 0.125)
    d = cs.SX.sym("d")
    s = f(d, coefs)
    grad = cs.Function("g", [d], [cs.jacobian(s, d)])
    h = 1e-6
    for delay in (0.02, 0.07):
        fd = (np.array(f(delay + h, coefs)) - np.array(f(delay - h, coefs))).ravel() / (2 * h)
        assert np.abs(np.array(grad(delay)).ravel() - fd).max() <= 1e-5
