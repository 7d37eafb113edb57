"""Plugin discovery through the ``nmsm`` entry-point group, duplicates, lookups."""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import pytest

from nmsm.core.registry import build_registry, get_registry
from nmsm.errors import RegistryError


def _fake_distribution(root: Path, dist: str, module: str, body: str) -> None:
    """An installed-looking distribution: a module plus a .dist-info with an nmsm entry point."""
    (root / f"{module}.py").write_text(textwrap.dedent(body))
    info = root / f"{dist}-1.2.3.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 1.2.3\n")
    (info / "entry_points.txt").write_text(f"[nmsm]\n{module} = {module}\n")


_TERM_MODULE = """
    from typing import ClassVar
    import attrs
    from nmsm.core.term import CostTerm
    from nmsm.hookspecs import hookimpl

    @attrs.frozen(kw_only=True)
    class Dup(CostTerm):
        '''A third-party term.'''
        type: ClassVar[str] = "{name}"
        tools: ClassVar[frozenset[str]] = frozenset({{"DO"}})

    @hookimpl
    def nmsm_cost_terms():
        return [Dup]
"""


@pytest.fixture
def extra_path(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    yield tmp_path
    for name in ("fake_plugin_a", "fake_plugin_b"):
        sys.modules.pop(name, None)


def test_builtin_plugins_come_from_the_nmsm_distribution() -> None:
    items = get_registry().items()
    assert {it.distribution for it in items if it.cls.__module__.startswith("nmsm.")} <= {"nmsm"}


def test_third_party_term_is_discovered(extra_path: Path) -> None:
    _fake_distribution(extra_path, "fake-plugin-a", "fake_plugin_a", _TERM_MODULE.format(name="fancy_goal"))
    registry = build_registry()
    cls = registry.get("cost", "fancy_goal", "DO")
    (item,) = [it for it in registry.items("cost") if it.name == "fancy_goal"]
    assert item.distribution == "fake-plugin-a" and item.version == "1.2.3"
    assert cls.__doc__ == "A third-party term."


def test_duplicate_name_names_both_distributions(extra_path: Path) -> None:
    _fake_distribution(extra_path, "fake-plugin-a", "fake_plugin_a", _TERM_MODULE.format(name="same_goal"))
    _fake_distribution(extra_path, "fake-plugin-b", "fake_plugin_b", _TERM_MODULE.format(name="same_goal"))
    with pytest.raises(RegistryError) as info:
        build_registry()
    text = str(info.value)
    assert "same_goal" in text and "fake-plugin-a" in text and "fake-plugin-b" in text


def test_disable_plugins_env(extra_path: Path, monkeypatch) -> None:
    _fake_distribution(extra_path, "fake-plugin-a", "fake_plugin_a", _TERM_MODULE.format(name="same_goal"))
    _fake_distribution(extra_path, "fake-plugin-b", "fake_plugin_b", _TERM_MODULE.format(name="same_goal"))
    monkeypatch.setenv("NMSM_DISABLE_PLUGINS", "fake-plugin-b")
    registry = build_registry()
    assert registry.get("cost", "same_goal", "DO").__module__ == "fake_plugin_a"


def test_unknown_and_disallowed_names_list_valid_ones(extra_path: Path) -> None:
    _fake_distribution(extra_path, "fake-plugin-a", "fake_plugin_a", _TERM_MODULE.format(name="fancy_goal"))
    registry = build_registry()
    with pytest.raises(RegistryError, match="unknown cost 'no_such_term' for DO. Valid cost names for DO: .*fancy_goal"
                                            r".*needs that package installed.*'nmsm plugins' lists"):
        registry.get("cost", "no_such_term", "DO")
    with pytest.raises(RegistryError, match=r"unknown cost 'fancy_gaol' for DO \(did you mean 'fancy_goal'\?\)"):
        registry.get("cost", "fancy_gaol", "DO")
    with pytest.raises(RegistryError, match="not allowed in Tracking Optimization .*accepted by: DO"):
        registry.get("cost", "fancy_goal", "TO")


def test_broken_plugin_names_its_distribution(extra_path: Path) -> None:
    _fake_distribution(extra_path, "fake-plugin-a", "fake_plugin_a", "raise ImportError('boom')\n")
    with pytest.raises(RegistryError, match="fake-plugin-a.*failed to load.*boom"):
        build_registry()


def test_broken_plugin_says_how_to_leave_it_out(extra_path: Path) -> None:
    _fake_distribution(extra_path, "fake-plugin-a", "fake_plugin_a", "raise ImportError('boom')\n")
    with pytest.raises(RegistryError) as info:
        build_registry()
    assert str(info.value) == (
        "plugin 'fake_plugin_a = fake_plugin_a' of distribution 'fake-plugin-a' 1.2.3 failed to load: ImportError: "
        "boom. Fix or uninstall 'fake-plugin-a', or leave it out with NMSM_DISABLE_PLUGINS=fake-plugin-a")


def test_a_name_clash_names_the_plugin_to_leave_out(extra_path: Path) -> None:
    _fake_distribution(extra_path, "fake-plugin-a", "fake_plugin_a",
                       _TERM_MODULE.format(name="generalized_coordinate_tracking").replace('{"DO"}', '{"TO"}'))
    with pytest.raises(RegistryError, match="by nmsm.terms.* from distribution 'nmsm' .* and by fake_plugin_a.Dup "
                                            "from distribution 'fake-plugin-a' 1.2.3. Uninstall one of them or leave "
                                            "one out with NMSM_DISABLE_PLUGINS=fake-plugin-a."):
        build_registry()


def test_environment_naming_a_distribution_not_installed_is_warned(extra_path: Path, monkeypatch) -> None:
    _fake_distribution(extra_path, "fake-plugin-a", "fake_plugin_a", _TERM_MODULE.format(name="fancy_goal"))
    monkeypatch.setenv("NMSM_LOAD_PLUGINS", "Fake_Plugin_A,fake-plugin-z")  # names compare as pip compares them
    with pytest.warns(UserWarning) as record:
        registry = build_registry()
    assert registry.get("cost", "fancy_goal", "DO").__module__ == "fake_plugin_a"
    (message,) = [str(w.message) for w in record]
    assert message.startswith("NMSM_LOAD_PLUGINS names 'fake-plugin-z', not an installed nmsm plugin distribution "
                              "(installed: ")
    assert "fake-plugin-a" in message and "nmsm" in message
    monkeypatch.delenv("NMSM_LOAD_PLUGINS")
    monkeypatch.setenv("NMSM_DISABLE_PLUGINS", "fake-plugin-y")
    with pytest.warns(UserWarning, match="NMSM_DISABLE_PLUGINS names 'fake-plugin-y', not an installed"):
        build_registry()


def test_disabling_nmsm_itself_is_refused(monkeypatch) -> None:
    monkeypatch.setenv("NMSM_DISABLE_PLUGINS", "NMSM")
    with pytest.raises(RegistryError, match="NMSM_DISABLE_PLUGINS names 'nmsm': nmsm's own terms, .* cannot be left "
                                            "out"):
        build_registry()
