"""NCP's output ``.osimx`` names the model NCP used, so ``nmsm export`` needs no ``--model``.

The tutorial's input ``mtpResults/*_mtp.osimx`` says ``UF_Subject_3_reduced_muscles.osim``
(relative to the original tool's working folder, not to the ``.osimx``); copied verbatim into
the results folder it named a missing file and the export of NCP's own result failed."""

from __future__ import annotations

from pathlib import Path

from nmsm.cli import main
from nmsm.io.osimx import read_osimx
from nmsm.tools.dispatch import run_settings_file


def test_ncp_output_osimx_names_the_input_model_and_exports(shared_data, tmp_path, capsys) -> None:
    folder = shared_data / "ncp" / "uf_subject3_tutorial"
    results = tmp_path / "ncp"
    run = run_settings_file(folder / "CompletedSettingsFiles" / "NCPSettingsV1.xml", results_directory=results,
                            print_level=0)
    assert run.solver.success, run.solver.status
    (osimx,) = results.glob("*_ncp.osimx")
    model = read_osimx(osimx).model_path(osimx)
    assert Path(model).samefile(folder / "UF_Subject_3_reduced_muscles.osim")
    assert main(["export", str(osimx), "-o", str(tmp_path / "exported.osim")]) == 0
    assert (tmp_path / "exported.osim").stat().st_size > 0
