"""What the plugin registry checks when it is built, and errors raised inside a term's own code.

Each test installs a small plugin the way ``test_registry.py`` does (a ``.dist-info`` with an
``nmsm`` entry point on ``sys.path``), whose module is built here from classes defined in the
test, and builds the registry through :func:`nmsm.core.registry.build_registry`.
"""

from __future__ import annotations

import itertools
import subprocess
import sys
import types
from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar

import attrs
import numpy as np
import pytest

from nmsm.core.plugin_bases import ContactModel, Controller, ModelModifier
from nmsm.core.registry import build_registry
from nmsm.core.term import ConstraintTerm, CostTerm, SourceRef, TermSpec
from nmsm.errors import InputError, NmsmError, RegistryError
from nmsm.hookspecs import hookimpl
from nmsm.core.ocp import ContinuousCost, PathConstraint

DIST = "check-plugin"


@pytest.fixture
def install(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Callable[..., types.ModuleType]:
    """``install(dist=DIST, plain=None, **hooks)``: an installed-looking distribution ``dist``
    whose ``nmsm`` entry point names a module holding ``hooks`` (marked with @hookimpl) and the
    ``plain`` attributes (not marked)."""
    monkeypatch.syspath_prepend(str(tmp_path))
    counter = itertools.count()

    def _install(dist: str = DIST, plain: dict[str, Any] | None = None, **hooks: Callable[[], Any]) -> types.ModuleType:
        module_name = f"check_plugin_{dist.replace('-', '_')}_{next(counter)}"
        module = types.ModuleType(module_name)
        for name, func in hooks.items():
            setattr(module, name, hookimpl(func))
        for name, value in (plain or {}).items():
            setattr(module, name, value)
        monkeypatch.setitem(sys.modules, module_name, module)
        info = tmp_path / f"{dist}-1.2.3.dist-info"
        info.mkdir()
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: 1.2.3\n")
        (info / "entry_points.txt").write_text(f"[nmsm]\nchecks = {module_name}\n")
        return module

    return _install


def _refused(*parts: str) -> str:
    """The RegistryError of build_registry(), checked to contain every one of ``parts``."""
    with pytest.raises(RegistryError) as info:
        build_registry()
    text = str(info.value)
    for part in parts:
        assert part in text, f"{part!r} not in: {text}"
    return text


# ----- classes of the right base, per hook (problem 1) ---------------------------------------------
@attrs.frozen(kw_only=True)
class _Path(PathConstraint):
    """A constraint class."""

    type: ClassVar[str] = "check_path"
    coordinate: str = ""

    def value(self, ctx: Any) -> Any:
        return ctx.coordinate(self.coordinate)


@attrs.frozen(kw_only=True)
class _Goal(ContinuousCost):
    """A valid cost term."""

    type: ClassVar[str] = "check_goal"
    tools: ClassVar[frozenset[str]] = frozenset({"TO", "DO"})
    coordinate: str = ""
    count: int = 1

    def quantity(self, ctx: Any) -> Any:
        return ctx.coordinate(self.coordinate) * self.count


class _Modifier(ModelModifier):
    """A model modifier."""

    type: ClassVar[str] = "checkModifier"


def test_a_constraint_returned_by_the_cost_hook_is_refused(install) -> None:
    install(nmsm_cost_terms=lambda: [_Path])
    _refused("nmsm_cost_terms()", f"{__name__}._Path", f"'{DIST}' 1.2.3", "not a subclass of nmsm.core.term.CostTerm",
             "it is a ConstraintTerm: return it from nmsm_constraint_terms()", f"NMSM_DISABLE_PLUGINS={DIST}")


def test_a_cost_returned_by_the_constraint_hook_is_refused(install) -> None:
    install(nmsm_constraint_terms=lambda: [_Goal])
    _refused("nmsm_constraint_terms()", f"{__name__}._Goal", "not a subclass of nmsm.core.term.ConstraintTerm",
             "return it from nmsm_cost_terms()")


@pytest.mark.parametrize("hook, base", [
    ("nmsm_controllers", Controller), ("nmsm_model_modifiers", ModelModifier), ("nmsm_contact_models", ContactModel),
])
def test_non_term_hooks_check_their_base(install, hook: str, base: type) -> None:
    returned = _Goal if base is ModelModifier else _Modifier
    install(**{hook: lambda: [returned]})
    _refused(f"{hook}()", returned.__qualname__, f"not a subclass of {base.__module__}.{base.__qualname__}")


def test_valid_classes_of_every_hook_register(install) -> None:
    install(nmsm_cost_terms=lambda: [_Goal], nmsm_constraint_terms=lambda: [_Path],
            nmsm_model_modifiers=lambda: [_Modifier])
    registry = build_registry()
    assert registry.get("cost", "check_goal", "DO") is _Goal
    assert registry.get("constraint", "check_path", "TO") is _Path
    assert registry.get("modifier", "checkModifier", "DO") is _Modifier


# ----- classes no settings file could use (problem 2) ------------------------------------------------
class _NotATerm:
    """A plain class."""

    type = "check_not_a_term"
    tools = frozenset({"TO"})


class _Undecorated(ContinuousCost):
    """No @attrs.frozen: 'coordinate' is no field."""

    type: ClassVar[str] = "check_undecorated"
    coordinate: str = ""


@attrs.frozen(kw_only=True)
class _TypeField(ContinuousCost):
    """'type' without ClassVar."""

    type: str = "check_type_field"


@attrs.frozen(kw_only=True)
class _NoTools(CostTerm):
    """CostTerm sets no tools."""

    type: ClassVar[str] = "check_no_tools"


@attrs.frozen(kw_only=True)
class _ToolsString(ContinuousCost):
    """'tools' as a plain string."""

    type: ClassVar[str] = "check_tools_string"
    tools: ClassVar[Any] = "TO"


@attrs.frozen(kw_only=True)
class _NoType(ContinuousCost):
    """No type."""


@pytest.mark.parametrize("cls, expected", [
    (_NotATerm, "is not a subclass of nmsm.core.term.CostTerm"),
    (_Undecorated, "is not decorated with @attrs.frozen(kw_only=True): 'coordinate' would not be a field"),
    (_TypeField, "'type' must be a ClassVar[str], not an attrs field (write type: ClassVar[str] = 'check_type_field')"),
    (_NoTools, "sets no tools, so no tool could ever use it"),
    (_ToolsString, "sets 'tools' to the string 'TO', not a set of tool codes"),
    (_NoType, "sets no 'type'"),
])
def test_unusable_term_classes_are_refused_at_registration(install, cls: type, expected: str) -> None:
    install(nmsm_cost_terms=lambda: [cls])
    _refused(f"class {__name__}.{cls.__qualname__} returned by nmsm_cost_terms()", f"'{DIST}' 1.2.3", expected)


# ----- what a hook returns (problem 3) -------------------------------------------------------------
def _raise() -> list[type]:
    raise RuntimeError("hook blew up")


@pytest.mark.parametrize("hook, expected", [
    (lambda: _Goal, f"hook nmsm_cost_terms() returned {__name__}._Goal (a class), not a list of classes "
                    "(write return [_Goal])"),
    (lambda: ["check_goal"], "hook nmsm_cost_terms() returned 'check_goal' (a str) in its list, not a class"),
    (_raise, "hook nmsm_cost_terms() raised RuntimeError: hook blew up"),
])
def test_hook_results_that_are_no_list_of_classes_name_the_plugin(install, hook: Callable, expected: str) -> None:
    install(nmsm_cost_terms=hook)
    _refused(f"plugin 'checks = check_plugin_check_plugin_0' of distribution '{DIST}' 1.2.3", expected)


def test_a_hook_returning_none_adds_nothing(install) -> None:
    install(nmsm_cost_terms=lambda: None, nmsm_constraint_terms=lambda: [_Path])
    assert build_registry().get("constraint", "check_path", "TO") is _Path


# ----- hook names (problem 4) ----------------------------------------------------------------------
def test_a_misspelled_hook_is_an_error(install) -> None:
    install(nmsm_cost_term=lambda: [_Goal])
    _refused("implements unknown hook 'nmsm_cost_term' (did you mean 'nmsm_cost_terms'?)",
             "valid hooks: nmsm_cost_terms, nmsm_constraint_terms, nmsm_controllers", f"'{DIST}' 1.2.3")


def test_a_hook_with_arguments_is_an_error(install) -> None:
    install(nmsm_cost_terms=lambda config: [_Goal], nmsm_constraint_terms=lambda: [_Path])
    _refused(f"plugin 'checks = check_plugin_check_plugin_0' of distribution '{DIST}' 1.2.3 cannot be registered: "
             "PluginValidationError", "'config'")


def test_a_hook_function_without_hookimpl_is_an_error(install) -> None:
    install(plain={"nmsm_cost_terms": lambda: [_Goal]})
    _refused("defines nmsm_cost_terms() without @hookimpl")


# ----- field types the settings reader reads (problem 5) -------------------------------------------
class _Custom:
    pass


@attrs.frozen(kw_only=True)
class _DictField(ContinuousCost):
    type: ClassVar[str] = "check_dict_field"
    gains: dict[str, float] = attrs.field(factory=dict)


@attrs.frozen(kw_only=True)
class _CustomField(ContinuousCost):
    type: ClassVar[str] = "check_custom_field"
    weird: _Custom | None = None


@attrs.frozen(kw_only=True)
class _MixedField(ContinuousCost):
    type: ClassVar[str] = "check_mixed_field"
    pair: tuple[str, float] = ("a", 1.0)


@pytest.mark.parametrize("cls, expected", [
    (_DictField, "has field 'gains' annotated dict[str, float], which the settings reader cannot read"),
    (_CustomField, f"has field 'weird' annotated {__name__}._Custom | None, which the settings reader cannot read"),
    (_MixedField, "has field 'pair' annotated tuple[str, float]"),
])
def test_field_types_the_reader_cannot_read_are_refused(install, cls: type, expected: str) -> None:
    install(nmsm_cost_terms=lambda: [cls])
    _refused(expected, "supported: str, int, float, bool, X | None, tuple[X, ...] and list[X]", "converter")


def _gains(text: Any) -> dict[str, float]:
    return {k: float(v) for k, v in (item.split(":") for item in text.split())} if isinstance(text, str) else text


@attrs.frozen(kw_only=True)
class _Converted(ContinuousCost):
    """Any annotation is fine with a converter that reads the element's text."""

    type: ClassVar[str] = "check_converted"
    gains: dict[str, float] = attrs.field(factory=dict, converter=_gains)
    names: tuple[str, ...] = ()
    limits: list[float] | None = None
    flags: tuple[bool, bool] = (False, False)


def test_supported_field_types_and_converters_register(install) -> None:
    install(nmsm_cost_terms=lambda: [_Converted])
    cls = build_registry().get("cost", "check_converted", "TO")
    (term,) = cls.from_spec(TermSpec("cost", "check_converted", {"gains": "a:1 b:2.5", "limits": "1 2"}))
    assert term.gains == {"a": 1.0, "b": 2.5} and term.limits == [1.0, 2.0]


# ----- an exception inside a term's own code (problem 7) -------------------------------------------
@attrs.frozen(kw_only=True)
class _Buggy(ContinuousCost):
    """quantity() has a bug; bind() calls super() (the slotted class keeps working)."""

    type: ClassVar[str] = "check_buggy"
    coordinate: str = ""
    where: str = "quantity"

    def bind(self, ctx: Any) -> None:
        super().bind(ctx)
        if self.where == "bind":
            ctx.require_coordinates(self, self.coordinate)  # a typo: no such ctx method
        if self.where == "input":
            raise self.error("no such coordinate", element="<coordinate>")

    def quantity(self, ctx: Any) -> Any:
        return {}["missing_key"]


class _Ctx:
    tool = "TO"

    def reduce_cost(self, term: Any, normalized: Any) -> Any:
        return normalized

    def reduce_constraint(self, term: Any, value: Any) -> Any:
        return value, term.min_error, term.max_error


def _buggy(install, where: str) -> Any:
    install(nmsm_cost_terms=lambda: [_Buggy])
    cls = build_registry().get("cost", "check_buggy", "TO")
    spec = TermSpec("cost", "check_buggy", {"is_enabled": "true", "coordinate": "knee", "where": where},
                    SourceRef("goals.xml", 27), {"coordinate": 29})
    (term,) = cls.from_spec(spec)
    return term


def test_an_exception_in_quantity_names_file_line_term_class_and_distribution(install) -> None:
    from nmsm.core.problem import OptimizationProblem

    term = _buggy(install, "quantity")
    with pytest.raises(NmsmError) as info:
        OptimizationProblem("p").add_term(term, _Ctx())
    text = str(info.value)
    assert text.startswith("goals.xml:27: term 'check_buggy'"), text
    assert f"({__name__}._Buggy from distribution '{DIST}' 1.2.3)" in text
    assert "failed while building its expression, in quantity(): KeyError 'missing_key'" in text
    assert "(run with --traceback for details)" in text
    assert isinstance(info.value.__cause__, KeyError)  # --traceback shows the origin


def test_an_exception_in_bind_is_reported_the_same_way(install) -> None:
    term = _buggy(install, "bind")
    with pytest.raises(NmsmError, match=r"goals.xml:27: .*in bind\(\): AttributeError '_Ctx' object has no "
                                        r"attribute 'require_coordinates'") as info:
        term.bind(_Ctx())
    assert isinstance(info.value.__cause__, AttributeError)


def test_input_errors_raised_on_purpose_by_a_term_pass_unchanged(install) -> None:
    term = _buggy(install, "input")
    with pytest.raises(InputError) as info:
        term.bind(_Ctx())
    assert str(info.value) == "goals.xml:29: <coordinate>: term 'check_buggy': no such coordinate"


def test_a_wrong_quantity_type_is_reported_from_the_base_class(install) -> None:
    @attrs.frozen(kw_only=True)
    class _Text(CostTerm):
        type: ClassVar[str] = "check_text"
        tools: ClassVar[frozenset[str]] = frozenset({"TO"})

        def quantity(self, ctx: Any) -> Any:
            return "oops"

    with pytest.raises(NmsmError, match=r"term 'check_text' .*in normalized\(\): TypeError unsupported operand"):
        _Text().residuals(_Ctx())
    assert float(np.sum(_Goal(count=2).residuals(types.SimpleNamespace(
        coordinate=lambda name: np.ones(3), reduce_cost=lambda term, z: z)))) == 6.0


def test_constraint_terms_are_guarded_too() -> None:
    @attrs.frozen(kw_only=True)
    class _Bad(ConstraintTerm):
        type: ClassVar[str] = "check_bad"
        tools: ClassVar[frozenset[str]] = frozenset({"TO"})

        def value(self, ctx: Any) -> Any:
            raise ValueError("bad shape")

    with pytest.raises(NmsmError, match=r"term 'check_bad' .*_Bad\) failed .*in value\(\): ValueError bad shape"):
        _Bad().bounded(_Ctx())


# ----- nmsm plugins (problems 8, 9) ----------------------------------------------------------------
def test_nmsm_plugins_lists_the_working_plugins_and_one_line_per_broken_one(install, tmp_path, capsys) -> None:
    from nmsm.cli import main

    install(nmsm_cost_terms=lambda: [_Goal, _NoTools])
    (tmp_path / "broken_import_plugin.py").write_text("raise ImportError('needs scikit-xyz')\n")
    info = tmp_path / "broken-plugin-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: broken-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[nmsm]\nbroken = broken_import_plugin\nmissing = json:no_such_attribute\n")
    try:
        assert main(["plugins"]) == 1
    finally:
        sys.modules.pop("broken_import_plugin", None)
    out = capsys.readouterr().out
    assert "generalized_coordinate_tracking" in out and "check_goal" in out  # nmsm's and the good class
    problems = out[out.index("plugin problem(s)"):].splitlines()[1:]
    assert len(problems) == 3, problems
    assert "plugin 'broken = broken_import_plugin' of distribution 'broken-plugin' 0.1 failed to load: ImportError: " \
           "needs scikit-xyz. Fix or uninstall 'broken-plugin', or leave it out with " \
           "NMSM_DISABLE_PLUGINS=broken-plugin" in problems[0]
    assert "plugin 'missing = json:no_such_attribute'" in problems[1] and "AttributeError" in problems[1]
    assert "check_no_tools" not in out.split("plugin problem(s)")[0] and "_NoTools" in problems[2]


