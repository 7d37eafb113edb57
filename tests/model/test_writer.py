"""Writing changes back into .osim files: nothing else changes, OpenSim reads the result."""

from __future__ import annotations

import difflib
from pathlib import Path

import numpy as np
import pytest

from nmsm.model import load_model
from nmsm.model.osim_writer import OsimWriter, format_number


def _changed_lines(a: Path, b: Path) -> list[str]:
    diff = difflib.unified_diff(a.read_text().splitlines(), b.read_text().splitlines(), lineterm="", n=0)
    return [line for line in diff if line[:1] in "+-" and not line.startswith(("+++", "---"))]


@pytest.mark.parametrize("relative", ["models/RCNL2024.osim", "moco2d/2D_gait.osim",
                                      "gcp/patient3_right_foot/footModel_1.osim"])
def test_no_change_writes_identical_content(relative: str, shared_data: Path, tmp_path: Path) -> None:
    source = shared_data / relative
    out = OsimWriter(source).write(tmp_path / "same.osim")
    assert out.read_bytes() == source.read_bytes()


def test_changes_touch_only_their_elements(shared_data: Path, tmp_path: Path, bridge) -> None:
    source = shared_data / "models" / "RCNL2024.osim"
    writer = OsimWriter(source)
    writer.set_joint_frame("knee_r", "parent", orientation=[-0.05, 0.01, 0.1])
    writer.set_joint_frame("knee_r", "child", translation=[-0.008, -0.004, -0.0015])
    writer.set_marker_location("C7", [-0.07, 0.44, 0.001])
    writer.set_muscle_property("soleus_r", "optimal_fiber_length", 0.0451)
    writer.set_muscle_property("soleus_r", "appliesForce", False)  # absent in the file: inserted
    out = writer.write(tmp_path / "changed.osim")
    changed = _changed_lines(source, out)
    assert sum(line.startswith("-") for line in changed) == 4
    assert sum(line.startswith("+") for line in changed) == 5
    assert "+\t\t\t\t\t<appliesForce>false</appliesForce>" in changed
    model = load_model(out)
    assert list(model.frames["/jointset/knee_r/femur_r_offset"].orientation) == [-0.05, 0.01, 0.1]
    assert list(model.frames["/jointset/knee_r/tibia_r_offset"].translation) == [-0.008, -0.004, -0.0015]
    assert list(model.marker("C7").location) == [-0.07, 0.44, 0.001]
    assert model.muscle("soleus_r").optimal_fiber_length == 0.0451
    assert model.muscle("soleus_r").applies_force is False
    summary = bridge.call("oracle_model_summary", path=str(out))
    assert summary["muscles"]["soleus_r"]["optimal_fiber_length"] == 0.0451
    assert summary["muscles"]["soleus_r"]["applies_force"] is False
    assert summary["markers"]["C7"]["location"] == [-0.07, 0.44, 0.001]


def test_edits_land_on_their_elements_after_unicode_line_separators(shared_data: Path, tmp_path: Path) -> None:
    """Python's ``splitlines`` also ends lines at U+0085 (byte 0x85, Windows' "…", in an
    ISO-8859-1 file), U+2028 and U+2029, which XML treats as text: the writer numbers lines as
    the parser does, so an edit after such characters lands on its own element."""
    text = (shared_data / "models" / "RCNL2024.osim").read_text(encoding="utf-8")
    text = text.replace('encoding="UTF-8"', 'encoding="ISO-8859-1"', 1)
    notes = "pasted notes, ten Windows ellipses" + "\x85" * 10 + " and two separators\u2028\u2029"
    text = text.replace("\t<Model ", f"\t<!-- {notes} -->\n\t<Model ", 1)
    source = tmp_path / "latin1.osim"
    source.write_bytes(text.encode("latin-1", errors="xmlcharrefreplace"))
    before = load_model(source)
    writer = OsimWriter(source)
    edited = {"C7": [-0.07, 0.44, 0.001], "R_Asis": [0.01, 0.02, 0.03], "L_Heel": [-0.1, 0.0, 0.2]}
    for name, location in edited.items():
        writer.set_marker_location(name, location)
    writer.set_muscle_property("soleus_r", "optimal_fiber_length", 0.0451)
    after = load_model(writer.write(tmp_path / "out.osim"))
    moved = {m.name for m in before.markers if not np.array_equal(m.location, after.marker(m.name).location)}
    assert moved == set(edited)
    assert all(list(after.marker(n).location) == loc for n, loc in edited.items())
    changed = {m.name for m in before.muscles
               if m.optimal_fiber_length != after.muscle(m.name).optimal_fiber_length}
    assert changed == {"soleus_r"} and after.muscle("soleus_r").optimal_fiber_length == 0.0451


def test_scaled_body_is_read_by_opensim_as_nmsm_scales_it(shared_data: Path, tmp_path: Path, bridge) -> None:
    from nmsm.model import CasadiModel, ModelParameters

    source = shared_data / "models" / "RCNL2024.osim"
    writer = OsimWriter(source)
    writer.scale_body("femur_r", 1.07)
    out = writer.write(tmp_path / "scaled.osim")
    model = load_model(source)
    params = ModelParameters(model)
    params.body_scale("femur_r")
    cm = CasadiModel(model, params)
    q = np.zeros((2, cm.n))
    q[1, model.coordinate_index("knee_angle_r")] = 1.0
    q = cm.coordinates.dependent_values(q)
    ref = bridge.call("oracle_kinematics", path=str(out), q=q)
    ours = np.stack([np.array(cm.marker_positions(row, [1.07])).T for row in q])
    order = [model.marker_names.index(n) for n in ref["marker_names"]]
    assert np.abs(ours[:, order] - ref["markers"]).max() <= 1e-9
    scaled = load_model(out)
    assert scaled.bodies["femur_r"].mass_center == pytest.approx(model.bodies["femur_r"].mass_center * 1.07)
    assert scaled.bodies["femur_r"].inertia == pytest.approx(model.bodies["femur_r"].inertia * 1.07**2)


def test_number_format_round_trips() -> None:
    for value in (0.1, -0.070770028484130998, 1e-17, 123456.789, 0.0, 2.0):
        assert float(format_number(value)) == value
