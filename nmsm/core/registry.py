"""Plugin registry: every term, constraint, controller and model modifier, by kind and name.

Plugins are modules named by entry points in the ``nmsm`` group (nmsm's own built-ins
included). Each implements hooks of :mod:`nmsm.hookspecs` returning classes. A class
says its ``type`` (the settings name) and ``tools`` (which tools accept it).

Environment variables (reproducible runs, debugging):

``NMSM_LOAD_PLUGINS``
    Comma-separated distribution names; only these plugins load (``nmsm`` is always loaded).
``NMSM_DISABLE_PLUGINS``
    Comma-separated distribution names never loaded.
``NMSM_TRACE_PLUGINS``
    If set, print which plugin provided each class as the registry is built.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterable
from functools import cache
from importlib import metadata

import attrs
import pluggy

from nmsm.errors import RegistryError
from nmsm.hookspecs import ENTRY_POINT_GROUP, PROJECT_NAME, NmsmHookSpecs

#: kind -> hook name
KINDS: dict[str, str] = {
    "cost": "nmsm_cost_terms",
    "constraint": "nmsm_constraint_terms",
    "controller": "nmsm_controllers",
    "modifier": "nmsm_model_modifiers",
    "contact": "nmsm_contact_models",
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


def _split_env(name: str) -> set[str]:
    return {p.strip() for p in os.environ.get(name, "").split(",") if p.strip()}


class Registry:
    """All registered classes, checked for duplicates when built."""

    def __init__(self, items: Iterable[RegisteredItem]) -> None:
        self._items: dict[tuple[str, str], list[RegisteredItem]] = {}
        for item in items:
            self._add(item)

    def _add(self, item: RegisteredItem) -> None:
        same = self._items.setdefault((item.kind, item.name), [])
        for other in same:
            overlap = other.tools & item.tools
            if overlap or not (other.tools or item.tools):
                raise RegistryError(
                    f"{item.kind} '{item.name}' is registered twice for tool(s) "
                    f"{', '.join(sorted(overlap)) or 'all'}: by {other.cls.__module__}.{other.cls.__qualname__} "
                    f"from distribution '{other.distribution}' {other.version} and by "
                    f"{item.cls.__module__}.{item.cls.__qualname__} from distribution "
                    f"'{item.distribution}' {item.version}. Uninstall one of them or set "
                    f"NMSM_DISABLE_PLUGINS."
                )
        same.append(item)

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
        raise RegistryError(f"unknown {kind} '{name}' for {tool}. Valid {kind} names for {tool}: {valid}")


def _plugin_manager() -> tuple[pluggy.PluginManager, dict[int, tuple[str, str]]]:
    """Load every ``nmsm`` entry point; return the manager and plugin -> (dist, version)."""
    pm = pluggy.PluginManager(PROJECT_NAME)
    pm.add_hookspecs(NmsmHookSpecs)
    only = _split_env("NMSM_LOAD_PLUGINS")
    disabled = _split_env("NMSM_DISABLE_PLUGINS")
    origin: dict[int, tuple[str, str]] = {}
    seen: set[tuple[str, str]] = set()
    for dist in metadata.distributions():
        dist_name = dist.metadata["Name"] or "?"
        for ep in dist.entry_points:
            if ep.group != ENTRY_POINT_GROUP:
                continue
            key = (dist_name, ep.value)
            if key in seen:  # the same distribution found twice on sys.path
                continue
            seen.add(key)
            if dist_name in disabled:
                continue
            if only and dist_name != PROJECT_NAME and dist_name not in only:
                continue
            try:
                plugin = ep.load()
            except Exception as exc:  # a broken third-party plugin must say who it is
                raise RegistryError(
                    f"plugin entry point '{ep.name} = {ep.value}' of distribution "
                    f"'{dist_name}' {dist.version} failed to load: {exc!r}"
                ) from exc
            if pm.is_registered(plugin):
                continue
            pm.register(plugin, name=f"{dist_name}:{ep.name}")
            origin[id(plugin)] = (dist_name, dist.version)
    return pm, origin


def build_registry() -> Registry:
    """Discover plugins through entry points and build a fresh :class:`Registry`."""
    pm, origin = _plugin_manager()
    trace = bool(os.environ.get("NMSM_TRACE_PLUGINS"))
    items: list[RegisteredItem] = []
    for kind, hook_name in KINDS.items():
        caller = getattr(pm.hook, hook_name)
        for impl in caller.get_hookimpls():
            classes = impl.function() or []
            dist, version = origin.get(id(impl.plugin), ("?", "?"))
            for cls in classes:
                name = getattr(cls, "type", None) or getattr(cls, "name", None)
                if not isinstance(name, str) or not name:
                    raise RegistryError(
                        f"{kind} class {cls.__module__}.{cls.__qualname__} from distribution "
                        f"'{dist}' has no 'type' name"
                    )
                tools = frozenset(getattr(cls, "tools", frozenset()))
                unknown = tools - set(TOOL_NAMES)
                if unknown:
                    raise RegistryError(
                        f"{kind} '{name}' from distribution '{dist}' names unknown tool(s) "
                        f"{sorted(unknown)} (expected any of {', '.join(TOOL_NAMES)})"
                    )
                item = RegisteredItem(kind, name, cls, tools, dist, version, impl.plugin_name)
                if trace:
                    print(f"[nmsm plugins] {kind} {name} <- {dist} {version} ({impl.plugin_name})", file=sys.stderr)
                items.append(item)
    if not any(dist == PROJECT_NAME for dist, _ in origin.values()):
        raise RegistryError(
            "no nmsm plugins found: the built-in terms register through the 'nmsm' entry-point "
            "group, so nmsm must be installed (pip install -e . or pip install .), not only on sys.path"
        )
    return Registry(items)


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
