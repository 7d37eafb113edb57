"""``user_defined`` constraint term (DO): a Python function's output, path or terminal.

Elements: ``function_name`` (see :mod:`nmsm.terms.treatment.user_functions`),
``constraint_term_type`` (``path`` | ``terminal``), ``max_error``/``min_error``, and extra
elements for the function (``term.options``).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import attrs

from nmsm.core.term import TermSpec
from nmsm.core.ocp import PathConstraint
from nmsm.terms.treatment.user_functions import resolve_user_function
from nmsm.core.user_terms import from_spec_with_options, options_field

CONSTRAINT_KINDS = ("path", "terminal")


@attrs.frozen(kw_only=True)
class UserDefinedConstraint(PathConstraint):
    """A constraint computed by a user-named Python function (path or terminal)."""

    type: ClassVar[str] = "user_defined"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})
    #: the pendulum of nmsm.testing.check_term: the final forward speed of its tip marker
    check_example: ClassVar[Mapping[str, str]] = {"function_name": "footSpeedConstraint",
                                                  "constraint_term_type": "terminal", "marker_name": "tip_1"}
    function_name: str
    constraint_term_type: str = "path"
    options: Mapping[str, str] = options_field()

    @property
    def evaluation(self) -> str:  # type: ignore[override]
        """``terminal`` or ``path``, as ``<constraint_term_type>`` says."""
        return "terminal" if self.constraint_term_type == "terminal" else "path"

    @classmethod
    def from_spec(cls, spec: TermSpec) -> list[Any]:
        return from_spec_with_options(cls, spec)

    def bind(self, ctx: Any) -> None:
        if self.constraint_term_type not in CONSTRAINT_KINDS:
            raise self.error(f"<constraint_term_type> '{self.constraint_term_type}' is not valid",
                             element="<constraint_term_type>", expected="path or terminal")
        resolve_user_function(self.function_name, term=self)

    def value(self, ctx: Any) -> Any:
        return resolve_user_function(self.function_name, term=self)(ctx, self)
