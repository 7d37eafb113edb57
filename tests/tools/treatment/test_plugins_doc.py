"""The cost term of docs/plugins.md, run as written: it imports as a plugin module would, builds
into a treatment problem, and has exact derivatives."""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path

import casadi as cs
import numpy as np

from treatment_pendulum_case import build_case

DOC = Path(__file__).resolve().parents[3] / "docs" / "plugins.md"


def _documented_term_class(tmp_path: Path) -> type:
    """The documented code written to a module file and imported, as a plugin's would be."""
    text = DOC.read_text()
    section = text[text.index("## 2. A cost term"):]
    module_file = tmp_path / "doc_plugin_terms.py"
    module_file.write_text(re.search(r"```python\n(.*?)```", section, re.S).group(1))
    spec = importlib.util.spec_from_file_location("doc_plugin_terms", module_file)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    try:
        spec.loader.exec_module(module)
    finally:
        sys.modules.pop(spec.name, None)
    return module.CoordinateLimitPenalty


def test_documented_term_builds_with_exact_derivatives(tmp_path: Path) -> None:
    cls = _documented_term_class(tmp_path)
    limit, sharpness = 0.2, 50.0
    term = cls(coordinate="q0", upper_limit=limit, sharpness=sharpness, max_allowable_error=0.01)
    built = build_case([term], tool="TO", guess_scale=1.0)
    problem = built.problem
    x0 = np.clip(problem.initial_scaled(), *problem.bounds_scaled())
    residual = problem.function(problem.costs[0].residuals)
    value = np.asarray(residual(x0, problem.parameter_values())).ravel()
    assert np.all(np.isfinite(value)) and np.any(np.abs(value) > 1e-6)
    # exact Jacobian against central differences along a random direction
    direction = np.random.default_rng(1).standard_normal(x0.size) * 1e-3
    jac = cs.Function("j", [problem.scaled_vector(), problem.parameter_vector()],
                      [cs.jacobian(problem.costs[0].residuals, problem.scaled_vector())])
    ad = np.asarray(jac(x0, problem.parameter_values())) @ direction
    h = 1e-4
    p = problem.parameter_values()
    fd = (np.asarray(residual(x0 + h * direction, p)).ravel() - np.asarray(residual(x0 - h * direction, p)).ravel()) / (2 * h)
    assert np.allclose(ad, fd, rtol=1e-4, atol=1e-8)


def test_documented_term_declares_its_settings_elements(tmp_path: Path) -> None:
    cls = _documented_term_class(tmp_path)
    assert cls.type == "coordinate_limit_penalty"
    assert cls.tools == frozenset({"TO", "DO"})
    assert {"coordinate", "upper_limit", "sharpness"} <= set(cls.xml_fields())


def test_documented_term_passes_check_term_as_documented(tmp_path: Path) -> None:
    from nmsm.testing import check_term

    cls = _documented_term_class(tmp_path)
    report = check_term(cls, {"coordinate": "q0", "upper_limit": "0.2"})
    assert report.not_built is None and "derivatives" in report.passed
