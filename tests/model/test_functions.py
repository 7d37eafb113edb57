"""OpenSim functions: values and derivatives against OpenSim, symbolic == numeric, bad knots."""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest
from lxml import etree

from nmsm.errors import ModelError
from nmsm.model.functions import (
    Constant,
    LinearFunction,
    MultiplierFunction,
    NaturalCubicSpline,
    PiecewiseLinearFunction,
    PolynomialFunction,
    SimmSpline,
    parse_function,
    value_and_derivatives,
)


def _probe(x: np.ndarray) -> np.ndarray:
    span = x[-1] - x[0]
    inside = np.linspace(x[0], x[-1], 41)
    return np.concatenate([x, inside, [x[0] - 0.5 * span, x[0] - 1e-3, x[-1] + 1e-3, x[-1] + 0.7 * span]])


def _spline_cases(rng: np.random.Generator) -> list[tuple[np.ndarray, np.ndarray]]:
    cases = []
    for n in (2, 3, 4, 5, 13):
        x = np.sort(rng.uniform(-1.5, 2.0, n))
        cases.append((x, rng.normal(0.0, 0.3, n)))
    knee_x = np.array([0, 0.174533, 0.349066, 0.523599, 0.698132, 0.872665, 1.0472, 1.22173, 1.39626, 1.5708,
                       1.74533, 1.91986, 2.0944])
    knee_y = np.array([0, 0.059461, 0.109399, 0.150618, 0.18392, 0.210107, 0.229983, 0.24435, 0.254012, 0.25977,
                       0.262428, 0.262788, 0.261654])
    cases.append((knee_x, knee_y))
    return cases


def _check_against(reference: np.ndarray, function, x: np.ndarray) -> None:
    scale = max(1.0, float(np.abs(reference).max()))
    for order in range(3):
        assert np.abs(function.numeric(x, order) - reference[order]).max() <= 1e-11 * scale, order
    # generic evaluation (numpy and CasADi) and closed-form derivatives agree with OpenSim too
    assert np.abs(function(x) - reference[0]).max() <= 1e-11 * scale
    s = cs.SX.sym("s")
    value, d1, d2 = value_and_derivatives(function, s)
    f = cs.Function("f", [s], [value, d1, d2, cs.gradient(function(s), s)])
    for i, xi in enumerate(x):
        v, a, b, ad = (float(o) for o in f(xi))
        assert abs(v - reference[0, i]) <= 1e-11 * scale
        assert abs(a - reference[1, i]) <= 1e-10 * scale
        assert abs(ad - reference[1, i]) <= 1e-10 * scale
        assert abs(b - reference[2, i]) <= 1e-9 * scale


def test_simm_spline_matches_opensim(bridge) -> None:
    rng = np.random.default_rng(7)
    for x, y in _spline_cases(rng):
        spline = SimmSpline(x, y)
        probe = _probe(x)
        reference = bridge.call("oracle_function_values", spec={"type": "SimmSpline", "x": list(x), "y": list(y)}, x=probe)
        _check_against(reference, spline, probe)


def test_simple_functions_match_opensim(bridge) -> None:
    rng = np.random.default_rng(8)
    x = np.sort(rng.uniform(-1, 1, 6))
    y = rng.normal(size=6)
    probe = _probe(x)
    cases = [
        ({"type": "PiecewiseLinearFunction", "x": list(x), "y": list(y)}, PiecewiseLinearFunction(x, y)),
        ({"type": "LinearFunction", "slope": -1.7, "intercept": 0.3}, LinearFunction(-1.7, 0.3)),
        ({"type": "Constant", "value": 0.00275}, Constant(0.00275)),
        ({"type": "PolynomialFunction", "coefficients": [0.5, -2.0, 1.0, 0.25]}, PolynomialFunction((0.5, -2.0, 1.0, 0.25))),
        ({"type": "MultiplierFunction", "scale": 0.988523, "function": {"type": "SimmSpline", "x": list(x), "y": list(y)}},
         MultiplierFunction(SimmSpline(x, y), 0.988523)),
    ]
    for spec, ours in cases:
        points = probe
        if spec["type"] == "PiecewiseLinearFunction":
            # the slope exactly at an interior knot depends on OpenSim's bisection (either side)
            points = probe[~np.isin(probe, x[1:-1])]
        reference = bridge.call("oracle_function_values", spec=spec, x=points)
        _check_against(reference, ours, points)


def test_natural_cubic_spline_interpolates_with_natural_ends() -> None:
    # OpenSim's NaturalCubicSpline is not exposed to Python: checked against scipy's natural spline
    from scipy.interpolate import CubicSpline

    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(0, 3, 9))
    y = rng.normal(size=9)
    ours = NaturalCubicSpline(x, y)
    reference = CubicSpline(x, y, bc_type="natural")
    inside = np.linspace(x[0], x[-1], 57)
    for order in range(3):
        expected = reference(inside, order)
        assert np.abs(ours.numeric(inside, order) - expected).max() <= 1e-12 * max(1.0, np.abs(expected).max())
    below, above = x[0] - 0.4, x[-1] + 0.4
    assert ours.numeric(below) == pytest.approx(y[0] + reference(x[0], 1) * (below - x[0]), abs=1e-12)
    assert ours.numeric(above) == pytest.approx(y[-1] + reference(x[-1], 1) * (above - x[-1]), abs=1e-12)


def test_non_monotonic_knots_name_component_and_file(tmp_path) -> None:
    xml = """<CustomJoint name="knee_r"><SpatialTransform><TransformAxis name="rotation3">
    <SimmSpline name="function"><x>0 0.5 0.4 1.0</x><y>0 1 2 3</y></SimmSpline></TransformAxis></SpatialTransform>
    </CustomJoint>"""
    elem = etree.fromstring(xml).find(".//SimmSpline")
    with pytest.raises(ModelError) as info:
        parse_function(elem, file=tmp_path / "m.osim", owner="CustomJoint 'knee_r' rotation3")
    text = str(info.value)
    assert "m.osim" in text and "knee_r" in text and "strictly increasing" in text


def test_unsupported_function_type() -> None:
    elem = etree.fromstring("<Sine name='function'><amplitude>1</amplitude></Sine>")
    with pytest.raises(ModelError, match="Sine"):
        parse_function(elem, file="x.osim", owner="joint")


def test_truncated_power_form_falls_back_when_inaccurate() -> None:
    # knots far from the first one make the truncated-power form lose digits: the selected
    # piecewise form is used instead and still matches the numeric evaluation
    x = np.array([0.0, 1.0, 2.0, 1.0e5, 2.0e5])
    y = np.array([0.0, 1.0, 0.0, 1.0, 0.0])
    spline = SimmSpline(x, y)
    probe = _probe(x)
    s = cs.SX.sym("s")
    f = cs.Function("f", [s], [spline(s)])
    values = np.array([float(f(v)) for v in probe])
    assert np.allclose(values, spline.numeric(probe), rtol=1e-13, atol=1e-13)
