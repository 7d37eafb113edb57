"""Tutorial subject 3, NCP settings V1-V3 run as they are (``nmsm run`` path), against NCPResultsV1-V3.

Both our results and the original's are scored by our code on the same inputs and terms
(:mod:`nmsm.tools.ncp.table`): our final cost must not exceed the original's, and the mean
moment RMS and the activation RMS must be within 1.1 x the original's.
"""

from __future__ import annotations

import pytest

from nmsm.io.osimx import read_osimx
from nmsm.tools.dispatch import run_settings_file
from nmsm.tools.ncp.table import compare_results, format_table

VERSIONS = (1, 2, 3)


@pytest.fixture(scope="module")
def rows(shared_data, tmp_path_factory):
    folder = shared_data / "ncp" / "uf_subject3_tutorial" / "CompletedSettingsFiles"
    out = []
    for v in VERSIONS:
        results = tmp_path_factory.mktemp(f"V{v}")
        run = run_settings_file(folder / f"NCPSettingsV{v}.xml", results_directory=results, print_level=0)
        assert run.solver.success, run.solver.status
        out.append((run, compare_results(folder / f"NCPSettingsV{v}.xml", results, folder / f"NCPResultsV{v}", label=f"V{v}")))
    print()
    print(format_table([row for _, row in out], per_coordinate=True))
    return out


@pytest.mark.parametrize("index", range(len(VERSIONS)))
def test_cost_not_above_original(rows, index) -> None:
    _, row = rows[index]
    assert row.ours.costs["total"] <= row.original.costs["total"]


@pytest.mark.parametrize("index", range(len(VERSIONS)))
def test_fit_within_ten_percent_of_original(rows, index) -> None:
    _, row = rows[index]
    assert row.ours.metrics.mean_moment_rms <= 1.1 * row.original.metrics.mean_moment_rms
    assert row.ours.metrics.activation_rms_pooled <= 1.1 * row.original.metrics.activation_rms_pooled


def test_outputs_match_the_original_layout(rows, shared_data) -> None:
    run, row = rows[0]
    folder = run.results_directory
    original = shared_data / "ncp" / "uf_subject3_tutorial" / "CompletedSettingsFiles" / "NCPResultsV1"
    ours_files = {p.relative_to(folder).as_posix() for p in folder.rglob("*.sto")} | {p.name for p in folder.glob("*.osimx")}
    theirs = {p.relative_to(original).as_posix() for p in original.rglob("*.sto")} | {p.name for p in original.glob("*.osimx")}
    assert theirs <= ours_files
    osimx = read_osimx(folder / "UF_Subject_3_reduced_muscles_mtp_ncp.osimx")
    assert [(s.muscle_group_name, s.num_synergies) for s in osimx.synergies] == [("RightLeg", 3)]
    assert set(osimx.muscles) == set(read_osimx(original / "UF_Subject_3_reduced_muscles_mtp_ncp.osimx").muscles)
    assert row.ours.costs["total"] == pytest.approx(run.costs["total"], rel=1e-9)  # files hold what was optimized
