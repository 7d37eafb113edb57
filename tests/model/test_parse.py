"""Reading .osim files: every shared model against OpenSim's own reading of it, old-format
upgrade through the bridge, and clear errors for what nmsm cannot represent."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from nmsm.errors import ModelError
from nmsm.model import load_model
from nmsm.model.components import ConditionalPathPoint, MovingPathPoint

from model_testing import EXPECTED_MODEL_COUNT, MODEL_FILES


def test_all_shared_models_are_listed(shared_data: Path) -> None:
    assert len(MODEL_FILES) == EXPECTED_MODEL_COUNT


@pytest.mark.parametrize("relative", MODEL_FILES)
def test_model_matches_opensim_reading(relative: str, shared_data: Path, bridge, model_cache) -> None:
    model, _ = model_cache(shared_data / relative)
    ref = bridge.call("oracle_model_summary", path=model.source_file)
    assert ref["coordinates"] == model.coordinate_names
    assert [ref["coordinates"][i] for i in np.argsort(ref["q_index"])] == model.tree_coordinate_names
    for c in model.coordinates:
        info = ref["coordinate_info"][c.name]
        assert info["motion"] == c.motion_type, c.name
        assert np.array_equal(info["range"], c.range), c.name
        assert (info["default"], info["locked"], info["clamped"], info["joint"]) == (
            c.default_value, c.locked, c.clamped, c.joint), c.name
    assert list(ref["bodies"]) == list(model.bodies)
    for name, body in ref["bodies"].items():
        ours = model.bodies[name]
        i = ours.inertia
        assert body["mass"] == ours.mass
        assert np.array_equal(body["com"], ours.mass_center)
        assert np.array_equal(body["inertia"], [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]])
    assert list(ref["markers"]) == model.marker_names
    for name, marker in ref["markers"].items():
        assert (marker["body"], list(marker["location"])) == (model.marker(name).body, list(model.marker(name).location))
    assert list(ref["muscles"]) == model.muscle_names
    for name, muscle in ref["muscles"].items():
        ours = model.muscle(name)
        assert muscle["type"] == ours.type
        for key in ("max_isometric_force", "optimal_fiber_length", "tendon_slack_length",
                    "pennation_angle_at_optimal", "max_contraction_velocity", "applies_force"):
            assert muscle[key] == getattr(ours, key), (name, key)
        assert muscle["points"] == [p.name for p in ours.geometry.points]
        assert muscle["point_types"] == [type(p).__name__ for p in ours.geometry.points]
        assert muscle["wraps"] == [w.wrap_object for w in ours.geometry.wraps]
    assert ref["groups"] == model.groups
    assert {n: (j["type"], j["parent"], j["child"]) for n, j in ref["joints"].items()} == {
        j.name: (j.type, j.parent_body, j.child_body) for j in model.joints}
    assert list(ref["gravity"]) == list(model.gravity)
    assert set(ref["wrap_objects"]) == set(model.wrap_objects)
    for name, wrap in ref["wrap_objects"].items():
        ours = model.wrap_objects[name]
        assert (wrap["type"], wrap["body"], wrap["active"], wrap["quadrant"]) == (ours.type, ours.body, ours.active,
                                                                                  ours.quadrant)
        assert np.array_equal(wrap["translation"], ours.translation)
        assert np.array_equal(wrap["rotation"], ours.rotation)
        for key in ("radius", "length", "inner_radius", "outer_radius", "dimensions"):
            if key in wrap:
                assert np.array_equal(wrap[key], ours.parameters[key]), (name, key)


def test_muscle_paths_parse_every_point_type(shared_data: Path) -> None:
    gait = load_model(shared_data / "jmp" / "gait2392_walk_free" / "subject01_gait2392_scaled.osim")
    rect_fem = gait.muscle("rect_fem_r").geometry.points
    moving = [p for p in rect_fem if isinstance(p, MovingPathPoint)]
    assert moving and moving[0].coordinates == ("knee_angle_r",) * 3
    assert moving[0].body == "tibia_r"
    # x location at 0 rad: scale 0.988523 x spline value 0.0617576 (file values)
    assert moving[0].functions[0].numeric(0.0) == pytest.approx(0.988523 * 0.0617576, rel=1e-12)
    semimem = gait.muscle("semimem_r").geometry.points
    conditional = [p for p in semimem if isinstance(p, ConditionalPathPoint)]
    assert conditional[0].coordinate == "knee_angle_r"
    assert conditional[0].range == pytest.approx((-0.558505, 0.174533))
    rcnl = load_model(shared_data / "models" / "RCNL2024.osim")
    wraps = rcnl.muscle("addbrev_r").geometry.wraps
    assert [(w.wrap_object, w.method, w.range) for w in wraps] == [("AB_at_femshaft_r", "hybrid", (-1, -1))]
    assert rcnl.group_members("knee_ext_r") == ["recfem_r", "vasint_r", "vaslat_r", "vasmed_r"]
    moco = load_model(shared_data / "moco2d" / "2D_gait.osim")  # components under <components>
    assert len(moco.muscles) == 18 and moco.muscles[0].type == "DeGrooteFregly2016Muscle"
    assert [a.name for a in moco.actuators] == ["lumbarAct"]
    assert len(moco.contact_forces) == 4 and moco.contact_geometry["/contactgeometryset/heel_r"].radius == 0.035


def test_old_format_is_upgraded_once_into_the_cache(shared_data: Path, bridge, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv("NMSM_CACHE_DIR", str(tmp_path))
    source = shared_data / "core" / "nmsm_core_tests" / "model" / "arm26.osim"
    model = load_model(source)
    assert model.file == str(source) and model.version == 20303
    cached = Path(model.source_file)
    assert cached.parent == tmp_path / "models" and cached.is_file()
    stamp = cached.stat().st_mtime_ns
    again = load_model(source)
    assert again.source_file == str(cached) and cached.stat().st_mtime_ns == stamp
    assert model.coordinate_names == ["r_shoulder_elev", "r_elbow_flex"]
    assert {w.type for w in model.wrap_objects.values()} == {"WrapCylinder", "WrapEllipsoid"}


# ---------------------------------------------------------------------------- bad input
_MODEL = """<?xml version="1.0" encoding="UTF-8" ?>
<OpenSimDocument Version="40000">
  <Model name="tiny">
    <Ground name="ground"/>
    <BodySet name="bodyset"><objects>
      <Body name="link"><mass>2</mass><mass_center>0 -0.5 0</mass_center><inertia>0.1 0.1 0.1 0 0 0</inertia></Body>
    </objects></BodySet>
    <JointSet name="jointset"><objects>
      {joint}
    </objects></JointSet>
    <ConstraintSet name="constraintset"><objects>{constraints}</objects></ConstraintSet>
  </Model>
