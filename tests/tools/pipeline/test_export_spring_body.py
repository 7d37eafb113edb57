"""``nmsm export`` of a GCP spring whose ``<parent_body>`` is no body of the model (fuzz audit of
.osimx files): the contact sphere was written on ``/bodyset/<name>``, the export exited 0 and
OpenSim could not load the model ("could not find '/bodyset/no_such_body'"; an emptied
``<parent_body>`` gave ``/bodyset/``). Now one error naming the .osimx, the element, the spring,
close matches and the model's bodies, and nothing written."""

from __future__ import annotations

import re

import pytest

from nmsm.cli import main

GCP = ("gcp", "uf_subject3_tutorial")


def _osimx(shared_data, tmp_path, parent_body: str | None):
    folder = shared_data.joinpath(*GCP)
    text = (folder / "CompletedSettingsFiles" / "GCPResultsV4" / "bodyModel_gcp.osimx").read_text(encoding="utf-8")
    # the tutorial's resting length is negative (a sphere radius cannot be): a positive one
    text = re.sub(r"<resting_spring_length>[^<]*<", "<resting_spring_length>0.01<", text)
    if parent_body is not None:
        text, count = re.subn(r"<parent_body>[^<]*<", f"<parent_body>{parent_body}<", text, count=1)
        assert count == 1
    path = tmp_path / "mutated_gcp.osimx"
    path.write_text(text, encoding="utf-8")
    return path, folder / "bodyModel.osim"


@pytest.mark.parametrize(("parent_body", "hint"), [("calcn_rr", "did you mean 'calcn_r'"), ("", "")])
def test_a_spring_on_a_body_the_model_lacks_is_one_error(shared_data, tmp_path, capsys, parent_body, hint) -> None:
    osimx, model = _osimx(shared_data, tmp_path, parent_body)
    output = tmp_path / "exported.osim"
    assert main(["export", str(osimx), "--model", str(model), "-o", str(output)]) != 0
    err = capsys.readouterr().err
    assert f"{osimx}: <parent_body>: the parent body '{parent_body}' of spring 'spring_marker_1'" in err
    assert hint in err and "calcn_r" in err and "Traceback" not in err
    assert not output.exists()
    # --no-contact leaves the springs out: the model is exported
    assert main(["export", str(osimx), "--model", str(model), "--no-contact", "-o", str(output)]) == 0


def test_springs_on_the_model_bodies_export(shared_data, tmp_path) -> None:
    osimx, model = _osimx(shared_data, tmp_path, None)
    output = tmp_path / "exported.osim"
    assert main(["export", str(osimx), "--model", str(model), "-o", str(output)]) == 0
    assert output.read_text(encoding="utf-8").count("<SmoothSphereHalfSpaceForce") == 83
