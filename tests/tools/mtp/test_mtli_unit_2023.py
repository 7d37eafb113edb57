"""The original's 2023 Muscle-Tendon Length Initialization unit test, reproduced.

``mtp/mtl_initialization_unit_2023``: 4 gait trials, 12 passive trials, 34 muscles;
design vector ``parameterChange`` = 34 l_o scales, 34 l_ts scales, 11 group + 2 muscle
max-length variables, 1 stress scale. Every modeled array and cost term matches.
"""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

from nmsm.core.registry import get_registry
from nmsm.tools.mtp.mtli_model import MtliContext, PassiveTrial, max_length_variable_index, mtli_quantities
from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters

P = "experimentalData."
#: expected-array name -> (term type, the 2023 defaults e, c)
TERMS = {
    "passiveMomentMatching": ("passive_joint_moment", 2.0, 0.0),
    "optimalFiberLengthPenalty": ("optimal_muscle_fiber_length", 0.3, 1.0),
    "tendonSlackLengthPenalty": ("tendon_slack_length", 1.0, 1.0),
    "minNormalizedFiberLength": ("minimum_normalized_muscle_fiber_length", 0.3, 0.0),
    "maxNormalizedFiberLength": ("maximum_normalized_muscle_fiber_length", 0.03, 0.0),
    "lMtildaMaxSetPointPenalty": ("grouped_maximum_normalized_muscle_fiber_length", 0.1, 0.0),
    "normalizedFiberLengthPairSimilarity": ("grouped_normalized_muscle_fiber_length", 0.1, 0.0),
    "maximumMuscleStressPenalty": ("maximum_muscle_stress", 0.1, 1.2),
    "minimizePassiveForce": ("passive_muscle_force", 10.0, 0.0),
}


def _numeric(*expressions):
    return [np.array(v.full()) for v in cs.Function("f", [], list(expressions)).call([])]


@pytest.fixture(scope="module")
def unit(shared_data):
    folder = shared_data / "mtp" / "mtl_initialization_unit_2023" / "npz"
    d = dict(np.load(folder / "muscleTendonLengthInitializationCostFunctionTesting.npz"))
    n = int(d[P + "numMuscles"])
    muscles = MuscleParameters([f"m{i}" for i in range(n)], d[P + "maxIsometricForce"], d[P + "optimalFiberLength"],
                               d[P + "tendonSlackLength"], d[P + "pennationAngle"])
    groups, i = [], 0
    while f"{P}normalizedFiberLengthGroups{{{i}}}" in d:
        groups.append(MuscleGroup(str(i), tuple(int(v) - 1 for v in d[f"{P}normalizedFiberLengthGroups{{{i}}}"])))
        i += 1
    gait = [d[P + "gaitData.muscleTendonLength"][t].T for t in range(d[P + "gaitData.muscleTendonLength"].shape[0])]
    passive = tuple(
        PassiveTrial(f"p{t}", np.arange(101.0), d[P + "passiveData.muscleTendonLength"][t].T,
                     np.transpose(d[P + "passiveData.momentArms"][t], (2, 0, 1)), d[P + "passiveData.experimentalMoments"][t].T)
        for t in range(d[P + "passiveData.muscleTendonLength"].shape[0])
    )
    x = d["parameterChange"]
    so, sts, lmax, stress = x[:n], x[n : 2 * n], x[2 * n : -1], x[-1]
    f0, fiber, force, moments = mtli_quantities(
        muscles, gait, passive, optimal_fiber_length=cs.DM(so), tendon_slack_length=cs.DM(sts), stress_scale=stress,
        absolute_lengths=False, update_max_isometric_force=True, maximum_muscle_stress=float(d[P + "maximumMuscleStress"]),
    )
    index = max_length_variable_index(n, groups)
    assert np.array_equal(index + 1, d[P + "groupedMaxNormalizedFiberLength"])
    ctx = MtliContext(muscles, False, cs.DM(so), cs.DM(sts), cs.DM(lmax), stress, index, fiber, force, moments, passive,
                      tuple(groups), float(d[P + "minNormalizedMuscleFiberLength"]), float(d[P + "maxNormalizedMuscleFiberLength"]))
    expected = {name: dict(np.load(folder / f"{name}.npz")) for name in (
        "expectedNormalizedFiberLength", "expectedPassiveForce", "expectedPassiveModelMoments", "expectedIndividualCosts",
        "expectedCost")}
    return ctx, expected


@pytest.mark.parametrize("attribute, name, key", [
    ("fiber_length", "expectedNormalizedFiberLength", "normalizedFiberLength"),
    ("passive_force", "expectedPassiveForce", "passiveForce"),
    ("passive_moments", "expectedPassiveModelMoments", "passiveModelMoments"),
])
def test_modeled_values(unit, attribute, name, key):
    ctx, expected = unit
    ours = _numeric(*getattr(ctx, attribute))
    stored = expected[name][key]
    scale = np.abs(stored).max()
    error = max(np.abs(o - stored[:, t, :]).max() for t, o in enumerate(ours))
    assert error <= 1e-12 * max(scale, 1.0)


def test_cost_terms_and_total(unit):
    ctx, expected = unit
    registry = get_registry()
    total = 0.0
    for key, (term_type, e, c) in TERMS.items():
        term = registry.get("cost", term_type, "MTLI")(max_allowable_error=e, error_center=c)
        term.bind(ctx)
        ours = _numeric(term.residuals(ctx))[0].ravel()
        stored = expected["expectedIndividualCosts"]["cost." + key].ravel()
        assert ours.size == stored.size, key
        assert np.sum(ours**2) == pytest.approx(np.sum(stored**2), rel=1e-12, abs=1e-20), key
        total += float(np.sum(ours**2))
    stored_vector = expected["expectedCost"]["expectedCost"]
    assert total == pytest.approx(float(np.sum(stored_vector**2)), rel=1e-12)
