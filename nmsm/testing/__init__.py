"""Conformance checks a term author runs on their own class: :func:`check_term`.

In the manner of scikit-learn's ``check_estimator``::

    from nmsm.testing import check_term
    from my_plugin.terms import CoordinateLimitPenalty

    def test_conforms():
        report = check_term(CoordinateLimitPenalty, {"coordinate": "q0", "upper_limit": "0.2"})
        assert report.not_built is None and not report.warnings

:func:`check_term` raises :class:`TermCheckError` saying what is wrong, and returns a
:class:`TermCheckReport` of what it checked. ``nmsm plugins --check`` runs it on every
registered term and constraint.

Checks, for every term (the names in ``report.passed``):

``declaration``            the class is usable from settings XML (decorated, ``type``, ``tools``,
                           field types), has a docstring, and a Treatment Optimization term
                           declares its ``evaluation`` (it subclasses a base of :mod:`nmsm.core.ocp`);
``settings``               the example settings elements build at least one term (``from_spec``);
``bad elements refused``   an :class:`~nmsm.errors.InputError` naming the element for an unknown
                           element (unless the term has an ``options`` field, which keeps them),
                           ``max_allowable_error`` 0 (costs), ``min_error`` above ``max_error``
                           (constraints).

Then, on a small synthetic problem of the tool (built in code, no files of the user's):

``shape``                  the term builds on the tool's problem through the tool's own context
                           and reduction (a treatment quantity has the shape its evaluation needs;
                           a GCP quantity has one block per foot), has at least one residual, and
                           depends on the design variables;
``built, finite``          its residuals are finite near the starting point;
``derivatives``            their exact (CasADi) derivative along a random direction matches
                           central finite differences;
``zero at perfect tracking``  a tracking term is zero where the synthetic data are reproduced
                           exactly (built-in tracking terms; ``zero_at_tracking=True`` for yours);
``unknown names refused``  a name element (``<coordinate>``, ``<marker>``, ...) naming what the
                           problem has not is refused with an InputError quoting the name.

The synthetic problems: Treatment Optimization (TO, VO, DO): a term is built on the first of
these whose context its ``bind`` accepts (``report.problem`` names it):

* ``pendulum``: a two-link pendulum with a coupled coordinate; coordinates ``q0``, ``q1``,
  ``follower``, markers ``tip_0``, ``tip_1``, ``follower_marker``, bodies ``link_0``,
  ``link_1``, torque controls ``q0_moment``, ``q1_moment``; states at the tracked motion
  (:mod:`nmsm.testing.pendulum_problem`);
* ``leg``: a planar leg on the pendulum's names (hip ``q0``, knee ``q1``, bodies ``link_0``,
  ``link_1``, markers ``tip_0``, ``tip_1``, torque control ``q0_moment``) with an ankle
  ``q2``, toes ``q3``, a two-segment foot (hindfoot ``calcn``, ``toes``) on an
  elastic-foundation contact surface (ground-reaction columns ``ground_force_v[xyz]``,
  ``ground_torque_[xyz]``), muscles ``muscle_0``..``muscle_2`` driven by the synergies
  ``group_1``, ``group_2`` of synergy group ``group`` (vectors optimized except in VO,
  surrogate fitted to the leg's own path geometry); its tracked ground reactions and muscle
  activations are the model's at the start (:mod:`nmsm.testing.leg_problem`).

MTP, SynX, MTLI, NCP, GCP, JMP: :mod:`nmsm.testing.synthetic_problems` (muscles, synergy groups,
a foot, a leg). A term refused by every problem of its tool is reported as not built
(``report.not_built`` gives each problem's reason); its declaration and settings checks still
run. A treatment term that differentiates a quantity depending on the controls gets a
:class:`~nmsm.core.ocp.DiscontinuousDerivativeWarning`, recorded in ``report.warnings``.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from typing import Any

import attrs
import numpy as np

from nmsm.core.ocp import TREATMENT_TOOLS, DiscontinuousDerivativeWarning
from nmsm.core.term import (
    LIST_TO_SINGULAR,
    ConstraintTerm,
    CostTerm,
    SourceRef,
    Term,
    TermSpec,
    term_class_problems,
)
from nmsm.errors import InputError, NmsmError
from nmsm.testing.synthetic_problems import BUILDERS, ZERO_AT_TRACKED, SyntheticProblem

#: Values of fields on the synthetic pendulum (and the leg, which has these names too), used
#: when the example does not give them.
PENDULUM_VALUES: dict[str, str] = {
    "coordinate": "q0",
    "load": "q0_moment",
    "marker": "tip_1",
    "body": "link_1",
    "axis": "x",  # markers (orientations and angular momentum: "z")
    "controller": "q0_moment",
}

#: Names of the synthetic leg the pendulum has not (muscles, contact, synergies), and a user
#: function no problem has, used for required fields the example does not give.
PLACEHOLDER_VALUES: dict[str, str] = {
    "muscle": "muscle_0",
    "hindfoot_body": "calcn",
    "force": "ground_force_vx",
    "moment": "ground_torque_z",
    "synergy": "group_1",
    "synergies": "group_1 group_2",
    "function_name": "check_term_no_such_function",
}

#: Families whose ``*_tracking`` treatment cost is zero on the tracked motion.
_ZERO_AT_TRACKING = ("generalized_coordinate", "generalized_speed", "marker_position", "marker_velocity",
                     "body_orientation", "external_force", "external_moment", "center_of_pressure",
                     "center_of_presssure", "muscle_activation")

#: Fields naming a part of the model or data; :func:`check_term` sets each to a name the
#: synthetic problem has not and expects an InputError quoting it.
NAME_FIELDS = ("coordinate", "load", "marker", "body", "controller", "muscle", "hindfoot_body", "synergy", "force",
               "moment")


class TermCheckError(AssertionError):
    """A term class fails a conformance check (the message names the class and the check)."""


@attrs.define
class TermCheckReport:
    """What :func:`check_term` checked: ``passed`` (names of checks), ``not_built`` (why the
    term was not built on the synthetic problem, or None), ``warnings`` (messages of
    :class:`~nmsm.core.ocp.DiscontinuousDerivativeWarning` while building) and ``problem``
    (the synthetic problem it was built on: the tool's code, or for TO, VO and DO
    ``"pendulum"`` or ``"leg"``)."""

    cls: type
    passed: list[str] = attrs.field(factory=list)
    not_built: str | None = None
    warnings: list[str] = attrs.field(factory=list)
    problem: str | None = None


def check_term(cls: type, example: Mapping[str, str] | None = None, *, tool: str | None = None,
               zero_at_tracking: bool | None = None) -> TermCheckReport:
    """Run the conformance checks of the module docstring on term class ``cls``.

    ``example``: settings elements -> text for the term's fields (what its ``<RCNLCostTerm>``
    would hold, without ``type`` and ``is_enabled``; default: the class's ``check_example``);
    fields missing from it take :data:`PENDULUM_VALUES` (and required ones
    :data:`PLACEHOLDER_VALUES`). A required field still without a value stops the checks
    after the declaration (``report.not_built`` says which). ``tool``: the tool to check for
    (default: a treatment tool the class accepts, else its first tool with a synthetic
    problem). ``zero_at_tracking``: demand (True) or skip (False) the tracking check; None:
    for the built-in tracking terms.
    """
    report = TermCheckReport(cls)
    name = f"{getattr(cls, '__module__', '?')}.{getattr(cls, '__qualname__', cls)}"
    if not (isinstance(cls, type) and issubclass(cls, (CostTerm, ConstraintTerm))):
        raise TermCheckError(f"{name} is not a subclass of nmsm.core.term.CostTerm or ConstraintTerm")
    _check_declaration(cls, name, report)
    if tool is not None and tool not in cls.tools:
        raise TermCheckError(f"{name}: check_term(tool='{tool}'), but the class accepts {sorted(cls.tools)}")
    tool = tool or (sorted(cls.tools & TREATMENT_TOOLS) or sorted(cls.tools & set(BUILDERS))
                    or sorted(cls.tools))[0]
    elements = _example_elements(cls, example)
    missing = cls._missing_required({cls.aliases.get(e, e) for e in elements}
                                    | {s for p, s in LIST_TO_SINGULAR.items() if p in elements})
    if missing:
        report.not_built = (f"no example value for required {', '.join(f'<{m}>' for m in missing)}: set "
                            f"check_example on the class or pass check_term(cls, example={{...}})")
        return report
    terms = _check_settings(cls, name, elements, report)
    if tool not in TREATMENT_TOOLS and tool not in BUILDERS:
        report.not_built = f"no synthetic problem for {tool} (declaration and settings checked)"
        return report
    built = _build(name, terms[0], tool, report)
    if built is None:
        return report
    if zero_at_tracking is None:
        family = cls.type[: -len("_tracking")] if cls.type.endswith("_tracking") else None
        zero_at_tracking = (family in _ZERO_AT_TRACKING if tool in TREATMENT_TOOLS
                            else (tool, cls.type) in ZERO_AT_TRACKED)
    _check_numbers(name, cls, terms[0], tool, built, zero_at_tracking, report)
    _check_bad_names(name, cls, tool, elements, report)
    return report


def _check_declaration(cls: type, name: str, report: TermCheckReport) -> None:
    problems = term_class_problems(cls)
    if problems:
        raise TermCheckError(f"{name} " + "; ".join(problems))
    if not cls.type:
        raise TermCheckError(f"{name} sets no 'type' (its settings name)")
    if not cls.tools:
        raise TermCheckError(f"{name} accepts no tool (set tools: ClassVar[frozenset[str]])")
    if not (cls.__doc__ or "").strip():
        raise TermCheckError(f"{name} has no docstring (say what the quantity is, with its unit)")
    if cls.tools & TREATMENT_TOOLS and getattr(cls, "evaluation", None) is None:
        raise TermCheckError(f"{name} accepts {sorted(cls.tools & TREATMENT_TOOLS)} but declares no 'evaluation': "
                             "subclass ContinuousCost, DiscreteCost, PathConstraint or TerminalConstraint "
                             "from nmsm.core.ocp")
    report.passed.append("declaration")


def _example_elements(cls: type, example: Mapping[str, str] | None) -> dict[str, str]:
    elements = dict(cls.check_example if example is None else example)
    given = {cls.aliases.get(e, e) for e in elements}
    given |= {single for plural, single in LIST_TO_SINGULAR.items() if plural in given}
    fields = cls.xml_fields()
    for field, text in PENDULUM_VALUES.items():
        if field in fields and field not in given:
            elements[field] = text
    if "axis" in fields and "axis" not in given and "marker" not in fields:
        elements["axis"] = "z"  # the pendulum turns about z: orientations and angular momentum vary there only
    for field in cls._missing_required(given | set(elements)):
        if field in PLACEHOLDER_VALUES:
            elements[field] = PLACEHOLDER_VALUES[field]
    return elements


def _spec(cls: type, elements: Mapping[str, str]) -> TermSpec:
    fields = {"type": cls.type, "is_enabled": "true", **elements}
    return TermSpec(cls.kind, cls.type, fields, SourceRef("check_term.xml", 1))


def _check_settings(cls: type, name: str, elements: dict[str, str], report: TermCheckReport) -> list[Term]:
    try:
        terms = cls.from_spec(_spec(cls, elements))
    except InputError as exc:
        raise TermCheckError(f"{name}: the example elements {elements} do not build a term ({exc}); "
                             "pass check_term(cls, example={...}) with valid element texts") from exc
    if not terms:
        raise TermCheckError(f"{name}: from_spec built no term from {elements}")
    report.passed.append("settings")
    if cls.kind == "cost":
        bad_values = {"max_allowable_error": "0"}
    else:
        bad_values = {"min_error": "2", "max_error": "1"}
    wrongs = [bad_values]
    if "options" not in cls.xml_fields():  # a term with ``options`` keeps unknown elements as its options
        wrongs.insert(0, {"element_that_is_not_a_field": "1"})
    for wrong in wrongs:
        try:
            cls.from_spec(_spec(cls, {**elements, **wrong}))
        except InputError as exc:
            if not any(element in str(exc) for element in wrong):
                raise TermCheckError(f"{name}: the settings elements {wrong} were refused, but the message names "
                                     f"none of them: {exc}") from exc
            continue
        raise TermCheckError(f"{name}: the settings elements {wrong} were accepted "
                             "(expected an InputError naming them)")
    report.passed.append("bad elements refused")
    return terms


def _pendulum_problem(tool: str) -> SyntheticProblem:
    """The pendulum problem; tracked point: the states on the tracked motion."""
    from nmsm.testing.pendulum_problem import build_pendulum_problem

    return _treatment_problem(build_pendulum_problem([], tool=tool))


def _leg_problem(tool: str) -> SyntheticProblem:
    """The leg problem (muscles, synergies, foot contact); tracked point: its start."""
    from nmsm.testing.leg_problem import build_leg_problem

    return _treatment_problem(build_leg_problem([], tool=tool))


def _treatment_problem(built: Any) -> SyntheticProblem:
    """Its tracked point is set once the term is added (:func:`_start`): terms may add variables."""
    return SyntheticProblem(built.problem, built.context, None)


def _start(built: SyntheticProblem) -> np.ndarray:
    """The treatment problem's starting point within its bounds (the tracked motion)."""
    lower, upper = built.problem.bounds_scaled()
    return np.clip(built.problem.initial_scaled(), lower, upper)


