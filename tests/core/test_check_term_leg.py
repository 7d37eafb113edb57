"""``nmsm.testing.check_term`` on terms of muscles, synergies and foot contact: built on the
synthetic leg (:mod:`nmsm.testing.leg_problem`), and refused when broken."""

from __future__ import annotations

from typing import Any, ClassVar

import attrs
import casadi as cs
import numpy as np
import pytest

from nmsm.core.ocp import ContinuousCost, DiscreteCost
from nmsm.testing import TermCheckError, check_term

_NUMBERS = ["declaration", "settings", "bad elements refused", "shape", "built, finite", "derivatives"]


@attrs.frozen(kw_only=True)
class _ForceTracking(ContinuousCost):
    """F_exp - F of a ground reaction force column (N), as a plugin would write it."""

    type: ClassVar[str] = "check_term_probe_force_tracking"
    check_example: ClassVar[dict[str, str]] = {"force": "ground_force_vy"}
    force: str

    def bind(self, ctx: Any) -> None:
        ctx.require_reaction(self, self.force, "force", "<force>")

    def quantity(self, ctx: Any) -> Any:
        return cs.MX(ctx.tracked_ground_reaction_force(self.force)) - ctx.ground_reaction_force(self.force)


@attrs.frozen(kw_only=True)
class _ActivationTracking(ContinuousCost):
    """a_exp - a of one muscle (dimensionless)."""

    type: ClassVar[str] = "check_term_probe_activation_tracking"
    check_example: ClassVar[dict[str, str]] = {"muscle": "muscle_1"}
    muscle: str

    def bind(self, ctx: Any) -> None:
        ctx.require_tracked_activation(self, self.muscle, "<muscle>")

    def quantity(self, ctx: Any) -> Any:
        return cs.MX(ctx.tracked_muscle_activation(self.muscle)) - ctx.muscle_activation(self.muscle)


@attrs.frozen(kw_only=True)
class _MetabolicEnergy(DiscreteCost):
    """Metabolic energy over the movement (J)."""

    type: ClassVar[str] = "check_term_probe_metabolic_energy"
    tools: ClassVar[frozenset[str]] = frozenset({"DO"})

    def bind(self, ctx: Any) -> None:
        ctx.require_metabolic_model(self)

    def quantity(self, ctx: Any) -> Any:
        return ctx.integrate(ctx.metabolic_rate()) * ctx.final_time


def _half_derivative(x: Any) -> Any:
    """x^2 whose CasADi derivative is x dx (half the true one): a wrong exact derivative."""
    return x * cs.stop_diff(x, 1)


@pytest.mark.parametrize("cls, checks", [
    (_ForceTracking, _NUMBERS + ["zero at perfect tracking", "unknown names refused"]),
    (_ActivationTracking, _NUMBERS + ["zero at perfect tracking", "unknown names refused"]),
    (_MetabolicEnergy, _NUMBERS),
])
def test_a_correct_leg_term_passes_every_check_on_the_leg(cls: type, checks: list[str]) -> None:
    report = check_term(cls, zero_at_tracking="zero at perfect tracking" in checks)
    assert (report.passed, report.not_built, report.problem) == (checks, None, "leg")


def _broken(base: type, quantity: Any, bind: Any = None) -> type:
    @attrs.frozen(kw_only=True)
    class Broken(base):
        """A broken probe term of check_term's tests (units of its quantity)."""

        def quantity(self, ctx: Any) -> Any:
            return quantity(self, ctx, base.quantity(self, ctx))

    if bind is not None:
        Broken.bind = bind
    return Broken


