"""IPOPT options the treatment tools add per tool: Design Optimization's adaptive barrier,
Verification Optimization's warm start; a user's ``ipopt_options`` win."""

from __future__ import annotations

from types import SimpleNamespace

from nmsm.tools.treatment.run import (DESIGN_OPTIONS, FEASIBLE_START, FEASIBLE_START_OPTIONS, WARM_START_OPTIONS,
                                      _ipopt_kwargs)
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


def test_a_verification_from_a_feasible_start_can_stop_where_it_starts() -> None:
    """Bound multipliers mu/slack and a smaller mu only when the start satisfies every
    constraint; from an infeasible one the plain warm start."""
    vo = _prepared("VO", {"states": object()})
    feasible = _ipopt_kwargs(vo, TreatmentOptions(), None, start_violation=FEASIBLE_START / 10)["ipopt_options"]
    assert feasible["bound_mult_init_method"] == "mu-based" and feasible["mu_init"] == FEASIBLE_START_OPTIONS["mu_init"]
    assert feasible["bound_push"] == WARM_START_OPTIONS["bound_push"]
    infeasible = _ipopt_kwargs(vo, TreatmentOptions(), None, start_violation=0.3)["ipopt_options"]
    assert "bound_mult_init_method" not in infeasible and infeasible["mu_init"] == WARM_START_OPTIONS["mu_init"]
    tracking = _ipopt_kwargs(_prepared("TO", {"states": object()}), TreatmentOptions(), None,
                             start_violation=0.0)["ipopt_options"]
    assert "bound_mult_init_method" not in tracking and "mu_init" not in tracking


def _solver_file(folder, hessian: str | None):
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.solver import OptimalControlSolverSettings

    element = f"<hessian_approximation>{hessian}</hessian_approximation>" if hessian is not None else ""
    path = folder / "solver.xml"
    path.write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<NMSMPipelineDocument Version="1.5.3"><OptimalControlSolverSettings><GpopsSettings>
<setup_mesh_method>none</setup_mesh_method><setup_nlp_linear_solver>mumps</setup_nlp_linear_solver>
{element}</GpopsSettings></OptimalControlSolverSettings></NMSMPipelineDocument>""", encoding="utf-8")
    return path, OptimalControlSolverSettings.from_document(read_settings_document(path))


def test_the_solver_file_chooses_the_hessian(tmp_path) -> None:
    from nmsm.tools.treatment.solver_options import plan_from_settings

    for hessian, expected in ((None, "exact"), ("exact", "exact"), ("limited-memory", "limited-memory")):
        _, settings = _solver_file(tmp_path, hessian)
        plan = plan_from_settings(settings.gpops)
        assert plan.ipopt["hessian"] == expected
        prepared = SimpleNamespace(tool="TO", plan=plan, files=SimpleNamespace(results={}))
        assert _ipopt_kwargs(prepared, TreatmentOptions(), None)["hessian"] == expected
        assert _ipopt_kwargs(prepared, TreatmentOptions(hessian="exact"), None)["hessian"] == "exact"


def test_an_unknown_hessian_is_refused_at_its_element(tmp_path) -> None:
    import pytest

    from nmsm.errors import InputError

    with pytest.raises(InputError, match="hessian_approximation") as error:
        _solver_file(tmp_path, "bfgs")
    assert "limited-memory" in str(error.value)
