"""Python functions named by ``user_defined`` terms (``<function_name>``).

A user function takes ``(ctx, term)`` - the :class:`~nmsm.core.ocp.OcpContext`
and the term (its extra settings elements are in ``term.options``, strings) - and returns a
CasADi expression: a (K, 1) column on the collocation points for continuous costs and path
constraints, a scalar for discrete costs and terminal constraints (use ``ctx.initial`` /
``ctx.final``). The term then treats it like a built-in quantity: costs add
``((g - error_center) / max_allowable_error)^2`` (integrated for continuous ones),
constraints bound it by ``[min_error, max_error]``.

Differs from the original: MATLAB user functions take ``(values, modeledValues, auxdata,
term)`` and a discrete cost's output is added as it is; here it is normalized and squared
like every other term (return ``sqrt`` of a non-negative cost to add it as it is).

``<function_name>`` is either ``package.module:function`` (imported) or a name registered
in :data:`USER_FUNCTIONS` (built-ins below; plugins may add entries at import time).

Built-ins (the kicking tutorials name them; their MATLAB files were not distributed, so
they are implemented from the tutorials' description - a kick reaching a target toe speed):

``footSpeedCost``        discrete: forward (ground x) velocity of marker ``<marker_name>`` at
                         the final time minus ``<target_speed>`` (m/s)
``footSpeedConstraint``  terminal: forward (ground x) velocity of ``<marker_name>`` at the
                         final time (m/s), bounded by min_error/max_error
(The original's DO V5 result meets the 14.3-14.4 m/s bounds with this component: 14.300 m/s,
while the velocity magnitude is 14.64 m/s.)
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from typing import Any

from nmsm.errors import InputError

UserFunction = Callable[[Any, Any], Any]


def _option(term: Any, name: str, *, number: bool = False) -> Any:
    options = getattr(term, "options", {}) or {}
    if name not in options:
        raise term.error(f"user function '{term.function_name}' needs <{name}>", element=f"<{name}>",
                         expected=f"a <{name}> element in the term")
    value = options[name]
    if number:
        try:
            number_value = float(value)
        except ValueError:
            raise term.error(f"<{name}> = '{value}' is not a number", element=f"<{name}>") from None
        if not math.isfinite(number_value):  # float() reads nan and inf: IPOPT then stopped at its first iterate
            raise term.error(f"<{name}> = '{value}' is not finite", element=f"<{name}>", expected="a finite number")
        return number_value
    return value


def foot_speed(ctx: Any, term: Any) -> Any:
    """Forward (x) velocity (m/s) of ``<marker_name>`` at the final time."""
    marker = _option(term, "marker_name")
    ctx.require_marker(term, marker, element="<marker_name>")
    return ctx.final.marker_velocity(marker)[:, 0]


def foot_speed_cost(ctx: Any, term: Any) -> Any:
    """``footSpeedCost``: final forward toe velocity minus ``<target_speed>`` (m/s)."""
    return foot_speed(ctx, term) - _option(term, "target_speed", number=True)


def foot_speed_constraint(ctx: Any, term: Any) -> Any:
    """``footSpeedConstraint``: final forward toe velocity (m/s)."""
    return foot_speed(ctx, term)


USER_FUNCTIONS: dict[str, UserFunction] = {
    "footSpeedCost": foot_speed_cost,
    "footSpeedConstraint": foot_speed_constraint,
}


def resolve_user_function(name: str, *, term: Any = None) -> UserFunction:
    """The callable named ``name`` (``module:function`` or a key of USER_FUNCTIONS)."""
    def fail(message: str) -> InputError:
        if term is not None:
            return term.error(message, element="<function_name>",
                              expected="'package.module:function' or one of " + ", ".join(sorted(USER_FUNCTIONS)))
        return InputError(message, element="<function_name>")

    if ":" in name:
        module_name, _, attr = name.partition(":")
        try:
            module = importlib.import_module(module_name)
        except ImportError as exc:
            raise fail(f"cannot import module '{module_name}' for user function '{name}': {exc}") from exc
        fn = getattr(module, attr, None)
        if not callable(fn):
            raise fail(f"module '{module_name}' has no function '{attr}'")
        return fn
    if name in USER_FUNCTIONS:
        return USER_FUNCTIONS[name]
    raise fail(f"unknown user function '{name}' (MATLAB function files cannot be run; give a Python function)")
