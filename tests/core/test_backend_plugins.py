"""Back ends are registered through the ``nmsm_backends`` hook and found by name: nmsm's own
and a plugin's alike."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import casadi as cs
import numpy as np
import pytest

from nmsm.core.backends import Backend, backend_names, get_backend
from nmsm.core.problem import OptimizationProblem
from nmsm.core.registry import build_registry, get_registry
from nmsm.errors import RegistryError
from nmsm.hookspecs import BUILTIN_PLUGINS

ROOT = Path(__file__).resolve().parents[2]

#: a plugin's back end: projected gradient descent on the problem's weighted residuals
_BACKEND_MODULE = """
    import time
    from typing import ClassVar

    import casadi as cs
    import numpy as np

    from nmsm.core.backends import Backend
    from nmsm.core.solution import Solution
    from nmsm.hookspecs import hookimpl

    class GradientDescent(Backend):
        '''Projected gradient descent with a fixed step (a plugin's back end).'''

        type: ClassVar[str] = "gradient_descent"
        calls: ClassVar[list] = []

        def solve(self, problem, *, step=0.004, iterations=200):
            type(self).calls.append(problem.name)
            xs, ps = problem.scaled_vector(), problem.parameter_vector()
            f = problem.objective()
            grad = cs.Function("grad", [xs, ps], [f, cs.gradient(f, xs)])
            lo, hi = problem.bounds_scaled()
            x, p = np.clip(problem.initial_scaled(), lo, hi), problem.parameter_values()
            start = time.perf_counter()
            for _ in range(iterations):
                cost, g = grad(x, p)
                x = np.clip(x - step * np.asarray(g).ravel(), lo, hi)
            return Solution(values=problem.unpack(x), cost=float(cost), term_costs=problem.term_costs(x),
                            success=True, status="fixed iterations", iterations=iterations,
                            wall_time=time.perf_counter() - start, backend=self.type, x_scaled=x)

    @hookimpl
    def nmsm_backends():
        return [GradientDescent]
"""


@pytest.fixture
def plugin_backend(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """An installed-looking distribution whose entry point registers ``gradient_descent``;
    the process registry rebuilt with it (and rebuilt without it afterwards)."""
    (tmp_path / "fake_backend_plugin.py").write_text(textwrap.dedent(_BACKEND_MODULE))
    info = tmp_path / "fake_backend_plugin-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: fake-backend-plugin\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[nmsm]\nfake_backend_plugin = fake_backend_plugin\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    get_registry.cache_clear()
    yield tmp_path
    get_registry.cache_clear()
    sys.modules.pop("fake_backend_plugin", None)


def test_builtin_backends_come_through_the_hook() -> None:
    items = {it.name: it for it in get_registry().items("backend")}
    assert {"ipopt", "least_squares"} <= set(items)
    assert all(it.distribution == "nmsm" and issubclass(it.cls, Backend) for it in items.values())
    assert type(get_backend("ipopt")).__name__ == "IpoptBackend"


def test_plugin_backend_is_found_by_name_and_used(plugin_backend: Path) -> None:
    assert "gradient_descent" in backend_names()
    (item,) = [it for it in get_registry().items("backend") if it.name == "gradient_descent"]
    assert item.distribution == "fake-backend-plugin" and item.version == "1.0"
    problem = OptimizationProblem("through_plugin")
    x = problem.variable("x", [0.0, 0.0], lower=-5, upper=[5, 1.5])
    problem.add_cost("fit", x - cs.DM([1.0, 2.0]))
    solution = problem.solve("gradient_descent")
    assert solution.backend == "gradient_descent"
    assert sys.modules["fake_backend_plugin"].GradientDescent.calls == ["through_plugin"]
    np.testing.assert_allclose(solution["x"].ravel(), [1.0, 1.5], atol=1e-9)


def test_a_backend_that_is_no_backend_class_is_refused(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "fake_bad_backend.py").write_text(textwrap.dedent("""
        from nmsm.hookspecs import hookimpl

        class NotABackend:
            type = "not_a_backend"

        @hookimpl
        def nmsm_backends():
            return [NotABackend]
    """))
    info = tmp_path / "fake_bad_backend-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: fake-bad-backend\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text("[nmsm]\nfake_bad_backend = fake_bad_backend\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        with pytest.raises(RegistryError, match="is not a subclass of nmsm.core.backends.base.Backend"):
            build_registry()
    finally:
        sys.modules.pop("fake_bad_backend", None)


def test_pyproject_names_every_builtin_plugin() -> None:
    import tomllib

    declared = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["entry-points"]["nmsm"]
    assert declared == BUILTIN_PLUGINS
