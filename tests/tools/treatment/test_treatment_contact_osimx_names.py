"""A body or marker name of an .osimx contact surface that the model lacks, as the treatment
tools apply the surface (fuzz audit of .osimx files): ``<hindfoot_body>no_such_body``, a
spring's ``<parent_body>`` off the foot and an unknown ``<midfoot_superior_marker>`` were errors
naming the *model* file ("personalized.osim: <hindfoot_body>: no body ''", "personalized.osim:
spring on body ''", "personalized.osim: no markers NO_SUCH"), where the value is not.
Now the error names the .osimx, the surface's line and element, the spring, and the model."""

from __future__ import annotations

import re
from types import SimpleNamespace

import pytest

from nmsm.controllers.contact.elastic_foundation import ElasticFoundationContact
from nmsm.errors import InputError
from nmsm.model.osim import load_model

GCP = ("gcp", "uf_subject3_tutorial")


@pytest.fixture(scope="module")
def body_model(shared_data):
    return load_model(shared_data.joinpath(*GCP) / "bodyModel.osim")


def _discover(shared_data, tmp_path, body_model, pattern: str | None = None, value: str = ""):
    text = (shared_data.joinpath(*GCP) / "CompletedSettingsFiles" / "GCPResultsV4" / "bodyModel_gcp.osimx").read_text(
        encoding="utf-8")
    if pattern is not None:
        text, count = re.subn(pattern, value, text, count=1)
        assert count == 1
    path = tmp_path / "surface.osimx"
    path.write_text(text, encoding="utf-8")
    line = next(i for i, t in enumerate(text.splitlines(), start=1) if "<RCNLContactSurface>" in t)
    return path, line, ElasticFoundationContact.discover(SimpleNamespace(osimx=path, model=SimpleNamespace(model=body_model)))


@pytest.mark.parametrize(("pattern", "value", "element", "message"), [
    (r"<hindfoot_body>calcn_r<", "<hindfoot_body>calcn_rr<", "<hindfoot_body>", "no body 'calcn_rr'"),
    (r"<parent_body>[^<]*<", "<parent_body>tibia_r<", "<parent_body>",
     "spring 'spring_marker_1' is on body 'tibia_r', not on the foot"),
    (r"<midfoot_superior_marker>[^<]*<", "<midfoot_superior_marker>R_MIDFOOT<", "<midfoot_superior_marker>",
     "no marker 'R_MIDFOOT'"),
])
def test_a_body_of_the_osimx_the_model_lacks_names_the_osimx(shared_data, tmp_path, body_model, pattern, value,
                                                             element, message) -> None:
    with pytest.raises(InputError) as info:
        _discover(shared_data, tmp_path, body_model, pattern, value)
    error = info.value
    text = (tmp_path / "surface.osimx").read_text(encoding="utf-8")
    line = next(i for i, t in enumerate(text.splitlines(), start=1) if "<RCNLContactSurface>" in t)
    assert error.file == str(tmp_path / "surface.osimx") and error.element == element and error.line == line
    assert message in error.detail and "bodyModel.osim" in error.detail


def test_the_tutorial_surface_applies(shared_data, tmp_path, body_model) -> None:
    _, _, contacts = _discover(shared_data, tmp_path, body_model)
    assert [c.load_bodies for c in contacts] == [("calcn_r", "toes_r")]
