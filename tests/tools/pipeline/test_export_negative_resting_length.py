"""``nmsm export`` of a GCP ``.osimx`` whose resting spring length is not positive (the original
tool's GCPResultsV4: -0.43 mm). The length is the contact spheres' radius: it was a
``ValueError: math domain error`` traceback; now one error naming the value and ``--no-contact``,
and nothing written. With ``--no-contact`` the model is exported."""

from __future__ import annotations

from nmsm.cli import main

GCP = ("gcp", "uf_subject3_tutorial")


def test_non_positive_resting_length_is_a_clear_error(shared_data, tmp_path, capsys) -> None:
    folder = shared_data.joinpath(*GCP)
    osimx = folder / "CompletedSettingsFiles" / "GCPResultsV4" / "bodyModel_gcp.osimx"
    args = ["export", str(osimx), "--model", str(folder / "bodyModel.osim")]
    assert main([*args, "-o", str(tmp_path / "with_contact.osim")]) != 0
    err = capsys.readouterr().err
    assert "resting spring length" in err and "--no-contact" in err and "Traceback" not in err
    assert not (tmp_path / "with_contact.osim").exists()
    assert main([*args, "--no-contact", "-o", str(tmp_path / "no_contact.osim")]) == 0
    assert (tmp_path / "no_contact.osim").stat().st_size > 0
