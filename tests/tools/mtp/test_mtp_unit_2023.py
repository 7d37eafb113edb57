"""The original's 2023 MTP cost-function unit test, reproduced from the same inputs.

Inputs and expected arrays: ``mtp/cost_function_unit_2023/{with,without}_synergy_extrapolation``
(Patient 3: 4 trials, 34 muscles, 6 coordinates). The original splined the EMG through
every 4th sample and clipped negative neural activations hard: both are set here
(``stride=4``, ``clip_smoothing=0``); the SynX path rounds the EMG to 4 decimals, as the
original's ``calcMuscleExcitationsSynX`` does.

The data were computed with the original's early-2023 force-length and force-velocity
curves (:data:`nmsm.model.hill.CURVES_2023`), so the chains here use them. With the
pipeline's current curves (:data:`nmsm.model.hill.CURVES`) the model moments differ by up
to 6.2e-4 of the peak (0.059 N m); every other quantity does not depend on them.
"""

from __future__ import annotations

import casadi as cs
import numpy as np
import pytest

import mtp_unit2023 as u
from nmsm.core.registry import get_registry
from nmsm.model import hill
from nmsm.tools.mtp.context import MtpContext
from nmsm.tools.mtp.model import TrialChain

CASES = ("without", "with")


def _numeric(*expressions):
    values = cs.Function("f", [], list(expressions)).call([])
    return [np.array(v.full()) for v in values]


def _models(shared_data, case):
    d = u.load(shared_data, case, "initialValues")
    splines = u.load(shared_data, "with", "emgSplines") if case == "without" else u.load(shared_data, "with", "emgSplines")
    plain_emg = u.spline_samples(d, splines)
    mus, des = u.muscles(d), u.design(d)
    trials = u.trials(d, plain_emg)
    chains = [TrialChain(t, stride=4, clip_smoothing=0.0, curves=hill.CURVES_2023) for t in trials]
    scale = cs.DM(d["emgScaleFactors"].reshape(1, -1))
    plain = [c.evaluate(mus, des, cs.DM(x) * cs.repmat(scale, x.shape[0], 1), float(d[u.P + "vMaxFactor"]))
             for c, x in zip(chains, plain_emg)]
    synx = None
    if case == "with":
        sx = u.synergy_extrapolation(d)
        expanded = [np.round(d[u.P + "emgDataExpanded"][t].T, 4) for t in range(len(trials))]
        samples = sx.excitation_samples(expanded, d["emgScaleFactors"], cs.DM(d["synergyWeights"]))
        synx = [c.evaluate(mus, des, x, float(d[u.P + "vMaxFactor"])) for c, x in zip(chains, samples)]
    return d, plain, synx


@pytest.fixture(scope="module", params=CASES)
def case(request, shared_data):
    return request.param, _models(shared_data, request.param)


def _expected(shared_data, case, name, key):
    return u.per_trial(u.load(shared_data, case, name)[key])


@pytest.mark.parametrize("quantity, file, key", [
    ("excitations", "muscleExcitationsExpected", "muscleExcitationsExpected"),
    ("neural_activations", "neuralActivationsExpected", "neuralActivationsExpected"),
    ("activations", "muscleActivationsExpected", "muscleActivationsExpected"),
    ("normalized_fiber_length", "normalizedMuscleLengthandVelocitiesExpected", "lMtildaExpected"),
    ("normalized_fiber_velocity", "normalizedMuscleLengthandVelocitiesExpected", "vMtildaExpected"),
    ("passive_force", "muscleMomentsAndForcesExpected", "passiveForceExpected"),
])
def test_modeled_values(case, shared_data, quantity, file, key):
    name, (_, plain, _) = case
    ours = _numeric(*[getattr(m, quantity) for m in plain])
    expected = _expected(shared_data, name, file, key)
    scale = max(np.abs(e).max() for e in expected)
    error = max(np.abs(o - e).max() for o, e in zip(ours, expected))
    assert error <= 1e-6 * scale, f"{quantity}: {error:.3g} (scale {scale:.3g})"


