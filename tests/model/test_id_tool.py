"""OpenSim's ID-tool processing (pad, IIR low-pass, quintic spline) and ``nmsm id`` against
OpenSim's InverseDynamicsTool on the tutorial data."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import InputError
from nmsm.io.storage import read_storage
from nmsm.model import load_model
from nmsm.model.external_loads import read_external_loads
from nmsm.model.id_tool import inverse_dynamics_of_motion
from nmsm.model.signal import lowpass_iir, pad, quintic_spline

MTP = Path("mtp") / "uf_subject3_tutorial"
PRE = Path("preprocessing") / "uf_subject3_tutorial" / "PreCompleted" / "input_data"


def _loads_file(shared_data: Path, folder: Path) -> Path:
    """The tutorial's ExternalLoads description, pointed at the preprocessed GRF file."""
    text = (shared_data / PRE / "externalLoads.xml").read_text()
    grf = shared_data / MTP / "preprocessed" / "GRFData" / "gait_1.sto"
    text = text.replace("GaitTrial48_forces_ec_reordered.mot", str(grf))
    path = folder / "loads.xml"
    path.write_text(text)
    return path


def test_pad_and_filter_match_opensim_storage(shared_data: Path, bridge) -> None:
    ik = shared_data / MTP / "preprocessed" / "IKData" / "gait_1.sto"
    table = read_storage(ik)
    n = table.n_rows // 2
    reference = bridge.call("oracle_storage_filter", coordinates_file=str(ik), lowpass_hz=-1.0)
    assert np.abs(pad(table.time, n) - reference["times"]).max() <= 1e-12
    assert np.array_equal(pad(table.data, n), reference["data"])
    reference = bridge.call("oracle_storage_filter", coordinates_file=str(ik), lowpass_hz=6.0)
    times = pad(table.time, n)
    filtered = lowpass_iir(pad(table.data, n), times[1] - times[0], 6.0)
    assert np.abs(filtered - reference["data"]).max() <= 1e-11


def test_quintic_spline_matches_opensim_gcv_spline(bridge) -> None:
    rng = np.random.default_rng(51)
    times = np.cumsum(rng.uniform(0.008, 0.012, 40))
    values = np.sin(7 * times) + 0.01 * rng.normal(size=40)
    at = np.concatenate([times, 0.5 * (times[1:] + times[:-1])])
    reference = bridge.call("oracle_gcv_spline", times=times, values=values, at=at)
    ours = quintic_spline(times, values[:, None], at)
    for order in range(3):
        scale = max(1.0, np.abs(reference[order]).max())
        assert np.abs(ours[order][:, 0] - reference[order]).max() <= 1e-9 * scale


def test_too_short_or_uneven_motion_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="too few"):
        quintic_spline(np.arange(5.0), np.zeros((5, 1)), np.arange(5.0))
    from nmsm.model.signal import uniform_interval

    with pytest.raises(InputError, match="uniformly"):
        uniform_interval(np.array([0.0, 0.01, 0.03, 0.04]))


@pytest.mark.parametrize("case", ["no_loads_6hz", "grf_6hz", "grf_unfiltered"])
def test_nmsm_id_matches_opensim_id_tool(case: str, shared_data: Path, bridge, tmp_path: Path) -> None:
    if case == "no_loads_6hz":
        model_path = shared_data / PRE / "UF_Subject_3_reduced_muscles.osim"
        motion = shared_data / PRE / "GaitTrial_IKResults.mot"  # degrees; its GRF file is not in the data
        loads, cutoff = None, 6.0
    else:
        model_path = shared_data / MTP / "UF_Subject_3_reduced_muscles.osim"
        motion = shared_data / MTP / "preprocessed" / "IKData" / "gait_1.sto"
        loads = _loads_file(shared_data, tmp_path)
        cutoff = 6.0 if case == "grf_6hz" else -1.0
    out = tmp_path / "opensim_id.sto"
    bridge.call("oracle_inverse_dynamics_tool", model_path=str(model_path), coordinates_file=str(motion),
                output_file=str(out), external_loads_file=None if loads is None else str(loads), lowpass_hz=cutoff)
    reference = read_storage(out)
    ours = inverse_dynamics_of_motion(load_model(model_path), read_storage(motion),
                                      external_loads=None if loads is None else read_external_loads(loads),
                                      lowpass_hz=cutoff if cutoff > 0 else None)
    assert ours.labels == reference.labels
    assert np.abs(ours.time - reference.time).max() <= 1e-12
    assert np.abs(ours.data - reference.data).max() <= 1e-6


