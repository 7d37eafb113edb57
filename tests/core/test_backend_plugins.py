"""Back ends are registered through the ``nmsm_backends`` hook and found by name: nmsm's own
and a plugin's alike."""

from __future__ import annotations

import re
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


def _documented_backend() -> str:
    """The back end of docs/plugins.md ("A back end"), as written there."""
    text = (ROOT / "docs" / "plugins.md").read_text(encoding="utf-8")
    return re.search(r"```python\n(.*?)```", text[text.index("## 5. A back end"):], re.S).group(1)


@pytest.fixture
def plugin_backend(tmp_path: Path, monkeypatch: pytest.MonkeyPatch):
    """An installed-looking distribution whose entry point names the documented back end
    (``lbfgsb``); the process registry rebuilt with it (and rebuilt without it afterwards)."""
    (tmp_path / "fake_backend_plugin.py").write_text(_documented_backend())
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


def test_plugin_backend_is_found_by_name_and_used(plugin_backend: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert "lbfgsb" in backend_names()
    (item,) = [it for it in get_registry().items("backend") if it.name == "lbfgsb"]
    assert item.distribution == "fake-backend-plugin" and item.version == "1.0"
    calls = []
    documented = sys.modules["fake_backend_plugin"].LbfgsB
    solve = documented.solve
    monkeypatch.setattr(documented, "solve", lambda self, problem, **options: calls.append(problem.name) or
                        solve(self, problem, **options))
    problem = OptimizationProblem("through_plugin")
    x = problem.variable("x", [0.0, 0.0], lower=-5, upper=[5, 1.5])
    problem.add_cost("fit", x - cs.DM([1.0, 2.0]))
    solution = problem.solve("lbfgsb", maxiter=200)
    assert calls == ["through_plugin"]
    assert solution.backend == "lbfgsb" and solution.success
    np.testing.assert_allclose(solution["x"].ravel(), [1.0, 1.5], atol=1e-6)
    with pytest.raises(RegistryError, match=r"unknown back end 'lbfgs' \(did you mean 'lbfgsb'\?\); registered "
                                            r"back ends: .*lbfgsb"):
        problem.solve("lbfgs")


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


def test_a_builtin_plugin_missing_from_an_older_install_is_loaded() -> None:
    """An editable install made before a built-in plugin module was added names fewer entry
    points than BUILTIN_PLUGINS: the missing modules are loaded as nmsm's own all the same."""
    from nmsm.core.registry import PluginSource, _builtins_missing_from

    old = [PluginSource(name, value, "nmsm", "0.1.0", lambda: None) for name, value in BUILTIN_PLUGINS.items()
           if name != "builtin_backends"]
    (added,) = _builtins_missing_from(old)
    assert (added.name, added.value, added.distribution, added.is_nmsm) == ("builtin_backends",
                                                                            "nmsm.core.backends.builtin", "nmsm", True)
    assert added.load().__name__ == "nmsm.core.backends.builtin"
    assert _builtins_missing_from(old + [added]) == [] and _builtins_missing_from([]) == []
