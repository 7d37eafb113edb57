"""Both feet of the tutorial's trial (``gcp/uf_subject3_tutorial``, ``gait_1``: right foot on
plate 2, left foot on plate 1) in one settings file with two ``<GCPContactSurface>``
elements, built in ``tmp_path`` by :func:`nmsm.examples.tutorial_two_feet.write_two_feet_tutorial`
(the left foot's medial and lateral toe markers, which the tutorial's model lacks, added as
the mirror images of the right foot's).

Criterion: per foot, the vertical force RMS and the moment RMS of the two-foot run are no
worse than those of a run of that foot alone. The default suite runs the tutorial's V1
settings with 3 evaluations per task; the slow test runs them as they are (20).
"""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from nmsm.cli import main
from nmsm.errors import InputError
from nmsm.examples.tutorial_two_feet import write_two_feet_tutorial
from nmsm.io.osimx import read_osimx
from nmsm.io.settings.reader import read_settings_document
from nmsm.io.settings.gcp import GroundContactPersonalizationSettings
from nmsm.tools.gcp.run import load_feet, run_settings

JUDGED = ("Fy (N)", "Mx (N m)", "My (N m)", "Mz (N m)")
CHEAP_ITERATIONS = 3


def _run(tutorial, folder, feet, max_iterations=None, update_motion=False):
    settings = write_two_feet_tutorial(tutorial, folder, feet=feet, max_iterations=max_iterations)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # a few evaluations per task (or the tutorial's limit): accepted, stamped as unconverged
        return run_settings(settings, update_motion=update_motion, accept_unconverged=True)


def _runs(tutorial, tmp_path_factory, max_iterations):
    both = _run(tutorial, tmp_path_factory.mktemp("both_feet"), ("right", "left"), max_iterations,
                update_motion=True)
    alone = {foot: _run(tutorial, tmp_path_factory.mktemp(f"{foot}_foot"), (foot,), max_iterations)
             for foot in ("right", "left")}
    return both, alone


def _assert_each_foot_as_good_as_alone(both, alone):
    for index, foot in ((1, "right"), (2, "left")):
        single = alone[foot].errors[1]
        worse = {row: (both.errors[index][row], single[row]) for row in JUDGED
                 if both.errors[index][row] > single[row] * (1 + 1e-9)}
        assert not worse, f"{foot} foot worse with both feet than alone: {worse}"


@pytest.fixture(scope="module")
def cheap_runs(tutorial, tmp_path_factory):
    return _runs(tutorial, tmp_path_factory, CHEAP_ITERATIONS)


def test_both_feet_each_as_good_as_alone(cheap_runs):
    both, alone = cheap_runs
    _assert_each_foot_as_good_as_alone(both, alone)
    assert [len(group.feet) for group in both.groups] == [1, 1]  # the feet solved separately
    # each foot's reactions are fitted (the initial springs miss the vertical force by > 100 N RMS)
    for index in (1, 2):
        assert both.errors[index]["Fy (N)"] < 40.0


def test_both_feet_results_written(cheap_runs):
    both, _ = cheap_runs
    folder = both.results_directory
    for foot in (1, 2):
        for kind in ("experimentalFootKinematics", "optimizedFootKinematics", "replacedExperimentalGroundReactions",
                     "optimizedGroundReactions"):
            assert (folder / f"bodyModel_Foot_{foot}_{kind}.sto").is_file()
    for name in ("GRFData/gcp_modeled_gait_1.sto", "GRFData/gcp_modeled_gait_1_CoP.sto", "IKData/gcp_modeled_gait_1.sto"):
        assert (folder / name).is_file(), name
    (osimx,) = folder.glob("*.osimx")
    surfaces = read_osimx(osimx).contact_surfaces
    assert [(s.hindfoot_body, s.is_left_foot) for s in surfaces] == [("calcn_r", False), ("calcn_l", True)]
    assert [s.force_columns[1] for s in surfaces] == ["ground_force_2_vy", "ground_force_1_vy"]
    for surface, group in zip(surfaces, both.groups):
        assert surface.resting_spring_length == pytest.approx(group.state.resting_spring_length, rel=1e-12)
        np.testing.assert_allclose([k.spring_constant for k in surface.springs], group.state.spring_constants,
                                   rtol=1e-12)