def test_external_loads_errors(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.model.external_loads import sample_loads

    bad = tmp_path / "bad.xml"
    bad.write_text("<OpenSimDocument><Other/></OpenSimDocument>")
    with pytest.raises(InputError, match="no <ExternalLoads>"):
        read_external_loads(bad)
    loads = read_external_loads(_loads_file(shared_data, tmp_path))
    assert [f.body for f in loads.forces] == ["calcn_l", "calcn_r"]
    with pytest.raises(InputError, match="cover"):
        sample_loads(loads, np.array([0.0, 10.0]))


def test_loads_expressed_in_body_frames_match_opensim(shared_data: Path, bridge, tmp_path: Path) -> None:
    """Forces given in a body's frame and points fixed in a body, converted with the motion's
    kinematics (as OpenSim's ExternalForce does)."""
    from nmsm.io.storage import table_from_columns, write_storage

    model_path = shared_data / MTP / "UF_Subject_3_reduced_muscles.osim"
    motion = shared_data / MTP / "preprocessed" / "IKData" / "gait_1.sto"
    grf = read_storage(shared_data / MTP / "preprocessed" / "GRFData" / "gait_1.sto")
    columns = {label: grf.column(label) for label in grf.labels}
    n = grf.n_rows
    for axis, value in zip("xyz", (0.12, -0.03, 0.01)):
        columns[f"ground_force_2_p{axis}"] = np.full(n, value)  # a point fixed in calcn_r (m)
    data = tmp_path / "grf_body.sto"
    write_storage(data, table_from_columns(grf.time, columns, name="grf"))
    from lxml import etree

    tree = etree.parse(str(shared_data / PRE / "externalLoads.xml"))
    tree.find(".//datafile").text = str(data)
    left, right = tree.findall(".//ExternalForce")
    left.find("force_expressed_in_body").text = "calcn_l"  # the raw numbers read as calcn_l-frame forces
    right.find("point_expressed_in_body").text = "calcn_r"
    loads_path = tmp_path / "loads_body.xml"
    tree.write(str(loads_path))
    loads = read_external_loads(loads_path)
    assert [(f.force_frame, f.point_frame) for f in loads.forces] == [("calcn_l", "ground"), ("ground", "calcn_r")]
    out = tmp_path / "opensim_id.sto"
    bridge.call("oracle_inverse_dynamics_tool", model_path=str(model_path), coordinates_file=str(motion),
                output_file=str(out), external_loads_file=str(loads_path), lowpass_hz=6.0)
    reference = read_storage(out)
    ours = inverse_dynamics_of_motion(load_model(model_path), read_storage(motion), external_loads=loads, lowpass_hz=6.0)
    assert np.abs(ours.data - reference.data).max() <= 1e-6


def test_contact_forces_with_external_loads_warn(shared_data: Path) -> None:
    """The 2D Moco model's smooth-sphere contacts plus its measured ground reactions: both act,
    so the feet are loaded twice — said, not silently summed."""
    folder = shared_data / "moco2d"
    model = load_model(folder / "2D_gait.osim")
    motion = read_storage(folder / "referenceCoordinates.sto")
    loads = read_external_loads(folder / "referenceGRF.xml")
    with pytest.warns(UserWarning, match=r"contact forces \(SmoothSphereHalfSpaceForce contactHeel_r, contactHeel_l, contactFront_r, "
                                         r"contactFront_l\).*loaded twice.*appliesForce"):
        inverse_dynamics_of_motion(model, motion, external_loads=loads)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        inverse_dynamics_of_motion(model, motion)  # contact alone: nothing to say
