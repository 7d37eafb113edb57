"""``user_defined`` cost term (DO): a Python function's output as a continuous or discrete cost.

Elements: ``function_name`` (``package.module:function`` or a registered name, see
:mod:`nmsm.terms.treatment.user_functions`), ``cost_term_type`` (``continuous`` |
``discrete``), ``max_allowable_error``/``error_center``, and any extra elements the function
reads from ``term.options`` (e.g. ``marker_name``, ``target_speed``).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import attrs

from nmsm.core.term import TermSpec
from nmsm.core.ocp import ContinuousCost
from nmsm.terms.treatment.user_functions import resolve_user_function
from nmsm.core.user_terms import from_spec_with_options, options_field

COST_KINDS = ("continuous", "discrete")


@attrs.frozen(kw_only=True)
class UserDefinedCost(ContinuousCost):
    """A cost computed by a user-named Python function (continuous or discrete)."""

    type: ClassVar[str] = "user_defined"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})
    #: the pendulum of nmsm.testing.check_term: the final forward speed of its tip marker
    check_example: ClassVar[Mapping[str, str]] = {"function_name": "footSpeedCost", "cost_term_type": "discrete",
                                                  "marker_name": "tip_1", "target_speed": "1.0"}
    function_name: str
    cost_term_type: str = "continuous"
    options: Mapping[str, str] = options_field()

    @property
    def evaluation(self) -> str:  # type: ignore[override]
        """``discrete`` or ``continuous``, as ``<cost_term_type>`` says."""
        return "discrete" if self.cost_term_type == "discrete" else "continuous"

    @classmethod
    def from_spec(cls, spec: TermSpec) -> list[Any]:
        return from_spec_with_options(cls, spec)

    def bind(self, ctx: Any) -> None:
        if self.cost_term_type not in COST_KINDS:
            raise self.error(f"<cost_term_type> '{self.cost_term_type}' is not valid", element="<cost_term_type>",
                             expected="continuous or discrete")
        resolve_user_function(self.function_name, term=self)

    def quantity(self, ctx: Any) -> Any:
        return resolve_user_function(self.function_name, term=self)(ctx, self)
