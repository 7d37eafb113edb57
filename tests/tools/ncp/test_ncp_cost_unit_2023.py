"""The early-2023 NCP unit test (``ncp/cost_function_unit_2023``): same inputs, same activations, same cost.

The 2023 design vector (1392 values) holds the 12 synergy vectors of two 74-muscle groups
(contiguous in the MAData column order, as the 2023 code laid them out) and 2 trials x 12
synergies x 21 command nodes. Activations must match the saved ones to round-off; the cost
of the six 2023 terms (five enabled) is compared with the saved MATLAB cost, with the
moments computed through the original's early-2023 force-length and force-velocity curves
(:data:`nmsm.model.hill.CURVES_2023`; with the pipeline's current curves the cost is
29.95739 instead of 29.95991).
"""

from __future__ import annotations

import numpy as np
import pytest

from nmsm.core.term import TermSpec
from nmsm.core.registry import build_terms
from nmsm.io.storage import read_storage
from nmsm.model import hill
from nmsm.tools.mtp.muscles import MuscleGroup, MuscleParameters
from nmsm.tools.ncp.inputs import NcpInputs, NcpTrial
from nmsm.tools.ncp.problem import score
from nmsm.tools.ncp.solution import SynergySolution
from nmsm.tools.ncp.spline import commands_from_nodes
from nmsm.tools.ncp.synergies import SynergyGroup, SynergyLayout

#: |ours - MATLAB| / MATLAB for the saved cost: measured 2.4e-16 with the 2023 curves
COST_RELATIVE_TOLERANCE = 1e-12


@pytest.fixture(scope="module")
def unit(shared_data):
    folder = shared_data / "ncp" / "cost_function_unit_2023" / "npz"
    inputs = dict(np.load(folder / "inputs.npz"))
    params = dict(np.load(folder / "params.npz"))
    values = np.load(folder / "optimizedValues.npz")["optimizedValues"]
    names = read_storage(
        shared_data / "ncp" / "patient3_bilateral_trials1to3" / "preprocessed" / "MAData" / "trial_1" / "trial_1_Length.sto"
    ).labels
    assert np.allclose(
        read_storage(shared_data / "ncp" / "patient3_bilateral_trials1to3" / "preprocessed" / "MAData" / "trial_1"
                     / "trial_1_Length.sto").data.T,
        inputs["inputs.muscleTendonLength"][0],
    )  # the 2023 arrays are in MAData column order
    layout = SynergyLayout([SynergyGroup("right_side", names[:74], 6), SynergyGroup("left_side", names[74:], 6)])
    muscles = MuscleParameters(names, inputs["inputs.maxIsometricForce"], inputs["inputs.optimalFiberLength"],
                               inputs["inputs.tendonSlackLength"], inputs["inputs.pennationAngle"])
    trials = [
        NcpTrial(
            name=f"trial_{t + 1}",
            time=inputs["inputs.time"][t],
            lengths=inputs["inputs.muscleTendonLength"][t].T,
            velocities=inputs["inputs.muscleTendonVelocity"][t].T,
            moment_arms=inputs["inputs.momentArms"][t].transpose(2, 0, 1),
            moments=inputs["inputs.inverseDynamicsMoments"][t].T,
            mtp_activations=inputs["inputs.mtpActivations"][t].T,
        )
        for t in range(2)
    ]
    groups = lambda key, n: [MuscleGroup(f"{key}{i}", inputs[f"inputs.{key}{{{i}}}"].astype(int) - 1) for i in range(n)]  # noqa: E731
    ncp_inputs = NcpInputs(
        layout=layout, coordinates=[f"coordinate_{j}" for j in range(17)], trials=trials, muscles=muscles,
        mtp_muscles=names[:90], activation_groups=groups("activationGroups", 36),
        fiber_length_groups=groups("normalizedFiberLengthGroups", 22), v_max_factor=float(inputs["inputs.vMaxFactor"]),
        curves=hill.CURVES_2023,
    )
    specs = []
    for i in range(6):
        field = {k.rsplit(".", 1)[1]: str(v) for k, v in params.items() if k.startswith(f"params.costTerms{{{i}}}.")}
        specs.append(TermSpec("cost", field["type"], {
            "is_enabled": "true" if field["isEnabled"] == "1" else "false",
            "max_allowable_error": field["maxAllowableError"], "error_center": field["errorCenter"],
        }))
    weights = np.zeros((12, 148))
    k = 0
    for g in range(2):
        for s in range(6):
            weights[6 * g + s, 74 * g : 74 * (g + 1)] = values[k : k + 74]
            k += 74
    nodes = values[k:].reshape(2, 12, 21)
    solution = SynergySolution(layout, weights, [commands_from_nodes(nodes[t].T, 101) for t in range(2)], ["trial_1", "trial_2"])
    return {
        "inputs": ncp_inputs, "terms": build_terms(specs, "NCP"), "solution": solution,
        "activations": np.load(folder / "activations.npz")["activations"],
        "cost": float(np.load(folder / "cost.npz")["cost"]),
    }


def test_activations_reproduced(unit) -> None:
    for t in range(2):
        assert np.abs(unit["solution"].activations(t) - unit["activations"][t].T).max() < 1e-12
    normalized = unit["solution"].normalized()
    assert np.abs(normalized.activations(1) - unit["activations"][1].T).max() < 1e-12


def test_cost_reproduced(unit) -> None:
    terms = unit["terms"]
    assert [t.type for t in terms] == [
        "moment_tracking", "activation_tracking", "activation_minimization", "grouped_activations", "grouped_fiber_lengths",
    ]
    costs = score(unit["inputs"], terms, unit["solution"])
    print({k: round(v, 8) for k, v in costs.items()}, "MATLAB", unit["cost"])
    assert costs["total"] == pytest.approx(unit["cost"], rel=COST_RELATIVE_TOLERANCE)
    # the activation terms only need the saved activations: check them by hand (raw/e/sqrt(n))
    a = unit["activations"]
    by_hand = np.mean(((a[:, :90, :] - np.stack([t.mtp_activations.T for t in unit["inputs"].trials])) / 0.01) ** 2)
    assert costs["activation_tracking"] == pytest.approx(by_hand, rel=1e-12)
    assert costs["activation_minimization"] == pytest.approx(np.mean((a[:, 90:, :] / 0.05) ** 2), rel=1e-12)
