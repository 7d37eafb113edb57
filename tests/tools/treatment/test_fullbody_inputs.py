"""The full-body gait case's inputs (issue 24): model, GCP settings of each foot, synthetic
activations, synergy pairing and the TO/VO/DO settings files."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import attrs
import numpy as np
import pytest

from nmsm.examples import fullbody_data as fd


@pytest.fixture(scope="module")
def model_file(shared_data, tmp_path_factory):
    from nmsm.examples.fullbody_model import write_fullbody_model

    shared = fd.shared_inputs(shared_data)
    return write_fullbody_model(shared.body_model, shared.muscle_model,
                                tmp_path_factory.mktemp("fullbody") / "model" / "fullbody.osim")


def test_model_has_86_muscles_on_the_gcp_skeleton(shared_data, model_file):
    from nmsm.model import load_model

    model = load_model(model_file)
    body = load_model(fd.shared_inputs(shared_data).body_model)
    assert len(model.muscle_names) == 86 and len(model.coordinate_names) == 41
    assert model.coordinate_names == body.coordinate_names
    for side, group in fd.LEG_GROUPS.items():
        members = model.group_members(group)
        assert len(members) == 43 and all(m.endswith(f"_{side}") for m in members)
    root = ET.parse(model_file).getroot()
    joints = {j.get("name"): ET.tostring(j) for j in root.iter("JointSet")}
    body_root = ET.parse(fd.shared_inputs(shared_data).body_model).getroot()
    assert joints == {j.get("name"): ET.tostring(j) for j in body_root.iter("JointSet")}
    markers = {m.get("name"): m for m in root.iter("Marker")}
    right = [float(v) for v in markers["R_Toe_Medial"].findtext("location").split()]
    left = [float(v) for v in markers["L_Toe_Medial"].findtext("location").split()]
    assert markers["L_Toe_Medial"].findtext("socket_parent_frame") == "/bodyset/calcn_l"
    assert left == [right[0], right[1], -right[2]]
    assert "L_Toe_Lateral" in markers


@pytest.mark.parametrize("side", ["r", "l"])
def test_gcp_settings_of_each_foot_read(shared_data, model_file, tmp_path, side):
    from nmsm.examples.fullbody_gcp import gcp_settings_xml
    from nmsm.io.settings.reader import read_settings_document
    from nmsm.io.settings.gcp import GroundContactPersonalizationSettings

    shared = fd.shared_inputs(shared_data)
    path = tmp_path / "settings" / f"GCP_{side}.xml"
    path.parent.mkdir()
    path.write_text(gcp_settings_xml(shared.gcp_settings, path.parent, side=side, model=model_file,
                                     preprocessed=shared.preprocessed, results=tmp_path / "gcp"), encoding="utf-8")
    settings = GroundContactPersonalizationSettings.from_document(read_settings_document(path))
    (surface,) = settings.contact_surfaces
    plate = 2 if side == "r" else 1
    assert surface.is_left_foot == (side == "l")
    assert surface.hindfoot_body == f"calcn_{side}"
    assert tuple(surface.force_columns) == tuple(f"ground_force_{plate}_v{a}" for a in "xyz")
    assert surface.medial_marker == f"{side.upper()}_Toe_Medial"
    assert len(settings.tasks) == 3 and Path(settings.input_model_file).resolve() == model_file.resolve()


def test_static_optimization_recovers_reachable_moments():
    """Known answer: moments made by known activations (inside the bounds) are reproduced,
    and no activation is larger than it needs to be."""
    from nmsm.examples.fullbody_activations import static_optimization
    from nmsm.tools.mtp.muscles import MuscleParameters
    from nmsm.tools.ncp.forces import moment_gains
    from nmsm.tools.ncp.inputs import NcpTrial

    rng = np.random.default_rng(3)
    frames, coordinates, muscles = 12, 2, 6
    parameters = MuscleParameters(tuple(f"m{k}" for k in range(muscles)), np.full(muscles, 1000.0),
                                  np.full(muscles, 0.1), np.full(muscles, 0.2), np.zeros(muscles))
    lengths = 0.2 + 0.1 * (0.9 + 0.1 * rng.random((frames, muscles)))
    arms = rng.choice([-1.0, 1.0], size=(1, coordinates, muscles)) * (0.02 + 0.03 * rng.random((frames, coordinates,
                                                                                             muscles)))
    trial = NcpTrial(name="t", time=np.arange(frames) * 0.01, lengths=lengths, velocities=np.zeros((frames, muscles)),
                     moment_arms=arms, moments=np.zeros((frames, coordinates)))
    truth = 0.05 + 0.3 * rng.random((frames, muscles))
    moments = moment_gains(trial, parameters, 10.0).moments(truth)
    trial = attrs.evolve(trial, moments=moments)
    result = static_optimization(trial, parameters, ("c1", "c2"), moment_weight=1e4)
    assert np.max(np.abs(result.modeled - moments)) < 0.05 * np.max(np.abs(moments))
    assert np.all(result.activations >= 0.01 - 1e-9) and np.all(result.activations <= 1 + 1e-9)
    assert np.sum(result.activations ** 2) <= np.sum(truth ** 2) + 1e-6


def test_synergy_pairs_follow_the_mirrored_vectors(tmp_path):
    from nmsm.examples.fullbody import synergy_pairs
    from nmsm.io.storage import Table, write_storage

    right = [f"m{k}_r" for k in range(6)]
    muscles = right + [m[:-2] + "_l" for m in right]
    rng = np.random.default_rng(0)
    W_r = rng.random((3, 6)) ** 4
    order = [2, 0, 1]  # left synergy j is right synergy order[j]
    weights = np.zeros((6, 12))
    weights[:3, :6] = W_r
    weights[3:, 6:] = W_r[order]
    write_storage(tmp_path / "synergyWeights.sto", Table(time=np.arange(1.0, 7.0), labels=tuple(muscles), data=weights))
    names = tuple(f"right_leg_{k}" for k in (1, 2, 3)) + tuple(f"left_leg_{k}" for k in (1, 2, 3))
    write_storage(tmp_path / "gait_1_synergyCommands.sto", Table(time=[0.0, 1.0], labels=names, data=np.ones((2, 6))))
    pairs = dict(synergy_pairs(tmp_path))
    assert pairs == {f"right_leg_{order[j] + 1}": f"left_leg_{j + 1}" for j in range(3)}


def _folders(tmp_path: Path):
    from nmsm.examples.fullbody_settings import CaseFolders

    case = tmp_path / "case"
    return CaseFolders(settings=case / "stress_coarse", model=case / "model" / "fullbody.osim",
                       osimx=case / "prepared" / "fullbody_stress.osimx", tracked=case / "data",
                       guess=case / "prepared" / "ncp", surrogate=case / "prepared" / "surrogate_stress",
                       results=case / "stress_coarse" / "results")


def _stress_controllers():
    from nmsm.examples.fullbody_settings import Controllers

    pairs = tuple((f"right_leg_{k}", f"left_leg_{k}") for k in range(1, 6))
    return Controllers(name="stress", synergy_names=tuple(n for p in pairs for n in p),
                       surrogate_coordinates=fd.muscle_coordinates(),
                       torque_coordinates=fd.LUMBAR + fd.arm_coordinates(),
                       muscles=("soleus_r", "soleus_l"), optimize_vectors=True, max_synergy_activation=10,
                       pairs=pairs, paretic="right_leg_1")


@pytest.mark.parametrize("mesh, size", [("coarse", (5, 4)), ("full", (25, 4))])
def test_settings_files_chain_to_vo_do(tmp_path, mesh, size):
    from nmsm.examples.fullbody_settings import write_treatment_settings

    folders = _folders(tmp_path)
    paths = write_treatment_settings(_stress_controllers(), folders, mesh)
    roots = {tool: ET.parse(path).getroot()[0] for tool, path in paths.items()}
    assert [r.tag for r in roots.values()] == ["TrackingOptimizationTool", "VerificationOptimizationTool",
                                                "DesignOptimizationTool"]
    for root in roots.values():
        assert len(root.findtext("states_coordinate_list").split()) == 31
        assert root.findtext("input_model_file") == "../model/fullbody.osim"
    assert roots["vo"].findtext("initial_guess_directory") == roots["to"].findtext("results_directory") == "results/to"
    assert roots["do"].findtext("tracked_quantities_directory") == roots["vo"].findtext("results_directory")
    assert roots["vo"].findtext("RCNLSynergyController/optimize_synergy_vectors") == "false"
    do_types = [t.text for t in roots["do"].iter("type")]
    assert "synergy_amplitude_symmetry" in do_types and "paretic_synergy_scale" in do_types
    assert roots["do"].findtext("model_functions") == "scaleSynergyActivation"
    solver = ET.parse(folders.settings / "solver.xml").getroot()
    assert (int(solver.findtext(".//setup_mesh_phase_intervals")),
            int(solver.findtext(".//setup_mesh_phase_colpoints_per_Interval"))) == size
