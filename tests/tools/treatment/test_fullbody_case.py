"""The full-body gait stress case (issue 24) from its settings files, coarse mesh: the TO
problem builds at the expected size and its derivatives agree with finite differences.

The case is prepared quickly (``write_case(..., quick=True)``: the GCP tutorial's right foot
and its mirror image instead of two GCP runs, 3 surrogate poses per frame); the settings
files are the ones ``python -m nmsm.examples.fullbody write`` writes. Solving it is in the
slow suite (``test_fullbody_coarse_solve.py``), the ``scale`` marker (``test_fullbody_solve.py``,
full mesh) and ``benchmarks/bench_fullbody.py``.
"""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.examples import fullbody_data as fd


@pytest.fixture(scope="module")
def quick_stress(shared_data, tmp_path_factory):
    from nmsm.examples.fullbody import write_case

    return write_case(tmp_path_factory.mktemp("fullbody_quick"), "stress", "coarse", shared_data, quick=True)


@pytest.fixture(scope="module")
def built(quick_stress):
    from nmsm.tools.treatment.run import run_settings

    return run_settings(quick_stress["to"], evaluate_only=True, write_results=False)


def test_stress_problem_size(built):
    problem = built.prepared.built.problem
    points = 5 * 4  # coarse: 5 intervals x 4 collocation points
    states, synergies, torques = 31, 10, 11
    weights = 2 * 43 * 5  # each leg's 43 muscles x 5 synergies, optimized
    activations = 2 * 43 * points  # lifted: the activations C W on the collocation points
    assert problem.n_variables == (2 * states * (points + 1) + (states + synergies + torques) * points + weights
                                   + activations)
    blocks = {c.name.split(":")[0]: 0 for c in built.solution.constraints}
    for c in built.solution.constraints:
        blocks[c.name.split(":")[0]] += c.size
    assert blocks == {"dynamics_defects": 2 * states * points, "synergy_vector_normalization": synergies,
                      "kinetic_consistency": 25 * points, "root_segment_residual_load": 6 * points,
                      "lifted": activations}
    names = set(built.solution.term_costs)
    assert {f"muscle_activation_tracking:{m}" for m in ("soleus_r", "soleus_l", "glmax1_l")} <= names
    assert {f"external_force_tracking:ground_force_{p}_vy" for p in (1, 2)} <= names
    assert np.isfinite(built.solution.cost) and built.solution.cost > 0


def test_stress_derivatives_match_finite_differences(built):
    """Directional derivatives (CasADi AD, as IPOPT gets them) of the objective and every
    constraint at the start point equal central differences."""
    problem = built.prepared.built.problem
    x = problem.scaled_vector()
    g, _, _ = problem.constraint_vector()
    f = problem.objective()
    d = cs.MX.sym("d", x.shape[0])
    p = problem.parameter_vector()
    values = cs.Function("values", [x, p], [f, g])
    directional = cs.Function("directional", [x, p, d], [cs.jtimes(f, x, d), cs.jtimes(g, x, d)])
    x0 = problem.initial_scaled()
    p0 = problem.parameter_values()
    rng = np.random.default_rng(0)
    direction = rng.standard_normal(x0.size)
    direction /= np.linalg.norm(direction)
    df, dg = (np.asarray(v, float).ravel() for v in directional(x0, p0, direction))
    h = 1e-6
    f_plus, g_plus = (np.asarray(v, float).ravel() for v in values(x0 + h * direction, p0))
    f_minus, g_minus = (np.asarray(v, float).ravel() for v in values(x0 - h * direction, p0))
    assert np.all(np.isfinite(dg)) and np.isfinite(df[0])
    np.testing.assert_allclose(df, (f_plus - f_minus) / (2 * h), rtol=1e-5, atol=1e-8)
    np.testing.assert_allclose(dg, (g_plus - g_minus) / (2 * h), rtol=1e-4, atol=1e-6 * max(1.0, np.abs(dg).max()))


def test_stress_settings_name_the_case_inputs(quick_stress):
    text = quick_stress["to"].read_text(encoding="utf-8")
    assert "<surrogate_model_data_directory>../prepared/surrogate_stress_quick<" in text
    assert text.count("_moment") > 25 and " ".join(fd.state_coordinates()) in text