def test_two_surface_osimx_read_by_treatment_and_export(cheap_runs, tmp_path):
    from nmsm.controllers.contact.elastic_foundation import ElasticFoundationContact
    from nmsm.model.osim import load_model

    both, _ = cheap_runs
    (osimx,) = both.results_directory.glob("*.osimx")
    model_file = both.settings.input_model_file
    surfaces = read_osimx(osimx).contact_surfaces
    contacts = ElasticFoundationContact.discover(SimpleNamespace(osimx=osimx,
                                                                 model=SimpleNamespace(model=load_model(model_file))))
    assert [(c.load_bodies, c.is_left_foot) for c in contacts] == [(("calcn_r", "toes_r"), False),
                                                                     (("calcn_l", "toes_l"), True)]
    assert [c.force_labels for c in contacts] == [s.force_columns for s in surfaces]
    exported = tmp_path / "exported.osim"
    assert main(["export", str(osimx), "--model", str(model_file), "-o", str(exported)]) == 0
    text = exported.read_text(encoding="utf-8")
    assert text.count("<SmoothSphereHalfSpaceForce") == sum(len(s.springs) for s in surfaces)
    assert "/bodyset/calcn_l" in text and "/bodyset/toes_r" in text


@pytest.mark.slow
def test_both_feet_each_as_good_as_alone_full_settings(tutorial, tmp_path_factory):
    both, alone = _runs(tutorial, tmp_path_factory, None)
    _assert_each_foot_as_good_as_alone(both, alone)


# ---------------------------------------------------------------------------- bad input
@pytest.fixture(scope="module")
def two_feet_settings(tutorial, tmp_path_factory):
    return write_two_feet_tutorial(tutorial, tmp_path_factory.mktemp("two_feet_settings"))


def _load(settings, tmp_path, replace):
    text = settings.read_text(encoding="utf-8")
    for old, new in replace.items():
        assert old in text
        text = text.replace(old, new)
    edited = tmp_path / "GCPSettings.xml"
    edited.write_text(text, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        load_feet(GroundContactPersonalizationSettings.from_document(read_settings_document(edited)))


@pytest.mark.parametrize(("replace", "element", "message"), [
    ({"<hindfoot_body>calcn_l<": "<hindfoot_body>calcn_r<"}, "<hindfoot_body>",
     "'calcn_r' is also the <hindfoot_body> of <GCPContactSurface> Right foot (line"),
    ({"ground_force_1_vx ground_force_1_vy ground_force_1_vz": "ground_force_2_vx ground_force_2_vy ground_force_2_vz"},
     "<force_columns>", "also the <force_columns> of <GCPContactSurface> Right foot"),
    ({"ground_moment_1_my": "ground_moment_3_my"}, "<moment_columns>",
     "names column 'ground_moment_3_my', which"),
    ({"ground_force_1_pz": "ground_force_1_qz"}, "<electrical_center_columns>",
     "names column 'ground_force_1_qz', which"),
    ({"<hindfoot_body>calcn_l<": "<hindfoot_body>calcn_left<"}, "<hindfoot_body>", "no body 'calcn_left' (model"),
    ({"<heel_marker>L_Heel<": "<heel_marker>L_Heel_Lateral<"}, "<heel_marker>",
     "the model has no marker 'L_Heel_Lateral'"),
], ids=["same-hindfoot", "same-plate", "moment-column", "center-column", "no-such-body", "no-such-marker"])
def test_bad_left_surface_is_one_error_at_its_line(two_feet_settings, tmp_path, replace, element, message):
    with pytest.raises(InputError) as caught:
        _load(two_feet_settings, tmp_path, replace)
    text = two_feet_settings.read_text(encoding="utf-8")
    line = next(i for i, t in enumerate(text.splitlines(), start=1) if '<GCPContactSurface name="Left foot"' in t)
    error = caught.value
    assert (error.file, error.line) == (str(tmp_path / "GCPSettings.xml"), line)
    assert error.element == f"<GCPContactSurface> Left foot: {element}"
    assert message in error.detail


def test_left_toe_markers_missing_from_the_model_say_how_to_add_them(tutorial, two_feet_settings, tmp_path):
    """The tutorial's own model has no ``L_Toe_Medial``: the error names the right foot's twin."""
    with pytest.raises(InputError) as caught:
        _load(two_feet_settings, tmp_path, {str(two_feet_settings.parent / "bodyModel.osim"):
                                            str(tutorial / "bodyModel.osim")})
    error = caught.value
    assert error.element == "<GCPContactSurface> Left foot: <medial_marker>"
    assert "no marker 'L_Toe_Medial'" in error.detail
    assert "the model has 'R_Toe_Medial' on 'calcn_r'" in error.expected


def test_bad_input_writes_nothing(two_feet_settings, tmp_path, capsys):
    text = two_feet_settings.read_text(encoding="utf-8").replace("<hindfoot_body>calcn_l<",
                                                                 "<hindfoot_body>calcn_r<")
    edited = tmp_path / "GCPSettings.xml"
    edited.write_text(text, encoding="utf-8")
    assert main(["run", str(edited), "-o", str(tmp_path / "results")]) != 0
    assert "the same foot twice" in capsys.readouterr().err
    assert not (tmp_path / "results").exists()