def test_nmsm_plugins_accepts_every_kind_it_lists(capsys) -> None:
    from nmsm.cli import main

    assert main(["plugins", "--kind", "contact"]) == 0
    rows = capsys.readouterr().out.splitlines()[1:]
    assert rows and all(row.startswith("contact ") for row in rows)


def test_nmsm_plugins_into_a_closed_pipe_is_quiet() -> None:
    proc = subprocess.Popen([sys.executable, "-m", "nmsm", "plugins"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    proc.stdout.close()  # the reader (`head`) is gone before anything is written
    _, err = proc.communicate(timeout=120)
    assert b"Traceback" not in err and b"BrokenPipe" not in err, err.decode()
    assert proc.returncode == 0


def test_inspect_plugins_keeps_the_good_classes(install) -> None:
    from nmsm.core.registry import inspect_plugins

    install(nmsm_cost_terms=lambda: [_Goal, _NotATerm])
    report = inspect_plugins()
    assert report.registry.get("cost", "check_goal", "TO") is _Goal
    assert [p.distribution for p in report.problems] == [DIST]


# ----- controllers: the settings element selects them --------------------------------------------------
class _TorqueLike(Controller):
    type = "check_torque_like"
    settings_element = "RCNLTorqueController"


class _NoElement(Controller):
    type = "check_no_element"


def test_two_controllers_for_one_settings_element_are_refused(install) -> None:
    install(nmsm_controllers=lambda: [_TorqueLike])
    with pytest.raises(RegistryError, match=r"both handle <RCNLTorqueController> in DO, TO, VO: a settings file "
                                            r"could select only one of them"):
        build_registry()


def test_a_controller_without_a_settings_element_is_refused(install) -> None:
    install(nmsm_controllers=lambda: [_NoElement])
    with pytest.raises(RegistryError, match=r"controller 'check_no_element' .* sets no settings_element"):
        build_registry()