</OpenSimDocument>
"""
_PIN = """<PinJoint name="hinge"><socket_parent_frame>/ground</socket_parent_frame>
        <socket_child_frame>/bodyset/link</socket_child_frame>
        <coordinates><Coordinate name="angle"/></coordinates></PinJoint>"""


def _write(tmp_path: Path, joint: str = _PIN, constraints: str = "") -> Path:
    path = tmp_path / "tiny.osim"
    path.write_text(_MODEL.format(joint=joint, constraints=constraints))
    return path


def test_tiny_model_loads(tmp_path: Path) -> None:
    model = load_model(_write(tmp_path))
    assert model.coordinate_names == ["angle"] and model.coordinates[0].range == (-10.0, 10.0)


def test_unsupported_joint_type_is_named(tmp_path: Path) -> None:
    joint = _PIN.replace("PinJoint", "EllipsoidJoint")
    with pytest.raises(ModelError) as info:
        load_model(_write(tmp_path, joint))
    text = str(info.value)
    assert "EllipsoidJoint 'hinge'" in text and "tiny.osim" in text and "not supported" in text


def test_missing_frame_is_named(tmp_path: Path) -> None:
    joint = _PIN.replace("/bodyset/link", "/bodyset/nothing")
    with pytest.raises(ModelError, match="PinJoint 'hinge'.*'/bodyset/nothing' names no frame"):
        load_model(_write(tmp_path, joint))


def test_coupler_with_two_independent_coordinates_is_refused(tmp_path: Path) -> None:
    joint = _PIN.replace('<Coordinate name="angle"/>', "").replace("PinJoint", "UniversalJoint")
    joint = joint.replace("<coordinates></coordinates>", '<coordinates><Coordinate name="a"/><Coordinate name="b"/></coordinates>')
    coupler = """<CoordinateCouplerConstraint name="link_c"><coupled_coordinates_function><LinearFunction>
      <coefficients>1 0</coefficients></LinearFunction></coupled_coordinates_function>
      <independent_coordinate_names>a b</independent_coordinate_names>
      <dependent_coordinate_name>a</dependent_coordinate_name></CoordinateCouplerConstraint>"""
    with pytest.raises(ModelError, match="link_c.*2 independent coordinates"):
        load_model(_write(tmp_path, joint, coupler))


def test_non_monotonic_spline_in_a_model_names_joint_and_file(tmp_path: Path) -> None:
    joint = """<CustomJoint name="knee"><socket_parent_frame>/ground</socket_parent_frame>
      <socket_child_frame>/bodyset/link</socket_child_frame>
      <coordinates><Coordinate name="flex"/></coordinates>
      <SpatialTransform><TransformAxis name="rotation1"><coordinates>flex</coordinates><axis>0 0 1</axis>
      <LinearFunction name="function"><coefficients>1 0</coefficients></LinearFunction></TransformAxis>
      <TransformAxis name="translation1"><coordinates>flex</coordinates><axis>1 0 0</axis>
      <SimmSpline name="function"><x>0 1 0.5 2</x><y>0 1 2 3</y></SimmSpline></TransformAxis>
      </SpatialTransform></CustomJoint>"""
    with pytest.raises(ModelError) as info:
        load_model(_write(tmp_path, joint))
    text = str(info.value)
    assert "tiny.osim" in text and "CustomJoint 'knee' translation1" in text and "strictly increasing" in text


def test_not_xml_and_missing_file(tmp_path: Path) -> None:
    bad = tmp_path / "bad.osim"
    bad.write_text("this is not xml")
    with pytest.raises(ModelError, match="bad.osim.*not a valid XML"):
        load_model(bad)
    with pytest.raises(ModelError, match="not found"):
        load_model(tmp_path / "absent.osim")


def test_cache_dir_follows_environment(tmp_path: Path, monkeypatch) -> None:
    from nmsm.model.osim import cache_dir

    monkeypatch.setenv("NMSM_CACHE_DIR", str(tmp_path))
    assert cache_dir() == tmp_path / "models"
    monkeypatch.delenv("NMSM_CACHE_DIR")
    assert cache_dir() == Path(os.path.expanduser("~")) / ".cache" / "nmsm" / "models"
