"""The tutorial's subject 3 chained by one pipeline file (JMP -> MTP -> NCP -> GCP) gives the
same results as running the four settings files one by one, with NCP pointed by hand at the
MTP results (what a user of the original does by copying folders).

The tutorial's MTP, NCP and GCP use their own models (reduced muscles, body model), so those
stages keep their ``input_model_file`` (``keep_settings_inputs``); GCP also keeps its own
(absent) ``.osimx``. NCP's ``input_osimx_file`` and ``mtp_results_directory`` are wired to the
pipeline's MTP stage. Slow: four real tools on real data (several minutes).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from nmsm.io.osimx import read_osimx
from nmsm.io.storage import read_storage

pytestmark = [pytest.mark.slow, pytest.mark.shared_data]


def _settings(shared: Path) -> dict[str, Path]:
    return {
        "jmp": shared / "jmp/uf_subject3_tutorial/CompletedSettingsFiles/JMPSettingsSimultaneous.xml",
        "mtp": shared / "mtp/uf_subject3_tutorial/CompletedSettingsFiles/MTPSettingsV1.xml",
        "ncp": shared / "ncp/uf_subject3_tutorial/CompletedSettingsFiles/NCPSettingsV1.xml",
        "gcp": shared / "gcp/uf_subject3_tutorial/CompletedSettingsFiles/GCPSettingsV1.xml",
    }


def _pipeline(folder: Path, files: dict[str, Path]) -> Path:
    keep = {"jmp": "", "mtp": "input_model_file", "ncp": "input_model_file",
            "gcp": "input_model_file input_osimx_file"}
    stages = "".join(f'<Stage name="{name}"><keep_settings_inputs>{keep[name]}</keep_settings_inputs>'
                     f"<settings_file>{path}</settings_file></Stage>" for name, path in files.items())
    path = folder / "pipeline.xml"
    path.write_text(f'<NMSMPipelineDocument Version="1.5.3"><PipelineTool name="subject 3">'
                    f"<results_directory>chained</results_directory><StageList>{stages}</StageList>"
                    f"</PipelineTool></NMSMPipelineDocument>")
    return path


def _ncp_settings_on(mtp_results: Path, original: Path, target: Path) -> Path:
    """The tutorial's NCP settings pointed at another MTP results folder (what a user edits)."""
    from nmsm.io.settings.ncp import NeuralControlPersonalizationSettings
    from nmsm.tools.pipeline.stage_settings import StageSettings

    settings = StageSettings.from_file(original, NeuralControlPersonalizationSettings)
    settings.set_path("mtp_results_directory", mtp_results)
    settings.set_path("input_osimx_file", next(mtp_results.glob("*_mtp.osimx")))
    settings.absolutize()
    target.write_text(settings.text(target, target.parent / "unused"))
    return target


def test_subject3_chain_equals_stages_one_by_one(shared_data: Path, tmp_path: Path) -> None:
    from nmsm.tools.gcp.run import run_settings as run_gcp
    from nmsm.tools.jmp.run import run_settings as run_jmp
    from nmsm.tools.mtp.run import run_settings as run_mtp
    from nmsm.tools.ncp.run import run_settings as run_ncp
    from nmsm.tools.pipeline.runner import RAN, UP_TO_DATE, run_pipeline_file

    files = _settings(shared_data)
    # the tutorials as they are: GCP V1 stops at its evaluation limit (as the original did)
    run = run_pipeline_file(_pipeline(tmp_path, files), log=None, accept_unconverged=True)
    assert [s.status for s in run.stages] == [RAN] * 4
    assert run.stage("ncp").wired["mtp_results_directory"] == "mtp_results from stage 'mtp'"
    chained = tmp_path / "chained"

    alone = tmp_path / "alone"
    jmp = run_jmp(files["jmp"], results_directory=alone / "jmp", quiet=True, accept_unconverged=True)
    run_mtp(files["mtp"], results_directory=alone / "mtp", accept_unconverged=True)
    ncp_file = _ncp_settings_on(alone / "mtp", files["ncp"], tmp_path / "ncp_alone.xml")
    run_ncp(ncp_file, results_directory=alone / "ncp", print_level=0, accept_unconverged=True)
    run_gcp(files["gcp"], results_directory=alone / "gcp", accept_unconverged=True)

    # JMP: the same personalized model
    assert (chained / "jmp" / jmp.output_model.name).read_text() == jmp.output_model.read_text()
    # MTP and NCP: the same muscle parameters; NCP the same synergy weights
    for stage in ("mtp", "ncp"):
        a = read_osimx(next((chained / stage).glob("*.osimx"))).muscles
        b = read_osimx(next((alone / stage).glob("*.osimx"))).muscles
        assert a.keys() == b.keys()
        for name in a:
            for field in ("electromechanical_delay", "activation_time_constant", "emg_scale_factor",
                          "optimal_fiber_length", "tendon_slack_length"):
                x, y = getattr(a[name], field), getattr(b[name], field)
                assert (x is None) == (y is None)
                if x is not None:
                    assert x == pytest.approx(y, rel=1e-9, abs=1e-12), f"{stage} {name} {field}"
    wa = read_storage(chained / "ncp" / "synergyWeights.sto")
    wb = read_storage(alone / "ncp" / "synergyWeights.sto")
    np.testing.assert_allclose(wa.data, wb.data, rtol=1e-8, atol=1e-10)
    # GCP: the same springs and contact properties
    sa = read_osimx(next((chained / "gcp").glob("*_gcp.osimx"))).contact_surfaces
    sb = read_osimx(next((alone / "gcp").glob("*_gcp.osimx"))).contact_surfaces
    assert len(sa) == len(sb)
    for x, y in zip(sa, sb):
        assert x.resting_spring_length == pytest.approx(y.resting_spring_length, rel=1e-8)
        np.testing.assert_allclose([s.spring_constant for s in x.springs], [s.spring_constant for s in y.springs],
                                   rtol=1e-8)
    # run again: every stage up to date
    again = run_pipeline_file(tmp_path / "pipeline.xml", log=None, accept_unconverged=True)
    assert [s.status for s in again.stages] == [UP_TO_DATE] * 4
