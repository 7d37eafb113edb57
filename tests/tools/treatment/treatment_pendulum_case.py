"""A synthetic treatment problem on a pendulum (shared by the tests of this folder): the one of
:mod:`nmsm.testing.pendulum_problem`, starting at 0.9 x the tracked states by default."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from nmsm.testing.pendulum_problem import DURATION, build_pendulum_problem, reference_data  # noqa: F401
from nmsm.tools.treatment.formulation import TreatmentProblem


def build_case(terms: Sequence[Any], *, guess_scale: float = 0.9, **options: Any) -> TreatmentProblem:
    return build_pendulum_problem(terms, guess_scale=guess_scale, **options)