@pytest.mark.parametrize("quantity, file, key", [
    ("excitations", "synxMuscleExcitationsExpected", "muscleExcitationsExpected"),
    ("neural_activations", "synxNeuralActivationsExpected", "neuralActivationsExpected"),
    ("activations", "synxMuscleActivationsExpected", "muscleActivationsExpected"),
    ("normalized_fiber_length", "synxNormalizedMuscleLengthandVelocitiesExpected", "lMtildaExpected"),
    ("passive_force", "synxMuscleMomentsAndForcesExpected", "passiveForceExpected"),
])
def test_synx_modeled_values(shared_data, quantity, file, key):
    _, _, synx = _models(shared_data, "with")
    ours = _numeric(*[getattr(m, quantity) for m in synx])
    expected = _expected(shared_data, "with", file, key)
    scale = max(np.abs(e).max() for e in expected)
    error = max(np.abs(o - e).max() for o, e in zip(ours, expected))
    assert error <= 1e-6 * scale, f"{quantity}: {error:.3g} (scale {scale:.3g})"


def test_synx_undelayed_excitations(shared_data):
    d = u.load(shared_data, "with", "initialValues")
    _, _, synx = _models(shared_data, "with")
    expected = u.load(shared_data, "with", "synxMuscleExcitationsNoTDelayExpected")["muscleExcitationsNoTDelayExpected"]
    pad = int(d[u.P + "numPaddingFrames"])
    ours = _numeric(*[m.excitations_undelayed for m in synx])
    for t, x in enumerate(ours):
        assert np.abs(x[pad:-pad] - expected[:, :, t]).max() <= 1e-12


def test_model_moments(case, shared_data):
    """Model moments to round-off with the 2023 curves (measured: 1.5e-15 of the peak)."""
    name, (_, plain, synx) = case
    pairs = [(plain, "muscleMomentsAndForcesExpected")]
    if synx is not None:
        pairs.append((synx, "synxMuscleMomentsAndForcesExpected"))
    for models, file in pairs:
        expected = _expected(shared_data, name, file, "modelMomentsExpected")
        ours = _numeric(*[m.moments for m in models])
        scale = max(np.abs(e).max() for e in expected)
        error = max(np.abs(o - e).max() for o, e in zip(ours, expected))
        assert error <= 1e-12 * scale, f"{file}: {error:.3g} N m (peak {scale:.3g})"


#: expected-array name -> (term type, tool, the 2023 function defaults e, c)
TERMS_2023 = {
    "activationTimePenalty": ("activation_time_constant", "MTP", 0.02, 0.015),
    "activationNonlinearityPenalty": ("activation_nonlinearity_constant", "MTP", 0.1, 0.0),
    "lMoPenalty": ("optimal_muscle_fiber_length", "MTP", 0.1, 0.0),
    "lTsPenalty": ("tendon_slack_length", "MTP", 0.1, 0.0),
    "emgScalePenalty": ("emg_scale_factor", "MTP", 0.2, 0.3),
    "lMtildaPenalty": ("normalized_muscle_fiber_length", "MTP", 0.1, 0.0),
    "lmtildaPairedSimilarity": ("grouped_normalized_muscle_fiber_length", "MTP", 0.05, 0.0),
    "emgScalePairedSimilarity": ("grouped_emg_scale_factor", "MTP", 0.1, 0.0),
    "tdelayPairedSimilarity": ("grouped_electromechanical_delay", "MTP", 0.2, 0.0),
    "minPassiveForce": ("passive_muscle_force", "MTP", 50.0, 0.0),
    "synergyMuscleExcitationMinimization": ("extrapolated_muscle_activation", "SynX", 0.3, 0.0),
    "residualMuscleActivationMinimization": ("residual_muscle_activation", "SynX", 0.3, 0.0),
    "excitationPenalty": ("muscle_excitation_penalty", "SynX", 0.25, 0.5),
}
#: moment terms: the 2023 "without" file used e = 2
MOMENT_TERMS_2023 = {
    "momentMatching": ("inverse_dynamics_joint_moment", "MTP", {"without": 2.0, "with": 2.5}),
    "synxMomentMatching": ("measured_inverse_dynamics_joint_moment", "SynX", {"with": 2.0}),
}


