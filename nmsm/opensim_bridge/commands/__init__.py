"""Commands the OpenSim worker answers, one module per family.

Runs inside the worker only: modules here may import ``opensim`` but never CasADi.
Add a command by decorating a function with :func:`command` in a module of this
package; its keyword arguments and return value must be picklable (numpy arrays,
lists, dicts, str, numbers).
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable
from typing import Any

COMMANDS: dict[str, Callable[..., Any]] = {}


def command(func: Callable[..., Any]) -> Callable[..., Any]:
    """Register ``func`` as a worker command under its own name."""
    if func.__name__ in COMMANDS:
        raise ValueError(f"bridge command '{func.__name__}' defined twice")
    COMMANDS[func.__name__] = func
    return func


def load_all() -> None:
    """Import every command module of this package."""
    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")