#: the synthetic treatment problems, tried in this order: a term is built on the first whose
#: context its ``bind`` accepts
TREATMENT_PROBLEMS: tuple[tuple[str, Any], ...] = (("pendulum", _pendulum_problem), ("leg", _leg_problem))


def _build(name: str, term: Term, tool: str, report: TermCheckReport) -> SyntheticProblem | None:
    """The tool's synthetic problem with the term added; None (``report.not_built`` says why)
    when binding the term raised an InputError on every synthetic problem of the tool (it needs
    what they have not). ``report.problem`` names the problem it was built on."""
    candidates = TREATMENT_PROBLEMS if tool in TREATMENT_TOOLS else ((tool, BUILDERS[tool]),)
    refusals = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DiscontinuousDerivativeWarning)
        for label, builder in candidates:
            built = builder(tool)
            try:
                term.bind(built.context)
            except InputError as exc:  # the term needs what this synthetic problem has not (bind said so)
                refusals.append(f"{label}: {exc}" if len(candidates) > 1 else str(exc))
                continue
            except NmsmError as exc:
                raise TermCheckError(f"{name}: bind failed on the synthetic {tool} problem ({label}): {exc}") from exc
            break
        else:
            report.not_built = "; ".join(refusals)
            return None
        report.problem = label
        try:
            form = built.form_problem(term) if built.form_problem is not None else None
            if form is None:
                built.add_term(term)
        except NmsmError as exc:  # bound, but its quantity does not build (shape, a missing quantity, ...)
            raise TermCheckError(f"{name}: building on the synthetic {tool} problem ({label}) failed: {exc}") from exc
        except Exception as exc:  # the tool's reduction refused the quantity's form
            raise TermCheckError(f"{name}: building on the synthetic {tool} problem ({label}) failed: "
                                 f"{type(exc).__name__}: {exc}") from exc
    if form is not None:
        raise TermCheckError(f"{name}: on the synthetic {tool} problem the {form}")
    if tool in TREATMENT_TOOLS:
        built.tracked = _start(built)
    for warning in caught:
        if issubclass(warning.category, DiscontinuousDerivativeWarning):
            report.warnings.append(str(warning.message))
        else:
            warnings.warn_explicit(warning.message, warning.category, warning.filename, warning.lineno)
    return built