def _context(d, plain, synx):
    sx = u.synergy_extrapolation(d) if synx is not None else None
    missing = tuple(sorted(i for g in sx.missing_muscles for i in g)) if sx else ()
    n = d[u.P + "optimalFiberLength"].size
    return MtpContext(
        muscles=u.muscles(d), design=u.design(d), models=plain, synx_models=synx,
        inverse_dynamics_moments=[d[u.P + "experimentalMoments"][t].T for t in range(len(plain))],
        initial_fiber_length=[d[u.P + "normalizedFiberLength"][t].T for t in range(len(plain))],
        activation_groups=u.groups(d, u.P + "activationGroups"),
        fiber_length_groups=u.groups(d, u.P + "normalizedFiberLengthGroups"),
        measured=tuple(i for i in range(n) if i not in missing), missing=missing,
        padding=int(d[u.P + "numPaddingFrames"]),
    )


def _term_cost(term, ctx):
    return _numeric(cs.sumsqr(term.residuals(ctx)))[0].item()


def test_cost_terms(case, shared_data):
    name, (d, plain, synx) = case
    ctx = _context(d, plain, synx)
    expected = u.load(shared_data, name, "individualCostsExpected")
    registry = get_registry()
    for key, (term_type, tool, e, c) in TERMS_2023.items():
        full = "individualCostsExpected." + key
        if full not in expected:
            continue
        term = registry.get("cost", term_type, tool)(max_allowable_error=e, error_center=c)
        target = float(np.sum(expected[full] ** 2))
        if key == "excitationPenalty":
            target = float(np.sum((np.sqrt(0.1) * expected[full]) ** 2))
        assert _term_cost(term, ctx) == pytest.approx(target, rel=1e-9, abs=1e-14), key


def test_total_cost(case, shared_data):
    """The 2023 total (with SynX: 379.29278859; without: 217.62267151), moment terms included."""
    name, (d, plain, synx) = case
    ctx = _context(d, plain, synx)
    expected = u.load(shared_data, name, "individualCostsExpected")
    registry = get_registry()
    total = moments = 0.0
    for key, (term_type, tool, e, c) in TERMS_2023.items():
        if "individualCostsExpected." + key in expected:
            total += _term_cost(registry.get("cost", term_type, tool)(max_allowable_error=e, error_center=c), ctx)
    for key, (term_type, tool, errors) in MOMENT_TERMS_2023.items():
        if name in errors:
            moments += _term_cost(registry.get("cost", term_type, tool)(max_allowable_error=errors[name]), ctx)
    stored = float(u.load(shared_data, name, "costExpected")["costExpected"])
    stored_moments = sum(float(np.sum(expected["individualCostsExpected." + k] ** 2))
                         for k in MOMENT_TERMS_2023 if "individualCostsExpected." + k in expected)
    assert total == pytest.approx(stored - stored_moments, rel=1e-9)
    assert moments == pytest.approx(stored_moments, rel=1e-12)
    assert total + moments == pytest.approx(stored, rel=1e-12)


def test_nonlinear_constraint(shared_data):
    """``log(sum(exp(500 (l - 1.3)))) / 500`` and the 0.3 counterpart per muscle (2023 arrays).

    The original sums the exponentials directly: where they all underflow it gets
    ``-inf`` (then clipped to -1; with overflow it would get ``inf``). Our log-sum-exp is
    stable, so those entries are compared with the original's arithmetic, the rest with
    the stored values.
    """
    d, plain, _ = _models(shared_data, "with")
    from nmsm.tools.mtp.problem import fiber_length_constraints

    upper, lower = fiber_length_constraints(plain)
    ours = np.concatenate([v.ravel() for v in _numeric(upper, lower)])
    expected = u.load(shared_data, "with", "expectedNonlinearConstraint")["expectedNonlinearConstraint"]
    lengths = np.stack(_numeric(*[m.normalized_fiber_length for m in plain]))  # (trial, frame, muscle)
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        naive = np.concatenate([
            np.log(np.sum(np.exp(500 * (lengths - 1.3)), axis=(0, 1))) / 500,
            np.log(np.sum(np.exp(500 * (0.3 - lengths)), axis=(0, 1))) / 500,
        ])
    finite = np.isfinite(naive) & (np.abs(naive) <= 1000)
    assert np.abs(ours[finite] - expected[finite]).max() <= 1e-10
    artifacts = np.where(naive < -1000, -1.0, np.where(naive > 1000, 1.0, naive))[~finite]
    artifacts = np.nan_to_num(artifacts, nan=0.0, neginf=-1.0, posinf=1.0)
    assert np.array_equal(artifacts, expected[~finite])
    assert (~finite).sum() == 2  # two muscles whose exponentials all underflow (stored as -1)
