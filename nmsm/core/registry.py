"""Plugin registry: every term, constraint, controller, model modifier, contact model and back
end, by kind and name.

Plugins are modules named by entry points in the ``nmsm`` group (nmsm's own built-ins
included). Each implements hooks of :mod:`nmsm.hookspecs` returning classes. A class
says its ``type`` (the settings name) and ``tools`` (which tools accept it).

Environment variables (reproducible runs, debugging):

``NMSM_LOAD_PLUGINS``
    Comma-separated distribution names; only these plugins load (``nmsm`` is always loaded).
``NMSM_DISABLE_PLUGINS``
    Comma-separated distribution names never loaded (``nmsm`` itself cannot be).
``NMSM_TRACE_PLUGINS``
    If set, print which plugin provided each class as the registry is built.

Distribution names are compared as pip does (case, ``-``, ``_`` and ``.`` alike); a name
that is not an installed plugin distribution is warned about.

Every class is checked when the registry is built, so a plugin author gets one message naming
the class, the plugin (entry point, distribution, version) and what was expected: a hook must
return a list of classes of the hook's base (:data:`BASES`); a class sets a ``type`` and
``tools``; a term class is an attrs class whose fields the settings reader can read
(:func:`nmsm.core.term.term_class_problems`); a hook implementation must name a hook of
:mod:`nmsm.hookspecs`. :func:`inspect_plugins` collects every problem without stopping (for
``nmsm plugins``); :func:`build_registry` raises them.
"""

from __future__ import annotations

import difflib
import os
import re
import sys
import warnings
from collections.abc import Callable, Iterable
from functools import cache
from importlib import metadata
from typing import Any

import attrs
import pluggy

from nmsm.core.origins import origin_of, record_origin  # noqa: F401  (origin_of: part of this module's API)
from nmsm.core.term import Term, TermSpec, _location, parse_bool, term_class_problems
from nmsm.errors import InputError, RegistryError
from nmsm.hookspecs import BUILTIN_PLUGINS, ENTRY_POINT_GROUP, PROJECT_NAME, NmsmHookSpecs

#: kind -> hook name
KINDS: dict[str, str] = {
    "cost": "nmsm_cost_terms",
    "constraint": "nmsm_constraint_terms",
    "controller": "nmsm_controllers",
    "modifier": "nmsm_model_modifiers",
    "contact": "nmsm_contact_models",
    "backend": "nmsm_backends",
}

#: kind -> the base class its hook's classes subclass (module, class name): imported when checked
BASES: dict[str, tuple[str, str]] = {
    "cost": ("nmsm.core.term", "CostTerm"),
    "constraint": ("nmsm.core.term", "ConstraintTerm"),
    "controller": ("nmsm.core.plugin_bases", "Controller"),
    "modifier": ("nmsm.core.plugin_bases", "ModelModifier"),
    "contact": ("nmsm.core.plugin_bases", "ContactModel"),
    "backend": ("nmsm.core.backends.base", "Backend"),
}

#: Tool codes used in ``tools`` class attributes.
TOOL_NAMES: dict[str, str] = {
    "JMP": "Joint Model Personalization",
    "MTLI": "Muscle-Tendon Length Initialization",
    "MTP": "Muscle-Tendon Personalization",
    "SynX": "Synergy Extrapolation (inside MTP)",
    "NCP": "Neural Control Personalization",
    "GCP": "Ground Contact Personalization",
    "TO": "Tracking Optimization",
    "VO": "Verification Optimization",
    "DO": "Design Optimization",
}


@attrs.frozen
class RegisteredItem:
    """One registered class and where it came from."""

    kind: str
    name: str
    cls: type
    tools: frozenset[str]
    distribution: str
    version: str
    plugin: str

    @property
    def description(self) -> str:
        doc = (self.cls.__doc__ or "").strip()
        return doc.splitlines()[0] if doc else ""



def _split_env(name: str) -> list[str]:
    return [p.strip() for p in os.environ.get(name, "").split(",") if p.strip()]


