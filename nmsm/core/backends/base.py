"""What a back end is, and finding one by name.

A back end is a class registered through the :func:`~nmsm.hookspecs.NmsmHookSpecs.nmsm_backends`
hook (nmsm's own through the entry point ``builtin_backends``, a plugin's through its own):
it sets ``type``, the name a tool asks for (``problem.solve("ipopt")``), and implements
:meth:`Backend.solve`. :func:`get_backend` finds it in the registry.
"""

from __future__ import annotations

from typing import Any, ClassVar

from nmsm.core.registry import TOOL_NAMES, Registry, get_registry
from nmsm.errors import RegistryError


class Backend:
    """A solver of optimization problems, chosen by name.

    ``type`` is its name, by which code chooses it (settings files do not); ``tools`` is every
    tool code, since a back end is found by name alone, whatever the tool. :meth:`solve`
    takes the problem and the back end's options as keywords and returns a
    :class:`~nmsm.core.solution.Solution`. Which problems a back end accepts is its own
    business: the built-in ones take an :class:`~nmsm.core.problem.OptimizationProblem`,
    and ``levenberg_marquardt`` also a :class:`~nmsm.core.residual_problem.ResidualProblem`;
    a back end given a problem it cannot solve raises :class:`TypeError` or
    :class:`ValueError` saying which it takes.
    """

    type: ClassVar[str] = ""
    tools: ClassVar[frozenset[str]] = frozenset(TOOL_NAMES)

    def solve(self, problem: Any, **options: Any) -> Any:
        """Solve ``problem`` with ``options``; returns a :class:`~nmsm.core.solution.Solution`."""
        raise NotImplementedError(f"{type(self).__name__}.solve")


def backend_names(registry: Registry | None = None) -> list[str]:
    """The names of every registered back end, sorted."""
    return (registry or get_registry()).names("backend")


def get_backend(name: str, *, registry: Registry | None = None) -> Backend:
    """The back end registered as ``name`` (an instance of its class).

    Raises :class:`~nmsm.errors.RegistryError` naming the registered back ends (and the
    closest name) when none is registered as ``name``.
    """
    import difflib

    registry = registry or get_registry()
    for item in registry.items("backend"):
        if item.name == name:
            return item.cls()
    known = backend_names(registry)
    close = difflib.get_close_matches(name, known, n=1)
    hint = f" (did you mean '{close[0]}'?)" if close else ""
    raise RegistryError(f"unknown back end '{name}'{hint}; registered back ends: {', '.join(known) or '(none)'}. "
                        "A back end from a plugin package needs that package installed in this environment "
                        "('nmsm plugins --kind backend' lists them)")
