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
from nmsm.core.term import CostTerm
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


#: built-in treatment tracking terms of the leg's data, zero where the leg reproduces them
_LEG_TRACKING = {"external_force_tracking", "external_moment_tracking", "center_of_pressure_tracking",
                 "center_of_presssure_tracking", "muscle_activation_tracking"}


@pytest.mark.parametrize("cls", _term_classes())
def test_every_registered_term_passes_check_term(cls: type) -> None:
    """Every built-in term is built and its derivatives checked on a synthetic problem of its
    tool (TO/VO/DO: the pendulum, or the leg for muscles, synergies and foot contact)."""
    report = check_term(cls)
    assert "declaration" in report.passed
    if not cls.__module__.startswith("nmsm."):  # an installed plugin: its own tests say more
        return
    assert report.not_built is None, report.not_built
    assert "derivatives" in report.passed
    if cls.type in _LEG_TRACKING:
        assert report.problem == "leg" and "zero at perfect tracking" in report.passed


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


def _half_derivative(x: Any) -> Any:
    """x^2 whose CasADi derivative is x dx (half the true one): a wrong exact derivative."""
    return x * cs.stop_diff(x, 1)


_NUMBERS = ["declaration", "settings", "bad elements refused", "shape", "built, finite", "derivatives"]


@pytest.mark.parametrize("cls, checks", [
    (_Tracking, _NUMBERS + ["unknown names refused"]),
    (_CoordinateTracking, _NUMBERS + ["zero at perfect tracking", "unknown names refused"]),
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
    """(q_exp - q)^2 with one factor hidden from CasADi (exact derivative half the true one)."""

    def quantity(self, ctx: Any) -> Any:
        return _half_derivative(super().quantity(ctx))


@attrs.frozen(kw_only=True)
class _SizeTracking(_Tracking):
    """A continuous cost with the wrong shape (a scalar)."""

    def quantity(self, ctx: Any) -> Any:
        return cs.sum1(super().quantity(ctx))


@attrs.frozen(kw_only=True)
class _NonFinite(_Tracking):
    """The square root of a negative number (NaN)."""

    def quantity(self, ctx: Any) -> Any:
        return cs.sqrt(-1 - super().quantity(ctx) ** 2)


@attrs.frozen(kw_only=True)
class _MisspelledQuantity(_Tracking):
    """Asks the context for a quantity it has not."""

    def quantity(self, ctx: Any) -> Any:
        return ctx.coordinat(self.coordinate)


@attrs.frozen(kw_only=True)
class _TrackingWithoutNameCheck(_Tracking):
    """q_exp - q (rad) with a bind that checks nothing: a wrong name fails only while building."""

    def bind(self, ctx: Any) -> None:
        pass


@attrs.frozen(kw_only=True)
class _DataOnly(_Tracking):
    """The tracked coordinate alone: data, no design variable."""

    def quantity(self, ctx: Any) -> Any:
        return ctx.tracked_coordinate(self.coordinate)


@attrs.frozen(kw_only=True)
class _VagueNameCheck(_Tracking):
    """Refuses an unknown coordinate without saying which."""

    def bind(self, ctx: Any) -> None:
        if self.coordinate not in ctx.state_coordinates:
            raise self.error("unknown coordinate")


@attrs.frozen(kw_only=True)
class _AcceptsZeroError(_Tracking):
    """Redeclares max_allowable_error without the base's validator (0 would divide by zero)."""

    max_allowable_error: float = 1.0


@pytest.mark.parametrize("cls, message", [
    (_VagueNameCheck, "check_term_no_such_coordinate' was refused, but the message does not name it"),
    (_AcceptsZeroError, r"\{'max_allowable_error': '0'\} were accepted"),
    (_OffsetTracking, "not zero on the tracked motion"),
    (_HiddenDerivative, "differs from finite differences"),
    (_SizeTracking, r"\(K, 1\)|column|shape"),
    (_NonFinite, "non-finite values"),
    (_MisspelledQuantity, "coordinat"),
    (_TrackingWithoutNameCheck, "check_term_no_such_coordinate.*not refused with an InputError"),
    (_DataOnly, "does not depend on any design variable"),
])
def test_broken_terms_are_refused(cls: type, message: str) -> None:
    with pytest.raises(TermCheckError, match=message):
        check_term(cls)


# ----- the personalization tools' synthetic problems -------------------------------------------
def _personalization(tool: str, type_: str, quantity: Any, *, base: type = CostTerm) -> type:
    """A cost term of ``tool`` whose raw quantity is ``quantity(ctx)``, as a plugin would write it."""

    @attrs.frozen(kw_only=True)
    class Probe(base):
        """A probe term of check_term's tests (units of its quantity)."""

        tools: ClassVar[frozenset[str]] = frozenset({tool})

        def quantity(self, ctx: Any) -> Any:
            return quantity(ctx)

    Probe.type = type_
    return Probe


def _mtp_moments(ctx: Any) -> Any:
    return ctx.moment_errors(synx=False)


def _gcp_forces(ctx: Any) -> Any:
    return tuple(ctx.force_errors(foot, [1]) for foot in range(ctx.n_feet))


def _jmp_markers(ctx: Any) -> Any:
    return ctx.marker_position_errors()


@pytest.mark.parametrize("tool, quantity", [
    ("MTP", _mtp_moments),
    ("SynX", lambda ctx: ctx.moment_errors(synx=True)),
    ("MTLI", lambda ctx: cs.vertcat(*ctx.passive_force)),
    ("NCP", lambda ctx: ctx.moment_errors()),
    ("GCP", _gcp_forces),
    ("JMP", _jmp_markers),
])
def test_a_correct_personalization_term_passes_every_check(tool: str, quantity: Any) -> None:
    report = check_term(_personalization(tool, "check_term_probe", quantity))
    assert report.passed == _NUMBERS
    assert report.not_built is None


@pytest.mark.parametrize("tool, quantity, zero", [
    ("MTP", _mtp_moments, True),
    ("NCP", lambda ctx: ctx.moment_errors(), True),
    ("JMP", _jmp_markers, True),
    ("MTLI", lambda ctx: cs.vertcat(*[m - cs.DM(t.inverse_dynamics_moments)
                                      for t, m in zip(ctx.passive_trials, ctx.passive_moments)]), True),
])
def test_a_personalization_tracking_term_is_zero_where_the_data_are_reproduced(tool: str, quantity: Any,
                                                                               zero: bool) -> None:
    report = check_term(_personalization(tool, "check_term_probe", quantity), zero_at_tracking=zero)
    assert report.passed[-1] == "zero at perfect tracking"


@pytest.mark.parametrize("tool, quantity, message", [
    ("MTP", lambda ctx: _mtp_moments(ctx) + 0.1, "not zero on the tracked motion"),
    ("NCP", lambda ctx: ctx.moment_errors() + 0.1, "not zero on the tracked motion"),
    ("JMP", lambda ctx: _jmp_markers(ctx) + 1e-3, "not zero on the tracked motion"),
    ("MTP", lambda ctx: _half_derivative(_mtp_moments(ctx)), "differs from finite differences"),
    ("NCP", lambda ctx: _half_derivative(ctx.moment_errors()), "differs from finite differences"),
    ("GCP", lambda ctx: tuple(_half_derivative(b) for b in _gcp_forces(ctx)), "differs from finite differences"),
    ("GCP", lambda ctx: ctx.force_errors(0, [1]), "one block per foot"),
    ("MTP", lambda ctx: cs.MX(0, 1), "no residual"),
    ("NCP", lambda ctx: ctx.inputs.trials[0].moments, "does not depend on any design variable"),
    ("MTLI", lambda ctx: ctx.no_such_quantity, "no_such_quantity"),
])
def test_broken_personalization_terms_are_refused(tool: str, quantity: Any, message: str) -> None:
    cls = _personalization(tool, "check_term_probe", quantity)
    with pytest.raises(TermCheckError, match=message):
        check_term(cls, zero_at_tracking=message.startswith("not zero"))


def test_a_term_is_checked_for_the_tool_asked() -> None:
    from nmsm.core.registry import get_registry

    penalty = get_registry().get("cost", "muscle_excitation_penalty", "SynX")  # MTP and SynX
    assert check_term(penalty, tool="SynX").passed == _NUMBERS
    with pytest.raises(TermCheckError, match=r"tool='GCP'.*accepts \['MTP', 'SynX'\]"):
        check_term(penalty, tool="GCP")


def test_zero_at_tracking_on_a_problem_without_a_tracked_point_is_refused() -> None:
    with pytest.raises(TermCheckError, match="no point where its data are tracked exactly"):
        check_term(_personalization("GCP", "check_term_probe", _gcp_forces), zero_at_tracking=True)


# ----- derivatives of quantities that jump between mesh intervals ------------------------------
@attrs.frozen(kw_only=True)
class _Jerk(_Tracking):
    """d/dt of the coordinate's acceleration (rad/s^3): a control, free to jump between intervals."""

    type: ClassVar[str] = "check_term_probe_jerk"

    def quantity(self, ctx: Any) -> Any:
        return ctx.differentiate(ctx.acceleration(self.coordinate))


@attrs.frozen(kw_only=True)
class _SpeedRate(_Tracking):
    """d/dt of the coordinate's speed (rad/s^2): a state, continuous across intervals."""

    type: ClassVar[str] = "check_term_probe_speed_rate"

    def quantity(self, ctx: Any) -> Any:
        return ctx.differentiate(ctx.speed(self.coordinate))


def test_differentiating_a_control_warns_once_per_term() -> None:
    from nmsm.core.ocp import DiscontinuousDerivativeWarning
    from nmsm.io.term_spec import SourceRef
    from nmsm.testing.pendulum_problem import build_pendulum_problem

    first = _Jerk(coordinate="q0", source=SourceRef("jerk.xml", 4))
    same = _Jerk(coordinate="q1", source=SourceRef("jerk.xml", 4))  # the same <RCNLCostTerm>, another item
    other = _Jerk(coordinate="q1", source=SourceRef("jerk.xml", 9))
    with pytest.warns(DiscontinuousDerivativeWarning) as caught:
        build_pendulum_problem([first, same, other])
    messages = [str(w.message) for w in caught if issubclass(w.category, DiscontinuousDerivativeWarning)]
    assert len(messages) == 2
    assert messages[0].startswith("jerk.xml:4: term 'check_term_probe_jerk'") and "jump" in messages[0]
    assert messages[1].startswith("jerk.xml:9: ")
    report = check_term(_Jerk)
    assert len(report.warnings) == 1 and "depends on the controls" in report.warnings[0]


def test_differentiating_a_state_does_not_warn() -> None:
    from nmsm.core.ocp import DiscontinuousDerivativeWarning
    from nmsm.testing.pendulum_problem import build_pendulum_problem

    with warnings.catch_warnings():
        warnings.simplefilter("error", DiscontinuousDerivativeWarning)
        build_pendulum_problem([_SpeedRate(coordinate="q0")])
    assert check_term(_SpeedRate).warnings == []


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
