"""IPOPT options the treatment tools add per tool: Design Optimization's adaptive barrier,
Verification Optimization's warm start; a user's ``ipopt_options`` win."""

from __future__ import annotations

from types import SimpleNamespace

from nmsm.tools.treatment.run import DESIGN_OPTIONS, WARM_START_OPTIONS, _ipopt_kwargs
from nmsm.tools.treatment.tool import TreatmentOptions

PLAN = {"max_iter": 500, "tol": 1e-4, "linear_solver": "mumps", "print_level": 0}


def _prepared(tool: str, results: dict | None = None) -> SimpleNamespace:
    return SimpleNamespace(tool=tool, plan=SimpleNamespace(ipopt=PLAN),
                           files=SimpleNamespace(results=results or {}))


def test_design_optimization_uses_the_adaptive_barrier() -> None:
    options = _ipopt_kwargs(_prepared("DO"), TreatmentOptions(), None)["ipopt_options"]
    assert options["mu_strategy"] == "adaptive" == DESIGN_OPTIONS["mu_strategy"]
    for tool in ("TO", "VO"):
        assert "mu_strategy" not in _ipopt_kwargs(_prepared(tool), TreatmentOptions(), None)["ipopt_options"]


def test_user_ipopt_options_override_the_tool_defaults() -> None:
    mine = TreatmentOptions(ipopt_options={"mu_strategy": "monotone", "mu_init": 1e-3})
    assert _ipopt_kwargs(_prepared("DO"), mine, None)["ipopt_options"]["mu_strategy"] == "monotone"
    warm = _ipopt_kwargs(_prepared("VO", {"states": object()}), mine, None)["ipopt_options"]
    assert warm["mu_init"] == 1e-3 and warm["bound_push"] == WARM_START_OPTIONS["bound_push"]
