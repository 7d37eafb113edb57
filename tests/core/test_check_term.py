"""``nmsm.testing.check_term`` on every registered term (plugins included), on broken terms it
must refuse, and every registered name documented where a user looks."""

from __future__ import annotations

import re
import warnings
from pathlib import Path
from typing import Any, ClassVar

import attrs
import casadi as cs
import numpy as np
import pytest

from nmsm.core.ocp import ContinuousCost
from nmsm.core.registry import get_registry
from nmsm.testing import TermCheckError, check_term

DOCS = Path(__file__).resolve().parents[2] / "docs"


def _term_classes() -> list[Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        items = get_registry().items()
    seen: dict[type, Any] = {}
    for item in items:
        if item.kind in ("cost", "constraint") and item.cls not in seen:
            seen[item.cls] = pytest.param(item.cls, id=f"{item.kind}:{item.name}:{item.cls.__name__}")
    return list(seen.values())


@pytest.mark.parametrize("cls", _term_classes())
def test_every_registered_term_passes_check_term(cls: type) -> None:
    report = check_term(cls)
    assert "declaration" in report.passed


@attrs.frozen(kw_only=True)
class _Tracking(ContinuousCost):
    """q_exp - q (rad), as a plugin would write it."""

    type: ClassVar[str] = "check_term_probe_tracking"
    coordinate: str

    def bind(self, ctx: Any) -> None:
        ctx.require_coordinate(self, self.coordinate)

    def quantity(self, ctx: Any) -> Any:
        return ctx.tracked_coordinate(self.coordinate) - ctx.coordinate(self.coordinate)


@attrs.frozen(kw_only=True)
class _CoordinateTracking(_Tracking):
    """q_exp - q (rad), under the built-in family's name (so the tracking check applies)."""

    type: ClassVar[str] = "generalized_coordinate_tracking"


@pytest.mark.parametrize("cls, checks", [
    (_Tracking, ["declaration", "settings", "bad elements refused", "built, finite", "derivatives"]),
    (_CoordinateTracking, ["declaration", "settings", "bad elements refused", "built, finite", "derivatives",
                           "zero at perfect tracking"]),
])
def test_a_correct_term_passes_every_check(cls: type, checks: list[str]) -> None:
    report = check_term(cls)
    assert report.passed == checks
    assert report.not_built is None


@attrs.frozen(kw_only=True)
class _OffsetTracking(_Tracking):
    """q_exp - q + 0.1 (rad): not zero where the motion is the tracked one."""

    type: ClassVar[str] = "generalized_coordinate_tracking"

    def quantity(self, ctx: Any) -> Any:
        return super().quantity(ctx) + 0.1


@attrs.frozen(kw_only=True)
class _HiddenDerivative(_Tracking):
    """(q_exp - q)^2 with its derivative hidden from CasADi (exact derivative 0)."""

    def quantity(self, ctx: Any) -> Any:
        return cs.stop_diff(super().quantity(ctx) ** 2, 1)


@attrs.frozen(kw_only=True)
class _SizeTracking(_Tracking):
    """A continuous cost with the wrong shape (a scalar)."""

    def quantity(self, ctx: Any) -> Any:
        return cs.sum1(super().quantity(ctx))


@attrs.frozen(kw_only=True)
class _MisspelledQuantity(_Tracking):
    """Asks the context for a quantity it has not."""

    def quantity(self, ctx: Any) -> Any:
        return ctx.coordinat(self.coordinate)


@pytest.mark.parametrize("cls, message", [
    (_OffsetTracking, "not zero on the tracked motion"),
    (_HiddenDerivative, "differs from finite differences"),
    (_SizeTracking, r"\(K, 1\)|column|shape"),
    (_MisspelledQuantity, "coordinat"),
])
def test_broken_terms_are_refused(cls: type, message: str) -> None:
    with pytest.raises(TermCheckError, match=message):
        check_term(cls)


def test_a_term_without_evaluation_is_refused() -> None:
    from nmsm.core.term import CostTerm

    @attrs.frozen(kw_only=True)
    class NoEvaluation(CostTerm):
        """Raw CostTerm for a treatment tool."""

        type: ClassVar[str] = "check_term_no_evaluation"
        tools: ClassVar[frozenset[str]] = frozenset({"TO"})

    with pytest.raises(TermCheckError, match="declares no 'evaluation'"):
        check_term(NoEvaluation)


def test_every_registered_name_is_documented() -> None:
    text = "\n".join(p.read_text(encoding="utf-8") for p in sorted(DOCS.glob("*.md")))
    text += (Path(__file__).resolve().parents[2] / "plugins_example" / "README.md").read_text(encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        items = get_registry().items()
    missing = sorted({f"{it.kind} {it.name}" for it in items if not re.search(rf"\b{re.escape(it.name)}\b", text)})
    assert not missing, f"registered names documented nowhere in docs/*.md: {missing}"


def test_the_terms_catalog_is_current() -> None:
    from nmsm.testing.term_catalog import catalog

    assert (DOCS / "terms.md").read_text(encoding="utf-8") == catalog(), \
        "docs/terms.md is stale: python -m nmsm.testing.term_catalog > docs/terms.md"
