"""The CostTerm base: normalized formula, reductions, settings conversion and errors."""

from __future__ import annotations

from typing import ClassVar

import attrs
import numpy as np
import pytest

from nmsm.core import reductions
from nmsm.core.term import ConstraintTerm, CostTerm, SourceRef, TermSpec
from nmsm.errors import InputError


@attrs.frozen(kw_only=True)
class _Offsets(CostTerm):
    """Test term: the raw quantity is a fixed array."""

    type: ClassVar[str] = "offsets"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})
    coordinate: str = ""
    values: tuple[float, ...] = ()

    def quantity(self, ctx):
        return np.asarray(self.values)


class _MeanSquareContext:
    tool = "MTP"

    def reduce_cost(self, term, z):
        return reductions.mean_square(z)

    def reduce_constraint(self, term, value):
        return value, term.min_error, term.max_error


def test_normalized_cost_matches_hand_computation() -> None:
    term = _Offsets(values=(1.0, 3.0, -2.0), error_center=1.0, max_allowable_error=2.0)
    r = term.residuals(_MeanSquareContext())
    # z = (x - 1)/2 = [0, 1, -1.5]; mean of squares = (0 + 1 + 2.25)/3
    assert float(np.sum(r**2)) == pytest.approx(3.25 / 3)


def test_quadrature_reduction() -> None:
    r = reductions.quadrature(np.array([1.0, 2.0]), np.array([0.25, 0.75]))
    assert float(np.sum(r**2)) == pytest.approx(0.25 * 1 + 0.75 * 4)


def test_from_spec_converts_and_splits_lists() -> None:
    spec = TermSpec(
        "cost", "offsets",
        {"is_enabled": "true", "max_allowable_error": "2.5", "coordinate_list": "knee ankle", "values": "1 2"},
        SourceRef("s.xml", 7),
    )
    terms = _Offsets.from_spec(spec)
    assert [t.coordinate for t in terms] == ["knee", "ankle"]
    assert terms[0].max_allowable_error == 2.5 and terms[0].values == (1.0, 2.0)
    assert terms[0].source == SourceRef("s.xml", 7)


def test_from_spec_unknown_element_names_file_line_and_valid_fields() -> None:
    spec = TermSpec("cost", "offsets", {"is_enabled": "true", "colour": "red"}, SourceRef("s.xml", 12), {"colour": 14})
    with pytest.raises(InputError) as info:
        _Offsets.from_spec(spec)
    text = str(info.value)
    assert "s.xml:14" in text and "<colour>" in text and "max_allowable_error" in text


def test_zero_max_allowable_error_rejected() -> None:
    spec = TermSpec("cost", "offsets", {"max_allowable_error": "0"}, SourceRef("s.xml", 3))
    with pytest.raises(InputError, match="must be > 0"):
        _Offsets.from_spec(spec)


def test_empty_max_allowable_error_treated_as_absent() -> None:
    spec = TermSpec("cost", "offsets", {"max_allowable_error": ""}, SourceRef("s.xml", 3))
    with pytest.warns(UserWarning, match="treated as absent"):
        (term,) = _Offsets.from_spec(spec)
    assert term.max_allowable_error == 1.0


def test_constraint_aliases_and_order() -> None:
    @attrs.frozen(kw_only=True)
    class _C(ConstraintTerm):
        type: ClassVar[str] = "c"
        tools: ClassVar[frozenset[str]] = frozenset({"TO"})

    (c,) = _C.from_spec(TermSpec("constraint", "c", {"max_value": "2", "min_value": "-3"}))
    assert (c.min_error, c.max_error) == (-3.0, 2.0)
    with pytest.raises(InputError, match="min_error"):
        _C.from_spec(TermSpec("constraint", "c", {"max_error": "-2", "min_error": "3"}))


# ----- reading values (an int is not truncated; normalization numbers are finite) -----------------
@attrs.frozen(kw_only=True)
class _Counted(CostTerm):
    type: ClassVar[str] = "counted"
    tools: ClassVar[frozenset[str]] = frozenset({"MTP"})
    count: int = 1