def _expression(name: str, cls: type, term: Term, built: SyntheticProblem) -> Any:
    import casadi as cs

    problem = built.problem
    entries = [e for e in (problem.costs if cls.kind == "cost" else problem.constraints) if e.term is term]
    if not entries:
        raise TermCheckError(f"{name}: the built problem has no entry of the term")
    return cs.vertcat(*[e.residuals if cls.kind == "cost" else e.expression for e in entries])


def _check_numbers(name: str, cls: type, term: Term, tool: str, built: SyntheticProblem,
                   zero_at_tracking: bool, report: TermCheckReport) -> None:
    """Shape, finite values, dependence on the variables, exact vs finite-difference
    derivatives, zero on the tracked point (module docstring)."""
    import casadi as cs

    problem = built.problem
    expression = _expression(name, cls, term, built)
    if expression.numel() == 0:
        raise TermCheckError(f"{name}: no residual on the synthetic {tool} problem (an empty quantity)")
    x = problem.scaled_vector()
    p = problem.parameter_vector()
    if not cs.depends_on(expression, x):
        raise TermCheckError(f"{name}: its value does not depend on any design variable of the synthetic {tool} "
                             "problem (a constant cannot be optimized: does it read data instead of the model?)")
    report.passed.append("shape")
    lower, upper = problem.bounds_scaled()
    start = np.clip(problem.initial_scaled() if built.tracked is None else built.tracked, lower, upper)
    rng = np.random.default_rng(0)
    x0 = np.clip(start + 0.05 * rng.standard_normal(start.size), lower, upper)
    values = problem.parameter_values()
    f = cs.Function("f", [x, p], [expression])
    jac = cs.Function("j", [x, p], [cs.jacobian(expression, x)])
    value = np.asarray(f(x0, values)).ravel()
    if not np.all(np.isfinite(value)):
        raise TermCheckError(f"{name}: non-finite values on the synthetic {tool} problem")
    report.passed.append("built, finite")
    direction = rng.standard_normal(x0.size)
    direction /= np.linalg.norm(direction)
    h = 1e-6
    forward = np.asarray(f(x0 + h * direction, values)).ravel()
    backward = np.asarray(f(x0 - h * direction, values)).ravel()
    fd = (forward - backward) / (2 * h)
    ad = np.asarray(jac(x0, values)) @ direction
    scale = max(1.0, float(np.max(np.abs(ad), initial=0.0)))
    if not np.allclose(ad, fd, rtol=1e-4, atol=1e-5 * scale):
        worst = int(np.argmax(np.abs(ad - fd)))
        raise TermCheckError(f"{name}: exact derivative {ad[worst]:.6g} differs from finite differences "
                             f"{fd[worst]:.6g} (row {worst})")
    report.passed.append("derivatives")
    if zero_at_tracking:
        if built.tracked is None:
            raise TermCheckError(f"{name}: zero_at_tracking asked, but the synthetic {tool} problem has no point "
                                 "where its data are tracked exactly")
        at_tracked = np.asarray(f(built.tracked, values)).ravel()
        if np.max(np.abs(at_tracked), initial=0.0) > 1e-6:
            raise TermCheckError(f"{name}: not zero on the tracked motion (max |residual| "
                                 f"{np.max(np.abs(at_tracked)):.3g})")
        report.passed.append("zero at perfect tracking")