def _normalize(name: str) -> str:
    """A distribution name as pip compares it (PEP 503)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def _qualified(obj: type) -> str:
    return f"{obj.__module__}.{obj.__qualname__}"


class Registry:
    """All registered classes, checked for duplicates when built."""

    def __init__(self, items: Iterable[RegisteredItem] = ()) -> None:
        self._items: dict[tuple[str, str], list[RegisteredItem]] = {}
        for item in items:
            self._add(item)

    def _add(self, item: RegisteredItem) -> None:
        same = self._items.setdefault((item.kind, item.name), [])
        for other in same:
            overlap = other.tools & item.tools
            if not (overlap or not (other.tools or item.tools)):
                continue
            tools = ", ".join(sorted(overlap)) or "all"
            if other.cls is item.cls and other.distribution == item.distribution:
                raise RegistryError(
                    f"{item.kind} '{item.name}' ({_qualified(item.cls)}) is registered twice for tool(s) {tools} "
                    f"by distribution '{item.distribution}' {item.version}: its hooks return the class twice"
                )
            plugins = [d for d in (other.distribution, item.distribution) if _normalize(d) != PROJECT_NAME]
            disable = " or ".join(f"NMSM_DISABLE_PLUGINS={d}" for d in dict.fromkeys(plugins))
            raise RegistryError(
                f"{item.kind} '{item.name}' is registered twice for tool(s) "
                f"{tools}: by {_qualified(other.cls)} "
                f"from distribution '{other.distribution}' {other.version} and by "
                f"{_qualified(item.cls)} from distribution "
                f"'{item.distribution}' {item.version}. Uninstall one of them"
                + (f" or leave one out with {disable}." if disable else ".")
            )
        if item.kind == "controller":
            self._check_controller_element(item)
        same.append(item)
        record_origin(item.cls, item.distribution, item.version)

    def _check_controller_element(self, item: RegisteredItem) -> None:
        """A controller's settings element selects it: two controllers for the same element
        and tool would leave one of them unreachable."""
        element = getattr(item.cls, "settings_element", "")
        if not element:
            raise RegistryError(f"controller '{item.name}' ({_qualified(item.cls)}) of distribution "
                                f"'{item.distribution}' {item.version} sets no settings_element, so no settings "
                                "file could select it (write settings_element: ClassVar[str] = \"MyController\")")
        for (kind, _), group in self._items.items():
            for other in group:
                overlap = other.tools & item.tools
                if kind != "controller" or not overlap or getattr(other.cls, "settings_element", "") != element:
                    continue
                raise RegistryError(
                    f"controllers '{other.name}' ({_qualified(other.cls)}, distribution '{other.distribution}') and "
                    f"'{item.name}' ({_qualified(item.cls)}, distribution '{item.distribution}') both handle "
                    f"<{element}> in {', '.join(sorted(overlap))}: a settings file could select only one of them. "
                    "Give one another settings_element, or uninstall one"
                )

    def items(self, kind: str | None = None, tool: str | None = None) -> list[RegisteredItem]:
        """Registered items, sorted by kind then name, optionally filtered."""
        out = [
            it
            for group in self._items.values()
            for it in group
            if (kind is None or it.kind == kind) and (tool is None or tool in it.tools)
        ]
        return sorted(out, key=lambda it: (list(KINDS).index(it.kind), it.name, sorted(it.tools)))

    def names(self, kind: str, tool: str | None = None) -> list[str]:
        return sorted({it.name for it in self.items(kind, tool)})

    def get(self, kind: str, name: str, tool: str) -> type:
        """The class registered as ``name`` of ``kind`` for ``tool``.

        Raises :class:`RegistryError` listing the valid names when ``name`` is unknown or
        not accepted by ``tool``.
        """
        if kind not in KINDS:
            raise RegistryError(f"unknown kind '{kind}' (expected one of {', '.join(KINDS)})")
        candidates = self._items.get((kind, name), [])
        for it in candidates:
            if tool in it.tools:
                return it.cls
        valid = ", ".join(self.names(kind, tool)) or "(none)"
        if candidates:
            accepted = ", ".join(sorted(set().union(*(c.tools for c in candidates))))
            raise RegistryError(
                f"{kind} '{name}' is not allowed in {TOOL_NAMES.get(tool, tool)} ({tool}); "
                f"it is accepted by: {accepted}. Valid {kind} names for {tool}: {valid}"
            )
        close = difflib.get_close_matches(name, self.names(kind, tool), n=1)
        hint = f" (did you mean '{close[0]}'?)" if close else ""
        raise RegistryError(f"unknown {kind} '{name}' for {tool}{hint}. Valid {kind} names for {tool}: {valid}. "
                            "A name from a plugin package needs that package installed in this environment "
                            "('nmsm plugins' lists what is installed)")


@attrs.frozen
class PluginSource:
    """One plugin to load: an ``nmsm`` entry point of an installed distribution.

    ``load`` returns the plugin object (a module, or any object with hook functions). Tests
    and tools that hold a plugin object already build one with :meth:`of`.
    """

    name: str
    value: str
    distribution: str
    version: str
    load: Callable[[], object] = attrs.field(eq=False, repr=False)

    @classmethod
    def of(cls, plugin: object, distribution: str, version: str = "0", name: str | None = None) -> PluginSource:
        """A plugin object at hand, as if ``distribution`` named it by an entry point."""
        value = getattr(plugin, "__name__", None) or type(plugin).__name__
        return cls(name or value, value, distribution, version, lambda: plugin)

    @property
    def label(self) -> str:
        """``plugin 'NAME = VALUE' of distribution 'DIST' VERSION``, for messages."""
        return f"plugin '{self.name} = {self.value}' of distribution '{self.distribution}' {self.version}"

    @property
    def is_nmsm(self) -> bool:
        return _normalize(self.distribution) == PROJECT_NAME

    @property
    def remedy(self) -> str:
        """How to run without this plugin (nothing for nmsm's own)."""
        if self.is_nmsm:
            return "(nmsm's own plugin: please report this)"
        return (f"Fix or uninstall '{self.distribution}', or leave it out with "
                f"NMSM_DISABLE_PLUGINS={self.distribution}")


@attrs.frozen
class PluginProblem:
    """Why a plugin, or one of its classes, is left out of the registry."""

    distribution: str
    plugin: str
    message: str


@attrs.frozen
class PluginReport:
    """The registry of every class that passed the checks, and every problem found."""

    registry: Registry
    problems: tuple[PluginProblem, ...]

    def raise_problems(self) -> None:
        """:class:`RegistryError` listing every problem (nothing if none)."""
        if len(self.problems) == 1:
            raise RegistryError(self.problems[0].message)
        if self.problems:
            lines = "\n".join(f"  - {p.message}" for p in self.problems)
            raise RegistryError(f"{len(self.problems)} plugin problems (nmsm plugins lists them):\n{lines}")


def discover_plugins() -> list[PluginSource]:
    """Every ``nmsm`` entry point of the installed distributions, nmsm's own first, after
    ``NMSM_LOAD_PLUGINS`` / ``NMSM_DISABLE_PLUGINS``."""
    only = _split_env("NMSM_LOAD_PLUGINS")
    disabled = _split_env("NMSM_DISABLE_PLUGINS")
    if any(_normalize(name) == PROJECT_NAME for name in disabled):
        raise RegistryError(
            f"NMSM_DISABLE_PLUGINS names '{PROJECT_NAME}': nmsm's own terms, constraints, controllers and "
            f"modifiers register as the '{PROJECT_NAME}' plugin and cannot be left out (remove it from "
            f"NMSM_DISABLE_PLUGINS; name third-party distributions only)"
        )
    found: list[PluginSource] = []
    seen: set[tuple[str, str, str]] = set()
    for dist in metadata.distributions():
        dist_name = dist.metadata["Name"] or "?"
        for ep in dist.entry_points:
            if ep.group != ENTRY_POINT_GROUP:
                continue
            key = (_normalize(dist_name), ep.name, ep.value)
            if key in seen:  # the same distribution found twice on sys.path
                continue
            seen.add(key)
            found.append(PluginSource(ep.name, ep.value, dist_name, dist.version, ep.load))
    found += _builtins_missing_from(found)
    installed = {_normalize(src.distribution): src.distribution for src in found}
    for variable, names in (("NMSM_LOAD_PLUGINS", only), ("NMSM_DISABLE_PLUGINS", disabled)):
        unknown = [name for name in names if _normalize(name) not in installed and _normalize(name) != PROJECT_NAME]
        if unknown:
            listed = ", ".join(sorted(installed.values(), key=_normalize)) or "(none)"
            warnings.warn(
                f"{variable} names {', '.join(repr(n) for n in unknown)}, not an installed nmsm plugin distribution "
                f"(installed: {listed}); ignored",
                stacklevel=3,
            )
    keep_only = {_normalize(n) for n in only}
    leave_out = {_normalize(n) for n in disabled}
    out = [
        src for src in found
        if _normalize(src.distribution) not in leave_out
        and (not keep_only or src.is_nmsm or _normalize(src.distribution) in keep_only)
    ]
    # nmsm's own first: a clash with a built-in name then blames the plugin
    return sorted(out, key=lambda src: (not src.is_nmsm, _normalize(src.distribution), src.name))


def _builtins_missing_from(found: list[PluginSource]) -> list[PluginSource]:
    """nmsm's own plugin modules (:data:`~nmsm.hookspecs.BUILTIN_PLUGINS`) that the installed
    nmsm's entry points do not name: an editable install keeps the entry points of the day it
    was installed, and a built-in module added since is loaded all the same."""
    import importlib

    own = [src for src in found if src.is_nmsm]
    if not own:
        return []
    named = {src.value for src in own}
    return [PluginSource(name, value, own[0].distribution, own[0].version,
                         lambda value=value: importlib.import_module(value))
            for name, value in BUILTIN_PLUGINS.items() if value not in named]


def _describe(obj: object) -> str:
    """A returned object for messages: ``'text' (a str)``, ``mod.Class (a class)``."""
    if isinstance(obj, type):
        return f"{_qualified(obj)} (a class)"
    text = repr(obj)
    if len(text) > 80:
        text = text[:77] + "..."
    return f"{text} (a {type(obj).__name__})"


def _base(kind: str) -> type:
    import importlib

    module, name = BASES[kind]
    return getattr(importlib.import_module(module), name)


def _check_class(kind: str, obj: object) -> tuple[str, frozenset[str], list[str]]:
    """``(name, tools, problems)`` of a class returned by ``kind``'s hook."""
    assert isinstance(obj, type)
    base = _base(kind)
    if not issubclass(obj, base):
        text = f"is not a subclass of {_qualified(base)}, the base of {kind} classes"
        for other_kind in KINDS:
            other = _base(other_kind)
            if other_kind != kind and issubclass(obj, other):
                text += f" (it is a {other.__name__}: return it from {KINDS[other_kind]}())"
                break
        return "", frozenset(), [text]
    if issubclass(obj, Term):
        problems = term_class_problems(obj)
        if problems:
            return "", frozenset(), problems
    problems = []
    name = getattr(obj, "type", None) or getattr(obj, "name", None)
    if not isinstance(name, str) or not name:
        problems.append("sets no 'type' (its settings name): add type: ClassVar[str] = \"my_name\"")
        name = ""
    raw = getattr(obj, "tools", None)
    tools: frozenset[str] = frozenset()
    expected = f"codes among {', '.join(TOOL_NAMES)}"
    if isinstance(raw, str):
        problems.append(f"sets 'tools' to the string {raw!r}, not a set of tool codes "
                        f"(write tools: ClassVar[frozenset[str]] = frozenset({{{raw!r}}}); {expected})")
    elif not isinstance(raw, (set, frozenset, tuple, list)) or not all(isinstance(t, str) for t in raw):
        problems.append(f"sets 'tools' to {_describe(raw)}, not a set of tool codes "
                        f"(write tools: ClassVar[frozenset[str]] = frozenset({{...}}); {expected})")
    else:
        tools = frozenset(raw)
        unknown = tools - set(TOOL_NAMES)
        if unknown:
            problems.append(f"names unknown tool(s) {sorted(unknown)} (expected any of {', '.join(TOOL_NAMES)})")
        elif not tools:
            problems.append(f"sets no tools, so no tool could ever use it (write tools: ClassVar[frozenset[str]] = "
                            f"frozenset({{...}}) with {expected})")
    return name, tools, problems


def inspect_plugins(plugins: Iterable[PluginSource] | None = None) -> PluginReport:
    """Load ``plugins`` (default: :func:`discover_plugins`) and check every class, without stopping.

    Each problem (a plugin that does not load, a hook that raises or returns something other
    than a list of classes, a class of the wrong base or that no settings file could use, an
    unknown hook, a name registered twice) is reported with the plugin and left out; the
    returned registry holds the rest.
    """
    sources = discover_plugins() if plugins is None else list(plugins)
    if not any(src.is_nmsm for src in sources):
        raise RegistryError(
            "no nmsm plugins found: the built-in terms register through the 'nmsm' entry-point "
            "group, so nmsm must be installed (pip install -e . or pip install .), not only on sys.path"
        )
    trace = bool(os.environ.get("NMSM_TRACE_PLUGINS"))
    pm = pluggy.PluginManager(PROJECT_NAME)
    pm.add_hookspecs(NmsmHookSpecs)
    problems: list[PluginProblem] = []

    def problem(src: PluginSource, text: str, *, remedy: bool = True) -> None:
        problems.append(PluginProblem(src.distribution, src.name, f"{text}. {src.remedy}" if remedy else text))

    by_plugin: dict[int, PluginSource] = {}
    for src in sources:
        try:
            plugin = src.load()
        except Exception as exc:  # a broken third-party plugin must say who it is
            problem(src, f"{src.label} failed to load: {type(exc).__name__}: {exc}")
            continue
        if pm.is_registered(plugin):  # one module named by two entry points
            continue
        try:
            pm.register(plugin, name=f"{src.distribution}:{src.name}")
        except Exception as exc:  # pluggy: a hook implementation whose arguments the hook does not have
            problem(src, f"{src.label} cannot be registered: {type(exc).__name__}: {exc}")
            continue  # its hooks registered before the error are skipped below (not in by_plugin)
        by_plugin[id(plugin)] = src
        for hook_name in KINDS.values():
            if callable(getattr(plugin, hook_name, None)) and pm.parse_hookimpl_opts(plugin, hook_name) is None:
                problem(src, f"{src.label} defines {hook_name}() without @hookimpl "
                             f"(from nmsm.hookspecs import hookimpl), so nmsm never calls it")
        for caller in pm.get_hookcallers(plugin) or ():
            if caller.has_spec() or all(i.optionalhook for i in caller.get_hookimpls() if i.plugin is plugin):
                continue
            close = difflib.get_close_matches(caller.name, list(KINDS.values()), n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            problem(src, f"{src.label} implements unknown hook '{caller.name}'{hint}, which nmsm never calls; "
                         f"valid hooks: {', '.join(KINDS.values())}")

    registry = Registry()
    for kind, hook_name in KINDS.items():
        for impl in getattr(pm.hook, hook_name).get_hookimpls():
            src = by_plugin.get(id(impl.plugin))
            if src is None:  # a plugin pluggy refused (reported above)
                continue
            try:
                returned = impl.function()
            except Exception as exc:
                problem(src, f"{src.label}: hook {hook_name}() raised {type(exc).__name__}: {exc}")
                continue
            if returned is None:  # pluggy's "nothing to add"
                continue
            if not isinstance(returned, (list, tuple)):
                hint = f" (write return [{returned.__name__}])" if isinstance(returned, type) else ""
                problem(src, f"{src.label}: hook {hook_name}() returned {_describe(returned)}, not a list of "
                             f"classes{hint}")
                continue
            for obj in returned:
                if not isinstance(obj, type):
                    problem(src, f"{src.label}: hook {hook_name}() returned {_describe(obj)} in its list, not a class")
                    continue
                name, tools, issues = _check_class(kind, obj)
                for issue in issues:
                    problem(src, f"{src.label}: class {_qualified(obj)} returned by {hook_name}() {issue}")
                if issues:
                    continue
                item = RegisteredItem(kind, name, obj, tools, src.distribution, src.version, impl.plugin_name)
                try:
                    registry._add(item)
                except RegistryError as exc:
                    problem(src, str(exc), remedy="NMSM_DISABLE_PLUGINS" not in str(exc))
                    continue
                if trace:
                    print(f"[nmsm plugins] {kind} {name} <- {src.distribution} {src.version} ({impl.plugin_name})",
                          file=sys.stderr)
    return PluginReport(registry, tuple(problems))


def build_registry(plugins: Iterable[PluginSource] | None = None) -> Registry:
    """Discover plugins through entry points (or load ``plugins``) and build a fresh
    :class:`Registry`; :class:`RegistryError` naming every plugin problem found."""
    report = inspect_plugins(plugins)
    report.raise_problems()
    return report.registry


@cache
def get_registry() -> Registry:
    """The process-wide registry (built once)."""
    return build_registry()


def classes_in_package(package_name: str, base: type) -> list[type]:
    """Every subclass of ``base`` defined in the modules of ``package_name`` (recursively).

    Built-in plugin packages use this in their hook implementations, so a new term is one
    new module with one class, and nothing else to edit.
    """
    import importlib
    import inspect
    import pkgutil

    package = importlib.import_module(package_name)
    found: list[type] = []
    for info in pkgutil.walk_packages(package.__path__, prefix=package_name + "."):
        if info.name.rsplit(".", 1)[-1].startswith("_"):
            continue
        module = importlib.import_module(info.name)
        for _, obj in inspect.getmembers(module, inspect.isclass):
            if (
                obj.__module__ == module.__name__
                and issubclass(obj, base)
                and obj is not base
                and not inspect.isabstract(obj)
                and getattr(obj, "type", None)
                and not obj.__dict__.get("abstract", False)
            ):
                found.append(obj)
    return found


def build_terms(specs: list[TermSpec], tool: str, *, registry: Any = None) -> list[Term]:
    """Registered term instances for the enabled specs of ``tool``, in declaration order.

    A term without ``<is_enabled>``, or with an empty one, is not used (the original's default,
    false), with a warning; an ``<is_enabled>`` other than true/false, and unknown or
    disallowed type names, raise :class:`InputError` naming the file and line.
    """
    registry = registry or get_registry()
    out: list[Term] = []
    for spec in specs:
        tag = "RCNLCostTerm" if spec.kind == "cost" else "RCNLConstraintTerm"
        where = _location(spec.source.file, spec.source.line)
        text = spec.fields.get("is_enabled")
        if text is None or not text.strip():  # the original's default: false
            state = "has no <is_enabled>" if text is None else "has an empty <is_enabled>"
            warnings.warn(f"{where}<{tag}> '{spec.type}' {state}: not used "
                          f"(write <is_enabled>true</is_enabled>)", stacklevel=2)
            continue
        try:
            enabled = parse_bool(text)
        except ValueError as exc:
            raise InputError(f"<{tag}> '{spec.type}': <is_enabled> is '{text}'", file=spec.source.file,
                             line=spec.field_lines.get("is_enabled", spec.source.line), element="<is_enabled>",
                             expected="true or false") from exc
        if not enabled:
            continue
        try:
            cls = registry.get(spec.kind, spec.type, tool)
        except RegistryError as exc:
            raise InputError(str(exc), file=spec.source.file, line=spec.source.line, element="<type>") from exc
        out.extend(cls.from_spec(spec))
    return out