def test_int_field_refuses_a_fraction_and_names_the_element_and_line() -> None:
    spec = TermSpec("cost", "counted", {"count": "2.7"}, SourceRef("s.xml", 3), {"count": 5})
    with pytest.raises(InputError, match=r"s.xml:5: cannot read <count> = '2.7' of term 'counted': '2.7' is not an "
                                         r"integer \(expected int\)"):
        _Counted.from_spec(spec)
    assert [t.count for t in _Counted.from_spec(TermSpec("cost", "counted", {"count": "3"}))] == [3]
    assert [t.count for t in _Counted.from_spec(TermSpec("cost", "counted", {"count": "4.0"}))] == [4]


@pytest.mark.parametrize("element, text", [
    ("max_allowable_error", "inf"), ("error_center", "nan"), ("error_center", "-Infinity"),
])
def test_non_finite_cost_normalization_is_refused(element: str, text: str) -> None:
    spec = TermSpec("cost", "offsets", {element: text}, SourceRef("s.xml", 3), {element: 8})
    with pytest.raises(InputError) as info:
        _Offsets.from_spec(spec)
    assert str(info.value) == (f"s.xml:8: <{element}>: term 'offsets': '{text}' is not a finite number "
                               f"(expected a finite number)")


def test_non_finite_constraint_bounds_are_refused_as_written() -> None:
    @attrs.frozen(kw_only=True)
    class _C(ConstraintTerm):
        type: ClassVar[str] = "c"
        tools: ClassVar[frozenset[str]] = frozenset({"TO"})

    spec = TermSpec("constraint", "c", {"max_value": "inf"}, SourceRef("s.xml", 3), {"max_value": 6})
    with pytest.raises(InputError, match=r"s.xml:6: <max_value>: term 'c': 'inf' is not a finite number"):
        _C.from_spec(spec)
    spec = TermSpec("constraint", "c", {"min_error": "nan"}, SourceRef("s.xml", 3), {"min_error": 7})
    with pytest.raises(InputError, match=r"s.xml:7: <min_error>: term 'c': 'nan' is not a finite number"):
        _C.from_spec(spec)


# ----- <is_enabled> ------------------------------------------------------------------------------
class _OnlyOffsets:
    """A registry holding only :class:`_Offsets`."""

    def get(self, kind, name, tool):
        return _Offsets


@pytest.mark.parametrize("given,message", [
    ({}, "has no <is_enabled>"),
    # <is_enabled/> (or blank) is read as the missing element is: it used to switch the term
    # off silently (fuzz audit)
    ({"is_enabled": " "}, "has an empty <is_enabled>"),
])
def test_a_term_without_a_usable_is_enabled_is_not_used_and_warned_about(given: dict, message: str) -> None:
    from nmsm.core.registry import build_terms

    specs = [TermSpec("cost", "offsets", {**given, "values": "1"}, SourceRef("s.xml", 21)),
             TermSpec("cost", "offsets", {"is_enabled": "true", "values": "2"}, SourceRef("s.xml", 25))]
    with pytest.warns(UserWarning) as record:
        terms = build_terms(specs, "MTP", registry=_OnlyOffsets())
    assert [t.values for t in terms] == [(2.0,)]
    assert [str(w.message) for w in record] == [
        f"s.xml:21: <RCNLCostTerm> 'offsets' {message}: not used (write <is_enabled>true</is_enabled>)"]


def test_is_enabled_other_than_true_or_false_names_file_line_and_element() -> None:
    from nmsm.core.registry import build_terms

    spec = TermSpec("cost", "offsets", {"is_enabled": "yes"}, SourceRef("s.xml", 21), {"is_enabled": 22})
    with pytest.raises(InputError) as info:
        build_terms([spec], "MTP", registry=_OnlyOffsets())
    assert str(info.value) == ("s.xml:22: <is_enabled>: <RCNLCostTerm> 'offsets': <is_enabled> is 'yes' "
                               "(expected true or false)")