@pytest.mark.parametrize("cls, message", [
    (_broken(_ForceTracking, lambda t, ctx, q: q + 1.0), "not zero on the tracked motion"),
    (_broken(_ActivationTracking, lambda t, ctx, q: q + 0.01), "not zero on the tracked motion"),
    (_broken(_ForceTracking, lambda t, ctx, q: _half_derivative(q)), "differs from finite differences"),
    (_broken(_ActivationTracking, lambda t, ctx, q: _half_derivative(q)), "differs from finite differences"),
    (_broken(_MetabolicEnergy, lambda t, ctx, q: _half_derivative(q)), "differs from finite differences"),
    (_broken(_ForceTracking, lambda t, ctx, q: cs.sum1(q)), r"\(K, 1\)|column|shape"),
    (_broken(_ActivationTracking, lambda t, ctx, q: cs.sqrt(-1 - q**2)), "non-finite values"),
    (_broken(_ForceTracking, lambda t, ctx, q: cs.MX(ctx.tracked_ground_reaction_force(t.force))),
     "does not depend on any design variable"),
    (_broken(_MetabolicEnergy, lambda t, ctx, q: ctx.metabolic_rat()), "metabolic_rat"),
    (_broken(_ForceTracking, lambda t, ctx, q: q, bind=lambda self, ctx: ctx.require_muscle(self, "muscle_0")),
     "check_term_no_such_force.*not refused with an InputError"),
])
def test_broken_leg_terms_are_refused(cls: type, message: str) -> None:
    with pytest.raises(TermCheckError, match=message):
        check_term(cls, zero_at_tracking=message.startswith("not zero"))


def test_a_term_neither_problem_serves_gets_both_reasons() -> None:
    report = check_term(_ForceTracking, {"force": "ground_force_1_vy"})
    assert report.problem is None
    assert report.not_built.startswith("pendulum: ") and "; leg: " in report.not_built
    assert report.not_built.count("'ground_force_1_vy'") == 2


def test_the_leg_reproduces_its_tracked_ground_reactions_and_activations() -> None:
    """At the start the leg's contact and synergy-driven muscles give the tracked data, so
    tracking terms are zero there; the foot is loaded and pushed both ways (impulses)."""
    from nmsm.testing.leg_problem import GRF_COLUMNS, build_leg_problem

    built = build_leg_problem([], tool="DO")
    ctx, problem = built.context, built.problem
    force = ctx.foot_ground_reaction("calcn")[0]
    activations = ctx.muscle_activations()
    x0 = problem.initial_scaled()
    modeled = np.asarray(problem.evaluate(force, x0))
    tracked = np.column_stack([np.asarray(ctx.tracked_ground_reaction_force(c)).ravel() for c in GRF_COLUMNS["force"]])
    np.testing.assert_allclose(modeled, tracked, rtol=1e-9, atol=1e-9)
    assert modeled[:, 1].min() > 10.0 and modeled[:, 0].min() < -10.0 < 10.0 < modeled[:, 0].max()
    a = np.asarray(problem.evaluate(activations, problem.initial_scaled()))
    a_exp = np.column_stack([np.asarray(ctx.tracked_muscle_activation(m)).ravel() for m in ctx.muscle_names])
    np.testing.assert_allclose(a, a_exp, rtol=1e-9, atol=1e-12)
    assert 0.05 < a.min() and a.max() < 0.5


@pytest.mark.parametrize("name, kind, tool", [
    ("muscle_activation_deviation", "constraint", "VO"),  # synergy vectors fixed in VO
    ("muscle_activation_tracking", "cost", "TO"),
    ("external_moment_tracking", "cost", "TO"),
    ("synergy_vector_sum", "constraint", "TO"),
])
def test_leg_terms_are_built_for_each_of_their_tools(name: str, kind: str, tool: str) -> None:
    from nmsm.core.registry import get_registry

    report = check_term(get_registry().get(kind, name, tool), tool=tool)
    assert report.problem == "leg" and report.not_built is None and "derivatives" in report.passed


def test_the_legs_synergy_vectors_are_optimized_except_in_verification() -> None:
    from nmsm.testing.leg_problem import build_leg_problem

    assert {tool: "synergy_weights" in build_leg_problem([], tool=tool).problem.variables
            for tool in ("TO", "VO", "DO")} == {"TO": True, "VO": False, "DO": True}


def test_plugins_check_says_where_each_term_was_built(capsys: pytest.CaptureFixture[str]) -> None:
    import warnings

    from nmsm.commands import _check_terms
    from nmsm.core.registry import get_registry

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        items = [it for it in get_registry().items() if it.name in ("external_force_tracking", "generalized_speed_tracking")]
    assert _check_terms(items) == 0
    lines = sorted(line for line in capsys.readouterr().out.splitlines() if line.startswith("ok"))
    assert [line.split(":")[0] for line in lines] == ["ok      cost external_force_tracking",
                                                      "ok      cost generalized_speed_tracking"]
    assert lines[0].endswith("(on leg)") and lines[1].endswith("(on pendulum)")