def _check_bad_names(name: str, cls: type, tool: str, elements: dict[str, str], report: TermCheckReport) -> None:
    """Each name element the term has (``<coordinate>``, ``<marker>``, ...) set to a name the
    synthetic problem lacks: building must raise an InputError quoting the name."""
    fields = cls.xml_fields()
    checked = False
    for field in NAME_FIELDS:
        if field not in fields or fields[field] is not str:
            continue
        wrong = f"check_term_no_such_{field}"
        term = cls.from_spec(_spec(cls, {**{k: v for k, v in elements.items()
                                            if cls.aliases.get(k, k) != field
                                            and LIST_TO_SINGULAR.get(k) != field}, field: wrong}))[0]
        outcome = TermCheckReport(cls)
        try:
            built = _build(name, term, tool, outcome)
        except TermCheckError as exc:
            raise TermCheckError(f"{name}: <{field}> '{wrong}' (a name the synthetic problem has not) was not refused "
                                 f"with an InputError (call ctx.require_... in bind): {exc}") from exc
        if built is not None:
            raise TermCheckError(f"{name}: <{field}> '{wrong}' (a name the synthetic problem has not) was accepted "
                                 "(expected an InputError naming it, raised from bind with ctx.require_...)")
        if wrong not in (outcome.not_built or ""):
            raise TermCheckError(f"{name}: <{field}> '{wrong}' was refused, but the message does not name it: "
                                 f"{outcome.not_built}")
        checked = True
    if checked:
        report.passed.append("unknown names refused")


__all__ = ["NAME_FIELDS", "PENDULUM_VALUES", "PLACEHOLDER_VALUES", "TermCheckError", "TermCheckReport", "check_term"]
